//! Keep mode's facet level ([`FacetLevel`] on [`Domain`]): the PLC's subsegments and
//! subfacets, the boundary a cell's refinement point must respect. Its conflict test finds
//! the subsegment or subfacet a point encroaches (in its closed diametric or equatorial ball)
//! or whose protection its cavity would break; its policy refuses splits next to small input
//! angles and splits much smaller than the cell (a cascade); its refinement points are Li's:
//! the point of the subsegment's picking interval or the subfacet's picking disk creating the
//! fewest small slivers. Restoring empty encroachment after a split (the subsegment and
//! subfacet queues) is `recover.rs`.

use super::domain::{seg_key, tri_key, Domain, VertexKind};
use super::levels::{try_candidate, Conflict, FacetLevel, Picker, Request};
use super::outcome::{BoundaryKind, Outcome, Refusal};
use super::recover::{Settled, MAX_RECOVERY_SPLITS};
use crate::delaunay::{tables::FACE, Cavity, Delaunay, INFINITE};
use crate::geom::{diametric_ball, equatorial_ball, tri_circumcenter};
use crate::run::error::MeshError;
use glam::DVec3;
use rand::Rng;

/// A boundary element a point would encroach.
#[derive(Debug, Clone, Copy)]
pub(crate) enum Boundary {
    Segment(u32, u32),
    Facet(u32, [u32; 3]),
}

/// An encroached element much smaller than the cell (radius below this fraction of the
/// cell's circumradius) is not split for it: without small input angles an encroached element
/// has radius >= R / 2 (the paper, section 2.4), and a much smaller one means a cascade of ever
/// smaller splits (an acute angle nearby).
const CASCADE_RADIUS_FRACTION: f64 = 0.25;

impl FacetLevel for Domain {
    type Element = Boundary;

    fn triangulation(&mut self) -> &mut Delaunay {
        &mut self.dt
    }

    fn encroached(&self, cavity: &Cavity) -> Option<Boundary> {
        self.boundary_in_cavity(cavity)
    }

    fn judge(&self, b: Boundary, r: f64, request: Request) -> Conflict<Boundary> {
        if self.is_frozen(b) {
            return Conflict::Refused(Refusal::FrozenInterface);
        }
        let large = self.boundary_radius(b) >= CASCADE_RADIUS_FRACTION * r;
        match request {
            // Splitting the boundary next to a small angle for shape would never end (the
            // paper assumes no small angles).
            Request::ShapeNearSmallAngle => Conflict::Refused(Refusal::NearSmallAngle),
            Request::Shape if self.is_protected(b) => Conflict::Refused(Refusal::NearSmallAngle),
            Request::Shape if large => Conflict::Encroaches(b),
            Request::Shape => Conflict::Refused(self.cascade(b)),
            // For size the element is split even next to a small angle: such splits stop
            // once the elements are a fraction of f, unlike splits for shape.
            Request::SizeNearSmallAngle if large => Conflict::Encroaches(b),
            Request::SizeNearSmallAngle if self.is_protected(b) => {
                Conflict::Refused(Refusal::NearSmallAngle)
            }
            Request::SizeNearSmallAngle => Conflict::Refused(Refusal::CentroidCascade),
        }
    }

    fn refine_encroached(
        &mut self,
        b: Boundary,
        picker: &mut Picker,
    ) -> Result<Outcome, MeshError> {
        self.split_boundary(b, picker)
    }
}

