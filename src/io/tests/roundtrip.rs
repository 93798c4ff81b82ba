//! Write, read back, same mesh: for every writer, through the extension dispatch.

use super::TempDir;
use crate::io::{read_mesh, vtu, write_mesh, CellField};
use crate::mesh::TetMesh;
use glam::DVec3;

/// An n×n×n block of cubes, each split into 6 tets around its main diagonal (Kuhn), with
/// awkward coordinates (irrational offsets, tiny and huge magnitudes, -0), region = cube layer
/// (including 0 and a negative value) and boundary triangles on the block's faces with one
/// marker per side (including 0 and a negative one).
pub(crate) fn sample_mesh(n: u32) -> TetMesh {
    let id = |i: u32, j: u32, k: u32| (k * (n + 1) + j) * (n + 1) + i;
    let mut m = TetMesh::default();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let p = DVec3::new(i as f64, j as f64, k as f64) * std::f64::consts::FRAC_1_SQRT_2
                    + DVec3::new(1e-300, -0.0, 1.0 / 3.0);
                m.vertices.push(p);
            }
        }
    }
    m.vertices[1].x = 1e300;
    m.vertices[2].y = -0.0;
    let kuhn: [[usize; 4]; 6] = [
        [0, 1, 3, 7],
        [0, 1, 5, 7],
        [0, 2, 3, 7],
        [0, 2, 6, 7],
        [0, 4, 5, 7],
        [0, 4, 6, 7],
    ];
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c: Vec<u32> = (0..8)
                    .map(|b| id(i + (b & 1), j + ((b >> 1) & 1), k + ((b >> 2) & 1)))
                    .collect();
                for t in kuhn {
                    m.tets.push([c[t[0]], c[t[1]], c[t[2]], c[t[3]]]);
                    m.tet_regions.push(k as i32 - 1);
                }
            }
        }
    }
    // Boundary: the z = 0 and x = n faces, two triangles per square.
    for j in 0..n {
        for i in 0..n {
            let (a, b, c, d) = (
                id(i, j, 0),
                id(i + 1, j, 0),
                id(i + 1, j + 1, 0),
                id(i, j + 1, 0),
            );
            m.boundary.extend([[a, c, b], [a, d, c]]);
            m.boundary_markers.extend([0, 0]);
            let (a, b, c, d) = (
                id(n, i, j),
                id(n, i + 1, j),
                id(n, i + 1, j + 1),
                id(n, i, j + 1),
            );
            m.boundary.extend([[a, b, c], [a, c, d]]);
            m.boundary_markers.extend([-7, 42]);
        }
    }
    m
}

fn assert_bitwise_equal(a: &TetMesh, b: &TetMesh, what: &str) {
    assert_eq!(a.vertices.len(), b.vertices.len(), "{what}");
    for (i, (p, q)) in a.vertices.iter().zip(&b.vertices).enumerate() {
        let bits = |v: DVec3| [v.x.to_bits(), v.y.to_bits(), v.z.to_bits()];
        assert_eq!(bits(*p), bits(*q), "{what}: vertex {i} {p:?} vs {q:?}");
    }
    assert_eq!(a.tets, b.tets, "{what}: tets");
    assert_eq!(a.tet_regions, b.tet_regions, "{what}: regions");
    assert_eq!(a.boundary, b.boundary, "{what}: boundary");
    assert_eq!(a.boundary_markers, b.boundary_markers, "{what}: markers");
}

#[test]
fn medit_msh_and_tetgen_round_trip_exactly() {
    let m = sample_mesh(3);
    let dir = TempDir::new("rt");
    for name in ["a.mesh", "b.msh", "c.ele", "d.node", "e.FACE", "f.MESH"] {
        let p = dir.path(name);
        write_mesh(&p, &m, &[]).unwrap_or_else(|e| panic!("{e}"));
        let back = read_mesh(&p).unwrap_or_else(|e| panic!("{e}"));
        assert_bitwise_equal(&m, &back, name);
    }
    for ext in ["node", "ele", "face"] {
        assert!(dir.path(&format!("c.{ext}")).exists(), "c.{ext}");
    }
}

