//! Inside and outside of a dirty surface by its generalized winding number w: a point is in
//! the solid where w >= 1/2.
//!
//! w is never summed over all triangles per query. The input triangles and the holes' fans
//! (`holes`) together are closed as an oriented cycle, so their winding count N is an integer,
//! carried exactly from point to point by the signed crossings of the segment between them
//! (`SurfaceOracle::counting`); then w = N - w_F, w_F the fans' own winding number, evaluated
//! through a tree (exact near a fan, a dipole far from it, zero without holes). w is
//! continuous across a fan and jumps by one across an input triangle, so along a segment the
//! solid's boundary lies at input triangles where the label changes, and, near the fans only,
//! where w passes 1/2 between them (a hole spanned: found by bisection).

use super::super::oracle::{Crossing, SurfaceOracle};
use super::super::winding::WindingNumber;
use super::holes::Hole;
use glam::DVec3;

/// A fan farther than this many of its radii from a segment cannot move w by a quarter along
/// it (the solid angle of a ball of radius r seen from distance d is at most
/// 2 pi (1 - sqrt(1 - (r/d)^2)): at 2.5 radii, 0.083 of the sphere).
const FAR_RADII: f64 = 2.5;

/// Bisection steps placing a spanning boundary point (relative precision 2^-40 of the segment).
const BISECTIONS: usize = 40;

/// Where a segment passes the solid's boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoundaryPoint {
    pub point: DVec3,
    /// Parameter along the segment.
    pub t: f64,
    /// The input triangle it lies on (ids of the counting surface), None where it spans a hole.
    pub triangle: Option<u32>,
}

/// The labelling of space by a repaired surface.
pub struct SolidLabels {
    /// Over the input triangles, then the fans' (ids from `n_input`).
    pub segments: SurfaceOracle,
    fans: WindingNumber,
    holes: Vec<Hole>,
    n_input: u32,
}

impl SolidLabels {
    pub(super) fn new(
        segments: SurfaceOracle,
        fans: WindingNumber,
        holes: Vec<Hole>,
        n_input: usize,
    ) -> Self {
        SolidLabels {
            segments,
            fans,
            holes,
            n_input: n_input as u32,
        }
    }

    /// The winding count of the closed input-and-fans surface at `p` (from a ray).
    pub fn count(&self, p: DVec3) -> i32 {
        self.segments.region(p) as i32
    }

    /// The generalized winding number of the input at `p`, given the count there.
    pub fn winding(&self, count: i32, p: DVec3) -> f64 {
        let fans = if self.holes.is_empty() {
            0.0
        } else {
            self.fans.at(p)
        };
        f64::from(count) - fans
    }

    /// Whether `p`, where the count is `count`, lies in the solid.
    pub fn inside(&self, count: i32, p: DVec3) -> bool {
        if self.holes.is_empty() {
            return count >= 1;
        }
        self.winding(count, p) >= 0.5
    }

    /// Whether `p` lies where the solid's boundary spans a hole: w is neither near 0 nor near
    /// 1 there (off the input, w is within a quarter of an integer except near a hole).
    pub fn spans_at(&self, p: DVec3) -> bool {
        if self.holes.is_empty() || self.clear_of_fans(p, 0.0) {
            return false;
        }
        let w = self.winding(self.count(p), p);
        (w - w.round()).abs() > 0.25
    }

    /// Whether some fan lies near enough to the segment [p, q] for w to pass 1/2 between two
    /// input triangles along it.
    pub fn near_fans(&self, p: DVec3, q: DVec3) -> bool {
        self.holes
            .iter()
            .any(|h| segment_distance(h.centre, p, q) <= FAR_RADII * h.radius)
    }

    /// Whether no triangle and no fan's influence comes within `r` of `p`: then every point
    /// of that ball has one label.
    pub fn clear_within(&self, p: DVec3, r: f64) -> bool {
        self.clear_of_fans(p, r) && self.segments.clear_within(p, r)
    }