impl Domain {
    /// The conflict test without a policy (`FacetLevel::encroached`): the boundary element
    /// whose protection inserting the probed point would violate. Looks at the cavity and the
    /// ring of tets around it (an equatorial ball can hold p while the (obtuse) tet on its
    /// inner side does not have p in its circumsphere); of the encroached elements it names
    /// the smallest subsegment (by key), else the smallest subfacet.
    fn boundary_in_cavity(&self, cavity: &Cavity) -> Option<Boundary> {
        let dom = self;
        if let Some((f, t)) = dom.frozen_removed_by(cavity) {
            return Some(Boundary::Facet(f, t)); // refused by the policy
        }
        let p = cavity.point();
        let (removed, faces) = dom.dt.cavity(cavity);
        // Every vertex of a cavity tet is on the cavity's boundary, and a ring tet adds one
        // vertex to a boundary face: if no boundary face has a vertex on the domain boundary,
        // no cavity or ring tet has two, so the scan below would find no subsegment or
        // subfacet (and, crossing or not, name none).
        let on_boundary = |v: u32| v == INFINITE || dom.kind[v as usize] != VertexKind::Volume;
        if !faces
            .iter()
            .any(|f| f.vertices().into_iter().any(on_boundary))
        {
            return None;
        }
        let mut scan = BoundaryScan {
            p,
            removed,
            seg: None,
            facet: None,
            any_facet: None,
            crossed: None,
        };
        let mut crosses = false;
        for &t in removed {
            if !dom.dt.is_finite(t) || dom.dt.tag(t) == 0 {
                crosses = true;
                continue;
            }
            scan.tet(dom, t, true);
        }
        // The ring: the tets across the cavity's boundary faces (a tet may come up more than
        // once; the checks are idempotent). One whose face has no boundary vertex has at most
        // one (its apex).
        for f in faces {
            if !f.vertices().into_iter().any(on_boundary) {
                continue;
            }
            let t = f.outer_tet();
            if dom.dt.is_finite(t) && dom.dt.tag(t) != 0 {
                scan.tet(dom, t, false);
            }
        }
        if let Some((a, b)) = scan.seg {
            return Some(Boundary::Segment(a, b));
        }
        // A subsegment the point would remove without encroaching it (one left encroached):
        // split first, as if encroached, since a frozen facet may keep it from being split
        // afterwards.
        if let Some((a, b)) = dom.subsegments_removed_by(cavity).into_iter().min() {
            return Some(Boundary::Segment(a, b));
        }
        if let Some((fi, t)) = scan.facet {
            return Some(Boundary::Facet(fi, t));
        }
        if crosses || scan.crossed.is_some() {
            return scan
                .crossed
                .or_else(|| scan.any_facet.map(|(fi, t)| Boundary::Facet(fi, t)));
        }
        None
    }

    /// Queues the subsegments and subfacets among the edges and faces of tet `t` and its
    /// neighbours.
    pub(super) fn queue_boundary_around(&mut self, t: u32) {
        let mut near = vec![t];
        near.extend(self.dt.neighbors(t));
        for u in near {
            if !self.dt.is_finite(u) {
                continue;
            }
            let v = self.dt.tet(u);
            for i in 0..4 {
                for j in i + 1..4 {
                    let k = seg_key(v[i], v[j]);
                    if self.subsegs.contains_key(&k) {
                        self.dirty_segs.push(k);
                    }
                }
                let f = tri_key(FACE[i].map(|l| v[l]));
                if self.subfacets.contains_key(&f) {
                    self.dirty_tris.push(f);
                }
            }
        }
    }

    /// Whether `b` lies on a frozen facet (see `Domain::frozen`).
    fn is_frozen(&self, b: Boundary) -> bool {
        match b {
            Boundary::Segment(a, c) => self.is_frozen_subsegment(seg_key(a, c)),
            Boundary::Facet(f, _) => self.frozen[f as usize],
        }
    }

    /// Why a split of `b` for a much larger cell is refused: a cascade, next to a small angle
    /// or not.
    fn cascade(&self, b: Boundary) -> Refusal {
        if self
            .boundary_vertices(b)
            .iter()
            .any(|&v| v != u32::MAX && self.influenced_by_acute_angle(v))
        {
            Refusal::CascadeNearSmallAngle
        } else {
            Refusal::Cascade
        }
    }

    /// Whether refinement must not split boundary element `b`: it touches a small input
    /// angle (`Domain::near_small_angle_element`).
    fn is_protected(&self, b: Boundary) -> bool {
        match b {
            Boundary::Segment(a, c) => self.near_small_angle_element(&[a, c]),
            Boundary::Facet(_, t) => self.near_small_angle_element(&t),
        }
    }

    /// The vertices of boundary element `b` (a subsegment's third entry is `u32::MAX`).
    fn boundary_vertices(&self, b: Boundary) -> [u32; 3] {
        match b {
            Boundary::Segment(a, c) => [a, c, u32::MAX],
            Boundary::Facet(_, t) => t,
        }
    }

    fn boundary_radius(&self, b: Boundary) -> f64 {
        match b {
            Boundary::Segment(a, b) => 0.5 * self.point(a).distance(self.point(b)),
            Boundary::Facet(_, t) => {
                let [x, y, z] = t.map(|v| self.point(v));
                equatorial_ball(x, y, z).map_or(0.0, |(_, r)| r)
            }
        }
    }

