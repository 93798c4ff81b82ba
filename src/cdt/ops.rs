//! The triangulation's internals: vertex placement, splits and flips, legalization, the
//! visibility walk, and constrained-edge recovery (Sloan's flips).

use super::*;

impl FacetMesh {
    /// Slots of the facet's triangles.
    pub(super) fn facet_tris(&self) -> impl Iterator<Item = u32> + '_ {
        (0..self.tris.len() as u32).filter(|&t| self.tris[t as usize].inside())
    }

    pub(super) fn proj(&self, p: DVec3) -> DVec2 {
        DVec2::new(p[self.axes[0]], p[self.axes[1]])
    }

    pub(super) fn add_vertex(&mut self, id: u32, p: DVec3) -> u32 {
        let l = self.gid.len() as u32;
        self.gid.push(id);
        self.p3.push(p);
        self.p2.push(self.proj(p));
        self.vtri.push(NONE);
        if id != NONE {
            self.local.insert(id, l);
        }
        l
    }

    /// Adds vertex `id` at `p` in the triangle or on the edge `loc`; returns its local index and
    /// the triangles around it.
    pub(super) fn place(&mut self, loc: Loc, id: u32, p: DVec3) -> (u32, Vec<u32>) {
        let l = self.add_vertex(id, p);
        match loc {
            Loc::In(t) => (l, self.split_tri(t, l).to_vec()),
            Loc::Edge(t, i) => (l, self.split_edge_at(t, i, l)),
            _ => unreachable!("place: {loc:?}"),
        }
    }

    /// The vertex across neighbour reference `r` (the apex of the other triangle).
    pub(super) fn apex(&self, r: u32) -> u32 {
        self.tris[(r / 3) as usize].v[(r % 3) as usize]
    }

    /// A triangle's global ids, canonical.
    pub(super) fn gtri(&self, t: u32) -> [u32; 3] {
        canon(self.tris[t as usize].v.map(|v| self.gid[v as usize]))
    }

    /// Exact "d strictly inside the circle of ccw (a, b, c)" through the lifting from `eye`,
    /// for d across edge (b, c). Symmetric: equals "a inside the circle of (d, c, b)". It reads
    /// the sign from a triangle whose lifted tet is positive; a nearly flat triangle of points
    /// off the plane may have a non-positive one, and if both do the edge is left as it is.
    pub(super) fn incircle(&self, a: u32, b: u32, c: u32, d: u32) -> bool {
        let [a, b, c, d] = [a, b, c, d].map(|v| self.p3[v as usize]);
        if orient3d(a, b, c, self.eye) > 0.0 {
            insphere(a, b, c, self.eye, d) > 0.0
        } else {
            orient3d(d, c, b, self.eye) > 0.0 && insphere(d, c, b, self.eye, a) > 0.0
        }
    }

    /// Whether replacing diagonal (x, y) of the quad (c, x, d, y) by (c, d) gives two ccw
    /// triangles (c, x, d), (d, y, c).
    pub(super) fn convex(&self, c: u32, x: u32, y: u32, d: u32) -> bool {
        let [c, x, y, d] = [c, x, y, d].map(|v| self.p2[v as usize]);
        orient2d(c, x, d) > 0.0 && orient2d(d, y, c) > 0.0
    }

    /// Sets neighbour `i` of `t` to `r` and the back reference.
    pub(super) fn set_nb(&mut self, t: u32, i: usize, r: u32) {
        self.tris[t as usize].n[i] = r;
        if r != NONE {
            self.tris[(r / 3) as usize].n[(r % 3) as usize] = t * 3 + i as u32;
        }
    }

    /// Overwrites triangle `t` (neighbours unset) and points its vertices at it.
    pub(super) fn put(&mut self, t: u32, v: [u32; 3], f: u8) {
        self.tris[t as usize] = Tri { v, n: [NONE; 3], f };
        for w in v {
            self.vtri[w as usize] = t;
        }
    }

    pub(super) fn new_tri(&mut self) -> u32 {
        self.tris.push(Tri::default());
        (self.tris.len() - 1) as u32
    }

    /// Renumbers `t` so that its old index `i` becomes 0.
    pub(super) fn rotate(&mut self, t: u32, i: usize) {
        if i == 0 {
            return;
        }
        let o = self.tris[t as usize];
        let mut r = Tri {
            v: [0; 3],
            n: [0; 3],
            f: o.f & INSIDE,
        };
        for k in 0..3 {
            let s = (k + i) % 3;
            r.v[k] = o.v[s];
            r.n[k] = o.n[s];
            r.f |= ((o.f >> s) & 1) << k;
        }
        self.tris[t as usize] = r;
        for k in 0..3 {
            self.set_nb(t, k, r.n[k]);
        }
    }

    /// Splits triangle `t` into three around local vertex `p`; returns them.
    pub(super) fn split_tri(&mut self, t: u32, p: u32) -> [u32; 3] {
        let o = self.tris[t as usize];
        let ids = [t, self.new_tri(), self.new_tri()];
        for k in 0..3 {
            let mut v = o.v;
            v[k] = p;
            self.put(ids[k], v, (o.f & INSIDE) | (o.f & (1 << k)));
        }
        for k in 0..3 {
            self.set_nb(ids[k], k, o.n[k]);
            for j in 0..3 {
                if j != k {
                    self.tris[ids[k] as usize].n[j] = ids[j] * 3 + k as u32;
                }
            }
        }
        ids
    }

    /// Splits edge `i` of `t` (and the triangle across) at local vertex `p`; returns the new
    /// triangles (2 or 4).
    pub(super) fn split_edge_at(&mut self, t: u32, i: usize, p: u32) -> Vec<u32> {
        self.rotate(t, i);
        let tv = self.tris[t as usize];
        let (r, [a, x, y]) = (tv.n[0], tv.v);
        let c = tv.f & 1;
        let t2 = self.new_tri();
        self.put(t, [a, x, p], (tv.f & INSIDE) | c | (tv.f & 4));
        self.put(t2, [a, p, y], (tv.f & INSIDE) | c | (tv.f & 2));
        self.set_nb(t, 2, tv.n[2]);
        self.set_nb(t2, 1, tv.n[1]);
        self.set_nb(t, 1, t2 * 3 + 2);
        if r == NONE {
            return vec![t, t2];
        }
        let u = r / 3;
        self.rotate(u, (r % 3) as usize);
        let uv = self.tris[u as usize]; // [b, y, x]
        let b = uv.v[0];
        let u2 = self.new_tri();
        self.put(u, [b, y, p], (uv.f & INSIDE) | c | (uv.f & 4));
        self.put(u2, [b, p, x], (uv.f & INSIDE) | c | (uv.f & 2));
        self.set_nb(u, 2, uv.n[2]);
        self.set_nb(u2, 1, uv.n[1]);
        self.set_nb(u, 1, u2 * 3 + 2);
        self.set_nb(u, 0, t2 * 3);
        self.set_nb(u2, 0, t * 3);
        vec![t, t2, u, u2]
    }

    /// Flips edge `i` of `t`: (a, x, y) + (b, y, x) become (a, x, b) + (b, y, a) in the same
    /// slots; returns the other slot. The caller checks convexity and the constraint.
    pub(super) fn flip_at(&mut self, t: u32, i: usize) -> u32 {
        self.rotate(t, i);
        let r = self.tris[t as usize].n[0];
        let u = r / 3;
        self.rotate(u, (r % 3) as usize);
        let (tv, uv) = (self.tris[t as usize], self.tris[u as usize]);
        let [a, x, y] = tv.v;
        let b = uv.v[0];
        let bit = |f: u8, k: usize| (f >> k) & 1;
        let ft = (tv.f & INSIDE) | bit(uv.f, 1) | (bit(tv.f, 2) << 2);
        let fu = (uv.f & INSIDE) | bit(tv.f, 1) | (bit(uv.f, 2) << 2);
        self.put(t, [a, x, b], ft);
        self.put(u, [b, y, a], fu);
        self.set_nb(t, 0, uv.n[1]);
        self.set_nb(t, 2, tv.n[2]);
        self.set_nb(u, 0, tv.n[1]);
        self.set_nb(u, 2, uv.n[2]);
        self.set_nb(t, 1, u * 3 + 1);
        u
    }

    /// Whether edge `i` of `t` is non-constrained, not locally Delaunay and flippable.
    pub(super) fn should_flip(&self, t: u32, i: usize) -> bool {
        let tr = self.tris[t as usize];
        if tr.cons(i) || tr.n[i] == NONE {
            return false;
        }
        let (c, x, y, d) = (tr.v[i], tr.v[nx(i)], tr.v[pv(i)], self.apex(tr.n[i]));
        self.incircle(c, x, y, d) && self.convex(c, x, y, d)
    }

    /// Lawson flips around the new vertex `p`, starting from triangles holding it; records the
    /// facet triangles flipped away (they never hold `p`, so they pre-existed).
    pub(super) fn legalize(&mut self, p: u32, mut stack: Vec<u32>, removed: &mut Vec<[u32; 3]>) {
        // Safety net only: with a consistent lifting the flips terminate long before this.
        let mut budget = 4 * self.tris.len() + 64;
        while let Some(t) = stack.pop() {
            let Some(k) = self.tris[t as usize].find(p) else {
                continue;
            };
            if budget == 0 || !self.should_flip(t, k) {
                continue;
            }
            budget -= 1;
            let u = self.tris[t as usize].n[k] / 3;
            if self.tris[u as usize].inside() {
                removed.push(self.gtri(u));
            }
            self.flip_at(t, k);
            stack.push(t);
            stack.push(u);
        }
    }

    /// Lawson flips after an insertion, then the Change (added = facet triangles around `l`).
    pub(super) fn finish(&mut self, l: u32, new: Vec<u32>, mut removed: Vec<[u32; 3]>) -> Change {
        self.legalize(l, new, &mut removed);
        self.hint = self.vtri[l as usize];
        let added = self.star(l);
        Change { removed, added }
    }

    /// The facet triangles (global ids) around local vertex `l`.
    pub(super) fn star(&self, l: u32) -> Vec<[u32; 3]> {
        let mut out = Vec::new();
        self.find_in_star(l, |t, _| {
            if self.tris[t as usize].inside() {
                out.push(self.gtri(t));
            }
            false
        });
        out
    }

    /// Visits the triangles around local vertex `v` as (triangle, index of v) until `f` says
    /// stop; returns where it stopped.
    pub(super) fn find_in_star(
        &self,
        v: u32,
        mut f: impl FnMut(u32, usize) -> bool,
    ) -> Option<(u32, usize)> {
        let t0 = self.vtri[v as usize];
        let k0 = self.tris[t0 as usize].find(v).expect("vertex index");
        let (mut t, mut k) = (t0, k0);
        loop {
            if f(t, k) {
                return Some((t, k));
            }
            let r = self.tris[t as usize].n[nx(k)]; // counter-clockwise
            if r == NONE {
                break;
            }
            (t, k) = (r / 3, nx((r % 3) as usize));
            if t == t0 {
                return None;
            }
        }
        // Open star (a super-triangle vertex): go clockwise from the start too.
        (t, k) = (t0, k0);
        loop {
            let r = self.tris[t as usize].n[pv(k)];
            if r == NONE {
                return None;
            }
            (t, k) = (r / 3, pv((r % 3) as usize));
            if f(t, k) {
                return Some((t, k));
            }
        }
    }

    /// Edge between local vertices a and b as (triangle, edge index), if it exists.
    pub(super) fn find_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let (t, k) = self.find_in_star(a, |t, k| {
            let v = self.tris[t as usize].v;
            v[nx(k)] == b || v[pv(k)] == b
        })?;
        let v = self.tris[t as usize].v;
        Some((t, if v[nx(k)] == b { pv(k) } else { nx(k) }))
    }

    /// Edge (a, b) by global ids, if it is an edge with a facet triangle on one side.
    pub(super) fn facet_edge(&self, a: u32, b: u32) -> Option<(u32, usize)> {
        let (&la, &lb) = (self.local.get(&a)?, self.local.get(&b)?);
        let (t, i) = self.find_edge(la, lb)?;
        let r = self.tris[t as usize].n[i];
        let inside = |s: u32| self.tris[s as usize].inside();
        (inside(t) || (r != NONE && inside(r / 3))).then_some((t, i))
    }

    /// Stochastic visibility walk from the hint to projected point q.
    pub(super) fn walk(&self, q: DVec2) -> Loc {
        self.walk_from(self.hint, q)
    }

    /// Stochastic visibility walk from triangle `start` to projected point q.
    pub(super) fn walk_from(&self, start: u32, q: DVec2) -> Loc {
        let (mut t, mut came) = (start, 3);
        let mut rng = (q.x.to_bits() ^ q.y.to_bits().rotate_left(29)) as u32 | 1;
        for _ in 0..4 * self.tris.len() + 64 {
            let tr = self.tris[t as usize];
            rng ^= rng << 13;
            rng ^= rng >> 17;
            rng ^= rng << 5;
            let s = (rng % 3) as usize;
            let mut zero = [false; 3];
            let mut next = None;
            for m in 0..3 {
                let i = (s + m) % 3;
                if i == came {
                    continue;
                }
                let o = self.side(&tr, i, q);
                if o < 0.0 {
                    next = Some(i);
                    break;
                }
                zero[i] = o == 0.0;
            }
            match next {
                Some(i) => {
                    if tr.n[i] == NONE {
                        return Loc::Outside;
                    }
                    (t, came) = (tr.n[i] / 3, (tr.n[i] % 3) as usize);
                }
                None => return Self::classify(t, zero),
            }
        }
        // Unreachable in practice (the stochastic walk terminates); scan as a fallback.
        for (t, tr) in self.tris.iter().enumerate() {
            let o = [0, 1, 2].map(|i| self.side(tr, i, q));
            if o.iter().all(|&x| x >= 0.0) {
                return Self::classify(t as u32, o.map(|x| x == 0.0));
            }
        }
        Loc::Outside
    }

    /// orient2d of edge `i` of `tr` (as the triangle runs) and q: > 0 on the triangle's side.
    pub(super) fn side(&self, tr: &Tri, i: usize, q: DVec2) -> f64 {
        let [a, b] = [nx(i), pv(i)].map(|k| self.p2[tr.v[k] as usize]);
        orient2d(a, b, q)
    }

    /// Global ids of edge `i` of `tr`, smaller first.
    pub(super) fn edge_ids(&self, tr: &Tri, i: usize) -> [u32; 2] {
        let [a, b] = [nx(i), pv(i)].map(|k| self.gid[tr.v[k] as usize]);
        [a.min(b), a.max(b)]
    }

    pub(super) fn classify(t: u32, zero: [bool; 3]) -> Loc {
        let pos = |z: bool| zero.iter().position(|&x| x == z).unwrap();
        match zero.iter().filter(|&&z| z).count() {
            0 => Loc::In(t),
            1 => Loc::Edge(t, pos(true)),
            _ => Loc::Vertex(t, pos(false)),
        }
    }

    /// Recovers the constrained edge between local vertices a and b; returns the chain of
    /// vertices along it (split at vertices lying exactly on it).
    pub(super) fn recover(&mut self, a: u32, b: u32) -> Result<Vec<u32>, String> {
        let mut chain = vec![a];
        let mut s = a;
        while s != b {
            let (e, cross) = self.trace(s, b)?;
            if !cross.is_empty() {
                self.flip_out(s, e, cross)?;
            }
            let (t, i) = self.find_edge(s, e).ok_or("internal: lost edge")?;
            self.tris[t as usize].f |= 1 << i;
            let r = self.tris[t as usize].n[i];
            self.tris[(r / 3) as usize].f |= 1 << (r % 3);
            chain.push(e);
            s = e;
        }
        Ok(chain)
    }

    /// From vertex s towards b: the first vertex met (b, or one exactly on the segment) and
    /// the edges crossed before it, as (right, left) pairs.
    pub(super) fn trace(&self, s: u32, b: u32) -> Result<(u32, Vec<(u32, u32)>), String> {
        let (ps, pb) = (self.p2[s as usize], self.p2[b as usize]);
        let mut hit = None;
        let start = self.find_in_star(s, |t, k| {
            let tr = &self.tris[t as usize];
            let (v1, v2) = (tr.v[nx(k)], tr.v[pv(k)]);
            let o1 = orient2d(ps, self.p2[v1 as usize], pb);
            let o2 = orient2d(ps, self.p2[v2 as usize], pb);
            if o2 < 0.0 && o1 == 0.0 {
                hit = Some(v1);
            }
            o2 < 0.0 && o1 >= 0.0
        });
        if let Some(h) = hit {
            return Ok((h, Vec::new()));
        }
        let (mut t, mut e) = start.ok_or("internal: constraint direction not found")?;
        let mut cross = Vec::new();
        loop {
            let tr = self.tris[t as usize];
            let (v1, v2) = (tr.v[nx(e)], tr.v[pv(e)]);
            if tr.cons(e) {
                let [s, b, v1, v2] = [s, b, v1, v2].map(|v| self.gid[v as usize]);
                return Err(format!("polygon edges cross: ({s}, {b}) and ({v1}, {v2})"));
            }
            cross.push((v1, v2));
            let r = tr.n[e];
            ensure!(r != NONE, "internal: constraint left the super-triangle");
            let (u, j, w) = (r / 3, (r % 3) as usize, self.apex(r));
            if w == b {
                return Ok((b, cross));
            }
            let ow = orient2d(ps, pb, self.p2[w as usize]);
            if ow == 0.0 {
                return Ok((w, cross));
            }
            // u = (w, v2, v1): keep crossing through (v1, w) or (w, v2).
            (t, e) = (u, if ow > 0.0 { nx(j) } else { pv(j) });
        }
    }

    /// Sloan's edge recovery: flips the edges crossing segment (s, e) until none is left.
    pub(super) fn flip_out(
        &mut self,
        s: u32,
        e: u32,
        cross: Vec<(u32, u32)>,
    ) -> Result<(), String> {
        let (ps, pe) = (self.p2[s as usize], self.p2[e as usize]);
        let mut queue: VecDeque<(u32, u32)> = cross.into();
        let mut stall = 0;
        while let Some((x, y)) = queue.pop_front() {
            let (t, i) = self.find_edge(x, y).ok_or("internal: lost edge")?;
            let tr = self.tris[t as usize];
            let (c, d) = (tr.v[i], self.apex(tr.n[i]));
            if self.convex(c, tr.v[nx(i)], tr.v[pv(i)], d) {
                self.flip_at(t, i);
                stall = 0;
                let oc = orient2d(ps, pe, self.p2[c as usize]);
                let od = orient2d(ps, pe, self.p2[d as usize]);
                if (oc > 0.0 && od < 0.0) || (oc < 0.0 && od > 0.0) {
                    queue.push_back((c, d));
                }
            } else {
                queue.push_back((x, y));
                stall += 1;
                ensure!(stall <= queue.len(), "internal: edge recovery stalled");
            }
        }
        Ok(())
    }

    /// Lawson flips over the whole triangulation (after edge recovery). Flips reuse the two
    /// triangle slots, so a stack of slots stays valid; a flipped pair is checked again.
    pub(super) fn make_cdt(&mut self) -> Result<(), String> {
        let mut stack: Vec<u32> = (0..self.tris.len() as u32).collect();
        let mut budget = self.tris.len().saturating_mul(self.tris.len()) + 10_000;
        while let Some(t) = stack.pop() {
            if let Some(i) = (0..3).find(|&i| self.should_flip(t, i)) {
                ensure!(budget > 0, "internal: too many flips");
                budget -= 1;
                stack.extend([t, self.flip_at(t, i)]);
            }
        }
        Ok(())
    }
}
