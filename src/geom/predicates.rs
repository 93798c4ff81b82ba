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
//!
//! # Semi-static filters
//!
//! [`orient3d`] and [`insphere`] first evaluate Shewchuk's determinant expressions in plain
//! `f64` (no FMA: Rust never contracts) and return that value when its magnitude exceeds an
//! error bound `eps`; otherwise they call robust's adaptive (exact) predicate. The bound is
//! computed per call from the largest coordinate differences per axis (as CGAL's
//! `Static_filters` do), so it adapts to the scale of the input.
//!
//! **Derivation.** Let `u = 2^-53` (unit roundoff, round to nearest). Let `X`, `Y`, `Z` be the
//! largest magnitudes of the *computed* x-, y-, z-differences (for orient3d the three
//! differences `a-d, b-d, c-d`; for insphere the four `·-e`), `M = max(X, Y, Z)`. For every
//! computed quantity `q̂` (exact value `q`) track `|q| <= S·m` and `|q̂ - q| <= E·m` where `m`
//! is the quantity's monomial in the maxima: a difference has `m = X` (or Y, Z), a 2x2 minor
//! `XY`, a 3x3 term `XYZ`, a lift `x²+y²+z²` is bounded with `m = M²`, insphere's determinant
//! has `m = XYZ·M²`. The rules (standard model, `|fl(x) - x| <= u·|fl(x)|` and `<= u·|x|`):
//!
//! * difference `d̂ = fl(p - q)` (an input to the rest): `E = u`, `S = 1 + u` (as `|d̂| <= m`);
//!   a difference that is subnormal is exact.
//! * sum `fl(â ± b̂)`: `E = Ea + Eb + u·(Sa + Ea + Sb + Eb)`, `S = Sa + Sb` (a subnormal sum is
//!   exact, so underflow adds nothing).
//! * product `fl(â·b̂)`: `|â b̂ - a b| <= |â|·|b̂ - b| + |b|·|â - a|` and the rounding adds
//!   `u·|â b̂| + η` where `η = 2^-1075` covers a subnormal result. We require `min(X, Y, Z) >=
//!   2^-190` ([`FILTER_MIN`]) so every monomial (degree <= 5, all maxima <= 1 worst case) is at
//!   least `2^-950 >= η / u`: then `η <= u·m`, and
//!   `E = (Sa + Ea)·Eb + Sb·Ea + u·(Sa + Ea)(Sb + Eb) + u`, `S = Sa·Sb`.
//!
//! Propagating exactly (rational arithmetic in `u`) through the evaluation order used below
//! (minors `x·y - x·y`; terms `(z·m1 - z·m2) + z·m3`; lifts `(x·x + y·y) + z·z`; insphere
//! `(l·t - l·t) + (l·t - l·t)`; orient3d `(z·m1 + z·m2) + z·m3`) gives
//!
//! * orient3d: `|det̂ - det| <= 55.00000000000004·u·XYZ`,
//! * insphere: `|det̂ - det| <= 1288.000000000002·u·XYZ·M²`.
//!
//! (Same order as CGAL's generated bounds, 5.11e-15 and 1.2466e-13, for their evaluation
//! orders; ours are 6.11e-15 and 1.43e-13.) The bound itself is evaluated in floating point as
//! `((((C·X)·Y)·Z)·M)·M`, which can only lose a factor `(1 - u)^5`; the constants are rounded
//! up to `56·u` ([`ORIENT3D_EPS`]) and `1289·u` ([`INSPHERE_EPS`]), which covers that. With
//! `FILTER_MIN = 2^-190` every product in the bound is a normal number (`C·2^-950 > 2^-1022`);
//! with `M <= 2^190` ([`FILTER_MAX`]) no intermediate can overflow (each is below
//! `73·M^5 < 2^960`). When `|det̂| > eps` the sign of `det̂` is the sign of `det`. Otherwise
//! (or when the maxima leave `[FILTER_MIN, FILTER_MAX]`, or for NaN, where every comparison is
//! false) the exact predicate decides. One more exact shortcut: if the differences along one
//! axis are all exactly zero, every term of the expansion has a zero factor, so the
//! determinant is exactly zero. The bounds are re-derived by a test (`filter_bounds_derivation`)
//! and the filters are checked against robust on near-degenerate inputs.

use super::wide::{W3, W5};
use glam::DVec3;
use std::cmp::Ordering;

/// Largest accepted coordinate magnitude. robust's insphere evaluates degree-5 products of
/// coordinate differences; 1e75 already overflows (NaN), so stay far below that.
pub const MAX_COORD: f64 = 1e30;
/// Smallest accepted non-zero coordinate magnitude (degree-5 products must not underflow).
pub const MIN_COORD: f64 = 1e-30;

/// `max` for the filters' maxima: one `maxsd` (LLVM turns `if a > b { a } else { b }` into
/// a mispredicting branch in places). Unlike `f64::max` it need not skip NaN operands: a NaN
/// difference makes the determinant NaN, and a NaN determinant never passes the filter test.
#[inline(always)]
fn fmax(a: f64, b: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is baseline on x86_64; the intrinsics only move and compare registers.
    unsafe {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_max_sd, _mm_set_sd};
        _mm_cvtsd_f64(_mm_max_sd(_mm_set_sd(a), _mm_set_sd(b)))
    }
    #[cfg(not(target_arch = "x86_64"))]
    a.max(b)
}

/// `min` counterpart of [`fmax`].
#[inline(always)]
fn fmin(a: f64, b: f64) -> f64 {
    #[cfg(target_arch = "x86_64")]
    // SAFETY: SSE2 is baseline on x86_64; the intrinsics only move and compare registers.
    unsafe {
        use std::arch::x86_64::{_mm_cvtsd_f64, _mm_min_sd, _mm_set_sd};
        _mm_cvtsd_f64(_mm_min_sd(_mm_set_sd(a), _mm_set_sd(b)))
    }
    #[cfg(not(target_arch = "x86_64"))]
    a.min(b)
}

