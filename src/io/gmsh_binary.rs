//! Gmsh `.msh` 4.1 binary writer: the same content as [`super::gmsh::format_msh`] (physical
//! names, one surface entity per boundary marker and one volume per region attribute, one node
//! block, element tags tet i = i + 1 and boundary triangle j = #tets + j + 1), with the entity,
//! node and element sections in the binary layout of the MSH 4.1 specification: `$MeshFormat`
//! `4.1 1 8` and the int 1 (the reader's endianness check), then `int` as 4 and `size_t` as 8
//! little-endian bytes, coordinates as 8-byte doubles. `$PhysicalNames` stays ASCII, as in
//! gmsh's own binary files. Ten-node tets: [`format_msh_binary_quadratic`], the content of
//! [`super::gmsh::format_msh_quadratic`].

use super::elements::{Elements, GMSH_TET_ORDER, TRIANGLE_ORDER};
use super::gmsh::{bbox, element_types, entities};
use super::text::{
    check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, with_path, write_err,
};
use super::IoError;
use crate::mesh::{QuadraticNodes, TetMesh};
use std::io::Write;
use std::path::Path;

/// Writes `mesh` as a gmsh 4.1 binary `.msh` file.
pub fn write_msh_binary(path: &Path, mesh: &TetMesh) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_msh_binary(&mut w, mesh)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` with its mid-edge nodes as a gmsh 4.1 binary `.msh` file of ten-node tets.
pub fn write_msh_binary_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> Result<(), IoError> {
    check_mesh(mesh, &[]).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_msh_binary_quadratic(&mut w, mesh, quadratic)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

fn int<W: Write>(w: &mut W, v: i32) -> std::io::Result<()> {
    w.write_all(&v.to_le_bytes())
}

fn size<W: Write>(w: &mut W, v: usize) -> std::io::Result<()> {
    w.write_all(&(v as u64).to_le_bytes())
}

fn double<W: Write>(w: &mut W, v: f64) -> std::io::Result<()> {
    w.write_all(&v.to_le_bytes())
}

/// An entity record: tag, bounding box, one physical tag, no bounding entities.
fn entity<W: Write>(w: &mut W, tag: usize, b: [f64; 6], value: i32) -> std::io::Result<()> {
    int(w, tag as i32)?;
    for x in b {
        double(w, x)?;
    }
    size(w, 1)?;
    int(w, value)?;
    size(w, 0)
}

/// Writes `mesh` in gmsh 4.1 binary format to any writer.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_msh_binary<W: Write>(w: &mut W, mesh: &TetMesh) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    format_elements(w, &Elements::new(mesh, None))
}

/// [`format_msh_binary`] of ten-node tets (type 11) and six-node boundary triangles (type 9),
/// node order as in [`super::gmsh::format_msh_quadratic`].
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_msh_binary_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
) -> std::io::Result<()> {
    check_mesh_io(mesh, &[])?;
    check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)))
}

fn format_elements<W: Write>(w: &mut W, el: &Elements) -> std::io::Result<()> {
    let mesh = el.mesh;
    let (nv, nt, nb) = (el.n_nodes(), mesh.tets.len(), mesh.boundary.len());
    let (volumes, surfaces) = entities(mesh);
    let (tet_type, tri_type) = element_types(el);
    w.write_all(b"$MeshFormat\n4.1 1 8\n")?;
    int(w, 1)?;
    w.write_all(b"\n$EndMeshFormat\n")?;
    super::gmsh::write_physical_names(w, &volumes, &surfaces)?;

    w.write_all(b"$Entities\n")?;
    for n in [0, 0, surfaces.len(), volumes.len()] {
        size(w, n)?;
    }
    for (k, e) in surfaces.iter().enumerate() {
        entity(w, k + 1, bbox(el, false, &e.elements), e.value)?;
    }
    for (k, e) in volumes.iter().enumerate() {
        entity(w, k + 1, bbox(el, true, &e.elements), e.value)?;
    }
    w.write_all(b"\n$EndEntities\n")?;

    w.write_all(b"$Nodes\n")?;
    if nv == 0 {
        for _ in 0..4 {
            size(w, 0)?;
        }
    } else {
        for n in [1, nv, 1, nv] {
            size(w, n)?;
        }
        for v in [3, 1, 0] {
            int(w, v)?;
        }
        size(w, nv)?;
        for i in 1..=nv {
            size(w, i)?;
        }
        for p in el.nodes() {
            for x in p.to_array() {
                double(w, x)?;
            }
        }
    }
    w.write_all(b"\n$EndNodes\n")?;

    let ne = nt + nb;
    let blocks = volumes.iter().filter(|e| !e.elements.is_empty()).count() + surfaces.len();
    w.write_all(b"$Elements\n")?;
    if ne == 0 {
        for _ in 0..4 {
            size(w, 0)?;
        }
    } else {
        for n in [blocks, ne, 1, ne] {
            size(w, n)?;
        }
    }
    for (k, e) in volumes.iter().enumerate() {
        if e.elements.is_empty() {
            continue;
        }
        for v in [3, k as i32 + 1, tet_type] {
            int(w, v)?;
        }
        size(w, e.elements.len())?;
        for &i in &e.elements {
            size(w, i + 1)?;
            for v in el.tet_in(i, &GMSH_TET_ORDER) {
                size(w, v as usize + 1)?;
            }
        }
    }
    for (k, e) in surfaces.iter().enumerate() {
        for v in [2, k as i32 + 1, tri_type] {
            int(w, v)?;
        }
        size(w, e.elements.len())?;
        for &j in &e.elements {
            size(w, nt + j + 1)?;
            for v in el.triangle_in(j, &TRIANGLE_ORDER) {
                size(w, v as usize + 1)?;
            }
        }
    }
    w.write_all(b"\n$EndElements\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The layout on one tet: the header with the endianness int, then each section's counts
    /// where the specification puts them (Gmsh 4.15 reading the files is the ctest
    /// msh_binary_readback_*).
    #[test]
    fn layout_of_one_tet() {
        let m = TetMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            tets: vec![[0, 1, 2, 3]],
            tet_regions: vec![5],
            boundary: vec![[0, 2, 1]],
            boundary_markers: vec![2],
        };
        let mut out = Vec::new();
        format_msh_binary(&mut out, &m).unwrap();
        let head = b"$MeshFormat\n4.1 1 8\n";
        assert_eq!(&out[..head.len()], head);
        assert_eq!(&out[head.len()..head.len() + 4], &1i32.to_le_bytes());
        let find = |s: &[u8]| out.windows(s.len()).position(|w| w == s).unwrap() + s.len();
        let u64_at = |o: usize| u64::from_le_bytes(out[o..o + 8].try_into().unwrap());
        // $Nodes: 1 block, 4 nodes, tags 1..4; then the block header and the tags.
        let nodes = find(b"$Nodes\n");
        assert_eq!([0, 8, 16, 24].map(|k| u64_at(nodes + k)), [1, 4, 1, 4]);
        assert_eq!(u64_at(nodes + 32 + 12), 4);
        // $Elements: 2 blocks (the volume, the surface), 2 elements, tags 1..2.
        let elems = find(b"$Elements\n");
        assert_eq!([0, 8, 16, 24].map(|k| u64_at(elems + k)), [2, 2, 1, 2]);
        // The tet block: dim 3, entity 1, type 4, one element: tag 1, nodes 1 2 3 4.
        let block = elems + 32;
        assert_eq!(
            &out[block..block + 12],
            &[3, 0, 0, 0, 1, 0, 0, 0, 4, 0, 0, 0]
        );
        assert_eq!(
            [0, 1, 2, 3, 4, 5].map(|k| u64_at(block + 12 + 8 * k)),
            [1, 1, 1, 2, 3, 4]
        );
        assert!(out.ends_with(b"\n$EndElements\n"));
        let text = String::from_utf8_lossy(&out);
        assert!(text.contains("$PhysicalNames\n2\n3 5 \"region_5\"\n2 2 \"marker_2\"\n"));
    }
}
