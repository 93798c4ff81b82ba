//! The conflict region ("cavity") of a point and its star retriangulation (Bowyer–Watson).
//!
//! A finite tet conflicts with p when p is inside its circumsphere (perturbed in-sphere, so
//! ties never happen); a hull tet conflicts when p is strictly outside its hull face or, when
//! p lies on the hull face's plane, exactly when the finite tet behind that face conflicts
//! (the sphere meets the plane in the face's circumcircle). The cavity is the connected set of
//! conflicting tets around the tet containing p; its boundary is star-shaped from p.

use super::tables::FACE;
use super::{has_infinite, Delaunay, Inserted, Tet, DEAD, INFINITE};
use crate::geom::{insphere, insphere_tie, orient3d, InsphereFan};
use glam::DVec3;

/// Reusable buffers for cavity searches.
#[derive(Debug, Clone, Default)]
pub(super) struct Scratch {
    /// Tets in conflict.
    cavity: Vec<u32>,
    /// Cavity boundary as (cavity tet, local face) pairs.
    boundary: Vec<(u32, u8)>,
    /// Boundary faces copied out before their tets are reused: vertices, outer neighbour ref,
    /// tag of the cavity tet that owned the face.
    faces: Vec<([u32; 3], u32, u32)>,
    /// Tets created by the last insertion.
    pub(super) created: Vec<u32>,
    /// Directed boundary edge -> face reference of the new tet that owns it.
    edges: EdgeTable,
}

