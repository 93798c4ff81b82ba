//! Tests of the facet triangulation (construction, insertion, splits, refusals, validation).

use super::*;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use std::collections::HashSet;

/// `f(s, t)` for flat (s, t) pairs.
fn map2(c: &[f64], f: impl Fn(f64, f64) -> DVec3) -> Vec<DVec3> {
    c.chunks(2).map(|c| f(c[0], c[1])).collect()
}
fn xy(c: &[f64]) -> Vec<DVec3> {
    map2(c, p)
}
fn p(x: f64, y: f64) -> DVec3 {
    DVec3::new(x, y, 0.0)
}
const SQUARE: [f64; 8] = [0., 0., 1., 0., 1., 1., 0., 1.];
const SQUARE_HOLE: [f64; 16] = [
    0., 0., 4., 0., 4., 4., 0., 4., 1., 1., 3., 1., 3., 3., 1., 3.,
];
/// Points of the plane through `o` spanned by `u`, `v` (exact for small integer s, t).
fn plane(o: DVec3, u: DVec3, v: DVec3) -> impl Fn(f64, f64) -> DVec3 {
    move |s, t| o + u * s + v * t
}

/// Keeps a set of subfacets in sync through the Change lists and checks it.
struct Tracker(HashSet<[u32; 3]>);
impl Tracker {
    fn new(m: &FacetMesh) -> Self {
        Tracker(m.triangles().into_iter().collect())
    }
    fn apply(&mut self, ch: &Change, m: &FacetMesh) {
        assert!(
            ch.removed.iter().all(|r| self.0.remove(r)),
            "removed a non-triangle"
        );
        assert!(
            ch.added.iter().all(|a| self.0.insert(*a)),
            "added a triangle twice"
        );
        assert_eq!(self.0, m.triangles().into_iter().collect::<HashSet<_>>());
        assert_eq!(self.0.len(), m.num_triangles());
    }
}

fn check_ccw(m: &FacetMesh) {
    for t in m.triangles() {
        let [a, b, c] = t.map(|i| m.point(i).unwrap());
        assert!((b - a).cross(c - a).dot(m.normal()) > 0.0, "{t:?} not ccw");
    }
}

/// `n` random operations, each checked against a Tracker: with probability `split` a
/// subsegment split at a float point near its middle (not exactly on the line), else an
/// insertion of `f(s, t)`, s, t in [0, 1), or (one in four) of the float circumcentre of a
/// random subfacet. A refusal must change nothing; a point on a subsegment splits it.
/// Validates every 100 steps and at the end.
fn drive(m: &mut FacetMesh, n: usize, split: f64, seed: u64, f: impl Fn(f64, f64) -> DVec3) {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let (mut tr, mut id) = (Tracker::new(m), 1_000_000 + m.num_vertices() as u32);
    for step in 0..n {
        let before = m.triangles();
        let ch = if rng.gen_bool(split) {
            let segs = m.constrained_edges();
            let [a, b] = segs[rng.gen_range(0..segs.len())];
            let (pa, pb) = (m.point(a).unwrap(), m.point(b).unwrap());
            let ch = m.split_edge(a, b, id, pa.lerp(pb, rng.gen_range(0.3..0.7)));
            assert!(m.is_constrained(a, id) && m.is_constrained(id, b));
            assert!(!m.is_constrained(a, b));
            ch.unwrap()
        } else {
            let tris = m.triangles();
            let [a, b, c] = tris[rng.gen_range(0..tris.len())].map(|i| m.point(i).unwrap());
            let (ab, ac) = (b - a, c - a);
            let (n, l2) = (ab.cross(ac), [ab.length_squared(), ac.length_squared()]);
            let cc = a + (n.cross(ab) * l2[1] + ac.cross(n) * l2[0]) / n.length_squared() / 2.;
            let q = [f(rng.gen(), rng.gen()), cc][rng.gen_bool(0.25) as usize];
            match m.insert(id, q) {
                Ok(ch) => ch,
                Err(InsertError::OnConstrainedEdge(a, b)) => m.split_edge(a, b, id, q).unwrap(),
                Err(_) => {
                    assert_eq!(before, m.triangles());
                    continue;
                }
            }
        };
        tr.apply(&ch, m);
        id += 1;
        if step % 100 == 0 {
            m.validate().unwrap_or_else(|e| panic!("step {step}: {e}"));
        }
    }
    m.validate().unwrap();
    check_ccw(m);
}

