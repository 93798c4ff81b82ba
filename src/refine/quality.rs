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

use super::classify::{Classifier, Step};
use super::domain::{Domain, VertexKind};
use super::levels::{Conflict, Picker};
use super::mark::Regions;
use super::outcome::{Outcome, Refusal};
use super::plan::{split_seed, Plan, Planner};
use super::plc_level::{Boundary, SplitPlan};
use super::queue::{work_off_planned, BadLevel, BadQueues, Class, Ended, PlannedLevel, Taken};
use super::recover::Settled;
use crate::delaunay::{ProbeBuffers, INFINITE};
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::Refusals;
use crate::run::spacing::Spacing;
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rustc_hash::FxHashSet;

/// A queued bad tet: its class (which queue) and the tet as it was when judged (a tet id is
/// reused once the tet is gone, so the vertices tell whether it is still the same tet). 24
/// bytes: the queues hold up to about one entry per tet of the final mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) struct Bad {
    pub(super) class: Class,
    pub(super) tet: u32,
    pub(super) verts: [u32; 4],
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
    /// Buffers of the plans made on the calling thread (`plan_now`).
    probe_buf: ProbeBuffers,
    /// Where the tets logged since the last step begin (`push_recent` gives them regions).
    retag_from: usize,
    /// Batches chosen so far, and per vertex the last batch that claimed it (`select`).
    batches: u32,
    claims: Vec<u32>,
    /// An error met where it could not be returned (classifying when a budget stops the
    /// loop); `run` returns it.
    failed: Option<MeshError>,
}

#[derive(Debug, Clone, Copy)]
pub(super) struct BoundingBox {
    lo: DVec3,
    hi: DVec3,
}

impl BoundingBox {
    pub(super) fn contains(&self, p: DVec3) -> bool {
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
            probe_buf: ProbeBuffers::default(),
            retag_from: 0,
            batches: 0,
            claims: Vec::new(),
            failed: None,
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

    /// After a refinement step: the tets it created get their regions when it inserted a
    /// boundary vertex (a volume point's cavity never holds a subfacet — the refiner splits
    /// what it would encroach instead —, so its tets inherit the right region). They stay
    /// logged, and are classified after the batch ([`Self::classify_created`]).
    fn push_recent(&mut self) -> Result<(), MeshError> {
        if std::mem::take(&mut self.dom.boundary_inserted) {
            let log = std::mem::take(&mut self.dom.created_log);
            self.dom.retag_created(&log[self.retag_from..]);
            self.dom.created_log = log;
        }
        self.retag_from = self.dom.created_log.len();
        Ok(())
    }

    /// Classifies the tets created since the last call and queues the bad ones (each once: a
    /// slot reused is logged again), in slot order.
    fn classify_created(&mut self) -> Result<(), MeshError> {
        let mut log = std::mem::take(&mut self.dom.created_log);
        self.retag_from = 0;
        log.sort_unstable();
        log.dedup();
        let result = self.push_tets(&log);
        log.clear();
        self.dom.created_log = log;
        result
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
            let judge = self.classifier();
            s.steps = crate::parallel::map_collect(chunk, |&t| judge.prepare(t));
            s.queries.clear();
            s.queries
                .extend(s.steps.iter().filter_map(|step| match step {
                    Step::Need(p) => Some(p.query),
                    Step::Done(_) => None,
                }));
            s.values.clear();
            s.values.resize(s.queries.len(), f64::NAN);
            if !s.queries.is_empty() {
                self.spacing.at_many(&s.queries, &mut s.values);
            }
            let mut pending = Vec::with_capacity(s.queries.len());
            for step in &s.steps {
                if let Step::Need(p) = step {
                    let f = self.capped_spacing(p.query, s.values[pending.len()], p.tag)?;
                    pending.push((*p, f));
                }
            }
            let judge = self.classifier();
            let judged = crate::parallel::map_collect(&pending, |(p, f)| judge.finish(p, *f));
            let mut judged = judged.into_iter();
            for step in &s.steps {
                let b = match step {
                    Step::Done(b) => *b,
                    Step::Need(_) => judged.next().flatten(),
                };
                if let Some(b) = b {
                    self.queues.push(b.class, b);
                }
            }
        }
        Ok(())
    }

