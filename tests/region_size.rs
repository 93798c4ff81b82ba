//! `--region-size ID:H` (and `Mesher::set_region_size`): the tets of one region get spacing at
//! most H, the other regions keep theirs.

mod common;

use common::size_caps::run;
use slivermesh::mesh::TetMesh;
use std::path::PathBuf;

fn model(name: &str) -> PathBuf {
    common::models_dir().join(name)
}

/// Mean edge length (edges counted once per tet) of the tets of each region: (region, count,
/// mean); region 1 (x in [0, 1]) only over its tets at least 0.5 away from region 2 (x >= 1),
/// past the grading next to it.
fn mean_edges(mesh: &TetMesh) -> Vec<(i32, usize, f64)> {
    let mut acc: Vec<(i32, usize, f64)> = vec![];
    for (t, &r) in mesh.tets.iter().zip(&mesh.tet_regions) {
        let p = t.map(|v| mesh.vertices[v as usize]);
        if r == 1 && (p[0] + p[1] + p[2] + p[3]).x / 4.0 > 0.5 {
            continue;
        }
        let mut sum = 0.0;
        for i in 0..4 {
            for j in i + 1..4 {
                sum += p[i].distance(p[j]);
            }
        }
        match acc.iter_mut().find(|a| a.0 == r) {
            Some(a) => {
                a.1 += 1;
                a.2 += sum / 6.0;
            }
            None => acc.push((r, 1, sum / 6.0)),
        }
    }
    acc.sort_by_key(|a| a.0);
    acc.into_iter()
        .map(|(r, n, s)| (r, n, s / n as f64))
        .collect()
}

fn mesh_with(mode: &str, extra: &[&str]) -> TetMesh {
    let dir = std::env::temp_dir().join(format!("slivermesh-regionsize-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let out = dir.join(format!("{mode}-{}.mesh", extra.join("_").replace(':', "-")));
    let input = model("poly/two_materials.poly");
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

/// two_materials.poly: two unit cubes side by side, regions 1 and 2. With region 2 limited to
/// H = 0.05 its tets' mean edge is below 1.5 H; region 1 keeps the spacing away from region 2:
/// with `--size 0.25` its mean edge there is over 3 times region 2's, with the automatic
/// spacing (graded from the fine interface) over 1.5 times.
#[test]
fn region_size_refines_one_region_only() {
    const H: f64 = 0.05;
    for mode in ["keep", "approximate"] {
        for (size, ratio) in [(None, 1.5), (Some("0.25"), 3.0)] {
            let mut extra = vec![];
            if let Some(s) = size {
                extra.extend(["--size", s]);
            }
            let plain = mean_edges(&mesh_with(mode, &extra));
            extra.extend(["--region-size", "2:0.05"]);
            let limited = mean_edges(&mesh_with(mode, &extra));
            println!("{mode} {size:?}: without {plain:?}, with --region-size 2:{H} {limited:?}");
            let [(1, _, e1), (2, n2, e2)] = limited[..] else {
                panic!("{limited:?}")
            };
            assert!(e2 < 1.5 * H, "{mode}: region 2's mean edge {e2} vs H = {H}");
            assert!(e1 > ratio * e2, "{mode}: region 1 {e1}, region 2 {e2}");
            assert!(n2 > 5 * plain[1].1, "{mode}: {n2} tets vs {:?}", plain[1]);
        }
    }
}

#[test]
fn region_size_errors_name_the_id_and_the_option() {
    common::size_caps::check_unknown_ids_and_bad_values("--region-size", "region");
}

#[test]
fn api_region_size_checks_h_and_the_id() {
    let mut m = slivermesh::api::Mesher::new();
    let e = m.set_region_size(2, 0.0).unwrap_err().to_string();
    assert!(e.contains("region 2") && e.contains("h = 0"), "{e}");
    assert!(m.set_region_size(2, f64::NAN).is_err());
    let input =
        slivermesh::io::read_plc(&model("poly/two_materials.poly"), &Default::default()).unwrap();
    let mut m = slivermesh::api::Mesher::from_plc(input).unwrap();
    m.set_region_size(5, 0.1).unwrap();
    let e = m.refine().unwrap_err().to_string();
    assert!(
        e.contains("region 5") && e.contains("its regions: 1, 2"),
        "{e}"
    );
}
