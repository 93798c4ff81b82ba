//! The improver's objective: the smallest sine of a tet's six dihedral angles, large angles
//! weighted more once bad ([`Objective`]).
//!
//! sin(theta) is small both for angles near 0 and near 180 degrees, so maximising the smallest
//! sine pushes both ends of the dihedral range inwards (Klingner & Shewchuk's choice). For the
//! edge e between the faces opposite vertices k and l, sin(theta_e) = 6V * |e| / (|n_k| |n_l|)
//! with |n| twice a face's area. The sign follows the orientation, so an inverted tet scores
//! below every valid one. Floating point only: validity is decided by the exact `orient3d`.

use glam::DVec3;

/// The two faces (by opposite local vertex) meeting at edges ab, ac, ad, bc, bd, cd.
const EDGE_FACES: [[usize; 2]; 6] = [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]];

/// sin of the dihedral angle of the regular tetrahedron (2 sqrt 2 / 3).
pub const REGULAR_SIN: f64 = 0.942_809_041_582_063_4;

/// Smallest sine of the dihedral angles of (a, b, c, d), signed by its orientation: in (0, 1]
/// for a positively oriented tet, <= 0 for a flat or inverted one. Never NaN for finite input.
#[inline]
pub fn min_sin(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let (u, v, w) = (b - a, c - a, d - a);
    let n = [
        (v - u).cross(w - u).length(),
        w.cross(v).length(),
        u.cross(w).length(),
        v.cross(u).length(),
    ];
    let det = u.dot(v.cross(w));
    let l2 = crate::geom::measures::edge_lengths_sq(u, v, w);
    let mut m = f64::INFINITY;
    for (i, [k, l]) in EDGE_FACES.iter().copied().enumerate() {
        m = m.min(l2[i].sqrt() / (n[k] * n[l]));
    }
    let s = det * m;
    if s.is_finite() {
        s.clamp(-1.0, 1.0)
    } else {
        0.0
    }
}

/// Obtuse angles above 180 degrees minus this count more than their sine (TetGen's optimiser
/// bounds the largest dihedral angle at 165 degrees, the acute-free goal is 160).
const LARGE_ANGLE_PIVOT_DEG: f64 = 20.0;

/// The improver's objective, per tet: [`min_sin`] with two changes.
///
/// - Large angles count more than small ones once they are bad: an obtuse angle whose sine
///   `s` is below `pivot` (the sine of the target angle, or of 20 degrees if that is smaller)
///   scores `s * s / pivot`. Where a small input angle forces a degenerate tet, the improver
///   then prefers a small angle to a large one: an angle near 180 degrees harms the
///   interpolation of a finite element (Babuska and Aziz's maximum angle condition), one near
///   0 mostly its conditioning. Above the pivot nothing changes, and the pivot is never above
///   the target, so a tet the target calls good is scored as before.
/// - It is capped by `rho_weight / rho` (rho the radius-edge ratio, circumradius over
///   shortest edge). With `rho_weight = sin(target) * max_rho` a tet whose rho exceeds
///   `max_rho` scores below the target like one with a small angle: it is worked on, and no
///   change trades angles for a short edge under a large circumsphere. `rho_weight = inf`
///   leaves the angles alone.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Objective {
    pub pivot: f64,
    pub rho_weight: f64,
}

impl Objective {
    /// The objective for a target angle (degrees) and a radius-edge bound (inf: none).
    pub fn new(target_deg: f64, max_rho: f64) -> Objective {
        let target = target_deg.to_radians().sin();
        Objective {
            pivot: target_deg.min(LARGE_ANGLE_PIVOT_DEG).to_radians().sin(),
            rho_weight: target * max_rho,
        }
    }

    /// The objective of tet (a, b, c, d): <= 0 when flat or inverted.
    #[inline]
    pub fn of(&self, a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        let (u, v, w) = (b - a, c - a, d - a);
        // Outward normals (for a positive tet) of the faces opposite a, b, c, d.
        let n = [(v - u).cross(w - u), w.cross(v), u.cross(w), v.cross(u)];
        let len = n.map(|x| x.length());
        let det = u.dot(v.cross(w));
        let l2 = crate::geom::measures::edge_lengths_sq(u, v, w);
        let mut m = f64::INFINITY;
        let mut weighted = f64::INFINITY;
        for (i, [k, l]) in EDGE_FACES.iter().copied().enumerate() {
            let r = l2[i].sqrt() / (len[k] * len[l]);
            m = m.min(r);
            let s = det * r;
            // Outward normals at an acute angle to each other: an obtuse dihedral angle.
            if s > 0.0 && s < self.pivot && n[k].dot(n[l]) > 0.0 {
                weighted = weighted.min(s * s / self.pivot);
            }
        }
        let s = det * m;
        if !s.is_finite() {
            return 0.0;
        }
        let s = s.clamp(-1.0, 1.0);
        if s <= 0.0 {
            return s;
        }
        let s = s.min(weighted);
        if self.rho_weight == f64::INFINITY {
            return s;
        }
        // 2 R det = |num|, so 1 / rho = shortest * 2 det / |num|.
        let num = v.cross(w) * l2[0] + w.cross(u) * l2[1] + u.cross(v) * l2[2];
        let shortest = l2.iter().copied().fold(f64::INFINITY, f64::min).sqrt();
        let inv_rho = 2.0 * det * shortest / num.length();
        if inv_rho.is_finite() {
            s.min(self.rho_weight * inv_rho)
        } else {
            s
        }
    }
}

