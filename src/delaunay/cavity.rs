//! The conflict region ("cavity") of a point and its star retriangulation (Bowyer–Watson).
//!
//! A finite tet conflicts with p when p is inside its circumsphere (perturbed in-sphere, so
//! ties never happen); a hull tet conflicts when p is strictly outside its hull face or, when
//! p lies on the hull face's plane, exactly when the finite tet behind that face conflicts
//! (the sphere meets the plane in the face's circumcircle). The cavity is the connected set of
//! conflicting tets around the tet containing p; its boundary is star-shaped from p.

use super::tables::FACE;
use super::{has_infinite, Delaunay, DelaunayError, Inserted, Tet, DEAD, INFINITE};
use crate::geom::{insphere, insphere_tie, insphere_tie_by_coordinates, orient3d, InsphereFan};
use glam::DVec3;

/// Reusable buffers for cavity searches.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// The last search's cavity and boundary.
    pub(super) search: SearchBuffers,
    /// Tets created by the last insertion.
    pub(super) created: Vec<u32>,
    /// Vertices of the tets the last insertion deleted.
    pub(super) removed: Vec<[u32; 4]>,
    /// The ids those tets had, in the same order (the created tets reuse some of them).
    pub(super) removed_ids: Vec<u32>,
    /// Tags of the boundary faces' owners (when tags are enabled).
    tags: Vec<u32>,
    /// Directed boundary edge -> face reference of the new tet that owns it.
    edges: EdgeTable,
    /// The point whose probe ([`Delaunay::probe`]) filled `cavity` and `boundary`; cleared by
    /// any other search or edit. Only a [`Cavity`] token for this point (and the current
    /// generation) reads or inserts them.
    probed: Option<DVec3>,
    /// A copy of one probed cavity, kept while other points are probed ([`Delaunay::keep`]).
    kept: KeptCavity,
}

/// See [`Delaunay::keep`].
#[derive(Debug, Clone, Default)]
struct KeptCavity {
    /// The probed point and the generation of the probe (None: nothing kept).
    of: Option<(DVec3, u64)>,
    cavity: Vec<u32>,
    boundary: Vec<BoundaryFace>,
}

impl Scratch {
    pub(super) fn memory_bytes(&self) -> usize {
        self.search.memory_bytes()
            + self.created.capacity() * 4
            + self.removed.capacity() * 16
            + self.removed_ids.capacity() * 4
            + self.tags.capacity() * 4
            + self.edges.memory_bytes()
            + self.kept.cavity.capacity() * 4
            + self.kept.boundary.capacity() * std::mem::size_of::<BoundaryFace>()
    }
}

/// The lists a cavity search fills.
#[derive(Debug, Clone, Default)]
pub(super) struct SearchBuffers {
    /// Tets in conflict.
    pub(super) cavity: Vec<u32>,
    /// For each cavity tet, the local index of the face it was reached through (4: start).
    entry: Vec<u8>,
    /// Cavity boundary faces.
    pub(super) boundary: Vec<BoundaryFace>,
}

impl SearchBuffers {
    pub(super) fn memory_bytes(&self) -> usize {
        self.cavity.capacity() * 4
            + self.entry.capacity()
            + self.boundary.capacity() * std::mem::size_of::<BoundaryFace>()
    }
}

/// Where a cavity search records the tets it visited ([`INSIDE`], [`OUTSIDE`], 0: not
/// visited): the triangulation's mark array, or a search's own table when several search at
/// once (`shared.rs`).
pub(super) trait Marks {
    fn get(&self, t: u32) -> u8;
    fn set(&mut self, t: u32, m: u8);
    /// Hints tet `t`'s mark into the cache.
    fn prefetch(&self, t: u32);
    /// Sets every mark back to zero after a search that visited the tets of `cavity` and
    /// those across `boundary` (a stopped one marked only tets in these lists too).
    fn clear(&mut self, cavity: &[u32], boundary: &[BoundaryFace]);
}

/// The triangulation's one-byte mark per tet slot.
pub(super) struct ArrayMarks<'a>(pub(super) &'a mut [u8]);

