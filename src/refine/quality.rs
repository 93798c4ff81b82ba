//! "Clean Bad Elements" (the paper's REMOVE-SLIVER main loop): size-bad tets (R / f(c) > B)
//! first, then radius-edge-bad (rho > rho0), then slivers (sigma < sigma0). A bad tet is
//! refined from a random point of its picking ball (c, delta R) chosen, among `max_tries`
//! draws, to create no small sliver (a new sliver with circumradius <= b R); when its
//! circumcentre encroaches a subsegment or subfacet, that boundary element is split from its
//! own picking interval or disk instead.

use super::domain::{seg_key, tri_key, Domain, VertexKind};
use super::mark::Regions;
use super::{MeshError, Params, Spacing};
use crate::delaunay::{tables::FACE, DryRun, INFINITE};
use crate::geom::{diametric_ball, equatorial_ball, tri_circumcenter};
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;
use std::cmp::Ordering;
use std::collections::VecDeque;

/// Badness classes, in refinement priority order.
const SIZE: u8 = 2;
const RATIO: u8 = 1;
const SLIVER: u8 = 0;

#[derive(Debug, Clone, Copy)]
struct Bad {
    class: u8,
    badness: f64,
    tet: u32,
    verts: [u32; 4],
}
impl PartialEq for Bad {
    fn eq(&self, o: &Self) -> bool {
        self.cmp(o) == Ordering::Equal
    }
}
impl Eq for Bad {}
impl PartialOrd for Bad {
    fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
        Some(self.cmp(o))
    }
}
impl Ord for Bad {
    fn cmp(&self, o: &Self) -> Ordering {
        self.class
            .cmp(&o.class)
            .then(self.badness.total_cmp(&o.badness))
            .then(o.verts.cmp(&self.verts))
    }
}

/// A boundary element a point would encroach.
#[derive(Debug, Clone, Copy)]
enum Boundary {
    Segment(u32, u32),
    Facet(u32, [u32; 3]),
}

pub struct Refiner<'a> {
    pub dom: &'a mut Domain,
    pub params: &'a Params,
    pub spacing: &'a dyn Spacing,
    pub regions: &'a Regions,
    rng: ChaCha8Rng,
    /// One FIFO queue per badness class; the highest class is served first.
    queues: [VecDeque<Bad>; 3],
    /// Bad tets left alone because fixing them needed an ever smaller boundary split (the
    /// signature of an acute input angle).
    pub gave_up: usize,
    /// Bad tets (vertex quadruples) left alone because fixing them needed a split of a
    /// boundary element next to a small input angle: they are within its influence.
    pub blocked_by_small_angle: FxHashSet<[u32; 4]>,
    pub stop_reason: Option<String>,
    /// cos(params.min_dihedral): a tet whose largest dihedral cosine exceeds it is a sliver.
    cos_min_dihedral: f64,
    /// The bounding box of the input vertices.
    domain_box: BoundingBox,
}

#[derive(Debug, Clone, Copy)]
struct BoundingBox {
    lo: DVec3,
    hi: DVec3,
}

impl BoundingBox {
    fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.lo).all() && p.cmple(self.hi).all()
    }
}

