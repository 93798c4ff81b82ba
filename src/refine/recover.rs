//! "Enforce Empty Encroachment" (the paper's first step, Shewchuk's conforming Delaunay
//! boundary recovery): split subsegments whose diametric ball holds a vertex or that are not
//! Delaunay edges, then subfacets whose equatorial ball holds a vertex or that are not Delaunay
//! faces; a subfacet split yields to the split of a subsegment its centre encroaches.
//! When it returns, every subsegment is an edge and every subfacet a face of the
//! triangulation (checked exactly, combinatorially), so the boundary is conforming.

use super::domain::{seg_key, tri_key, Domain};
use crate::delaunay::{tables::FACE, INFINITE};
use crate::geom::{diametric_ball, equatorial_ball, tri_circumcenter};
use crate::run::error::MeshError;
use glam::DVec3;

/// Safety net against a non-terminating recovery (e.g. an input angle so small that even
/// concentric shells cannot help within floating point): the number of splits allowed.
pub const MAX_RECOVERY_SPLITS: usize = 2_000_000;

/// Whether boundary recovery finished.
#[must_use]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Settled {
    /// Every subsegment and subfacet is present and unencroached (unless protected).
    Conforming,
    /// The split budget ran out first: the boundary may not conform.
    BudgetSpent,
}

/// Why a boundary element is not conforming yet.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) enum Status {
    Ok,
    Missing,
    Encroached,
}

impl Domain {
    /// Splits until every subsegment and subfacet is present and unencroached.
    pub fn recover_boundary(&mut self, budget: &mut usize) -> Result<Settled, MeshError> {
        let mut segs: Vec<(u32, u32)> = self.subsegs.keys().copied().collect();
        segs.sort_unstable(); // deterministic order
        let mut tris: Vec<[u32; 3]> = self.subfacets.keys().copied().collect();
        tris.sort_unstable();
        self.dirty_segs.extend(segs);
        self.dirty_tris.extend(tris);
        self.settle(budget)
    }

    /// Queues the subsegments and subfacets among the edges and faces of the tets the last
    /// insertion created: the new vertex may encroach them.
    /// Also queues those among the deleted tets' edges and faces: an insertion on one facet
    /// may remove a subfacet of another, which must then be recovered.
    pub fn queue_around_last_insertion(&mut self) {
        let created = self.dt.last_created().iter().map(|&t| self.dt.tet(t));
        let quads: Vec<[u32; 4]> = created
            .chain(self.dt.last_removed().iter().copied())
            .collect();
        for v in quads {
            // Only edges and faces whose vertices all lie on the boundary can be boundary
            // elements; most tets have a volume vertex and are skipped without a lookup.
            let on_boundary = v.map(|x| {
                x != INFINITE && self.kind[x as usize] != super::domain::VertexKind::Volume
            });
            if on_boundary.iter().filter(|&&b| b).count() < 2 {
                continue;
            }
            for i in 0..4 {
                for j in i + 1..4 {
                    let k = seg_key(v[i], v[j]);
                    if on_boundary[i] && on_boundary[j] && self.subsegs.contains_key(&k) {
                        self.dirty_segs.push(k);
                    }
                }
                let f = FACE[i].map(|l| v[l]);
                let face_on_boundary = (0..4).all(|l| l == i || on_boundary[l]);
                if face_on_boundary && self.subfacets.contains_key(&tri_key(f)) {
                    self.dirty_tris.push(tri_key(f));
                }
            }
        }
    }

    /// Works through the queued subsegments (first) and subfacets until none is missing or
    /// encroached; every split queues what it creates or may encroach. Each split spends one
    /// unit of `budget`.
    pub fn settle(&mut self, budget: &mut usize) -> Result<Settled, MeshError> {
        loop {
            if let Some((a, b)) = self.dirty_segs.pop() {
                if !self.subsegs.contains_key(&(a, b)) {
                    continue;
                }
                let status = self.subsegment_status(a, b);
                if status == Status::Ok {
                    continue;
                }
                if !spend(budget) {
                    return Ok(Settled::BudgetSpent);
                }
                let Some(p) = self.split_point_clear_of_frozen(a, b, status) else {
                    let (pa, pb) = (self.point(a), self.point(b));
                    frozen_missing(status, &format!("subsegment ({a}, {b}) from {pa} to {pb}"))?;
                    continue;
                };
                if self.split_removed_first(p, self.dt.vertex_tet(a), Some((a, b)))? {
                    self.dirty_segs.push((a, b));
                    continue;
                }
                self.split_subsegment(a, b, p, None)?;
                continue;
            }
            let Some(tri) = self.dirty_tris.pop() else {
                return Ok(Settled::Conforming);
            };
            let Some(&f) = self.subfacets.get(&tri) else {
                continue;
            };
            let status = self.subfacet_status(tri);
            if status != Status::Ok && self.frozen[f as usize] {
                frozen_missing(status, &format!("subfacet {tri:?} of facet {f}"))?;
                continue;
            }
            let within_budget = match status {
                Status::Ok => true,
                Status::Missing if self.flip_to_match(f, tri) => true,
                _ => self.split_subfacet(f, tri, status, budget)?,
            };
            if !within_budget {
                return Ok(Settled::BudgetSpent);
            }
        }
    }