impl Marks for ArrayMarks<'_> {
    #[inline(always)]
    fn get(&self, t: u32) -> u8 {
        debug_assert!((t as usize) < self.0.len());
        // SAFETY: one mark per tet slot, and searches only reach tet slots.
        unsafe { *self.0.get_unchecked(t as usize) }
    }
    #[inline(always)]
    fn set(&mut self, t: u32, m: u8) {
        debug_assert!((t as usize) < self.0.len());
        // SAFETY: as in `get`.
        unsafe { *self.0.get_unchecked_mut(t as usize) = m }
    }
    #[inline(always)]
    fn prefetch(&self, t: u32) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults and reads nothing; the pointer arithmetic wraps.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            _mm_prefetch(
                self.0.as_ptr().wrapping_add(t as usize) as *const i8,
                _MM_HINT_T0,
            );
        }
    }
    #[inline]
    fn clear(&mut self, cavity: &[u32], boundary: &[BoundaryFace]) {
        for &t in cavity {
            self.set(t, 0);
        }
        for f in boundary {
            self.set(f.outer >> 2, 0);
        }
    }
}

/// A face of the cavity boundary, copied out of the cavity tet that owns it (so the slot can
/// be reused): its vertices as seen from inside the cavity (`FACE` order of the owner), the
/// reference to the outer neighbour's face, and the owner.
#[derive(Debug, Clone, Copy, Default)]
pub struct BoundaryFace {
    pub(super) v: [u32; 3],
    pub(super) outer: u32,
    pub(super) owner: u32,
}

impl BoundaryFace {
    /// The face's vertices, positively oriented with the new point: the tet `(a, b, c, p)` is
    /// the one inserting p creates on it (a face holding `INFINITE` makes a hull tet).
    #[inline]
    pub fn vertices(&self) -> [u32; 3] {
        self.v
    }
    /// The tet outside the cavity across this face (it survives the insertion).
    #[inline]
    pub fn outer_tet(&self) -> u32 {
        self.outer >> 2
    }
    /// The cavity tet this face belongs to.
    #[inline]
    pub fn owner(&self) -> u32 {
        self.owner
    }
}

/// What a probe found (see [`Delaunay::probe`]).
#[derive(Debug)]
pub enum Probe {
    /// The point equals this vertex.
    Duplicate(u32),
    /// The point's cavity: read it with [`Delaunay::cavity`], insert the point with
    /// [`Delaunay::insert_cavity`].
    Cavity(Cavity),
}

/// A claim on the cavity a probe computed (held in the triangulation's one set of buffers):
/// current until the triangulation changes or a different point is probed, either of which
/// overwrites them ([`Delaunay::is_current`]). Neither `Clone` nor `Copy`: inserting consumes
/// it.
#[derive(Debug)]
pub struct Cavity {
    p: DVec3,
    /// The probe's hint, for locating `p` afresh once the token is stale.
    hint: Option<u32>,
    /// [`Delaunay`]'s edit counter at the probe.
    generation: u64,
}

impl Cavity {
    /// The probed point.
    #[inline]
    pub fn point(&self) -> DVec3 {
        self.p
    }
}

/// Sees a cavity's boundary faces while the search finds them, and may stop it (a refinement
/// point's small slivers are counted so, and a hopeless candidate is left half-searched).
pub trait CavityWatch {
    /// Whether the search shows this watch anything (false: the calls compile away).
    const WATCHES: bool = true;

    /// While the search runs, boundary faces come in multiples of this many (the rest at its
    /// end).
    const BATCH: usize;

    /// Boundary faces found since the last call, with the triangulation's points (a face with
    /// `INFINITE` makes a hull tet); false stops the search.
    fn faces(&mut self, faces: &[BoundaryFace], points: &[DVec3]) -> bool;
}

/// The watch of a plain search: sees nothing, never stops it.
pub struct NoWatch;

impl CavityWatch for NoWatch {
    const WATCHES: bool = false;
    const BATCH: usize = 1;

