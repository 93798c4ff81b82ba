//! Stanford `.ply` reader (ASCII and binary, either byte order), producing a [`PlcInput`] of
//! polygon facets.
//!
//! Supported subset:
//! - Header: `ply`, `format ascii|binary_little_endian|binary_big_endian 1.0`, `comment` and
//!   `obj_info` lines, `element NAME COUNT`, `property TYPE NAME` and
//!   `property list COUNT_TYPE ITEM_TYPE NAME`, `end_header`. Types: `char uchar short ushort
//!   int uint float double` and their sized names (`int8` ... `float64`).
//! - `vertex` needs scalar properties `x`, `y`, `z` (any numeric type; others are ignored);
//!   `face` needs an integer list property `vertex_indices` (or `vertex_index`) of 3 or more
//!   0-based vertex ids: triangles and polygons. Other elements (`edge`, `material`, ...) are
//!   read and skipped, in either order.
//! - ASCII bodies are free-form whitespace-separated numbers (usually one element per line);
//!   errors name the 1-based line. Binary errors name the element and the byte offset; bytes
//!   after the last element are ignored.
//!
//! Each face becomes one facet with one polygon and marker = its 1-based face index; with
//! `ReadOptions::merge_coplanar` the facets are then merged by
//! [`crate::plc::coplanar::merge_coplanar_facets`], which renumbers the markers the same way.
//! Not supported: triangle strips (`tristrips`), coordinates stored as lists.

use super::text::{cap, err_at, err_file, read_bytes, with_path, Lines, Tokens};
use super::{IoError, ReadOptions};
use crate::plc::{Facet, PlcInput};
use glam::DVec3;
use std::path::Path;

/// Reads a `.ply` file.
pub fn read_ply(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let bytes = read_bytes(path)?;
    parse_ply(&bytes, options).map_err(|e| with_path(e, path))
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Scalar {
    I8,
    U8,
    I16,
    U16,
    I32,
    U32,
    F32,
    F64,
}

impl Scalar {
    fn parse(name: &str) -> Option<Self> {
        Some(match name {
            "char" | "int8" => Scalar::I8,
            "uchar" | "uint8" => Scalar::U8,
            "short" | "int16" => Scalar::I16,
            "ushort" | "uint16" => Scalar::U16,
            "int" | "int32" => Scalar::I32,
            "uint" | "uint32" => Scalar::U32,
            "float" | "float32" => Scalar::F32,
            "double" | "float64" => Scalar::F64,
            _ => return None,
        })
    }

    fn size(self) -> usize {
        match self {
            Scalar::I8 | Scalar::U8 => 1,
            Scalar::I16 | Scalar::U16 => 2,
            Scalar::I32 | Scalar::U32 | Scalar::F32 => 4,
            Scalar::F64 => 8,
        }
    }

    fn name(self) -> &'static str {
        match self {
            Scalar::I8 => "char",
            Scalar::U8 => "uchar",
            Scalar::I16 => "short",
            Scalar::U16 => "ushort",
            Scalar::I32 => "int",
            Scalar::U32 => "uint",
            Scalar::F32 => "float",
            Scalar::F64 => "double",
        }
    }

    fn is_int(self) -> bool {
        !matches!(self, Scalar::F32 | Scalar::F64)
    }
}

#[derive(Debug)]
enum Kind {
    Scalar(Scalar),
    List { count: Scalar, item: Scalar },
}

#[derive(Debug)]
struct Property {
    name: String,
    kind: Kind,
}

#[derive(Debug)]
struct Element {
    name: String,
    count: usize,
    line: usize,
    props: Vec<Property>,
}

impl Element {
    fn scalar(&self, name: &str) -> Result<usize, IoError> {
        self.props
            .iter()
            .position(|p| p.name == name && matches!(p.kind, Kind::Scalar(_)))
            .ok_or_else(|| {
                err_at(
                    self.line,
                    format!("element '{}' has no scalar property '{name}'", self.name),
                )
            })
    }
}

#[derive(Clone, Copy, PartialEq, Debug)]
enum Format {
    Ascii,
    Binary { big_endian: bool },
}

