//! The improvement pass (issue 12) on the shared models, through the API in keep mode with
//! default spacing: no flat or inverted tet, the boundary still the input surface (area per
//! marker and volume to 1e-9, every boundary vertex on it), regions kept, quality bounds on the
//! acute-free models, `improve = 0` keeps the Delaunay mesh, and determinism.

mod common;
use common::*;
use slivermesh::api::Mesher;
use slivermesh::geom::TetQuality;
use slivermesh::improve;
use slivermesh::TetMesh;

fn mesh(rel: &str, improve_on: bool) -> (TetMesh, slivermesh::run::report::Report) {
    let mut m = Mesher::from_plc(read_model(rel)).unwrap();
    m.set_param("improve", if improve_on { 1.0 } else { 0.0 })
        .unwrap();
    m.refine().unwrap_or_else(|e| panic!("{rel}: {e}"));
    let out = m.take_output().unwrap();
    (out.mesh, out.report)
}

/// Everything the pass must keep, and no degenerate tet.
fn check_kept(rel: &str, m: &TetMesh) {
    let input = read_model(rel);
    check_orientation(m);
    improve::check_no_degenerate(m).unwrap();
    check_boundary_faces_are_tet_faces(m);
    let want = facet_area_by_marker(&input);
    let got = boundary_area_by_marker(m);
    assert_eq!(want.len(), got.len(), "{rel}: markers");
    for (mk, a) in &want {
        let g = got.get(mk).copied().unwrap_or(0.0);
        assert!(
            rel_close(g, *a, 1e-9),
            "{rel}: marker {mk}: area {g}, facets {a}"
        );
    }
    check_on_input_surface(rel, &input, m);
    // Input vertices keep their ids and places; deleted ones are dropped from the output.
    assert_eq!(
        m.vertices[..input.vertices.len()],
        input.vertices[..],
        "{rel}: input vertices"
    );
    let mut used = vec![false; m.vertices.len()];
    m.tets
        .iter()
        .flatten()
        .for_each(|&v| used[v as usize] = true);
    assert!(used.iter().all(|&u| u), "{rel}: a vertex no tet uses");
    if let Some(v) = enclosed_volume(&input) {
        let vol = total_volume(m);
        assert!(rel_close(vol, v, 1e-9), "{rel}: volume {vol}, expected {v}");
    }
}

fn dihedral_range(m: &TetMesh) -> (f64, f64) {
    m.tets.iter().fold((180.0f64, 0.0f64), |(lo, hi), t| {
        let p = t.map(|v| m.vertices[v as usize]);
        let q = TetQuality::of(p[0], p[1], p[2], p[3]);
        (lo.min(q.min_dihedral), hi.max(q.max_dihedral))
    })
}

const ACUTE_FREE: &[&str] = &[
    "poly/cube.poly",
    "poly/lshape.poly",
    "poly/stairs.poly",
    "poly/box_with_cavity.poly",
    "poly/two_materials.poly",
    "poly/drilled_block.poly",
    "poly/thin_plate.poly",
    "poly/tetgen_example.poly",
    "off/cube.off",
    "off/cross.off",
];

#[test]
fn acute_free_models_reach_25_to_160_degrees() {
    for &rel in ACUTE_FREE {
        let (m, r) = mesh(rel, true);
        check_kept(rel, &m);
        let (lo, hi) = dihedral_range(&m);
        assert!(
            lo >= 25.0 && hi <= 160.0,
            "{rel}: dihedral {lo:.3} / {hi:.3}"
        );
        assert!(
            (r.min_dihedral_deg - lo).abs() < 1e-9,
            "{rel}: report {}",
            r.min_dihedral_deg
        );
        assert_eq!(r.n_tets, m.tets.len());
    }
}

/// Largest radius-edge ratio of `m`'s tets, measured on the mesh.
fn max_rho(m: &TetMesh) -> f64 {
    m.tets
        .iter()
        .map(|t| {
            let p = t.map(|v| m.vertices[v as usize]);
            slivermesh::geom::radius_edge_ratio(p[0], p[1], p[2], p[3])
        })
        .fold(0.0, f64::max)
}

