//! Kernel tests: validity on uniform, clustered, grid, sphere and coplanar-start inputs, counts
//! against an independent brute-force Delaunay, dry runs, probes, duplicates and errors.

use super::*;
use crate::geom::insphere;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;

// The point sets and `sorted_tets` serve the parallel kernel's tests too (parallel_tests.rs).

pub(super) fn uniform(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
        .collect()
}

pub(super) fn grid(k: usize) -> Vec<DVec3> {
    let mut pts = vec![];
    for x in 0..k {
        for y in 0..k {
            for z in 0..k {
                pts.push(DVec3::new(x as f64, y as f64, z as f64));
            }
        }
    }
    pts
}

pub(super) fn sphere(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    (0..n)
        .map(|_| loop {
            let p = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - 1.0;
            if p.length_squared() > 0.01 && p.length_squared() <= 1.0 {
                break p.normalize();
            }
        })
        .collect()
}

pub(super) fn clustered(n: usize, seed: u64) -> Vec<DVec3> {
    let mut rng = ChaCha8Rng::seed_from_u64(seed);
    let centres: Vec<DVec3> = (0..5)
        .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
        .collect();
    (0..n)
        .map(|i| {
            let c = centres[i % centres.len()];
            let d = DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.5;
            c + d * 1e-3 * (1.0 + (i % 7) as f64)
        })
        .collect()
}

/// Independent reference: the Delaunay tets of points in general position are exactly the
/// quadruples whose circumsphere holds no other point (O(n^5); small n only).
fn brute_force_delaunay_count(pts: &[DVec3]) -> usize {
    let n = pts.len();
    let mut count = 0;
    for a in 0..n {
        for b in a + 1..n {
            for c in b + 1..n {
                for d in c + 1..n {
                    let (mut p, q, r, s) = (pts[a], pts[b], pts[c], pts[d]);
                    let mut q = q;
                    let o = orient3d(p, q, r, s);
                    if o == 0.0 {
                        continue;
                    }
                    if o < 0.0 {
                        std::mem::swap(&mut p, &mut q);
                    }
                    let empty = (0..n)
                        .filter(|&e| e != a && e != b && e != c && e != d)
                        .all(|e| insphere(p, q, r, s, pts[e]) < 0.0);
                    if empty {
                        count += 1;
                    }
                }
            }
        }
    }
    count
}

#[test]
fn finite_tet_count_matches_brute_force() {
    for seed in 0..6 {
        let pts = uniform(18 + seed as usize * 3, seed);
        let (dt, stats) = Delaunay::from_points(&pts).unwrap();
        dt.validate().unwrap();
        assert_eq!(stats.inserted, pts.len());
        assert_eq!(
            dt.num_finite_tets(),
            brute_force_delaunay_count(&pts),
            "seed {seed}"
        );
    }
}

#[test]
fn uniform_bulk_is_valid() {
    let pts = uniform(20_000, 1);
    let (dt, stats) = Delaunay::from_points(&pts).unwrap();
    assert_eq!(stats.inserted, 20_000);
    assert_eq!(dt.num_vertices(), 20_000);
    dt.validate().unwrap();
    // Euler-style sanity: about 6.5 tets per point for uniform points in a cube.
    let ratio = dt.num_finite_tets() as f64 / 20_000.0;
    assert!((6.0..7.0).contains(&ratio), "tets per point {ratio}");
}

#[test]
fn incremental_insertion_is_valid() {
    let pts = uniform(500, 2);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    for (k, p) in uniform(2000, 3).into_iter().enumerate() {
        // Spread the new points beyond the hull too.
        let p = p * 1.5 - 0.25;
        let r = dt.insert(p, None).unwrap();
        assert_eq!(r, Inserted::New((500 + k) as u32));
        if k % 500 == 0 {
            dt.validate().unwrap();
        }
    }
    dt.validate().unwrap();
    assert_eq!(dt.num_vertices(), 2500);
}

