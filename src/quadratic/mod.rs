//! Ten-node tets (`--order 2`): a mid-edge node on every edge of the linear mesh, on the input
//! surface for boundary and interface edges where the surface mode knows the surface
//! ([`BoundaryCurving`]), at the midpoint elsewhere; then every tet checked for validity over
//! its whole volume ([`jacobian`]) and the curved edges of the few that fold straightened.
//!
//! Corner vertices never move, so the linear mesh's quality and conformity carry over; the
//! curving only changes where the boundary lies between them.

pub mod jacobian;
#[cfg(test)]
mod tests;

use crate::mesh::{QuadraticNodes, TetMesh, TRIANGLE_EDGES};
use glam::DVec3;
use jacobian::Tet10;
use serde::Serialize;

/// Where a boundary edge's mid-edge node goes: implemented by a surface mode that knows the
/// input surface (the approximate mode projects onto its patches and feature curves).
pub trait BoundaryCurving {
    /// The point of the input surface for the node of boundary edge `(a, b)` whose midpoint is
    /// `mid`; `triangles` are the boundary triangles (indices into `TetMesh::boundary`) around
    /// the edge. `None` keeps the midpoint.
    fn curve(&self, a: u32, b: u32, mid: DVec3, triangles: &[u32]) -> Option<DVec3>;
}

/// A node is moved onto the surface only this close to its edge's midpoint, as a fraction of
/// the edge's length: a projection farther than that went to another part of the surface
/// (a thin part's other side) rather than to the surface between the edge's ends.
const MAX_CURVING: f64 = 0.25;

/// What the elevation to ten-node tets did, for the run's report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct QuadraticReport {
    /// Mid-edge nodes in all (corner vertices not counted).
    pub n_edge_nodes: usize,
    /// Boundary (and interface) edges.
    pub n_boundary_edges: usize,
    /// Boundary edges whose node lies on the input surface off the midpoint.
    pub n_curved_edges: usize,
    /// Curved edges put back at the midpoint because a tet around them would fold.
    pub n_straightened_edges: usize,
    /// The smallest scaled Jacobian at a tet corner (1 for a regular tet; Gmsh's `minSJ` for
    /// straight tets).
    pub min_scaled_jacobian: f64,
    /// A lower bound over every element of its Jacobian determinant relative to its straight
    /// tet's; above zero, no element folds anywhere.
    pub min_jacobian_ratio: f64,
}

/// The ten-node mesh on `mesh`: boundary nodes placed by `curving` (None: every node at its
/// midpoint, as in keep mode, where the facets are planar), then curved edges straightened
/// until every element is valid everywhere.
pub fn elevate(
    mesh: &TetMesh,
    curving: Option<&dyn BoundaryCurving>,
) -> (QuadraticNodes, QuadraticReport) {
    let mut nodes = QuadraticNodes::straight(mesh);
    let first = mesh.vertices.len() as u32;
    let boundary_edges = boundary_edge_triangles(mesh, &nodes);
    let mut curved = vec![false; nodes.points.len()];
    let mut n_curved_edges = 0;
    if let Some(curving) = curving {
        for (node, a, b, triangles) in &boundary_edges {
            let (pa, pb) = (mesh.vertices[*a as usize], mesh.vertices[*b as usize]);
            let mid = (pa + pb) * 0.5;
            let Some(p) = curving.curve(*a, *b, mid, triangles) else {
                continue;
            };
            if p != mid && p.distance(mid) <= MAX_CURVING * pa.distance(pb) {
                nodes.points[(node - first) as usize] = p;
                curved[(node - first) as usize] = true;
                n_curved_edges += 1;
            }
        }
    }
    let n_straightened_edges = straighten_folds(mesh, &mut nodes, &mut curved);
    let (min_scaled_jacobian, min_jacobian_ratio) = validity(mesh, &nodes, &curved);
    let report = QuadraticReport {
        n_edge_nodes: nodes.points.len(),
        n_boundary_edges: boundary_edges.len(),
        n_curved_edges,
        n_straightened_edges,
        min_scaled_jacobian,
        min_jacobian_ratio,
    };
    (nodes, report)
}