    /// Whether every fan is too far from the ball of radius `r` about `p` to move w by a
    /// quarter in it.
    pub fn clear_of_fans(&self, p: DVec3, r: f64) -> bool {
        self.holes
            .iter()
            .all(|h| (h.centre - p).length() - r > FAR_RADII * h.radius)
    }

    /// The holes spanned.
    pub fn n_holes(&self) -> usize {
        self.holes.len()
    }

    /// Whether `t` (an id of `segments`) is an input triangle, not a fan's.
    pub fn is_input(&self, t: u32) -> bool {
        t < self.n_input
    }

    /// Where [p, q] passes the solid's boundary, given the count at p and `crossings` (from
    /// `segments.crossings(p, q)`); None when a crossing is not proper (the caller decides
    /// otherwise).
    pub fn boundary_points(
        &self,
        p: DVec3,
        q: DVec3,
        crossings: &[Crossing],
        count_p: i32,
    ) -> Option<Vec<BoundaryPoint>> {
        if crossings.iter().any(|x| !x.proper) {
            return None;
        }
        let mut out = Vec::new();
        if !self.near_fans(p, q) {
            // Far from every fan, w is the count to within a quarter: labels change only at
            // input triangles.
            let mut n = count_p;
            for x in crossings {
                let before = n >= 1;
                n += i32::from(x.delta);
                if (n >= 1) != before {
                    out.push(BoundaryPoint {
                        point: x.point,
                        t: x.t,
                        triangle: Some(x.triangle),
                    });
                }
            }
            return Some(out);
        }
        // Pieces between input crossings: w is continuous along each (a fan's crossing moves
        // the count and the fans' w together).
        let mut piece_start = (0.0, count_p);
        let mut n = count_p;
        let mut label = self.inside(n, p);
        for (k, x) in crossings.iter().enumerate() {
            if !self.is_input(x.triangle) {
                n += i32::from(x.delta);
                continue;
            }
            let before = self.inside(n, x.point);
            if before != label {
                out.push(self.bisect(p, q, piece_start, x.t, label, &crossings[..k]));
            }
            n += i32::from(x.delta);
            let after = self.inside(n, x.point);
            if after != before {
                out.push(BoundaryPoint {
                    point: x.point,
                    t: x.t,
                    triangle: Some(x.triangle),
                });
            }
            label = after;
            piece_start = (x.t, n);
        }
        if self.inside(n, q) != label {
            out.push(self.bisect(p, q, piece_start, 1.0, label, crossings));
        }
        Some(out)
    }

    /// The point of [p, q] between parameters `start.0` (count `start.1`, label `label`) and
    /// `end` where the label changes, by bisection; `crossings` (sorted, the fans' ones within
    /// the piece move the count) up to the piece's end.
    fn bisect(
        &self,
        p: DVec3,
        q: DVec3,
        start: (f64, i32),
        end: f64,
        label: bool,
        crossings: &[Crossing],
    ) -> BoundaryPoint {
        let count_at = |t: f64| {
            start.1
                + crossings
                    .iter()
                    .filter(|x| x.t > start.0 && x.t < t)
                    .map(|x| i32::from(x.delta))
                    .sum::<i32>()
        };
        let (mut lo, mut hi) = (start.0, end);
        for _ in 0..BISECTIONS {
            let mid = (lo + hi) / 2.0;
            if self.inside(count_at(mid), p + (q - p) * mid) == label {
                lo = mid;
            } else {
                hi = mid;
            }
        }
        let t = (lo + hi) / 2.0;
        BoundaryPoint {
            point: p + (q - p) * t,
            t,
            triangle: None,
        }
    }
}

/// Distance from `c` to the segment [p, q].
fn segment_distance(c: DVec3, p: DVec3, q: DVec3) -> f64 {
    let d = q - p;
    let len2 = d.length_squared();
    let t = if len2 > 0.0 {
        ((c - p).dot(d) / len2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (p + d * t - c).length()
}