#[test]
fn grid_is_valid() {
    // Every tet of a grid is cospherical with its neighbours: only the perturbation decides.
    let pts = grid(12);
    let (dt, stats) = Delaunay::from_points(&pts).unwrap();
    dt.validate().unwrap();
    assert_eq!(stats.inserted, pts.len());
    // Every tet is inside the cube [0, 11]^3, whose volume is 11^3.
    let vol: f64 = dt
        .finite_tets()
        .map(|t| {
            let q = t.map(|v| dt.point(v));
            orient3d(q[0], q[1], q[2], q[3]) / 6.0
        })
        .sum();
    assert!((vol - 1331.0).abs() < 1e-9, "volume {vol}");
}

/// Ties broken by coordinates: a grid (cospherical everywhere) gives the same tets whatever
/// the order of its points, and a subset's triangulation keeps every tet of the whole whose
/// vertices it holds (what a partition's parts rely on).
#[test]
fn ties_by_coordinates_do_not_depend_on_the_order() {
    let pts = grid(5);
    // Inserted one at a time (the later, the higher a point's index rank), after a first tet.
    let tets_of = |points: &[DVec3]| {
        let first = [0, 1, 2, 3].map(|k| points[k]);
        let (mut dt, _) = Delaunay::from_points_with(&first, true).unwrap();
        for &p in &points[4..] {
            dt.insert(p, None).unwrap();
        }
        dt.validate().unwrap();
        let mut tets: Vec<[[u64; 3]; 4]> = dt
            .finite_tets()
            .map(|t| {
                let mut k = t.map(|v| dt.point(v).to_array().map(f64::to_bits));
                k.sort_unstable();
                k
            })
            .collect();
        tets.sort_unstable();
        tets
    };
    // A first tet that is not flat, then the grid in random orders.
    let lead = |points: &mut Vec<DVec3>| {
        for q in [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
        ]
        .into_iter()
        .rev()
        {
            let i = points.iter().position(|&p| p == q).unwrap();
            let p = points.remove(i);
            points.insert(0, p);
        }
    };
    let mut ordered = pts.clone();
    lead(&mut ordered);
    let whole = tets_of(&ordered);
    let mut rng = ChaCha8Rng::seed_from_u64(7);
    for _ in 0..3 {
        let mut shuffled = pts.clone();
        for i in (1..shuffled.len()).rev() {
            shuffled.swap(i, rng.gen_range(0..=i));
        }
        lead(&mut shuffled);
        assert_eq!(tets_of(&shuffled), whole);
    }
    // The points with x <= 2: every tet of the whole among them is one of theirs.
    let mut half: Vec<DVec3> = pts.iter().copied().filter(|p| p.x <= 2.0).collect();
    lead(&mut half);
    let sub: std::collections::HashSet<_> = tets_of(&half).into_iter().collect();
    let inside = |k: &[[u64; 3]; 4]| k.iter().all(|c| f64::from_bits(c[0]) <= 2.0);
    for t in whole.iter().filter(|t| inside(t)) {
        assert!(sub.contains(t), "{t:?}");
    }
}

#[test]
fn grid_incremental_in_input_order_is_valid() {
    // Insert grid points one by one in scanline order: many hull-coplanar insertions.
    let pts = grid(6);
    let mut seedpts = vec![pts[0], pts[1], pts[6], pts[36]];
    let (mut dt, _) = Delaunay::from_points(&seedpts).unwrap();
    for (i, &p) in pts.iter().enumerate() {
        if [0, 1, 6, 36].contains(&i) {
            continue;
        }
        dt.insert(p, None).unwrap();
        seedpts.push(p);
    }
    dt.validate().unwrap();
    assert_eq!(dt.num_vertices(), 216);
}

#[test]
fn sphere_points_are_valid() {
    let pts = sphere(5000, 4);
    let (dt, _) = Delaunay::from_points(&pts).unwrap();
    dt.validate().unwrap();
}

#[test]
fn clustered_points_are_valid() {
    let pts = clustered(20_000, 5);
    let (dt, _) = Delaunay::from_points(&pts).unwrap();
    dt.validate().unwrap();
}

#[test]
fn coplanar_start_is_valid() {
    // Many coplanar (and collinear) points come first in the input and in any order.
    let mut pts: Vec<DVec3> = (0..200)
        .map(|i| DVec3::new((i % 20) as f64, (i / 20) as f64, 0.0))
        .collect();
    pts.extend((0..50).map(|i| DVec3::new(i as f64 * 0.5, 0.0, 0.0)));
    pts.push(DVec3::new(3.3, 4.4, 2.0));
    pts.push(DVec3::new(7.1, 1.4, -1.5));
    let (dt, stats) = Delaunay::from_points(&pts).unwrap();
    dt.validate().unwrap();
    // (0.5 * even i) duplicates the grid's integer points on the x axis: 20 duplicates.
    assert_eq!(stats.duplicates, 20);
    assert_eq!(dt.num_vertices(), pts.len() - 20);
}

