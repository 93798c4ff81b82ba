//! The paper's second kind of input: an "almost good" mesh whose slivers are to be removed.
//! Its boundary triangles become the facets, its vertices are all kept, its regions are
//! re-seeded from one tet each, and refinement runs without a size bound.

use super::{mesh_domain, ConstantSpacing, MeshError, Params, Report};
use crate::mesh::TetMesh;
use crate::plc::{Facet, PlcInput, Region};
use glam::DVec3;

/// Removes the slivers (and radius-edge-bad tets) of an existing mesh, keeping its boundary
/// triangles (as facets with their markers) and region attributes.
pub fn remove_slivers(existing: &TetMesh, params: &Params) -> Result<(TetMesh, Report), MeshError> {
    if existing.boundary.is_empty() {
        return Err(MeshError::InvalidInput(
            "the mesh has no boundary triangles: its boundary cannot be kept".into(),
        ));
    }
    let mut input = plc_of_mesh(existing);
    // Flat sides tiled by triangles become polygons again where they can (no vertex inside).
    crate::plc::coplanar::merge_coplanar_facets(&mut input);
    let (lo, hi) = existing.vertices.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(l, h), &p| (l.min(p), h.max(p)),
    );
    // No size bound: a spacing far above the domain's size.
    let unbounded = ConstantSpacing(1e3 * (hi - lo).length().max(1e-300));
    // The angles between boundary triangles are not input features: shape bounds are
    // enforced everywhere (the vertex budget still bounds the work).
    mesh_domain(&input, params, Some(&unbounded), None, false)
}

fn plc_of_mesh(m: &TetMesh) -> PlcInput {
    let facets = m
        .boundary
        .iter()
        .zip(m.boundary_markers.iter().chain(std::iter::repeat(&0)))
        .map(|(t, &marker)| Facet {
            polygons: vec![t.to_vec()],
            marker,
            ..Default::default()
        })
        .collect();
    let mut regions: Vec<Region> = vec![];
    for (t, &attr) in m.tets.iter().zip(m.tet_regions.iter()) {
        if attr != 0 && !regions.iter().any(|r| r.attribute == attr) {
            let c = t.iter().map(|&v| m.vertices[v as usize]).sum::<DVec3>() / 4.0;
            regions.push(Region {
                point: c,
                attribute: attr,
                max_size: None,
            });
        }
    }
    PlcInput {
        vertices: m.vertices.clone(),
        facets,
        holes: vec![],
        regions,
    }
}
