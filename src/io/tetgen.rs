//! TetGen mesh files `.node` / `.ele` / `.face`: writer, and a reader for the same subset.
//!
//! Given any of `X.node`, `X.ele` or `X.face` (or any other extension), the three files
//! `X.node`, `X.ele` and `X.face` are written, **1-based** like TetGen's default:
//! - `X.node`: `<#points> 3 0 0`, then `<id> <x> <y> <z>`;
//! - `X.ele`: `<#tets> 4 1`, then `<id> <v1> <v2> <v3> <v4> <region attribute>`; tets keep the
//!   mesh's positive orientation, which is also TetGen's;
//! - `X.face`: `<#triangles> 1`, then `<id> <v1> <v2> <v3> <facet marker>`.
//!
//! Ten-node tets ([`write_tetgen_quadratic`]), as `tetgen -o2` writes them: `X.node` holds the
//! corners, then the mid-edge nodes; `X.ele` is `<#tets> 10 1`, each tet its corners a, b, c, d
//! and then the nodes of the edges cd, ad, ab, bc, bd, ac (TetGen's fixed order: see
//! `elements::TETGEN_TET_ORDER` for where in tetgen.cxx it comes from); `X.face` has per
//! triangle a, b, c, then the nodes of the edges opposite them: bc, ca, ab.
//!
//! Read: `X.node` (attributes and markers ignored; its first id, 0 or 1, sets the base of every
//! index), `X.ele` (4 or 10 nodes per tet: the first 4 are the corners; the first attribute,
//! an integer possibly written as `2.0`, is the region, 0 without attributes) and, if it
//! exists, `X.face` (marker 0 when the file has none; beside a 10-node `.ele`, 6 nodes per
//! face, as TetGen writes and reads them, of which the first 3 are kept). Ids must be
//! consecutive from the base. Errors name the file and line.

use super::elements::{Elements, TETGEN_TET_ORDER, TETGEN_TRIANGLE_ORDER};
use super::poly::{parse_node, NodeList};
use super::text::{
    check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, err_at,
    parse_integral_i32, read_text, with_path, write_err, write_int_line, Lines, F,
};
use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The `.node`, `.ele` and `.face` paths that belong with `path`.
pub fn tetgen_paths(path: &Path) -> (PathBuf, PathBuf, PathBuf) {
    (
        path.with_extension("node"),
        path.with_extension("ele"),
        path.with_extension("face"),
    )
}

/// Writes `mesh` as `X.node`, `X.ele` and `X.face` (see the module doc).
pub fn write_tetgen(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    write_files(path, &Elements::new(mesh, None))
}

/// Writes `mesh` with its mid-edge nodes as TetGen `-o2` files `X.node`, `X.ele` (10 nodes per
/// tet) and `X.face` (6 nodes per triangle); see the module doc for the node order.
pub fn write_tetgen_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    write_files(path, &Elements::new(mesh, Some(quadratic)))
}

fn write_files(path: &Path, el: &Elements) -> Result<(), IoError> {
    let (node, ele, face) = tetgen_paths(path);
    let write = |p: &Path, f: &dyn Fn(&mut dyn Write) -> std::io::Result<()>| {
        let mut w = create(p)?;
        f(&mut w)
            .and_then(|_| w.flush())
            .map_err(|e| write_err(p, e))
    };
    write(&node, &|w| node_part(w, el))?;
    write(&ele, &|w| ele_part(w, el))?;
    write(&face, &|w| face_part(w, el))
}

/// Writes the `.node` part.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_node(w: &mut dyn Write, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    node_part(w, &Elements::new(mesh, None))
}

/// Writes the `.ele` part.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_ele(w: &mut dyn Write, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    ele_part(w, &Elements::new(mesh, None))
}

/// Writes the `.face` part.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_face(w: &mut dyn Write, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    face_part(w, &Elements::new(mesh, None))
}

/// The three parts of the `-o2` files of `mesh` with its mid-edge nodes, one writer each
/// (`.node`, `.ele`, `.face`).
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_tetgen_quadratic(
    node: &mut dyn Write,
    ele: &mut dyn Write,
    face: &mut dyn Write,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    check_quadratic_io(mesh, quadratic)?;
    let el = Elements::new(mesh, Some(quadratic));
    node_part(node, &el)?;
    ele_part(ele, &el)?;
    face_part(face, &el)
}

fn node_part(w: &mut dyn Write, el: &Elements) -> std::io::Result<()> {
    writeln!(w, "{} 3 0 0", el.n_nodes())?;
    for (i, p) in el.nodes().enumerate() {
        writeln!(w, "{} {} {} {}", i + 1, F(p.x), F(p.y), F(p.z))?;
    }
    writeln!(w, "# written by slivermesh")
}

