//! Mesh improvement after refinement (Klingner & Shewchuk, "Aggressive tetrahedral mesh
//! improvement", IMR 2007): on the final [`TetMesh`], with no knowledge of how it was made.
//!
//! - `quality`: the objective, the smallest sine of the dihedral angles (small for angles near
//!   0 and near 180 degrees alike; below the target a large angle counts more than a small
//!   one), capped so that a radius-edge ratio over the bound scores as badly as an angle
//!   under the target;
//! - `topo`: the working mesh (tet slots, vertex stars, boundary triangles, edge rings);
//! - `constraints`: how each vertex may move (input vertices never, segment vertices along the
//!   segment, facet vertices in the facet's plane), and the flat facet patches;
//! - `flips`: edge removal (3-2, 4-4 and larger rings by dynamic programming), the boundary 2-2
//!   flip inside one facet patch, face removal (2-3) and multi-face removal;
//! - `smooth`: non-smooth optimisation of the worst objective of a vertex's star;
//! - `insert`: a new vertex joined to the outer faces of a cavity around the tet, placed by
//!   the same optimisation.
//!
//! The driver takes the tets whose objective is below the target, worst first, and tries the
//! best topological change touching the tet, then smoothing of its vertices, then insertion.
//! Every accepted change keeps every tet it makes positively oriented (exact `orient3d`) and
//! strictly raises the worst objective of the tets it replaces or moves. Passes repeat until one changes
//! nothing or the budget is spent. Order: by objective, then tet slot; no hashing decides
//! anything, so the result is deterministic.
//!
//! Threads (`batch`): the driver stays serial (one tet at a time, in heap order, on the
//! calling thread), but the plans it asks for, which only read the mesh (the best flip, the
//! smoothing of a vertex, an insertion, a deletion), are made ahead in batches on the run's
//! threads, each with its footprint (the vertices whose stars and tets it read). A plan made
//! ahead is used only if no change since its batch began marked a vertex of its footprint,
//! and made again otherwise: it is then bit for bit the plan the driver would make now. So the
//! changes, their order, the stats and the mesh are those of the one-thread run for every
//! thread count (with one thread nothing is planned ahead); the threads decide only how much
//! planning is done twice. The working mesh's set-up (the tets' objectives and radius-edge
//! ratios, the vertex stars) is also spread over the threads, each value depending on its own
//! tet or vertex only.

mod batch;
mod constraints;
mod delete;
mod flips;
mod insert;
pub mod quality;
mod rho_repair;
mod smooth;
mod topo;

use crate::geom::orient3d;
use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::run::error::MeshError;
use crate::run::params::{Params, SurfaceMode};
use crate::run::report::ImproveStats;
use constraints::Constraint;
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::cmp::Reverse;
use std::collections::BinaryHeap;
use topo::Work;

/// Boundary marker of triangles the improver must keep exactly as they are (never flipped,
/// split nor moved, even where coplanar with a neighbour): faces that another mesh shares,
/// such as a zone's outer faces (`partition::zone`).
pub const HELD_MARKER: i32 = i32::MIN + 2;

/// What the improver is asked to do.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Options {
    /// Full improvement (true) or only the removal of flat and inverted tets (false: the
    /// refinement's Delaunay mesh is kept wherever it is valid).
    pub improve: bool,
    /// Tets whose smallest dihedral-angle sine is below sin(target_deg) are worked on.
    pub target_deg: f64,
    /// Passes at most over the bad tets.
    pub max_passes: usize,
    /// Radius-edge ratio above which a tet counts as bad like one below the target angle
    /// (`quality::objective`); infinite: angles only.
    pub max_rho: f64,
    /// Radius-edge bound no change may break: a change that would make a tet exceed it is
    /// refused unless a tet it replaces exceeded it already, and then the new ones may not
    /// exceed the worst of those (`ImproveStats::rho_vetoes` counts the refusals); infinite: none.
    pub keep_rho: f64,
    /// Radius-edge bound that tets are repaired to after the passes, by a vertex at or short
    /// of their circumcentre (`rho_repair`; the zones of a partitioned run, where refinement
    /// could not put it in); infinite: no repair.
    pub repair_rho: f64,
}

impl Default for Options {
    fn default() -> Self {
        Options {
            improve: true,
            target_deg: 26.0,
            max_passes: 4,
            max_rho: f64::INFINITY,
            keep_rho: f64::INFINITY,
            repair_rho: f64::INFINITY,
        }
    }
}

