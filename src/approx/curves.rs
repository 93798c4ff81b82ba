//! Feature curves as arc-length parametrised polylines, the patches each curve and corner
//! touches, and the small corners whose neighbourhood the surface mesher protects.

use crate::surface::features::Features;
use crate::surface::InputSurface;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// Corners where feature curves (or a patch) meet below this angle, degrees, are "small":
/// the mesher does not enforce shape next to them (the 60 degrees).
pub const SMALL_CORNER_DEG: f64 = 60.0;

/// Radius of a small corner's protecting ball, as a fraction of the distance to the nearest
/// other corner or curve end (below one half, so two balls never overlap).
const PROTECT_FRACTION: f64 = 0.4;

/// One feature polyline, parametrised by arc length from its first vertex.
#[derive(Debug, Clone)]
pub struct Curve {
    pub points: Vec<DVec3>,
    /// Arc length at each point (`cum[0] = 0`); a closed curve repeats its first point last.
    pub cum: Vec<f64>,
    pub closed: bool,
    /// Input vertex at each end (the same for a closed curve).
    pub ends: [u32; 2],
    /// Patches on either side of the curve, ascending.
    pub patches: Vec<u32>,
}

impl Curve {
    pub fn length(&self) -> f64 {
        *self.cum.last().unwrap_or(&0.0)
    }

    /// The point at arc length `s` (clamped to the curve).
    pub fn point_at(&self, s: f64) -> DVec3 {
        let s = s.clamp(0.0, self.length());
        let k = self
            .cum
            .partition_point(|&c| c <= s)
            .clamp(1, self.cum.len() - 1);
        let (s0, s1) = (self.cum[k - 1], self.cum[k]);
        let t = if s1 > s0 { (s - s0) / (s1 - s0) } else { 0.0 };
        self.points[k - 1].lerp(self.points[k], t)
    }

    /// The point of the curve nearest to `p`, and the unit direction of the curve there.
    pub fn closest(&self, p: DVec3) -> Option<(DVec3, DVec3)> {
        self.points
            .windows(2)
            .filter_map(|w| {
                let (a, b) = (w[0], w[1]);
                let d = b - a;
                let len2 = d.length_squared();
                (len2 > 0.0).then(|| {
                    let t = ((p - a).dot(d) / len2).clamp(0.0, 1.0);
                    (a + d * t, d / len2.sqrt())
                })
            })
            .min_by(|x, y| x.0.distance_squared(p).total_cmp(&y.0.distance_squared(p)))
    }

    /// Largest distance of the curve between arc lengths `s0 < s1` from the chord joining
    /// its points there.
    pub fn chord_deviation(&self, s0: f64, s1: f64) -> f64 {
        let (a, b) = (self.point_at(s0), self.point_at(s1));
        let first = self.cum.partition_point(|&c| c <= s0);
        let last = self.cum.partition_point(|&c| c < s1);
        (first..last)
            .map(|k| point_segment_distance(self.points[k], a, b))
            .fold(0.0, f64::max)
    }
}

/// Distance from `p` to the segment [a, b].
pub fn point_segment_distance(p: DVec3, a: DVec3, b: DVec3) -> f64 {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 {
        ((p - a).dot(ab) / l2).clamp(0.0, 1.0)
    } else {
        0.0
    };
    (a + ab * t - p).length()
}

/// A corner of the feature graph (a polyline end), with the patches around it.
#[derive(Debug, Clone)]
pub struct Corner {
    pub vertex: u32,
    pub point: DVec3,
    pub patches: Vec<u32>,
    /// Smallest angle between its curves or spanned by a patch, degrees.
    pub angle: f64,
    /// Protecting-ball radius when the corner is small (`angle < SMALL_CORNER_DEG`), else 0
    /// (it can be 0 for a small corner too, when another corner coincides with it).
    pub protect_radius: f64,
}

/// The curves and corners of a surface's features.
#[derive(Debug, Clone, Default)]
pub struct FeatureCurves {
    pub curves: Vec<Curve>,
    pub corners: Vec<Corner>,
    /// Input vertex -> index into `corners`.
    pub corner_of: FxHashMap<u32, u32>,
}

impl FeatureCurves {
    pub fn new(s: &InputSurface, f: &Features) -> FeatureCurves {
        let edge_patches = edge_patches(s, f);
        let mut curves = Vec::with_capacity(f.polylines.len());
        for pl in &f.polylines {
            let mut ids = pl.vertices.clone();
            if pl.closed {
                ids.push(ids[0]);
            }
            let points: Vec<DVec3> = ids.iter().map(|&v| s.vertices[v as usize]).collect();
            let mut cum = Vec::with_capacity(points.len());
            let mut acc = 0.0;
            for (k, p) in points.iter().enumerate() {
                if k > 0 {
                    acc += (*p - points[k - 1]).length();
                }
                cum.push(acc);
            }
            let mut patches: Vec<u32> = ids
                .windows(2)
                .flat_map(|w| {
                    edge_patches
                        .get(&key(w[0], w[1]))
                        .cloned()
                        .unwrap_or_default()
                })
                .collect();
            patches.sort_unstable();
            patches.dedup();
            curves.push(Curve {
                points,
                cum,
                closed: pl.closed,
                ends: [ids[0], *ids.last().unwrap()],
                patches,
            });
        }
        let corners = corners(s, f, &curves);
        let corner_of = corners
            .iter()
            .enumerate()
            .map(|(k, c)| (c.vertex, k as u32))
            .collect();
        FeatureCurves {
            curves,
            corners,
            corner_of,
        }
    }

