//! Quality refinement (issue 4) on the acute-free models: every tet meets the bounds, the
//! boundary still conforms, the volume is preserved, the mesh is still Delaunay; size
//! conformity with a graded spacing; determinism.

mod common;
use common::*;
use slivermesh::geom::TetQuality;
use slivermesh::refine::mesh;
use slivermesh::run::params::Params;
use slivermesh::run::spacing::{ConstantSpacing, FnSpacing, Spacing};
use slivermesh::{DVec3, TetMesh};

const ACUTE_FREE: &[(&str, Option<f64>)] = &[
    ("poly/cube.poly", Some(1.0)),
    ("poly/lshape.poly", Some(3.0)),
    ("poly/stairs.poly", Some(20.0)),
    ("poly/box_with_cavity.poly", Some(63.0)),
    ("poly/two_materials.poly", Some(2.0)),
    ("poly/drilled_block.poly", Some(8.0)),
    ("poly/thin_plate.poly", Some(50.0)),
    ("poly/tetgen_example.poly", Some(17.9375)),
    ("off/cube.off", Some(8.0)),
    ("off/cross.off", None),
];

fn check_quality(rel: &str, m: &TetMesh, params: &Params) {
    for (i, t) in m.tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
        let q = TetQuality::of(a, b, c, d);
        assert!(q.rho <= params.rho0 + 1e-12, "{rel}: tet {i} rho {}", q.rho);
        assert!(q.sigma >= params.sigma0, "{rel}: tet {i} sigma {}", q.sigma);
        assert!(
            q.min_dihedral >= params.min_dihedral - 1e-9,
            "{rel}: tet {i} min dihedral {}",
            q.min_dihedral
        );
    }
}

fn refined(
    rel: &str,
    volume: Option<f64>,
    params: &Params,
    spacing: Option<&dyn Spacing>,
) -> TetMesh {
    let input = read_model(rel);
    let (m, report) = mesh(&input, params, spacing, None).unwrap_or_else(|e| panic!("{rel}: {e}"));
    assert!(report.complete, "{rel}: {:?}", report.stop_reason);
    assert_eq!(report.n_relabelled, 0, "{rel}: region labels leaked");
    check_conforming(rel, &input, &m, volume);
    check_quality(rel, &m, params);
    m
}

/// Region labels stay right next to small input angles: tets made by a boundary split whose
/// cavity crossed a subfacet deleted for a moment take their old neighbours' region
/// (`Domain::retag_created`) instead of leaking it across the boundary. Before that, the
/// re-marking after the first pass corrected 774 tets on elephant and 4,747 on oblong (keep
/// mode, default settings), tets the refinement had worked on as inside.
#[test]
fn region_labels_do_not_leak_next_to_small_angles() {
    for rel in ["off/elephant.off", "off/oblong.off"] {
        let input = read_model(rel);
        let params = Params::default();
        let (m, report) =
            mesh(&input, &params, None, None).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert_eq!(report.n_relabelled, 0, "{rel}: region labels leaked");
        check_conforming(rel, &input, &m, None);
    }
}

#[test]
fn acute_free_models_meet_every_bound_with_default_spacing() {
    let params = Params::default();
    for &(rel, vol) in ACUTE_FREE {
        refined(rel, vol, &params, None);
    }
}

#[test]
fn acute_free_models_meet_every_bound_with_a_fine_constant_spacing() {
    let params = Params::default();
    for &(rel, vol) in &ACUTE_FREE[..3] {
        refined(rel, vol, &params, Some(&ConstantSpacing(0.15)));
    }
}

#[test]
fn two_materials_keeps_region_volumes_after_refinement() {
    let m = refined(
        "poly/two_materials.poly",
        Some(2.0),
        &Params::default(),
        Some(&ConstantSpacing(0.2)),
    );
    assert!(rel_close(region_volume(&m, 1), 1.0, 1e-9));
    assert!(rel_close(region_volume(&m, 2), 1.0, 1e-9));
}

