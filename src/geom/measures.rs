//! Constructions (circumcentres, equatorial and diametric balls) and tetrahedron quality
//! measures, in floating point.
//!
//! These are measures, not topological decisions: nothing here decides connectivity, so plain
//! `f64` arithmetic is fine. Only the orientation determinant `det[b-a, c-a, d-a]` (= 6·V) comes
//! from the adaptive predicate [`orient3d`], so a tet is *degenerate* (flat) exactly when its
//! orientation is exactly zero, the same answer the Delaunay kernel sees.
//!
//! Notation: R circumradius, L shortest edge, V volume, r inradius, for a tet (a, b, c, d).
//!
//! | measure | definition | regular tet | degenerate (flat) tet |
//! |---|---|---|---|
//! | [`circumcenter`], [`circumradius`] | centre / radius of the sphere through a, b, c, d | R = (√6/4)·edge | `None` / +∞ |
//! | [`shortest_edge`], [`longest_edge`] | min / max of the 6 edge lengths | edge | (as is) |
//! | [`volume`] | det[b-a, c-a, d-a] / 6, **signed**, > 0 for positive orientation | edge³/(6√2) | 0 |
//! | [`inradius`] | r = 3·\|V\| / (total face area) | edge/(2√6) | 0 |
//! | [`radius_edge_ratio`] | rho = R / L | √6/4 ≈ 0.6124 ([`REGULAR_RHO`]) | +∞ |
//! | [`sigma`] | \|V\| / L³ | 1/(6√2) ≈ 0.1179 ([`REGULAR_SIGMA`]) | 0 |
//! | [`aspect`] | R / (3r) | 1 ([`REGULAR_ASPECT`]) | +∞ |
//! | [`dihedral_angles`] | the 6 interior dihedral angles, degrees | arccos(1/3) ≈ 70.5288° ([`REGULAR_DIHEDRAL`]) | each 0 or 180 |
//! | [`min_max_dihedral`] | (smallest, largest) dihedral angle, degrees | (70.5288, 70.5288) | (0, 180) |
//!
//! rho is small for every well-shaped tet but does *not* detect slivers (a flat tet with four
//! nearly cospherical vertices has rho ≈ 0.7); sigma does (sigma → 0), and so do the dihedral
//! angles (max → 180°). sigma does not detect needles (one far vertex): rho does.
//!
//! Shape measures (rho, sigma, aspect, angles) are invariant under translation, rotation,
//! reflection and uniform scaling, and use |V|: an inverted tet measures like its mirror image.
//! Only [`volume`] (and [`TetQuality::volume`]) keeps the sign. None of these functions returns
//! NaN for finite input in the accepted coordinate range ([`super::MAX_COORD`]).
//!
//! Boundary constructions for refinement: [`tri_circumcenter`] / [`tri_circumradius`] /
//! [`equatorial_ball`] (the smallest sphere through a subfacet's three vertices: its centre lies
//! in the triangle's plane) and [`diametric_ball`] (a subsegment's midpoint and half-length).
//!
//! For a refinement loop use [`TetQuality::of`], which computes every measure in one pass
//! (one orientation predicate, three cross products, two `atan2`).

use super::predicates::orient3d;
use glam::DVec3;

/// rho = R/L of the regular tetrahedron: √6/4.
pub const REGULAR_RHO: f64 = 0.612_372_435_695_794_5;
/// sigma = V/L³ of the regular tetrahedron: 1/(6√2).
pub const REGULAR_SIGMA: f64 = 0.117_851_130_197_757_9;
/// aspect = R/(3r) of the regular tetrahedron: 1.
pub const REGULAR_ASPECT: f64 = 1.0;
/// Dihedral angle of the regular tetrahedron in degrees: arccos(1/3).
pub const REGULAR_DIHEDRAL: f64 = 70.528_779_365_509_31;

/// Vertex pairs (local indices into (a, b, c, d)) of the edges, in the order used by
/// [`dihedral_angles`]: ab, ac, ad, bc, bd, cd. Edge `i` is opposite edge `5 - i`.
pub const DIHEDRAL_EDGES: [[usize; 2]; 6] = [[0, 1], [0, 2], [0, 3], [1, 2], [1, 3], [2, 3]];

// ---------------------------------------------------------------------------------------------
// Shared kernels (all relative to vertex a, which keeps the arithmetic well conditioned).
// ---------------------------------------------------------------------------------------------

/// Squared edge lengths in [`DIHEDRAL_EDGES`] order, from u = b-a, v = c-a, w = d-a.
#[inline(always)]
pub(crate) fn edge_lengths_sq(u: DVec3, v: DVec3, w: DVec3) -> [f64; 6] {
    [
        u.length_squared(),
        v.length_squared(),
        w.length_squared(),
        (v - u).length_squared(),
        (w - u).length_squared(),
        (w - v).length_squared(),
    ]
}

#[inline(always)]
fn min6(x: &[f64; 6]) -> f64 {
    x[0].min(x[1]).min(x[2]).min(x[3]).min(x[4]).min(x[5])
}

#[inline(always)]
fn max6(x: &[f64; 6]) -> f64 {
    x[0].max(x[1]).max(x[2]).max(x[3]).max(x[4]).max(x[5])
}

/// Area vectors (twice the area, outward for a positively oriented tet) of the faces opposite
/// a, b, c, d. For a negatively oriented tet all four point inward, which leaves every
/// dihedral angle unchanged.
#[inline(always)]
fn face_normals(u: DVec3, v: DVec3, w: DVec3) -> [DVec3; 4] {
    [
        (v - u).cross(w - u), // bcd
        w.cross(v),           // adc
        u.cross(w),           // abd
        v.cross(u),           // acb
    ]
}

