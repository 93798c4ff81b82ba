//! The automatic spacing used when the caller gives none: a Lipschitz extension of the
//! boundary's local edge lengths after recovery (which splits the boundary down to its local
//! feature size), sampled on a grid: f(x) = min over boundary vertices v of h_v + alpha |x - v|.

use super::domain::Domain;
use crate::run::spacing::Spacing;
use glam::DVec3;

/// Grading: how fast the automatic spacing may grow away from the boundary.
const ALPHA: f64 = 0.35;
/// Boundary sizes below this many times ALPHA x cell are kept as points (exact near them).
const SMALL_CELLS: f64 = 2.0;
/// Grid cells along the longest side of the bounding box.
const CELLS: usize = 40;

pub struct AutoSpacing {
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    /// f at each cell centre (up to the chamfer propagation's approximation).
    value: Vec<f64>,
    /// Boundary vertices whose h is small next to the cell size, (point, h), so that f near
    /// them is exact instead of smeared over whole cells (a cluster of tiny edges at an acute
    /// corner must not make a whole cell fine): for cell i, those of it and its 26 neighbours
    /// are `nearby[nearby_start[i]..nearby_start[i + 1]]`, side by side for `at`.
    nearby: Vec<(DVec3, f64)>,
    nearby_start: Vec<u32>,
}

