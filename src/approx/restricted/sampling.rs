//! The surface mesher's first points: the far box around the surface, samples along the
//! feature curves and over the patches, kept apart by a Poisson-disk grid.

use super::*;

impl SurfaceMesher<'_> {
    /// The spacing at the surface's vertices, median (the sample grid's cell size).
    pub(super) fn typical_spacing(&mut self) -> f64 {
        let step = (self.surface.vertices.len() / 64).max(1);
        let pts: Vec<DVec3> = self
            .surface
            .vertices
            .iter()
            .step_by(step)
            .copied()
            .collect();
        let mut raw = vec![f64::NAN; pts.len()];
        if !pts.is_empty() {
            self.spacing.at_many(&pts, &mut raw);
        }
        let mut v: Vec<f64> = pts
            .into_iter()
            .zip(raw)
            .map(|(p, raw)| {
                let triangle = match self.thin {
                    Some(_) => self.oracle.closest(p).map(|c| c.triangle),
                    None => None,
                };
                self.f_value(p, raw, triangle)
            })
            .collect();
        v.sort_by(f64::total_cmp);
        v.get(v.len() / 2).copied().unwrap_or(1.0)
    }

    /// Points along a curve, at most f apart (at least two pieces, three on a closed curve,
    /// so that no two subsegments share both ends).
    pub(super) fn sample_curve(
        &mut self,
        ci: u32,
        curve: &Curve,
        points: &mut Vec<DVec3>,
        grid: &mut SampleGrid,
    ) {
        let len = curve.length();
        let mut params = vec![0.0];
        let mut s = 0.0;
        loop {
            let step = self.f(curve.point_at(s)).min(len);
            if s + step >= len - 0.3 * step {
                break;
            }
            s += step;
            params.push(s);
        }
        let min_pieces = if curve.closed { 3 } else { 2 };
        if params.len() < min_pieces {
            params = (0..min_pieces)
                .map(|k| len * k as f64 / min_pieces as f64)
                .collect();
        }
        params.push(len);
        let corner = |v: u32| self.curves.corner_of[&v] + 8;
        let mut ids = vec![corner(curve.ends[0])];
        for &s in &params[1..params.len() - 1] {
            let p = curve.point_at(s);
            ids.push(points.len() as u32);
            points.push(p);
            self.loc.push(Loc::Curve(ci));
            grid.add(p);
        }
        ids.push(corner(curve.ends[1]));
        for k in 0..ids.len() - 1 {
            self.segs.all.insert(
                key2(ids[k], ids[k + 1]),
                SubSeg {
                    curve: ci,
                    s: [params[k], params[k + 1]],
                    ends: [ids[k], ids[k + 1]],
                },
            );
        }
    }

    /// Poisson-disk samples of every triangle's interior: random points (regular lattices
    /// would put four samples on one circle everywhere on a planar patch, and the Delaunay
    /// triangulation would be full of flat tets), greedy, at least 0.7 f from every accepted
    /// sample and curve point.
    ///
    /// The spacing is evaluated in batches (`Spacing::at_many`): first at every triangle's
    /// centroid (which sets its number of draws), then at the draws of as many triangles as
    /// make [`SPACING_BATCH`] points (the draws do not depend on the spacing); the values are
    /// then used in the order of one by one.
    pub(super) fn sample_patches(
        &mut self,
        points: &mut Vec<DVec3>,
        grid: &mut SampleGrid,
        seed: u64,
    ) {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let n = self.surface.triangles.len();
        let centroids: Vec<DVec3> = (0..n)
            .map(|t| {
                let [a, b, c] = self.surface.corners(t);
                (a + b + c) / 3.0
            })
            .collect();
        let mut at_centroid = vec![f64::NAN; n];
        for (p, out) in centroids
            .chunks(SPACING_BATCH)
            .zip(at_centroid.chunks_mut(SPACING_BATCH))
        {
            self.spacing.at_many(p, out);
        }
        // Triangles whose draws are waiting for their spacing, and the draws.
        let (mut group, mut draws, mut at_draw) = (vec![], vec![], vec![]);
        let mut t = 0;
        while t < n || !group.is_empty() {
            if t < n && draws.len() < SPACING_BATCH {
                let [a, b, c] = self.surface.corners(t);
                let area = 0.5 * (b - a).cross(c - a).length();
                let h = self.bounded(at_centroid[t], Some(t as u32));
                let tries = ((4.0 * area / (h * h)).ceil() as usize).clamp(1, 1 << 16);
                for _ in 0..tries {
                    let (mut u, mut v): (f64, f64) = (rng.gen(), rng.gen());
                    if u + v > 1.0 {
                        (u, v) = (1.0 - u, 1.0 - v);
                    }
                    draws.push(a + (b - a) * u + (c - a) * v);
                }
                group.push((t, tries));
                t += 1;
                continue;
            }
            at_draw.clear();
            at_draw.resize(draws.len(), f64::NAN);
            self.spacing.at_many(&draws, &mut at_draw);
            let mut k = 0;
            for &(t, tries) in &group {
                // Noted in the order of one by one (the first bad value is the error).
                self.f_value(centroids[t], at_centroid[t], Some(t as u32));
                for _ in 0..tries {
                    let p = draws[k];
                    let r = 0.7 * self.f_value(p, at_draw[k], Some(t as u32));
                    k += 1;
                    if grid.has_within(p, r) {
                        continue;
                    }
                    // A repaired input's triangle may bound the solid in part only.
                    if self
                        .repair
                        .is_some_and(|rep| !rep.bounds_solid_at(p, self.surface.normal(t)))
                    {
                        continue;
                    }
                    grid.add(p);
                    points.push(p);
                    self.loc.push(Loc::Patch(self.patch_of[t]));
                }
            }
            group.clear();
            draws.clear();
        }
    }
}