/// The improvement keeps rho0 (2 by default) where refinement met it: on every acute-free
/// model, at its defaults and at a fixed size of 1/20 of its extent, the output's largest
/// radius-edge ratio is at most 2 and its smallest dihedral angle at least 15 degrees (before
/// the veto: up to 4.59 at box_with_cavity's --size 0.2).
#[test]
fn acute_free_models_keep_rho0() {
    for &rel in ACUTE_FREE {
        let input = read_model(rel);
        let (lo, hi) = input.vertices.iter().fold(
            (slivermesh::DVec3::INFINITY, slivermesh::DVec3::NEG_INFINITY),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        let size = (hi - lo).max_element() / 20.0;
        for size in [None, Some(size)] {
            let mut m = Mesher::from_plc(input.clone()).unwrap();
            if let Some(h) = size {
                m.set_spacing_constant(h).unwrap();
            }
            m.refine().unwrap_or_else(|e| panic!("{rel}: {e}"));
            let out = m.take_output().unwrap();
            let rho = max_rho(&out.mesh);
            let (dmin, _) = dihedral_range(&out.mesh);
            assert!(
                rho <= 2.0 + 1e-9 && dmin >= 15.0,
                "{rel} at size {size:?}: max rho {rho:.3}, min dihedral {dmin:.2}"
            );
        }
    }
}

#[test]
fn regions_keep_their_volume() {
    let (m, _) = mesh("poly/two_materials.poly", true);
    assert!(rel_close(region_volume(&m, 1), 1.0, 1e-9));
    assert!(rel_close(region_volume(&m, 2), 1.0, 1e-9));
}

/// improve = 0: the refinement's Delaunay mesh as it is (when it has no flat tet), reported so.
#[test]
fn no_improve_keeps_the_delaunay_mesh() {
    for rel in ["poly/two_materials.poly", "off/cross.off"] {
        let (m, r) = mesh(rel, false);
        check_delaunay(&m);
        check_kept(rel, &m);
        assert!(r.delaunay, "{rel}");
        let (m2, r2) = mesh(rel, true);
        assert!(!r2.delaunay || m2 == m, "{rel}");
        assert!(r2.min_dihedral_deg >= r.min_dihedral_deg, "{rel}");
    }
}

#[test]
fn deterministic() {
    let (a, _) = mesh("poly/tetgen_example.poly", true);
    let (b, _) = mesh("poly/tetgen_example.poly", true);
    assert_eq!(a, b);
}

/// The acute models: no degenerate tet, the surface kept, the improvement helps, and the
/// dihedral angles within [`floor_deg`, `ceiling_deg`] (a little outside what the improver
/// reaches today; the floors are above tetgen -pq1.414 at a similar tet count on rotor, spool,
/// elephant, part, the ceilings below its maxima on all but anchor; before the improver's
/// vertex insertion and the refinement's refusal to split flat tets, rotor, spool and anchor
/// ended at 0.00 degrees).
fn acute(rel: &str, floor_deg: f64, ceiling_deg: f64) {
    let (m, r) = mesh(rel, true);
    check_kept(rel, &m);
    let (lo, hi) = dihedral_range(&m);
    assert!(
        lo >= r.dihedral_before_improve_deg[0],
        "{rel}: {lo} < before"
    );
    assert!(lo >= floor_deg, "{rel}: min dihedral {lo} < {floor_deg}");
    assert!(
        hi <= ceiling_deg,
        "{rel}: max dihedral {hi} > {ceiling_deg}"
    );
}

#[test]
fn acute_rotor() {
    acute("off/rotor.off", 6.5, 170.0);
}
#[test]
fn acute_part() {
    acute("off/part.off", 3.0, 172.0);
}
#[test]
fn acute_fandisk_joint() {
    acute("off/fandisk.off", 17.0, 160.0);
    acute("off/joint.off", 9.0, 165.0);
}
#[test]
fn acute_others() {
    for (rel, floor_deg, ceiling_deg) in [
        ("off/anchor.off", 0.3, 177.0),
        ("off/elephant.off", 12.0, 160.0),
        ("off/oblong.off", 12.0, 160.0),
        ("off/spool.off", 12.0, 165.0),
        ("off/star.off", 30.0, 140.0),
    ] {
        acute(rel, floor_deg, ceiling_deg);
    }
}

/// The radius-edge repair (`improve::Options::repair_rho`, what the zones of a partitioned
/// run use) on a serial mesh of the cube held to a tighter bound than it was refined for:
/// vertices go in inside and on the boundary facets (splitting boundary triangles), and the
/// mesh stays a conforming tiling of the same box with its boundary triangles on its sides.
#[test]
fn rho_repair_puts_vertices_in_where_tets_are_over_the_bound() {
    let input = read_model("poly/cube.poly");
    let spacing = slivermesh::run::spacing::ConstantSpacing(0.2);
    let params = slivermesh::run::params::Params::default();
    let (mesh, _, _) = slivermesh::pipeline::mesh(&input, &params, Some(&spacing), None).unwrap();
    let bound = 1.3;
    let over = |m: &TetMesh| {
        (m.tets.iter())
            .filter(|t| {
                let p = t.map(|v| m.vertices[v as usize]);
                slivermesh::geom::radius_edge_ratio(p[0], p[1], p[2], p[3]) > bound
            })
            .count()
    };
    let opts = improve::Options {
        repair_rho: bound,
        keep_rho: bound,
        ..improve::Options::default()
    };
    let (out, stats) = improve::improve(&mesh, Some(&input), &opts);
    println!("over {bound}: {} -> {}, {stats:?}", over(&mesh), over(&out));
    assert!(
        stats.rho_repairs > 0 && over(&out) < over(&mesh),
        "{stats:?}"
    );
    assert!(out.vertices.len() > mesh.vertices.len());
    assert!(
        out.boundary.len() > mesh.boundary.len(),
        "no boundary triangle split"
    );
    check_orientation(&out);
    improve::check_no_degenerate(&out).unwrap();
    check_boundary_faces_are_tet_faces(&out);
    let volume = total_volume(&out);
    assert!((volume - 1.0).abs() < 1e-12, "volume {volume}");
    let mut area = 0.0;
    for b in &out.boundary {
        let [x, y, z] = b.map(|v| out.vertices[v as usize]);
        area += 0.5 * (y - x).cross(z - x).length();
        let on_side = |p: slivermesh::DVec3| p.to_array().iter().any(|&c| c == 0.0 || c == 1.0);
        assert!(
            [x, y, z].into_iter().all(on_side),
            "{b:?} off the cube's sides"
        );
    }
    assert!((area - 6.0).abs() < 1e-12, "boundary area {area}");
    let boundary = boundary_keys(&out);
    for (f, &k) in &out.face_counts() {
        assert!(
            k == 2 || (k == 1 && boundary.contains(f)),
            "face {f:?} in {k} tets"
        );
    }
}
