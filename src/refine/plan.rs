//! What refining one bad tet will do, decided without changing anything: keep mode's cell
//! level plans a batch of bad tets at once on the run's threads, then applies the plans in
//! queue order (`quality.rs`). A plan reads the triangulation through a shared reference
//! (`Delaunay::probe_shared`), and its random draws come from a generator seeded by the run's
//! seed and the tet's vertices, so it depends on the mesh and the tet only: never on the thread
//! that made it, nor on how many there are.
//!
//! A plan is applied as made while what it read is unchanged ([`Plan::still_valid`]): the tet,
//! and for a plan made from a probed cavity that cavity and the tets around it (no tet of
//! either removed since the batch was planned; the boundary elements a point encroaches live
//! in those tets, so the conflict test's answer stands too). Otherwise the tet is planned
//! again on the mesh as it is then, by the same code.

use super::domain::Domain;
use super::levels::{pick_in_ball, Conflict, Picker, Probing, Request, Score};
use super::outcome::Refusal;
use super::plc_level::{Boundary, SplitPlan};
use super::quality::{Bad, BoundingBox};
use super::queue::Class;
use crate::delaunay::{CavityWatch, NoWatch, OwnedCavity, ProbeBuffers, SharedProbe};
use crate::geom::circumsphere;
use crate::geom::insphere;
use crate::geom::screen::longest_edge_direct as longest_edge;
use crate::run::params::Params;
use glam::DVec3;
use rustc_hash::FxHashSet;

/// What refining a bad tet will do.
#[derive(Debug)]
pub(crate) enum Plan {
    /// Leave it, for this reason.
    Refuse(Refusal),
    /// Put it aside until every queue is empty.
    Defer,
    /// Restore empty encroachment around it (refused for the reason if that splits
    /// nothing); `located`: the tet whose region decided it, if one did.
    Resettle {
        reason: Refusal,
        located: Option<u32>,
    },
    /// Its point (with this cavity) conflicts with the boundary: refine that first (`split`:
    /// planned too), or leave the tet (never `Conflict::Free`).
    Yield {
        conflict: Conflict<Boundary>,
        cavity: OwnedCavity,
        split: Option<SplitPlan>,
    },
    /// Insert a volume vertex with this cavity.
    Insert(OwnedCavity),
    /// Insert a volume vertex here, its cavity searched then (no candidate was kept).
    InsertAt(DVec3),
}

impl Plan {
    /// Whether the plan still holds in `dom` (see the module doc): the caller knows the tet is
    /// still a tet of the mesh.
    pub(super) fn still_valid(&self, dom: &Domain) -> bool {
        match self {
            Plan::Refuse(_) | Plan::Defer => true,
            Plan::Resettle { located, .. } => {
                located.is_none_or(|t| !dom.dt.removed_since_tracking(t))
            }
            Plan::Yield { cavity, .. } | Plan::Insert(cavity) => cavity.intact(&dom.dt),
            Plan::InsertAt(_) => false,
        }
    }
}

/// Circumradius / longest edge above which a bad tet is deferred (see [`Planner::plan`]).
const DEFER_RADIUS_PER_EDGE: f64 = 3.0;

/// A circumcentre outside the domain's box and further than this many longest edges from
/// its tet is not located (see [`Planner::screen_circumcentre`]).
const FAR_CENTRE_PER_EDGE: f64 = 100.0;

/// What a plan reads: the mesh, the parameters, Li's point choice (its generator reseeded per
/// tet), the tets known to be futile and the input's bounding box.
pub(super) struct Planner<'a> {
    pub dom: &'a Domain,
    pub params: &'a Params,
    pub picker: &'a Picker,
    pub futile: &'a FxHashSet<[u32; 4]>,
    pub domain_box: BoundingBox,
}