struct Header {
    format: Format,
    elements: Vec<Element>,
    /// Byte offset of the body and number of header lines.
    body: usize,
    lines: usize,
}

/// The header's lines with their numbers, up to and including `end_header`.
fn parse_header(bytes: &[u8]) -> Result<Header, IoError> {
    let mut format = None;
    let mut elements: Vec<Element> = Vec::new();
    let mut pos = 0;
    let mut line = 0;
    loop {
        if pos >= bytes.len() {
            return Err(err_at(
                line + 1,
                "unexpected end of file: expected 'end_header'",
            ));
        }
        let end = bytes[pos..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(bytes.len(), |i| pos + i);
        let text = String::from_utf8_lossy(&bytes[pos..end]);
        pos = (end + 1).min(bytes.len());
        line += 1;
        let mut words = text.split_whitespace();
        let kw = words.next().unwrap_or("");
        if line == 1 {
            if kw != "ply" || words.next().is_some() {
                return Err(err_at(
                    1,
                    format!("expected 'ply' header, found '{}'", text.trim()),
                ));
            }
            continue;
        }
        match kw {
            "format" => {
                let f = match words.next() {
                    Some("ascii") => Format::Ascii,
                    Some("binary_little_endian") => Format::Binary { big_endian: false },
                    Some("binary_big_endian") => Format::Binary { big_endian: true },
                    other => {
                        return Err(err_at(
                            line,
                            format!(
                                "unknown PLY format '{}' (ascii, binary_little_endian or \
                                 binary_big_endian)",
                                other.unwrap_or("")
                            ),
                        ))
                    }
                };
                if words.next() != Some("1.0") {
                    return Err(err_at(line, "expected PLY version 1.0 after the format"));
                }
                format = Some(f);
            }
            "comment" | "obj_info" | "" => {}
            "element" => {
                let name = words
                    .next()
                    .ok_or_else(|| err_at(line, "expected element name, found end of line"))?;
                let count = words.next().unwrap_or("");
                let count = super::text::parse_usize(count, line, "element count")?;
                elements.push(Element {
                    name: name.to_string(),
                    count,
                    line,
                    props: Vec::new(),
                });
            }
            "property" => {
                let el = elements
                    .last_mut()
                    .ok_or_else(|| err_at(line, "'property' before any 'element'"))?;
                let ty = |w: Option<&str>| {
                    let w = w.unwrap_or("");
                    Scalar::parse(w)
                        .ok_or_else(|| err_at(line, format!("unknown property type '{w}'")))
                };
                let first = words.next();
                let kind = if first == Some("list") {
                    let count = ty(words.next())?;
                    let item = ty(words.next())?;
                    if !count.is_int() {
                        return Err(err_at(line, "a list's count type must be an integer type"));
                    }
                    Kind::List { count, item }
                } else {
                    Kind::Scalar(ty(first)?)
                };
                let name = words
                    .next()
                    .ok_or_else(|| err_at(line, "expected property name, found end of line"))?;
                el.props.push(Property {
                    name: name.to_string(),
                    kind,
                });
            }
            "end_header" => break,
            other => {
                return Err(err_at(line, format!("unknown PLY header line '{other}'")));
            }
        }
    }
    let format = format.ok_or_else(|| err_at(2, "no 'format' line in the PLY header"))?;
    Ok(Header {
        format,
        elements,
        body: pos,
        lines: line,
    })
}

/// Where element values come from.
enum Body<'a> {
    Ascii(Tokens<'a>),
    Binary {
        bytes: &'a [u8],
        pos: usize,
        big_endian: bool,
    },
}

/// Context of a value, turned into a message only on error.
struct At<'e> {
    element: &'e Element,
    index: usize,
    property: &'e str,
}

impl At<'_> {
    fn what(&self) -> String {
        format!(
            "'{}' of {} {} of {}",
            self.property,
            self.element.name,
            self.index + 1,
            self.element.count
        )
    }
}