#[test]
fn graded_spacing_is_respected() {
    let x0 = DVec3::new(0.0, 0.0, 0.0);
    let f = FnSpacing(move |p: DVec3| 0.02 + 0.2 * p.distance(x0));
    let params = Params::default();
    let m = refined("poly/cube.poly", Some(1.0), &params, Some(&f));
    let mut min_ratio = f64::INFINITY;
    let mut max_ratio: f64 = 0.0;
    for t in &m.tets {
        let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
        let q = TetQuality::of(a, b, c, d);
        let centre = q.circumcenter.unwrap();
        assert!(q.circumradius / f.at(centre) <= params.size_factor * (1.0 + 1e-9));
        for (x, y) in [(a, b), (a, c), (a, d), (b, c), (b, d), (c, d)] {
            let r = x.distance(y) / f.at((x + y) * 0.5);
            min_ratio = min_ratio.min(r);
            max_ratio = max_ratio.max(r);
        }
    }
    eprintln!(
        "graded: {} tets, edge/f in [{min_ratio:.3}, {max_ratio:.3}]",
        m.tets.len()
    );
    // Edge length / f at the midpoint: measured band (see docs/parameters.md).
    assert!(max_ratio <= 2.0, "max edge/f {max_ratio}");
    assert!(min_ratio >= 0.2, "min edge/f {min_ratio}");
    // Graded: small tets near x0, large ones far away.
    let near = m
        .tets
        .iter()
        .filter(|t| m.vertices[t[0] as usize].length() < 0.2)
        .count();
    assert!(near > 20, "refined near x0: {near}");
}

#[test]
fn same_seed_same_mesh_and_other_seed_other_mesh() {
    let input = read_model("poly/lshape.poly");
    let params = Params::default();
    let h = ConstantSpacing(0.3);
    let (a, _) = mesh(&input, &params, Some(&h), None).unwrap();
    let (b, _) = mesh(&input, &params, Some(&h), None).unwrap();
    assert_eq!(a, b);
    let other = Params { seed: 99, ..params };
    let (c, _) = mesh(&input, &other, Some(&h), None).unwrap();
    assert_ne!(a, c);
}

#[test]
fn bad_spacing_is_an_error_naming_the_point() {
    let input = read_model("poly/cube.poly");
    let f = FnSpacing(|p: DVec3| if p.x > 0.5 { f64::NAN } else { 0.3 });
    let err = mesh(&input, &Params::default(), Some(&f), None).unwrap_err();
    let msg = err.to_string();
    assert!(msg.contains("NaN") && msg.contains("spacing"), "{msg}");
    let zero = FnSpacing(|_| 0.0);
    assert!(mesh(&input, &Params::default(), Some(&zero), None).is_err());
}

#[test]
fn vertex_budget_stops_with_a_reason() {
    let input = read_model("poly/cube.poly");
    let params = Params {
        max_vertices: 200,
        ..Params::default()
    };
    let (_, report) = mesh(&input, &params, Some(&ConstantSpacing(0.05)), None).unwrap();
    assert!(!report.complete);
    assert!(report.stop_reason.unwrap().contains("max_vertices"));
    // The bad tets still queued are counted as left by the budget (no other reason on this
    // acute-free model).
    let r = &report.refusals;
    assert!(r.budget > 0, "{r:?}");
    assert_eq!(r.total, r.budget, "{r:?}");
}

/// A vertex budget too small for boundary recovery itself is a bad parameter named as such,
/// not an internal error (there is no conforming mesh to stop with).
#[test]
fn vertex_budget_too_small_for_boundary_recovery_is_invalid_input() {
    let input = read_model("off/joint.off");
    let params = Params {
        max_vertices: 10,
        ..Params::default()
    };
    match mesh(&input, &params, None, None) {
        Err(slivermesh::run::error::MeshError::InvalidInput(m)) => {
            assert!(m.contains("max_vertices"), "{m}")
        }
        r => panic!("expected InvalidInput, got {:?}", r.map(|(_, r)| r)),
    }
}

#[test]
fn progress_callback_can_cancel() {
    let input = read_model("poly/cube.poly");
    let mut calls = 0;
    let mut cb = |_: f64, _: usize| {
        calls += 1;
        false
    };
    let r = mesh(
        &input,
        &Params::default(),
        Some(&ConstantSpacing(0.03)),
        Some(&mut cb),
    );
    assert!(matches!(
        r,
        Err(slivermesh::run::error::MeshError::Cancelled)
    ));
    assert!(calls >= 1);
}

