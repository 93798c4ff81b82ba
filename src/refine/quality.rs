//! "Clean Bad Elements" (the paper's REMOVE-SLIVER main loop): size-bad tets (R / f(c) > B)
//! first, then radius-edge-bad (rho > rho0), then slivers (sigma < sigma0). A bad tet is
//! refined from a point of its picking ball (c, delta R) that creates no small sliver (a new
//! sliver with circumradius <= b R): the centre c itself if it does not (its cavity is known
//! from the boundary check), else the best of up to `max_tries` random draws; when its
//! circumcentre encroaches a subsegment or subfacet, that boundary element is split from its
//! own picking interval or disk instead.
//!
//! Refining one bad tet (`refine_tet` and the helpers it returns through) decides and says
//! what it did as an [`Outcome`]; `run`, the queue loop, keeps all the books (counts per
//! refusal reason, the deferred queue, the tets left at once when looked at again).

use super::domain::{seg_key, tri_key, Domain, VertexKind};
use super::mark::Regions;
use super::outcome::{BoundaryKind, Outcome, Refusal, Refusals};
use super::recover::Settled;
use super::{MeshError, Params, Spacing};
use crate::delaunay::{tables::FACE, BoundaryFace, Cavity, Probe, INFINITE};
use crate::geom::screen::{
    longest_edge_direct as longest_edge, shortest_edge_sq, sliver_measures, SliverScreen,
};
use crate::geom::{
    circum_offset_crossed, circumsphere, diametric_ball, equatorial_ball, insphere, orient3d,
    tri_circumcenter,
};
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