#[test]
fn vtu_round_trips_tets_regions_and_fields() {
    let m = sample_mesh(2);
    let q: Vec<f64> = (0..m.tets.len()).map(|i| (i as f64).sqrt() / 7.0).collect();
    let r: Vec<f64> = (0..m.tets.len()).map(|i| -(i as f64) * 1e-20).collect();
    let fields = [
        CellField {
            name: "rho",
            values: &q,
        },
        CellField {
            name: "sigma",
            values: &r,
        },
    ];
    let dir = TempDir::new("vtu");
    let p = dir.path("m.vtu");
    write_mesh(&p, &m, &fields).unwrap();
    let d = vtu::read_vtu(&p).unwrap();
    let expect = TetMesh {
        boundary: vec![],
        boundary_markers: vec![],
        ..m.clone()
    };
    assert_bitwise_equal(&expect, &d.mesh, "vtu");
    assert_eq!(d.cell_fields.len(), 2);
    assert_eq!(d.cell_fields[0].0, "rho");
    assert_eq!(d.cell_fields[0].1, q);
    assert_eq!(d.cell_fields[1].0, "sigma");
    assert_eq!(d.cell_fields[1].1, r);
    assert_bitwise_equal(&expect, &read_mesh(&p).unwrap(), "vtu via read_mesh");
}

#[test]
fn empty_mesh_round_trips() {
    let m = TetMesh::default();
    let dir = TempDir::new("empty");
    for name in ["a.mesh", "b.msh", "c.ele", "d.vtu"] {
        let p = dir.path(name);
        write_mesh(&p, &m, &[]).unwrap();
        assert_eq!(read_mesh(&p).unwrap(), m, "{name}");
    }
}

#[test]
fn writers_reject_inconsistent_meshes_and_unknown_extensions() {
    let dir = TempDir::new("bad");
    let mut m = sample_mesh(1);
    m.tets[0][2] = 99;
    for name in ["a.vtu", "a.mesh", "a.msh", "a.ele"] {
        let e = write_mesh(&dir.path(name), &m, &[]).unwrap_err();
        assert!(e.message.contains("tet 0"), "{e}");
        assert!(!dir.path(name).exists(), "nothing written for {name}");
    }
    let mut sink = Vec::new();
    assert!(crate::io::gmsh::format_msh(&mut sink, &m).is_err());
    assert!(crate::io::medit::format_medit(&mut sink, &m).is_err());
    assert!(crate::io::tetgen::format_ele(&mut sink, &m).is_err());
    assert!(vtu::format_vtu(&mut sink, &m, &[]).is_err());
    let m = sample_mesh(1);
    let short = [1.0];
    let e = write_mesh(
        &dir.path("a.vtu"),
        &m,
        &[CellField {
            name: "q",
            values: &short,
        }],
    )
    .unwrap_err();
    assert!(e.message.contains("cell field 'q' has 1 values"), "{e}");
    let mut m2 = sample_mesh(1);
    m2.boundary_markers.pop();
    assert!(write_mesh(&dir.path("a.msh"), &m2, &[]).is_err());
    let e = write_mesh(&dir.path("a.obj"), &m, &[]).unwrap_err();
    assert!(
        e.message.contains(".vtu, .mesh, .msh, .node, .ele, .face"),
        "{e}"
    );
    let e = read_mesh(&dir.path("a.stl")).unwrap_err();
    assert!(e.message.contains("unsupported mesh format"), "{e}");
    let e = write_mesh(&dir.path("no/such/dir/a.vtu"), &m, &[]).unwrap_err();
    assert!(e.message.contains("cannot write"), "{e}");
}

