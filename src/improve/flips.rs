//! Topological transformations: edge removal (Shewchuk's dynamic programming over the ring
//! of the edge; the 3-2 and 4-4 flips are its rings of 3 and 4), the same over an open ring
//! whose two end faces are coplanar triangles of one facet patch (the boundary 2-2 flip, with
//! a flat tet on the facet as its ring of one), and face removal (the 2-3 flip, and the
//! multi-face removal that generalises it).
//!
//! A change is planned first and applied only when every new tet is positively oriented by
//! the exact `orient3d` and the worst objective of the new tets beats that of the old ones.
//! Positive orientation of all new tets is sufficient: they have the same outer faces as the
//! old ones, so (a degree argument) they tile the same polyhedron.

use super::topo::{edge_key, face, key3, Work, DEAD};
use super::Improver;

/// Longest ring edge removal considers (the table is O(n^3)).
const MAX_RING: usize = 12;
/// Most faces a multi-face removal takes out.
const MAX_SANDWICH: usize = 8;

/// A planned change, applied by [`Improver::apply`].
#[derive(Debug, PartialEq)]
pub(crate) struct Plan {
    /// Worst objective of the new tets (+inf when none is created).
    pub new_min: f64,
    kill: Vec<u32>,
    make: Vec<[u32; 4]>,
    region: i32,
    /// Boundary triangles replaced: (index, new triangle).
    boundary: Vec<(u32, [u32; 3])>,
    /// Boundary flip: the patch edge removed and the one made (`edge_key`s).
    diagonal: Option<(u64, u64)>,
    kind: Kind,
}

#[derive(Clone, Copy, PartialEq, Eq, Debug)]
pub(crate) enum Kind {
    EdgeRemoval,
    BoundaryFlip,
    FaceRemoval,
    MultiFaceRemoval,
}

/// The least of the old tets' objectives, and whether they all share one region.
fn old_min(w: &Work, tets: &[u32]) -> (f64, Option<i32>) {
    let r = w.region[tets[0] as usize];
    let same = tets.iter().all(|&t| w.region[t as usize] == r);
    (w.worst_q(tets), same.then_some(r))
}

/// The smallest gain that counts (keeps rounding noise from cycling).
pub(crate) const MIN_GAIN: f64 = 1e-9;

