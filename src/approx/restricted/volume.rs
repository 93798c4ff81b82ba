//! The cell level of the restricted Delaunay mesher: once the surface is good, the tets whose
//! circumcentres lie inside the surface are refined in the same triangulation (CGAL Mesh_3's
//! cell level, with Li's picking ball for the refinement point).
//!
//! A bad cell (too large for f, radius-edge ratio over rho0, or a sliver) is refined at a point
//! of its picking ball that creates the fewest small slivers. A point inside a restricted
//! facet's surface ball would change the restricted surface: that facet is refined at its
//! surface centre instead (the surface level's own rule), and a point inside a feature
//! subsegment's diametric ball splits the subsegment. Next to a small corner cells are left as
//! they are, as the surface is.
//!
//! Which cells are inside and which facets are restricted is kept up to date by `tracking`.

use super::facet_level::Encroached;
use super::{Loc, SurfaceMesher};
use crate::delaunay::tables::FACE;
use crate::delaunay::{Inserted, Probe, INFINITE};
use crate::geom::screen::{shortest_edge_sq, sliver_measures};
use crate::refine::levels::{
    pick_in_ball, Conflict, FacetLevel, GiveUp, Picker, Request, SliverBounds,
};
use crate::refine::outcome::{Outcome, Refusal};
use crate::refine::queue::{work_off, BadLevel, BadQueues, Class, Ended};
use crate::refine::{AutoSpacing, MarkerCapped};
use crate::run::error::MeshError;
use crate::run::report::Refusals;
use crate::run::spacing::Spacing;
use glam::DVec3;
use rand::SeedableRng;
use rand_chacha::ChaCha8Rng;
use rustc_hash::{FxHashMap, FxHashSet};

/// What the cell level aims for (from `run::params::Params`).
#[derive(Debug, Clone, Copy)]
pub struct VolumeCriteria {
    pub rho0: f64,
    pub sigma0: f64,
    pub min_dihedral_deg: f64,
    /// Picking ball radius, in circumradii.
    pub delta: f64,
    /// Small slivers are those with circumradius <= b times the bad cell's.
    pub b: f64,
    pub max_tries: usize,
    pub size_factor: f64,
    /// Whether f is the caller's; otherwise the cells are sized by the surface's edges,
    /// graded inwards (as keep mode's automatic spacing).
    pub user_spacing: bool,
    pub seed: u64,
}

/// The spacing a cell was classified with, reused while the cell (its id and vertices) is the
/// same: its circumcentre is then the same point.
type Sized = Option<f64>;

/// [`Sized`] as a queue entry stores it: NaN for none (8 bytes instead of 16).
fn stored(sized: Sized) -> f64 {
    sized.unwrap_or(f64::NAN)
}

fn unstored(f: f64) -> Sized {
    (!f.is_nan()).then_some(f)
}

/// The most cells classified with one batched spacing evaluation (`Spacing::at_many`).
const SPACING_BATCH: usize = crate::refine::SPACING_BATCH;

/// A cell's classification before its spacing is known.
enum CellStep {
    /// Good, outside, or next to a small corner.
    Done(Option<Class>),
    /// The spacing at the circumcentre `centre` (radius `r`) decides.
    Need { centre: DVec3, r: f64 },
}

/// A queued bad cell: id, vertices (as when it was judged), and the spacing it was classified
/// with ([`stored`]; 32 bytes, as the queues hold up to about one entry per tet of the final
/// mesh).
pub(super) type Cell = (u32, [u32; 4], f64);

/// Times a cell may wait for the surface or a subsegment to be refined for it before it is
/// left as it is.
const MAX_CELL_DEFERRALS: u8 = 4;

/// The cell level stops drawing from a picking ball after 5 draws that all leave at least 3
/// small slivers. Measured with 20 draws (joint, fandisk, elephant): of such balls the
/// remaining 15 draws found a sliver-free point in 2-5%, against 57-59% of the balls whose
/// best had one small sliver; the hopeless balls took most of the draws.
const APPROX_GIVE_UP: GiveUp = GiveUp {
    after: 5,
    n_small: 3,
};

