//! Exact geometric predicates in slivermesh's sign convention.
//!
//! This is the only module that calls the `robust` crate (Shewchuk's adaptive predicates).
//! Our convention: `orient3d(a, b, c, d) > 0` iff `det[b-a, c-a, d-a] > 0`, i.e. the tet
//! (a, b, c, d) is positively oriented (right-handed): (0,0,0),(1,0,0),(0,1,0),(0,0,1) is positive.
//! `insphere(a, b, c, d, e) > 0` iff e lies strictly inside the circumsphere of the positively
//! oriented tet (a, b, c, d).
//!
//! Predicates are exact for finite inputs whose magnitudes lie in [`MIN_COORD`, `MAX_COORD`]
//! (or are zero); [`check_coordinate`] enforces that range at the API boundary.

use glam::DVec3;
use std::cmp::Ordering;

/// Largest accepted coordinate magnitude. robust's insphere evaluates degree-5 products of
/// coordinate differences; 1e75 already overflows (NaN), so stay far below that.
pub const MAX_COORD: f64 = 1e30;
/// Smallest accepted non-zero coordinate magnitude (degree-5 products must not underflow).
pub const MIN_COORD: f64 = 1e-30;

#[inline(always)]
fn c3(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Exact sign-valued orientation: > 0 if (a,b,c,d) is positively oriented, 0 if coplanar.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    // robust's orient3d is positive when d lies *below* the plane of counter-clockwise abc,
    // i.e. negative for a right-handed tet: negate to get our convention.
    -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Exact in-sphere test for a positively oriented tet (a,b,c,d): > 0 iff e is strictly inside.
#[inline]
pub fn insphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> f64 {
    // robust's insphere expects its own positive orientation (our negative one) and then returns
    // > 0 for inside. Swapping a and b turns our positive tet into robust's positive tet.
    robust::insphere(c3(b), c3(a), c3(c), c3(d), c3(e))
}

/// Sign of a float as an `Ordering` (predicate results are exact, so no tolerance).
#[inline(always)]
pub fn sign(x: f64) -> Ordering {
    if x > 0.0 {
        Ordering::Greater
    } else if x < 0.0 {
        Ordering::Less
    } else {
        Ordering::Equal
    }
}

/// In-sphere with symbolic perturbation (Edelsbrunner–Mücke style, as in CGAL's
/// `side_of_oriented_sphere` with perturbation): never returns 0 for five distinct points of
/// which the first four are a positively oriented tet.
///
/// Each point carries a rank (its vertex index); a point of higher rank is perturbed by a larger
/// lift, so on an exact tie the sign is decided by the orientations of the leading monomials.
/// Returns true iff e is (symbolically) strictly inside the circumsphere of (a,b,c,d).
pub fn insphere_sos(p: [DVec3; 4], ranks: [u32; 4], e: DVec3, rank_e: u32) -> bool {
    let s = insphere(p[0], p[1], p[2], p[3], e);
    if s != 0.0 {
        return s > 0.0;
    }
    insphere_tie(p, ranks, e, rank_e)
}

/// Tie-break for an exact in-sphere zero; see [`insphere_sos`].
#[cold]
pub fn insphere_tie(p: [DVec3; 4], ranks: [u32; 4], e: DVec3, rank_e: u32) -> bool {
    // Visit points by decreasing rank; the first one whose cofactor orientation is non-zero
    // decides. Replacing p_i by e in the tet gives that cofactor's sign.
    let mut order = [0usize, 1, 2, 3, 4];
    let rank = |i: usize| if i == 4 { rank_e } else { ranks[i] };
    order.sort_unstable_by_key(|&i| std::cmp::Reverse(rank(i)));
    for &i in &order {
        if i == 4 {
            // e itself has the largest remaining lift: it is lifted above the sphere (outside).
            return false;
        }
        let mut q = p;
        q[i] = e;
        let o = orient3d(q[0], q[1], q[2], q[3]);
        if o != 0.0 {
            return o > 0.0;
        }
    }
    unreachable!("insphere_tie: the first four points must form a non-degenerate tet")
}

/// Why a coordinate was rejected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum CoordError {
    NotFinite,
    TooLarge,
    TooSmall,
}

impl std::fmt::Display for CoordError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            CoordError::NotFinite => write!(f, "coordinate is not finite"),
            CoordError::TooLarge => write!(f, "coordinate magnitude exceeds {MAX_COORD:e}"),
            CoordError::TooSmall => {
                write!(f, "non-zero coordinate magnitude below {MIN_COORD:e}")
            }
        }
    }
}

