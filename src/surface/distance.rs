//! Two-sided Hausdorff distance between triangle surfaces, by dense sampling: every triangle
//! is sampled on a barycentric grid fine enough that no point of it is farther than `spacing`
//! from a sample, and each sample's distance to the other surface is exact up to rounding
//! (closest point through the AABB tree). The result therefore underestimates the true
//! distance by at most `spacing`.

use super::oracle::SurfaceOracle;
use super::InputSurface;
use glam::DVec3;

/// The two one-sided distances, each with the sample point that attains it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Hausdorff {
    /// max over samples of `a` of the distance to `b`.
    pub a_to_b: f64,
    pub worst_on_a: DVec3,
    /// max over samples of `b` of the distance to `a`.
    pub b_to_a: f64,
    pub worst_on_b: DVec3,
}

impl Hausdorff {
    /// The symmetric (two-sided) distance.
    pub fn max(&self) -> f64 {
        self.a_to_b.max(self.b_to_a)
    }
}

/// Sample points of every triangle of `s`, at most `spacing` apart along each edge direction.
pub fn samples(s: &InputSurface, spacing: f64) -> Vec<DVec3> {
    samples_per_edge_at_least(s, spacing, 1)
}

/// [`samples`], with every triangle's edges cut into at least `min_pieces` (small triangles
/// still get interior samples, where a curved surface is farthest from them).
pub fn samples_per_edge_at_least(s: &InputSurface, spacing: f64, min_pieces: usize) -> Vec<DVec3> {
    assert!(spacing > 0.0, "sampling spacing must be positive");
    let mut out = Vec::new();
    for t in 0..s.triangles.len() {
        let [a, b, c] = s.corners(t);
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let k = ((longest / spacing).ceil() as usize).clamp(min_pieces.max(1), 4096);
        for i in 0..=k {
            for j in 0..=(k - i) {
                let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
                out.push(a + (b - a) * u + (c - a) * v);
            }
        }
    }
    out
}

/// Largest distance from the samples of `from` to the surface behind `to`, and where.
pub fn one_sided(from: &InputSurface, to: &SurfaceOracle, spacing: f64) -> (f64, DVec3) {
    let mut worst = (0.0, DVec3::ZERO);
    for p in samples(from, spacing) {
        if let Some(c) = to.closest(p) {
            if c.distance > worst.0 {
                worst = (c.distance, p);
            }
        }
    }
    worst
}

/// Two-sided sampled Hausdorff distance between `a` and `b`.
pub fn hausdorff(a: &InputSurface, b: &InputSurface, spacing: f64) -> Hausdorff {
    let (oa, ob) = (SurfaceOracle::new(a), SurfaceOracle::new(b));
    let (a_to_b, worst_on_a) = one_sided(a, &ob, spacing);
    let (b_to_a, worst_on_b) = one_sided(b, &oa, spacing);
    Hausdorff {
        a_to_b,
        worst_on_a,
        b_to_a,
        worst_on_b,
    }
}