impl<'a> Refiner<'a> {
    pub fn new(
        dom: &'a mut Domain,
        params: &'a Params,
        spacing: &'a dyn Spacing,
        regions: &'a Regions,
    ) -> Self {
        let n_input = dom
            .kind
            .iter()
            .take_while(|k| **k == VertexKind::Input)
            .count();
        let (lo, hi) = dom.dt.points()[..n_input].iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(l, h), &p| (l.min(p), h.max(p)),
        );
        Refiner {
            rng: ChaCha8Rng::seed_from_u64(params.seed),
            dom,
            params,
            spacing,
            regions,
            queues: Default::default(),
            gave_up: 0,
            blocked_by_small_angle: FxHashSet::default(),
            stop_reason: None,
            cos_min_dihedral: params.min_dihedral.to_radians().cos(),
            domain_box: BoundingBox { lo, hi },
        }
    }

    /// Spacing at `p` for a tet of region tag `tag`: the user's f, capped by the region's
    /// maximum size; a value that is not finite and positive is an error.
    pub fn spacing_at(&self, p: DVec3, tag: u32) -> Result<f64, MeshError> {
        let mut f = self.spacing.at(p);
        if !(f.is_finite() && f > 0.0) {
            return Err(MeshError::BadSpacing { point: p, value: f });
        }
        if let Some(m) = self.regions.max_size.get(tag as usize).copied().flatten() {
            f = f.min(m);
        }
        Ok(f)
    }

    fn classify(&self, t: u32) -> Result<Option<Bad>, MeshError> {
        // Tets logged as created may have been deleted again by a later insertion.
        if !self.dom.dt.is_alive(t) {
            return Ok(None);
        }
        let tag = self.dom.dt.tag(t);
        if tag == 0 || !self.dom.dt.is_finite(t) {
            return Ok(None);
        }
        let [a, b, c, d] = self.dom.dt.tet_points(t);
        let s = Shape::of(a, b, c, d);
        let verts = self.dom.dt.tet(t);
        let bad = |class, badness| {
            Some(Bad {
                class,
                badness,
                tet: t,
                verts,
            })
        };
        if verts.iter().any(|&v| self.dom.near_acute(v)) {
            // Next to a small input angle only size is enforced, and by the longest edge: the
            // tets there may stay flat, and a flat tet's circumradius says nothing about its size.
            let centroid = (a + b + c + d) * 0.25;
            let xi =
                longest_edge(a, b, c, d) / (EDGE_PER_RADIUS * self.spacing_at(centroid, tag)?);
            return Ok((xi > self.params.size_factor).then_some(Bad {
                class: SIZE,
                badness: xi,
                tet: t,
                verts,
            }));
        }
        let Some(centre) = s.circumcenter else {
            return Ok(bad(SLIVER, f64::INFINITY));
        };
        let xi = s.circumradius / self.spacing_at(centre, tag)?;
        let rho = s.circumradius / s.shortest_edge;
        Ok(if xi > self.params.size_factor {
            bad(SIZE, xi)
        } else if rho > self.params.rho0 {
            bad(RATIO, rho)
        } else if self.is_sliver(&s) {
            bad(SLIVER, s.max_cos_dihedral)
        } else {
            None
        })
    }

    /// Queues the bad tets among those created since the last call.
    fn push_recent(&mut self) -> Result<(), MeshError> {
        let recent = std::mem::take(&mut self.dom.created_log);
        self.push_tets(&recent)
    }

    fn push_tets(&mut self, tets: &[u32]) -> Result<(), MeshError> {
        for &t in tets {
            if let Some(b) = self.classify(t)? {
                self.queues[b.class as usize].push_back(b);
            }
        }
        Ok(())
    }

    fn next_bad(&mut self) -> Option<Bad> {
        self.queues.iter_mut().rev().find_map(|q| q.pop_front())
    }

    /// Runs the refinement until no bad tet is left or a budget stops it.
    pub fn run(&mut self, progress: &mut dyn FnMut(usize) -> bool) -> Result<(), MeshError> {
        let all: Vec<u32> = self.dom.dt.finite_tet_ids().collect();
        self.push_tets(&all)?;
        let mut steps = 0usize;
        while let Some(bad) = self.next_bad() {
            if !self.dom.dt.is_alive(bad.tet) || self.dom.dt.tet(bad.tet) != bad.verts {
                continue;
            }
            if self.dom.dt.num_vertices() >= self.params.max_vertices {
                self.stop_reason = Some(format!(
                    "vertex budget max_vertices = {} reached",
                    self.params.max_vertices
                ));
                return Ok(());
            }
            steps += 1;
            if steps % 1024 == 0 && !progress(self.dom.dt.num_vertices()) {
                return Err(MeshError::Cancelled);
            }
            let gave_up = self.gave_up;
            let before = self.dom.dt.num_vertices();
            self.refine_tet(bad)?;
            // A boundary split need not destroy the tet that asked for it: look again (only
            // if something was inserted, or it would come back forever).
            if self.gave_up == gave_up
                && self.dom.dt.num_vertices() > before
                && self.dom.dt.is_alive(bad.tet)
                && self.dom.dt.tet(bad.tet) == bad.verts
            {
                self.push_tets(&[bad.tet])?;
            }
        }
        Ok(())
    }

    fn refine_tet(&mut self, bad: Bad) -> Result<(), MeshError> {
        // Shape bounds are not enforced next to acute input angles (the paper assumes none;
        // enforcing them there splits the boundary without end). Size still is.
        if bad.class != SIZE && bad.verts.iter().any(|&v| self.dom.near_acute(v)) {
            self.gave_up += 1;
            return Ok(());
        }
        let [a, b, c, d] = self.dom.dt.tet_points(bad.tet);
        if bad.verts.iter().any(|&v| self.dom.near_acute(v)) {
            // Size-bad next to a small angle (see `classify`): split at the centroid, which
            // lies in the tet even when it is flat and its circumcentre is far away.
            let centroid = (a + b + c + d) * 0.25;
            return self.insert_volume_point(centroid, 0.5 * longest_edge(a, b, c, d), bad.tet);
        }
        let q = Shape::of(a, b, c, d);
        let Some(centre) = q.circumcenter else {
            self.gave_up += 1;
            return Ok(());
        };
        let r = q.circumradius;
        let centroid = (a + b + c + d) * 0.25;
        if !self.domain_box.contains(centre)
            && centre.distance(centroid) > FAR_CENTRE_PER_EDGE * longest_edge(a, b, c, d)
        {
            // A nearly flat tet next to the boundary (four almost cocircular points): its
            // circumcentre is outside the domain and far away; it would encroach only
            // boundary elements far smaller than r (the cascade the guard below refuses), and
            // locating it costs a long walk through exact predicates. Only restoring the
            // boundary around it can help.
            if !self.resettle_near(bad.tet)? {
                self.gave_up += 1;
            }
            return Ok(());
        }
        if let Some(bnd) = self.encroached_boundary(centre, Some(bad.tet)) {
            if self.is_protected(bnd) {
                self.gave_up += 1;
                self.blocked_by_small_angle.insert(sorted4(bad.verts));
                return Ok(());
            }
            let rb = self.boundary_radius(bnd);
            // Without small input angles an encroached boundary element has R >= R_tau / 2
            // (the paper, section 2.4); a much smaller one means splitting it would start a
            // cascade of ever smaller splits (an acute angle nearby).
            if rb < 0.25 * r && !self.resettle_near(bad.tet)? {
                self.gave_up += 1;
                if self
                    .boundary_vertices(bnd)
                    .iter()
                    .any(|&v| v != u32::MAX && self.dom.influenced_by_acute_angle(v))
                {
                    self.blocked_by_small_angle.insert(sorted4(bad.verts));
                }
                return Ok(());
            }
            return self.split_boundary(bnd, r);
        }
        // Draw candidates from the picking ball; keep the one with fewest small slivers.
        let mut best: Option<(usize, f64, DVec3)> = None;
        for _ in 0..self.params.max_tries.max(1) {
            let p = centre + self.random_in_ball() * (self.params.delta * r);
            let Some((n_small, worst)) = self.small_slivers(p, r, Some(bad.tet), None) else {
                continue; // p would break the boundary
            };
            if best.is_none_or(|(n, w, _)| (n_small, -worst) < (n, -w)) {
                best = Some((n_small, worst, p));
            }
            if n_small == 0 {
                break;
            }
        }
        let p = match best {
            Some((_, _, p)) => p,
            None => centre,
        };
        if self.encroached_boundary(p, Some(bad.tet)).is_some() {
            // Every draw would break the boundary and so does the centre (only near it).
            if let Some(bnd) = self.encroached_boundary(centre, Some(bad.tet)) {
                return self.split_boundary(bnd, r);
            }
            self.gave_up += 1;
            return Ok(());
        }
        self.dom
            .insert_point(p, super::domain::VertexKind::Volume, Some(bad.tet))?;
        self.settle_boundary()?;
        self.push_recent()
    }

    /// Inserts `p` (for bad tet `t` of size `r`) unless it would break the boundary; then the
    /// boundary element is split instead if it is not much smaller than `r`, else nothing.
    fn insert_volume_point(&mut self, p: DVec3, r: f64, t: u32) -> Result<(), MeshError> {
        let DryRun::Cavity { removed, .. } = self.dom.dt.dry_run(p, Some(t)) else {
            self.gave_up += 1; // p is a vertex already (a flat tet's centroid can be)
            return Ok(());
        };
        if let Some(bnd) = self.boundary_in_cavity(p, &removed) {
            if !self.is_protected(bnd) && self.boundary_radius(bnd) >= 0.25 * r {
                return self.split_boundary(bnd, r);
            }
            if self.is_protected(bnd) {
                self.blocked_by_small_angle
                    .insert(sorted4(self.dom.dt.tet(t)));
            }
            self.gave_up += 1;
            return Ok(());
        }
        self.dom
            .insert_point(p, super::domain::VertexKind::Volume, Some(t))?;
        self.settle_boundary()?;
        self.push_recent()
    }

    fn random_in_ball(&mut self) -> DVec3 {
        loop {
            let v = DVec3::new(
                self.rng.gen_range(-1.0..1.0),
                self.rng.gen_range(-1.0..1.0),
                self.rng.gen_range(-1.0..1.0),
            );
            if v.length_squared() <= 1.0 {
                return v;
            }
        }
    }

    /// Small slivers (circumradius <= b R, sigma < sigma0) inserting `p` would create, and the
    /// smallest sigma among them; None if inserting `p` would cross the boundary (unless the
    /// boundary element is `allowed`, the one being split).
    fn small_slivers(
        &mut self,
        p: DVec3,
        r: f64,
        hint: Option<u32>,
        allowed: Option<Boundary>,
    ) -> Option<(usize, f64)> {
        let DryRun::Cavity { removed, faces } = self.dom.dt.dry_run(p, hint) else {
            return None;
        };
        if allowed.is_none() && self.boundary_in_cavity(p, &removed).is_some() {
            return None;
        }
        let mut n = 0;
        let mut worst = f64::INFINITY;
        for f in faces {
            if f.contains(&INFINITE) {
                continue;
            }
            let [x, y, z] = f.map(|v| self.dom.point(v));
            let s = Shape::of(x, y, z, p);
            if s.circumradius <= self.params.b * r && self.is_sliver(&s) {
                n += 1;
                worst = worst.min(s.max_cos_dihedral.mul_add(-1.0, 1.0));
            }
        }
        Some((n, worst))
    }

    fn is_sliver(&self, s: &Shape) -> bool {
        s.sigma < self.params.sigma0 || s.max_cos_dihedral > self.cos_min_dihedral
    }

    /// The boundary element whose protection inserting `p` would violate: a subsegment or
    /// subfacet among the cavity's edges/faces with `p` in its closed diametric/equatorial
    /// ball, or, when the cavity would cross the boundary (it holds an outside tet or would
    /// delete a subfacet), the subfacet it crosses.
    fn encroached_boundary(&mut self, p: DVec3, hint: Option<u32>) -> Option<Boundary> {
        let DryRun::Cavity { removed, .. } = self.dom.dt.dry_run(p, hint) else {
            return None;
        };
        self.boundary_in_cavity(p, &removed)
    }

    /// See [`Self::encroached_boundary`]; `removed` is the cavity of `p`.
    fn boundary_in_cavity(&self, p: DVec3, removed: &[u32]) -> Option<Boundary> {
        let dom = &*self.dom;
        let mut crosses = false;
        let mut crossed: Option<Boundary> = None;
        let mut segs = vec![];
        let mut facets = vec![];
        // The cavity and the ring of tets around it: an equatorial ball can hold p while the
        // (obtuse) tet on its inner side does not have p in its circumsphere.
        let mut sorted = removed.to_vec();
        sorted.sort_unstable();
        let in_removed = |t: u32| sorted.binary_search(&t).is_ok();
        // (Ring tets may repeat: harmless, the checks below are idempotent.)
        let mut near: Vec<u32> = removed.to_vec();
        for &t in removed {
            for n in dom.dt.neighbors(t) {
                if !in_removed(n) {
                    near.push(n);
                }
            }
        }
        for (k, &t) in near.iter().enumerate() {
            let in_cavity = k < removed.len();
            if !dom.dt.is_finite(t) || dom.dt.tag(t) == 0 {
                crosses |= in_cavity;
                continue;
            }
            let v = dom.dt.tet(t);
            let on_boundary = v.map(|x| dom.kind[x as usize] != VertexKind::Volume);
            if on_boundary.iter().filter(|&&b| b).count() < 2 {
                continue; // no subsegment or subfacet among its edges and faces
            }
            for i in 0..4 {
                for j in i + 1..4 {
                    let k = seg_key(v[i], v[j]);
                    if on_boundary[i] && on_boundary[j] && dom.subsegs.contains_key(&k) {
                        segs.push(k);
                    }
                }
                if on_boundary[i] {
                    continue; // face i is opposite vertex i: it holds the other three
                }
                let f = FACE[i].map(|l| v[l]);
                if let Some(&fi) = dom.subfacets.get(&tri_key(f)) {
                    facets.push((fi, tri_key(f)));
                    let n = dom.dt.neighbors(t)[i];
                    if in_cavity && in_removed(n) {
                        crosses = true;
                        crossed = Some(Boundary::Facet(fi, tri_key(f)));
                    }
                }
            }
        }
        segs.sort_unstable();
        segs.dedup();
        for &(a, b) in &segs {
            let (c, r) = diametric_ball(dom.point(a), dom.point(b));
            if p.distance_squared(c) <= r * r {
                return Some(Boundary::Segment(a, b));
            }
        }
        facets.sort_unstable();
        facets.dedup();
        for &(fi, t) in &facets {
            let [x, y, z] = t.map(|v| dom.point(v));
            if let Some((c, r)) = equatorial_ball(x, y, z) {
                if p.distance_squared(c) <= r * r {
                    return Some(Boundary::Facet(fi, t));
                }
            }
        }
        if crosses {
            return crossed.or_else(|| facets.first().map(|&(fi, t)| Boundary::Facet(fi, t)));
        }
        None
    }

    /// Queues the subsegments and subfacets around tet `t` and restores empty encroachment
    /// there. Returns whether anything was split (a vertex of `t` may be the encroacher that
    /// made it hug the boundary).
    fn resettle_near(&mut self, t: u32) -> Result<bool, MeshError> {
        let n_before = self.dom.dt.num_vertices();
        let mut near = vec![t];
        near.extend(self.dom.dt.neighbors(t));
        for u in near {
            if !self.dom.dt.is_finite(u) {
                continue;
            }
            let v = self.dom.dt.tet(u);
            for i in 0..4 {
                for j in i + 1..4 {
                    let k = seg_key(v[i], v[j]);
                    if self.dom.subsegs.contains_key(&k) {
                        self.dom.dirty_segs.push(k);
                    }
                }
                let f = tri_key(FACE[i].map(|l| v[l]));
                if self.dom.subfacets.contains_key(&f) {
                    self.dom.dirty_tris.push(f);
                }
            }
        }
        self.settle_boundary()?;
        self.push_recent()?;
        Ok(self.dom.dt.num_vertices() > n_before)
    }

    /// Whether refinement must not split boundary element `b`: it touches a small input
    /// angle (`Domain::near_acute_element`).
    fn is_protected(&self, b: Boundary) -> bool {
        match b {
            Boundary::Segment(a, c) => self.dom.near_acute_element(&[a, c]),
            Boundary::Facet(_, t) => self.dom.near_acute_element(&t),
        }
    }

    /// The vertices of boundary element `b` (a subsegment's third entry is `u32::MAX`).
    fn boundary_vertices(&self, b: Boundary) -> [u32; 3] {
        match b {
            Boundary::Segment(a, c) => [a, c, u32::MAX],
            Boundary::Facet(_, t) => t,
        }
    }

    fn boundary_radius(&self, b: Boundary) -> f64 {
        match b {
            Boundary::Segment(a, b) => 0.5 * self.dom.point(a).distance(self.dom.point(b)),
            Boundary::Facet(_, t) => {
                let [x, y, z] = t.map(|v| self.dom.point(v));
                equatorial_ball(x, y, z).map_or(0.0, |(_, r)| r)
            }
        }
    }

    /// Splits a boundary element from its picking region, then restores empty encroachment
    /// around the new vertex.
    fn split_boundary(&mut self, b: Boundary, _r_tau: f64) -> Result<(), MeshError> {
        match b {
            Boundary::Segment(a, c) => self.split_segment_picked(a, c)?,
            Boundary::Facet(f, t) => {
                let [x, y, z] = t.map(|v| self.dom.point(v));
                let Some(cf) = tri_circumcenter(x, y, z) else {
                    self.gave_up += 1;
                    return Ok(());
                };
                let cf = self.dom.snap_to_facet_plane(f, cf);
                let enc = self.dom.facet_subsegments_encroached_by(f, cf);
                if let Some(&(a, c)) = enc.first() {
                    self.split_segment_picked(a, c)?;
                } else if self.dom.facets[f as usize].locate(cf).is_none() {
                    self.gave_up += 1;
                    return Ok(());
                } else {
                    let rf = cf.distance(x);
                    let n = (y - x).cross(z - x).normalize();
                    let u = (y - x).normalize();
                    let w = n.cross(u);
                    let mut best: Option<(usize, f64, DVec3)> = None;
                    for _ in 0..self.params.max_tries.max(1) {
                        let (s, th) = (
                            self.rng.gen::<f64>().sqrt(),
                            self.rng.gen::<f64>() * std::f64::consts::TAU,
                        );
                        let p = cf + (u * th.cos() + w * th.sin()) * (s * self.params.delta * rf);
                        let p = self.dom.snap_to_facet_plane(f, p);
                        if self.dom.facets[f as usize].locate(p).is_none()
                            || !self.dom.facet_subsegments_encroached_by(f, p).is_empty()
                        {
                            continue;
                        }
                        let hint = self.dom.dt.vertex_tet(t[0]);
                        let Some((n_small, worst)) = self.small_slivers(p, rf, hint, Some(b))
                        else {
                            continue;
                        };
                        if best.is_none_or(|(n, w, _)| (n_small, -worst) < (n, -w)) {
                            best = Some((n_small, worst, p));
                        }
                        if n_small == 0 {
                            break;
                        }
                    }
                    let p = best.map_or(cf, |(_, _, p)| p);
                    let hint = self.dom.dt.vertex_tet(t[0]);
                    self.dom.split_in_facet(f, p, hint)?;
                }
            }
        }
        self.settle_boundary()?;
        self.push_recent()
    }

    /// Splits subsegment ac from its picking interval (midpoint +- delta/2 of its length), or at
    /// the concentric-shell point next to an acute input vertex.
    fn split_segment_picked(&mut self, a: u32, c: u32) -> Result<(), MeshError> {
        let (pa, pc) = (self.dom.point(a), self.dom.point(c));
        let shell = self.dom.acute_vertices.contains(&a) != self.dom.acute_vertices.contains(&c);
        let p = if shell {
            self.dom.segment_split_point(a, c)
        } else {
            let r = 0.5 * pa.distance(pc);
            let mut best: Option<(usize, f64, DVec3)> = None;
            for _ in 0..self.params.max_tries.max(1) {
                let t = 0.5 + self.rng.gen_range(-0.5..0.5) * self.params.delta;
                let p = pa + (pc - pa) * t;
                let hint = self.dom.dt.vertex_tet(a);
                let Some((n_small, worst)) =
                    self.small_slivers(p, r, hint, Some(Boundary::Segment(a, c)))
                else {
                    continue;
                };
                if best.is_none_or(|(n, w, _)| (n_small, -worst) < (n, -w)) {
                    best = Some((n_small, worst, p));
                }
                if n_small == 0 {
                    break;
                }
            }
            best.map_or(pa + (pc - pa) * 0.5, |(_, _, p)| p)
        };
        self.dom.split_subsegment(a, c, p)?;
        Ok(())
    }

    /// After a boundary split, restores empty encroachment around it.
    fn settle_boundary(&mut self) -> Result<(), MeshError> {
        let mut budget = super::recover::MAX_RECOVERY_SPLITS;
        self.dom.settle(&mut budget)
    }
}

