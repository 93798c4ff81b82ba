//! Shared plumbing for the text formats: line and token readers that remember 1-based line
//! numbers, number parsing with messages that say what was expected, exact float formatting,
//! and mesh consistency checks used by every writer.
//!
//! Errors made here carry an empty `path`; the per-format `read_*` functions fill it in with
//! [`with_path`] so that parse functions can also be tested on in-memory strings.

use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use glam::DVec3;
use std::borrow::Cow;
use std::fmt;
use std::path::Path;

/// An error at a 1-based line, path filled in later by [`with_path`].
pub(crate) fn err_at(line: usize, message: impl Into<String>) -> IoError {
    IoError {
        path: String::new(),
        line: Some(line),
        message: message.into(),
    }
}

/// An error without a line (binary formats, whole-file problems).
pub(crate) fn err_file(message: impl Into<String>) -> IoError {
    IoError {
        path: String::new(),
        line: None,
        message: message.into(),
    }
}

/// Sets the path of an error that has none yet (errors from a sibling file keep their own).
pub(crate) fn with_path(mut e: IoError, path: &Path) -> IoError {
    if e.path.is_empty() {
        e.path = path.display().to_string();
    }
    e
}

/// Reads a whole file as bytes, mapping the OS error to an [`IoError`].
pub(crate) fn read_bytes(path: &Path) -> Result<Vec<u8>, IoError> {
    std::fs::read(path).map_err(|e| IoError {
        path: path.display().to_string(),
        line: None,
        message: format!("cannot read file: {e}"),
    })
}

/// Reads a whole file as text; invalid UTF-8 (e.g. Latin-1 in comments) is replaced, not fatal.
pub(crate) fn read_text(path: &Path) -> Result<String, IoError> {
    let bytes = read_bytes(path)?;
    Ok(match String::from_utf8(bytes) {
        Ok(s) => s,
        Err(e) => String::from_utf8_lossy(e.as_bytes()).into_owned(),
    })
}

/// Creates a file for writing, buffered.
pub(crate) fn create(path: &Path) -> Result<std::io::BufWriter<std::fs::File>, IoError> {
    std::fs::File::create(path)
        .map(|f| std::io::BufWriter::with_capacity(1 << 16, f))
        .map_err(|e| write_err(path, e))
}

/// Maps a write failure to an [`IoError`].
pub(crate) fn write_err(path: &Path, e: std::io::Error) -> IoError {
    IoError {
        path: path.display().to_string(),
        line: None,
        message: format!("cannot write file: {e}"),
    }
}

/// A capacity hint that a corrupt count cannot turn into a huge allocation.
pub(crate) fn cap(n: usize) -> usize {
    n.min(1 << 16)
}

/// Converts a vertex count or index to `u32`, the id type of the mesh model.
pub(crate) fn to_u32(
    n: usize,
    line: usize,
    what: &(impl fmt::Display + ?Sized),
) -> Result<u32, IoError> {
    u32::try_from(n).map_err(|_| err_at(line, format!("{what} {n} is too large (limit 2^32-1)")))
}

/// Removes a `#` comment from a line.
fn strip_comment(line: &str) -> &str {
    match line.find('#') {
        Some(i) => &line[..i],
        None => line,
    }
}

/// Line-oriented reader: yields the non-blank lines of a text, `#` comments removed.
pub(crate) struct Lines<'a> {
    inner: std::iter::Enumerate<std::str::Lines<'a>>,
    /// Number of the last line handed out (0 before the first).
    last: usize,
    /// Lines before `text` in its file (a body after a header parsed separately).
    offset: usize,
}

