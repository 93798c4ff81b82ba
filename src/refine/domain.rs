//! The state shared by boundary recovery and quality refinement: the Delaunay triangulation,
//! the subsegments and each facet's 2D triangulation (its subfacets), and what every vertex
//! lies on.

use super::plc_level::FacetSplitCache;
use crate::cdt::{Change, FacetMesh};
use crate::delaunay::{Cavity, Delaunay, Inserted};
use crate::plc::{Plc, PlcInput};
use crate::run::error::MeshError;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// Where a vertex lies; decides which boundary structures a split must update.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VertexKind {
    /// An input vertex.
    Input,
    /// Inserted on input segment `seg`.
    Segment(u32),
    /// Inserted inside input facet `facet`.
    Facet(u32),
    /// Inserted in the interior of the domain.
    Volume,
}

/// An input segment: an edge of at least one facet polygon.
#[derive(Debug, Clone)]
pub struct Segment {
    pub ends: [u32; 2],
    /// Facets whose polygons use this segment.
    pub facets: Vec<u32>,
}

pub struct Domain {
    pub dt: Delaunay,
    pub kind: Vec<VertexKind>,
    pub segments: Vec<Segment>,
    /// Current subsegments (sorted endpoint pair) -> input segment.
    pub subsegs: FxHashMap<(u32, u32), u32>,
    pub facets: Vec<FacetMesh>,
    pub markers: Vec<i32>,
    /// Current subfacets (sorted vertex triple) -> input facet.
    pub subfacets: FxHashMap<[u32; 3], u32>,
    /// Input vertices where two segments meet at an acute angle (split by concentric shells).
    pub acute_vertices: FxHashSet<u32>,
    /// Input vertices where segments meet at a small angle (< SMALL_ANGLE_DEG).
    pub small_angle_vertices: FxHashSet<u32>,
    /// Input segments (indices into `segments`) between two facets meeting at less than
    /// SMALL_ANGLE_DEG: the whole segment is a small angle.
    pub small_angle_segments: FxHashSet<u32>,
    /// Input facets around a small-angle segment.
    pub small_angle_facets: FxHashSet<u32>,
    /// Per vertex: within the influence of a small input angle (see `near_small_angle`).
    near_small: Vec<bool>,
    /// `Params::small_angle_reach`.
    small_angle_reach: f64,
    /// Protecting balls around the acute input vertices: vertex -> radius. Inside one,
    /// boundary elements are split only when missing from the triangulation, not when merely
    /// encroached (Pav & Walkington's protection): near an acute apex, splits encroach each
    /// other's balls at every scale and would never stop.
    pub protect_radius: FxHashMap<u32, f64>,
    /// Per vertex: the acute input vertex whose protecting ball holds it, or `NO_APEX`.
    pub apex: Vec<u32>,
    /// Per facet: its acute input vertices.
    facet_apexes: Vec<Vec<u32>>,
    /// Subsegments and subfacets to check for encroachment (see `recover::settle`).
    pub dirty_segs: Vec<(u32, u32)>,
    pub dirty_tris: Vec<[u32; 3]>,
    /// Tets created by insertions since the refiner last looked (it classifies them).
    pub created_log: Vec<u32>,
    /// Whether a boundary vertex (segment or facet) was inserted since the refiner last looked:
    /// only then can a cavity have crossed a subfacet (`retag_created`).
    pub boundary_inserted: bool,
    /// Per facet, what splitting its subfacets reads (built when first needed, then kept up
    /// to date by the splits).
    pub(super) split_caches: Vec<Option<FacetSplitCache>>,
    /// Per facet: frozen, never split nor flipped (a partition's interface, meshed alike on
    /// both sides: `crate::partition`). No point is inserted whose cavity would remove one of
    /// its subfacets; being encroached is allowed.
    pub frozen: Vec<bool>,
    /// Whether any facet is frozen.
    pub any_frozen: bool,
}

/// Input angles below this (between segments at a vertex, or between facets at a segment) are
/// "small": refinement does not enforce shape bounds next to them (`near_small_angle`).
/// "Acute" means below 90 degrees and matters only for segments meeting at a vertex: those get
/// a protecting ball and concentric-shell splits (`acute_vertices`); an acute angle that is
/// not small needs nothing more, since refinement terminates around it in practice (Shewchuk).
pub const SMALL_ANGLE_DEG: f64 = 60.0;

