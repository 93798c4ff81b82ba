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
fn edge_lengths_sq(u: DVec3, v: DVec3, w: DVec3) -> [f64; 6] {
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
    if det == 0.0 {
        return None;
    }
    let num = l2[0] * v.cross(w) + l2[1] * w.cross(u) + l2[2] * u.cross(v);
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
    let len = [
        n[0].length(),
        n[1].length(),
        n[2].length(),
        n[3].length(),
    ];
    if det == 0.0 || len.iter().any(|&x| x == 0.0) {
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
/// denominator: c = a + (|u|²(v×w) + |v|²(w×u) + |w|²(u×v)) / (2·det[u,v,w]),
/// u = b-a, v = c-a, w = d-a. Independent of the orientation of (a, b, c, d).
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
/// c = a + (|u|²(v×n) + |v|²(n×u)) / (2|n|²), u = b-a, v = c-a, n = u×v.
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
/// `shortest_edge` is still the real one. No field is ever NaN for finite input.
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
        let off = (l2[0] * vw + l2[1] * wu + l2[2] * uv) * (0.5 / det);
        if !off.is_finite() {
            return TetQuality::flat(shortest_edge);
        }
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

    /// True for a flat tet (exact orientation zero).
    #[inline]
    pub fn is_flat(&self) -> bool {
        self.circumcenter.is_none()
    }
}
