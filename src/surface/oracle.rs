//! Geometric queries on a triangle surface through an AABB tree: the closest surface point,
//! the triangles a segment meets, and whether a point is inside the closed surface.
//!
//! The tree only culls: boxes are padded by a tiny multiple of the model size so that floating
//! point slab tests never cull a triangle the exact test would accept. Whether a segment meets
//! a triangle and on which side of the surface a point lies are decided by signs of the exact
//! `orient3d`; only the crossing point itself and distances are floating point.

use super::InputSurface;
use crate::geom::orient3d;
use crate::plc::exact::{point_in_triangle_3d, segment_meets_triangle};
use glam::DVec3;
use std::cmp::Ordering;

/// Triangles per leaf.
const LEAF_SIZE: usize = 4;

#[derive(Debug, Clone, Copy)]
struct Node {
    lo: DVec3,
    hi: DVec3,
    /// Leaf: first index into `order`; inner node: index of the left child (right = left + 1).
    first: u32,
    /// Leaf: number of triangles (> 0); inner node: 0.
    count: u32,
}

/// The nearest surface point to a query.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Closest {
    pub point: DVec3,
    pub triangle: u32,
    pub distance: f64,
}

/// A triangle met by a segment, with where (parameter along the segment and point).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Crossing {
    pub triangle: u32,
    /// In [0, 1] from the segment's start (the middle of the overlap for a coplanar segment).
    pub t: f64,
    pub point: DVec3,
}

/// Where a point lies relative to a closed surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Inside,
    Outside,
    OnSurface,
}

/// An AABB tree over the triangles of an [`InputSurface`].
pub struct SurfaceOracle<'a> {
    surface: &'a InputSurface,
    nodes: Vec<Node>,
    order: Vec<u32>,
    /// Triangles with three collinear corners take no part in exact queries.
    flat: Vec<bool>,
    pad: f64,
    diagonal: f64,
}