pub(super) struct VolumeState {
    crit: VolumeCriteria,
    slivers: SliverBounds,
    /// Li's point choice (small slivers, random draws); None while lent out.
    picker: Option<Picker>,
    /// Bad cells per class, the highest served first (`refine::queue`).
    queues: BadQueues<Cell>,
    /// How often a bad cell was left as it was, per reason (the run's report).
    pub(super) refusals: Refusals,
    deferrals: FxHashMap<[u32; 4], u8>,
    pub(super) spacing: Option<AutoSpacing>,
    /// Per vertex id: within a small corner's ball (cells there are left as they are).
    near_small: Vec<bool>,
    /// The caller's progress callback asked to stop.
    cancelled: bool,
}

impl VolumeState {
    pub(super) fn cancelled(&self) -> bool {
        self.cancelled
    }
}

impl SurfaceMesher<'_> {
    /// Starts the cell level on the current triangulation (the surface is good).
    pub(super) fn start_volume(&mut self, crit: VolumeCriteria, faces: &[super::FaceRef]) {
        let spacing = (!crit.user_spacing).then(|| self.surface_sizes(faces));
        self.vol = Some(Box::new(VolumeState {
            crit,
            slivers: SliverBounds::new(crit.sigma0, crit.min_dihedral_deg),
            picker: Some(
                Picker::new(
                    ChaCha8Rng::seed_from_u64(crit.seed ^ 0x766f_6c75_6d65),
                    crit.delta,
                    crit.max_tries,
                    crit.b,
                    crit.sigma0,
                    crit.min_dihedral_deg,
                )
                .giving_up(APPROX_GIVE_UP),
            ),
            queues: BadQueues::default(),
            refusals: Refusals::default(),
            deferrals: FxHashMap::default(),
            spacing,
            near_small: vec![],
            cancelled: false,
        }));
        self.mark_near_small_corners();
        let tets: Vec<u32> = self.dt.finite_tet_ids().collect();
        self.queue_batch(&tets);
    }

    /// Extends the per-vertex small-corner flags to the vertices inserted since.
    fn mark_near_small_corners(&mut self) {
        let Some(mut vol) = self.vol.take() else {
            return;
        };
        for v in vol.near_small.len()..self.dt.num_vertex_ids() {
            let near = self.near_small_corner(self.dt.point(v as u32));
            vol.near_small.push(near);
        }
        self.vol = Some(vol);
    }

    /// The default cell spacing: at each surface vertex the mean length of its boundary
    /// edges, extended inwards with keep mode's grading.
    pub(super) fn surface_sizes(&self, faces: &[super::FaceRef]) -> AutoSpacing {
        let mut sum: FxHashMap<u32, (f64, f64)> = FxHashMap::default();
        for &(t, i) in faces {
            let tv = self.dt.tet(t);
            let f = FACE[i].map(|k| tv[k]);
            for j in 0..3 {
                let (a, b) = (f[j], f[(j + 1) % 3]);
                let l = self.dt.point(a).distance(self.dt.point(b));
                for v in [a, b] {
                    let e = sum.entry(v).or_default();
                    e.0 += l;
                    e.1 += 1.0;
                }
            }
        }
        let mut sized: Vec<(u32, DVec3, f64)> = sum
            .into_iter()
            .map(|(v, (s, n))| (v, self.dt.point(v), s / n))
            .collect();
        sized.sort_unstable_by_key(|s| s.0);
        let sized: Vec<(DVec3, f64)> = sized.into_iter().map(|(_, p, h)| (p, h)).collect();
        AutoSpacing::from_sizes(&sized)
    }

    /// After an insertion (cell level on): the created tets are queued when bad.
    pub(super) fn queue_cells(&mut self, created: &[u32]) {
        if self.vol.is_some() {
            self.mark_near_small_corners();
            self.queue_batch(created);
        }
    }

    /// Classifies `tets` and queues the bad ones, in their order. The spacing at their
    /// circumcentres is evaluated in batches (one `Spacing::at_many` call per
    /// [`SPACING_BATCH`] cells: after an insertion, one for all the cells it created), at the
    /// same points as one by one.
    fn queue_batch(&mut self, tets: &[u32]) {
        let mut steps = Vec::with_capacity(tets.len().min(SPACING_BATCH));
        let mut centres = Vec::with_capacity(steps.capacity());
        let mut values = Vec::with_capacity(steps.capacity());
        for chunk in tets.chunks(SPACING_BATCH) {
            steps.clear();
            centres.clear();
            for &t in chunk {
                let step = self.prepare_cell(t);
                if let CellStep::Need { centre, .. } = step {
                    centres.push(centre);
                }
                steps.push(step);
            }
            values.clear();
            values.resize(centres.len(), f64::NAN);
            if !centres.is_empty() {
                self.cell_spacing().at_many(&centres, &mut values);
            }
            let mut k = 0;
            for (&t, step) in chunk.iter().zip(&steps) {
                let (class, sized) = match *step {
                    CellStep::Done(class) => (class, None),
                    CellStep::Need { r, .. } => {
                        let f = values[k];
                        k += 1;
                        (self.finish_cell(t, r, f), Some(f))
                    }
                };
                if let Some(class) = class {
                    let tv = self.dt.tet(t);
                    if let Some(vol) = self.vol.as_mut() {
                        vol.queues.push(class, (t, tv, stored(sized)));
                    }
                }
            }
        }
    }

    /// The spacing cells are sized by: the automatic one capped by the marker sizes, or the
    /// caller's (capped already).
    fn cell_spacing(&self) -> MarkerCapped<'_> {
        match self.vol.as_ref().and_then(|v| v.spacing.as_ref()) {
            Some(s) => MarkerCapped {
                inner: s,
                caps: self.marker_caps,
            },
            None => MarkerCapped {
                inner: self.spacing,
                caps: None,
            },
        }
    }

    /// The class of a bad inside cell, or None when it is good, outside or next to a small
    /// corner; `sized`: the spacing this same cell was classified with before (the caller
    /// checks that it is the same), reused. Returns the spacing used too.
    fn cell_class(&self, t: u32, sized: Sized) -> (Option<Class>, Sized) {
        match self.prepare_cell(t) {
            CellStep::Done(class) => (class, None),
            CellStep::Need { centre, r } => {
                let f = sized.unwrap_or_else(|| self.cell_spacing().at(centre));
                (self.finish_cell(t, r, f), Some(f))
            }
        }
    }

    /// [`Self::cell_class`] up to the spacing it needs.
    fn prepare_cell(&self, t: u32) -> CellStep {
        let Some(vol) = self.vol.as_ref() else {
            return CellStep::Done(None);
        };
        if !self.dt.is_alive(t) || !self.is_inside(t) {
            return CellStep::Done(None);
        }
        let tv = self.dt.tet(t);
        if tv.contains(&INFINITE) || tv.iter().any(|&v| self.loc[v as usize] == Loc::Far) {
            return CellStep::Done(None);
        }
        let near_small = |v: u32| match vol.near_small.get(v as usize) {
            Some(&near) => near,
            None => self.near_small_corner(self.dt.point(v)),
        };
        if tv.iter().any(|&v| near_small(v)) {
            return CellStep::Done(None);
        }
        match self.sphere_of(t) {
            Some((centre, r)) => CellStep::Need { centre, r },
            None => CellStep::Done(None),
        }
    }

    /// The rest of [`Self::cell_class`], given `f` at the circumcentre (radius `r`).
    fn finish_cell(&self, t: u32, r: f64, f: f64) -> Option<Class> {
        let vol = self.vol.as_ref()?;
        let f = match self.region_caps.get(self.region_of(t) as usize) {
            Some(&cap) => f.min(cap),
            None => f,
        };
        if r > vol.crit.size_factor * f {
            return Some(Class::Size);
        }
        let tv = self.dt.tet(t);
        let [a, b, c, d] = tv.map(|v| self.dt.point(v));
        let l2 = shortest_edge_sq(a, b, c, d);
        if r * r > vol.crit.rho0 * vol.crit.rho0 * l2 {
            return Some(Class::Ratio);
        }
        let (sigma, max_cos) = sliver_measures(a, b, c, d, l2);
        vol.slivers
            .is_sliver(sigma, max_cos)
            .then_some(Class::Sliver)
    }

    /// Runs both levels until no bad facet, subsegment or cell is left (or a budget stops it):
    /// `refine::queue::work_off` over the cells ([`CellLevel`]), the surface and subsegment
    /// levels worked off before each cell.
    pub(super) fn refine_volume(
        &mut self,
        progress: &mut Option<crate::run::progress::Progress>,
    ) -> Option<String> {
        if self.vol.as_ref().is_none_or(|v| v.cancelled) {
            return None;
        }
        let mut level = CellLevel {
            m: self,
            stop: None,
        };
        let ended = work_off(&mut level, &mut |n| {
            progress.as_mut().is_none_or(|p| p(0.5, n))
        });
        let stop = level.stop.take();
        match ended {
            Ok(Ended::Done) => None,
            Ok(Ended::Stopped) => stop,
            Ok(Ended::Cancelled) => {
                if let Some(vol) = self.vol.as_mut() {
                    vol.cancelled = true;
                }
                None
            }
            Err(e) => {
                self.bad_spacing.get_or_insert(e);
                None
            }
        }
    }

    /// Refines bad cell `t` (still bad, classified with `sized`) and says what it did.
    fn refine_cell(&mut self, t: u32, sized: Sized) -> Result<Outcome, MeshError> {
        let tv = self.dt.tet(t);
        let Some((centre, r)) = self.sphere_of(t) else {
            return Ok(Outcome::Refused(Refusal::NoCircumsphere));
        };
        let Probe::Cavity(cavity) = self.dt.probe(centre, Some(t)) else {
            // The centre is a vertex already.
            return Ok(Outcome::Refused(Refusal::Duplicate));
        };
        match self.conflict(&cavity, r, Request::Shape) {
            Conflict::Free => {}
            Conflict::Encroaches(e) => return self.yield_to_surface(t, tv, e, sized),
            Conflict::Refused(reason) => return Ok(Outcome::Refused(reason)),
        }
        let mut picker = self.lend_picker();
        let centre = cavity.point();
        let picked = pick_in_ball(self, &mut picker, centre, Some(cavity), r, t);
        self.return_picker(picker);
        // Not reached: the centre's cavity is a candidate, so one is always kept.
        let Some(cavity) = picked else {
            return Ok(Outcome::Refused(Refusal::Duplicate));
        };
        match self.dt.insert_cavity(cavity) {
            Ok(Inserted::New(id)) => {
                self.loc.push(Loc::Volume);
                debug_assert_eq!(self.loc.len(), id as usize + 1);
                self.after_insertion();
                Ok(Outcome::Inserted)
            }
            // A draw on a vertex, or a degenerate insertion: nothing changed.
            _ => Ok(Outcome::Refused(Refusal::Duplicate)),
        }
    }

    /// The surface or a subsegment is refined for cell `t` instead of it (the facet level
    /// refines the facet now or queues the subsegments); the cell waits, queued again (a
    /// limited number of times: then it is left, [`Refusal::WaitedForBoundary`]). Returns
    /// the facet level's outcome while the cell waits.
    fn yield_to_surface(
        &mut self,
        t: u32,
        tv: [u32; 4],
        encroached: Encroached,
        sized: Sized,
    ) -> Result<Outcome, MeshError> {
        let mut picker = self.lend_picker();
        let outcome = self.refine_encroached(encroached, &mut picker);
        self.return_picker(picker);
        let outcome = outcome?;
        let vol = self.vol.as_mut().expect("the cell level is on");
        let mut key = tv;
        key.sort_unstable();
        let n = vol.deferrals.entry(key).or_default();
        *n += 1;
        if *n > MAX_CELL_DEFERRALS {
            return Ok(Outcome::Refused(Refusal::WaitedForBoundary));
        }
        // The refined surface may have replaced the cell: its spacing is reused only if it is
        // still there.
        let same = self.dt.is_alive(t) && self.dt.tet(t) == tv;
        let (class, sized) = self.cell_class(t, sized.filter(|_| same));
        if let Some(vol) = self.vol.as_mut() {
            vol.queues
                .push(class.unwrap_or(Class::Size), (t, tv, stored(sized)));
        }
        Ok(outcome)
    }

    /// The cell level's picker, lent to a level function that takes the mesher too.
    fn lend_picker(&mut self) -> Picker {
        self.vol
            .as_mut()
            .and_then(|v| v.picker.take())
            .expect("the cell level's picker is at hand")
    }

    fn return_picker(&mut self, picker: Picker) {
        if let Some(vol) = self.vol.as_mut() {
            vol.picker = Some(picker);
        }
    }
}

