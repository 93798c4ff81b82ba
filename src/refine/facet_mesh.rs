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
//!   one consistent lifting (inversion centred at E), so Lawson flips stay consistent. A triangle
//!   with orient3d(a, b, c, E) <= 0 (possible only for nearly degenerate triangles of non-planar
//!   points) is treated as never violated.
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
//! vertices (Lawson flips), recovery of each polygon edge by Sloan's flip algorithm (a vertex
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

use crate::geom::{check_coordinate, insphere, orient3d};
use glam::{DVec2, DVec3};
use rustc_hash::FxHashMap;
use std::collections::VecDeque;
use std::sync::atomic::{AtomicU32, Ordering::Relaxed};

/// "No neighbour" (super-triangle hull edge) / global id of the temporary vertices.
const NONE: u32 = u32::MAX;
/// Flag bit: triangle is part of the facet.
const INSIDE: u8 = 8;

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
    /// The point lies exactly on this subsegment: use [`FacetMesh::split_edge`].
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
        match self {
            InsertError::Outside => write!(f, "point outside the facet"),
            InsertError::OnVertex(v) => write!(f, "point coincides with vertex {v}"),
            InsertError::OnConstrainedEdge(a, b) => write!(f, "point on subsegment ({a}, {b})"),
            InsertError::IdInUse(v) => write!(f, "vertex id {v} already used"),
            InsertError::NotFinite => write!(f, "point is not finite"),
        }
    }
}
impl std::error::Error for InsertError {}

impl std::fmt::Display for SplitError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SplitError::NotAnEdge(a, b) => write!(f, "({a}, {b}) is not an edge of the facet"),
            SplitError::IdInUse(v) => write!(f, "vertex id {v} already used"),
            SplitError::NotFinite => write!(f, "point is not finite"),
            SplitError::WouldInvert => write!(f, "split point too far off the segment"),
        }
    }
}
impl std::error::Error for SplitError {}

/// A facet's constrained Delaunay triangulation; see the module documentation.
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
    /// Walk start (last triangle found); atomic so that `locate(&self)` can update it.
    hint: AtomicU32,
}

impl Clone for FacetMesh {
    fn clone(&self) -> Self {
        FacetMesh {
            tris: self.tris.clone(),
            gid: self.gid.clone(),
            p3: self.p3.clone(),
            p2: self.p2.clone(),
            vtri: self.vtri.clone(),
            local: self.local.clone(),
            axes: self.axes,
            normal: self.normal,
            eye: self.eye,
            n_inside: self.n_inside,
            expected_area: self.expected_area,
            hint: AtomicU32::new(self.hint.load(Relaxed)),
        }
    }
}

