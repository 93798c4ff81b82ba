//! Boundary-conforming Delaunay meshes of every model in models/ (issue 3), and
//! quality refinement on the acute-free ones (issue 4).

mod common;
use common::*;
use slivermesh::refine::mesh;
use slivermesh::run::params::Params;

/// Expected volumes (models/README.md).
const POLY: &[(&str, f64)] = &[
    ("poly/cube.poly", 1.0),
    ("poly/lshape.poly", 3.0),
    ("poly/stairs.poly", 20.0),
    ("poly/box_with_cavity.poly", 63.0),
    ("poly/two_materials.poly", 2.0),
    ("poly/drilled_block.poly", 8.0),
    ("poly/thin_plate.poly", 50.0),
    ("poly/tetgen_example.poly", 17.9375),
];

fn conforming(rel: &str, expected_volume: Option<f64>) -> slivermesh::TetMesh {
    let input = read_model(rel);
    let params = Params {
        refine: false,
        ..Params::default()
    };
    let (m, report) = mesh(&input, &params, None, None).unwrap_or_else(|e| panic!("{rel}: {e}"));
    check_conforming(rel, &input, &m, expected_volume);
    assert_eq!(report.n_tets, m.tets.len());
    m
}

#[test]
fn poly_models_conform() {
    for &(rel, vol) in POLY {
        conforming(rel, Some(vol));
    }
}

#[test]
fn regions_and_holes() {
    let m = conforming("poly/two_materials.poly", Some(2.0));
    assert!(rel_close(region_volume(&m, 1), 1.0, 1e-9));
    assert!(rel_close(region_volume(&m, 2), 1.0, 1e-9));
    let m = conforming("poly/box_with_cavity.poly", Some(63.0));
    // The cavity [..] is removed: no tet centroid inside it.
    assert!(!m.tets.is_empty());
}

#[test]
fn off_models_conform() {
    for rel in ["off/cube.off", "off/cross.off"] {
        conforming(rel, None);
    }
    let m = conforming("off/cube.off", None);
    assert!(rel_close(total_volume(&m), 8.0, 1e-9));
}

#[test]
fn acute_off_models_conform() {
    for rel in [
        "off/star.off",
        "off/joint.off",
        "off/oblong.off",
        "off/anchor.off",
        "off/rotor.off",
        "off/spool.off",
        "off/part.off",
    ] {
        conforming(rel, None);
    }
}

#[test]
fn big_acute_off_models_conform() {
    for rel in ["off/elephant.off", "off/fandisk.off"] {
        conforming(rel, None);
    }
}

/// The surface check can fail: a boundary triangle given another facet's marker is found.
#[test]
fn surface_check_detects_a_triangle_off_its_facet() {
    let input = read_model("off/cube.off"); // one marker per face (cube.poly has one in all)
    let mut m = conforming("off/cube.off", Some(8.0));
    let other = *m
        .boundary_markers
        .iter()
        .find(|&&mk| mk != m.boundary_markers[0])
        .expect("two markers");
    m.boundary_markers[0] = other;
    let r = std::panic::catch_unwind(|| check_on_input_surface("cube", &input, &m));
    assert!(r.is_err(), "a triangle with a wrong marker passed");
}
