//! What the restricted mesher keeps up to date at every insertion, for both levels: each tet's
//! circumcentre and region (the input's region holding its circumcentre, 0 outside), and the
//! restricted facets with their surface balls.
//!
//! One walk over the first triangulation classifies everything; afterwards each insertion only
//! looks at its new tets. Each face's Voronoi edge (the segment between the circumcentres of its
//! two tets) is crossed with the surface once: that makes the face restricted, and its proper
//! crossings, each from one side of an input triangle to the other, carry the region from one
//! tet to the other (a ray decides where a crossing is not proper or a circumcentre is missing;
//! with one region this is the parity of the crossings).

use super::{key3, Restricted, SurfaceMesher};
use crate::delaunay::tables::FACE;
use crate::delaunay::{Delaunay, INFINITE};
use crate::geom::circumsphere;
use crate::surface::oracle::{Crossing, SurfaceOracle};
use glam::DVec3;
use rustc_hash::FxHashMap;

/// A restricted facet's surface centre, surface-ball radius, the input triangle the centre
/// lies on and whether it spans a hole instead (`Restricted`).
pub(super) type SurfaceBall = (DVec3, f64, u32, bool);

/// A repaired input's tet region: the winding count at the circumcentre and whether it lies
/// in the solid, as `count * 2 + inside` (two's complement bits).
fn repaired_region(count: i32, inside: bool) -> u32 {
    ((count << 1) | i32::from(inside)) as u32
}

/// The winding count of a repaired input's region.
pub(super) fn count_of(region: u32) -> i32 {
    (region as i32) >> 1
}

/// Whether a repaired input's region is in the solid.
pub(super) fn label_of(region: u32) -> u32 {
    region & 1
}

/// Whether `face` was a restricted facet before the insertion (`before`: the records the
/// removed tets' faces had).
fn was_restricted(before: &[([u32; 3], SurfaceBall)], face: [u32; 3]) -> bool {
    let key = key3(face);
    before.iter().any(|(k, _)| *k == key)
}

/// The face of created tet `t` across the cavity's boundary: the one opposite the new vertex.
fn outer_face(dt: &Delaunay, t: u32, new_vertex: u32) -> Option<usize> {
    dt.tet(t).iter().position(|&v| v == new_vertex)
}

/// Relative margin of [`SurfaceMesher::surface_untouched`]'s distance test.
const UNTOUCHED_MARGIN: f64 = 1e-6;

#[derive(Default)]
pub(super) struct Tracking {
    /// Per tet id.
    pub tets: Vec<TetInfo>,
    /// The restricted facets (sorted vertices) and their surface balls.
    pub restricted: FxHashMap<[u32; 3], SurfaceBall>,
}

impl Tracking {
    /// Whether face `i` of live tet `t` is a restricted facet (a key of `restricted`).
    pub fn is_restricted(&self, t: u32, i: usize) -> bool {
        self.tets
            .get(t as usize)
            .is_some_and(|info| info.restricted & (1 << i) != 0)
    }

    /// Records whether face `i` of tet `t` is restricted, on `t` and on the tet across it.
    fn mark_face(&mut self, dt: &Delaunay, t: u32, i: usize, restricted: bool) {
        let (n, j) = dt.mirror(t, i);
        for (tet, face) in [(t, i), (n, j)] {
            let bits = &mut self.tets[tet as usize].restricted;
            *bits = (*bits & !(1 << face)) | (u8::from(restricted) << face);
        }
    }
}

/// What is tracked of one tet, side by side: each insertion reads it for the tets around its
/// cavity, and the cell level for the tets it looks at.
#[derive(Debug, Clone, Copy)]
pub(super) struct TetInfo {
    centre: DVec3,
    /// Negative when the tet has no circumsphere (flat or infinite).
    radius: f64,
    /// The region holding the circumcentre (`InputSurface::sides`; 0 outside or without one);
    /// for a repaired input, `repaired_region`.
    region: u32,
    /// Bit i: face i (opposite vertex i) is a key of [`Tracking::restricted`]. Kept exact on
    /// both tets of each face, so that the faces of removed and probed tets that are not
    /// restricted (nearly all) are not looked up in the map.
    restricted: u8,
}

impl Default for TetInfo {
    fn default() -> Self {
        TetInfo {
            centre: DVec3::ZERO,
            radius: -1.0,
            region: 0,
            restricted: 0,
        }
    }
}

impl TetInfo {
    /// Tet `tv`'s circumsphere (`geom::circumsphere` of its vertices in their order), region
    /// not known yet.
    fn of(dt: &Delaunay, tv: [u32; 4]) -> TetInfo {
        if tv.contains(&INFINITE) {
            return TetInfo::default();
        }
        let [a, b, c, d] = tv.map(|v| dt.point(v));
        match circumsphere(a, b, c, d) {
            Some((centre, radius)) => TetInfo {
                centre,
                radius,
                region: 0,
                restricted: 0,
            },
            None => TetInfo::default(),
        }
    }

