//! Parallel bulk insertion (`Delaunay::from_points_threads`): partitioned Bowyer–Watson after
//! Marot, Pellerin and Remacle, "One machine, one minute, three billion tetrahedra" (IJNME
//! 2019, the HXT scheme), on std threads of a rayon pool. See docs/parallel.md.
//!
//! Each BRIO round ([`hilbert::brio_rounds`]) big enough is inserted in *phases*. A phase
//! splits the points still to insert into T parts of equal size along a space-filling curve
//! (Z-order) over the whole bounding box (later phases: slabs across the axis the points left
//! spread most along), and gives every vertex (inserted or not) the part its key falls in.
//! Thread i inserts the points of part i, in BRIO order, touching only
//!
//! - tets it *owns*: every finite vertex in part i (the vertex at infinity is in every part),
//!   and
//! - tets sharing a face with a tet it owns (the outer side of a cavity face, a step of the
//!   walk).
//!
//! Two threads never touch the same tet: a tet touched by i and j would have one face whose
//! finite vertices are all in part i and one whose finite vertices are all in part j; two
//! faces of a tet share an edge, which has a finite vertex. A walk that would step into a tet
//! it does not own, a cavity that would take in one, or a hull test that would have to read
//! past one, gives the point up ("deferred"): it is tried again in the next phase, with shifted
//! parts, and after the last phase the round's rest is inserted serially.
//!
//! The result does not depend on the thread count or on timing: the ranks of the symbolic
//! perturbation are the BRIO positions whatever the insertion order, so every insertion order
//! builds the one Delaunay triangulation of the perturbed points. (Each thread's work is also
//! deterministic: what it reads only it writes, so which points it defers depends only on the
//! partition.)
//!
//! Storage: the tet records, marks and incident-tet pointers are viewed as relaxed atomics for
//! the phase (plain loads and stores on x86-64; no data race is possible, and the ownership
//! rule above makes them exclusive anyway). New slots come from a per-thread free list, then
//! from a per-thread block of dead slots appended before the phase; a thread whose slots run
//! out defers the rest of its points.

use super::cavity::{BoundaryFace, EdgeTable, INSIDE, OUTSIDE};
use super::tables::FACE;
use super::{
    has_infinite, hilbert, Delaunay, DelaunayError, InsertStats, Inserted, Tet, DEAD, INFINITE,
    NO_TET,
};
use crate::geom::{self, insphere, insphere_tie, orient3d, InsphereFan};
use glam::DVec3;
use rayon::prelude::*;
use std::sync::atomic::{AtomicU32, AtomicU8, Ordering::Relaxed};

/// Bits per axis of the partition keys (63-bit keys: fine enough for clustered points).
const KEY_BITS: u32 = 21;
/// A round is split among the threads when it has at least this many points per thread.
const MIN_PHASE_POINTS_PER_THREAD: usize = 4096;
/// A retry phase runs while this many points per thread are left.
const MIN_RETRY_POINTS_PER_THREAD: usize = 512;
/// Phases per round at most (then the rest is inserted serially).
const MAX_ATTEMPTS: u32 = 4;
/// Fresh tet slots per point given to a thread (net growth is about 6.75 per point for uniform
/// points, hull tets included), plus a margin per thread.
const SLOTS_PER_POINT: usize = 7;
const SLOT_MARGIN: usize = 1024;
/// Parts are numbered in a byte.
pub const MAX_THREADS: usize = 255;

/// The thread count `threads` asks for: 0 means all cores (`available_parallelism`), and at
/// most [`MAX_THREADS`].
pub fn resolve_threads(threads: usize) -> usize {
    let t = if threads == 0 {
        std::thread::available_parallelism().map_or(1, |n| n.get())
    } else {
        threads
    };
    t.clamp(1, MAX_THREADS)
}

/// What the parallel phases of a bulk insertion did (for tests, docs and tuning).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct ParallelReport {
    /// Threads used (1: the serial kernel ran).
    pub threads: usize,
    /// Phases run (all rounds).
    pub phases: usize,
    /// Points inserted (or found to be duplicates) by the threads of a phase.
    pub parallel_points: usize,
    /// Points inserted serially: the small first rounds and what the phases deferred.
    pub serial_points: usize,
}

/// A tet record seen as atomics: the layout of [`Tet`].
#[repr(C, align(32))]
struct AtomicTet {
    v: [AtomicU32; 4],
    n: [AtomicU32; 4],
}

const _: () = assert!(
    std::mem::size_of::<AtomicTet>() == std::mem::size_of::<Tet>()
        && std::mem::align_of::<AtomicTet>() == std::mem::align_of::<Tet>()
        && std::mem::size_of::<AtomicU32>() == 4
        && std::mem::align_of::<AtomicU32>() == 4
);