impl AutoSpacing {
    pub(crate) fn from_boundary(dom: &Domain) -> AutoSpacing {
        let pts = dom.dt.points();
        let mut h = vec![f64::INFINITY; pts.len()];
        for t in dom.subfacets.keys() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let l = pts[a as usize].distance(pts[b as usize]);
                h[a as usize] = h[a as usize].min(l);
                h[b as usize] = h[b as usize].min(l);
            }
        }
        let sized: Vec<(DVec3, f64)> = pts
            .iter()
            .zip(&h)
            .filter(|(_, hv)| hv.is_finite())
            .map(|(&p, &hv)| (p, hv))
            .collect();
        AutoSpacing::from_sizes(&sized)
    }

    /// The Lipschitz extension of sizes h_v given at points v.
    pub(crate) fn from_sizes(sized: &[(DVec3, f64)]) -> AutoSpacing {
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for &(p, _) in sized {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        if sized.is_empty() {
            (lo, hi) = (DVec3::ZERO, DVec3::ONE);
        }
        let ext = (hi - lo).max_element().max(1e-300);
        let cell = ext / CELLS as f64;
        let dims = ((hi - lo) / cell)
            .as_uvec3()
            .to_array()
            .map(|d| d as usize + 1);
        let n = dims[0] * dims[1] * dims[2];
        let mut s = AutoSpacing {
            lo,
            cell,
            dims,
            value: vec![ext / 4.0; n],
            nearby: vec![],
            nearby_start: vec![],
        };
        let mut small: Vec<Vec<(DVec3, f64)>> = vec![vec![]; n];
        for &(p, hv) in sized {
            let i = s.index(p);
            let at_centre = hv + ALPHA * p.distance(s.centre(i));
            s.value[i] = s.value[i].min(at_centre);
            if hv < SMALL_CELLS * ALPHA * cell {
                small[i].push((p, hv));
            }
        }
        for list in &mut small {
            prune_dominated(list);
        }
        s.gather_nearby(&small);
        s.propagate();
        s
    }

    /// The (x, y, z) grid coordinates of cell i.
    fn coords(&self, i: usize) -> (usize, usize, usize) {
        let [nx, ny, _] = self.dims;
        (i % nx, (i / nx) % ny, i / (nx * ny))
    }

    fn centre(&self, i: usize) -> DVec3 {
        let (ii, jj, kk) = self.coords(i);
        self.lo + DVec3::new(ii as f64 + 0.5, jj as f64 + 0.5, kk as f64 + 0.5) * self.cell
    }

    fn index(&self, p: DVec3) -> usize {
        let c = ((p - self.lo) / self.cell).max(DVec3::ZERO);
        let i = (c.x as usize).min(self.dims[0] - 1);
        let j = (c.y as usize).min(self.dims[1] - 1);
        let k = (c.z as usize).min(self.dims[2] - 1);
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// Fills `nearby`: per cell, the small sizes of it and its 26 neighbours (cells in z, y, x
    /// order), so that `at` reads one slice. Scattered from the few cells that hold small sizes
    /// (visited in index order, so each list keeps the z, y, x order of its cells).
    fn gather_nearby(&mut self, small: &[Vec<(DVec3, f64)>]) {
        let holding: Vec<usize> = (0..small.len()).filter(|&i| !small[i].is_empty()).collect();
        let mut start = vec![0u32; small.len() + 1];
        for &i in &holding {
            let n = small[i].len() as u32;
            for c in self.neighbourhood(i) {
                start[c + 1] += n;
            }
        }
        for c in 0..small.len() {
            start[c + 1] += start[c];
        }
        let mut next: Vec<u32> = start[..small.len()].to_vec();
        let mut nearby = vec![(DVec3::ZERO, 0.0); start[small.len()] as usize];
        for &i in &holding {
            for c in self.neighbourhood(i) {
                let at = next[c] as usize;
                nearby[at..at + small[i].len()].copy_from_slice(&small[i]);
                next[c] += small[i].len() as u32;
            }
        }
        self.nearby = nearby;
        self.nearby_start = start;
    }

    /// Cell i and its neighbours (26 inside the grid), in index order.
    fn neighbourhood(&self, i: usize) -> impl Iterator<Item = usize> {
        let [nx, ny, nz] = self.dims;
        let (ii, jj, kk) = self.coords(i);
        (kk.saturating_sub(1)..(kk + 2).min(nz)).flat_map(move |k| {
            (jj.saturating_sub(1)..(jj + 2).min(ny)).flat_map(move |j| {
                (ii.saturating_sub(1)..(ii + 2).min(nx)).map(move |c| (k * ny + j) * nx + c)
            })
        })
    }

    /// Two chamfer sweeps (forward, backward) over the 26-neighbourhood enforce
    /// f(x) <= f(y) + ALPHA |x - y| between neighbouring cells: the shortest chains of steps
    /// run straight, in steps the forward sweep takes and steps the backward one takes, in
    /// either order (a second pair of sweeps changes values by rounding only).
    fn propagate(&mut self) {
        let [nx, ny, nz] = self.dims;
        let idx = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        // The 27 offsets and what stepping along each adds, computed once.
        let mut steps = [(0i64, 0i64, 0i64, 0.0f64); 27];
        let mut n = 0;
        for dk in -1i64..=1 {
            for dj in -1i64..=1 {
                for di in -1i64..=1 {
                    let d = ((di * di + dj * dj + dk * dk) as f64).sqrt() * self.cell;
                    steps[n] = (di, dj, dk, ALPHA * d);
                    n += 1;
                }
            }
        }
        // A sweep takes the neighbours it has passed already: the forward one the 13 before a
        // cell in index order (the steps before the centre, `steps[13]`), the backward one the
        // 13 after. For interior cells, as index offsets and what each step adds.
        let halves = [&steps[..13], &steps[14..]];
        let offsets = halves.map(|half| -> Vec<isize> {
            half.iter()
                .map(|&(di, dj, dk, _)| (di + (dj + dk * ny as i64) * nx as i64) as isize)
                .collect()
        });
        let adds = halves.map(|half| -> Vec<f64> { half.iter().map(|st| st.3).collect() });
        for pass in 0..2 {
            for kk in 0..nz {
                for jj in 0..ny {
                    for ii in 0..nx {
                        let (i, j, k) = if pass == 0 {
                            (ii, jj, kk)
                        } else {
                            (nx - 1 - ii, ny - 1 - jj, nz - 1 - kk)
                        };
                        let mut best = self.value[idx(i, j, k)];
                        let interior =
                            i > 0 && j > 0 && k > 0 && i + 1 < nx && j + 1 < ny && k + 1 < nz;
                        if interior {
                            // No bounds to check; a plain comparison (no NaN here).
                            let at = idx(i, j, k);
                            for (&offset, &add) in offsets[pass].iter().zip(&adds[pass]) {
                                let x = self.value[at.wrapping_add_signed(offset)] + add;
                                if x < best {
                                    best = x;
                                }
                            }
                            self.value[idx(i, j, k)] = best;
                            continue;
                        }
                        for &(di, dj, dk, add) in halves[pass] {
                            let (a, b, c) = (i as i64 + di, j as i64 + dj, k as i64 + dk);
                            if a < 0
                                || b < 0
                                || c < 0
                                || a >= nx as i64
                                || b >= ny as i64
                                || c >= nz as i64
                            {
                                continue;
                            }
                            best =
                                best.min(self.value[idx(a as usize, b as usize, c as usize)] + add);
                        }
                        self.value[idx(i, j, k)] = best;
                    }
                }
            }
        }
    }
}

/// Drops the entries another one dominates (h_u + ALPHA |u - v| <= h_v): they never give the
/// minimum.
fn prune_dominated(list: &mut Vec<(DVec3, f64)>) {
    list.sort_by(|a, b| a.1.total_cmp(&b.1));
    let mut kept: Vec<(DVec3, f64)> = Vec::with_capacity(list.len());
    for &(p, hv) in list.iter() {
        if !kept.iter().any(|&(q, hq)| hq + ALPHA * q.distance(p) <= hv) {
            kept.push((p, hv));
        }
    }
    *list = kept;
}

impl Spacing for AutoSpacing {
    fn at(&self, p: DVec3) -> f64 {
        // Far sizes through the cell centre's value (Lipschitz from the centre), near small
        // ones exactly from the cell and its 26 neighbours: a small size further away than a
        // cell is already within its grading in the centre values.
        let i = self.index(p);
        let f = self.value[i] + ALPHA * p.distance(self.centre(i));
        let range = self.nearby_start[i] as usize..self.nearby_start[i + 1] as usize;
        self.nearby[range]
            .iter()
            .fold(f, |f, &(q, hq)| f.min(hq + ALPHA * q.distance(p)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    fn exact(sized: &[(DVec3, f64)], p: DVec3) -> f64 {
        sized
            .iter()
            .map(|&(q, h)| h + ALPHA * q.distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn close_to_the_exact_lipschitz_extension() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut sized: Vec<(DVec3, f64)> = (0..400)
            .map(|_| {
                let p = DVec3::new(rng.gen(), rng.gen(), rng.gen());
                (p, rng.gen_range(0.01..0.1))
            })
            .collect();
        // A cluster of tiny sizes, as at an acute corner after recovery.
        let corner = DVec3::new(0.3, 0.6, 0.2);
        for k in 0..30 {
            let r = 0.5f64.powi(k / 3 + 3);
            sized.push((corner + DVec3::new(r, 0.0, 0.0), r * 0.3));
        }
        let s = AutoSpacing::from_sizes(&sized);
        for _ in 0..2000 {
            let p = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            let (f, e) = (s.at(p), exact(&sized, p));
            assert!(
                f >= e * (1.0 - 1e-12) && f <= 3.0 * e,
                "{p}: {f} vs exact {e}"
            );
        }
        // Next to the corner the tiny sizes count exactly; half a cell away they have graded.
        let near = corner + DVec3::new(1e-4, 0.0, 0.0);
        assert!((s.at(near) - exact(&sized, near)).abs() < 1e-12);
        let away = corner + DVec3::new(0.0, 0.5 / CELLS as f64, 0.0);
        assert!(s.at(away) > 10.0 * exact(&sized, near));
    }

    /// The sweeps reach their fixpoint: no cell's value exceeds a neighbour's plus the step,
    /// on scattered sizes and on a single tiny one (the longest chains of steps).
    #[test]
    fn grid_values_are_graded_between_all_neighbours() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(9);
        let scattered: Vec<(DVec3, f64)> = (0..300)
            .map(|_| {
                let p = DVec3::new(rng.gen(), rng.gen::<f64>() * 0.6, rng.gen::<f64>() * 0.3);
                (p, rng.gen_range(0.001..0.2))
            })
            .collect();
        let single = vec![
            (DVec3::new(0.9, 0.05, 0.1), 1e-4),
            (DVec3::ZERO, 1.0),
            (DVec3::new(1.0, 0.7, 0.4), 1.0),
        ];
        for sized in [scattered, single] {
            let s = AutoSpacing::from_sizes(&sized);
            let [nx, ny, nz] = s.dims;
            for i in 0..s.value.len() {
                let (x, y, z) = s.coords(i);
                for j in s.neighbourhood(i) {
                    let (a, b, c) = s.coords(j);
                    let d = [x.abs_diff(a), y.abs_diff(b), z.abs_diff(c)];
                    let step = ALPHA * s.cell * ((d[0] + d[1] + d[2]) as f64).sqrt();
                    assert!(
                        s.value[i] <= (s.value[j] + step) * (1.0 + 1e-12),
                        "cell {i} of {nx}x{ny}x{nz}: {} > {} + {step}",
                        s.value[i],
                        s.value[j]
                    );
                }
            }
        }
    }
}