/// The two faces (by opposite vertex) that meet at each edge of [`DIHEDRAL_EDGES`].
const EDGE_FACES: [[usize; 2]; 6] = [[2, 3], [1, 3], [1, 2], [0, 3], [0, 2], [0, 1]];

/// Circumcentre offset from a (Shewchuk's formula), given u = b-a, v = c-a, w = d-a, their
/// squared lengths and det = det[u, v, w] from the adaptive orientation predicate.
#[inline(always)]
fn circum_offset(u: DVec3, v: DVec3, w: DVec3, l2: [f64; 3], det: f64) -> Option<DVec3> {
    circum_offset_crossed([v.cross(w), w.cross(u), u.cross(v)], l2, det)
}

/// The one circumcentre formula (see [`circumcenter`]): the offset from a, given the cross
/// products `[v×w, w×u, u×v]` of u = b-a, v = c-a, w = d-a, their squared lengths `l2` and
/// det = det[u, v, w] (from [`orient3d`]). For callers that have the cross products already.
#[inline(always)]
pub fn circum_offset_crossed(cross: [DVec3; 3], l2: [f64; 3], det: f64) -> Option<DVec3> {
    if det == 0.0 {
        return None;
    }
    let num = l2[0] * cross[0] + l2[1] * cross[1] + l2[2] * cross[2];
    let o = num * (0.5 / det);
    if o.is_finite() {
        Some(o)
    } else {
        None
    }
}

/// Interior dihedral angle (radians) at an edge of length `len` between faces with area
/// vectors `n1`, `n2`, for a tet with orientation determinant `det`.
///
/// Uses |n1 × n2| = |det|·len (exact identity) for the sine, so angles near 0° and 180° (the
/// sliver case) keep full relative accuracy instead of suffering acos's cancellation.
#[inline(always)]
fn dihedral_rad(n1: DVec3, n2: DVec3, det: f64, len: f64) -> f64 {
    (det.abs() * len).atan2(-n1.dot(n2))
}

/// (min, max) dihedral angles in degrees from precomputed face normals. Picks the extreme
/// edges by cosine (monotone in the angle) and evaluates only those two angles accurately.
#[inline(always)]
fn min_max_dihedral_from(n: &[DVec3; 4], l2: &[f64; 6], det: f64) -> (f64, f64) {
    let len = [n[0].length(), n[1].length(), n[2].length(), n[3].length()];
    if det == 0.0 || len.contains(&0.0) {
        return (0.0, 180.0);
    }
    let (mut imin, mut imax) = (0usize, 0usize);
    let (mut cmax, mut cmin) = (f64::NEG_INFINITY, f64::INFINITY);
    for (i, [k, l]) in EDGE_FACES.iter().copied().enumerate() {
        let c = -n[k].dot(n[l]) / (len[k] * len[l]);
        if c > cmax {
            cmax = c;
            imin = i; // largest cosine = smallest angle
        }
        if c < cmin {
            cmin = c;
            imax = i;
        }
    }
    let ang = |i: usize| {
        let [k, l] = EDGE_FACES[i];
        dihedral_rad(n[k], n[l], det, l2[i].sqrt()).to_degrees()
    };
    (ang(imin), ang(imax))
}

// ---------------------------------------------------------------------------------------------
// Constructions
// ---------------------------------------------------------------------------------------------