impl<'a> Lines<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        Self::after(text, 0)
    }

    /// Lines of a text that starts after line `offset` of its file.
    pub(crate) fn after(text: &'a str, offset: usize) -> Self {
        Lines {
            inner: text.lines().enumerate(),
            last: offset,
            offset,
        }
    }

    /// The next non-blank record, or `None` at end of file.
    pub(crate) fn next_opt(&mut self) -> Option<Record<'a>> {
        for (i, raw) in self.inner.by_ref() {
            let content = strip_comment(raw);
            if !content.trim().is_empty() {
                self.last = self.offset + i + 1;
                return Some(Record {
                    line: self.last,
                    fields: content.split_whitespace(),
                });
            }
        }
        None
    }

    /// The next non-blank record; end of file is an error naming what was expected.
    pub(crate) fn next(
        &mut self,
        what: &(impl fmt::Display + ?Sized),
    ) -> Result<Record<'a>, IoError> {
        match self.next_opt() {
            Some(r) => Ok(r),
            None => Err(self.eof(what)),
        }
    }

    /// Checks that nothing but comments and blank lines follows: extra records usually mean a
    /// count in the file is wrong.
    pub(crate) fn expect_end(&mut self, after: &str) -> Result<(), IoError> {
        match self.next_opt() {
            None => Ok(()),
            Some(r) => Err(err_at(
                r.line,
                format!("unexpected data after {after} (is a count wrong?)"),
            )),
        }
    }

    /// An "unexpected end of file" error, reported at the line after the last record read.
    pub(crate) fn eof(&self, what: &(impl fmt::Display + ?Sized)) -> IoError {
        err_at(
            self.last + 1,
            format!("unexpected end of file: expected {what}"),
        )
    }
}

/// One line's whitespace-separated fields.
#[derive(Debug)]
pub(crate) struct Record<'a> {
    pub(crate) line: usize,
    fields: std::str::SplitWhitespace<'a>,
}

impl<'a> Record<'a> {
    /// Builds a record from one line's text (used by readers that scan lines themselves).
    #[cfg(test)]
    pub(crate) fn of(line: usize, text: &'a str) -> Self {
        Record {
            line,
            fields: text.split_whitespace(),
        }
    }

    /// The next field as text, or `None` at end of line.
    pub(crate) fn word_opt(&mut self) -> Option<&'a str> {
        self.fields.next()
    }

    /// The next field as text; end of line is an error naming what was expected.
    pub(crate) fn word(&mut self, what: &(impl fmt::Display + ?Sized)) -> Result<&'a str, IoError> {
        self.fields
            .next()
            .ok_or_else(|| err_at(self.line, format!("expected {what}, found end of line")))
    }

    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, IoError> {
        let w = self.word(what)?;
        parse_f64(w, self.line, what)
    }

    pub(crate) fn i64(&mut self, what: &str) -> Result<i64, IoError> {
        let w = self.word(what)?;
        parse_i64(w, self.line, what)
    }

    pub(crate) fn i32(&mut self, what: &str) -> Result<i32, IoError> {
        let w = self.word(what)?;
        parse_i32(w, self.line, what)
    }

    pub(crate) fn usize(&mut self, what: &(impl fmt::Display + ?Sized)) -> Result<usize, IoError> {
        let w = self.word(what)?;
        parse_usize(w, self.line, what)
    }

    /// An optional trailing count: absent gives `None`, present must be valid.
    pub(crate) fn usize_opt(&mut self, what: &str) -> Result<Option<usize>, IoError> {
        match self.fields.next() {
            Some(w) => parse_usize(w, self.line, what).map(Some),
            None => Ok(None),
        }
    }

    pub(crate) fn i32_opt(&mut self, what: &str) -> Result<Option<i32>, IoError> {
        match self.fields.next() {
            Some(w) => parse_i32(w, self.line, what).map(Some),
            None => Ok(None),
        }
    }

    pub(crate) fn f64_opt(&mut self, what: &str) -> Result<Option<f64>, IoError> {
        match self.fields.next() {
            Some(w) => parse_f64(w, self.line, what).map(Some),
            None => Ok(None),
        }
    }

    /// Three coordinates `x y z`.
    pub(crate) fn point(&mut self) -> Result<DVec3, IoError> {
        let x = self.f64("x coordinate")?;
        let y = self.f64("y coordinate")?;
        let z = self.f64("z coordinate")?;
        Ok(DVec3::new(x, y, z))
    }

    /// A 0-based vertex id from a `base`-based index, checked against `n` vertices.
    pub(crate) fn index(
        &mut self,
        base: usize,
        n: usize,
        what: &(impl fmt::Display + ?Sized),
    ) -> Result<u32, IoError> {
        let w = self.word(what)?;
        parse_index(w, self.line, base, n, what)
    }
}

