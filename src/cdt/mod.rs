//! The 2D constrained Delaunay triangulation of one planar facet (its "subfacets"), a kernel
//! beside `delaunay` (the 3D one) that refinement keeps one of per input facet.
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

/// A polygon without repeated consecutive vertices and without a repeated first vertex at
/// its end.
fn clean_polygon(poly: &[u32]) -> Vec<u32> {
    let mut c = poly.to_vec();
    c.dedup();
    while c.len() > 1 && c.first() == c.last() {
        c.pop();
    }
    c
}

/// The distinct vertex ids of the polygons, in order of first appearance, and their bounding
/// box, after checking every id and coordinate (hole points included) and that every hole
/// has 3 or more vertices.
fn checked_vertices(
    points: &[DVec3],
    outer: &[Vec<u32>],
    holes: &[Vec<u32>],
    hole_points: &[DVec3],
) -> Result<(Vec<u32>, DVec3, DVec3), String> {
    let (mut ids, mut seen) = (Vec::new(), FxHashMap::default());
    let (mut lo, mut hi) = (DVec3::INFINITY, DVec3::NEG_INFINITY);
    for &id in outer.iter().chain(holes).flatten() {
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
    Ok((ids, lo, hi))
}

/// How a facet is projected to 2D and lifted for the in-circle test (see the module comment).
struct Plane {
    /// The dominant axis of the normal, dropped by the projection.
    k: usize,
    /// The 3D axes used as 2D (u, v), ordered so that the largest outer polygon is ccw.
    axes: [usize; 2],
    /// That polygon's vector area (Newell).
    nrm: DVec3,
    /// The unit normal, on the side from which that polygon is seen ccw.
    normal: DVec3,
    /// That polygon's vertex where its winding is read (lexicographically smallest in 2D).
    v0: DVec3,
    /// The lifting point E, off the plane on the normal's side.
    eye: DVec3,
}

impl Plane {
    /// Normal and projection from the outer polygon with the largest area; the exact winding
    /// at its extreme vertex orders the 2D axes so that it is counter-clockwise. `lo`, `hi`:
    /// the bounding box of the facet's vertices.
    fn of(points: &[DVec3], outer: &[Vec<u32>], lo: DVec3, hi: DVec3) -> Result<Plane, String> {
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
        Ok(Plane {
            k,
            axes,
            nrm,
            normal,
            v0,
            eye,
        })
    }
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
        let outer: Vec<Vec<u32>> = outer
            .iter()
            .map(|p| clean_polygon(p))
            .filter(|p| !p.is_empty())
            .collect();
        let holes: Vec<Vec<u32>> = holes.iter().map(|p| clean_polygon(p)).collect();
        let (ids, lo, hi) = checked_vertices(points, &outer, &holes, hole_points)?;
        let plane = Plane::of(points, &outer, lo, hi)?;
        let mut fm = FacetMesh {
            tris: Vec::with_capacity(2 * ids.len() + 8),
            gid: Vec::new(),
            p3: Vec::new(),
            p2: Vec::new(),
            vtri: Vec::new(),
            local: FxHashMap::default(),
            axes: plane.axes,
            normal: plane.normal,
            eye: plane.eye,
            n_inside: 0,
            expected_area: None,
            hint: 0,
        };
        fm.add_super_triangle(&plane, lo, hi);
        fm.insert_vertices(points, &ids)?;
        let loc = |fm: &FacetMesh, id: u32| fm.local[&id];
        for poly in &outer {
            for (a, b) in poly_edges(poly) {
                fm.recover(loc(&fm, a), loc(&fm, b))?;
            }
        }
        let seeds = fm.removed_region_seeds(&holes, hole_points)?;
        fm.mark_inside(seeds)?;
        fm.make_cdt()?;
        fm.hint = fm.tris.iter().position(|t| t.inside()).unwrap() as u32;
        if hole_points.is_empty() {
            let area = |p: &Vec<u32>| 0.5 * newell(points, p).length(); // 0 for 1 or 2 vertices
            let a: f64 = outer.iter().map(area).sum::<f64>() - holes.iter().map(area).sum::<f64>();
            fm.expected_area = Some(a);
        }
        fm.shrink_to_fit();
        Ok(fm)
    }

    /// Gives back the spare capacity of a new facet's arrays: a PLC can have many small facets
    /// (a partition's interfaces are one facet a triangle), most of which are never split.
    fn shrink_to_fit(&mut self) {
        self.tris.shrink_to_fit();
        self.gid.shrink_to_fit();
        self.p3.shrink_to_fit();
        self.p2.shrink_to_fit();
        self.vtri.shrink_to_fit();
        self.local.shrink_to_fit();
    }

    /// The area [`Self::validate`] expects the facet's triangles to cover, when the caller
    /// knows it better than the polygons say (outer polygons that nest, as in TetGen's .poly,
    /// where a hole's outline is a polygon of the facet too).
    pub fn expect_area(&mut self, area: f64) {
        self.expected_area = Some(area);
    }

    /// The super-triangle, well around the bounding box (`lo`, `hi`), its vertices put (in
    /// float) on the plane through `plane.v0` so that the lifting treats them like the others.
    fn add_super_triangle(&mut self, plane: &Plane, lo: DVec3, hi: DVec3) {
        let (lo2, hi2) = (self.proj(lo), self.proj(hi));
        let (c, r) = ((lo2 + hi2) * 0.5, (hi2 - lo2).max_element() * 0.5);
        let (k, v0, nrm) = (plane.k, plane.v0, plane.nrm);
        for (du, dv) in [(-20.0, -10.0), (20.0, -10.0), (0.0, 20.0)] {
            let (mut p, [iu, iv]) = (DVec3::ZERO, plane.axes);
            (p[iu], p[iv]) = (c.x + du * r, c.y + dv * r);
            p[k] = v0[k] - (nrm[iu] * (p[iu] - v0[iu]) + nrm[iv] * (p[iv] - v0[iv])) / nrm[k];
            self.add_vertex(NONE, p);
        }
        self.new_tri();
        self.put(0, [0, 1, 2], 0);
    }

    /// Inserts the polygon vertices `ids` (Delaunay insertion, Lawson flips). BRIO + Hilbert
    /// order: points along a polygon in order (e.g. a circle) would cost O(n) flips each; this
    /// keeps construction near O(n log n).
    fn insert_vertices(&mut self, points: &[DVec3], ids: &[u32]) -> Result<(), String> {
        let order = brio_order(
            &ids.iter().map(|&i| points[i as usize]).collect::<Vec<_>>(),
            1,
        );
        for id in order.into_iter().map(|k| ids[k as usize]) {
            let p = points[id as usize];
            match self.walk(self.proj(p)) {
                Loc::Vertex(t, i) => {
                    let other = self.gid[self.tris[t as usize].v[i] as usize];
                    return Err(format!("vertices {other} and {id} coincide ({p})"));
                }
                Loc::Outside => return Err(format!("internal: vertex {id} off super-triangle")),
                loc => {
                    let (l, new) = self.place(loc, id, p);
                    self.legalize(l, new, &mut Vec::new());
                    self.hint = self.vtri[l as usize];
                }
            }
        }
        Ok(())
    }

    /// Recovers the hole polygons' edges and returns the seeds of the removed regions: the
    /// super-triangle, the inner side of each hole polygon edge and the triangles holding the
    /// hole points.
    fn removed_region_seeds(
        &mut self,
        holes: &[Vec<u32>],
        hole_points: &[DVec3],
    ) -> Result<Vec<u32>, String> {
        let loc = |fm: &FacetMesh, id: u32| fm.local[&id];
        let mut seeds = vec![self.vtri[0]];
        for poly in holes {
            let (w, _) = winding(poly, |id| self.p2[loc(self, id) as usize]);
            ensure!(w != 0.0, "hole {poly:?} degenerate/not simple");
            for (a, b) in poly_edges(poly) {
                for e in self.recover(loc(self, a), loc(self, b))?.windows(2) {
                    let (t, i) = self.find_edge(e[0], e[1]).unwrap();
                    let left = self.tris[t as usize].v[nx(i)] == e[0];
                    let other = self.tris[t as usize].n[i] / 3;
                    seeds.push(if left == (w > 0.0) { t } else { other });
                }
            }
        }
        for &h in hole_points {
            if let Loc::In(t) | Loc::Edge(t, _) | Loc::Vertex(t, _) = self.walk(self.proj(h)) {
                seeds.push(t);
            }
        }
        Ok(seeds)
    }

    /// Flood fills the removed regions from `seeds` (constrained edges bound it) and flags
    /// every other triangle inside the facet; fails if nothing is left or a polygon edge has
    /// the removed region on both sides.
    fn mark_inside(&mut self, mut seeds: Vec<u32>) -> Result<(), String> {
        let mut out = vec![false; self.tris.len()];
        while let Some(t) = seeds.pop() {
            if !std::mem::replace(&mut out[t as usize], true) {
                let tr = self.tris[t as usize];
                let open = |&i: &usize| !tr.cons(i) && tr.n[i] != NONE;
                seeds.extend((0..3).filter(open).map(|i| tr.n[i] / 3));
            }
        }
        for (tr, _) in self.tris.iter_mut().zip(&out).filter(|(_, &o)| !o) {
            tr.f |= INSIDE;
            self.n_inside += 1;
        }
        ensure!(self.n_inside > 0, "holes cover the whole facet");
        for tr in &self.tris {
            for i in (0..3).filter(|&i| tr.cons(i) && !tr.inside()) {
                if !self.tris[(tr.n[i] / 3) as usize].inside() {
                    let e = self.edge_ids(tr, i);
                    return Err(format!("polygon edge {e:?} lies outside the facet"));
                }
            }
        }
        Ok(())
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
        self.locate_from(self.hint, p)
    }

    /// [`Self::locate`], walking from a triangle at vertex `near` (a global id of the facet;
    /// else from the last insertion): short when `near` is close to `p`, wherever the facet
    /// was changed last.
    pub fn locate_near(&self, p: DVec3, near: u32) -> Option<[u32; 3]> {
        let start = self
            .local
            .get(&near)
            .map_or(self.hint, |&l| self.vtri[l as usize]);
        self.locate_from(start, p)
    }

    fn locate_from(&self, start: u32, p: DVec3) -> Option<[u32; 3]> {
        let t = match self.walk_from(start, self.proj(p)) {
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
        self.validate_with(true)
    }

    /// [`Self::validate`] without the constrained Delaunay property: what must hold after
    /// [`Self::flip`] took a diagonal the 3D triangulation chose (refinement matches it).
    pub fn validate_structure(&self) -> Result<(), String> {
        self.validate_with(false)
    }

    fn validate_with(&self, delaunay: bool) -> Result<(), String> {
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
                let bad = delaunay && inside && !cons && self.incircle(tr.v[i], x, y, ur.v[j]);
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
}

mod ops;
#[cfg(test)]
mod tests;
