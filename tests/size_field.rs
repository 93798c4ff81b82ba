//! `slivermesh mesh --size-field`: a size field on a background mesh (MEDIT .sol + .mesh,
//! TetGen .mtr + .node/.ele) drives the spacing of the output.

use slivermesh::mesh::TetMesh;
use slivermesh::DVec3;
use std::collections::HashSet;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The field: 10x finer at x = 0 than at x = 1.
fn field(p: DVec3) -> f64 {
    0.02 + 0.18 * p.x
}

/// The unit cube split into n^3 cubes of 6 positively oriented tets (Kuhn split).
fn background(n: usize) -> TetMesh {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| ((k * m + j) * m + i) as u32;
    let mut mesh = TetMesh::default();
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                mesh.vertices
                    .push(DVec3::new(i as f64, j as f64, k as f64) / n as f64);
            }
        }
    }
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |d: usize| id(i + (d & 1), j + ((d >> 1) & 1), k + ((d >> 2) & 1));
                for (a, b) in [(1, 2), (1, 4), (2, 1), (2, 4), (4, 1), (4, 2)] {
                    let mut t = [c(0), c(a), c(a | b), c(7)];
                    let [p, q, r, s] = t.map(|v| mesh.vertices[v as usize]);
                    if (q - p).cross(r - p).dot(s - p) < 0.0 {
                        t.swap(1, 2);
                    }
                    mesh.tets.push(t);
                    mesh.tet_regions.push(0);
                }
            }
        }
    }
    mesh
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!(
        "slivermesh-sizefield-{name}-{}",
        std::process::id()
    ));
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

fn model(name: &str) -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name)
}

fn run(args: &[&std::ffi::OsStr]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_slivermesh"))
        .args(args)
        .output()
        .unwrap()
}

/// Meshes the unit cube with `--size-field field_file` and checks the edges against the field.
fn check_cube(field_file: &Path, out: &Path) {
    let o = run(&[
        "mesh".as_ref(),
        model("poly/cube.poly").as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--size-field".as_ref(),
        field_file.as_os_str(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let m = slivermesh::io::read_mesh(out).unwrap();
    let mut edges = HashSet::new();
    for t in &m.tets {
        for i in 0..4 {
            for j in i + 1..4 {
                edges.insert((t[i].min(t[j]), t[i].max(t[j])));
            }
        }
    }
    let (mut within, mut fine_sum, mut fine_n, mut coarse_sum, mut coarse_n) = (0, 0.0, 0, 0.0, 0);
    for &(a, b) in &edges {
        let (p, q) = (m.vertices[a as usize], m.vertices[b as usize]);
        let mid = (p + q) / 2.0;
        let ratio = p.distance(q) / field(mid);
        if (1.0 / 2.5..=2.5).contains(&ratio) {
            within += 1;
        }
        if mid.x < 0.15 {
            fine_sum += p.distance(q);
            fine_n += 1;
        } else if mid.x > 0.85 {
            coarse_sum += p.distance(q);
            coarse_n += 1;
        }
    }
    let frac = within as f64 / edges.len() as f64;
    let grading = (coarse_sum / coarse_n as f64) / (fine_sum / fine_n as f64);
    println!(
        "{}: {} vertices, {} tets, {} edges, {:.1}% within 2.5x of the field, mean edge \
         x > 0.85 / x < 0.15 = {grading:.2}",
        field_file.display(),
        m.vertices.len(),
        m.tets.len(),
        edges.len(),
        100.0 * frac
    );
    assert!(
        frac >= 0.9,
        "only {:.1}% of the edges within 2.5x",
        100.0 * frac
    );
    assert!(grading > 3.0, "the mesh is not graded: {grading}");
}

fn values_text(mesh: &TetMesh) -> String {
    mesh.vertices
        .iter()
        .map(|&p| format!("{}\n", field(p)))
        .collect()
}

#[test]
fn sol_size_field_grades_the_cube() {
    let dir = temp_dir("sol");
    let bg = background(10);
    slivermesh::io::write_mesh(&dir.join("bg.mesh"), &bg, &[]).unwrap();
    let sol = dir.join("bg.sol");
    let text = format!(
        "MeshVersionFormatted 2\n\nDimension 3\n\nSolAtVertices\n{}\n1 1\n{}\nEnd\n",
        bg.vertices.len(),
        values_text(&bg)
    );
    std::fs::write(&sol, text).unwrap();
    check_cube(&sol, &dir.join("out.mesh"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn mtr_size_field_grades_the_cube() {
    let dir = temp_dir("mtr");
    let bg = background(10);
    slivermesh::io::write_mesh(&dir.join("bg.node"), &bg, &[]).unwrap();
    let mtr = dir.join("bg.mtr");
    std::fs::write(
        &mtr,
        format!("{} 1\n{}", bg.vertices.len(), values_text(&bg)),
    )
    .unwrap();
    check_cube(&mtr, &dir.join("out.mesh"));
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn size_field_errors() {
    let dir = temp_dir("errors");
    let bg = background(2);
    slivermesh::io::write_mesh(&dir.join("bg.mesh"), &bg, &[]).unwrap();
    let sol = dir.join("bg.sol");
    // One value short: the count line says so, the value section ends early.
    let text = format!(
        "MeshVersionFormatted 2\nDimension 3\nSolAtVertices\n{}\n1 1\n{}End\n",
        bg.vertices.len() - 1,
        values_text(&bg)
            .lines()
            .skip(1)
            .map(|l| format!("{l}\n"))
            .collect::<String>()
    );
    std::fs::write(&sol, text).unwrap();
    let out = dir.join("out.mesh");
    let cube = model("poly/cube.poly");
    let o = run(&[
        "mesh".as_ref(),
        cube.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--size-field".as_ref(),
        sol.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(
        err.contains("bg.sol") && err.contains("26 values") && err.contains("27 vertices"),
        "{err}"
    );
    let o = run(&[
        "mesh".as_ref(),
        cube.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--size".as_ref(),
        "0.1".as_ref(),
        "--size-field".as_ref(),
        sol.as_os_str(),
    ]);
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(!o.status.success());
    assert!(err.contains("--size"), "{err}");
    std::fs::remove_dir_all(&dir).ok();
}
