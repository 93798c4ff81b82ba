//! Abaqus `.inp` writer (also read by CalculiX, Code_Aster's converters, meshio).
//!
//! Written: `*HEADING`; `*NODE, NSET=ALL_NODES` (1-based ids, the mesh's vertex order); one
//! `*ELEMENT, TYPE=C3D4, ELSET=REGION_<attribute>` block per region attribute (element id = the
//! tet's 1-based place in the mesh, so the ids are those of every other writer; the node order
//! is the mesh's, positively oriented, which is Abaqus's C3D4 order); `*ELSET, ELSET=ALL_TETS`;
//! one `*SURFACE, TYPE=ELEMENT, NAME=MARKER_<marker>` per boundary marker, each boundary
//! triangle as (element, face) with the C3D4 face numbers S1 = (1, 2, 3), S2 = (1, 4, 2),
//! S3 = (2, 4, 3), S4 = (3, 4, 1). A negative attribute or marker is written `M` and its
//! absolute value (`REGION_M1`). An interface triangle (a face of two tets) is given on the tet
//! its normal points out of. Writing only.
//!
//! Ten-node tets ([`format_inp_quadratic`]): `*NODE` lists the corners, then the mid-edge
//! nodes; the elements are `TYPE=C3D10` with the corners and then the nodes of the edges
//! (1,2), (2,3), (3,1), (1,4), (2,4), (3,4), Abaqus's C3D10 order (the mesh's own); sets and
//! surfaces are the same, C3D10 numbering its faces as C3D4 does.

use super::elements::{Elements, TET_ORDER};
use super::text::{check_mesh, check_quadratic, create, with_path, write_err, F};
use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use rustc_hash::FxHashMap;
use std::collections::BTreeMap;
use std::io::Write;
use std::path::Path;

/// C3D4 face number (1-based) of the face opposite each local vertex.
const FACE_OPPOSITE: [u8; 4] = [3, 4, 2, 1];

