//! VTK XML UnstructuredGrid (`.vtu`) writer, and a reader for the same subset (the binary
//! appended form of the same arrays: `super::vtu_binary`, written only).
//!
//! Written (VTK file version 1.0, ASCII, one `Piece`): `Points` as `Float64` with 3
//! components; `Cells` with `connectivity` and `offsets` as `Int64` and `types` as `UInt8`
//! (all 10 = `VTK_TETRA`); `CellData` with `region` (`Int32`, the tet region attribute) and one
//! `Float64` array per [`CellField`]. Floats are written so they read back bit for bit (checked
//! against VTK 9.7's reader). A non-finite field value (only a degenerate tet has one) is
//! written as `nan`, `inf` or `-inf`: this module reads them back exactly and VTK 9.7 reads
//! `nan` and `inf`, but it reads `-inf` as `inf`, and older VTK ASCII parsers may reject such
//! an array.
//! Boundary triangles are not written (a `.vtu` holds the tets only: use `.mesh` or `.msh` to
//! keep boundary markers). Ten-node tets ([`format_vtu_quadratic`]): the points are the corners
//! and then the mid-edge nodes, the cells `VTK_QUADRATIC_TETRA` (24) with the corners and the
//! edges ab, bc, ac, ad, bd, cd (VTK's order, the mesh's own); the cell data is the same.
//!
//! One piece of a distributed mesh ([`write_vtu_piece`], `crate::distributed`) adds the global
//! ids as `Int64` arrays: `PointData` `GlobalNodeId` (declared as the point `GlobalIds`) and
//! `CellData` `GlobalCellId`; [`write_pvtu`] writes the `.pvtu` naming the pieces (no ghosts).
//!
//! Read: ASCII `DataArray`s only (no `binary`/`appended`/compressed data), one `Piece`, cells of
//! type 10 only; `Points`, `connectivity`, `offsets`, `types`, the `region` cell array (tets get
//! region 0 when it is absent), every other `CellData` array as a named field and every scalar
//! `PointData` array as a named point field. Errors carry the line of the offending array.

use super::elements::Elements;
use super::text::{
    check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, err_at, err_file,
    float_text, parse_f64, read_text, to_u32, with_path, write_err, write_float_line,
    write_int_line, write_line,
};
use super::{CellField, IoError};
use crate::mesh::{QuadraticNodes, TetMesh};
use glam::DVec3;
use std::io::Write;
use std::path::Path;

/// Writes `mesh` with `cell_fields` as a `.vtu` file.
pub fn write_vtu(path: &Path, mesh: &TetMesh, cell_fields: &[CellField]) -> Result<(), IoError> {
    check_mesh(mesh, &field_lens(cell_fields)).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_vtu(&mut w, mesh, cell_fields)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Name of the point array of global vertex ids in a piece of a distributed mesh.
pub const GLOBAL_NODE_ID: &str = "GlobalNodeId";
/// Name of the cell array of global tet ids in a piece of a distributed mesh.
pub const GLOBAL_CELL_ID: &str = "GlobalCellId";

/// The global ids of one piece of a distributed mesh: one per point, one per cell.
#[derive(Debug, Clone, Copy)]
pub struct GlobalIds<'a> {
    pub points: &'a [i64],
    pub cells: &'a [i64],
}

