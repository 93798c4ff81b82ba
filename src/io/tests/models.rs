//! Every model in models/ reads, with the expected counts.

use super::{model, models_in, TempDir};
use crate::io::{read_plc, ReadOptions};
use crate::plc::{Facet, PlcInput};
use glam::DVec3;

fn plain() -> ReadOptions {
    ReadOptions::default()
}

fn merged() -> ReadOptions {
    ReadOptions {
        merge_coplanar: true,
    }
}

fn newell(plc: &PlcInput, lp: &[u32]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..lp.len() {
        let p = plc.vertices[lp[i] as usize];
        let q = plc.vertices[lp[(i + 1) % lp.len()] as usize];
        n += p.cross(q);
    }
    n
}

fn loops(f: &Facet) -> impl Iterator<Item = &Vec<u32>> {
    f.polygons.iter().chain(&f.hole_polygons)
}

/// Enclosed volume of a closed, outward-oriented polygon surface (holes oriented inversely).
fn volume(plc: &PlcInput) -> f64 {
    let mut v = 0.0;
    for f in &plc.facets {
        for lp in loops(f) {
            v += plc.vertices[lp[0] as usize].dot(newell(plc, lp)) / 6.0;
        }
    }
    v
}

/// Total facet area (outer polygons minus hole polygons).
fn area(plc: &PlcInput) -> f64 {
    plc.facets
        .iter()
        .map(|f| {
            let n = f
                .polygons
                .iter()
                .map(|lp| newell(plc, lp))
                .fold(DVec3::ZERO, |a, b| a + b);
            let h = f
                .hole_polygons
                .iter()
                .map(|lp| newell(plc, lp))
                .fold(DVec3::ZERO, |a, b| a + b);
            (n + h).length() / 2.0
        })
        .sum()
}

fn counts(p: &PlcInput) -> (usize, usize, usize, usize) {
    (
        p.vertices.len(),
        p.facets.len(),
        p.holes.len(),
        p.regions.len(),
    )
}