fn ele_part(w: &mut dyn Write, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    writeln!(w, "{} {} 1", mesh.tets.len(), el.tet_nodes())?;
    let mut line = Vec::new();
    let mut ids: Vec<i64> = Vec::with_capacity(12);
    for (i, &r) in mesh.tet_regions.iter().enumerate() {
        ids.clear();
        ids.push(i as i64 + 1);
        ids.extend(el.tet_in(i, &TETGEN_TET_ORDER).map(|v| i64::from(v) + 1));
        ids.push(i64::from(r));
        write_int_line(w, &mut line, &ids)?;
    }
    writeln!(w, "# written by slivermesh")
}

fn face_part(w: &mut dyn Write, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    writeln!(w, "{} 1", mesh.boundary.len())?;
    let mut line = Vec::new();
    let mut ids: Vec<i64> = Vec::with_capacity(8);
    for (j, &m) in mesh.boundary_markers.iter().enumerate() {
        ids.clear();
        ids.push(j as i64 + 1);
        ids.extend(
            el.triangle_in(j, &TETGEN_TRIANGLE_ORDER)
                .map(|v| i64::from(v) + 1),
        );
        ids.push(i64::from(m));
        write_int_line(w, &mut line, &ids)?;
    }
    writeln!(w, "# written by slivermesh")
}

/// Reads `X.node`, `X.ele` and (if present) `X.face`.
pub fn read_tetgen(path: &Path) -> Result<TetMesh, IoError> {
    let (node, ele, face) = tetgen_paths(path);
    let node_text = read_text(&node)?;
    let ele_text = read_text(&ele)?;
    let face_text = if face.exists() {
        Some(read_text(&face)?)
    } else {
        None
    };
    let nodes = parse_node(&node_text).map_err(|e| with_path(e, &node))?;
    let mut mesh = TetMesh::default();
    let per_tet = parse_ele(&ele_text, &nodes, &mut mesh).map_err(|e| with_path(e, &ele))?;
    if let Some(t) = face_text {
        // TetGen -o2 writes its faces with their three mid-edge nodes too.
        let per_face = if per_tet == 10 { 6 } else { 3 };
        parse_face_nodes(&t, &nodes, per_face, &mut mesh).map_err(|e| with_path(e, &face))?;
    }
    mesh.vertices = nodes.vertices;
    Ok(mesh)
}

/// Checks a record's leading id against its expected value.
fn check_id(r: &mut super::text::Record, expected: usize, what: &str) -> Result<(), IoError> {
    let id = r.i64(&format!("{what} id"))?;
    if id != expected as i64 {
        return Err(err_at(
            r.line,
            format!("{what} id {id} out of sequence: expected {expected}"),
        ));
    }
    Ok(())
}

/// Parses `.ele` text into `mesh.tets` and `mesh.tet_regions`; returns the nodes per tet (4,
/// or 10 for TetGen `-o2` files, whose first four are the corners).
pub fn parse_ele(text: &str, nodes: &NodeList, mesh: &mut TetMesh) -> Result<usize, IoError> {
    let mut lines = Lines::new(text);
    let mut r = lines.next("header '<#tets> <nodes per tet> <#attributes>'")?;
    let n = r.usize("number of tetrahedra")?;
    let k = r.usize_opt("nodes per tetrahedron")?.unwrap_or(4);
    if k != 4 && k != 10 {
        return Err(err_at(
            r.line,
            format!("nodes per tetrahedron must be 4 or 10, found {k}"),
        ));
    }
    let nattr = r.usize_opt("number of attributes")?.unwrap_or(0);
    let nv = nodes.vertices.len();
    mesh.tets.reserve(super::text::cap(n));
    for i in 0..n {
        let mut r = lines.next(&format!("tetrahedron {} of {n}", i + 1))?;
        check_id(&mut r, nodes.base + i, "tetrahedron")?;
        let mut t = [0u32; 4];
        for c in t.iter_mut() {
            *c = r.index(nodes.base, nv, "tetrahedron vertex index")?;
        }
        for _ in 4..k {
            r.index(nodes.base, nv, "tetrahedron vertex index")?;
        }
        let region = if nattr > 0 {
            let w = r.word("region attribute")?;
            parse_integral_i32(w, r.line, "region attribute")?
        } else {
            0
        };
        mesh.tets.push(t);
        mesh.tet_regions.push(region);
    }
    lines.expect_end(&format!("the {n} tetrahedra declared"))?;
    Ok(k)
}