impl<'a> SurfaceOracle<'a> {
    pub fn new(surface: &'a InputSurface) -> SurfaceOracle<'a> {
        let n = surface.triangles.len();
        let diagonal = surface.bbox_diagonal();
        let mut o = SurfaceOracle {
            surface,
            nodes: Vec::with_capacity(2 * n / LEAF_SIZE + 1),
            order: (0..n as u32).collect(),
            flat: (0..n).map(|t| is_flat(surface.corners(t))).collect(),
            pad: 1e-9 * diagonal.max(f64::MIN_POSITIVE),
            diagonal,
        };
        let centroids: Vec<DVec3> = (0..n)
            .map(|t| {
                let [a, b, c] = surface.corners(t);
                (a + b + c) / 3.0
            })
            .collect();
        if n > 0 {
            o.nodes.push(o.leaf(0, n));
            o.split(0, &centroids);
        }
        o
    }

    fn leaf(&self, first: usize, count: usize) -> Node {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for &t in &self.order[first..first + count] {
            for p in self.surface.corners(t as usize) {
                lo = lo.min(p);
                hi = hi.max(p);
            }
        }
        Node {
            lo: lo - DVec3::splat(self.pad),
            hi: hi + DVec3::splat(self.pad),
            first: first as u32,
            count: count as u32,
        }
    }

    /// Splits node `k` at the median centroid along its longest axis, recursively.
    fn split(&mut self, k: usize, centroids: &[DVec3]) {
        let mut work = vec![k];
        while let Some(k) = work.pop() {
            let node = self.nodes[k];
            let (first, count) = (node.first as usize, node.count as usize);
            if count <= LEAF_SIZE {
                continue;
            }
            let extent = node.hi - node.lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let half = count / 2;
            let key = |t: &u32| (centroids[*t as usize][axis], *t);
            self.order[first..first + count]
                .select_nth_unstable_by(half, |a, b| key(a).partial_cmp(&key(b)).unwrap());
            let left = self.nodes.len();
            let (l, r) = (
                self.leaf(first, half),
                self.leaf(first + half, count - half),
            );
            self.nodes.push(l);
            self.nodes.push(r);
            self.nodes[k].first = left as u32;
            self.nodes[k].count = 0;
            work.push(left);
            work.push(left + 1);
        }
    }

    fn leaf_triangles(&self, node: &Node) -> &[u32] {
        &self.order[node.first as usize..(node.first + node.count) as usize]
    }

    /// The surface point nearest to `p` (ties: the lowest triangle id found first).
    pub fn closest(&self, p: DVec3) -> Option<Closest> {
        let mut best: Option<Closest> = None;
        let mut stack = vec![0usize];
        while let Some(k) = stack.pop() {
            let Some(node) = self.nodes.get(k) else {
                break;
            };
            let bound = best.map_or(f64::INFINITY, |b| b.distance);
            if box_distance(node, p) > bound {
                continue;
            }
            if node.count > 0 {
                for &t in self.leaf_triangles(node) {
                    let [a, b, c] = self.surface.corners(t as usize);
                    let q = closest_on_triangle(p, a, b, c);
                    let d = (q - p).length();
                    if best.is_none_or(|b| d < b.distance) {
                        best = Some(Closest {
                            point: q,
                            triangle: t,
                            distance: d,
                        });
                    }
                }
            } else {
                let (l, r) = (node.first as usize, node.first as usize + 1);
                let (dl, dr) = (
                    box_distance(&self.nodes[l], p),
                    box_distance(&self.nodes[r], p),
                );
                // Visit the nearer child first: push it last.
                if dl <= dr {
                    stack.extend([r, l]);
                } else {
                    stack.extend([l, r]);
                }
            }
        }
        best
    }

    /// The distance from `p` to the surface when it exceeds `r`, else None. Stops at the first
    /// triangle within `r`: a sampled Hausdorff distance only needs the samples that raise the
    /// running maximum, and most samples lie close to the other surface.
    pub fn distance_beyond(&self, p: DVec3, r: f64) -> Option<f64> {
        self.distance_beyond_hinted(p, r, &mut None)
    }

    /// [`Self::distance_beyond`], trying triangle `hint` first and leaving there the triangle
    /// found within `r` (or the nearest one): consecutive queries at nearby points mostly end
    /// at the first test.
    pub fn distance_beyond_hinted(&self, p: DVec3, r: f64, hint: &mut Option<u32>) -> Option<f64> {
        let within = |t: u32| {
            let [a, b, c] = self.surface.corners(t as usize);
            (closest_on_triangle(p, a, b, c) - p).length() <= r
        };
        if hint.is_some_and(|t| (t as usize) < self.surface.triangles.len() && within(t)) {
            return None;
        }
        let mut stack = [0usize; 128];
        let mut top = usize::from(!self.nodes.is_empty());
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top]];
            if box_distance(node, p) > r {
                continue;
            }
            if node.count > 0 {
                for &t in self.leaf_triangles(node) {
                    if within(t) {
                        *hint = Some(t);
                        return None;
                    }
                }
            } else {
                let (l, r_) = (node.first as usize, node.first as usize + 1);
                // The nearer child last, visited first: it most likely holds a near triangle.
                let near_left = box_distance(&self.nodes[l], p) <= box_distance(&self.nodes[r_], p);
                (stack[top], stack[top + 1]) = if near_left { (r_, l) } else { (l, r_) };
                top += 2;
            }
        }
        let closest = self.closest(p)?;
        *hint = Some(closest.triangle);
        Some(closest.distance)
    }

    /// Every triangle the closed segment [p, q] meets, ordered by parameter then triangle id.
    pub fn crossings(&self, p: DVec3, q: DVec3) -> Vec<Crossing> {
        let mut out = Vec::new();
        self.visit_segment(p, q, |t| {
            if self.flat[t as usize] {
                return;
            }
            let [a, b, c] = self.surface.corners(t as usize);
            if segment_meets_triangle(p, q, a, b, c) {
                let t_param = crossing_parameter(p, q, a, b, c);
                out.push(Crossing {
                    triangle: t,
                    t: t_param,
                    point: p + (q - p) * t_param,
                });
            }
        });
        out.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.triangle.cmp(&y.triangle)));
        out
    }

    /// [`Self::crossings`], and whether p and q lie on different sides of the closed surface
    /// when that is clean to tell: every crossing proper (not through an edge, a vertex or
    /// an end of the segment), else None.
    pub fn crossings_and_parity(&self, p: DVec3, q: DVec3) -> (Vec<Crossing>, Option<bool>) {
        let mut out = Vec::new();
        let (mut odd, mut clean) = (false, true);
        self.visit_segment(p, q, |t| {
            if self.flat[t as usize] {
                return;
            }
            let [a, b, c] = self.surface.corners(t as usize);
            if segment_meets_triangle(p, q, a, b, c) {
                let t_param = crossing_parameter(p, q, a, b, c);
                out.push(Crossing {
                    triangle: t,
                    t: t_param,
                    point: p + (q - p) * t_param,
                });
                match proper_crossing(p, q, a, b, c) {
                    Crossed::Yes => odd = !odd,
                    _ => clean = false,
                }
            }
        });
        out.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.triangle.cmp(&y.triangle)));
        (out, clean.then_some(odd))
    }

    /// Inside, outside or on the closed surface, by the parity of proper crossings of a ray;
    /// a ray that touches an edge, a vertex or a triangle's plane is replaced by another. Needs
    /// no consistent orientation of the triangles.
    pub fn side(&self, p: DVec3) -> Side {
        let far = 4.0 * self.diagonal.max(1.0) + p.abs().max_element();
        for k in 0..MAX_RAYS {
            let q = p + ray_direction(k) * far;
            match self.ray_parity(p, q) {
                Some(Ok(odd)) => return if odd { Side::Inside } else { Side::Outside },
                Some(Err(OnSurface)) => return Side::OnSurface,
                None => continue,
            }
        }
        // Every one of MAX_RAYS generic directions grazed an edge or a vertex: only a point
        // on the surface's edges does that.
        Side::OnSurface
    }

    /// Some(Ok(odd)) for a clean ray, Some(Err) when p is on the surface, None when degenerate.
    fn ray_parity(&self, p: DVec3, q: DVec3) -> Option<Result<bool, OnSurface>> {
        let mut odd = false;
        let mut degenerate = false;
        let mut on_surface = false;
        self.visit_segment(p, q, |t| {
            if degenerate || on_surface || self.flat[t as usize] {
                return;
            }
            let [a, b, c] = self.surface.corners(t as usize);
            match proper_crossing(p, q, a, b, c) {
                Crossed::No => {}
                Crossed::Yes => odd = !odd,
                Crossed::Degenerate => degenerate = true,
                Crossed::StartsOn => on_surface = true,
            }
        });
        if on_surface {
            Some(Err(OnSurface))
        } else if degenerate {
            None
        } else {
            Some(Ok(odd))
        }
    }

    /// Calls `f` with every triangle whose box the segment [p, q] may touch.
    fn visit_segment(&self, p: DVec3, q: DVec3, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        // Median splits: the depth is about log2 of the leaves, far below the stack's size.
        let mut stack = [0usize; 128];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top]];
            if !segment_hits_box(node, p, q) {
                continue;
            }
            if node.count > 0 {
                for &t in self.leaf_triangles(node) {
                    f(t);
                }
            } else {
                stack[top] = node.first as usize + 1;
                stack[top + 1] = node.first as usize;
                top += 2;
            }
        }
    }
}