/// Writes the sample mesh in every format to `$SLIVERMESH_IO_SAMPLES` for checks by external
/// readers (meshio, gmsh, VTK): `cargo test --lib write_samples -- --ignored`.
#[test]
#[ignore]
fn write_samples_for_external_readers() {
    let Ok(dir) = std::env::var("SLIVERMESH_IO_SAMPLES") else {
        return;
    };
    let dir = std::path::PathBuf::from(dir);
    std::fs::create_dir_all(&dir).unwrap();
    let m = sample_mesh(3);
    let q: Vec<f64> = (0..m.tets.len()).map(|i| i as f64 / 3.0).collect();
    let fields = [CellField {
        name: "quality",
        values: &q,
    }];
    for name in ["sample.vtu", "sample.mesh", "sample.msh", "sample.ele"] {
        write_mesh(&dir.join(name), &m, &fields).unwrap();
    }
}

/// Reads every mesh file in `$SLIVERMESH_IO_SAMPLES` (e.g. files that gmsh or meshio wrote from
/// the samples) and compares it with the sample mesh: `cargo test --lib read_samples -- --ignored
/// --nocapture`.
#[test]
#[ignore]
fn read_samples_from_external_writers() {
    let Ok(dir) = std::env::var("SLIVERMESH_IO_SAMPLES") else {
        return;
    };
    let m = sample_mesh(3);
    let mut names: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| {
            let ext = p.extension().and_then(|e| e.to_str()).unwrap_or("");
            ["vtu", "mesh", "msh", "ele"].contains(&ext)
        })
        .collect();
    names.sort();
    for p in names {
        match read_mesh(&p) {
            Ok(r) => eprintln!(
                "{}: {} vertices (same: {}), {} tets (same: {}), regions same: {}, {} boundary \
                 (same: {}), markers same: {}",
                p.display(),
                r.vertices.len(),
                r.vertices == m.vertices,
                r.tets.len(),
                r.tets == m.tets,
                r.tet_regions == m.tet_regions,
                r.boundary.len(),
                r.boundary == m.boundary,
                r.boundary_markers == m.boundary_markers
            ),
            Err(e) => eprintln!("{e}"),
        }
    }
}

/// `F` as the writers printed floats before zmij: Display for integral values below 1e15,
/// `{:?}` for the rest.
fn std_text(x: f64) -> String {
    if x.is_finite() && x.fract() == 0.0 && x.abs() < 1e15 {
        format!("{x}")
    } else {
        format!("{x:?}")
    }
}

#[test]
fn float_text_is_the_shortest_round_trip_in_the_std_notation() {
    use crate::io::text::F;
    use rand::{Rng, SeedableRng};
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(11);
    let mut values = vec![
        0.0,
        -0.0,
        1.0,
        -3.0,
        0.1,
        1e-4,
        9.999999999999998e-5,
        1e-5,
        1.234e-7,
        1e15,
        1.5e15,
        4503599627370495.5,
        9999999999999998.0,
        1e16,
        1.5e300,
        5e-324,
        f64::MAX,
        f64::MIN_POSITIVE,
    ];
    for _ in 0..200_000 {
        // Mesh coordinates and measures: every magnitude a model may have, some rounded.
        let e = rng.gen_range(-9..18);
        let mut x = rng.gen_range(1.0..10.0) * 10f64.powi(e) * if rng.gen() { 1.0 } else { -1.0 };
        if rng.gen_range(0..4) == 0 {
            x = (x * 1000.0).round() / 1000.0;
        }
        values.push(x);
        values.push(f64::from_bits(rng.gen::<u64>()));
    }
    for x in values.into_iter().filter(|x| x.is_finite()) {
        let text = F(x).to_string();
        assert_eq!(
            text.parse::<f64>().unwrap().to_bits(),
            x.to_bits(),
            "{text}"
        );
        // Where a value lies halfway between two shortest decimals (seen only above 1e8) the
        // two formatters may pick different ones; both read back exactly.
        if x.abs() < 1e8 {
            assert_eq!(text, std_text(x), "{x:e}");
        } else {
            assert_eq!(text.len(), std_text(x).len(), "{x:e}");
        }
    }
    assert_eq!(F(f64::NAN).to_string(), "nan");
    assert_eq!(F(f64::NEG_INFINITY).to_string(), "-inf");
}