/// The triangulation's arrays as the threads of a phase see them.
struct Shared<'a> {
    tets: &'a [AtomicTet],
    mark: &'a [AtomicU8],
    vertex_tet: &'a [AtomicU32],
    points: &'a [DVec3],
    rank: &'a [u32],
    /// Part of each vertex for this phase.
    part: &'a [u8],
}

impl<'a> Shared<'a> {
    fn new(
        tets: &'a mut [Tet],
        mark: &'a mut [u8],
        vertex_tet: &'a mut [u32],
        points: &'a [DVec3],
        rank: &'a [u32],
        part: &'a [u8],
    ) -> Self {
        // SAFETY: `AtomicTet` is `repr(C)` with the fields of `Tet` in the same order, and
        // `AtomicU32` / `AtomicU8` have the size, alignment and bit validity of `u32` / `u8`
        // (asserted above for the records), so each slice is reinterpreted element for element
        // with its length unchanged. The exclusive borrows last as long as the views, so every
        // access meanwhile is atomic.
        unsafe {
            Shared {
                tets: &*(tets as *mut [Tet] as *const [AtomicTet]),
                mark: &*(mark as *mut [u8] as *const [AtomicU8]),
                vertex_tet: &*(vertex_tet as *mut [u32] as *const [AtomicU32]),
                points,
                rank,
                part,
            }
        }
    }

    // Unchecked indexing on the hot paths, as in the serial kernel. Invariants: neighbour
    // references of alive tets name existing slots, finite vertex ids of alive tets index the
    // vertex arrays (checked in debug builds); a thread follows references only out of tets it
    // owns or touches, whose records no other thread writes during the phase.

    /// The record of slot `t`.
    #[inline(always)]
    fn rec(&self, t: u32) -> &AtomicTet {
        debug_assert!((t as usize) < self.tets.len());
        // SAFETY: see the invariants above.
        unsafe { self.tets.get_unchecked(t as usize) }
    }

    #[inline(always)]
    fn verts(&self, t: u32) -> [u32; 4] {
        let a = &self.rec(t).v;
        [
            a[0].load(Relaxed),
            a[1].load(Relaxed),
            a[2].load(Relaxed),
            a[3].load(Relaxed),
        ]
    }
    #[inline(always)]
    fn vert(&self, t: u32, i: usize) -> u32 {
        self.rec(t).v[i].load(Relaxed)
    }
    #[inline(always)]
    fn nbrs(&self, t: u32) -> [u32; 4] {
        let a = &self.rec(t).n;
        [
            a[0].load(Relaxed),
            a[1].load(Relaxed),
            a[2].load(Relaxed),
            a[3].load(Relaxed),
        ]
    }
    #[inline(always)]
    fn nbr(&self, t: u32, i: usize) -> u32 {
        self.rec(t).n[i].load(Relaxed)
    }
    #[inline(always)]
    fn set_nbr(&self, t: u32, i: usize, r: u32) {
        self.rec(t).n[i].store(r, Relaxed);
    }
    #[inline(always)]
    fn write(&self, t: u32, v: [u32; 4], n: [u32; 4]) {
        let a = self.rec(t);
        for k in 0..4 {
            a.v[k].store(v[k], Relaxed);
            a.n[k].store(n[k], Relaxed);
        }
    }
    #[inline(always)]
    fn kill(&self, t: u32) {
        for x in &self.rec(t).v {
            x.store(DEAD, Relaxed);
        }
    }
    #[inline(always)]
    fn mark(&self, t: u32) -> u8 {
        debug_assert!((t as usize) < self.mark.len());
        // SAFETY: one mark per tet slot.
        unsafe { self.mark.get_unchecked(t as usize) }.load(Relaxed)
    }
    #[inline(always)]
    fn set_mark(&self, t: u32, m: u8) {
        debug_assert!((t as usize) < self.mark.len());
        // SAFETY: one mark per tet slot.
        unsafe { self.mark.get_unchecked(t as usize) }.store(m, Relaxed);
    }
    #[inline(always)]
    fn point(&self, v: u32) -> DVec3 {
        debug_assert!((v as usize) < self.points.len());
        // SAFETY: see the invariants above (called with finite vertex ids of alive tets and
        // with ids of points to insert).
        unsafe { *self.points.get_unchecked(v as usize) }
    }
    /// Whether every finite vertex of `v` is in part `me`.
    #[inline(always)]
    fn owned(&self, v: [u32; 4], me: u8) -> bool {
        v.iter().all(|&x| {
            x == INFINITE || {
                debug_assert!((x as usize) < self.part.len());
                // SAFETY: `part` has one entry per vertex id; see the invariants above.
                unsafe { *self.part.get_unchecked(x as usize) == me }
            }
        })
    }

    /// Perturbed in-sphere test of finite tet `v` against `p` of rank `rank`.
    #[inline]
    fn finite_conflict(&self, v: [u32; 4], p: DVec3, rank: u32) -> bool {
        let q = v.map(|i| self.point(i));
        let s = insphere(q[0], q[1], q[2], q[3], p);
        if s != 0.0 {
            return s > 0.0;
        }
        insphere_tie(q, v.map(|i| self.rank[i as usize]), p, rank)
    }