    /// The judge of this level's tets.
    fn classifier(&self) -> Classifier<'_> {
        Classifier {
            dom: self.dom,
            params: self.params,
            picker: &self.picker,
        }
    }

    /// Runs the refinement until no bad tet is left or a budget stops it (the loop is
    /// `queue::work_off`'s, with this level's hooks).
    pub fn run(&mut self, progress: &mut dyn FnMut(usize) -> bool) -> Result<(), MeshError> {
        self.dom.build_split_caches();
        let all: Vec<u32> = self.dom.dt.finite_tet_ids().collect();
        self.push_tets(&all)?;
        let ended = work_off_planned(self, progress)?;
        self.dom.dt.untrack_removals();
        if let Some(e) = self.failed.take() {
            return Err(e);
        }
        match ended {
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
        if let Err(e) = self.classify_created() {
            self.failed.get_or_insert(e);
        }
        let queued = self.queues.iter();
        let left: FxHashSet<u32> = std::iter::once(&bad)
            .chain(queued)
            .filter(|b| self.is_current(**b))
            .map(|b| b.tet)
            .collect();
        self.refusals.count_budget(left.len());
        self.stop_reason = Some(reason);
    }

    /// The planner of this level: what a plan reads.
    fn planner(&self) -> Planner<'_> {
        Planner {
            dom: self.dom,
            params: self.params,
            picker: &self.picker,
            futile: &self.futile,
            domain_box: self.domain_box,
        }
    }

    /// Plans bad tet `bad` (`may_defer`: it was not deferred already) on the mesh as it is now.
    fn plan_now(&mut self, bad: Bad, may_defer: bool) -> Plan {
        let mut buf = std::mem::take(&mut self.probe_buf);
        let plan = self.planner().plan(bad, may_defer, &mut buf);
        self.probe_buf = buf;
        plan
    }

    /// Carries out `plan` for bad tet `bad`: says what it did, and `run` keeps the books.
    fn apply(&mut self, bad: Bad, plan: Plan) -> Result<Outcome, MeshError> {
        match plan {
            Plan::Refuse(reason) => Ok(Outcome::Refused(reason)),
            Plan::Defer => Ok(Outcome::Deferred),
            Plan::Resettle { reason, .. } => self.resettle_or_refuse(bad.tet, reason),
            // (Never `Free`: the planner inserts then.)
            Plan::Yield {
                conflict, split, ..
            } => Ok(self
                .yield_to_boundary(bad.tet, conflict, split)?
                .unwrap_or(Outcome::Refused(Refusal::Duplicate))),
            Plan::Insert(cavity) => {
                self.dom
                    .insert_point(cavity.point(), VertexKind::Volume, None, Some(&cavity))?;
                self.settle_and_queue(Outcome::Inserted)
            }
            Plan::InsertAt(p) => self.insert_volume_vertex(p, bad.tet),
        }
    }

    /// Inserts volume vertex `p` (located from tet `hint`), restores empty encroachment around
    /// it and queues the new bad tets.
    fn insert_volume_vertex(&mut self, p: DVec3, hint: u32) -> Result<Outcome, MeshError> {
        self.dom
            .insert_point(p, VertexKind::Volume, Some(hint), None)?;
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
    fn refine_boundary(
        &mut self,
        b: Boundary,
        planned: Option<SplitPlan>,
    ) -> Result<Outcome, MeshError> {
        // A split planned with the batch is carried out while it holds; else planned now, by
        // the same code with the same draws.
        let plan = match planned {
            Some(plan) if plan.still_valid(self.dom) => plan,
            _ => {
                let mut picker = self.picker.reseeded(split_seed(self.params.seed, b));
                let mut buf = std::mem::take(&mut self.probe_buf);
                let plan = self.dom.plan_split(b, &mut picker, &mut buf);
                self.probe_buf = buf;
                plan
            }
        };
        let outcome = self.dom.apply_split(plan)?;
        if !matches!(outcome, Outcome::Refused(_)) {
            self.push_recent()?;
        }
        Ok(outcome)
    }

    /// What bad tet `t` does when its point conflicts with the boundary: the encroached
    /// element is refined first, or the tet is left (for a cascade, after restoring the
    /// boundary around it: all that may help). None when the point breaks nothing.
    fn yield_to_boundary(
        &mut self,
        t: u32,
        conflict: Conflict<Boundary>,
        split: Option<SplitPlan>,
    ) -> Result<Option<Outcome>, MeshError> {
        Ok(Some(match conflict {
            Conflict::Free => return Ok(None),
            Conflict::Encroaches(b) => self.refine_boundary(b, split)?,
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
        let plan = self.plan_now(bad, !deferred);
        self.apply(bad, plan)
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

impl PlannedLevel for Refiner<'_> {
    type Plan = Plan;

    fn batch_size(&self) -> usize {
        // Small meshes: fewer plans at once, as more of them would meet.
        (self.dom.dt.num_finite_tets() / PLAN_TETS_PER_ENTRY).clamp(1, PLAN_BATCH)
    }

    fn select(&mut self, window: Taken<Bad>, size: usize) -> (Taken<Bad>, Taken<Bad>) {
        // Tets sharing a vertex with a chosen tet or its neighbours are left for a later
        // batch: their cavities would likely meet. A vertex is claimed by this batch when its
        // stamp is the batch's number.
        self.batches += 1;
        let batch = self.batches;
        let mut claims = std::mem::take(&mut self.claims);
        claims.resize(self.dom.dt.num_vertex_ids(), 0);
        let (mut chosen, mut rest) = (Vec::with_capacity(size), Vec::new());
        for (bad, source) in window {
            if !self.is_current(bad) {
                continue;
            }
            let dt = &self.dom.dt;
            let mut near = [INFINITE; 8];
            near[..4].copy_from_slice(&bad.verts);
            for (i, apex) in near[4..].iter_mut().enumerate() {
                let (n, j) = dt.mirror(bad.tet, i);
                *apex = dt.tet(n)[j];
            }
            let free = |v: &u32| *v == INFINITE || claims[*v as usize] != batch;
            if chosen.len() < size && near.iter().all(free) {
                for v in near.into_iter().filter(|&v| v != INFINITE) {
                    claims[v as usize] = batch;
                }
                chosen.push((bad, source));
            } else {
                rest.push((bad, source));
            }
        }
        self.claims = claims;
        (chosen, rest)
    }

    fn plan_batch(&mut self, batch: &[(Bad, bool)]) -> Vec<Plan> {
        self.dom.dt.track_removals();
        let planner = self.planner();
        crate::parallel::map_collect_init(
            batch,
            PLAN_PARALLEL_MIN,
            PLAN_PARALLEL_MIN / 2,
            ProbeBuffers::default,
            |buf, &(bad, deferred)| planner.plan(bad, !deferred, buf),
        )
    }

    fn refine_planned(
        &mut self,
        bad: Bad,
        deferred: bool,
        plan: Option<Plan>,
    ) -> Result<Outcome, MeshError> {
        let plan = match plan {
            Some(plan) if plan.still_valid(self.dom) => plan,
            _ => self.plan_now(bad, !deferred),
        };
        self.apply(bad, plan)
    }

    fn after_batch(&mut self) -> Result<(), MeshError> {
        self.classify_created()
    }
}

/// The most bad tets planned together (`PlannedLevel::batch_size`), and the tets of the mesh
/// per planned tet at least (so that few plans of a batch meet).
const PLAN_BATCH: usize = 512;
const PLAN_TETS_PER_ENTRY: usize = 64;

/// Batches of fewer bad tets are planned on the calling thread.
const PLAN_PARALLEL_MIN: usize = 32;

/// A tet's vertex ids in increasing order (a key independent of orientation).
pub fn sorted4(mut t: [u32; 4]) -> [u32; 4] {
    t.sort_unstable();
    t
}

#[cfg(test)]
mod tests;