/// Unit roundoff of `f64` (round to nearest): 2^-53.
const U: f64 = 1.0 / 9_007_199_254_740_992.0;
/// Static-filter error coefficient of [`orient3d`] (see the module notes): `56·u`.
pub const ORIENT3D_EPS: f64 = 56.0 * U;
/// Static-filter error coefficient of [`insphere`] (see the module notes): `1289·u`.
pub const INSPHERE_EPS: f64 = 1289.0 * U;
/// Smallest per-axis difference maximum for which the filters are valid (underflow): 2^-190.
pub const FILTER_MIN: f64 = 6.372_367_644_529_809e-58;
/// Largest difference magnitude for which the filters are valid (overflow): 2^190.
pub const FILTER_MAX: f64 = 1.569_275_433_846_670_2e57;

#[inline(always)]
fn c3(p: DVec3) -> robust::Coord3D<f64> {
    robust::Coord3D {
        x: p.x,
        y: p.y,
        z: p.z,
    }
}

/// Exact sign-valued orientation: > 0 if (a,b,c,d) is positively oriented, 0 if coplanar.
///
/// A semi-static floating-point filter (see [the filter notes](self#semi-static-filters))
/// decides almost every call; the rest go to robust's adaptive predicate. The value is
/// `det[b-a, c-a, d-a]` up to a small relative error; its sign is exact.
#[inline]
pub fn orient3d(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    match orient3d_filter(a, b, c, d) {
        Some(v) => v,
        None => orient3d_exact(a, b, c, d),
    }
}

/// Exact sign-valued 2D orientation: > 0 iff (a, b, c) turn counter-clockwise, 0 if collinear.
///
/// Shewchuk's adaptive orient2d (its own dynamic filter decides almost every call, and three
/// points sharing a coordinate give exactly 0 at once) when every coordinate difference is 0
/// or within the filters' range (then no product underflows or overflows, which its
/// exactness needs); else the lifted [`orient3d`], which has the same sign.
#[inline]
pub fn orient2d(a: [f64; 2], b: [f64; 2], c: [f64; 2]) -> f64 {
    let safe = |d: f64| d == 0.0 || (FILTER_MIN..=FILTER_MAX).contains(&d.abs());
    if [a[0] - c[0], b[0] - c[0], a[1] - c[1], b[1] - c[1]]
        .into_iter()
        .all(safe)
    {
        let p = |q: [f64; 2]| robust::Coord { x: q[0], y: q[1] };
        return robust::orient2d(p(a), p(b), p(c));
    }
    let lift = |q: [f64; 2]| DVec3::new(q[0], q[1], 0.0);
    orient3d(lift(a), lift(b), lift(c), DVec3::Z)
}

/// The semi-static filter of [`orient3d`]: `Some(value)` when it decides the sign.
#[inline(always)]
fn orient3d_filter(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<f64> {
    // Shewchuk's orient3d evaluation (pa, pb, pc, pd) = (a, b, c, d); its sign is the
    // opposite of ours, so the result is negated.
    let (adx, bdx, cdx) = (a.x - d.x, b.x - d.x, c.x - d.x);
    let (ady, bdy, cdy) = (a.y - d.y, b.y - d.y, c.y - d.y);
    let (adz, bdz, cdz) = (a.z - d.z, b.z - d.z, c.z - d.z);
    let det = adz * (bdx * cdy - cdx * bdy)
        + bdz * (cdx * ady - adx * cdy)
        + cdz * (adx * bdy - bdx * ady);
    let mx = fmax(fmax(adx.abs(), bdx.abs()), cdx.abs());
    let my = fmax(fmax(ady.abs(), bdy.abs()), cdy.abs());
    let mz = fmax(fmax(adz.abs(), bdz.abs()), cdz.abs());
    let lo = fmin(fmin(mx, my), mz);
    let hi = fmax(fmax(mx, my), mz);
    if lo >= FILTER_MIN && hi <= FILTER_MAX {
        let eps = ORIENT3D_EPS * mx * my * mz;
        if det.abs() > eps {
            return Some(-det);
        }
    } else if lo == 0.0 && det == 0.0 {
        // All differences along one axis are exactly zero: every term of the determinant has
        // a factor from each axis, so it is exactly zero. (det == 0 rules out NaN and inf.)
        return Some(0.0);
    }
    None
}

#[cold]
#[inline(never)]
fn orient3d_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    if let Some(v) = orient3d_lattice(a, b, c, d) {
        return v;
    }
    // robust's orient3d is positive when d lies *below* the plane of counter-clockwise abc,
    // i.e. negative for a right-handed tet: negate to get our convention.
    -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
}

/// Exact in-sphere test for a positively oriented tet (a,b,c,d): > 0 iff e is strictly inside.
///
/// Filtered like [`orient3d`]; the value is the lifted 4x4 determinant up to a small relative
/// error, its sign is exact.
#[inline]
pub fn insphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> f64 {
    match insphere_filter(a, b, c, d, e) {
        Some(v) => v,
        None => insphere_exact(a, b, c, d, e),
    }
}

/// The in-sphere determinant from the coordinate differences to e, ordered
/// `[aex, bex, cex, dex, aey, .., dey, aez, .., dez]`, in Shewchuk's evaluation order. Shared by
/// the float filter (its error bound is derived for exactly this sequence of operations) and the
/// exact i128 lattice path.
#[inline(always)]
fn insphere_det<T>(d: [T; 12]) -> T
where
    T: Copy + std::ops::Add<Output = T> + std::ops::Sub<Output = T> + std::ops::Mul<Output = T>,
{
    let [aex, bex, cex, dex, aey, bey, cey, dey, aez, bez, cez, dez] = d;
    let ab = aex * bey - bex * aey;
    let bc = bex * cey - cex * bey;
    let cd = cex * dey - dex * cey;
    let da = dex * aey - aex * dey;
    let ac = aex * cey - cex * aey;
    let bd = bex * dey - dex * bey;
    let abc = aez * bc - bez * ac + cez * ab;
    let bcd = bez * cd - cez * bd + dez * bc;
    let cda = cez * da + dez * ac + aez * cd;
    let dab = dez * ab + aez * bd + bez * da;
    let alift = aex * aex + aey * aey + aez * aez;
    let blift = bex * bex + bey * bey + bez * bez;
    let clift = cex * cex + cey * cey + cez * cez;
    let dlift = dex * dex + dey * dey + dez * dez;
    (dlift * abc - clift * dab) + (blift * cda - alift * bcd)
}