#[test]
fn unit_square_windings_flips_opposite() {
    let pts = xy(&SQUARE);
    let r = FacetMesh::new(&pts, &[vec![3, 2, 1, 0, 3]], &[], &[]).unwrap();
    r.validate().unwrap();
    assert_eq!(r.normal(), -DVec3::Z);
    check_ccw(&r);
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
    m.validate().unwrap();
    assert_eq!((m.num_triangles(), m.constrained_edges().len()), (2, 4));
    assert_eq!((m.normal(), m.area()), (DVec3::Z, 1.0));
    check_ccw(&m);
    let (a, b) = [(1, 3), (0, 2)][m.opposite(0, 2).is_some() as usize];
    let [l, r] = m.opposite(a, b).unwrap();
    assert!(l.is_some() && r.is_some() && l != r);
    let c = if a == 0 { 2 } else { 3 };
    assert_eq!(m.opposite(0, 1).unwrap(), [Some(c), None]);
    assert_eq!(m.opposite(1, 0).unwrap()[0], None);
    let mut tr = Tracker::new(&m);
    let before = tr.0.clone();
    tr.apply(&m.flip_change(a, b).unwrap(), &m);
    m.validate().unwrap(); // cocircular: both diagonals are Delaunay
    assert!(m.opposite(a, b).is_none() && m.flip(l.unwrap(), r.unwrap()));
    assert_eq!(Tracker::new(&m).0, before);
    assert!(!m.flip(0, 1) && !m.flip(0, 9));
    // a non-convex quad does not flip
    let pts = xy(&[0., 0., 4., 0., 1., 1., 0., 4.]);
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
    assert!(m.opposite(0, 2).is_some() && !m.flip(0, 2));
}

#[test]
fn l_shape_and_holes() {
    let pts = xy(&[0., 0., 2., 0., 2., 1., 1., 1., 1., 2., 0., 2.]);
    let mut m = FacetMesh::new(&pts, &[(0..6).collect()], &[], &[]).unwrap();
    m.validate().unwrap();
    assert_eq!((m.num_triangles(), m.area()), (4, 3.0));
    assert_eq!(m.locate(p(1.5, 1.5)), None);
    assert!(m.locate(p(0.5, 1.5)).is_some() && m.locate(p(1., 1.)).is_some());
    assert_eq!(m.insert(10, p(1.5, 1.5)), Err(InsertError::Outside));
    drive(&mut m, 400, 0.2, 7, |x, y| p(2.0 * x, 2.0 * y));
    assert!(m.num_vertices() > 200 && m.num_vertices() < 400);
    // square with a square hole given as a polygon of either winding
    let pts = xy(&SQUARE_HOLE);
    for hole in [vec![4, 5, 6, 7], vec![7, 6, 5, 4]] {
        let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[hole], &[]).unwrap();
        m.validate().unwrap();
        assert_eq!((m.num_triangles(), m.constrained_edges().len()), (8, 8));
        assert_eq!(m.locate(p(2., 2.)), None);
        drive(&mut m, 300, 0.2, 3, |x, y| p(4. * x, 4. * y));
        assert!((m.area() - 12.0).abs() < 1e-12);
    }
    // TetGen style: the inner polygon is an outer one, the hole is marked by a point
    let outer = [vec![0, 1, 2, 3], vec![4, 5, 6, 7]];
    let mut m = FacetMesh::new(&pts, &outer, &[], &[p(2., 2.)]).unwrap();
    m.validate().unwrap();
    assert_eq!((m.num_triangles(), m.area()), (8, 12.0));
    drive(&mut m, 300, 0.2, 4, |x, y| p(4. * x, 4. * y));
    assert!((m.area() - 12.0).abs() < 1e-12);
    // without the hole point the inner polygon is only imprinted
    let m = FacetMesh::new(&pts, &outer, &[], &[]).unwrap();
    assert_eq!(m.num_triangles(), 10);
    assert!(m.locate(p(2., 2.)).is_some());
    // an island inside a hole stays
    let mut pts = pts.clone();
    pts.extend(xy(&[1.5, 1.5, 2.5, 1.5, 2.5, 2.5, 1.5, 2.5]));
    let outer = [vec![0, 1, 2, 3], vec![8, 9, 10, 11]];
    let m = FacetMesh::new(&pts, &outer, &[vec![4, 5, 6, 7]], &[]).unwrap();
    m.validate().unwrap();
    assert_eq!(m.area(), 13.0);
    assert!(m.locate(p(2., 2.)).is_some() && m.locate(p(1.2, 2.)).is_none());
}

