//! Two-sided Hausdorff distance between triangle surfaces, by dense sampling: every triangle
//! is sampled finely enough that no point of it is farther than `spacing` from a sample, and
//! each sample's distance to the other surface is exact up to rounding (closest point through
//! the AABB tree). The result therefore underestimates the true distance by at most
//! `spacing`.

use super::oracle::SurfaceOracle;
use super::InputSurface;
use glam::DVec3;
use rustc_hash::FxHashMap;

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
///
/// A triangle is sampled on a barycentric grid of step at most `spacing` along each edge: no
/// point of it is farther than `spacing` / sqrt(3) from a sample. A long thin triangle, where
/// that grid would be mostly redundant points along its length, is sampled in rows instead
/// (see `Rows`), with the same guarantee and fewer samples.
///
/// Each sample is taken once: a vertex by the first triangle using it, an edge's grid points
/// by the first triangle cutting it into as many pieces (its neighbour mostly does: the two
/// triangles' grids meet there), from its lower vertex id to the higher so that both
/// triangles would compute the same points.
pub fn samples_per_edge_at_least(s: &InputSurface, spacing: f64, min_pieces: usize) -> Vec<DVec3> {
    assert!(spacing > 0.0, "sampling spacing must be positive");
    // Each triangle's grid size (0: rows), decided once; the output reserved for all their
    // samples, so that it is written once instead of copied through every doubling into fresh
    // memory (a third of a run's page faults).
    let mut bound = s.vertices.len();
    let plans: Vec<u16> = (0..s.triangles.len())
        .map(|t| {
            let plan = Sampling::of(s.corners(t), spacing, min_pieces);
            bound += plan.beyond_corners();
            match plan {
                Sampling::Rows(_) => 0,
                Sampling::Grid(k) => k as u16,
            }
        })
        .collect();
    let mut out = Vec::with_capacity(bound);
    let mut vertex_done = vec![false; s.vertices.len()];
    // Edge (sorted ids) -> the number of pieces its grid points were taken with.
    let mut edge_done: FxHashMap<[u32; 2], usize> = FxHashMap::default();
    edge_done.reserve(s.triangles.len() * 3 / 2);
    for (t, &pieces) in plans.iter().enumerate() {
        for v in s.triangles[t] {
            if !std::mem::replace(&mut vertex_done[v as usize], true) {
                out.push(s.vertices[v as usize]);
            }
        }
        let [a, b, c] = s.corners(t);
        let k = pieces as usize;
        if k == 0 {
            Rows::of([a, b, c], spacing / 3f64.sqrt()).sample_inside(&mut out);
            continue;
        }
        let ids = s.triangles[t];
        for e in 0..3 {
            let (u, v) = (ids[e].min(ids[(e + 1) % 3]), ids[e].max(ids[(e + 1) % 3]));
            if edge_done.insert([u, v], k) != Some(k) {
                let (p, q) = (s.vertices[u as usize], s.vertices[v as usize]);
                out.extend((1..k).map(|i| p + (q - p) * (i as f64 / k as f64)));
            }
        }
        // The points strictly inside.
        for i in 1..k {
            for j in 1..(k - i) {
                let (u, v) = (i as f64 / k as f64, j as f64 / k as f64);
                out.push(a + (b - a) * u + (c - a) * v);
            }
        }
    }
    out
}

/// Most pieces a triangle's edge is cut into (a u16 holds it).
const MAX_PIECES: usize = 4096;

/// How one triangle is sampled: a barycentric grid with `k` pieces along each edge, or rows
/// (a long thin triangle, where the rows take fewer samples).
enum Sampling {
    Grid(usize),
    Rows(Rows),
}

impl Sampling {
    fn of([a, b, c]: [DVec3; 3], spacing: f64, min_pieces: usize) -> Sampling {
        let longest = (b - a).length().max((c - b).length()).max((a - c).length());
        let k = ((longest / spacing).ceil() as usize).clamp(min_pieces.max(1), MAX_PIECES);
        let grid_samples = (k + 1) * (k + 2) / 2;
        let rows = Rows::of([a, b, c], spacing / 3f64.sqrt());
        if k > min_pieces && rows.count() < grid_samples {
            Sampling::Rows(rows)
        } else {
            Sampling::Grid(k)
        }
    }

    /// At most this many samples besides the three corners (shared edges count for each side).
    fn beyond_corners(&self) -> usize {
        match self {
            Sampling::Rows(rows) => rows.count(),
            &Sampling::Grid(k) => (k + 1) * (k + 2) / 2 - 3,
        }
    }
}

/// Samples of a triangle along rows parallel to its longest edge `a`-`b`, at most `step`
/// apart and `step` from the next row, the other two edges sampled as well. A point lies
/// between two rows, within `step` / 2 of the border of the strip of the triangle between
/// them, whose every point is within `step` / 2 of a sample: within `step` of a sample in all.
struct Rows {
    /// Longest edge first.
    corners: [DVec3; 3],
    rows: usize,
    step: f64,
}

impl Rows {
    fn of(corners: [DVec3; 3], step: f64) -> Rows {
        let corners = super::longest_edge_first(corners);
        let [a, b, c] = corners;
        let height = (b - a).cross(c - a).length() / (b - a).length().max(f64::MIN_POSITIVE);
        Rows {
            corners,
            rows: ((height / step).ceil() as usize).clamp(1, 4096),
            step,
        }
    }

    /// Steps along a segment of length `len` (at least 1).
    fn steps(&self, len: f64) -> usize {
        ((len / self.step).ceil() as usize).clamp(1, 4096)
    }

    /// The ends of row `j` (row 0 is edge a-b, the last one apex c).
    fn row(&self, j: usize) -> (DVec3, DVec3) {
        let [a, b, c] = self.corners;
        let tau = j as f64 / self.rows as f64;
        (a + (c - a) * tau, b + (c - b) * tau)
    }

    fn count(&self) -> usize {
        let [a, b, c] = self.corners;
        let along_rows: usize = (0..=self.rows)
            .map(|j| {
                let (p, r) = self.row(j);
                self.steps((r - p).length()) + 1
            })
            .sum();
        along_rows + self.steps((c - a).length()) + self.steps((c - b).length())
    }

    /// The samples other than the three corners.
    fn sample_inside(&self, out: &mut Vec<DVec3>) {
        let [a, b, c] = self.corners;
        // The last row is corner c alone.
        for j in 0..self.rows {
            let (p, r) = self.row(j);
            let n = self.steps((r - p).length());
            let ends = if j == 0 { 1..n } else { 0..n + 1 };
            out.extend(ends.map(|i| p + (r - p) * (i as f64 / n as f64)));
        }
        for (from, to) in [(a, c), (b, c)] {
            let n = self.steps((to - from).length());
            out.extend((1..n).map(|i| from + (to - from) * (i as f64 / n as f64)));
        }
    }
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
