//! Features, oracle and distance on synthetic surfaces with known answers, and on the shared
//! models against brute force.

use super::distance::{hausdorff, samples};
use super::features::{FeatureParams, Features};
use super::oracle::{closest_on_triangle, Side, SurfaceOracle};
use super::InputSurface;
use crate::io::{read_plc, ReadOptions};
use crate::plc::validate;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

/// A closed prism over a regular `n`-gon of radius 1, z in [0, h]; side quads split in two,
/// caps fanned from their centres. Every triangle is its own facet.
fn prism(n: usize, h: f64) -> InputSurface {
    let mut v = Vec::new();
    for k in 0..n {
        let a = std::f64::consts::TAU * k as f64 / n as f64;
        v.push(DVec3::new(a.cos(), a.sin(), 0.0));
        v.push(DVec3::new(a.cos(), a.sin(), h));
    }
    let (bottom, top) = (v.len() as u32, v.len() as u32 + 1);
    v.push(DVec3::ZERO);
    v.push(DVec3::new(0.0, 0.0, h));
    let mut t = Vec::new();
    for k in 0..n as u32 {
        let j = (k + 1) % n as u32;
        let (b0, t0, b1, t1) = (2 * k, 2 * k + 1, 2 * j, 2 * j + 1);
        t.push([b0, b1, t1]);
        t.push([b0, t1, t0]);
        t.push([bottom, b1, b0]);
        t.push([top, t0, t1]);
    }
    InputSurface::from_triangles(v, t)
}

fn model_surface(rel: &str) -> InputSurface {
    let path = crate::io::tests::model(rel);
    let input = read_plc(
        &path,
        &ReadOptions {
            merge_coplanar: true,
        },
    )
    .unwrap();
    InputSurface::from_plc(&validate(&input).unwrap())
}

#[test]
fn cylinder_has_two_closed_rims_and_three_patches() {
    let s = prism(32, 2.0);
    let f = Features::detect(&s, &FeatureParams::default());
    assert_eq!(f.edges.len(), 64, "the two rims");
    assert!(f.corners.is_empty());
    assert_eq!(f.polylines.len(), 2);
    assert!(f
        .polylines
        .iter()
        .all(|l| l.closed && l.vertices.len() == 32));
    assert_eq!(f.n_patches, 3);
}

#[test]
fn hexagonal_prism_edges_are_all_features_at_forty_degrees() {
    let s = prism(6, 1.0);
    let f = Features::detect(&s, &FeatureParams::default());
    // 6 vertical edges (60 deg normal turn) and 12 rim edges; cap fan spokes are flat.
    assert_eq!(f.edges.len(), 18);
    assert_eq!(
        f.corners.len(),
        12,
        "every prism vertex has three feature edges"
    );
    assert_eq!(f.polylines.len(), 18);
    assert!(f
        .polylines
        .iter()
        .all(|l| !l.closed && l.vertices.len() == 2));
    assert_eq!(f.n_patches, 8);
    // Above 60 degrees the vertical edges are smooth and the rims become closed loops.
    let loose = FeatureParams {
        feature_angle: 61.0,
        ..Default::default()
    };
    let g = Features::detect(&s, &loose);
    assert_eq!(g.edges.len(), 12);
    // A rim turns by 60 degrees at each vertex, below 61: two closed loops, no corner.
    assert!(g.corners.is_empty());
    assert_eq!(g.polylines.len(), 2);
    assert!(g.polylines.iter().all(|l| l.closed));
    assert_eq!(g.n_patches, 3);
}

#[test]
fn corner_angles_of_a_cube_are_right_angles() {
    let s = model_surface("off/cube.off");
    let f = Features::detect(&s, &FeatureParams::default());
    assert_eq!(f.edges.len(), 12);
    assert_eq!(f.corners.len(), 8);
    assert_eq!(f.n_patches, 6);
    for c in f.corner_angles(&s) {
        assert!((c.angle - 90.0).abs() < 1e-9, "{c:?}");
    }
}

#[test]
fn markers_split_patches_only_when_asked() {
    let mut s = prism(32, 2.0);
    // Label one half of the side wall differently.
    for t in 0..s.triangles.len() {
        s.marker_of[t] = i32::from(t < 64);
    }
    let plain = Features::detect(&s, &FeatureParams::default());
    let labelled = Features::detect(
        &s,
        &FeatureParams {
            use_markers: true,
            ..Default::default()
        },
    );
    assert_eq!(plain.n_patches, 3);
    assert!(labelled.n_patches > 3);
    assert!(labelled.edges.len() > plain.edges.len());
}

