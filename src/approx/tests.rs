use super::*;
use crate::io::{read_plc, ReadOptions};
use crate::run::params::SurfaceMode;
use crate::run::spacing::ConstantSpacing;
use std::path::Path;

fn model(name: &str) -> PlcInput {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name);
    read_plc(
        &path,
        &ReadOptions {
            merge_coplanar: true,
        },
    )
    .unwrap()
}

fn approximate() -> Params {
    Params {
        surface_mode: SurfaceMode::Approximate,
        ..Params::default()
    }
}

/// Prints the figures of one model (`SM_MODEL=off/fandisk.off cargo test --release
/// approx::tests::explore -- --ignored --nocapture`).
#[test]
#[ignore]
fn explore() {
    let name = std::env::var("SM_MODEL").unwrap_or_else(|_| "off/cube.off".into());
    let input = model(&name);
    let t = std::time::Instant::now();
    let (mesh, _, report) = mesh(&input, &approximate(), None, None).unwrap();
    let q = crate::quality::measure(&mesh).unwrap();
    println!(
        "{name}: {} tets in {:.2}s",
        mesh.tets.len(),
        t.elapsed().as_secs_f64()
    );
    println!("{report:#?}");
    println!("{}", crate::quality::table(&q));
}

fn check_mesh(name: &str, size: Option<f64>) -> (TetMesh, Report) {
    let input = model(name);
    let spacing = size.map(ConstantSpacing);
    let f = spacing.as_ref().map(|s| s as &dyn Spacing);
    let (mesh, _, report) = mesh(&input, &approximate(), f, None).unwrap();
    // Every tet positively oriented by the exact predicate.
    for (k, t) in mesh.tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| mesh.vertices[v as usize]);
        assert!(
            crate::geom::orient3d(a, b, c, d) > 0.0,
            "{name}: tet {k} not positive"
        );
    }
    // The boundary triangles are exactly the tet faces with one tet, each facing out of it.
    let mut once: std::collections::HashMap<[u32; 3], u32> = Default::default();
    for t in &mesh.tets {
        for f in crate::delaunay::tables::FACE {
            let mut key = f.map(|k| t[k]);
            key.sort_unstable();
            *once.entry(key).or_default() += 1;
        }
    }
    let mut open: Vec<[u32; 3]> = once.into_iter().filter(|e| e.1 == 1).map(|e| e.0).collect();
    let mut boundary: Vec<[u32; 3]> = mesh
        .boundary
        .iter()
        .map(|b| {
            let mut key = *b;
            key.sort_unstable();
            key
        })
        .collect();
    open.sort_unstable();
    boundary.sort_unstable();
    assert_eq!(
        open, boundary,
        "{name}: boundary triangles are not the open tet faces"
    );
    // Every boundary vertex lies on the input surface (surface centres and curve points are
    // on it, and the improvement slides vertices back onto it).
    let plc = crate::plc::validate(&input).unwrap();
    let surface = crate::surface::InputSurface::from_plc(&plc);
    let oracle = crate::surface::oracle::SurfaceOracle::new(&surface);
    let tolerance = 1e-9 * surface.bbox_diagonal();
    for &v in mesh.boundary.iter().flatten() {
        let p = mesh.vertices[v as usize];
        assert!(
            oracle.distance_beyond(p, tolerance).is_none(),
            "{name}: boundary vertex {v} at {p} is off the input surface"
        );
    }
    let s = report
        .surface
        .clone()
        .expect("approximate mode reports the surface");
    assert!(
        s.hausdorff_input_to_output <= s.surface_distance
            && s.hausdorff_output_to_input <= s.surface_distance,
        "{name}: boundary {:.3e} / {:.3e} from the input, bound {:.3e}",
        s.hausdorff_input_to_output,
        s.hausdorff_output_to_input,
        s.surface_distance
    );
    assert!(
        s.feature_distance <= s.surface_distance,
        "{name}: features {s:?}"
    );
    assert!(
        s.relative_volume_difference.abs() < 5e-3,
        "{name}: volume {s:?}"
    );
    (mesh, report)
}