/// Centre of the sphere through a, b, c, d; `None` when the tet is flat (exact orientation
/// zero) or the centre is not representable.
///
/// Shewchuk's formula relative to a, with the adaptive orientation determinant in the
/// denominator: `c = a + (|u|²(v×w) + |v|²(w×u) + |w|²(u×v)) / (2·det[u, v, w])` with
/// `u = b-a, v = c-a, w = d-a`. Independent of the orientation of (a, b, c, d).
///
/// A near-flat tet has an ill-conditioned centre (a perturbation of the vertices moves it by
/// about R/sigma times as much; the tests see an absolute error within ε·R/sigma).
#[inline]
pub fn circumcenter(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<DVec3> {
    circumsphere(a, b, c, d).map(|(center, _)| center)
}

/// Circumcentre and circumradius together (`None` for a flat tet). The radius is the length of
/// the computed offset from a.
#[inline]
pub fn circumsphere(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Option<(DVec3, f64)> {
    let (u, v, w) = (b - a, c - a, d - a);
    let l2 = [u.length_squared(), v.length_squared(), w.length_squared()];
    let o = circum_offset(u, v, w, l2, orient3d(a, b, c, d))?;
    Some((a + o, o.length()))
}

/// Circumradius R; +∞ for a flat tet.
#[inline]
pub fn circumradius(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    circumsphere(a, b, c, d).map_or(f64::INFINITY, |(_, r)| r)
}

/// Circumcentre of the triangle (a, b, c) in 3D: the point of its plane equidistant from the
/// three vertices (the centre of a subfacet's equatorial ball). `None` for collinear or
/// coincident points.
///
/// `c = a + (|u|²(v×n) + |v|²(n×u)) / (2|n|²)` with `u = b-a, v = c-a, n = u×v`.
#[inline]
pub fn tri_circumcenter(a: DVec3, b: DVec3, c: DVec3) -> Option<DVec3> {
    equatorial_ball(a, b, c).map(|(center, _)| center)
}

/// Circumradius of the triangle (a, b, c) in 3D; +∞ for collinear points.
#[inline]
pub fn tri_circumradius(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    equatorial_ball(a, b, c).map_or(f64::INFINITY, |(_, r)| r)
}

/// Equatorial ball of the triangle (a, b, c): its 3D circumcentre and circumradius, i.e. the
/// smallest ball with a, b, c on its boundary. `None` for collinear points.
#[inline]
pub fn equatorial_ball(a: DVec3, b: DVec3, c: DVec3) -> Option<(DVec3, f64)> {
    let (u, v) = (b - a, c - a);
    let n = u.cross(v);
    let n2 = n.length_squared();
    if n2 == 0.0 {
        return None;
    }
    let o = (u.length_squared() * v.cross(n) + v.length_squared() * n.cross(u)) * (0.5 / n2);
    if o.is_finite() {
        Some((a + o, o.length()))
    } else {
        None
    }
}

/// Diametric ball of the segment ab: its midpoint and half its length.
#[inline]
pub fn diametric_ball(a: DVec3, b: DVec3) -> (DVec3, f64) {
    (a.midpoint(b), 0.5 * a.distance(b))
}

// ---------------------------------------------------------------------------------------------
// Individual measures
// ---------------------------------------------------------------------------------------------

/// Length of the shortest of the six edges.
#[inline]
pub fn shortest_edge(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    min6(&edge_lengths_sq(b - a, c - a, d - a)).sqrt()
}

/// Length of the longest of the six edges.
#[inline]
pub fn longest_edge(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    max6(&edge_lengths_sq(b - a, c - a, d - a)).sqrt()
}

/// Signed volume det[b-a, c-a, d-a] / 6: positive for a positively oriented tet (the
/// [`orient3d`] convention), exactly 0 iff the four points are coplanar.
#[inline]
pub fn volume(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    orient3d(a, b, c, d) / 6.0
}

/// Inradius r = 3|V| / (total face area); 0 for a flat tet.
#[inline]
pub fn inradius(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let det = orient3d(a, b, c, d);
    if det == 0.0 {
        return 0.0;
    }
    let n = face_normals(b - a, c - a, d - a);
    // 3|V| / A = (|det|/2) / (sum |n_i| / 2)
    det.abs() / (n[0].length() + n[1].length() + n[2].length() + n[3].length())
}

/// Radius-edge ratio rho = R/L (regular tet √6/4, [`REGULAR_RHO`]); +∞ for a flat tet.
#[inline]
pub fn radius_edge_ratio(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let r = circumradius(a, b, c, d);
    if r.is_infinite() {
        return f64::INFINITY;
    }
    r / shortest_edge(a, b, c, d)
}

/// Sliver measure sigma = |V| / L³ (regular tet 1/(6√2), [`REGULAR_SIGMA`]); 0 for a flat tet.
#[inline]
pub fn sigma(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let v = volume(a, b, c, d).abs();
    if v == 0.0 {
        return 0.0;
    }
    let l = shortest_edge(a, b, c, d);
    v / (l * l * l)
}

/// Aspect ratio R / (3r) (regular tet 1, larger is worse); +∞ for a flat tet.
#[inline]
pub fn aspect(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> f64 {
    let r = inradius(a, b, c, d);
    let big_r = circumradius(a, b, c, d);
    if r == 0.0 || big_r.is_infinite() {
        return f64::INFINITY;
    }
    big_r / (3.0 * r)
}

/// The six interior dihedral angles in degrees, at the edges ab, ac, ad, bc, bd, cd
/// ([`DIHEDRAL_EDGES`]); regular tet: all [`REGULAR_DIHEDRAL`]. For a flat tet each angle is
/// 0 or 180. Never NaN.
#[inline]
pub fn dihedral_angles(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> [f64; 6] {
    let (u, v, w) = (b - a, c - a, d - a);
    let det = orient3d(a, b, c, d);
    let n = face_normals(u, v, w);
    let l2 = edge_lengths_sq(u, v, w);
    let mut out = [0.0; 6];
    for (i, [k, l]) in EDGE_FACES.iter().copied().enumerate() {
        out[i] = dihedral_rad(n[k], n[l], det, l2[i].sqrt()).to_degrees();
    }
    out
}

/// (smallest, largest) dihedral angle in degrees; (0, 180) for a flat tet.
#[inline]
pub fn min_max_dihedral(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> (f64, f64) {
    let (u, v, w) = (b - a, c - a, d - a);
    let n = face_normals(u, v, w);
    min_max_dihedral_from(&n, &edge_lengths_sq(u, v, w), orient3d(a, b, c, d))
}

// ---------------------------------------------------------------------------------------------
// All at once
// ---------------------------------------------------------------------------------------------

/// Every quality measure of one tet, computed in a single pass by [`TetQuality::of`].
///
/// A flat tet (exact orientation 0, which includes coincident vertices) gets rho = aspect =
/// circumradius = +∞, sigma = volume = 0, dihedral angles (0, 180) and no circumcentre; its
/// `shortest_edge` is still the real one. The same values are reported if the circumcentre
/// overflows, which needs coordinates outside the accepted range ([`super::MAX_COORD`]).
/// No field is ever NaN for finite input.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TetQuality {
    /// Radius-edge ratio R/L (regular: [`REGULAR_RHO`]).
    pub rho: f64,
    /// |V|/L³ (regular: [`REGULAR_SIGMA`]).
    pub sigma: f64,
    /// R/(3r) (regular: 1).
    pub aspect: f64,
    /// Smallest dihedral angle, degrees.
    pub min_dihedral: f64,
    /// Largest dihedral angle, degrees.
    pub max_dihedral: f64,
    /// Signed volume, > 0 for positive orientation.
    pub volume: f64,
    /// Circumradius R.
    pub circumradius: f64,
    /// Shortest edge length L.
    pub shortest_edge: f64,
    /// Circumcentre (`None` for a flat tet); refinement needs it for the size test R/f(c).
    pub circumcenter: Option<DVec3>,
}

impl TetQuality {
    /// Computes every measure of the tet (a, b, c, d) in one pass: one adaptive orientation
    /// predicate, three cross products shared by the circumcentre and the face normals, and two
    /// `atan2` for the extreme dihedral angles.
    #[inline]
    pub fn of(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> TetQuality {
        let (u, v, w) = (b - a, c - a, d - a);
        let det = orient3d(a, b, c, d);
        let l2 = edge_lengths_sq(u, v, w);
        let shortest_edge = min6(&l2).sqrt();
        if det == 0.0 {
            return TetQuality::flat(shortest_edge);
        }
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let Some(off) = circum_offset_crossed([vw, wu, uv], [l2[0], l2[1], l2[2]], det) else {
            return TetQuality::flat(shortest_edge);
        };
        let circumradius = off.length();
        // Same as face_normals(u, v, w), reusing the cross products.
        let n = [(v - u).cross(w - u), -vw, -wu, -uv];
        let area2 = n[0].length() + n[1].length() + n[2].length() + n[3].length();
        let abs_det = det.abs();
        let abs_vol = abs_det / 6.0;
        let inradius = abs_det / area2;
        let (min_dihedral, max_dihedral) = min_max_dihedral_from(&n, &l2, det);
        TetQuality {
            rho: circumradius / shortest_edge,
            sigma: abs_vol / (shortest_edge * shortest_edge * shortest_edge),
            aspect: circumradius / (3.0 * inradius),
            min_dihedral,
            max_dihedral,
            volume: det / 6.0,
            circumradius,
            shortest_edge,
            circumcenter: Some(a + off),
        }
    }

    /// The values reported for a flat tet with the given shortest edge.
    #[inline]
    fn flat(shortest_edge: f64) -> TetQuality {
        TetQuality {
            rho: f64::INFINITY,
            sigma: 0.0,
            aspect: f64::INFINITY,
            min_dihedral: 0.0,
            max_dihedral: 180.0,
            volume: 0.0,
            circumradius: f64::INFINITY,
            shortest_edge,
            circumcenter: None,
        }
    }

    /// True for a flat tet (exact orientation zero; see the type's documentation).
    #[inline]
    pub fn is_flat(&self) -> bool {
        self.circumcenter.is_none()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DQuat;
    use std::f64::consts::PI;

    /// |got - want| <= tol * max(1, |want|).
    #[track_caller]
    fn close(got: f64, want: f64, tol: f64) {
        let err = (got - want).abs();
        assert!(
            err <= tol * want.abs().max(1.0),
            "got {got:e}, want {want:e} (err {err:e}, tol {tol:e})"
        );
    }

    #[track_caller]
    fn close_v(got: DVec3, want: DVec3, tol: f64) {
        for i in 0..3 {
            close(got[i], want[i], tol);
        }
    }

    /// Regular tet with edge 2√2, centred at the origin, positively oriented.
    fn regular() -> [DVec3; 4] {
        [
            DVec3::new(1.0, 1.0, 1.0),
            DVec3::new(-1.0, 1.0, -1.0),
            DVec3::new(1.0, -1.0, -1.0),
            DVec3::new(-1.0, -1.0, 1.0),
        ]
    }

    /// Right-corner tet with legs p, q, s along x, y, z.
    fn corner(p: f64, q: f64, s: f64) -> [DVec3; 4] {
        [
            DVec3::ZERO,
            DVec3::new(p, 0.0, 0.0),
            DVec3::new(0.0, q, 0.0),
            DVec3::new(0.0, 0.0, s),
        ]
    }

    /// Four points near the unit circle of z = 0, alternately lifted by ±e: a sliver, flat for
    /// e = 0. Ordered to be positively oriented for e > 0.
    fn sliver(e: f64) -> [DVec3; 4] {
        [
            DVec3::new(1.0, 0.0, e),
            DVec3::new(0.0, 1.0, -e),
            DVec3::new(0.0, -1.0, -e),
            DVec3::new(-1.0, 0.0, e),
        ]
    }

    fn q(t: [DVec3; 4]) -> TetQuality {
        TetQuality::of(t[0], t[1], t[2], t[3])
    }

    /// Reference dihedral angle at edge (i, j), computed differently from the library: project
    /// the two other vertices onto the plane orthogonal to the edge and take the angle between
    /// the projections with acos.
    fn dihedral_by_projection(t: [DVec3; 4], i: usize, j: usize) -> f64 {
        let others: Vec<usize> = (0..4).filter(|&k| k != i && k != j).collect();
        let e = (t[j] - t[i]).normalize();
        let proj = |k: usize| {
            let x = t[k] - t[i];
            x - e * x.dot(e)
        };
        let (x, y) = (proj(others[0]), proj(others[1]));
        (x.dot(y) / (x.length() * y.length()))
            .clamp(-1.0, 1.0)
            .acos()
            .to_degrees()
    }

    #[test]
    fn regular_constants_match_their_closed_forms() {
        close(REGULAR_RHO, 6f64.sqrt() / 4.0, 1e-16);
        close(REGULAR_SIGMA, 1.0 / (6.0 * 2f64.sqrt()), 1e-16);
        close(REGULAR_DIHEDRAL, (1.0f64 / 3.0).acos() * 180.0 / PI, 1e-15);
        assert_eq!(DIHEDRAL_EDGES.len(), EDGE_FACES.len());
        // each edge's two faces are the faces opposite the two vertices not on the edge
        for (e, f) in DIHEDRAL_EDGES.iter().zip(EDGE_FACES.iter()) {
            for k in f {
                assert!(!e.contains(k));
            }
        }
    }

    #[test]
    fn regular_tet_known_answers() {
        let [a, b, c, d] = regular();
        let edge = 8f64.sqrt();
        close_v(circumcenter(a, b, c, d).unwrap(), DVec3::ZERO, 1e-15);
        close(circumradius(a, b, c, d), 3f64.sqrt(), 1e-15);
        close(volume(a, b, c, d), 8.0 / 3.0, 1e-15);
        close(inradius(a, b, c, d), 1.0 / 3f64.sqrt(), 1e-15);
        close(shortest_edge(a, b, c, d), edge, 1e-15);
        close(longest_edge(a, b, c, d), edge, 1e-15);
        close(radius_edge_ratio(a, b, c, d), 6f64.sqrt() / 4.0, 1e-15);
        close(sigma(a, b, c, d), 1.0 / (6.0 * 2f64.sqrt()), 1e-15);
        close(aspect(a, b, c, d), 1.0, 1e-15);
        let want = (1.0f64 / 3.0).acos().to_degrees();
        for x in dihedral_angles(a, b, c, d) {
            close(x, want, 1e-13);
        }
        let (lo, hi) = min_max_dihedral(a, b, c, d);
        close(lo, want, 1e-13);
        close(hi, want, 1e-13);
        let tq = q(regular());
        close(tq.rho, REGULAR_RHO, 1e-15);
        close(tq.sigma, REGULAR_SIGMA, 1e-15);
        close(tq.aspect, REGULAR_ASPECT, 1e-15);
        close(tq.min_dihedral, REGULAR_DIHEDRAL, 1e-13);
        close(tq.max_dihedral, REGULAR_DIHEDRAL, 1e-13);
        close(tq.volume, 8.0 / 3.0, 1e-15);
        close(tq.circumradius, 3f64.sqrt(), 1e-15);
        close(tq.shortest_edge, edge, 1e-15);
        close_v(tq.circumcenter.unwrap(), DVec3::ZERO, 1e-15);
        assert!(!tq.is_flat());
    }

    #[test]
    fn right_corner_tet_known_answers() {
        let [a, b, c, d] = corner(1.0, 1.0, 1.0);
        close_v(circumcenter(a, b, c, d).unwrap(), DVec3::splat(0.5), 1e-15);
        close(circumradius(a, b, c, d), 3f64.sqrt() / 2.0, 1e-15);
        assert_eq!(volume(a, b, c, d), 1.0 / 6.0);
        close(shortest_edge(a, b, c, d), 1.0, 1e-15);
        close(longest_edge(a, b, c, d), 2f64.sqrt(), 1e-15);
        // total area 3/2 + √3/2; r = 3V/A = 1/(3 + √3)
        close(inradius(a, b, c, d), 1.0 / (3.0 + 3f64.sqrt()), 1e-15);
        close(radius_edge_ratio(a, b, c, d), 3f64.sqrt() / 2.0, 1e-15);
        close(sigma(a, b, c, d), 1.0 / 6.0, 1e-15);
        close(
            aspect(a, b, c, d),
            3f64.sqrt() / 2.0 * (3.0 + 3f64.sqrt()) / 3.0,
            1e-15,
        );
        let acute = (1.0 / 3f64.sqrt()).acos().to_degrees();
        close(acute, 54.735_610_317_245_35, 1e-15);
        let ang = dihedral_angles(a, b, c, d);
        let want = [90.0, 90.0, 90.0, acute, acute, acute];
        for i in 0..6 {
            close(ang[i], want[i], 1e-13);
        }
        let (lo, hi) = min_max_dihedral(a, b, c, d);
        close(lo, acute, 1e-13);
        close(hi, 90.0, 1e-13);
    }

    /// Closed forms for a right-corner tet with arbitrary legs; also covers a needle.
    fn check_corner(p: f64, qq: f64, s: f64, tol: f64) {
        let t = corner(p, qq, s);
        let [a, b, c, d] = t;
        let big_r = (p * p + qq * qq + s * s).sqrt() / 2.0;
        let vol = p * qq * s / 6.0;
        let l = p.min(qq).min(s);
        let area = (p * qq + p * s + qq * s) / 2.0
            + (p * p * qq * qq + qq * qq * s * s + s * s * p * p).sqrt() / 2.0;
        let r = 3.0 * vol / area;
        close_v(
            circumcenter(a, b, c, d).unwrap(),
            DVec3::new(p, qq, s) / 2.0,
            tol,
        );
        close(circumradius(a, b, c, d), big_r, tol);
        close(volume(a, b, c, d), vol, tol);
        close(inradius(a, b, c, d), r, tol);
        close(shortest_edge(a, b, c, d), l, tol);
        let longest = (p * p + qq * qq)
            .max(p * p + s * s)
            .max(qq * qq + s * s)
            .sqrt();
        close(longest_edge(a, b, c, d), longest, tol);
        close(radius_edge_ratio(a, b, c, d), big_r / l, tol);
        close(sigma(a, b, c, d), vol / (l * l * l), tol);
        close(aspect(a, b, c, d), big_r / (3.0 * r), tol);
        // dihedral at a hypotenuse edge: acos(n_i/|n|), n = (1/p, 1/q, 1/s), i the axis of the
        // face the edge lies in.
        let n = DVec3::new(1.0 / p, 1.0 / qq, 1.0 / s);
        let want = [
            90.0,
            90.0,
            90.0,
            (n.z / n.length()).acos().to_degrees(),
            (n.y / n.length()).acos().to_degrees(),
            (n.x / n.length()).acos().to_degrees(),
        ];
        let got = dihedral_angles(a, b, c, d);
        for i in 0..6 {
            close(got[i], want[i], tol * 100.0);
        }
        let tq = q(t);
        close(tq.rho, big_r / l, tol);
        close(tq.sigma, vol / (l * l * l), tol);
        close(tq.aspect, big_r / (3.0 * r), tol);
        close(tq.volume, vol, tol);
        close(tq.circumradius, big_r, tol);
        close(tq.shortest_edge, l, tol);
        let lo = want.iter().copied().fold(f64::INFINITY, f64::min);
        let hi = want.iter().copied().fold(0.0, f64::max);
        close(tq.min_dihedral, lo, tol * 100.0);
        close(tq.max_dihedral, hi, tol * 100.0);
    }

    #[test]
    fn right_corner_tets_with_unequal_legs() {
        check_corner(1.0, 1.0, 1.0, 1e-15);
        check_corner(2.0, 3.0, 5.0, 1e-15);
        check_corner(0.25, 7.0, 1.5, 1e-15);
    }

    #[test]
    fn needle_has_large_rho_but_is_no_sliver() {
        let eps = 1e-3;
        check_corner(eps, eps, 1.0, 1e-14);
        let tq = q(corner(eps, eps, 1.0));
        // rho = sqrt(1 + 2 eps²) / (2 eps) ≈ 500
        close(tq.rho, (1.0 + 2.0 * eps * eps).sqrt() / (2.0 * eps), 1e-14);
        assert!(tq.rho > 499.0);
        // sigma = 1/(6 eps): a needle is not a sliver
        close(tq.sigma, 1.0 / (6.0 * eps), 1e-14);
        // two dihedral angles tend to 45°, none to 0 or 180
        close(
            tq.min_dihedral,
            (1.0 / (2.0 + eps * eps).sqrt()).acos().to_degrees(),
            1e-12,
        );
        close(tq.max_dihedral, 90.0, 1e-12);
        assert!(tq.aspect > 100.0);
    }

    #[test]
    fn sliver_known_answers() {
        for e in [0.1, 1e-3, 1e-6, 1e-9] {
            let t = sliver(e);
            let [a, b, c, d] = t;
            // centre on the z axis by symmetry, at z = 0. The circumcentre of a sliver is
            // ill-conditioned (the bisector planes are nearly parallel to z): error ~ eps / e.
            let c0 = circumcenter(a, b, c, d).unwrap();
            close_v(c0, DVec3::ZERO, 1e-15 / e);
            close(circumradius(a, b, c, d), (1.0 + e * e).sqrt(), 1e-15);
            close(volume(a, b, c, d), 4.0 * e / 3.0, 1e-14);
            let l = (2.0 + 4.0 * e * e).sqrt();
            close(shortest_edge(a, b, c, d), l, 1e-15);
            close(longest_edge(a, b, c, d), 2.0, 1e-15);
            let r = e / (1.0 + 4.0 * e * e).sqrt();
            close(inradius(a, b, c, d) / r, 1.0, 1e-12);
            // rho stays near 1/√2: the radius-edge ratio does not see slivers ...
            close(
                radius_edge_ratio(a, b, c, d),
                (1.0 + e * e).sqrt() / l,
                1e-14,
            );
            // ... sigma does
            let sig = 4.0 * e / 3.0 / (l * l * l);
            close(sigma(a, b, c, d) / sig, 1.0, 1e-12);
            let asp = (1.0 + e * e).sqrt() * (1.0 + 4.0 * e * e).sqrt() / (3.0 * e);
            close(aspect(a, b, c, d) / asp, 1.0, 1e-12);
            // diagonal edges (ad and bc here) are at π - 2 atan(2e); the four sides at
            // atan(2e sqrt(2 + 4e²)). Compare the distance to 180 / 0 relatively: the angles
            // must keep full accuracy near the extremes.
            let diag = 180.0 - (2.0 * (2.0 * e).atan()).to_degrees();
            let side = (2.0 * e * (2.0 + 4.0 * e * e).sqrt()).atan().to_degrees();
            let ang = dihedral_angles(a, b, c, d);
            for (i, &x) in ang.iter().enumerate() {
                if i == 2 || i == 3 {
                    close((180.0 - x) / (180.0 - diag), 1.0, 1e-9);
                } else {
                    close(x / side, 1.0, 1e-9);
                }
            }
            let tq = q(t);
            close((180.0 - tq.max_dihedral) / (180.0 - diag), 1.0, 1e-9);
            close(tq.min_dihedral / side, 1.0, 1e-9);
            close(tq.sigma / sig, 1.0, 1e-12);
            close(tq.aspect / asp, 1.0, 1e-12);
            close(tq.rho, (1.0 + e * e).sqrt() / l, 1e-14);
        }
        // sigma → 0 and the max angle → 180 as the sliver flattens
        assert!(
            sigma(
                sliver(1e-9)[0],
                sliver(1e-9)[1],
                sliver(1e-9)[2],
                sliver(1e-9)[3]
            ) < 1e-9
        );
        assert!(q(sliver(1e-9)).max_dihedral > 180.0 - 1e-6);
    }

    #[test]
    fn flat_tets_are_degenerate_not_nan() {
        let flat = [
            sliver(0.0),
            // coplanar, not cocircular
            [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(3.0, 2.0, 0.0)],
            // collinear
            [DVec3::ZERO, DVec3::X, DVec3::X * 2.0, DVec3::Y],
            // coincident
            [DVec3::ZERO, DVec3::ZERO, DVec3::X, DVec3::Y],
            [DVec3::ONE; 4],
        ];
        for t in flat {
            let [a, b, c, d] = t;
            assert_eq!(circumcenter(a, b, c, d), None);
            assert_eq!(circumsphere(a, b, c, d), None);
            assert_eq!(circumradius(a, b, c, d), f64::INFINITY);
            assert_eq!(volume(a, b, c, d), 0.0);
            assert_eq!(inradius(a, b, c, d), 0.0);
            assert_eq!(radius_edge_ratio(a, b, c, d), f64::INFINITY);
            assert_eq!(sigma(a, b, c, d), 0.0);
            assert_eq!(aspect(a, b, c, d), f64::INFINITY);
            assert_eq!(min_max_dihedral(a, b, c, d), (0.0, 180.0));
            for x in dihedral_angles(a, b, c, d) {
                assert!(x == 0.0 || x == 180.0, "{x}");
            }
            let tq = q(t);
            assert!(tq.is_flat());
            assert_eq!(tq.rho, f64::INFINITY);
            assert_eq!(tq.sigma, 0.0);
            assert_eq!(tq.aspect, f64::INFINITY);
            assert_eq!((tq.min_dihedral, tq.max_dihedral), (0.0, 180.0));
            assert_eq!(tq.volume, 0.0);
            assert_eq!(tq.circumradius, f64::INFINITY);
            assert_eq!(tq.shortest_edge, shortest_edge(a, b, c, d));
        }
        // the flat sliver's angles: diagonals 180, sides 0
        let [a, b, c, d] = sliver(0.0);
        assert_eq!(
            dihedral_angles(a, b, c, d),
            [0.0, 0.0, 180.0, 180.0, 0.0, 0.0]
        );
    }

    /// A generic, positively oriented, not-too-regular tet.
    fn generic() -> [DVec3; 4] {
        [
            DVec3::new(0.1, -0.3, 0.2),
            DVec3::new(1.7, 0.2, -0.1),
            DVec3::new(0.4, 1.3, 0.3),
            DVec3::new(0.6, 0.5, 2.1),
        ]
    }

    #[test]
    fn generic_tet_properties() {
        let t = generic();
        let [a, b, c, d] = t;
        assert!(volume(a, b, c, d) > 0.0);
        let (cc, r) = circumsphere(a, b, c, d).unwrap();
        for p in t {
            close(cc.distance(p), r, 1e-14);
        }
        // dihedral angles against an independent construction
        let ang = dihedral_angles(a, b, c, d);
        for (k, [i, j]) in DIHEDRAL_EDGES.iter().copied().enumerate() {
            close(ang[k], dihedral_by_projection(t, i, j), 1e-11);
        }
        let (lo, hi) = min_max_dihedral(a, b, c, d);
        close(lo, ang.iter().copied().fold(f64::INFINITY, f64::min), 1e-15);
        close(hi, ang.iter().copied().fold(0.0, f64::max), 1e-15);
        // volume: sum over faces of (1/3) * area * distance from the in-centre ... use instead
        // the independent triple product
        close(
            volume(a, b, c, d),
            (b - a).dot((c - a).cross(d - a)) / 6.0,
            1e-15,
        );
        // TetQuality agrees with the individual functions
        let tq = q(t);
        close(tq.rho, radius_edge_ratio(a, b, c, d), 1e-15);
        close(tq.sigma, sigma(a, b, c, d), 1e-15);
        close(tq.aspect, aspect(a, b, c, d), 1e-15);
        close(tq.min_dihedral, lo, 1e-15);
        close(tq.max_dihedral, hi, 1e-15);
        assert_eq!(tq.volume, volume(a, b, c, d));
        close(tq.circumradius, r, 1e-15);
        close_v(tq.circumcenter.unwrap(), cc, 1e-15);
        assert_eq!(tq.shortest_edge, shortest_edge(a, b, c, d));
        // Inradius: the in-centre (area-weighted vertex average with opposite-face areas) is at
        // distance r from every face plane.
        let n = face_normals(b - a, c - a, d - a);
        let ar: Vec<f64> = n.iter().map(|x| x.length()).collect();
        let tot: f64 = ar.iter().sum();
        let inc = (a * ar[0] + b * ar[1] + c * ar[2] + d * ar[3]) / tot;
        let rin = inradius(a, b, c, d);
        for (f, p) in [(0, b), (1, a), (2, a), (3, a)] {
            close((inc - p).dot(n[f].normalize()).abs(), rin, 1e-14);
        }
    }

    #[test]
    fn orientation_flips_only_the_volume_sign() {
        for t in [generic(), regular(), corner(2.0, 3.0, 5.0), sliver(1e-3)] {
            let [a, b, c, d] = t;
            let p = q([a, b, c, d]);
            let m = q([b, a, c, d]);
            assert!(p.volume > 0.0);
            assert_eq!(m.volume, -p.volume);
            close(m.rho, p.rho, 1e-14);
            close(m.sigma, p.sigma, 1e-14);
            close(m.aspect, p.aspect, 1e-14);
            close(m.min_dihedral, p.min_dihedral, 1e-12);
            close(m.max_dihedral, p.max_dihedral, 1e-12);
            // (the sliver's centre is ill-conditioned, error ~ eps / 1e-3)
            close_v(m.circumcenter.unwrap(), p.circumcenter.unwrap(), 1e-12);
            // swapping a and b swaps edges ac<->bc and ad<->bd
            let x = dihedral_angles(a, b, c, d);
            let y = dihedral_angles(b, a, c, d);
            let perm = [0, 3, 4, 1, 2, 5];
            for i in 0..6 {
                close(y[i], x[perm[i]], 1e-12);
            }
        }
    }

    fn transform(t: [DVec3; 4], rot: DQuat, scale: f64, shift: DVec3) -> [DVec3; 4] {
        t.map(|p| rot * p * scale + shift)
    }

    #[test]
    fn invariant_under_translation_rotation_and_scaling() {
        let rot = DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
        let mirror = |t: [DVec3; 4]| t.map(|p| DVec3::new(-p.x, p.y, p.z));
        for t in [generic(), corner(0.25, 7.0, 1.5), sliver(1e-2)] {
            let base = q(t);
            let base_ang = dihedral_angles(t[0], t[1], t[2], t[3]);
            for (rot, scale, shift) in [
                (DQuat::IDENTITY, 1.0, DVec3::new(1e3, -5e2, 7.0)),
                (DQuat::IDENTITY, 1e-3, DVec3::ZERO),
                (DQuat::IDENTITY, 1e4, DVec3::ZERO),
                (rot, 1.0, DVec3::ZERO),
                (rot, 37.5, DVec3::new(-3.0, 11.0, 0.5)),
            ] {
                let u = transform(t, rot, scale, shift);
                let tq = q(u);
                close(tq.rho, base.rho, 1e-10);
                close(tq.sigma, base.sigma, 1e-10);
                close(tq.aspect, base.aspect, 1e-10);
                close(tq.min_dihedral, base.min_dihedral, 1e-9);
                close(tq.max_dihedral, base.max_dihedral, 1e-9);
                close(tq.volume, base.volume * scale.powi(3), 1e-10);
                close(tq.circumradius, base.circumradius * scale, 1e-10);
                close(tq.shortest_edge, base.shortest_edge * scale, 1e-10);
                let want_c = rot * base.circumcenter.unwrap() * scale + shift;
                close_v(tq.circumcenter.unwrap(), want_c, 1e-10);
                let ang = dihedral_angles(u[0], u[1], u[2], u[3]);
                for i in 0..6 {
                    close(ang[i], base_ang[i], 1e-9);
                }
            }
            // a reflection changes only the sign of the volume
            let m = q(mirror(t));
            close(m.volume, -base.volume, 1e-14);
            close(m.sigma, base.sigma, 1e-14);
            close(m.max_dihedral, base.max_dihedral, 1e-12);
        }
    }

    #[test]
    fn scaled_rotated_regular_tet() {
        let rot = DQuat::from_euler(glam::EulerRot::ZYX, 0.3, -1.1, 2.4);
        let (scale, shift) = (0.013, DVec3::new(5.0, -2.0, 9.0));
        let t = transform(regular(), rot, scale, shift);
        let [a, b, c, d] = t;
        let edge = 8f64.sqrt() * scale;
        let tq = q(t);
        close(tq.rho, 6f64.sqrt() / 4.0, 1e-12);
        close(tq.sigma, 1.0 / (6.0 * 2f64.sqrt()), 1e-12);
        close(tq.aspect, 1.0, 1e-12);
        close(tq.min_dihedral, (1.0f64 / 3.0).acos().to_degrees(), 1e-10);
        close(tq.max_dihedral, (1.0f64 / 3.0).acos().to_degrees(), 1e-10);
        close(tq.volume / (edge.powi(3) / (6.0 * 2f64.sqrt())), 1.0, 1e-12);
        close(tq.circumradius / (edge * 6f64.sqrt() / 4.0), 1.0, 1e-12);
        close(tq.shortest_edge / edge, 1.0, 1e-12);
        close_v(tq.circumcenter.unwrap(), shift, 1e-12);
        close(longest_edge(a, b, c, d) / edge, 1.0, 1e-12);
        close(
            inradius(a, b, c, d) / (edge / (2.0 * 6f64.sqrt())),
            1.0,
            1e-12,
        );
        for x in dihedral_angles(a, b, c, d) {
            close(x, REGULAR_DIHEDRAL, 1e-10);
        }
    }

    #[test]
    fn circumcenter_is_stable_far_from_the_origin() {
        // A small tet far away: the result must be as good as the nearby one, shifted.
        let shift = DVec3::new(1e6, -2e6, 3e6);
        let t = generic();
        let near = circumcenter(t[0], t[1], t[2], t[3]).unwrap();
        let f = t.map(|p| p + shift);
        let far = circumcenter(f[0], f[1], f[2], f[3]).unwrap();
        close_v(far - shift, near, 1e-8);
        // a thin but non-flat tet still has a finite, equidistant centre
        let s = sliver(1e-12);
        let (cc, r) = circumsphere(s[0], s[1], s[2], s[3]).unwrap();
        for p in s {
            close(cc.distance(p), r, 1e-10);
        }
    }

    #[test]
    fn triangle_circumcentre_and_balls() {
        let (o, x, y, z) = (DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z);
        close_v(
            tri_circumcenter(o, 2.0 * x, 2.0 * y).unwrap(),
            DVec3::new(1.0, 1.0, 0.0),
            1e-15,
        );
        close(tri_circumradius(o, 2.0 * x, 2.0 * y), 2f64.sqrt(), 1e-15);
        // equilateral triangle x, y, z: centroid, radius sqrt(2/3)
        let (c, r) = equatorial_ball(x, y, z).unwrap();
        close_v(c, DVec3::splat(1.0 / 3.0), 1e-15);
        close(r, (2.0f64 / 3.0).sqrt(), 1e-15);
        // an obtuse triangle in a tilted plane: the centre is outside the triangle, in the
        // plane, equidistant, and the radius is |ab| / (2 sin C) (law of sines)
        let rot = DQuat::from_axis_angle(DVec3::new(-1.0, 0.5, 2.0).normalize(), 1.3);
        let shift = DVec3::new(3.0, -1.0, 4.0);
        let (a, b, cc) = (
            rot * DVec3::new(0.0, 0.0, 0.0) + shift,
            rot * DVec3::new(4.0, 0.0, 0.0) + shift,
            rot * DVec3::new(1.0, 0.5, 0.0) + shift,
        );
        let (centre, rad) = equatorial_ball(a, b, cc).unwrap();
        for p in [a, b, cc] {
            close(centre.distance(p), rad, 1e-14);
        }
        let n = (b - a).cross(cc - a).normalize();
        close((centre - a).dot(n), 0.0, 1e-14);
        let (ca, cb) = (a - cc, b - cc);
        let sin_c = ca.cross(cb).length() / (ca.length() * cb.length());
        close(rad, 4.0 / (2.0 * sin_c), 1e-14);
        close_v(
            rot.inverse() * (centre - shift),
            DVec3::new(2.0, -2.75, 0.0),
            1e-14,
        );
        // collinear and coincident: none
        assert_eq!(tri_circumcenter(o, x, 3.0 * x), None);
        assert_eq!(equatorial_ball(y, y, z), None);
        assert_eq!(tri_circumradius(o, x, -x), f64::INFINITY);
        // diametric ball
        let (m, h) = diametric_ball(DVec3::new(1.0, 2.0, 3.0), DVec3::new(3.0, 6.0, 7.0));
        assert_eq!(m, DVec3::new(2.0, 4.0, 5.0));
        assert_eq!(h, 3.0);
    }
}