/// The approximate mode's cell level as `refine::queue::work_off` drives it: the surface and
/// subsegment levels below are worked off before each cell (`SurfaceMesher::refine`), and a
/// cell is still bad when it is a tet of the mesh and [`SurfaceMesher::cell_class`] gives it a
/// class (inside, not next to a small corner, bad for the criteria).
struct CellLevel<'m, 'g> {
    m: &'m mut SurfaceMesher<'g>,
    /// Why a level below stopped (a budget).
    stop: Option<String>,
}

impl CellLevel<'_, '_> {
    fn vol(&mut self) -> &mut VolumeState {
        self.m.vol.as_mut().expect("the cell level is on")
    }

    /// Counts the bad cells still queued when a budget stopped refinement.
    fn count_left(&mut self) {
        let m = &*self.m;
        let Some(vol) = m.vol.as_ref() else {
            return;
        };
        let left: FxHashSet<u32> = vol
            .queues
            .iter()
            .filter(|&&(t, tv, _)| m.dt.is_alive(t) && m.dt.tet(t) == tv)
            .map(|&(t, _, _)| t)
            .collect();
        let n = left.len();
        self.vol().refusals.count_budget(n);
    }
}

impl BadLevel for CellLevel<'_, '_> {
    type Bad = Cell;
    type Error = MeshError;