    /// Hints the coordinates of vertex `v` (any id, `INFINITE` included) into the cache.
    #[inline(always)]
    fn prefetch_point(&self, v: u32) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults and reads nothing (any address is allowed); the
        // pointer arithmetic wraps, so it is defined for any id. SSE is baseline on x86_64.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let ptr = self.points.as_ptr().wrapping_add(v as usize) as *const i8;
            _mm_prefetch(ptr, _MM_HINT_T0);
            _mm_prefetch(ptr.wrapping_add(16), _MM_HINT_T0);
        }
    }

    /// Hints the records and marks of `t`'s neighbours into the cache.
    #[inline(always)]
    fn prefetch_neighbors(&self, t: u32) {
        #[cfg(target_arch = "x86_64")]
        // SAFETY: a prefetch never faults and reads nothing; the pointer arithmetic wraps, so
        // it is defined for any neighbour reference. SSE is baseline on x86_64.
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            for r in self.nbrs(t) {
                let n = (r >> 2) as usize;
                _mm_prefetch(self.tets.as_ptr().wrapping_add(n) as *const i8, _MM_HINT_T0);
                _mm_prefetch(self.mark.as_ptr().wrapping_add(n) as *const i8, _MM_HINT_T0);
            }
        }
    }
}

/// Why a thread gave a point up.
enum GiveUp {
    /// The walk or the cavity reached past the tets the thread owns.
    Conflict,
    /// The thread's tet slots ran out.
    Slots,
}

/// One thread's state; kept across phases for its buffers.
#[derive(Default)]
struct Worker {
    /// Its part.
    me: u8,
    rng: u32,
    /// Points to insert this phase (internal ids, BRIO order) and those given up.
    todo: Vec<u32>,
    deferred: Vec<u32>,
    /// Coordinates of the points given up this phase: a later copy of one waits too, so that
    /// the first copy of a point is the one that becomes a vertex, as in the serial kernel.
    deferred_at: rustc_hash::FxHashSet<[u64; 3]>,
    /// Dead slots it may reuse, then fresh ones.
    free: Vec<u32>,
    fresh: std::ops::Range<u32>,
    cavity: Vec<u32>,
    entry: Vec<u8>,
    boundary: Vec<BoundaryFace>,
    created: Vec<u32>,
    edges: EdgeTable,
    /// A tet it owns (NO_TET: none found; it then gives every point up).
    last: u32,
    inserted: usize,
    duplicates: usize,
    alive: isize,
    ghosts: isize,
    /// On-CPU seconds of its last phase (tracing only).
    cpu: f64,
}

impl Worker {
    fn run(&mut self, sh: &Shared, trace: bool) {
        let cpu0 = if trace { on_cpu() } else { 0.0 };
        self.created.clear();
        self.deferred.clear();
        self.deferred_at.clear();
        let todo = std::mem::take(&mut self.todo);
        let mut out_of_slots = false;
        for &id in &todo {
            if out_of_slots || self.last == NO_TET {
                self.deferred.push(id);
                continue;
            }
            // (+ 0.0 makes -0.0 into 0.0: equal points, equal keys.)
            let at = sh.point(id).to_array().map(|x| (x + 0.0).to_bits());
            if !self.deferred_at.is_empty() && self.deferred_at.contains(&at) {
                self.deferred.push(id);
                continue;
            }
            match self.insert(sh, id) {
                Ok(()) => {}
                Err(GiveUp::Conflict) => {
                    self.deferred.push(id);
                    self.deferred_at.insert(at);
                }
                Err(GiveUp::Slots) => {
                    out_of_slots = true;
                    self.deferred.push(id);
                }
            }
        }
        self.todo = todo;
        self.todo.clear();
        if trace {
            self.cpu = on_cpu() - cpu0;
        }
    }

    fn insert(&mut self, sh: &Shared, id: u32) -> Result<(), GiveUp> {
        let p = sh.point(id);
        let rank = sh.rank[id as usize];
        let hint = self.hint_towards(sh, p);
        let start = self.locate(sh, p, hint).ok_or(GiveUp::Conflict)?;
        let sv = sh.verts(start);
        if sv.iter().any(|&v| v != INFINITE && sh.point(v) == p) {
            self.duplicates += 1;
            return Ok(());
        }
        if !self.find_cavity(sh, p, rank, start) {
            return Err(GiveUp::Conflict);
        }
        let need = self.boundary.len().saturating_sub(self.cavity.len());
        if need > self.free.len() + self.fresh.len() {
            return Err(GiveUp::Slots);
        }
        self.fill_cavity(sh, id);
        self.inserted += 1;
        Ok(())
    }

