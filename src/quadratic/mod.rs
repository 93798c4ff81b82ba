//! Ten-node tets (`--order 2`): a mid-edge node on every edge of the linear mesh, on the input
//! surface for boundary and interface edges where the surface mode knows the surface
//! ([`BoundaryCurving`]), at the midpoint elsewhere; then every tet checked for validity over
//! its whole volume ([`jacobian`]); a tet that would fold gets its interior nodes moved with
//! its curved boundary, or else its curved edges straightened.
//!
//! Corner vertices never move, so the linear mesh's quality and conformity carry over; the
//! curving only changes where the boundary lies between them.

pub mod jacobian;
#[cfg(test)]
mod tests;

use crate::mesh::{QuadraticNodes, TetMesh, TET_EDGES, TRIANGLE_EDGES};
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

/// A tet is accepted when its Jacobian determinant stays above this fraction of its straight
/// tet's everywhere (by the Bernstein bound): valid with a margin, so that no element is
/// nearly folded, and readers that measure validity their own way (Gmsh's `minSJ`) agree.
const MIN_JACOBIAN_RATIO: f64 = 0.1;

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
    /// Interior nodes moved off their midpoints to follow the curved boundary (where a tet
    /// would fold otherwise).
    pub n_moved_interior_nodes: usize,
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
    let repaired = Folds::new(mesh, &mut nodes, &mut curved).repair();
    let (min_scaled_jacobian, min_jacobian_ratio) = validity(mesh, &nodes);
    let report = QuadraticReport {
        n_edge_nodes: nodes.points.len(),
        n_boundary_edges: boundary_edges.len(),
        n_curved_edges,
        n_straightened_edges: repaired.straightened,
        n_moved_interior_nodes: repaired.moved,
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

/// The state of the fold repair: which nodes are curved, which lie on the boundary, and the
/// tets around each node.
struct Folds<'a> {
    mesh: &'a TetMesh,
    nodes: &'a mut QuadraticNodes,
    curved: &'a mut [bool],
    on_boundary: Vec<bool>,
    /// Tets around node `first + k`: `tets_of[start[k]..start[k + 1]]`.
    start: Vec<usize>,
    tets_of: Vec<u32>,
    first: u32,
}

/// What the fold repair did.
#[derive(Debug, Default, Clone, Copy)]
struct FoldRepair {
    straightened: usize,
    moved: usize,
}

impl<'a> Folds<'a> {
    fn new(mesh: &'a TetMesh, nodes: &'a mut QuadraticNodes, curved: &'a mut [bool]) -> Self {
        let first = mesh.vertices.len() as u32;
        let n = nodes.points.len();
        let mut on_boundary = vec![false; n];
        for e in nodes.boundary_edges.iter().flatten() {
            on_boundary[(e - first) as usize] = true;
        }
        let mut start = vec![0usize; n + 1];
        for e in nodes.tet_edges.iter().flatten() {
            start[(e - first) as usize + 1] += 1;
        }
        for k in 0..n {
            start[k + 1] += start[k];
        }
        let mut fill = start.clone();
        let mut tets_of = vec![0u32; start[n]];
        for (t, edges) in nodes.tet_edges.iter().enumerate() {
            for e in edges {
                let k = (e - first) as usize;
                tets_of[fill[k]] = t as u32;
                fill[k] += 1;
            }
        }
        Folds {
            mesh,
            nodes,
            curved,
            on_boundary,
            start,
            tets_of,
            first,
        }
    }

    fn index(&self, n: u32) -> usize {
        (n - self.first) as usize
    }

    fn is_curved(&self, n: u32) -> bool {
        self.curved[self.index(n)]
    }

    fn tets_around(&self, n: u32) -> &[u32] {
        let k = self.index(n);
        &self.tets_of[self.start[k]..self.start[k + 1]]
    }

    fn valid(&self, t: usize) -> bool {
        tet10(self.mesh, self.nodes, t).jacobian_ratio_bound() >= MIN_JACOBIAN_RATIO
    }

    /// The midpoint of tet `t`'s edge `e` (`TET_EDGES` order).
    fn midpoint(&self, t: usize, e: usize) -> DVec3 {
        let (i, j) = TET_EDGES[e];
        let tet = self.mesh.tets[t];
        (self.mesh.vertices[tet[i] as usize] + self.mesh.vertices[tet[j] as usize]) * 0.5
    }