/// Each boundary edge once: its node, its two corners, and the boundary triangles around it.
fn boundary_edge_triangles(
    mesh: &TetMesh,
    nodes: &QuadraticNodes,
) -> Vec<(u32, u32, u32, Vec<u32>)> {
    let mut around: Vec<(u32, u32, u32, u32)> = Vec::with_capacity(3 * mesh.boundary.len());
    for (t, (tri, edges)) in mesh.boundary.iter().zip(&nodes.boundary_edges).enumerate() {
        for (k, &(i, j)) in TRIANGLE_EDGES.iter().enumerate() {
            let (a, b) = (tri[i].min(tri[j]), tri[i].max(tri[j]));
            around.push((edges[k], a, b, t as u32));
        }
    }
    around.sort_unstable();
    let mut out: Vec<(u32, u32, u32, Vec<u32>)> = Vec::new();
    for (node, a, b, t) in around {
        match out.last_mut() {
            Some(last) if last.0 == node => last.3.push(t),
            _ => out.push((node, a, b, vec![t])),
        }
    }
    out
}

/// The ten-node tet `t` of the mesh.
fn tet10(mesh: &TetMesh, nodes: &QuadraticNodes, t: usize) -> Tet10 {
    Tet10 {
        corners: mesh.tets[t].map(|v| mesh.vertices[v as usize]),
        mids: nodes.tet_edges[t].map(|n| nodes.position(mesh, n)),
    }
}

/// Puts the curved nodes of every tet that may fold (its Jacobian bound at or below zero)
/// back at their midpoints, until none may. Terminates: each pass straightens at least one
/// node, and a tet with no curved node is its straight tet, which is valid. Returns how many
/// nodes were straightened.
fn straighten_folds(mesh: &TetMesh, nodes: &mut QuadraticNodes, curved: &mut [bool]) -> usize {
    let first = mesh.vertices.len() as u32;
    let is_curved = |curved: &[bool], n: u32| n >= first && curved[(n - first) as usize];
    let mut suspects: Vec<usize> = (0..mesh.tets.len())
        .filter(|&t| nodes.tet_edges[t].iter().any(|&n| is_curved(curved, n)))
        .collect();
    let mut straightened = 0;
    while !suspects.is_empty() {
        let folding: Vec<usize> = suspects
            .iter()
            .copied()
            .filter(|&t| tet10(mesh, nodes, t).jacobian_ratio_bound() <= 0.0)
            .collect();
        if folding.is_empty() {
            break;
        }
        for &t in &folding {
            let [a, b, c, d] = mesh.tets[t];
            let corners = [a, b, c, d];
            for (e, &n) in nodes.tet_edges[t].iter().enumerate() {
                if is_curved(curved, n) {
                    let (i, j) = crate::mesh::TET_EDGES[e];
                    nodes.points[(n - first) as usize] = (mesh.vertices[corners[i] as usize]
                        + mesh.vertices[corners[j] as usize])
                        * 0.5;
                    curved[(n - first) as usize] = false;
                    straightened += 1;
                }
            }
        }
        suspects.retain(|&t| nodes.tet_edges[t].iter().any(|&n| is_curved(curved, n)));
    }
    straightened
}

/// The smallest corner scaled Jacobian over all tets, and the smallest Jacobian ratio bound
/// (1 where a tet has no curved node).
fn validity(mesh: &TetMesh, nodes: &QuadraticNodes, curved: &[bool]) -> (f64, f64) {
    let first = mesh.vertices.len() as u32;
    let mut min_sj = f64::INFINITY;
    let mut min_ratio: f64 = 1.0;
    for t in 0..mesh.tets.len() {
        let tet = tet10(mesh, nodes, t);
        min_sj = min_sj.min(tet.min_corner_scaled_jacobian());
        if nodes.tet_edges[t]
            .iter()
            .any(|&n| n >= first && curved[(n - first) as usize])
        {
            min_ratio = min_ratio.min(tet.jacobian_ratio_bound());
        }
    }
    if mesh.tets.is_empty() {
        min_sj = 0.0;
    }
    (min_sj, min_ratio)
}