    #[inline]
    fn next_random(&mut self) -> u32 {
        let mut x = self.rng;
        x ^= x << 13;
        x ^= x >> 17;
        x ^= x << 5;
        self.rng = x;
        x
    }

    /// As `Delaunay::hint_towards`, over this thread's last insertion (tets it owns).
    fn hint_towards(&self, sh: &Shared, p: DVec3) -> u32 {
        let mut best = f64::MAX;
        let mut hint = self.last;
        let p3 = p * 3.0;
        for &t in self.created.iter().step_by(3) {
            let v = sh.verts(t);
            if !has_infinite(v) {
                let c = sh.point(v[0]) + sh.point(v[1]) + sh.point(v[2]);
                let d = c.distance_squared(p3);
                if d < best {
                    best = d;
                    hint = t;
                }
            }
        }
        hint
    }

    /// The visibility walk of `Delaunay::locate` from `start` (a tet this thread owns), over
    /// owned tets only: None when it would step into another.
    fn locate(&mut self, sh: &Shared, p: DVec3, start: u32) -> Option<u32> {
        let me = self.me;
        let mut t = start;
        if let Some(k) = sh.verts(t).iter().position(|&x| x == INFINITE) {
            t = sh.nbr(t, k) >> 2;
            if !sh.owned(sh.verts(t), me) {
                return None;
            }
        }
        let mut came_from = u32::MAX;
        'walk: loop {
            let v = sh.verts(t);
            let nb = sh.nbrs(t);
            let r = self.next_random() as usize;
            for k in 0..4 {
                let i = (r + k) & 3;
                let n = nb[i] >> 2;
                if n == came_from {
                    continue;
                }
                let f = FACE[i];
                if orient3d(sh.point(v[f[0]]), sh.point(v[f[1]]), sh.point(v[f[2]]), p) < 0.0 {
                    let nv = sh.verts(n);
                    if !sh.owned(nv, me) {
                        return None;
                    }
                    if has_infinite(nv) {
                        return Some(n);
                    }
                    came_from = t;
                    t = n;
                    continue 'walk;
                }
            }
            return Some(t);
        }
    }

    /// Whether tet `n` (vertices `nv`), across a face of cavity tet `from`, conflicts with
    /// `p`; None when deciding would read a tet this thread may not touch (p on the plane of a
    /// hull face whose finite tet is beyond the thread's tets).
    #[inline]
    fn conflict(
        &self,
        sh: &Shared,
        n: u32,
        nv: [u32; 4],
        from: u32,
        p: DVec3,
        rank: u32,
    ) -> Option<bool> {
        match nv.iter().position(|&x| x == INFINITE) {
            None => Some(sh.finite_conflict(nv, p, rank)),
            Some(k) => {
                let f = FACE[k];
                let o = orient3d(
                    sh.point(nv[f[0]]),
                    sh.point(nv[f[1]]),
                    sh.point(nv[f[2]]),
                    p,
                );
                if o != 0.0 {
                    return Some(o > 0.0);
                }
                // The finite tet behind the hull face decides (as in `Delaunay::in_conflict`).
                // It shares that face with `n`: it may be read when it is `from` or when the
                // face's vertices are this thread's.
                let behind = sh.nbr(n, k) >> 2;
                if behind != from && !sh.owned(nv, self.me) {
                    return None;
                }
                Some(sh.finite_conflict(sh.verts(behind), p, rank))
            }
        }
    }

    /// `Delaunay::find_cavity` over owned tets: false (marks cleared, cavity void) when a
    /// conflicting tet is not owned or a test cannot be decided.
    fn find_cavity(&mut self, sh: &Shared, p: DVec3, rank: u32, start: u32) -> bool {
        let me = self.me;
        self.cavity.clear();
        self.entry.clear();
        self.boundary.clear();
        sh.set_mark(start, INSIDE);
        self.cavity.push(start);
        self.entry.push(4);
        let mut head = 0;
        let mut ok = true;
        'search: while head < self.cavity.len() {
            let t = self.cavity[head];
            let entry = self.entry[head] as usize;
            head += 1;
            let v = sh.verts(t);
            let nb = sh.nbrs(t);
            let finite = !has_infinite(v);
            // The apex of each neighbour across a face (its only vertex off the face), its
            // coordinates prefetched before the tests, as in the serial search.
            let mut apex = [INFINITE; 4];
            for (i, a) in apex.iter_mut().enumerate() {
                if i != entry {
                    let r = nb[i];
                    *a = sh.vert(r >> 2, (r & 3) as usize);
                    sh.prefetch_point(*a);
                }
            }
            let fan = finite.then(|| InsphereFan::new(v.map(|x| sh.point(x)), p));
            for (i, &r) in nb.iter().enumerate() {
                if i == entry {
                    continue; // the tet it was reached from: in the cavity
                }
                let n = r >> 2;
                let m = sh.mark(n);
                if m == INSIDE {
                    continue;
                }
                if m != OUTSIDE {
                    let conflict = match (&fan, apex[i]) {
                        (Some(fan), a) if a != INFINITE => {
                            let f = FACE[i];
                            match fan.across(f[0], f[1], f[2], sh.point(a), p) {
                                Some(det) => det > 0.0,
                                None => sh.finite_conflict(sh.verts(n), p, rank),
                            }
                        }
                        _ => match self.conflict(sh, n, sh.verts(n), t, p, rank) {
                            Some(c) => c,
                            None => {
                                ok = false;
                                break 'search;
                            }
                        },
                    };
                    if conflict {
                        if !sh.owned(sh.verts(n), me) {
                            ok = false;
                            break 'search;
                        }
                        sh.set_mark(n, INSIDE);
                        self.cavity.push(n);
                        self.entry.push((r & 3) as u8);
                        sh.prefetch_neighbors(n);
                        continue;
                    }
                    sh.set_mark(n, OUTSIDE);
                }
                self.boundary.push(BoundaryFace {
                    v: FACE[i].map(|k| v[k]),
                    outer: r,
                    owner: t,
                });
            }
        }
        for &t in &self.cavity {
            sh.set_mark(t, 0);
        }
        for f in &self.boundary {
            sh.set_mark(f.outer >> 2, 0);
        }
        ok
    }

    /// `Delaunay::fill_cavity` with this thread's slots.
    fn fill_cavity(&mut self, sh: &Shared, id: u32) {
        let (nf, nc) = (self.boundary.len(), self.cavity.len());
        let removed_ghosts = self
            .cavity
            .iter()
            .filter(|&&t| has_infinite(sh.verts(t)))
            .count();
        self.created.clear();
        self.created.extend_from_slice(&self.cavity[..nf.min(nc)]);
        for _ in nc..nf {
            let t = match self.free.pop() {
                Some(t) => t,
                None => self.fresh.next().expect("slots were counted"),
            };
            self.created.push(t);
        }
        for &t in self.cavity.iter().skip(nf) {
            sh.kill(t);
            self.free.push(t);
        }
        self.edges.begin(nf);
        let mut new_ghosts = 0;
        for (f, &t) in self.boundary.iter().zip(&self.created) {
            let face = f.v;
            sh.write(t, [face[0], face[1], face[2], id], [0, 0, 0, f.outer]);
            sh.set_nbr(f.outer >> 2, (f.outer & 3) as usize, t * 4 + 3);
            for j in 0..3 {
                self.edges
                    .insert(face[(j + 1) % 3], face[(j + 2) % 3], t * 4 + j as u32);
            }
            for v in face {
                if v != INFINITE {
                    sh.vertex_tet[v as usize].store(t, Relaxed);
                } else {
                    new_ghosts += 1;
                }
            }
        }
        for (f, &t) in self.boundary.iter().zip(&self.created) {
            let face = f.v;
            for j in 0..3 {
                sh.set_nbr(t, j, self.edges.get(face[(j + 2) % 3], face[(j + 1) % 3]));
            }
        }
        let last = *self.created.last().expect("a cavity has boundary faces");
        sh.vertex_tet[id as usize].store(last, Relaxed);
        self.last = last;
        self.alive += nf as isize - nc as isize;
        self.ghosts += new_ghosts as isize - removed_ghosts as isize;
    }
}