    #[inline(always)]
    fn faces(&mut self, _: &[BoundaryFace], _: &[DVec3]) -> bool {
        true
    }
}

/// Cavity search marks (zero: not visited).
pub(super) const INSIDE: u8 = 1;
pub(super) const OUTSIDE: u8 = 2;
const _: () = assert!(OUTSIDE - 1 == INSIDE);

/// What inserting a point would do, computed without changing the triangulation.
#[derive(Debug, Clone, PartialEq)]
pub enum DryRun {
    /// The point equals this vertex.
    Duplicate(u32),
    /// Inserting the point would delete `removed` tets and create one tet `(a, b, c, p)` per
    /// face `[a, b, c]` (positively oriented; a face holding `INFINITE` makes a hull tet).
    Cavity {
        removed: Vec<u32>,
        faces: Vec<[u32; 3]>,
    },
}

impl Delaunay {
    /// Inserts vertex `id` (its coordinates already stored), locating from tet `hint`.
    pub(super) fn insert_vertex(&mut self, id: u32, hint: u32) -> Inserted {
        let p = self.points[id as usize];
        let rank = self.rank[id as usize];
        let start = self.locate(p, hint);
        if let Some(dup) = self.coincident_vertex(start, p) {
            return Inserted::Duplicate(dup);
        }
        self.find_cavity(p, rank, start, &mut NoWatch);
        self.fill_cavity(id);
        self.n_vertices += 1;
        Inserted::New(id)
    }

    /// The tets a new point at `p` would remove and the faces it would connect to, without
    /// changing the triangulation. `hint` is a tet to start the walk from (any alive tet).
    /// Allocates; [`Self::probe`] and [`Self::cavity`] do the same in place.
    pub fn dry_run(&mut self, p: DVec3, hint: Option<u32>) -> DryRun {
        match self.probe(p, hint) {
            Probe::Duplicate(v) => DryRun::Duplicate(v),
            Probe::Cavity(c) => {
                let (removed, faces) = self.cavity(&c);
                DryRun::Cavity {
                    removed: removed.to_vec(),
                    faces: faces.iter().map(|f| f.v).collect(),
                }
            }
        }
    }

    /// Computes the cavity a new point at `p` would have, without changing the triangulation
    /// (refinement tests candidate points with this). `hint` is a tet to start the walk from
    /// (any alive tet). The cavity goes into the triangulation's one set of buffers, so a
    /// probe makes every earlier token stale unless it is of the same point.
    pub fn probe(&mut self, p: DVec3, hint: Option<u32>) -> Probe {
        match self.start_probe(p, hint) {
            Err(dup) => Probe::Duplicate(dup),
            Ok(start) => {
                // The would-be vertex ranks above every existing one, as a real insertion
                // would.
                self.find_cavity(p, self.points.len() as u32, start, &mut NoWatch);
                self.probed(p, hint)
            }
        }
    }

    /// [`Self::probe`], showing `watch` the cavity's boundary faces as the search finds them:
    /// None when `watch` stopped the search (the buffers then hold no cavity).
    pub fn probe_watched(
        &mut self,
        p: DVec3,
        hint: Option<u32>,
        watch: &mut impl CavityWatch,
    ) -> Option<Probe> {
        match self.start_probe(p, hint) {
            Err(dup) => Some(Probe::Duplicate(dup)),
            Ok(start) => self
                .find_cavity(p, self.points.len() as u32, start, watch)
                .then(|| self.probed(p, hint)),
        }
    }

    /// Locates `p` from `hint` for a probe: the tet the search starts from, or the vertex at p.
    fn start_probe(&mut self, p: DVec3, hint: Option<u32>) -> Result<u32, u32> {
        let start = hint.filter(|&t| self.is_alive(t)).unwrap_or(self.last);
        let start = self.locate(p, start);
        match self.coincident_vertex(start, p) {
            Some(dup) => {
                self.scratch.probed = None;
                Err(dup)
            }
            None => Ok(start),
        }
    }

