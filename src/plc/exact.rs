//! Exact 2D and 3D incidence tests built on `geom::orient3d` and `geom::orient2d` (only `geom`
//! may call `robust`).
//!
//! Every decision here is a sign of an exact predicate; no tolerance.

use crate::geom::orient3d;
use glam::DVec3;
use std::cmp::Ordering;

/// A point in a facet's 2D projection.
pub type P2 = [f64; 2];

/// Sign of the 2D orientation: > 0 iff (a, b, c) turn counter-clockwise.
pub fn orient2d(a: P2, b: P2, c: P2) -> Ordering {
    sign(crate::geom::orient2d(a, b, c))
}

/// Sign of `orient3d` as an ordering.
pub fn orient3(a: DVec3, b: DVec3, c: DVec3, d: DVec3) -> Ordering {
    sign(orient3d(a, b, c, d))
}

fn sign(x: f64) -> Ordering {
    crate::geom::sign(x)
}

/// Lexicographic (x, then y) order; along any line it is a monotone order.
fn lex(a: P2, b: P2) -> Ordering {
    a[0].total_cmp(&b[0]).then(a[1].total_cmp(&b[1]))
}

/// True iff the closed segments [a, b] and [c, d] (no endpoint shared) have a common point.
pub fn segments_meet_2d(a: P2, b: P2, c: P2, d: P2) -> bool {
    let o1 = orient2d(a, b, c);
    let o2 = orient2d(a, b, d);
    let o3 = orient2d(c, d, a);
    let o4 = orient2d(c, d, b);
    if (o1 == o2 && o1 != Ordering::Equal) || (o3 == o4 && o3 != Ordering::Equal) {
        return false;
    }
    if o1 == Ordering::Equal && o2 == Ordering::Equal {
        // Collinear: the 1D intervals in lexicographic order must overlap.
        let (lo1, hi1) = if lex(a, b).is_le() { (a, b) } else { (b, a) };
        let (lo2, hi2) = if lex(c, d).is_le() { (c, d) } else { (d, c) };
        let lo = if lex(lo1, lo2).is_ge() { lo1 } else { lo2 };
        let hi = if lex(hi1, hi2).is_le() { hi1 } else { hi2 };
        return lex(lo, hi).is_le();
    }
    true
}

/// For segments [p, a] and [p, d] sharing only the endpoint p: true iff they overlap along a
/// piece of line (collinear and pointing the same way from p).
pub fn shared_end_overlap_2d(p: P2, a: P2, d: P2) -> bool {
    orient2d(p, a, d) == Ordering::Equal && lex(a, p) == lex(d, p)
}

/// True iff p lies in the closed triangle (a, b, c) (2D, non-degenerate triangle).
pub fn point_in_triangle_2d(p: P2, a: P2, b: P2, c: P2) -> bool {
    let o = [orient2d(a, b, p), orient2d(b, c, p), orient2d(c, a, p)];
    !(o.contains(&Ordering::Less) && o.contains(&Ordering::Greater))
}

/// Drops coordinate `axis`, keeping the other two in cyclic order.
pub fn drop_axis(p: DVec3, axis: usize) -> P2 {
    let a = p.to_array();
    [a[(axis + 1) % 3], a[(axis + 2) % 3]]
}

/// An axis whose projection keeps the (non-degenerate) triangle non-degenerate.
fn projection_axis(a: DVec3, b: DVec3, c: DVec3) -> usize {
    let n = (b - a).cross(c - a).abs();
    let mut axes = [0usize, 1, 2];
    axes.sort_by(|&i, &j| n[j].total_cmp(&n[i]));
    // The float normal picks the best axis; the exact test guards against rounding.
    for axis in axes {
        let (pa, pb, pc) = (drop_axis(a, axis), drop_axis(b, axis), drop_axis(c, axis));
        if orient2d(pa, pb, pc) != Ordering::Equal {
            return axis;
        }
    }
    panic!("projection_axis: degenerate triangle {a} {b} {c}")
}

/// True iff p lies in the closed triangle (a, b, c) in 3D.
pub fn point_in_triangle_3d(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    if orient3(a, b, c, p) != Ordering::Equal {
        return false;
    }
    coplanar_point_in_triangle(p, a, b, c)
}

fn coplanar_point_in_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    let k = projection_axis(a, b, c);
    let pr = |q: DVec3| drop_axis(q, k);
    point_in_triangle_2d(pr(p), pr(a), pr(b), pr(c))
}