impl std::fmt::Debug for FacetMesh {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("FacetMesh")
            .field("vertices", &self.num_vertices())
            .field("triangles", &self.n_inside)
            .field("normal", &self.normal)
            .finish()
    }
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
            let mut c: Vec<u32> = Vec::with_capacity(poly.len());
            for &v in poly {
                if c.last() != Some(&v) {
                    c.push(v);
                }
            }
            while c.len() > 1 && c.first() == c.last() {
                c.pop();
            }
            c
        };
        let outer: Vec<Vec<u32>> = outer.iter().map(clean).filter(|p| !p.is_empty()).collect();
        let holes: Vec<Vec<u32>> = holes.iter().map(clean).filter(|p| !p.is_empty()).collect();
        let mut ids: Vec<u32> = Vec::new();
        let mut seen = FxHashMap::default();
        for &id in outer.iter().chain(&holes).flatten() {
            let p = *points
                .get(id as usize)
                .ok_or_else(|| format!("vertex id {id} out of range ({} points)", points.len()))?;
            check_coordinate(p).map_err(|e| format!("vertex {id} at {p}: {e}"))?;
            if seen.insert(id, ()).is_none() {
                ids.push(id);
            }
        }
        for &h in hole_points {
            check_coordinate(h).map_err(|e| format!("hole point {h}: {e}"))?;
        }

        // Normal and projection from the outer polygon with the largest area.
        let (best, nrm) = outer
            .iter()
            .filter(|p| p.len() >= 3)
            .map(|p| (p, newell(points, p)))
            .max_by(|a, b| a.1.length_squared().total_cmp(&b.1.length_squared()))
            .ok_or("facet has no outer polygon with 3 or more vertices")?;
        if nrm.length_squared() == 0.0 || !nrm.is_finite() {
            return Err(format!("outer polygon {best:?} has no area"));
        }
        let a = nrm.abs();
        let k = if a.x >= a.y && a.x >= a.z {
            0
        } else if a.y >= a.z {
            1
        } else {
            2
        };
        let cyc = [(k + 1) % 3, (k + 2) % 3];
        let at = |ax: [usize; 2], id: u32| {
            let p = points[id as usize];
            DVec2::new(p[ax[0]], p[ax[1]])
        };
        let (w, m) = winding(best, |id| at(cyc, id));
        if w == 0.0 {
            return Err(format!(
                "outer polygon {best:?} is degenerate or not simple"
            ));
        }
        let (axes, s) = if w > 0.0 {
            (cyc, 1.0)
        } else {
            ([cyc[1], cyc[0]], -1.0)
        };
        let normal = nrm.normalize() * if nrm[k] * s < 0.0 { -1.0 } else { 1.0 };

        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for &id in &ids {
            lo = lo.min(points[id as usize]);
            hi = hi.max(points[id as usize]);
        }
        let ext = (hi - lo).max_element();
        let v0 = points[best[m] as usize];
        let eye = v0 + DVec3::AXES[k] * (s * ext);
        let n = best.len();
        let tri3 = [best[(m + n - 1) % n], best[m], best[(m + 1) % n]].map(|i| points[i as usize]);
        if orient3d(tri3[0], tri3[1], tri3[2], eye) <= 0.0 {
            return Err(format!("facet polygon {best:?} is too far from planar"));
        }

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
            hint: AtomicU32::new(0),
        };
        // Super-triangle, well around the projected bounding box, its vertices put (in float)
        // on the plane through v0 so that the lifting treats them like the others.
        let (mut lo2, mut hi2) = (DVec2::splat(f64::INFINITY), DVec2::splat(f64::NEG_INFINITY));
        for &id in &ids {
            lo2 = lo2.min(at(axes, id));
            hi2 = hi2.max(at(axes, id));
        }
        let c = (lo2 + hi2) * 0.5;
        let r = (hi2 - lo2).max_element() * 0.5;
        for d in [
            DVec2::new(-20.0, -10.0),
            DVec2::new(20.0, -10.0),
            DVec2::new(0.0, 20.0),
        ] {
            let q = c + d * r;
            let mut p = DVec3::ZERO;
            p[axes[0]] = q.x;
            p[axes[1]] = q.y;
            p[k] = v0[k]
                - (nrm[axes[0]] * (q.x - v0[axes[0]]) + nrm[axes[1]] * (q.y - v0[axes[1]]))
                    / nrm[k];
            fm.add_vertex(NONE, p);
        }
        fm.tris.push(Tri {
            v: [0, 1, 2],
            n: [NONE; 3],
            f: 0,
        });
        fm.vtri = vec![0; 3];

        for &id in &ids {
            let p = points[id as usize];
            let l = match fm.walk(fm.proj(p)) {
                Loc::In(t) => {
                    let l = fm.add_vertex(id, p);
                    let new = fm.split_tri(t, l);
                    fm.legalize(l, new.to_vec(), &mut Vec::new());
                    l
                }
                Loc::Edge(t, i) => {
                    let l = fm.add_vertex(id, p);
                    let new = fm.split_edge_at(t, i, l);
                    fm.legalize(l, new.to_vec(), &mut Vec::new());
                    l
                }
                Loc::Vertex(t, i) => {
                    let other = fm.gid[fm.tris[t as usize].v[i] as usize];
                    return Err(format!(
                        "vertices {other} and {id} coincide in the facet's projection (at {p})"
                    ));
                }
                Loc::Outside => {
                    return Err(format!("internal: vertex {id} outside super-triangle"))
                }
            };
            fm.hint.store(fm.vtri[l as usize], Relaxed);
        }

        let loc = |fm: &FacetMesh, id: u32| fm.local[&id];
        for poly in &outer {
            for (a, b) in poly_edges(poly) {
                fm.recover(loc(&fm, a), loc(&fm, b))?;
            }
        }
        // Seeds of the removed regions: the super-triangle, the inner side of hole polygons,
        // hole points.
        let mut seeds = vec![fm.vtri[0]];
        for poly in &holes {
            let (w, _) = winding(poly, |id| fm.p2[loc(&fm, id) as usize]);
            if poly.len() >= 3 && w == 0.0 {
                return Err(format!("hole polygon {poly:?} is degenerate or not simple"));
            }
            for (a, b) in poly_edges(poly) {
                let chain = fm.recover(loc(&fm, a), loc(&fm, b))?;
                for e in chain.windows(2) {
                    let (t, i) = fm.find_edge(e[0], e[1]).unwrap();
                    let left = fm.tris[t as usize].v[nx(i)] == e[0];
                    let side = if left == (w > 0.0) {
                        t
                    } else {
                        fm.tris[t as usize].n[i] / 3
                    };
                    seeds.push(side);
                }
            }
        }
        for &h in hole_points {
            match fm.walk(fm.proj(h)) {
                Loc::In(t) | Loc::Edge(t, _) | Loc::Vertex(t, _) => seeds.push(t),
                Loc::Outside => {}
            }
        }
        let mut out = vec![false; fm.tris.len()];
        while let Some(t) = seeds.pop() {
            if std::mem::replace(&mut out[t as usize], true) {
                continue;
            }
            let tr = fm.tris[t as usize];
            for i in 0..3 {
                if !tr.cons(i) && tr.n[i] != NONE {
                    seeds.push(tr.n[i] / 3);
                }
            }
        }
        for (t, tr) in fm.tris.iter_mut().enumerate() {
            if !out[t] {
                tr.f |= INSIDE;
                fm.n_inside += 1;
            }
        }
        if fm.n_inside == 0 {
            return Err("the facet has no area left (holes cover it)".into());
        }
        for tr in &fm.tris {
            for i in 0..3 {
                if tr.cons(i) && !tr.inside() && !fm.tris[(tr.n[i] / 3) as usize].inside() {
                    let (a, b) = (fm.gid[tr.v[nx(i)] as usize], fm.gid[tr.v[pv(i)] as usize]);
                    return Err(format!("polygon edge ({a}, {b}) lies outside the facet"));
                }
            }
        }
        fm.make_cdt()?;
        let t = (0..fm.tris.len()).find(|&t| fm.tris[t].inside()).unwrap();
        fm.hint.store(t as u32, Relaxed);
        if hole_points.is_empty() {
            let area = |p: &Vec<u32>| {
                if p.len() >= 3 {
                    0.5 * newell(points, p).length()
                } else {
                    0.0
                }
            };
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
        if !p.is_finite() {
            return Err(InsertError::NotFinite);
        }
        let mut removed = Vec::new();
        let (l, new) = match self.walk(self.proj(p)) {
            Loc::Outside => return Err(InsertError::Outside),
            Loc::Vertex(t, i) => {
                let v = self.tris[t as usize].v[i];
                return match self.find_in_star(v, |t, _| self.tris[t as usize].inside()) {
                    Some(_) => Err(InsertError::OnVertex(self.gid[v as usize])),
                    None => Err(InsertError::Outside),
                };
            }
            Loc::Edge(t, i) => {
                let tr = self.tris[t as usize];
                if tr.cons(i) {
                    let (a, b) = (tr.v[nx(i)], tr.v[pv(i)]);
                    return Err(InsertError::OnConstrainedEdge(
                        self.gid[a as usize],
                        self.gid[b as usize],
                    ));
                }
                if !tr.inside() {
                    return Err(InsertError::Outside);
                }
                removed.push(self.gtri(t));
                removed.push(self.gtri(tr.n[i] / 3));
                let l = self.add_vertex(id, p);
                (l, self.split_edge_at(t, i, l).to_vec())
            }
            Loc::In(t) => {
                if !self.tris[t as usize].inside() {
                    return Err(InsertError::Outside);
                }
                removed.push(self.gtri(t));
                let l = self.add_vertex(id, p);
                (l, self.split_tri(t, l).to_vec())
            }
        };
        self.n_inside += 2;
        Ok(self.finish(l, new, removed))
    }

    /// Splits the edge (a, b) (normally a subsegment) at vertex `id` placed at `p`, a point
    /// near the segment (a float midpoint: need not be exactly on it). The edge is replaced by
    /// a-p and p-b, both constrained if ab was; the one or two adjacent facet triangles are split,
    /// then Lawson flips restore the constrained Delaunay property.
    pub fn split_edge(&mut self, a: u32, b: u32, id: u32, p: DVec3) -> Result<Change, SplitError> {
        if id == NONE || self.local.contains_key(&id) {
            return Err(SplitError::IdInUse(id));
        }
        if !p.is_finite() {
            return Err(SplitError::NotFinite);
        }
        let (t, i) = self.facet_edge(a, b).ok_or(SplitError::NotAnEdge(a, b))?;
        let q = self.proj(p);
        let tr = self.tris[t as usize];
        let u = tr.n[i] / 3;
        let ur = self.tris[u as usize];
        let j = (tr.n[i] % 3) as usize;
        let (c, x, y, d) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)], ur.v[j]);
        let pp = |v: u32| self.p2[v as usize];
        let ok = orient2d(pp(c), pp(x), q) > 0.0
            && orient2d(pp(c), q, pp(y)) > 0.0
            && orient2d(pp(d), pp(y), q) > 0.0
            && orient2d(pp(d), q, pp(x)) > 0.0;
        if !ok {
            return Err(SplitError::WouldInvert);
        }
        let mut removed = Vec::new();
        for s in [t, u] {
            if self.tris[s as usize].inside() {
                removed.push(self.gtri(s));
                self.n_inside += 1;
            }
        }
        let l = self.add_vertex(id, p);
        let new = self.split_edge_at(t, i, l);
        Ok(self.finish(l, new.to_vec(), removed))
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
        Some(Change {
            removed,
            added: vec![self.gtri(t), self.gtri(u)],
        })
    }

    /// The facet triangle holding p (projected on the facet plane; closed triangles, a point on
    /// a shared edge or vertex gets one of them), or None if p is outside the facet.
    pub fn locate(&self, p: DVec3) -> Option<[u32; 3]> {
        let t = match self.walk(self.proj(p)) {
            Loc::Outside => return None,
            Loc::In(t) => t,
            Loc::Edge(t, i) => {
                let u = self.tris[t as usize].n[i];
                if self.tris[t as usize].inside() || u == NONE {
                    t
                } else {
                    u / 3
                }
            }
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
        (0..self.tris.len() as u32)
            .filter(|&t| self.tris[t as usize].inside())
            .map(|t| self.gtri(t))
            .collect()
    }

    /// Number of triangles of the facet.
    pub fn num_triangles(&self) -> usize {
        self.n_inside
    }

    /// The facet triangles around vertex `id` (empty if it is not a vertex).
    pub fn triangles_around(&self, id: u32) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        if let Some(&l) = self.local.get(&id) {
            self.find_in_star(l, |t, _| {
                if self.tris[t as usize].inside() {
                    out.push(self.gtri(t));
                }
                false
            });
        }
        out
    }

    /// All constrained edges (subsegments), each once as [min id, max id].
    pub fn constrained_edges(&self) -> Vec<[u32; 2]> {
        let mut out = Vec::new();
        for (t, tr) in self.tris.iter().enumerate() {
            for i in 0..3 {
                if tr.cons(i) && (t as u32) * 3 + (i as u32) < tr.n[i] {
                    let (a, b) = (
                        self.gid[tr.v[nx(i)] as usize],
                        self.gid[tr.v[pv(i)] as usize],
                    );
                    out.push([a.min(b), a.max(b)]);
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
        Some(if a_first {
            [mine, theirs]
        } else {
            [theirs, mine]
        })
    }

    /// Global ids of all vertices (polygon vertices and inserted ones).
    pub fn vertices(&self) -> impl Iterator<Item = u32> + '_ {
        self.gid[3..].iter().copied()
    }

    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.gid.len() - 3
    }

    /// Whether `id` is a vertex of this facet.
    pub fn contains_vertex(&self, id: u32) -> bool {
        self.local.contains_key(&id)
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
        (0..self.tris.len())
            .filter(|&t| self.tris[t].inside())
            .map(|t| {
                let [a, b, c] = self.tris[t].v.map(|v| self.p3[v as usize]);
                0.5 * (b - a).cross(c - a).length()
            })
            .sum()
    }

    /// Full consistency check (for tests; O(n)): adjacency symmetry, ccw orientation of every
    /// triangle, constrained and inside flags consistent across edges, vertex index, Euler count,
    /// constrained Delaunay (no apex strictly inside across a non-constrained facet edge), and
    /// the facet's area against the polygons' area (relative 1e-9; see the module limits).
    pub fn validate(&self) -> Result<(), String> {
        let nv = self.gid.len();
        if self.tris.len() != 2 * nv - 5 {
            return Err(format!("{} triangles for {nv} vertices", self.tris.len()));
        }
        let mut n_in = 0;
        for (t, tr) in self.tris.iter().enumerate() {
            let g = |k: usize| self.gid[tr.v[k] as usize];
            if tr.v.iter().any(|&v| v as usize >= nv) || tr.v[0] == tr.v[1] || tr.v[1] == tr.v[2] {
                return Err(format!("triangle {t} has bad vertices {:?}", tr.v));
            }
            let [a, b, c] = tr.v.map(|v| self.p2[v as usize]);
            if orient2d(a, b, c) <= 0.0 {
                return Err(format!(
                    "triangle {t} ({}, {}, {}) is not ccw",
                    g(0),
                    g(1),
                    g(2)
                ));
            }
            if tr.inside() {
                n_in += 1;
                if tr.v.iter().any(|&v| v < 3) {
                    return Err(format!("facet triangle {t} uses a temporary vertex"));
                }
            }
            for i in 0..3 {
                let (x, y) = (tr.v[nx(i)], tr.v[pv(i)]);
                let r = tr.n[i];
                if r == NONE {
                    if x >= 3 || y >= 3 {
                        return Err(format!("triangle {t} edge {i} has no neighbour"));
                    }
                    continue;
                }
                let (u, j) = ((r / 3) as usize, (r % 3) as usize);
                let ur = self
                    .tris
                    .get(u)
                    .ok_or(format!("triangle {t}: bad neighbour"))?;
                if ur.n[j] != (t * 3 + i) as u32 || ur.v[nx(j)] != y || ur.v[pv(j)] != x {
                    return Err(format!("triangles {t} and {u} disagree on their edge"));
                }
                if tr.cons(i) != ur.cons(j) {
                    return Err(format!("triangles {t}, {u}: constrained flag differs"));
                }
                if !tr.cons(i) && tr.inside() != ur.inside() {
                    return Err(format!(
                        "facet boundary between {t} and {u} not constrained"
                    ));
                }
                if tr.cons(i) && !tr.inside() && !ur.inside() {
                    return Err(format!("constrained edge of {t} outside the facet"));
                }
                if tr.inside() && !tr.cons(i) && self.incircle(tr.v[i], x, y, ur.v[j]) {
                    return Err(format!(
                        "edge ({}, {}) not locally Delaunay: {} inside circle of ({}, {}, {})",
                        g(nx(i)),
                        g(pv(i)),
                        self.gid[ur.v[j] as usize],
                        g(0),
                        g(1),
                        g(2)
                    ));
                }
            }
        }
        if n_in != self.n_inside {
            return Err(format!(
                "{n_in} facet triangles, counter says {}",
                self.n_inside
            ));
        }
        for v in 0..nv {
            let t = self.vtri[v] as usize;
            if self.tris.get(t).and_then(|tr| tr.find(v as u32)).is_none() {
                return Err(format!("vertex {} has a stale triangle", self.gid[v]));
            }
            if v >= 3 && self.local.get(&self.gid[v]) != Some(&(v as u32)) {
                return Err(format!("vertex {} missing from the id map", self.gid[v]));
            }
        }
        if let Some(exp) = self.expected_area {
            let got = self.area();
            if (got - exp).abs() > 1e-9 * exp.abs() {
                return Err(format!("triangles cover area {got}, polygons have {exp}"));
            }
        }
        Ok(())
    }

    // ---------------------------------------------------------------- internals

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

    /// A triangle's global ids, canonical.
    fn gtri(&self, t: u32) -> [u32; 3] {
        canon(self.tris[t as usize].v.map(|v| self.gid[v as usize]))
    }

    /// Exact "d strictly inside the circle of ccw (a, b, c)" through the lifting from `eye`.
    fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool {
        let [a, b, c, d] = [a, b, c, d].map(|v| self.p3[v as usize]);
        orient3d(a, b, c, self.eye) > 0.0 && insphere(a, b, c, self.eye, d) > 0.0
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
        let r = tr.n[i];
        let d = self.tris[(r / 3) as usize].v[(r % 3) as usize];
        let (c, x, y) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)]);
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
        self.hint.store(self.vtri[l as usize], Relaxed);
        let mut added = Vec::new();
        self.find_in_star(l, |t, _| {
            if self.tris[t as usize].inside() {
                added.push(self.gtri(t));
            }
            false
        });
        Change { removed, added }
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
        Some(if v[nx(k)] == b {
            (t, pv(k))
        } else {
            (t, nx(k))
        })
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
        let mut t = self.hint.load(Relaxed);
        if t as usize >= self.tris.len() {
            t = 0;
        }
        let mut came = 3;
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
                let o = orient2d(
                    self.p2[tr.v[nx(i)] as usize],
                    self.p2[tr.v[pv(i)] as usize],
                    q,
                );
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
                None => {
                    self.hint.store(t, Relaxed);
                    return Self::classify(t, zero);
                }
            }
        }
        // Unreachable in practice (the stochastic walk terminates); scan as a fallback.
        for (t, tr) in self.tris.iter().enumerate() {
            let o = [0, 1, 2].map(|i| {
                orient2d(
                    self.p2[tr.v[nx(i)] as usize],
                    self.p2[tr.v[pv(i)] as usize],
                    q,
                )
            });
            if o.iter().all(|&x| x >= 0.0) {
                return Self::classify(t as u32, o.map(|x| x == 0.0));
            }
        }
        Loc::Outside
    }

    fn classify(t: u32, zero: [bool; 3]) -> Loc {
        match zero {
            [false, false, false] => Loc::In(t),
            [true, false, false] => Loc::Edge(t, 0),
            [false, true, false] => Loc::Edge(t, 1),
            [false, false, true] => Loc::Edge(t, 2),
            [false, true, true] => Loc::Vertex(t, 0),
            [true, false, true] => Loc::Vertex(t, 1),
            _ => Loc::Vertex(t, 2),
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
            let (t, i) = self
                .find_edge(s, e)
                .ok_or("internal: recovered edge missing")?;
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
                let g = |v: u32| self.gid[v as usize];
                return Err(format!(
                    "polygon edges cross: ({}, {}) and ({}, {})",
                    g(s),
                    g(b),
                    g(v1),
                    g(v2)
                ));
            }
            cross.push((v1, v2));
            let r = tr.n[e];
            if r == NONE {
                return Err("internal: constraint left the super-triangle".into());
            }
            let (u, j) = (r / 3, (r % 3) as usize);
            let w = self.tris[u as usize].v[j];
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
            let (t, i) = self
                .find_edge(x, y)
                .ok_or("internal: crossing edge vanished")?;
            let tr = self.tris[t as usize];
            let r = tr.n[i];
            let d = self.tris[(r / 3) as usize].v[(r % 3) as usize];
            let c = tr.v[i];
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
                if stall > queue.len() {
                    return Err("internal: edge recovery stalled".into());
                }
            }
        }
        Ok(())
    }

    /// Lawson flips over the whole triangulation (after edge recovery).
    fn make_cdt(&mut self) -> Result<(), String> {
        let mut stack = Vec::new();
        for (t, tr) in self.tris.iter().enumerate() {
            for i in 0..3 {
                if !tr.cons(i) && tr.n[i] != NONE && ((t * 3 + i) as u32) < tr.n[i] {
                    stack.push((tr.v[nx(i)], tr.v[pv(i)]));
                }
            }
        }
        let mut budget = self.tris.len().saturating_mul(self.tris.len()) + 10_000;
        while let Some((a, b)) = stack.pop() {
            let Some((t, i)) = self.find_edge(a, b) else {
                continue;
            };
            if !self.should_flip(t, i) {
                continue;
            }
            if budget == 0 {
                return Err("internal: too many flips (is the facet planar?)".into());
            }
            budget -= 1;
            let tr = self.tris[t as usize];
            let d = self.tris[(tr.n[i] / 3) as usize].v[(tr.n[i] % 3) as usize];
            let (c, x, y) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)]);
            self.flip_at(t, i);
            stack.extend([(c, x), (x, d), (d, y), (y, c)]);
        }
        Ok(())
    }
}

#[cfg(test)]
mod tests {
    // TESTS
}
