//! Size fields on a background mesh ([`BackgroundSpacing`]), read from the formats of other
//! meshers' adaptive loops:
//!
//! - MEDIT/MMG `.sol` (ASCII): `MeshVersionFormatted 1|2|3`, `Dimension 3`, `SolAtVertices`,
//!   the count, `1 1` (one solution, of type 1: a scalar), one value per vertex, `End`
//!   (free format, `#` comments). The background mesh is the `.mesh` with the same stem
//!   beside it (`bg.sol` -> `bg.mesh`), read with [`super::medit::read_medit`].
//! - TetGen `.mtr`: `<#points> 1`, then one value per line. The background mesh is the
//!   `.node`/`.ele` with the same stem beside it, read with [`super::tetgen::read_tetgen`].
//!
//! Values must be finite and positive, one per background vertex. Errors name the file and
//! the 1-based line.

use super::text::{err_at, err_file, parse_f64, read_text, with_path, Lines, Tokens};
use super::IoError;
use crate::refine::background::BackgroundSpacing;
use std::path::Path;

/// Reads a size field (`.sol` with its `.mesh`, or `.mtr` with its `.node`/`.ele`), chosen
/// by the extension (case-insensitive).
pub fn read_size_field(path: &Path) -> Result<BackgroundSpacing, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase());
    let (values, mesh) = match ext.as_deref() {
        Some("sol") => {
            let values = read_text(path)
                .and_then(|t| parse_sol(&t).map_err(|e| with_path(e, path)))
                .map_err(|e| e.to_string())?;
            let mesh = super::medit::read_medit(&path.with_extension("mesh"))
                .map_err(|e| format!("{e} (the background mesh of {})", path.display()))?;
            (values, mesh)
        }
        Some("mtr") => {
            let values = read_text(path)
                .and_then(|t| parse_mtr(&t).map_err(|e| with_path(e, path)))
                .map_err(|e| e.to_string())?;
            let mesh = super::tetgen::read_tetgen(&path.with_extension("node"))
                .map_err(|e| format!("{e} (the background mesh of {})", path.display()))?;
            (values, mesh)
        }
        _ => {
            return Err(format!(
                "{}: unsupported size field format (expected .sol with its .mesh, or .mtr \
                 with its .node/.ele)",
                path.display()
            ))
        }
    };
    if values.len() != mesh.vertices.len() {
        return Err(format!(
            "{}: {} values, but the background mesh has {} vertices (one value per vertex \
             needed)",
            path.display(),
            values.len(),
            mesh.vertices.len()
        ));
    }
    BackgroundSpacing::new(mesh.vertices, mesh.tets, values)
        .map_err(|e| format!("{}: {e}", path.display()))
}

/// A size value: finite and positive.
fn size_value(w: &str, line: usize, what: &str) -> Result<f64, IoError> {
    let v = parse_f64(w, line, what)?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(err_at(
            line,
            format!("{what} is {v}: sizes must be positive"),
        ))
    }
}