impl Scratch {
    pub(super) fn memory_bytes(&self) -> usize {
        self.cavity.capacity() * 4
            + self.boundary.capacity() * 8
            + self.faces.capacity() * 20
            + self.created.capacity() * 4
            + self.edges.memory_bytes()
    }
}

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
        self.find_cavity(p, rank, start);
        self.fill_cavity(id);
        self.n_vertices += 1;
        Inserted::New(id)
    }

    /// The tets a new point at `p` would remove and the faces it would connect to, without
    /// changing the triangulation (refinement tests candidate points with this). `hint` is a
    /// tet to start the walk from (any alive tet).
    pub fn dry_run(&mut self, p: DVec3, hint: Option<u32>) -> DryRun {
        let hint = hint.filter(|&t| self.is_alive(t)).unwrap_or(self.last);
        let start = self.locate(p, hint);
        if let Some(dup) = self.coincident_vertex(start, p) {
            return DryRun::Duplicate(dup);
        }
        // The would-be vertex ranks above every existing one, as a real insertion would.
        self.find_cavity(p, self.points.len() as u32, start);
        let faces = self
            .scratch
            .boundary
            .iter()
            .map(|&(t, i)| {
                let v = self.tets[t as usize].v;
                FACE[i as usize].map(|k| v[k])
            })
            .collect();
        DryRun::Cavity {
            removed: self.scratch.cavity.clone(),
            faces,
        }
    }

    fn coincident_vertex(&self, t: u32, p: DVec3) -> Option<u32> {
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
        insphere_tie(q, v.map(|i| self.rank[i as usize]), p, rank)
    }

    /// Grows the cavity of `p` from `start` (which must conflict) into the scratch buffers.
    ///
    /// Breadth-first, with the cavity list as the queue: when a tet joins the cavity its
    /// neighbours' records and marks are prefetched, and they are usually in cache by the time
    /// it is dequeued and they are tested.
    fn find_cavity(&mut self, p: DVec3, rank: u32, start: u32) {
        const INSIDE: u8 = 1;
        const OUTSIDE: u8 = 2;
        const _: () = assert!(OUTSIDE - 1 == INSIDE);
        let mut s = std::mem::take(&mut self.scratch);
        s.cavity.clear();
        s.boundary.clear();
        self.mark[start as usize] = INSIDE;
        s.cavity.push(start);
        let mut head = 0;
        while head < s.cavity.len() {
            let t = s.cavity[head];
            head += 1;
            let Tet { v, n: nb } = self.tets[t as usize];
            if has_infinite(v) {
                // A hull tet: the general test for each neighbour.
                for (i, &r) in nb.iter().enumerate() {
                    let n = r >> 2;
                    let m = self.mark[n as usize];
                    if m == INSIDE {
                        continue;
                    }
                    if m != OUTSIDE {
                        if self.in_conflict(n, p, rank) {
                            self.mark[n as usize] = INSIDE;
                            s.cavity.push(n);
                            self.prefetch_neighbors(n);
                            continue;
                        }
                        self.mark[n as usize] = OUTSIDE;
                    }
                    s.boundary.push((t, i as u8));
                }
                continue;
            }
            // A finite tet: the neighbour across face i is (face i reversed, apex); only its
            // apex is a new point. Prefetch the apexes, then test with the shared fan.
            // (Loaded unconditionally: a branch on the mark here mispredicts often, and the
            // records of marked neighbours are in cache anyway.)
            let mut apex = [INFINITE; 4];
            for (i, &r) in nb.iter().enumerate() {
                apex[i] = self.tets[(r >> 2) as usize].v[(r & 3) as usize];
                self.prefetch_point(apex[i]);
            }
            let pts = &self.points;
            let q = [
                pts[v[0] as usize],
                pts[v[1] as usize],
                pts[v[2] as usize],
                pts[v[3] as usize],
            ];
            let fan = InsphereFan::new(q, p);
            s.cavity.reserve(4);
            s.boundary.reserve(4);
            for (i, &r) in nb.iter().enumerate() {
                let n = r >> 2;
                let m = self.mark[n as usize];
                let (inside, boundary) = if m == 0 {
                    let f = FACE[i];
                    let conflict = if apex[i] == INFINITE {
                        self.in_conflict(n, p, rank)
                    } else {
                        let q = self.points[apex[i] as usize];
                        match fan.across(f[0], f[1], f[2], q, p) {
                            Some(det) => det > 0.0,
                            None => self.finite_in_conflict(n, p, rank),
                        }
                    };
                    self.mark[n as usize] = OUTSIDE - conflict as u8;
                    self.prefetch_neighbors(n);
                    (conflict, !conflict)
                } else {
                    (false, m == OUTSIDE)
                };
                // Branch-free pushes: write the slot, advance the length by the condition.
                // SAFETY: capacity for 4 more of each was reserved above.
                unsafe {
                    let len = s.cavity.len();
                    s.cavity.as_mut_ptr().add(len).write(n);
                    s.cavity.set_len(len + inside as usize);
                    let len = s.boundary.len();
                    s.boundary.as_mut_ptr().add(len).write((t, i as u8));
                    s.boundary.set_len(len + boundary as usize);
                }
            }
        }
        // Leave every mark at zero for the next search.
        for &t in &s.cavity {
            self.mark[t as usize] = 0;
        }
        for &(t, i) in &s.boundary {
            self.mark[(self.tets[t as usize].n[i as usize] >> 2) as usize] = 0;
        }
        self.scratch = s;
    }

    /// Hints the coordinates of vertex `v` (any id, `INFINITE` included) into the cache.
    #[inline(always)]
    fn prefetch_point(&self, v: u32) {
        #[cfg(target_arch = "x86_64")]
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
    fn prefetch_neighbors(&self, t: u32) {
        #[cfg(target_arch = "x86_64")]
        unsafe {
            use std::arch::x86_64::{_mm_prefetch, _MM_HINT_T0};
            let nb = self.tets.get_unchecked(t as usize).n;
            for r in nb {
                let n = (r >> 2) as usize;
                _mm_prefetch(self.tets.as_ptr().add(n) as *const i8, _MM_HINT_T0);
                _mm_prefetch(self.mark.as_ptr().add(n) as *const i8, _MM_HINT_T0);
            }
        }
    }

    /// Replaces the cavity in the scratch buffers by the star of vertex `id`.
    ///
    /// The new tets reuse the cavity's slots first (then the free list, then fresh slots);
    /// their mutual links are found by pairing each directed boundary edge with its reverse
    /// in a small open-addressing table.
    fn fill_cavity(&mut self, id: u32) {
        let mut s = std::mem::take(&mut self.scratch);
        s.faces.clear();
        for &(t, i) in &s.boundary {
            let v = self.tets[t as usize].v;
            let face = FACE[i as usize].map(|k| v[k]);
            let tag = self.tags.get(t as usize).copied().unwrap_or(0);
            s.faces.push((face, self.tets[t as usize].n[i as usize], tag));
        }
        let removed_ghosts = s
            .cavity
            .iter()
            .filter(|&&t| has_infinite(self.tets[t as usize].v))
            .count();
        // Slots: the cavity's first, then the free list, then new ones.
        let (nf, nc) = (s.faces.len(), s.cavity.len());
        s.created.clear();
        s.created.extend_from_slice(&s.cavity[..nf.min(nc)]);
        for _ in nc..nf {
            let t = match self.free.pop() {
                Some(t) => t,
                None => {
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
        for &t in s.cavity.iter().skip(nf) {
            self.tets[t as usize].v = [DEAD; 4];
            self.free.push(t);
        }
        s.edges.begin(nf);
        let mut new_ghosts = 0;
        for (&(face, outer, tag), &t) in s.faces.iter().zip(&s.created) {
            self.tets[t as usize].v = [face[0], face[1], face[2], id];
            if self.tags_enabled {
                self.tags[t as usize] = tag;
            }
            let me = t * 4 + 3;
            self.set_neighbor(me, outer);
            self.set_neighbor(outer, me);
            // Face j (j < 3) holds the new vertex and the boundary edge face[j+1] -> face[j+2];
            // register it, then (second pass) pair it with the reverse edge.
            for j in 0..3 {
                s.edges.insert(face[(j + 1) % 3], face[(j + 2) % 3], t * 4 + j as u32);
            }
            for v in face {
                if v != INFINITE {
                    self.vertex_tet[v as usize] = t;
                } else {
                    new_ghosts += 1;
                }
            }
        }
        // The neighbouring boundary face runs along each edge the other way. Each side writes
        // its own link.
        for (&(face, _, _), &t) in s.faces.iter().zip(&s.created) {
            for j in 0..3 {
                let other = s.edges.get(face[(j + 2) % 3], face[(j + 1) % 3]);
                self.tets[t as usize].n[j] = other;
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
    keys: Vec<u64>,
    vals: Vec<u32>,
    stamp: Vec<u32>,
    generation: u32,
    shift: u32,
}

impl EdgeTable {
    /// Starts a new cavity with `faces` boundary faces.
    #[inline]
    fn begin(&mut self, faces: usize) {
        // 3 directed edges per face: keep the load factor <= 3/16.
        let want = (faces * 16).next_power_of_two().max(512);
        if want > self.keys.len() {
            self.keys = vec![0; want];
            self.vals = vec![0; want];
            self.stamp = vec![0; want];
            self.generation = 0;
            self.shift = 64 - want.trailing_zeros();
        }
        self.generation = self.generation.wrapping_add(1);
        if self.generation == 0 {
            self.stamp.fill(0);
            self.generation = 1;
        }
    }

    /// Registers directed edge `a -> b` owned by face reference `val`.
    #[inline]
    fn insert(&mut self, a: u32, b: u32, val: u32) {
        let mask = self.keys.len() - 1;
        let mut slot = (edge_hash(a, b) >> self.shift) as usize;
        while self.stamp[slot] == self.generation {
            slot = (slot + 1) & mask;
        }
        self.stamp[slot] = self.generation;
        self.keys[slot] = edge_key(a, b);
        self.vals[slot] = val;
    }

    /// The owner of directed edge `a -> b`, which must have been registered (the cavity
    /// boundary is a closed surface: every edge appears once in each direction).
    #[inline]
    fn get(&self, a: u32, b: u32) -> u32 {
        let mask = self.keys.len() - 1;
        let want = edge_key(a, b);
        let mut slot = (edge_hash(a, b) >> self.shift) as usize;
        loop {
            assert!(
                self.stamp[slot] == self.generation,
                "cavity boundary is not a closed surface"
            );
            if self.keys[slot] == want {
                return self.vals[slot];
            }
            slot = (slot + 1) & mask;
        }
    }

    fn memory_bytes(&self) -> usize {
        self.keys.capacity() * 8 + self.vals.capacity() * 4 + self.stamp.capacity() * 4
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