/// Models with small input angles (every .off model but cube and cross): refinement
/// terminates, the mesh conforms (Delaunay, boundary tiled per marker, enclosed volume kept),
/// and every tet away from the small angles meets the bounds (`complete`); the report counts
/// the ones within their influence that do not, and how often refinement left a bad tet alone,
/// per reason: the reasons add up to the total (the one counter refinement kept before the
/// reasons were told apart, and equal to it when they were).
#[test]
fn acute_models_terminate_and_meet_bounds_away_from_small_angles() {
    let params = Params::default();
    let mut seen = slivermesh::run::report::Refusals::default();
    for rel in [
        "off/star.off",
        "off/oblong.off",
        "off/joint.off",
        "off/part.off",
        "off/spool.off",
        "off/rotor.off",
        "off/anchor.off",
        "off/elephant.off",
        "off/fandisk.off",
    ] {
        let input = read_model(rel);
        let (m, report) =
            mesh(&input, &params, None, None).unwrap_or_else(|e| panic!("{rel}: {e}"));
        assert!(report.complete, "{rel}: {:?}", report.stop_reason);
        check_conforming(rel, &input, &m, None);
        assert!(report.n_acute_angles > 0, "{rel}: no acute angle reported");
        let r = &report.refusals;
        let sum: usize = r.counts().iter().map(|(_, n)| n).sum();
        assert_eq!(sum, r.total, "{rel}: {r:?}");
        assert_eq!(r.budget, 0, "{rel}: {r:?}");
        seen.add(r);
        // Every bad tet is counted as near an acute angle.
        let bad = m
            .tets
            .iter()
            .filter(|t| {
                let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
                let q = slivermesh::geom::TetQuality::of(a, b, c, d);
                q.rho > params.rho0
                    || q.sigma < params.sigma0
                    || q.min_dihedral < params.min_dihedral
            })
            .count();
        assert_eq!(bad, report.n_bad_near_acute, "{rel}");
        // No tet of (numerically) no volume: four cocircular vertices of a facet, a rounding
        // error off its plane, are left out of the output (refine/output.rs). Before that,
        // spool had 351, rotor 327, anchor 149; the few left are other configurations.
        let flat = m
            .tets
            .iter()
            .filter(|t| {
                let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
                TetQuality::of(a, b, c, d).sigma < 1e-9
            })
            .count();
        // (refinement alone: with min_dihedral 18, the default since issue 12, rotor has 13 and
        // spool 2; the improvement pass every API/CLI output goes through leaves none with
        // orient3d <= 0 and re-shapes the rest, tests/improve.rs)
        let allowed = if ["off/part.off", "off/rotor.off", "off/spool.off"].contains(&rel) {
            20
        } else {
            0
        };
        assert!(flat <= allowed, "{rel}: {flat} tets of no volume");
    }
    // The reasons the acute models give (on every one but star, which has none, most tets
    // are left within a small angle's influence).
    assert!(seen.near_small_angle > seen.total / 2, "{seen:?}");
    for (name, n) in [
        ("flat_by_construction", seen.flat_by_construction),
        ("far_centre", seen.far_centre),
        ("subfacet_centre_outside", seen.subfacet_centre_outside),
    ] {
        assert!(n > 0, "no {name}: {seen:?}");
    }
}

/// The paper's second input kind: an "almost good" Delaunay mesh with slivers (here
/// two_materials.poly refined for size and radius-edge ratio only, written as medit .mesh and
/// read back). Its boundary triangles
/// (with markers) and regions are kept; afterwards every tet meets the bounds.
#[test]
fn slivers_of_an_existing_mesh_are_removed() {
    let input = read_model("poly/two_materials.poly");
    let almost_good = Params {
        sigma0: 0.0,
        min_dihedral: 0.0,
        ..Params::default()
    };
    let (m0, _) = mesh(&input, &almost_good, Some(&ConstantSpacing(0.15)), None).unwrap();
    let path =
        std::env::temp_dir().join(format!("slivermesh-existing-{}.mesh", std::process::id()));
    slivermesh::io::write_mesh(&path, &m0, &[]).unwrap();
    let existing = slivermesh::io::read_mesh(&path).unwrap();
    std::fs::remove_file(&path).ok();
    let params = Params::default();
    let (m, report) = slivermesh::refine::existing::remove_slivers(&existing, &params).unwrap();
    assert!(report.complete, "{:?}", report.stop_reason);
    check_orientation(&m);
    check_delaunay(&m);
    check_boundary_faces_are_tet_faces(&m);
    check_quality("existing two_materials", &m, &params);
    assert!(rel_close(total_volume(&m), 2.0, 1e-9));
    assert!(rel_close(region_volume(&m, 1), 1.0, 1e-9));
    assert!(rel_close(region_volume(&m, 2), 1.0, 1e-9));
    // boundary and interface area per marker
    let (got, want) = (
        boundary_area_by_marker(&m),
        boundary_area_by_marker(&existing),
    );
    assert_eq!(got.len(), want.len(), "markers {got:?} vs {want:?}");
    for (mk, a) in &want {
        let g = got.get(mk).copied().unwrap_or(0.0);
        assert!(rel_close(g, *a, 1e-9), "marker {mk}: area {g}, input {a}");
    }
    // the input had flat tets, the output has none
    let before = existing
        .tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|v| existing.vertices[v as usize]);
            TetQuality::of(a, b, c, d).min_dihedral
        })
        .fold(180.0, f64::min);
    assert!(
        before < params.min_dihedral,
        "the input already had no sliver: {before}"
    );
}