    /// A subsegment is fine when it is an edge of the triangulation and no vertex of a tet
    /// around it lies strictly inside its diametric ball (for a Delaunay edge, a vertex in the
    /// ball implies one among the edge's link).
    pub(super) fn subsegment_status(&self, a: u32, b: u32) -> Status {
        let mut ring = Vec::with_capacity(16);
        if !self.dt.edge_ring(a, b, &mut ring) {
            return Status::Missing;
        }
        let (c, r) = diametric_ball(self.point(a), self.point(b));
        let r2 = r * r;
        for t in ring {
            let v = self.dt.tet(t);
            for &w in &v {
                if w != a && w != b && w != INFINITE && self.point(w).distance_squared(c) < r2 {
                    return self.encroached_unless_protected(&[a, b]);
                }
            }
        }
        Status::Ok
    }

    /// A subfacet is fine when it is a face of the triangulation and neither apex of its two
    /// tets lies strictly inside its equatorial ball.
    pub(super) fn subfacet_status(&self, t: [u32; 3]) -> Status {
        let Some(sides) = self.dt.find_face(t[0], t[1], t[2]) else {
            return Status::Missing;
        };
        let Some((c, r)) = equatorial_ball(self.point(t[0]), self.point(t[1]), self.point(t[2]))
        else {
            return Status::Missing;
        };
        for (tet, i) in sides {
            let apex = self.dt.tet(tet)[i];
            if apex != INFINITE && self.point(apex).distance_squared(c) < r * r {
                return self.encroached_unless_protected(&t);
            }
        }
        Status::Ok
    }

    /// Inside a protecting ball an encroached element that is present is left alone, and so
    /// is one of a frozen facet.
    fn encroached_unless_protected(&self, verts: &[u32]) -> Status {
        let frozen = match *verts {
            [a, b] => self.is_frozen_subsegment(seg_key(a, b)),
            [a, b, c] => self.is_frozen_subfacet(&tri_key([a, b, c])),
            _ => false,
        };
        if frozen || self.protected(verts) {
            Status::Ok
        } else {
            Status::Encroached
        }
    }

    /// A subfacet can be missing only because the 3D triangulation broke a cocircular tie the
    /// other way: if flipping one of its unconstrained edges in the facet yields two faces the
    /// 3D triangulation has, take that flip instead of inserting a point.
    fn flip_to_match(&mut self, f: u32, tri: [u32; 3]) -> bool {
        for k in 0..3 {
            let (x, y, z) = (tri[k], tri[(k + 1) % 3], tri[(k + 2) % 3]);
            let fm = &self.facets[f as usize];
            if fm.is_constrained(x, y) {
                continue;
            }
            let Some(d) = fm
                .opposite(x, y)
                .into_iter()
                .flatten()
                .flatten()
                .find(|&d| d != z)
            else {
                continue;
            };
            if self.dt.find_face(z, x, d).is_none() || self.dt.find_face(z, d, y).is_none() {
                continue;
            }
            if self.facets[f as usize].flip(x, y) {
                self.subfacets.remove(&tri_key([x, y, z]));
                self.subfacets.remove(&tri_key([x, y, d]));
                for t in [tri_key([z, x, d]), tri_key([z, d, y])] {
                    self.subfacets.insert(t, f);
                    self.dirty_tris.push(t);
                }
                return true;
            }
        }
        false
    }

