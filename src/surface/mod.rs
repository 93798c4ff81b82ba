//! The input surface as a description of a piecewise smooth boundary (groundwork of the
//! `approximate` surface mode): the triangles of a checked [`Plc`], their sharp features, and a
//! geometric oracle over them.
//!
//! - [`InputSurface`]: every facet triangle of the checked PLC with its facet and marker.
//! - [`features`]: sharp edges (normals differ by more than a feature angle, labels change,
//!   non-manifold edges) joined into polylines between corners; smooth patches.
//! - [`oracle`]: an AABB tree over the triangles: closest point, segment crossings (the exact
//!   segment/triangle test decides, floating point only places the crossing), inside test by
//!   ray parity with exact predicates.
//! - [`thickness`]: the radius of the largest empty ball touching the surface at each vertex,
//!   inside or outside (half the local thickness, or half the gap to another part).
//! - [`distance`]: two-sided Hausdorff distance between two triangle surfaces, by dense
//!   sampling.

pub mod distance;
pub mod features;
pub mod oracle;
pub mod repair;
#[cfg(test)]
mod test_shapes;
#[cfg(test)]
mod tests;
pub mod thickness;
pub mod winding;

use crate::plc::Plc;
use glam::DVec3;

/// The facet triangles of a checked PLC, in facet order.
#[derive(Debug, Clone, PartialEq)]
pub struct InputSurface {
    pub vertices: Vec<DVec3>,
    /// Counter-clockwise seen from the tip of their facet's normal.
    pub triangles: Vec<[u32; 3]>,
    /// Index of the facet each triangle belongs to.
    pub facet_of: Vec<u32>,
    /// Marker of that facet.
    pub marker_of: Vec<i32>,
    /// The region on each side of each triangle (normal side first): 0 outside the domain
    /// (the exterior and holes), else the [`Plc::domain_cells`] index + 1. A triangle between
    /// two regions is an interface.
    pub sides: Vec<[u32; 2]>,
}

impl InputSurface {
    /// Every triangle of every facet of `plc`.
    pub fn from_plc(plc: &Plc) -> InputSurface {
        let mut s = InputSurface {
            vertices: plc.vertices.clone(),
            triangles: Vec::new(),
            facet_of: Vec::new(),
            marker_of: Vec::new(),
            sides: Vec::new(),
        };
        let region_of_cell = plc.region_of_cell();
        for (k, f) in plc.facets.iter().enumerate() {
            for (i, &t) in f.triangles.iter().enumerate() {
                s.triangles.push(t);
                s.facet_of.push(k as u32);
                s.marker_of.push(f.marker);
                let cells = f.triangle_cells.get(i).copied().unwrap_or([0, 0]);
                s.sides.push(cells.map(|c| region_of_cell[c as usize]));
            }
        }
        s
    }

    /// A surface from raw triangles (one facet per triangle, marker 0) bounding one region:
    /// each triangle has region 1 on one side and the outside on the other.
    pub fn from_triangles(vertices: Vec<DVec3>, triangles: Vec<[u32; 3]>) -> InputSurface {
        let n = triangles.len();
        InputSurface {
            vertices,
            triangles,
            facet_of: (0..n as u32).collect(),
            marker_of: vec![0; n],
            sides: vec![[1, 0]; n],
        }
    }

    /// Number of regions (the largest label in `sides`).
    pub fn n_regions(&self) -> u32 {
        self.sides.iter().flatten().copied().max().unwrap_or(0)
    }

    /// The corner points of triangle `t`.
    pub fn corners(&self, t: usize) -> [DVec3; 3] {
        self.triangles[t].map(|v| self.vertices[v as usize])
    }

    /// Unit normal of triangle `t` (zero for a degenerate triangle).
    pub fn normal(&self, t: usize) -> DVec3 {
        let [a, b, c] = self.corners(t);
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// Total area.
    pub fn area(&self) -> f64 {
        (0..self.triangles.len())
            .map(|t| {
                let [a, b, c] = self.corners(t);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Length of the diagonal of the bounding box of the vertices used by triangles.
    pub fn bbox_diagonal(&self) -> f64 {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        // Plain comparisons (one instruction each; the coordinates are finite): this runs
        // over every corner several times per run.
        for &v in self.triangles.as_flattened() {
            let p = self.vertices[v as usize].to_array();
            for k in 0..3 {
                lo[k] = if p[k] < lo[k] { p[k] } else { lo[k] };
                hi[k] = if p[k] > hi[k] { p[k] } else { hi[k] };
            }
        }
        if lo[0] > hi[0] {
            0.0
        } else {
            (DVec3::from_array(hi) - DVec3::from_array(lo)).length()
        }
    }
}

/// The corners of a triangle turned (cyclically, keeping its orientation) so that the first
/// edge is the longest.
pub(crate) fn longest_edge_first([a, b, c]: [DVec3; 3]) -> [DVec3; 3] {
    let (ab, bc, ca) = ((b - a).length(), (c - b).length(), (a - c).length());
    if ab >= bc && ab >= ca {
        [a, b, c]
    } else if bc >= ca {
        [b, c, a]
    } else {
        [c, a, b]
    }
}
