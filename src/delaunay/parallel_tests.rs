//! Parallel bulk insertion: the same tets as the serial kernel for every thread count
//! (uniform, clustered, sphere points), valid and deterministic on degenerate grids.

use super::*;
use crate::delaunay::tests::{clustered, grid, sorted_tets, sphere, uniform};

/// Triangulates `pts` with 1 thread and with each of `threads`, validates every result, and
/// asserts the same tet set (and vertex pointers' validity) each time; returns the reports.
fn same_for_every_thread_count(pts: &[DVec3], threads: &[usize]) -> Vec<ParallelReport> {
    let (serial, s1) = Delaunay::from_points(pts).unwrap();
    serial.validate().unwrap();
    let want = sorted_tets(&serial);
    let mut reports = vec![];
    for &t in threads {
        let (dt, st, report) = Delaunay::from_points_report(pts, t).unwrap();
        dt.validate().unwrap_or_else(|e| panic!("{t} threads: {e}"));
        assert_eq!(st, s1, "{t} threads: insertion counts");
        assert_eq!(dt.num_vertices(), serial.num_vertices());
        assert!(
            sorted_tets(&dt) == want,
            "{t} threads: other tets than 1 thread"
        );
        assert_eq!(report.threads, t);
        assert_eq!(report.parallel_points + report.serial_points, pts.len());
        reports.push(report);
    }
    reports
}

#[test]
fn uniform_points_give_the_same_tets_for_any_thread_count() {
    let pts = uniform(60_000, 11);
    let reports = same_for_every_thread_count(&pts, &[2, 3, 4]);
    // The phases did most of the work (the point of the exercise).
    for r in &reports {
        assert!(r.phases >= 1, "{r:?}");
        assert!(r.parallel_points > pts.len() * 3 / 4, "{r:?}");
    }
}

#[test]
fn clustered_points_give_the_same_tets_for_any_thread_count() {
    let pts = clustered(60_000, 12);
    same_for_every_thread_count(&pts, &[2, 3]);
}

#[test]
fn sphere_points_give_the_same_tets_for_any_thread_count() {
    // Every point is on the hull: the threads insert through hull tets.
    let pts = sphere(40_000, 13);
    same_for_every_thread_count(&pts, &[2, 4]);
}

#[test]
fn duplicates_give_the_same_tets_for_any_thread_count() {
    let mut pts = uniform(30_000, 14);
    let copies: Vec<DVec3> = pts.iter().step_by(7).copied().collect();
    pts.extend(copies);
    // Signed zeros: equal points.
    pts.extend([DVec3::new(0.0, 0.5, 0.5), DVec3::new(-0.0, 0.5, 0.5)]);
    let reports = same_for_every_thread_count(&pts, &[2]);
    assert!(reports[0].phases >= 1);
}

#[test]
fn grid_is_valid_deterministic_and_as_serial() {
    // Cospherical everywhere: the perturbation (ranks = BRIO positions, the same for any
    // thread count) decides every tie, so the triangulation is still unique.
    let pts = grid(32);
    let reports = same_for_every_thread_count(&pts, &[2, 3]);
    assert!(reports[0].phases >= 1, "{:?}", reports[0]);
    // And twice the same with the same thread count (same slots too: deterministic work).
    let (a, _) = Delaunay::from_points_threads(&pts, 2).unwrap();
    let (b, _) = Delaunay::from_points_threads(&pts, 2).unwrap();
    assert!((0..a.tet_capacity() as u32)
        .all(|t| a.is_alive(t) == b.is_alive(t) && (!a.is_alive(t) || a.tet(t) == b.tet(t))));
}

#[test]
fn small_and_degenerate_inputs_match_serial() {
    // Too few points for a phase: the serial kernel's path, the same errors.
    let pts = uniform(100, 15);
    same_for_every_thread_count(&pts, &[2]);
    let flat: Vec<DVec3> = (0..50)
        .map(|i| DVec3::new(i as f64, (i * i) as f64, 0.0))
        .collect();
    assert_eq!(
        Delaunay::from_points_threads(&flat, 2).unwrap_err(),
        Delaunay::from_points(&flat).unwrap_err()
    );
    let mut bad = uniform(20_000, 16);
    bad[12_345].y = f64::NAN;
    bad[15_000].x = 1e300;
    assert_eq!(
        Delaunay::from_points_threads(&bad, 2)
            .unwrap_err()
            .to_string(),
        Delaunay::from_points(&bad).unwrap_err().to_string()
    );
}

#[test]
fn zero_threads_means_all_cores() {
    let cores = std::thread::available_parallelism().map_or(1, |n| n.get());
    assert_eq!(resolve_threads(0), cores.min(MAX_THREADS));
    assert_eq!(resolve_threads(3), 3);
    assert_eq!(resolve_threads(100_000), MAX_THREADS);
}