/// Protecting-ball radius as a fraction of the distance from an acute vertex to its nearest
/// other input vertex (below one half, so that the balls of two vertices never overlap).
pub const PROTECT_FRACTION: f64 = 0.4;

/// `Domain::apex` of a vertex in no protecting ball.
pub const NO_APEX: u32 = u32::MAX;

pub fn seg_key(a: u32, b: u32) -> (u32, u32) {
    (a.min(b), a.max(b))
}

pub fn tri_key(t: [u32; 3]) -> [u32; 3] {
    let mut k = t;
    k.sort_unstable();
    k
}

impl Domain {
    /// Triangulates the input vertices and sets up the segments (the checked PLC's, in its
    /// numbering) and the facet triangulations.
    pub fn new(input: &PlcInput, plc: &Plc) -> Result<Domain, MeshError> {
        Self::new_with_ties(input, plc, false)
    }

    /// [`Domain::new`], the triangulation breaking its ties by the points' coordinates when
    /// `ties_by_coordinates` (`Delaunay::from_points_with`): a partition's parts and band,
    /// which must have their shared triangles alike.
    pub fn new_with_ties(
        input: &PlcInput,
        plc: &Plc,
        ties_by_coordinates: bool,
    ) -> Result<Domain, MeshError> {
        let (mut dt, stats) = Delaunay::from_points_with(&input.vertices, ties_by_coordinates)
            .map_err(|e| MeshError::InvalidInput(e.to_string()))?;
        if stats.duplicates > 0 {
            return Err(MeshError::InvalidInput(format!(
                "{} duplicate vertices",
                stats.duplicates
            )));
        }
        dt.enable_tags();
        let segments: Vec<Segment> = plc
            .segments
            .iter()
            .map(|s| Segment {
                ends: s.vertices,
                facets: s.facets.clone(),
            })
            .collect();
        let seg_index: FxHashMap<(u32, u32), u32> = (segments.iter().enumerate())
            .map(|(i, s)| (seg_key(s.ends[0], s.ends[1]), i as u32))
            .collect();
        let mut facets = Vec::with_capacity(input.facets.len());
        let mut markers = vec![];
        let mut subfacets = FxHashMap::default();
        for (fi, (f, checked)) in input.facets.iter().zip(&plc.facets).enumerate() {
            // The constraints and their order (which decides cocircular ties) are the input's
            // polygons; which regions of the facet are holes is the validator's decision, its
            // hole loops (from hole polygons and hole points alike), not a rule of our own.
            let holes: Vec<Vec<u32>> = (checked.loops.iter())
                .filter(|l| l.is_hole)
                .map(|l| l.vertices.clone())
                .collect();
            let mut fm = FacetMesh::new(&input.vertices, &f.polygons, &holes, &[])
                .map_err(|e| MeshError::InvalidInput(format!("facet {fi}: {e}")))?;
            fm.expect_area(checked.area);
            for t in fm.triangles() {
                subfacets.insert(tri_key(t), fi as u32);
            }
            facets.push(fm);
            markers.push(f.marker);
        }
        let acute_vertices = acute_vertices_of(&input.vertices, &segments);
        Ok(Domain {
            dt,
            kind: vec![VertexKind::Input; input.vertices.len()],
            protect_radius: FxHashMap::default(),
            apex: vec![NO_APEX; input.vertices.len()],
            facet_apexes: vec![vec![]; input.facets.len()],
            subsegs: seg_index,
            segments,
            facets,
            markers,
            subfacets,
            acute_vertices,
            small_angle_vertices: FxHashSet::default(),
            small_angle_segments: FxHashSet::default(),
            small_angle_facets: FxHashSet::default(),
            near_small: vec![false; input.vertices.len()],
            small_angle_reach: f64::INFINITY,
            dirty_segs: vec![],
            dirty_tris: vec![],
            created_log: vec![],
            boundary_inserted: false,
            split_caches: Vec::new(),
            frozen: vec![false; input.facets.len()],
            any_frozen: false,
        })
    }

