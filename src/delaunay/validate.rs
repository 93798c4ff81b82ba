//! Structural and Delaunay validity checks (tests and debugging only; never on the hot path).

use super::tables::FACE;
use super::{Delaunay, DEAD, INFINITE};
use crate::geom::{insphere_sos, orient3d};

impl Delaunay {
    /// Checks: every alive tet's neighbours are alive and point back through the same face;
    /// finite tets are positively oriented; the hull is convex; every interior face is locally
    /// Delaunay (perturbed in-sphere), which implies the whole triangulation is Delaunay; each
    /// inserted vertex's incident-tet pointer is right; counts agree.
    pub fn validate(&self) -> Result<(), String> {
        let mut alive = 0;
        let mut ghosts = 0;
        for t in 0..self.tets.len() as u32 {
            let v = self.tets[t as usize].v;
            if v[0] == DEAD {
                continue;
            }
            alive += 1;
            let n_inf = v.iter().filter(|&&x| x == INFINITE).count();
            if n_inf > 1 {
                return Err(format!("tet {t} {v:?} has {n_inf} infinite vertices"));
            }
            if n_inf == 1 {
                ghosts += 1;
            } else {
                let q = self.tet_points(t);
                if orient3d(q[0], q[1], q[2], q[3]) <= 0.0 {
                    return Err(format!("tet {t} {v:?} is not positively oriented"));
                }
            }
            #[allow(clippy::needless_range_loop)] // i indexes FACE, the tet and its neighbours
            for i in 0..4 {
                let r = self.tets[t as usize].n[i];
                let (n, j) = (r >> 2, (r & 3) as usize);
                if !self.is_alive(n) {
                    return Err(format!("tet {t} face {i}: neighbour {n} is not alive"));
                }
                if self.tets[n as usize].n[j] != t * 4 + i as u32 {
                    return Err(format!(
                        "tet {t} face {i}: neighbour {n} does not point back"
                    ));
                }
                let mut mine = FACE[i].map(|k| v[k]);
                let w = self.tets[n as usize].v;
                let mut theirs = FACE[j].map(|k| w[k]);
                mine.sort_unstable();
                theirs.sort_unstable();
                if mine != theirs {
                    return Err(format!("tet {t} face {i} and tet {n} face {j} differ"));
                }
                self.check_face(t, i, n, j)?;
            }
        }
        if alive != self.n_alive || ghosts != self.n_ghost {
            return Err(format!(
                "counts: {alive} alive / {ghosts} hull tets found, {} / {} recorded",
                self.n_alive, self.n_ghost
            ));
        }
        let mut n_vertices = 0;
        for (v, &t) in self.vertex_tet.iter().enumerate() {
            if t == super::NO_TET {
                continue;
            }
            n_vertices += 1;
            if !self.is_alive(t) || !self.tets[t as usize].v.contains(&(v as u32)) {
                return Err(format!("vertex {v}: incident tet {t} does not hold it"));
            }
        }
        if n_vertices != self.n_vertices {
            return Err(format!(
                "{n_vertices} vertices have tets, {} recorded",
                self.n_vertices
            ));
        }
        Ok(())
    }

    /// Local Delaunay / convexity across face i of t (shared with face j of n).
    fn check_face(&self, t: u32, i: usize, n: u32, j: usize) -> Result<(), String> {
        let v = self.tets[t as usize].v;
        let apex = self.tets[n as usize].v[j];
        let t_finite = !v.contains(&INFINITE);
        if t_finite && apex != INFINITE {
            let q = self.tet_points(t);
            let ranks = v.map(|x| self.rank[x as usize]);
            let e = self.points[apex as usize];
            let inside = if self.ties_by_coordinates {
                let s = crate::geom::insphere(q[0], q[1], q[2], q[3], e);
                s > 0.0 || (s == 0.0 && crate::geom::insphere_tie_by_coordinates(q, e))
            } else {
                insphere_sos(q, ranks, e, self.rank[apex as usize])
            };
            if inside {
                return Err(format!(
                    "face {i} of tet {t} {v:?} is not locally Delaunay: vertex {apex} is inside"
                ));
            }
        }
        if !t_finite && apex != INFINITE && v[i] != INFINITE {
            // Two hull tets sharing a face through infinity: the hull must be convex there.
            let k = v.iter().position(|&x| x == INFINITE).unwrap();
            let f = FACE[k].map(|l| self.points[v[l] as usize]);
            if orient3d(f[0], f[1], f[2], self.points[apex as usize]) > 0.0 {
                return Err(format!(
                    "hull is not convex at tet {t} {v:?} (vertex {apex})"
                ));
            }
        }
        Ok(())
    }
}
