//! What refining one bad element did (`Refiner::refine_tet` decides, `Refiner::run` keeps the
//! books), and the count of bad tets left alone per reason that the report carries.

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

    /// Whether the tet is left at once when looked at again ([`Refusal::Futile`]).
    pub(super) fn remembered(self) -> bool {
        matches!(self, Refusal::Cascade | Refusal::CascadeNearSmallAngle)
    }
}

/// How many times refinement left a bad tet as it was, per reason (a tet looked at again and
/// left again counts again; many are removed later by other insertions), and how many bad
/// tets a budget left queued. Keep mode and existing meshes; zero in approximate mode.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Refusals {
    /// The sum of all the counts below.
    pub total: usize,
    /// Refused for a cascade before, left at once when looked at again.
    pub futile: usize,
    /// Flat by construction (three vertices on one segment, four in one facet).
    pub flat_by_construction: usize,
    /// No circumsphere in floating point.
    pub no_circumsphere: usize,
    /// Flat to rounding (the computed circumcentre is outside its own circumsphere).
    pub flat_to_rounding: usize,
    /// Circumcentre outside the domain's box and far away.
    pub far_centre: usize,
    /// Deferred, and its circumcentre outside the domain.
    pub centre_outside_domain: usize,
    /// Within a small input angle's influence.
    pub near_small_angle: usize,
    /// The point to insert was a vertex already.
    pub duplicate: usize,
    /// The circumcentre encroaches a much smaller boundary element (a cascade).
    pub cascade: usize,
    /// The same, the element within a small angle's influence.
    pub cascade_near_small_angle: usize,
    /// Size-bad next to a small angle, its centroid breaking a much smaller boundary element.
    pub centroid_cascade: usize,
    /// The subfacet to split has no circumcentre.
    pub flat_subfacet: usize,
    /// The subfacet's circumcentre lies outside its facet.
    pub subfacet_centre_outside: usize,
    /// Bad tets still queued when a budget (vertices, or boundary splits) stopped refinement.
    pub budget: usize,
}

impl Refusals {
    /// Counts one refusal.
    pub(super) fn count(&mut self, r: Refusal) {
        *self.slot(r) += 1;
        self.total += 1;
    }

    /// Counts `n` bad tets left queued by a budget.
    pub(super) fn count_budget(&mut self, n: usize) {
        self.budget += n;
        self.total += n;
    }

    /// The total and the reasons counted, e.g. "1750 (near_small_angle 1585, cascade 165)".
    pub fn summary(&self) -> String {
        let reasons: Vec<String> = self
            .counts()
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(name, n)| format!("{name} {n}"))
            .collect();
        if reasons.is_empty() {
            self.total.to_string()
        } else {
            format!("{} ({})", self.total, reasons.join(", "))
        }
    }

    fn slot(&mut self, r: Refusal) -> &mut usize {
        match r {
            Refusal::Futile => &mut self.futile,
            Refusal::FlatByConstruction => &mut self.flat_by_construction,
            Refusal::NoCircumsphere => &mut self.no_circumsphere,
            Refusal::FlatToRounding => &mut self.flat_to_rounding,
            Refusal::FarCentre => &mut self.far_centre,
            Refusal::CentreOutsideDomain => &mut self.centre_outside_domain,
            Refusal::NearSmallAngle => &mut self.near_small_angle,
            Refusal::Duplicate => &mut self.duplicate,
            Refusal::Cascade => &mut self.cascade,
            Refusal::CascadeNearSmallAngle => &mut self.cascade_near_small_angle,
            Refusal::CentroidCascade => &mut self.centroid_cascade,
            Refusal::FlatSubfacet => &mut self.flat_subfacet,
            Refusal::SubfacetCentreOutside => &mut self.subfacet_centre_outside,
        }
    }

    /// Adds another pass's counts.
    pub fn add(&mut self, o: &Refusals) {
        let Refusals {
            total,
            futile,
            flat_by_construction,
            no_circumsphere,
            flat_to_rounding,
            far_centre,
            centre_outside_domain,
            near_small_angle,
            duplicate,
            cascade,
            cascade_near_small_angle,
            centroid_cascade,
            flat_subfacet,
            subfacet_centre_outside,
            budget,
        } = o;
        self.total += total;
        self.futile += futile;
        self.flat_by_construction += flat_by_construction;
        self.no_circumsphere += no_circumsphere;
        self.flat_to_rounding += flat_to_rounding;
        self.far_centre += far_centre;
        self.centre_outside_domain += centre_outside_domain;
        self.near_small_angle += near_small_angle;
        self.duplicate += duplicate;
        self.cascade += cascade;
        self.cascade_near_small_angle += cascade_near_small_angle;
        self.centroid_cascade += centroid_cascade;
        self.flat_subfacet += flat_subfacet;
        self.subfacet_centre_outside += subfacet_centre_outside;
        self.budget += budget;
    }

    /// The counts by reason (without the total), named as in the JSON report.
    pub fn counts(&self) -> [(&'static str, usize); 14] {
        let Refusals {
            total: _,
            futile,
            flat_by_construction,
            no_circumsphere,
            flat_to_rounding,
            far_centre,
            centre_outside_domain,
            near_small_angle,
            duplicate,
            cascade,
            cascade_near_small_angle,
            centroid_cascade,
            flat_subfacet,
            subfacet_centre_outside,
            budget,
        } = *self;
        [
            ("futile", futile),
            ("flat_by_construction", flat_by_construction),
            ("no_circumsphere", no_circumsphere),
            ("flat_to_rounding", flat_to_rounding),
            ("far_centre", far_centre),
            ("centre_outside_domain", centre_outside_domain),
            ("near_small_angle", near_small_angle),
            ("duplicate", duplicate),
            ("cascade", cascade),
            ("cascade_near_small_angle", cascade_near_small_angle),
            ("centroid_cascade", centroid_cascade),
            ("flat_subfacet", flat_subfacet),
            ("subfacet_centre_outside", subfacet_centre_outside),
            ("budget", budget),
        ]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const ALL: [Refusal; 13] = [
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
    ];

    /// Every reason is counted in a field of its own, named in `counts` as in the JSON report,
    /// and the total is their sum; two passes add up.
    #[test]
    fn every_reason_has_its_own_count_named_as_in_the_json() {
        let mut r = Refusals::default();
        for (k, &reason) in ALL.iter().enumerate() {
            for _ in 0..=k {
                r.count(reason);
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