/// Token-oriented reader for free-format files (medit, ASCII STL): tokens carry their line.
pub(crate) struct Tokens<'a> {
    lines: Lines<'a>,
    current: Option<Record<'a>>,
}

impl<'a> Tokens<'a> {
    pub(crate) fn new(text: &'a str) -> Self {
        Self::of_lines(Lines::new(text))
    }

    pub(crate) fn of_lines(lines: Lines<'a>) -> Self {
        Tokens {
            lines,
            current: None,
        }
    }

    /// The next token with its line, or `None` at end of file.
    pub(crate) fn next_opt(&mut self) -> Option<(usize, &'a str)> {
        loop {
            if let Some(rec) = self.current.as_mut() {
                if let Some(w) = rec.word_opt() {
                    return Some((rec.line, w));
                }
            }
            self.current = Some(self.lines.next_opt()?);
        }
    }

    /// The next token; end of file is an error naming what was expected.
    pub(crate) fn next(&mut self, what: &str) -> Result<(usize, &'a str), IoError> {
        self.next_opt().ok_or_else(|| self.lines.eof(what))
    }

    /// The line of the last token handed out.
    pub(crate) fn line(&self) -> Option<usize> {
        self.current.as_ref().map(|r| r.line)
    }

    /// An "unexpected end of file" error naming what was expected.
    pub(crate) fn eof(&self, what: &str) -> IoError {
        self.lines.eof(what)
    }

    /// Drops the rest of the current line (e.g. a solid's name in STL).
    pub(crate) fn skip_line(&mut self) {
        self.current = None;
    }

    pub(crate) fn f64(&mut self, what: &str) -> Result<f64, IoError> {
        let (l, w) = self.next(what)?;
        parse_f64(w, l, what)
    }

    pub(crate) fn i32(&mut self, what: &str) -> Result<i32, IoError> {
        let (l, w) = self.next(what)?;
        parse_i32(w, l, what)
    }

    pub(crate) fn usize(&mut self, what: &str) -> Result<usize, IoError> {
        let (l, w) = self.next(what)?;
        parse_usize(w, l, what)
    }

    pub(crate) fn point(&mut self) -> Result<DVec3, IoError> {
        let x = self.f64("x coordinate")?;
        let y = self.f64("y coordinate")?;
        let z = self.f64("z coordinate")?;
        Ok(DVec3::new(x, y, z))
    }

    /// A raw index token with its line, for checking once the vertex count is known.
    pub(crate) fn raw_index(&mut self, what: &str) -> Result<(usize, i64), IoError> {
        let (l, w) = self.next(what)?;
        Ok((l, parse_i64(w, l, what)?))
    }
}

/// A finite float; `nan` and `inf` are rejected (they cannot be geometry).
pub(crate) fn parse_f64(w: &str, line: usize, what: &str) -> Result<f64, IoError> {
    match w.parse::<f64>() {
        Ok(v) if v.is_finite() => Ok(v),
        Ok(_) => Err(err_at(
            line,
            format!("bad number '{w}' for {what}: not finite"),
        )),
        Err(_) => Err(err_at(line, format!("bad number '{w}' for {what}"))),
    }
}

pub(crate) fn parse_i64(
    w: &str,
    line: usize,
    what: &(impl fmt::Display + ?Sized),
) -> Result<i64, IoError> {
    w.parse::<i64>()
        .map_err(|_| err_at(line, format!("bad integer '{w}' for {what}")))
}