    /// Splits subfacet `tri` of facet `f` at its circumcentre, or, when that centre lies
    /// outside the facet or encroaches one of the facet's subsegments, splits those
    /// subsegments instead. Returns false when `budget` ran out (before any split or between
    /// two).
    fn split_subfacet(
        &mut self,
        f: u32,
        tri: [u32; 3],
        status: Status,
        budget: &mut usize,
    ) -> Result<bool, MeshError> {
        let what = format!("subfacet {tri:?} of facet {f}");
        let [a, b, c] = tri.map(|v| self.point(v));
        let Some(centre) = tri_circumcenter(a, b, c) else {
            return Err(MeshError::Internal(format!(
                "facet {f}: flat subfacet {tri:?}"
            )));
        };
        let centre = self.snap_to_facet_plane(f, centre);
        let encroached = self.facet_subsegments_encroached_by(f, centre);
        if !encroached.is_empty() {
            for (x, y) in encroached {
                if self.subsegs.contains_key(&(x, y)) {
                    if !spend(budget) {
                        return Ok(false);
                    }
                    let Some(p) = self.split_point_clear_of_frozen(x, y, status) else {
                        frozen_missing(status, &what)?;
                        return Ok(true);
                    };
                    if self.split_removed_first(p, self.dt.vertex_tet(x), Some((x, y)))? {
                        self.dirty_tris.push(tri);
                        return Ok(true);
                    }
                    self.split_subsegment(x, y, p, None)?;
                }
            }
            // The subfacet yielded to the subsegments but is still encroached unless those
            // splits changed it: it is looked at again (nothing else queues it when the
            // subsegments are not its edges).
            self.dirty_tris.push(tri);
            return Ok(true);
        }
        // The centre may still be refused: beyond a subsegment that it does not encroach
        // (possible when a protected subsegment is left encroached), split that subsegment
        // instead; on a vertex of the facet (a cocircular neighbour) or outside through
        // rounding, the subfacet's centroid splits it.
        let fm = &self.facets[f as usize];
        let p = if fm.locate(centre).is_some() && fm.can_insert(centre).is_ok() {
            centre
        } else if let Some([x, y]) = fm.constrained_edge_towards(tri, centre) {
            if !spend(budget) {
                return Ok(false);
            }
            let Some(p) = self.split_point_clear_of_frozen(x, y, status) else {
                frozen_missing(status, &what)?;
                return Ok(true);
            };
            if self.split_removed_first(p, self.dt.vertex_tet(x), Some((x, y)))? {
                self.dirty_tris.push(tri);
                return Ok(true);
            }
            self.split_subsegment(x, y, p, None)?;
            self.dirty_tris.push(tri); // looked at again, as above
            return Ok(true);
        } else {
            (a + b + c) / 3.0
        };
        if !spend(budget) {
            return Ok(false);
        }
        let hint = self.dt.vertex_tet(tri[0]);
        let Some(p) = self.facet_point_clear_of_frozen(f, p, [a, b, c], hint) else {
            frozen_missing(status, &what)?;
            return Ok(true);
        };
        if self.split_removed_first(p, hint, None)? {
            self.dirty_tris.push(tri);
            return Ok(true);
        }
        self.split_in_facet(f, p, hint, None)?;
        Ok(true)
    }

    /// With frozen facets: splits first a subsegment other than `splitting` that a point at
    /// `p` would remove, and says whether it did. Once the point is in, a frozen facet could
    /// keep that subsegment from being split, and then it could not be recovered; now it can
    /// be split (`p` was chosen so, `Domain::may_split_at`).
    pub(super) fn split_removed_first(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
        splitting: Option<(u32, u32)>,
    ) -> Result<bool, MeshError> {
        if !self.any_frozen {
            return Ok(false);
        }
        let crate::delaunay::Probe::Cavity(cavity) = self.dt.probe(p, hint) else {
            return Ok(false);
        };
        let removed = self.subsegments_removed_by(&cavity);
        let Some((x, y)) = removed.into_iter().find(|&k| Some(k) != splitting) else {
            return Ok(false);
        };
        let Some(q) = self.split_point_clear_of_frozen(x, y, Status::Encroached) else {
            return Ok(false);
        };
        self.split_subsegment(x, y, q, None)?;
        Ok(true)
    }