    /// The token of the cavity of `p` the buffers now hold.
    fn probed(&mut self, p: DVec3, hint: Option<u32>) -> Probe {
        self.scratch.probed = Some(p);
        Probe::Cavity(Cavity {
            p,
            hint,
            generation: self.generation,
        })
    }

    /// Keeps a copy of `cavity`'s cavity (when its token is current) for
    /// [`Self::insert_cavity`] to use after other probes, if nothing is edited in between: one
    /// candidate kept while others are tried is inserted without a new search. (The copy
    /// replaces the one kept before.) Only a probe from a hint is kept: the search the
    /// insertion would make afresh starts at the same (alive) tet and finds the same cavity in
    /// the same order, so the copy changes the work and nothing else.
    pub fn keep(&mut self, cavity: &Cavity) {
        if cavity.hint.is_some() && self.is_current(cavity) {
            let s = &mut self.scratch;
            s.kept.of = Some((cavity.p, cavity.generation));
            s.kept.cavity.clone_from(&s.search.cavity);
            s.kept.boundary.clone_from(&s.search.boundary);
        }
    }

    /// Whether the buffers still hold `cavity`'s cavity: no edit since its probe, and the last
    /// probe was of the same point.
    #[inline]
    pub fn is_current(&self, cavity: &Cavity) -> bool {
        self.generation == cavity.generation && self.scratch.probed == Some(cavity.p)
    }

    /// The probed cavity: the tets inserting the point would delete, and the cavity's
    /// boundary faces (one new tet each). A stale token is a bug: it panics in debug builds
    /// and reads an empty cavity in release builds.
    pub fn cavity(&self, cavity: &Cavity) -> (&[u32], &[BoundaryFace]) {
        let current = self.is_current(cavity);
        debug_assert!(current, "stale cavity token");
        if !current {
            return (&[], &[]);
        }
        (&self.scratch.search.cavity, &self.scratch.search.boundary)
    }

    /// Inserts the probed point, with its cavity when the token is current, else (the
    /// triangulation changed, or another point was probed since) searching afresh from the
    /// probe's hint like [`Self::insert`].
    pub fn insert_cavity(&mut self, cavity: Cavity) -> Result<Inserted, DelaunayError> {
        if !self.is_current(&cavity) {
            let s = &mut self.scratch;
            if s.kept.of != Some((cavity.p, cavity.generation))
                || cavity.generation != self.generation
            {
                return self.insert(cavity.p, cavity.hint);
            }
            std::mem::swap(&mut s.search.cavity, &mut s.kept.cavity);
            std::mem::swap(&mut s.search.boundary, &mut s.kept.boundary);
            s.kept.of = None;
            // The walk a fresh search would take, for the walks' random choices that follow
            // (it is short: the probe's hint is near p).
            if let Some(hint) = cavity.hint.filter(|&t| self.is_alive(t)) {
                self.locate(cavity.p, hint);
            }
        }
        let id = self.push_vertex(cavity.p)?;
        // The probe ranked the would-be vertex `points.len()` before the push: `id`. (No
        // vertex came since: an insertion edits, and a duplicate one is popped again.)
        self.fill_cavity(id);
        self.n_vertices += 1;
        Ok(Inserted::New(id))
    }

    pub(super) fn coincident_vertex(&self, t: u32, p: DVec3) -> Option<u32> {
        self.tets[t as usize]
            .v
            .iter()
            .copied()
            .find(|&v| v != INFINITE && self.points[v as usize] == p)
    }

    /// Whether tet `t` conflicts with point `p` of perturbation rank `rank`.
    pub(super) fn in_conflict(&self, t: u32, p: DVec3, rank: u32) -> bool {
        let v = self.tets[t as usize].v;
        match v.iter().position(|&x| x == INFINITE) {
            None => self.finite_in_conflict(t, p, rank),
            Some(k) => {
                let f = FACE[k];
                let o = orient3d(
                    self.points[v[f[0]] as usize],
                    self.points[v[f[1]] as usize],
                    self.points[v[f[2]] as usize],
                    p,
                );
                if o != 0.0 {
                    o > 0.0
                } else {
                    let behind = self.tets[t as usize].n[k] >> 2;
                    self.finite_in_conflict(behind, p, rank)
                }
            }
        }
    }

