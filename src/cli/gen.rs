//! Seeded point-set generators shared by `slivermesh gen-points`, the built-in demo and
//! `benches/delaunay.rs` (which includes this file by path), so the benchmark, the CLI and the
//! CGAL comparison triangulate exactly the same inputs.
//!
//! All generators use `ChaCha8Rng::seed_from_u64(seed)`, which is portable: the same kind, n and
//! seed give bit-identical points on every platform.

use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// The kinds of point sets we benchmark.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    /// Uniform random in the unit cube [0,1)^3 (general position almost surely).
    Uniform,
    /// The integer grid {0..k-1}^3 with k = round(cbrt(n)): exactly cospherical everywhere.
    Grid,
    /// Uniform random on the unit sphere (every point on the hull; nearly cospherical).
    Sphere,
    /// Gaussian blobs: about n/10,000 centres (at least 1) uniform in the unit cube, sigma 0.01.
    Clustered,
}

impl Kind {
    pub const ALL: [Kind; 4] = [Kind::Uniform, Kind::Grid, Kind::Sphere, Kind::Clustered];

    pub fn name(self) -> &'static str {
        match self {
            Kind::Uniform => "uniform",
            Kind::Grid => "grid",
            Kind::Sphere => "sphere",
            Kind::Clustered => "clustered",
        }
    }

    pub fn from_name(s: &str) -> Option<Kind> {
        Kind::ALL.into_iter().find(|k| k.name() == s)
    }
}

/// Side of the grid used for `n` requested points (k^3 points are made).
pub fn grid_side(n: usize) -> usize {
    let k = (n as f64).cbrt().round() as usize;
    // cbrt of a perfect cube can come out a hair low or high; fix up exactly.
    let mut k = k.max(1);
    while (k + 1).pow(3) <= n {
        k += 1;
    }
    while k > 1 && k.pow(3) > n && (k - 1).pow(3) >= n {
        k -= 1;
    }
    k
}

/// Generates a point set of the given kind. `Grid` makes `grid_side(n)^3` points; the others
/// make exactly `n`.
pub fn generate(kind: Kind, n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    match kind {
        Kind::Uniform => (0..n)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
            .collect(),
        Kind::Grid => {
            let k = grid_side(n);
            let mut pts = Vec::with_capacity(k * k * k);
            for i in 0..k {
                for j in 0..k {
                    for l in 0..k {
                        pts.push(DVec3::new(i as f64, j as f64, l as f64));
                    }
                }
            }
            pts
        }
        Kind::Sphere => (0..n)
            .map(|_| loop {
                let v = DVec3::new(gauss(&mut rng), gauss(&mut rng), gauss(&mut rng));
                let len = v.length();
                if len > 1e-9 {
                    break v / len;
                }
            })
            .collect(),
        Kind::Clustered => {
            let n_centres = (n / 10_000).max(1);
            let centres: Vec<DVec3> = (0..n_centres)
                .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
                .collect();
            let sigma = 0.01;
            (0..n)
                .map(|_| {
                    let c = centres[rng.gen_range(0..n_centres)];
                    c + sigma * DVec3::new(gauss(&mut rng), gauss(&mut rng), gauss(&mut rng))
                })
                .collect()
        }
    }
}

/// A standard normal sample (Box–Muller; one of the pair is discarded for simplicity).
fn gauss(rng: &mut ChaCha8Rng) -> f64 {
    // u1 in (0, 1] so that ln(u1) is finite.
    let u1: f64 = 1.0 - rng.gen::<f64>();
    let u2: f64 = rng.gen();
    (-2.0 * u1.ln()).sqrt() * (std::f64::consts::TAU * u2).cos()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn grid_side_is_nearest_cube_root() {
        assert_eq!(grid_side(1), 1);
        assert_eq!(grid_side(8), 2);
        assert_eq!(grid_side(1_000_000), 100);
        assert_eq!(grid_side(999_999), 100);
        assert_eq!(grid_side(1_000_001), 100);
        assert_eq!(grid_side(27_000), 30);
    }

    #[test]
    fn generators_are_deterministic_and_sized() {
        for kind in Kind::ALL {
            let a = generate(kind, 1000, 7);
            let b = generate(kind, 1000, 7);
            assert_eq!(a, b, "{kind:?}");
            assert_eq!(a.len(), 1000, "{kind:?}");
            assert!(a.iter().all(|p| p.is_finite()));
        }
        assert_ne!(
            generate(Kind::Uniform, 10, 1),
            generate(Kind::Uniform, 10, 2)
        );
    }

    #[test]
    fn generators_have_their_shape() {
        let u = generate(Kind::Uniform, 5000, 3);
        assert!(u
            .iter()
            .all(|p| p.cmpge(DVec3::ZERO).all() && p.cmplt(DVec3::ONE).all()));
        let s = generate(Kind::Sphere, 5000, 3);
        assert!(s.iter().all(|p| (p.length() - 1.0).abs() < 1e-12));
        let g = generate(Kind::Grid, 64, 3);
        assert!(g
            .iter()
            .all(|p| p.x.fract() == 0.0 && p.max_element() <= 3.0));
        let c = generate(Kind::Clustered, 5000, 3);
        let mean = c.iter().copied().sum::<DVec3>() / c.len() as f64;
        // One centre: points are within a few sigma of the mean.
        assert!(c.iter().all(|p| (*p - mean).length() < 0.1));
    }
}