/// Writes one piece of a distributed mesh: [`write_vtu`]'s file plus the global ids
/// ([`GLOBAL_NODE_ID`] point data, [`GLOBAL_CELL_ID`] cell data); `binary`: in VTK's binary
/// appended form (`super::vtu_binary`), else ASCII.
pub fn write_vtu_piece(
    path: &Path,
    mesh: &TetMesh,
    ids: GlobalIds,
    cell_fields: &[CellField],
    binary: bool,
) -> Result<(), IoError> {
    check_mesh(mesh, &field_lens(cell_fields)).map_err(|e| with_path(e, path))?;
    check_global_ids(mesh, ids).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    let written = if binary {
        super::vtu_binary::format_piece(&mut w, mesh, ids, cell_fields)
    } else {
        format_elements(&mut w, &Elements::new(mesh, None), cell_fields, Some(ids))
    };
    written
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// One global id per point and per cell of `mesh`.
fn check_global_ids(mesh: &TetMesh, ids: GlobalIds) -> Result<(), IoError> {
    if ids.points.len() != mesh.vertices.len() || ids.cells.len() != mesh.tets.len() {
        return Err(err_file(format!(
            "{} global point ids for {} points, {} global cell ids for {} cells",
            ids.points.len(),
            mesh.vertices.len(),
            ids.cells.len(),
            mesh.tets.len()
        )));
    }
    Ok(())
}

/// Writes the `.pvtu` of a distributed mesh whose pieces ([`write_vtu_piece`], `cell_fields`
/// the names of their Float64 cell fields) are `pieces`, paths relative to the `.pvtu`'s folder.
pub fn write_pvtu(path: &Path, pieces: &[String], cell_fields: &[&str]) -> Result<(), IoError> {
    let mut w = create(path)?;
    format_pvtu(&mut w, pieces, cell_fields)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// The `.pvtu` document of [`write_pvtu`]: the arrays of [`write_vtu_piece`], in its order.
pub fn format_pvtu<W: Write>(
    w: &mut W,
    pieces: &[String],
    cell_fields: &[&str],
) -> std::io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"PUnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">"
    )?;
    // No ghost cells: every tet is in exactly one piece.
    writeln!(w, "<PUnstructuredGrid GhostLevel=\"0\">")?;
    writeln!(w, "<PPointData GlobalIds=\"{GLOBAL_NODE_ID}\">")?;
    writeln!(w, "<PDataArray type=\"Int64\" Name=\"{GLOBAL_NODE_ID}\"/>")?;
    writeln!(w, "</PPointData>")?;
    writeln!(
        w,
        "<PCellData Scalars=\"region\" GlobalIds=\"{GLOBAL_CELL_ID}\">"
    )?;
    writeln!(w, "<PDataArray type=\"Int32\" Name=\"region\"/>")?;
    writeln!(w, "<PDataArray type=\"Int64\" Name=\"{GLOBAL_CELL_ID}\"/>")?;
    for name in cell_fields {
        writeln!(
            w,
            "<PDataArray type=\"Float64\" Name=\"{}\"/>",
            xml_escape(name)
        )?;
    }
    writeln!(w, "</PCellData>")?;
    writeln!(w, "<PPoints>")?;
    writeln!(
        w,
        "<PDataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"/>"
    )?;
    writeln!(w, "</PPoints>")?;
    for piece in pieces {
        writeln!(w, "<Piece Source=\"{}\"/>", xml_escape(piece))?;
    }
    writeln!(w, "</PUnstructuredGrid>\n</VTKFile>")
}

/// Writes `mesh` with its mid-edge nodes and `cell_fields` as a `.vtu` file of
/// `VTK_QUADRATIC_TETRA` cells.
pub fn write_vtu_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
    cell_fields: &[CellField],
) -> Result<(), IoError> {
    check_mesh(mesh, &field_lens(cell_fields)).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_vtu_quadratic(&mut w, mesh, quadratic, cell_fields)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Escapes a string for an XML attribute value.
pub(super) fn xml_escape(s: &str) -> String {
    let mut out = String::with_capacity(s.len());
    for c in s.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            _ => out.push(c),
        }
    }
    out
}

/// Writes items `per_line` to a line, each appended to the line by `text`.
fn write_rows<W: Write, T: Copy>(
    w: &mut W,
    items: &[T],
    per_line: usize,
    mut text: impl FnMut(&mut Vec<u8>, T),
) -> std::io::Result<()> {
    let mut line = Vec::new();
    for chunk in items.chunks(per_line) {
        write_line(w, &mut line, chunk, &mut text)?;
    }
    Ok(())
}

/// Appends integer `x` to a line.
fn push_int(line: &mut Vec<u8>, x: impl itoa::Integer) {
    line.extend_from_slice(itoa::Buffer::new().format(x).as_bytes());
}

