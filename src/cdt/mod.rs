//! One facet's own 2D constrained Delaunay triangulation (its "subfacets").
//!
//! Boundary recovery keeps, for every input facet (a planar polygon, possibly with holes), a
//! triangulation of the vertices lying on it; subsegments and subfacets are split until every
//! subfacet is a face of the 3D Delaunay tetrahedralization. [`FacetMesh`] is that per-facet
//! triangulation: vertices carry global ids (`u32`) and 3D coordinates, polygon edges are
//! constrained edges ("subsegments"), and every change is reported as a [`Change`] so that the
//! caller can keep a set of subfacets in sync.
//!
//! # Predicates (all exact, all through `crate::geom`)
//! - **Orientation**: points are projected by dropping the dominant axis `k` of the facet normal
//!   (no arithmetic, so exact); the two remaining axes are ordered so that counter-clockwise in
//!   2D means "the facet normal points at the viewer". `orient2d` is `orient3d` of the projected
//!   points lifted to z = 0 with apex (0, 0, 1), which is exactly the 2D determinant.
//! - **In-circle**: `insphere(a, b, c, E, d)` with E one fixed point off the facet plane on the
//!   normal's side, so that (a, b, c, E) is positively oriented for ccw abc. For coplanar points
//!   this is exactly "d strictly inside the circumcircle of abc in the plane"; for points a
//!   rounding error off the plane (float circumcentres, midpoints, non-planar input) it is still
//!   one consistent lifting (inversion centred at E), so Lawson flips stay consistent. The test
//!   of an edge is symmetric (the same answer from both triangles): the sign is read from a side
//!   whose lifted tet (a, b, c, E) is positive; a nearly flat triangle of points off the plane
//!   may have a non-positive one, and if both sides do, the edge counts as Delaunay.
//! - **Ties** (cocircular points, everywhere on axis-aligned grids) count as "not inside": the
//!   existing diagonal stays. [`FacetMesh::flip`] lets the caller pick the other one (e.g. to
//!   match the 3D triangulation's symbolic tie-break).
//!
//! # Representation and algorithms
//! A flat `Vec` of triangles (3 local vertex indices ccw, 3 neighbour references
//! `tri * 3 + edge`, one flag byte: constrained bit per edge + "inside the facet"). Edge `i` of a
//! triangle is the one opposite its vertex `i`. Three temporary vertices (local 0..3, never
//! exposed) form a super-triangle around the facet; the triangles outside the facet (beyond its
//! boundary, in holes) are kept but flagged outside, so point location is a plain stochastic
//! visibility walk (Devillers et al., terminates in any triangulation) and "is p in the facet"
//! is "is the triangle found inside". Triangles are never deleted (every operation splits or
//! flips), so there is no free list. Construction: incremental Delaunay insertion of the polygon
//! vertices in BRIO order (Lawson flips), recovery of each polygon edge by Sloan's flip algorithm (a vertex
//! lying exactly on the edge splits it), flood fill from the super-triangle, from the inner side
//! of hole polygons and from hole points (bounded by constrained edges), then Lawson flips to the
//! constrained Delaunay triangulation. `insert`/`split_edge` cost a walk plus O(flips).
//!
//! # Limits
//! - No vertex removal. Polygons must be simple and must not cross (crossings are reported);
//!   two vertices with the same projected position are an error.
//! - The facet normal (and so the ccw sense of every reported triangle) is the right-hand normal
//!   of the outer polygon with the largest area; other polygons' windings do not matter.
//! - Points passed to `split_edge` must be near the segment: a point whose projection would
//!   invert an adjacent triangle is refused ([`SplitError::WouldInvert`]).
//! - [`FacetMesh::validate`]'s area check assumes outer polygons do not nest and is skipped when
//!   hole points are used (their extent is not given as polygons).
//! - Points off the plane by far more than rounding, relative to the local spacing (e.g. 1e-9
//!   off the plane and 1e-10 from an edge), can leave an edge that the lifted test calls
//!   non-Delaunay but whose quadrilateral is not convex in the projection, so it cannot flip;
//!   `validate` then reports it. A rounding error off the plane (float circumcentres and
//!   midpoints) did not trigger this in randomized tests.

use crate::delaunay::hilbert::brio_order;
use crate::geom::{check_coordinate, insphere, orient3d};
use glam::{DVec2, DVec3};
use rustc_hash::FxHashMap;
use std::collections::VecDeque;

/// "No neighbour" (super-triangle hull edge) / global id of the temporary vertices.
const NONE: u32 = u32::MAX;
/// Flag bit: triangle is part of the facet.
const INSIDE: u8 = 8;

/// Returns `Err(format!(..))` unless the condition holds.
macro_rules! ensure {
    ($c:expr, $($m:tt)+) => {
        let ok: bool = $c;
        if !ok {
            return Err(format!($($m)+));
        }
    };
}

#[inline(always)]
fn nx(i: usize) -> usize {
    [1, 2, 0][i]
}
#[inline(always)]
fn pv(i: usize) -> usize {
    [2, 0, 1][i]
}

/// Exact 2D orientation: > 0 iff (a, b, c) is counter-clockwise.
#[inline]
fn orient2d(a: DVec2, b: DVec2, c: DVec2) -> f64 {
    // det[b-a, c-a, d-a] with d = (0,0,1) and a, b, c at z = 0 is (b-a) x (c-a) in 2D: exact.
    orient3d(a.extend(0.0), b.extend(0.0), c.extend(0.0), DVec3::Z)
}

/// Rotates a triangle so that its smallest id comes first (orientation kept).
fn canon(v: [u32; 3]) -> [u32; 3] {
    let m = (0..3).min_by_key(|&i| v[i]).unwrap();
    [v[m], v[nx(m)], v[pv(m)]]
}

#[derive(Clone, Copy, Debug, Default)]
struct Tri {
    /// Local vertex indices, counter-clockwise.
    v: [u32; 3],
    /// `n[i]`: neighbour across edge i (opposite `v[i]`) as `tri * 3 + its edge index`, or NONE.
    n: [u32; 3],
    /// Bit i: edge i constrained; `INSIDE`: part of the facet.
    f: u8,
}

impl Tri {
    fn cons(&self, i: usize) -> bool {
        self.f & (1 << i) != 0
    }
    fn inside(&self) -> bool {
        self.f & INSIDE != 0
    }
    fn find(&self, v: u32) -> Option<usize> {
        self.v.iter().position(|&w| w == v)
    }
}

/// Where a walk ended.
#[derive(Clone, Copy, Debug, PartialEq)]
enum Loc {
    In(u32),
    Edge(u32, usize),
    Vertex(u32, usize),
    Outside,
}

/// Triangles (global ids, ccw, smallest id first) that an operation removed and added.
/// Applying `removed` then `added` to the set of [`FacetMesh::triangles`] before the operation
/// gives the set after it. Only triangles of the facet are listed.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct Change {
    pub removed: Vec<[u32; 3]>,
    pub added: Vec<[u32; 3]>,
}

/// Why [`FacetMesh::insert`] did nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum InsertError {
    /// The point is outside the facet (beyond its boundary or in a hole).
    Outside,
    /// The point projects exactly onto this existing vertex.
    OnVertex(u32),
    /// The point lies exactly on this subsegment (smaller id first): use
    /// [`FacetMesh::split_edge`].
    OnConstrainedEdge(u32, u32),
    /// The id is already a vertex of this facet (or is `u32::MAX`, reserved).
    IdInUse(u32),
    /// A coordinate is NaN or infinite.
    NotFinite,
}

/// Why [`FacetMesh::split_edge`] did nothing.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SplitError {
    /// (a, b) is not an edge of the facet's triangulation.
    NotAnEdge(u32, u32),
    /// The id is already a vertex of this facet (or is `u32::MAX`, reserved).
    IdInUse(u32),
    /// A coordinate is NaN or infinite.
    NotFinite,
    /// The point is so far off the segment that an adjacent triangle would be inverted.
    WouldInvert,
}

impl std::fmt::Display for InsertError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "facet insertion refused: {self:?}")
    }
}
impl std::error::Error for InsertError {}

impl std::fmt::Display for SplitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "facet edge split refused: {self:?}")
    }
}
impl std::error::Error for SplitError {}

/// A facet's constrained Delaunay triangulation; see the module documentation.
#[derive(Clone, Debug)]
pub struct FacetMesh {
    tris: Vec<Tri>,
    /// Local vertex -> global id (NONE for the 3 super-triangle vertices, locals 0..3).
    gid: Vec<u32>,
    p3: Vec<DVec3>,
    /// Projected coordinates (exact copies of two 3D coordinates).
    p2: Vec<DVec2>,
    /// Local vertex -> one triangle holding it.
    vtri: Vec<u32>,
    local: FxHashMap<u32, u32>,
    /// 3D axes used as 2D (u, v).
    axes: [usize; 2],
    normal: DVec3,
    /// The lifting point E off the plane.
    eye: DVec3,
    n_inside: usize,
    expected_area: Option<f64>,
    /// Walk start: a triangle at the last inserted vertex.
    hint: u32,
}