    #[inline]
    fn finite_in_conflict(&self, t: u32, p: DVec3, rank: u32) -> bool {
        let v = self.tets[t as usize].v;
        let q = v.map(|i| self.points[i as usize]);
        let s = insphere(q[0], q[1], q[2], q[3], p);
        if s != 0.0 {
            return s > 0.0;
        }
        if self.ties_by_coordinates {
            return insphere_tie_by_coordinates(q, p);
        }
        insphere_tie(q, v.map(|i| self.rank[i as usize]), p, rank)
    }

    /// Grows the cavity of `p` from `start` (which must conflict) into the scratch buffers,
    /// marking with the triangulation's own mark array (see [`Self::search_cavity`]).
    fn find_cavity<W: CavityWatch>(
        &mut self,
        p: DVec3,
        rank: u32,
        start: u32,
        watch: &mut W,
    ) -> bool {
        let mut s = std::mem::take(&mut self.scratch);
        let mut mark = std::mem::take(&mut self.mark);
        s.probed = None;
        let found = self.search_cavity(
            &mut ArrayMarks(&mut mark),
            &mut s.search,
            p,
            rank,
            start,
            watch,
        );
        self.mark = mark;
        self.scratch = s;
        found
    }

    /// Grows the cavity of `p` (perturbation rank `rank`) from `start` (which must conflict)
    /// into `s`, recording visits in `marks` (zero for every tet before and after). Reads the
    /// triangulation only, so several searches may run at once with their own buffers and
    /// marks (`shared.rs`).
    ///
    /// Breadth-first, with the cavity list as the queue: when a tet joins the cavity its
    /// neighbours' records and marks are prefetched, and they are usually in cache by the time
    /// it is dequeued and they are tested.
    ///
    /// `watch` sees the boundary faces in batches of its `BATCH` as they are found (a face
    /// found is final: the tet behind it stays outside) and the rest at the end; when it
    /// returns false the search stops, and false is returned.
    pub(super) fn search_cavity<W: CavityWatch, M: Marks>(
        &self,
        marks: &mut M,
        s: &mut SearchBuffers,
        p: DVec3,
        rank: u32,
        start: u32,
        watch: &mut W,
    ) -> bool {
        s.cavity.clear();
        s.entry.clear();
        s.boundary.clear();
        marks.set(start, INSIDE);
        s.cavity.push(start);
        s.entry.push(4);
        let mut head = 0;
        let mut watched = 0;
        let mut stopped = false;
        while head < s.cavity.len() {
            if W::WATCHES && s.boundary.len() - watched >= W::BATCH {
                let upto = s.boundary.len() - (s.boundary.len() - watched) % W::BATCH;
                if !watch.faces(&s.boundary[watched..upto], &self.points) {
                    stopped = true;
                    break;
                }
                watched = upto;
            }
            let t = s.cavity[head];
            head += 1;
            let Tet { v, n: nb } = *self.tet_ref(t);
            s.cavity.reserve(4);
            s.entry.reserve(4);
            s.boundary.reserve(4);
            if has_infinite(v) {
                // A hull tet: the general test for each neighbour.
                for (i, &r) in nb.iter().enumerate() {
                    let n = r >> 2;
                    let m = marks.get(n);
                    if m == INSIDE {
                        continue;
                    }
                    if m != OUTSIDE {
                        if self.in_conflict(n, p, rank) {
                            marks.set(n, INSIDE);
                            s.cavity.push(n);
                            s.entry.push((r & 3) as u8);
                            self.prefetch_neighbors(n, marks);
                            continue;
                        }
                        marks.set(n, OUTSIDE);
                    }
                    s.boundary.push(BoundaryFace {
                        v: FACE[i].map(|k| v[k]),
                        outer: r,
                        owner: t,
                    });
                }
                continue;
            }
            // A finite tet: the neighbour across face i is (face i reversed, apex); only its
            // apex is a new point. The face it was reached through (`entry`) is known to be
            // inside: skip it without a (hard to predict) branch on its mark, and test the
            // other three, prefetching their apexes first, with one shared fan.
            let entry = s.entry[head - 1] as usize;
            let q = [
                self.point_ref(v[0]),
                self.point_ref(v[1]),
                self.point_ref(v[2]),
                self.point_ref(v[3]),
            ];
            if entry < 4 {
                let faces = [(entry + 1) & 3, (entry + 2) & 3, (entry + 3) & 3];
                let mut apex = [INFINITE; 3];
                for (a, &i) in apex.iter_mut().zip(&faces) {
                    let r = nb[i];
                    *a = self.tet_ref(r >> 2).v[(r & 3) as usize];
                    self.prefetch_point(*a);
                }
                let fan = InsphereFan::new(q, p);
                for (&a, &i) in apex.iter().zip(&faces) {
                    // SAFETY: 4 slots of each were reserved for this tet; 3 calls push at
                    // most one each.
                    unsafe { self.test_face(marks, s, &fan, t, v, i, nb[i], a, p, rank) };
                }
            } else {
                // The start tet: all four faces.
                let fan = InsphereFan::new(q, p);
                for (i, &r) in nb.iter().enumerate() {
                    let a = self.tet_ref(r >> 2).v[(r & 3) as usize];
                    // SAFETY: 4 slots of each were reserved for this tet; 4 calls push at
                    // most one each.
                    unsafe { self.test_face(marks, s, &fan, t, v, i, r, a, p, rank) };
                }
            }
        }
        if W::WATCHES && !stopped {
            stopped = !watch.faces(&s.boundary[watched..], &self.points);
        }
        marks.clear(&s.cavity, &s.boundary);
        if stopped {
            s.cavity.clear();
            s.boundary.clear();
        }
        !stopped
    }