    /// Records the small input angles the validator found (see `near_small_angle`) and puts a
    /// protecting ball around every acute input vertex (see `protect_radius`). Not called for
    /// the boundary of an existing mesh, whose angles are not features.
    pub fn set_input_angles(&mut self, plc: &crate::plc::Plc, reach: f64) {
        self.small_angle_reach = reach;
        for &v in &self.acute_vertices {
            let r = PROTECT_FRACTION * nearest_neighbor_distance(&self.dt, v);
            self.protect_radius.insert(v, r);
            self.apex[v as usize] = v;
        }
        self.record_facet_apexes();
        let acute = plc.acute_angles();
        let small: Vec<u32> = (acute.segment_angles.iter())
            .filter(|a| {
                a.degrees < SMALL_ANGLE_DEG
                    && !(a.segments.iter()).any(|&s| self.on_frozen(&self.segments[s]))
            })
            .map(|a| a.vertex)
            .collect();
        self.small_angle_vertices.extend(small);
        // Nor is a dihedral angle with a frozen facet a feature: its triangles are never split,
        // and being encroached is allowed them, so splits next to it cannot cascade.
        self.small_angle_segments.extend(
            (acute.dihedral_angles.iter())
                .filter(|a| {
                    a.degrees < SMALL_ANGLE_DEG
                        && !(a.facets.iter()).any(|&f| self.frozen[f as usize])
                })
                .map(|a| a.segment as u32),
        );
        for &s in &self.small_angle_segments {
            self.small_angle_facets
                .extend(self.segments[s as usize].facets.iter().copied());
        }
        self.mark_near_small_angles();
    }

    /// Lists, per facet, its vertices with a protecting ball.
    fn record_facet_apexes(&mut self) {
        for (f, fm) in self.facets.iter().enumerate() {
            let apexes = &mut self.facet_apexes[f];
            apexes.extend(
                fm.vertices()
                    .filter(|v| self.protect_radius.contains_key(v)),
            );
            apexes.sort_unstable();
        }
    }

    /// Computes `near_small_angle` for every vertex present.
    fn mark_near_small_angles(&mut self) {
        self.near_small = (0..self.kind.len() as u32)
            .map(|v| self.is_near_small_angle(v, self.point(v), self.kind[v as usize]))
            .collect();
    }

    /// See `near_small_angle`; for a vertex `v` at `p` of kind `kind` (its apex already recorded).
    fn is_near_small_angle(&self, v: u32, p: DVec3, kind: VertexKind) -> bool {
        let apex = self.apex[v as usize];
        if apex != NO_APEX && self.small_angle_vertices.contains(&apex) {
            return true;
        }
        // Within reach of a small-angle vertex `e` of the element the vertex lies on.
        let reach = self.small_angle_reach;
        let reaches = |e: &u32| {
            self.small_angle_vertices.contains(e)
                && self
                    .protect_radius
                    .get(e)
                    .is_some_and(|&r| self.point(*e).distance(p) < reach * r)
        };
        match kind {
            VertexKind::Input => self.small_angle_vertices.contains(&v),
            VertexKind::Segment(s) => {
                self.small_angle_segments.contains(&s)
                    || self.segments[s as usize].ends.iter().any(reaches)
            }
            VertexKind::Facet(f) => {
                self.small_angle_facets.contains(&f)
                    || self.facet_apexes[f as usize].iter().any(reaches)
            }
            VertexKind::Volume => false,
        }
    }

    /// Whether vertex `v` is within the influence of a small input angle, where quality
    /// cannot always be enforced without an endless cascade of boundary splits: in the
    /// protecting ball of a vertex where segments meet at a small angle, on a segment between
    /// facets meeting at a small angle or on one of those facets, or on a segment or facet
    /// holding a small-angle vertex and within `Params::small_angle_reach` protecting-ball
    /// radii of it (computed once per vertex, when it is inserted).
    pub fn near_small_angle(&self, v: u32) -> bool {
        self.near_small[v as usize]
    }