/// Eight points far around the surface, so that every face near it has two finite tets.
pub(super) fn far_box(s: &InputSurface, diagonal: f64) -> Vec<DVec3> {
    let mut lo = DVec3::splat(f64::INFINITY);
    let mut hi = DVec3::splat(f64::NEG_INFINITY);
    for p in &s.vertices {
        lo = lo.min(*p);
        hi = hi.max(*p);
    }
    let pad = DVec3::splat(diagonal.max(1e-300));
    let (lo, hi) = (lo - pad, hi + pad);
    (0..8)
        .map(|k| {
            DVec3::new(
                if k & 1 == 0 { lo.x } else { hi.x },
                if k & 2 == 0 { lo.y } else { hi.y },
                if k & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect()
}

/// A uniform hash grid of accepted samples (Poisson-disk rejection).
pub(super) struct SampleGrid {
    cell: f64,
    origin: DVec3,
    cells: FxHashMap<[i64; 3], Vec<DVec3>>,
}

impl SampleGrid {
    pub(super) fn new(cell: f64, s: &InputSurface) -> SampleGrid {
        let origin = s.vertices.first().copied().unwrap_or(DVec3::ZERO);
        SampleGrid {
            cell: cell.max(1e-12 * s.bbox_diagonal().max(1e-300)),
            origin,
            cells: FxHashMap::default(),
        }
    }

    fn index(&self, p: DVec3) -> [i64; 3] {
        ((p - self.origin) / self.cell)
            .floor()
            .as_i64vec3()
            .to_array()
    }

    pub(super) fn add(&mut self, p: DVec3) {
        let k = self.index(p);
        self.cells.entry(k).or_default().push(p);
    }

    fn has_within(&self, p: DVec3, r: f64) -> bool {
        let reach = ((r / self.cell).ceil() as i64).clamp(1, 8);
        let c = self.index(p);
        for dx in -reach..=reach {
            for dy in -reach..=reach {
                for dz in -reach..=reach {
                    if let Some(list) = self.cells.get(&[c[0] + dx, c[1] + dy, c[2] + dz]) {
                        if list.iter().any(|q| (*q - p).length_squared() < r * r) {
                            return true;
                        }
                    }
                }
            }
        }
        false
    }
}