    fn centre(&self) -> Option<DVec3> {
        (self.radius >= 0.0).then_some(self.centre)
    }
}

/// Every tet's region and every restricted facet, from one pass over the triangulation.
struct Classified {
    tets: Vec<TetInfo>,
    restricted: Vec<Restricted>,
}

impl SurfaceMesher<'_> {
    /// Classifies the whole triangulation and queues its bad restricted facets.
    pub(super) fn start_tracking(&mut self) {
        let classified = self.classify_tets();
        self.track = Tracking {
            tets: classified.tets,
            restricted: classified
                .restricted
                .iter()
                .map(|r| (key3(r.vertices), (r.centre, r.radius, r.triangle, r.span)))
                .collect(),
        };
        self.queue_bad(&classified.restricted);
        #[cfg(test)]
        if CHECK_EVERY_INSERTION.get() {
            self.assert_restricted_bits();
        }
    }

    /// Whether tet `t`'s circumcentre lies inside the domain (in any region).
    pub(super) fn is_inside(&self, t: u32) -> bool {
        self.region_of(t) != 0
    }

    /// The region holding tet `t`'s circumcentre (0 outside).
    pub(super) fn region_of(&self, t: u32) -> u32 {
        let region = self.track.tets.get(t as usize).map_or(0, |i| i.region);
        match self.repair {
            Some(_) => label_of(region),
            None => region,
        }
    }

    /// The oracle of the segment queries: the repaired input's counting surface, else the
    /// surface's own.
    fn segments(&self) -> &SurfaceOracle {
        self.repair.map_or(self.oracle, |r| &r.labels.segments)
    }

    /// The region (as tracked) of a point, from a ray.
    fn region_at(&self, p: DVec3) -> u32 {
        match self.repair {
            Some(r) => {
                let count = r.labels.count(p);
                repaired_region(count, r.labels.inside(count, p))
            }
            None => self.oracle.region(p),
        }
    }

    /// The circumcentre and circumradius of live tet `t` (None when flat or infinite), as
    /// `geom::circumsphere` gives them.
    pub(super) fn sphere_of(&self, t: u32) -> Option<(DVec3, f64)> {
        let info = self.track.tets.get(t as usize)?;
        info.centre().map(|c| (c, info.radius))
    }

    /// The region of a tet with circumcentre `centre`, given the region of the tet across a
    /// face and the crossings of the segment between their circumcentres (None: a centre
    /// missing), ordered from the other tet's centre towards `centre` when `towards`, else
    /// the other way. Where the crossings do not settle it, a ray does. A flat tet (no
    /// centre) is outside.
    fn region_across(
        &self,
        other: u32,
        centre: Option<DVec3>,
        crossings: Option<&[Crossing]>,
        towards: bool,
    ) -> u32 {
        let from = match self.repair {
            Some(_) => count_of(other) as u32,
            None => other,
        };
        let carried = |x: &[Crossing]| {
            let region = if towards {
                self.segments().region_across(from, x, true)
            } else {
                self.segments().region_across(from, x.iter().rev(), false)
            };
            match (self.repair, centre) {
                (Some(r), Some(c)) => region.map(|n| {
                    let count = n as i32;
                    repaired_region(count, r.labels.inside(count, c))
                }),
                _ => region,
            }
        };
        match (centre, crossings) {
            (None, _) => 0,
            (Some(c), Some(x)) => carried(x).unwrap_or_else(|| self.region_at(c)),
            (Some(c), None) => self.region_at(c),
        }
    }

    /// After inserting `new_vertex`: the restricted facets of the removed tets go; the created
    /// tets get their circumcentre and region, their faces are checked (each Voronoi edge crossed
    /// once) and the bad restricted facets queued. A cell-level point whose Voronoi cell misses
    /// the surface changes none of that but the regions (`surface_untouched`).
    pub(super) fn track_insertion(&mut self, new_vertex: u32, created: &[u32]) {
        let mut track = std::mem::take(&mut self.track);
        let cap = self.dt.tet_capacity();
        if track.tets.len() < cap {
            track.tets.resize(cap, TetInfo::default());
        }
        // Read before the created tets take over the removed ones' slots.
        let removed: Vec<TetInfo> = self
            .dt
            .last_removed_ids()
            .iter()
            .map(|&t| track.tets[t as usize])
            .collect();
        let removed_region = removed
            .iter()
            .find_map(|info| info.centre().map(|_| info.region));
        // Then every cavity boundary face had a Voronoi edge, crossed when it last changed.
        let removed_centred = removed.iter().all(|info| info.centre().is_some());
        for &t in created {
            track.tets[t as usize] = TetInfo::of(&self.dt, self.dt.tet(t));
        }
        if let Some(region) =
            removed_region.filter(|_| self.surface_untouched(new_vertex, created, &track.tets))
        {
            for &t in created {
                track.tets[t as usize].region = region;
                // The restricted facets are unchanged: only a face across the cavity's
                // boundary can be one, and the tet outside still records it.
                if let Some(i) = outer_face(&self.dt, t, new_vertex) {
                    let (n, j) = self.dt.mirror(t, i);
                    if track.is_restricted(n, j) {
                        track.tets[t as usize].restricted |= 1 << i;
                    }
                }
            }
            self.track = track;
            #[cfg(test)]
            if CHECK_EVERY_INSERTION.get() {
                self.assert_restricted_bits();
            }
            return;
        }
        // A facet found again with the same surface centre, ball and input triangle was judged
        // already (its criteria depend on nothing else): it is not judged again.
        let mut before = vec![];
        for (tv, info) in self.dt.last_removed().iter().zip(&removed) {
            for (i, f) in FACE.iter().enumerate() {
                if info.restricted & (1 << i) == 0 {
                    continue;
                }
                let key = key3(f.map(|k| tv[k]));
                if let Some(old) = track.restricted.remove(&key) {
                    before.push((key, old));
                }
            }
        }
        // The records across the cavity's boundary are read first, side by side: their cache
        // misses then overlap instead of each waiting behind the previous face's surface query
        // (fandisk 1-2% less CPU time). `black_box` only keeps the reads; nothing depends on it.
        let mut across = 0u8;
        for &t in created {
            if let Some(i) = outer_face(&self.dt, t, new_vertex) {
                across ^= track.tets[self.dt.mirror(t, i).0 as usize].restricted;
            }
        }
        std::hint::black_box(across);
        let mut found = vec![];
        // The faces across the cavity's boundary first: they give the created tets their
        // regions, which the inner faces of a repaired input's new star need.
        for outer_pass in [true, false] {
            for &t in created {
                let tv = self.dt.tet(t);
                let nb = self.dt.neighbors(t);
                let c = track.tets[t as usize].centre();
                for i in 0..4 {
                    let n = nb[i];
                    let outer = tv[i] == new_vertex;
                    if outer != outer_pass || (!outer && n < t) {
                        continue; // an inner face of the new star, seen from the other tet
                    }
                    // Infinite tets have no centre: the neighbour's record alone says it.
                    let other = track.tets[n as usize];
                    let face = FACE[i].map(|k| tv[k]);
                    let both_centred = c.is_some() && other.centre().is_some();
                    // (Not for a repaired input: its restricted facets are where the label changes,
                    // and the old edge may have crossed triangles inside or outside the solid.)
                    if outer
                        && self.repair.is_none()
                        && both_centred
                        && removed_centred
                        && !was_restricted(&before, face)
                    {
                        // The new Voronoi edge is the part of the old one outside the new vertex's
                        // cell: the old one crossed nothing, so neither does it (even parity).
                        track.tets[t as usize].region = other.region;
                        track.mark_face(&self.dt, t, i, false);
                        continue;
                    }
                    let crossings = match (c, other.centre()) {
                        (Some(c), Some(cn)) => Some(self.segments().crossings(c, cn)),
                        _ => None,
                    };
                    if outer {
                        track.tets[t as usize].region =
                            self.region_across(other.region, c, crossings.as_deref(), false);
                    }
                    let ends = c
                        .zip(other.centre())
                        .map(|(c, cn)| (c, track.tets[t as usize].region, cn, other.region));
                    let crossings = crossings.unwrap_or_default();
                    let restricted = self.facet_from(face, crossings, ends);
                    track.mark_face(&self.dt, t, i, restricted.is_some());
                    if let Some(r) = restricted {
                        let key = key3(r.vertices);
                        let ball = (r.centre, r.radius, r.triangle, r.span);
                        track.restricted.insert(key, ball);
                        if !before.contains(&(key, ball)) {
                            found.push(r);
                        }
                    }
                }
            }
        }
        self.track = track;
        self.queue_bad(&found);
        #[cfg(test)]
        if CHECK_EVERY_INSERTION.get() {
            self.assert_restricted_bits();
        }
    }

    /// Whether cell-level vertex `v`'s Voronoi cell certainly misses the surface. The cell is
    /// the hull of the created tets' circumcentres (all finite): it lies in any ball holding
    /// them, here the one about the middle of their bounding box. If that ball misses the
    /// surface:
    /// - every new face at `v` has its Voronoi edge in the cell: none is restricted;
    /// - every cavity boundary face keeps the part of its old Voronoi edge outside the cell,
    ///   so the same crossings: the same record, judged already;
    /// - the removed tets' inner faces had their Voronoi edges in the cell: none was
    ///   restricted;
    /// - the cell is in one region, so all created circumcentres are in the region
    ///   of the removed ones (which lie in it too: `v` is nearer to them than any other site).
    fn surface_untouched(&self, v: u32, created: &[u32], tets: &[TetInfo]) -> bool {
        if !matches!(self.loc.get(v as usize), Some(super::Loc::Volume)) {
            return false;
        }
        let mut centres = Vec::with_capacity(created.len());
        for &t in created {
            match tets[t as usize].centre() {
                Some(c) => centres.push(c),
                None => return false, // a flat or infinite new tet: the cell is not that hull
            }
        }
        let (lo, hi) = centres
            .iter()
            .fold((DVec3::INFINITY, DVec3::NEG_INFINITY), |(lo, hi), &c| {
                (lo.min(c), hi.max(c))
            });
        let middle = (lo + hi) / 2.0;
        let radius = centres
            .iter()
            .map(|&c| (c - middle).length())
            .fold(0.0, f64::max);
        // The distances are floating point: a relative margin far above their rounding.
        let radius = radius * (1.0 + UNTOUCHED_MARGIN);
        match self.repair {
            Some(r) => r.labels.clear_within(middle, radius),
            None => self.oracle.clear_within(middle, radius),
        }
    }

    /// [`Classified`]: a walk from tet to neighbouring tet, where the segment between their
    /// circumcentres (the face's Voronoi edge) is crossed once for both questions: it makes
    /// the face restricted, and its crossings carry the region across (when they do not
    /// settle it, or a centre is missing, a ray decides).
    fn classify_tets(&self) -> Classified {
        let cap = self.dt.tet_capacity();
        let mut out = Classified {
            tets: vec![TetInfo::default(); cap],
            restricted: vec![],
        };
        let mut reached = vec![false; cap];
        let mut done = vec![false; cap];
        let mut queue = std::collections::VecDeque::new();
        for t in self.dt.finite_tet_ids() {
            out.tets[t as usize] = TetInfo::of(&self.dt, self.dt.tet(t));
            if queue.is_empty() {
                if let Some(c) = out.tets[t as usize].centre() {
                    out.tets[t as usize].region = self.region_at(c);
                    reached[t as usize] = true;
                    queue.push_back(t);
                }
            }
        }
        while let Some(t) = queue.pop_front() {
            done[t as usize] = true;
            let tv = self.dt.tet(t);
            for (i, &n) in self.dt.neighbors(t).iter().enumerate() {
                if done[n as usize] || !self.dt.is_finite(n) {
                    continue;
                }
                let (c, cn) = (out.tets[t as usize].centre(), out.tets[n as usize].centre());
                let crossings = match (c, cn) {
                    (Some(c), Some(cn)) => Some(self.segments().crossings(c, cn)),
                    _ => None,
                };
                if !reached[n as usize] {
                    reached[n as usize] = true;
                    out.tets[n as usize].region = self.region_across(
                        out.tets[t as usize].region,
                        cn,
                        crossings.as_deref(),
                        true,
                    );
                    queue.push_back(n);
                }
                let ends = c.zip(cn).map(|(c, cn)| {
                    let info = &out.tets;
                    (c, info[t as usize].region, cn, info[n as usize].region)
                });
                let crossings = crossings.unwrap_or_default();
                let face = FACE[i].map(|k| tv[k]);
                if let Some(r) = self.facet_from(face, crossings, ends) {
                    out.restricted.push(r);
                    let (n, j) = self.dt.mirror(t, i);
                    out.tets[t as usize].restricted |= 1 << i;
                    out.tets[n as usize].restricted |= 1 << j;
                }
            }
        }
        out
    }
}

#[cfg(test)]
thread_local! {
    /// Test switch: check the restricted bits after every insertion on this thread.
    pub(in crate::approx) static CHECK_EVERY_INSERTION: std::cell::Cell<bool> =
        const { std::cell::Cell::new(false) };
}

#[cfg(test)]
impl SurfaceMesher<'_> {
    /// Every live tet's restricted bits agree with the map, and every key of the map is a
    /// face of two live tets (none left behind by a removal).
    pub(super) fn assert_restricted_bits(&self) {
        let mut marked = 0;
        for t in 0..self.dt.tet_capacity() as u32 {
            if !self.dt.is_alive(t) {
                continue;
            }
            let tv = self.dt.tet(t);
            for (i, f) in FACE.iter().enumerate() {
                let key = key3(f.map(|k| tv[k]));
                let in_map = self.track.restricted.contains_key(&key);
                assert_eq!(
                    self.track.is_restricted(t, i),
                    in_map,
                    "tet {t} face {i} {key:?}: bit and map disagree"
                );
                marked += usize::from(in_map);
            }
        }
        assert_eq!(
            marked,
            2 * self.track.restricted.len(),
            "stale restricted facets"
        );
    }
}