    /// Shrinks every protecting ball to at most `radius` (inside one the surface is not
    /// refined, so its size bounds how far the boundary may stray there).
    pub fn cap_protect_radius(&mut self, radius: f64) {
        for c in &mut self.corners {
            c.protect_radius = c.protect_radius.min(radius);
        }
    }

    /// Small corners (angle below [`SMALL_CORNER_DEG`]).
    pub fn small_corners(&self) -> impl Iterator<Item = &Corner> {
        self.corners.iter().filter(|c| c.angle < SMALL_CORNER_DEG)
    }
}

fn key(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// Patches of the triangles around every feature edge.
fn edge_patches(s: &InputSurface, f: &Features) -> FxHashMap<[u32; 2], Vec<u32>> {
    let mut out: FxHashMap<[u32; 2], Vec<u32>> = f.edges.iter().map(|&e| (e, Vec::new())).collect();
    for (t, tri) in s.triangles.iter().enumerate() {
        for j in 0..3 {
            if let Some(list) = out.get_mut(&key(tri[j], tri[(j + 1) % 3])) {
                list.push(f.patch_of[t]);
            }
        }
    }
    out
}

/// Every polyline end (and every corner the feature detection found) with its patches,
/// angle and protecting radius.
fn corners(s: &InputSurface, f: &Features, curves: &[Curve]) -> Vec<Corner> {
    let mut ids: Vec<u32> = f.corners.clone();
    ids.extend(curves.iter().flat_map(|c| c.ends));
    let cone = cone_angles(s);
    ids.extend(
        cone.iter()
            .filter(|(_, &a)| a < CONE_CORNER_DEG)
            .map(|(&v, _)| v),
    );
    ids.sort_unstable();
    ids.dedup();
    let mut patches: FxHashMap<u32, Vec<u32>> = ids.iter().map(|&v| (v, Vec::new())).collect();
    for (t, tri) in s.triangles.iter().enumerate() {
        for v in tri {
            if let Some(list) = patches.get_mut(v) {
                list.push(f.patch_of[t]);
            }
        }
    }
    let mut angle: FxHashMap<u32, f64> = f
        .corner_angles(s)
        .into_iter()
        .map(|c| (c.vertex, c.angle))
        .collect();
    for v in &ids {
        let a = cone.get(v).copied().unwrap_or(360.0);
        let e = angle.entry(*v).or_insert(a);
        *e = e.min(a);
    }
    let points: Vec<DVec3> = ids.iter().map(|&v| s.vertices[v as usize]).collect();
    let nearest = nearest_other_distances(&points);
    ids.iter()
        .enumerate()
        .map(|(k, &v)| {
            let mut p = patches.remove(&v).unwrap_or_default();
            p.sort_unstable();
            p.dedup();
            let a = angle.get(&v).copied().unwrap_or(180.0);
            Corner {
                vertex: v,
                point: points[k],
                patches: p,
                angle: a,
                protect_radius: if a < SMALL_CORNER_DEG {
                    PROTECT_FRACTION * nearest[k]
                } else {
                    0.0
                },
            }
        })
        .collect()
}

/// A vertex whose triangles' angles there sum to less than this is the apex of a sharp cone
/// (a spike's tip whose edges are not sharp enough to be features): a corner, as surface
/// refinement cannot shape the facets around it.
const CONE_CORNER_DEG: f64 = 300.0;

/// Sum of the triangle angles at every vertex.
fn cone_angles(s: &InputSurface) -> FxHashMap<u32, f64> {
    let mut sum: FxHashMap<u32, f64> = FxHashMap::default();
    for tri in &s.triangles {
        for j in 0..3 {
            let p = s.vertices[tri[j] as usize];
            let a = s.vertices[tri[(j + 1) % 3] as usize] - p;
            let b = s.vertices[tri[(j + 2) % 3] as usize] - p;
            *sum.entry(tri[j]).or_default() += a.cross(b).length().atan2(a.dot(b)).to_degrees();
        }
    }
    sum
}

/// For each point, the distance to the nearest other point (infinite when alone). Sorted
/// sweep along x: O(n log n) for spread points.
fn nearest_other_distances(points: &[DVec3]) -> Vec<f64> {
    let mut order: Vec<usize> = (0..points.len()).collect();
    order.sort_by(|&i, &j| points[i].x.total_cmp(&points[j].x).then(i.cmp(&j)));
    let mut best = vec![f64::INFINITY; points.len()];
    for (k, &i) in order.iter().enumerate() {
        for &j in &order[k + 1..] {
            let dx = points[j].x - points[i].x;
            if dx >= best[i] {
                break;
            }
            let d = (points[j] - points[i]).length();
            best[i] = best[i].min(d);
            best[j] = best[j].min(d);
        }
        for &j in order[..k].iter().rev() {
            if points[i].x - points[j].x >= best[i] {
                break;
            }
            best[i] = best[i].min((points[j] - points[i]).length());
        }
    }
    best
}