/// The document up to the first `DataArray`: XML declaration, `VTKFile` (version 1.0, little
/// endian, `UInt64` headers), `UnstructuredGrid`, the one `Piece` and `<Points>`. Shared by the
/// ASCII and the binary appended writers.
pub(super) fn write_prologue<W: Write>(
    w: &mut W,
    n_points: usize,
    n_cells: usize,
) -> std::io::Result<()> {
    writeln!(w, "<?xml version=\"1.0\"?>")?;
    writeln!(
        w,
        "<VTKFile type=\"UnstructuredGrid\" version=\"1.0\" byte_order=\"LittleEndian\" \
         header_type=\"UInt64\">"
    )?;
    writeln!(w, "<UnstructuredGrid>")?;
    writeln!(
        w,
        "<Piece NumberOfPoints=\"{n_points}\" NumberOfCells=\"{n_cells}\">"
    )?;
    writeln!(w, "<Points>")
}

/// The VTK cell type of the tets and its node count: `VTK_TETRA` (10) with 4 nodes, or
/// `VTK_QUADRATIC_TETRA` (24) with 10 (corners, then edges ab, bc, ac, ad, bd, cd: the mesh's
/// own order).
pub(super) fn cell_type(el: &Elements) -> (u8, usize) {
    if el.is_quadratic() {
        (24, 10)
    } else {
        (10, 4)
    }
}

/// Writes `mesh` in `.vtu` format to any writer.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_vtu<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    cell_fields: &[CellField],
) -> std::io::Result<()> {
    check_mesh_io(mesh, &field_lens(cell_fields))?;
    format_elements(w, &Elements::new(mesh, None), cell_fields, None)
}

/// Writes `mesh` with its mid-edge nodes as `VTK_QUADRATIC_TETRA` cells in `.vtu` format:
/// the points are the corners and then the mid-edge nodes, the cell data as in [`format_vtu`].
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_vtu_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
    cell_fields: &[CellField],
) -> std::io::Result<()> {
    check_mesh_io(mesh, &field_lens(cell_fields))?;
    check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)), cell_fields, None)
}

/// The (name, length) of each cell field, for the mesh checks.
pub(super) fn field_lens<'a>(cell_fields: &[CellField<'a>]) -> Vec<(&'a str, usize)> {
    cell_fields
        .iter()
        .map(|f| (f.name, f.values.len()))
        .collect()
}

fn format_elements<W: Write>(
    w: &mut W,
    el: &Elements,
    cell_fields: &[CellField],
    ids: Option<GlobalIds>,
) -> std::io::Result<()> {
    let mesh = el.mesh;
    let nt = mesh.tets.len();
    let (ty, k) = cell_type(el);
    write_prologue(w, el.n_nodes(), nt)?;
    writeln!(
        w,
        "<DataArray type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\" format=\"ascii\">"
    )?;
    let mut line = Vec::new();
    for p in el.nodes() {
        write_float_line(w, &mut line, &p.to_array())?;
    }
    writeln!(w, "</DataArray>\n</Points>\n<Cells>")?;
    writeln!(
        w,
        "<DataArray type=\"Int64\" Name=\"connectivity\" format=\"ascii\">"
    )?;
    for i in 0..nt {
        let t = el.tet(i).map(i64::from);
        write_int_line(w, &mut line, &t[..k])?;
    }
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        "<DataArray type=\"Int64\" Name=\"offsets\" format=\"ascii\">"
    )?;
    let offsets: Vec<usize> = (1..=nt).map(|i| k * i).collect();
    write_rows(w, &offsets, 16, push_int)?;
    writeln!(w, "</DataArray>")?;
    writeln!(
        w,
        "<DataArray type=\"UInt8\" Name=\"types\" format=\"ascii\">"
    )?;
    let types = vec![ty; nt];
    write_rows(w, &types, 32, push_int)?;
    writeln!(w, "</DataArray>\n</Cells>")?;
    if let Some(ids) = ids {
        writeln!(w, "<PointData GlobalIds=\"{GLOBAL_NODE_ID}\">")?;
        writeln!(
            w,
            "<DataArray type=\"Int64\" Name=\"{GLOBAL_NODE_ID}\" format=\"ascii\">"
        )?;
        write_rows(w, ids.points, 16, push_int)?;
        writeln!(w, "</DataArray>\n</PointData>")?;
        writeln!(
            w,
            "<CellData Scalars=\"region\" GlobalIds=\"{GLOBAL_CELL_ID}\">"
        )?;
    } else {
        writeln!(w, "<CellData Scalars=\"region\">")?;
    }
    writeln!(
        w,
        "<DataArray type=\"Int32\" Name=\"region\" format=\"ascii\">"
    )?;
    write_rows(w, &mesh.tet_regions, 16, push_int)?;
    writeln!(w, "</DataArray>")?;
    if let Some(ids) = ids {
        writeln!(
            w,
            "<DataArray type=\"Int64\" Name=\"{GLOBAL_CELL_ID}\" format=\"ascii\">"
        )?;
        write_rows(w, ids.cells, 16, push_int)?;
        writeln!(w, "</DataArray>")?;
    }
    for f in cell_fields {
        writeln!(
            w,
            "<DataArray type=\"Float64\" Name=\"{}\" format=\"ascii\">",
            xml_escape(f.name)
        )?;
        let mut buf = zmij::Buffer::new();
        write_rows(w, f.values, 8, |line, x| {
            line.extend_from_slice(float_text(x, &mut buf).as_bytes())
        })?;
        writeln!(w, "</DataArray>")?;
    }
    writeln!(w, "</CellData>\n</Piece>\n</UnstructuredGrid>\n</VTKFile>")
}

