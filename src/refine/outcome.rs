//! What refining one bad element did (`Refiner::refine_tet` decides, `Refiner::run` keeps the
//! books), and how a refusal is counted in the report's per-reason counts
//! (`run::report::Refusals`).

use crate::run::report::Refusals;

/// What refining one bad tet did.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Outcome {
    /// A volume vertex was inserted: a point of its picking ball, or its centroid.
    Inserted,
    /// A boundary element of this kind was split instead (one the chosen point encroached, or
    /// the subsegment a subfacet's centre encroached).
    Split(BoundaryKind),
    /// The encroached boundary element was queued at its level, which refines it before the
    /// element that asked is looked at again (the approximate mode's subsegments).
    Queued(BoundaryKind),
    /// Restoring the boundary around it split something; it is looked at again if it survived.
    Resettled,
    /// Put aside until every other bad tet is handled.
    Deferred,
    /// Left as it is.
    Refused(Refusal),
    /// Restoring the boundary after an insertion spent the split budget: refinement stops.
    BudgetSpent,
}

/// A kind of boundary element.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum BoundaryKind {
    Segment,
    Facet,
}

/// Why a bad tet was left as it is (the comment where each is produced says why nothing else
/// helps there).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Refusal {
    /// Refused with [`Refusal::Cascade`] or [`Refusal::CascadeNearSmallAngle`] before, and
    /// looked at again: left at once.
    Futile,
    /// Three vertices on one segment or four in one facet; restoring the boundary around it
    /// split nothing.
    FlatByConstruction,
    /// No circumsphere (degenerate in floating point).
    NoCircumsphere,
    /// Its computed circumcentre is not inside its own circumsphere (flat to rounding);
    /// restoring the boundary around it split nothing.
    FlatToRounding,
    /// Its circumcentre is outside the domain's box and far away; restoring the boundary
    /// around it split nothing.
    FarCentre,
    /// Deferred already, and its circumcentre lies outside the domain; restoring the boundary
    /// around it split nothing.
    CentreOutsideDomain,
    /// Within a small input angle's influence, where shape is enforced only by a close
    /// circumcentre that breaks no boundary, or the boundary element to split touches a small
    /// angle.
    NearSmallAngle,
    /// The point to insert is a vertex already.
    Duplicate,
    /// Its circumcentre encroaches a boundary element much smaller than itself (splitting it
    /// would start a cascade of ever smaller splits), and restoring the boundary around it
    /// split nothing. Remembered: looked at again, it is [`Refusal::Futile`].
    Cascade,
    /// [`Refusal::Cascade`], the boundary element within a small angle's influence.
    CascadeNearSmallAngle,
    /// Size-bad next to a small angle: its centroid would break a boundary element much
    /// smaller than itself.
    CentroidCascade,
    /// The subfacet to split has no circumcentre (flat in floating point).
    FlatSubfacet,
    /// The circumcentre of the subfacet to split lies outside its facet and encroaches none
    /// of its subsegments.
    SubfacetCentreOutside,
    /// Its point encroached the boundary each time it was looked at, the boundary was refined
    /// for it as many times as allowed, and it is left (the approximate mode's cell level).
    WaitedForBoundary,
    /// Its point, or the boundary split it asked for, would remove a subfacet of a frozen
    /// facet (a partition's interface, see `Domain::frozen`).
    FrozenInterface,
}

impl Refusal {
    /// Whether the tet counts as left within a small angle's influence (the report's
    /// `n_bad_near_acute`).
    pub(super) fn within_small_angle(self) -> bool {
        matches!(
            self,
            Refusal::NearSmallAngle | Refusal::CascadeNearSmallAngle
        )
    }

    /// Counts this refusal in `counts` (its reason's count and the total).
    pub(super) fn count(self, counts: &mut Refusals) {
        let slot = match self {
            Refusal::Futile => &mut counts.futile,
            Refusal::FlatByConstruction => &mut counts.flat_by_construction,
            Refusal::NoCircumsphere => &mut counts.no_circumsphere,
            Refusal::FlatToRounding => &mut counts.flat_to_rounding,
            Refusal::FarCentre => &mut counts.far_centre,
            Refusal::CentreOutsideDomain => &mut counts.centre_outside_domain,
            Refusal::NearSmallAngle => &mut counts.near_small_angle,
            Refusal::Duplicate => &mut counts.duplicate,
            Refusal::Cascade => &mut counts.cascade,
            Refusal::CascadeNearSmallAngle => &mut counts.cascade_near_small_angle,
            Refusal::CentroidCascade => &mut counts.centroid_cascade,
            Refusal::FlatSubfacet => &mut counts.flat_subfacet,
            Refusal::SubfacetCentreOutside => &mut counts.subfacet_centre_outside,
            Refusal::WaitedForBoundary => &mut counts.waited_for_boundary,
            Refusal::FrozenInterface => &mut counts.frozen_interface,
        };
        *slot += 1;
        counts.total += 1;
    }

    /// Whether the tet is left at once when looked at again ([`Refusal::Futile`]).
    pub(super) fn remembered(self) -> bool {
        matches!(self, Refusal::Cascade | Refusal::CascadeNearSmallAngle)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::report::Refusals;

    const ALL: [Refusal; 15] = [
        Refusal::Futile,
        Refusal::FlatByConstruction,
        Refusal::NoCircumsphere,
        Refusal::FlatToRounding,
        Refusal::FarCentre,
        Refusal::CentreOutsideDomain,
        Refusal::NearSmallAngle,
        Refusal::Duplicate,
        Refusal::Cascade,
        Refusal::CascadeNearSmallAngle,
        Refusal::CentroidCascade,
        Refusal::FlatSubfacet,
        Refusal::SubfacetCentreOutside,
        Refusal::WaitedForBoundary,
        Refusal::FrozenInterface,
    ];

    /// Every reason is counted in a field of its own, named in `counts` as in the JSON report,
    /// and the total is their sum; two passes add up.
    #[test]
    fn every_reason_has_its_own_count_named_as_in_the_json() {
        let mut r = Refusals::default();
        for (k, &reason) in ALL.iter().enumerate() {
            for _ in 0..=k {
                reason.count(&mut r);
            }
        }
        r.count_budget(ALL.len() + 1);
        let mut values: Vec<usize> = r.counts().iter().map(|&(_, n)| n).collect();
        values.sort_unstable();
        assert_eq!(values, (1..=ALL.len() + 1).collect::<Vec<_>>());
        assert_eq!(r.total, values.iter().sum::<usize>());
        let json = serde_json::to_value(&r).unwrap();
        let fields = json.as_object().unwrap();
        assert_eq!(fields.len(), r.counts().len() + 1);
        assert_eq!(json["total"], r.total);
        for (name, n) in r.counts() {
            assert_eq!(json[name], n, "{name}");
        }
        let mut twice = r.clone();
        twice.add(&r);
        assert_eq!(twice.total, 2 * r.total);
        for ((_, a), (_, b)) in twice.counts().into_iter().zip(r.counts()) {
            assert_eq!(a, 2 * b);
        }
        assert!(r.summary().starts_with(&format!("{} (futile 1, ", r.total)));
    }
}