impl Body<'_> {
    /// The line of the last ASCII value read (binary: none).
    fn line(&self) -> Option<usize> {
        match self {
            Body::Ascii(t) => t.line(),
            Body::Binary { .. } => None,
        }
    }

    fn value(&mut self, ty: Scalar, at: &At) -> Result<f64, IoError> {
        match self {
            Body::Ascii(tok) => {
                let Some((line, w)) = tok.next_opt() else {
                    return Err(tok.eof(&at.what()));
                };
                let v = if ty.is_int() {
                    w.parse::<i64>().ok().map(|v| v as f64)
                } else {
                    w.parse::<f64>().ok()
                };
                let v =
                    v.ok_or_else(|| err_at(line, format!("bad number '{w}' for {}", at.what())))?;
                if !in_range(ty, v) {
                    return Err(err_at(
                        line,
                        format!("{} = {w} does not fit its type {}", at.what(), ty.name()),
                    ));
                }
                Ok(v)
            }
            Body::Binary {
                bytes,
                pos,
                big_endian,
            } => {
                let n = ty.size();
                let Some(b) = bytes.get(*pos..*pos + n) else {
                    return Err(err_file(format!(
                        "binary PLY truncated: {} needs {n} bytes at byte offset {pos}, the file \
                         has {}",
                        at.what(),
                        bytes.len()
                    )));
                };
                *pos += n;
                Ok(decode(ty, b, *big_endian))
            }
        }
    }
}

fn in_range(ty: Scalar, v: f64) -> bool {
    let (lo, hi) = match ty {
        Scalar::I8 => (i8::MIN as f64, i8::MAX as f64),
        Scalar::U8 => (0.0, u8::MAX as f64),
        Scalar::I16 => (i16::MIN as f64, i16::MAX as f64),
        Scalar::U16 => (0.0, u16::MAX as f64),
        Scalar::I32 => (i32::MIN as f64, i32::MAX as f64),
        Scalar::U32 => (0.0, u32::MAX as f64),
        Scalar::F32 | Scalar::F64 => return true,
    };
    v >= lo && v <= hi
}

fn decode(ty: Scalar, b: &[u8], big: bool) -> f64 {
    macro_rules! num {
        ($t:ty, $n:literal) => {{
            let mut a = [0u8; $n];
            a.copy_from_slice(b);
            if big {
                <$t>::from_be_bytes(a) as f64
            } else {
                <$t>::from_le_bytes(a) as f64
            }
        }};
    }
    match ty {
        Scalar::I8 => b[0] as i8 as f64,
        Scalar::U8 => b[0] as f64,
        Scalar::I16 => num!(i16, 2),
        Scalar::U16 => num!(u16, 2),
        Scalar::I32 => num!(i32, 4),
        Scalar::U32 => num!(u32, 4),
        Scalar::F32 => num!(f32, 4),
        Scalar::F64 => num!(f64, 8),
    }
}

/// A face as read: vertex ids not yet checked against the vertex count, and its line (ASCII).
struct RawFace {
    ids: Vec<f64>,
    line: Option<usize>,
}