/// Parses `.face` text into `mesh.boundary` and `mesh.boundary_markers`.
pub fn parse_face(text: &str, nodes: &NodeList, mesh: &mut TetMesh) -> Result<(), IoError> {
    parse_face_nodes(text, nodes, 3, mesh)
}

/// [`parse_face`] of faces with `per_face` nodes each (3, or 6 beside a ten-node `.ele`: the
/// corners, then three mid-edge nodes, which are read past).
pub fn parse_face_nodes(
    text: &str,
    nodes: &NodeList,
    per_face: usize,
    mesh: &mut TetMesh,
) -> Result<(), IoError> {
    let mut lines = Lines::new(text);
    let mut r = lines.next("header '<#faces> <markers 0|1>'")?;
    let n = r.usize("number of faces")?;
    let markers = r.usize_opt("marker flag (0 or 1)")?.unwrap_or(0) != 0;
    let nv = nodes.vertices.len();
    mesh.boundary.reserve(super::text::cap(n));
    for i in 0..n {
        let mut r = lines.next(&format!("face {} of {n}", i + 1))?;
        check_id(&mut r, nodes.base + i, "face")?;
        let mut t = [0u32; 3];
        for c in t.iter_mut() {
            *c = r.index(nodes.base, nv, "face vertex index")?;
        }
        for _ in 3..per_face {
            r.index(nodes.base, nv, "face mid-edge node index")?;
        }
        let m = if markers { r.i32("face marker")? } else { 0 };
        mesh.boundary.push(t);
        mesh.boundary_markers.push(m);
    }
    lines.expect_end(&format!("the {n} faces declared"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    fn nodes() -> NodeList {
        NodeList {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            base: 1,
        }
    }

    #[test]
    fn reads_ten_node_tets_and_float_attributes() {
        let mut m = TetMesh::default();
        let n = NodeList { base: 0, ..nodes() };
        parse_ele("1 10 2\n0 0 1 2 3 0 1 2 3 0 1 -2.0 7\n", &n, &mut m).unwrap();
        assert_eq!(m.tets, vec![[0, 1, 2, 3]]);
        assert_eq!(m.tet_regions, vec![-2]);
        parse_face("1 0\n0 0 2 1\n", &n, &mut m).unwrap();
        assert_eq!(m.boundary_markers, vec![0]);
    }

    fn ele_err(text: &str, line: usize, needle: &str) {
        let e = parse_ele(text, &nodes(), &mut TetMesh::default()).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    fn face_err(text: &str, line: usize, needle: &str) {
        let e = parse_face(text, &nodes(), &mut TetMesh::default()).unwrap_err();
        assert_eq!(e.line, Some(line), "{e}");
        assert!(e.message.contains(needle), "'{needle}' not in: {e}");
    }

    #[test]
    fn malformed_ele_and_face_files() {
        ele_err("", 1, "unexpected end");
        ele_err("1 6 0\n", 1, "4 or 10");
        ele_err("2 4 0\n1 1 2 3 4\n", 3, "tetrahedron 2 of 2");
        ele_err("1 4 0\n1 1 2 3 5\n", 2, "out of range");
        ele_err("1 4 0\n2 1 2 3 4\n", 2, "out of sequence");
        ele_err("1 4 1\n1 1 2 3 4\n", 2, "expected region attribute");
        ele_err("1 4 1\n1 1 2 3 4 0.5\n", 2, "must be an integer");
        face_err("1 1\n1 1 2 3\n", 2, "expected face marker");
        face_err("1 1\n1 1 2 0 4\n", 2, "out of range");
        face_err("1 1\n1 1 2 x 4\n", 2, "bad integer 'x'");
        ele_err("1 4 0\n1 1 2 3 4\n2 1 2 3 4\n", 3, "after the 1 tetrahedra");
        face_err("1 0\n1 1 2 3\n2 1 2 4\n", 3, "after the 1 faces");
    }

    #[test]
    fn truncated_files_never_panic() {
        let mut buf = Vec::new();
        let mesh = TetMesh {
            vertices: nodes().vertices,
            tets: vec![[0, 1, 2, 3]],
            tet_regions: vec![3],
            boundary: vec![[0, 2, 1]],
            boundary_markers: vec![4],
        };
        format_ele(&mut buf, &mesh).unwrap();
        format_face(&mut buf, &mesh).unwrap();
        let t = String::from_utf8(buf).unwrap();
        for cut in 0..t.len() {
            let _ = parse_ele(&t[..cut], &nodes(), &mut TetMesh::default());
            let _ = parse_face(&t[..cut], &nodes(), &mut TetMesh::default());
        }
    }
}
