//! The refinement levels, in the manner of CGAL Mesh_3's mesher levels: subsegments, facets
//! and cells share one Delaunay triangulation, and a level's refinement point is tested
//! against the levels below it before it is inserted.
//!
//! The cell level asks its facet level ([`FacetLevel`]) what a point would do
//! ([`FacetLevel::conflict`]): break nothing ([`Conflict::Free`]: insert it), encroach a
//! subsegment or facet ([`Conflict::Encroaches`]: that element is refined first, from its own
//! picking interval, disk or surface centre, and the cell is looked at again), or be refused
//! with a reason (a small input angle, a cascade of ever smaller splits). Two facet levels
//! fill the interface: keep mode's PLC subfacets and subsegments (`refine::plc_level`, on
//! `Domain`) and the approximate mode's restricted Delaunay facets and feature subsegments
//! (`approx::restricted`).
//!
//! Li's point choice is written once, here, for every level: the point of a picking region
//! that creates the fewest small slivers ([`Picker`]), among those that break nothing below
//! ([`pick_in_ball`], [`try_candidate`]).

use super::outcome::{Outcome, Refusal};
use crate::delaunay::{BoundaryFace, Cavity, CavityWatch, Delaunay, Probe, INFINITE};
use crate::geom::circumsphere;
use crate::geom::screen::{shortest_edge_sq, sliver_measures, SliverScreen};
use crate::run::error::MeshError;
use glam::DVec3;
use rand::Rng;
use rand_chacha::ChaCha8Rng;

/// What a higher level's refinement point would do to the level below it.
#[derive(Debug)]
pub(crate) enum Conflict<E> {
    /// It breaks nothing below: insert it.
    Free,
    /// It would encroach lower-level element `E`: refine that first (the higher element is
    /// looked at again afterwards, if it is still there).
    Encroaches(E),
    /// The higher element is left as it is, for this reason.
    Refused(Refusal),
}

/// Why a cell asks for a point: the facet level's policy on what it splits differs.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Request {
    /// Shape (radius-edge ratio or sliver), or size away from a small input angle.
    Shape,
    /// Shape within a small input angle's influence: nothing below is split for it.
    ShapeNearSmallAngle,
    /// Size within a small input angle's influence (at the centroid).
    SizeNearSmallAngle,
}

/// The facet level below the cells (with the subsegment level below it): the boundary a
/// cell's refinement point must respect.
pub(crate) trait FacetLevel {
    /// A subsegment or facet of this level a point can encroach.
    type Element;

    /// The triangulation all levels share.
    fn triangulation(&mut self) -> &mut Delaunay;

    /// The element a point would encroach, given its probed cavity: the conflict test
    /// without a policy (None: it breaks nothing).
    fn encroached(&self, cavity: &Cavity) -> Option<Self::Element>;

    /// The level's policy for element `e` that a cell of circumradius `r`, asking because of
    /// `request`, would encroach: refine it first, or leave the cell (never `Free`).
    fn judge(&self, e: Self::Element, r: f64, request: Request) -> Conflict<Self::Element>;

    /// The conflict test of a cell's point (its probed cavity), for a cell of circumradius
    /// `r` asking because of `request`: free, which element to refine first, or why the cell
    /// is left.
    fn conflict(&self, cavity: &Cavity, r: f64, request: Request) -> Conflict<Self::Element> {
        match self.encroached(cavity) {
            None => Conflict::Free,
            Some(e) => self.judge(e, r, request),
        }
    }

    /// Refines encroached element `e` (from its own refinement point, with `picker` where
    /// the level chooses by small slivers) or queues it at its level; the levels below work
    /// off what that queued before the cell is looked at again.
    fn refine_encroached(
        &mut self,
        e: Self::Element,
        picker: &mut Picker,
    ) -> Result<Outcome, MeshError>;
}

/// Li's point choice: the small slivers a candidate point would create, and the random draws
/// from a picking region.
pub(crate) struct Picker {
    pub rng: ChaCha8Rng,
    /// Picking region radius, in radii of the element refined.
    pub delta: f64,
    /// Random draws per element (at least one).
    pub max_tries: usize,
    /// A new tet with circumradius at most `b` times the element's is a small sliver.
    b: f64,
    pub slivers: SliverBounds,
    /// Clears most new tets from squared measures alone (`geom::screen`).
    screen: SliverScreen,
    /// When to stop drawing before `max_tries` (None: never).
    give_up: Option<GiveUp>,
}

/// Stop drawing once `after` draws have left the best candidate with at least `n_small`
/// small slivers: the rest of the picking ball is then mostly sliver-making too, and the
/// remaining draws rarely find a sliver-free point (see `APPROX_GIVE_UP`).
#[derive(Debug, Clone, Copy)]
pub(crate) struct GiveUp {
    pub after: usize,
    pub n_small: usize,
}

