//! Radius-edge repair: a vertex inserted at (or short of) the circumcentre of a tet over the
//! radius-edge bound, as Delaunay refinement would, where refinement could not. Used on the
//! zones of a partitioned run (`partition::zone`): there the parts' refinement refused the
//! circumcentres that would encroach a frozen interface, and the improver, which works on
//! angles, leaves such tets over the bound. In the zone the old interface is free, so the
//! point can go in now.
//!
//! The cavity is the tets crossed on the way from the bad tet to the point, and those around
//! them (same region, never across a boundary triangle) whose circumsphere holds the point,
//! grown across every outer face that the point does not see (the mesh need not be
//! Delaunay); the point is joined to its outer faces (`Improver::cone`). The change is made
//! only when every new tet is positively oriented by the exact `orient3d` (so the cone tiles
//! the cavity), none exceeds the bound (failing that, the largest new ratio is below the bad
//! tet's, and a later round goes on), and the worst new angle objective is at least `floor`. Around the circumcentre and on the way back to the tet's centroid several points
//! are tried ([`candidates`]); where none has its new tets within the bound, the best one's
//! point is moved by the improver's ascent on the objective capped at the bound. Where the
//! circumcentre encroaches a boundary triangle of a flat patch (beyond it or in its equatorial
//! ball), the patch's triangles around the point are split instead, as refinement splits an
//! encroached subfacet ([`Improver::plan_boundary_split`]). The improver's passes then work on
//! the angles around the new vertices (`improve_work`).

use super::constraints::Constraint;
use super::insert::{Insertion, NEW};
use super::quality::Objective;
use super::topo::{edge_key, face, key3, Work, DEAD};
use super::Improver;
use crate::geom::{circumsphere, equatorial_ball, insphere, orient3d, tri_circumcenter};
use glam::DVec3;

/// Most tets in a repair's cavity.
const MAX_CAVITY: usize = 64;
/// Where the points are tried: at these fractions of the way from the tet's centroid to its
/// circumcentre, and around each within this fraction of that distance times the
/// circumradius (Li's picking region around the circumcentre, made deterministic: the
/// directions of an icosahedron's vertices).
const TOWARD_CENTRE: [f64; 3] = [1.0, 0.7, 0.4];
const PICKING_RADIUS: f64 = 0.25;
/// Rounds over the tets still over the bound.
const REPAIR_ROUNDS: usize = 3;