    /// Where to split subsegment ab: `segment_split_point`, or, when that point's insertion
    /// would remove a frozen subfacet (or a subsegment no point could split then), the first
    /// point of ab at 0.4, 0.6, 0.3, 0.7, 0.2 or 0.8 of its length that does not; failing
    /// that, when the element the split is for (`status`) is missing, the first that removes
    /// no frozen subfacet (an encroached one is better left so). None for a frozen subsegment
    /// or when no point will do.
    pub(super) fn split_point_clear_of_frozen(
        &mut self,
        a: u32,
        b: u32,
        status: Status,
    ) -> Option<DVec3> {
        let p = self.split_point_looking(a, b, true);
        match status {
            Status::Missing => p.or_else(|| self.split_point_looking(a, b, false)),
            _ => p,
        }
    }

    /// [`Domain::split_point_clear_of_frozen`], looking at the other subsegments a point would
    /// remove only when `spare_others`.
    pub(super) fn split_point_looking(
        &mut self,
        a: u32,
        b: u32,
        spare_others: bool,
    ) -> Option<DVec3> {
        if self.is_frozen_subsegment(seg_key(a, b)) {
            return None;
        }
        let hint = self.dt.vertex_tet(a);
        let (pa, pb) = (self.point(a), self.point(b));
        let first = self.segment_split_point(a, b);
        let splitting = Some(seg_key(a, b));
        std::iter::once(first)
            .chain([0.4, 0.6, 0.3, 0.7, 0.2, 0.8].map(|t| pa + (pb - pa) * t))
            .find(|&q| self.may_split_looking(q, hint, None, splitting, spare_others))
    }

    /// `p` to split a subfacet with corners `corners` of facet `f`, or, when its insertion
    /// would remove a frozen subfacet, the first of the subfacet's centroid and its points
    /// halfway from there to each corner that the facet takes and that does not.
    fn facet_point_clear_of_frozen(
        &mut self,
        f: u32,
        p: DVec3,
        corners: [DVec3; 3],
        hint: Option<u32>,
    ) -> Option<DVec3> {
        if self.may_split_at(p, hint, None, None) {
            return Some(p);
        }
        let centroid = (corners[0] + corners[1] + corners[2]) / 3.0;
        let mut candidates = vec![centroid];
        candidates.extend(corners.iter().map(|&c| (centroid + c) * 0.5));
        candidates.into_iter().find(|&q| {
            let fm = &self.facets[f as usize];
            fm.locate(q).is_some()
                && fm.can_insert(q).is_ok()
                && self.may_split_at(q, hint, None, None)
        })
    }

    /// Subsegments of facet `f` whose closed diametric ball contains `p` (up to rounding).
    pub fn facet_subsegments_encroached_by(&self, f: u32, p: DVec3) -> Vec<(u32, u32)> {
        let mut out = vec![];
        for [x, y] in self.facets[f as usize].constrained_edges() {
            let (c, r) = diametric_ball(self.point(x), self.point(y));
            // Slightly inflated: a rounded circumcentre meant to lie on the subsegment (the
            // hypotenuse of a right subfacet) must count as encroaching it, or it would be
            // inserted into the facet a rounding error away from the segment.
            if p.distance_squared(c) <= r * r * (1.0 + 1e-9) {
                out.push(seg_key(x, y));
            }
        }
        out.sort_unstable();
        out.dedup();
        out
    }

    /// For an axis-aligned facet, puts the coordinate along its normal back exactly on the
    /// plane (the circumcentre formula rounds it); other facets keep the computed point.
    pub fn snap_to_facet_plane(&self, f: u32, p: DVec3) -> DVec3 {
        let verts: Vec<u32> = self.facets[f as usize].vertices().collect();
        let Some(&v0) = verts.first() else {
            return p;
        };
        let q0 = self.point(v0);
        let mut p = p;
        for axis in 0..3 {
            if verts.iter().all(|&v| self.point(v)[axis] == q0[axis]) {
                p[axis] = q0[axis];
            }
        }
        p
    }
}

/// An element that a frozen facet keeps from being split may stay encroached, but not missing:
/// the boundary would not conform.
fn frozen_missing(status: Status, what: &str) -> Result<(), MeshError> {
    if status == Status::Missing {
        return Err(MeshError::Internal(format!(
            "{what} is missing from the mesh and cannot be split next to a frozen interface"
        )));
    }
    Ok(())
}

/// Spends one split of `budget`; false (nothing spent) when it is spent already.
fn spend(budget: &mut usize) -> bool {
    if *budget == 0 {
        return false;
    }
    *budget -= 1;
    true
}