impl Delaunay {
    /// [`Self::from_points`] on `threads` threads (0: all cores): the same triangulation (the
    /// same tets with the same vertex ids) for any thread count. One thread runs the serial
    /// kernel.
    pub fn from_points_threads(
        points: &[DVec3],
        threads: usize,
    ) -> Result<(Self, InsertStats), DelaunayError> {
        Self::from_points_report(points, threads).map(|(dt, stats, _)| (dt, stats))
    }

    /// [`Self::from_points_threads`], also saying what the parallel phases did.
    pub fn from_points_report(
        points: &[DVec3],
        threads: usize,
    ) -> Result<(Self, InsertStats, ParallelReport), DelaunayError> {
        let threads = resolve_threads(threads);
        let serial = |points| {
            Self::from_points(points).map(|(dt, s)| {
                let report = ParallelReport {
                    threads: 1,
                    serial_points: points.len(),
                    ..Default::default()
                };
                (dt, s, report)
            })
        };
        if threads == 1 {
            let cpu0 = tracing().then(on_cpu);
            let r = serial(points);
            if let Some(cpu0) = cpu0 {
                eprintln!("serial kernel: {:.3} s on CPU", on_cpu() - cpu0);
            }
            return r;
        }
        let Ok(pool) = rayon::ThreadPoolBuilder::new().num_threads(threads).build() else {
            return serial(points);
        };
        pool.install(|| Self::build_parallel(points, threads))
    }