/// Parses the text of a MEDIT `.sol` file: the values of its `SolAtVertices` section.
pub fn parse_sol(text: &str) -> Result<Vec<f64>, IoError> {
    let mut tok = Tokens::new(text);
    let mut seen_version = false;
    let mut values: Option<Vec<f64>> = None;
    while let Some((line, kw)) = tok.next_opt() {
        let lower = kw.to_ascii_lowercase();
        match lower.as_str() {
            "meshversionformatted" | "dimension" => {
                seen_version |= super::medit::read_header_value(&mut tok, lower.as_str())?;
            }
            "solatvertices" => {
                if values.is_some() {
                    return Err(err_at(line, "second SolAtVertices section"));
                }
                let n = tok.usize("number of vertices")?;
                let (l, kinds) = tok.next("number of solutions per vertex")?;
                if kinds != "1" {
                    return Err(err_at(
                        l,
                        format!(
                            "{kinds} solutions per vertex: only one scalar solution ('1 1') \
                             is supported"
                        ),
                    ));
                }
                let (l, kind) = tok.next("solution type")?;
                match kind {
                    "1" => {}
                    "3" => {
                        return Err(err_at(
                            l,
                            "solution type 3 (a metric tensor): anisotropic metrics are not \
                             supported, only a scalar size (type 1)",
                        ))
                    }
                    _ => {
                        return Err(err_at(
                            l,
                            format!(
                                "solution type '{kind}': only a scalar size (type 1) is supported"
                            ),
                        ))
                    }
                }
                let mut v = Vec::with_capacity(super::text::cap(n));
                for i in 0..n {
                    let what = format!("the size at vertex {}", i + 1);
                    let (l, w) = tok.next(&what)?;
                    v.push(size_value(w, l, &what)?);
                }
                values = Some(v);
            }
            "end" => break,
            _ if kw.parse::<f64>().is_ok() => {
                return Err(err_at(
                    line,
                    format!(
                        "found number '{kw}' where a keyword was expected (is the vertex count \
                         wrong?)"
                    ),
                ))
            }
            _ => {
                return Err(err_at(
                    line,
                    format!("unknown or unsupported keyword '{kw}' (only SolAtVertices is read)"),
                ))
            }
        }
    }
    if !seen_version {
        return Err(err_at(1, "missing 'MeshVersionFormatted' header"));
    }
    values.ok_or_else(|| err_file("no SolAtVertices section"))
}