impl Planner<'_> {
    /// The plan for bad tet `bad` (`may_defer`: it was not deferred already), probing with
    /// `buf`.
    pub(super) fn plan(&self, bad: Bad, may_defer: bool, buf: &mut ProbeBuffers) -> Plan {
        let dom = self.dom;
        if self.futile.contains(&super::quality::sorted4(bad.verts)) {
            return Plan::Refuse(Refusal::Futile);
        }
        if dom.flat_by_construction(bad.verts) {
            // No point inside it or at its centre can help (see `flat_by_construction`):
            // restoring the boundary around it may; else the improvement removes it.
            return resettle(Refusal::FlatByConstruction);
        }
        let near = bad.verts.iter().any(|&v| dom.near_small_angle(v));
        let [a, b, c, d] = dom.dt.tet_points(bad.tet);
        if near && bad.class == Class::Size {
            // Size-bad next to a small angle (see `classify`): split at the centroid, which
            // lies in the tet even when it is flat and its circumcentre is far away.
            let centroid = (a + b + c + d) * 0.25;
            let r = 0.5 * longest_edge(a, b, c, d);
            return match dom.dt.probe_shared(centroid, bad.tet, buf, &mut NoWatch) {
                Some(SharedProbe::Cavity(cavity)) => {
                    match dom.conflict_owned(&cavity, r, Request::SizeNearSmallAngle) {
                        Conflict::Free => Plan::Insert(cavity),
                        conflict => self.yield_plan(conflict, cavity, buf),
                    }
                }
                // The centroid is a vertex already (a flat tet's centroid can be).
                _ => Plan::Refuse(Refusal::Duplicate),
            };
        }
        let Some((centre, r)) = circumsphere(a, b, c, d) else {
            return Plan::Refuse(Refusal::NoCircumsphere);
        };
        if let Some(plan) = self.screen_circumcentre(bad, centre, r, near, may_defer) {
            return plan;
        }
        let Some(SharedProbe::Cavity(cavity)) =
            dom.dt.probe_shared(centre, bad.tet, buf, &mut NoWatch)
        else {
            // The centre is a vertex already (it breaks nothing).
            return match near {
                true => Plan::Refuse(Refusal::NearSmallAngle),
                false => self.pick(bad, centre, r, None, buf),
            };
        };
        // Next to a small angle: only the centre, and only if it breaks no boundary (see
        // `screen_circumcentre`).
        let request = match near {
            true => Request::ShapeNearSmallAngle,
            false => Request::Shape,
        };
        match dom.conflict_owned(&cavity, r, request) {
            Conflict::Free => {}
            conflict => return self.yield_plan(conflict, cavity, buf),
        }
        match near {
            true => Plan::Insert(cavity),
            false => self.pick(bad, centre, r, Some(cavity), buf),
        }
    }

    /// The guards on bad tet `bad`'s circumcentre `centre` (circumradius `r`; `near`: next to
    /// a small angle) before its cavity is probed: the plan when the tet is flat to rounding,
    /// its centre is far outside the domain, it is next to a small angle with a far centre,
    /// or it must wait; None when the centre is worth probing.
    fn screen_circumcentre(
        &self,
        bad: Bad,
        centre: DVec3,
        r: f64,
        near: bool,
        may_defer: bool,
    ) -> Option<Plan> {
        let dom = self.dom;
        let [a, b, c, d] = dom.dt.tet_points(bad.tet);
        if insphere(a, b, c, d, centre) <= 0.0 {
            // The computed centre is not inside the tet's own circumsphere (exact test): the
            // tet is flat to rounding (four nearly cocircular points, seen on coplanar
            // boundary triangles of separate facets) and its float circumsphere is noise. A
            // point there would not remove the tet, and it would be drawn again without end;
            // only restoring the boundary around it can help.
            return Some(resettle(Refusal::FlatToRounding));
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
            return Some(resettle(Refusal::FarCentre));
        }
        // Next to a small angle shape is improved only by the circumcentre, and only when it
        // breaks no boundary: splitting the boundary there for shape would never end (the
        // paper assumes no small angles). Only tets whose circumcentre is close (a sliver's,
        // not a cap's) are tried: a far centre has a huge cavity that always reaches the
        // boundary. Random draws from the picking ball as well cost 3-10x the time there for
        // 10-30% fewer bad tets (measured on the .off models). A tet the centre does not fix
        // is left, counted as within the angle's influence.
        if near && r > le {
            return Some(Plan::Refuse(Refusal::NearSmallAngle));
        }
        // A flat tet with a far circumcentre (one hugging the boundary, made by a boundary
        // split) waits until every other bad tet is handled: by then most are gone, and its
        // centre's cavity is large (measured on anchor.off: 2,100 tets on average, nearly
        // every one ending in a refused boundary split).
        if r > DEFER_RADIUS_PER_EDGE * le {
            if may_defer {
                return Some(Plan::Defer);
            }
            // Deferred already: when its circumcentre lies outside the domain, probing that
            // centre means a huge cavity (thousands of tets) that crosses the boundary, which
            // can only end in a refused split (the boundary element is far smaller than R).
            // Restoring the boundary around it is all that can help.
            let t = dom.dt.locate_shared(centre, bad.tet);
            if !dom.dt.is_finite(t) || dom.dt.tag(t) == 0 {
                return Some(Plan::Resettle {
                    reason: Refusal::CentreOutsideDomain,
                    located: Some(t),
                });
            }
        }
        None
    }

    /// The plan of a tet whose point (with `cavity`) conflicts with the boundary: the
    /// encroached element's split planned too.
    fn yield_plan(
        &self,
        conflict: Conflict<Boundary>,
        cavity: OwnedCavity,
        buf: &mut ProbeBuffers,
    ) -> Plan {
        let split = match conflict {
            Conflict::Encroaches(b) => {
                let mut picker = self.picker.reseeded(split_seed(self.params.seed, b));
                Some(self.dom.plan_split(b, &mut picker, buf))
            }
            _ => None,
        };
        Plan::Yield {
            conflict,
            cavity,
            split,
        }
    }

    /// Li's choice in bad tet `bad`'s picking ball (centre `centre`, circumradius `r`, which
    /// breaks no boundary: `centre_cavity` is its probe, None if it is a vertex), drawing from
    /// a generator seeded by the run's seed and the tet.
    fn pick(
        &self,
        bad: Bad,
        centre: DVec3,
        r: f64,
        centre_cavity: Option<OwnedCavity>,
        buf: &mut ProbeBuffers,
    ) -> Plan {
        let mut picker = self.picker.reseeded(tet_seed(self.params.seed, bad.verts));
        let mut probing = SharedProbing { dom: self.dom, buf };
        match pick_in_ball(&mut probing, &mut picker, centre, centre_cavity, r, bad.tet) {
            Some(cavity) => Plan::Insert(cavity),
            None => Plan::InsertAt(centre),
        }
    }
}

