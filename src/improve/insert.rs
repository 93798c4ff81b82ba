//! Vertex insertion, for tets that flips and smoothing leave bad (Klingner & Shewchuk's third
//! operation): typically a flat tet whose four vertices are fixed on the boundary, lying on
//! a nearly flat fold of it, where no flip applies and nothing may move.
//!
//! The cavity starts as the bad tet and its face neighbours (same region, never across a
//! boundary triangle); the new vertex is joined to every outer face of the cavity, starting
//! at the bad tet's centroid and moved by the smoothing ascent to maximise the worst new tet.
//! Then the cavity takes the tet beyond the outer face of the worst new tet (the face that
//! binds the vertex) and the ascent goes on from where it stopped, a few times; the best
//! cavity is kept (in the manner of Gmsh/HXT's growing cavities).
//! The change is applied only when every new tet is positively oriented by the exact
//! `orient3d` and the worst new tet beats the worst cavity tet. The outer faces are kept, so
//! (the degree argument of `flips`) the new tets tile the cavity.

use super::constraints::Constraint;
use super::flips::MIN_GAIN;
use super::topo::{face, DEAD};
use super::Improver;
use glam::DVec3;

/// Growth steps of a cavity (each adds the tet beyond the worst new tet's outer face).
const MAX_GROWTH: usize = 8;
/// Most tets in a cavity (keeps the ascent cheap).
const MAX_CAVITY: usize = 24;

/// A planned insertion, applied by [`Improver::apply_insertion`].
#[derive(Debug, PartialEq)]
pub(crate) struct Insertion {
    pub(super) at: DVec3,
    pub(super) kill: Vec<u32>,
    /// New tets, with `NEW` standing for the new vertex.
    pub(super) make: Vec<[u32; 4]>,
    pub(super) region: i32,
    pub new_min: f64,
}

/// Stand-in id of the vertex being planned (never a real vertex id).
pub(super) const NEW: u32 = DEAD - 1;

impl Improver<'_> {
    /// The best insertion into a cavity around tet `t`, if one raises the worst objective.
    pub(crate) fn plan_insertion(&self, t: u32) -> Option<Insertion> {
        let w = &self.w;
        if !w.alive[t as usize] {
            return None;
        }
        let region = w.region[t as usize];
        let mut x = w.points(&w.tets[t as usize]).iter().sum::<DVec3>() * 0.25;
        let mut cavity = vec![t];
        for i in 0..4 {
            if let Some(nb) = self.beyond(t, i, region) {
                cavity.push(nb);
            }
        }
        let mut best: Option<Insertion> = None;
        for _ in 0..MAX_GROWTH {
            let (make, from) = self.cone(&cavity, region);
            let old = w.worst_q(&cavity);
            let q0 = self.star_min(&make, NEW, x);
            let (at, new_min) = self.ascend(&make, NEW, x, q0, Constraint::Free);
            x = at;
            if new_min > old + MIN_GAIN
                && best.as_ref().is_none_or(|b| new_min > b.new_min)
                && self.swallows_only_free(&cavity, &make)
                && make.iter().all(|t| {
                    let p = t.map(|v| if v == NEW { at } else { w.p(v) });
                    crate::geom::orient3d(p[0], p[1], p[2], p[3]) > 0.0
                })
                && self.keeps_rho(
                    &cavity,
                    make.iter()
                        .map(|t| t.map(|v| if v == NEW { at } else { w.p(v) })),
                )
            {
                best = Some(Insertion {
                    at,
                    kill: cavity.clone(),
                    make: make.clone(),
                    region,
                    new_min,
                });
            }
            if cavity.len() >= MAX_CAVITY {
                break;
            }
            // Grow across the outer face of the worst new tet that has a tet beyond it.
            let mut order: Vec<(f64, usize)> = make
                .iter()
                .enumerate()
                .map(|(k, t)| (self.star_min(std::slice::from_ref(t), NEW, at), k))
                .collect();
            order.sort_by(|a, b| a.0.total_cmp(&b.0).then(a.1.cmp(&b.1)));
            let Some(nb) = order.iter().find_map(|&(_, k)| {
                let (c, i) = from[k];
                self.beyond(c, i, region).filter(|nb| !cavity.contains(nb))
            }) else {
                break;
            };
            cavity.push(nb);
        }
        best
    }

    /// The tet of region `region` across face `i` of tet `c`, unless that face is a boundary
    /// triangle or on the hull.
    pub(super) fn beyond(&self, c: u32, i: usize, region: i32) -> Option<u32> {
        let w = &self.w;
        let f = face(w.tets[c as usize], i);
        if w.is_boundary_face(f) {
            return None;
        }
        let (pair, n) = w.face_tets(f);
        let nb = if pair[0] == c { pair[1] } else { pair[0] };
        (n == 2 && w.region[nb as usize] == region).then_some(nb)
    }

    /// The new tets joining `NEW` to the outer faces of `cavity` (tets of region `region`;
    /// each new tet is a cavity tet with the vertex opposite that face replaced), with the
    /// (cavity tet, face) each comes from.
    pub(super) fn cone(&self, cavity: &[u32], region: i32) -> (Vec<[u32; 4]>, Vec<(u32, usize)>) {
        let mut make = vec![];
        let mut from = vec![];
        for &c in cavity {
            let tv = self.w.tets[c as usize];
            for i in 0..4 {
                let inner = self
                    .beyond(c, i, region)
                    .is_some_and(|nb| cavity.contains(&nb));
                if !inner {
                    let mut nt = tv;
                    nt[i] = NEW;
                    make.push(nt);
                    from.push((c, i));
                }
            }
        }
        (make, from)
    }

    /// Whether every vertex the cone leaves out (all its tets in the cavity) is a free
    /// interior vertex: the insertion deletes it.
    pub(super) fn swallows_only_free(&self, cavity: &[u32], make: &[[u32; 4]]) -> bool {
        cavity
            .iter()
            .flat_map(|&c| self.w.tets[c as usize])
            .all(|u| {
                matches!(self.cons[u as usize], Constraint::Free)
                    || make.iter().any(|t| t.contains(&u))
            })
    }

    /// Carries an insertion out; returns the new tets. A free vertex the cavity swallowed
    /// (every tet of it was in the cavity) is deleted.
    pub(crate) fn apply_insertion(&mut self, plan: Insertion) -> Vec<u32> {
        let v = self.w.add_vertex(plan.at);
        self.cons.push(Constraint::Free);
        self.stats.insertions += 1;
        self.fill_cavity(v, &plan)
    }

    /// The tets of `plan`'s cavity replaced by its new ones, joined to vertex `v` (already
    /// added at `plan.at`); returns the new tets.
    pub(super) fn fill_cavity(&mut self, v: u32, plan: &Insertion) -> Vec<u32> {
        let mut old: Vec<u32> = plan
            .kill
            .iter()
            .flat_map(|&t| self.w.tets[t as usize])
            .collect();
        old.sort_unstable();
        old.dedup();
        for &t in &plan.kill {
            self.w.kill_tet(t);
        }
        let made = plan
            .make
            .iter()
            .map(|t| {
                let t = t.map(|u| if u == NEW { v } else { u });
                self.w.add_tet(t, plan.region)
            })
            .collect();
        for u in old {
            if self.w.star[u as usize].is_empty() {
                self.forget_vertex(u);
            }
        }
        made
    }
}