/// The angle in degrees whose sine is `s` (for reporting thresholds).
pub fn sin_to_deg(s: f64) -> f64 {
    s.clamp(-1.0, 1.0).asin().to_degrees()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geom::dihedral_angles;

    fn brute(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        dihedral_angles(a, b, c, d)
            .iter()
            .map(|x| x.to_radians().sin())
            .fold(f64::INFINITY, f64::min)
    }

    #[test]
    fn matches_dihedral_angles() {
        let s = (2.0f64).sqrt();
        let regular = [
            DVec3::new(1.0, 0.0, -1.0 / s),
            DVec3::new(-1.0, 0.0, -1.0 / s),
            DVec3::new(0.0, 1.0, 1.0 / s),
            DVec3::new(0.0, -1.0, 1.0 / s),
        ];
        let [a, b, c, d] = regular;
        let q = min_sin(a, b, c, d).abs();
        assert!((q - REGULAR_SIN).abs() < 1e-12, "{q}");
        let cases = [
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            // sliver: four nearly coplanar points of a square
            [
                DVec3::ZERO,
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.05),
                DVec3::new(0.0, 1.0, 0.0),
            ],
            // needle
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 40.0)],
            // cap: one vertex near the opposite face's centre
            [
                DVec3::ZERO,
                DVec3::X,
                DVec3::new(0.5, 0.9, 0.0),
                DVec3::new(0.5, 0.3, 0.02),
            ],
        ];
        for [a, b, c, d] in cases {
            let (p, q) = (min_sin(a, b, c, d), brute(a, b, c, d));
            let p = p.abs();
            assert!((p - q).abs() < 1e-9, "{p} vs {q}");
        }
    }

    /// The radius-edge cap alone (no obtuse weighting).
    fn capped(rho_weight: f64) -> Objective {
        Objective {
            pivot: 0.0,
            rho_weight,
        }
    }

    #[test]
    fn objective_caps_by_radius_edge_ratio() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        let rho = crate::geom::radius_edge_ratio(a, b, c, d);
        assert_eq!(capped(f64::INFINITY).of(a, b, c, d), min_sin(a, b, c, d));
        let q = capped(0.1).of(a, b, c, d);
        assert!((q - 0.1 / rho).abs() < 1e-12, "{q} vs {}", 0.1 / rho);
        // A tet with good angles but a short edge under a large sphere: the cap binds.
        let e = DVec3::new(0.05, 0.0, 0.0);
        let (p, q, r, s) = (
            DVec3::ZERO,
            e,
            DVec3::new(0.02, 1.0, 0.0),
            DVec3::new(0.03, 0.5, 0.9),
        );
        let rho = crate::geom::radius_edge_ratio(p, q, r, s);
        let o = capped(0.5).of(p, q, r, s);
        assert!((o - (0.5 / rho).min(min_sin(p, q, r, s))).abs() < 1e-12);
        assert_eq!(capped(0.5).of(b, a, c, d), min_sin(b, a, c, d));
    }

    /// An obtuse angle below the pivot scores s^2 / pivot, an acute one s; at and above the
    /// pivot nothing changes.
    #[test]
    fn large_angles_count_more_than_small_ones_below_the_pivot() {
        let obj = Objective::new(20.0, f64::INFINITY);
        let check = |t: [DVec3; 4], obtuse_worst: bool| {
            let [a, b, c, d] = t;
            let angles = dihedral_angles(a, b, c, d);
            let s = angles
                .iter()
                .map(|x| {
                    let s = x.to_radians().sin();
                    if *x > 90.0 && s < obj.pivot {
                        s * s / obj.pivot
                    } else {
                        s
                    }
                })
                .fold(f64::INFINITY, f64::min);
            let q = obj.of(a, b, c, d);
            assert!((q - s).abs() < 1e-9, "{q} vs {s} ({angles:?})");
            let largest = angles.iter().copied().fold(0.0, f64::max);
            assert_eq!(q < min_sin(a, b, c, d) - 1e-12, obtuse_worst, "{angles:?}");
            assert_eq!(
                obtuse_worst,
                largest > 180.0 - obj.pivot.asin().to_degrees()
            );
        };
        // cap: one vertex near the opposite face's centre (angles near 180)
        let cap = [
            DVec3::ZERO,
            DVec3::X,
            DVec3::new(0.5, 0.9, 0.0),
            DVec3::new(0.5, 0.3, 0.02),
        ];
        check(cap, true);
        // needle: small angles only
        check(
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 40.0)],
            false,
        );
        // corner tet: 90 degrees at most
        check([DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z], false);
    }

    #[test]
    fn sign_follows_orientation() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        assert!(min_sin(a, b, c, d) > 0.0);
        assert!(min_sin(b, a, c, d) < 0.0);
        assert_eq!(min_sin(a, b, c, a + b), 0.0);
        assert_eq!(min_sin(a, a, c, d), 0.0);
    }
}