#[test]
fn degenerate_inputs_are_errors() {
    let flat: Vec<DVec3> = (0..10)
        .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    assert!(matches!(
        Delaunay::from_points(&flat),
        Err(DelaunayError::Degenerate { .. })
    ));
    let line: Vec<DVec3> = (0..10).map(|i| DVec3::splat(i as f64)).collect();
    assert!(Delaunay::from_points(&line).is_err());
    assert!(Delaunay::from_points(&[]).is_err());
    let bad = [DVec3::ZERO, DVec3::X, DVec3::new(f64::NAN, 0.0, 0.0)];
    match Delaunay::from_points(&bad) {
        Err(DelaunayError::BadCoordinate { index: 2, .. }) => {}
        other => panic!("{other:?}"),
    }
}

#[test]
fn duplicates_are_skipped() {
    let mut pts = uniform(100, 6);
    pts.push(pts[10]);
    pts.push(pts[20]);
    let (mut dt, stats) = Delaunay::from_points(&pts).unwrap();
    assert_eq!(stats.duplicates, 2);
    assert_eq!(dt.num_vertices(), 100);
    assert_eq!(dt.insert(pts[5], None).unwrap(), Inserted::Duplicate(5));
    assert_eq!(dt.num_vertex_ids(), 102);
    dt.validate().unwrap();
}

#[test]
fn dry_run_predicts_insertion_and_changes_nothing() {
    let pts = uniform(3000, 7);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    for p in uniform(50, 8) {
        let before: Vec<[u32; 4]> = dt.finite_tets().collect();
        let DryRun::Cavity { removed, faces } = dt.dry_run(p, None) else {
            panic!("not a duplicate");
        };
        assert_eq!(before, dt.finite_tets().collect::<Vec<_>>());
        let removed_finite = removed.iter().filter(|&&t| dt.is_finite(t)).count();
        let Inserted::New(id) = dt.insert(p, None).unwrap() else {
            panic!()
        };
        let mut predicted: Vec<[u32; 4]> = faces
            .iter()
            .map(|f| [f[0], f[1], f[2], id])
            .filter(|t| !t.contains(&INFINITE))
            .map(|mut t| {
                t.sort_unstable();
                t
            })
            .collect();
        let mut actual: Vec<[u32; 4]> = dt
            .finite_tets()
            .filter(|t| t.contains(&id))
            .map(|mut t| {
                t.sort_unstable();
                t
            })
            .collect();
        predicted.sort_unstable();
        actual.sort_unstable();
        assert_eq!(predicted, actual);
        assert_eq!(
            before.len() + predicted.len() - removed_finite,
            dt.num_finite_tets()
        );
    }
    dt.validate().unwrap();
}

#[test]
fn new_tets_are_positive_for_faces_from_dry_run() {
    let pts = uniform(500, 9);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    let p = DVec3::splat(0.5);
    if let DryRun::Cavity { faces, .. } = dt.dry_run(p, None) {
        for f in faces.iter().filter(|f| !f.contains(&INFINITE)) {
            let q = f.map(|v| dt.point(v));
            assert!(orient3d(q[0], q[1], q[2], p) > 0.0);
        }
    }
}

#[test]
fn validate_catches_corruption() {
    let pts = uniform(200, 10);
    let (dt, _) = Delaunay::from_points(&pts).unwrap();
    let t = dt.finite_tet_ids().next().unwrap();
    let mut flipped = dt.clone();
    flipped.tets[t as usize].v.swap(0, 1);
    assert!(flipped.validate().unwrap_err().contains("orient"));
    let mut unlinked = dt.clone();
    unlinked.tets[t as usize].n[0] = unlinked.tets[t as usize].n[1];
    assert!(unlinked.validate().is_err());
    // Moving a vertex slightly breaks the empty-sphere property somewhere.
    let mut moved = dt.clone();
    let v = moved.tets[t as usize].v[0];
    let centre = moved.points.iter().sum::<DVec3>() / 200.0;
    moved.points[v as usize] = moved.points[v as usize].lerp(centre, 0.3);
    assert!(moved.validate().is_err());
}