pub(crate) fn parse_i32(w: &str, line: usize, what: &str) -> Result<i32, IoError> {
    w.parse::<i32>()
        .map_err(|_| err_at(line, format!("bad integer '{w}' for {what}")))
}

pub(crate) fn parse_usize(
    w: &str,
    line: usize,
    what: &(impl fmt::Display + ?Sized),
) -> Result<usize, IoError> {
    w.parse::<usize>()
        .map_err(|_| err_at(line, format!("bad non-negative integer '{w}' for {what}")))
}

/// An integer given possibly as a float (`2` or `2.0`), as TetGen writes attributes.
pub(crate) fn parse_integral_i32(w: &str, line: usize, what: &str) -> Result<i32, IoError> {
    if let Ok(v) = w.parse::<i32>() {
        return Ok(v);
    }
    let v = parse_f64(w, line, what)?;
    if v.fract() == 0.0 && v >= i32::MIN as f64 && v <= i32::MAX as f64 {
        Ok(v as i32)
    } else {
        Err(err_at(
            line,
            format!("{what} must be an integer (32-bit), found '{w}'"),
        ))
    }
}

/// Checks a `base`-based index against `n` vertices; returns the 0-based id.
pub(crate) fn check_index(
    v: i64,
    line: usize,
    base: usize,
    n: usize,
    what: &(impl fmt::Display + ?Sized),
) -> Result<u32, IoError> {
    let lo = base as i64;
    let hi = n as i64 + lo - 1;
    if v < lo || v > hi {
        let range = if n == 0 {
            "there are no vertices".to_string()
        } else {
            format!("valid: {lo}..={hi}")
        };
        return Err(err_at(line, format!("{what} {v} out of range ({range})")));
    }
    to_u32((v - lo) as usize, line, what)
}

pub(crate) fn parse_index(
    w: &str,
    line: usize,
    base: usize,
    n: usize,
    what: &(impl fmt::Display + ?Sized),
) -> Result<u32, IoError> {
    let v = parse_i64(w, line, what)?;
    check_index(v, line, base, n, what)
}

/// Writes `values` as one line, separated by spaces, each appended by `push`. The writers' hot
/// loops (.ele/.face, medit's elements, .vtu's arrays): formatting into a reused buffer is
/// several times faster than `writeln!` through `dyn Write`.
pub(crate) fn write_line<T: Copy>(
    w: &mut dyn std::io::Write,
    line: &mut Vec<u8>,
    values: &[T],
    mut push: impl FnMut(&mut Vec<u8>, T),
) -> std::io::Result<()> {
    line.clear();
    for (k, &v) in values.iter().enumerate() {
        if k > 0 {
            line.push(b' ');
        }
        push(line, v);
    }
    line.push(b'\n');
    w.write_all(line)
}

/// [`write_line`] of integers, through itoa.
pub(crate) fn write_int_line(
    w: &mut dyn std::io::Write,
    line: &mut Vec<u8>,
    values: &[i64],
) -> std::io::Result<()> {
    let mut buf = itoa::Buffer::new();
    write_line(w, line, values, |l, v| {
        l.extend_from_slice(buf.format(v).as_bytes())
    })
}

/// Formats a float so that parsing it back gives the same bits, as short as possible:
/// integral values below 1e15 without a fraction (`3`, `-0`), everything else with the
/// shortest round-trip representation in the notation of Rust's `{:?}` (`0.1`, `1e-7`,
/// `1.2345678901234567e300`). Non-finite values print as `nan`, `inf`, `-inf`.
pub(crate) struct F(pub f64);

impl fmt::Display for F {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&float_text(self.0, &mut zmij::Buffer::new()))
    }
}

/// Below this magnitude `{:?}` switches to exponent notation.
const SHORTEST_DECIMAL: f64 = 1e-4;

