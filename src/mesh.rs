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