#[test]
fn tags_are_inherited_through_cavities() {
    let pts = uniform(2000, 11);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    dt.enable_tags();
    let region = |dt: &Delaunay, t: u32| {
        let c = dt.tet_points(t).iter().sum::<DVec3>() / 4.0;
        if c.x < 0.5 {
            1
        } else {
            2
        }
    };
    let ids: Vec<u32> = dt.finite_tet_ids().collect();
    for t in ids {
        let r = region(&dt, t);
        dt.set_tag(t, r);
    }
    let mut checked = 0;
    for p in uniform(300, 12) {
        let DryRun::Cavity { removed, .. } = dt.dry_run(p, None) else {
            continue;
        };
        let finite: Vec<u32> = removed
            .iter()
            .copied()
            .filter(|&t| dt.is_finite(t))
            .collect();
        let tags: Vec<u32> = finite.iter().map(|&t| dt.tag(t)).collect();
        let uniform_tag = tags.iter().all(|&g| g == tags[0]) && removed.len() == finite.len();
        dt.insert(p, None).unwrap();
        if uniform_tag {
            for &t in dt.last_created() {
                assert_eq!(dt.tag(t), tags[0]);
            }
            checked += 1;
        }
    }
    assert!(checked > 100, "{checked}");
    dt.validate().unwrap();
}

/// Finite tets as sorted vertex quadruples, sorted (independent of tet ids and orientation).
pub(super) fn sorted_tets(dt: &Delaunay) -> Vec<[u32; 4]> {
    let mut t: Vec<[u32; 4]> = dt
        .finite_tets()
        .map(|mut t| {
            t.sort_unstable();
            t
        })
        .collect();
    t.sort_unstable();
    t
}

fn probed(dt: &mut Delaunay, p: DVec3) -> Cavity {
    match dt.probe(p, None) {
        Probe::Cavity(c) => c,
        Probe::Duplicate(v) => panic!("{p} is vertex {v}"),
    }
}

#[test]
fn inserting_a_probed_cavity_matches_plain_insertion() {
    let pts = uniform(2000, 13);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    let mut reference = dt.clone();
    let new = uniform(200, 14);
    for (k, pair) in new.chunks(2).enumerate() {
        let (p, q) = (pair[0], pair[1]);
        let cp = probed(&mut dt, p);
        let cq = probed(&mut dt, q);
        // One set of buffers: probing q made p's token stale.
        assert!(!dt.is_current(&cp) && dt.is_current(&cq));
        let (removed, faces) = dt.cavity(&cq);
        assert!(!removed.is_empty() && !faces.is_empty());
        let n = dt.num_vertex_ids() as u32;
        if k % 2 == 0 {
            // Both stale when inserted: fresh searches.
            assert_eq!(dt.insert_cavity(cp), Ok(Inserted::New(n)));
            assert!(!dt.is_current(&cq));
            assert_eq!(dt.insert_cavity(cq), Ok(Inserted::New(n + 1)));
            reference.insert(p, None).unwrap();
            reference.insert(q, None).unwrap();
        } else {
            // Both current when inserted: the probed cavities are used.
            assert_eq!(dt.insert_cavity(cq), Ok(Inserted::New(n)));
            let cp = probed(&mut dt, p);
            assert_eq!(dt.insert_cavity(cp), Ok(Inserted::New(n + 1)));
            reference.insert(q, None).unwrap();
            reference.insert(p, None).unwrap();
        }
        assert_eq!(dt.num_vertices(), reference.num_vertices());
    }
    dt.validate().unwrap();
    assert_eq!(sorted_tets(&dt), sorted_tets(&reference));
}

