//! Object File Format (`.off`) reader, producing a [`PlcInput`] of polygon facets.
//!
//! Supported subset: ASCII OFF as written by CGAL, Geomview and MeshLab.
//! - Header keyword `OFF` (also `COFF`, `NOFF`, `CNOFF`, `STOFF` and their combinations, whose
//!   extra per-vertex fields are ignored), optionally followed on the same line by the counts.
//! - Counts `<#vertices> <#faces> [#edges]` (the edge count is ignored).
//! - Vertices `x y z [ignored fields]`; faces `k v1 ... vk [ignored colour fields]` with
//!   0-based indices and k >= 3 (polygons of any size).
//! - `#` comments and blank lines anywhere.
//!
//! Each face becomes one facet with one polygon and marker = its 1-based facet index; with
//! `ReadOptions::merge_coplanar` the facets are then merged by
//! [`crate::plc::coplanar::merge_coplanar_facets`], which renumbers the markers the same way.
//! Not supported: binary OFF, 4D/nD OFF (`4OFF`, `nOFF`), vertex colours as data.

use super::text::{err_at, read_text, to_u32, with_path, Lines};
use super::{IoError, ReadOptions};
use crate::plc::{Facet, PlcInput};
use std::path::Path;

/// Reads an `.off` file.
pub fn read_off(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let text = read_text(path)?;
    parse_off(&text, options).map_err(|e| with_path(e, path))
}

/// Parses the text of an `.off` file.
pub fn parse_off(text: &str, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let mut lines = Lines::new(text);
    let mut r = lines.next("'OFF' header")?;
    let kw = r.word("'OFF' header")?;
    let upper = kw.to_ascii_uppercase();
    let known = upper
        .strip_suffix("OFF")
        .is_some_and(|p| p.chars().all(|c| matches!(c, 'C' | 'N' | 'S' | 'T')));
    if !known {
        return Err(err_at(
            r.line,
            format!("expected 'OFF' header, found '{kw}'"),
        ));
    }
    // The counts follow on the header line or on the next record.
    let (mut counts, nv) = match r.word_opt() {
        Some(w) if w.eq_ignore_ascii_case("BINARY") => {
            return Err(err_at(r.line, "binary OFF is not supported"));
        }
        Some(w) => {
            let nv = super::text::parse_usize(w, r.line, "number of vertices")?;
            (r, nv)
        }
        None => {
            let mut c = lines.next("counts '<#vertices> <#faces> <#edges>'")?;
            let nv = c.usize("number of vertices")?;
            (c, nv)
        }
    };
    parse_body(&mut lines, nv, &mut counts, options)
}

fn parse_body(
    lines: &mut Lines,
    nv: usize,
    counts: &mut super::text::Record,
    options: &ReadOptions,
) -> Result<PlcInput, IoError> {
    let nf = counts.usize("number of faces")?;
    counts.usize_opt("number of edges")?;
    to_u32(nv, counts.line, "number of vertices")?;
    let mut plc = PlcInput::default();
    plc.vertices.reserve(super::text::cap(nv));
    for i in 0..nv {
        let mut r = lines.next(&format_args!("vertex {} of {nv}", i + 1))?;
        plc.vertices.push(r.point()?);
    }
    plc.facets.reserve(super::text::cap(nf));
    for i in 0..nf {
        // Names for error messages, formatted only when one is made.
        let face = i + 1;
        let mut r = lines.next(&format_args!("face {face} of {nf}"))?;
        let k = r.usize(&format_args!("number of corners of face {face} of {nf}"))?;
        if k < 3 {
            return Err(err_at(
                r.line,
                format!("face {face} of {nf} has {k} corners (at least 3 needed)"),
            ));
        }
        let mut poly = Vec::with_capacity(super::text::cap(k));
        for _ in 0..k {
            poly.push(r.index(0, nv, &format_args!("face {face} of {nf}: vertex index"))?);
        }
        plc.facets.push(Facet {
            polygons: vec![poly],
            marker: i32::try_from(i + 1).unwrap_or(i32::MAX),
            ..Facet::default()
        });
    }
    lines.expect_end(&format!("the {nf} faces declared"))?;
    if options.merge_coplanar {
        crate::plc::coplanar::merge_coplanar_facets(&mut plc);
    }
    Ok(plc)
}

#[cfg(test)]
mod tests {
    use super::*;

    const CUBE: &str = "OFF\n# a comment\n8 12 0\n\n-1 -1 -1\n-1 1 -1\n1 1 -1\n1 -1 -1\n\
        -1 -1 1\n-1 1 1\n1 1 1\n1 -1 1\n3  0 1 3\n3  3 1 2\n3  0 4 1\n3  1 4 5\n3  3 2 7\n\
        3  7 2 6\n3  4 0 3\n3  7 4 3\n3  6 4 7\n3  6 5 4\n3  1 5 6\n3  2 1 6\n";

    #[test]
    fn reads_triangles_and_polygons() {
        let p = parse_off(CUBE, &ReadOptions::default()).unwrap();
        assert_eq!(p.vertices.len(), 8);
        assert_eq!(p.facets.len(), 12);
        assert_eq!(p.facets[11].marker, 12);
        let q = parse_off(
            "COFF 4 1 0\n0 0 0 1 1 1\n1 0 0 1 1 1\n1 1 0 1 1 1\n0 1 0 1 1 1\n4 0 1 2 3 255 0 0\n",
            &ReadOptions::default(),
        )
        .unwrap();
        assert_eq!(q.facets[0].polygons, vec![vec![0, 1, 2, 3]]);
    }

    #[test]
    fn merged_cube_has_six_facets() {
        let opts = ReadOptions {
            merge_coplanar: true,
        };
        let p = parse_off(CUBE, &opts).unwrap();
        assert_eq!(p.facets.len(), 6);
        for f in &p.facets {
            assert_eq!(f.polygons.len(), 1);
            assert_eq!(f.polygons[0].len(), 4);
        }
    }

    fn expect_err(text: &str, line: usize, needle: &str) {
        let e = parse_off(text, &ReadOptions::default()).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_off_files() {
        expect_err("", 1, "unexpected end of file");
        expect_err("PLY\n", 1, "expected 'OFF' header");
        expect_err("OFF BINARY\n", 1, "binary OFF");
        expect_err("OFF\n3 1\n0 0 0\n1 0 0\n", 5, "expected vertex 3 of 3");
        expect_err("OFF\n3 1\n0 0 0\n1 0 0\n0 1 x\n", 5, "bad number 'x'");
        expect_err(
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n",
            6,
            "out of range",
        );
        expect_err("OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n2 0 1\n", 6, "at least 3");
        expect_err(
            "OFF\n3 2\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n",
            7,
            "expected face 2 of 2",
        );
        expect_err(
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1\n",
            6,
            "vertex index, found end of line",
        );
        expect_err("OFF\n-3 1\n", 2, "bad non-negative integer '-3'");
        expect_err(
            "OFF\n3 1\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n# ok\n3 0 1 2\n",
            8,
            "unexpected data after the 1 faces declared (is a count wrong?)",
        );
    }

    #[test]
    fn truncated_off_never_panics() {
        let opts = ReadOptions {
            merge_coplanar: true,
        };
        for cut in 0..CUBE.len() {
            let _ = parse_off(&CUBE[..cut], &opts);
        }
    }
}