/// True iff the closed segment [p, q] meets the closed triangle (a, b, c).
pub fn segment_meets_triangle(p: DVec3, q: DVec3, a: DVec3, b: DVec3, c: DVec3) -> bool {
    let op = orient3(a, b, c, p);
    let oq = orient3(a, b, c, q);
    match (op, oq) {
        (Ordering::Equal, Ordering::Equal) => {
            let k = projection_axis(a, b, c);
            let pr = |x: DVec3| drop_axis(x, k);
            let (p2, q2, a2, b2, c2) = (pr(p), pr(q), pr(a), pr(b), pr(c));
            point_in_triangle_2d(p2, a2, b2, c2)
                || point_in_triangle_2d(q2, a2, b2, c2)
                || segments_meet_2d(p2, q2, a2, b2)
                || segments_meet_2d(p2, q2, b2, c2)
                || segments_meet_2d(p2, q2, c2, a2)
        }
        // The segment touches the plane only at one endpoint.
        (Ordering::Equal, _) => coplanar_point_in_triangle(p, a, b, c),
        (_, Ordering::Equal) => coplanar_point_in_triangle(q, a, b, c),
        _ if op == oq => false,
        _ => {
            // Strictly crossing the plane: the line must pass through the closed triangle.
            let o = [
                orient3(p, q, a, b),
                orient3(p, q, b, c),
                orient3(p, q, c, a),
            ];
            !(o.contains(&Ordering::Less) && o.contains(&Ordering::Greater))
        }
    }
}

/// For triangle (p, c, d) and a point a: true iff the segment from p towards a enters the
/// closed triangle beyond p (a coplanar with it and inside its angle at p).
fn ray_enters_corner(p: DVec3, a: DVec3, c: DVec3, d: DVec3) -> bool {
    if orient3(p, c, d, a) != Ordering::Equal {
        return false;
    }
    let k = projection_axis(p, c, d);
    let pr = |x: DVec3| drop_axis(x, k);
    let (p2, a2, c2, d2) = (pr(p), pr(a), pr(c), pr(d));
    let s = orient2d(p2, c2, d2);
    let o1 = orient2d(p2, c2, a2);
    let o2 = orient2d(p2, a2, d2);
    o1 != s.reverse() && o2 != s.reverse()
}

/// How two triangles of different facets relate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Contact {
    /// They meet in exactly the convex hull of their shared vertices (possibly nothing).
    Clean,
    /// They share an edge (only that edge in common); the caller checks it is a segment.
    SharedEdge([u32; 2]),
    /// They meet in more than their shared vertices: the facets intersect illegally.
    Clash,
}

/// Classifies the intersection of two non-degenerate triangles given by ids and points.
pub fn triangle_contact(ti: [u32; 3], t: [DVec3; 3], si: [u32; 3], s: [DVec3; 3]) -> Contact {
    // The shared corners as (index in t, index in s), in a fixed array: this runs for every
    // pair of neighbouring triangles of the input.
    let mut pairs = [(0, 0); 3];
    let mut n_shared = 0;
    for (i, j) in (0..3).flat_map(|i| (0..3).map(move |j| (i, j))) {
        if ti[i] == si[j] && n_shared < 3 {
            pairs[n_shared] = (i, j);
            n_shared += 1;
        }
    }
    let shared = &pairs[..n_shared];
    // Rotate so the shared vertices come first (cyclic rotations keep orientation).
    let rot = |first: usize| [first, (first + 1) % 3, (first + 2) % 3];
    // Most pairs the broad phase passes are separated by one of the two planes (apart from
    // the vertices they share): two or three orientations settle them.
    if shared.len() < 2 && (strictly_one_side(t, s, &si, &ti) || strictly_one_side(s, t, &ti, &si))
    {
        return Contact::Clean;
    }
    match shared.len() {
        0 => {
            let hit = (0..3)
                .any(|i| segment_meets_triangle(t[i], t[(i + 1) % 3], s[0], s[1], s[2]))
                || (0..3).any(|i| segment_meets_triangle(s[i], s[(i + 1) % 3], t[0], t[1], t[2]));
            if hit {
                Contact::Clash
            } else {
                Contact::Clean
            }
        }
        1 => {
            let (i, j) = shared[0];
            let [p, a, b] = rot(i).map(|k| t[k]);
            let [_, c, d] = rot(j).map(|k| s[k]);
            let clash = segment_meets_triangle(a, b, s[0], s[1], s[2])
                || segment_meets_triangle(c, d, t[0], t[1], t[2])
                || ray_enters_corner(p, a, c, d)
                || ray_enters_corner(p, b, c, d)
                || ray_enters_corner(p, c, a, b)
                || ray_enters_corner(p, d, a, b);
            if clash {
                Contact::Clash
            } else {
                Contact::Clean
            }
        }
        2 => {
            let (u, v) = (t[shared[0].0], t[shared[1].0]);
            let a = t[3 - shared[0].0 - shared[1].0];
            let b = s[3 - shared[0].1 - shared[1].1];
            if orient3(u, v, a, b) != Ordering::Equal {
                // Distinct planes meet in the line uv, so the triangles meet in edge uv only.
                let (x, y) = (ti[shared[0].0], ti[shared[1].0]);
                return Contact::SharedEdge([x.min(y), x.max(y)]);
            }
            let k = projection_axis(u, v, a);
            let pr = |x: DVec3| drop_axis(x, k);
            if orient2d(pr(u), pr(v), pr(a)) == orient2d(pr(u), pr(v), pr(b)) {
                Contact::Clash
            } else {
                let (x, y) = (ti[shared[0].0], ti[shared[1].0]);
                Contact::SharedEdge([x.min(y), x.max(y)])
            }
        }
        _ => Contact::Clash,
    }
}