#[test]
fn a_cavity_token_is_stale_after_an_insertion() {
    let pts = uniform(1000, 15);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    let mut reference = dt.clone();
    let [p, q] = [DVec3::new(0.31, 0.52, 0.47), DVec3::new(0.7, 0.2, 0.6)];
    let cp = probed(&mut dt, p);
    dt.insert(q, None).unwrap();
    assert!(!dt.is_current(&cp));
    // Reading it is a bug: loud in debug builds, an empty cavity in release builds.
    let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| dt.cavity(&cp).0.len()));
    if cfg!(debug_assertions) {
        assert!(read.is_err());
    } else {
        assert_eq!(read.ok(), Some(0));
    }
    // Inserting it searches afresh.
    let n = dt.num_vertex_ids() as u32;
    assert_eq!(dt.insert_cavity(cp), Ok(Inserted::New(n)));
    assert_eq!(dt.point(n), p);
    reference.insert(q, None).unwrap();
    reference.insert(p, None).unwrap();
    dt.validate().unwrap();
    assert_eq!(sorted_tets(&dt), sorted_tets(&reference));
}

#[test]
fn a_probe_of_a_vertex_is_a_duplicate() {
    let pts = uniform(500, 16);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    let cavity = probed(&mut dt, DVec3::splat(0.5));
    for (v, &p) in pts.iter().enumerate().step_by(50) {
        let Probe::Duplicate(d) = dt.probe(p, None) else {
            panic!("vertex {v} not found");
        };
        assert_eq!(dt.point(d), p);
    }
    // A duplicate probe leaves no cavity: earlier tokens are stale.
    assert!(!dt.is_current(&cavity));
    assert_eq!(dt.num_vertex_ids(), 500);
}

#[test]
fn vertex_star_of_a_high_degree_vertex() {
    // The centre of a sphere of points is in every tet: its star overflows the small set.
    let mut pts = sphere(400, 15);
    pts.push(DVec3::ZERO);
    let (dt, _) = Delaunay::from_points(&pts).unwrap();
    let c = (pts.len() - 1) as u32;
    let mut star = dt.vertex_star(c);
    star.sort_unstable();
    let mut expected: Vec<u32> = (0..dt.tet_capacity() as u32)
        .filter(|&t| dt.is_alive(t) && dt.tet(t).contains(&c))
        .collect();
    expected.sort_unstable();
    assert!(expected.len() > 300, "{}", expected.len());
    assert_eq!(star, expected);
    for v in 0..400u32 {
        let t = dt
            .find_edge(c, v)
            .expect("every sphere point is joined to the centre");
        assert!(dt.tet(t).contains(&c) && dt.tet(t).contains(&v));
    }
}

#[test]
fn edge_ring_is_every_tet_holding_the_edge() {
    // Interior and hull edges of a point cloud with a grid part (cospherical ties).
    let mut pts = sphere(200, 3);
    for i in 0..3 {
        for j in 0..3 {
            for k in 0..3 {
                pts.push(DVec3::new(i as f64, j as f64, k as f64) * 0.2);
            }
        }
    }
    let (dt, _) = Delaunay::from_points(&pts).unwrap();
    let mut ring = vec![];
    let mut edges = 0;
    for a in 0..pts.len() as u32 {
        for b in a + 1..pts.len() as u32 {
            let mut expected: Vec<u32> = (0..dt.tet_capacity() as u32)
                .filter(|&t| dt.is_alive(t) && dt.tet(t).contains(&a) && dt.tet(t).contains(&b))
                .collect();
            let found = dt.edge_ring(a, b, &mut ring);
            assert_eq!(found, !expected.is_empty(), "edge {a} {b}");
            // Consecutive ring tets share a face.
            for (i, &t) in ring.iter().enumerate() {
                let u = ring[(i + 1) % ring.len()];
                assert!(dt.neighbors(t).contains(&u));
            }
            ring.sort_unstable();
            expected.sort_unstable();
            assert_eq!(ring, expected, "edge {a} {b}");
            edges += found as usize;
        }
    }
    assert!(edges > 500, "{edges}");
}

/// Counts the faces a watched probe shows, stopping after `stop_after` (None: never).
struct FaceCounter {
    seen: Vec<[u32; 3]>,
    stop_after: Option<usize>,
}

impl CavityWatch for FaceCounter {
    // Not the sliver screen's 8: any batch size works.
    const BATCH: usize = 5;

    fn faces(&mut self, faces: &[BoundaryFace], points: &[DVec3]) -> bool {
        assert!(faces.iter().all(|f| f
            .vertices()
            .iter()
            .all(|&v| v == INFINITE || (v as usize) < points.len())));
        self.seen.extend(faces.iter().map(|f| f.vertices()));
        self.stop_after.is_none_or(|n| self.seen.len() <= n)
    }
}