/// A mesh read back from a `.vtu` file with its named cell fields (`region` excluded).
#[derive(Debug, Clone, PartialEq)]
pub struct VtuData {
    pub mesh: TetMesh,
    pub cell_fields: Vec<(String, Vec<f64>)>,
    /// Scalar point arrays (e.g. a distributed piece's `GlobalNodeId`).
    pub point_fields: Vec<(String, Vec<f64>)>,
}

/// Reads a `.vtu` file written by [`write_vtu`] (or any file in the documented subset).
pub fn read_vtu(path: &Path) -> Result<VtuData, IoError> {
    let text = read_text(path)?;
    parse_vtu(&text).map_err(|e| with_path(e, path))
}

/// One `DataArray` found in the document.
struct Array<'a> {
    section: String,
    name: String,
    line: usize,
    body: &'a str,
    /// Line on which `body` starts.
    body_line: usize,
    components: usize,
}

/// 1-based line of byte offset `pos`.
#[cfg(test)]
fn line_of(text: &str, pos: usize) -> usize {
    let mut c = LineCounter::default();
    c.line_at(text, pos)
}

/// Line numbers of increasing byte offsets, counted incrementally (linear overall).
#[derive(Default)]
struct LineCounter {
    pos: usize,
    line: usize,
}

impl LineCounter {
    fn line_at(&mut self, text: &str, pos: usize) -> usize {
        let pos = pos.min(text.len());
        if pos < self.pos {
            *self = LineCounter::default();
        }
        self.line += text.as_bytes()[self.pos..pos]
            .iter()
            .filter(|&&b| b == b'\n')
            .count();
        self.pos = pos;
        self.line + 1
    }
}

/// Undoes the five predefined XML entities.
fn xml_unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Value of attribute `key` in the inside of a start tag.
fn attr<'a>(tag: &'a str, key: &str) -> Option<&'a str> {
    let mut rest = tag;
    while let Some(i) = rest.find(key) {
        let before_ok = i == 0 || rest.as_bytes()[i - 1].is_ascii_whitespace();
        let after = rest[i + key.len()..].trim_start();
        if before_ok {
            if let Some(after) = after.strip_prefix('=') {
                let after = after.trim_start();
                let q = after.chars().next()?;
                if q == '"' || q == '\'' {
                    let end = after[1..].find(q)?;
                    return Some(&after[1..1 + end]);
                }
            }
        }
        rest = &rest[i + key.len()..];
    }
    None
}

