//! The fast screening form of the tet measures, beside their definitions in `measures.rs`:
//! what refinement decides on for every new tet, without trigonometry or square roots where it
//! can. [`SliverScreen`] clears most good tets from squared quantities alone (profiled: the
//! classification of new tets and the small-sliver test of candidate points dominate
//! refinement); [`sliver_measures`] gives sigma and the cosine of the smallest dihedral angle
//! for the rest. Tests check both against [`super::TetQuality`].

use glam::DVec3;

/// Length of the longest edge, from the six point differences (not through b - a, c - a,
/// d - a as [`super::longest_edge`]: refinement's decisions were measured with this form).
#[inline]
pub fn longest_edge_direct(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    [
        a.distance_squared(b),
        a.distance_squared(c),
        a.distance_squared(d),
        b.distance_squared(c),
        b.distance_squared(d),
        c.distance_squared(d),
    ]
    .into_iter()
    .fold(0.0, f64::max)
    .sqrt()
}

/// Squared length of the shortest edge, from the six point differences.
#[inline]
pub fn shortest_edge_sq(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    [
        a.distance_squared(b),
        a.distance_squared(c),
        a.distance_squared(d),
        b.distance_squared(c),
        b.distance_squared(d),
        c.distance_squared(d),
    ]
    .into_iter()
    .fold(f64::INFINITY, f64::min)
}

/// sigma = V / L^3 and the cosine of the smallest dihedral angle, given L^2 = `l2`: the
/// trigonometry-free form of [`super::TetQuality`]'s `sigma` and `min_dihedral` (equal to
/// 1e-12, checked by a test). V comes from the float determinant, not [`super::orient3d`].
#[inline]
pub fn sliver_measures(a: DVec3, b: DVec3, c: DVec3, d: DVec3, l2: f64) -> (f64, f64) {
    let volume = (b - a).dot((c - a).cross(d - a)).abs() / 6.0;
    // Face normals, all outward or all inward (the sign cancels): the dihedral angle at an
    // edge is pi minus the angle between its two faces' normals, so its cosine is
    // -n_i . n_j / (|n_i| |n_j|).
    let n = [
        (d - b).cross(c - b),
        (c - a).cross(d - a),
        (d - a).cross(b - a),
        (b - a).cross(c - a),
    ];
    let len = n.map(|v| v.length());
    let mut max_cos = -1.0f64;
    for i in 0..4 {
        for j in i + 1..4 {
            let cos = -n[i].dot(n[j]) / (len[i] * len[j]);
            max_cos = max_cos.max(cos);
        }
    }
    let sigma = volume / (l2 * l2.sqrt());
    (sigma, if max_cos.is_nan() { 1.0 } else { max_cos })
}

/// A cheap sufficient condition for "not a sliver" (sigma >= sigma0 and every dihedral angle
/// within [min_dihedral, 180 - min_dihedral]), in squares only: no square root, no division.
/// It holds with a relative margin, so that [`sliver_measures`] would surely find the tet
/// good too; the tets it does not clear (slivers and near misses) get the full measures.
#[derive(Debug, Clone, Copy)]
pub struct SliverScreen {
    /// 36 sigma0^2 (1 + MARGIN): sigma >= sigma0 iff det^2 >= 36 sigma0^2 L^6.
    sigma: f64,
    /// sin^2(min_dihedral) (1 + MARGIN): the dihedral angle at edge e, between the faces
    /// with normals (cross products) n_r and n_s, has sin = |det| |e| / (|n_r| |n_s|).
    dihedral: f64,
}

impl SliverScreen {
    /// Tets screened together by [`Self::for_each_uncleared`] (lanes of one vectorized pass).
    pub const BATCH: usize = 8;

    const MARGIN: f64 = 1e-6;

    /// The screen for the bounds sigma >= `sigma0` and smallest dihedral angle >=
    /// `min_dihedral_deg`.
    pub fn new(sigma0: f64, min_dihedral_deg: f64) -> Self {
        let s0 = min_dihedral_deg.to_radians().sin();
        SliverScreen {
            sigma: 36.0 * sigma0 * sigma0 * (1.0 + Self::MARGIN),
            dihedral: s0 * s0 * (1.0 + Self::MARGIN),
        }
    }