#[test]
fn a_watched_probe_shows_every_boundary_face_once_and_a_stopped_one_leaves_no_trace() {
    let pts = uniform(3000, 21);
    let (mut dt, _) = Delaunay::from_points(&pts).unwrap();
    let reference = dt.clone();
    let mut stopped = 0;
    for (k, p) in uniform(300, 22).into_iter().enumerate() {
        // Points outside the hull too (hull tets in the cavity).
        let p = if k % 5 == 0 { p * 1.5 - 0.25 } else { p };
        let mut all = FaceCounter {
            seen: vec![],
            stop_after: None,
        };
        let Some(Probe::Cavity(c)) = dt.probe_watched(p, None, &mut all) else {
            panic!("an unstopped probe of a new point gives its cavity");
        };
        let mut faces: Vec<[u32; 3]> = dt.cavity(&c).1.iter().map(|f| f.vertices()).collect();
        faces.sort_unstable();
        all.seen.sort_unstable();
        assert_eq!(all.seen, faces, "point {k}");
        // Stopped at various points of the search, including at its end.
        let mut some = FaceCounter {
            seen: vec![],
            stop_after: Some(k % faces.len()),
        };
        if dt.probe_watched(p, None, &mut some).is_none() {
            stopped += 1;
            // The marks were reset: the next search and an insertion are as without it.
            let again = probed(&mut dt, p);
            let mut faces_again: Vec<[u32; 3]> =
                dt.cavity(&again).1.iter().map(|f| f.vertices()).collect();
            faces_again.sort_unstable();
            assert_eq!(faces_again, faces, "point {k} after a stopped probe");
        }
    }
    assert!(stopped > 250, "{stopped} probes stopped");
    // Probing changed nothing.
    assert_eq!(sorted_tets(&dt), sorted_tets(&reference));
    let mut inserted = dt.clone();
    let mut plain = reference;
    for p in uniform(100, 23) {
        let mut stop = FaceCounter {
            seen: vec![],
            stop_after: Some(3),
        };
        assert!(inserted.probe_watched(p, None, &mut stop).is_none());
        inserted.insert(p, None).unwrap();
        plain.insert(p, None).unwrap();
    }
    inserted.validate().unwrap();
    assert_eq!(sorted_tets(&inserted), sorted_tets(&plain));
}

/// Every tet slot: its vertices and neighbour references (dead ones too), ids included.
fn slots(dt: &Delaunay) -> Vec<([u32; 4], [u32; 4])> {
    dt.tets.iter().map(|t| (t.v, t.n)).collect()
}

#[test]
fn inserting_a_kept_cavity_after_other_probes_is_a_fresh_insertion_exactly() {
    let pts = uniform(2000, 31);
    let (mut kept, _) = Delaunay::from_points(&pts).unwrap();
    let mut fresh = kept.clone();
    let mut rng = ChaCha8Rng::seed_from_u64(32);
    let mut used = 0;
    for k in 0..150 {
        let p = DVec3::new(rng.gen(), rng.gen(), rng.gen());
        let others: Vec<DVec3> = (0..k % 4)
            .map(|_| p + DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.02)
            .collect();
        let hint = (k % 5 != 0).then(|| kept.finite_tet_ids().nth(k * 7).unwrap());
        let start = hint.map(|h| kept.tet(h));
        for (keeps, dt) in [(true, &mut kept), (false, &mut fresh)] {
            assert_eq!(hint.map(|h| dt.tet(h)), start);
            let Probe::Cavity(c) = dt.probe(p, hint) else {
                panic!("a new point");
            };
            if keeps {
                dt.keep(&c);
            }
            for &q in &others {
                dt.probe(q, hint);
            }
            dt.insert_cavity(c).unwrap();
        }
        used += usize::from(hint.is_some() && !others.is_empty());
        // The same tets in the same slots, and the same walks to come.
        assert_eq!(slots(&kept), slots(&fresh), "point {k}");
        assert_eq!(kept.rng, fresh.rng, "point {k}: the walks' random state");
    }
    assert!(used > 80);
    kept.validate().unwrap();
}