/// Collects the `DataArray`s with the section (`Points`, `Cells`, `CellData`, `PointData`)
/// that encloses each; also checks the document type and a single `Piece`.
fn scan(text: &str) -> Result<(Vec<Array<'_>>, usize, usize), IoError> {
    let mut arrays = Vec::new();
    let mut section = String::new();
    let mut piece: Option<(usize, usize)> = None;
    let mut seen_grid = false;
    let mut pos = 0;
    let mut lines = LineCounter::default();
    while let Some(off) = text[pos..].find('<') {
        let start = pos + off;
        let line = lines.line_at(text, start);
        if text[start..].starts_with("<!--") {
            let end = text[start..]
                .find("-->")
                .ok_or_else(|| err_at(line, "unterminated comment"))?;
            pos = start + end + 3;
            continue;
        }
        let end = text[start..]
            .find('>')
            .ok_or_else(|| err_at(line, "unterminated tag"))?;
        let tag = &text[start + 1..start + end];
        pos = start + end + 1;
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        let closing = tag.starts_with('/');
        let name: &str = tag
            .trim_start_matches('/')
            .split(|c: char| c.is_whitespace() || c == '/')
            .next()
            .unwrap_or("");
        match (name, closing) {
            ("VTKFile", false) => {
                if attr(tag, "type") != Some("UnstructuredGrid") {
                    return Err(err_at(line, "not a VTK UnstructuredGrid file"));
                }
                if attr(tag, "compressor").is_some() {
                    return Err(err_at(line, "compressed .vtu files are not supported"));
                }
            }
            ("UnstructuredGrid", false) => seen_grid = true,
            ("Piece", false) => {
                if piece.is_some() {
                    return Err(err_at(line, "more than one Piece is not supported"));
                }
                let count = |k: &str| -> Result<usize, IoError> {
                    let v = attr(tag, k)
                        .ok_or_else(|| err_at(line, format!("Piece has no {k} attribute")))?;
                    super::text::parse_usize(v, line, k)
                };
                piece = Some((count("NumberOfPoints")?, count("NumberOfCells")?));
            }
            ("AppendedData", false) => {
                return Err(err_at(line, "appended (binary) data is not supported"));
            }
            ("Points" | "Cells" | "CellData" | "PointData", false) if !tag.ends_with('/') => {
                section = name.to_string();
            }
            ("Points" | "Cells" | "CellData" | "PointData", true) => section.clear(),
            ("DataArray", false) => {
                let format = attr(tag, "format").unwrap_or("ascii");
                if format != "ascii" {
                    return Err(err_at(
                        line,
                        format!("DataArray format '{format}' is not supported (ascii only)"),
                    ));
                }
                let components = match attr(tag, "NumberOfComponents") {
                    Some(c) => super::text::parse_usize(c, line, "NumberOfComponents")?,
                    None => 1,
                };
                let body_line = lines.line_at(text, pos);
                let body = if tag.ends_with('/') {
                    ""
                } else {
                    let close = text[pos..]
                        .find("</DataArray")
                        .ok_or_else(|| err_at(line, "DataArray is not closed"))?;
                    let body = &text[pos..pos + close];
                    pos += close;
                    body
                };
                arrays.push(Array {
                    section: section.clone(),
                    name: xml_unescape(attr(tag, "Name").unwrap_or("")),
                    line,
                    body,
                    body_line,
                    components,
                });
            }
            _ => {}
        }
    }
    if !seen_grid {
        return Err(err_at(1, "no UnstructuredGrid element: not a .vtu file"));
    }
    let (np, nc) = piece.ok_or_else(|| err_file("no Piece element"))?;
    Ok((arrays, np, nc))
}

/// Parses the numbers of an array body, checking the count; errors at the offending line.
fn numbers<T>(
    a: &Array,
    expected: usize,
    parse: impl Fn(&str, usize) -> Result<T, IoError>,
) -> Result<Vec<T>, IoError> {
    let mut out = Vec::with_capacity(super::text::cap(expected));
    for (k, l) in a.body.lines().enumerate() {
        for w in l.split_whitespace() {
            out.push(parse(w, a.body_line + k)?);
        }
    }
    if out.len() != expected {
        return Err(err_at(
            a.line,
            format!(
                "DataArray '{}' has {} values, expected {expected}",
                a.name,
                out.len()
            ),
        ));
    }
    Ok(out)
}

