//! The improver's working mesh: tets in slots (a free list keeps ids stable and reuse
//! deterministic), vertex stars, boundary triangles by sorted key, and the rings around edges.

use super::batch::note;
use super::quality::Objective;
use crate::geom::orient3d;
use crate::mesh::TetMesh;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

pub(crate) const DEAD: u32 = u32::MAX;

/// Sorted copy of a face's vertex ids (the boundary map's key).
#[inline]
pub(crate) fn key3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

pub(crate) struct Work {
    pub pos: Vec<DVec3>,
    pub tets: Vec<[u32; 4]>,
    pub region: Vec<i32>,
    pub alive: Vec<bool>,
    free: Vec<u32>,
    /// Alive tets around each vertex (order changes as tets come and go, deterministically).
    pub star: Vec<Vec<u32>>,
    /// Boundary triangles (oriented as given), their markers and facet patch
    /// (`DEAD`: none known, so the triangle never moves or flips).
    pub btri: Vec<[u32; 3]>,
    pub bmarker: Vec<i32>,
    pub bpatch: Vec<u32>,
    /// Sorted triangle -> index into `btri`.
    pub bmap: FxHashMap<[u32; 3], u32>,
    /// Boundary triangles around each vertex.
    pub bstar: Vec<Vec<u32>>,
    /// Boundary edges (sorted pair, smaller id high) inside one facet patch: the only ones a
    /// boundary flip may remove.
    pub flat_edges: FxHashSet<u64>,
    /// Objective of every tet slot.
    pub q: Vec<f64>,
    pub objective: Objective,
    /// Vertices deletion removed (no tet uses them; the output drops them).
    pub deleted: Vec<u32>,
    /// The radius-edge bound no change may break (`Options::keep_rho`; infinite: none).
    pub rho_limit: f64,
    /// Vertices of the tets that exceeded `rho_limit` on entry and of the tets around them:
    /// where refinement did not meet the bound (next to small input angles), changes touching
    /// them are not held to it.
    pub rho_exempt: Vec<bool>,
    /// Per vertex: the batch (`epoch`) in which a change last marked it (`touch`), so that a
    /// plan made at the start of the batch is known to be still the plan (`batch`).
    changed_at: Vec<u32>,
    /// The current batch.
    pub epoch: u32,
}

/// What the radius-edge bound says of a change (`Work::keeps_rho`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum RhoCheck {
    /// No tet exceeds the bound where none did.
    Keeps,
    /// One would, next to where refinement left the bound unmet: the bound gives way.
    GivesWay,
    /// One would: the change is refused.
    Vetoed,
}

/// Face `i` of tet `tv` (the one opposite its vertex `i`).
#[inline]
pub(crate) fn face(tv: [u32; 4], i: usize) -> [u32; 3] {
    [tv[(i + 1) % 4], tv[(i + 2) % 4], tv[(i + 3) % 4]]
}

/// The key of edge (a, b) in `Work::flat_edges`.
#[inline]
pub(crate) fn edge_key(a: u32, b: u32) -> u64 {
    ((a.min(b) as u64) << 32) | a.max(b) as u64
}

/// The tets around an edge (a, b), in order: tet `tets[i]` is (a, b, ring[i], ring[i+1])
/// positively oriented (indices mod the ring length when `closed`).
pub(crate) struct Ring {
    pub ring: Vec<u32>,
    pub tets: Vec<u32>,
    pub closed: bool,
}

/// Parity of the permutation taking `t` to `(p[0], p[1], p[2], p[3])` (all of t's vertices).
pub(crate) fn even_perm(t: &[u32; 4], p: [u32; 4]) -> bool {
    let idx = p.map(|v| t.iter().position(|&x| x == v).unwrap_or(0));
    let mut inv = 0;
    for i in 0..4 {
        for j in i + 1..4 {
            if idx[i] > idx[j] {
                inv += 1;
            }
        }
    }
    inv % 2 == 0
}

/// Puts every tet id into the stars of its vertices, in id order (as `Work::push_tet` would
/// one tet after the other). On the run's threads: each takes a range of vertices and scans
/// all the tets for them, so every star gets the same ids in the same order whatever the
/// thread count. The stars already hold the room they need (nothing is allocated here: a
/// star allocated on a pool thread would live in that thread's heap).
fn fill_stars(star: &mut [Vec<u32>], tets: &[[u32; 4]]) {
    let fill = |lo: usize, stars: &mut [Vec<u32>]| {
        let hi = lo + stars.len();
        for (i, t) in tets.iter().enumerate() {
            for &v in t {
                let v = v as usize;
                if (lo..hi).contains(&v) {
                    stars[v - lo].push(i as u32);
                }
            }
        }
    };
    let threads = crate::parallel::current_threads();
    if threads <= 1 || tets.len() < 1 << 16 {
        return fill(0, star);
    }
    let chunk = star.len().div_ceil(threads);
    crate::parallel::install(|| {
        use rayon::prelude::*;
        star.par_chunks_mut(chunk)
            .enumerate()
            .for_each(|(k, s)| fill(k * chunk, s));
    });
}