    /// One neighbour of a dequeued finite cavity tet `t` (vertices `v`): the neighbour across
    /// face `i` (reference `r`, apex `apex`) is tested if unmarked, and joins the cavity or
    /// makes face `i` a boundary face.
    ///
    /// # Safety
    /// `s.cavity`, `s.entry` and `s.boundary` must each have spare capacity for one more
    /// element (the pushes are unchecked).
    #[allow(clippy::too_many_arguments)]
    #[inline(always)]
    unsafe fn test_face<M: Marks>(
        &self,
        marks: &mut M,
        s: &mut SearchBuffers,
        fan: &InsphereFan,
        t: u32,
        v: [u32; 4],
        i: usize,
        r: u32,
        apex: u32,
        p: DVec3,
        rank: u32,
    ) {
        let n = r >> 2;
        let m = marks.get(n);
        let f = FACE[i];
        let (inside, boundary) = if m == 0 {
            let conflict = if apex == INFINITE {
                self.in_conflict(n, p, rank)
            } else {
                match fan.across(f[0], f[1], f[2], self.point_ref(apex), p) {
                    Some(det) => det > 0.0,
                    None => self.finite_in_conflict(n, p, rank),
                }
            };
            marks.set(n, OUTSIDE - conflict as u8);
            self.prefetch_neighbors(n, marks);
            (conflict, !conflict)
        } else {
            (false, m == OUTSIDE)
        };
        // Branch-free pushes: write the slot, advance the length by the condition.
        // SAFETY: the caller guarantees capacity for one more of each (the fn's contract); each
        // vector gets at most one element here.
        unsafe {
            let len = s.cavity.len();
            s.cavity.as_mut_ptr().add(len).write(n);
            s.cavity.set_len(len + inside as usize);
            s.entry.as_mut_ptr().add(len).write((r & 3) as u8);
            s.entry.set_len(len + inside as usize);
            let len = s.boundary.len();
            let face = BoundaryFace {
                v: [v[f[0]], v[f[1]], v[f[2]]],
                outer: r,
                owner: t,
            };
            s.boundary.as_mut_ptr().add(len).write(face);
            s.boundary.set_len(len + boundary as usize);
        }
    }