    /// Whether tet `verts` is flat by construction: three of its vertices lie on one input
    /// segment, or all four in one input facet. Boundary points are rounded, so the exact
    /// predicates see such a tet with a positive volume, but that volume is rounding noise:
    /// its centroid and circumcentre lie on the boundary to rounding, and a volume vertex
    /// there would encroach the boundary at every scale (a cascade of splits converging on
    /// it, seen on spool.off).
    pub fn flat_by_construction(&self, verts: [u32; 4]) -> bool {
        let on_segment = |v: u32, s: u32| match self.kind[v as usize] {
            VertexKind::Segment(t) => t == s,
            VertexKind::Input => self.segments[s as usize].ends.contains(&v),
            _ => false,
        };
        let in_facet = |v: u32, f: u32| self.facets[f as usize].point(v).is_some();
        for &v in &verts {
            match self.kind[v as usize] {
                VertexKind::Segment(s) => {
                    if verts.iter().filter(|&&w| on_segment(w, s)).count() >= 3 {
                        return true;
                    }
                    let facets = &self.segments[s as usize].facets;
                    if facets
                        .iter()
                        .any(|&f| verts.iter().all(|&w| in_facet(w, f)))
                    {
                        return true;
                    }
                }
                VertexKind::Facet(f) => return verts.iter().all(|&w| in_facet(w, f)),
                VertexKind::Input | VertexKind::Volume => {}
            }
        }
        false
    }

    /// The acute input vertex whose protecting ball holds a new boundary point `p` (the
    /// nearest, if several), or `NO_APEX`. Volume points are never protected.
    fn apex_of(&self, p: DVec3, kind: VertexKind) -> u32 {
        let candidates: &[u32] = match kind {
            VertexKind::Segment(s) => &self.segments[s as usize].ends,
            VertexKind::Facet(f) => &self.facet_apexes[f as usize],
            VertexKind::Input | VertexKind::Volume => &[],
        };
        candidates
            .iter()
            .filter_map(|&v| {
                let r = *self.protect_radius.get(&v)?;
                let d = self.point(v).distance(p);
                (d < r).then_some((d, v))
            })
            .min_by(|x, y| x.0.total_cmp(&y.0))
            .map_or(NO_APEX, |(_, v)| v)
    }

    /// Whether vertex `v` is within the influence of an acute input angle: next to a small
    /// one (`near_small_angle`) or in the protecting ball of an acute input vertex, where boundary
    /// elements may stay encroached.
    pub fn influenced_by_acute_angle(&self, v: u32) -> bool {
        self.near_small_angle(v) || self.apex[v as usize] != NO_APEX
    }

    /// Whether the boundary element with vertices `verts` is exempt from splitting for
    /// encroachment alone during boundary recovery: all of them lie in one protecting ball
    /// (see `protect_radius`), or it is near a small angle (`near_small_angle_element`).
    pub fn protected(&self, verts: &[u32]) -> bool {
        let a = self.apex[verts[0] as usize];
        (a != NO_APEX && verts.iter().all(|&v| self.apex[v as usize] == a))
            || self.near_small_angle_element(verts)
    }

    /// Whether a boundary element with vertices `verts` touches a feature with a small angle,
    /// where quality is not enforced and splits would encroach each other without end.
    pub fn near_small_angle_element(&self, verts: &[u32]) -> bool {
        verts.iter().any(|&v| self.near_small_angle(v))
    }

    pub fn point(&self, v: u32) -> DVec3 {
        self.dt.point(v)
    }

    /// Freezes `facets` (see [`Domain::frozen`]). Segments of frozen facets only are never
    /// split, so the angles between them are no features: they make no acute vertex (nor, in
    /// `set_input_angles`, a small angle).
    pub fn freeze_facets(&mut self, facets: &[u32]) {
        for &f in facets {
            self.frozen[f as usize] = true;
        }
        self.any_frozen |= !facets.is_empty();
        if self.any_frozen {
            let open: Vec<Segment> = (self.segments.iter())
                .filter(|s| !self.frozen_only(s))
                .cloned()
                .collect();
            self.acute_vertices = acute_vertices_of(self.dt.points(), &open);
        }
    }

    /// Whether a facet of segment `s` is frozen (it is never split then).
    fn on_frozen(&self, s: &Segment) -> bool {
        self.any_frozen && s.facets.iter().any(|&f| self.frozen[f as usize])
    }

    /// Whether every facet of segment `s` is frozen.
    fn frozen_only(&self, s: &Segment) -> bool {
        self.any_frozen && s.facets.iter().all(|&f| self.frozen[f as usize])
    }

    /// Whether the subfacet with sorted vertices `key` is one of a frozen facet.
    pub fn is_frozen_subfacet(&self, key: &[u32; 3]) -> bool {
        self.any_frozen
            && self
                .subfacets
                .get(key)
                .is_some_and(|&f| self.frozen[f as usize])
    }