#[test]
fn tilted_planes() {
    // x + 2y + 3z = 6 (dominant axis z) and 3x - y - 2z = -7 (dominant x, reversed winding)
    let cases = [
        ([6., 0., 0.], [-2., 1., 0.], [-3., 0., 1.], false),
        ([1., 2., 3.], [1., 3., 0.], [0., -2., 1.], true),
    ];
    for (o, u, v, rev) in cases {
        let (u, v) = (DVec3::from(u), DVec3::from(v));
        let f = plane(o.into(), u, v);
        // an L with a collinear vertex at (4, 0), and a square hole
        let (c, h) = (
            [0., 0., 4., 0., 8., 0., 8., 4., 4., 4., 4., 8., 0., 8.],
            [1., 1., 3., 1.],
        );
        let pts = [map2(&c, &f), map2(&h, &f), map2(&[3., 3., 1., 3.], &f)].concat();
        let mut outer: Vec<u32> = (0..7).collect();
        if rev {
            outer.reverse();
        }
        let mut m = FacetMesh::new(&pts, &[outer], &[vec![7, 8, 9, 10]], &[]).unwrap();
        m.validate().unwrap();
        let n = u.cross(v);
        assert!(m.normal().dot(n) * if rev { -1.0 } else { 1.0 } > 0.0);
        assert!(m.is_constrained(0, 1) && m.is_constrained(1, 2) && !m.is_constrained(0, 2));
        let (mut tr, exact) = (Tracker::new(&m), [5., 1., 6., 2., 1., 6., 2., 5.]);
        for (k, &q) in map2(&exact, &f).iter().enumerate() {
            tr.apply(&m.insert(100 + k as u32, q).unwrap(), &m); // exactly on the plane
        }
        drive(&mut m, 500, 0.2, 11, |s, t| f(8.0 * s, 8.0 * t)); // a rounding error off it
        assert!((m.area() - 44.0 * n.length()).abs() < 1e-9 * m.area());
    }
}