    /// Hints the coordinates of vertex `v` (any id, `INFINITE` included) into the cache.
    #[inline(always)]
    fn prefetch_point(&self, v: u32) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults and reads nothing (any address is allowed); the
        // pointer arithmetic wraps, so it is defined for any id. SSE is baseline on x86_64.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            // wrapping: the address is only a hint, never dereferenced
            let ptr = self.points.as_ptr().wrapping_add(v as usize) as *const i8;
            _mm_prefetch(ptr, _MM_HINT_T0);
            _mm_prefetch(ptr.wrapping_add(16), _MM_HINT_T0);
        }
    }

    /// Hints the records and marks of `t`'s neighbours into the cache.
    #[inline(always)]
    fn prefetch_neighbors<M: Marks>(&self, t: u32, marks: &M) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults and reads nothing; the pointer arithmetic wraps, so
        // it is defined for any neighbour reference. SSE is baseline on x86_64.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            for r in self.tet_ref(t).n {
                let n = r >> 2;
                _mm_prefetch(
                    self.tets.as_ptr().wrapping_add(n as usize) as *const i8,
                    _MM_HINT_T0,
                );
                marks.prefetch(n);
            }
        }
    }

    /// Replaces the cavity in the scratch buffers by the star of vertex `id`.
    ///
    /// The new tets reuse the cavity's slots first (then the free list, then fresh slots);
    /// their mutual links are found by pairing each directed boundary edge with its reverse
    /// in a small open-addressing table.
    pub(super) fn fill_cavity(&mut self, id: u32) {
        let mut s = std::mem::take(&mut self.scratch);
        s.probed = None;
        self.generation += 1;
        // Remember the deleted tets (refinement re-checks the boundary elements they held).
        s.removed.clear();
        for &t in &s.search.cavity {
            s.removed.push(self.tet_ref(t).v);
        }
        s.removed_ids.clone_from(&s.search.cavity);
        if let Some(log) = &mut self.removals {
            for &t in &s.search.cavity {
                log.set(t);
            }
        }
        let removed_ghosts = s
            .search
            .cavity
            .iter()
            .filter(|&&t| has_infinite(self.tet_ref(t).v))
            .count();
        // Slots: the cavity's first, then the free list, then new ones.
        let (nf, nc) = (s.search.boundary.len(), s.search.cavity.len());
        s.created.clear();
        s.created.extend_from_slice(&s.search.cavity[..nf.min(nc)]);
        for _ in nc..nf {
            let t = match self.free.pop() {
                Some(t) => t,
                None => {
                    self.grow_tets();
                    self.tets.push(Tet::default());
                    self.mark.push(0);
                    if self.tags_enabled {
                        self.tags.push(0);
                    }
                    (self.tets.len() - 1) as u32
                }
            };
            s.created.push(t);
        }
        // Tags of the owners, read before their slots are overwritten.
        if self.tags_enabled {
            s.tags.clear();
            s.tags.extend(
                s.search
                    .boundary
                    .iter()
                    .map(|f| self.tags[f.owner as usize]),
            );
        }
        for &t in s.search.cavity.iter().skip(nf) {
            self.tet_mut(t).v = [DEAD; 4];
            self.free.push(t);
        }
        s.edges.begin(nf);
        let mut new_ghosts = 0;
        for (k, (f, &t)) in s.search.boundary.iter().zip(&s.created).enumerate() {
            let face = f.v;
            *self.tet_mut(t) = Tet {
                v: [face[0], face[1], face[2], id],
                n: [0, 0, 0, f.outer],
            };
            if self.tags_enabled {
                self.tags[t as usize] = s.tags[k];
            }
            self.tet_mut(f.outer >> 2).n[(f.outer & 3) as usize] = t * 4 + 3;
            // Face j (j < 3) holds the new vertex and the boundary edge face[j+1] -> face[j+2];
            // register it, then (second pass) pair it with the reverse edge.
            for j in 0..3 {
                s.edges
                    .insert(face[(j + 1) % 3], face[(j + 2) % 3], t * 4 + j as u32);
            }
            for v in face {
                if v != INFINITE {
                    debug_assert!((v as usize) < self.vertex_tet.len());
                    // SAFETY: finite vertex ids of alive tets index the vertex arrays.
                    unsafe { *self.vertex_tet.get_unchecked_mut(v as usize) = t };
                } else {
                    new_ghosts += 1;
                }
            }
        }
        // The neighbouring boundary face runs along each edge the other way. Each side writes
        // its own link.
        for (f, &t) in s.search.boundary.iter().zip(&s.created) {
            let face = f.v;
            for j in 0..3 {
                let other = s.edges.get(face[(j + 2) % 3], face[(j + 1) % 3]);
                self.tet_mut(t).n[j] = other;
            }
        }
        let last = *s.created.last().expect("a cavity has boundary faces");
        self.vertex_tet[id as usize] = last;
        self.last = last;
        self.n_alive = self.n_alive + nf - nc;
        self.n_ghost = self.n_ghost + new_ghosts - removed_ghosts;
        self.scratch = s;
    }
}