    /// Whether subsegment `key` lies on a frozen facet's polygon.
    pub fn is_frozen_subsegment(&self, key: (u32, u32)) -> bool {
        self.any_frozen
            && self.subsegs.get(&key).is_some_and(|&s| {
                (self.segments[s as usize].facets.iter()).any(|&f| self.frozen[f as usize])
            })
    }

    /// A frozen subfacet that inserting `cavity`'s point would remove (both its tets in the
    /// cavity), as (facet, sorted vertices). A frozen subsegment cannot go without one of its
    /// frozen subfacets.
    pub fn frozen_removed_by(&self, cavity: &Cavity) -> Option<(u32, [u32; 3])> {
        if !self.any_frozen {
            return None;
        }
        let (removed, _) = self.dt.cavity(cavity);
        let on_boundary =
            |x: u32| x != crate::delaunay::INFINITE && self.kind[x as usize] != VertexKind::Volume;
        for &t in removed {
            let v = self.dt.tet(t);
            let boundary = v.map(on_boundary);
            if boundary.iter().filter(|&&b| b).count() < 3 {
                continue; // no face on the boundary (most cavity tets)
            }
            let neighbors = self.dt.neighbors(t);
            for (i, n) in neighbors.into_iter().enumerate() {
                let f = crate::delaunay::tables::FACE[i];
                if n < t || !f.iter().all(|&l| boundary[l]) || !removed.contains(&n) {
                    continue; // each inner boundary face once
                }
                let face = tri_key(f.map(|l| v[l]));
                if let Some(&f) = self.subfacets.get(&face) {
                    if self.frozen[f as usize] {
                        return Some((f, face));
                    }
                }
            }
        }
        None
    }

    /// With frozen facets, the subsegments that inserting `cavity`'s point would remove (every
    /// tet around them in the cavity). A frozen facet may keep such a subsegment from being
    /// split, and then it could not be recovered; without frozen facets none is looked for.
    pub fn subsegments_removed_by(&self, cavity: &Cavity) -> Vec<(u32, u32)> {
        let mut out = vec![];
        if !self.any_frozen {
            return out;
        }
        let (removed, _) = self.dt.cavity(cavity);
        let on_segment = |x: u32| {
            x != crate::delaunay::INFINITE
                && matches!(
                    self.kind[x as usize],
                    VertexKind::Input | VertexKind::Segment(_)
                )
        };
        let mut ring = vec![];
        for &t in removed {
            let v = self.dt.tet(t);
            let on = v.map(on_segment);
            for i in 0..4 {
                for j in i + 1..4 {
                    let key = seg_key(v[i], v[j]);
                    if on[i]
                        && on[j]
                        && self.subsegs.contains_key(&key)
                        && !out.contains(&key)
                        && self.dt.edge_ring(key.0, key.1, &mut ring)
                        && ring.iter().all(|r| removed.contains(r))
                    {
                        out.push(key);
                    }
                }
            }
        }
        out
    }

    /// Whether a point that splits a boundary element (the subsegment `splitting`, if it is
    /// one) may go at `p`: its cavity (`probed` when that is a current probe of `p`, else
    /// probed from `hint`) removes no frozen subfacet, nor, when `spare_others`, another
    /// subsegment that no point could split then (`split_point_clear_of_frozen`, not looking
    /// further): that one could not be recovered. A duplicate may not go.
    pub fn may_split_at(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
        probed: Option<&Cavity>,
        splitting: Option<(u32, u32)>,
    ) -> bool {
        self.may_split_looking(p, hint, probed, splitting, true)
    }

    /// [`Domain::may_split_at`], looking at the other subsegments the point would remove only
    /// when `spare_others` (a split point for one of those is not looked at further).
    pub(super) fn may_split_looking(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
        probed: Option<&Cavity>,
        splitting: Option<(u32, u32)>,
        spare_others: bool,
    ) -> bool {
        if !self.any_frozen {
            return true;
        }
        let probe;
        let cavity = match probed {
            Some(c) if c.point() == p && self.dt.is_current(c) => c,
            _ => match self.dt.probe(p, hint) {
                crate::delaunay::Probe::Cavity(c) => {
                    probe = c;
                    &probe
                }
                crate::delaunay::Probe::Duplicate(_) => return false,
            },
        };
        if self.frozen_removed_by(cavity).is_some() {
            return false;
        }
        if !spare_others {
            return true;
        }
        let others: Vec<(u32, u32)> = (self.subsegments_removed_by(cavity).into_iter())
            .filter(|&k| Some(k) != splitting)
            .collect();
        others
            .into_iter()
            .all(|(a, b)| self.split_point_looking(a, b, false).is_some())
    }