impl Improver<'_> {
    /// Repairs the tets over radius-edge ratio `bound`, worst first, in rounds, with new tets
    /// no worse than angle objective `floor` (`target`: the sine of the improvement target).
    /// Returns how many vertices went in.
    pub(super) fn repair_rho(&mut self, bound: f64, floor: f64, target: f64) -> usize {
        let mut repaired = 0;
        for _ in 0..REPAIR_ROUNDS {
            let mut over: Vec<(f64, u32)> = (0..self.w.tets.len() as u32)
                .filter(|&t| self.w.alive[t as usize])
                .map(|t| (Work::rho_at(self.w.points(&self.w.tets[t as usize])), t))
                .filter(|&(rho, _)| rho > bound)
                .collect();
            over.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
            let mut this_round = 0;
            for (_, t) in over {
                // An earlier repair may have removed it (its slot may hold another tet now).
                if !self.w.alive[t as usize]
                    || Work::rho_at(self.w.points(&self.w.tets[t as usize])) <= bound
                {
                    continue;
                }
                // A circumcentre beyond the tet's boundary face: that face is split (its patch
                // around the point), as refinement would; else a point inside.
                if let Some(plan) = self.plan_boundary_split(t, bound, floor) {
                    self.apply_boundary_split(plan);
                } else if let Some(plan) = self.plan_rho_repair(t, bound, floor, target) {
                    let v = self.w.add_vertex(plan.at);
                    self.cons.push(Constraint::Free);
                    self.fill_cavity(v, &plan);
                } else {
                    continue;
                }
                self.stats.rho_repairs += 1;
                this_round += 1;
            }
            repaired += this_round;
            if this_round == 0 {
                break;
            }
        }
        repaired
    }

    /// Of the points tried for tet `t` (see [`candidates`]) whose insertion is valid with no
    /// new tet worse than `floor`: the one with the best worst new tet among those whose new
    /// tets are all within `bound`, else the one whose worst new tet has the smallest
    /// radius-edge ratio if that is below `t`'s (a later round goes on from there).
    /// If none is within the bound, the best moved by [`Self::placed_for_rho`] may be.
    fn plan_rho_repair(
        &mut self,
        t: u32,
        bound: f64,
        floor: f64,
        target: f64,
    ) -> Option<Insertion> {
        let w = &self.w;
        let corners = w.points(&w.tets[t as usize]);
        let region = w.region[t as usize];
        // (within the bound, its ranking value, the plan): the best is the largest pair.
        let mut best: Option<(bool, f64, Insertion)> = None;
        for at in candidates(corners)? {
            let Some(cavity) = self.cavity_seeing(t, at, region) else {
                continue;
            };
            let (make, _) = self.cone(&cavity, region);
            let new_min = self.star_min(&make, NEW, at);
            if new_min < floor || !self.swallows_only_free(&cavity, &make) {
                continue;
            }
            let new_rho = self.cone_rho(&make, at);
            let rank = if new_rho <= bound {
                (true, new_min)
            } else {
                (false, -new_rho)
            };
            if best.as_ref().is_none_or(|b| rank > (b.0, b.1)) {
                let plan = Insertion {
                    at,
                    kill: cavity,
                    make,
                    region,
                    new_min,
                };
                best = Some((rank.0, rank.1, plan));
            }
        }
        let (within, value, plan) = best?;
        if within {
            return Some(plan);
        }
        let rho_t = Work::rho_at(corners);
        match self.placed_for_rho(&plan, bound, floor, target) {
            Some(placed) => Some(placed),
            None => (-value < rho_t).then_some(plan),
        }
    }

    /// `plan`'s point moved by the improver's ascent on the objective capped at `bound`
    /// (`quality::Objective`, its `rho_weight` for `target`, the sine of the target angle), in
    /// the same cavity: the plan there if all its new tets are then valid, within the bound
    /// and no worse than `floor` in angle.
    fn placed_for_rho(
        &mut self,
        plan: &Insertion,
        bound: f64,
        floor: f64,
        target: f64,
    ) -> Option<Insertion> {
        let angles = self.w.objective;
        self.w.objective = Objective {
            rho_weight: target * bound,
            ..angles
        };
        let q0 = self.star_min(&plan.make, NEW, plan.at);
        let (at, _) = self.ascend(&plan.make, NEW, plan.at, q0, Constraint::Free);
        self.w.objective = angles;
        let valid = self.cone_positive(&plan.make, at);
        let within = self.cone_rho(&plan.make, at) <= bound;
        let new_min = self.star_min(&plan.make, NEW, at);
        (valid && within && new_min >= floor).then(|| Insertion {
            at,
            kill: plan.kill.clone(),
            make: plan.make.clone(),
            region: plan.region,
            new_min,
        })
    }

    /// Tet `tv` of a cone with `NEW` at `at`.
    fn cone_tet(&self, tv: &[u32; 4], at: DVec3) -> [DVec3; 4] {
        tv.map(|v| if v == NEW { at } else { self.w.p(v) })
    }

    /// Whether every tet of cone `make` is positively oriented (exact `orient3d`), `NEW` at
    /// `at`.
    fn cone_positive(&self, make: &[[u32; 4]], at: DVec3) -> bool {
        make.iter().all(|tv| {
            let p = self.cone_tet(tv, at);
            orient3d(p[0], p[1], p[2], p[3]) > 0.0
        })
    }

    /// The largest radius-edge ratio of the tets of cone `make`, `NEW` at `at`.
    fn cone_rho(&self, make: &[[u32; 4]], at: DVec3) -> f64 {
        (make.iter())
            .map(|tv| Work::rho_at(self.cone_tet(tv, at)))
            .fold(0.0, f64::max)
    }

    /// The cavity for a point at `at` (see the module comment), or None if the point is not
    /// reached from tet `t` inside region `region` or the cavity grows too large.
    fn cavity_seeing(&self, t: u32, at: DVec3, region: i32) -> Option<Vec<u32>> {
        // Walk to the tet holding the point, keeping the tets crossed.
        let mut cavity = vec![t];
        let mut c = t;
        while let Some(i) = (0..4).find(|&i| !self.sees(c, i, at)) {
            let nb = self.beyond(c, i, region)?;
            if cavity.contains(&nb) || cavity.len() >= MAX_CAVITY {
                return None;
            }
            cavity.push(nb);
            c = nb;
        }
        self.grow_cavity(cavity, at, region, &[])
    }

    /// Whether `at` is strictly on the inner side of face i of tet c.
    fn sees(&self, c: u32, i: usize, at: DVec3) -> bool {
        let mut p = self.w.points(&self.w.tets[c as usize]);
        p[i] = at;
        orient3d(p[0], p[1], p[2], p[3]) > 0.0
    }

    /// `cavity` grown by the tets around whose circumsphere holds `at`, then across every
    /// outer face `at` does not see but those in `split` (boundary triangles `at` lies in);
    /// None if it would grow past [`MAX_CAVITY`] or across a boundary triangle.
    fn grow_cavity(
        &self,
        mut cavity: Vec<u32>,
        at: DVec3,
        region: i32,
        split: &[[u32; 3]],
    ) -> Option<Vec<u32>> {
        let w = &self.w;
        let mut next = 0;
        while next < cavity.len() {
            let c = cavity[next];
            next += 1;
            for i in 0..4 {
                let Some(nb) = self.beyond(c, i, region) else {
                    continue;
                };
                let p = w.points(&w.tets[nb as usize]);
                if !cavity.contains(&nb) && insphere(p[0], p[1], p[2], p[3], at) > 0.0 {
                    cavity.push(nb);
                    if cavity.len() > MAX_CAVITY {
                        return None;
                    }
                }
            }
        }
        loop {
            let hidden = cavity.iter().find_map(|&c| {
                (0..4).find_map(|i| {
                    let inner = self
                        .beyond(c, i, region)
                        .is_some_and(|nb| cavity.contains(&nb));
                    let f = key3(face(w.tets[c as usize], i));
                    (!inner && !split.contains(&f) && !self.sees(c, i, at)).then_some((c, i))
                })
            });
            let Some((c, i)) = hidden else {
                return Some(cavity);
            };
            cavity.push(self.beyond(c, i, region)?);
            if cavity.len() > MAX_CAVITY {
                return None;
            }
        }
    }

    /// For tet `t` with a boundary face whose outer side holds its circumcentre: the split of
    /// the boundary triangles of that face's flat patch around the circumcentre's projection
    /// on it (those whose circumcircle holds the point), as refinement splits an encroached
    /// subfacet. Judged like [`Self::plan_rho_repair`]'s points.
    fn plan_boundary_split(&self, t: u32, bound: f64, floor: f64) -> Option<BoundarySplit> {
        let w = &self.w;
        let tv = w.tets[t as usize];
        let corners = w.points(&tv);
        let (centre, _) = circumsphere(corners[0], corners[1], corners[2], corners[3])?;
        // The boundary face whose outer side or equatorial ball holds the circumcentre, else
        // the boundary triangle through which the way to it leaves the region.
        let found = (0..4).find_map(|i| {
            let &b = w.bmap.get(&key3(face(tv, i)))?;
            let [x, y, z] = w.btri[b as usize].map(|v| w.p(v));
            let encroached = !self.sees(t, i, centre)
                || equatorial_ball(x, y, z).is_some_and(|(c, r)| c.distance(centre) < r);
            encroached.then_some((b, vec![t]))
        });
        let (b, path) = match found {
            Some(f) => f,
            None => self.boundary_on_the_way(t, centre)?,
        };
        if w.bpatch[b as usize] == DEAD {
            return None;
        }
        // The circumcentre's projection on the face's plane, and the face's circumcentre.
        let tri = w.btri[b as usize].map(|v| w.p(v));
        let points = [
            onto_plane(centre, tri),
            tri_circumcenter(tri[0], tri[1], tri[2]),
        ];
        let rank = |s: &BoundarySplit| {
            let within = s.worst_rho <= bound;
            (
                within,
                if within {
                    s.insertion.new_min
                } else {
                    -s.worst_rho
                },
            )
        };
        let best = (points.into_iter().flatten())
            .filter_map(|at| self.plan_split_at(&path, b, snap_to(at, tri), floor))
            .max_by(|a, b| {
                rank(a)
                    .partial_cmp(&rank(b))
                    .unwrap_or(std::cmp::Ordering::Equal)
            })?;
        (best.worst_rho <= bound || best.worst_rho < Work::rho_at(corners)).then_some(best)
    }

    /// The boundary triangle through which the walk from tet `t` toward `at` leaves its
    /// region, with the tets crossed (`t` first); None if it leaves through the hull.
    fn boundary_on_the_way(&self, t: u32, at: DVec3) -> Option<(u32, Vec<u32>)> {
        let w = &self.w;
        let region = w.region[t as usize];
        let mut path = vec![t];
        let mut c = t;
        while let Some(i) = (0..4).find(|&i| !self.sees(c, i, at)) {
            if let Some(&b) = w.bmap.get(&key3(face(w.tets[c as usize], i))) {
                return Some((b, path));
            }
            let nb = self.beyond(c, i, region)?;
            if path.contains(&nb) || path.len() >= MAX_CAVITY {
                return None;
            }
            path.push(nb);
            c = nb;
        }
        None
    }

    /// The split of boundary triangle `b` (and those of its patch around) at `at`, the
    /// cavity holding the tets `path` (the bad tet first): valid, no new tet worse than
    /// `floor`.
    fn plan_split_at(&self, path: &[u32], b: u32, at: DVec3, floor: f64) -> Option<BoundarySplit> {
        let w = &self.w;
        let t = path[0];
        let region = w.region[t as usize];
        let patch = w.bpatch[b as usize];
        let normal = self.normals[patch as usize];
        // The patch's triangles around `at` whose circumcircle holds it, `at` inside one.
        let faces = self.patch_triangles_holding(b, at)?;
        let split: Vec<[u32; 3]> = faces.iter().map(|&f| key3(w.btri[f as usize])).collect();
        // The tets on each side of the split triangles (a region interface has two): t's
        // side, one tet of t's region a triangle, then the other, one a triangle or none.
        let mut sides: [Vec<u32>; 2] = [path.to_vec(), vec![]];
        let mut far_counts = vec![];
        for &f in &faces {
            let (pair, n) = w.face_tets(w.btri[f as usize]);
            let near = pair[..n]
                .iter()
                .filter(|&&c| w.region[c as usize] == region);
            if near.count() != 1 {
                return None;
            }
            far_counts.push(n - 1);
            for &c in &pair[..n] {
                let side = usize::from(w.region[c as usize] != region);
                if !sides[side].contains(&c) {
                    sides[side].push(c);
                }
            }
        }
        let other_region = sides[1].first().map(|&c| w.region[c as usize]);
        if far_counts.iter().any(|&k| k != far_counts[0])
            || sides[1]
                .iter()
                .any(|&c| Some(w.region[c as usize]) != other_region)
        {
            return None;
        }
        let [near_side, far_side] = sides;
        let cavity = self.grow_cavity(near_side, at, region, &split)?;
        let (make, from) = self.cone(&cavity, region);
        let without_split = |make: Vec<[u32; 4]>, from: Vec<(u32, usize)>| -> Vec<[u32; 4]> {
            (make.into_iter().zip(from))
                .filter(|(_, (c, i))| !split.contains(&key3(face(w.tets[*c as usize], *i))))
                .map(|(m, _)| m)
                .collect()
        };
        let make = without_split(make, from);
        let other = match other_region {
            None => None,
            Some(r) => {
                let cavity = self.grow_cavity(far_side, at, r, &split)?;
                let (make, from) = self.cone(&cavity, r);
                Some(Insertion {
                    at,
                    kill: cavity,
                    make: without_split(make, from),
                    region: r,
                    new_min: 0.0,
                })
            }
        };
        // The new boundary triangles: the split triangles' outer edges joined to `at`, each
        // a face of a new tet.
        let mut fan = vec![];
        for &f in &faces {
            let tri = w.btri[f as usize];
            for k in 0..3 {
                let (u, v) = (tri[k], tri[(k + 1) % 3]);
                let shared = faces.iter().any(|&g| {
                    g != f && w.btri[g as usize].contains(&u) && w.btri[g as usize].contains(&v)
                });
                if !shared {
                    fan.push([u, v, NEW]);
                }
            }
        }
        let in_tets = |make: &[[u32; 4]]| {
            fan.iter()
                .all(|f| make.iter().any(|t| f.iter().all(|v| t.contains(v))))
        };
        if fan.len() != faces.len() + 2
            || !in_tets(&make)
            || other.as_ref().is_some_and(|o| !in_tets(&o.make))
        {
            return None;
        }
        let all_new: Vec<[u32; 4]> = make
            .iter()
            .chain(other.iter().flat_map(|o| &o.make))
            .copied()
            .collect();
        let new_min = self.star_min(&all_new, NEW, at);
        let new_rho = self.cone_rho(&all_new, at);
        let fine = self.cone_positive(&all_new, at)
            && new_min >= floor
            && self.swallows_only_free(&cavity, &make)
            && other
                .as_ref()
                .is_none_or(|o| self.swallows_only_free(&o.kill, &o.make));
        fine.then(|| BoundarySplit {
            worst_rho: new_rho,
            insertion: Insertion {
                at,
                kill: cavity,
                make,
                region,
                new_min,
            },
            other,
            normal,
            replace: faces,
            fan,
            marker: w.bmarker[b as usize],
            patch,
        })
    }

    /// Boundary triangle `b` and the triangles of its flat patch reached from it across the
    /// patch's flat edges whose circumcircle holds `at`; None unless `at` is strictly inside
    /// one of them.
    fn patch_triangles_holding(&self, b: u32, at: DVec3) -> Option<Vec<u32>> {
        let w = &self.w;
        let patch = w.bpatch[b as usize];
        let normal = self.normals[patch as usize];
        let mut faces = vec![b];
        let mut next = 0;
        while next < faces.len() {
            let f = faces[next];
            next += 1;
            let tri = w.btri[f as usize];
            for k in 0..3 {
                let (u, v) = (tri[k], tri[(k + 1) % 3]);
                if !w.flat_edges.contains(&edge_key(u, v)) {
                    continue;
                }
                let across = w.bstar[u as usize].iter().copied().find(|&g| {
                    g != f && w.btri[g as usize].contains(&v) && w.bpatch[g as usize] == patch
                });
                let Some(g) = across else { continue };
                let [x, y, z] = w.btri[g as usize].map(|q| w.p(q));
                let holds = tri_circumcenter(x, y, z)
                    .is_some_and(|c| c.distance_squared(at) < c.distance_squared(x));
                if holds && !faces.contains(&g) {
                    faces.push(g);
                    if faces.len() > MAX_CAVITY {
                        return None;
                    }
                }
            }
        }
        let inside = |f: u32| {
            let [x, y, z] = w.btri[f as usize].map(|q| w.p(q));
            let side = |a: DVec3, b: DVec3| orient3d(a, b, at, a + normal);
            let s = [side(x, y), side(y, z), side(z, x)];
            s.iter().all(|&v| v > 0.0) || s.iter().all(|&v| v < 0.0)
        };
        faces.iter().any(|&f| inside(f)).then_some(faces)
    }

    /// Carries a boundary split out: the insertion, the split triangles replaced by the fan
    /// (their slots reused), the new vertex sliding in the patch's plane.
    fn apply_boundary_split(&mut self, plan: BoundarySplit) {
        let v = self.w.add_vertex(plan.insertion.at);
        self.cons.push(Constraint::Plane(plan.normal));
        self.fill_cavity(v, &plan.insertion);
        if let Some(other) = &plan.other {
            self.fill_cavity(v, other);
        }
        for (k, f) in plan.fan.into_iter().enumerate() {
            let f = f.map(|u| if u == NEW { v } else { u });
            match plan.replace.get(k) {
                Some(&slot) => self.w.replace_btri(slot, f),
                None => {
                    self.w.add_btri(f, plan.marker, plan.patch);
                }
            }
            self.w.flat_edges.insert(edge_key(f[0], v));
            self.w.flat_edges.insert(edge_key(f[1], v));
        }
    }
}