pub(crate) struct Improver<'s> {
    w: Work,
    cons: Vec<Constraint>,
    normals: Vec<DVec3>,
    /// Approximate mode: the boundary vertices that slide on the input surface, and how.
    slide: Option<&'s dyn SurfaceSlide>,
    stats: ImproveStats,
}

/// How the boundary vertices of an approximated surface may move (approximate mode): within
/// their tangent plane, then put back on the input surface, as long as the boundary triangles
/// around them stay close to it.
///
/// `Sync`: the improver plans on the run's threads (`batch`), and every answer must depend on
/// the arguments only.
pub trait SurfaceSlide: Sync {
    /// Whether boundary vertex `v` may move (not at a corner).
    fn slides(&self, v: u32) -> bool;
    /// For a vertex on a feature curve (at `at`): the curve's direction there (it moves along
    /// it); None for a vertex inside a patch (it moves in its tangent plane).
    fn along(&self, v: u32, at: DVec3) -> Option<DVec3>;
    /// `x` put on the part of the input surface where `v` may lie, or None.
    fn project(&self, v: u32, x: DVec3) -> Option<DVec3>;
    /// Whether a boundary triangle with these corners stays within the distance bound.
    fn keeps_close(&self, triangle: [DVec3; 3]) -> bool;
}

/// Objective above which a tet's float orientation is taken as its exact one (it is a ratio of
/// the determinant to products of edge lengths and face areas: rounding cannot reach it).
const SURELY_POSITIVE: f64 = 1e-6;

/// The climb (`Improver::climb`): rounds at most, degrees gained per round, the most tets a
/// round may work on, and the angle it stops at.
const CLIMB_ROUNDS: usize = 12;
const CLIMB_STEP_DEG: f64 = 2.0;
const CLIMB_MAX_TETS: usize = 200;
const CLIMB_LIMIT_DEG: f64 = 45.0;

/// The worst angle a radius-edge repair may make (`Options::repair_rho`): the passes after it
/// work on the angles around its vertex.
const REPAIR_FLOOR_DEG: f64 = 10.0;
/// Radius-edge repairs, each followed by the passes, at most.
const REPAIR_CYCLES: usize = 3;

/// Smoothings of one vertex per pass at most (each must gain, but gains can be small).
const MAX_SMOOTHINGS: u8 = 2;

/// A heap entry: the tet's objective (`key`), slot and vertices.
type Entry = (u64, u32, [u32; 4]);