#[test]
fn features_of_every_shared_surface_are_consistent() {
    for name in ["fandisk", "joint", "rotor", "elephant", "part"] {
        let s = model_surface(&format!("off/{name}.off"));
        let f = Features::detect(&s, &FeatureParams::default());
        // Every feature edge is on exactly one polyline, polylines end at corners.
        let mut covered = Vec::new();
        for l in &f.polylines {
            let n = l.vertices.len();
            let m = if l.closed { n } else { n - 1 };
            for i in 0..m {
                let (a, b) = (l.vertices[i], l.vertices[(i + 1) % n]);
                covered.push([a.min(b), a.max(b)]);
            }
            if !l.closed {
                for end in [l.vertices[0], l.vertices[n - 1]] {
                    assert!(f.corners.binary_search(&end).is_ok(), "{name}: open end");
                }
            }
        }
        covered.sort_unstable();
        assert_eq!(
            covered, f.edges,
            "{name}: polylines cover the feature edges once"
        );
        assert!(f.patch_of.iter().all(|&p| (p as usize) < f.n_patches));
        // Two runs agree (no hash order leaks out).
        assert_eq!(f, Features::detect(&s, &FeatureParams::default()));
    }
}

#[test]
fn closest_point_matches_brute_force() {
    // joint's long CAD strips are cut into many pieces: the tree over them must still find the
    // nearest triangle, near the surface as well as far from it.
    for name in ["off/fandisk.off", "off/joint.off"] {
        let s = model_surface(name);
        let o = SurfaceOracle::new(&s);
        let mut rng = ChaCha8Rng::seed_from_u64(7);
        let d = s.bbox_diagonal();
        for k in 0..400 {
            let p = if k % 2 == 0 {
                DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 * d - DVec3::splat(d / 2.0)
            } else {
                let [a, b, c] = s.corners(rng.gen_range(0..s.triangles.len()));
                let (mut u, mut v) = (rng.gen::<f64>(), rng.gen::<f64>());
                if u + v > 1.0 {
                    (u, v) = (1.0 - u, 1.0 - v);
                }
                let off = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - DVec3::splat(0.5);
                a + (b - a) * u + (c - a) * v + off * (0.01 * d)
            };
            let fast = o.closest(p).unwrap();
            let brute = (0..s.triangles.len())
                .map(|t| {
                    let [a, b, c] = s.corners(t);
                    (closest_on_triangle(p, a, b, c) - p).length()
                })
                .fold(f64::INFINITY, f64::min);
            assert!((fast.distance - brute).abs() <= 1e-12 * d, "{name} {p}");
            // Within a radius just above and just below the distance.
            assert_eq!(o.distance_beyond(p, fast.distance * 1.001), None, "{p}");
            assert_eq!(
                o.distance_beyond(p, fast.distance * 0.999),
                Some(fast.distance),
                "{name} {p}"
            );
        }
    }
}

/// A run of nearby queries with a hint (the last triangle found, then its neighbours) answers
/// exactly as the plain query.
#[test]
fn hinted_distance_queries_match_plain_ones() {
    let s = model_surface("off/fandisk.off");
    let o = SurfaceOracle::new(&s);
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    let d = s.bbox_diagonal();
    let mut hint = None;
    let mut p = s.vertices[0];
    for k in 0..3000 {
        if k % 100 == 0 {
            p = s.vertices[rng.gen_range(0..s.vertices.len())];
        }
        p += DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 4e-3 * d - DVec3::splat(2e-3 * d);
        let r = [1e-4, 1e-3, 1e-2][k % 3] * d;
        assert_eq!(
            o.distance_beyond_hinted(p, r, &mut hint),
            o.distance_beyond(p, r),
            "{p} {r}"
        );
    }
}