/// Vector area (twice the area, along the right-hand normal) of a closed polygon.
fn newell(points: &[DVec3], poly: &[u32]) -> DVec3 {
    let o = points[poly[0] as usize];
    let mut s = DVec3::ZERO;
    for i in 1..poly.len().saturating_sub(1) {
        s += (points[poly[i] as usize] - o).cross(points[poly[i + 1] as usize] - o);
    }
    s
}

/// Exact winding of a simple polygon: orientation at its lexicographically smallest vertex
/// (> 0 ccw, < 0 cw, 0 degenerate). Also returns that vertex's position in `poly`.
fn winding(poly: &[u32], p: impl Fn(u32) -> DVec2) -> (f64, usize) {
    let n = poly.len();
    let lex = |a: DVec2, b: DVec2| a.x.total_cmp(&b.x).then(a.y.total_cmp(&b.y));
    let m = (0..n).min_by(|&i, &j| lex(p(poly[i]), p(poly[j]))).unwrap();
    let o = orient2d(p(poly[(m + n - 1) % n]), p(poly[m]), p(poly[(m + 1) % n]));
    (o, m)
}

/// The polygon's edges: closed for 3+ vertices, one edge for 2, none for 1.
fn poly_edges(poly: &[u32]) -> impl Iterator<Item = (u32, u32)> + '_ {
    let n = poly.len();
    let m = match n {
        0 | 1 => 0,
        2 => 1,
        _ => n,
    };
    (0..m).map(move |i| (poly[i], poly[(i + 1) % n]))
}

impl FacetMesh {
    /// Triangulates a facet: `outer` polygons (vertex ids into `points`, in order; a 2-vertex
    /// polygon is a lone segment, a 1-vertex one a lone point), `holes` polygons whose inside is
    /// removed, and TetGen-style `hole_points` whose region (bounded by polygon edges) is removed.
    /// All polygon edges become constrained edges; vertices lying exactly on one split it.
    /// The result is the constrained Delaunay triangulation of the region.
    ///
    /// Errors (with ids and coordinates in the message): an id out of range or a bad coordinate,
    /// no outer polygon with positive area, two vertices projecting to the same point, crossing
    /// polygon edges, a constrained edge left entirely outside the facet, an empty facet.
    pub fn new(
        points: &[DVec3],
        outer: &[Vec<u32>],
        holes: &[Vec<u32>],
        hole_points: &[DVec3],
    ) -> Result<FacetMesh, String> {
        let clean = |poly: &Vec<u32>| {
            let mut c = poly.clone();
            c.dedup();
            while c.len() > 1 && c.first() == c.last() {
                c.pop();
            }
            c
        };
        let outer: Vec<Vec<u32>> = outer.iter().map(clean).filter(|p| !p.is_empty()).collect();
        let holes: Vec<Vec<u32>> = holes.iter().map(clean).collect();
        let (mut ids, mut seen) = (Vec::new(), FxHashMap::default());
        let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
        for &id in outer.iter().chain(&holes).flatten() {
            ensure!((id as usize) < points.len(), "vertex id {id} out of range");
            let p = points[id as usize];
            check_coordinate(p).map_err(|e| format!("vertex {id} at {p}: {e}"))?;
            if seen.insert(id, ()).is_none() {
                (lo, hi) = (lo.min(p), hi.max(p));
                ids.push(id);
            }
        }
        for &h in hole_points {
            check_coordinate(h).map_err(|e| format!("hole point {h}: {e}"))?;
        }
        let short = holes.iter().find(|h| h.len() < 3);
        ensure!(short.is_none(), "hole {short:?}: under 3 vertices");

        // Normal and projection from the outer polygon with the largest area; the exact winding
        // at its extreme vertex orders the 2D axes so that it is counter-clockwise.
        let (best, nrm) = outer
            .iter()
            .filter(|p| p.len() >= 3)
            .map(|p| (p, newell(points, p)))
            .max_by(|a, b| a.1.length_squared().total_cmp(&b.1.length_squared()))
            .ok_or("facet has no outer polygon with 3 or more vertices")?;
        let k = (0..3).fold(0, |k, i| if nrm[i].abs() > nrm[k].abs() { i } else { k });
        let ok = nrm[k] != 0.0 && nrm.is_finite();
        ensure!(ok, "outer polygon {best:?} has no area");
        let cyc = [(k + 1) % 3, (k + 2) % 3];
        let (w, m) = winding(best, |id| {
            let p = points[id as usize];
            DVec2::new(p[cyc[0]], p[cyc[1]])
        });
        ensure!(w != 0.0, "polygon {best:?} degenerate/not simple");
        let s = w.signum();
        let axes = if s > 0.0 { cyc } else { [cyc[1], cyc[0]] };
        let normal = nrm.normalize() * if nrm[k] * s < 0.0 { -1.0 } else { 1.0 };
        // The lifting point: above the polygon's extreme vertex, on the normal's side.
        let n = best.len();
        let v0 = points[best[m] as usize];
        let eye = v0 + DVec3::AXES[k] * (s * (hi - lo).max_element());
        let [a, b] = [best[(m + n - 1) % n], best[(m + 1) % n]].map(|i| points[i as usize]);
        let ok = orient3d(a, v0, b, eye) > 0.0;
        ensure!(ok, "polygon {best:?} is too far from planar");

        let mut fm = FacetMesh {
            tris: Vec::with_capacity(2 * ids.len() + 8),
            gid: Vec::new(),
            p3: Vec::new(),
            p2: Vec::new(),
            vtri: Vec::new(),
            local: FxHashMap::default(),
            axes,
            normal,
            eye,
            n_inside: 0,
            expected_area: None,
            hint: 0,
        };
        // Super-triangle well around the bounding box, its vertices put (in float) on the plane
        // through v0 so that the lifting treats them like the others.
        let (lo2, hi2) = (fm.proj(lo), fm.proj(hi));
        let (c, r) = ((lo2 + hi2) * 0.5, (hi2 - lo2).max_element() * 0.5);
        for (du, dv) in [(-20.0, -10.0), (20.0, -10.0), (0.0, 20.0)] {
            let (mut p, [iu, iv]) = (DVec3::ZERO, axes);
            (p[iu], p[iv]) = (c.x + du * r, c.y + dv * r);
            p[k] = v0[k] - (nrm[iu] * (p[iu] - v0[iu]) + nrm[iv] * (p[iv] - v0[iv])) / nrm[k];
            fm.add_vertex(NONE, p);
        }
        fm.new_tri();
        fm.put(0, [0, 1, 2], 0);
        // BRIO + Hilbert order: points along a polygon in order (e.g. a circle) would cost O(n)
        // flips each; this keeps construction near O(n log n).
        let order = brio_order(
            &ids.iter().map(|&i| points[i as usize]).collect::<Vec<_>>(),
            1,
        );
        for id in order.into_iter().map(|k| ids[k as usize]) {
            let p = points[id as usize];
            match fm.walk(fm.proj(p)) {
                Loc::Vertex(t, i) => {
                    let other = fm.gid[fm.tris[t as usize].v[i] as usize];
                    return Err(format!("vertices {other} and {id} coincide ({p})"));
                }
                Loc::Outside => return Err(format!("internal: vertex {id} off super-triangle")),
                loc => {
                    let (l, new) = fm.place(loc, id, p);
                    fm.legalize(l, new, &mut Vec::new());
                    fm.hint = fm.vtri[l as usize];
                }
            }
        }

        let loc = |fm: &FacetMesh, id: u32| fm.local[&id];
        for poly in &outer {
            for (a, b) in poly_edges(poly) {
                fm.recover(loc(&fm, a), loc(&fm, b))?;
            }
        }
        // Flood fill the removed regions from the super-triangle, the inner side of each hole
        // polygon edge and the hole points; constrained edges bound it.
        let mut seeds = vec![fm.vtri[0]];
        for poly in &holes {
            let (w, _) = winding(poly, |id| fm.p2[loc(&fm, id) as usize]);
            ensure!(w != 0.0, "hole {poly:?} degenerate/not simple");
            for (a, b) in poly_edges(poly) {
                for e in fm.recover(loc(&fm, a), loc(&fm, b))?.windows(2) {
                    let (t, i) = fm.find_edge(e[0], e[1]).unwrap();
                    let left = fm.tris[t as usize].v[nx(i)] == e[0];
                    let other = fm.tris[t as usize].n[i] / 3;
                    seeds.push(if left == (w > 0.0) { t } else { other });
                }
            }
        }
        for &h in hole_points {
            if let Loc::In(t) | Loc::Edge(t, _) | Loc::Vertex(t, _) = fm.walk(fm.proj(h)) {
                seeds.push(t);
            }
        }
        let mut out = vec![false; fm.tris.len()];
        while let Some(t) = seeds.pop() {
            if !std::mem::replace(&mut out[t as usize], true) {
                let tr = fm.tris[t as usize];
                let open = |&i: &usize| !tr.cons(i) && tr.n[i] != NONE;
                seeds.extend((0..3).filter(open).map(|i| tr.n[i] / 3));
            }
        }
        for (tr, _) in fm.tris.iter_mut().zip(&out).filter(|(_, &o)| !o) {
            tr.f |= INSIDE;
            fm.n_inside += 1;
        }
        ensure!(fm.n_inside > 0, "holes cover the whole facet");
        for tr in &fm.tris {
            for i in (0..3).filter(|&i| tr.cons(i) && !tr.inside()) {
                if !fm.tris[(tr.n[i] / 3) as usize].inside() {
                    let e = fm.edge_ids(tr, i);
                    return Err(format!("polygon edge {e:?} lies outside the facet"));
                }
            }
        }
        fm.make_cdt()?;
        fm.hint = fm.tris.iter().position(|t| t.inside()).unwrap() as u32;
        if hole_points.is_empty() {
            let area = |p: &Vec<u32>| 0.5 * newell(points, p).length(); // 0 for 1 or 2 vertices
            let a: f64 = outer.iter().map(area).sum::<f64>() - holes.iter().map(area).sum::<f64>();
            fm.expected_area = Some(a);
        }
        Ok(fm)
    }

