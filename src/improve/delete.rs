//! Vertex deletion, the counterpart of insertion (Klingner & Shewchuk's third operation,
//! both ways): a free interior vertex of a bad tet is removed by contracting it onto one of
//! its neighbours. Typically an interior vertex refinement squeezed into a thin layer between
//! two boundary sheets, where every tet around it is flat and no position of it helps.
//!
//! Contracting v onto a neighbour u removes the tets around edge uv and gives every other tet
//! around v the vertex u in its place: the cone from u over the faces of v's link that do not
//! hold u. The link is kept, so when every new tet is positively oriented by the exact
//! `orient3d` the new tets tile v's star (the degree argument of `flips`). Of all neighbours,
//! the one whose worst new tet is best is taken, if that beats the worst tet around v.

use super::batch::note;
use super::constraints::Constraint;
use super::flips::MIN_GAIN;
use super::Improver;

/// Largest star tried (a contraction evaluates every tet of it per neighbour).
const MAX_STAR: usize = 64;

/// A planned deletion, applied by [`Improver::apply_deletion`].
#[derive(Debug, PartialEq)]
pub(crate) struct Deletion {
    v: u32,
    kill: Vec<u32>,
    /// New tets, each with the region of the tet it replaces.
    make: Vec<([u32; 4], i32)>,
    pub new_min: f64,
}

impl Improver<'_> {
    /// The best deletion of a free interior vertex of tet `t`, if one raises the worst
    /// objective around it.
    pub(crate) fn plan_deletion(&self, t: u32) -> Option<Deletion> {
        let w = &self.w;
        if !w.alive[t as usize] {
            return None;
        }
        let mut best: Option<Deletion> = None;
        for v in w.tets[t as usize] {
            let star = &w.star[v as usize];
            if !matches!(self.cons[v as usize], Constraint::Free) || star.len() > MAX_STAR {
                continue;
            }
            star.iter().for_each(|&s| note(&w.tets[s as usize]));
            let old = w.worst_q(star);
            let mut link: Vec<u32> = star
                .iter()
                .flat_map(|&s| w.tets[s as usize])
                .filter(|&u| u != v)
                .collect();
            link.sort_unstable();
            link.dedup();
            for u in link {
                let floor = best.as_ref().map_or(old, |b| b.new_min.max(old));
                if let Some(d) = self.contraction(v, u, floor) {
                    best = Some(d);
                }
            }
        }
        best
    }

    /// Contraction of v onto u, if its worst new tet beats `floor` by `MIN_GAIN` and every new
    /// tet is positively oriented.
    fn contraction(&self, v: u32, u: u32, floor: f64) -> Option<Deletion> {
        let w = &self.w;
        let mut make = vec![];
        let mut new_min = f64::INFINITY;
        for &s in &w.star[v as usize] {
            let tv = w.tets[s as usize];
            if tv.contains(&u) {
                continue;
            }
            let nt = tv.map(|x| if x == v { u } else { x });
            let [a, b, c, d] = w.points(&nt);
            new_min = new_min.min(w.objective.of(a, b, c, d));
            if new_min <= floor + MIN_GAIN {
                return None;
            }
            make.push((nt, w.region[s as usize]));
        }
        if make.is_empty() || !make.iter().all(|&(nt, _)| w.positive(nt)) {
            return None;
        }
        if !self.keeps_rho(&w.star[v as usize], make.iter().map(|(nt, _)| w.points(nt))) {
            return None;
        }
        Some(Deletion {
            v,
            kill: w.star[v as usize].clone(),
            make,
            new_min,
        })
    }

    /// Records vertex `v`, which no tet uses any more, as deleted: nothing moves it again and
    /// the output drops it.
    pub(crate) fn forget_vertex(&mut self, v: u32) {
        self.cons[v as usize] = Constraint::Fixed;
        self.w.deleted.push(v);
        self.stats.deletions += 1;
    }

    /// Carries a deletion out; returns the new tets. The vertex keeps its slot, unused (the
    /// output drops it).
    pub(crate) fn apply_deletion(&mut self, plan: Deletion) -> Vec<u32> {
        for &t in &plan.kill {
            self.w.kill_tet(t);
        }
        self.forget_vertex(plan.v);
        plan.make
            .iter()
            .map(|&(t, region)| self.w.add_tet(t, region))
            .collect()
    }
}