    /// Splits boundary element `b` from its picking region, then restores empty encroachment
    /// around the new vertex (the subsegment and subfacet queues, `Domain::settle`).
    fn split_boundary(&mut self, b: Boundary, picker: &mut Picker) -> Result<Outcome, MeshError> {
        let split = match b {
            Boundary::Segment(a, c) => match self.split_segment_picked(a, c, picker)? {
                Ok(()) => BoundaryKind::Segment,
                Err(refusal) => return Ok(Outcome::Refused(refusal)),
            },
            Boundary::Facet(f, t) => match self.split_subfacet_picked(f, t, picker)? {
                Ok(kind) => kind,
                Err(refusal) => return Ok(Outcome::Refused(refusal)),
            },
        };
        let mut budget = MAX_RECOVERY_SPLITS;
        Ok(match self.settle(&mut budget)? {
            Settled::Conforming => Outcome::Split(split),
            Settled::BudgetSpent => Outcome::BudgetSpent,
        })
    }

    /// Splits subfacet `t` of facet `f` from its picking disk (its circumcentre first, then
    /// random draws), or the facet's subsegment that centre encroaches. Returns the kind of
    /// element split, or why nothing was.
    fn split_subfacet_picked(
        &mut self,
        f: u32,
        t: [u32; 3],
        picker: &mut Picker,
    ) -> Result<Result<BoundaryKind, Refusal>, MeshError> {
        let [x, y, z] = t.map(|v| self.point(v));
        let Some(cf) = tri_circumcenter(x, y, z) else {
            return Ok(Err(Refusal::FlatSubfacet));
        };
        // The facet's plane snap and subsegment balls, once for the centre and all the draws
        // (the same tests as snap_to_facet_plane and facet_subsegments_encroached_by, which
        // walk the whole facet).
        let (snap, balls) = self.split_cache(f);
        let cf = snap.apply(cf);
        let enc = balls
            .iter()
            .filter(|b| cf.distance_squared(b.centre) <= b.r2)
            .map(|b| b.key)
            .min();
        if let Some((a, c)) = enc {
            return Ok(self
                .split_segment_picked(a, c, picker)?
                .map(|()| BoundaryKind::Segment));
        }
        if self.facets[f as usize].locate_near(cf, t[0]).is_none() {
            return Ok(Err(Refusal::SubfacetCentreOutside));
        }
        let rf = cf.distance(x);
        let n = (y - x).cross(z - x).normalize();
        let u = (y - x).normalize();
        let w = n.cross(u);
        // The centre first (it passed the facet checks above), then random draws.
        let mut best = None;
        let hint = self.dt.vertex_tet(t[0]);
        let centre_ok = try_candidate(self, picker, cf, rf, hint, false, &mut best);
        let tries = if centre_ok { 0 } else { picker.max_tries };
        for _ in 0..tries {
            let (s, th) = (
                picker.rng.gen::<f64>().sqrt(),
                picker.rng.gen::<f64>() * std::f64::consts::TAU,
            );
            let p = cf + (u * th.cos() + w * th.sin()) * (s * picker.delta * rf);
            let p = snap.apply(p);
            if self.facets[f as usize].locate_near(p, t[0]).is_none()
                || balls.iter().any(|b| p.distance_squared(b.centre) <= b.r2)
            {
                continue;
            }
            let hint = self.dt.vertex_tet(t[0]);
            if try_candidate(self, picker, p, rf, hint, false, &mut best) {
                break;
            }
        }
        let (p, cavity) = match best {
            Some(c) => (c.cavity.point(), Some(c.cavity)),
            None => (cf, None),
        };
        let hint = self.dt.vertex_tet(t[0]);
        if !self.may_split_at(p, hint, cavity.as_ref(), None) {
            return Ok(Err(Refusal::FrozenInterface));
        }
        if self.split_removed_first(p, hint, None)? {
            return Ok(Ok(BoundaryKind::Segment));
        }
        self.split_in_facet(f, p, hint, cavity)?;
        Ok(Ok(BoundaryKind::Facet))
    }

