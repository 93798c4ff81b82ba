//! Vertex smoothing that maximises the worst objective of the vertex's star (Klingner &
//! Shewchuk's non-smooth optimisation, after Freitag et al.): the search direction is the
//! point of least norm in the convex hull of the gradients of the (nearly) worst tets, so a
//! step along it raises all of them; the step is halved until the worst improves.
//!
//! A boundary vertex moves only within its constraint (facet plane or segment line): the
//! displacement is projected, never the position, so the vertex keeps its offset from the
//! plane to rounding. A move is kept only if every tet of the star stays positively oriented
//! by the exact `orient3d` and every boundary triangle around the vertex keeps its side.

use super::batch::note;
use super::constraints::{on_hull, Constraint};
use super::flips::MIN_GAIN;
use super::quality::Objective;
use super::topo::DEAD;
use super::Improver;
use crate::geom::orient3d;
use glam::DVec3;

/// Gradient steps per smoothing of one vertex.
const MAX_STEPS: usize = 8;
/// Smallest gain of the star's worst objective for a move to be kept.
const SMOOTH_GAIN: f64 = 1e-5;
/// Tets within this of the worst are taken as active.
const ACTIVE: f64 = 1e-3;

/// What smoothing a vertex would do ([`Improver::plan_smoothing`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub(crate) enum Smoothing {
    /// Nothing: no move gains enough, or none is valid.
    Stays,
    /// The vertex turns out to be on the hull: it is fixed from now on, unmoved.
    Fix,
    /// It moves here.
    Move(DVec3),
}

/// The objective of star tet `t` (vertex ids) with vertex `v` at `x`.
#[inline]
fn q_at(pos: &[DVec3], objective: Objective, t: &[u32; 4], v: u32, x: DVec3) -> f64 {
    let p = t.map(|u| if u == v { x } else { pos[u as usize] });
    objective.of(p[0], p[1], p[2], p[3])
}

/// The point of least norm in the convex hull of `g` (Frank-Wolfe; exact for two points).
fn min_norm(g: &[DVec3]) -> DVec3 {
    match g.len() {
        0 => DVec3::ZERO,
        1 => g[0],
        _ => {
            let mut x = g[0];
            for _ in 0..32 {
                // The vertex minimising <x, g_i>, then the exact line search on [x, g_i].
                let s = *g
                    .iter()
                    .min_by(|a, b| a.dot(x).total_cmp(&b.dot(x)))
                    .unwrap_or(&x);
                let d = s - x;
                let dd = d.length_squared();
                if dd <= 0.0 {
                    break;
                }
                let t = (-x.dot(d) / dd).clamp(0.0, 1.0);
                if t <= 0.0 {
                    break;
                }
                x += d * t;
            }
            x
        }
    }
}