impl Improver<'_> {
    /// Objective of a would-be tet, or -inf when it is not positively oriented (exact test,
    /// only made for tets that could help).
    fn candidate(&self, t: [u32; 4], floor: f64) -> f64 {
        let [a, b, c, d] = self.w.points(&t);
        let q = self.w.objective.of(a, b, c, d);
        if q <= floor || !self.w.positive(t) {
            return f64::NEG_INFINITY;
        }
        q
    }

    /// Removal of edge (a, b): interior edges with a closed ring, or boundary edges inside one
    /// facet patch (open ring ending at the edge's two boundary triangles).
    pub(crate) fn plan_edge(&self, a: u32, b: u32) -> Option<Plan> {
        let w = &self.w;
        let ring = w.ring(a, b)?;
        let (old, region) = old_min(w, &ring.tets);
        let region = region?;
        let r = &ring.ring;
        let mut boundary = vec![];
        if ring.closed {
            if r.len() < 3 || r.len() > MAX_RING || r.iter().any(|&x| w.is_boundary_face([a, b, x]))
            {
                return None;
            }
        } else {
            boundary = self.open_ring_boundary(a, b, r)?;
            if r.len() == 2 {
                // A flat tet on the facet: its two other faces must have a tet beyond them.
                let (first, last) = (r[0], r[1]);
                for f in [[a, first, last], [b, first, last]] {
                    if w.face_tets(f).1 != 2 || w.is_boundary_face(f) {
                        return None;
                    }
                }
                return Some(Plan {
                    new_min: f64::INFINITY,
                    kill: ring.tets,
                    make: vec![],
                    region,
                    boundary,
                    diagonal: Some((edge_key(a, b), edge_key(first, last))),
                    kind: Kind::BoundaryFlip,
                });
            }
        }
        let floor = old + MIN_GAIN;
        let n = r.len();
        // best[i][j]: the best worst objective triangulating polygon r[i..=j]; split[i][j] its apex.
        let mut best = [[f64::INFINITY; MAX_RING]; MAX_RING];
        let mut split = [[0u8; MAX_RING]; MAX_RING];
        for gap in 2..n {
            for i in 0..n - gap {
                let j = i + gap;
                let mut top = f64::NEG_INFINITY;
                for k in i + 1..j {
                    let sub = best[i][k].min(best[k][j]);
                    if sub <= top || sub <= floor {
                        continue;
                    }
                    let up = self.candidate([r[i], r[k], r[j], b], floor.max(top));
                    if up <= top {
                        continue;
                    }
                    let down = self.candidate([r[k], r[i], r[j], a], floor.max(top));
                    let v = sub.min(up).min(down);
                    if v > top {
                        top = v;
                        split[i][j] = k as u8;
                    }
                }
                best[i][j] = top;
            }
        }
        let new_min = best[0][n - 1];
        if new_min <= floor {
            return None;
        }
        let mut make = Vec::with_capacity(2 * (n - 2));
        let mut stack = vec![(0usize, n - 1)];
        while let Some((i, j)) = stack.pop() {
            if j < i + 2 {
                continue;
            }
            let k = split[i][j] as usize;
            make.push([r[i], r[k], r[j], b]);
            make.push([r[k], r[i], r[j], a]);
            stack.push((i, k));
            stack.push((k, j));
        }
        Some(Plan {
            new_min,
            kill: ring.tets,
            make,
            region,
            diagonal: (!ring.closed).then(|| (edge_key(a, b), edge_key(r[0], r[n - 1]))),
            boundary,
            kind: if ring.closed {
                Kind::EdgeRemoval
            } else {
                Kind::BoundaryFlip
            },
        })
    }

    /// For the open ring `r` of boundary edge (a, b): the two boundary triangles that replace
    /// (a, b, first) and (a, b, last) when the edge is removed, if it is a flat edge of one
    /// patch, the ring is short enough, and no inner ring face is a boundary triangle.
    fn open_ring_boundary(&self, a: u32, b: u32, r: &[u32]) -> Option<Vec<(u32, [u32; 3])>> {
        let w = &self.w;
        let k = r.len() - 1;
        if k + 1 > MAX_RING || !w.flat_edges.contains(&edge_key(a, b)) {
            return None;
        }
        let (first, last) = (r[0], r[k]);
        let t1 = *w.bmap.get(&key3([a, b, first]))?;
        let t2 = *w.bmap.get(&key3([a, b, last]))?;
        if w.bpatch[t1 as usize] == DEAD || w.bpatch[t1 as usize] != w.bpatch[t2 as usize] {
            return None;
        }
        if r[1..k].iter().any(|&x| w.is_boundary_face([a, b, x])) {
            return None;
        }
        self.flipped_triangles(a, b, first, last, t1, t2)
    }

    /// The two triangles replacing boundary triangles t1 = (a, b, p) and t2 = (a, b, q) of one
    /// patch when the diagonal ab of the quad a-p-b-q becomes pq: oriented like the old ones
    /// with respect to the patch normal, and only when the quad is strictly convex.
    fn flipped_triangles(
        &self,
        a: u32,
        b: u32,
        p: u32,
        q: u32,
        t1: u32,
        t2: u32,
    ) -> Option<Vec<(u32, [u32; 3])>> {
        let w = &self.w;
        let n = self.normals[w.bpatch[t1 as usize] as usize];
        let side = |f: [u32; 3]| {
            let [x, y, z] = f.map(|v| w.p(v));
            (y - x).cross(z - x).dot(n)
        };
        let s1 = side(w.btri[t1 as usize]).signum();
        let s2 = side(w.btri[t2 as usize]).signum();
        if s1 != s2 || s1 == 0.0 {
            return None;
        }
        // Both diagonals cross: a, b on opposite sides of pq, p, q of ab (in the plane).
        let (sa, sb) = (side([p, q, a]), side([p, q, b]));
        let (sp, sq) = (side([a, b, p]), side([a, b, q]));
        if !(sa * sb < 0.0 && sp * sq < 0.0) {
            return None;
        }
        let orient = |f: [u32; 3]| {
            if side(f).signum() == s1 {
                f
            } else {
                [f[0], f[2], f[1]]
            }
        };
        Some(vec![(t1, orient([p, q, a])), (t2, orient([p, q, b]))])
    }

    /// Face removal from interior face f, whose two tets have apexes d and e: the faces
    /// sandwiched between d and e (f, then faces joined to it across an edge, each the base of
    /// a tet with apex d and one with apex e) are removed and the tets they bound become tets
    /// around the new edge de, one per edge of the sandwich's outline. One face is the 2-3
    /// flip; more is Klingner & Shewchuk's multi-face removal. The sandwich grows greedily
    /// across the outline edge of the worst new tet; the best stage is kept.
    pub(crate) fn plan_faces(&self, f: [u32; 3]) -> Option<Plan> {
        let w = &self.w;
        if w.is_boundary_face(f) {
            return None;
        }
        let (pair, n) = w.face_tets(f);
        if n != 2 {
            return None;
        }
        let region = old_min(w, &pair).1?;
        let apex = |t: u32| w.tets[t as usize].into_iter().find(|v| !f.contains(v));
        let (d, e) = (apex(pair[0])?, apex(pair[1])?);
        let [mut a, mut b, c] = f;
        let t1 = w.tets[pair[0] as usize];
        if !super::topo::even_perm(&t1, [a, b, c, d]) {
            std::mem::swap(&mut a, &mut b);
        }
        // The outline, directed so that (x, y, e, d) is the new tet of edge (x, y).
        let mut outline = vec![(a, b), (b, c), (c, a)];
        // Float objectives while growing; the exact orientation test is made for a stage
        // about to be kept.
        let q_of = |t: [u32; 4]| {
            let [p, q, r, s] = w.points(&t);
            w.objective.of(p, q, r, s)
        };
        let mut q: Vec<f64> = outline.iter().map(|&(x, y)| q_of([x, y, e, d])).collect();
        let mut kill = pair.to_vec();
        let mut best: Option<Plan> = None;
        loop {
            let new_min = q.iter().copied().fold(f64::INFINITY, f64::min);
            if new_min > w.worst_q(&kill) + MIN_GAIN
                && best.as_ref().is_none_or(|b| new_min > b.new_min)
                && outline.iter().all(|&(x, y)| w.positive([x, y, e, d]))
            {
                best = Some(Plan {
                    new_min,
                    kill: kill.clone(),
                    make: outline.iter().map(|&(x, y)| [x, y, e, d]).collect(),
                    region,
                    boundary: vec![],
                    diagonal: None,
                    kind: if kill.len() == 2 {
                        Kind::FaceRemoval
                    } else {
                        Kind::MultiFaceRemoval
                    },
                });
            }
            if kill.len() >= 2 * MAX_SANDWICH {
                break;
            }
            let mut order: Vec<usize> = (0..outline.len()).collect();
            order.sort_by(|&i, &j| q[i].total_cmp(&q[j]).then(i.cmp(&j)));
            let Some((k, v, tets)) = order.iter().find_map(|&k| {
                let (x, y) = outline[k];
                self.sandwiched(x, y, d, e, region, &kill)
                    .filter(|&(v, _)| outline.iter().all(|&(p, _)| p != v))
                    .map(|(v, tets)| (k, v, tets))
            }) else {
                break;
            };
            let (x, y) = outline[k];
            outline.splice(k..=k, [(x, v), (v, y)]);
            q.splice(k..=k, [q_of([x, v, e, d]), q_of([v, y, e, d])]);
            kill.extend(tets);
        }
        best
    }

    /// The face (x, y, v) beyond outline edge (x, y) of a sandwich between d and e, if it is
    /// sandwiched too: an interior face whose two tets, both of `region` and not yet in
    /// `kill`, have apexes d and e. Returns v and those two tets.
    fn sandwiched(
        &self,
        x: u32,
        y: u32,
        d: u32,
        e: u32,
        region: i32,
        kill: &[u32],
    ) -> Option<(u32, [u32; 2])> {
        let w = &self.w;
        let fd = [x, y, d];
        if w.is_boundary_face(fd) {
            return None;
        }
        let (pair, n) = w.face_tets(fd);
        let td = *pair.iter().find(|t| !kill.contains(t))?;
        if n != 2 || w.region[td as usize] != region {
            return None;
        }
        let v = w.tets[td as usize]
            .into_iter()
            .find(|&u| u != x && u != y && u != d)?;
        let g = [x, y, v];
        if v == e || w.is_boundary_face(g) || w.is_boundary_face([x, y, e]) {
            return None;
        }
        let (pair, n) = w.face_tets(g);
        let te = if pair[0] == td { pair[1] } else { pair[0] };
        if n != 2
            || te == DEAD
            || kill.contains(&te)
            || w.region[te as usize] != region
            || !w.tets[te as usize].contains(&e)
        {
            return None;
        }
        Some((v, [td, te]))
    }

    /// Carries a plan out; returns the new tets.
    pub(crate) fn apply(&mut self, plan: Plan) -> Vec<u32> {
        for &t in &plan.kill {
            self.w.kill_tet(t);
        }
        let made: Vec<u32> = plan
            .make
            .iter()
            .map(|&t| self.w.add_tet(t, plan.region))
            .collect();
        for &(i, f) in &plan.boundary {
            self.w.replace_btri(i, f);
        }
        if let Some((gone, new)) = plan.diagonal {
            // The removed diagonal leaves the patch, the new one joins it.
            self.w.flat_edges.remove(&gone);
            self.w.flat_edges.insert(new);
        }
        match plan.kind {
            Kind::EdgeRemoval => self.stats.edge_removals += 1,
            Kind::BoundaryFlip => self.stats.boundary_flips += 1,
            Kind::FaceRemoval => self.stats.face_removals += 1,
            Kind::MultiFaceRemoval => self.stats.multi_face_removals += 1,
        }
        made
    }

    /// Every plan touching tet t (its six edges, four faces), best first.
    pub(crate) fn best_plan(&self, t: u32) -> Option<Plan> {
        let tv = self.w.tets[t as usize];
        let mut best: Option<Plan> = None;
        let mut consider = |p: Option<Plan>| {
            if let Some(p) = p {
                if best.as_ref().is_none_or(|b| p.new_min > b.new_min)
                    && self.keeps_rho(&p.kill, p.make.iter().map(|t| self.w.points(t)))
                {
                    best = Some(p);
                }
            }
        };
        for i in 0..4 {
            for j in i + 1..4 {
                consider(self.plan_edge(tv[i], tv[j]));
            }
        }
        for i in 0..4 {
            consider(self.plan_faces(face(tv, i)));
        }
        best
    }
}