/// Parses the bytes of a `.ply` file, ASCII or binary.
pub fn parse_ply(bytes: &[u8], options: &ReadOptions) -> Result<PlcInput, IoError> {
    let header = parse_header(bytes)?;
    let text;
    let mut body = match header.format {
        Format::Ascii => {
            text = String::from_utf8_lossy(&bytes[header.body..]);
            Body::Ascii(Tokens::of_lines(Lines::after(&text, header.lines)))
        }
        Format::Binary { big_endian } => Body::Binary {
            bytes,
            pos: header.body,
            big_endian,
        },
    };
    let mut vertices: Option<Vec<DVec3>> = None;
    let mut faces: Option<Vec<RawFace>> = None;
    let mut row: Vec<f64> = Vec::new();
    let mut list: Vec<f64> = Vec::new();
    for el in &header.elements {
        if el.props.is_empty() {
            continue; // nothing stored
        }
        let coords = match el.name.as_str() {
            "vertex" => Some([el.scalar("x")?, el.scalar("y")?, el.scalar("z")?]),
            _ => None,
        };
        let ids = match el.name.as_str() {
            "face" => Some(face_list(el)?),
            _ => None,
        };
        let mut verts = Vec::with_capacity(if coords.is_some() { cap(el.count) } else { 0 });
        let mut fs = Vec::with_capacity(if ids.is_some() { cap(el.count) } else { 0 });
        for index in 0..el.count {
            row.clear();
            for (k, p) in el.props.iter().enumerate() {
                let at = At {
                    element: el,
                    index,
                    property: &p.name,
                };
                match p.kind {
                    Kind::Scalar(ty) => row.push(body.value(ty, &at)?),
                    Kind::List { count, item } => {
                        let n = body.value(count, &at)?;
                        if n < 0.0 {
                            return Err(located(
                                body.line(),
                                format!("negative list length {n} for {}", at.what()),
                            ));
                        }
                        list.clear();
                        list.reserve(cap(n as usize));
                        for _ in 0..n as usize {
                            list.push(body.value(item, &at)?);
                        }
                        if ids == Some(k) {
                            let face_line = body.line();
                            if list.len() < 3 {
                                return Err(located(
                                    face_line,
                                    format!(
                                        "face {} has {} corners (at least 3 needed)",
                                        index + 1,
                                        list.len()
                                    ),
                                ));
                            }
                            fs.push(RawFace {
                                ids: list.clone(),
                                line: face_line,
                            });
                        }
                        row.push(0.0);
                    }
                }
            }
            if let Some([x, y, z]) = coords {
                let p = DVec3::new(row[x], row[y], row[z]);
                if !p.is_finite() {
                    return Err(located(
                        body.line(),
                        format!("vertex {} of {} is not finite", index + 1, el.count),
                    ));
                }
                verts.push(p);
            }
        }
        if coords.is_some() {
            vertices = Some(verts);
        }
        if ids.is_some() {
            faces = Some(fs);
        }
    }
    if let Body::Ascii(tok) = &mut body {
        if let Some((line, _)) = tok.next_opt() {
            return Err(err_at(
                line,
                "unexpected data after the elements declared (is a count wrong?)",
            ));
        }
    }
    let vertices = vertices.ok_or_else(|| err_file("no 'vertex' element in the PLY header"))?;
    let faces = faces.ok_or_else(|| err_file("no 'face' element in the PLY header"))?;
    assemble(vertices, &faces, options)
}

/// The index of a face element's vertex list property.
fn face_list(el: &Element) -> Result<usize, IoError> {
    let k = el
        .props
        .iter()
        .position(|p| {
            matches!(p.kind, Kind::List { .. })
                && (p.name == "vertex_indices" || p.name == "vertex_index")
        })
        .ok_or_else(|| {
            err_at(
                el.line,
                "element 'face' has no list property 'vertex_indices'",
            )
        })?;
    if let Kind::List { item, .. } = el.props[k].kind {
        if !item.is_int() {
            return Err(err_at(
                el.line,
                "face vertex indices must have an integer type",
            ));
        }
    }
    Ok(k)
}

fn located(line: Option<usize>, message: String) -> IoError {
    match line {
        Some(l) => err_at(l, message),
        None => err_file(message),
    }
}

fn assemble(
    vertices: Vec<DVec3>,
    faces: &[RawFace],
    options: &ReadOptions,
) -> Result<PlcInput, IoError> {
    let nv = vertices.len();
    super::text::to_u32(nv, 1, "number of vertices")?;
    let mut plc = PlcInput {
        vertices,
        ..PlcInput::default()
    };
    plc.facets.reserve(faces.len());
    for (i, f) in faces.iter().enumerate() {
        let mut poly = Vec::with_capacity(f.ids.len());
        for &v in &f.ids {
            if v < 0.0 || v >= nv as f64 {
                return Err(located(
                    f.line,
                    format!(
                        "face {}: vertex index {v} out of range (valid: 0..={})",
                        i + 1,
                        nv as i64 - 1
                    ),
                ));
            }
            poly.push(v as u32);
        }
        plc.facets.push(Facet {
            polygons: vec![poly],
            marker: i32::try_from(i + 1).unwrap_or(i32::MAX),
            ..Facet::default()
        });
    }
    if options.merge_coplanar {
        crate::plc::coplanar::merge_coplanar_facets(&mut plc);
    }
    Ok(plc)
}

#[cfg(test)]
mod tests;