    /// Inserts vertex `id` at `p` (a point of the facet, possibly a rounding error off its plane)
    /// and restores the constrained Delaunay property by Lawson flips (constrained edges never
    /// flip). Points outside the facet, on an existing vertex or exactly on a subsegment are
    /// refused and nothing changes.
    pub fn insert(&mut self, id: u32, p: DVec3) -> Result<Change, InsertError> {
        if id == NONE || self.local.contains_key(&id) {
            return Err(InsertError::IdInUse(id));
        }
        let (t, i) = self.insertion_place(p)?;
        let tr = self.tris[t as usize];
        let mut removed = vec![self.gtri(t)];
        if i < 3 {
            removed.push(self.gtri(tr.n[i] / 3));
        }
        let loc = if i < 3 { Loc::Edge(t, i) } else { Loc::In(t) };
        let (l, new) = self.place(loc, id, p);
        self.n_inside += 2;
        Ok(self.finish(l, new, removed))
    }

    /// Walking in a straight line from the centroid of facet triangle `tri` (global ids)
    /// towards `p`, the first constrained edge crossed (global ids), if the line leaves through
    /// one before reaching `p`. This is the subsegment to split when a subfacet's circumcentre
    /// lies beyond the facet's boundary (Ruppert's rule, without assuming the subsegment is
    /// encroached).
    pub fn constrained_edge_towards(&self, tri: [u32; 3], p: DVec3) -> Option<[u32; 2]> {
        let (t0, i0) = self.facet_edge(tri[0], tri[1])?;
        let apex = *self.local.get(&tri[2])?;
        let t0 = if self.tris[t0 as usize].find(apex).is_some() {
            t0
        } else {
            self.tris[t0 as usize].n[i0] / 3
        };
        self.tris[t0 as usize].find(apex)?;
        let target = self.proj(p);
        let tr = self.tris[t0 as usize];
        let start = tr.v.iter().map(|&v| self.p2[v as usize]).sum::<DVec2>() / 3.0;
        let mut t = t0;
        for _ in 0..self.tris.len() {
            let tr = self.tris[t as usize];
            // Leave through edge i when the target is strictly beyond it and the line from
            // the start crosses it.
            let exit = (0..3).find(|&i| {
                let (x, y) = (self.p2[tr.v[nx(i)] as usize], self.p2[tr.v[pv(i)] as usize]);
                orient2d(x, y, target) < 0.0
                    && orient2d(start, target, x) <= 0.0
                    && orient2d(start, target, y) >= 0.0
            })?;
            if tr.cons(exit) {
                return Some(self.edge_ids(&tr, exit));
            }
            let r = tr.n[exit];
            if r == NONE {
                return None;
            }
            t = r / 3;
        }
        None
    }

    /// Whether [`FacetMesh::insert`] would accept `p` (the same checks, nothing changes).
    pub fn can_insert(&self, p: DVec3) -> Result<(), InsertError> {
        self.insertion_place(p).map(|_| ())
    }

    /// Where `p` would be inserted: (triangle, edge index or 3 for its interior).
    fn insertion_place(&self, p: DVec3) -> Result<(u32, usize), InsertError> {
        if !p.is_finite() {
            return Err(InsertError::NotFinite);
        }
        let loc = self.walk(self.proj(p));
        let (t, i) = match loc {
            Loc::Outside => return Err(InsertError::Outside),
            Loc::Vertex(t, i) => {
                let v = self.tris[t as usize].v[i];
                return match self.find_in_star(v, |t, _| self.tris[t as usize].inside()) {
                    Some(_) => Err(InsertError::OnVertex(self.gid[v as usize])),
                    None => Err(InsertError::Outside),
                };
            }
            Loc::Edge(t, i) => (t, i),
            Loc::In(t) => (t, 3),
        };
        let tr = self.tris[t as usize];
        if i < 3 && tr.cons(i) {
            let [a, b] = self.edge_ids(&tr, i);
            return Err(InsertError::OnConstrainedEdge(a, b));
        }
        if !tr.inside() {
            return Err(InsertError::Outside);
        }
        Ok((t, i))
    }

    /// Whether splitting edge ab at `p` would leave both adjacent triangles (inside or outside
    /// the facet) positively oriented; false also when ab is not an edge.
    pub fn can_split(&self, a: u32, b: u32, p: DVec3) -> bool {
        self.facet_edge(a, b)
            .is_some_and(|(t, i)| self.split_keeps_orientation(t, i, p))
    }