/// Writes `mesh` as an Abaqus `.inp` file.
pub fn write_inp(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    let mut w = create(path)?;
    format_inp(&mut w, mesh)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` with its mid-edge nodes as an Abaqus `.inp` file of C3D10 elements.
pub fn write_inp_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_inp_quadratic(&mut w, mesh, quadratic)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// The set name of an attribute or marker.
fn name(prefix: &str, v: i32) -> String {
    if v < 0 {
        format!("{prefix}_M{}", v.unsigned_abs())
    } else {
        format!("{prefix}_{v}")
    }
}

/// For each boundary triangle: the 1-based element and C3D4 face it lies on, on the tet its
/// normal points out of where two tets share it.
fn boundary_faces(mesh: &TetMesh) -> Vec<Option<(usize, u8)>> {
    let key = |mut f: [u32; 3]| {
        f.sort_unstable();
        f
    };
    let index: FxHashMap<[u32; 3], usize> = mesh
        .boundary
        .iter()
        .enumerate()
        .map(|(i, &f)| (key(f), i))
        .collect();
    let mut out: Vec<Option<(usize, u8)>> = vec![None; mesh.boundary.len()];
    for (t, tv) in mesh.tets.iter().enumerate() {
        for (k, &face) in FACE_OPPOSITE.iter().enumerate() {
            let tri = [tv[(k + 1) % 4], tv[(k + 2) % 4], tv[(k + 3) % 4]];
            let Some(&b) = index.get(&key(tri)) else {
                continue;
            };
            // The triangle's normal points away from this tet when its fourth vertex lies
            // behind the triangle's plane.
            let [a, bb, c] = mesh.boundary[b].map(|v| mesh.vertices[v as usize]);
            let d = mesh.vertices[tv[k] as usize];
            let behind = (bb - a).cross(c - a).dot(d - a) < 0.0;
            if out[b].is_none() || behind {
                out[b] = Some((t + 1, face));
            }
        }
    }
    out
}

/// Writes `mesh` in Abaqus `.inp` format to any writer.
pub fn format_inp<W: Write>(w: &mut W, mesh: &TetMesh) -> std::io::Result<()> {
    super::text::check_mesh_io(mesh, &[])?;
    format_elements(w, &Elements::new(mesh, None))
}

/// Writes `mesh` with its mid-edge nodes as C3D10 elements in Abaqus `.inp` format (nodes:
/// the corners, then the mid-edge nodes; element sets and surfaces as in [`format_inp`]).
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_inp_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> std::io::Result<()> {
    super::text::check_mesh_io(mesh, &[])?;
    super::text::check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)))
}

fn format_elements<W: Write>(w: &mut W, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    let ty = if el.is_quadratic() { "C3D10" } else { "C3D4" };
    writeln!(w, "*HEADING")?;
    writeln!(
        w,
        "slivermesh {}: {} nodes, {} {ty} elements, {} boundary faces",
        env!("CARGO_PKG_VERSION"),
        el.n_nodes(),
        mesh.tets.len(),
        mesh.boundary.len()
    )?;
    writeln!(w, "*NODE, NSET=ALL_NODES")?;
    for (i, p) in el.nodes().enumerate() {
        writeln!(w, "{}, {}, {}, {}", i + 1, F(p.x), F(p.y), F(p.z))?;
    }
    let mut regions: BTreeMap<i32, Vec<usize>> = BTreeMap::new();
    for (t, &r) in mesh.tet_regions.iter().enumerate() {
        regions.entry(r).or_default().push(t);
    }
    let mut line = String::new();
    for (&r, tets) in &regions {
        writeln!(w, "*ELEMENT, TYPE={ty}, ELSET={}", name("REGION", r))?;
        for &t in tets {
            // Abaqus data lines hold at most 16 entries: an element number and 10 nodes fit.
            line.clear();
            line.push_str(itoa::Buffer::new().format(t + 1));
            for v in el.tet_in(t, &TET_ORDER) {
                line.push_str(", ");
                line.push_str(itoa::Buffer::new().format(v as usize + 1));
            }
            writeln!(w, "{line}")?;
        }
    }
    if !mesh.tets.is_empty() {
        writeln!(w, "*ELSET, ELSET=ALL_TETS, GENERATE")?;
        writeln!(w, "1, {}, 1", mesh.tets.len())?;
    }
    let faces = boundary_faces(mesh);
    let mut markers: BTreeMap<i32, Vec<(usize, u8)>> = BTreeMap::new();
    for (f, &m) in faces.iter().zip(&mesh.boundary_markers) {
        if let Some(f) = f {
            markers.entry(m).or_default().push(*f);
        }
    }
    for (&m, faces) in &markers {
        writeln!(w, "*SURFACE, TYPE=ELEMENT, NAME={}", name("MARKER", m))?;
        for (e, s) in faces {
            writeln!(w, "{e}, S{s}")?;
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// Two tets sharing the face (1, 2, 3), regions 1 and 2, that face an interface with
    /// marker 7 and the other six faces boundary with marker 3.
    fn two_tets() -> TetMesh {
        TetMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, DVec3::ONE],
            tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
            tet_regions: vec![1, -2],
            boundary: vec![
                [0, 2, 1],
                [0, 1, 3],
                [0, 3, 2],
                [1, 2, 3],
                [1, 2, 4],
                [2, 3, 4],
                [3, 1, 4],
            ],
            boundary_markers: vec![3, 3, 3, 7, 3, 3, 3],
        }
    }

    #[test]
    fn sections_and_faces() {
        let m = two_tets();
        for t in &m.tets {
            let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
            assert!(crate::geom::orient3d(a, b, c, d) > 0.0);
        }
        let mut out = Vec::new();
        format_inp(&mut out, &m).unwrap();
        let text = String::from_utf8(out).unwrap();
        assert!(
            text.contains("*NODE, NSET=ALL_NODES\n1, 0, 0, 0\n2, 1, 0, 0\n"),
            "{text}"
        );
        assert!(
            text.contains("*ELEMENT, TYPE=C3D4, ELSET=REGION_M2\n2, 2, 3, 4, 5\n"),
            "{text}"
        );
        assert!(
            text.contains("*ELEMENT, TYPE=C3D4, ELSET=REGION_1\n1, 1, 2, 3, 4\n"),
            "{text}"
        );
        // The interface (1, 2, 3) 0-based, normal along +(1,1,1): out of tet 1, its face S3
        // (local vertices 1, 3, 2, opposite vertex 0).
        assert!(
            text.contains("*SURFACE, TYPE=ELEMENT, NAME=MARKER_7\n1, S3\n"),
            "{text}"
        );
        // Tet 1's face (0, 2, 1) is S1 (opposite local vertex 3).
        let m3 = text.split("NAME=MARKER_3\n").nth(1).unwrap();
        let m3 = m3.split('*').next().unwrap();
        assert!(m3.lines().any(|l| l == "1, S1"), "{m3}");
        assert_eq!(m3.lines().count(), 6);
    }
}