/// Total order key of an objective value (worst first out of a max-heap of `Reverse`).
fn key(q: f64) -> u64 {
    let b = q.to_bits();
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// Improves `mesh`. `input` is the domain it was made from (keep mode): with it, boundary
/// vertices move within their facet or segment and boundary triangles of one facet may flip;
/// without it (an existing mesh) the boundary stays as it is.
pub fn improve(
    mesh: &TetMesh,
    input: Option<&PlcInput>,
    opts: &Options,
) -> (TetMesh, ImproveStats) {
    improve_with(mesh, input, opts, None)
}

/// [`improve`], with the boundary vertices `slide` names moving on the input surface (an
/// approximated surface; `input` is then None).
pub fn improve_with(
    mesh: &TetMesh,
    input: Option<&PlcInput>,
    opts: &Options,
    slide: Option<&dyn SurfaceSlide>,
) -> (TetMesh, ImproveStats) {
    let start = std::time::Instant::now();
    let objective = quality::Objective::new(opts.target_deg, opts.max_rho);
    improve_work(Work::new(mesh, objective), input, opts, slide, start)
}

/// [`improve_with`] on a mesh it owns: the mesh is freed once its working copy is built, so
/// the two are not held together with the output.
fn improve_owned(
    mesh: TetMesh,
    input: Option<&PlcInput>,
    opts: &Options,
    slide: Option<&dyn SurfaceSlide>,
) -> (TetMesh, ImproveStats) {
    let start = std::time::Instant::now();
    let objective = quality::Objective::new(opts.target_deg, opts.max_rho);
    let w = Work::new(&mesh, objective);
    drop(mesh);
    improve_work(w, input, opts, slide, start)
}

fn improve_work(
    mut w: Work,
    input: Option<&PlcInput>,
    opts: &Options,
    slide: Option<&dyn SurfaceSlide>,
    start: std::time::Instant,
) -> (TetMesh, ImproveStats) {
    w.set_rho_limit(opts.keep_rho);
    let (mut cons, normals) = constraints::classify(&mut w, input);
    if let Some(s) = slide {
        constraints::let_slide(&w, &mut cons, s);
    }
    let mut im = Improver {
        w,
        cons,
        normals,
        slide,
        stats: ImproveStats::default(),
    };
    im.stats.degenerate_before = (0..im.w.tets.len())
        .filter(|&t| im.w.q[t] < SURELY_POSITIVE && !im.w.positive(im.w.tets[t]))
        .count();
    if opts.improve || im.stats.degenerate_before > 0 {
        im.run(opts);
    }
    let floor = REPAIR_FLOOR_DEG.to_radians().sin();
    for _ in 0..REPAIR_CYCLES {
        if !opts.improve
            || !opts.repair_rho.is_finite()
            || im.repair_rho(opts.repair_rho, floor, opts.target_deg.to_radians().sin()) == 0
        {
            break;
        }
        // The bound gives way only where the repairs left it unmet.
        im.w.set_rho_limit(opts.keep_rho);
        im.run(opts);
    }
    im.stats.seconds = start.elapsed().as_secs_f64();
    (im.w.into_mesh(), im.stats)
}

impl Improver<'_> {
    /// `Work::keeps_rho` as a yes or no, counting the refusals and where the bound gave way
    /// (for the plan running on this thread: `batch::tallied`).
    fn keeps_rho(&self, old: &[u32], new: impl IntoIterator<Item = [DVec3; 4]>) -> bool {
        match self.w.keeps_rho(old, new) {
            topo::RhoCheck::Keeps => true,
            topo::RhoCheck::GivesWay => {
                batch::count_rho(false);
                true
            }
            topo::RhoCheck::Vetoed => {
                batch::count_rho(true);
                false
            }
        }
    }

    fn bad(&self, t: u32, target: f64, improve: bool) -> bool {
        let q = self.w.q[t as usize];
        if improve && q < target {
            return true;
        }
        // A clearly positive objective needs a clearly positive determinant: only tets near
        // flat can have a float sign that differs from the exact one.
        q < SURELY_POSITIVE && (q <= 0.0 || !self.w.positive(self.w.tets[t as usize]))
    }

    fn run(&mut self, opts: &Options) {
        let target = opts.target_deg.to_radians().sin();
        let mut st = PassState {
            // Work budget: changes per pass, a multiple of the mesh size.
            budget: 4 * self.w.tets.len() + 1000,
            clock: 1,
            stamp: vec![0; self.w.pos.len()],
            tried: vec![0; self.w.tets.len()],
        };
        for _ in 0..opts.max_passes {
            if self.pass(target, opts.improve, &mut st) == 0 {
                break;
            }
        }
        if opts.improve {
            self.climb(target, &mut st);
        }
    }

    /// Once every tet is above the target: passes over the worst tets with a target a little
    /// above the worst, as long as few tets are below it (so the cost does not grow with the
    /// mesh: on a large mesh many tets sit just above the target and this stops at once) and
    /// the worst keeps rising. Small meshes of simple domains gain the most (tetgen's coarse
    /// meshes of them are nearly regular).
    fn climb(&mut self, target: f64, st: &mut PassState) {
        let limit = CLIMB_LIMIT_DEG.to_radians().sin();
        let mut worst = self.worst();
        for _ in 0..CLIMB_ROUNDS {
            if worst < target || worst >= limit {
                return;
            }
            let next = ((worst.asin().to_degrees() + CLIMB_STEP_DEG)
                .to_radians()
                .sin())
            .min(limit);
            let below = (0..self.w.tets.len())
                .filter(|&t| self.w.alive[t] && self.w.q[t] < next)
                .count();
            if below > CLIMB_MAX_TETS {
                return;
            }
            self.pass(next, true, st);
            let now = self.worst();
            if now <= worst {
                return;
            }
            worst = now;
        }
    }

    /// The worst objective of the alive tets.
    fn worst(&self) -> f64 {
        (0..self.w.tets.len())
            .filter(|&t| self.w.alive[t])
            .map(|t| self.w.q[t])
            .fold(f64::INFINITY, f64::min)
    }

    /// Whether the heap entry (`t`, `tv`) is to be worked on now: the tet is still there and
    /// bad, and something changed around it since it was last tried in vain.
    fn due(&self, t: u32, tv: [u32; 4], target: f64, improve: bool, st: &PassState) -> bool {
        let ti = t as usize;
        if !self.w.alive[ti] || self.w.tets[ti] != tv || !self.bad(t, target, improve) {
            return false;
        }
        let tried = st.tried.get(ti).copied().unwrap_or(0);
        tried == 0 || tv.iter().any(|&v| st.stamp[v as usize] > tried)
    }

    /// One pass over the tets below `target` (or only the flat and inverted ones when not
    /// `improve`), worst first; returns the number of changes.
    ///
    /// With several threads, the plans are made ahead in batches (`batch`): when the tet taken
    /// from the heap has none, the next due tets of the heap get theirs on the run's threads,
    /// against the mesh as it stands. The tets are still taken and worked on one at a time in
    /// heap order, and a plan made ahead is used only where it is the one `work_on` would make
    /// now, so the changes are those of the serial loop.
    fn pass(&mut self, target: f64, improve: bool, st: &mut PassState) -> usize {
        self.stats.passes += 1;
        let mut heap: BinaryHeap<Reverse<Entry>> = BinaryHeap::new();
        for t in 0..self.w.tets.len() as u32 {
            if self.w.alive[t as usize] && self.bad(t, target, improve) {
                heap.push(Reverse((
                    key(self.w.q[t as usize]),
                    t,
                    self.w.tets[t as usize],
                )));
            }
        }
        let ahead = crate::parallel::current_threads() > 1;
        let mut planned: FxHashMap<(u32, [u32; 4]), batch::Ahead> = FxHashMap::default();
        // The last entry the latest batch looked at: a later entry without plans starts the
        // next batch, an earlier one (made since) is planned when worked on.
        let mut horizon: Option<Entry> = None;
        let mut changes = 0;
        let mut smoothings = vec![0u8; self.w.pos.len()];
        while let Some(Reverse(entry)) = heap.pop() {
            if changes >= st.budget {
                break;
            }
            let (_, t, tv) = entry;
            let mut plans = planned.remove(&(t, tv));
            if !self.due(t, tv, target, improve, st) {
                continue;
            }
            if ahead && plans.is_none() && horizon.is_none_or(|h| entry > h) {
                heap.push(Reverse(entry));
                horizon =
                    self.plan_batch(&mut heap, &mut planned, &smoothings, target, improve, st);
                heap.pop();
                plans = planned.remove(&(t, tv));
            }
            let (touched, capped) =
                self.work_on(t, tv, &mut smoothings, st, plans.unwrap_or_default());
            if st.tried.len() < self.w.tets.len() {
                st.tried.resize(self.w.tets.len(), 0);
            }
            if touched.is_empty() {
                if !capped {
                    st.tried[t as usize] = st.clock;
                }
                continue;
            }
            changes += 1;
            for n in touched {
                st.tried[n as usize] = 0;
                if self.bad(n, target, improve) {
                    heap.push(Reverse((
                        key(self.w.q[n as usize]),
                        n,
                        self.w.tets[n as usize],
                    )));
                }
            }
        }
        changes
    }

    /// Makes the plans of the next `batch::batch_size` due entries of `heap` that have none,
    /// on the run's threads, into `planned`; the heap is left as it was. Returns the last
    /// entry looked at.
    fn plan_batch(
        &mut self,
        heap: &mut BinaryHeap<Reverse<Entry>>,
        planned: &mut FxHashMap<(u32, [u32; 4]), batch::Ahead>,
        smoothings: &[u8],
        target: f64,
        improve: bool,
        st: &PassState,
    ) -> Option<Entry> {
        let t0 = std::time::Instant::now();
        let size = batch::batch_size(crate::parallel::current_threads());
        let mut seen: Vec<Entry> = Vec::with_capacity(4 * size);
        let mut batch: Vec<(u32, [u32; 4])> = Vec::with_capacity(size);
        while batch.len() < size && seen.len() < 4 * size {
            let Some(Reverse(e)) = heap.pop() else {
                break;
            };
            seen.push(e);
            let (_, t, tv) = e;
            if !planned.contains_key(&(t, tv)) && self.due(t, tv, target, improve, st) {
                batch.push((t, tv));
            }
        }
        let horizon = seen.last().copied();
        heap.extend(seen.into_iter().map(Reverse));
        // (A tet in the heap twice is planned once.)
        batch.sort_unstable();
        batch.dedup();
        self.w.epoch += 1;
        let epoch = self.w.epoch;
        let this = &*self;
        let plans = crate::parallel::map_collect_split(&batch, batch::PLAN_SPLIT, |&(t, tv)| {
            this.plan_ahead(t, tv, smoothings, epoch)
        });
        planned.extend(batch.into_iter().zip(plans));
        self.stats.seconds_plans += t0.elapsed().as_secs_f64();
        horizon
    }
}