struct OnSurface;

/// Ray directions tried before giving up (each a generic direction; grazing rays are rare).
const MAX_RAYS: usize = 64;

/// The k-th ray direction: points of a golden-angle spiral on the unit sphere, offset so
/// that none is axis-aligned or lies in a coordinate plane.
fn ray_direction(k: usize) -> DVec3 {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let z = 1.0 - 2.0 * ((k as f64 + 0.37) / (MAX_RAYS as f64 + 0.5));
    let r = (1.0 - z * z).sqrt();
    let phi = golden * k as f64 + 0.61;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

enum Crossed {
    No,
    Yes,
    Degenerate,
    StartsOn,
}

/// Exact classification of segment [p, q] against triangle (a, b, c).
fn proper_crossing(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Crossed {
    let sign = |x: f64| crate::geom::sign(x);
    let op = sign(orient3d(a, b, c, p));
    let oq = sign(orient3d(a, b, c, q));
    if op == Ordering::Equal {
        return if point_in_triangle_3d(p, a, b, c) {
            Crossed::StartsOn
        } else if oq == Ordering::Equal {
            Crossed::Degenerate
        } else {
            Crossed::No
        };
    }
    if oq == Ordering::Equal {
        return Crossed::Degenerate;
    }
    if op == oq {
        return Crossed::No;
    }
    let o = [
        sign(orient3d(p, q, a, b)),
        sign(orient3d(p, q, b, c)),
        sign(orient3d(p, q, c, a)),
    ];
    let has = |s| o.contains(&s);
    if has(Ordering::Less) && has(Ordering::Greater) {
        Crossed::No
    } else if has(Ordering::Equal) {
        Crossed::Degenerate
    } else {
        Crossed::Yes
    }
}

fn is_flat([a, b, c]: [DVec3; 3]) -> bool {
    let n = (b - a).cross(c - a);
    // Exactly collinear corners have a zero cross product in every rounding only when they
    // are degenerate; a tiny non-zero one is still a valid (thin) triangle for orient3d.
    n == DVec3::ZERO && {
        let lift = |p: DVec3| DVec3::new(p.x, p.y, 0.0);
        orient3d(lift(a), lift(b), lift(c), DVec3::Z) == 0.0
            && orient3d(
                DVec3::new(a.y, a.z, 0.0),
                DVec3::new(b.y, b.z, 0.0),
                DVec3::new(c.y, c.z, 0.0),
                DVec3::Z,
            ) == 0.0
            && orient3d(
                DVec3::new(a.z, a.x, 0.0),
                DVec3::new(b.z, b.x, 0.0),
                DVec3::new(c.z, c.x, 0.0),
                DVec3::Z,
            ) == 0.0
    }
}

/// Where [p, q] meets the plane of (a, b, c), from the two orientation determinants.
fn crossing_parameter(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let dp = orient3d(a, b, c, p);
    let dq = orient3d(a, b, c, q);
    if dp == dq {
        // Coplanar segment: the middle of its overlap is a fair representative.
        let mid = closest_on_triangle((p + q) / 2.0, a, b, c);
        let d = q - p;
        let len2 = d.length_squared();
        return if len2 > 0.0 {
            ((mid - p).dot(d) / len2).clamp(0.0, 1.0)
        } else {
            0.0
        };
    }
    (dp / (dp - dq)).clamp(0.0, 1.0)
}

fn box_distance(node: &Node, p: DVec3) -> f64 {
    let d = (node.lo - p).max(p - node.hi).max(DVec3::ZERO);
    d.length()
}

/// Slab test of segment [p, q] against a (padded) box; conservative.
fn segment_hits_box(node: &Node, p: DVec3, q: DVec3) -> bool {
    let d = q - p;
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (lo, hi, o, dk) = (node.lo[k], node.hi[k], p[k], d[k]);
        if dk == 0.0 {
            if o < lo || o > hi {
                return false;
            }
            continue;
        }
        let (mut a, mut b) = ((lo - o) / dk, (hi - o) / dk);
        if a > b {
            std::mem::swap(&mut a, &mut b);
        }
        t0 = t0.max(a);
        t1 = t1.min(b);
        if t0 > t1 * (1.0 + 1e-12) + 1e-300 {
            return false;
        }
    }
    true
}

/// The point of triangle (a, b, c) nearest to p (Ericson, Real-Time Collision Detection 5.1.5).
pub fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> DVec3 {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return a;
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return b;
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        return a + ab * (d1 / (d1 - d3));
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return c;
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        return a + ac * (d2 / (d2 - d6));
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        return b + (c - b) * ((d4 - d3) / ((d4 - d3) + (d5 - d6)));
    }
    let denom = va + vb + vc;
    if denom <= 0.0 {
        // Degenerate triangle: the nearest of its three edges.
        return [(a, b), (b, c), (c, a)]
            .into_iter()
            .map(|(u, v)| closest_on_segment(p, u, v))
            .min_by(|x, y| {
                (*x - p)
                    .length_squared()
                    .total_cmp(&(*y - p).length_squared())
            })
            .unwrap_or(a);
    }
    let (v, w) = (vb / denom, vc / denom);
    a + ab * v + ac * w
}

fn closest_on_segment(p: DVec3, a: DVec3, b: DVec3) -> DVec3 {
    let d = b - a;
    let len2 = d.length_squared();
    if len2 == 0.0 {
        return a;
    }
    a + d * ((p - a).dot(d) / len2).clamp(0.0, 1.0)
}