/// What a sliver is: sigma = V / L^3 below sigma0, or a dihedral angle below the bound.
#[derive(Debug, Clone, Copy)]
pub(crate) struct SliverBounds {
    sigma0: f64,
    /// cos(min dihedral): a tet whose largest dihedral cosine exceeds it is a sliver.
    cos_min_dihedral: f64,
}

impl SliverBounds {
    pub fn new(sigma0: f64, min_dihedral_deg: f64) -> SliverBounds {
        SliverBounds {
            sigma0,
            cos_min_dihedral: min_dihedral_deg.to_radians().cos(),
        }
    }

    /// Whether a tet with these measures is a sliver.
    #[inline]
    pub fn is_sliver(&self, sigma: f64, max_cos_dihedral: f64) -> bool {
        sigma < self.sigma0 || max_cos_dihedral > self.cos_min_dihedral
    }
}

/// How good a candidate point is: fewer small slivers first, then the larger smallest
/// dihedral angle among them (`margin`: 1 - its cosine).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Score {
    pub n_small: usize,
    pub margin: f64,
}

impl Score {
    fn better_than(&self, o: &Score) -> bool {
        (self.n_small, -self.margin) < (o.n_small, -o.margin)
    }
}

/// A probed candidate point and its score.
pub(crate) struct Candidate {
    pub score: Score,
    pub cavity: Cavity,
}

impl Picker {
    pub fn new(
        rng: ChaCha8Rng,
        delta: f64,
        max_tries: usize,
        b: f64,
        sigma0: f64,
        min_dihedral_deg: f64,
    ) -> Picker {
        Picker {
            rng,
            delta,
            max_tries: max_tries.max(1),
            b,
            slivers: SliverBounds::new(sigma0, min_dihedral_deg),
            screen: SliverScreen::new(sigma0, min_dihedral_deg),
            give_up: None,
        }
    }

    /// The picker, drawing no more once `give_up` says so.
    pub fn giving_up(self, give_up: GiveUp) -> Picker {
        Picker {
            give_up: Some(give_up),
            ..self
        }
    }

    /// Whether to stop after `draws` draws with `best` the best candidate's score so far.
    fn gives_up(&self, draws: usize, best: Option<&Score>) -> bool {
        self.give_up
            .is_some_and(|g| draws >= g.after && best.is_some_and(|b| b.n_small >= g.n_small))
    }

    /// The sliver screen for these bounds (the cell level classifies with it too).
    pub fn screen(&self) -> &SliverScreen {
        &self.screen
    }

    /// A uniformly random point of the ball of radius `delta * r` around `centre`.
    pub fn in_ball(&mut self, centre: DVec3, r: f64) -> DVec3 {
        centre + random_in_unit_ball(&mut self.rng) * (self.delta * r)
    }

    /// The small slivers (circumradius <= b r) inserting the probed point would create.
    pub fn small_slivers(&self, dt: &Delaunay, cavity: &Cavity, r: f64) -> Score {
        let mut count = self.sliver_count(cavity.point(), r, None);
        count.faces(dt.cavity(cavity).1, dt.points());
        count.score
    }

    /// A count of the small slivers of a point `p` for an element of radius `r`, to watch its
    /// cavity search; it stops the search once the point cannot beat `limit` (the best
    /// candidate's score).
    fn sliver_count(&self, p: DVec3, r: f64, limit: Option<Score>) -> SliverCount<'_> {
        SliverCount {
            picker: self,
            p,
            max_r: self.b * r,
            limit,
            score: Score {
                n_small: 0,
                margin: f64::INFINITY,
            },
        }
    }

    /// For the new tet (x, y, z, p): 1 - cos(its smallest dihedral angle) if it is a sliver
    /// with circumradius <= `max_r`.
    #[inline]
    fn small_sliver(&self, x: DVec3, y: DVec3, z: DVec3, p: DVec3, max_r: f64) -> Option<f64> {
        let (sigma, max_cos) = sliver_measures(x, y, z, p, shortest_edge_sq(x, y, z, p));
        let small = circumsphere(x, y, z, p).map_or(f64::INFINITY, |s| s.1) <= max_r;
        (self.slivers.is_sliver(sigma, max_cos) && small).then(|| max_cos.mul_add(-1.0, 1.0))
    }
}

/// Counts the small slivers of a candidate point's new tets as its cavity search finds them.
struct SliverCount<'a> {
    picker: &'a Picker,
    p: DVec3,
    max_r: f64,
    limit: Option<Score>,
    score: Score,
}

