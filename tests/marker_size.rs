//! `--marker-size ID:H` (and `Mesher::set_marker_size`): the boundary triangles of the input
//! facets of marker ID get spacing about H, the spacing grows away from them
//! (`refine::MARKER_GRADING`), the rest of the boundary keeps its own.

mod common;

use common::size_caps::run;
use glam::DVec3;
use slivermesh::mesh::TetMesh;
use std::path::{Path, PathBuf};

const H: f64 = 0.05;

fn model(name: &str) -> PathBuf {
    common::models_dir().join(name)
}

fn mesh_with(input: &Path, mode: &str, extra: &[&str]) -> TetMesh {
    let dir = std::env::temp_dir().join(format!("slivermesh-markersize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let stem = input.file_stem().unwrap().to_str().unwrap();
    let tag = extra.join("_").replace([':', '-'], "");
    let out = dir.join(format!("{stem}-{mode}-{tag}.mesh"));
    let mut args = vec![
        "mesh",
        input.to_str().unwrap(),
        "-o",
        out.to_str().unwrap(),
        "--surface",
        mode,
    ];
    args.extend_from_slice(extra);
    let o = run(&args);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let mesh = slivermesh::io::read_mesh(&out).unwrap();
    let _ = std::fs::remove_file(&out);
    mesh
}

/// Count and mean edge length of the boundary triangles that `pick` (marker, corners) keeps.
fn boundary_edges(mesh: &TetMesh, pick: impl Fn(i32, [DVec3; 3]) -> bool) -> (usize, f64) {
    let (mut n, mut sum) = (0, 0.0);
    for (t, &m) in mesh.boundary.iter().zip(&mesh.boundary_markers) {
        let p = t.map(|v| mesh.vertices[v as usize]);
        if pick(m, p) {
            n += 1;
            sum += (p[0].distance(p[1]) + p[1].distance(p[2]) + p[2].distance(p[0])) / 3.0;
        }
    }
    (n, if n > 0 { sum / n as f64 } else { f64::NAN })
}

fn centroid(p: [DVec3; 3]) -> DVec3 {
    (p[0] + p[1] + p[2]) / 3.0
}

/// two_materials.poly: two unit cubes side by side; the interface x = 1 has marker 2, the
/// outer faces marker 1. With `--marker-size 2:0.05` the interface's triangles have a mean
/// edge within 1.5x of H (both ways), and marker 1's triangles far from it (|x - 1| > 0.7) are
/// much coarser: over 3 times with `--size 0.25`, over 1.5 times with the automatic spacing
/// (approximate mode's default spacing, diagonal / 25 = 0.098, is only twice H).
#[test]
fn marker_size_refines_the_marked_facets_only() {
    let input = model("poly/two_materials.poly");
    for mode in ["keep", "approximate"] {
        for (size, ratio) in [(None, 1.5), (Some("0.25"), 3.0)] {
            let mut extra = vec![];
            if let Some(s) = size {
                extra.extend(["--size", s]);
            }
            let plain = mesh_with(&input, mode, &extra);
            extra.extend(["--marker-size", "2:0.05"]);
            let capped = mesh_with(&input, mode, &extra);
            let marked = |m: &TetMesh| boundary_edges(m, |k, _| k == 2);
            let far =
                |m: &TetMesh| boundary_edges(m, |k, p| k == 1 && (centroid(p).x - 1.0).abs() > 0.7);
            let (n2, e2) = marked(&capped);
            let (n1, e1) = far(&capped);
            println!(
                "{mode} {size:?}: marker 2 {:?} -> ({n2}, {e2:.4}); marker 1 far {:?} -> \
                 ({n1}, {e1:.4})",
                marked(&plain),
                far(&plain)
            );
            assert!(
                e2 < 1.5 * H && e2 > H / 1.5,
                "{mode}: marker 2's mean edge {e2}"
            );
            assert!(e1 > ratio * e2, "{mode}: marker 1 far {e1}, marker 2 {e2}");
            assert!(
                n2 > 2 * marked(&plain).0,
                "{mode}: {n2} vs {:?}",
                marked(&plain)
            );
        }
    }
}

/// An outer face as the marked one: the unit cube with its x = 0 face marked 3, the others 1.
/// Its triangles get about H; the faces' triangles beyond x = 0.6 are at least 3 times
/// coarser (with `--size 0.3`).
#[test]
fn marker_size_on_an_outer_face() {
    let dir = std::env::temp_dir().join(format!("slivermesh-markersize-in-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let input = dir.join("cube3.poly");
    let cube = std::fs::read_to_string(model("poly/cube.poly")).unwrap();
    // The fifth facet (x = 0: 1 5 7 3) gets marker 3.
    let mut facets = 0;
    let text: Vec<String> = cube
        .lines()
        .map(|l| {
            if l == "1 0 1" {
                facets += 1;
                if facets == 5 {
                    return "1 0 3".to_string();
                }
            }
            l.to_string()
        })
        .collect();
    assert_eq!(facets, 6);
    std::fs::write(&input, text.join("\n") + "\n").unwrap();
    for mode in ["keep", "approximate"] {
        let m = mesh_with(&input, mode, &["--size", "0.3", "--marker-size", "3:0.05"]);
        let (n3, e3) = boundary_edges(&m, |k, p| {
            assert!(k != 3 || p.iter().all(|q| q.x.abs() < 1e-9));
            k == 3
        });
        let (n1, e1) = boundary_edges(&m, |k, p| k == 1 && centroid(p).x > 0.6);
        println!("{mode}: marker 3 ({n3}, {e3:.4}), marker 1 beyond x = 0.6 ({n1}, {e1:.4})");
        assert!(
            e3 < 1.5 * H && e3 > H / 1.5,
            "{mode}: marker 3's mean edge {e3}"
        );
        assert!(e1 > 3.0 * e3, "{mode}: {e1} vs {e3}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Approximate mode on a plain surface (cube.off: the reader numbers the merged facets 1..6,
/// which are no labels, so the output's markers are the smooth patches): the cap still applies
/// to the input facet of that number. Facet 2 is the face x = -1.
#[test]
fn marker_size_applies_where_markers_do_not_survive() {
    let input = model("off/cube.off");
    let options = slivermesh::io::ReadOptions {
        merge_coplanar: true,
    };
    let plc = slivermesh::io::read_plc(&input, &options).unwrap();
    assert_eq!(plc.facets.len(), 6);
    assert!(plc.facets[1].polygons[0]
        .iter()
        .all(|&v| plc.vertices[v as usize].x == -1.0));
    let m = mesh_with(&input, "approximate", &["--marker-size", "2:0.05"]);
    let on = |x: f64| move |_: i32, p: [DVec3; 3]| p.iter().all(|q| (q.x - x).abs() < 1e-9);
    let (n_marked, e_marked) = boundary_edges(&m, on(-1.0));
    let (n_opposite, e_opposite) = boundary_edges(&m, on(1.0));
    println!("x = -1: ({n_marked}, {e_marked:.4}); x = 1: ({n_opposite}, {e_opposite:.4})");
    assert!(e_marked < 1.5 * H && e_marked > H / 1.5, "{e_marked}");
    assert!(e_opposite > 2.0 * e_marked, "{e_opposite} vs {e_marked}");
}

#[test]
fn marker_size_errors_name_the_id_and_the_option() {
    common::size_caps::check_unknown_ids_and_bad_values("--marker-size", "marker");
}

#[test]
fn api_marker_size_checks_h_and_the_id() {
    let mut m = slivermesh::api::Mesher::new();
    let e = m.set_marker_size(2, 0.0).unwrap_err().to_string();
    assert!(e.contains("marker 2") && e.contains("h = 0"), "{e}");
    assert!(m.set_marker_size(2, f64::NAN).is_err());
    assert!(m.set_marker_size(2, f64::INFINITY).is_err());
    let input =
        slivermesh::io::read_plc(&model("poly/two_materials.poly"), &Default::default()).unwrap();
    let mut m = slivermesh::api::Mesher::from_plc(input).unwrap();
    m.set_marker_size(5, 0.1).unwrap();
    let e = m.refine().unwrap_err().to_string();
    assert!(
        e.contains("marker 5") && e.contains("its markers: 1, 2"),
        "{e}"
    );
    // Given again, the size replaces the old one; a marker the input has meshes.
    let input =
        slivermesh::io::read_plc(&model("poly/two_materials.poly"), &Default::default()).unwrap();
    let mut m = slivermesh::api::Mesher::from_plc(input).unwrap();
    m.set_marker_size(2, 0.2)
        .unwrap()
        .set_marker_size(2, 0.1)
        .unwrap();
    m.refine().unwrap();
}