impl Work {
    pub fn new(mesh: &TetMesh, objective: Objective) -> Work {
        let n = mesh.vertices.len();
        let mut w = Work {
            pos: mesh.vertices.clone(),
            tets: Vec::with_capacity(mesh.tets.len() + mesh.tets.len() / 8),
            region: Vec::with_capacity(mesh.tets.len()),
            alive: Vec::with_capacity(mesh.tets.len()),
            free: vec![],
            star: vec![Vec::new(); n],
            btri: mesh.boundary.clone(),
            bmarker: mesh.boundary_markers.clone(),
            bpatch: vec![DEAD; mesh.boundary.len()],
            bmap: FxHashMap::default(),
            bstar: vec![Vec::new(); n],
            flat_edges: FxHashSet::default(),
            q: Vec::with_capacity(mesh.tets.len()),
            objective,
            deleted: vec![],
            rho_limit: f64::INFINITY,
            rho_exempt: vec![],
            changed_at: vec![0; n],
            epoch: 0,
        };
        let mut degree = vec![0u32; n];
        mesh.tets
            .iter()
            .flatten()
            .for_each(|&v| degree[v as usize] += 1);
        for (s, &d) in w.star.iter_mut().zip(&degree) {
            s.reserve_exact(d as usize + 4);
        }
        // The tets' objectives on the run's threads (`crate::parallel`, in tet order).
        let pos = &w.pos;
        w.q = crate::parallel::map_collect(&mesh.tets, |t| {
            let [a, b, c, d] = t.map(|v| pos[v as usize]);
            objective.of(a, b, c, d)
        });
        w.tets.extend_from_slice(&mesh.tets);
        w.region
            .extend((0..mesh.tets.len()).map(|i| mesh.tet_regions.get(i).copied().unwrap_or(0)));
        w.alive.resize(mesh.tets.len(), true);
        fill_stars(&mut w.star, &mesh.tets);
        w.bmap.reserve(mesh.boundary.len());
        for (i, &f) in mesh.boundary.iter().enumerate() {
            w.bmap.insert(key3(f), i as u32);
            for v in f {
                w.bstar[v as usize].push(i as u32);
            }
        }
        w
    }

    /// Marks vertex `v` as changed in this batch (its star, position, constraint or boundary
    /// triangles, or the objective of a tet around it).
    #[inline]
    pub fn touch(&mut self, v: u32) {
        self.changed_at[v as usize] = self.epoch;
    }

    /// Whether no change has marked `v` since batch `epoch` began.
    #[inline]
    pub fn unchanged_since(&self, v: u32, epoch: u32) -> bool {
        self.changed_at[v as usize] < epoch
    }

    pub fn p(&self, v: u32) -> DVec3 {
        self.pos[v as usize]
    }

    /// The least objective of tets `tets`.
    /// Radius-edge ratio of a tet with these corners.
    pub fn rho_at(p: [DVec3; 4]) -> f64 {
        crate::geom::radius_edge_ratio(p[0], p[1], p[2], p[3])
    }

    /// Sets the radius-edge bound and marks the vertices where the mesh exceeds it now.
    pub fn set_rho_limit(&mut self, limit: f64) {
        self.rho_limit = limit;
        self.rho_exempt = vec![false; self.pos.len()];
        if limit.is_infinite() {
            return;
        }
        let mut over = vec![false; self.pos.len()];
        // The tets' ratios on the run's threads (`crate::parallel`; dead slots are skipped).
        let rho_over =
            crate::parallel::map_collect(&self.tets, |t| Self::rho_at(self.points(t)) > limit);
        for ((tv, &alive), &high) in self.tets.iter().zip(&self.alive).zip(&rho_over) {
            if alive && high {
                tv.iter().for_each(|&v| over[v as usize] = true);
            }
        }
        // And the tets around those vertices: the changes that fix a bad tet there reach one
        // ring out.
        for t in 0..self.tets.len() {
            let tv = self.tets[t];
            if self.alive[t] && tv.iter().any(|&v| over[v as usize]) {
                tv.iter().for_each(|&v| self.rho_exempt[v as usize] = true);
            }
        }
    }