/// Directed boundary edges of a cavity and the new faces owning them: open addressing with
/// linear probing, invalidated wholesale per cavity by a generation stamp. All edges are
/// inserted first, then looked up, so the probes' branches are predictable.
#[derive(Debug, Clone, Default)]
pub(super) struct EdgeTable {
    slots: Vec<EdgeSlot>,
    generation: u32,
    shift: u32,
}

/// One slot: a directed edge, its owner, and the generation that wrote it (one 16-byte
/// record, so a probe touches one cache line).
#[derive(Debug, Clone, Copy, Default)]
#[repr(C, align(16))]
struct EdgeSlot {
    key: u64,
    val: u32,
    stamp: u32,
}

impl EdgeTable {
    /// Starts a new cavity with `faces` boundary faces.
    #[inline]
    pub(super) fn begin(&mut self, faces: usize) {
        // 3 directed edges per face: keep the load factor <= 3/16.
        let want = (faces * 16).next_power_of_two().max(512);
        if want > self.slots.len() {
            self.slots = vec![EdgeSlot::default(); want];
            self.generation = 0;
            self.shift = 64 - want.trailing_zeros();
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.slots.fill(EdgeSlot::default());
            self.generation = 1;
        }
    }

    /// Registers directed edge `a -> b` owned by face reference `val`.
    #[inline]
    pub(super) fn insert(&mut self, a: u32, b: u32, val: u32) {
        let mask = self.slots.len() - 1;
        let mut slot = (edge_hash(a, b) >> self.shift) as usize;
        // SAFETY: slots are masked to the table length (a power of two).
        unsafe {
            while self.slots.get_unchecked(slot).stamp == self.generation {
                slot = (slot + 1) & mask;
            }
            *self.slots.get_unchecked_mut(slot) = EdgeSlot {
                key: edge_key(a, b),
                val,
                stamp: self.generation,
            };
        }
    }

    /// The owner of directed edge `a -> b`, which must have been registered (the cavity
    /// boundary is a closed surface: every edge appears once in each direction).
    #[inline]
    pub(super) fn get(&self, a: u32, b: u32) -> u32 {
        let mask = self.slots.len() - 1;
        let want = edge_key(a, b);
        let mut slot = (edge_hash(a, b) >> self.shift) as usize;
        // SAFETY: slots are masked to the table length (a power of two).
        unsafe {
            loop {
                let e = self.slots.get_unchecked(slot);
                assert!(
                    e.stamp == self.generation,
                    "cavity boundary is not a closed surface"
                );
                if e.key == want {
                    return e.val;
                }
                slot = (slot + 1) & mask;
            }
        }
    }

    pub(super) fn memory_bytes(&self) -> usize {
        self.slots.capacity() * std::mem::size_of::<EdgeSlot>()
    }
}

#[inline]
fn edge_hash(a: u32, b: u32) -> u64 {
    (edge_key(a, b) ^ (a as u64).rotate_left(17)).wrapping_mul(0x9E37_79B9_7F4A_7C15)
}

#[inline]
fn edge_key(a: u32, b: u32) -> u64 {
    ((a as u64) << 32) | b as u64
}
