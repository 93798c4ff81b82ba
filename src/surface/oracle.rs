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

/// Pieces per leaf.
const LEAF_SIZE: usize = 4;

/// Triangles are cut into pieces one to two times this share of the bounding-box diagonal
/// across, at
/// most [`MAX_PIECES`] each, and the tree is built over the pieces' boxes: one box around a
/// long thin CAD strip would cover much of the model, and every query near it would test the
/// triangle and walk the boxes above it (measured on joint: 104 boxes per segment query with
/// pieces made by halving the longest edge, which leaves a thin strip long).
const PIECE_FRACTION: f64 = 1.0 / 64.0;
const MAX_PIECES: usize = 1024;

mod occupancy;
use occupancy::{Occupancy, GRID_FRACTION};

/// A piece of a triangle: only its box is kept; queries test the whole triangle.
#[derive(Debug, Clone, Copy)]
struct Piece {
    triangle: u32,
    lo: DVec3,
    hi: DVec3,
}

/// An axis-aligned box.
#[derive(Debug, Clone, Copy)]
struct Aabb {
    lo: DVec3,
    hi: DVec3,
}

#[derive(Debug, Clone, Copy)]
struct Node {
    bounds: Aabb,
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
    /// Through the triangle's interior, not an edge, a vertex or an end of the segment.
    pub proper: bool,
    /// The change of the winding count from the segment's start to its end across this
    /// triangle: +1 from its front (the side its normal points to) to its back, -1 the other
    /// way, 0 when not proper.
    pub delta: i8,
}

/// Where a point lies relative to a closed surface.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Side {
    Inside,
    Outside,
    OnSurface,
}

/// An AABB tree over the triangles of an [`InputSurface`].
pub struct SurfaceOracle {
    nodes: Vec<Node>,
    pieces: Vec<Piece>,
    /// Piece ids in leaf order.
    order: Vec<u32>,
    /// Per leaf position in `order`: the piece's triangle, and its box (padded as the nodes).
    leaf_tri: Vec<u32>,
    leaf_box: Vec<Aabb>,
    /// Every triangle's corner points, side by side (the queries' innermost loads).
    corners: Vec<[DVec3; 3]>,
    /// Per triangle: the triangles across its three edges (`NO_NEIGHBOUR` on a border or a
    /// non-manifold edge).
    neighbours: Vec<[u32; 3]>,
    grid: Occupancy,
    /// Triangles with three collinear corners take no part in exact queries.
    flat: Vec<bool>,
    /// Per triangle: its [`Frame`] (None when it has no area to speak of).
    frames: Vec<Option<Frame>>,
    /// Per triangle: the regions on its two sides (`InputSurface::sides`).
    sides: Vec<[u32; 2]>,
    /// Regions are winding counts (`Self::counting`), not `sides`.
    counting: bool,
    pad: f64,
    diagonal: f64,
}

impl SurfaceOracle {
    /// The oracle of `surface` (it keeps copies of what it needs: the surface may go).
    pub fn new(surface: &InputSurface) -> SurfaceOracle {
        Self::build(surface, true)
    }

    /// An oracle for distance queries ([`Self::closest`], [`Self::distance_beyond_hinted`]):
    /// without the occupancy grid, which only answers segment queries early (they still work,
    /// through the tree) and costs as much to build as the tree on a coarse surface, and with
    /// whole triangles in the leaves (pieces tighten the boxes a segment passes; a distance
    /// query prunes well enough by whole triangles, and the tree is cheaper to build).
    pub fn for_distances(surface: &InputSurface) -> SurfaceOracle {
        Self::build(surface, false)
    }

    /// An oracle whose regions are winding counts: the number of times the oriented triangles
    /// wind around a point (as `i32` bits in a `u32`), carried across each crossing by its
    /// `delta`. For a surface that is closed as an oriented cycle (every edge used as often in
    /// each direction, however many triangles meet there, intersecting or not) the count is
    /// the winding number itself.
    pub fn counting(surface: &InputSurface) -> SurfaceOracle {
        SurfaceOracle {
            counting: true,
            ..Self::build(surface, true)
        }
    }

