//! Tests for `plc::validate`: model files and one small input per error.
//!
//! The readers here are minimal, test-only stand-ins for the io module (written concurrently)
//! so these tests do not depend on it; they will be replaced by `io::read_plc`.

use super::{Facet, PlcInput, Region};
use glam::DVec3;
use std::path::PathBuf;

mod errors;
mod models;

/// The test models, kept in the repository (`models/`, see its README).
pub fn models_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models")
}

/// Whitespace tokens of the non-comment lines.
fn lines(text: &str) -> impl Iterator<Item = Vec<&str>> {
    text.lines()
        .map(|l| l.split('#').next().unwrap())
        .map(|l| l.split_whitespace().collect::<Vec<_>>())
        .filter(|t| !t.is_empty())
}

fn num(s: &str) -> f64 {
    s.parse().unwrap_or_else(|_| panic!("bad number {s:?}"))
}

fn point(t: &[&str]) -> DVec3 {
    DVec3::new(num(t[0]), num(t[1]), num(t[2]))
}

/// TetGen .poly with the points inline (all our models are).
pub fn parse_poly(text: &str) -> PlcInput {
    let mut it = lines(text);
    let head = it.next().unwrap();
    let n = num(head[0]) as usize;
    let mut base = 0;
    let mut vertices = Vec::with_capacity(n);
    for i in 0..n {
        let t = it.next().unwrap();
        if i == 0 {
            base = num(t[0]) as u32;
        }
        vertices.push(point(&t[1..]));
    }
    let nf = num(it.next().unwrap()[0]) as usize;
    let mut facets = Vec::with_capacity(nf);
    for _ in 0..nf {
        let t = it.next().unwrap();
        let npoly = num(t[0]) as usize;
        let nholes = t.get(1).map_or(0, |s| num(s) as usize);
        let marker = t.get(2).map_or(0, |s| num(s) as i32);
        let mut f = Facet {
            marker,
            ..Facet::default()
        };
        for _ in 0..npoly {
            let p = it.next().unwrap();
            let k = num(p[0]) as usize;
            f.polygons
                .push(p[1..=k].iter().map(|s| num(s) as u32 - base).collect());
        }
        for _ in 0..nholes {
            f.hole_points.push(point(&it.next().unwrap()[1..]));
        }
        facets.push(f);
    }
    let nh = it.next().map_or(0, |t| num(t[0]) as usize);
    let holes = (0..nh).map(|_| point(&it.next().unwrap()[1..])).collect();
    let nr = it.next().map_or(0, |t| num(t[0]) as usize);
    let regions = (0..nr)
        .map(|_| {
            let t = it.next().unwrap();
            Region {
                point: point(&t[1..]),
                attribute: num(t[4]) as i32,
                max_size: t.get(5).map(|s| num(s)).filter(|&v| v > 0.0),
            }
        })
        .collect();
    PlcInput {
        vertices,
        facets,
        holes,
        regions,
    }
}

/// OFF surface, one facet per face.
pub fn parse_off(text: &str) -> PlcInput {
    let mut it = lines(text);
    let mut head = it.next().unwrap();
    if head[0] == "OFF" {
        head = if head.len() > 1 {
            head[1..].to_vec()
        } else {
            it.next().unwrap()
        };
    }
    let (nv, nf) = (num(head[0]) as usize, num(head[1]) as usize);
    let vertices = (0..nv).map(|_| point(&it.next().unwrap())).collect();
    let facets = (0..nf)
        .map(|_| {
            let t = it.next().unwrap();
            let k = num(t[0]) as usize;
            Facet {
                polygons: vec![t[1..=k].iter().map(|s| num(s) as u32).collect()],
                ..Facet::default()
            }
        })
        .collect();
    PlcInput {
        vertices,
        facets,
        ..PlcInput::default()
    }
}

pub fn read_model(rel: &str) -> PlcInput {
    let path = models_dir().join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    if rel.ends_with(".off") {
        parse_off(&text)
    } else {
        parse_poly(&text)
    }
}

/// A facet with the given outer polygons.
pub fn facet(polygons: &[&[u32]]) -> Facet {
    Facet {
        polygons: polygons.iter().map(|p| p.to_vec()).collect(),
        ..Facet::default()
    }
}

/// An axis-aligned box [lo, hi] as 8 vertices (id = first + x + 2y + 4z) and 6 quads.
pub fn add_box(input: &mut PlcInput, lo: DVec3, hi: DVec3) {
    let b = input.vertices.len() as u32;
    for i in 0..8 {
        let pick = |bit: u32, l: f64, h: f64| if i & bit != 0 { h } else { l };
        input.vertices.push(DVec3::new(
            pick(1, lo.x, hi.x),
            pick(2, lo.y, hi.y),
            pick(4, lo.z, hi.z),
        ));
    }
    for q in [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ] {
        input.facets.push(facet(&[&q.map(|v| v + b)]));
    }
}

pub fn unit_cube() -> PlcInput {
    let mut input = PlcInput::default();
    add_box(&mut input, DVec3::ZERO, DVec3::ONE);
    input
}
