//! "Clean Bad Elements" (the paper's REMOVE-SLIVER main loop): size-bad tets (R / f(c) > B)
//! first, then radius-edge-bad (rho > rho0), then slivers (sigma < sigma0). A bad tet is
//! refined from a point of its picking ball (c, delta R) that creates no small sliver (a new
//! sliver with circumradius <= b R): the centre c itself if it does not (its cavity is known
//! from the boundary check), else the best of up to `max_tries` random draws; when its
//! circumcentre encroaches a subsegment or subfacet, that boundary element is split from its
//! own picking interval or disk instead. This is keep mode's cell level: the boundary below it
//! is asked through [`FacetLevel`] (`plc_level.rs`), and Li's point choice is `levels.rs`'s.
//!
//! Refining one bad tet (`refine_tet` and the helpers it returns through) decides and says
//! what it did as an [`Outcome`]; the loop is `queue::work_off`'s (shared with the approximate
//! mode's cell level), which counts the refusals per reason, and `Refiner`'s
//! [`BadLevel::record`] keeps the level's own books (the deferred queue, the tets left at once
//! when looked at again).

use super::domain::{Domain, VertexKind};
use super::levels::{pick_in_ball, Conflict, FacetLevel, Picker, Request};
use super::mark::Regions;
use super::outcome::{Outcome, Refusal};
use super::plc_level::Boundary;
use super::queue::{work_off, BadLevel, BadQueues, Class, Ended};
use super::recover::Settled;
use crate::delaunay::{Cavity, Probe};
use crate::geom::screen::{longest_edge_direct as longest_edge, sliver_measures};
use crate::geom::{circum_offset_crossed, circumsphere, insphere, orient3d};
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::Refusals;
use crate::run::spacing::Spacing;
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;

/// Badness classes, in refinement priority order (the highest first).
const SIZE: Class = Class::Size;
const RATIO: Class = Class::Ratio;
const SLIVER: Class = Class::Sliver;

/// A queued bad tet: its class (which queue) and the tet as it was when judged (a tet id is
/// reused once the tet is gone, so the vertices tell whether it is still the same tet). 24
/// bytes: the queues hold up to about one entry per tet of the final mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Bad {
    class: Class,
    tet: u32,
    verts: [u32; 4],
}

/// A tet's classification before its spacing is known ([`Refiner::prepare_classify`]).
enum Step {
    Done(Option<Bad>),
    Need(Pending),
}

/// A tet waiting for the spacing at `query` (the centroid next to a small angle, where
/// `circum` is None; else the circumcentre, `circum` its offset from the first vertex and the
/// orientation determinant).
#[derive(Clone, Copy)]
struct Pending {
    tet: u32,
    verts: [u32; 4],
    tag: u32,
    query: DVec3,
    circum: Option<(DVec3, f64)>,
}

/// The most tets classified with one batched spacing evaluation (`Spacing::at_many`).
pub const SPACING_BATCH: usize = 4096;

/// Reused buffers of the batched classification.
#[derive(Default)]
struct Batch {
    steps: Vec<Step>,
    queries: Vec<DVec3>,
    values: Vec<f64>,
}

/// Circumradius / longest edge above which a bad tet is deferred (see `refine_tet`).
const DEFER_RADIUS_PER_EDGE: f64 = 3.0;