/// Circumradius / longest edge above which a bad tet is deferred (see `refine_tet`).
const DEFER_RADIUS_PER_EDGE: f64 = 3.0;

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
    /// Flat tets with a far circumcentre, served after every queue is empty
    /// ([`Outcome::Deferred`]).
    deferred: VecDeque<Bad>,
    /// How often a bad tet was left alone, per reason.
    pub refusals: Refusals,
    /// Bad tets (vertex quadruples) left alone within a small input angle's influence
    /// ([`Refusal::within_small_angle`]).
    pub blocked_by_small_angle: FxHashSet<[u32; 4]>,
    /// Bad tets (vertex quadruples) whose circumcentre encroached a boundary element too small
    /// to split, with nothing to restore around them ([`Refusal::remembered`]): looked at
    /// again (flips and boundary restoration re-queue them), they are left at once
    /// ([`Refusal::Futile`]) instead of probing that centre's cavity again (thousands of tets
    /// next to a finely split boundary; most of keep-mode oblong.off's time was such repeats).
    futile: FxHashSet<[u32; 4]>,
    pub stop_reason: Option<String>,
    /// cos(params.min_dihedral): a tet whose largest dihedral cosine exceeds it is a sliver.
    cos_min_dihedral: f64,
    /// The bounding box of the input vertices.
    domain_box: BoundingBox,
    screen: SliverScreen,
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
            deferred: VecDeque::new(),
            refusals: Refusals::default(),
            blocked_by_small_angle: FxHashSet::default(),
            futile: FxHashSet::default(),
            stop_reason: None,
            cos_min_dihedral: params.min_dihedral.to_radians().cos(),
            domain_box: BoundingBox { lo, hi },
            screen: SliverScreen::new(params.sigma0, params.min_dihedral),
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
        let verts = self.dom.dt.tet(t);
        let [a, b, c, d] = verts.map(|v| self.dom.point(v));
        let bad = |class, badness| {
            Some(Bad {
                class,
                badness,
                tet: t,
                verts,
            })
        };
        let near = verts.iter().any(|&v| self.dom.near_acute(v));
        if near {
            // Next to a small input angle size is measured by the longest edge: the tets there
            // may stay flat, and a flat tet's circumradius says nothing about its size.
            let centroid = (a + b + c + d) * 0.25;
            let xi =
                longest_edge(a, b, c, d) / (EDGE_PER_RADIUS * self.spacing_at(centroid, tag)?);
            if xi > self.params.size_factor {
                return Ok(bad(SIZE, xi));
            }
        }
        // The measures, each computed only when the tests before it pass, sharing the edge
        // vectors and cross products: the circumsphere (geom's one formula), then the sliver
        // screen (geom::screen).
        let (u, v, w) = (b - a, c - a, d - a);
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let lu = [u.length_squared(), v.length_squared(), w.length_squared()];
        let det = orient3d(a, b, c, d);
        let Some(offset) = circum_offset_crossed([vw, wu, uv], lu, det) else {
            return Ok(bad(SLIVER, f64::INFINITY));
        };
        let (centre, circumradius) = (a + offset, offset.length());
        if !near {
            let xi = circumradius / self.spacing_at(centre, tag)?;
            if xi > self.params.size_factor {
                return Ok(bad(SIZE, xi));
            }
        }
        let e = [
            lu[0],
            lu[1],
            lu[2],
            (c - b).length_squared(),
            (d - b).length_squared(),
            (d - c).length_squared(),
        ];
        let l2 = e[0].min(e[1]).min(e[2]).min(e[3]).min(e[4]).min(e[5]);
        let rho = circumradius / l2.sqrt();
        if rho > self.params.rho0 {
            return Ok(bad(RATIO, rho));
        }
        let n = [
            (d - b).cross(c - b).length_squared(),
            vw.length_squared(),
            wu.length_squared(),
            uv.length_squared(),
        ];
        if self.screen.clears(det, e, l2, n) {
            return Ok(None);
        }
        let (sigma, max_cos_dihedral) = sliver_measures(a, b, c, d, l2);
        Ok(if self.is_sliver_by(sigma, max_cos_dihedral) {
            bad(SLIVER, max_cos_dihedral)
        } else {
            None
        })
    }

    /// Queues the bad tets among those created since the last call.
    fn push_recent(&mut self) -> Result<(), MeshError> {
        let recent = std::mem::take(&mut self.dom.created_log);
        // A volume point's cavity never holds a subfacet (the refiner splits what it would
        // encroach instead), so its tets inherit the right region.
        if std::mem::take(&mut self.dom.boundary_inserted) {
            self.dom.retag_created(&recent);
        }
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

    /// The next bad tet, and whether it was deferred already.
    fn next_bad(&mut self) -> Option<(Bad, bool)> {
        if let Some(b) = self.queues.iter_mut().rev().find_map(|q| q.pop_front()) {
            return Some((b, false));
        }
        self.deferred.pop_front().map(|b| (b, true))
    }

    /// Runs the refinement until no bad tet is left or a budget stops it.
    pub fn run(&mut self, progress: &mut dyn FnMut(usize) -> bool) -> Result<(), MeshError> {
        let all: Vec<u32> = self.dom.dt.finite_tet_ids().collect();
        self.push_tets(&all)?;
        let mut steps = 0usize;
        while let Some((bad, was_deferred)) = self.next_bad() {
            if !self.is_current(bad) {
                continue;
            }
            if self.dom.dt.num_vertices() >= self.params.max_vertices {
                let max = self.params.max_vertices;
                self.stop(format!("vertex budget max_vertices = {max} reached"), bad);
                return Ok(());
            }
            steps += 1;
            if steps % 1024 == 0 && !progress(self.dom.dt.num_vertices()) {
                return Err(MeshError::Cancelled);
            }
            let before = self.dom.dt.num_vertices();
            let outcome = self.refine_tet(bad, !was_deferred)?;
            if !self.record(bad, outcome, before)? {
                return Ok(());
            }
        }
        Ok(())
    }

    /// Whether queued bad tet `bad` is still a tet of the mesh.
    fn is_current(&self, bad: Bad) -> bool {
        self.dom.dt.is_alive(bad.tet) && self.dom.dt.tet(bad.tet) == bad.verts
    }

    /// The books of one refined bad tet (`n_before`: the vertex count before), all kept here:
    /// refusals counted per reason, the tets left within a small angle's influence or left for
    /// good, the deferred queue, and a second look at a tet that survived a split. Returns
    /// false when refinement must stop.
    fn record(&mut self, bad: Bad, outcome: Outcome, n_before: usize) -> Result<bool, MeshError> {
        match outcome {
            Outcome::Refused(reason) => {
                self.refusals.count(reason);
                if reason.remembered() {
                    self.futile.insert(sorted4(bad.verts));
                }
                if reason.within_small_angle() {
                    self.blocked_by_small_angle.insert(sorted4(bad.verts));
                }
            }
            Outcome::Deferred => self.deferred.push_back(bad),
            Outcome::BudgetSpent => {
                let max = super::recover::MAX_RECOVERY_SPLITS;
                self.stop(
                    format!("boundary split budget ({max} splits after one insertion) spent"),
                    bad,
                );
                return Ok(false);
            }
            Outcome::Inserted | Outcome::Split(_) | Outcome::Resettled => {
                // A boundary split need not destroy the tet that asked for it: look again
                // (only if something was inserted, or it would come back forever).
                if self.dom.dt.num_vertices() > n_before && self.is_current(bad) {
                    self.push_tets(&[bad.tet])?;
                }
            }
        }
        Ok(true)
    }

    /// Stops refinement for `reason` (a budget), counting the bad tets still queued (`bad`
    /// among them while it is a tet) as left by the budget.
    fn stop(&mut self, reason: String, bad: Bad) {
        let queued = self.queues.iter().flatten().chain(&self.deferred);
        let left: FxHashSet<u32> = std::iter::once(&bad)
            .chain(queued)
            .filter(|b| self.is_current(**b))
            .map(|b| b.tet)
            .collect();
        self.refusals.count_budget(left.len());
        self.stop_reason = Some(reason);
    }

    /// Refines bad tet `bad` (`may_defer`: it was not deferred already) by Li's point choice,
    /// unless a guard below finds that nothing would help: says what it did, and `run` keeps
    /// the books.
    fn refine_tet(&mut self, bad: Bad, may_defer: bool) -> Result<Outcome, MeshError> {
        if self.futile.contains(&sorted4(bad.verts)) {
            return Ok(Outcome::Refused(Refusal::Futile));
        }
        if self.dom.flat_by_construction(bad.verts) {
            // No point inside it or at its centre can help (see `flat_by_construction`):
            // restoring the boundary around it may; else the improvement removes it.
            return self.resettle_or_refuse(bad.tet, Refusal::FlatByConstruction);
        }
        let near = bad.verts.iter().any(|&v| self.dom.near_acute(v));
        let [a, b, c, d] = self.dom.dt.tet_points(bad.tet);
        if near && bad.class == SIZE {
            // Size-bad next to a small angle (see `classify`): split at the centroid, which
            // lies in the tet even when it is flat and its circumcentre is far away.
            let centroid = (a + b + c + d) * 0.25;
            return self.insert_volume_point(centroid, 0.5 * longest_edge(a, b, c, d), bad.tet);
        }
        let Some((centre, r)) = circumsphere(a, b, c, d) else {
            return Ok(Outcome::Refused(Refusal::NoCircumsphere));
        };
        if let Some(outcome) = self.screen_circumcentre(bad, centre, r, near, may_defer)? {
            return Ok(outcome);
        }
        let (centre_cavity, centre_breaks) = self.encroached_boundary(centre, Some(bad.tet));
        if near {
            // Only the centre, and only if it breaks no boundary (see `screen_circumcentre`).
            // No cavity: the centre is a vertex already.
            return match (centre_breaks, centre_cavity) {
                (None, Some(cavity)) => self.insert_volume_vertex(centre, bad.tet, Some(cavity)),
                _ => Ok(Outcome::Refused(Refusal::NearSmallAngle)),
            };
        }
        if let Some(bnd) = centre_breaks {
            return self.refine_encroached(bad, bnd, r);
        }
        self.insert_from_picking_ball(bad, centre, r, centre_cavity)
    }

    /// The guards on bad tet `bad`'s circumcentre `centre` (circumradius `r`; `near`: next to
    /// a small angle) before its cavity is probed: what to do instead when the tet is flat to
    /// rounding, its centre is far outside the domain, it is next to a small angle with a far
    /// centre, or it must wait; None when the centre is worth probing.
    fn screen_circumcentre(
        &mut self,
        bad: Bad,
        centre: DVec3,
        r: f64,
        near: bool,
        may_defer: bool,
    ) -> Result<Option<Outcome>, MeshError> {
        let [a, b, c, d] = self.dom.dt.tet_points(bad.tet);
        if insphere(a, b, c, d, centre) <= 0.0 {
            // The computed centre is not inside the tet's own circumsphere (exact test): the
            // tet is flat to rounding (four nearly cocircular points, seen on coplanar
            // boundary triangles of separate facets) and its float circumsphere is noise. A
            // point there would not remove the tet, and it would be drawn again without end;
            // only restoring the boundary around it can help.
            return self
                .resettle_or_refuse(bad.tet, Refusal::FlatToRounding)
                .map(Some);
        }
        let centroid = (a + b + c + d) * 0.25;
        let le = longest_edge(a, b, c, d);
        if !self.domain_box.contains(centre) && centre.distance(centroid) > FAR_CENTRE_PER_EDGE * le
        {
            // A nearly flat tet next to the boundary (four almost cocircular points): its
            // circumcentre is outside the domain and far away; it would encroach only
            // boundary elements far smaller than r (the cascade `refine_encroached` refuses),
            // and locating it costs a long walk through exact predicates. Only restoring the
            // boundary around it can help.
            return self
                .resettle_or_refuse(bad.tet, Refusal::FarCentre)
                .map(Some);
        }
        // Next to a small angle shape is improved only by the circumcentre, and only when it
        // breaks no boundary: splitting the boundary there for shape would never end (the
        // paper assumes no small angles). Only tets whose circumcentre is close (a sliver's,
        // not a cap's) are tried: a far centre has a huge cavity that always reaches the
        // boundary. Random draws from the picking ball as well cost 3-10x the time there for
        // 10-30% fewer bad tets (measured on the .off models). A tet the centre does not fix
        // is left, counted as within the angle's influence.
        if near && r > le {
            return Ok(Some(Outcome::Refused(Refusal::NearSmallAngle)));
        }
        // A flat tet with a far circumcentre (one hugging the boundary, made by a boundary
        // split) waits until every other bad tet is handled: by then most are gone, and its
        // centre's cavity is large (measured on anchor.off: 2,100 tets on average, nearly
        // every one ending in a refused boundary split).
        if r > DEFER_RADIUS_PER_EDGE * le {
            if may_defer {
                return Ok(Some(Outcome::Deferred));
            }
            // Deferred already: when its circumcentre lies outside the domain, probing that
            // centre means a huge cavity (thousands of tets) that crosses the boundary, which
            // can only end in a refused split (the boundary element is far smaller than R).
            // Restoring the boundary around it is all that can help.
            let t = self.dom.dt.locate_point(centre, Some(bad.tet));
            if !self.dom.dt.is_finite(t) || self.dom.dt.tag(t) == 0 {
                return self
                    .resettle_or_refuse(bad.tet, Refusal::CentreOutsideDomain)
                    .map(Some);
            }
        }
        Ok(None)
    }

    /// Inserts the best point of bad tet `bad`'s picking ball (centre `centre`, circumradius
    /// `r`, which breaks no boundary: the caller checked, with the probe `centre_cavity`,
    /// None if the centre is a vertex).
    fn insert_from_picking_ball(
        &mut self,
        bad: Bad,
        centre: DVec3,
        r: f64,
        centre_cavity: Option<Cavity>,
    ) -> Result<Outcome, MeshError> {
        // Draw candidates from the picking ball; keep the one with fewest small slivers among
        // those that break no boundary.
        let mut best = None;
        // The centre is a point of the picking ball too, and its cavity is at hand (probed by
        // the boundary check above, which it passed): the first candidate.
        if let Some(cavity) = centre_cavity {
            if let Some((n_small, worst)) = self.small_slivers(&cavity, r, None) {
                best = Some(Candidate {
                    n_small,
                    worst,
                    cavity,
                });
            }
        }
        if best.as_ref().is_none_or(|b| b.n_small > 0) {
            for _ in 0..self.params.max_tries.max(1) {
                let p = centre + self.random_in_ball() * (self.params.delta * r);
                if self.try_candidate(p, r, Some(bad.tet), None, &mut best) {
                    break;
                }
            }
        }
        // The chosen point breaks no boundary: a candidate was only kept after that check on
        // its cavity, and the centre passed it above (nothing has changed since). When it was
        // the last one probed (the usual case: its draw ended the search), its cavity is
        // still current and the insertion reuses it.
        match best {
            Some(b) => self.insert_volume_vertex(b.cavity.point(), bad.tet, Some(b.cavity)),
            None => self.insert_volume_vertex(centre, bad.tet, None),
        }
    }

    /// Inserts volume vertex `p` (located from tet `hint`, or with `cavity`, a probe of `p`,
    /// while current), restores empty encroachment around it and queues the new bad tets.
    fn insert_volume_vertex(
        &mut self,
        p: DVec3,
        hint: u32,
        cavity: Option<Cavity>,
    ) -> Result<Outcome, MeshError> {
        self.dom
            .insert_point(p, super::domain::VertexKind::Volume, Some(hint), cavity)?;
        self.settle_and_queue(Outcome::Inserted)
    }

    /// After an insertion: restores empty encroachment around it and queues the new bad
    /// tets. Returns `done`, or `BudgetSpent` when the split budget ran out first.
    fn settle_and_queue(&mut self, done: Outcome) -> Result<Outcome, MeshError> {
        let mut budget = super::recover::MAX_RECOVERY_SPLITS;
        let settled = self.dom.settle(&mut budget)?;
        self.push_recent()?;
        Ok(match settled {
            Settled::Conforming => done,
            Settled::BudgetSpent => Outcome::BudgetSpent,
        })
    }

    /// Bad tet `bad` (circumradius `r`), whose circumcentre encroaches boundary element `bnd`
    /// (or whose cavity crosses it): split `bnd` from its picking region, unless it touches a
    /// small angle or is much smaller than the tet.
    fn refine_encroached(&mut self, bad: Bad, bnd: Boundary, r: f64) -> Result<Outcome, MeshError> {
        if self.is_protected(bnd) {
            return Ok(Outcome::Refused(Refusal::NearSmallAngle));
        }
        let rb = self.boundary_radius(bnd);
        // Without small input angles an encroached boundary element has R >= R_tau / 2
        // (the paper, section 2.4); a much smaller one means splitting it would start a
        // cascade of ever smaller splits (an acute angle nearby).
        if rb >= 0.25 * r {
            return self.split_boundary(bnd, r);
        }
        // Restoring the boundary around the tet is all that may help. When it split anything,
        // `bnd` (and the tet) may be gone: `bnd` is never split for this tet, which `run`
        // looks at again if it survived. When it split nothing, the tet is left for good.
        let cascade = if self
            .boundary_vertices(bnd)
            .iter()
            .any(|&v| v != u32::MAX && self.dom.influenced_by_acute_angle(v))
        {
            Refusal::CascadeNearSmallAngle
        } else {
            Refusal::Cascade
        };
        self.resettle_or_refuse(bad.tet, cascade)
    }

    /// Inserts `p` (for size-bad tet `t` of size `r`) unless it would break the boundary; then
    /// the boundary element is split instead if it is not much smaller than `r`, else nothing.
    fn insert_volume_point(&mut self, p: DVec3, r: f64, t: u32) -> Result<Outcome, MeshError> {
        let Probe::Cavity(cavity) = self.dom.dt.probe(p, Some(t)) else {
            // p is a vertex already (a flat tet's centroid can be)
            return Ok(Outcome::Refused(Refusal::Duplicate));
        };
        if let Some(bnd) = self.boundary_in_cavity(&cavity) {
            // Only size refinement comes here: the boundary element is split even next to a
            // small angle (such splits stop once the elements are a fraction of f, unlike
            // splits for shape, which can go on without end).
            if self.boundary_radius(bnd) >= 0.25 * r {
                return self.split_boundary(bnd, r);
            }
            // A much smaller one would start a cascade (see `refine_encroached`): the tet is
            // left, within the small angle's influence when the element touches one.
            return Ok(Outcome::Refused(if self.is_protected(bnd) {
                Refusal::NearSmallAngle
            } else {
                Refusal::CentroidCascade
            }));
        }
        self.insert_volume_vertex(p, t, Some(cavity))
    }

    fn random_in_ball(&mut self) -> DVec3 {
        random_in_unit_ball(&mut self.rng)
    }

    /// Probes candidate `p` for a bad element of circumradius `r` and makes it `best` if it
    /// creates fewer small slivers (circumradius <= b r, sigma < sigma0 or a small dihedral
    /// angle; ties: the larger smallest dihedral angle) and breaks no boundary (except the
    /// element being split, `allowed`). Returns true when `p` creates no small sliver (the
    /// search can stop; `best`'s cavity is then current).
    fn try_candidate(
        &mut self,
        p: DVec3,
        r: f64,
        hint: Option<u32>,
        allowed: Option<Boundary>,
        best: &mut Option<Candidate>,
    ) -> bool {
        let Probe::Cavity(cavity) = self.dom.dt.probe(p, hint) else {
            return false;
        };
        let limit = best.as_ref().map(|b| b.n_small);
        let Some((n_small, worst)) = self.small_slivers(&cavity, r, limit) else {
            return false; // more small slivers than the best
        };
        if best
            .as_ref()
            .is_some_and(|b| (n_small, -worst) >= (b.n_small, -b.worst))
        {
            return false; // not better: whether it breaks the boundary does not matter
        }
        if allowed.is_none() && self.boundary_in_cavity(&cavity).is_some() {
            return false; // p would break the boundary
        }
        *best = Some(Candidate {
            n_small,
            worst,
            cavity,
        });
        n_small == 0
    }

    /// Small slivers (circumradius <= b R, sigma < sigma0 or a small dihedral angle) inserting
    /// the probed point would create, and the smallest 1 - cos(smallest dihedral angle) among
    /// them; None as soon as there are more than `limit`.
    fn small_slivers(&self, cavity: &Cavity, r: f64, limit: Option<usize>) -> Option<(usize, f64)> {
        let mut n = 0;
        let mut worst = f64::INFINITY;
        let max_r = self.params.b * r;
        let p = cavity.point();
        let faces = self.dom.dt.cavity(cavity).1;
        let points = self.dom.dt.points();
        let corners = |f: &BoundaryFace| {
            let v = f.vertices();
            (!v.contains(&INFINITE)).then(|| v.map(|v| points[v as usize]))
        };
        let mut over = false;
        // The sliver screen first (most new tets pass it), then the full measures.
        self.screen
            .for_each_uncleared(faces, corners, p, |[x, y, z]| {
                if let Some(w) = self.small_sliver(x, y, z, p, max_r) {
                    n += 1;
                    if limit.is_some_and(|m| n > m) {
                        over = true;
                        return false;
                    }
                    worst = worst.min(w);
                }
                true
            });
        if over {
            return None;
        }
        Some((n, worst))
    }

    /// For the new tet (x, y, z, p): 1 - cos(its smallest dihedral angle) if it is a sliver
    /// with circumradius <= `max_r`.
    #[inline]
    fn small_sliver(&self, x: DVec3, y: DVec3, z: DVec3, p: DVec3, max_r: f64) -> Option<f64> {
        {
            let (sigma, max_cos) = sliver_measures(x, y, z, p, shortest_edge_sq(x, y, z, p));
            if self.is_sliver_by(sigma, max_cos)
                && circumsphere(x, y, z, p).map_or(f64::INFINITY, |s| s.1) <= max_r
            {
                return Some(max_cos.mul_add(-1.0, 1.0));
            }
        }
        None
    }

    #[inline]
    fn is_sliver_by(&self, sigma: f64, max_cos_dihedral: f64) -> bool {
        sigma < self.params.sigma0 || max_cos_dihedral > self.cos_min_dihedral
    }

    /// The boundary element whose protection inserting `p` would violate: a subsegment or
    /// subfacet among the cavity's edges/faces with `p` in its closed diametric/equatorial
    /// ball, or, when the cavity would cross the boundary (it holds an outside tet or would
    /// delete a subfacet), the subfacet it crosses.
    /// Also returns `p`'s probe (None: `p` is a vertex, and breaks nothing).
    fn encroached_boundary(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
    ) -> (Option<Cavity>, Option<Boundary>) {
        let Probe::Cavity(cavity) = self.dom.dt.probe(p, hint) else {
            return (None, None);
        };
        let breaks = self.boundary_in_cavity(&cavity);
        (Some(cavity), breaks)
    }

    /// See [`Self::encroached_boundary`], for a probed cavity. Looks at the cavity and the
    /// ring of tets around it (an equatorial ball can hold p while the (obtuse) tet on its
    /// inner side does not have p in its circumsphere); of the encroached elements it names
    /// the smallest subsegment (by key), else the smallest subfacet.
    fn boundary_in_cavity(&self, cavity: &Cavity) -> Option<Boundary> {
        let dom = &*self.dom;
        let p = cavity.point();
        let (removed, faces) = dom.dt.cavity(cavity);
        // Every vertex of a cavity tet is on the cavity's boundary, and a ring tet adds one
        // vertex to a boundary face: if no boundary face has a vertex on the domain boundary,
        // no cavity or ring tet has two, so the scan below would find no subsegment or
        // subfacet (and, crossing or not, name none).
        let on_boundary = |v: u32| v == INFINITE || dom.kind[v as usize] != VertexKind::Volume;
        if !faces
            .iter()
            .any(|f| f.vertices().into_iter().any(on_boundary))
        {
            return None;
        }
        let mut scan = BoundaryScan {
            p,
            removed,
            seg: None,
            facet: None,
            any_facet: None,
            crossed: None,
        };
        let mut crosses = false;
        for &t in removed {
            if !dom.dt.is_finite(t) || dom.dt.tag(t) == 0 {
                crosses = true;
                continue;
            }
            scan.tet(dom, t, true);
        }
        // The ring: the tets across the cavity's boundary faces (a tet may come up more than
        // once; the checks are idempotent). One whose face has no boundary vertex has at most
        // one (its apex).
        for f in faces {
            if !f.vertices().into_iter().any(on_boundary) {
                continue;
            }
            let t = f.outer_tet();
            if dom.dt.is_finite(t) && dom.dt.tag(t) != 0 {
                scan.tet(dom, t, false);
            }
        }
        if let Some((a, b)) = scan.seg {
            return Some(Boundary::Segment(a, b));
        }
        if let Some((fi, t)) = scan.facet {
            return Some(Boundary::Facet(fi, t));
        }
        if crosses || scan.crossed.is_some() {
            return scan
                .crossed
                .or_else(|| scan.any_facet.map(|(fi, t)| Boundary::Facet(fi, t)));
        }
        None
    }

    /// Restores empty encroachment around tet `t` (a vertex of `t` may be the encroacher that
    /// made it hug the boundary): `Resettled` if that split anything, else refused for
    /// `reason`.
    fn resettle_or_refuse(&mut self, t: u32, reason: Refusal) -> Result<Outcome, MeshError> {
        let n_before = self.dom.dt.num_vertices();
        self.queue_boundary_around(t);
        Ok(match self.settle_and_queue(Outcome::Resettled)? {
            Outcome::Resettled if self.dom.dt.num_vertices() == n_before => {
                Outcome::Refused(reason)
            }
            outcome => outcome,
        })
    }

    /// Queues the subsegments and subfacets among the edges and faces of tet `t` and its
    /// neighbours.
    fn queue_boundary_around(&mut self, t: u32) {
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
    fn split_boundary(&mut self, b: Boundary, _r_tau: f64) -> Result<Outcome, MeshError> {
        let split = match b {
            Boundary::Segment(a, c) => {
                self.split_segment_picked(a, c)?;
                BoundaryKind::Segment
            }
            Boundary::Facet(f, t) => match self.split_subfacet_picked(f, t)? {
                Ok(kind) => kind,
                Err(refusal) => return Ok(Outcome::Refused(refusal)),
            },
        };
        self.settle_and_queue(Outcome::Split(split))
    }

    /// Splits subfacet `t` of facet `f` from its picking disk (its circumcentre first, then
    /// random draws), or the facet's subsegment that centre encroaches. Returns the kind of
    /// element split, or why nothing was.
    fn split_subfacet_picked(
        &mut self,
        f: u32,
        t: [u32; 3],
    ) -> Result<Result<BoundaryKind, Refusal>, MeshError> {
        let [x, y, z] = t.map(|v| self.dom.point(v));
        let Some(cf) = tri_circumcenter(x, y, z) else {
            return Ok(Err(Refusal::FlatSubfacet));
        };
        // The facet's plane snap and subsegment balls, once for the centre and all the draws
        // (the same tests as snap_to_facet_plane and facet_subsegments_encroached_by, which
        // walk the whole facet).
        let snap = PlaneSnap::of(self.dom, f);
        let balls = subsegment_balls(self.dom, f);
        let cf = snap.apply(cf);
        let enc = balls
            .iter()
            .filter(|b| cf.distance_squared(b.centre) <= b.r2)
            .map(|b| b.key)
            .min();
        if let Some((a, c)) = enc {
            self.split_segment_picked(a, c)?;
            return Ok(Ok(BoundaryKind::Segment));
        }
        if self.dom.facets[f as usize].locate(cf).is_none() {
            return Ok(Err(Refusal::SubfacetCentreOutside));
        }
        let rf = cf.distance(x);
        let n = (y - x).cross(z - x).normalize();
        let u = (y - x).normalize();
        let w = n.cross(u);
        // The centre first (it passed the facet checks above), then random draws.
        let mut best = None;
        let b = Boundary::Facet(f, t);
        let hint = self.dom.dt.vertex_tet(t[0]);
        let centre_ok = self.try_candidate(cf, rf, hint, Some(b), &mut best);
        let tries = if centre_ok {
            0
        } else {
            self.params.max_tries.max(1)
        };
        for _ in 0..tries {
            let (s, th) = (
                self.rng.gen::<f64>().sqrt(),
                self.rng.gen::<f64>() * std::f64::consts::TAU,
            );
            let p = cf + (u * th.cos() + w * th.sin()) * (s * self.params.delta * rf);
            let p = snap.apply(p);
            if self.dom.facets[f as usize].locate(p).is_none()
                || balls.iter().any(|b| p.distance_squared(b.centre) <= b.r2)
            {
                continue;
            }
            let hint = self.dom.dt.vertex_tet(t[0]);
            if self.try_candidate(p, rf, hint, Some(b), &mut best) {
                break;
            }
        }
        let (p, cavity) = match best {
            Some(c) => (c.cavity.point(), Some(c.cavity)),
            None => (cf, None),
        };
        let hint = self.dom.dt.vertex_tet(t[0]);
        self.dom.split_in_facet(f, p, hint, cavity)?;
        Ok(Ok(BoundaryKind::Facet))
    }

    /// Splits subsegment ac from its picking interval (midpoint +- delta/2 of its length), or at
    /// the concentric-shell point next to an acute input vertex.
    fn split_segment_picked(&mut self, a: u32, c: u32) -> Result<(), MeshError> {
        let (pa, pc) = (self.dom.point(a), self.dom.point(c));
        let shell = self.dom.acute_vertices.contains(&a) != self.dom.acute_vertices.contains(&c);
        let (p, cavity) = if shell {
            (self.dom.segment_split_point(a, c), None)
        } else {
            let r = 0.5 * pa.distance(pc);
            let mut best = None;
            for _ in 0..self.params.max_tries.max(1) {
                let t = 0.5 + self.rng.gen_range(-0.5..0.5) * self.params.delta;
                let p = pa + (pc - pa) * t;
                let hint = self.dom.dt.vertex_tet(a);
                let allowed = Some(Boundary::Segment(a, c));
                if self.try_candidate(p, r, hint, allowed, &mut best) {
                    break;
                }
            }
            match best {
                Some(b) => (b.cavity.point(), Some(b.cavity)),
                None => (pa + (pc - pa) * 0.5, None),
            }
        };
        self.dom.split_subsegment(a, c, p, cavity)?;
        Ok(())
    }
}

/// A circumcentre outside the domain's box and further than this many longest edges from
/// its tet is not located (see `refine_tet`).
const FAR_CENTRE_PER_EDGE: f64 = 100.0;

/// Longest edge over circumradius of a regular tet (sqrt(8/3)): the size measure next to small
/// angles compares the longest edge with this many times f.
const EDGE_PER_RADIUS: f64 = 1.632_993_161_855_452;

/// A uniformly random point of the closed unit ball (rejection from the cube).
pub(crate) fn random_in_unit_ball(rng: &mut impl Rng) -> DVec3 {
    loop {
        let v = DVec3::new(
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
            rng.gen_range(-1.0..1.0),
        );
        if v.length_squared() <= 1.0 {
            return v;
        }
    }
}

/// A tet's vertex ids in increasing order (a key independent of orientation).
pub fn sorted4(mut t: [u32; 4]) -> [u32; 4] {
    t.sort_unstable();
    t
}

/// [`Domain::snap_to_facet_plane`] for one facet, its vertices looked at once: the
/// coordinates shared by all of them.
struct PlaneSnap([Option<f64>; 3]);

impl PlaneSnap {
    fn of(dom: &Domain, f: u32) -> PlaneSnap {
        let mut verts = dom.facets[f as usize].vertices();
        let mut axes = [None; 3];
        if let Some(v0) = verts.next() {
            let q0 = dom.point(v0);
            axes = [Some(q0.x), Some(q0.y), Some(q0.z)];
            for v in verts {
                let q = dom.point(v);
                for (axis, a) in axes.iter_mut().enumerate() {
                    if a.is_some_and(|c| q[axis] != c) {
                        *a = None;
                    }
                }
            }
        }
        PlaneSnap(axes)
    }

    fn apply(&self, mut p: DVec3) -> DVec3 {
        for (axis, a) in self.0.iter().enumerate() {
            if let Some(c) = a {
                p[axis] = *c;
            }
        }
        p
    }
}

/// A subsegment's closed diametric ball, slightly inflated, as
/// [`Domain::facet_subsegments_encroached_by`] tests it.
struct SubsegmentBall {
    key: (u32, u32),
    centre: DVec3,
    r2: f64,
}

/// The balls of facet `f`'s subsegments.
fn subsegment_balls(dom: &Domain, f: u32) -> Vec<SubsegmentBall> {
    dom.facets[f as usize]
        .constrained_edges()
        .into_iter()
        .map(|[x, y]| {
            let (centre, r) = diametric_ball(dom.point(x), dom.point(y));
            SubsegmentBall {
                key: seg_key(x, y),
                centre,
                r2: r * r * (1.0 + 1e-9),
            }
        })
        .collect()
}

/// A candidate point (its probe) and the small slivers inserting it would create.
#[derive(Debug)]
struct Candidate {
    n_small: usize,
    /// Smallest 1 - cos(smallest dihedral angle) among them.
    worst: f64,
    cavity: Cavity,
}

/// The boundary elements among a cavity's and its ring's edges and faces that a point
/// encroaches or whose protection the cavity would break (see
/// [`Refiner::boundary_in_cavity`]).
struct BoundaryScan<'c> {
    p: DVec3,
    /// The cavity tets.
    removed: &'c [u32],
    /// Smallest encroached subsegment.
    seg: Option<(u32, u32)>,
    /// Smallest encroached subfacet.
    facet: Option<(u32, [u32; 3])>,
    /// Smallest subfacet seen.
    any_facet: Option<(u32, [u32; 3])>,
    /// The last subfacet seen with the cavity on both sides.
    crossed: Option<Boundary>,
}