    /// Checks that every frozen subfacet is a face of the triangulation.
    pub fn check_frozen_present(&self) -> Result<(), MeshError> {
        if !self.any_frozen {
            return Ok(());
        }
        for (key, &f) in &self.subfacets {
            if self.frozen[f as usize] && self.dt.find_face(key[0], key[1], key[2]).is_none() {
                return Err(MeshError::Internal(format!(
                    "frozen facet {f}: triangle {key:?} is no longer a face of the mesh"
                )));
            }
        }
        Ok(())
    }

    /// Inserts a new vertex into the 3D triangulation, located from `hint`, or with
    /// `probed`'s cavity when that is a current probe of `p`.
    pub fn insert_point(
        &mut self,
        p: DVec3,
        kind: VertexKind,
        hint: Option<u32>,
        probed: Option<Cavity>,
    ) -> Result<u32, MeshError> {
        let inserted = match probed {
            Some(c) if c.point() == p && self.dt.is_current(&c) => self.dt.insert_cavity(c),
            _ => self.dt.insert(p, hint),
        };
        match inserted {
            Ok(Inserted::New(id)) => {
                let apex = self.apex_of(p, kind);
                self.kind.push(kind);
                self.apex.push(apex);
                let near = self.is_near_small_angle(id, p, kind);
                self.near_small.push(near);
                self.queue_around_last_insertion();
                self.created_log.extend_from_slice(self.dt.last_created());
                self.boundary_inserted |= kind != VertexKind::Volume;
                Ok(id)
            }
            Ok(Inserted::Duplicate(v)) => Err(MeshError::Internal(format!(
                "new {kind:?} point ({}, {}, {}) coincides with vertex {v} ({:?})",
                p.x, p.y, p.z, self.kind[v as usize]
            ))),
            Err(e) => Err(MeshError::Internal(e.to_string())),
        }
    }

    fn apply_change(&mut self, facet: u32, change: &Change) {
        for t in &change.removed {
            self.subfacets.remove(&tri_key(*t));
        }
        for t in &change.added {
            self.subfacets.insert(tri_key(*t), facet);
            self.dirty_tris.push(tri_key(*t));
        }
    }

    /// Where to split subsegment ab: its midpoint, or, next to an acute input vertex, the
    /// point at a power-of-two distance from it closest to the midpoint (concentric shells,
    /// Shewchuk 2002) so that splits around the apex stop encroaching each other.
    pub fn segment_split_point(&self, a: u32, b: u32) -> DVec3 {
        let (pa, pb) = (self.point(a), self.point(b));
        let apex = match (
            self.acute_vertices.contains(&a),
            self.acute_vertices.contains(&b),
        ) {
            (true, false) => Some((pa, pb)),
            (false, true) => Some((pb, pa)),
            _ => None,
        };
        let Some((o, q)) = apex else {
            return pa + (pb - pa) * 0.5;
        };
        let len = o.distance(q);
        let shell = 2f64.powf((len * 0.5).log2().round());
        let t = (shell / len).clamp(0.25, 0.75);
        o + (q - o) * t
    }

    /// Splits subsegment ab at `p` (`probed`: its probe, see [`Self::insert_point`]): inserts
    /// the vertex and updates subsegments and every facet holding the segment. Returns the new
    /// vertex.
    pub fn split_subsegment(
        &mut self,
        a: u32,
        b: u32,
        p: DVec3,
        probed: Option<Cavity>,
    ) -> Result<u32, MeshError> {
        let key = seg_key(a, b);
        let seg = *self
            .subsegs
            .get(&key)
            .ok_or_else(|| MeshError::Internal(format!("({a}, {b}) is not a subsegment")))?;
        let p = self.splittable_point(seg, a, b, p);
        let hint = self.dt.vertex_tet(a);
        // `p` may have moved: then `probed` is not of it.
        let id = self.insert_point(p, VertexKind::Segment(seg), hint, probed)?;
        self.subsegs.remove(&key);
        for half in [seg_key(a, id), seg_key(id, b)] {
            self.subsegs.insert(half, seg);
            self.dirty_segs.push(half);
        }
        for f in self.segments[seg as usize].facets.clone() {
            let change = self.facets[f as usize]
                .split_edge(a, b, id, p)
                .map_err(|e| MeshError::Internal(format!("facet {f}: {e}")))?;
            self.apply_change(f, &change);
            let (pa, pb) = (self.point(a), self.point(b));
            if let Some(cache) = self.split_cache_mut(f) {
                cache.split_subsegment((a, pa), (b, pb), (id, p));
            }
        }
        Ok(id)
    }