/// Checks that a point can be used with the exact predicates without overflow or underflow.
pub fn check_coordinate(p: DVec3) -> Result<(), CoordError> {
    for v in p.to_array() {
        if !v.is_finite() {
            return Err(CoordError::NotFinite);
        }
        let m = v.abs();
        if m > MAX_COORD {
            return Err(CoordError::TooLarge);
        }
        if m != 0.0 && m < MIN_COORD {
            return Err(CoordError::TooSmall);
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    const O: DVec3 = DVec3::ZERO;
    const X: DVec3 = DVec3::X;
    const Y: DVec3 = DVec3::Y;
    const Z: DVec3 = DVec3::Z;

    #[test]
    fn orient3d_right_handed_is_positive() {
        assert!(orient3d(O, X, Y, Z) > 0.0);
        assert!(orient3d(O, Y, X, Z) < 0.0);
        assert_eq!(orient3d(O, X, Y, X + Y), 0.0);
        // value is det[b-a, c-a, d-a] = 6 * volume
        assert_eq!(orient3d(O, X, Y, Z), 1.0);
    }

    #[test]
    fn orient3d_exact_on_collinear_and_tiny_offsets() {
        let a = DVec3::new(1.0, 1.0, 1.0);
        let b = DVec3::new(3.0, 5.0, 7.0);
        let d = DVec3::new(2.0, 3.0, 4.0); // on segment ab
        assert_eq!(orient3d(a, b, d, DVec3::new(3.0, -1.0, 7.0)), 0.0);
        // a point one ulp off the plane z = 0.5 must get the right sign
        let p = [DVec3::new(0.0, 0.0, 0.5), DVec3::new(12.0, 0.0, 0.5), DVec3::new(0.0, 24.0, 0.5)];
        let above = DVec3::new(3.1, 7.3, f64::from_bits(0.5f64.to_bits() + 1));
        let below = DVec3::new(3.1, 7.3, f64::from_bits(0.5f64.to_bits() - 1));
        assert!(orient3d(p[0], p[1], p[2], above) > 0.0);
        assert!(orient3d(p[0], p[1], p[2], below) < 0.0);
    }

    #[test]
    fn insphere_inside_is_positive() {
        assert!(insphere(O, X, Y, Z, DVec3::splat(0.25)) > 0.0);
        assert!(insphere(O, X, Y, Z, DVec3::splat(2.0)) < 0.0);
        // (1,1,1) lies on the sphere through O, X, Y, Z (centre (.5,.5,.5)).
        assert_eq!(insphere(O, X, Y, Z, DVec3::ONE), 0.0);
        // the newest (highest-rank) point of a tie is perturbed outside
        assert!(!insphere_sos([O, X, Y, Z], [0, 1, 2, 3], DVec3::ONE, 4));
    }

    #[test]
    fn insphere_sos_is_consistent_across_a_shared_face() {
        // O, X, Y, Z and W = (1,1,0) are cospherical. T1 = (O,X,Y,Z) and T2 = (W,Y,X,Z) share
        // face XYZ. Face XYZ is locally Delaunay iff W is outside T1's sphere iff O is outside
        // T2's sphere: the perturbed predicate must agree with itself for every rank order.
        let w = DVec3::new(1.0, 1.0, 0.0);
        let t2 = [w, Y, X, Z];
        assert!(orient3d(t2[0], t2[1], t2[2], t2[3]) > 0.0);
        let mut perms = vec![];
        permute(&mut [0u32, 1, 2, 3, 4], 0, &mut perms);
        for r in perms {
            // ranks of O, X, Y, Z, W
            let in1 = insphere_sos([O, X, Y, Z], [r[0], r[1], r[2], r[3]], w, r[4]);
            let in2 = insphere_sos(t2, [r[4], r[2], r[1], r[3]], O, r[0]);
            assert_eq!(in1, in2, "ranks {r:?}");
        }
    }

    fn permute(a: &mut [u32; 5], k: usize, out: &mut Vec<[u32; 5]>) {
        if k == a.len() {
            out.push(*a);
            return;
        }
        for i in k..a.len() {
            a.swap(k, i);
            permute(a, k + 1, out);
            a.swap(k, i);
        }
    }

    #[test]
    fn coordinate_validation() {
        assert!(check_coordinate(DVec3::new(1.0, -2.0, 0.0)).is_ok());
        assert_eq!(
            check_coordinate(DVec3::new(f64::NAN, 0.0, 0.0)),
            Err(CoordError::NotFinite)
        );
        assert_eq!(
            check_coordinate(DVec3::new(0.0, 1e31, 0.0)),
            Err(CoordError::TooLarge)
        );
        assert_eq!(
            check_coordinate(DVec3::new(0.0, 0.0, 1e-40)),
            Err(CoordError::TooSmall)
        );
        // at the limits the predicates stay exact (no NaN)
        let s = MAX_COORD;
        let v = insphere(
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(s, 0.0, 0.0),
            DVec3::new(0.0, s, 0.0),
            DVec3::new(0.0, 0.0, s),
            DVec3::new(s, s, s),
        );
        assert!(v.is_finite());
    }
}
