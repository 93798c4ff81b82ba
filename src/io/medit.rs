//! Medit / INRIA `.mesh` (ASCII) reader and writer for tetrahedral meshes.
//!
//! Written: `MeshVersionFormatted 2` (double precision), `Dimension 3`, `Vertices` (reference
//! 0), `Tetrahedra` with the region attribute as reference, `Triangles` (the boundary) with the
//! facet marker as reference, `End`. Indices are 1-based; empty element sections are omitted.
//!
//! Ten-node tets ([`format_medit_quadratic`]): `Vertices` holds every node, the corners and
//! then the mid-edge nodes (P2 elements index the one vertex list, as in libMeshb);
//! `TetrahedraP2` lists per tet the corners a, b, c, d, then the nodes of the edges ab, bc,
//! ac, ad, bd, cd, and the reference; `TrianglesP2` the corners a, b, c, then ab, bc, ca.
//! libMeshb fixes no node order for P2 elements (its manual, "GmfSetHONodesOrdering": a file
//! may carry its order in `TetrahedraP2Ordering`/`TrianglesP2Ordering`), so the order is also
//! written in those keywords before the elements: per node, its barycentric multi-index.
//! The order is the one of gmsh's `.mesh` reader and writer (`GModelIO_MESH.cpp` reads a
//! `TetrahedraP2` line into its own tet10 with the last two edges swapped, gmsh's 01, 12, 20,
//! 30, 32, 31 being ours with bd and cd exchanged; `TrianglesP2` as is) and Vizir4's default
//! when a file has no ordering keyword (as reimplemented in Metris's `gen_ordering_Vizir`:
//! corners, then edges 01, 12, 02, 03, 13, 23 and for triangles 01, 12, 20). MMG reads no P2
//! elements.
//!
//! Read: the same keywords (case-insensitive, free format: tokens may be split across lines,
//! `#` comments), `MeshVersionFormatted` 1, 2 or 3, `Dimension 3` only. `Vertices`,
//! `Tetrahedra` (reference -> `tet_regions`) and `Triangles` (-> `boundary`, reference ->
//! `boundary_markers`) are kept; `TetrahedraP2` and `TrianglesP2` are read as their corners
//! (the mid-edge nodes stay in the vertex list, used by no tet); `Edges`, `Quadrilaterals`,
//! `Hexahedra`, `Prisms`, `Pyramids`, `Corners`, `Ridges`, `Required*`, `Normals`,
//! `NormalAtVertices`, `Tangents`, `TangentAtVertices`, the two P2 ordering keywords and
//! `Identifier`/`Geometry` are read past; any other section is an error. Tetrahedra are kept
//! as written: the reader does not reorient them. Binary `.meshb` is not supported.

use super::elements::{Elements, TET_ORDER, TRIANGLE_ORDER};
use super::text::{
    check_index, check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, err_at,
    read_text, to_u32, with_path, write_err, write_int_line, Tokens, F,
};
use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use std::io::Write;
use std::path::Path;

/// Reads and checks the value after a MEDIT header keyword (`lower`: "meshversionformatted",
/// a version 1-3, or "dimension", 3), for .mesh and .sol files alike; true for the version.
pub(super) fn read_header_value(tok: &mut Tokens, lower: &str) -> Result<bool, IoError> {
    if lower == "dimension" {
        let (l, w) = tok.next("dimension")?;
        if w != "3" {
            return Err(err_at(l, format!("dimension must be 3, found '{w}'")));
        }
        return Ok(false);
    }
    let (l, w) = tok.next("mesh version")?;
    if !matches!(w, "1" | "2" | "3") {
        return Err(err_at(
            l,
            format!("unsupported MeshVersionFormatted '{w}' (1, 2 or 3)"),
        ));
    }
    Ok(true)
}

/// Writes `mesh` as a medit `.mesh` file.
pub fn write_medit(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_medit(&mut w, mesh)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` with its mid-edge nodes as a medit `.mesh` file of `TetrahedraP2`.
pub fn write_medit_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_medit_quadratic(&mut w, mesh, quadratic)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` in medit format to any writer.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_medit<W: Write>(w: &mut W, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    format_elements(w, &Elements::new(mesh, None))
}

/// Writes `mesh` with its mid-edge nodes as `TetrahedraP2` and `TrianglesP2` (see the module
/// doc for the node order and where it comes from).
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_medit_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)))
}

/// libMeshb's `TetrahedraP2Ordering`: per node of a `TetrahedraP2` entry, its barycentric
/// (Bezier) multi-index, component k for corner k: corners, then edges 01, 12, 02, 03, 13, 23.
const TET_P2_ORDERING: [[u8; 4]; 10] = [
    [2, 0, 0, 0],
    [0, 2, 0, 0],
    [0, 0, 2, 0],
    [0, 0, 0, 2],
    [1, 1, 0, 0],
    [0, 1, 1, 0],
    [1, 0, 1, 0],
    [1, 0, 0, 1],
    [0, 1, 0, 1],
    [0, 0, 1, 1],
];