/// The plane shortcuts of the "within r of a triangle" test (far from the plane, or over the
/// triangle) answer as the closest point does, on fat, thin and needle triangles, away from
/// ties at the rounding level.
#[test]
fn triangle_within_test_matches_the_closest_point() {
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let unit =
        |rng: &mut ChaCha8Rng| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - DVec3::ONE;
    let mut triangles = vec![];
    for k in 0..300 {
        let (a, b) = (unit(&mut rng), unit(&mut rng));
        // Every third triangle thin: its apex close to the line through a and b.
        let thin = [1.0, 1e-3, 1e-9][k % 3];
        triangles.push([a, b, a + (b - a) * 0.3 + unit(&mut rng) * thin]);
    }
    let vertices: Vec<DVec3> = triangles.iter().flatten().copied().collect();
    let ids = (0..triangles.len() as u32)
        .map(|t| [3 * t, 3 * t + 1, 3 * t + 2])
        .collect();
    let s = InputSurface::from_triangles(vertices, ids);
    let o = SurfaceOracle::for_distances(&s);
    let (mut over, mut near) = (0, 0);
    for (t, &[a, b, c]) in triangles.iter().enumerate() {
        for _ in 0..40 {
            let p = (a + b + c) / 3.0 + unit(&mut rng) * 0.8;
            let d = (closest_on_triangle(p, a, b, c) - p).length();
            let r = d * [0.5, 0.99, 1.01, 2.0][rng.gen_range(0..4)];
            assert_eq!(o.within(t as u32, p, r), d <= r, "triangle {t}, {p}, r {r}");
            over += usize::from(d <= r);
            near += usize::from((d - r).abs() < 0.02 * d);
        }
    }
    assert!(over > 3000 && near > 3000, "{over} {near}");
}

/// Every triangle of `s` the segment [p, q] meets, by testing them all.
fn brute_crossings(s: &InputSurface, p: DVec3, q: DVec3) -> Vec<u32> {
    (0..s.triangles.len() as u32)
        .filter(|&t| {
            let [a, b, c] = s.corners(t as usize);
            crate::plc::exact::segment_meets_triangle(p, q, a, b, c)
        })
        .collect()
}

#[test]
fn segment_crossings_match_brute_force() {
    let s = model_surface("off/joint.off");
    let o = SurfaceOracle::new(&s);
    let mut rng = ChaCha8Rng::seed_from_u64(3);
    let d = s.bbox_diagonal();
    let lo = s
        .vertices
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |m, v| m.min(*v));
    for _ in 0..200 {
        let mut pick = || lo + DVec3::new(rng.gen(), rng.gen(), rng.gen()) * d * 0.6;
        let (p, q) = (pick(), pick());
        let mut fast: Vec<u32> = o.crossings(p, q).iter().map(|c| c.triangle).collect();
        fast.sort_unstable();
        assert_eq!(fast, brute_crossings(&s, p, q));
        for c in o.crossings(p, q) {
            let [a, b, cc] = s.corners(c.triangle as usize);
            let gap = (closest_on_triangle(c.point, a, b, cc) - c.point).length();
            assert!(gap <= 1e-9 * d, "crossing point off its triangle by {gap}");
        }
    }
}

/// Short segments near the surface (Voronoi edges are: the occupancy grid answers most of
/// them) and near joint's long thin triangles (cut into pieces in the tree): the same
/// triangles as brute force, and the crossing parity agrees with the inside test.
#[test]
fn short_segment_crossings_and_parity_match_brute_force() {
    for name in ["off/joint.off", "off/fandisk.off"] {
        let s = model_surface(name);
        let o = SurfaceOracle::new(&s);
        let mut rng = ChaCha8Rng::seed_from_u64(11);
        let d = s.bbox_diagonal();
        let mut clean = 0;
        for k in 0..3000 {
            let v = s.vertices[rng.gen_range(0..s.vertices.len())];
            let mut unit = || DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - DVec3::ONE;
            let scale = [1e-3, 1e-2, 5e-2][k % 3] * d;
            let p = v + unit() * scale;
            let q = p + unit() * scale;
            let (found, parity) = o.crossings_and_parity(p, q);
            let mut fast: Vec<u32> = found.iter().map(|c| c.triangle).collect();
            fast.sort_unstable();
            assert_eq!(fast, brute_crossings(&s, p, q), "{name}: {p} {q}");
            if let Some(odd) = parity {
                clean += 1;
                let sides = (o.side(p), o.side(q));
                assert_eq!(odd, sides.0 != sides.1, "{name}: {p} {q} {sides:?}");
            }
        }
        assert!(clean > 2900, "{name}: only {clean} clean parities");
    }
}

