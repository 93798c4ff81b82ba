//! Incremental 3D Delaunay tetrahedralization (Bowyer–Watson) over flat arrays.
//!
//! Algorithms: BRIO + Hilbert insertion order ([`hilbert`]); stochastic visibility walk from a
//! hint (`locate`); conflict region ("cavity") grown with the exact in-sphere test and
//! retriangulated as a star from the new point (`cavity`); symbolic perturbation by vertex id
//! for cospherical ties (`geom::insphere_sos`), so grids and other degenerate inputs give one
//! consistent triangulation. The hull is closed by "ghost" tets that carry the vertex at
//! infinity ([`INFINITE`]).
//!
//! Storage: per tet 4 vertex ids and 4 neighbour references (`tet * 4 + face`, `face` = local
//! index of the opposite vertex in the neighbour) plus a one-byte scratch mark: 33 bytes. Deleted
//! slots go to a free list. Limits: fewer than 2^30 tets and 2^32 - 2 vertices; coordinates as
//! accepted by `geom::check_coordinate`.

mod cavity;
pub mod hilbert;
mod locate;
mod parallel;
mod shared;
pub mod tables;
mod validate;

use crate::geom::{self, orient3d};
pub use cavity::{BoundaryFace, Cavity, CavityWatch, DryRun, NoWatch, Probe};
use glam::DVec3;
pub use parallel::{resolve_threads, ParallelReport, MAX_THREADS};
pub use shared::{OwnedCavity, ProbeBuffers, SharedProbe};
use tables::FACE;

/// Id of the vertex at infinity (hull tets carry it).
pub const INFINITE: u32 = u32::MAX;
/// Vertex id stored in all four slots of a deleted tet.
const DEAD: u32 = u32::MAX - 1;
/// "No tet" (a vertex not in the triangulation).
pub const NO_TET: u32 = u32::MAX;

#[derive(Debug, Clone, PartialEq)]
pub enum DelaunayError {
    /// Point `index` has a coordinate the exact predicates cannot handle.
    BadCoordinate {
        index: usize,
        point: DVec3,
        reason: geom::CoordError,
    },
    /// Fewer than four affinely independent points: no tetrahedron exists.
    Degenerate { reason: String },
    /// The triangulation has no tet yet (single insertions need `from_points` first).
    Empty,
}

impl std::fmt::Display for DelaunayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DelaunayError::BadCoordinate {
                index,
                point,
                reason,
            } => write!(
                f,
                "point {index} ({}, {}, {}): {reason}",
                point.x, point.y, point.z
            ),
            DelaunayError::Degenerate { reason } => write!(f, "degenerate input: {reason}"),
            DelaunayError::Empty => write!(f, "the triangulation has no tetrahedron yet"),
        }
    }
}
impl std::error::Error for DelaunayError {}

/// What bulk insertion did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InsertStats {
    /// Points that became vertices.
    pub inserted: usize,
    /// Points equal to an earlier point: skipped (their ids stay unused).
    pub duplicates: usize,
}

/// Result of inserting one point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inserted {
    /// A new vertex with this id.
    New(u32),
    /// The point equals existing vertex `0`; nothing changed.
    Duplicate(u32),
}

/// One tet: 4 vertex ids and 4 neighbour references (`tet * 4 + face`), in one 32-byte
/// block so a conflict test touches a single cache line.
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(32))]
struct Tet {
    v: [u32; 4],
    n: [u32; 4],
}

/// The 3D Delaunay triangulation of a point set.
#[derive(Debug, Clone, Default)]
pub struct Delaunay {
    points: Vec<DVec3>,
    /// One alive tet incident to each vertex, `NO_TET` if the vertex is not inserted.
    vertex_tet: Vec<u32>,
    /// Symbolic-perturbation rank of each vertex: its insertion index (bulk) or its id (later
    /// insertions). Fixed for the vertex's lifetime so every tie is decided the same way.
    rank: Vec<u32>,
    /// Ties broken by the points' coordinates instead of `rank`
    /// (`geom::insphere_tie_by_coordinates`): set for triangulations that must break their
    /// ties as another triangulation of an overlapping point set does (a partition's parts).
    ties_by_coordinates: bool,
    tets: Vec<Tet>,
    /// Scratch flag per tet for cavity searches; zero between calls.
    mark: Vec<u8>,
    free: Vec<u32>,
    /// Optional caller data per tet (e.g. region), inherited by the tets a cavity creates from
    /// the cavity tet on the other side of their outer face; empty unless enabled.
    tags: Vec<u32>,
    tags_enabled: bool,
    n_alive: usize,
    n_ghost: usize,
    n_vertices: usize,
    /// Hint for the next location: the last tet created.
    last: u32,
    rng: u32,
    /// Edit counter, bumped by every change to the tets (so far only `fill_cavity` makes any
    /// after construction; whatever else edits them must bump it too): a [`Cavity`] token
    /// from an earlier generation is stale.
    generation: u64,
    scratch: cavity::Scratch,
    /// The tet slots removed since [`Self::track_removals`] (None: not tracking).
    removals: Option<shared::RemovalLog>,
}