/// A planned split of boundary triangles (`Improver::plan_boundary_split`).
struct BoundarySplit {
    /// The largest radius-edge ratio of the new tets.
    worst_rho: f64,
    /// The cavity on the bad tet's side, and on the other side of a region interface.
    insertion: Insertion,
    other: Option<Insertion>,
    /// The patch's normal: the new vertex moves in its plane.
    normal: DVec3,
    /// The boundary triangles split, and the ones that replace them (`NEW` the new vertex).
    replace: Vec<u32>,
    fan: Vec<[u32; 3]>,
    marker: i32,
    patch: u32,
}

/// `p` projected onto the plane of triangle `tri`; None for a flat triangle.
fn onto_plane(p: DVec3, tri: [DVec3; 3]) -> Option<DVec3> {
    let n = (tri[1] - tri[0]).cross(tri[2] - tri[0]).try_normalize()?;
    Some(p - n * n.dot(p - tri[0]))
}

/// `p` with the coordinates that triangle `tri`'s corners share set to theirs (a point on
/// an axis-aligned facet stays exactly on it).
fn snap_to(mut p: DVec3, tri: [DVec3; 3]) -> DVec3 {
    for axis in 0..3 {
        if tri[0][axis] == tri[1][axis] && tri[1][axis] == tri[2][axis] {
            p[axis] = tri[0][axis];
        }
    }
    p
}

/// The points tried for a tet with corners `p` (see [`TOWARD_CENTRE`]); None for a flat tet.
fn candidates(p: [DVec3; 4]) -> Option<Vec<DVec3>> {
    let (centre, radius) = circumsphere(p[0], p[1], p[2], p[3])?;
    let centroid = p.iter().sum::<DVec3>() * 0.25;
    let g = (1.0 + 5f64.sqrt()) / 2.0;
    let mut directions = vec![];
    for a in [-1.0, 1.0] {
        for b in [-g, g] {
            directions.push(DVec3::new(0.0, a, b));
            directions.push(DVec3::new(a, b, 0.0));
            directions.push(DVec3::new(b, 0.0, a));
        }
    }
    let mut out = vec![];
    for s in TOWARD_CENTRE {
        let base = centroid + (centre - centroid) * s;
        out.push(base);
        let r = PICKING_RADIUS * s * radius;
        out.extend(directions.iter().map(|d| base + d.normalize() * r));
    }
    Some(out)
}