/// libMeshb's `TrianglesP2Ordering`: corners, then edges 01, 12, 20.
const TRIANGLE_P2_ORDERING: [[u8; 3]; 6] = [
    [2, 0, 0],
    [0, 2, 0],
    [0, 0, 2],
    [1, 1, 0],
    [0, 1, 1],
    [1, 0, 1],
];

fn format_elements<W: Write>(w: &mut W, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    let p2 = if el.is_quadratic() { "P2" } else { "" };
    let mut line = Vec::new();
    let mut ids: Vec<i64> = Vec::with_capacity(11);
    writeln!(w, "MeshVersionFormatted 2\n\nDimension 3\n")?;
    writeln!(w, "Vertices\n{}", el.n_nodes())?;
    for p in el.nodes() {
        writeln!(w, "{} {} {} 0", F(p.x), F(p.y), F(p.z))?;
    }
    if !mesh.tets.is_empty() {
        if el.is_quadratic() {
            writeln!(w, "\nTetrahedraP2Ordering\n{}", TET_P2_ORDERING.len())?;
            for o in TET_P2_ORDERING {
                write_int_line(w, &mut line, &o.map(i64::from))?;
            }
        }
        writeln!(w, "\nTetrahedra{p2}\n{}", mesh.tets.len())?;
        for (i, &r) in mesh.tet_regions.iter().enumerate() {
            ids.clear();
            ids.extend(el.tet_in(i, &TET_ORDER).map(|v| i64::from(v) + 1));
            ids.push(i64::from(r));
            write_int_line(w, &mut line, &ids)?;
        }
    }
    if !mesh.boundary.is_empty() {
        if el.is_quadratic() {
            writeln!(w, "\nTrianglesP2Ordering\n{}", TRIANGLE_P2_ORDERING.len())?;
            for o in TRIANGLE_P2_ORDERING {
                write_int_line(w, &mut line, &o.map(i64::from))?;
            }
        }
        writeln!(w, "\nTriangles{p2}\n{}", mesh.boundary.len())?;
        for (j, &m) in mesh.boundary_markers.iter().enumerate() {
            ids.clear();
            ids.extend(el.triangle_in(j, &TRIANGLE_ORDER).map(|v| i64::from(v) + 1));
            ids.push(i64::from(m));
            write_int_line(w, &mut line, &ids)?;
        }
    }
    writeln!(w, "\nEnd")
}

/// Reads a medit `.mesh` file.
pub fn read_medit(path: &Path) -> Result<TetMesh, IoError> {
    let text = read_text(path)?;
    parse_medit(&text).map_err(|e| with_path(e, path))
}

/// Tokens per entry of the sections that are read past.
fn skipped_section_width(kw: &str) -> Option<usize> {
    const TABLE: &[(&str, usize)] = &[
        ("edges", 3),
        ("quadrilaterals", 5),
        ("hexahedra", 9),
        ("prisms", 7),
        ("pyramids", 6),
        ("corners", 1),
        ("ridges", 1),
        ("requiredvertices", 1),
        ("requirededges", 1),
        ("requiredtriangles", 1),
        ("requiredquadrilaterals", 1),
        ("requiredtetrahedra", 1),
        ("normals", 3),
        ("normalatvertices", 2),
        ("tangents", 3),
        ("tangentatvertices", 2),
        ("tetrahedrap2ordering", 4),
        ("trianglesp2ordering", 3),
    ];
    let kw = kw.to_ascii_lowercase();
    TABLE.iter().find(|(k, _)| *k == kw).map(|&(_, n)| n)
}