    fn build(surface: &InputSurface, for_segments: bool) -> SurfaceOracle {
        let n = surface.triangles.len();
        let diagonal = surface.bbox_diagonal();
        let piece = if for_segments {
            PIECE_FRACTION * diagonal
        } else {
            f64::INFINITY
        };
        let pieces = cut_into_pieces(surface, piece);
        let corners: Vec<[DVec3; 3]> = (0..n).map(|t| surface.corners(t)).collect();
        let mut o = SurfaceOracle {
            nodes: Vec::with_capacity(2 * pieces.len() / LEAF_SIZE + 1),
            order: (0..pieces.len() as u32).collect(),
            leaf_tri: vec![],
            leaf_box: vec![],
            neighbours: edge_neighbours(&surface.triangles),
            grid: if for_segments {
                Occupancy::new(&pieces, &corners, GRID_FRACTION * diagonal)
            } else {
                Occupancy::empty()
            },
            frames: corners.iter().map(|&c| Frame::of(c)).collect(),
            sides: surface.sides.clone(),
            counting: false,
            corners,
            pieces,
            flat: (0..n).map(|t| is_flat(surface.corners(t))).collect(),
            pad: 1e-9 * diagonal.max(f64::MIN_POSITIVE),
            diagonal,
        };
        let centroids: Vec<DVec3> = o.pieces.iter().map(|p| (p.lo + p.hi) / 2.0).collect();
        let m = o.pieces.len();
        if m > 0 {
            o.nodes.push(o.leaf(0, m));
            o.split(0, &centroids);
        }
        o.leaf_tri = o
            .order
            .iter()
            .map(|&k| o.pieces[k as usize].triangle)
            .collect();
        let pad = DVec3::splat(o.pad);
        o.leaf_box = o
            .order
            .iter()
            .map(|&k| Aabb {
                lo: o.pieces[k as usize].lo - pad,
                hi: o.pieces[k as usize].hi + pad,
            })
            .collect();
        o
    }

    fn leaf(&self, first: usize, count: usize) -> Node {
        let mut lo = DVec3::splat(f64::INFINITY);
        let mut hi = DVec3::splat(f64::NEG_INFINITY);
        for &k in &self.order[first..first + count] {
            lo = lo.min(self.pieces[k as usize].lo);
            hi = hi.max(self.pieces[k as usize].hi);
        }
        Node {
            bounds: Aabb {
                lo: lo - DVec3::splat(self.pad),
                hi: hi + DVec3::splat(self.pad),
            },
            first: first as u32,
            count: count as u32,
        }
    }