impl BoundaryScan<'_> {
    /// The edges and faces of tet `t` (finite, inside the domain; `in_cavity` if it is a
    /// cavity tet).
    #[inline]
    fn tet(&mut self, dom: &Domain, t: u32, in_cavity: bool) {
        let v = dom.dt.tet(t);
        let kind = v.map(|x| dom.kind[x as usize]);
        let on_boundary = kind.map(|k| k != VertexKind::Volume);
        let n_boundary = on_boundary.iter().filter(|&&b| b).count();
        if n_boundary < 2 {
            return; // no subsegment or subfacet among its edges and faces
        }
        // Subsegments join input and segment vertices only.
        let on_segment = kind.map(|k| matches!(k, VertexKind::Input | VertexKind::Segment(_)));
        for i in 0..4 {
            for j in i + 1..4 {
                if !(on_segment[i] && on_segment[j]) {
                    continue;
                }
                let k = seg_key(v[i], v[j]);
                if self.seg.is_some_and(|s| s <= k) || !dom.subsegs.contains_key(&k) {
                    continue; // (a smaller one is encroached already)
                }
                let (c, r) = diametric_ball(dom.point(k.0), dom.point(k.1));
                if self.p.distance_squared(c) <= r * r {
                    self.seg = Some(k);
                }
            }
            // Face i is opposite vertex i: it holds the other three, which must all lie on
            // the boundary for it to be a subfacet.
            if n_boundary < 3 || (n_boundary == 3 && on_boundary[i]) {
                continue;
            }
            let f = tri_key(FACE[i].map(|l| v[l]));
            let Some(&fi) = dom.subfacets.get(&f) else {
                continue;
            };
            let key = (fi, f);
            if self.any_facet.is_none_or(|a| key < a) {
                self.any_facet = Some(key);
            }
            if in_cavity && self.removed.contains(&dom.dt.neighbors(t)[i]) {
                self.crossed = Some(Boundary::Facet(fi, f));
            }
            if self.seg.is_none() && self.facet.is_none_or(|e| key < e) {
                let [x, y, z] = f.map(|v| dom.point(v));
                if let Some((c, r)) = equatorial_ball(x, y, z) {
                    if self.p.distance_squared(c) <= r * r {
                        self.facet = Some(key);
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests;