impl Improver<'_> {
    /// The plans `work_on` would ask for on tet `t` (vertices `tv`) if the mesh stayed as it
    /// is (and the smoothing caps as `smoothings` says), each with its footprint (`batch`), in
    /// batch `epoch`; only reads the mesh.
    fn plan_ahead(&self, t: u32, tv: [u32; 4], smoothings: &[u8], epoch: u32) -> batch::Ahead {
        let mut ahead = batch::Ahead {
            epoch,
            flip: Some(batch::recorded(&tv, || self.best_plan(t))),
            ..Default::default()
        };
        if ahead.flip.as_ref().is_some_and(|m| m.value.is_some()) {
            return ahead;
        }
        let mut capped = false;
        for (k, v) in tv.into_iter().enumerate() {
            if smoothings[v as usize] >= MAX_SMOOTHINGS {
                capped = true;
                continue;
            }
            let m = batch::recorded(&[], || self.plan_smoothing(v));
            let moves = matches!(m.value, smooth::Smoothing::Move(_));
            ahead.smooth[k] = Some(m);
            if moves {
                return ahead;
            }
        }
        if !capped {
            ahead.insertion = Some(batch::recorded(&tv, || self.plan_insertion(t)));
            ahead.deletion = Some(batch::recorded(&tv, || self.plan_deletion(t)));
        }
        ahead
    }

    /// The plan made `ahead` (in batch `epoch`) if no change since marked a vertex of its
    /// footprint, else `plan()` made now: the same value either way. The radius-edge tally of
    /// the one used is counted. (The unit tests make every plan used again and compare: a
    /// footprint that misses something a plan read fails them.)
    fn use_plan<T: PartialEq + std::fmt::Debug>(
        &mut self,
        ahead: Option<batch::Memo<T>>,
        epoch: u32,
        plan: impl Fn(&Self) -> T,
    ) -> T {
        let (value, tally) = match ahead {
            Some(m)
                if m.footprint
                    .iter()
                    .all(|&v| self.w.unchanged_since(v, epoch)) =>
            {
                if cfg!(test) {
                    let again = batch::tallied(|| plan(self));
                    assert_eq!(again.0, m.value, "a plan made ahead went stale");
                    assert_eq!(again.1, m.tally, "a plan made ahead went stale");
                }
                (m.value, m.tally)
            }
            _ => batch::tallied(|| plan(self)),
        };
        self.stats.rho_vetoes += tally.vetoes;
        self.stats.rho_yields += tally.yields;
        value
    }

    /// Tries the best flip touching tet `t` (vertices `tv`), else smoothing of its vertices,
    /// else an insertion around it or the deletion of one of its vertices, whichever is
    /// better, using the plans made `ahead` that are still valid. Returns the tets made or
    /// moved (empty: nothing changed them) and whether a vertex was skipped for its per-pass
    /// smoothing cap.
    fn work_on(
        &mut self,
        t: u32,
        tv: [u32; 4],
        smoothings: &mut Vec<u8>,
        st: &mut PassState,
        mut ahead: batch::Ahead,
    ) -> (Vec<u32>, bool) {
        let t0 = std::time::Instant::now();
        let plan = self.use_plan(ahead.flip.take(), ahead.epoch, |im| im.best_plan(t));
        self.stats.seconds_plans += t0.elapsed().as_secs_f64();
        if let Some(plan) = plan {
            // (A flat tet flipped off its facet makes no tet: `t` is gone all the same.)
            let touched = self.apply(plan);
            st.stamp_around(&self.w, &touched);
            for v in tv {
                st.stamp[v as usize] = st.clock;
            }
            return (touched, false);
        }
        let mut capped = false;
        for (k, v) in tv.into_iter().enumerate() {
            if smoothings[v as usize] >= MAX_SMOOTHINGS {
                capped = true;
                continue;
            }
            smoothings[v as usize] += 1;
            self.stats.smooth_attempts += 1;
            let t0 = std::time::Instant::now();
            let s = self.use_plan(ahead.smooth[k].take(), ahead.epoch, |im| {
                im.plan_smoothing(v)
            });
            let ok = self.apply_smoothing(v, s);
            self.stats.seconds_smooth += t0.elapsed().as_secs_f64();
            if ok {
                let touched = self.w.star[v as usize].clone();
                st.stamp_around(&self.w, &touched);
                return (touched, capped);
            }
        }
        if capped {
            return (vec![], true);
        }
        let insertion = self.use_plan(ahead.insertion.take(), ahead.epoch, |im| {
            im.plan_insertion(t)
        });
        let deletion = self.use_plan(ahead.deletion.take(), ahead.epoch, |im| im.plan_deletion(t));
        let touched = match (insertion, deletion) {
            (Some(i), Some(d)) if d.new_min > i.new_min => self.apply_deletion(d),
            (Some(i), _) => self.apply_insertion(i),
            (None, Some(d)) => self.apply_deletion(d),
            (None, None) => return (vec![], false),
        };
        st.stamp.resize(self.w.pos.len(), 0);
        smoothings.resize(self.w.pos.len(), 0);
        st.stamp_around(&self.w, &touched);
        (touched, false)
    }
}