    /// The body of [`Self::from_points_report`] on the pool of `threads` threads.
    fn build_parallel(
        points: &[DVec3],
        threads: usize,
    ) -> Result<(Self, InsertStats, ParallelReport), DelaunayError> {
        if let Some((index, reason)) = points
            .par_iter()
            .enumerate()
            .find_first(|(_, &p)| geom::check_coordinate(p).is_err())
            .map(|(i, &p)| (i, geom::check_coordinate(p).unwrap_err()))
        {
            return Err(DelaunayError::BadCoordinate {
                index,
                point: points[index],
                reason,
            });
        }
        let mut trace = Trace::new();
        let order = hilbert::brio_order_parallel(points, 0x5eed);
        trace.lap("brio order");
        let n = points.len();
        let mut dt = Delaunay {
            points: order.par_iter().map(|&i| points[i as usize]).collect(),
            vertex_tet: vec![NO_TET; n],
            rank: (0..n as u32).collect(),
            rng: 0x9e37_79b9,
            ..Default::default()
        };
        let expected = n * SLOTS_PER_POINT + threads * SLOT_MARGIN * 4 + 64;
        dt.tets.reserve(expected);
        dt.mark.reserve(expected);
        let sequence: Vec<u32> = (0..n as u32).collect();
        let first = dt.initial_tet(&sequence)?;
        let mut stats = InsertStats {
            inserted: 4,
            duplicates: 0,
        };
        let mut report = ParallelReport {
            threads,
            ..Default::default()
        };
        let keys = partition_keys(&dt.points);
        let mut part = vec![0u8; n];
        let mut workers: Vec<Worker> = (0..threads)
            .map(|i| Worker {
                me: i as u8,
                rng: 0x9e37_79b9 ^ (i as u32).wrapping_mul(0x85eb_ca6b),
                ..Default::default()
            })
            .collect();
        for round in hilbert::brio_rounds(n) {
            let mut pending: Vec<u32> = (round.start as u32..round.end as u32)
                .filter(|id| !first.contains(id))
                .collect();
            let mut attempt = 0;
            while attempt < MAX_ATTEMPTS {
                let min = if attempt == 0 {
                    MIN_PHASE_POINTS_PER_THREAD
                } else {
                    MIN_RETRY_POINTS_PER_THREAD
                };
                if pending.len() < threads * min {
                    break;
                }
                let before = pending.len();
                pending = dt.phase(
                    &mut workers,
                    &pending,
                    &keys,
                    &mut part,
                    attempt,
                    &mut stats,
                    &mut trace,
                );
                report.phases += 1;
                report.parallel_points += before - pending.len();
                trace.lap(&format!(
                    "phase {attempt}: {before} points, {} left",
                    pending.len()
                ));
                attempt += 1;
            }
            report.serial_points += pending.len();
            dt.insert_serially(&pending, &mut stats);
            trace.lap(&format!("round {round:?}: {} serially", pending.len()));
        }
        report.serial_points += 4;
        dt.renumber_parallel(&order, points);
        trace.lap("renumbered");
        trace.summary();
        Ok((dt, stats, report))
    }

    /// Inserts `ids` (internal ids, BRIO order) one by one, each located from the vertex before
    /// it in the order when that one is in.
    fn insert_serially(&mut self, ids: &[u32], stats: &mut InsertStats) {
        let mut previous = u32::MAX;
        for &id in ids {
            let p = self.points[id as usize];
            let hint = if id > 0 && id - 1 != previous {
                match self.vertex_tet[id as usize - 1] {
                    NO_TET => self.hint_towards(p),
                    t => t,
                }
            } else {
                self.hint_towards(p)
            };
            match self.insert_vertex(id, hint) {
                Inserted::New(_) => stats.inserted += 1,
                Inserted::Duplicate(_) => stats.duplicates += 1,
            }
            previous = id;
        }
    }