    /// Makes every tet valid: a folding tet first gets its interior nodes moved with its
    /// curved boundary ([`Self::shift_interior`]); where that fails, its curved nodes are
    /// straightened, the most displaced first, until it is valid. Terminates: a tet with no
    /// curved node is its straight tet, which is valid, each tet is shifted at most once, and
    /// a shift is kept only when every tet it touches is valid.
    fn repair(&mut self) -> FoldRepair {
        let mut done = FoldRepair::default();
        let mut shifted = vec![false; self.mesh.tets.len()];
        let mut queue: Vec<usize> = (0..self.mesh.tets.len())
            .filter(|&t| self.nodes.tet_edges[t].iter().any(|&n| self.is_curved(n)))
            .collect();
        while let Some(t) = queue.pop() {
            if self.valid(t) {
                continue;
            }
            if !shifted[t] {
                shifted[t] = true;
                if let Some(moved) = self.shift_interior(t) {
                    done.moved += moved;
                    continue;
                }
            }
            while !self.valid(t) {
                let Some(e) = (0..6)
                    .filter(|&e| self.is_curved(self.nodes.tet_edges[t][e]))
                    .max_by(|&x, &y| self.displacement(t, x).total_cmp(&self.displacement(t, y)))
                else {
                    // Only moved interior nodes are left off their midpoints: back to the
                    // straight tet, valid by construction.
                    self.straighten_all(t, &mut queue);
                    break;
                };
                let n = self.nodes.tet_edges[t][e];
                let k = self.index(n);
                self.nodes.points[k] = self.midpoint(t, e);
                self.curved[k] = false;
                done.straightened += 1;
                queue.extend(self.tets_around(n).iter().map(|&u| u as usize));
            }
        }
        done
    }

    /// Puts every node of tet `t` at its midpoint; the tets around them are checked again.
    fn straighten_all(&mut self, t: usize, queue: &mut Vec<usize>) {
        for e in 0..6 {
            let n = self.nodes.tet_edges[t][e];
            let k = self.index(n);
            self.nodes.points[k] = self.midpoint(t, e);
            self.curved[k] = false;
            queue.extend(self.tets_around(n).iter().map(|&u| u as usize));
        }
    }

    /// How far tet `t`'s edge `e` node is from the edge's midpoint.
    fn displacement(&self, t: usize, e: usize) -> f64 {
        let n = self.nodes.tet_edges[t][e];
        self.nodes
            .position(self.mesh, n)
            .distance(self.midpoint(t, e))
    }

    /// Moves each interior (non-boundary) node of tet `t` by half the mean displacement of the
    /// tet's curved nodes on edges sharing a corner with it, so that the interior follows the
    /// curved boundary; kept (returning how many nodes moved) only if `t` and every tet around
    /// the moved nodes is then valid.
    fn shift_interior(&mut self, t: usize) -> Option<usize> {
        let edges = self.nodes.tet_edges[t];
        let mut moves: Vec<(u32, DVec3)> = Vec::new();
        for (e, &n) in edges.iter().enumerate() {
            if self.on_boundary[self.index(n)] {
                continue;
            }
            let (i, j) = TET_EDGES[e];
            let (mut sum, mut count) = (DVec3::ZERO, 0.0);
            for (f, &m) in edges.iter().enumerate() {
                let (a, b) = TET_EDGES[f];
                let shares = a == i || a == j || b == i || b == j;
                if shares && self.is_curved(m) {
                    sum += self.nodes.position(self.mesh, m) - self.midpoint(t, f);
                    count += 1.0;
                }
            }
            if count > 0.0 {
                moves.push((n, sum * (0.5 / count)));
            }
        }
        if moves.is_empty() {
            return None;
        }
        let before: Vec<DVec3> = moves
            .iter()
            .map(|&(n, _)| self.nodes.points[self.index(n)])
            .collect();
        for &(n, d) in &moves {
            let k = self.index(n);
            self.nodes.points[k] += d;
        }
        let all_valid = self.valid(t)
            && moves
                .iter()
                .all(|&(n, _)| self.tets_around(n).iter().all(|&u| self.valid(u as usize)));
        if all_valid {
            return Some(moves.len());
        }
        for (&(n, _), p) in moves.iter().zip(before) {
            let k = self.index(n);
            self.nodes.points[k] = p;
        }
        None
    }
}

/// The smallest corner scaled Jacobian over all tets, and the smallest Jacobian ratio bound
/// (1 where every node of a tet is at its edge's midpoint).
fn validity(mesh: &TetMesh, nodes: &QuadraticNodes) -> (f64, f64) {
    let mut min_sj = f64::INFINITY;
    let mut min_ratio: f64 = 1.0;
    for t in 0..mesh.tets.len() {
        let tet = tet10(mesh, nodes, t);
        min_sj = min_sj.min(tet.min_corner_scaled_jacobian());
        let straight = Tet10::straight(tet.corners);
        if tet.mids != straight.mids {
            min_ratio = min_ratio.min(tet.jacobian_ratio_bound());
        }
    }
    if mesh.tets.is_empty() {
        min_sj = 0.0;
    }
    (min_sj, min_ratio)
}
