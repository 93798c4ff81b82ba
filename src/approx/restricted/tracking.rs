//! What the restricted mesher keeps up to date at every insertion, for both levels: each tet's
//! circumcentre and side (its circumcentre inside the surface or not), and the restricted
//! facets with their surface balls.
//!
//! One walk over the first triangulation classifies everything; afterwards each insertion only
//! looks at its new tets. Each face's Voronoi edge (the segment between the circumcentres of its
//! two tets) is crossed with the surface once: that makes the face restricted, and the parity of
//! its proper crossings says whether the side changes from one tet to the other (a ray decides
//! where a crossing is not proper or a circumcentre is missing).

use super::{circumcenter_of, key3, Queued, Restricted, SurfaceMesher};
use crate::delaunay::tables::FACE;
use crate::delaunay::INFINITE;
use crate::surface::oracle::Side;
use glam::DVec3;
use rustc_hash::FxHashMap;

#[derive(Default)]
pub(super) struct Tracking {
    /// Per tet id: its circumcentre lies inside the surface.
    pub inside: Vec<bool>,
    /// Per tet id: its circumcentre (None: flat or infinite).
    pub centre: Vec<Option<DVec3>>,
    /// The restricted facets (sorted vertices): surface centre, surface-ball radius and the
    /// input triangle the centre lies on.
    pub restricted: FxHashMap<[u32; 3], (DVec3, f64, u32)>,
}

/// Every tet's side and every restricted facet, from one pass over the triangulation.
struct Classified {
    inside: Vec<bool>,
    centre: Vec<Option<DVec3>>,
    restricted: Vec<Restricted>,
}

impl SurfaceMesher<'_> {
    /// Classifies the whole triangulation and queues its bad restricted facets.
    pub(super) fn start_tracking(&mut self) {
        let classified = self.classify_tets();
        self.track = Tracking {
            inside: classified.inside,
            centre: classified.centre,
            restricted: classified
                .restricted
                .iter()
                .map(|r| (key3(r.vertices), (r.centre, r.radius, r.triangle)))
                .collect(),
        };
        for r in classified.restricted {
            self.queue_if_bad(r);
        }
    }

    fn queue_if_bad(&mut self, r: Restricted) {
        if self.is_bad(&r) {
            self.facets.push(Queued {
                radius: r.radius,
                face: key3(r.vertices),
            });
        }
    }

    /// Whether tet `t`'s circumcentre lies inside the surface.
    pub(super) fn is_inside(&self, t: u32) -> bool {
        self.track.inside.get(t as usize).copied().unwrap_or(false)
    }

    /// The circumcentre of tet `t` (None when flat or infinite).
    pub(super) fn centre_of(&self, t: u32) -> Option<DVec3> {
        self.track.centre.get(t as usize).copied().flatten()
    }

    /// Whether a tet with circumcentre `centre` is inside, given the side of the tet across a
    /// face and the crossing parity of the segment between their circumcentres (None: not
    /// clean, or a centre missing; a ray decides). A flat tet (no centre) is outside.
    fn side_across(&self, other_inside: bool, centre: Option<DVec3>, parity: Option<bool>) -> bool {
        match (centre, parity) {
            (None, _) => false,
            (Some(_), Some(odd)) => other_inside != odd,
            (Some(c), None) => self.oracle.side(c) != Side::Outside,
        }
    }

    /// After inserting `new_vertex`: the restricted facets of the removed tets go; the created
    /// tets get their circumcentre and side, their faces are checked (each Voronoi edge crossed
    /// once) and the bad restricted facets queued.
    pub(super) fn track_insertion(&mut self, new_vertex: u32, created: &[u32]) {
        let mut track = std::mem::take(&mut self.track);
        // A facet found again with the same surface centre, ball and input triangle was judged
        // already (its criteria depend on nothing else): it is not judged again.
        let mut before = vec![];
        for tv in self.dt.last_removed() {
            for f in FACE {
                let key = key3(f.map(|k| tv[k]));
                if let Some(old) = track.restricted.remove(&key) {
                    before.push((key, old));
                }
            }
        }
        let cap = self.dt.tet_capacity();
        if track.inside.len() < cap {
            track.inside.resize(cap, false);
            track.centre.resize(cap, None);
        }
        for &t in created {
            let tv = self.dt.tet(t);
            track.centre[t as usize] = if tv.contains(&INFINITE) {
                None
            } else {
                circumcenter_of(&self.dt, tv)
            };
        }
        let mut found = vec![];
        for &t in created {
            let tv = self.dt.tet(t);
            let nb = self.dt.neighbors(t);
            let c = track.centre[t as usize];
            for i in 0..4 {
                let n = nb[i];
                let outer = tv[i] == new_vertex;
                if !outer && n < t {
                    continue; // an inner face of the new star, seen from the other tet
                }
                let cn = if self.dt.tet(n).contains(&INFINITE) {
                    None
                } else {
                    track.centre[n as usize]
                };
                let (crossings, parity) = match (c, cn) {
                    (Some(c), Some(cn)) => self.oracle.crossings_and_parity(c, cn),
                    _ => (vec![], None),
                };
                if outer {
                    track.inside[t as usize] =
                        self.side_across(track.inside[n as usize], c, parity);
                }
                let face = FACE[i].map(|k| tv[k]);
                if let Some(r) = Self::facet_from(&self.dt, face, crossings) {
                    let key = key3(r.vertices);
                    let ball = (r.centre, r.radius, r.triangle);
                    track.restricted.insert(key, ball);
                    if !before.contains(&(key, ball)) {
                        found.push(r);
                    }
                }
            }
        }
        self.track = track;
        for r in found {
            self.queue_if_bad(r);
        }
    }

    /// [`Classified`]: a walk from tet to neighbouring tet, where the segment between their
    /// circumcentres (the face's Voronoi edge) is crossed once for both questions: it makes
    /// the face restricted, and the parity of its proper crossings says whether the side
    /// changes (when a crossing is not proper, or a centre is missing, a ray decides).
    fn classify_tets(&self) -> Classified {
        let cap = self.dt.tet_capacity();
        let mut out = Classified {
            inside: vec![false; cap],
            centre: vec![None; cap],
            restricted: vec![],
        };
        let mut reached = vec![false; cap];
        let mut done = vec![false; cap];
        let mut queue = std::collections::VecDeque::new();
        for t in self.dt.finite_tet_ids() {
            out.centre[t as usize] = circumcenter_of(&self.dt, self.dt.tet(t));
            if queue.is_empty() {
                if let Some(c) = out.centre[t as usize] {
                    out.inside[t as usize] = self.oracle.side(c) != Side::Outside;
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
                let (c, cn) = (out.centre[t as usize], out.centre[n as usize]);
                let (crossings, parity) = match (c, cn) {
                    (Some(c), Some(cn)) => self.oracle.crossings_and_parity(c, cn),
                    _ => (vec![], None),
                };
                if !reached[n as usize] {
                    reached[n as usize] = true;
                    out.inside[n as usize] = self.side_across(out.inside[t as usize], cn, parity);
                    queue.push_back(n);
                }
                let face = FACE[i].map(|k| tv[k]);
                if let Some(r) = Self::facet_from(&self.dt, face, crossings) {
                    out.restricted.push(r);
                }
            }
        }
        out
    }
}