    /// Splits node `k` at the median centroid along its longest axis, recursively.
    fn split(&mut self, k: usize, centroids: &[DVec3]) {
        let mut work = vec![k];
        let mut keyed: Vec<(f64, u32)> = Vec::with_capacity(self.order.len());
        while let Some(k) = work.pop() {
            let node = self.nodes[k];
            let (first, count) = (node.first as usize, node.count as usize);
            if count <= LEAF_SIZE {
                continue;
            }
            let extent = node.bounds.hi - node.bounds.lo;
            let axis = if extent.x >= extent.y && extent.x >= extent.z {
                0
            } else if extent.y >= extent.z {
                1
            } else {
                2
            };
            let half = count / 2;
            // The keys side by side: the selection then reads no centroid through an index.
            keyed.clear();
            keyed.extend(
                self.order[first..first + count]
                    .iter()
                    .map(|&t| (centroids[t as usize][axis], t)),
            );
            keyed.select_nth_unstable_by(half, |a, b| a.partial_cmp(b).unwrap());
            for (o, k) in self.order[first..first + count].iter_mut().zip(&keyed) {
                *o = k.1;
            }
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

    /// The triangles of a leaf's pieces (a triangle may come up again in another leaf).
    fn leaf_triangles(&self, node: &Node) -> &[u32] {
        &self.leaf_tri[node.first as usize..(node.first + node.count) as usize]
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
                    let [a, b, c] = self.corners[t as usize];
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
        let within = |t: u32| self.within(t, p, r);
        if let Some(h0) = hint.filter(|&t| (t as usize) < self.corners.len()) {
            let h = match self.walk_towards(h0, p, r) {
                Walked::Within(t) => {
                    *hint = Some(t);
                    return None;
                }
                Walked::Stopped(t) => t,
            };
            // The next point of a run of samples mostly lies over a neighbour of the last
            // triangle found.
            if let Some(&n) = self.neighbours[h as usize]
                .iter()
                .find(|&&n| n != NO_NEIGHBOUR && within(n))
            {
                *hint = Some(n);
                return None;
            }
            // Or a neighbour's neighbour (a run of samples crossing a vertex of the last one).
            for n in self.neighbours[h as usize] {
                if n == NO_NEIGHBOUR {
                    continue;
                }
                if let Some(&m) = self.neighbours[n as usize]
                    .iter()
                    .find(|&&m| m != NO_NEIGHBOUR && m != h && within(m))
                {
                    *hint = Some(m);
                    return None;
                }
            }
        }
        if let Some(t) = self.triangle_within(p, r) {
            *hint = Some(t);
            return None;
        }
        let closest = self.closest(p)?;
        *hint = Some(closest.triangle);
        Some(closest.distance)
    }

    /// Whether no triangle comes within `r` of `p`.
    pub fn clear_within(&self, p: DVec3, r: f64) -> bool {
        self.triangle_within(p, r).is_none()
    }

    /// A triangle within `r` of `p`, found through the tree (the first one met).
    fn triangle_within(&self, p: DVec3, r: f64) -> Option<u32> {
        let within = |t: u32| self.within(t, p, r);
        let mut stack = [0usize; 128];
        let mut top = usize::from(!self.nodes.is_empty());
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top]];
            if box_distance(node, p) > r {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (&t, b) in self.leaf_tri[range.clone()]
                    .iter()
                    .zip(&self.leaf_box[range])
                {
                    // A piece whose (padded) box is farther than r does not hold the point of
                    // its triangle nearest to p, if that is within r: the piece that does is
                    // visited too. The box test is much cheaper than the closest point.
                    if aabb_distance(b, p) <= r && within(t) {
                        return Some(t);
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
        None
    }

    /// From triangle `t`, steps across an edge `p` lies beyond while the triangle reached is not
    /// within `r` of p (at most [`WALK_STEPS`] steps): on a surface made of small triangles the
    /// last triangle found is often a few triangles away from the next point of a run of
    /// samples, and the walk goes straight there where the rings around `t` try every
    /// neighbour.
    fn walk_towards(&self, mut t: u32, p: DVec3, r: f64) -> Walked {
        let mut last = NO_NEIGHBOUR;
        for step in 0..=WALK_STEPS {
            if self.within(t, p, r) {
                return Walked::Within(t);
            }
            let Some(frame) = &self.frames[t as usize] else {
                break;
            };
            let corners = self.corners[t as usize];
            let Some(edge) = (0..3).find(|&i| frame.inward[i].dot(p - corners[i]) < 0.0) else {
                // p lies over t, farther than r from its plane: the walk is done.
                break;
            };
            let next = self.neighbours[t as usize][edge];
            if step == WALK_STEPS || next == NO_NEIGHBOUR || next == last {
                break;
            }
            (last, t) = (t, next);
        }
        Walked::Stopped(t)
    }

    /// Whether triangle `t` comes within `r` of `p`: through its plane when p lies over it or
    /// farther than `r` from the plane (the common cases), else through its closest point.
    pub(crate) fn within(&self, t: u32, p: DVec3, r: f64) -> bool {
        let [a, b, c] = self.corners[t as usize];
        if let Some(frame) = &self.frames[t as usize] {
            let height = frame.normal.dot(p - a);
            if height.abs() > r {
                return false;
            }
            if frame.over(p, [a, b, c]) {
                return true;
            }
        }
        (closest_on_triangle(p, a, b, c) - p).length() <= r
    }

    /// Every triangle the closed segment [p, q] meets, ordered by parameter then triangle id.
    pub fn crossings(&self, p: DVec3, q: DVec3) -> Vec<Crossing> {
        self.crossings_and_parity(p, q).0
    }

    /// [`Self::crossings`], and whether p and q lie on different sides of the closed surface
    /// when that is clean to tell: every crossing proper (not through an edge, a vertex or
    /// an end of the segment), else None.
    pub fn crossings_and_parity(&self, p: DVec3, q: DVec3) -> (Vec<Crossing>, Option<bool>) {
        let (mut odd, mut clean) = (false, true);
        let mut out = Vec::new();
        self.visit_segment(p, q, |t| {
            if self.flat[t as usize] {
                return;
            }
            let [a, b, c] = self.corners[t as usize];
            if let Some((t_param, delta)) = segment_meets(p, q, a, b, c) {
                let proper = delta != 0;
                out.push(Crossing {
                    triangle: t,
                    t: t_param,
                    point: p + (q - p) * t_param,
                    proper,
                    delta,
                });
                if proper {
                    odd = !odd;
                } else {
                    clean = false;
                }
            }
        });
        out.sort_by(|x, y| x.t.total_cmp(&y.t).then(x.triangle.cmp(&y.triangle)));
        (out, clean.then_some(odd))
    }

    /// The region at the end of a segment that starts in region `from` and meets `crossings`
    /// (sorted along it, as [`Self::crossings`] gives them; `forward` false: the segment is
    /// walked from its end back to its start): each crossing passes from one side of its
    /// triangle to the other. None when that is not clean to tell: a crossing is not proper,
    /// or the region reached is on neither side of the next triangle (crossings whose order
    /// rounding decided). With one region this is the parity of the crossings; a counting
    /// oracle adds up their deltas.
    pub fn region_across<'c>(
        &self,
        from: u32,
        crossings: impl IntoIterator<Item = &'c Crossing>,
        forward: bool,
    ) -> Option<u32> {
        if self.counting {
            let sign = if forward { 1 } else { -1 };
            return crossings
                .into_iter()
                .try_fold(from as i32, |n, x| {
                    x.proper.then_some(n + sign * i32::from(x.delta))
                })
                .map(|n| n as u32);
        }
        crossings.into_iter().try_fold(from, |r, x| {
            let [a, b] = self.sides[x.triangle as usize];
            match () {
                _ if !x.proper => None,
                _ if r == a => Some(b),
                _ if r == b => Some(a),
                _ => None,
            }
        })
    }

    /// The region `p` lies in (`InputSurface::sides`: 0 outside), from the crossings of a
    /// ray walked back from its far end, which is outside; a ray that touches an edge, a
    /// vertex or a triangle's plane, or whose crossings do not chain, is replaced by another.
    /// A point on the surface gets the larger region of a triangle it lies on.
    pub fn region(&self, p: DVec3) -> u32 {
        let far = 4.0 * self.diagonal.max(1.0) + p.abs().max_element();
        for k in 0..MAX_RAYS {
            let q = p + ray_direction(k) * far;
            match self.ray_region(p, q) {
                Some(Ok(r)) => return r,
                Some(Err(_)) if self.counting => return 1,
                Some(Err(t)) => return self.sides[t as usize][0].max(self.sides[t as usize][1]),
                None => continue,
            }
        }
        // Only a point on the surface's edges grazes every one of MAX_RAYS directions.
        if self.counting {
            return 1;
        }
        self.closest(p).map_or(0, |c| {
            let [a, b] = self.sides[c.triangle as usize];
            a.max(b)
        })
    }

    /// Some(Ok(region)) for a clean ray, Some(Err(triangle)) when p lies on that triangle,
    /// None when degenerate.
    fn ray_region(&self, p: DVec3, q: DVec3) -> Option<Result<u32, u32>> {
        let mut hits: Vec<Crossing> = Vec::new();
        let mut degenerate = false;
        let mut on = None;
        self.visit_segment(p, q, |t| {
            if degenerate || on.is_some() || self.flat[t as usize] {
                return;
            }
            let [a, b, c] = self.corners[t as usize];
            match proper_crossing(p, q, a, b, c) {
                Crossed::No => {}
                Crossed::Yes => {
                    let (dp, dq) = (orient3d(a, b, c, p), orient3d(a, b, c, q));
                    hits.push(Crossing {
                        triangle: t,
                        t: dp / (dp - dq),
                        point: p,
                        proper: true,
                        // Walked from q: into the triangle's back when q is in front.
                        delta: if dq > 0.0 { 1 } else { -1 },
                    });
                }
                Crossed::Degenerate => degenerate = true,
                Crossed::StartsOn => on = Some(t),
            }
        });
        if let Some(t) = on {
            return Some(Err(t));
        }
        if degenerate {
            return None;
        }
        // From q (outside) back to p.
        hits.sort_by(|x, y| y.t.total_cmp(&x.t).then(x.triangle.cmp(&y.triangle)));
        self.region_across(0, &hits, true).map(Ok)
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
            let [a, b, c] = self.corners[t as usize];
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

    /// Calls `f` once with every triangle a piece box of which the segment [p, q] may touch.
    fn visit_segment(&self, p: DVec3, q: DVec3, mut f: impl FnMut(u32)) {
        if self.nodes.is_empty() {
            return;
        }
        if self.grid.surely_clear(p, q) {
            return;
        }
        let slab = Slab::new(p, q);
        let mut seen = SeenTriangles::default();
        // Median splits: the depth is about log2 of the leaves, far below the stack's size.
        let mut stack = [0usize; 128];
        let mut top = 1;
        while top > 0 {
            top -= 1;
            let node = &self.nodes[stack[top]];
            if !segment_hits_box(&node.bounds, &slab) {
                continue;
            }
            if node.count > 0 {
                let range = node.first as usize..(node.first + node.count) as usize;
                for (&t, b) in self.leaf_tri[range.clone()]
                    .iter()
                    .zip(&self.leaf_box[range])
                {
                    if segment_hits_box(b, &slab) && seen.insert(t) {
                        f(t);
                    }
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

/// See `SurfaceOracle::neighbours`.
const NO_NEIGHBOUR: u32 = u32::MAX;

/// The most edges [`SurfaceOracle::walk_towards`] crosses.
const WALK_STEPS: usize = 4;

/// Where a walk over the triangles ended.
enum Walked {
    /// At a triangle within the distance.
    Within(u32),
    /// At a triangle that is not, the last one reached.
    Stopped(u32),
}

/// The triangles across each triangle's edges (`NO_NEIGHBOUR` unless exactly two share it).
fn edge_neighbours(triangles: &[[u32; 3]]) -> Vec<[u32; 3]> {
    let mut edges: Vec<(u64, u32, u8)> = Vec::with_capacity(3 * triangles.len());
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            let key = (u64::from(a.min(b)) << 32) | u64::from(a.max(b));
            edges.push((key, t as u32, k as u8));
        }
    }
    edges.sort_unstable();
    let mut out = vec![[NO_NEIGHBOUR; 3]; triangles.len()];
    for run in edges.chunk_by(|x, y| x.0 == y.0) {
        if let [(_, t, i), (_, u, j)] = *run {
            out[t as usize][i as usize] = u;
            out[u as usize][j as usize] = t;
        }
    }
    out
}

/// The triangles one segment query has handed out (pieces of a triangle share its tests).
#[derive(Default)]
struct SeenTriangles {
    first: [u32; 16],
    n: usize,
    more: Vec<u32>,
}

impl SeenTriangles {
    /// Whether `t` is new (and records it).
    fn insert(&mut self, t: u32) -> bool {
        let n = self.n.min(self.first.len());
        if self.first[..n].contains(&t) || self.more.contains(&t) {
            return false;
        }
        if self.n < self.first.len() {
            self.first[self.n] = t;
        } else {
            self.more.push(t);
        }
        self.n += 1;
        true
    }
}

/// Every triangle cut into pieces `len` to 2 `len` across (at most [`MAX_PIECES`] each), as
/// boxes: strips parallel to its longest edge, each cut across along that edge (a triangle
/// under 2 `len` stays whole: smaller pieces only make the tree deeper). The boxes only need
/// to cover the triangle: they are padded like the nodes.
fn cut_into_pieces(surface: &InputSurface, len: f64) -> Vec<Piece> {
    let mut pieces = Vec::with_capacity(surface.triangles.len());
    let mut polygon = Vec::with_capacity(8);
    for t in 0..surface.triangles.len() {
        let [a, b, c] = super::longest_edge_first(surface.corners(t));
        let long = (b - a).length();
        let height = (b - a).cross(c - a).length() / long.max(f64::MIN_POSITIVE);
        let count = |step: f64| {
            let n = |x: f64| ((x / step).floor() as usize).max(1);
            (n(height), n(long))
        };
        let mut step = if len > 0.0 {
            len
        } else {
            long.max(height).max(f64::MIN_POSITIVE)
        };
        while count(step).0 * count(step).1 > MAX_PIECES {
            step *= 1.25;
        }
        let (rows, slices) = count(step);
        let along = (b - a) / long.max(f64::MIN_POSITIVE);
        let row = |j: usize| {
            let tau = j as f64 / rows as f64;
            (a + (c - a) * tau, b + (c - b) * tau)
        };
        for j in 0..rows {
            let ((p0, r0), (p1, r1)) = (row(j), row(j + 1));
            for i in 0..slices {
                // The outer slices reach past the triangle: rounding never leaves a part out.
                let from = if i == 0 {
                    f64::NEG_INFINITY
                } else {
                    i as f64 * long / slices as f64
                };
                let to = if i + 1 == slices {
                    f64::INFINITY
                } else {
                    (i + 1) as f64 * long / slices as f64
                };
                polygon.clear();
                polygon.extend([p0, r0, r1, p1]);
                clip(&mut polygon, |x| (x - a).dot(along) - from);
                clip(&mut polygon, |x| to - (x - a).dot(along));
                if let Some(&first) = polygon.first() {
                    let (lo, hi) = polygon
                        .iter()
                        .fold((first, first), |(lo, hi), &x| (lo.min(x), hi.max(x)));
                    pieces.push(Piece {
                        triangle: t as u32,
                        lo,
                        hi,
                    });
                }
            }
        }
    }
    pieces
}

/// Keeps the part of convex `polygon` where `side` is not negative (Sutherland-Hodgman).
fn clip(polygon: &mut Vec<DVec3>, side: impl Fn(DVec3) -> f64) {
    let n = polygon.len();
    let mut out = Vec::with_capacity(n + 2);
    for k in 0..n {
        let (x, y) = (polygon[k], polygon[(k + 1) % n]);
        let (sx, sy) = (side(x), side(y));
        if sx >= 0.0 {
            out.push(x);
        }
        if (sx >= 0.0) != (sy >= 0.0) {
            out.push(x + (y - x) * (sx / (sx - sy)));
        }
    }
    *polygon = out;
}

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

pub(crate) fn is_flat([a, b, c]: [DVec3; 3]) -> bool {
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

/// Whether the closed segment [p, q] meets triangle (a, b, c) (exact) and if so where, as
/// a parameter along it, and the crossing's `Crossing::delta` (0 unless proper: through the
/// triangle's interior with both ends off its plane).
fn segment_meets(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> Option<(f64, i8)> {
    let dp = orient3d(a, b, c, p);
    let dq = orient3d(a, b, c, q);
    let (sp, sq) = (crate::geom::sign(dp), crate::geom::sign(dq));
    let meets = match (sp, sq) {
        (Ordering::Equal, Ordering::Equal) => segment_meets_triangle(p, q, a, b, c),
        (Ordering::Equal, _) => point_in_triangle_3d(p, a, b, c),
        (_, Ordering::Equal) => point_in_triangle_3d(q, a, b, c),
        _ if sp == sq => false,
        _ => {
            let o = [
                crate::geom::sign(orient3d(p, q, a, b)),
                crate::geom::sign(orient3d(p, q, b, c)),
                crate::geom::sign(orient3d(p, q, c, a)),
            ];
            let has = |s| o.contains(&s);
            if has(Ordering::Less) && has(Ordering::Greater) {
                false
            } else {
                // orient3d is positive in front of the triangle: from front to back adds one.
                let delta = match () {
                    _ if has(Ordering::Equal) => 0,
                    _ if dp > 0.0 => 1,
                    _ => -1,
                };
                return Some(((dp / (dp - dq)).clamp(0.0, 1.0), delta));
            }
        }
    };
    meets.then(|| (crossing_parameter(p, q, a, b, c, dp, dq), 0))
}

/// Where [p, q] meets the plane of (a, b, c), from the two orientation determinants.
fn crossing_parameter(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3, dp: f64, dq: f64) -> f64 {
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
    aabb_distance(&node.bounds, p)
}

fn aabb_distance(b: &Aabb, p: DVec3) -> f64 {
    (b.lo - p).max(p - b.hi).max(DVec3::ZERO).length()
}

/// Segment [p, q] set up for slab tests against many boxes.
struct Slab {
    p: DVec3,
    d: DVec3,
    inv: DVec3,
    /// Some coordinate of the direction is zero (or so tiny that its inverse overflows): the
    /// general test would meet 0 * inf.
    axis_parallel: bool,
}

impl Slab {
    fn new(p: DVec3, q: DVec3) -> Slab {
        let d = q - p;
        let inv = DVec3::ONE / d;
        Slab {
            p,
            d,
            inv,
            axis_parallel: !inv.is_finite(),
        }
    }
}

/// Slab test of a segment against a (padded) box; conservative.
fn segment_hits_box(bx: &Aabb, s: &Slab) -> bool {
    if s.axis_parallel {
        return segment_hits_box_axis_parallel(bx, s);
    }
    // No NaN can arise here (finite boxes, no zero direction), so plain comparisons do (the
    // NaN-aware f64::min and max cost several instructions each).
    let (a, b) = ((bx.lo - s.p) * s.inv, (bx.hi - s.p) * s.inv);
    let lt = |x: f64, y: f64| if x < y { x } else { y };
    let gt = |x: f64, y: f64| if x > y { x } else { y };
    let t0 = gt(gt(gt(lt(a.x, b.x), lt(a.y, b.y)), lt(a.z, b.z)), 0.0);
    let t1 = lt(lt(lt(gt(a.x, b.x), gt(a.y, b.y)), gt(a.z, b.z)), 1.0);
    t0 <= t1 * (1.0 + 1e-12) + 1e-300
}

/// [`segment_hits_box`] for a segment parallel to a coordinate plane.
fn segment_hits_box_axis_parallel(bx: &Aabb, s: &Slab) -> bool {
    let (mut t0, mut t1) = (0.0f64, 1.0f64);
    for k in 0..3 {
        let (lo, hi, o, dk) = (bx.lo[k], bx.hi[k], s.p[k], s.d[k]);
        // Along an axis the segment does not (measurably) move, its box is its start.
        if dk == 0.0 || !s.inv[k].is_finite() {
            if o < lo || o > hi {
                return false;
            }
            continue;
        }
        let (mut a, mut b) = ((lo - o) * s.inv[k], (hi - o) * s.inv[k]);
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

/// A triangle's unit normal and, per edge, the in-plane direction across it towards the
/// triangle: the distance to its plane, and whether a point lies over it, by dot products.
#[derive(Debug, Clone, Copy)]
struct Frame {
    normal: DVec3,
    /// Edge i runs from corner i to corner i + 1.
    inward: [DVec3; 3],
}

impl Frame {
    fn of([a, b, c]: [DVec3; 3]) -> Option<Frame> {
        let n = (b - a).cross(c - a);
        let len = n.length();
        // Too thin for the plane to be well defined: the closest point decides.
        if len.is_nan() || len <= 1e-12 * (b - a).length_squared().max((c - a).length_squared()) {
            return None;
        }
        let normal = n / len;
        Some(Frame {
            normal,
            inward: [b - a, c - b, a - c].map(|e| normal.cross(e)),
        })
    }

    /// Whether p's projection onto the plane lies in the triangle with `corners` (then the
    /// plane's distance is the triangle's).
    fn over(&self, p: DVec3, corners: [DVec3; 3]) -> bool {
        (0..3).all(|i| self.inward[i].dot(p - corners[i]) >= 0.0)
    }
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
