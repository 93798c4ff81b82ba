//! Point location by a stochastic visibility walk (Devillers, Pion, Teillaud, "Walking in a
//! triangulation", 2002): from the current tet, cross a face that has the query point strictly
//! beyond it, testing faces from a random start so the walk cannot cycle.

use super::tables::FACE;
use super::{has_infinite, Delaunay, INFINITE};
use crate::geom::orient3d;
use glam::DVec3;

impl Delaunay {
    /// Returns a finite tet whose closure contains `p`, or a hull tet whose hull face has `p`
    /// strictly outside it.
    pub(super) fn locate(&mut self, p: DVec3, start: u32) -> u32 {
        let mut rng = self.rng;
        let t = self.walk(p, start, &mut rng);
        self.rng = rng;
        t
    }

    /// [`Self::locate`] with the walk's random choices drawn from `rng` (xorshift state,
    /// nonzero): reads the triangulation only.
    pub(super) fn walk(&self, p: DVec3, start: u32, rng: &mut u32) -> u32 {
        let mut t = start;
        if let Some(k) = self.infinite_index(t) {
            t = self.tets[t as usize].n[k] >> 2;
        }
        let mut came_from = u32::MAX;
        'walk: loop {
            let v = self.tets[t as usize].v;
            let r = super::xorshift(rng) as usize;
            for k in 0..4 {
                let i = (r + k) & 3;
                let n = self.tets[t as usize].n[i] >> 2;
                if n == came_from {
                    continue; // we crossed this face towards p: p is on our side of it
                }
                let f = FACE[i];
                let (a, b, c) = (
                    self.points[v[f[0]] as usize],
                    self.points[v[f[1]] as usize],
                    self.points[v[f[2]] as usize],
                );
                if orient3d(a, b, c, p) < 0.0 {
                    if self.infinite_index(n).is_some() {
                        return n;
                    }
                    came_from = t;
                    t = n;
                    continue 'walk;
                }
            }
            return t;
        }
    }

    /// A start for locating `p` near the last insertion: among every third finite tet the last
    /// insertion created (all incident to the last new vertex), the one whose outer face's
    /// centroid is nearest to `p`. Halves the walk for spatially sorted insertions
    /// (6.7 -> 3.7 tets per point on 1e6 uniform points). Falls back to the last created tet.
    pub(super) fn hint_towards(&self, p: DVec3) -> u32 {
        let mut best = f64::MAX;
        let mut hint = self.last;
        let p3 = p * 3.0;
        for &t in self.scratch.created.iter().step_by(3) {
            let v = self.tet_ref(t).v;
            if !has_infinite(v) {
                let c = self.point_ref(v[0]) + self.point_ref(v[1]) + self.point_ref(v[2]);
                let d = c.distance_squared(p3);
                if d < best {
                    best = d;
                    hint = t;
                }
            }
        }
        hint
    }

    /// Local index of the infinite vertex of tet `t`, if it is a hull tet.
    #[inline]
    pub(super) fn infinite_index(&self, t: u32) -> Option<usize> {
        self.tets[t as usize].v.iter().position(|&v| v == INFINITE)
    }
}