impl Delaunay {
    /// Triangulates `points`; vertex id i is `points[i]` (duplicates are skipped, ids unused).
    /// Inserts in BRIO / Hilbert order.
    pub fn from_points(points: &[DVec3]) -> Result<(Self, InsertStats), DelaunayError> {
        Self::from_points_with(points, false)
    }

    /// [`Self::from_points`], its ties broken by the points' coordinates when
    /// `ties_by_coordinates` (see the field), for its whole life.
    pub fn from_points_with(
        points: &[DVec3],
        ties_by_coordinates: bool,
    ) -> Result<(Self, InsertStats), DelaunayError> {
        for (index, &p) in points.iter().enumerate() {
            geom::check_coordinate(p).map_err(|reason| DelaunayError::BadCoordinate {
                index,
                point: p,
                reason,
            })?;
        }
        // Build over the points in insertion order, so that vertices close in space are close
        // in memory (and the newest point always has the highest rank), then renumber to the
        // caller's ids.
        let order = hilbert::brio_order(points, 0x5eed);
        let mut dt = Delaunay {
            points: order.iter().map(|&i| points[i as usize]).collect(),
            vertex_tet: vec![NO_TET; points.len()],
            rank: (0..points.len() as u32).collect(),
            ties_by_coordinates,
            rng: 0x9e37_79b9,
            ..Default::default()
        };
        // Uniform points give ~6.77 tets per point (24π²/35 for a Poisson process, a little
        // less with the boundary); reserving avoids a doubling peak, and growth beyond is by
        // 1/8 steps (`grow_tets`).
        let expected = points.len() * 68 / 10 + 64;
        dt.tets.reserve(expected);
        dt.mark.reserve(expected);
        let sequence: Vec<u32> = (0..points.len() as u32).collect();
        let first = dt.initial_tet(&sequence)?;
        let mut stats = InsertStats {
            inserted: 4,
            duplicates: 0,
        };
        for id in 0..points.len() as u32 {
            if first.contains(&id) {
                continue;
            }
            let hint = dt.hint_towards(dt.points[id as usize]);
            match dt.insert_vertex(id, hint) {
                Inserted::New(_) => stats.inserted += 1,
                Inserted::Duplicate(_) => stats.duplicates += 1,
            }
        }
        dt.renumber(&order, points);
        Ok((dt, stats))
    }

    /// Inserts one point, locating it from `hint` (a tet id) or from the last insertion.
    /// A duplicate of an existing vertex changes nothing and consumes no id.
    /// It always searches: [`Self::insert_cavity`] saves the search for a probed point.
    pub fn insert(&mut self, p: DVec3, hint: Option<u32>) -> Result<Inserted, DelaunayError> {
        let id = self.push_vertex(p)?;
        let hint = match hint.filter(|&t| self.is_alive(t)) {
            Some(t) => t,
            None => self.hint_towards(p),
        };
        let r = self.insert_vertex(id, hint);
        if let Inserted::Duplicate(_) = r {
            self.points.pop();
            self.vertex_tet.pop();
            self.rank.pop();
        }
        Ok(r)
    }

    /// Appends `p` as the next vertex id (ranked by it), not yet in the triangulation.
    fn push_vertex(&mut self, p: DVec3) -> Result<u32, DelaunayError> {
        if self.n_alive == 0 {
            return Err(DelaunayError::Empty);
        }
        let index = self.points.len();
        geom::check_coordinate(p).map_err(|reason| DelaunayError::BadCoordinate {
            index,
            point: p,
            reason,
        })?;
        self.points.push(p);
        self.vertex_tet.push(NO_TET);
        self.rank.push(index as u32);
        Ok(index as u32)
    }

