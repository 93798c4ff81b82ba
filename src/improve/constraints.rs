//! How each vertex may move, and which boundary triangles lie on one flat facet patch.
//!
//! Input vertices never move. A Steiner vertex on an input segment moves along it; one on a
//! facet moves in the plane of its patch (a maximal set of same-marker boundary triangles
//! joined by edges that are not on an input segment). Without the input description (an
//! existing mesh) every boundary vertex is fixed and no patch is known.
//!
//! Which segment a boundary vertex lies on is decided geometrically (distance to the segment
//! below 1e-9 of its length): Steiner points are constructed on their segment, facet points
//! are kept away from segments by encroachment, so the margin is many orders wide. This only
//! chooses what a vertex may do; every change is still checked with the exact predicates.

use super::topo::{Work, DEAD};
use crate::plc::PlcInput;
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// What a vertex may do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) enum Constraint {
    Fixed,
    Free,
    /// Move only in the plane with this unit normal.
    Plane(DVec3),
    /// Move only along this unit direction.
    Line(DVec3),
}

impl Constraint {
    /// Removes the components of a displacement the constraint forbids.
    #[inline]
    pub fn project(&self, d: DVec3) -> DVec3 {
        match *self {
            Constraint::Fixed => DVec3::ZERO,
            Constraint::Free => d,
            Constraint::Plane(n) => d - n * d.dot(n),
            Constraint::Line(u) => u * d.dot(u),
        }
    }
}

/// Relative distance below which a boundary vertex is taken to lie on a segment.
const ON_SEGMENT: f64 = 1e-9;

fn dist_to_segment(p: DVec3, a: DVec3, b: DVec3) -> (f64, f64) {
    let ab = b - a;
    let l2 = ab.length_squared();
    let t = if l2 > 0.0 { (p - a).dot(ab) / l2 } else { 0.0 };
    (p.distance(a + ab * t.clamp(0.0, 1.0)), t)
}

/// The input segments: sorted vertex pairs of every facet polygon's sides, sorted, unique.
fn segments(input: &PlcInput) -> Vec<[u32; 2]> {
    let mut s = vec![];
    for f in &input.facets {
        for poly in f.polygons.iter().chain(&f.hole_polygons) {
            let n = poly.len();
            if n < 2 {
                continue;
            }
            let sides = if n == 2 { 1 } else { n };
            for i in 0..sides {
                let (a, b) = (poly[i], poly[(i + 1) % n]);
                if a != b {
                    s.push([a.min(b), a.max(b)]);
                }
            }
        }
    }
    s.sort_unstable();
    s.dedup();
    s
}

/// For each vertex, the segment (index into `segs`) it lies inside, if any (Steiner vertices
/// on the boundary only).
fn segment_of(w: &Work, n_input: usize, segs: &[[u32; 2]]) -> Vec<u32> {
    let mut out = vec![DEAD; w.pos.len()];
    if segs.is_empty() {
        return out;
    }
    let (lo, hi) = w.pos.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(l, h), &p| (l.min(p), h.max(p)),
    );
    let cell = ((hi - lo).length() / 128.0).max(1e-300);
    let at = |p: DVec3| {
        let c = ((p - lo) / cell).floor();
        (c.x as i64, c.y as i64, c.z as i64)
    };
    let mut grid: FxHashMap<(i64, i64, i64), Vec<u32>> = FxHashMap::default();
    for (s, &[a, b]) in segs.iter().enumerate() {
        let (pa, pb) = (w.p(a), w.p(b));
        let steps = ((pa.distance(pb) / (0.5 * cell)).ceil() as usize).clamp(1, 1 << 14);
        let mut last = None;
        for k in 0..=steps {
            let c = at(pa.lerp(pb, k as f64 / steps as f64));
            if last != Some(c) {
                let e = grid.entry(c).or_default();
                if e.last() != Some(&(s as u32)) {
                    e.push(s as u32);
                }
                last = Some(c);
            }
        }
    }
    for (v, slot) in out.iter_mut().enumerate().skip(n_input) {
        if w.bstar[v].is_empty() {
            continue;
        }
        let p = w.pos[v];
        let (cx, cy, cz) = at(p);
        let mut best = (f64::INFINITY, DEAD);
        for dx in -1..=1 {
            for dy in -1..=1 {
                for dz in -1..=1 {
                    let Some(list) = grid.get(&(cx + dx, cy + dy, cz + dz)) else {
                        continue;
                    };
                    for &s in list {
                        let [a, b] = segs[s as usize];
                        let (pa, pb) = (w.p(a), w.p(b));
                        let (d, t) = dist_to_segment(p, pa, pb);
                        let rel = d / pa.distance(pb).max(1e-300);
                        if t > 0.0 && t < 1.0 && rel <= ON_SEGMENT && (rel, s) < best {
                            best = (rel, s);
                        }
                    }
                }
            }
        }
        *slot = best.1;
    }
    out
}