/// Parses the text of a TetGen `.mtr` file.
pub fn parse_mtr(text: &str) -> Result<Vec<f64>, IoError> {
    let mut lines = Lines::new(text);
    let mut head = lines.next("the header '<#points> 1'")?;
    let n = head.usize("number of points")?;
    let per = head.usize("number of values per point")?;
    if per != 1 {
        return Err(err_at(
            head.line,
            format!("{per} values per point: only 1 (an isotropic size) is supported"),
        ));
    }
    let mut values = Vec::with_capacity(super::text::cap(n));
    for i in 0..n {
        let what = format!("the size at point {}", i + 1);
        let mut r = lines.next(&what)?;
        let w = r.word(&what)?;
        values.push(size_value(w, r.line, &what)?);
        if r.word_opt().is_some() {
            return Err(err_at(r.line, "expected one value per line"));
        }
    }
    lines.expect_end("the sizes")?;
    Ok(values)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::spacing::Spacing;
    use glam::DVec3;

    fn err_sol(text: &str, line: usize, needle: &str) {
        let e = parse_sol(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "{e}");
    }

    fn err_mtr(text: &str, line: usize, needle: &str) {
        let e = parse_mtr(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "{e}");
    }

    #[test]
    fn reads_sol_values() {
        let t = "MeshVersionFormatted 2\n# c\nDimension\n3\nSolAtVertices\n3\n1 1\n0.5\n0.25 \
                 1e-1\nEnd\n";
        assert_eq!(parse_sol(t).unwrap(), vec![0.5, 0.25, 0.1]);
    }

    #[test]
    fn malformed_sol_files() {
        let h = "MeshVersionFormatted 2\nDimension 3\n";
        err_sol(
            &format!("{h}SolAtVertices\n2\n1 1\n0.5\n-1\nEnd\n"),
            7,
            "vertex 2",
        );
        err_sol(
            &format!("{h}SolAtVertices\n2\n1 1\n0.5\nabc\nEnd\n"),
            7,
            "'abc'",
        );
        err_sol(
            &format!("{h}SolAtVertices\n2\n1 1\n0.5\nnan\n"),
            7,
            "not finite",
        );
        err_sol(&format!("{h}SolAtVertices\n2\n1 3\n"), 5, "anisotropic");
        err_sol(&format!("{h}SolAtVertices\n2\n2 1 1\n"), 5, "one scalar");
        err_sol(
            &format!("{h}SolAtVertices\n3\n1 1\n0.5\n0.5\n"),
            8,
            "end of file",
        );
        err_sol(
            &format!("{h}SolAtVertices\n1\n1 1\n0.5\n0.5\n"),
            7,
            "number '0.5'",
        );
        err_sol(&format!("{h}SolAtTetrahedra\n1\n"), 3, "SolAtTetrahedra");
        err_sol("MeshVersionFormatted 2\nDimension 2\n", 2, "dimension");
        err_sol(
            "Dimension 3\nSolAtVertices 1 1 1 0.5\n",
            1,
            "MeshVersionFormatted",
        );
        assert!(parse_sol(h)
            .unwrap_err()
            .message
            .contains("no SolAtVertices"));
    }

    #[test]
    fn reads_mtr_values() {
        assert_eq!(
            parse_mtr("3 1\n0.5\n0.25\n# c\n1\n").unwrap(),
            vec![0.5, 0.25, 1.0]
        );
        err_mtr("3 1\n0.5\n0\n1\n", 3, "point 2");
        err_mtr("2 1\n0.5\n", 3, "end of file");
        err_mtr("1 1\n0.5\n0.5\n", 3, "unexpected data");
        err_mtr("1 6\n0.5\n", 1, "only 1");
        err_mtr("1 1\n0.5 2\n", 2, "one value");
    }

    fn write(dir: &Path, name: &str, text: &str) -> std::path::PathBuf {
        let p = dir.join(name);
        std::fs::write(&p, text).unwrap();
        p
    }

    #[test]
    fn reads_sol_and_mtr_files_with_their_meshes() {
        let dir = std::env::temp_dir().join(format!("slivermesh-sizefield-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let mesh = "MeshVersionFormatted 2\nDimension 3\nVertices\n4\n0 0 0 0\n1 0 0 0\n0 1 0 0\n\
                    0 0 1 0\nTetrahedra\n1\n1 2 3 4 0\nEnd\n";
        write(&dir, "bg.mesh", mesh);
        let sol = write(
            &dir,
            "bg.sol",
            "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n4\n1 1\n1\n2\n3\n4\nEnd\n",
        );
        let s = read_size_field(&sol).unwrap();
        let p = DVec3::new(0.1, 0.2, 0.3);
        assert!((s.at(p) - (1.0 + 0.1 + 0.4 + 0.9)).abs() < 1e-12);

        write(
            &dir,
            "tg.node",
            "4 3 0 0\n1 0 0 0\n2 1 0 0\n3 0 1 0\n4 0 0 1\n",
        );
        write(&dir, "tg.ele", "1 4 0\n1 1 2 3 4\n");
        let mtr = write(&dir, "tg.mtr", "4 1\n1\n2\n3\n4\n");
        let s = read_size_field(&mtr).unwrap();
        assert!((s.at(p) - 2.4).abs() < 1e-12);

        // Errors name the file (and line).
        let short = write(&dir, "short.mtr", "3 1\n1\n2\n3\n");
        std::fs::copy(dir.join("tg.node"), dir.join("short.node")).unwrap();
        std::fs::copy(dir.join("tg.ele"), dir.join("short.ele")).unwrap();
        let e = read_size_field(&short).unwrap_err();
        assert!(
            e.contains("short.mtr") && e.contains("3 values") && e.contains("4 vertices"),
            "{e}"
        );
        let bad = write(&dir, "bad.mtr", "4 1\n1\n2\n-3\n4\n");
        let e = read_size_field(&bad).unwrap_err();
        assert!(e.contains("bad.mtr:4:") && e.contains("point 3"), "{e}");
        let lonely = write(
            &dir,
            "lonely.sol",
            "MeshVersionFormatted 2 SolAtVertices 1 1 1 0.5",
        );
        let e = read_size_field(&lonely).unwrap_err();
        assert!(
            e.contains("lonely.mesh") && e.contains("background mesh of"),
            "{e}"
        );
        let e = read_size_field(&dir.join("x.txt")).unwrap_err();
        assert!(e.contains("x.txt") && e.contains("unsupported"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