#[test]
fn random_insertions_into_square() {
    let mut m = FacetMesh::new(&xy(&SQUARE), &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
    drive(&mut m, 500, 0.0, 1, p);
    let (nv, nb) = (m.num_vertices(), m.constrained_edges().len());
    assert!(nv > 450 && m.num_triangles() == 2 * nv - nb - 2);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for _ in 0..200 {
        let q = p(rng.gen(), rng.gen());
        let [a, b, c] = m.locate(q).unwrap().map(|i| m.proj(m.point(i).unwrap()));
        let q = m.proj(q);
        let ok = |(x, y): (DVec2, DVec2)| orient2d(x, y, q) >= 0.0;
        assert!([(a, b), (b, c), (c, a)].into_iter().all(ok));
    }
    // many more: stays fast (walk + flips, not O(n) per insertion)
    let t0 = std::time::Instant::now();
    for id in 10..20_010 {
        m.insert(id, p(rng.gen(), rng.gen())).unwrap();
    }
    assert!(t0.elapsed().as_secs_f64() < 10.0, "{:?}", t0.elapsed());
    m.validate().unwrap();
}

#[test]
fn grid_20x20_cocircular() {
    let pts = xy(&SQUARE.map(|c| 19. * c));
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[], &[]).unwrap();
    let mut tr = Tracker::new(&m);
    let mut grid: Vec<u32> = (10..410).collect();
    let mut rng = ChaCha8Rng::seed_from_u64(2);
    for i in (1..grid.len()).rev() {
        grid.swap(i, rng.gen_range(0..=i));
    }
    for id in grid {
        let q = p(((id - 10) % 20) as f64, ((id - 10) / 20) as f64);
        let ch = match m.insert(id, q) {
            Ok(ch) => ch,
            Err(InsertError::OnConstrainedEdge(a, b)) => m.split_edge(a, b, id, q).unwrap(),
            Err(InsertError::OnVertex(_)) => continue, // a corner
            Err(e) => panic!("{e}"),
        };
        tr.apply(&ch, &m);
    }
    m.validate().unwrap();
    assert_eq!((m.num_vertices(), m.num_triangles()), (400, 2 * 19 * 19));
    assert_eq!((m.constrained_edges().len(), m.area()), (4 * 19, 361.0));
}

#[test]
fn split_boundary_repeatedly_off_the_line() {
    let [o, u, v] = [[0.1, 0.2, 0.3], [0.7, 0.1, -0.3], [-0.2, 0.9, 0.4]].map(DVec3::from);
    let f = plane(o, u, v);
    let pts = map2(&[0., 0., 3., 0., 3., 2., 1., 3., 0., 2.], &f);
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3, 4]], &[], &[]).unwrap();
    m.validate().unwrap();
    // split points are not exactly on the segments
    let off = (1..50).filter(|&k| {
        let q = pts[0].lerp(pts[1], k as f64 / 50.0);
        orient2d(m.proj(pts[0]), m.proj(pts[1]), m.proj(q)) != 0.0
    });
    assert!(off.count() > 10);
    let area = m.area();
    drive(&mut m, 500, 0.8, 9, |s, t| f(3. * s, 3. * t));
    assert!(m.constrained_edges().len() > 300);
    assert!((m.area() - area).abs() < 1e-9 * area);
}

#[test]
fn refusals_change_nothing() {
    let pts = xy(&SQUARE_HOLE);
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3]], &[vec![4, 5, 6, 7]], &[]).unwrap();
    let before = m.triangles();
    for (q, e) in [
        (p(5., 1.), InsertError::Outside),
        (p(500., -1e6), InsertError::Outside),
        (p(2., 2.), InsertError::Outside),
        (p(2., 0.), InsertError::OnConstrainedEdge(0, 1)),
        (p(2., 1.), InsertError::OnConstrainedEdge(4, 5)),
        (p(4., 4.), InsertError::OnVertex(2)),
        (p(f64::NAN, 0.5), InsertError::NotFinite),
    ] {
        assert_eq!(m.insert(50, q), Err(e));
    }
    assert_eq!(m.insert(3, p(0.5, 0.5)), Err(InsertError::IdInUse(3)));
    for (a, b, id, q, e) in [
        (0, 2, 50, p(2., 2.), SplitError::NotAnEdge(0, 2)),
        (0, 1, 50, p(2., 3.5), SplitError::WouldInvert),
        (0, 1, 1, p(2., 0.), SplitError::IdInUse(1)),
    ] {
        assert_eq!(m.split_edge(a, b, id, q), Err(e));
    }
    assert_eq!((m.triangles(), m.num_vertices()), (before, 8));
    m.validate().unwrap();
    assert_eq!((m.locate(p(2., 2.)), m.locate(p(9., 9.))), (None, None));
    assert!(m.locate(p(2., 0.)).is_some() && m.locate(p(2., 1.)).is_some());
}