    /// One parallel phase over `pending` (internal ids, BRIO order): returns the points the
    /// threads gave up, in BRIO order.
    #[allow(clippy::too_many_arguments)] // the build's state, passed down once per phase
    fn phase(
        &mut self,
        workers: &mut [Worker],
        pending: &[u32],
        keys: &[u64],
        part: &mut [u8],
        attempt: u32,
        stats: &mut InsertStats,
        trace: &mut Trace,
    ) -> Vec<u32> {
        let threads = workers.len();
        self.partition(pending, keys, part, attempt, threads);
        for w in workers.iter_mut() {
            w.todo.clear();
        }
        for &id in pending {
            workers[part[id as usize] as usize].todo.push(id);
        }
        // Start tets: one owned tet near each thread's first point, found serially.
        for w in workers.iter_mut() {
            w.last = NO_TET;
            w.created.clear();
            if let Some(&id) = w.todo.first() {
                let p = self.points[id as usize];
                let near = self.locate(p, self.last);
                w.last = self.owned_tet_near(near, w.me, part);
            }
        }
        // Slots: a share of the free list, then a block of fresh dead slots each.
        let total: usize = workers.iter().map(|w| w.todo.len()).sum();
        let free_before = self.free.len();
        let mut fresh = 0;
        for w in workers.iter_mut() {
            let want = w.todo.len() * SLOTS_PER_POINT + SLOT_MARGIN;
            let share = (free_before * w.todo.len() / total.max(1)).min(self.free.len());
            w.free.clear();
            w.free.extend(self.free.drain(self.free.len() - share..));
            let base = (self.tets.len() + fresh) as u32;
            let extra = want.saturating_sub(share);
            w.fresh = base..base + extra as u32;
            fresh += extra;
        }
        let dead = Tet {
            v: [DEAD; 4],
            n: [u32::MAX; 4],
        };
        if self.tets.capacity() < self.tets.len() + fresh {
            self.tets.reserve_exact(fresh);
        }
        self.tets.par_extend(rayon::iter::repeat_n(dead, fresh));
        self.mark.resize(self.tets.len(), 0);
        {
            let sh = Shared::new(
                &mut self.tets,
                &mut self.mark,
                &mut self.vertex_tet,
                &self.points,
                &self.rank,
                part,
            );
            let sh = &sh;
            let on = trace.on;
            let cpu0 = if on { on_cpu() } else { 0.0 };
            rayon::scope(|s| {
                for w in workers.iter_mut() {
                    s.spawn(move |_| w.run(sh, on));
                }
            });
            if on {
                // This thread ran some of the workers (or none); the phase's critical path is
                // the busiest worker.
                let mine = on_cpu() - cpu0;
                let busiest = workers.iter().map(|w| w.cpu).fold(0.0, f64::max);
                trace.excess += (busiest - mine).max(0.0);
            }
        }
        // Merge: counts, slots, a hint, the deferred points.
        self.generation += 1;
        self.scratch.created.clear();
        let mut deferred = Vec::new();
        for w in workers.iter_mut() {
            self.n_vertices += w.inserted;
            stats.inserted += w.inserted;
            stats.duplicates += w.duplicates;
            w.inserted = 0;
            w.duplicates = 0;
            self.n_alive = (self.n_alive as isize + w.alive) as usize;
            self.n_ghost = (self.n_ghost as isize + w.ghosts) as usize;
            w.alive = 0;
            w.ghosts = 0;
            self.free.append(&mut w.free);
            self.free.extend(w.fresh.clone());
            w.fresh = 0..0;
            if w.last != NO_TET {
                self.last = w.last;
            }
            deferred.append(&mut w.deferred);
        }
        deferred.par_sort_unstable();
        deferred
    }

    /// Gives every vertex its part for phase `attempt` of `pending`. The first attempt cuts
    /// the Z-order curve into pieces of equal pending counts; later ones cut space into slabs
    /// of equal pending counts across the axis along which the pending points spread most
    /// (they lie near the earlier borders, which the new ones then cross).
    fn partition(
        &self,
        pending: &[u32],
        keys: &[u64],
        part: &mut [u8],
        attempt: u32,
        threads: usize,
    ) {
        if attempt == 0 {
            let mut sample: Vec<u64> = pending.par_iter().map(|&i| keys[i as usize]).collect();
            let splits = quantiles(&mut sample, threads);
            part.par_iter_mut()
                .zip(keys.par_iter())
                .for_each(|(p, &k)| *p = slot_of(&splits, k));
            return;
        }
        let (sum, sum2) = pending
            .par_iter()
            .map(|&i| {
                let p = self.points[i as usize];
                (p, p * p)
            })
            .reduce(|| (DVec3::ZERO, DVec3::ZERO), |a, b| (a.0 + b.0, a.1 + b.1));
        let n = pending.len().max(1) as f64;
        let variance = sum2 / n - (sum / n) * (sum / n);
        let axis = if variance.x >= variance.y && variance.x >= variance.z {
            0
        } else if variance.y >= variance.z {
            1
        } else {
            2
        };
        let mut sample: Vec<u64> = pending
            .par_iter()
            .map(|&i| coordinate_key(self.points[i as usize][axis]))
            .collect();
        let splits = quantiles(&mut sample, threads);
        part.par_iter_mut()
            .zip(self.points.par_iter())
            .for_each(|(p, q)| *p = slot_of(&splits, coordinate_key(q[axis])));
    }

    /// A tet near `t` whose finite vertices are all in part `me` (breadth-first over at most a
    /// few thousand tets), or `NO_TET`.
    fn owned_tet_near(&self, t: u32, me: u8, part: &[u8]) -> u32 {
        const LIMIT: usize = 4096;
        let owned = |t: u32| {
            self.tets[t as usize]
                .v
                .iter()
                .all(|&x| x == INFINITE || part[x as usize] == me)
        };
        let mut queue = vec![t];
        let mut seen = rustc_hash::FxHashSet::default();
        seen.insert(t);
        let mut k = 0;
        while k < queue.len() && k < LIMIT {
            let t = queue[k];
            k += 1;
            if owned(t) {
                return t;
            }
            for r in self.tets[t as usize].n {
                if seen.insert(r >> 2) {
                    queue.push(r >> 2);
                }
            }
        }
        NO_TET
    }