/// Whether the corners of `other` that are not corners of `plane_of` (by index: `other_ids`
/// against `plane_ids`) all lie strictly on one side of the plane of `plane_of`.
fn strictly_one_side(
    plane_of: [DVec3; 3],
    other: [DVec3; 3],
    other_ids: &[u32; 3],
    plane_ids: &[u32; 3],
) -> bool {
    let [a, b, c] = plane_of;
    let mut side = None;
    for k in 0..3 {
        if plane_ids.contains(&other_ids[k]) {
            continue;
        }
        let o = orient3(a, b, c, other[k]);
        if o == Ordering::Equal || side.is_some_and(|s| s != o) {
            return false;
        }
        side = Some(o);
    }
    side.is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn v(x: f64, y: f64, z: f64) -> DVec3 {
        DVec3::new(x, y, z)
    }

    #[test]
    fn orient2d_sign() {
        assert_eq!(orient2d([0., 0.], [1., 0.], [0., 1.]), Ordering::Greater);
        assert_eq!(orient2d([0., 0.], [0., 1.], [1., 0.]), Ordering::Less);
        assert_eq!(orient2d([0., 0.], [1., 1.], [3., 3.]), Ordering::Equal);
        // one ulp off a line is still seen
        let y = f64::from_bits(0.5f64.to_bits() + 1);
        assert_eq!(orient2d([0., 0.5], [1., 0.5], [0.3, y]), Ordering::Greater);
    }

    #[test]
    fn segments_2d() {
        assert!(segments_meet_2d([0., 0.], [2., 2.], [0., 2.], [2., 0.]));
        assert!(!segments_meet_2d([0., 0.], [1., 1.], [0., 2.], [0.9, 1.2]));
        // touching: endpoint on the other segment
        assert!(segments_meet_2d([0., 0.], [2., 0.], [1., 0.], [1., 5.]));
        // collinear overlapping / disjoint
        assert!(segments_meet_2d([0., 0.], [2., 0.], [1., 0.], [3., 0.]));
        assert!(!segments_meet_2d([0., 0.], [1., 0.], [2., 0.], [3., 0.]));
        assert!(shared_end_overlap_2d([0., 0.], [1., 0.], [2., 0.]));
        assert!(!shared_end_overlap_2d([0., 0.], [1., 0.], [-2., 0.]));
    }

    #[test]
    fn triangle_contacts() {
        let t = [v(0., 0., 0.), v(1., 0., 0.), v(0., 1., 0.)];
        // crossing without shared vertices
        let s = [v(0.2, 0.2, -1.), v(0.2, 0.2, 1.), v(5., 5., 0.5)];
        assert_eq!(triangle_contact([0, 1, 2], t, [3, 4, 5], s), Contact::Clash);
        // far apart
        let s = [v(0., 0., 1.), v(1., 0., 1.), v(0., 1., 1.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [3, 4, 5], s), Contact::Clean);
        // shared edge, perpendicular: clean
        let s = [v(0., 0., 0.), v(1., 0., 0.), v(0., 0., 1.)];
        assert_eq!(
            triangle_contact([0, 1, 2], t, [0, 1, 5], s),
            Contact::SharedEdge([0, 1])
        );
        // shared edge, coplanar on the same side: overlap
        let s = [v(1., 0., 0.), v(0., 0., 0.), v(0.5, 0.2, 0.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [1, 0, 5], s), Contact::Clash);
        // shared edge, coplanar on opposite sides: clean
        let s = [v(1., 0., 0.), v(0., 0., 0.), v(0.5, -0.2, 0.)];
        assert_eq!(
            triangle_contact([0, 1, 2], t, [1, 0, 5], s),
            Contact::SharedEdge([0, 1])
        );
        // shared vertex, the other triangle pierces through: clash
        let s = [v(0., 0., 0.), v(0.5, 0.2, 1.), v(0.5, 0.2, -1.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [0, 4, 5], s), Contact::Clash);
        // shared vertex, coplanar, overlapping wedge: clash
        let s = [v(0., 0., 0.), v(1., 1., 0.), v(-1., 1., 0.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [0, 4, 5], s), Contact::Clash);
        // shared vertex, coplanar, wedges apart: clean
        let s = [v(0., 0., 0.), v(-1., 0., 0.), v(-1., -1., 0.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [0, 4, 5], s), Contact::Clean);
        // shared vertex only, other triangle rises away: clean
        let s = [v(0., 0., 0.), v(-1., 0., 1.), v(0., -1., 1.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [0, 4, 5], s), Contact::Clean);
        // shared vertex, an edge of s lies along an edge of t: clash
        let s = [v(0., 0., 0.), v(0.5, 0., 0.), v(0., 0., 1.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [0, 4, 5], s), Contact::Clash);
        // no shared id, but touching at a vertex: clash
        let s = [v(0.5, 0.5, 0.), v(1., 1., 1.), v(2., 1., 1.)];
        assert_eq!(triangle_contact([0, 1, 2], t, [3, 4, 5], s), Contact::Clash);
    }
}