    fn split_keeps_orientation(&self, t: u32, i: usize, p: DVec3) -> bool {
        let q = self.proj(p);
        let tr = self.tris[t as usize];
        let u = tr.n[i] / 3;
        let ur = self.tris[u as usize];
        let j = (tr.n[i] % 3) as usize;
        let (c, x, y, d) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)], ur.v[j]);
        let pp = |v: u32| self.p2[v as usize];
        orient2d(pp(c), pp(x), q) > 0.0
            && orient2d(pp(c), q, pp(y)) > 0.0
            && orient2d(pp(d), pp(y), q) > 0.0
            && orient2d(pp(d), q, pp(x)) > 0.0
    }

    /// Splits the edge (a, b) (normally a subsegment) at vertex `id` placed at `p`, a point
    /// near the segment (a float midpoint: need not be exactly on it). The edge is replaced by
    /// a-p and p-b, both constrained if ab was; the one or two adjacent facet triangles are split,
    /// then Lawson flips restore the constrained Delaunay property. On error nothing changes.
    pub fn split_edge(&mut self, a: u32, b: u32, id: u32, p: DVec3) -> Result<Change, SplitError> {
        if id == NONE || self.local.contains_key(&id) {
            return Err(SplitError::IdInUse(id));
        }
        if !p.is_finite() {
            return Err(SplitError::NotFinite);
        }
        let (t, i) = self.facet_edge(a, b).ok_or(SplitError::NotAnEdge(a, b))?;
        if !self.split_keeps_orientation(t, i, p) {
            return Err(SplitError::WouldInvert);
        }
        let tr = self.tris[t as usize];
        let u = tr.n[i] / 3;
        let mut removed = Vec::new();
        for s in [t, u] {
            if self.tris[s as usize].inside() {
                removed.push(self.gtri(s));
                self.n_inside += 1;
            }
        }
        let (l, new) = self.place(Loc::Edge(t, i), id, p);
        Ok(self.finish(l, new, removed))
    }

    /// Flips the non-constrained facet edge (a, b) if its quadrilateral is strictly convex
    /// (whatever the in-circle test says). Returns whether it flipped.
    pub fn flip(&mut self, a: u32, b: u32) -> bool {
        self.flip_change(a, b).is_some()
    }

    /// As [`FacetMesh::flip`], returning the two removed and two added triangles.
    pub fn flip_change(&mut self, a: u32, b: u32) -> Option<Change> {
        let (t, i) = self.facet_edge(a, b)?;
        let tr = self.tris[t as usize];
        let u = tr.n[i] / 3;
        if tr.cons(i) || !tr.inside() {
            return None;
        }
        let d = self.tris[u as usize].v[(tr.n[i] % 3) as usize];
        if !self.convex(tr.v[i], tr.v[nx(i)], tr.v[pv(i)], d) {
            return None;
        }
        let removed = vec![self.gtri(t), self.gtri(u)];
        self.flip_at(t, i);
        let added = vec![self.gtri(t), self.gtri(u)];
        Some(Change { removed, added })
    }

    /// The facet triangle holding p (projected on the facet plane; closed triangles, a point on
    /// a shared edge or vertex gets one of them), or None if p is outside the facet.
    pub fn locate(&self, p: DVec3) -> Option<[u32; 3]> {
        let t = match self.walk(self.proj(p)) {
            Loc::Outside => return None,
            Loc::In(t) => t,
            Loc::Edge(t, i) => match self.tris[t as usize].n[i] {
                u if u != NONE && !self.tris[t as usize].inside() => u / 3,
                _ => t,
            },
            Loc::Vertex(t, i) => {
                let v = self.tris[t as usize].v[i];
                self.find_in_star(v, |s, _| self.tris[s as usize].inside())
                    .map_or(t, |(s, _)| s)
            }
        };
        self.tris[t as usize].inside().then(|| self.gtri(t))
    }

    /// All triangles of the facet (global ids, ccw about [`FacetMesh::normal`], smallest id
    /// first).
    pub fn triangles(&self) -> Vec<[u32; 3]> {
        self.facet_tris().map(|t| self.gtri(t)).collect()
    }

    /// Number of triangles of the facet.
    pub fn num_triangles(&self) -> usize {
        self.n_inside
    }

    /// The facet triangles around vertex `id` (empty if it is not a vertex).
    pub fn triangles_around(&self, id: u32) -> Vec<[u32; 3]> {
        self.local.get(&id).map_or(Vec::new(), |&l| self.star(l))
    }

    /// All constrained edges (subsegments), each once as [min id, max id].
    pub fn constrained_edges(&self) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        for (t, tr) in self.tris.iter().enumerate() {
            for i in 0..3 {
                if tr.cons(i) && (t as u32) * 3 + (i as u32) < tr.n[i] {
                    out.push(self.edge_ids(tr, i));
                }
            }
        }
        out
    }

    /// Whether (a, b) is a constrained edge (subsegment) of this facet.
    pub fn is_constrained(&self, a: u32, b: u32) -> bool {
        self.facet_edge(a, b)
            .is_some_and(|(t, i)| self.tris[t as usize].cons(i))
    }

    /// For a facet edge (a, b): the apexes of the facet triangles to its left (the triangle
    /// (a, b, c) ccw) and to its right ((b, a, d) ccw); `None` on a side outside the facet.
    /// Returns None if (a, b) is not an edge of the facet.
    pub fn opposite(&self, a: u32, b: u32) -> Option<[Option<u32>; 2]> {
        let (t, i) = self.facet_edge(a, b)?;
        let tr = self.tris[t as usize];
        let r = tr.n[i];
        let ur = self.tris[(r / 3) as usize];
        let side = |s: &Tri, k: usize| s.inside().then(|| self.gid[s.v[k] as usize]);
        let (mine, theirs) = (side(&tr, i), side(&ur, (r % 3) as usize));
        let a_first = self.gid[tr.v[nx(i)] as usize] == a;
        Some([[mine, theirs], [theirs, mine]][!a_first as usize])
    }

    /// Global ids of all vertices (polygon vertices and inserted ones).
    pub fn vertices(&self) -> impl Iterator<Item = u32> + '_ {
        self.gid[3..].iter().copied()
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.gid.len() - 3
    }

    /// The 3D position of vertex `id`.
    pub fn point(&self, id: u32) -> Option<DVec3> {
        self.local.get(&id).map(|&l| self.p3[l as usize])
    }

    /// Unit normal: triangles are counter-clockwise seen from the side it points to.
    pub fn normal(&self) -> DVec3 {
        self.normal
    }

    /// Sum of the 3D areas of the facet triangles.
    pub fn area(&self) -> f64 {
        let area = |t: u32| {
            let [a, b, c] = self.tris[t as usize].v.map(|v| self.p3[v as usize]);
            0.5 * (b - a).cross(c - a).length()
        };
        self.facet_tris().map(area).sum()
    }

    /// Full consistency check (for tests; O(n)): adjacency symmetry, ccw orientation of every
    /// triangle, constrained and inside flags consistent across edges, vertex index, Euler count,
    /// constrained Delaunay (no apex strictly inside across a non-constrained facet edge), and
    /// the facet's area against the polygons' area (relative 1e-9; see the module limits).
    pub fn validate(&self) -> Result<(), String> {
        let (nv, nt) = (self.gid.len(), self.tris.len());
        ensure!(nt == 2 * nv - 5, "{nt} triangles for {nv} vertices");
        let mut n_in = 0;
        for (t, tr) in self.tris.iter().enumerate() {
            let ([a, b, c], g) = (tr.v, self.gtri(t as u32));
            let ok = a.max(b).max(c) < nv as u32 && a != b && b != c && c != a;
            ensure!(ok, "triangle {t}: bad vertices");
            let [a, b, c] = tr.v.map(|v| self.p2[v as usize]);
            ensure!(orient2d(a, b, c) > 0.0, "triangle {g:?} not ccw");
            n_in += tr.inside() as usize;
            let ok = !tr.inside() || tr.v.iter().all(|&v| v >= 3);
            ensure!(ok, "triangle {t} uses a temporary vertex");
            for i in 0..3 {
                let (x, y, r) = (tr.v[nx(i)], tr.v[pv(i)], tr.n[i]);
                if r == NONE {
                    ensure!(x < 3 && y < 3, "triangle {t}: no neighbour {i}");
                    continue;
                }
                let (u, j) = ((r / 3) as usize, (r % 3) as usize);
                let ur = self.tris.get(u).ok_or("bad neighbour reference")?;
                let ok = ur.n[j] == (t * 3 + i) as u32 && ur.v[nx(j)] == y && ur.v[pv(j)] == x;
                ensure!(ok, "triangles {t}, {u} disagree");
                let (cons, inside) = (tr.cons(i), tr.inside());
                ensure!(cons == ur.cons(j), "constrained flag {t}|{u}");
                let ok = cons || inside == ur.inside();
                ensure!(ok, "unconstrained boundary {t}|{u}");
                let ok = !cons || inside || ur.inside();
                ensure!(ok, "constrained edge {t}|{u} outside");
                let bad = inside && !cons && self.incircle(tr.v[i], x, y, ur.v[j]);
                let d = self.gid[ur.v[j] as usize];
                ensure!(!bad, "{d} in the circle of {g:?}");
            }
        }
        ensure!(n_in == self.n_inside, "facet triangle count");
        for v in 0..nv {
            let tr = self.tris.get(self.vtri[v] as usize);
            let ok = tr.and_then(|tr| tr.find(v as u32)).is_some();
            ensure!(ok, "vertex {} has a stale triangle", self.gid[v]);
            let ok = v < 3 || self.local.get(&self.gid[v]) == Some(&(v as u32));
            ensure!(ok, "vertex {} not in the id map", self.gid[v]);
        }
        if let Some(exp) = self.expected_area {
            let got = self.area();
            let ok = (got - exp).abs() <= 1e-9 * exp.abs();
            ensure!(ok, "triangles' area {got}, polygons' {exp}");
        }
        Ok(())
    }

    // ---------------------------------------------------------------- internals

    /// Slots of the facet's triangles.
    fn facet_tris(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tris.len() as u32).filter(|&t| self.tris[t as usize].inside())
    }

    fn proj(&self, p: DVec3) -> DVec2 {
        DVec2::new(p[self.axes[0]], p[self.axes[1]])
    }

    fn add_vertex(&mut self, id: u32, p: DVec3) -> u32 {
        let l = self.gid.len() as u32;
        self.gid.push(id);
        self.p3.push(p);
        self.p2.push(self.proj(p));
        self.vtri.push(NONE);
        if id != NONE {
            self.local.insert(id, l);
        }
        l
    }

    /// Adds vertex `id` at `p` in the triangle or on the edge `loc`; returns its local index and
    /// the triangles around it.
    fn place(&mut self, loc: Loc, id: u32, p: DVec3) -> (u32, Vec<u32>) {
        let l = self.add_vertex(id, p);
        match loc {
            Loc::In(t) => (l, self.split_tri(t, l).to_vec()),
            Loc::Edge(t, i) => (l, self.split_edge_at(t, i, l)),
            _ => unreachable!("place: {loc:?}"),
        }
    }

    /// The vertex across neighbour reference `r` (the apex of the other triangle).
    fn apex(&self, r: u32) -> u32 {
        self.tris[(r / 3) as usize].v[(r % 3) as usize]
    }

    /// A triangle's global ids, canonical.
    fn gtri(&self, t: u32) -> [u32; 3] {
        canon(self.tris[t as usize].v.map(|v| self.gid[v as usize]))
    }

    /// Exact "d strictly inside the circle of ccw (a, b, c)" through the lifting from `eye`,
    /// for d across edge (b, c). Symmetric: equals "a inside the circle of (d, c, b)". It reads
    /// the sign from a triangle whose lifted tet is positive; a nearly flat triangle of points
    /// off the plane may have a non-positive one, and if both do the edge is left as it is.
    fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool {
        let [a, b, c, d] = [a, b, c, d].map(|v| self.p3[v as usize]);
        if orient3d(a, b, c, self.eye) > 0.0 {
            insphere(a, b, c, self.eye, d) > 0.0
        } else {
            orient3d(d, c, b, self.eye) > 0.0 && insphere(d, c, b, self.eye, a) > 0.0
        }
    }

    /// Whether replacing diagonal (x, y) of the quad (c, x, d, y) by (c, d) gives two ccw
    /// triangles (c, x, d), (d, y, c).
    fn convex(&self, c: u32, x: u32, y: u32, d: u32) -> bool {
        let [c, x, y, d] = [c, x, y, d].map(|v| self.p2[v as usize]);
        orient2d(c, x, d) > 0.0 && orient2d(d, y, c) > 0.0
    }

    /// Sets neighbour `i` of `t` to `r` and the back reference.
    fn set_nb(&mut self, t: u32, i: usize, r: u32) {
        self.tris[t as usize].n[i] = r;
        if r != NONE {
            self.tris[(r / 3) as usize].n[(r % 3) as usize] = t * 3 + i as u32;
        }
    }

    /// Overwrites triangle `t` (neighbours unset) and points its vertices at it.
    fn put(&mut self, t: u32, v: [u32; 3], f: u8) {
        self.tris[t as usize] = Tri { v, n: [NONE; 3], f };
        for w in v {
            self.vtri[w as usize] = t;
        }
    }

    fn new_tri(&mut self) -> u32 {
        self.tris.push(Tri::default());
        (self.tris.len() - 1) as u32
    }

    /// Renumbers `t` so that its old index `i` becomes 0.
    fn rotate(&mut self, t: u32, i: usize) {
        if i == 0 {
            return;
        }
        let o = self.tris[t as usize];
        let mut r = Tri {
            v: [0; 3],
            n: [0; 3],
            f: o.f & INSIDE,
        };
        for k in 0..3 {
            let s = (k + i) % 3;
            r.v[k] = o.v[s];
            r.n[k] = o.n[s];
            r.f |= ((o.f >> s) & 1) << k;
        }
        self.tris[t as usize] = r;
        for k in 0..3 {
            self.set_nb(t, k, r.n[k]);
        }
    }

    /// Splits triangle `t` into three around local vertex `p`; returns them.
    fn split_tri(&mut self, t: u32, p: u32) -> [u32; 3] {
        let o = self.tris[t as usize];
        let ids = [t, self.new_tri(), self.new_tri()];
        for k in 0..3 {
            let mut v = o.v;
            v[k] = p;
            self.put(ids[k], v, (o.f & INSIDE) | (o.f & (1 << k)));
        }
        for k in 0..3 {
            self.set_nb(ids[k], k, o.n[k]);
            for j in 0..3 {
                if j != k {
                    self.tris[ids[k] as usize].n[j] = ids[j] * 3 + k as u32;
                }
            }
        }
        ids
    }

    /// Splits edge `i` of `t` (and the triangle across) at local vertex `p`; returns the new
    /// triangles (2 or 4).
    fn split_edge_at(&mut self, t: u32, i: usize, p: u32) -> Vec<u32> {
        self.rotate(t, i);
        let tv = self.tris[t as usize];
        let (r, [a, x, y]) = (tv.n[0], tv.v);
        let c = tv.f & 1;
        let t2 = self.new_tri();
        self.put(t, [a, x, p], (tv.f & INSIDE) | c | (tv.f & 4));
        self.put(t2, [a, p, y], (tv.f & INSIDE) | c | (tv.f & 2));
        self.set_nb(t, 2, tv.n[2]);
        self.set_nb(t2, 1, tv.n[1]);
        self.set_nb(t, 1, t2 * 3 + 2);
        if r == NONE {
            return vec![t, t2];
        }
        let u = r / 3;
        self.rotate(u, (r % 3) as usize);
        let uv = self.tris[u as usize]; // [b, y, x]
        let b = uv.v[0];
        let u2 = self.new_tri();
        self.put(u, [b, y, p], (uv.f & INSIDE) | c | (uv.f & 4));
        self.put(u2, [b, p, x], (uv.f & INSIDE) | c | (uv.f & 2));
        self.set_nb(u, 2, uv.n[2]);
        self.set_nb(u2, 1, uv.n[1]);
        self.set_nb(u, 1, u2 * 3 + 2);
        self.set_nb(u, 0, t2 * 3);
        self.set_nb(u2, 0, t * 3);
        vec![t, t2, u, u2]
    }

    /// Flips edge `i` of `t`: (a, x, y) + (b, y, x) become (a, x, b) + (b, y, a) in the same
    /// slots; returns the other slot. The caller checks convexity and the constraint.
    fn flip_at(&mut self, t: u32, i: usize) -> u32 {
        self.rotate(t, i);
        let r = self.tris[t as usize].n[0];
        let u = r / 3;
        self.rotate(u, (r % 3) as usize);
        let (tv, uv) = (self.tris[t as usize], self.tris[u as usize]);
        let [a, x, y] = tv.v;
        let b = uv.v[0];
        let bit = |f: u8, k: usize| (f >> k) & 1;
        let ft = (tv.f & INSIDE) | bit(uv.f, 1) | (bit(tv.f, 2) << 2);
        let fu = (uv.f & INSIDE) | bit(tv.f, 1) | (bit(uv.f, 2) << 2);
        self.put(t, [a, x, b], ft);
        self.put(u, [b, y, a], fu);
        self.set_nb(t, 0, uv.n[1]);
        self.set_nb(t, 2, tv.n[2]);
        self.set_nb(u, 0, tv.n[1]);
        self.set_nb(u, 2, uv.n[2]);
        self.set_nb(t, 1, u * 3 + 1);
        u
    }

    /// Whether edge `i` of `t` is non-constrained, not locally Delaunay and flippable.
    fn should_flip(&self, t: u32, i: usize) -> bool {
        let tr = self.tris[t as usize];
        if tr.cons(i) || tr.n[i] == NONE {
            return false;
        }
        let (c, x, y, d) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)], self.apex(tr.n[i]));
        self.incircle(c, x, y, d) && self.convex(c, x, y, d)
    }

    /// Lawson flips around the new vertex `p`, starting from triangles holding it; records the
    /// facet triangles flipped away (they never hold `p`, so they pre-existed).
    fn legalize(&mut self, p: u32, mut stack: Vec<u32>, removed: &mut Vec<[u32; 3]>) {
        // Safety net only: with a consistent lifting the flips terminate long before this.
        let mut budget = 4 * self.tris.len() + 64;
        while let Some(t) = stack.pop() {
            let Some(k) = self.tris[t as usize].find(p) else {
                continue;
            };
            if budget == 0 || !self.should_flip(t, k) {
                continue;
            }
            budget -= 1;
            let u = self.tris[t as usize].n[k] / 3;
            if self.tris[u as usize].inside() {
                removed.push(self.gtri(u));
            }
            self.flip_at(t, k);
            stack.push(t);
            stack.push(u);
        }
    }

    /// Lawson flips after an insertion, then the Change (added = facet triangles around `l`).
    fn finish(&mut self, l: u32, new: Vec<u32>, mut removed: Vec<[u32; 3]>) -> Change {
        self.legalize(l, new, &mut removed);
        self.hint = self.vtri[l as usize];
        let added = self.star(l);
        Change { removed, added }
    }

    /// The facet triangles (global ids) around local vertex `l`.
    fn star(&self, l: u32) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        self.find_in_star(l, |t, _| {
            if self.tris[t as usize].inside() {
                out.push(self.gtri(t));
            }
            false
        });
        out
    }

    /// Visits the triangles around local vertex `v` as (triangle, index of v) until `f` says
    /// stop; returns where it stopped.
    fn find_in_star(&self, v: u32, mut f: impl FnMut(u32, usize) -> bool) -> Option<(u32, usize)> {
        let t0 = self.vtri[v as usize];
        let k0 = self.tris[t0 as usize].find(v).expect("vertex index");
        let (mut t, mut k) = (t0, k0);
        loop {
            if f(t, k) {
                return Some((t, k));
            }
            let r = self.tris[t as usize].n[nx(k)]; // counter-clockwise
            if r == NONE {
                break;
            }
            (t, k) = (r / 3, nx((r % 3) as usize));
            if t == t0 {
                return None;
            }
        }
        // Open star (a super-triangle vertex): go clockwise from the start too.
        (t, k) = (t0, k0);
        loop {
            let r = self.tris[t as usize].n[pv(k)];
            if r == NONE {
                return None;
            }
            (t, k) = (r / 3, pv((r % 3) as usize));
            if f(t, k) {
                return Some((t, k));
            }
        }
    }

    /// Edge between local vertices a and b as (triangle, edge index), if it exists.
    fn find_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let (t, k) = self.find_in_star(a, |t, k| {
            let v = self.tris[t as usize].v;
            v[nx(k)] == b || v[pv(k)] == b
        })?;
        let v = self.tris[t as usize].v;
        Some((t, if v[nx(k)] == b { pv(k) } else { nx(k) }))
    }

    /// Edge (a, b) by global ids, if it is an edge with a facet triangle on one side.
    fn facet_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let (&la, &lb) = (self.local.get(&a)?, self.local.get(&b)?);
        let (t, i) = self.find_edge(la, lb)?;
        let r = self.tris[t as usize].n[i];
        let inside = |s: u32| self.tris[s as usize].inside();
        (inside(t) || (r != NONE && inside(r / 3))).then_some((t, i))
    }

    /// Stochastic visibility walk from the hint to projected point q.
    fn walk(&self, q: DVec2) -> Loc {
        let (mut t, mut came) = (self.hint, 3);
        let mut rng = (q.x.to_bits() ^ q.y.to_bits().rotate_left(29)) as u32 | 1;
        for _ in 0..4 * self.tris.len() + 64 {
            let tr = self.tris[t as usize];
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            let s = (rng % 3) as usize;
            let mut zero = [false; 3];
            let mut next = None;
            for m in 0..3 {
                let i = (s + m) % 3;
                if i == came {
                    continue;
                }
                let o = self.side(&tr, i, q);
                if o < 0.0 {
                    next = Some(i);
                    break;
                }
                zero[i] = o == 0.0;
            }
            match next {
                Some(i) => {
                    if tr.n[i] == NONE {
                        return Loc::Outside;
                    }
                    (t, came) = (tr.n[i] / 3, (tr.n[i] % 3) as usize);
                }
                None => return Self::classify(t, zero),
            }
        }
        // Unreachable in practice (the stochastic walk terminates); scan as a fallback.
        for (t, tr) in self.tris.iter().enumerate() {
            let o = [0, 1, 2].map(|i| self.side(tr, i, q));
            if o.iter().all(|&x| x >= 0.0) {
                return Self::classify(t as u32, o.map(|x| x == 0.0));
            }
        }
        Loc::Outside
    }

    /// orient2d of edge `i` of `tr` (as the triangle runs) and q: > 0 on the triangle's side.
    fn side(&self, tr: &Tri, i: usize, q: DVec2) -> f64 {
        let [a, b] = [nx(i), pv(i)].map(|k| self.p2[tr.v[k] as usize]);
        orient2d(a, b, q)
    }

    /// Global ids of edge `i` of `tr`, smaller first.
    fn edge_ids(&self, tr: &Tri, i: usize) -> [u32; 2] {
        let [a, b] = [nx(i), pv(i)].map(|k| self.gid[tr.v[k] as usize]);
        [a.min(b), a.max(b)]
    }

    fn classify(t: u32, zero: [bool; 3]) -> Loc {
        let pos = |z: bool| zero.iter().position(|&x| x == z).unwrap();
        match zero.iter().filter(|&&z| z).count() {
            0 => Loc::In(t),
            1 => Loc::Edge(t, pos(true)),
            _ => Loc::Vertex(t, pos(false)),
        }
    }

    /// Recovers the constrained edge between local vertices a and b; returns the chain of
    /// vertices along it (split at vertices lying exactly on it).
    fn recover(&mut self, a: u32, b: u32) -> Result<Vec<u32>, String> {
        let mut chain = vec![a];
        let mut s = a;
        while s != b {
            let (e, cross) = self.trace(s, b)?;
            if !cross.is_empty() {
                self.flip_out(s, e, cross)?;
            }
            let (t, i) = self.find_edge(s, e).ok_or("internal: lost edge")?;
            self.tris[t as usize].f |= 1 << i;
            let r = self.tris[t as usize].n[i];
            self.tris[(r / 3) as usize].f |= 1 << (r % 3);
            chain.push(e);
            s = e;
        }
        Ok(chain)
    }

    /// From vertex s towards b: the first vertex met (b, or one exactly on the segment) and
    /// the edges crossed before it, as (right, left) pairs.
    fn trace(&self, s: u32, b: u32) -> Result<(u32, Vec<(u32, u32)>), String> {
        let (ps, pb) = (self.p2[s as usize], self.p2[b as usize]);
        let mut hit = None;
        let start = self.find_in_star(s, |t, k| {
            let tr = &self.tris[t as usize];
            let (v1, v2) = (tr.v[nx(k)], tr.v[pv(k)]);
            let o1 = orient2d(ps, self.p2[v1 as usize], pb);
            let o2 = orient2d(ps, self.p2[v2 as usize], pb);
            if o2 < 0.0 && o1 == 0.0 {
                hit = Some(v1);
            }
            o2 < 0.0 && o1 >= 0.0
        });
        if let Some(h) = hit {
            return Ok((h, Vec::new()));
        }
        let (mut t, mut e) = start.ok_or("internal: constraint direction not found")?;
        let mut cross = Vec::new();
        loop {
            let tr = self.tris[t as usize];
            let (v1, v2) = (tr.v[nx(e)], tr.v[pv(e)]);
            if tr.cons(e) {
                let [s, b, v1, v2] = [s, b, v1, v2].map(|v| self.gid[v as usize]);
                return Err(format!("polygon edges cross: ({s}, {b}) and ({v1}, {v2})"));
            }
            cross.push((v1, v2));
            let r = tr.n[e];
            ensure!(r != NONE, "internal: constraint left the super-triangle");
            let (u, j, w) = (r / 3, (r % 3) as usize, self.apex(r));
            if w == b {
                return Ok((b, cross));
            }
            let ow = orient2d(ps, pb, self.p2[w as usize]);
            if ow == 0.0 {
                return Ok((w, cross));
            }
            // u = (w, v2, v1): keep crossing through (v1, w) or (w, v2).
            (t, e) = (u, if ow > 0.0 { nx(j) } else { pv(j) });
        }
    }

    /// Sloan's edge recovery: flips the edges crossing segment (s, e) until none is left.
    fn flip_out(&mut self, s: u32, e: u32, cross: Vec<(u32, u32)>) -> Result<(), String> {
        let (ps, pe) = (self.p2[s as usize], self.p2[e as usize]);
        let mut queue: VecDeque<(u32, u32)> = cross.into();
        let mut stall = 0;
        while let Some((x, y)) = queue.pop_front() {
            let (t, i) = self.find_edge(x, y).ok_or("internal: lost edge")?;
            let tr = self.tris[t as usize];
            let (c, d) = (tr.v[i], self.apex(tr.n[i]));
            if self.convex(c, tr.v[nx(i)], tr.v[pv(i)], d) {
                self.flip_at(t, i);
                stall = 0;
                let oc = orient2d(ps, pe, self.p2[c as usize]);
                let od = orient2d(ps, pe, self.p2[d as usize]);
                if (oc > 0.0 && od < 0.0) || (oc < 0.0 && od > 0.0) {
                    queue.push_back((c, d));
                }
            } else {
                queue.push_back((x, y));
                stall += 1;
                ensure!(stall <= queue.len(), "internal: edge recovery stalled");
            }
        }
        Ok(())
    }

    /// Lawson flips over the whole triangulation (after edge recovery). Flips reuse the two
    /// triangle slots, so a stack of slots stays valid; a flipped pair is checked again.
    fn make_cdt(&mut self) -> Result<(), String> {
        let mut stack: Vec<u32> = (0..self.tris.len() as u32).collect();
        let mut budget = self.tris.len().saturating_mul(self.tris.len()) + 10_000;
        while let Some(t) = stack.pop() {
            if let Some(i) = (0..3).find(|&i| self.should_flip(t, i)) {
                ensure!(budget > 0, "internal: too many flips");
                budget -= 1;
                stack.extend([t, self.flip_at(t, i)]);
            }
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;
    use std::collections::HashSet;

    /// `f(s, t)` for flat (s, t) pairs.
    fn map2(c: &[f64], f: impl Fn(f64, f64) -> DVec3) -> Vec<DVec3> {
        c.chunks(2).map(|c| f(c[0], c[1])).collect()
    }
    fn xy(c: &[f64]) -> Vec<DVec3> {
        map2(c, p)
    }
    fn p(x: f64, y: f64) -> DVec3 {
        DVec3::new(x, y, 0.0)
    }
    const SQUARE: [f64; 8] = [0., 0., 1., 0., 1., 1., 0., 1.];
    const SQUARE_HOLE: [f64; 16] = [
        0., 0., 4., 0., 4., 4., 0., 4., 1., 1., 3., 1., 3., 3., 1., 3.,
    ];
    /// Points of the plane through `o` spanned by `u`, `v` (exact for small integer s, t).
    fn plane(o: DVec3, u: DVec3, v: DVec3) -> impl Fn(f64, f64) -> DVec3 {
        move |s, t| o + u * s + v * t
    }

    /// Keeps a set of subfacets in sync through the Change lists and checks it.
    struct Tracker(HashSet<[u32; 3]>);
    impl Tracker {
        fn new(m: &FacetMesh) -> Self {
            Tracker(m.triangles().into_iter().collect())
        }
        fn apply(&mut self, ch: &Change, m: &FacetMesh) {
            assert!(
                ch.removed.iter().all(|r| self.0.remove(r)),
                "removed a non-triangle"
            );
            assert!(
                ch.added.iter().all(|a| self.0.insert(*a)),
                "added a triangle twice"
            );
            assert_eq!(self.0, m.triangles().into_iter().collect::<HashSet<_>>());
            assert_eq!(self.0.len(), m.num_triangles());
        }
    }

    fn check_ccw(m: &FacetMesh) {
        for t in m.triangles() {
            let [a, b, c] = t.map(|i| m.point(i).unwrap());
            assert!((b - a).cross(c - a).dot(m.normal()) > 0.0, "{t:?} not ccw");
        }
    }

    /// `n` random operations, each checked against a Tracker: with probability `split` a
    /// subsegment split at a float point near its middle (not exactly on the line), else an
    /// insertion of `f(s, t)`, s, t in [0, 1), or (one in four) of the float circumcentre of a
    /// random subfacet. A refusal must change nothing; a point on a subsegment splits it.
    /// Validates every 100 steps and at the end.
    fn drive(m: &mut FacetMesh, n: usize, split: f64, seed: u64, f: impl Fn(f64, f64) -> DVec3) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let (mut tr, mut id) = (Tracker::new(m), 1_000_000 + m.num_vertices() as u32);
        for step in 0..n {
            let before = m.triangles();
            let ch = if rng.gen_bool(split) {
                let segs = m.constrained_edges();
                let [a, b] = segs[rng.gen_range(0..segs.len())];
                let (pa, pb) = (m.point(a).unwrap(), m.point(b).unwrap());
                let ch = m.split_edge(a, b, id, pa.lerp(pb, rng.gen_range(0.3..0.7)));
                assert!(m.is_constrained(a, id) && m.is_constrained(id, b));
                assert!(!m.is_constrained(a, b));
                ch.unwrap()
            } else {
                let tris = m.triangles();
                let [a, b, c] = tris[rng.gen_range(0..tris.len())].map(|i| m.point(i).unwrap());
                let (ab, ac) = (b - a, c - a);
                let (n, l2) = (ab.cross(ac), [ab.length_squared(), ac.length_squared()]);
                let cc = a + (n.cross(ab) * l2[1] + ac.cross(n) * l2[0]) / n.length_squared() / 2.;
                let q = [f(rng.gen(), rng.gen()), cc][rng.gen_bool(0.25) as usize];
                match m.insert(id, q) {
                    Ok(ch) => ch,
                    Err(InsertError::OnConstrainedEdge(a, b)) => m.split_edge(a, b, id, q).unwrap(),
                    Err(_) => {
                        assert_eq!(before, m.triangles());
                        continue;
                    }
                }
            };
            tr.apply(&ch, m);
            id += 1;
            if step % 100 == 0 {
                m.validate().unwrap_or_else(|e| panic!("step {step}: {e}"));
            }
        }
        m.validate().unwrap();
        check_ccw(m);
    }

    #[test]
    fn unit_square_windings_flips_opposite() {
        let pts = xy(&SQUARE);
        let r = FacetMesh::new(&pts, &[vec![3, 2, 1, 0, 3]], &[], &[]).unwrap();
        r.validate().unwrap();
        assert_eq!(r.normal(), -DVec3::Z);
        check_ccw(&r);
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
        m.validate().unwrap();
        assert_eq!((m.num_triangles(), m.constrained_edges().len()), (2, 4));
        assert_eq!((m.normal(), m.area()), (DVec3::Z, 1.0));
        check_ccw(&m);
        let (a, b) = [(1, 3), (0, 2)][m.opposite(0, 2).is_some() as usize];
        let [l, r] = m.opposite(a, b).unwrap();
        assert!(l.is_some() && r.is_some() && l != r);
        let c = if a == 0 { 2 } else { 3 };
        assert_eq!(m.opposite(0, 1).unwrap(), [Some(c), None]);
        assert_eq!(m.opposite(1, 0).unwrap()[0], None);
        let mut tr = Tracker::new(&m);
        let before = tr.0.clone();
        tr.apply(&m.flip_change(a, b).unwrap(), &m);
        m.validate().unwrap(); // cocircular: both diagonals are Delaunay
        assert!(m.opposite(a, b).is_none() && m.flip(l.unwrap(), r.unwrap()));
        assert_eq!(Tracker::new(&m).0, before);
        assert!(!m.flip(0, 1) && !m.flip(0, 9));
        // a non-convex quad does not flip
        let pts = xy(&[0., 0., 4., 0., 1., 1., 0., 4.]);
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
        assert!(m.opposite(0, 2).is_some() && !m.flip(0, 2));
    }

    #[test]
    fn l_shape_and_holes() {
        let pts = xy(&[0., 0., 2., 0., 2., 1., 1., 1., 1., 2., 0., 2.]);
        let mut m = FacetMesh::new(&pts, &[(0..6).collect()], &[], &[]).unwrap();
        m.validate().unwrap();
        assert_eq!((m.num_triangles(), m.area()), (4, 3.0));
        assert_eq!(m.locate(p(1.5, 1.5)), None);
        assert!(m.locate(p(0.5, 1.5)).is_some() && m.locate(p(1., 1.)).is_some());
        assert_eq!(m.insert(10, p(1.5, 1.5)), Err(InsertError::Outside));
        drive(&mut m, 400, 0.2, 7, |x, y| p(2.0 * x, 2.0 * y));
        assert!(m.num_vertices() > 200 && m.num_vertices() < 400);
        // square with a square hole given as a polygon of either winding
        let pts = xy(&SQUARE_HOLE);
        for hole in [vec![4, 5, 6, 7], vec![7, 6, 5, 4]] {
            let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[hole], &[]).unwrap();
            m.validate().unwrap();
            assert_eq!((m.num_triangles(), m.constrained_edges().len()), (8, 8));
            assert_eq!(m.locate(p(2., 2.)), None);
            drive(&mut m, 300, 0.2, 3, |x, y| p(4. * x, 4. * y));
            assert!((m.area() - 12.0).abs() < 1e-12);
        }
        // TetGen style: the inner polygon is an outer one, the hole is marked by a point
        let outer = [vec![0, 1, 2, 3], vec![4, 5, 6, 7]];
        let mut m = FacetMesh::new(&pts, &outer, &[], &[p(2., 2.)]).unwrap();
        m.validate().unwrap();
        assert_eq!((m.num_triangles(), m.area()), (8, 12.0));
        drive(&mut m, 300, 0.2, 4, |x, y| p(4. * x, 4. * y));
        assert!((m.area() - 12.0).abs() < 1e-12);
        // without the hole point the inner polygon is only imprinted
        let m = FacetMesh::new(&pts, &outer, &[], &[]).unwrap();
        assert_eq!(m.num_triangles(), 10);
        assert!(m.locate(p(2., 2.)).is_some());
        // an island inside a hole stays
        let mut pts = pts.clone();
        pts.extend(xy(&[1.5, 1.5, 2.5, 1.5, 2.5, 2.5, 1.5, 2.5]));
        let outer = [vec![0, 1, 2, 3], vec![8, 9, 10, 11]];
        let m = FacetMesh::new(&pts, &outer, &[vec![4, 5, 6, 7]], &[]).unwrap();
        m.validate().unwrap();
        assert_eq!(m.area(), 13.0);
        assert!(m.locate(p(2., 2.)).is_some() && m.locate(p(1.2, 2.)).is_none());
    }

    #[test]
    fn tilted_planes() {
        // x + 2y + 3z = 6 (dominant axis z) and 3x - y - 2z = -7 (dominant x, reversed winding)
        let cases = [
            ([6., 0., 0.], [-2., 1., 0.], [-3., 0., 1.], false),
            ([1., 2., 3.], [1., 3., 0.], [0., -2., 1.], true),
        ];
        for (o, u, v, rev) in cases {
            let (u, v) = (DVec3::from(u), DVec3::from(v));
            let f = plane(o.into(), u, v);
            // an L with a collinear vertex at (4, 0), and a square hole
            let (c, h) = (
                [0., 0., 4., 0., 8., 0., 8., 4., 4., 4., 4., 8., 0., 8.],
                [1., 1., 3., 1.],
            );
            let pts = [map2(&c, &f), map2(&h, &f), map2(&[3., 3., 1., 3.], &f)].concat();
            let mut outer: Vec<u32> = (0..7).collect();
            if rev {
                outer.reverse();
            }
            let mut m = FacetMesh::new(&pts, &[outer], &[vec![7, 8, 9, 10]], &[]).unwrap();
            m.validate().unwrap();
            let n = u.cross(v);
            assert!(m.normal().dot(n) * if rev { -1.0 } else { 1.0 } > 0.0);
            assert!(m.is_constrained(0, 1) && m.is_constrained(1, 2) && !m.is_constrained(0, 2));
            let (mut tr, exact) = (Tracker::new(&m), [5., 1., 6., 2., 1., 6., 2., 5.]);
            for (k, &q) in map2(&exact, &f).iter().enumerate() {
                tr.apply(&m.insert(100 + k as u32, q).unwrap(), &m); // exactly on the plane
            }
            drive(&mut m, 500, 0.2, 11, |s, t| f(8.0 * s, 8.0 * t)); // a rounding error off it
            assert!((m.area() - 44.0 * n.length()).abs() < 1e-9 * m.area());
        }
    }

    #[test]
    fn random_insertions_into_square() {
        let mut m = FacetMesh::new(&xy(&SQUARE), &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
        drive(&mut m, 500, 0.0, 1, p);
        let (nv, nb) = (m.num_vertices(), m.constrained_edges().len());
        assert!(nv > 450 && m.num_triangles() == 2 * nv - nb - 2);
        let mut rng = ChaCha8Rng::seed_from_u64(5);
        for _ in 0..200 {
            let q = p(rng.gen(), rng.gen());
            let [a, b, c] = m.locate(q).unwrap().map(|i| m.proj(m.point(i).unwrap()));
            let q = m.proj(q);
            let ok = |(x, y): (DVec2, DVec2)| orient2d(x, y, q) >= 0.0;
            assert!([(a, b), (b, c), (c, a)].into_iter().all(ok));
        }
        // many more: stays fast (walk + flips, not O(n) per insertion)
        let t0 = std::time::Instant::now();
        for id in 10..20_010 {
            m.insert(id, p(rng.gen(), rng.gen())).unwrap();
        }
        assert!(t0.elapsed().as_secs_f64() < 10.0, "{:?}", t0.elapsed());
        m.validate().unwrap();
    }

    #[test]
    fn grid_20x20_cocircular() {
        let pts = xy(&SQUARE.map(|c| 19. * c));
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
        let mut tr = Tracker::new(&m);
        let mut grid: Vec<u32> = (10..410).collect();
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for i in (1..grid.len()).rev() {
            grid.swap(i, rng.gen_range(0..=i));
        }
        for id in grid {
            let q = p(((id - 10) % 20) as f64, ((id - 10) / 20) as f64);
            let ch = match m.insert(id, q) {
                Ok(ch) => ch,
                Err(InsertError::OnConstrainedEdge(a, b)) => m.split_edge(a, b, id, q).unwrap(),
                Err(InsertError::OnVertex(_)) => continue, // a corner
                Err(e) => panic!("{e}"),
            };
            tr.apply(&ch, &m);
        }
        m.validate().unwrap();
        assert_eq!((m.num_vertices(), m.num_triangles()), (400, 2 * 19 * 19));
        assert_eq!((m.constrained_edges().len(), m.area()), (4 * 19, 361.0));
    }

    #[test]
    fn split_boundary_repeatedly_off_the_line() {
        let [o, u, v] = [[0.1, 0.2, 0.3], [0.7, 0.1, -0.3], [-0.2, 0.9, 0.4]].map(DVec3::from);
        let f = plane(o, u, v);
        let pts = map2(&[0., 0., 3., 0., 3., 2., 1., 3., 0., 2.], &f);
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3, 4]], &[], &[]).unwrap();
        m.validate().unwrap();
        // split points are not exactly on the segments
        let off = (1..50).filter(|&k| {
            let q = pts[0].lerp(pts[1], k as f64 / 50.0);
            orient2d(m.proj(pts[0]), m.proj(pts[1]), m.proj(q)) != 0.0
        });
        assert!(off.count() > 10);
        let area = m.area();
        drive(&mut m, 500, 0.8, 9, |s, t| f(3. * s, 3. * t));
        assert!(m.constrained_edges().len() > 300);
        assert!((m.area() - area).abs() < 1e-9 * area);
    }

    #[test]
    fn refusals_change_nothing() {
        let pts = xy(&SQUARE_HOLE);
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[vec![4, 5, 6, 7]], &[]).unwrap();
        let before = m.triangles();
        for (q, e) in [
            (p(5., 1.), InsertError::Outside),
            (p(500., -1e6), InsertError::Outside),
            (p(2., 2.), InsertError::Outside),
            (p(2., 0.), InsertError::OnConstrainedEdge(0, 1)),
            (p(2., 1.), InsertError::OnConstrainedEdge(4, 5)),
            (p(4., 4.), InsertError::OnVertex(2)),
            (p(f64::NAN, 0.5), InsertError::NotFinite),
        ] {
            assert_eq!(m.insert(50, q), Err(e));
        }
        assert_eq!(m.insert(3, p(0.5, 0.5)), Err(InsertError::IdInUse(3)));
        for (a, b, id, q, e) in [
            (0, 2, 50, p(2., 2.), SplitError::NotAnEdge(0, 2)),
            (0, 1, 50, p(2., 3.5), SplitError::WouldInvert),
            (0, 1, 1, p(2., 0.), SplitError::IdInUse(1)),
        ] {
            assert_eq!(m.split_edge(a, b, id, q), Err(e));
        }
        assert_eq!((m.triangles(), m.num_vertices()), (before, 8));
        m.validate().unwrap();
        assert_eq!((m.locate(p(2., 2.)), m.locate(p(9., 9.))), (None, None));
        assert!(m.locate(p(2., 0.)).is_some() && m.locate(p(2., 1.)).is_some());
    }

    #[test]
    fn points_and_segments_inside_polygons() {
        let pts = [
            0., 0., 1., 0., 1., 1., 0., 1., 0.5, 0., 0.25, 0.5, 0.75, 0.5, 0.5, 0.25, 0.5, 0.75,
        ];
        let mut pts = xy(&pts);
        pts.push(p(0.25, 0.5));
        // a lone point on a boundary edge splits it
        let m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3], vec![4]], &[], &[]).unwrap();
        m.validate().unwrap();
        assert!(m.is_constrained(0, 4) && m.is_constrained(4, 1) && !m.is_constrained(0, 1));
        // a dangling segment is an inner subsegment
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3], vec![5, 6]], &[], &[]).unwrap();
        m.validate().unwrap();
        assert!(m.is_constrained(5, 6) && m.opposite(5, 6).unwrap().iter().all(|x| x.is_some()));
        let e = m.insert(20, p(0.5, 0.5));
        assert_eq!(e, Err(InsertError::OnConstrainedEdge(5, 6)));
        m.split_edge(5, 6, 20, p(0.5, 0.5)).unwrap();
        m.validate().unwrap();
        // errors: crossing segments, coincident vertices, no area, bad id
        let e = |outer: &[Vec<u32>]| FacetMesh::new(&pts, outer, &[], &[]).unwrap_err();
        assert!(e(&[vec![0, 1, 2, 3], vec![5, 6], vec![7, 8]]).contains("cross"));
        assert!(e(&[vec![0, 1, 2, 3], vec![5, 9]]).contains("coincide"));
        assert!(e(&[vec![0, 1, 4]]).contains("area"));
        assert!(e(&[vec![0, 1, 99]]).contains("range"));
    }

    /// Random star-shaped polygons (some with integer, collinear vertices) with a square hole,
    /// on randomly rotated planes (coordinates rounded: not exactly coplanar).
    #[test]
    fn random_polygons_on_rotated_planes() {
        for seed in 0..12u64 {
            let mut rng = ChaCha8Rng::seed_from_u64(seed);
            let axis = DVec3::new(rng.gen(), rng.gen(), rng.gen::<f64>() + 0.1).normalize();
            let q = glam::DQuat::from_axis_angle(axis, rng.gen_range(0.0..6.0));
            let f = move |s: f64, t: f64| q * DVec3::new(s, t, 0.0) + DVec3::new(0.1, 2.3, -0.7);
            let n = rng.gen_range(3..60);
            let round = |x: f64| if seed % 2 == 0 { x.round() } else { x };
            let mut st: Vec<(f64, f64)> = (0..n)
                .map(|i| {
                    let (a, r) = (
                        i as f64 / n as f64 * std::f64::consts::TAU,
                        rng.gen_range(3.0..5.0),
                    );
                    (round(a.cos() * r), round(a.sin() * r))
                })
                .collect();
            st.dedup();
            while st.len() > 1 && st.first() == st.last() {
                st.pop();
            }
            let k = st.len() as u32;
            st.extend([(-1., -1.), (1., -1.), (1., 1.), (-1., 1.)]);
            let pts: Vec<DVec3> = st.iter().map(|&(s, t)| f(s, t)).collect();
            let hole = vec![k, k + 1, k + 2, k + 3];
            let mut m = FacetMesh::new(&pts, &[(0..k).collect()], &[hole], &[]).unwrap();
            m.validate().unwrap();
            let g = |s: f64, t: f64| f(10. * s - 5., 10. * t - 5.);
            drive(&mut m, 800, 0.25, seed, g);
        }
    }
}