/// The text of [`F`], in `buf` where it can be.
pub(crate) fn float_text(x: f64, buf: &mut zmij::Buffer) -> Cow<'_, str> {
    if x.is_nan() {
        "nan".into()
    } else if x.is_infinite() {
        if x > 0.0 { "inf" } else { "-inf" }.into()
    } else if (SHORTEST_DECIMAL..1e16).contains(&x.abs()) || x == 0.0 {
        // zmij prints the same shortest digits as `{:?}` here (it may pick the other one of
        // two equally short, equally close decimals), several times faster; it prints
        // integral values with ".0" (`3.0`, `-0.0`), which Display leaves off.
        let text = buf.format_finite(x);
        if x.fract() == 0.0 && x.abs() < 1e15 {
            text.strip_suffix(".0").unwrap_or(text).into()
        } else {
            text.into()
        }
    } else {
        // Exponent notation, which zmij writes differently (`1e+300`).
        format!("{x:?}").into()
    }
}

/// [`write_line`] of [`F`] texts.
pub(crate) fn write_float_line(
    w: &mut dyn std::io::Write,
    line: &mut Vec<u8>,
    values: &[f64],
) -> std::io::Result<()> {
    let mut buf = zmij::Buffer::new();
    write_line(w, line, values, |l, v| {
        l.extend_from_slice(float_text(v, &mut buf).as_bytes())
    })
}

/// [`check_mesh`] for the `format_*` functions, which return `std::io::Error`.
pub(crate) fn check_mesh_io(mesh: &TetMesh, field_lens: &[(&str, usize)]) -> std::io::Result<()> {
    check_mesh(mesh, field_lens)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e.message))
}

/// [`check_quadratic`] for the `format_*` functions, which return `std::io::Error`.
pub(crate) fn check_quadratic_io(mesh: &TetMesh, q: &QuadraticNodes) -> std::io::Result<()> {
    check_quadratic(mesh, q)
        .map_err(|e| std::io::Error::new(std::io::ErrorKind::InvalidInput, e.message))
}

/// Checks that the mid-edge nodes `q` belong to `mesh` (one edge-node list per tet and per
/// boundary triangle, every id below the node count), so writers of ten-node tets never index
/// out of range.
pub(crate) fn check_quadratic(mesh: &TetMesh, q: &QuadraticNodes) -> Result<(), IoError> {
    let bad = |m: String| err_file(format!("cannot write inconsistent ten-node tets: {m}"));
    if q.tet_edges.len() != mesh.tets.len() {
        return Err(bad(format!(
            "{} tets but {} lists of mid-edge nodes",
            mesh.tets.len(),
            q.tet_edges.len()
        )));
    }
    if q.boundary_edges.len() != mesh.boundary.len() {
        return Err(bad(format!(
            "{} boundary triangles but {} lists of mid-edge nodes",
            mesh.boundary.len(),
            q.boundary_edges.len()
        )));
    }
    let n = q.n_nodes(mesh);
    if u32::try_from(n).is_err() {
        return Err(bad(format!("{n} nodes exceed the 32-bit id range")));
    }
    if let Some((i, e)) = q
        .tet_edges
        .iter()
        .enumerate()
        .find(|(_, e)| e.iter().any(|&v| v as usize >= n))
    {
        return Err(bad(format!(
            "tet {i}'s mid-edge nodes {e:?} refer to a node beyond the {n} nodes"
        )));
    }
    if let Some((i, e)) = q
        .boundary_edges
        .iter()
        .enumerate()
        .find(|(_, e)| e.iter().any(|&v| v as usize >= n))
    {
        return Err(bad(format!(
            "boundary triangle {i}'s mid-edge nodes {e:?} refer to a node beyond the {n} nodes"
        )));
    }
    Ok(())
}