    /// Whether tets with corners `new` may replace the tets `old` under the radius-edge bound:
    /// none of them above `rho_limit` unless an old tet was above it already, and then none
    /// above the largest old one. The bound gives way (`RhoCheck::GivesWay`) for changes
    /// touching a vertex where the mesh exceeded it on entry or next to one (`rho_exempt`); it
    /// always holds without a bound.
    pub fn keeps_rho(&self, old: &[u32], new: impl IntoIterator<Item = [DVec3; 4]>) -> RhoCheck {
        if self.rho_limit.is_infinite() {
            return RhoCheck::Keeps;
        }
        let mut cap = self.rho_limit;
        // Most changes create no tet over the bound: the old tets are measured only then.
        let over: Vec<f64> = new
            .into_iter()
            .map(Self::rho_at)
            .filter(|&r| r > cap)
            .collect();
        if over.is_empty() {
            return RhoCheck::Keeps;
        }
        for &t in old {
            cap = cap.max(Self::rho_at(self.points(&self.tets[t as usize])));
        }
        let exempt = |t: &u32| {
            self.tets[*t as usize]
                .iter()
                .any(|&v| self.rho_exempt.get(v as usize).copied().unwrap_or(false))
        };
        if over.iter().all(|&r| r <= cap) {
            RhoCheck::Keeps
        } else if old.iter().any(exempt) {
            RhoCheck::GivesWay
        } else {
            RhoCheck::Vetoed
        }
    }

    pub fn worst_q(&self, tets: &[u32]) -> f64 {
        tets.iter()
            .map(|&t| self.q[t as usize])
            .fold(f64::INFINITY, f64::min)
    }

    pub fn points(&self, t: &[u32; 4]) -> [DVec3; 4] {
        t.map(|v| self.pos[v as usize])
    }

    pub fn add_tet(&mut self, t: [u32; 4], region: i32) -> u32 {
        let [a, b, c, d] = self.points(&t);
        let q = self.objective.of(a, b, c, d);
        self.push_tet(t, region, q)
    }

    /// [`Self::add_tet`] with its objective `q` already known.
    fn push_tet(&mut self, t: [u32; 4], region: i32, q: f64) -> u32 {
        let id = match self.free.pop() {
            Some(id) => {
                self.tets[id as usize] = t;
                self.region[id as usize] = region;
                self.alive[id as usize] = true;
                self.q[id as usize] = q;
                id
            }
            None => {
                self.tets.push(t);
                self.region.push(region);
                self.alive.push(true);
                self.q.push(q);
                (self.tets.len() - 1) as u32
            }
        };
        for v in t {
            self.star[v as usize].push(id);
            self.touch(v);
        }
        id
    }

    /// Adds a vertex at `x` with an empty star; returns its id.
    pub fn add_vertex(&mut self, x: DVec3) -> u32 {
        self.pos.push(x);
        self.star.push(Vec::new());
        self.bstar.push(Vec::new());
        self.changed_at.push(self.epoch);
        (self.pos.len() - 1) as u32
    }

    pub fn kill_tet(&mut self, id: u32) {
        let t = self.tets[id as usize];
        for v in t {
            let s = &mut self.star[v as usize];
            if let Some(k) = s.iter().position(|&x| x == id) {
                s.swap_remove(k);
            }
            self.touch(v);
        }
        self.alive[id as usize] = false;
        self.free.push(id);
    }

    pub fn is_boundary_face(&self, f: [u32; 3]) -> bool {
        self.bmap.contains_key(&key3(f))
    }

    /// Replaces boundary triangle `i` by `f` (same marker and patch).
    pub fn replace_btri(&mut self, i: u32, f: [u32; 3]) {
        let old = self.btri[i as usize];
        self.bmap.remove(&key3(old));
        for v in old {
            let s = &mut self.bstar[v as usize];
            if let Some(k) = s.iter().position(|&x| x == i) {
                s.swap_remove(k);
            }
            self.touch(v);
        }
        self.btri[i as usize] = f;
        self.bmap.insert(key3(f), i);
        for v in f {
            self.bstar[v as usize].push(i);
            self.touch(v);
        }
    }

    /// Adds boundary triangle `f` with `marker` in `patch`; returns its index.
    pub fn add_btri(&mut self, f: [u32; 3], marker: i32, patch: u32) -> u32 {
        let i = self.btri.len() as u32;
        self.btri.push(f);
        self.bmarker.push(marker);
        self.bpatch.push(patch);
        self.bmap.insert(key3(f), i);
        for v in f {
            self.bstar[v as usize].push(i);
            self.touch(v);
        }
        i
    }