    /// The screen for one tet, as refinement's classification runs it (through
    /// [`Self::clears`]).
    pub fn clearly_not_sliver(&self, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> bool {
        let (u, v, w) = (b - a, c - a, d - a);
        let det = u.dot(v.cross(w));
        let e = [
            u.length_squared(),
            v.length_squared(),
            w.length_squared(),
            (c - b).length_squared(),
            (d - b).length_squared(),
            (d - c).length_squared(),
        ];
        let l2 = e[0].min(e[1]).min(e[2]).min(e[3]).min(e[4]).min(e[5]);
        if det * det <= self.sigma * (l2 * l2 * l2) {
            return false;
        }
        let n = [
            (d - b).cross(c - b).length_squared(),
            v.cross(w).length_squared(),
            w.cross(u).length_squared(),
            u.cross(v).length_squared(),
        ];
        self.clears(det, e, l2, n)
    }

    /// For every new tet (a, b, c, p) of `faces` (`corners` gives None for a face to skip): calls
    /// `f` with the corners of those the screen does not clear, in order, until `f` returns
    /// false. The screen runs over batches laid out by coordinate, so that it vectorizes.
    pub fn for_each_uncleared<F>(
        &self,
        faces: &[F],
        corners: impl Fn(&F) -> Option<[DVec3; 3]>,
        p: DVec3,
        mut f: impl FnMut([DVec3; 3]) -> bool,
    ) {
        const BATCH: usize = SliverScreen::BATCH;
        for batch in faces.chunks(BATCH) {
            // Skipped lanes and those beyond the batch stay zero (flat: never cleared).
            let mut q = [[0.0f64; BATCH]; 9];
            let mut tri = [None; BATCH];
            for (k, face) in batch.iter().enumerate() {
                let Some(c) = corners(face) else {
                    continue;
                };
                tri[k] = Some(c);
                for (j, &x) in c.iter().enumerate() {
                    let d = x - p;
                    q[3 * j][k] = d.x;
                    q[3 * j + 1][k] = d.y;
                    q[3 * j + 2][k] = d.z;
                }
            }
            let clear = self.clears_batch(&q);
            for (t, clear) in tri.into_iter().zip(clear) {
                if let Some(c) = t.filter(|_| !clear) {
                    if !f(c) {
                        return;
                    }
                }
            }
        }
    }

    /// The screen for a batch of tets (p, x_k, y_k, z_k) given by the coordinates relative to
    /// p: `q[0..3]` = x - p, `q[3..6]` = y - p, `q[6..9]` = z - p (lane k: tet k). Branch-free
    /// over the lanes, so that it vectorizes.
    #[inline]
    pub fn clears_batch<const N: usize>(&self, q: &[[f64; N]; 9]) -> [bool; N] {
        let mut out = [false; N];
        for (k, o) in out.iter_mut().enumerate() {
            let (ux, uy, uz) = (q[0][k], q[1][k], q[2][k]);
            let (vx, vy, vz) = (q[3][k], q[4][k], q[5][k]);
            let (wx, wy, wz) = (q[6][k], q[7][k], q[8][k]);
            // Face edges y - x, z - x, z - y.
            let (ax, ay, az) = (vx - ux, vy - uy, vz - uz);
            let (bx, by, bz) = (wx - ux, wy - uy, wz - uz);
            let (cx, cy, cz) = (wx - vx, wy - vy, wz - vz);
            let e = [
                ux * ux + uy * uy + uz * uz,
                vx * vx + vy * vy + vz * vz,
                wx * wx + wy * wy + wz * wz,
                ax * ax + ay * ay + az * az,
                bx * bx + by * by + bz * bz,
                cx * cx + cy * cy + cz * cz,
            ];
            let m = |a: f64, b: f64| if b < a { b } else { a };
            let l2 = m(m(m(e[0], e[1]), m(e[2], e[3])), m(e[4], e[5]));
            // Normals of the faces opposite x (p, y, z), y, z and p (x, y, z).
            let (nxx, nxy, nxz) = (vy * wz - vz * wy, vz * wx - vx * wz, vx * wy - vy * wx);
            let (nyx, nyy, nyz) = (wy * uz - wz * uy, wz * ux - wx * uz, wx * uy - wy * ux);
            let (nzx, nzy, nzz) = (uy * vz - uz * vy, uz * vx - ux * vz, ux * vy - uy * vx);
            let (npx, npy, npz) = (ay * bz - az * by, az * bx - ax * bz, ax * by - ay * bx);
            let det = ux * nxx + uy * nxy + uz * nxz;
            let n = [
                nxx * nxx + nxy * nxy + nxz * nxz,
                nyx * nyx + nyy * nyy + nyz * nyz,
                nzx * nzx + nzy * nzy + nzz * nzz,
                npx * npx + npy * npy + npz * npz,
            ];
            let det2 = det * det;
            let kd = self.dihedral;
            // Edges px, py, pz, xy, xz, yz and the faces meeting there (opposite the other
            // two vertices).
            *o = (det2 > self.sigma * (l2 * l2 * l2))
                & (det2 * e[0] >= kd * (n[1] * n[2]))
                & (det2 * e[1] >= kd * (n[0] * n[2]))
                & (det2 * e[2] >= kd * (n[0] * n[1]))
                & (det2 * e[3] >= kd * (n[2] * n[3]))
                & (det2 * e[4] >= kd * (n[1] * n[3]))
                & (det2 * e[5] >= kd * (n[0] * n[3]));
        }
        out
    }

    /// The screen from the tet's pieces: `det` = det[b-a, c-a, d-a] (up to a relative error
    /// far below the margin), the squared edge lengths `e` (ab, ac, ad, bc, bd, cd), the
    /// shortest `l2` and the squared normal lengths `n` of the faces opposite a, b, c, d.
    #[inline]
    pub fn clears(&self, det: f64, e: [f64; 6], l2: f64, n: [f64; 4]) -> bool {
        let det2 = det * det;
        if det2 <= self.sigma * (l2 * l2 * l2) {
            return false; // (a flat tet is never cleared, even with sigma0 = 0)
        }
        // Edges ab, ac, ad, bc, bd, cd and the faces meeting there (opposite the other two).
        let k = self.dihedral;
        det2 * e[0] >= k * (n[2] * n[3])
            && det2 * e[1] >= k * (n[1] * n[3])
            && det2 * e[2] >= k * (n[1] * n[2])
            && det2 * e[3] >= k * (n[0] * n[3])
            && det2 * e[4] >= k * (n[0] * n[2])
            && det2 * e[5] >= k * (n[0] * n[1])
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::TetQuality;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    /// The bounds refinement screens against by default (`run::params::Params`).
    struct Bounds {
        sigma0: f64,
        min_dihedral: f64,
    }
    impl Default for Bounds {
        fn default() -> Self {
            Bounds {
                sigma0: 0.02,
                min_dihedral: 15.0,
            }
        }
    }

    fn l2_of(p: &[DVec3; 4]) -> f64 {
        shortest_edge_sq(p[0], p[1], p[2], p[3])
    }

    #[test]
    fn sliver_screen_clears_only_good_tets() {
        let params = Bounds::default();
        let screen = SliverScreen::new(params.sigma0, params.min_dihedral);
        let cos_min = params.min_dihedral.to_radians().cos();
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let mut cleared = 0;
        let mut flagged = 0;
        for k in 0..200_000 {
            let mut p = [DVec3::ZERO; 4];
            for q in p.iter_mut() {
                *q = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            }
            if k % 2 == 1 {
                // Near-slivers and near-flat tets: squash the fourth vertex towards a plane.
                let t: f64 = rng.gen::<f64>().powi(4);
                p[3] = p[3].lerp((p[0] + p[1] + p[2]) / 3.0 + (p[3] - p[0]) * 0.01, 1.0 - t);
            }
            let (sigma, max_cos) = sliver_measures(p[0], p[1], p[2], p[3], l2_of(&p));
            let bad = sigma < params.sigma0 || max_cos > cos_min;
            // The batch form, as small_slivers runs it: (p[3], p[0], p[1], p[2]) relative to
            // p[3], in lane k % 4 of a batch of 4.
            let mut q = [[0.0; 4]; 9];
            for j in 0..3 {
                let d = p[j] - p[3];
                q[3 * j][k % 4] = d.x;
                q[3 * j + 1][k % 4] = d.y;
                q[3 * j + 2][k % 4] = d.z;
            }
            let batch = screen.clears_batch(&q);
            assert!(!batch[(k + 1) % 4], "an empty lane is cleared");
            let single = screen.clearly_not_sliver(p[0], p[1], p[2], p[3]);
            for clear in [single, batch[k % 4]] {
                if clear {
                    assert!(!bad, "{p:?}: cleared, sigma {sigma} cos {max_cos}");
                    cleared += 1;
                } else if !bad {
                    flagged += 1;
                }
            }
        }
        // It clears nearly every good tet (not those with a dihedral angle near 180 degrees).
        assert!(
            cleared > 100_000 && flagged < cleared / 100,
            "{cleared} {flagged}"
        );
    }

    #[test]
    fn screen_measures_agree_with_tet_quality() {
        let tets = [
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            [
                DVec3::new(0.1, 0.2, 0.0),
                DVec3::new(1.0, 0.1, 0.05),
                DVec3::new(0.4, 0.9, 0.1),
                DVec3::new(0.5, 0.4, 0.03),
            ],
            [
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.5, 0.866, 0.0),
                DVec3::new(0.5, 0.3, 0.8),
            ],
        ];
        for t in tets {
            for flip in [false, true] {
                let [a, mut b, mut c, d] = t;
                if flip {
                    std::mem::swap(&mut b, &mut c);
                }
                let (sigma, max_cos) = sliver_measures(a, b, c, d, l2_of(&[a, b, c, d]));
                let q = TetQuality::of(a, b, c, d);
                assert!((max_cos - q.min_dihedral.to_radians().cos()).abs() < 1e-12);
                assert!((sigma - q.sigma).abs() < 1e-12 * q.sigma.max(1.0));
                let le = longest_edge_direct(a, b, c, d);
                assert!((le - super::super::longest_edge(a, b, c, d)).abs() < 1e-12);
                let l = shortest_edge_sq(a, b, c, d).sqrt();
                assert!((l - q.shortest_edge).abs() < 1e-12);
            }
        }
    }
}