    /// Number of vertex ids handed out (including skipped duplicates).
    pub fn num_vertex_ids(&self) -> usize {
        self.points.len()
    }
    /// Number of vertices actually in the triangulation.
    pub fn num_vertices(&self) -> usize {
        self.n_vertices
    }
    /// Number of finite (non-hull) tets.
    pub fn num_finite_tets(&self) -> usize {
        self.n_alive - self.n_ghost
    }
    /// Coordinates of vertex `v`.
    pub fn point(&self, v: u32) -> DVec3 {
        self.points[v as usize]
    }
    /// All vertex coordinates, indexed by vertex id.
    pub fn points(&self) -> &[DVec3] {
        &self.points
    }
    /// Whether vertex `v` is in the triangulation (false for skipped duplicates).
    pub fn has_vertex(&self, v: u32) -> bool {
        self.vertex_tet
            .get(v as usize)
            .is_some_and(|&t| t != NO_TET)
    }
    /// An alive tet incident to vertex `v`, if `v` is in the triangulation.
    pub fn vertex_tet(&self, v: u32) -> Option<u32> {
        self.vertex_tet
            .get(v as usize)
            .copied()
            .filter(|&t| t != NO_TET)
    }
    /// Upper bound (exclusive) of tet ids, alive or not.
    pub fn tet_capacity(&self) -> usize {
        self.tets.len()
    }
    pub fn is_alive(&self, t: u32) -> bool {
        self.tets.get(t as usize).is_some_and(|t| t.v[0] != DEAD)
    }
    /// Whether alive tet `t` is finite (carries no infinite vertex).
    pub fn is_finite(&self, t: u32) -> bool {
        !has_infinite(self.tets[t as usize].v)
    }
    /// Vertex ids of tet `t` (positively oriented if finite).
    pub fn tet(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize].v
    }
    /// Neighbour tets of `t`; entry i is across the face opposite vertex i.
    pub fn neighbors(&self, t: u32) -> [u32; 4] {
        self.tets[t as usize].n.map(|r| r >> 2)
    }

    /// The tet across face `i` of tet `t`, and the index the shared face has in it.
    pub fn mirror(&self, t: u32, i: usize) -> (u32, usize) {
        let r = self.tets[t as usize].n[i];
        (r >> 2, (r & 3) as usize)
    }

    /// Corner coordinates of finite tet `t`.
    pub fn tet_points(&self, t: u32) -> [DVec3; 4] {
        self.tets[t as usize].v.map(|v| self.points[v as usize])
    }
    /// Ids of all alive finite tets.
    pub fn finite_tet_ids(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tets.len() as u32).filter(|&t| {
            let v = &self.tets[t as usize].v;
            v[0] != DEAD && !v.contains(&INFINITE)
        })
    }
    /// Positively oriented finite tets as vertex id quadruples.
    pub fn finite_tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        self.finite_tet_ids().map(|t| self.tets[t as usize].v)
    }
    /// Heap bytes held by the triangulation (arrays' capacities).
    pub fn memory_bytes(&self) -> usize {
        use std::mem::size_of;
        self.points.capacity() * size_of::<DVec3>()
            + self.vertex_tet.capacity() * 4
            + self.rank.capacity() * 4
            + self.tets.capacity() * std::mem::size_of::<Tet>()
            + self.mark.capacity()
            + self.free.capacity() * 4
            + self.scratch.memory_bytes()
            + self.removals.as_ref().map_or(0, |log| log.memory_bytes())
    }

    /// Turns on per-tet tags (all zero now); new tets inherit the tag of the cavity tet they
    /// replace across their outer face, so a region label survives insertions that do not
    /// cross region boundaries.
    pub fn enable_tags(&mut self) {
        self.tags = vec![0; self.tets.len()];
        self.tags_enabled = true;
    }
    pub fn tag(&self, t: u32) -> u32 {
        self.tags[t as usize]
    }
    pub fn set_tag(&mut self, t: u32, tag: u32) {
        self.tags[t as usize] = tag;
    }
    /// Vertex quadruples of the tets deleted by the last successful insertion.
    pub fn last_removed(&self) -> &[[u32; 4]] {
        &self.scratch.removed
    }

    /// The ids the tets of [`Self::last_removed`] had, in the same order: the created tets
    /// reuse some of them, so what a caller stored per id for the deleted tets is to be read
    /// before it stores anything for the created ones.
    pub fn last_removed_ids(&self) -> &[u32] {
        &self.scratch.removed_ids
    }

    /// A finite tet whose closure contains `p`, or a hull tet with `p` beyond its hull face.
    pub fn locate_point(&mut self, p: DVec3, hint: Option<u32>) -> u32 {
        let hint = hint.filter(|&t| self.is_alive(t)).unwrap_or(self.last);
        self.locate(p, hint)
    }

    /// Tets created by the last successful insertion (all incident to the new vertex).
    pub fn last_created(&self) -> &[u32] {
        &self.scratch.created
    }

    /// All alive tets incident to vertex `v` (hull tets included).
    pub fn vertex_star(&self, v: u32) -> Vec<u32> {
        // A vertex of a quality mesh has about 20-30 tets around it.
        let mut star = Vec::with_capacity(32);
        self.search_star(v, &mut star, |_| false);
        star
    }

    /// Breadth-first search of the star of vertex `v` (the order [`Self::vertex_star`] lists
    /// it in) for the first tet whose vertices satisfy `hit`; `star` receives the tets visited.
    #[inline]
    fn search_star(
        &self,
        v: u32,
        star: &mut Vec<u32>,
        mut hit: impl FnMut(&[u32; 4]) -> bool,
    ) -> Option<u32> {
        star.clear();
        let start = self.vertex_tet(v)?;
        let mut seen = SmallSet::new();
        seen.insert(start);
        star.push(start);
        let mut k = 0;
        while k < star.len() {
            let t = star[k];
            k += 1;
            let Tet { v: tv, n } = *self.tet_ref(t);
            if hit(&tv) {
                return Some(t);
            }
            for (i, &w) in tv.iter().enumerate() {
                if w == v {
                    continue; // the face opposite v does not contain v
                }
                let m = n[i] >> 2;
                if seen.insert(m) {
                    star.push(m);
                }
            }
        }
        None
    }

    /// A tet having both `a` and `b` as vertices (i.e. edge ab exists), if any.
    pub fn find_edge(&self, a: u32, b: u32) -> Option<u32> {
        self.search_star(a, &mut Vec::with_capacity(64), |v| v.contains(&b))
    }

    /// The tets around edge ab (hull tets included), in rotation order, into `ring`; false
    /// (and `ring` empty) when ab is not an edge. A walk across the faces holding ab: as many
    /// steps as tets around the edge, where collecting them from a's star visits all of it.
    pub fn edge_ring(&self, a: u32, b: u32, ring: &mut Vec<u32>) -> bool {
        ring.clear();
        let Some(start) = self.find_edge(a, b) else {
            return false;
        };
        let (mut t, mut prev) = (start, u32::MAX);
        loop {
            ring.push(t);
            let Tet { v, n } = *self.tet_ref(t);
            // The two faces holding ab are those opposite the other two vertices.
            let next = (0..4)
                .filter(|&i| v[i] != a && v[i] != b)
                .map(|i| n[i] >> 2)
                .find(|&m| m != prev)
                .unwrap_or(prev);
            (prev, t) = (t, next);
            if t == start || ring.len() > self.tets.len() {
                return true;
            }
        }
    }

    /// The tets (one or two) having face abc, with the local index of their fourth vertex.
    pub fn find_face(&self, a: u32, b: u32, c: u32) -> Option<[(u32, usize); 2]> {
        let t = self.search_star(a, &mut Vec::with_capacity(64), |v| {
            v.contains(&b) && v.contains(&c)
        })?;
        let v = self.tets[t as usize].v;
        let i = (0..4)
            .find(|&i| v[i] != a && v[i] != b && v[i] != c)
            .unwrap();
        Some([(t, i), self.mirror(t, i)])
    }

    /// Renames internal vertex `i` to `order[i]` and restores the caller's point order.
    fn renumber(&mut self, order: &[u32], points: &[DVec3]) {
        for tet in self.tets.iter_mut() {
            for v in tet.v.iter_mut() {
                if *v != INFINITE && *v != DEAD {
                    *v = order[*v as usize];
                }
            }
        }
        let mut vertex_tet = vec![NO_TET; points.len()];
        for (i, &t) in self.vertex_tet.iter().enumerate() {
            vertex_tet[order[i] as usize] = t;
        }
        self.vertex_tet = vertex_tet;
        self.rank = vec![0; points.len()];
        for (i, &o) in order.iter().enumerate() {
            self.rank[o as usize] = i as u32;
        }
        self.points.clear();
        self.points.extend_from_slice(points);
    }

    /// Picks four affinely independent points (earliest in `order`), builds their tet and the
    /// four hull tets around it.
    fn initial_tet(&mut self, order: &[u32]) -> Result<[u32; 4], DelaunayError> {
        let p = |i: u32| self.points[i as usize];
        let degenerate = |reason: &str| DelaunayError::Degenerate {
            reason: reason.to_string(),
        };
        let a = *order.first().ok_or_else(|| degenerate("no points"))?;
        let b = *order
            .iter()
            .find(|&&i| p(i) != p(a))
            .ok_or_else(|| degenerate("all points coincide"))?;
        let c = *order
            .iter()
            .find(|&&i| !collinear(p(a), p(b), p(i)))
            .ok_or_else(|| degenerate("all points are collinear"))?;
        let mut d = *order
            .iter()
            .find(|&&i| orient3d(p(a), p(b), p(c), p(i)) != 0.0)
            .ok_or_else(|| degenerate("all points are coplanar"))?;
        let mut a = a;
        if orient3d(p(a), p(b), p(c), p(d)) < 0.0 {
            std::mem::swap(&mut a, &mut d);
            // swapping two vertices flips the orientation
        }
        let tet = [a, b, c, d];
        debug_assert!(orient3d(p(a), p(b), p(c), p(d)) > 0.0);
        let t0 = self.alloc_tet(tet);
        let mut ghosts = [0u32; 4];
        for (i, g) in ghosts.iter_mut().enumerate() {
            let f = FACE[i];
            // The hull face seen from outside is the reversed face: INF lies beyond it.
            *g = self.alloc_tet([tet[f[1]], tet[f[0]], tet[f[2]], INFINITE]);
        }
        let all = [t0, ghosts[0], ghosts[1], ghosts[2], ghosts[3]];
        self.link_by_faces(&all);
        for v in tet {
            self.vertex_tet[v as usize] = t0;
        }
        self.n_vertices = 4;
        self.last = t0;
        Ok(tet)
    }

    /// Links the faces shared among `tets` (a small set; used at initialisation).
    fn link_by_faces(&mut self, tets: &[u32]) {
        let mut faces: Vec<([u32; 3], u32)> = vec![];
        for &t in tets {
            let v = self.tets[t as usize].v;
            for (i, f) in FACE.iter().enumerate() {
                let mut key = [v[f[0]], v[f[1]], v[f[2]]];
                key.sort_unstable();
                faces.push((key, t * 4 + i as u32));
            }
        }
        faces.sort_unstable();
        for pair in faces.chunks(2) {
            assert!(pair.len() == 2 && pair[0].0 == pair[1].0, "unpaired face");
            self.set_neighbor(pair[0].1, pair[1].1);
            self.set_neighbor(pair[1].1, pair[0].1);
        }
    }

    // Unchecked accessors for the hot paths. Invariants: neighbour references of alive tets
    // name existing slots (`tets` never shrinks), and finite vertex ids of alive tets index
    // `points` (checked in debug builds).

    #[inline(always)]
    fn tet_ref(&self, t: u32) -> &Tet {
        debug_assert!((t as usize) < self.tets.len());
        // SAFETY: see the invariants above.
        unsafe { self.tets.get_unchecked(t as usize) }
    }
    #[inline(always)]
    fn tet_mut(&mut self, t: u32) -> &mut Tet {
        debug_assert!((t as usize) < self.tets.len());
        // SAFETY: see the invariants above.
        unsafe { self.tets.get_unchecked_mut(t as usize) }
    }
    /// Coordinates of a finite vertex of an alive tet.
    #[inline(always)]
    fn point_ref(&self, v: u32) -> DVec3 {
        debug_assert!((v as usize) < self.points.len());
        // SAFETY: see the invariants above.
        unsafe { *self.points.get_unchecked(v as usize) }
    }

    #[inline]
    fn set_neighbor(&mut self, from: u32, to: u32) {
        self.tets[(from >> 2) as usize].n[(from & 3) as usize] = to;
    }

    /// Makes room for one more tet slot. Small arrays double (refinement grows a triangulation
    /// from a few tets by single insertions: growing by small steps would copy it many times
    /// over); from `GROW_BY_EIGHTHS` tets on they grow by 1/8 (doubling would nearly double the
    /// peak memory when a big triangulation barely outgrows its reservation).
    #[inline]
    fn grow_tets(&mut self) {
        /// 2^20 tets: 33 MiB of tet records and marks.
        const GROW_BY_EIGHTHS: usize = 1 << 20;
        if self.tets.len() == self.tets.capacity() {
            let len = self.tets.len();
            let extra = if len < GROW_BY_EIGHTHS { len } else { len / 8 } + 1024;
            self.tets.reserve_exact(extra);
            self.mark.reserve_exact(extra);
            if self.tags_enabled {
                self.tags.reserve_exact(extra);
            }
        }
    }

    fn alloc_tet(&mut self, v: [u32; 4]) -> u32 {
        self.n_alive += 1;
        if v.contains(&INFINITE) {
            self.n_ghost += 1;
        }
        if let Some(t) = self.free.pop() {
            self.tets[t as usize].v = v;
            t
        } else {
            self.grow_tets();
            self.tets.push(Tet {
                v,
                n: [u32::MAX; 4],
            });
            self.mark.push(0);
            if self.tags_enabled {
                self.tags.push(0);
            }
            (self.tets.len() - 1) as u32
        }
    }
}