/// The minimum of several spacings: a fine zone inside a coarse constant spacing; a bad value
/// of any of them fails the run (the minimum does not hide a NaN).
#[test]
fn minimum_of_spacings_is_respected_and_keeps_bad_values() {
    use slivermesh::run::error::MeshError;
    use slivermesh::run::spacing::MinSpacing;
    let fine_zone = |p: DVec3| if p.x < 0.3 { 0.06 } else { 10.0 };
    let f = MinSpacing(vec![
        Box::new(ConstantSpacing(0.2)),
        Box::new(FnSpacing(fine_zone)),
    ]);
    assert_eq!(f.at(DVec3::new(0.1, 0.5, 0.5)), 0.06);
    assert_eq!(f.at(DVec3::new(0.9, 0.5, 0.5)), 0.2);
    let params = Params::default();
    let m = refined("poly/cube.poly", Some(1.0), &params, Some(&f));
    let (mut fine, mut coarse) = (0, 0);
    for t in &m.tets {
        let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
        let q = TetQuality::of(a, b, c, d);
        let centre = q.circumcenter.unwrap();
        assert!(q.circumradius / f.at(centre) <= params.size_factor * (1.0 + 1e-9));
        if centre.x < 0.3 {
            fine += 1;
        } else {
            coarse += 1;
        }
    }
    // The fine zone is 3/7 of the volume of the coarse one but holds far more tets.
    assert!(fine > 3 * coarse, "fine {fine}, coarse {coarse}");
    let broken = MinSpacing(vec![
        Box::new(ConstantSpacing(0.2)),
        Box::new(FnSpacing(|p: DVec3| if p.x > 0.5 { f64::NAN } else { 1.0 })),
    ]);
    let input = read_model("poly/cube.poly");
    let r = mesh(&input, &params, Some(&broken), None);
    assert!(
        matches!(r, Err(MeshError::BadSpacing { value, .. }) if value.is_nan()),
        "{:?}",
        r.err()
    );
}

/// A shorter reach of small angles' influence (`small_angle_reach`): still terminates,
/// conforms and completes, every bad tet is within the (smaller) influence, and fewer are left
/// than with the default (whole facets) on a model whose small angles sit on large facets.
#[test]
fn shorter_small_angle_reach_leaves_fewer_bad_tets() {
    let input = read_model("off/joint.off");
    let default = Params::default();
    let short = Params {
        small_angle_reach: 2.0,
        ..Params::default()
    };
    let (_, wide) = mesh(&input, &default, None, None).unwrap();
    let (m, report) = mesh(&input, &short, None, None).unwrap();
    assert!(report.complete, "{:?}", report.stop_reason);
    check_conforming("off/joint.off", &input, &m, None);
    let bad = m
        .tets
        .iter()
        .filter(|t| {
            let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
            let q = TetQuality::of(a, b, c, d);
            q.rho > short.rho0 || q.sigma < short.sigma0 || q.min_dihedral < short.min_dihedral
        })
        .count();
    assert_eq!(bad, report.n_bad_near_acute);
    assert!(
        report.n_bad_near_acute < wide.n_bad_near_acute * 9 / 10,
        "reach 2: {} bad tets, default: {}",
        report.n_bad_near_acute,
        wide.n_bad_near_acute
    );
}