fn resettle(reason: Refusal) -> Plan {
    Plan::Resettle {
        reason,
        located: None,
    }
}

/// The seed of a tet's random draws: the run's seed mixed with its vertices (in increasing
/// order, so it names the tet whatever its orientation or slot).
fn tet_seed(seed: u64, verts: [u32; 4]) -> u64 {
    let mut h = seed ^ 0x9E37_79B9_7F4A_7C15;
    for v in super::quality::sorted4(verts) {
        h = (h ^ v as u64).wrapping_mul(0xBF58_476D_1CE4_E5B9);
        h ^= h >> 31;
    }
    h
}

/// The seed of the random draws splitting boundary element `b`: the run's seed mixed with its
/// vertices.
pub(super) fn split_seed(seed: u64, b: Boundary) -> u64 {
    match b {
        Boundary::Segment(a, c) => tet_seed(seed ^ 0x5e6, [a, c, u32::MAX, u32::MAX]),
        Boundary::Facet(_, [x, y, z]) => tet_seed(seed ^ 0xfac, [x, y, z, u32::MAX]),
    }
}

/// Keep mode's facet level probed through a shared reference ([`Probing`]), with a plan's own
/// buffers: the cavities come out owned.
pub(super) struct SharedProbing<'a> {
    dom: &'a Domain,
    buf: &'a mut ProbeBuffers,
}

impl<'a> SharedProbing<'a> {
    pub(super) fn new(dom: &'a Domain, buf: &'a mut ProbeBuffers) -> Self {
        SharedProbing { dom, buf }
    }
}

impl Probing for SharedProbing<'_> {
    type Cavity = OwnedCavity;

    fn probe(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
        watch: &mut impl CavityWatch,
    ) -> Option<OwnedCavity> {
        let hint = hint.unwrap_or(u32::MAX);
        match self.dom.dt.probe_shared(p, hint, self.buf, watch)? {
            SharedProbe::Cavity(cavity) => Some(cavity),
            SharedProbe::Duplicate(_) => None,
        }
    }

    fn small_slivers(&mut self, picker: &Picker, cavity: &OwnedCavity, r: f64) -> Score {
        picker.small_slivers_of(cavity.point(), cavity.boundary(), self.dom.dt.points(), r)
    }

    fn encroaches(&mut self, cavity: &OwnedCavity) -> bool {
        self.dom.boundary_in_owned(cavity).is_some()
    }

    fn keep(&mut self, _cavity: &OwnedCavity) {}
}