impl Improver<'_> {
    /// Worst objective of v's star with v at x.
    pub(crate) fn star_min(&self, star: &[[u32; 4]], v: u32, x: DVec3) -> f64 {
        star.iter()
            .map(|t| q_at(&self.w.pos, self.w.objective, t, v, x))
            .fold(f64::INFINITY, f64::min)
    }

    /// The worst objective of v's star with v at x if it beats `floor`, else `None`, found
    /// with the tets in `order` (indices into `star`; the worst ones first, so that a failing
    /// trial stops early). The value is `star_min`'s whenever it is returned.
    fn star_min_above(
        &self,
        star: &[[u32; 4]],
        order: &[usize],
        v: u32,
        x: DVec3,
        floor: f64,
    ) -> Option<f64> {
        let mut worst = f64::INFINITY;
        for &k in order {
            worst = worst.min(q_at(&self.w.pos, self.w.objective, &star[k], v, x));
            if worst <= floor {
                return None;
            }
        }
        Some(worst)
    }

    /// The non-smooth ascent of the worst objective of `star` (tets holding vertex `v`, which
    /// starts at `x0` with worst objective `q0`) within constraint `cons`: the position
    /// reached and its worst objective. Only the positions of the other vertices are read,
    /// so `v` may be a vertex not yet in the mesh.
    pub(crate) fn ascend(
        &self,
        star: &[[u32; 4]],
        v: u32,
        x0: DVec3,
        q0: f64,
        cons: Constraint,
    ) -> (DVec3, f64) {
        // Length scale: the mean edge length at v.
        let mut scale = 0.0;
        let mut count = 0.0;
        let mut centroid = DVec3::ZERO;
        for t in star {
            for &u in t {
                if u != v {
                    scale += self.w.p(u).distance(x0);
                    centroid += self.w.p(u);
                    count += 1.0;
                }
            }
        }
        let scale = scale / count;
        let mut x = x0;
        let mut qx = q0;

        // A first guess: the centroid of the neighbours (within the constraint).
        let guess = x0 + cons.project(centroid / count - x0);
        let mut order: Vec<usize> = (0..star.len()).collect();
        if let Some(qg) = self.star_min_above(star, &order, v, guess, qx + MIN_GAIN) {
            x = guess;
            qx = qg;
        }

        let h = 1e-7 * scale;
        for _ in 0..MAX_STEPS {
            let qs: Vec<f64> = star
                .iter()
                .map(|t| q_at(&self.w.pos, self.w.objective, t, v, x))
                .collect();
            let worst = qs.iter().copied().fold(f64::INFINITY, f64::min);
            order.sort_by(|&a, &b| qs[a].total_cmp(&qs[b]));
            let mut grads = vec![];
            for (t, &q) in star.iter().zip(&qs) {
                if q > worst + ACTIVE || grads.len() >= 6 {
                    continue;
                }
                let g = DVec3::new(
                    q_at(&self.w.pos, self.w.objective, t, v, x + DVec3::X * h) - q,
                    q_at(&self.w.pos, self.w.objective, t, v, x + DVec3::Y * h) - q,
                    q_at(&self.w.pos, self.w.objective, t, v, x + DVec3::Z * h) - q,
                ) / h;
                grads.push(cons.project(g));
            }
            let d = min_norm(&grads);
            let dl = d.length();
            if dl * scale <= 1e-9 || !dl.is_finite() {
                break;
            }
            let dir = cons.project(d / dl);
            // First step: where the linear model of the worst tet gains 0.5 (capped).
            let mut step = (0.5 / dl).min(0.3 * scale);
            let mut moved = false;
            for _ in 0..10 {
                let y = x + dir * step;
                if let Some(qy) = self.star_min_above(star, &order, v, y, qx + MIN_GAIN) {
                    x = y;
                    qx = qy;
                    moved = true;
                    break;
                }
                step *= 0.5;
            }
            if !moved {
                break;
            }
        }
        (x, qx)
    }

    /// Where smoothing would move vertex v to raise the worst objective of its star (only
    /// reads the mesh: [`Improver::apply_smoothing`] carries it out).
    pub(crate) fn plan_smoothing(&self, v: u32) -> Smoothing {
        let cons = self.cons[v as usize];
        if cons == Constraint::Fixed {
            return Smoothing::Stays;
        }
        note(&[v]);
        let ids = &self.w.star[v as usize];
        if ids.is_empty() {
            return Smoothing::Stays;
        }
        let star: Vec<[u32; 4]> = ids.iter().map(|&t| self.w.tets[t as usize]).collect();
        star.iter().for_each(|t| note(t));
        if cons == Constraint::Free && on_hull(&self.w, v, &mut Vec::new()) {
            // A hull face missing from the boundary list: the vertex is on the boundary.
            return Smoothing::Fix;
        }
        let x0 = self.w.p(v);
        let q0 = self.w.worst_q(ids);
        let (mut x, mut qx) = self.ascend(&star, v, x0, q0, cons);
        if let Some(s) = self.sliding(v) {
            // Back onto the input surface, where the move is judged.
            let Some(y) = s.project(v, x) else {
                return Smoothing::Stays;
            };
            x = y;
            qx = self.star_min(&star, v, x);
        }
        if qx <= q0 + SMOOTH_GAIN || qx.is_nan() || !self.valid_move(&star, v, x) {
            return Smoothing::Stays;
        }
        let moved = star
            .iter()
            .map(|tv| tv.map(|u| if u == v { x } else { self.w.p(u) }));
        if !self.keeps_rho(ids, moved) {
            return Smoothing::Stays;
        }
        Smoothing::Move(x)
    }

    /// Carries a smoothing out; true when the vertex moved.
    pub(crate) fn apply_smoothing(&mut self, v: u32, s: Smoothing) -> bool {
        match s {
            Smoothing::Stays => false,
            Smoothing::Fix => {
                self.cons[v as usize] = Constraint::Fixed;
                self.w.touch(v);
                false
            }
            Smoothing::Move(x) => {
                self.w.pos[v as usize] = x;
                self.w.touch(v);
                let objective = self.w.objective;
                for &t in &self.w.star[v as usize] {
                    let tv = self.w.tets[t as usize];
                    self.w.q[t as usize] = q_at(&self.w.pos, objective, &tv, v, x);
                }
                self.stats.smoothed += 1;
                true
            }
        }
    }

    /// The slide of boundary vertex `v`, if it slides on the input surface.
    fn sliding(&self, v: u32) -> Option<&dyn super::SurfaceSlide> {
        self.slide
            .filter(|s| !self.w.bstar[v as usize].is_empty() && s.slides(v))
    }

    /// Exact orientation of every star tet with v at x, and the boundary triangles' sides.
    fn valid_move(&self, star: &[[u32; 4]], v: u32, x: DVec3) -> bool {
        let old = self.w.pos[v as usize];
        let positive = |t: &[u32; 4]| {
            let p = t.map(|u| if u == v { x } else { self.w.pos[u as usize] });
            orient3d(p[0], p[1], p[2], p[3]) > 0.0
        };
        if let Some(s) = self.sliding(v) {
            // On a curved surface: no boundary triangle turns over, and each stays close.
            for &bt in &self.w.bstar[v as usize] {
                let tri = self.w.btri[bt as usize];
                let at = |y: DVec3| tri.map(|u| if u == v { y } else { self.w.pos[u as usize] });
                let normal = |[a, b, c]: [DVec3; 3]| (b - a).cross(c - a);
                if normal(at(old)).dot(normal(at(x))) <= 0.0 || !s.keeps_close(at(x)) {
                    return false;
                }
            }
            return star.iter().all(positive);
        }
        for &bt in &self.w.bstar[v as usize] {
            let patch = self.w.bpatch[bt as usize];
            if patch == DEAD {
                return false;
            }
            let n = self.normals[patch as usize];
            let tri = self.w.btri[bt as usize];
            let side = |y: DVec3| {
                let [a, b, c] = tri.map(|u| if u == v { y } else { self.w.pos[u as usize] });
                (b - a).cross(c - a).dot(n)
            };
            let (s0, s1) = (side(old), side(x));
            if s0 == 0.0 || s0.signum() != s1.signum() || s1 == 0.0 {
                return false;
            }
        }
        star.iter().all(positive)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn min_norm_of_two_and_three() {
        let g = [DVec3::new(1.0, 1.0, 0.0), DVec3::new(-1.0, 1.0, 0.0)];
        assert!((min_norm(&g) - DVec3::new(0.0, 1.0, 0.0)).length() < 1e-12);
        let g = [DVec3::X, DVec3::Y, DVec3::Z];
        assert!((min_norm(&g) - DVec3::splat(1.0 / 3.0)).length() < 1e-3);
        let g = [DVec3::X, -DVec3::X];
        assert!(min_norm(&g).length() < 1e-12);
    }
}