    /// Facet `f`'s plane snap and subsegment balls (from its split cache, built now if it was
    /// not: walking the whole facet for every split made keep mode quadratic in a facet's
    /// size).
    fn split_cache(&mut self, f: u32) -> (PlaneSnap, Vec<SubsegmentBall>) {
        if self.split_caches.len() < self.facets.len() {
            self.split_caches.resize_with(self.facets.len(), || None);
        }
        if self.split_caches[f as usize].is_none() {
            let cache = FacetSplitCache {
                snap: PlaneSnap::of(self, f),
                balls: subsegment_balls(self, f),
            };
            self.split_caches[f as usize] = Some(cache);
        }
        let cache = self.split_caches[f as usize]
            .as_ref()
            .map(|c| (c.snap, c.balls.clone()));
        cache.unwrap_or_else(|| (PlaneSnap::of(self, f), subsegment_balls(self, f)))
    }

    /// Splits subsegment ac from its picking interval (midpoint +- delta/2 of its length), or at
    /// the concentric-shell point next to an acute input vertex.
    fn split_segment_picked(
        &mut self,
        a: u32,
        c: u32,
        picker: &mut Picker,
    ) -> Result<Result<(), Refusal>, MeshError> {
        if self.is_frozen_subsegment(seg_key(a, c)) {
            return Ok(Err(Refusal::FrozenInterface));
        }
        let (pa, pc) = (self.point(a), self.point(c));
        let shell = self.acute_vertices.contains(&a) != self.acute_vertices.contains(&c);
        let (p, cavity) = if shell {
            (self.segment_split_point(a, c), None)
        } else {
            let r = 0.5 * pa.distance(pc);
            let mut best = None;
            for _ in 0..picker.max_tries {
                let t = 0.5 + picker.rng.gen_range(-0.5..0.5) * picker.delta;
                let p = pa + (pc - pa) * t;
                let hint = self.dt.vertex_tet(a);
                if try_candidate(self, picker, p, r, hint, false, &mut best) {
                    break;
                }
            }
            match best {
                Some(b) => (b.cavity.point(), Some(b.cavity)),
                None => (pa + (pc - pa) * 0.5, None),
            }
        };
        let hint = self.dt.vertex_tet(a);
        if !self.may_split_at(p, hint, cavity.as_ref(), Some(seg_key(a, c))) {
            return Ok(Err(Refusal::FrozenInterface));
        }
        if self.split_removed_first(p, hint, Some(seg_key(a, c)))? {
            return Ok(Ok(()));
        }
        self.split_subsegment(a, c, p, cavity)?;
        Ok(Ok(()))
    }
}

/// What splitting a facet's subfacets reads of the whole facet: its plane snap and its
/// subsegments' balls. Kept equal to what walking the facet would give: a vertex added to the
/// facet can only unset shared coordinates, and a subsegment split replaces one ball by two.
pub(super) struct FacetSplitCache {
    snap: PlaneSnap,
    balls: Vec<SubsegmentBall>,
}

impl FacetSplitCache {
    /// Vertex `p` was inserted into the facet.
    pub(super) fn add_vertex(&mut self, p: DVec3) {
        self.snap.add(p);
    }

    /// Subsegment ab of the facet was split at vertex `m` (each with its point).
    pub(super) fn split_subsegment(
        &mut self,
        (a, pa): (u32, DVec3),
        (b, pb): (u32, DVec3),
        (m, pm): (u32, DVec3),
    ) {
        self.snap.add(pm);
        self.balls.retain(|ball| ball.key != seg_key(a, b));
        self.balls.push(SubsegmentBall::of(a, pa, m, pm));
        self.balls.push(SubsegmentBall::of(m, pm, b, pb));
    }
}

/// [`Domain::snap_to_facet_plane`] for one facet, its vertices looked at once: the
/// coordinates shared by all of them.
#[derive(Clone, Copy)]
struct PlaneSnap([Option<f64>; 3]);

impl PlaneSnap {
    fn of(dom: &Domain, f: u32) -> PlaneSnap {
        let mut verts = dom.facets[f as usize].vertices();
        let mut axes = [None; 3];
        if let Some(v0) = verts.next() {
            let q0 = dom.point(v0);
            axes = [Some(q0.x), Some(q0.y), Some(q0.z)];
            for v in verts {
                let q = dom.point(v);
                for (axis, a) in axes.iter_mut().enumerate() {
                    if a.is_some_and(|c| q[axis] != c) {
                        *a = None;
                    }
                }
            }
        }
        PlaneSnap(axes)
    }

