//! Where the mid-edge nodes of ten-node tets go on the input surface: a feature edge's onto
//! its feature curve, a patch edge's onto its patch (`crate::quadratic::BoundaryCurving`).

use super::curves::FeatureCurves;
use super::Slide;
use crate::surface::oracle::SurfaceOracle;
use glam::DVec3;
use rustc_hash::FxHashSet;

pub(super) struct OnInputSurface<'a> {
    pub oracle: &'a SurfaceOracle,
    pub patch_of: &'a [u32],
    pub curves: &'a FeatureCurves,
    pub vertex_slide: &'a [Slide],
    /// Vertices on a span across a hole (`--repair`): no surface to curve onto there.
    pub on_span: &'a [bool],
    /// The output boundary's feature edges, as (smaller, larger) vertex pairs.
    pub feature_edges: FxHashSet<(u32, u32)>,
}

impl OnInputSurface<'_> {
    fn slide(&self, v: u32) -> Slide {
        self.vertex_slide
            .get(v as usize)
            .copied()
            .unwrap_or(Slide::Fixed)
    }

    /// The nearest point of the feature curve the edge `(a, b)` follows: the curve an end
    /// slides on, else (an edge between two corners) the nearest of all curves.
    fn onto_curve(&self, a: u32, b: u32, mid: DVec3) -> Option<DVec3> {
        let on_curve = [self.slide(a), self.slide(b)]
            .into_iter()
            .find_map(|s| match s {
                Slide::Curve(c) => Some(c),
                _ => None,
            });
        match on_curve {
            Some(c) => self.curves.curves[c as usize].closest(mid).map(|(p, _)| p),
            None => self
                .curves
                .curves
                .iter()
                .filter_map(|c| c.closest(mid).map(|(p, _)| p))
                .min_by(|p, q| p.distance_squared(mid).total_cmp(&q.distance_squared(mid))),
        }
    }

    /// The nearest point of the input surface, if it is on the patch an end of the edge
    /// slides on (near a crease the nearest point can be on the other patch).
    fn onto_patch(&self, a: u32, b: u32, mid: DVec3) -> Option<DVec3> {
        let closest = self.oracle.closest(mid)?;
        let patch = self.patch_of[closest.triangle as usize];
        let wanted = [self.slide(a), self.slide(b)]
            .into_iter()
            .find_map(|s| match s {
                Slide::Patch(p) => Some(p),
                _ => None,
            });
        match wanted {
            Some(p) if p != patch => None,
            _ => Some(closest.point),
        }
    }
}

impl crate::quadratic::BoundaryCurving for OnInputSurface<'_> {
    fn curve(&self, a: u32, b: u32, mid: DVec3, triangles: &[u32]) -> Option<DVec3> {
        let spans = |v: u32| self.on_span.get(v as usize).copied().unwrap_or(false);
        if spans(a) || spans(b) {
            return None;
        }
        let feature = triangles.len() != 2 || self.feature_edges.contains(&(a.min(b), a.max(b)));
        if feature {
            self.onto_curve(a, b, mid)
        } else {
            self.onto_patch(a, b, mid)
        }
    }
}