#[test]
fn inside_test_on_a_cylinder_and_a_model() {
    let s = prism(64, 2.0);
    let o = SurfaceOracle::new(&s);
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let inradius = (std::f64::consts::PI / 64.0).cos();
    for _ in 0..2000 {
        let p = DVec3::new(
            rng.gen_range(-1.5..1.5),
            rng.gen_range(-1.5..1.5),
            rng.gen_range(-0.5..2.5),
        );
        let r = p.truncate().length();
        let inside = r < inradius - 1e-6 && p.z > 1e-6 && p.z < 2.0 - 1e-6;
        let outside = r > 1.0 + 1e-6 || p.z < -1e-6 || p.z > 2.0 + 1e-6;
        match o.side(p) {
            Side::Inside => assert!(!outside, "{p} is outside"),
            Side::Outside => assert!(!inside, "{p} is inside"),
            Side::OnSurface => panic!("{p} is not on the surface"),
        }
    }
    // Vertices, edge midpoints and the axis through the cap centres (all degenerate for
    // axis-aligned rays) are classified.
    assert_eq!(o.side(s.vertices[0]), Side::OnSurface);
    assert_eq!(
        o.side((s.vertices[0] + s.vertices[1]) / 2.0),
        Side::OnSurface
    );
    assert_eq!(o.side(DVec3::new(0.0, 0.0, 1.0)), Side::Inside);
    assert_eq!(o.side(DVec3::new(0.0, 0.0, 3.0)), Side::Outside);

    // On a model: agree with the parity of a second, independent ray family (the closest
    // point's side is not usable: facet orientation is arbitrary), tested on the cube.
    let cube = model_surface("off/cube.off");
    let oc = SurfaceOracle::new(&cube);
    let lo = cube
        .vertices
        .iter()
        .fold(DVec3::splat(f64::INFINITY), |m, v| m.min(*v));
    let hi = cube
        .vertices
        .iter()
        .fold(DVec3::splat(f64::NEG_INFINITY), |m, v| m.max(*v));
    assert_eq!(oc.side((lo + hi) / 2.0), Side::Inside);
    assert_eq!(oc.side(hi + (hi - lo)), Side::Outside);
    assert_eq!(oc.side(lo), Side::OnSurface);
    // A face centre: on a facet diagonal shared by two triangles.
    assert_eq!(
        oc.side(DVec3::new(lo.x, (lo.y + hi.y) / 2.0, (lo.z + hi.z) / 2.0)),
        Side::OnSurface
    );
}

#[test]
fn hausdorff_of_known_shapes() {
    let a = prism(16, 1.0);
    assert!(hausdorff(&a, &a, 0.05).max() < 1e-12);
    // The same prism lifted by 0.25: every point moves 0.25, the nearest point of the other
    // is no farther than that.
    let mut b = a.clone();
    for v in &mut b.vertices {
        v.z += 0.25;
    }
    let h = hausdorff(&a, &b, 0.02);
    assert!((h.a_to_b - 0.25).abs() < 1e-12, "{h:?}");
    assert!((h.b_to_a - 0.25).abs() < 1e-12, "{h:?}");
    // Sampling is dense enough: every triangle's centroid is within spacing of a sample.
    let pts = samples(&a, 0.1);
    for t in 0..a.triangles.len() {
        let [p, q, r] = a.corners(t);
        let c = (p + q + r) / 3.0;
        let near = pts
            .iter()
            .map(|s| (*s - c).length())
            .fold(f64::INFINITY, f64::min);
        assert!(near <= 0.1);
    }
}

#[test]
fn samples_cover_thin_and_fat_triangles() {
    // Every point of every triangle lies within spacing / sqrt(3) of a sample, whichever
    // layout (grid or rows) a triangle gets; thin CAD strips get far fewer samples than a
    // grid over their longest edge would take.
    let mut rng = ChaCha8Rng::seed_from_u64(11);
    let spacing = 0.05;
    for case in 0..40 {
        let a = DVec3::ZERO;
        let b = DVec3::new(1.0 + rng.gen::<f64>(), 0.0, 0.0);
        let height = if case % 2 == 0 { 0.02 } else { 1.0 } * rng.gen::<f64>().max(0.05);
        let c = DVec3::new(rng.gen_range(-0.5..2.5), height, rng.gen_range(-0.1..0.1));
        let s = InputSurface::from_triangles(vec![a, b, c], vec![[0, 1, 2]]);
        let pts = samples(&s, spacing);
        assert_covered(
            &pts,
            [a, b, c],
            spacing,
            400,
            &mut rng,
            &format!("case {case}"),
        );
        if case % 2 == 0 {
            let longest = (b - a).length().max((c - b).length()).max((c - a).length());
            let k = (longest / spacing).ceil();
            assert!(
                (pts.len() as f64) < (k + 1.0) * (k + 2.0) / 2.0 / 1.5,
                "case {case}"
            );
        }
    }
}