/// The boundary of the output is a closed 2-manifold whose triangles carry one marker per
/// patch, and the tets fill the input's volume.
#[test]
fn cube_is_remeshed_exactly_with_one_marker_per_side() {
    let (mesh, report) = check_mesh("off/cube.off", Some(0.3));
    let mut markers = mesh.boundary_markers.clone();
    markers.sort_unstable();
    markers.dedup();
    assert_eq!(markers, vec![1, 2, 3, 4, 5, 6]);
    let s = report.surface.unwrap();
    assert_eq!(
        (s.n_corners, s.n_feature_polylines, s.n_patches),
        (8, 12, 6)
    );
    assert_eq!(s.n_small_corners, 0);
    // A cube is its own approximation: flat patches, straight features.
    assert!(s.hausdorff_input_to_output < 1e-12 && s.feature_distance < 1e-12);
    let mut edges: rustc_hash::FxHashMap<[u32; 2], u32> = Default::default();
    for t in &mesh.boundary {
        for j in 0..3 {
            let (a, b) = (t[j], t[(j + 1) % 3]);
            *edges.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    assert!(
        edges.values().all(|&n| n == 2),
        "boundary not a closed manifold"
    );
    assert!(
        report.min_dihedral_deg >= 20.0,
        "{}",
        report.min_dihedral_deg
    );
}

/// fandisk: curved patches within the distance bound, sharp creases kept, one small corner
/// (19 degrees) reported, and the angle floors of the issue met.
#[test]
fn fandisk_meets_the_distance_and_angle_bounds() {
    let (mesh, report) = check_mesh("off/fandisk.off", Some(0.05));
    let s = report.surface.unwrap();
    assert_eq!(s.n_small_corners, 1);
    assert!(s.n_patches >= 10, "{s:?}");
    let q = crate::quality::measure(&mesh).unwrap();
    // The floor is 15 degrees on models without small corners and 12 elsewhere; the
    // approximate mode's improvement target is 20.
    assert!(
        q.min_dihedral_deg >= 15.0,
        "min dihedral {}",
        q.min_dihedral_deg
    );
    let rho_away = s.max_rho_away_from_small_corners;
    assert!(
        rho_away > 0.5 && rho_away <= 2.0,
        "max rho away from the small corner {rho_away}"
    );
}

/// The restricted facets each tet records (`tracking::TetInfo`) agree with the map of them
/// after every insertion, at both levels, on models with features, thin parts and curved
/// patches (`assert_restricted_bits` panics at the first disagreement).
#[test]
fn restricted_bits_follow_every_insertion() {
    use super::restricted::CHECK_EVERY_INSERTION;
    CHECK_EVERY_INSERTION.set(true);
    for name in ["off/cross.off", "off/star.off", "off/spool.off"] {
        check_mesh(name, None);
    }
    CHECK_EVERY_INSERTION.set(false);
}

/// Same input, parameters and seed: the same mesh.
#[test]
fn approximate_mode_is_deterministic() {
    let a = check_mesh("off/cross.off", None).0;
    let b = check_mesh("off/cross.off", None).0;
    assert_eq!(a, b);
}

/// The cell level's refusals reach the report: fandisk asked for 25 degrees leaves a few bad
/// cells, each counted under its reason (the total is their sum).
#[test]
fn cell_level_refusals_are_reported() {
    let params = Params {
        min_dihedral: 25.0,
        ..approximate()
    };
    let input = model("off/fandisk.off");
    let (_, _, report) = crate::pipeline::mesh(&input, &params, None, None).unwrap();
    let r = &report.refusals;
    assert!(r.total > 0, "{r:?}");
    assert_eq!(r.total, r.counts().iter().map(|&(_, n)| n).sum::<usize>());
}

/// Bad input is refused as in keep mode, naming what is wrong.
#[test]
fn open_surface_is_refused_in_approximate_mode() {
    let mut input = model("off/cube.off");
    input.facets.pop();
    let e = mesh(&input, &approximate(), None, None).unwrap_err();
    assert!(matches!(e, MeshError::InvalidInput(_)), "{e}");
}

/// Two materials of a .poly (two unit cubes sharing a face, region attributes 1 and 2): each
/// region keeps its attribute and its volume, the shared face is an interface of one tet of
/// each region on every triangle, written once among the boundary triangles.
#[test]
fn two_materials_keep_their_attributes_and_interface() {
    let input = model("poly/two_materials.poly");
    let (m, _, _) = crate::pipeline::mesh(&input, &approximate(), None, None).unwrap();
    let mut volume: std::collections::BTreeMap<i32, f64> = Default::default();
    let mut faces: std::collections::HashMap<[u32; 3], Vec<i32>> = Default::default();
    for (t, &r) in m.tets.iter().zip(&m.tet_regions) {
        let p = t.map(|v| m.vertices[v as usize]);
        *volume.entry(r).or_default() += crate::geom::orient3d(p[0], p[1], p[2], p[3]) / 6.0;
        for k in 0..4 {
            let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
            f.sort_unstable();
            faces.entry(f).or_default().push(r);
        }
    }
    assert_eq!(volume.keys().copied().collect::<Vec<_>>(), vec![1, 2]);
    for (r, v) in &volume {
        assert!((v - 1.0).abs() < 1e-9, "region {r}: volume {v}");
    }
    let written: std::collections::HashSet<[u32; 3]> = m
        .boundary
        .iter()
        .map(|f| {
            let mut f = *f;
            f.sort_unstable();
            f
        })
        .collect();
    let mut interface_area = 0.0;
    for (f, regions) in &faces {
        assert!(regions.len() <= 2, "face {f:?} of {} tets", regions.len());
        if regions.len() == 2 && regions[0] != regions[1] {
            assert!(written.contains(f), "interface face {f:?} not written");
            let [a, b, c] = f.map(|v| m.vertices[v as usize]);
            interface_area += (b - a).cross(c - a).length() / 2.0;
            assert!(
                a.x == 1.0 && b.x == 1.0 && c.x == 1.0,
                "interface face {f:?} off x = 1"
            );
        }
    }
    assert!(
        (interface_area - 1.0).abs() < 1e-9,
        "interface area {interface_area}"
    );
}

/// Every triangulated model, the noisy elephant scan included, at the defaults: completes
/// with positive tets, the Hausdorff, feature and volume bounds (`check_mesh`), a minimum
/// dihedral angle of at least 15 degrees (12 with a small corner) and radius-edge ratios away
/// from small corners at most 2. Release builds only (about half a minute; minutes in a
/// debug build).
#[test]
fn models_meet_the_bounds_at_the_defaults() {
    if cfg!(debug_assertions) {
        eprintln!("skipped in a debug build: run cargo test --release");
        return;
    }
    let models = [
        "cube", "cross", "star", "oblong", "part", "rotor", "spool", "anchor", "fandisk", "joint",
        "elephant",
    ];
    for name in models {
        let path = format!("off/{name}.off");
        let (mesh, report) = check_mesh(&path, None);
        let s = report.surface.unwrap();
        let q = crate::quality::measure(&mesh).unwrap();
        let floor = if s.n_small_corners == 0 { 15.0 } else { 12.0 };
        assert!(
            q.min_dihedral_deg >= floor,
            "{name}: min dihedral {}",
            q.min_dihedral_deg
        );
        assert!(
            s.max_rho_away_from_small_corners <= 2.0,
            "{name}: max rho away from small corners {}",
            s.max_rho_away_from_small_corners
        );
    }
}

/// star.off (spikes with 35-degree apexes, flat sides) at user sizes: its coplanar samples
/// make nearly flat tets whose circumcentres are ill-conditioned, and a surface centre judged
/// on them once landed 1e-16 from a vertex; the zero-angle facets that followed cascaded until
/// the vertex budget stopped the run (sizes 0.05 to 0.3). Each size completes with the bounds.
#[test]
fn star_completes_at_user_sizes() {
    if cfg!(debug_assertions) {
        eprintln!("skipped in a debug build: run cargo test --release");
        return;
    }
    for size in [0.05, 0.1, 0.3] {
        let (mesh, _) = check_mesh("off/star.off", Some(size));
        let q = crate::quality::measure(&mesh).unwrap();
        assert!(
            q.min_dihedral_deg >= 12.0,
            "size {size}: {}",
            q.min_dihedral_deg
        );
    }
}

/// The report's volume figures are those of the mesh returned (after the improvement moved
/// and flipped it), measured here again from its tets.
#[test]
fn report_describes_the_improved_mesh() {
    let h = 0.3;
    let (mesh, report) = check_mesh("off/cube.off", Some(h));
    assert!(!report.delaunay, "the improvement changed nothing: no test");
    let p = |v: u32| mesh.vertices[v as usize];
    let (mut size, mut lo, mut hi) = (0.0f64, 180.0f64, 0.0f64);
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(p);
        let (_, r) = crate::geom::circumsphere(a, b, c, d).unwrap();
        size = size.max(r / h);
        let (l, u) = crate::geom::min_max_dihedral(a, b, c, d);
        (lo, hi) = (lo.min(l), hi.max(u));
    }
    let mut edges: Vec<[u32; 2]> = mesh
        .tets
        .iter()
        .flat_map(|t| {
            [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
                .map(|(i, j)| [t[i].min(t[j]), t[i].max(t[j])])
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let mut ratios: Vec<f64> = edges
        .iter()
        .map(|e| p(e[0]).distance(p(e[1])) / h)
        .collect();
    ratios.sort_by(f64::total_cmp);
    let close = |x: f64, y: f64| (x - y).abs() <= 1e-9 * y.abs().max(1.0);
    assert_eq!(report.n_tets, mesh.tets.len());
    assert!(
        close(report.max_size_ratio, size),
        "{} {size}",
        report.max_size_ratio
    );
    assert!(close(report.min_dihedral_deg, lo) && close(report.max_dihedral_deg, hi));
    assert!(close(report.edge_ratio_min, ratios[0]));
    assert!(close(report.edge_ratio_median, ratios[ratios.len() / 2]));
    assert!(close(report.edge_ratio_max, ratios[ratios.len() - 1]));
}

/// The shared scans at their defaults (models/scans: organic shapes, coarse folds over the
/// feature angle, thin parts): each completes with every bound of `check_mesh` and the
/// improvement's 20 degrees.
#[test]
fn scans_meet_the_bounds_at_the_defaults() {
    if cfg!(debug_assertions) {
        eprintln!("skipped in a debug build: run cargo test --release");
        return;
    }
    for name in ["bear_bis", "homer", "retinal"] {
        let (mesh, _) = check_mesh(&format!("scans/{name}.off"), None);
        let q = crate::quality::measure(&mesh).unwrap();
        assert!(
            q.min_dihedral_deg >= 19.99,
            "{name}: min dihedral {}",
            q.min_dihedral_deg
        );
    }
}

/// The scans that do not meet every bound yet (issue 36): they complete, with positive
/// tets and the volume, and the figures they reach are kept from getting worse. cheese (holes
/// through a thin body) keeps small corners on its rims, where the boundary strays up to 2.4
/// distance bounds; triceratops strays 1.01 bounds; dino keeps enough of its 1,241 crease
/// edges (a coarse scan's folds) to end at 18.3 degrees.
#[test]
fn thin_scans_complete() {
    if cfg!(debug_assertions) {
        eprintln!("skipped in a debug build: run cargo test --release");
        return;
    }
    for (name, min_dihedral, hausdorff_bounds) in [
        ("cheese", 19.99, 2.6),
        ("triceratops", 19.99, 1.1),
        ("dino", 18.0, 1.0),
    ] {
        let input = model(&format!("scans/{name}.off"));
        let (mesh, _, report) = mesh(&input, &approximate(), None, None).unwrap();
        for t in &mesh.tets {
            let [a, b, c, d] = t.map(|v| mesh.vertices[v as usize]);
            assert!(crate::geom::orient3d(a, b, c, d) > 0.0, "{name}");
        }
        let q = crate::quality::measure(&mesh).unwrap();
        let s = report.surface.unwrap();
        assert!(
            q.min_dihedral_deg >= min_dihedral,
            "{name}: {}",
            q.min_dihedral_deg
        );
        assert!(s.relative_volume_difference.abs() < 5e-3, "{name}: {s:?}");
        assert!(
            s.hausdorff_input_to_output.max(s.hausdorff_output_to_input)
                <= hausdorff_bounds * s.surface_distance,
            "{name}: {s:?}"
        );
    }
}

/// Noise is not a feature: the CAD models keep every crease, the scans lose their short
/// weak or free-hanging ones.
#[test]
fn noise_creases_are_dropped_on_scans_only() {
    use crate::surface::features::{FeatureParams, Features};
    for (name, noise) in [
        ("off/fandisk.off", false),
        ("off/joint.off", false),
        ("off/anchor.off", false),
        ("off/star.off", false),
        ("scans/dino.off", true),
    ] {
        let plc = crate::plc::validate(&model(name)).unwrap();
        let surface = crate::surface::InputSurface::from_plc(&plc);
        let p = FeatureParams::default();
        let h = super::DEFAULT_SPACING_FRACTION * surface.bbox_diagonal();
        let (denoised, dropped) = Features::detect_denoised(&surface, &p, &mut |_| h);
        let all = Features::detect(&surface, &p);
        if noise {
            assert!(
                dropped.edges > 500 && dropped.curves > 200,
                "{name}: {dropped:?}"
            );
            assert_eq!(
                denoised.edges.len() + dropped.edges,
                all.edges.len(),
                "{name}"
            );
        } else {
            assert_eq!(dropped.edges, 0, "{name}");
            assert_eq!(denoised, all, "{name}");
        }
    }
}