    /// Exact orientation test of a would-be tet.
    pub fn positive(&self, t: [u32; 4]) -> bool {
        let [a, b, c, d] = self.points(&t);
        orient3d(a, b, c, d) > 0.0
    }

    /// The tets around edge (a, b) in ring order, or `None` when they do not form one
    /// cycle or one path (a broken input).
    pub fn ring(&self, a: u32, b: u32) -> Option<Ring> {
        // (x, y, tet) with (a, b, x, y) positively ordered.
        note(&[a, b]);
        let mut links: Vec<(u32, u32, u32)> = Vec::with_capacity(12);
        let (sa, sb) = (&self.star[a as usize], &self.star[b as usize]);
        for &t in if sa.len() <= sb.len() { sa } else { sb } {
            let tv = &self.tets[t as usize];
            if !(tv.contains(&b) && tv.contains(&a)) {
                continue;
            }
            note(tv);
            let mut o = tv.iter().copied().filter(|&v| v != a && v != b);
            let (x, y) = (o.next()?, o.next()?);
            if even_perm(tv, [a, b, x, y]) {
                links.push((x, y, t));
            } else {
                links.push((y, x, t));
            }
        }
        let m = links.len();
        if m == 0 {
            return None;
        }
        // A start with no predecessor (a path); otherwise the smallest-id tet (a cycle).
        let start = (0..m)
            .find(|&i| !links.iter().any(|l| l.1 == links[i].0))
            .unwrap_or(0);
        let closed = links.iter().all(|l| links.iter().any(|k| k.1 == l.0));
        let mut ring = vec![links[start].0];
        let mut tets = Vec::with_capacity(m);
        let mut cur = start;
        loop {
            tets.push(links[cur].2);
            let y = links[cur].1;
            if y == ring[0] && tets.len() < m {
                return None; // several cycles
            }
            if tets.len() == m {
                if closed {
                    if y != ring[0] {
                        return None;
                    }
                } else {
                    ring.push(y);
                }
                break;
            }
            ring.push(y);
            cur = links.iter().position(|l| l.0 == y)?;
        }
        if !closed && links.iter().any(|l| l.1 == ring[0]) {
            return None;
        }
        Some(Ring { ring, tets, closed })
    }

    /// The (at most two) alive tets holding face `f`.
    pub fn face_tets(&self, f: [u32; 3]) -> ([u32; 2], usize) {
        let mut out = [DEAD; 2];
        let mut n = 0;
        note(&f);
        for &t in &self.star[f[0] as usize] {
            let tv = &self.tets[t as usize];
            if tv.contains(&f[1]) && tv.contains(&f[2]) {
                note(tv);
                if n < 2 {
                    out[n] = t;
                }
                n += 1;
            }
        }
        (out, n)
    }

    /// [`Work::to_mesh`], freeing the stars, maps and measures first: the output is built
    /// while only the tets are still held.
    pub fn into_mesh(mut self) -> TetMesh {
        self.star = Vec::new();
        self.bstar = Vec::new();
        self.bmap = FxHashMap::default();
        self.flat_edges = FxHashSet::default();
        self.q = Vec::new();
        self.rho_exempt = Vec::new();
        self.changed_at = Vec::new();
        self.free = Vec::new();
        self.to_mesh()
    }

    /// Back to a `TetMesh`: alive tets in slot order, boundary triangles in their order. The
    /// deleted vertices are dropped (later ones move down; the input's vertices, which are
    /// never deleted and come first, keep their ids).
    pub fn to_mesh(&self) -> TetMesh {
        let mut new_id: Vec<u32> = (0..self.pos.len() as u32).collect();
        let mut gone = vec![false; self.pos.len()];
        self.deleted.iter().for_each(|&v| gone[v as usize] = true);
        let mut vertices = Vec::with_capacity(self.pos.len() - self.deleted.len());
        for (v, &p) in self.pos.iter().enumerate() {
            new_id[v] = vertices.len() as u32;
            if !gone[v] {
                vertices.push(p);
            }
        }
        let map3 = |f: &[u32; 3]| f.map(|v| new_id[v as usize]);
        let mut m = TetMesh {
            vertices,
            boundary: self.btri.iter().map(map3).collect(),
            boundary_markers: self.bmarker.clone(),
            ..Default::default()
        };
        let n_alive = self.alive.iter().filter(|&&a| a).count();
        m.tets.reserve_exact(n_alive);
        m.tet_regions.reserve_exact(n_alive);
        for (i, t) in self.tets.iter().enumerate() {
            if self.alive[i] {
                m.tets.push(t.map(|v| new_id[v as usize]));
                m.tet_regions.push(self.region[i]);
            }
        }
        m
    }
}