    /// A float split point is a rounding error off its segment; next to a facet triangle whose
    /// apex is nearly on the segment that error can flip the triangle's orientation. Returns
    /// `p` if no facet of segment `seg` would see a flipped triangle, else a nearby point on
    /// ab that none does (or `p` when none is found; the facet then reports the problem).
    fn splittable_point(&self, seg: u32, a: u32, b: u32, p: DVec3) -> DVec3 {
        let (pa, pb) = (self.point(a), self.point(b));
        let ok = |q: DVec3| {
            self.segments[seg as usize]
                .facets
                .iter()
                .all(|&f| self.facets[f as usize].can_split(a, b, q))
        };
        if ok(p) {
            return p;
        }
        let len2 = pa.distance_squared(pb);
        let t0 = (p - pa).dot(pb - pa) / len2;
        for k in 1..=32 {
            let dt = 0.004 * k as f64 * if k % 2 == 0 { 1.0 } else { -1.0 };
            let q = pa + (pb - pa) * (t0 + dt).clamp(0.05, 0.95);
            if ok(q) {
                return q;
            }
        }
        p
    }

    /// Inserts `p` (inside facet `f`) into the 3D triangulation and the facet's triangulation
    /// (`probed`: its probe, see [`Self::insert_point`]).
    pub fn split_in_facet(
        &mut self,
        f: u32,
        p: DVec3,
        hint: Option<u32>,
        probed: Option<Cavity>,
    ) -> Result<u32, MeshError> {
        // Checked before the 3D insertion so that a refusal leaves both triangulations as
        // they were.
        self.facets[f as usize].can_insert(p).map_err(|e| {
            MeshError::Internal(format!(
                "facet {f}: point ({}, {}, {}) refused: {e:?}",
                p.x, p.y, p.z
            ))
        })?;
        let id = self.insert_point(p, VertexKind::Facet(f), hint, probed)?;
        let change = self.facets[f as usize].insert(id, p).map_err(|e| {
            MeshError::Internal(format!(
                "facet {f}: point ({}, {}, {}) not inserted: {e:?}",
                p.x, p.y, p.z
            ))
        })?;
        self.apply_change(f, &change);
        if let Some(cache) = self.split_cache_mut(f) {
            cache.add_vertex(p);
        }
        Ok(id)
    }

    /// Facet `f`'s split cache, if it was built.
    fn split_cache_mut(&mut self, f: u32) -> Option<&mut FacetSplitCache> {
        self.split_caches.get_mut(f as usize)?.as_mut()
    }
}

/// Distance from vertex `v` to its nearest neighbour (one of its Delaunay neighbours).
fn nearest_neighbor_distance(dt: &Delaunay, v: u32) -> f64 {
    let p = dt.point(v);
    dt.vertex_star(v)
        .into_iter()
        .flat_map(|t| dt.tet(t))
        .filter(|&w| w != v && w != crate::delaunay::INFINITE)
        .map(|w| dt.point(w).distance(p))
        .fold(f64::INFINITY, f64::min)
}

/// Input vertices where two segments meet at less than 90 degrees.
fn acute_vertices_of(points: &[DVec3], segments: &[Segment]) -> FxHashSet<u32> {
    let mut around: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for s in segments {
        around.entry(s.ends[0]).or_default().push(s.ends[1]);
        around.entry(s.ends[1]).or_default().push(s.ends[0]);
    }
    let mut acute = FxHashSet::default();
    for (&v, others) in &around {
        let o = points[v as usize];
        'pairs: for i in 0..others.len() {
            for j in i + 1..others.len() {
                let d1 = points[others[i] as usize] - o;
                let d2 = points[others[j] as usize] - o;
                if d1.dot(d2) > 1e-12 * d1.length() * d2.length() {
                    acute.insert(v);
                    break 'pairs;
                }
            }
        }
    }
    acute
}