#[test]
fn samples_of_a_closed_surface_cover_it_each_once() {
    // Neighbouring triangles share their edges' grid points: each is taken once, and every
    // point of every triangle still lies within spacing / sqrt(3) of a sample.
    let s = prism(16, 1.0);
    let spacing = 0.07;
    let pts = samples(&s, spacing);
    for (i, p) in pts.iter().enumerate() {
        let twice = pts[i + 1..].iter().any(|q| (*q - *p).length() < 1e-12);
        assert!(!twice, "sample {i} taken twice");
    }
    let mut rng = ChaCha8Rng::seed_from_u64(5);
    for t in 0..s.triangles.len() {
        let corners = s.corners(t);
        assert_covered(
            &pts,
            corners,
            spacing,
            50,
            &mut rng,
            &format!("triangle {t}"),
        );
    }
}

/// `n` random points of triangle `abc` each have a sample within spacing / sqrt(3) (the
/// sampling's guarantee).
fn assert_covered(
    pts: &[DVec3],
    [a, b, c]: [DVec3; 3],
    spacing: f64,
    n: usize,
    rng: &mut ChaCha8Rng,
    what: &str,
) {
    for _ in 0..n {
        let (mut u, mut v) = (rng.gen::<f64>(), rng.gen::<f64>());
        if u + v > 1.0 {
            (u, v) = (1.0 - u, 1.0 - v);
        }
        let x = a + (b - a) * u + (c - a) * v;
        let near = pts
            .iter()
            .map(|p| (*p - x).length())
            .fold(f64::INFINITY, f64::min);
        assert!(
            near <= spacing / 3f64.sqrt() * (1.0 + 1e-9),
            "{what}: {near}"
        );
    }
}

/// Two prisms, one inside the other, read through a PLC: three regions (outside 0, the shell
/// 1, the inner prism 2). A point's region by rays, and carried along random segments by
/// their crossings, agree with where the point is.
#[test]
fn regions_of_nested_prisms() {
    let outer = prism(12, 2.0);
    let mut inner = prism(12, 1.0);
    for p in &mut inner.vertices {
        *p = DVec3::new(0.5 * p.x, 0.5 * p.y, p.z + 0.5);
    }
    let mut input = crate::plc::PlcInput {
        vertices: outer.vertices.clone(),
        ..Default::default()
    };
    let shift = outer.vertices.len() as u32;
    input.vertices.extend(&inner.vertices);
    for (k, t) in outer
        .triangles
        .iter()
        .chain(
            inner
                .triangles
                .iter()
                .map(|t| t.map(|v| v + shift))
                .collect::<Vec<_>>()
                .iter(),
        )
        .enumerate()
    {
        input.facets.push(crate::plc::Facet {
            polygons: vec![t.to_vec()],
            marker: k as i32 + 1,
            ..Default::default()
        });
    }
    let plc = validate(&input).unwrap();
    assert_eq!(plc.region_attributes(), vec![1, 2], "no seeds: numbered");
    let s = InputSurface::from_plc(&plc);
    assert_eq!(s.n_regions(), 2);
    let o = SurfaceOracle::new(&s);
    let truth = |p: DVec3| {
        let r = DVec3::new(p.x, p.y, 0.0).length();
        // Inside the 12-gon of circumradius c (tested against its inradius and circumradius,
        // points in between skipped).
        let within = |c: f64, lo: f64, hi: f64| {
            let inr = c * (std::f64::consts::PI / 12.0).cos();
            if r < inr && p.z > lo && p.z < hi {
                Some(true)
            } else if r > c || p.z < lo || p.z > hi {
                Some(false)
            } else {
                None
            }
        };
        match (within(1.0, 0.0, 2.0)?, within(0.5, 0.5, 1.5)?) {
            (false, _) => Some(0),
            (true, false) => Some(1),
            (true, true) => Some(2),
        }
    };
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    let mut point = || {
        DVec3::new(
            rng.gen_range(-1.5..1.5),
            rng.gen_range(-1.5..1.5),
            rng.gen_range(-0.5..2.5),
        )
    };
    let mut checked = 0;
    for _ in 0..2000 {
        let (p, q) = (point(), point());
        let (Some(rp), Some(rq)) = (truth(p), truth(q)) else {
            continue;
        };
        assert_eq!(o.region(p), rp, "region of {p}");
        if let Some(r) = o.region_across(rp, &o.crossings(p, q), true) {
            assert_eq!(r, rq, "carried from {p} to {q}");
            checked += 1;
        }
    }
    assert!(checked > 1000, "{checked} segments carried cleanly");
}