/// A circumcentre outside the domain's box and further than this many longest edges from
/// its tet is not located (see `refine_tet`).
const FAR_CENTRE_PER_EDGE: f64 = 100.0;

/// Longest edge over circumradius of a regular tet (sqrt(8/3)): the size measure next to small
/// angles compares the longest edge with this many times f.
const EDGE_PER_RADIUS: f64 = 1.632_993_161_855_452;

/// A tet's vertex ids in increasing order (a key independent of orientation).
pub fn sorted4(mut t: [u32; 4]) -> [u32; 4] {
    t.sort_unstable();
    t
}

fn longest_edge(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    [
        a.distance_squared(b),
        a.distance_squared(c),
        a.distance_squared(d),
        b.distance_squared(c),
        b.distance_squared(d),
        c.distance_squared(d),
    ]
    .into_iter()
    .fold(0.0, f64::max)
    .sqrt()
}

/// The measures refinement decides on, computed without trigonometry.
#[derive(Debug, Clone, Copy)]
struct Shape {
    circumcenter: Option<DVec3>,
    circumradius: f64,
    shortest_edge: f64,
    sigma: f64,
    /// Cosine of the smallest dihedral angle.
    max_cos_dihedral: f64,
}

impl Shape {
    #[inline]
    fn of(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Shape {
        let sphere = crate::geom::circumsphere(a, b, c, d);
        let l2 = [
            a.distance_squared(b),
            a.distance_squared(c),
            a.distance_squared(d),
            b.distance_squared(c),
            b.distance_squared(d),
            c.distance_squared(d),
        ]
        .into_iter()
        .fold(f64::INFINITY, f64::min);
        let shortest_edge = l2.sqrt();
        let volume = (b - a).dot((c - a).cross(d - a)).abs() / 6.0;
        // Face normals, all outward or all inward (the sign cancels): the dihedral angle at an
        // edge is pi minus the angle between its two faces' normals, so its cosine is
        // -n_i . n_j / (|n_i| |n_j|).
        let n = [
            (d - b).cross(c - b),
            (c - a).cross(d - a),
            (d - a).cross(b - a),
            (b - a).cross(c - a),
        ];
        let len = n.map(|v| v.length());
        let mut max_cos = -1.0f64;
        for i in 0..4 {
            for j in i + 1..4 {
                let cos = -n[i].dot(n[j]) / (len[i] * len[j]);
                max_cos = max_cos.max(cos);
            }
        }
        Shape {
            circumcenter: sphere.map(|s| s.0),
            circumradius: sphere.map_or(f64::INFINITY, |s| s.1),
            shortest_edge,
            sigma: volume / (l2 * shortest_edge),
            max_cos_dihedral: if max_cos.is_nan() { 1.0 } else { max_cos },
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::TetQuality;

    #[test]
    fn shape_agrees_with_tet_quality() {
        let tets = [
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            [
                DVec3::new(0.1, 0.2, 0.0),
                DVec3::new(1.0, 0.1, 0.05),
                DVec3::new(0.4, 0.9, 0.1),
                DVec3::new(0.5, 0.4, 0.03),
            ],
            [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.5, 0.866, 0.0),
                DVec3::new(0.5, 0.3, 0.8),
            ],
        ];
        for t in tets {
            for flip in [false, true] {
                let [a, mut b, mut c, d] = t;
                if flip {
                    std::mem::swap(&mut b, &mut c);
                }
                let s = Shape::of(a, b, c, d);
                let q = TetQuality::of(a, b, c, d);
                assert!((s.max_cos_dihedral - q.min_dihedral.to_radians().cos()).abs() < 1e-12);
                assert!((s.sigma - q.sigma).abs() < 1e-12 * q.sigma.max(1.0));
                assert!((s.circumradius - q.circumradius).abs() < 1e-12);
            }
        }
    }
}