/// What passes share: the work budget per pass, and the change clock (a vertex's stamp is
/// the last change around it; a tet that nothing helped is not tried again until one of its
/// vertices is stamped later).
struct PassState {
    budget: usize,
    clock: u32,
    stamp: Vec<u32>,
    tried: Vec<u32>,
}

impl PassState {
    /// A new change: the vertices of `tets` get the next clock value.
    fn stamp_around(&mut self, w: &Work, tets: &[u32]) {
        self.clock += 1;
        for &n in tets {
            for v in w.tets[n as usize] {
                self.stamp[v as usize] = self.clock;
            }
        }
    }
}

/// Fails with [`MeshError::DegenerateTet`] naming the first tet (in output order) that is
/// not positively oriented by the exact `orient3d`. The tets are tested on the run's threads
/// (`crate::parallel`).
pub fn check_no_degenerate(mesh: &TetMesh) -> Result<(), MeshError> {
    let points = |t: &[u32; 4]| t.map(|v| mesh.vertices[v as usize]);
    let orient = |t: &[u32; 4]| {
        let p = points(t);
        orient3d(p[0], p[1], p[2], p[3])
    };
    match crate::parallel::position_first(&mesh.tets, |t| orient(t) <= 0.0) {
        None => Ok(()),
        Some(i) => Err(MeshError::DegenerateTet {
            index: i,
            vertices: mesh.tets[i],
            points: Box::new(points(&mesh.tets[i])),
            inverted: orient(&mesh.tets[i]) < 0.0,
        }),
    }
}