/// Checks that a mesh is self-consistent before writing it, so writers never index out of range.
pub(crate) fn check_mesh(mesh: &TetMesh, field_lens: &[(&str, usize)]) -> Result<(), IoError> {
    let bad = |m: String| err_file(format!("cannot write an inconsistent mesh: {m}"));
    let nv = mesh.vertices.len();
    if mesh.tet_regions.len() != mesh.tets.len() {
        return Err(bad(format!(
            "{} tets but {} region attributes",
            mesh.tets.len(),
            mesh.tet_regions.len()
        )));
    }
    if mesh.boundary_markers.len() != mesh.boundary.len() {
        return Err(bad(format!(
            "{} boundary triangles but {} markers",
            mesh.boundary.len(),
            mesh.boundary_markers.len()
        )));
    }
    if u32::try_from(nv).is_err() {
        return Err(bad(format!("{nv} vertices exceed the 32-bit id range")));
    }
    if let Some((i, t)) = mesh
        .tets
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= nv))
    {
        return Err(bad(format!(
            "tet {i} {t:?} refers to a vertex beyond the {nv} vertices"
        )));
    }
    if let Some((i, t)) = mesh
        .boundary
        .iter()
        .enumerate()
        .find(|(_, t)| t.iter().any(|&v| v as usize >= nv))
    {
        return Err(bad(format!(
            "boundary triangle {i} {t:?} refers to a vertex beyond the {nv} vertices"
        )));
    }
    for &(name, len) in field_lens {
        if len != mesh.tets.len() {
            return Err(bad(format!(
                "cell field '{name}' has {len} values for {} tets",
                mesh.tets.len()
            )));
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn float_format_round_trips_bitwise() {
        let xs = [
            0.0,
            -0.0,
            1.0,
            -3.0,
            0.1,
            1.0 / 3.0,
            1e-7,
            -2.5e-300,
            1e15,
            1e16,
            123456789012345.6,
            f64::MAX,
            f64::MIN_POSITIVE,
            5e-324,
            std::f64::consts::PI * 1e20,
        ];
        for x in xs {
            let s = F(x).to_string();
            let y: f64 = s.parse().unwrap();
            assert_eq!(x.to_bits(), y.to_bits(), "{x:?} -> {s}");
        }
        assert_eq!(F(2.0).to_string(), "2");
        assert_eq!(F(-0.0).to_string(), "-0");
        assert_eq!(F(0.5).to_string(), "0.5");
        assert_eq!(F(f64::NAN).to_string(), "nan");
    }

    #[test]
    fn lines_skip_comments_and_blanks_and_report_eof_line() {
        let mut l = Lines::new("# c\n\n 1 2 # x\n\n");
        let mut r = l.next("a").unwrap();
        assert_eq!(r.line, 3);
        assert_eq!(r.usize("a").unwrap(), 1);
        assert_eq!(r.usize("b").unwrap(), 2);
        let e = r.usize("c").unwrap_err();
        assert_eq!(e.line, Some(3));
        assert!(e.message.contains("expected c"), "{}", e.message);
        let e = l.next("more").unwrap_err();
        assert_eq!(e.line, Some(4));
        assert!(e.message.contains("unexpected end of file"));
    }

    #[test]
    fn numbers_are_checked() {
        assert!(parse_f64("nan", 1, "x").is_err());
        assert!(parse_f64("1e999", 1, "x").is_err());
        assert!(parse_f64("1.5", 1, "x").is_ok());
        assert_eq!(parse_integral_i32("2.0", 1, "a").unwrap(), 2);
        assert!(parse_integral_i32("2.5", 1, "a").is_err());
        let e = parse_index("9", 7, 1, 8, "vertex index").unwrap_err();
        assert_eq!(e.line, Some(7));
        assert!(e.message.contains("out of range"), "{}", e.message);
        assert_eq!(parse_index("8", 7, 1, 8, "v").unwrap(), 7);
        assert_eq!(Record::of(1, "x").word("w").unwrap(), "x");
    }
}