/// Largest angle (radians) between the normals of two triangles of one facet patch: facets
/// are planar to 1e-9 relative, a real crease is never this flat.
const MAX_PATCH_ANGLE: f64 = 1e-5;

fn coplanar(w: &Work, t1: u32, t2: u32) -> bool {
    let n = |t: u32| {
        let [a, b, c] = w.btri[t as usize].map(|v| w.p(v));
        (b - a).cross(c - a).normalize_or_zero()
    };
    let (n1, n2) = (n(t1), n(t2));
    n1 != DVec3::ZERO && n2 != DVec3::ZERO && n1.dot(n2).abs() >= MAX_PATCH_ANGLE.cos()
}

/// Whether a face at v belongs to one tet only (a hull face missing from the boundary list).
pub(crate) fn on_hull(w: &Work, v: u32, faces: &mut Vec<[u32; 3]>) -> bool {
    faces.clear();
    for &t in &w.star[v as usize] {
        let tv = w.tets[t as usize];
        for skip in 0..4 {
            if tv[skip] != v {
                let mut f = crate::mesh::tet_face(&tv, skip);
                f.sort_unstable();
                faces.push(f);
            }
        }
    }
    faces.sort_unstable();
    let mut i = 0;
    while i < faces.len() {
        let mut j = i;
        while j < faces.len() && faces[j] == faces[i] {
            j += 1;
        }
        if j - i != 2 {
            return true;
        }
        i = j;
    }
    false
}

/// Classifies every vertex and sets `w.bpatch`; returns the constraints and each patch's
/// unit normal (indexed by patch id).
pub(crate) fn classify(w: &mut Work, input: Option<&PlcInput>) -> (Vec<Constraint>, Vec<DVec3>) {
    let n = w.pos.len();
    let mut cons = vec![Constraint::Free; n];
    for (v, c) in cons.iter_mut().enumerate() {
        if w.star[v].is_empty() || !w.bstar[v].is_empty() {
            *c = Constraint::Fixed;
        }
    }
    let Some(input) = input else {
        return (cons, vec![]);
    };
    let n_input = input.vertices.len().min(n);
    // Input vertices never move (nor are deleted), interior ones included.
    cons[..n_input].fill(Constraint::Fixed);
    let segs = segments(input);
    let seg_of = segment_of(w, n_input, &segs);
    let on_seg = |v: u32, s: u32| -> bool {
        if (v as usize) < n_input {
            segs[s as usize].contains(&v)
        } else {
            seg_of[v as usize] == s
        }
    };
    let seg_edge = |u: u32, v: u32| -> bool {
        if (u as usize) < n_input && (v as usize) < n_input {
            return segs.binary_search(&[u.min(v), u.max(v)]).is_ok();
        }
        let s = if (u as usize) >= n_input {
            seg_of[u as usize]
        } else {
            seg_of[v as usize]
        };
        s != DEAD && on_seg(u, s) && on_seg(v, s)
    };

    let mut patches = join_flat_patches(w, &seg_edge);
    let normals = number_patches(w, &mut patches);
    for (patch, &marker) in w.bpatch.iter_mut().zip(&w.bmarker) {
        if marker == super::HELD_MARKER {
            *patch = DEAD; // (never moves, flips nor splits)
        }
    }

    for v in n_input..n {
        if w.bstar[v].is_empty() || w.star[v].is_empty() {
            continue;
        }
        cons[v] = if seg_of[v] != DEAD {
            let [a, b] = segs[seg_of[v] as usize];
            Constraint::Line((w.p(b) - w.p(a)).normalize_or_zero())
        } else {
            let p = w.bpatch[w.bstar[v][0] as usize];
            if p == DEAD {
                cons[v] = Constraint::Fixed; // on a held triangle
                continue;
            }
            let nrm = normals[p as usize];
            let one = w.bstar[v].iter().all(|&t| {
                let [a, b, c] = w.btri[t as usize].map(|x| w.p(x));
                let nt = (b - a).cross(c - a).normalize_or_zero();
                w.bpatch[t as usize] == p && nt.dot(nrm).abs() >= MAX_PATCH_ANGLE.cos()
            });
            if one && nrm != DVec3::ZERO {
                Constraint::Plane(nrm)
            } else {
                Constraint::Fixed
            }
        };
    }
    (cons, normals)
}

