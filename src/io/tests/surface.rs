//! `.ply` and `.obj` versions of the `.off` models, written here (not stored): they read back
//! to the same domain, in both surface modes, and mesh to the same result.

use super::{model, models_in, TempDir};
use crate::io::text::F;
use crate::io::{obj, off, ply, read_plc, ReadOptions};
use crate::plc::PlcInput;
use std::fmt::Write as _;

/// A PLY file of `p`'s facets (one polygon each): double coordinates (exact), a colour property
/// and an `edge` element to skip, in the given format.
pub(crate) fn ply_bytes(p: &PlcInput, format: &str) -> Vec<u8> {
    let mut out = format!(
        "ply\nformat {format} 1.0\ncomment written by slivermesh's tests\n\
         element vertex {}\nproperty double x\nproperty double y\nproperty double z\n\
         property uchar red\nelement face {}\nproperty list uchar int vertex_indices\n\
         element edge 1\nproperty int vertex1\nproperty int vertex2\nend_header\n",
        p.vertices.len(),
        p.facets.len()
    )
    .into_bytes();
    let big = format == "binary_big_endian";
    let ascii = format == "ascii";
    let num = |out: &mut Vec<u8>, v: f64, int: bool| {
        if ascii {
            out.extend_from_slice(format!("{} ", F(v)).as_bytes());
        } else if int {
            let v = v as i32;
            out.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        } else {
            out.extend(if big {
                v.to_be_bytes()
            } else {
                v.to_le_bytes()
            });
        }
    };
    for v in &p.vertices {
        for c in v.to_array() {
            num(&mut out, c, false);
        }
        if ascii {
            out.extend_from_slice(b"7\n");
        } else {
            out.push(7);
        }
    }
    for f in &p.facets {
        let poly = &f.polygons[0];
        if ascii {
            out.extend_from_slice(format!("{} ", poly.len()).as_bytes());
        } else {
            out.push(poly.len() as u8);
        }
        for &i in poly {
            num(&mut out, i as f64, true);
        }
        if ascii {
            out.push(b'\n');
        }
    }
    num(&mut out, 0.0, true);
    num(&mut out, 1.0, true);
    out
}

/// An OBJ file of `p`'s facets, cycling through the corner forms `i`, `i/t`, `i/t/n`, `i//n`
/// and negative (relative) indices.
pub(crate) fn obj_text(p: &PlcInput) -> String {
    let mut s = String::from("# written by slivermesh's tests\nmtllib none.mtl\no model\n");
    for v in &p.vertices {
        writeln!(s, "v {} {} {}", F(v.x), F(v.y), F(v.z)).unwrap();
    }
    s.push_str("vt 0 0\nvn 0 0 1\ng all\nusemtl none\ns 1\n");
    let nv = p.vertices.len() as i64;
    for (k, f) in p.facets.iter().enumerate() {
        s.push('f');
        for &i in &f.polygons[0] {
            let i = i as i64 + 1;
            let c = match k % 5 {
                0 => format!("{i}"),
                1 => format!("{i}/1"),
                2 => format!("{i}/1/1"),
                3 => format!("{i}//1"),
                _ => format!("{}", i - nv - 1),
            };
            write!(s, " {c}").unwrap();
        }
        s.push('\n');
    }
    s
}

const PLY_FORMATS: [&str; 3] = ["ascii", "binary_little_endian", "binary_big_endian"];

fn opts(merge: bool) -> ReadOptions {
    ReadOptions {
        merge_coplanar: merge,
    }
}

#[test]
fn every_off_model_reads_the_same_as_ply_and_obj() {
    for path in models_in("off", "off") {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let raw = off::read_off(&path, &opts(false)).unwrap();
        let merged = off::read_off(&path, &opts(true)).unwrap();
        for format in PLY_FORMATS {
            let bytes = ply_bytes(&raw, format);
            assert_eq!(
                ply::parse_ply(&bytes, &opts(false)).unwrap(),
                raw,
                "{name} {format}"
            );
            if format == "binary_little_endian" {
                let m = ply::parse_ply(&bytes, &opts(true)).unwrap();
                assert_eq!(m, merged, "{name} {format} merged");
            }
        }
        let text = obj_text(&raw);
        assert_eq!(
            obj::parse_obj(&text, &opts(false)).unwrap(),
            raw,
            "{name} obj"
        );
        assert_eq!(
            obj::parse_obj(&text, &opts(true)).unwrap(),
            merged,
            "{name} obj merged"
        );
    }
}

/// The check: `.ply` and `.obj` versions of two models, read by extension, mesh to
/// exactly the mesh of their `.off` (coplanar faces merged, as the CLI reads surfaces).
#[test]
fn ply_and_obj_versions_mesh_like_the_off() {
    use crate::refine::mesh;
    use crate::run::params::Params;
    use crate::run::spacing::ConstantSpacing;
    let dir = TempDir::new("surface");
    for (name, h) in [("cube", 0.25), ("cross", 0.04)] {
        let off_path = model(&format!("off/{name}.off"));
        let raw = read_plc(&off_path, &opts(false)).unwrap();
        let ply_path = dir.path(&format!("{name}.ply"));
        std::fs::write(&ply_path, ply_bytes(&raw, "binary_little_endian")).unwrap();
        let obj_path = dir.path(&format!("{name}.OBJ"));
        std::fs::write(&obj_path, obj_text(&raw)).unwrap();
        let params = Params::default();
        let h = ConstantSpacing(h);
        let (want, report) = mesh(
            &read_plc(&off_path, &opts(true)).unwrap(),
            &params,
            Some(&h),
            None,
        )
        .unwrap_or_else(|e| panic!("{name}.off: {e}"));
        assert!(want.tets.len() > 1000, "{name}: {} tets", want.tets.len());
        eprintln!("{name}: {} tets from .off, .ply and .obj", want.tets.len());
        for path in [&ply_path, &obj_path] {
            assert!(crate::io::is_surface_file(path));
            let input = read_plc(path, &opts(true)).unwrap();
            let (got, r) = mesh(&input, &params, Some(&h), None).unwrap();
            assert_eq!(got, want, "{}", path.display());
            let untimed = |r: &crate::run::report::Report| crate::run::report::Report {
                seconds_recovery: 0.0,
                seconds_refinement: 0.0,
                seconds_total: 0.0,
                ..r.clone()
            };
            assert_eq!(
                format!("{:?}", untimed(&r)),
                format!("{:?}", untimed(&report)),
                "{}",
                path.display()
            );
        }
    }
}

#[test]
fn damaged_ply_and_obj_never_panic() {
    let raw = off::read_off(&model("off/cross.off"), &opts(false)).unwrap();
    let mut inputs: Vec<(Vec<u8>, bool)> = PLY_FORMATS
        .iter()
        .map(|f| (ply_bytes(&raw, f), true))
        .collect();
    inputs.push((obj_text(&raw).into_bytes(), false));
    for (k, (data, is_ply)) in inputs.iter().enumerate() {
        super::fuzz::hammer(data, 150, 300, 11 + k as u64, &|b| {
            if *is_ply {
                let _ = ply::parse_ply(b, &opts(true));
            } else {
                let _ = obj::parse_obj(&String::from_utf8_lossy(b), &opts(true));
            }
        });
    }
}
