//! The improver's objective: the smallest sine of a tet's six dihedral angles.
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

/// The improver's objective: [`min_sin`], capped by `rho_weight / rho` (rho the radius-edge
/// ratio, circumradius over shortest edge). With `rho_weight = sin(target) * max_rho` a tet
/// whose rho exceeds `max_rho` scores below the target like one with a small angle: it is
/// worked on, and no change trades angles for a short edge under a large circumsphere.
/// `rho_weight = inf` leaves [`min_sin`] alone.
#[inline]
pub fn objective(a: DVec3, b: DVec3, c: DVec3, d: DVec3, rho_weight: f64) -> f64 {
    let s = min_sin(a, b, c, d);
    if s <= 0.0 || rho_weight == f64::INFINITY {
        return s;
    }
    let (u, v, w) = (b - a, c - a, d - a);
    let det = u.dot(v.cross(w));
    let l2 = crate::geom::measures::edge_lengths_sq(u, v, w);
    // 2 R det = |num|, so 1 / rho = shortest * 2 det / |num|.
    let num = v.cross(w) * l2[0] + w.cross(u) * l2[1] + u.cross(v) * l2[2];
    let shortest = l2.iter().copied().fold(f64::INFINITY, f64::min).sqrt();
    let inv_rho = 2.0 * det * shortest / num.length();
    if inv_rho.is_finite() {
        s.min(rho_weight * inv_rho)
    } else {
        s
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

    #[test]
    fn objective_caps_by_radius_edge_ratio() {
        let (a, b, c, d) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        let rho = crate::geom::radius_edge_ratio(a, b, c, d);
        assert_eq!(objective(a, b, c, d, f64::INFINITY), min_sin(a, b, c, d));
        let capped = objective(a, b, c, d, 0.1);
        assert!(
            (capped - 0.1 / rho).abs() < 1e-12,
            "{capped} vs {}",
            0.1 / rho
        );
        // A tet with good angles but a short edge under a large sphere: the cap binds.
        let e = DVec3::new(0.05, 0.0, 0.0);
        let (p, q, r, s) = (
            DVec3::ZERO,
            e,
            DVec3::new(0.02, 1.0, 0.0),
            DVec3::new(0.03, 0.5, 0.9),
        );
        let rho = crate::geom::radius_edge_ratio(p, q, r, s);
        let o = objective(p, q, r, s, 0.5);
        assert!((o - (0.5 / rho).min(min_sin(p, q, r, s))).abs() < 1e-12);
        assert_eq!(objective(b, a, c, d, 0.5), min_sin(b, a, c, d));
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