    fn queues(&mut self) -> &mut BadQueues<Cell> {
        &mut self.vol().queues
    }

    fn before_next(&mut self) -> bool {
        if let Some(reason) = self.m.refine() {
            self.stop = Some(reason);
            self.count_left();
            return false;
        }
        self.m.bad_spacing.is_none()
    }

    fn still_bad(&mut self, cell: &mut Cell) -> bool {
        let (t, tv, sized) = *cell;
        if !(self.m.dt.is_alive(t) && self.m.dt.tet(t) == tv) {
            return false;
        }
        let (class, sized) = self.m.cell_class(t, unstored(sized));
        cell.2 = stored(sized);
        class.is_some()
    }

    fn within_budget(&mut self, _cell: &Cell) -> bool {
        // The vertex budget is the levels' below (`before_next`).
        true
    }

    fn num_vertices(&self) -> usize {
        self.m.dt.num_vertices()
    }

    fn refine(&mut self, cell: Cell, _deferred: bool) -> Result<Outcome, MeshError> {
        self.m.refine_cell(cell.0, unstored(cell.2))
    }

    fn refusals(&mut self) -> &mut Refusals {
        &mut self.vol().refusals
    }

    fn record(&mut self, _cell: Cell, _outcome: Outcome, _n: usize) -> Result<bool, MeshError> {
        // A waiting cell is queued again by `yield_to_surface`; the new cells by
        // `after_insertion`.
        Ok(true)
    }
}