pub struct Refiner<'a> {
    pub dom: &'a mut Domain,
    pub params: &'a Params,
    pub spacing: &'a dyn Spacing,
    pub regions: &'a Regions,
    /// Li's point choice (small slivers, random draws), shared with the facet level's splits.
    picker: Picker,
    /// One FIFO queue per badness class, the highest class served first, then the flat tets
    /// with a far circumcentre ([`Outcome::Deferred`]), served after every queue is empty.
    queues: BadQueues<Bad>,
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
    /// The bounding box of the input vertices.
    domain_box: BoundingBox,
    /// Buffers of the batched classification (`push_tets`).
    batch: Batch,
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
            picker: Picker::new(
                ChaCha8Rng::seed_from_u64(params.seed),
                params.delta,
                params.max_tries,
                params.b,
                params.sigma0,
                params.min_dihedral,
            ),
            dom,
            params,
            spacing,
            regions,
            queues: BadQueues::default(),
            refusals: Refusals::default(),
            blocked_by_small_angle: FxHashSet::default(),
            futile: FxHashSet::default(),
            stop_reason: None,
            domain_box: BoundingBox { lo, hi },
            batch: Batch::default(),
        }
    }

    /// The spacing value `f` the user's function gave at `p`, for a tet of region tag `tag`:
    /// capped by the region's maximum size; a value that is not finite and positive is an
    /// error naming `p`.
    fn capped_spacing(&self, p: DVec3, f: f64, tag: u32) -> Result<f64, MeshError> {
        if !(f.is_finite() && f > 0.0) {
            return Err(MeshError::BadSpacing { point: p, value: f });
        }
        Ok(
            match self.regions.max_size.get(tag as usize).copied().flatten() {
                Some(m) => f.min(m),
                None => f,
            },
        )
    }

    /// Classification of tet `t` up to the spacing it needs: done (not a domain tet, or a
    /// sliver without a circumsphere), or the point whose spacing decides the rest
    /// ([`Refiner::finish_classify`]). Next to a small angle that point is the centroid (size
    /// by the longest edge), else the circumcentre.
    fn prepare_classify(&self, t: u32) -> Step {
        // Tets logged as created may have been deleted again by a later insertion.
        if !self.dom.dt.is_alive(t) {
            return Step::Done(None);
        }
        let tag = self.dom.dt.tag(t);
        if tag == 0 || !self.dom.dt.is_finite(t) {
            return Step::Done(None);
        }
        let verts = self.dom.dt.tet(t);
        let [a, b, c, d] = verts.map(|v| self.dom.point(v));
        let near = verts.iter().any(|&v| self.dom.near_small_angle(v));
        if near {
            // Next to a small input angle size is measured by the longest edge: the tets there
            // may stay flat, and a flat tet's circumradius says nothing about its size.
            return Step::Need(Pending {
                tet: t,
                verts,
                tag,
                query: (a + b + c + d) * 0.25,
                circum: None,
            });
        }
        let (u, v, w) = (b - a, c - a, d - a);
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let lu = [u.length_squared(), v.length_squared(), w.length_squared()];
        let det = orient3d(a, b, c, d);
        let Some(offset) = circum_offset_crossed([vw, wu, uv], lu, det) else {
            return Step::Done(Some(Bad {
                class: SLIVER,
                tet: t,
                verts,
            }));
        };
        Step::Need(Pending {
            tet: t,
            verts,
            tag,
            query: a + offset,
            circum: Some((offset, det)),
        })
    }

    /// The rest of [`Refiner::prepare_classify`] given `f`, the spacing at the pending tet's
    /// query point (region cap applied): the tet's badness class, if any.
    fn finish_classify(&self, p: &Pending, f: f64) -> Option<Bad> {
        let Pending {
            tet: t,
            verts,
            circum,
            ..
        } = *p;
        let [a, b, c, d] = verts.map(|v| self.dom.point(v));
        let bad = |class| {
            Some(Bad {
                class,
                tet: t,
                verts,
            })
        };
        let near = circum.is_none();
        if near {
            let xi = longest_edge(a, b, c, d) / (EDGE_PER_RADIUS * f);
            if xi > self.params.size_factor {
                return bad(SIZE);
            }
        }
        // The measures, each computed only when the tests before it pass, sharing the edge
        // vectors and cross products: the circumsphere (geom's one formula), then the sliver
        // screen (geom::screen).
        let (u, v, w) = (b - a, c - a, d - a);
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let lu = [u.length_squared(), v.length_squared(), w.length_squared()];
        let (offset, det) = match circum {
            Some(known) => known,
            None => {
                let det = orient3d(a, b, c, d);
                let Some(offset) = circum_offset_crossed([vw, wu, uv], lu, det) else {
                    return bad(SLIVER);
                };
                (offset, det)
            }
        };
        let circumradius = offset.length();
        if !near {
            let xi = circumradius / f;
            if xi > self.params.size_factor {
                return bad(SIZE);
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
            return bad(RATIO);
        }
        let n = [
            (d - b).cross(c - b).length_squared(),
            vw.length_squared(),
            wu.length_squared(),
            uv.length_squared(),
        ];
        if self.picker.screen().clears(det, e, l2, n) {
            return None;
        }
        let (sigma, max_cos_dihedral) = sliver_measures(a, b, c, d, l2);
        if self.picker.slivers.is_sliver(sigma, max_cos_dihedral) {
            bad(SLIVER)
        } else {
            None
        }
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

    /// Classifies `tets` and queues the bad ones, in their order. The spacing they need is
    /// evaluated in batches (one `Spacing::at_many` call per [`SPACING_BATCH`] tets: after an
    /// insertion, one call for all the tets it created), each at the same point as one by one,
    /// so the values and the queues are the same.
    fn push_tets(&mut self, tets: &[u32]) -> Result<(), MeshError> {
        let mut scratch = std::mem::take(&mut self.batch);
        let result = self.push_tets_with(tets, &mut scratch);
        self.batch = scratch;
        result
    }

    fn push_tets_with(&mut self, tets: &[u32], s: &mut Batch) -> Result<(), MeshError> {
        for chunk in tets.chunks(SPACING_BATCH) {
            s.steps.clear();
            s.queries.clear();
            for &t in chunk {
                let step = self.prepare_classify(t);
                if let Step::Need(p) = &step {
                    s.queries.push(p.query);
                }
                s.steps.push(step);
            }
            s.values.clear();
            s.values.resize(s.queries.len(), f64::NAN);
            if !s.queries.is_empty() {
                self.spacing.at_many(&s.queries, &mut s.values);
            }
            let mut k = 0;
            for step in &s.steps {
                let b = match step {
                    Step::Done(b) => *b,
                    Step::Need(p) => {
                        let f = self.capped_spacing(p.query, s.values[k], p.tag)?;
                        k += 1;
                        self.finish_classify(p, f)
                    }
                };
                if let Some(b) = b {
                    self.queues.push(b.class, b);
                }
            }
        }
        Ok(())
    }

    /// Runs the refinement until no bad tet is left or a budget stops it (the loop is
    /// `queue::work_off`'s, with this level's hooks).
    pub fn run(&mut self, progress: &mut dyn FnMut(usize) -> bool) -> Result<(), MeshError> {
        let all: Vec<u32> = self.dom.dt.finite_tet_ids().collect();
        self.push_tets(&all)?;
        match work_off(self, progress)? {
            Ended::Cancelled => Err(MeshError::Cancelled),
            Ended::Done | Ended::Stopped => Ok(()),
        }
    }

    /// Whether queued bad tet `bad` is still a tet of the mesh.
    fn is_current(&self, bad: Bad) -> bool {
        self.dom.dt.is_alive(bad.tet) && self.dom.dt.tet(bad.tet) == bad.verts
    }

    /// Stops refinement for `reason` (a budget), counting the bad tets still queued (`bad`
    /// among them while it is a tet) as left by the budget.
    fn stop(&mut self, reason: String, bad: Bad) {
        let queued = self.queues.iter();
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
        let near = bad.verts.iter().any(|&v| self.dom.near_small_angle(v));
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
        let Probe::Cavity(cavity) = self.dom.dt.probe(centre, Some(bad.tet)) else {
            // The centre is a vertex already (it breaks nothing).
            return match near {
                true => Ok(Outcome::Refused(Refusal::NearSmallAngle)),
                false => self.insert_from_picking_ball(bad, centre, r, None),
            };
        };
        // Next to a small angle: only the centre, and only if it breaks no boundary (see
        // `screen_circumcentre`).
        let request = match near {
            true => Request::ShapeNearSmallAngle,
            false => Request::Shape,
        };
        let conflict = self.dom.conflict(&cavity, r, request);
        if let Some(outcome) = self.yield_to_boundary(bad.tet, conflict)? {
            return Ok(outcome);
        }
        match near {
            true => self.insert_volume_vertex(centre, bad.tet, Some(cavity)),
            false => self.insert_from_picking_ball(bad, centre, r, Some(cavity)),
        }
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
            // boundary elements far smaller than r (the cascade the facet level refuses),
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
        // The chosen point breaks no boundary: a candidate is only kept after that check on
        // its cavity, and the centre passed it. When it was the last one probed (the usual
        // case: its draw ended the search), its cavity is still current and the insertion
        // reuses it.
        let dom = &mut *self.dom;
        match pick_in_ball(dom, &mut self.picker, centre, centre_cavity, r, bad.tet) {
            Some(cavity) => self.insert_volume_vertex(cavity.point(), bad.tet, Some(cavity)),
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

    /// Refines boundary element `b` that a bad tet's point encroaches (the facet level splits
    /// it from its picking region and restores empty encroachment around the new vertex), then
    /// queues the new bad tets.
    fn refine_boundary(&mut self, b: Boundary) -> Result<Outcome, MeshError> {
        let outcome = self.dom.refine_encroached(b, &mut self.picker)?;
        if !matches!(outcome, Outcome::Refused(_)) {
            self.push_recent()?;
        }
        Ok(outcome)
    }

    /// Inserts `p` (for size-bad tet `t` of size `r`) unless it would break the boundary; then
    /// the boundary element is split instead if it is not much smaller than `r`, else nothing.
    fn insert_volume_point(&mut self, p: DVec3, r: f64, t: u32) -> Result<Outcome, MeshError> {
        let Probe::Cavity(cavity) = self.dom.dt.probe(p, Some(t)) else {
            // p is a vertex already (a flat tet's centroid can be)
            return Ok(Outcome::Refused(Refusal::Duplicate));
        };
        let conflict = self.dom.conflict(&cavity, r, Request::SizeNearSmallAngle);
        if let Some(outcome) = self.yield_to_boundary(t, conflict)? {
            return Ok(outcome);
        }
        self.insert_volume_vertex(p, t, Some(cavity))
    }

    /// What bad tet `t` does when its point conflicts with the boundary: the encroached
    /// element is refined first, or the tet is left (for a cascade, after restoring the
    /// boundary around it: all that may help). None when the point breaks nothing.
    fn yield_to_boundary(
        &mut self,
        t: u32,
        conflict: Conflict<Boundary>,
    ) -> Result<Option<Outcome>, MeshError> {
        Ok(Some(match conflict {
            Conflict::Free => return Ok(None),
            Conflict::Encroaches(b) => self.refine_boundary(b)?,
            // When restoring split anything, the encroached element (and the tet) may be
            // gone: it is never split for this tet, which `run` looks at again if it
            // survived. When it split nothing, the tet is left for good.
            Conflict::Refused(reason @ (Refusal::Cascade | Refusal::CascadeNearSmallAngle)) => {
                self.resettle_or_refuse(t, reason)?
            }
            Conflict::Refused(reason) => Outcome::Refused(reason),
        }))
    }

    /// Restores empty encroachment around tet `t` (a vertex of `t` may be the encroacher that
    /// made it hug the boundary): `Resettled` if that split anything, else refused for
    /// `reason`.
    fn resettle_or_refuse(&mut self, t: u32, reason: Refusal) -> Result<Outcome, MeshError> {
        let n_before = self.dom.dt.num_vertices();
        self.dom.queue_boundary_around(t);
        Ok(match self.settle_and_queue(Outcome::Resettled)? {
            Outcome::Resettled if self.dom.dt.num_vertices() == n_before => {
                Outcome::Refused(reason)
            }
            outcome => outcome,
        })
    }
}

impl BadLevel for Refiner<'_> {
    type Bad = Bad;
    type Error = MeshError;

    fn queues(&mut self) -> &mut BadQueues<Bad> {
        &mut self.queues
    }

    fn still_bad(&mut self, bad: &mut Bad) -> bool {
        self.is_current(*bad)
    }

    fn within_budget(&mut self, bad: &Bad) -> bool {
        if self.dom.dt.num_vertices() < self.params.max_vertices {
            return true;
        }
        let max = self.params.max_vertices;
        self.stop(format!("vertex budget max_vertices = {max} reached"), *bad);
        false
    }

    fn num_vertices(&self) -> usize {
        self.dom.dt.num_vertices()
    }

    fn refine(&mut self, bad: Bad, deferred: bool) -> Result<Outcome, MeshError> {
        self.refine_tet(bad, !deferred)
    }

    fn refusals(&mut self) -> &mut Refusals {
        &mut self.refusals
    }

    /// The books of one refined bad tet (`n_before`: the vertex count before; a refusal is
    /// counted already): the tets left within a small angle's influence or left for good,
    /// the deferred queue, and a second look at a tet that survived a split. Returns false
    /// when refinement must stop.
    fn record(&mut self, bad: Bad, outcome: Outcome, n_before: usize) -> Result<bool, MeshError> {
        match outcome {
            Outcome::Refused(reason) => {
                if reason.remembered() {
                    self.futile.insert(sorted4(bad.verts));
                }
                if reason.within_small_angle() {
                    self.blocked_by_small_angle.insert(sorted4(bad.verts));
                }
            }
            Outcome::Deferred => self.queues.defer(bad),
            Outcome::BudgetSpent => {
                let max = super::recover::MAX_RECOVERY_SPLITS;
                self.stop(
                    format!("boundary split budget ({max} splits after one insertion) spent"),
                    bad,
                );
                return Ok(false);
            }
            Outcome::Inserted | Outcome::Split(_) | Outcome::Queued(_) | Outcome::Resettled => {
                // A boundary split need not destroy the tet that asked for it: look again
                // (only if something was inserted, or it would come back forever).
                if self.dom.dt.num_vertices() > n_before && self.is_current(bad) {
                    self.push_tets(&[bad.tet])?;
                }
            }
        }
        Ok(true)
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

#[cfg(test)]
mod tests;