/// The semi-static filter of [`insphere`]: `Some(value)` when it decides the sign.
#[inline(always)]
fn insphere_filter(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Option<f64> {
    // Shewchuk's insphere evaluation with (pa, pb, pc, pd, pe) = (b, a, c, d, e): robust's
    // insphere expects its own positive orientation (our negative one); swapping a and b
    // turns our positive tet into robust's positive tet, and then > 0 means inside.
    let (aex, bex, cex, dex) = (b.x - e.x, a.x - e.x, c.x - e.x, d.x - e.x);
    let (aey, bey, cey, dey) = (b.y - e.y, a.y - e.y, c.y - e.y, d.y - e.y);
    let (aez, bez, cez, dez) = (b.z - e.z, a.z - e.z, c.z - e.z, d.z - e.z);
    let det = insphere_det([aex, bex, cex, dex, aey, bey, cey, dey, aez, bez, cez, dez]);
    let mx = fmax(fmax(aex.abs(), bex.abs()), fmax(cex.abs(), dex.abs()));
    let my = fmax(fmax(aey.abs(), bey.abs()), fmax(cey.abs(), dey.abs()));
    let mz = fmax(fmax(aez.abs(), bez.abs()), fmax(cez.abs(), dez.abs()));
    let lo = fmin(fmin(mx, my), mz);
    let hi = fmax(fmax(mx, my), mz);
    if lo >= FILTER_MIN && hi <= FILTER_MAX {
        let eps = INSPHERE_EPS * mx * my * mz * hi * hi;
        if det.abs() > eps {
            return Some(det);
        }
    } else if lo == 0.0 && det == 0.0 {
        // Every term holds one x, one y and one z difference (times a lift): exactly zero.
        return Some(0.0);
    }
    None
}

#[cold]
#[inline(never)]
fn insphere_exact(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> f64 {
    if let Some(v) = insphere_lattice(a, b, c, d, e) {
        return v;
    }
    if let Some(v) = insphere_fixed(a, b, c, d, e) {
        return v;
    }
    robust::insphere(c3(b), c3(a), c3(c), c3(d), c3(e))
}

// ---------------------------------------------------------------------------------------------
// Exact evaluation on a lattice
// ---------------------------------------------------------------------------------------------
//
// Grids and other lattice inputs make exact zeros (cospherical, coplanar) common, and every
// zero costs robust's full adaptive evaluation. When every coordinate difference to the last
// point is computed exactly and all of them are integer multiples `k·2^s` of one power of two
// with |k| < 2^K, the determinant is evaluated exactly in i128 with Shewchuk's expression on
// the integers k (scaling all differences by 2^-s scales the determinant by a positive power
// of two, so the sign is unchanged). Bounds (|k| < 2^K): orient3d |terms| sum below
// 3·2·2^{3K} = 6·2^{3K} < 2^127 for K = 40; insphere, 2x2 minors < 2^{2K+1}, 3x3 terms
// < 6·2^{3K}, lifts < 3·2^{2K}, determinant (and every partial sum) < 4·3·6·2^{5K} = 72·2^{5K}
// < 2^127 for K = 24.

/// `a - b` if it is computed exactly (TwoSum's error term is zero), else `None`.
#[inline]
fn exact_diff(a: f64, b: f64) -> Option<f64> {
    // Knuth's TwoSum of a and -b: t is the rounding error of s (exact without overflow).
    let s = a - b;
    let bv = s - a;
    let av = s - bv;
    let t = (a - av) + (-b - bv);
    (t == 0.0 && s.is_finite()).then_some(s)
}

/// Exponents of the lowest and highest set bits of a finite non-zero double.
#[inline]
fn bit_span(x: f64) -> (i32, i32) {
    let bits = x.to_bits();
    let exp = ((bits >> 52) & 0x7ff) as i32;
    let frac = bits & ((1u64 << 52) - 1);
    let (m, e0) = if exp == 0 {
        (frac, -1074)
    } else {
        (frac | (1u64 << 52), exp - 1075)
    };
    (
        e0 + m.trailing_zeros() as i32,
        e0 + 63 - m.leading_zeros() as i32,
    )
}

/// The differences as integers `k` with `d = k·2^s`, if all fit in `|k| < 2^max_bits`.
fn lattice<const N: usize>(d: [f64; N], max_bits: i32) -> Option<([i128; N], i32)> {
    let (mut lo, mut hi) = (i32::MAX, i32::MIN);
    for &x in &d {
        if x != 0.0 {
            let (l, h) = bit_span(x);
            lo = lo.min(l);
            hi = hi.max(h);
        }
    }
    if lo == i32::MAX {
        return Some(([0; N], 0)); // all zero
    }
    if hi - lo >= max_bits {
        return None;
    }
    let mut k = [0i128; N];
    for (ki, &x) in k.iter_mut().zip(&d) {
        if x != 0.0 {
            let bits = x.to_bits();
            let exp = ((bits >> 52) & 0x7ff) as i32;
            let frac = bits & ((1u64 << 52) - 1);
            let (m, e0) = if exp == 0 {
                (frac, -1074)
            } else {
                (frac | (1u64 << 52), exp - 1075)
            };
            let shift = e0 - lo; // >= -trailing_zeros(m): the shifts below are exact
            let v = if shift >= 0 {
                (m as i128) << shift
            } else {
                (m >> -shift) as i128
            };
            *ki = if x < 0.0 { -v } else { v };
        }
    }
    Some((k, lo))
}

/// `k·2^e` as a double with the sign of k, or `None` if that would overflow or underflow
/// to zero.
fn scaled(k: i128, e: i32) -> Option<f64> {
    if k == 0 {
        return Some(0.0);
    }
    scaled_f64(k as f64, e)
}

/// Exact [`insphere`] in multi-word fixed point, for nearly cospherical inputs that are not
/// on a coarse lattice (points on a sphere: every test is nearly degenerate). All fifteen
/// coordinates are written as integers `X·2^s` with one exponent s; if |X| < 2^61 the
/// differences to e are exact i64 (< 2^62), the 2x2 minors exact i128 (< 2^125), the 3x3
/// terms 3-word (< 2^189), the lifts i128 (< 2^126) and the determinant 5-word (< 2^317),
/// all in two's complement. Coordinates spanning more than 61 bits go to robust.
#[inline(never)]
fn insphere_fixed(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Option<f64> {
    // Shewchuk's insphere with (pa, pb, pc, pd, pe) = (b, a, c, d, e), as in `insphere`.
    let coords = [
        b.x, a.x, c.x, d.x, e.x, b.y, a.y, c.y, d.y, e.y, b.z, a.z, c.z, d.z, e.z,
    ];
    if coords.iter().any(|x| !x.is_finite()) {
        return None;
    }
    let (k, s) = lattice(coords, 61)?;
    let x = |i: usize| (k[i] - k[4]) as i64;
    let y = |i: usize| (k[5 + i] - k[9]) as i64;
    let z = |i: usize| (k[10 + i] - k[14]) as i64;
    let (aex, bex, cex, dex) = (x(0), x(1), x(2), x(3));
    let (aey, bey, cey, dey) = (y(0), y(1), y(2), y(3));
    let (aez, bez, cez, dez) = (z(0), z(1), z(2), z(3));
    let m = |p: i64, q: i64, r: i64, t: i64| p as i128 * q as i128 - r as i128 * t as i128;
    let ab = m(aex, bey, bex, aey);
    let bc = m(bex, cey, cex, bey);
    let cd = m(cex, dey, dex, cey);
    let da = m(dex, aey, aex, dey);
    let ac = m(aex, cey, cex, aey);
    let bd = m(bex, dey, dex, bey);
    let abc = W3::mul(aez, bc).sub(W3::mul(bez, ac)).add(W3::mul(cez, ab));
    let bcd = W3::mul(bez, cd).sub(W3::mul(cez, bd)).add(W3::mul(dez, bc));
    let cda = W3::mul(cez, da).add(W3::mul(dez, ac)).add(W3::mul(aez, cd));
    let dab = W3::mul(dez, ab).add(W3::mul(aez, bd)).add(W3::mul(bez, da));
    let lift = |p: i64, q: i64, r: i64| {
        p as i128 * p as i128 + q as i128 * q as i128 + r as i128 * r as i128
    };
    let alift = lift(aex, aey, aez);
    let blift = lift(bex, bey, bez);
    let clift = lift(cex, cey, cez);
    let dlift = lift(dex, dey, dez);
    let det = W5::mul(dlift, abc)
        .sub(W5::mul(clift, dab))
        .add(W5::mul(blift, cda).sub(W5::mul(alift, bcd)));
    let (sign, approx) = det.sign_and_approx();
    if sign == 0 {
        return Some(0.0);
    }
    // The value: the determinant up to rounding, scaled back by 2^(5s) when representable;
    // only its sign matters to callers, so keep a unit of the right sign otherwise.
    match scaled_f64(approx, 5 * s) {
        Some(v) => Some(v),
        None => Some(sign as f64),
    }
}

/// `v·2^e` if finite and non-zero.
fn scaled_f64(v: f64, e: i32) -> Option<f64> {
    if !(-2000..=2000).contains(&e) {
        return None; // |v| < 2^330 here: certain overflow or underflow to zero
    }
    let c = e.clamp(-1000, 1000);
    let r = v * pow2(c) * pow2(e - c);
    (r.is_finite() && r != 0.0).then_some(r)
}

/// 2^e for |e| <= 1000, built from its bits.
#[inline]
fn pow2(e: i32) -> f64 {
    debug_assert!((-1000..=1000).contains(&e));
    f64::from_bits(((e + 1023) as u64) << 52)
}

/// Exact [`orient3d`] on a lattice (see above), `None` when the differences do not fit. On
/// a finer lattice (|k| < 2^62: exactly coplanar points off a coarse lattice, as in the planar
/// regions of a CAD surface whose triangle pairs validation tests) only an exact zero is
/// decided here, in 3-word fixed point (2x2 minors < 2^125, terms < 2^187); robust gives any
/// other value there, so every value is as robust's would be.
#[inline(never)]
fn orient3d_lattice(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<f64> {
    let diff = [
        exact_diff(a.x, d.x)?,
        exact_diff(b.x, d.x)?,
        exact_diff(c.x, d.x)?,
        exact_diff(a.y, d.y)?,
        exact_diff(b.y, d.y)?,
        exact_diff(c.y, d.y)?,
        exact_diff(a.z, d.z)?,
        exact_diff(b.z, d.z)?,
        exact_diff(c.z, d.z)?,
    ];
    let (k, s) = lattice(diff, 62)?;
    let [adx, bdx, cdx, ady, bdy, cdy, adz, bdz, cdz] = k;
    if k.iter().all(|x| x.unsigned_abs() < 1 << 40) {
        let det = adz * (bdx * cdy - cdx * bdy)
            + bdz * (cdx * ady - adx * cdy)
            + cdz * (adx * bdy - bdx * ady);
        // Shewchuk's sign is the opposite of ours.
        return scaled(-det, 3 * s);
    }
    let m = |p: i128, q: i128, r: i128, t: i128| p * q - r * t;
    let det = W3::mul(adz as i64, m(bdx, cdy, cdx, bdy))
        .add(W3::mul(bdz as i64, m(cdx, ady, adx, cdy)))
        .add(W3::mul(cdz as i64, m(adx, bdy, bdx, ady)));
    // What robust gives for an exact zero (its full evaluation), negated as in
    // `orient3d_exact`.
    det.is_zero().then_some(-0.0)
}

/// Exact [`insphere`] on a lattice (see above), `None` when the differences do not fit.
#[inline(never)]
fn insphere_lattice(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> Option<f64> {
    // Shewchuk's insphere with (pa, pb, pc, pd, pe) = (b, a, c, d, e), as in `insphere`.
    let diff = [
        exact_diff(b.x, e.x)?,
        exact_diff(a.x, e.x)?,
        exact_diff(c.x, e.x)?,
        exact_diff(d.x, e.x)?,
        exact_diff(b.y, e.y)?,
        exact_diff(a.y, e.y)?,
        exact_diff(c.y, e.y)?,
        exact_diff(d.y, e.y)?,
        exact_diff(b.z, e.z)?,
        exact_diff(a.z, e.z)?,
        exact_diff(c.z, e.z)?,
        exact_diff(d.z, e.z)?,
    ];
    let (k, s) = lattice(diff, 24)?;
    let det = insphere_det(k);
    scaled(det, 5 * s)
}

/// The in-sphere filter of the four tets across the faces of one tet, sharing the work: the
/// differences to `e`, the lifts and the 2x2 minors of the common tet's four points are
/// computed once. [`InsphereFan::across`] evaluates *bit for bit* the same expression (and
/// the same error bound) as [`insphere`]'s filter, so its decisions carry the same guarantee.
#[derive(Clone, Copy, Debug)]
pub struct InsphereFan {
    d: [[f64; 3]; 4],
    abs: [[f64; 3]; 4],
    lift: [f64; 4],
    /// `m[j][k] = d[j].x * d[k].y - d[k].x * d[j].y` (so `m[k][j] = -m[j][k]` exactly).
    m: [[f64; 4]; 4],
}

impl InsphereFan {
    /// Prepares the fan of the points `q` around the query point `e`.
    #[inline(always)]
    pub fn new(q: [DVec3; 4], e: DVec3) -> Self {
        let mut d = [[0.0; 3]; 4];
        let mut abs = [[0.0; 3]; 4];
        let mut lift = [0.0; 4];
        for k in 0..4 {
            let v = [q[k].x - e.x, q[k].y - e.y, q[k].z - e.z];
            d[k] = v;
            abs[k] = [v[0].abs(), v[1].abs(), v[2].abs()];
            lift[k] = v[0] * v[0] + v[1] * v[1] + v[2] * v[2];
        }
        let mut m = [[0.0; 4]; 4];
        for j in 0..4 {
            for k in j + 1..4 {
                let v = d[j][0] * d[k][1] - d[k][0] * d[j][1];
                m[j][k] = v;
                m[k][j] = -v;
            }
        }
        InsphereFan { d, abs, lift, m }
    }

    /// Filtered in-sphere of `e` for the tet `(q[b], q[a], q[c], apex)` (which must be
    /// positively oriented): `Some(value)` exactly when `insphere`'s filter would decide, with
    /// the same value; `None` means the exact predicate must decide.
    #[inline(always)]
    pub fn across(&self, a: usize, b: usize, c: usize, apex: DVec3, e: DVec3) -> Option<f64> {
        // Shewchuk's insphere with (pa, pb, pc, pd, pe) = (q[a], q[b], q[c], apex, e).
        let [aex, aey, aez] = self.d[a];
        let [bex, bey, bez] = self.d[b];
        let [cex, cey, cez] = self.d[c];
        let (dex, dey, dez) = (apex.x - e.x, apex.y - e.y, apex.z - e.z);
        let ab = self.m[a][b];
        let bc = self.m[b][c];
        let ac = self.m[a][c];
        let cd = cex * dey - dex * cey;
        let da = dex * aey - aex * dey;
        let bd = bex * dey - dex * bey;
        let abc = aez * bc - bez * ac + cez * ab;
        let bcd = bez * cd - cez * bd + dez * bc;
        let cda = cez * da + dez * ac + aez * cd;
        let dab = dez * ab + aez * bd + bez * da;
        let dlift = dex * dex + dey * dey + dez * dez;
        let det = (dlift * abc - self.lift[c] * dab) + (self.lift[b] * cda - self.lift[a] * bcd);
        let (sa, sb, sc) = (self.abs[a], self.abs[b], self.abs[c]);
        let mx = fmax(fmax(sa[0], sb[0]), fmax(sc[0], dex.abs()));
        let my = fmax(fmax(sa[1], sb[1]), fmax(sc[1], dey.abs()));
        let mz = fmax(fmax(sa[2], sb[2]), fmax(sc[2], dez.abs()));
        let lo = fmin(fmin(mx, my), mz);
        let hi = fmax(fmax(mx, my), mz);
        if lo >= FILTER_MIN && hi <= FILTER_MAX {
            let eps = INSPHERE_EPS * mx * my * mz * hi * hi;
            if det.abs() > eps {
                return Some(det);
            }
        } else if lo == 0.0 && det == 0.0 {
            return Some(0.0);
        }
        None
    }
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
    let mut order = [0usize, 1, 2, 3, 4];
    let rank = |i: usize| if i == 4 { rank_e } else { ranks[i] };
    order.sort_unstable_by_key(|&i| std::cmp::Reverse(rank(i)));
    insphere_tie_in_order(p, e, order)
}

/// The tie-break of [`insphere_tie`] with the points (0-3: `p`, 4: `e`) visited in `order`,
/// the most perturbed first: the first one whose cofactor orientation is non-zero decides
/// (replacing p_i by e in the tet gives that cofactor's sign).
fn insphere_tie_in_order(p: [DVec3; 4], e: DVec3, order: [usize; 5]) -> bool {
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
    unreachable!("insphere tie-break: the first four points must form a non-degenerate tet")
}

/// [`insphere_tie`] with the points ranked by their coordinates (lexicographically, x first;
/// the larger ranks higher) instead of by index: the tie-break then depends only on the
/// points, so every triangulation holding a set of points breaks its ties alike, whatever
/// the insertion order (CGAL's perturbation orders points the same way).
#[cold]
pub fn insphere_tie_by_coordinates(p: [DVec3; 4], e: DVec3) -> bool {
    let point = |i: usize| if i == 4 { e } else { p[i] };
    let mut order = [0usize, 1, 2, 3, 4];
    order.sort_unstable_by(|&i, &j| {
        let (a, b) = (point(i).to_array(), point(j).to_array());
        b.partial_cmp(&a).unwrap_or(Ordering::Equal)
    });
    insphere_tie_in_order(p, e, order)
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
        let p = [
            DVec3::new(0.0, 0.0, 0.5),
            DVec3::new(12.0, 0.0, 0.5),
            DVec3::new(0.0, 24.0, 0.5),
        ];
        let above = DVec3::new(3.1, 7.3, f64::from_bits(0.5f64.to_bits() + 1));
        let below = DVec3::new(3.1, 7.3, f64::from_bits(0.5f64.to_bits() - 1));
        assert!(orient3d(p[0], p[1], p[2], above) > 0.0);
        assert!(orient3d(p[0], p[1], p[2], below) < 0.0);
    }

    /// The 2D orientation has the sign of the lifted 3D one on generic, collinear (on a line
    /// and through shared coordinates), one-ulp-off, tiny and huge configurations.
    #[test]
    fn orient2d_signs_match_the_lifted_orient3d() {
        use rand::{Rng, SeedableRng};
        let lifted = |a: [f64; 2], b: [f64; 2], c: [f64; 2]| {
            let l = |q: [f64; 2]| DVec3::new(q[0], q[1], 0.0);
            sign(orient3d(l(a), l(b), l(c), DVec3::Z))
        };
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for k in 0..240_000 {
            // Inside the filters' range, near its ends, and beyond them (the lifted path).
            let scale = [1.0, 1e-40, 1e-56, 1e40, 1e56, 1e-200, 1e150, 1e-310][(k / 4) % 8];
            let mut q = || {
                [
                    rng.gen_range(-1.0..1.0) * scale,
                    rng.gen_range(-1.0..1.0) * scale,
                ]
            };
            let (a, b) = (q(), q());
            let c = match k % 4 {
                0 => q(),
                // On the line ab (up to rounding: either side or on it).
                1 => {
                    let t: f64 = rng.gen_range(-2.0..2.0);
                    [a[0] + t * (b[0] - a[0]), a[1] + t * (b[1] - a[1])]
                }
                // Sharing a coordinate with a and b: exactly collinear.
                2 => [a[0], rng.gen_range(-1.0..1.0) * scale],
                // One ulp off a's x.
                _ => [f64::from_bits(a[0].to_bits() + 1), a[1]],
            };
            let (a, b) = if k % 4 == 2 {
                ([c[0], a[1]], [c[0], b[1]])
            } else {
                (a, b)
            };
            assert_eq!(
                sign(orient2d(a, b, c)),
                lifted(a, b, c),
                "{a:?} {b:?} {c:?}"
            );
        }
        assert_eq!(orient2d([0.0, 0.0], [1.0, 0.0], [0.0, 1.0]), 1.0);
        assert_eq!(orient2d([0.0, 0.0], [0.0, 1.0], [1.0, 0.0]), -1.0);
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

    /// Re-derives the filter constants by the propagation rules of the module notes.
    #[test]
    fn filter_bounds_derivation() {
        assert_eq!(FILTER_MIN, 2f64.powi(-190));
        assert_eq!(FILTER_MAX, 2f64.powi(190));
        assert_eq!(U, 2f64.powi(-53));
        // (S, E) per quantity, in units of its monomial.
        type Q = (f64, f64);
        let diff: Q = (1.0 + U, U);
        let add = |a: Q, b: Q| (a.0 + b.0, a.1 + b.1 + U * (a.0 + a.1 + b.0 + b.1));
        let mul = |a: Q, b: Q| {
            (
                a.0 * b.0,
                (a.0 + a.1) * b.1 + b.0 * a.1 + U * (a.0 + a.1) * (b.0 + b.1) + U,
            )
        };
        let minor = add(mul(diff, diff), mul(diff, diff));
        let term = mul(diff, minor);
        let orient = add(add(term, term), term);
        let sq = mul(diff, diff);
        let lift = add(add(sq, sq), sq);
        let lt = mul(lift, add(add(term, term), term));
        let ins = add(add(lt, lt), add(lt, lt));
        // The evaluation of eps loses at most (1 - u)^5; keep a margin for this test's own
        // rounding (relative 1e-12).
        let shrink = (1.0 - U).powi(5) * (1.0 - 1e-12);
        assert!(
            orient.1 / U < 55.001 && ORIENT3D_EPS * shrink > orient.1,
            "{orient:?}"
        );
        assert!(
            ins.1 / U < 1288.001 && INSPHERE_EPS * shrink > ins.1,
            "{ins:?}"
        );
    }

    fn robust_orient(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
        -robust::orient3d(c3(a), c3(b), c3(c), c3(d))
    }
    fn robust_insphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3, e: DVec3) -> f64 {
        robust::insphere(c3(b), c3(a), c3(c), c3(d), c3(e))
    }

    /// The filtered predicates give robust's signs, on random and on nearly degenerate inputs
    /// (where the filter must hand over), at many scales and offsets.
    #[test]
    fn filters_agree_with_robust() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(42);
        let (mut undecided, mut total, mut orient_undecided) = (0, 0, 0);
        for iter in 0..200_000 {
            let scale = [1.0, 1e-30, 1e30, 3e-20, 7e15, 1e-3][iter % 6];
            let offset = [0.0, 1.0, -1e6, 0.5][(iter / 6) % 4] * scale;
            let rnd = |rng: &mut rand_chacha::ChaCha8Rng| {
                DVec3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()) * scale
                    + DVec3::splat(offset)
            };
            let (a, b, c, mut d) = (rnd(&mut rng), rnd(&mut rng), rnd(&mut rng), rnd(&mut rng));
            let kind = (iter / 24) % 4;
            if kind == 1 {
                // d (nearly) in the plane of a, b, c
                let (s, t) = (rng.gen::<f64>(), rng.gen::<f64>());
                d = a + (b - a) * s + (c - a) * t;
            }
            let e0 = rnd(&mut rng);
            let mut e = e0;
            if orient3d(a, b, c, d) != 0.0 && kind >= 2 {
                // e (nearly) on the sphere through a, b, c, d
                let (u, v, w) = (b - a, c - a, d - a);
                let n = (u.cross(v) * w.length_squared()
                    + v.cross(w) * u.length_squared()
                    + w.cross(u) * v.length_squared())
                    / (2.0 * u.dot(v.cross(w)));
                let centre = a + n;
                let dir = (e0 - centre).normalize();
                e = centre + dir * n.length();
                if kind == 3 {
                    // snap to a coarse lattice: exact ties happen
                    let g = scale / 8.0;
                    e = (e / g).round() * g;
                }
            }
            let o = orient3d(a, b, c, d);
            assert_eq!(
                sign(o),
                sign(robust_orient(a, b, c, d)),
                "orient {a} {b} {c} {d}"
            );
            if orient3d_filter(a, b, c, d).is_none() {
                orient_undecided += 1;
            }
            let (p, q) = if o < 0.0 { (b, a) } else { (a, b) };
            if o != 0.0 {
                let i = insphere(p, q, c, d, e);
                let r = robust_insphere(p, q, c, d, e);
                assert_eq!(sign(i), sign(r), "insphere {p} {q} {c} {d} {e}");
                total += 1;
                if insphere_filter(p, q, c, d, e).is_none() {
                    undecided += 1;
                }
            }
        }
        // The near-degenerate cases must exercise the hand-over, and most cases must not.
        assert!(
            total > 100_000 && undecided > total / 10 && undecided < total / 2,
            "{undecided} of {total}"
        );
        assert!(orient_undecided > 20_000, "{orient_undecided}");
    }

    #[test]
    fn insphere_fan_equals_the_filter_bit_for_bit() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut rnd = |s: f64| DVec3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()) * s;
        for it in 0..20_000 {
            let s = [1.0, 1e-20, 1e20, 1e-56][it % 4];
            let q = [rnd(s), rnd(s), rnd(s), rnd(s)];
            let e = if it % 3 == 0 {
                q[it % 4] + rnd(s) * 1e-9
            } else {
                rnd(s)
            };
            let apex = if it % 5 == 0 { q[(it + 1) % 4] } else { rnd(s) };
            let fan = InsphereFan::new(q, e);
            for (a, b, c) in [(1, 3, 2), (0, 2, 3), (3, 1, 0), (0, 1, 2), (2, 1, 0)] {
                let x = fan.across(a, b, c, apex, e);
                let y = insphere_filter(q[b], q[a], q[c], apex, e);
                assert_eq!(x.map(f64::to_bits), y.map(f64::to_bits), "{q:?} {apex} {e}");
            }
        }
    }

    /// The lattice path agrees with robust (signs, and orient3d values up to rounding) on
    /// lattices at several scales and offsets, exact zeros included, and declines
    /// non-lattice input.
    #[test]
    fn lattice_path_agrees_with_robust() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(99);
        let (mut decided, mut zeros) = (0, 0);
        for it in 0..100_000 {
            let scale = [1.0, 0.5, 2f64.powi(-60), 2f64.powi(70), 3.0][it % 5];
            let span = [4, 16, 1 << 20][(it / 5) % 3];
            let offset = [0.0, 1e6, -37.0][(it / 15) % 3] * scale;
            let mut g = || {
                DVec3::new(
                    rng.gen_range(0..span) as f64,
                    rng.gen_range(0..span) as f64,
                    rng.gen_range(0..span) as f64,
                ) * scale
                    + DVec3::splat(offset)
            };
            let (a, b, c, d, e) = (g(), g(), g(), g(), g());
            let o = robust_orient(a, b, c, d);
            if let Some(v) = orient3d_lattice(a, b, c, d) {
                assert_eq!(sign(v), sign(o), "{a} {b} {c} {d}");
                assert!((v - o).abs() <= 1e-9 * o.abs(), "{v} {o}");
                decided += 1;
            }
            if o != 0.0 {
                let (p, q) = if o < 0.0 { (b, a) } else { (a, b) };
                let r = robust_insphere(p, q, c, d, e);
                if let Some(v) = insphere_lattice(p, q, c, d, e) {
                    assert_eq!(sign(v), sign(r), "{p} {q} {c} {d} {e}");
                    decided += 1;
                    zeros += (v == 0.0) as usize;
                }
            }
        }
        assert!(decided > 150_000 && zeros > 1000, "{decided} {zeros}");
        // Not a lattice within the bit budget / inexact differences: declined.
        let x = DVec3::new(0.1, 0.7, 0.3);
        assert!(insphere_lattice(DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z, x).is_none());
        let big = DVec3::new(1e16, 0.0, 0.0);
        assert!(orient3d_lattice(DVec3::ZERO, DVec3::X, DVec3::Y, big + DVec3::Z * 0.5).is_none());
    }

    /// The lattice path's fine lattice (zeros only) agrees with robust: exactly coplanar
    /// points off the 40-bit lattice are zero with robust's value bit for bit; points nudged
    /// one ulp off the plane and random points are left to robust.
    #[test]
    fn fine_lattice_orient_zeros_agree_with_robust() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(17);
        let (mut zeros, mut nonzeros) = (0, 0);
        for it in 0..20_000 {
            let scale = [1.0, 2f64.powi(-20), 2f64.powi(30)][it % 3];
            // 47-bit integers times 2^-47 (beyond the 40-bit lattice path), d = b + c - a:
            // exactly coplanar, and the sums are exact.
            let mut g = || {
                let mut q = || (rng.gen_range(1u64 << 46..1u64 << 47) as f64) * 2f64.powi(-47);
                DVec3::new(q(), q(), q()) * scale
            };
            let (a, b, c) = (g(), g(), g());
            let mut d = b + c - a;
            if it % 4 == 3 {
                d.z = f64::from_bits(d.z.to_bits() + 1);
            }
            let o = robust_orient(a, b, c, d);
            match orient3d_lattice(a, b, c, d) {
                Some(v) => {
                    assert_eq!(o, 0.0, "{a} {b} {c} {d}");
                    assert_eq!(v.to_bits(), o.to_bits(), "{a} {b} {c} {d}");
                    zeros += 1;
                }
                None => {
                    nonzeros += usize::from(o != 0.0);
                }
            }
            assert_eq!(orient3d(a, b, c, d).to_bits(), o.to_bits());
            let e = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * scale;
            if orient3d_lattice(a, b, c, e).is_some() {
                assert_eq!(robust_orient(a, b, c, e), 0.0);
            }
        }
        assert!(zeros > 10_000 && nonzeros > 3_000, "{zeros} {nonzeros}");
    }

    /// The fixed-point path agrees with robust on points on a sphere (nearly cospherical),
    /// on exactly cospherical dyadic points, and on random points at several scales.
    #[test]
    fn fixed_point_insphere_agrees_with_robust() {
        use rand::{Rng, SeedableRng};
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(5);
        let mut decided = 0;
        let mut zeros = 0;
        for it in 0..60_000 {
            let scale = [1.0, 2f64.powi(-40), 2f64.powi(50), 3.7][it % 4];
            let kind = (it / 4) % 3;
            let mut pt = || -> DVec3 {
                let v =
                    DVec3::new(rng.gen::<f64>(), rng.gen::<f64>(), rng.gen::<f64>()) * 2.0 - 1.0;
                match kind {
                    0 => v.normalize() * scale,
                    1 => v * scale,
                    // exactly cospherical: (±3, ±4, 0)/5-type points are not dyadic; use
                    // points of the sphere x²+y²+z² = 25·4^k with integer coordinates
                    _ => {
                        let q = [
                            [3.0, 4.0, 0.0],
                            [0.0, 3.0, 4.0],
                            [4.0, 0.0, 3.0],
                            [5.0, 0.0, 0.0],
                            [0.0, -5.0, 0.0],
                            [0.0, 0.0, -5.0],
                            [-3.0, 0.0, 4.0],
                            [-4.0, -3.0, 0.0],
                        ][rng.gen_range(0..8)];
                        DVec3::new(q[0], q[1], q[2]) * scale * 0.125
                            + v * 2f64.powi(-60) * scale * (it % 2) as f64
                    }
                }
            };
            let (a, mut b, c, d, e) = (pt(), pt(), pt(), pt(), pt());
            let mut a = a;
            let o = robust_orient(a, b, c, d);
            if o == 0.0 {
                continue;
            }
            if o < 0.0 {
                std::mem::swap(&mut a, &mut b);
            }
            let r = robust_insphere(a, b, c, d, e);
            if let Some(v) = insphere_fixed(a, b, c, d, e) {
                assert_eq!(sign(v), sign(r), "{a} {b} {c} {d} {e}");
                decided += 1;
                zeros += (v == 0.0) as usize;
            }
        }
        assert!(decided > 40_000 && zeros > 500, "{decided} {zeros}");
    }

    #[test]
    fn filters_on_integer_grids_and_tiny_differences() {
        // Exact zeros (cospherical / coplanar lattice points) and differences near FILTER_MIN.
        let g = |x: i32, y: i32, z: i32| DVec3::new(x as f64, y as f64, z as f64);
        let pts: Vec<DVec3> = (0..64).map(|i| g(i % 4, (i / 4) % 4, i / 16)).collect();
        for i in 0..pts.len() {
            for j in (i * 7 % 5)..pts.len() {
                let (a, b, c, d, e) = (
                    pts[i],
                    pts[j],
                    pts[(i + 5) % 64],
                    pts[(j + 11) % 64],
                    pts[(i * 3 + j) % 64],
                );
                assert_eq!(sign(orient3d(a, b, c, d)), sign(robust_orient(a, b, c, d)));
                let (p, q) = if orient3d(a, b, c, d) < 0.0 {
                    (b, a)
                } else {
                    (a, b)
                };
                if orient3d(a, b, c, d) != 0.0 {
                    assert_eq!(
                        sign(insphere(p, q, c, d, e)),
                        sign(robust_insphere(p, q, c, d, e))
                    );
                }
            }
        }
        for k in [-200, -191, -190, -189, -150] {
            let s = 2f64.powi(k);
            let (a, b, c, d) = (DVec3::ZERO, DVec3::X * s, DVec3::Y * s, DVec3::Z * s);
            assert!(orient3d(a, b, c, d) > 0.0, "2^{k}");
            assert!(insphere(a, b, c, d, DVec3::splat(0.25 * s)) > 0.0, "2^{k}");
            assert!(insphere(a, b, c, d, DVec3::splat(2.0 * s)) < 0.0, "2^{k}");
            assert_eq!(insphere(a, b, c, d, DVec3::splat(s)), 0.0, "2^{k}");
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