    /// [`Self::renumber`] with the tets on the current rayon pool.
    fn renumber_parallel(&mut self, order: &[u32], points: &[DVec3]) {
        self.tets.par_iter_mut().for_each(|tet| {
            for v in tet.v.iter_mut() {
                if *v != INFINITE && *v != DEAD {
                    *v = order[*v as usize];
                }
            }
        });
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
}

/// A finite double as an integer of the same order.
#[inline]
fn coordinate_key(x: f64) -> u64 {
    let b = (x + 0.0).to_bits(); // -0.0 as 0.0
    if b >> 63 == 1 {
        !b
    } else {
        b | (1 << 63)
    }
}

/// The `parts - 1` values cutting `sample` into `parts` runs of equal length (reorders it).
fn quantiles(sample: &mut [u64], parts: usize) -> Vec<u64> {
    let n = sample.len();
    let mut splits = Vec::with_capacity(parts - 1);
    let mut rest: &mut [u64] = sample;
    let mut taken = 0;
    for j in 1..parts {
        if rest.is_empty() {
            splits.push(u64::MAX);
            continue;
        }
        let at = (n * j / parts).saturating_sub(taken).min(rest.len() - 1);
        let (_, &mut s, right) = rest.select_nth_unstable(at);
        splits.push(s);
        taken += at + 1;
        rest = right;
    }
    splits
}

/// The run of `k` among runs cut at `splits` (sorted).
#[inline]
fn slot_of(splits: &[u64], k: u64) -> u8 {
    splits.iter().filter(|&&b| b <= k).count() as u8
}

/// Whether `SLIVERMESH_PARALLEL_TRACE` asks for the diagnostics on stderr.
fn tracing() -> bool {
    std::env::var_os("SLIVERMESH_PARALLEL_TRACE").is_some()
}

/// Diagnostics of a parallel build on stderr (`SLIVERMESH_PARALLEL_TRACE` set): per step the
/// wall clock and the building thread's on-CPU and run-queue seconds, and at the end the
/// on-CPU time of the critical path (the building thread's, plus in each phase the busiest
/// worker's excess over what this thread ran) — what the build would take on idle cores
/// (Linux; elsewhere the CPU figures read 0).
struct Trace {
    on: bool,
    clock: std::time::Instant,
    excess: f64,
    cpu0: f64,
}

impl Trace {
    fn new() -> Self {
        let on = tracing();
        Trace {
            on,
            clock: std::time::Instant::now(),
            excess: 0.0,
            cpu0: if on { on_cpu() } else { 0.0 },
        }
    }

    fn lap(&self, what: &str) {
        if self.on {
            let (run, wait) = schedstat();
            eprintln!(
                "{:8.3} s wall, this thread {:.3} s on CPU, {:.3} s waiting: {what}",
                self.clock.elapsed().as_secs_f64(),
                run as f64 * 1e-9,
                wait as f64 * 1e-9
            );
        }
    }

    fn summary(&self) {
        if self.on {
            let mine = on_cpu() - self.cpu0;
            eprintln!(
                "critical path on CPU: {:.3} s (this thread {mine:.3} s, busiest workers' excess {:.3} s)",
                mine + self.excess,
                self.excess
            );
        }
    }
}

/// Morton (Z-order) keys of `points` over their bounding box, 21 bits per axis: the partition
/// keys. (Z-order rather than Hilbert: a tenth of the cost, and its first pieces are the same
/// half and quarter boxes.)
fn partition_keys(points: &[DVec3]) -> Vec<u64> {
    let (lo, hi) = points
        .par_iter()
        .fold(
            || (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        )
        .reduce(
            || (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |a, b| (a.0.min(b.0), a.1.max(b.1)),
        );
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let scale = ((1u32 << KEY_BITS) - 1) as f64 / extent;
    points
        .par_iter()
        .map(|&p| {
            let c = (p - lo) * scale;
            hilbert::morton_index([c.x as u32, c.y as u32, c.z as u32])
        })
        .collect()
}

/// On-CPU seconds of the calling thread.
fn on_cpu() -> f64 {
    schedstat().0 as f64 * 1e-9
}

/// (on-CPU ns, runqueue-wait ns) of the calling thread (tracing only).
fn schedstat() -> (u64, u64) {
    let text = std::fs::read_to_string("/proc/thread-self/schedstat").unwrap_or_default();
    let mut it = text
        .split_whitespace()
        .map(|x| x.parse::<u64>().unwrap_or(0));
    (it.next().unwrap_or(0), it.next().unwrap_or(0))
}

#[cfg(test)]
#[path = "parallel_tests.rs"]
mod tests;
