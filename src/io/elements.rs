//! The nodes and elements a mesh writer writes: the corners of four-node tets and three-node
//! boundary triangles, or, with [`QuadraticNodes`], corners and mid-edge nodes of ten-node tets
//! and six-node triangles. Every writer goes through [`Elements`], so the linear and the
//! quadratic forms of a format share one code path and differ only in the element type names
//! and the node order of each format (the `*_ORDER` permutations below).

use crate::mesh::{QuadraticNodes, TetMesh};
use glam::DVec3;

/// The nodes and element connectivity of a mesh of four-node or ten-node tets.
#[derive(Clone, Copy)]
pub(crate) struct Elements<'a> {
    pub mesh: &'a TetMesh,
    pub quadratic: Option<&'a QuadraticNodes>,
}

impl<'a> Elements<'a> {
    pub fn new(mesh: &'a TetMesh, quadratic: Option<&'a QuadraticNodes>) -> Self {
        Elements { mesh, quadratic }
    }

    /// Whether the tets have ten nodes.
    pub fn is_quadratic(&self) -> bool {
        self.quadratic.is_some()
    }

    /// Nodes per tet: 4 or 10.
    pub fn tet_nodes(&self) -> usize {
        if self.is_quadratic() {
            10
        } else {
            4
        }
    }

    /// Nodes per boundary triangle: 3 or 6.
    pub fn triangle_nodes(&self) -> usize {
        if self.is_quadratic() {
            6
        } else {
            3
        }
    }

    /// Number of nodes: the corners, then the mid-edge nodes.
    pub fn n_nodes(&self) -> usize {
        self.mesh.vertices.len() + self.quadratic.map_or(0, |q| q.points.len())
    }

    /// All node positions, node id order (corners first).
    pub fn nodes(&self) -> impl Iterator<Item = DVec3> + 'a {
        let extra: &'a [DVec3] = self.quadratic.map_or(&[], |q| &q.points);
        self.mesh.vertices.iter().chain(extra).copied()
    }

    /// The position of node `id`.
    pub fn position(&self, id: u32) -> DVec3 {
        match self.quadratic {
            Some(q) => q.position(self.mesh, id),
            None => self.mesh.vertices[id as usize],
        }
    }

    /// Node ids of tet `i` in the mesh's order (corners a, b, c, d, then the edges ab, bc, ac,
    /// ad, bd, cd: VTK's and Abaqus's order); the first [`Self::tet_nodes`] entries are valid.
    pub fn tet(&self, i: usize) -> [u32; 10] {
        let mut out = [0; 10];
        out[..4].copy_from_slice(&self.mesh.tets[i]);
        if let Some(q) = self.quadratic {
            out[4..].copy_from_slice(&q.tet_edges[i]);
        }
        out
    }

    /// Node ids of tet `i` permuted by `order` (a format's node order as indices into
    /// [`Self::tet`]), `tet_nodes()` of them.
    pub fn tet_in(&self, i: usize, order: &'static [usize; 10]) -> impl Iterator<Item = u32> {
        let t = self.tet(i);
        let n = self.tet_nodes();
        order.iter().take(n).map(move |&k| t[k])
    }

    /// Node ids of boundary triangle `j`: corners a, b, c, then the edges ab, bc, ca.
    pub fn triangle(&self, j: usize) -> [u32; 6] {
        let mut out = [0; 6];
        out[..3].copy_from_slice(&self.mesh.boundary[j]);
        if let Some(q) = self.quadratic {
            out[3..].copy_from_slice(&q.boundary_edges[j]);
        }
        out
    }

    /// Node ids of boundary triangle `j` permuted by `order`, `triangle_nodes()` of them.
    pub fn triangle_in(&self, j: usize, order: &'static [usize; 6]) -> impl Iterator<Item = u32> {
        let t = self.triangle(j);
        let n = self.triangle_nodes();
        order.iter().take(n).map(move |&k| t[k])
    }
}

/// The mesh's own order: VTK (`VTK_QUADRATIC_TETRA`), Abaqus C3D10, MEDIT `TetrahedraP2`.
pub(crate) const TET_ORDER: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 8, 9];

/// The mesh's own triangle order: gmsh (type 9), MEDIT `TrianglesP2`.
pub(crate) const TRIANGLE_ORDER: [usize; 6] = [0, 1, 2, 3, 4, 5];

/// Gmsh's 10-node tet (type 11): corners, then edges 01, 12, 20, 30, 32, 31 (the gmsh manual's
/// node ordering figure; the last two are ours swapped).
pub(crate) const GMSH_TET_ORDER: [usize; 10] = [0, 1, 2, 3, 4, 5, 6, 7, 9, 8];

/// TetGen `-o2`: corners, then edges 23, 03, 01, 12, 13, 02. From tetgen.cxx (1.5 and 1.6.1):
/// `outelements()` writes the corners `tet[4..8]`, then `extralist[0..6]`, where `highorder()`
/// puts the node of edge `i` at `edge2ver[i] = {0, 1, 2, 3, 8, 5}`, whose (org, dest) in
/// `orgpivot`/`destpivot` (less the offset 4) are (3,2), (3,0), (1,0), (1,2), (1,3), (0,2).
/// Checked against `tetgen -o2` 1.5.0 (Debian) on a unit tet.
pub(crate) const TETGEN_TET_ORDER: [usize; 10] = [0, 1, 2, 3, 9, 7, 4, 5, 8, 6];

/// TetGen `-o2` `.face`: corners a, b, c, then the edges opposite them: bc, ca, ab
/// (`outfaces()`: `extralist[ver2edge[...]]` from `enext(face)` on).
pub(crate) const TETGEN_TRIANGLE_ORDER: [usize; 6] = [0, 1, 2, 4, 5, 3];

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::{TET_EDGES, TRIANGLE_EDGES};

    /// The corner pairs of the nodes of a format's order, for the tables above.
    fn pairs(order: &[usize]) -> Vec<(usize, usize)> {
        order[4..]
            .iter()
            .map(|&k| {
                let (i, j) = TET_EDGES[k - 4];
                (i.min(j), i.max(j))
            })
            .collect()
    }

    #[test]
    fn format_orders_name_the_documented_edges() {
        assert_eq!(
            pairs(&GMSH_TET_ORDER),
            [(0, 1), (1, 2), (0, 2), (0, 3), (2, 3), (1, 3)]
        );
        assert_eq!(
            pairs(&TETGEN_TET_ORDER),
            [(2, 3), (0, 3), (0, 1), (1, 2), (1, 3), (0, 2)]
        );
        let tri: Vec<(usize, usize)> = TETGEN_TRIANGLE_ORDER[3..]
            .iter()
            .map(|&k| TRIANGLE_EDGES[k - 3])
            .collect();
        assert_eq!(tri, [(1, 2), (2, 0), (0, 1)]);
    }
}