/// Parses the text of a medit `.mesh` file.
pub fn parse_medit(text: &str) -> Result<TetMesh, IoError> {
    let mut tok = Tokens::new(text);
    let mut mesh = TetMesh::default();
    let mut seen_version = false;
    // Element indices with their lines, checked once the vertex count is known.
    let mut pending: Vec<(usize, i64, &'static str)> = Vec::new();
    let mut tets: Vec<[i64; 4]> = Vec::new();
    let mut tris: Vec<[i64; 3]> = Vec::new();
    let mut seen_vertices = false;
    while let Some((line, kw)) = tok.next_opt() {
        let lower = kw.to_ascii_lowercase();
        match lower.as_str() {
            "meshversionformatted" | "dimension" => {
                seen_version |= read_header_value(&mut tok, lower.as_str())?;
            }
            "vertices" => {
                if seen_vertices {
                    return Err(err_at(line, "second Vertices section"));
                }
                seen_vertices = true;
                let n = tok.usize("number of vertices")?;
                to_u32(n, line, "number of vertices")?;
                mesh.vertices.reserve(super::text::cap(n));
                for _ in 0..n {
                    mesh.vertices.push(tok.point()?);
                    tok.i32("vertex reference")?;
                }
            }
            "tetrahedra" | "tetrahedrap2" => {
                let n = tok.usize("number of tetrahedra")?;
                let k = if lower == "tetrahedra" { 4 } else { 10 };
                for _ in 0..n {
                    let mut t = [0i64; 10];
                    for c in t.iter_mut().take(k) {
                        let (l, v) = tok.raw_index("tetrahedron vertex index")?;
                        pending.push((l, v, "tetrahedron vertex index"));
                        *c = v;
                    }
                    tets.push([t[0], t[1], t[2], t[3]]);
                    mesh.tet_regions.push(tok.i32("tetrahedron reference")?);
                }
            }
            "triangles" | "trianglesp2" => {
                let n = tok.usize("number of triangles")?;
                let k = if lower == "triangles" { 3 } else { 6 };
                for _ in 0..n {
                    let mut t = [0i64; 6];
                    for c in t.iter_mut().take(k) {
                        let (l, v) = tok.raw_index("triangle vertex index")?;
                        pending.push((l, v, "triangle vertex index"));
                        *c = v;
                    }
                    tris.push([t[0], t[1], t[2]]);
                    mesh.boundary_markers.push(tok.i32("triangle reference")?);
                }
            }
            "identifier" | "geometry" => {
                // A quoted string, possibly with spaces: skip to the end of its line.
                tok.next("value")?;
                tok.skip_line();
            }
            "end" => break,
            other => match skipped_section_width(other) {
                Some(width) => {
                    let n = tok.usize(&format!("number of entries of {kw}"))?;
                    for _ in 0..n.saturating_mul(width) {
                        tok.next(&format!("entry of {kw}"))?;
                    }
                }
                None if kw.parse::<f64>().is_ok() => {
                    return Err(err_at(
                        line,
                        format!(
                            "found number '{kw}' where a keyword was expected (is the count of \
                             the previous section wrong?)"
                        ),
                    ))
                }
                None => {
                    return Err(err_at(
                        line,
                        format!("unknown or unsupported keyword '{kw}'"),
                    ))
                }
            },
        }
    }
    if !seen_version {
        return Err(err_at(1, "missing 'MeshVersionFormatted' header"));
    }
    let nv = mesh.vertices.len();
    for &(l, v, what) in &pending {
        check_index(v, l, 1, nv, what)?;
    }
    // All indices are in 1..=nv <= u32::MAX + 1 now, so the conversions below are exact.
    let id = |v: i64| (v - 1) as u32;
    mesh.tets = tets
        .iter()
        .map(|t| [id(t[0]), id(t[1]), id(t[2]), id(t[3])])
        .collect();
    mesh.boundary = tris
        .iter()
        .map(|t| [id(t[0]), id(t[1]), id(t[2])])
        .collect();
    Ok(mesh)
}

#[cfg(test)]
mod tests {
    use super::*;

    const SMALL: &str = "MeshVersionFormatted 2\nDimension\n3\nVertices\n4\n0 0 0 1\n1 0 0 1\n\
        0 1 0 1\n0 0 1 1\nEdges\n1\n1 2 0\nTetrahedra\n1\n1 2 3 4 7\nTriangles\n1\n1 3 2 5\nEnd\n";

    #[test]
    fn reads_sections_and_skips_edges() {
        let m = parse_medit(SMALL).unwrap();
        assert_eq!(m.vertices.len(), 4);
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(m.tet_regions, vec![7]);
        assert_eq!(m.boundary, vec![[0, 2, 1]]);
        assert_eq!(m.boundary_markers, vec![5]);
    }

    fn expect_err(text: &str, line: usize, needle: &str) {
        let e = parse_medit(text).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_medit_files() {
        expect_err("Dimension 3\n", 1, "missing 'MeshVersionFormatted'");
        expect_err(
            "MeshVersionFormatted 2\nDimension 2\n",
            2,
            "dimension must be 3",
        );
        expect_err(
            "MeshVersionFormatted 9\n",
            1,
            "unsupported MeshVersionFormatted",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n2\n0 0 0 0\n",
            5,
            "unexpected end",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n1\n0 0 x 0\n",
            4,
            "bad number 'x'",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nTetrahedra\n1\n1 1 1 2 0\n",
            7,
            "out of range",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\nTriangles\n1\n1 0 1 0\n",
            7,
            "out of range",
        );
        expect_err(
            "MeshVersionFormatted 2\nBlobs\n1\n",
            2,
            "unknown or unsupported keyword",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n-1\n",
            3,
            "bad non-negative integer",
        );
        expect_err(
            "MeshVersionFormatted 2\nVertices\n1\n0 0 0 0\n1 1 1 0\n",
            5,
            "found number '1' where a keyword was expected",
        );
    }

    #[test]
    fn truncated_medit_never_panics() {
        for cut in 0..SMALL.len() {
            let _ = parse_medit(&SMALL[..cut]);
        }
    }
}
