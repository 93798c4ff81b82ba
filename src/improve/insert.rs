//! Vertex insertion, for tets that flips and smoothing leave bad (Klingner & Shewchuk's third
//! operation): typically a flat tet whose four vertices are fixed on the boundary, lying on
//! a nearly flat fold of it, where no flip applies and nothing may move.
//!
//! A cavity is grown from the bad tet across interior faces (same region, never across a
//! boundary triangle), one and two layers deep; the new vertex is joined to every outer face
//! of the cavity, starting at the bad tet's centroid and moved by the smoothing ascent to
//! maximise the worst new tet (the better of the two cavities is taken).
//! The change is applied only when every new tet is positively oriented by the exact
//! `orient3d` and the worst new tet beats the worst cavity tet. The outer faces are kept, so
//! (the degree argument of `flips`) the new tets tile the cavity.

use super::constraints::Constraint;
use super::flips::MIN_GAIN;
use super::topo::DEAD;
use super::Improver;
use glam::DVec3;

/// Layers of face neighbours around the bad tet that a cavity may take.
const LAYERS: usize = 2;
/// Most tets in a cavity (keeps the ascent cheap).
const MAX_CAVITY: usize = 24;

/// A planned insertion, applied by [`Improver::apply_insertion`].
pub(crate) struct Insertion {
    at: DVec3,
    kill: Vec<u32>,
    /// New tets, with `NEW` standing for the new vertex.
    make: Vec<[u32; 4]>,
    region: i32,
    pub new_min: f64,
}

/// Stand-in id of the vertex being planned (never a real vertex id).
const NEW: u32 = DEAD - 1;

impl Improver<'_> {
    /// The best insertion into a cavity around tet `t`, if one raises the worst objective.
    pub(crate) fn plan_insertion(&self, t: u32) -> Option<Insertion> {
        let w = &self.w;
        let region = w.region[t as usize];
        let x0 = w.points(&w.tets[t as usize]).iter().sum::<DVec3>() * 0.25;
        let mut cavity = vec![t];
        let mut best: Option<Insertion> = None;
        for _ in 0..LAYERS {
            self.grow(&mut cavity, region);
            let Some(plan) = self.plan_cavity(&cavity, region, x0) else {
                continue;
            };
            if best.as_ref().is_none_or(|b| plan.new_min > b.new_min) {
                best = Some(plan);
            }
        }
        best
    }

    /// Adds to `cavity` its face neighbours of region `region` across interior faces, up to
    /// `MAX_CAVITY` tets. Whether the cavity is star-shaped from some point is left to the
    /// ascent: it starts wherever the centroid is, inverted new tets included (the signed
    /// objective rises as they turn over).
    fn grow(&self, cavity: &mut Vec<u32>, region: i32) {
        let w = &self.w;
        let layer = cavity.clone();
        for &c in &layer {
            let tv = w.tets[c as usize];
            for i in 0..4 {
                if cavity.len() >= MAX_CAVITY {
                    return;
                }
                let f = face(tv, i);
                if w.is_boundary_face(f) {
                    continue;
                }
                let (pair, n) = w.face_tets(f);
                if n != 2 {
                    continue;
                }
                let nb = if pair[0] == c { pair[1] } else { pair[0] };
                if cavity.contains(&nb) || w.region[nb as usize] != region {
                    continue;
                }
                cavity.push(nb);
            }
        }
    }

    /// The new vertex joined to the outer faces of `cavity`, placed by the ascent from `x0`.
    fn plan_cavity(&self, cavity: &[u32], region: i32, x0: DVec3) -> Option<Insertion> {
        let w = &self.w;
        let mut make = vec![];
        for &c in cavity {
            let tv = w.tets[c as usize];
            for i in 0..4 {
                let f = face(tv, i);
                let inner = !w.is_boundary_face(f) && {
                    let (pair, n) = w.face_tets(f);
                    n == 2 && cavity.contains(if pair[0] == c { &pair[1] } else { &pair[0] })
                };
                if !inner {
                    let mut nt = tv;
                    nt[i] = NEW;
                    make.push(nt);
                }
            }
        }
        let old = cavity
            .iter()
            .map(|&c| w.q[c as usize])
            .fold(f64::INFINITY, f64::min);
        let q0 = self.star_min(&make, NEW, x0);
        let (at, new_min) = self.ascend(&make, NEW, x0, q0, Constraint::Free);
        if new_min <= old + MIN_GAIN || new_min.is_nan() {
            return None;
        }
        let ok = make.iter().all(|t| {
            let p = t.map(|v| if v == NEW { at } else { w.p(v) });
            crate::geom::orient3d(p[0], p[1], p[2], p[3]) > 0.0
        });
        ok.then(|| Insertion {
            at,
            kill: cavity.to_vec(),
            make,
            region,
            new_min,
        })
    }

    /// Carries an insertion out; returns the new tets.
    pub(crate) fn apply_insertion(&mut self, plan: Insertion) -> Vec<u32> {
        let v = self.w.add_vertex(plan.at);
        self.cons.push(Constraint::Free);
        for &t in &plan.kill {
            self.w.kill_tet(t);
        }
        self.stats.insertions += 1;
        plan.make
            .iter()
            .map(|t| {
                let t = t.map(|u| if u == NEW { v } else { u });
                self.w.add_tet(t, plan.region)
            })
            .collect()
    }
}

/// Face `i` of tet `tv` (the one opposite its vertex `i`).
fn face(tv: [u32; 4], i: usize) -> [u32; 3] {
    [tv[(i + 1) % 4], tv[(i + 2) % 4], tv[(i + 3) % 4]]
}