/// Parses the text of a `.vtu` file.
pub fn parse_vtu(text: &str) -> Result<VtuData, IoError> {
    let (arrays, np, nc) = scan(text)?;
    if u32::try_from(nc).is_err() {
        return Err(err_file(format!("{nc} cells exceed the 32-bit id range")));
    }
    let find = |section: &str, name: Option<&str>| {
        arrays
            .iter()
            .find(|a| a.section == section && name.is_none_or(|n| a.name == n))
    };
    let pts = find("Points", None).ok_or_else(|| err_file("no Points DataArray"))?;
    if pts.components != 3 {
        return Err(err_at(pts.line, "Points must have 3 components"));
    }
    to_u32(np, pts.line, "number of points")?;
    let coords = numbers(pts, 3 * np, |w, l| parse_f64(w, l, "point coordinate"))?;
    let vertices: Vec<DVec3> = coords
        .chunks_exact(3)
        .map(|c| DVec3::new(c[0], c[1], c[2]))
        .collect();

    let cell_array = |name: &str| {
        find("Cells", Some(name)).ok_or_else(|| err_file(format!("no Cells '{name}' DataArray")))
    };
    let types_a = cell_array("types")?;
    let types = numbers(types_a, nc, |w, l| {
        super::text::parse_i64(w, l, "cell type")
    })?;
    if let Some(i) = types.iter().position(|&t| t != 10) {
        return Err(err_at(
            types_a.line,
            format!(
                "cell {i} has type {}: only tetrahedra (type 10) are supported",
                types[i]
            ),
        ));
    }
    let off_a = cell_array("offsets")?;
    let offsets = numbers(off_a, nc, |w, l| super::text::parse_i64(w, l, "offset"))?;
    if let Some(i) = (0..nc).find(|&i| offsets[i] != 4 * (i as i64 + 1)) {
        return Err(err_at(
            off_a.line,
            format!(
                "offset of cell {i} is {}: expected {}",
                offsets[i],
                4 * (i + 1)
            ),
        ));
    }
    let conn_a = cell_array("connectivity")?;
    let conn = numbers(conn_a, 4 * nc, |w, l| {
        super::text::parse_index(w, l, 0, np, "connectivity index")
    })?;
    let tets: Vec<[u32; 4]> = conn
        .chunks_exact(4)
        .map(|c| [c[0], c[1], c[2], c[3]])
        .collect();

    let mut tet_regions = vec![0; nc];
    let mut cell_fields = Vec::new();
    for a in arrays.iter().filter(|a| a.section == "CellData") {
        if a.components != 1 {
            return Err(err_at(
                a.line,
                format!(
                    "cell array '{}' has {} components: only scalars are supported",
                    a.name, a.components
                ),
            ));
        }
        if a.name == "region" {
            tet_regions = numbers(a, nc, |w, l| super::text::parse_i32(w, l, "region"))?;
        } else {
            let vals = numbers(a, nc, |w, l| {
                w.parse::<f64>()
                    .map_err(|_| err_at(l, format!("bad number '{w}' in cell array")))
            })?;
            cell_fields.push((a.name.clone(), vals));
        }
    }
    let mut point_fields = Vec::new();
    for a in arrays
        .iter()
        .filter(|a| a.section == "PointData" && a.components == 1)
    {
        let vals = numbers(a, np, |w, l| {
            w.parse::<f64>()
                .map_err(|_| err_at(l, format!("bad number '{w}' in point array")))
        })?;
        point_fields.push((a.name.clone(), vals));
    }
    Ok(VtuData {
        mesh: TetMesh {
            vertices,
            tets,
            tet_regions,
            boundary: Vec::new(),
            boundary_markers: Vec::new(),
        },
        cell_fields,
        point_fields,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn piece_carries_global_ids_and_the_pvtu_names_pieces() {
        let mesh = tet_mesh();
        let points: Vec<i64> = (0..mesh.vertices.len() as i64).map(|i| 10 + i).collect();
        let cells: Vec<i64> = (0..mesh.tets.len() as i64).map(|i| 7 + i).collect();
        let ids = GlobalIds {
            points: &points,
            cells: &cells,
        };
        let mut buf = Vec::new();
        format_elements(&mut buf, &Elements::new(&mesh, None), &[], Some(ids)).unwrap();
        let d = parse_vtu(std::str::from_utf8(&buf).unwrap()).unwrap();
        assert_eq!(d.mesh, mesh);
        let as_f64 = |v: &[i64]| v.iter().map(|&x| x as f64).collect::<Vec<_>>();
        assert_eq!(
            d.point_fields,
            vec![(GLOBAL_NODE_ID.into(), as_f64(&points))]
        );
        assert_eq!(d.cell_fields, vec![(GLOBAL_CELL_ID.into(), as_f64(&cells))]);
        let mut p = Vec::new();
        let names = ["a_0.vtu".to_string(), "a_1.vtu".to_string()];
        format_pvtu(&mut p, &names, &["q"]).unwrap();
        let p = String::from_utf8(p).unwrap();
        assert!(
            p.contains("<Piece Source=\"a_0.vtu\"/>\n<Piece Source=\"a_1.vtu\"/>"),
            "{p}"
        );
        assert!(
            p.contains("GlobalIds=\"GlobalNodeId\"") && p.contains("Name=\"q\""),
            "{p}"
        );
    }

    fn tet_mesh() -> TetMesh {
        TetMesh {
            vertices: vec![
                DVec3::ZERO,
                DVec3::X,
                DVec3::Y,
                DVec3::new(0.1, 0.2, 1.0 / 3.0),
            ],
            tets: vec![[0, 1, 2, 3]],
            tet_regions: vec![-4],
            boundary: vec![],
            boundary_markers: vec![],
        }
    }

    fn text(mesh: &TetMesh, fields: &[CellField]) -> String {
        let mut out = Vec::new();
        format_vtu(&mut out, mesh, fields).unwrap();
        String::from_utf8(out).unwrap()
    }

    #[test]
    fn round_trip_small_with_odd_field_name() {
        let m = tet_mesh();
        let vals = [f64::NAN];
        let t = text(
            &m,
            &[CellField {
                name: "a<\"b\">",
                values: &vals,
            }],
        );
        let d = parse_vtu(&t).unwrap();
        assert_eq!(d.mesh, m);
        assert_eq!(d.cell_fields.len(), 1);
        assert_eq!(d.cell_fields[0].0, "a<\"b\">");
        assert!(d.cell_fields[0].1[0].is_nan());
    }

    fn expect_err(text: &str, line: Option<usize>, needle: &str) {
        let e = parse_vtu(text).unwrap_err();
        assert_eq!(e.line, line, "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_vtu_files() {
        let good = text(&tet_mesh(), &[]);
        // Line numbers of the arrays in the writer's layout.
        let line = |pat: &str| line_of(&good, good.find(pat).unwrap());
        expect_err("", Some(1), "not a .vtu");
        expect_err(
            "<VTKFile type=\"PolyData\">",
            Some(1),
            "not a VTK UnstructuredGrid",
        );
        expect_err(
            &good.replace("0.1 0.2", "0.1 zz"),
            Some(line("0.1 0.2")),
            "bad number 'zz'",
        );
        expect_err(
            &good.replace("0 1 2 3\n", "0 1 2 9\n"),
            Some(line("0 1 2 3\n")),
            "out of range",
        );
        expect_err(
            &good.replace("0 1 2 3\n", "0 1 2\n"),
            Some(line("Name=\"connectivity\"")),
            "has 3 values, expected 4",
        );
        expect_err(
            &good.replace("\n10\n", "\n5\n"),
            Some(line("Name=\"types\"")),
            "only tetrahedra",
        );
        expect_err(
            &good.replace("format=\"ascii\"", "format=\"binary\""),
            Some(line("<DataArray")),
            "ascii only",
        );
        expect_err(
            &good.replace("NumberOfCells=\"1\"", "NumberOfCells=\"2\""),
            Some(line("Name=\"types\"")),
            "expected 2",
        );
        expect_err(
            &good.replace("0.1 0.2 0.3333333333333333\n", ""),
            Some(line("Name=\"Points\"")),
            "has 9 values, expected 12",
        );
    }

    #[test]
    fn truncated_vtu_never_panics() {
        let good = text(
            &tet_mesh(),
            &[CellField {
                name: "q",
                values: &[0.5],
            }],
        );
        for cut in 0..good.len() {
            let _ = parse_vtu(&good[..cut]);
        }
    }
}