#[test]
fn every_poly_model_reads_with_expected_counts() {
    let expect = [
        ("box_with_cavity", (16, 12, 1, 0)),
        ("cube", (8, 6, 0, 0)),
        ("drilled_block", (16, 10, 0, 0)),
        ("lshape", (12, 8, 0, 0)),
        ("stairs", (20, 12, 0, 0)),
        ("tetgen_example", (28, 23, 2, 2)),
        ("thin_plate", (8, 6, 0, 0)),
        ("two_materials", (12, 11, 0, 2)),
    ];
    let files = models_in("poly", "poly");
    assert_eq!(files.len(), expect.len(), "a new model needs an entry here");
    for (name, c) in expect {
        let path = model(&format!("poly/{name}.poly"));
        let p = read_plc(&path, &plain()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(counts(&p), c, "{name}");
        for f in &p.facets {
            for lp in &f.polygons {
                assert!(lp.iter().all(|&v| (v as usize) < p.vertices.len()));
            }
        }
    }
}

#[test]
fn poly_models_details() {
    let cube = read_plc(&model("poly/cube.poly"), &plain()).unwrap();
    assert_eq!(cube.vertices[7], DVec3::ONE);
    assert_eq!(
        cube.facets[0].polygons,
        vec![vec![0, 2, 3, 1]],
        "1-based ids"
    );
    assert!(cube.facets.iter().all(|f| f.marker == 1));
    assert!((volume(&cube).abs() - 1.0).abs() < 1e-12);

    let two = read_plc(&model("poly/two_materials.poly"), &plain()).unwrap();
    let attrs: Vec<i32> = two.regions.iter().map(|r| r.attribute).collect();
    assert_eq!(attrs, vec![1, 2]);
    assert!(
        two.regions.iter().all(|r| r.max_size.is_none()),
        "-1 = no limit"
    );
    assert_eq!(two.regions[1].point, DVec3::new(1.5, 0.5, 0.5));
    assert_eq!(two.facets.iter().filter(|f| f.marker == 2).count(), 1);

    let drilled = read_plc(&model("poly/drilled_block.poly"), &plain()).unwrap();
    for f in &drilled.facets[..2] {
        assert_eq!(f.polygons.len(), 2);
        assert_eq!(f.hole_points.len(), 1);
    }
    assert_eq!(drilled.facets[1].hole_points[0], DVec3::new(1.5, 1.5, 1.0));
    assert!(drilled.facets[2..].iter().all(|f| f.hole_points.is_empty()));
    assert_eq!(drilled.facets[9].marker, 3);

    let cavity = read_plc(&model("poly/box_with_cavity.poly"), &plain()).unwrap();
    assert_eq!(cavity.holes, vec![DVec3::splat(2.0)]);

    let ex = read_plc(&model("poly/tetgen_example.poly"), &plain()).unwrap();
    assert_eq!(ex.facets[2].polygons.len(), 2);
    assert_eq!(ex.facets[2].hole_points, vec![DVec3::new(1.0, 0.0, 2.25)]);
    assert_eq!(ex.facets[2].marker, 3);
    assert_eq!(ex.facets[1].marker, 9);
    let r = ex.regions[0];
    assert_eq!((r.point, r.attribute), (DVec3::new(1.0, 0.25, 0.1), 10));
    let s = r.max_size.unwrap();
    let v = s.powi(3) / (6.0 * std::f64::consts::SQRT_2);
    assert!((v - 0.001).abs() < 1e-15, "max volume 0.001 -> edge {s}");
    assert_eq!(ex.regions[1].attribute, 20);
}

#[test]
fn poly_as_smesh_and_with_separate_node_file() {
    // Rewrite cube.poly as X.smesh + X.node and as X.poly with a 0 node count.
    let cube = read_plc(&model("poly/cube.poly"), &plain()).unwrap();
    let dir = TempDir::new("smesh");
    let mut node = format!("{} 3 0 0\n", cube.vertices.len());
    for (i, p) in cube.vertices.iter().enumerate() {
        node += &format!("{} {} {} {}\n", i, p.x, p.y, p.z);
    }
    std::fs::write(dir.path("c.node"), &node).unwrap();
    let mut smesh = format!("0 3 0 0\n{} 1\n", cube.facets.len());
    let mut poly = format!("0 3 0 0\n{} 1\n", cube.facets.len());
    for f in &cube.facets {
        let ids: Vec<String> = f.polygons[0].iter().map(|v| v.to_string()).collect();
        smesh += &format!("4 {} 7\n", ids.join(" "));
        poly += &format!("1 0 7\n4 {}\n", ids.join(" "));
    }
    smesh += "0\n0\n";
    poly += "0\n";
    std::fs::write(dir.path("c.smesh"), &smesh).unwrap();
    std::fs::write(dir.path("c.POLY"), &poly).unwrap();
    let a = read_plc(&dir.path("c.smesh"), &plain()).unwrap();
    let b = read_plc(&dir.path("c.POLY"), &plain()).unwrap();
    assert_eq!(a, b);
    assert_eq!(a.vertices, cube.vertices);
    for (fa, fc) in a.facets.iter().zip(&cube.facets) {
        assert_eq!(fa.polygons, fc.polygons);
        assert_eq!(fa.marker, 7);
    }
    // A broken .node file is reported against the .node file.
    std::fs::write(dir.path("c.node"), "8 3 0 0\n0 0 0\n").unwrap();
    let e = read_plc(&dir.path("c.smesh"), &plain()).unwrap_err();
    assert!(e.path.ends_with("c.node") && e.line == Some(2), "{e}");
    std::fs::remove_file(dir.path("c.node")).unwrap();
    let e = read_plc(&dir.path("c.smesh"), &plain()).unwrap_err();
    assert!(
        e.path.ends_with("c.node") && e.message.contains("cannot read"),
        "{e}"
    );
}

fn off_header_counts(path: &std::path::Path) -> (usize, usize) {
    let text = std::fs::read_to_string(path).unwrap();
    let mut nums = text
        .lines()
        .map(|l| l.split('#').next().unwrap().trim())
        .find(|l| !l.is_empty() && !l.eq_ignore_ascii_case("OFF"))
        .unwrap()
        .split_whitespace()
        .map(|w| w.parse::<usize>().unwrap());
    (nums.next().unwrap(), nums.next().unwrap())
}

#[test]
fn every_off_model_reads_and_merging_keeps_area_and_volume() {
    let files = models_in("off", "off");
    assert!(files.len() >= 11, "{files:?}");
    for path in files {
        let name = path.file_name().unwrap().to_string_lossy().to_string();
        let p = read_plc(&path, &plain()).unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(
            (p.vertices.len(), p.facets.len()),
            off_header_counts(&path),
            "{name}"
        );
        assert!(p
            .facets
            .iter()
            .enumerate()
            .all(|(i, f)| f.marker == i as i32 + 1));
        let m = read_plc(&path, &merged()).unwrap();
        assert_eq!(m.vertices, p.vertices, "{name}: merging keeps every vertex");
        assert!(m.facets.len() <= p.facets.len());
        assert!(m
            .facets
            .iter()
            .enumerate()
            .all(|(i, f)| f.marker == i as i32 + 1));
        let (a0, a1) = (area(&p), area(&m));
        assert!((a0 - a1).abs() <= 1e-9 * a0, "{name}: area {a0} -> {a1}");
        let (v0, v1) = (volume(&p), volume(&m));
        assert!(
            (v0 - v1).abs() <= 1e-9 * v0.abs().max(a0.powf(1.5)),
            "{name}: volume {v0} -> {v1}"
        );
        // Every directed edge of the merged loops is matched by its reverse (closed surface).
        let mut edges = std::collections::HashMap::new();
        for f in &m.facets {
            for lp in loops(f) {
                for i in 0..lp.len() {
                    let (u, v) = (lp[i], lp[(i + 1) % lp.len()]);
                    *edges.entry((u, v)).or_insert(0i32) += 1;
                    *edges.entry((v, u)).or_insert(0i32) -= 1;
                }
            }
        }
        assert!(
            edges.values().all(|&c| c == 0),
            "{name}: merged surface not closed"
        );
    }
}

#[test]
fn cube_off_merges_into_six_quads_and_cross_into_polygons() {
    let m = read_plc(&model("off/cube.off"), &merged()).unwrap();
    assert_eq!(m.facets.len(), 6);
    assert!(m.facets.iter().all(|f| f.polygons[0].len() == 4));
    assert!((volume(&m) - 8.0).abs() < 1e-12);
    let c = read_plc(&model("off/cross.off"), &merged()).unwrap();
    let t = read_plc(&model("off/cross.off"), &plain()).unwrap();
    assert!(c.facets.len() < t.facets.len());
    assert!(c.facets.iter().all(|f| f.hole_polygons.is_empty()));
}

#[test]
fn stl_of_cube_off_reads_like_the_off() {
    let off = read_plc(&model("off/cube.off"), &plain()).unwrap();
    let dir = TempDir::new("stl");
    let mut ascii = String::from("solid cube\n");
    let mut bin = vec![0u8; 80];
    bin.extend_from_slice(&(off.facets.len() as u32).to_le_bytes());
    for f in &off.facets {
        ascii += "  facet normal 0 0 0\n    outer loop\n";
        bin.extend_from_slice(&[0u8; 12]);
        for &v in &f.polygons[0] {
            let p = off.vertices[v as usize];
            ascii += &format!("      vertex {} {} {}\n", p.x, p.y, p.z);
            for c in [p.x, p.y, p.z] {
                bin.extend_from_slice(&(c as f32).to_le_bytes());
            }
        }
        bin.extend_from_slice(&[0u8; 2]);
        ascii += "    endloop\n  endfacet\n";
    }
    ascii += "endsolid cube\n";
    std::fs::write(dir.path("a.stl"), &ascii).unwrap();
    std::fs::write(dir.path("b.STL"), &bin).unwrap();
    for name in ["a.stl", "b.STL"] {
        let s = read_plc(&dir.path(name), &plain()).unwrap();
        assert_eq!((s.vertices.len(), s.facets.len()), (8, 12), "{name}");
        assert!((volume(&s) - 8.0).abs() < 1e-12, "{name}");
        let m = read_plc(&dir.path(name), &merged()).unwrap();
        assert_eq!(m.facets.len(), 6, "{name}");
    }
}

#[test]
fn unknown_extension_lists_supported_ones() {
    let e = read_plc(std::path::Path::new("x.3ds"), &plain()).unwrap_err();
    assert!(
        e.message.contains(".poly, .smesh, .off, .stl, .ply, .obj"),
        "{e}"
    );
    assert!(e.message.contains("'.3ds'"), "{e}");
    let e = read_plc(std::path::Path::new("noext"), &plain()).unwrap_err();
    assert!(e.message.contains("no extension"), "{e}");
    let e = read_plc(&model("poly/missing.poly"), &plain()).unwrap_err();
    assert!(e.message.contains("cannot read file"), "{e}");
    assert_eq!(e.line, None);
}