/// The next value of xorshift32 state `x` (nonzero), the walks' random choices.
#[inline(always)]
fn xorshift(x: &mut u32) -> u32 {
    *x ^= *x << 13;
    *x ^= *x >> 17;
    *x ^= *x << 5;
    *x
}

/// A set of tet ids for walking a vertex star: open addressing in a fixed table on the stack
/// (no allocation, no clearing of a big array); beyond its capacity, a heap set.
struct SmallSet {
    table: [u32; SmallSet::SLOTS],
    len: usize,
    overflow: Option<rustc_hash::FxHashSet<u32>>,
}

impl SmallSet {
    const SLOTS: usize = 256;
    /// Entries kept in the table (load factor <= 1/2).
    const MAX_LEN: usize = Self::SLOTS / 2;
    const EMPTY: u32 = u32::MAX;

    #[inline]
    fn new() -> Self {
        SmallSet {
            table: [Self::EMPTY; Self::SLOTS],
            len: 0,
            overflow: None,
        }
    }

    /// Adds `t`; false if it was there already.
    #[inline]
    fn insert(&mut self, t: u32) -> bool {
        debug_assert!(t != Self::EMPTY);
        let mut slot =
            (t.wrapping_mul(0x9E37_79B1) >> (32 - Self::SLOTS.trailing_zeros())) as usize;
        loop {
            let e = self.table[slot];
            if e == t {
                return false;
            }
            if e == Self::EMPTY {
                break;
            }
            slot = (slot + 1) & (Self::SLOTS - 1);
        }
        if self.len < Self::MAX_LEN {
            self.table[slot] = t;
            self.len += 1;
            true
        } else {
            self.overflow.get_or_insert_with(Default::default).insert(t)
        }
    }
}

/// Whether a tet's vertex list holds the infinite vertex (branch-free: `INFINITE` is the
/// largest id, and dead slots never reach here).
#[inline(always)]
fn has_infinite(v: [u32; 4]) -> bool {
    v[0].max(v[1]).max(v[2].max(v[3])) == INFINITE
}

/// Exact collinearity: the three points are collinear iff all three coordinate-plane
/// projections are (exactly) collinear. Each 2D orientation is an exact orient3d with a lifted
/// apex.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    let lift = |p: DVec3, i: usize, j: usize| DVec3::new(p[i], p[j], 0.0);
    [(0, 1), (1, 2), (0, 2)]
        .iter()
        .all(|&(i, j)| orient3d(lift(a, i, j), lift(b, i, j), lift(c, i, j), DVec3::Z) == 0.0)
}

#[cfg(test)]
mod tests;
