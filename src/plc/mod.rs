//! Piecewise linear complex: the domain description and its validation.

use glam::DVec3;

/// One planar polygonal facet, possibly with polygonal holes inside it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Facet {
    /// Outer polygon(s): 0-based vertex ids in order around the polygon. TetGen facets may carry
    /// several polygons (e.g. a polygon and dangling segments); most have exactly one.
    pub polygons: Vec<Vec<u32>>,
    /// Points inside the facet's plane marking holes in the facet (TetGen style), if any.
    pub hole_points: Vec<DVec3>,
    /// Hole polygons given explicitly (C ABI `sm_add_facet_hole`).
    pub hole_polygons: Vec<Vec<u32>>,
    /// Boundary marker copied to every output boundary triangle of this facet.
    pub marker: i32,
}

/// A region seed: every tet in the connected component holding `point` gets `attribute`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub point: DVec3,
    pub attribute: i32,
    /// Maximum tet size (edge-length scale) in this region; `None` or non-positive = no limit.
    pub max_size: Option<f64>,
}

/// The unvalidated domain description, as read from a file or built through the API.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlcInput {
    pub vertices: Vec<DVec3>,
    pub facets: Vec<Facet>,
    /// Volume hole seeds: the connected component holding each point is removed.
    pub holes: Vec<DVec3>,
    pub regions: Vec<Region>,
}