#[test]
fn points_and_segments_inside_polygons() {
    let pts = [
        0., 0., 1., 0., 1., 1., 0., 1., 0.5, 0., 0.25, 0.5, 0.75, 0.5, 0.5, 0.25, 0.5, 0.75,
    ];
    let mut pts = xy(&pts);
    pts.push(p(0.25, 0.5));
    // a lone point on a boundary edge splits it
    let m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3], vec![4]], &[], &[]).unwrap();
    m.validate().unwrap();
    assert!(m.is_constrained(0, 4) && m.is_constrained(4, 1) && !m.is_constrained(0, 1));
    // a dangling segment is an inner subsegment
    let mut m = FacetMesh::new(&pts, &[vec![0, 1, 2, 3], vec![5, 6]], &[], &[]).unwrap();
    m.validate().unwrap();
    assert!(m.is_constrained(5, 6) && m.opposite(5, 6).unwrap().iter().all(|x| x.is_some()));
    let e = m.insert(20, p(0.5, 0.5));
    assert_eq!(e, Err(InsertError::OnConstrainedEdge(5, 6)));
    m.split_edge(5, 6, 20, p(0.5, 0.5)).unwrap();
    m.validate().unwrap();
    // errors: crossing segments, coincident vertices, no area, bad id
    let e = |outer: &[Vec<u32>]| FacetMesh::new(&pts, outer, &[], &[]).unwrap_err();
    assert!(e(&[vec![0, 1, 2, 3], vec![5, 6], vec![7, 8]]).contains("cross"));
    assert!(e(&[vec![0, 1, 2, 3], vec![5, 9]]).contains("coincide"));
    assert!(e(&[vec![0, 1, 4]]).contains("area"));
    assert!(e(&[vec![0, 1, 99]]).contains("range"));
}

/// Random star-shaped polygons (some with integer, collinear vertices) with a square hole,
/// on randomly rotated planes (coordinates rounded: not exactly coplanar).
#[test]
fn random_polygons_on_rotated_planes() {
    for seed in 0..12u64 {
        let mut rng = ChaCha8Rng::seed_from_u64(seed);
        let axis = DVec3::new(rng.gen(), rng.gen(), rng.gen::<f64>() + 0.1).normalize();
        let q = glam::DQuat::from_axis_angle(axis, rng.gen_range(0.0..6.0));
        let f = move |s: f64, t: f64| q * DVec3::new(s, t, 0.0) + DVec3::new(0.1, 2.3, -0.7);
        let n = rng.gen_range(3..60);
        let round = |x: f64| if seed % 2 == 0 { x.round() } else { x };
        let mut st: Vec<(f64, f64)> = (0..n)
            .map(|i| {
                let (a, r) = (
                    i as f64 / n as f64 * std::f64::consts::TAU,
                    rng.gen_range(3.0..5.0),
                );
                (round(a.cos() * r), round(a.sin() * r))
            })
            .collect();
        st.dedup();
        while st.len() > 1 && st.first() == st.last() {
            st.pop();
        }
        let k = st.len() as u32;
        st.extend([(-1., -1.), (1., -1.), (1., 1.), (-1., 1.)]);
        let pts: Vec<DVec3> = st.iter().map(|&(s, t)| f(s, t)).collect();
        let hole = vec![k, k + 1, k + 2, k + 3];
        let mut m = FacetMesh::new(&pts, &[(0..k).collect()], &[hole], &[]).unwrap();
        m.validate().unwrap();
        let g = |s: f64, t: f64| f(10. * s - 5., 10. * t - 5.);
        drive(&mut m, 800, 0.25, seed, g);
    }
}
