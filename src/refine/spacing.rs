//! The automatic spacing used when the caller gives none: a Lipschitz extension of the
//! boundary's local edge lengths after recovery (which splits the boundary down to its local
//! feature size), sampled on a grid: f(x) = min over boundary vertices v of h_v + alpha |x - v|.

use super::domain::Domain;
use super::Spacing;
use glam::DVec3;

/// Grading: how fast the automatic spacing may grow away from the boundary.
const ALPHA: f64 = 0.35;
/// Grid cells along the longest side of the bounding box.
const CELLS: usize = 40;

pub struct AutoSpacing {
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    value: Vec<f64>,
}

impl AutoSpacing {
    pub(crate) fn from_boundary(dom: &Domain) -> AutoSpacing {
        let pts = dom.dt.points();
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for &p in pts {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let ext = (hi - lo).max_element().max(1e-300);
        let cell = ext / CELLS as f64;
        let dims = ((hi - lo) / cell)
            .as_uvec3()
            .to_array()
            .map(|d| d as usize + 1);
        let mut h = vec![f64::INFINITY; pts.len()];
        for t in dom.subfacets.keys() {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                let l = pts[a as usize].distance(pts[b as usize]);
                h[a as usize] = h[a as usize].min(l);
                h[b as usize] = h[b as usize].min(l);
            }
        }
        let mut s = AutoSpacing {
            lo,
            cell,
            dims,
            value: vec![ext / 4.0; dims[0] * dims[1] * dims[2]],
        };
        for (v, &hv) in h.iter().enumerate() {
            if hv.is_finite() {
                let i = s.index(pts[v]);
                s.value[i] = s.value[i].min(hv);
            }
        }
        s.propagate();
        s
    }

    fn index(&self, p: DVec3) -> usize {
        let c = ((p - self.lo) / self.cell).max(DVec3::ZERO);
        let i = (c.x as usize).min(self.dims[0] - 1);
        let j = (c.y as usize).min(self.dims[1] - 1);
        let k = (c.z as usize).min(self.dims[2] - 1);
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    /// Two chamfer sweeps (forward, backward) over the 26-neighbourhood enforce
    /// f(x) <= f(y) + ALPHA |x - y| between neighbouring cells.
    fn propagate(&mut self) {
        let [nx, ny, nz] = self.dims;
        let idx = |i: usize, j: usize, k: usize| (k * ny + j) * nx + i;
        for _ in 0..2 {
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
                            for dk in -1i64..=1 {
                                for dj in -1i64..=1 {
                                    for di in -1i64..=1 {
                                        let (a, b, c) =
                                            (i as i64 + di, j as i64 + dj, k as i64 + dk);
                                        if a < 0
                                            || b < 0
                                            || c < 0
                                            || a >= nx as i64
                                            || b >= ny as i64
                                            || c >= nz as i64
                                        {
                                            continue;
                                        }
                                        let d = ((di * di + dj * dj + dk * dk) as f64).sqrt()
                                            * self.cell;
                                        best = best.min(
                                            self.value[idx(a as usize, b as usize, c as usize)]
                                                + ALPHA * d,
                                        );
                                    }
                                }
                            }
                            self.value[idx(i, j, k)] = best;
                        }
                    }
                }
            }
        }
    }
}

impl Spacing for AutoSpacing {
    fn at(&self, p: DVec3) -> f64 {
        // The cell value plus the grading over at most one cell diagonal keeps f Lipschitz.
        self.value[self.index(p)]
    }
}