    /// Point `q` joined the facet's vertices.
    fn add(&mut self, q: DVec3) {
        for (axis, a) in self.0.iter_mut().enumerate() {
            if a.is_some_and(|c| q[axis] != c) {
                *a = None;
            }
        }
    }

    fn apply(&self, mut p: DVec3) -> DVec3 {
        for (axis, a) in self.0.iter().enumerate() {
            if let Some(c) = a {
                p[axis] = *c;
            }
        }
        p
    }
}

/// A subsegment's closed diametric ball, slightly inflated, as
/// [`Domain::facet_subsegments_encroached_by`] tests it.
#[derive(Clone, Copy)]
struct SubsegmentBall {
    key: (u32, u32),
    centre: DVec3,
    r2: f64,
}

impl SubsegmentBall {
    fn of(x: u32, px: DVec3, y: u32, py: DVec3) -> SubsegmentBall {
        let (centre, r) = diametric_ball(px, py);
        SubsegmentBall {
            key: seg_key(x, y),
            centre,
            r2: r * r * (1.0 + 1e-9),
        }
    }
}

/// The balls of facet `f`'s subsegments.
fn subsegment_balls(dom: &Domain, f: u32) -> Vec<SubsegmentBall> {
    dom.facets[f as usize]
        .constrained_edges()
        .into_iter()
        .map(|[x, y]| SubsegmentBall::of(x, dom.point(x), y, dom.point(y)))
        .collect()
}

/// The boundary elements among a cavity's and its ring's edges and faces that a point
/// encroaches or whose protection the cavity would break (see
/// [`Domain::boundary_in_cavity`]).
struct BoundaryScan<'c> {
    p: DVec3,
    /// The cavity tets.
    removed: &'c [u32],
    /// Smallest encroached subsegment.
    seg: Option<(u32, u32)>,
    /// Smallest encroached subfacet.
    facet: Option<(u32, [u32; 3])>,
    /// Smallest subfacet seen.
    any_facet: Option<(u32, [u32; 3])>,
    /// The last subfacet seen with the cavity on both sides.
    crossed: Option<Boundary>,
}

impl BoundaryScan<'_> {
    /// The edges and faces of tet `t` (finite, inside the domain; `in_cavity` if it is a
    /// cavity tet).
    #[inline]
    fn tet(&mut self, dom: &Domain, t: u32, in_cavity: bool) {
        let v = dom.dt.tet(t);
        let kind = v.map(|x| dom.kind[x as usize]);
        let on_boundary = kind.map(|k| k != VertexKind::Volume);
        let n_boundary = on_boundary.iter().filter(|&&b| b).count();
        if n_boundary < 2 {
            return; // no subsegment or subfacet among its edges and faces
        }
        // Subsegments join input and segment vertices only.
        let on_segment = kind.map(|k| matches!(k, VertexKind::Input | VertexKind::Segment(_)));
        for i in 0..4 {
            for j in i + 1..4 {
                if !(on_segment[i] && on_segment[j]) {
                    continue;
                }
                let k = seg_key(v[i], v[j]);
                if self.seg.is_some_and(|s| s <= k) || !dom.subsegs.contains_key(&k) {
                    continue; // (a smaller one is encroached already)
                }
                let (c, r) = diametric_ball(dom.point(k.0), dom.point(k.1));
                if self.p.distance_squared(c) <= r * r {
                    self.seg = Some(k);
                }
            }
            // Face i is opposite vertex i: it holds the other three, which must all lie on
            // the boundary for it to be a subfacet.
            if n_boundary < 3 || (n_boundary == 3 && on_boundary[i]) {
                continue;
            }
            let f = tri_key(FACE[i].map(|l| v[l]));
            let Some(&fi) = dom.subfacets.get(&f) else {
                continue;
            };
            let key = (fi, f);
            if self.any_facet.is_none_or(|a| key < a) {
                self.any_facet = Some(key);
            }
            if in_cavity && self.removed.contains(&dom.dt.neighbors(t)[i]) {
                self.crossed = Some(Boundary::Facet(fi, f));
            }
            if self.seg.is_none() && self.facet.is_none_or(|e| key < e) {
                let [x, y, z] = f.map(|v| dom.point(v));
                if let Some((c, r)) = equatorial_ball(x, y, z) {
                    if self.p.distance_squared(c) <= r * r {
                        self.facet = Some(key);
                    }
                }
            }
        }
    }
}