impl CavityWatch for SliverCount<'_> {
    const BATCH: usize = SliverScreen::BATCH;

    /// False once the candidate cannot beat `limit`: more small slivers, or as many with a
    /// smallest margin no larger (either only grows worse as faces come).
    fn faces(&mut self, faces: &[BoundaryFace], points: &[DVec3]) -> bool {
        let corners = |f: &BoundaryFace| {
            let v = f.vertices();
            (!v.contains(&INFINITE)).then(|| v.map(|v| points[v as usize]))
        };
        let mut over = false;
        // The sliver screen first (most new tets pass it), then the full measures.
        let (picker, p, max_r, limit) = (self.picker, self.p, self.max_r, self.limit);
        let score = &mut self.score;
        picker
            .screen
            .for_each_uncleared(faces, corners, p, |[x, y, z]| {
                if let Some(margin) = picker.small_sliver(x, y, z, p, max_r) {
                    score.n_small += 1;
                    score.margin = score.margin.min(margin);
                    if limit.is_some_and(|b| !score.better_than(&b)) {
                        over = true;
                        return false;
                    }
                }
                true
            });
        !over
    }
}

/// Probes candidate `p` for an element of radius `r` and makes it `best` if it creates fewer
/// small slivers (ties: the larger smallest dihedral angle) and, when `check_conflict`, breaks
/// nothing below (`level.encroached`). Returns true when `p` creates no small sliver (the
/// search can stop; `best`'s cavity is then current).
pub(crate) fn try_candidate<F: FacetLevel + ?Sized>(
    level: &mut F,
    picker: &Picker,
    p: DVec3,
    r: f64,
    hint: Option<u32>,
    check_conflict: bool,
    best: &mut Option<Candidate>,
) -> bool {
    let limit = best.as_ref().map(|b| b.score);
    let mut count = picker.sliver_count(p, r, limit);
    let Some(probe) = level.triangulation().probe_watched(p, hint, &mut count) else {
        return false; // more small slivers than the best
    };
    let Probe::Cavity(cavity) = probe else {
        return false;
    };
    let score = count.score;
    if best.as_ref().is_some_and(|b| !score.better_than(&b.score)) {
        return false; // not better: whether it breaks the boundary does not matter
    }
    if check_conflict && level.encroached(&cavity).is_some() {
        return false; // p would break the boundary
    }
    // Inserting the best needs no second search.
    level.triangulation().keep(&cavity);
    *best = Some(Candidate { score, cavity });
    score.n_small == 0
}

/// Li's choice for a bad cell of circumradius `r` whose circumcentre `centre` breaks nothing
/// below (`centre_cavity`: its probe, None when it is a vertex): the centre if it creates no
/// small sliver, else the best of `max_tries` random points of the picking ball that break
/// nothing below. None when no candidate was kept.
pub(crate) fn pick_in_ball<F: FacetLevel + ?Sized>(
    level: &mut F,
    picker: &mut Picker,
    centre: DVec3,
    centre_cavity: Option<Cavity>,
    r: f64,
    hint: u32,
) -> Option<Cavity> {
    let mut best = None;
    // The centre is a point of the picking ball too, and its cavity is at hand: the first
    // candidate.
    if let Some(cavity) = centre_cavity {
        let score = picker.small_slivers(level.triangulation(), &cavity, r);
        level.triangulation().keep(&cavity);
        best = Some(Candidate { score, cavity });
    }
    if best.as_ref().is_none_or(|b| b.score.n_small > 0) {
        for draws in 0..picker.max_tries {
            if picker.gives_up(draws, best.as_ref().map(|b: &Candidate| &b.score)) {
                break;
            }
            let p = picker.in_ball(centre, r);
            if try_candidate(level, picker, p, r, Some(hint), true, &mut best) {
                break;
            }
        }
    }
    best.map(|b| b.cavity)
}

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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::SeedableRng;

    #[test]
    fn picker_gives_up_only_after_enough_draws_with_enough_small_slivers() {
        let picker = || Picker::new(ChaCha8Rng::seed_from_u64(1), 0.3, 20, 4.0, 0.02, 18.0);
        let score = |n_small| Score {
            n_small,
            margin: 0.1,
        };
        // Without a rule it never stops early.
        assert!(!picker().gives_up(19, Some(&score(9))));
        let p = picker().giving_up(GiveUp {
            after: 5,
            n_small: 3,
        });
        assert!(!p.gives_up(4, Some(&score(9))), "too few draws");
        assert!(p.gives_up(5, Some(&score(3))));
        assert!(
            !p.gives_up(5, Some(&score(2))),
            "a sliver-free point is still likely"
        );
        assert!(!p.gives_up(7, None), "no candidate kept yet");
    }
}