/// The flat patches: same-marker boundary triangles joined across the edges two of them share
/// that are not on a segment and along which they are coplanar (those edges join
/// `Work::flat_edges`).
fn join_flat_patches(w: &mut Work, seg_edge: &dyn Fn(u32, u32) -> bool) -> UnionFind {
    let nb = w.btri.len();
    let mut edges: Vec<(u64, u32)> = Vec::with_capacity(3 * nb);
    for (i, t) in w.btri.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            edges.push((((a.min(b) as u64) << 32) | a.max(b) as u64, i as u32));
        }
    }
    edges.sort_unstable();
    let mut patches = UnionFind::new(nb);
    let mut i = 0;
    while i < edges.len() {
        let mut j = i;
        while j < edges.len() && edges[j].0 == edges[i].0 {
            j += 1;
        }
        let mut merged = false;
        if j - i == 2 {
            let (t1, t2) = (edges[i].1, edges[i + 1].1);
            let key = edges[i].0;
            let (u, v) = ((key >> 32) as u32, key as u32);
            let flat = coplanar(w, t1, t2);
            let held = w.bmarker[t1 as usize] == super::HELD_MARKER;
            if w.bmarker[t1 as usize] == w.bmarker[t2 as usize] && !held && !seg_edge(u, v) && flat
            {
                patches.union(t1, t2);
                merged = true;
            }
        }
        if merged {
            w.flat_edges.insert(edges[i].0);
        }
        i = j;
    }
    patches
}

/// Numbers the patches in order of their smallest triangle (`Work::bpatch`); returns their
/// Newell normals, oriented like that triangle.
fn number_patches(w: &mut Work, patches: &mut UnionFind) -> Vec<DVec3> {
    let nb = w.btri.len();
    let mut id = vec![DEAD; nb];
    let mut normals: Vec<DVec3> = vec![];
    for t in 0..nb {
        let r = patches.find(t as u32) as usize;
        if id[r] == DEAD {
            id[r] = normals.len() as u32;
            normals.push(DVec3::ZERO);
        }
        w.bpatch[t] = id[r];
    }
    let mut reference = vec![DVec3::ZERO; normals.len()];
    for t in 0..nb {
        let [a, b, c] = w.btri[t].map(|v| w.p(v));
        let nt = (b - a).cross(c - a);
        let p = w.bpatch[t] as usize;
        if reference[p] == DVec3::ZERO {
            reference[p] = nt;
        }
        normals[p] += if nt.dot(reference[p]) < 0.0 { -nt } else { nt };
    }
    for nrm in &mut normals {
        *nrm = nrm.normalize_or_zero();
    }
    normals
}

/// Boundary vertices `slide` lets move get their curve's direction or their tangent plane (the
/// area-weighted normal of their boundary triangles) as constraint; the rest stay as
/// `classify` left them.
pub(crate) fn let_slide(w: &Work, cons: &mut [Constraint], slide: &dyn super::SurfaceSlide) {
    for (v, c) in cons.iter_mut().enumerate() {
        if w.bstar[v].is_empty() || w.star[v].is_empty() || !slide.slides(v as u32) {
            continue;
        }
        if let Some(u) = slide.along(v as u32, w.pos[v]) {
            *c = Constraint::Line(u);
            continue;
        }
        let n: DVec3 = w.bstar[v]
            .iter()
            .map(|&bt| {
                let [a, b, c] = w.btri[bt as usize].map(|u| w.pos[u as usize]);
                (b - a).cross(c - a)
            })
            .sum();
        if let Some(n) = n.try_normalize() {
            *c = Constraint::Plane(n);
        }
    }
}