/// The step every mesher output goes through: improvement (or, with `params.improve` false,
/// only the removal of flat and inverted tets; in approximate mode tets over `params.rho0`
/// count as bad) and the check that no tet is degenerate. Returns the mesh and what the pass
/// did; the caller re-measures what it reports (`Report::measure_shapes` when
/// [`ImproveStats::changed`]) and records the stats (`Report::record_improvement`).
pub fn finish(
    mesh: TetMesh,
    input: Option<&PlcInput>,
    params: &Params,
    slide: Option<&dyn SurfaceSlide>,
) -> Result<(TetMesh, ImproveStats), MeshError> {
    finish_with(mesh, input, &finish_options(params), slide)
}

/// [`finish`] with its options given (from [`finish_options`], changed).
pub fn finish_with(
    mesh: TetMesh,
    input: Option<&PlcInput>,
    opts: &Options,
    slide: Option<&dyn SurfaceSlide>,
) -> Result<(TetMesh, ImproveStats), MeshError> {
    let (out, stats) = improve_owned(mesh, input, opts, slide);
    check_no_degenerate(&out)?;
    Ok((out, stats))
}

/// The improver's options for a run's `params` (what [`finish`] uses).
pub fn finish_options(params: &Params) -> Options {
    Options {
        improve: params.improve,
        // Keep mode leaves tets over rho0 next to small input angles, where the cap made the
        // improver trade angles for them (spool: 4 -> 61 tets below 5 degrees): angles only.
        max_rho: match params.surface_mode {
            SurfaceMode::Approximate => params.rho0,
            SurfaceMode::Keep => f64::INFINITY,
        },
        target_deg: params.effective_improve_target(),
        // Keep mode: rho0 holds wherever refinement met it. Approximate mode: the objective's
        // cap already counts tets over rho0 as bad; a veto there also blocks the changes next
        // to small corners, where refinement leaves tets over it (measured: cheese 20 -> 16.6
        // degrees, dino 18.3 -> 15.8).
        keep_rho: match params.surface_mode {
            SurfaceMode::Approximate => f64::INFINITY,
            SurfaceMode::Keep => params.rho0,
        },
        ..Options::default()
    }
}

#[cfg(test)]
mod tests;
