//! The output model every writer consumes and every mesher produces.

use glam::DVec3;

/// A tetrahedral mesh as an FEM code wants it.
///
/// Vertex ids are 0-based indices into `vertices`; input vertices come first, in input order.
/// Tets are positively oriented (`geom::orient3d > 0`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TetMesh {
    pub vertices: Vec<DVec3>,
    pub tets: Vec<[u32; 4]>,
    /// Region attribute of each tet (0 when the input declares no regions).
    pub tet_regions: Vec<i32>,
    /// Boundary triangles (input facets, subdivided), oriented with the normal pointing out of
    /// the region on the side of the tet that owns them (for internal facets: either side).
    pub boundary: Vec<[u32; 3]>,
    /// Input facet marker of each boundary triangle.
    pub boundary_markers: Vec<i32>,
}

impl TetMesh {
    /// How many tets hold each face (by sorted vertex triple): 1 on the mesh's surface, 2
    /// inside, more where the mesh does not conform.
    pub fn face_counts(&self) -> rustc_hash::FxHashMap<[u32; 3], u32> {
        let mut faces = rustc_hash::FxHashMap::default();
        faces.reserve(2 * self.tets.len());
        for t in &self.tets {
            for skip in 0..4 {
                let mut f = tet_face(t, skip);
                f.sort_unstable();
                *faces.entry(f).or_insert(0) += 1;
            }
        }
        faces
    }

    /// Removes the boundary triangles with marker `marker` (a run's working marks).
    pub fn remove_boundary_marker(&mut self, marker: i32) {
        let mut kept = self.boundary_markers.iter().map(|&m| m != marker);
        self.boundary.retain(|_| kept.next().unwrap_or(true));
        self.boundary_markers.retain(|&m| m != marker);
    }
}

/// The face of tet `t` opposite its vertex `skip` (the other three in order).
pub fn tet_face(t: &[u32; 4], skip: usize) -> [u32; 3] {
    let mut f = [0; 3];
    let mut k = 0;
    for (i, &v) in t.iter().enumerate() {
        if i != skip {
            f[k] = v;
            k += 1;
        }
    }
    f
}

/// The mid-edge nodes that make a [`TetMesh`] a mesh of ten-node (quadratic) tets.
///
/// Node ids continue after the corner vertices: mid-edge node `k` is node
/// `mesh.vertices.len() + k`. Each edge has one node, shared by every tet and boundary
/// triangle around it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QuadraticNodes {
    /// Position of each mid-edge node (on the input surface for curved boundary edges).
    pub points: Vec<DVec3>,
    /// Per tet `[a, b, c, d]`, the node ids of its edges in the order
    /// `ab, bc, ac, ad, bd, cd` (VTK's `VTK_QUADRATIC_TETRA` and Abaqus C3D10 order).
    pub tet_edges: Vec<[u32; 6]>,
    /// Per boundary triangle `[a, b, c]`, the node ids of its edges `ab, bc, ca`.
    pub boundary_edges: Vec<[u32; 3]>,
}

/// The corner pairs of a tet's six edges, in [`QuadraticNodes::tet_edges`] order.
pub const TET_EDGES: [(usize, usize); 6] = [(0, 1), (1, 2), (0, 2), (0, 3), (1, 3), (2, 3)];

/// The corner pairs of a triangle's three edges, in [`QuadraticNodes::boundary_edges`] order.
pub const TRIANGLE_EDGES: [(usize, usize); 3] = [(0, 1), (1, 2), (2, 0)];

impl QuadraticNodes {
    /// One node at the midpoint of every edge of `mesh`'s tets and boundary triangles: the
    /// straight-sided ten-node mesh. Nodes are numbered in the order their edges first appear
    /// (tets first, in tet order), so the numbering depends only on the mesh.
    pub fn straight(mesh: &TetMesh) -> QuadraticNodes {
        let mut ids: rustc_hash::FxHashMap<(u32, u32), u32> = Default::default();
        let first = mesh.vertices.len() as u32;
        let mut points = Vec::new();
        let mut node = |a: u32, b: u32| -> u32 {
            let key = (a.min(b), a.max(b));
            *ids.entry(key).or_insert_with(|| {
                points.push((mesh.vertices[a as usize] + mesh.vertices[b as usize]) * 0.5);
                first + points.len() as u32 - 1
            })
        };
        let tet_edges = mesh
            .tets
            .iter()
            .map(|t| TET_EDGES.map(|(i, j)| node(t[i], t[j])))
            .collect();
        let boundary_edges = mesh
            .boundary
            .iter()
            .map(|t| TRIANGLE_EDGES.map(|(i, j)| node(t[i], t[j])))
            .collect();
        QuadraticNodes {
            points,
            tet_edges,
            boundary_edges,
        }
    }

    /// The position of node `id` (a corner vertex or a mid-edge node).
    pub fn position(&self, mesh: &TetMesh, id: u32) -> DVec3 {
        let first = mesh.vertices.len();
        match (id as usize).checked_sub(first) {
            Some(k) => self.points[k],
            None => mesh.vertices[id as usize],
        }
    }

    /// Node count of the ten-node mesh: corners plus mid-edge nodes.
    pub fn n_nodes(&self, mesh: &TetMesh) -> usize {
        mesh.vertices.len() + self.points.len()
    }
}
