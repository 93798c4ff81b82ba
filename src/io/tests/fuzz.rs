//! Fuzz-ish robustness: truncated and mutated files must give `Ok` or `IoError`, never panic.

use super::{models_in, roundtrip::sample_mesh};
use crate::io::{gmsh, medit, off, poly, stl, tetgen, vtu, ReadOptions};

/// A tiny deterministic xorshift generator.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 << 13;
        self.0 ^= self.0 >> 7;
        self.0 ^= self.0 << 17;
        self.0
    }

    fn below(&mut self, n: usize) -> usize {
        (self.next() % n.max(1) as u64) as usize
    }
}

/// Bytes that make parsers take unusual paths.
const NASTY: &[&[u8]] = &[
    b"0",
    b"-1",
    b"99999999999999999999",
    b"nan",
    b"1e999",
    b"#",
    b"\n",
    b" ",
    b"$End",
    b"<",
    b">",
    b"\"",
    b"4294967296",
    b"1.5",
    b"x",
    b"\xff",
];

/// Truncations at up to `cuts` places plus `mutations` random edits, each fed to `parse`.
pub(super) fn hammer(data: &[u8], cuts: usize, mutations: usize, seed: u64, parse: &dyn Fn(&[u8])) {
    parse(data);
    let step = (data.len() / cuts.max(1)).max(1);
    for cut in (0..data.len()).step_by(step) {
        parse(&data[..cut]);
    }
    let mut rng = Rng(seed | 1);
    for _ in 0..mutations {
        let mut d = data.to_vec();
        for _ in 0..1 + rng.below(3) {
            let at = rng.below(d.len());
            match rng.below(3) {
                0 if !d.is_empty() => {
                    let len = rng.below(8).min(d.len() - at);
                    d.drain(at..at + len);
                }
                1 => {
                    let ins = NASTY[rng.below(NASTY.len())];
                    d.splice(at..at, ins.iter().copied());
                }
                _ if !d.is_empty() => d[at] = rng.next() as u8,
                _ => {}
            }
        }
        parse(&d);
    }
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn damaged_domain_files_never_panic() {
    let merge = ReadOptions {
        merge_coplanar: true,
    };
    for path in models_in("poly", "poly") {
        let data = std::fs::read(&path).unwrap();
        hammer(&data, 200, 300, data.len() as u64, &|b| {
            let t = text(b);
            let mut none = || poly::parse_node("1 3\n1 0 0 0\n");
            let _ = poly::parse_poly(&t, &mut none);
            let _ = poly::parse_smesh(&t, &mut none);
            let _ = poly::parse_node(&t);
        });
    }
    for path in models_in("off", "off") {
        let data = std::fs::read(&path).unwrap();
        // The big models get fewer cuts: each parse with merging is a full pass.
        let (cuts, muts) = if data.len() > 50_000 {
            (10, 10)
        } else {
            (100, 100)
        };
        hammer(&data, cuts, muts, data.len() as u64, &|b| {
            let _ = off::parse_off(&text(b), &merge);
            let _ = stl::parse_stl(b, &merge);
        });
    }
}

#[test]
fn damaged_mesh_files_never_panic() {
    let m = sample_mesh(2);
    let mut buf = Vec::new();
    medit::format_medit(&mut buf, &m).unwrap();
    hammer(&buf, 300, 300, 1, &|b| {
        let _ = medit::parse_medit(&text(b));
    });
    buf.clear();
    gmsh::format_msh(&mut buf, &m).unwrap();
    hammer(&buf, 300, 300, 2, &|b| {
        let _ = gmsh::parse_msh(&text(b));
    });
    buf.clear();
    vtu::format_vtu(&mut buf, &m, &[]).unwrap();
    hammer(&buf, 300, 300, 3, &|b| {
        let _ = vtu::parse_vtu(&text(b));
    });
    let nodes = poly::NodeList {
        vertices: m.vertices.clone(),
        base: 1,
    };
    for (k, f) in [tetgen::format_node, tetgen::format_ele, tetgen::format_face]
        .iter()
        .enumerate()
    {
        buf.clear();
        f(&mut buf, &m).unwrap();
        hammer(&buf, 200, 200, 4 + k as u64, &|b| {
            let t = text(b);
            let mut mesh = crate::mesh::TetMesh::default();
            let _ = poly::parse_node(&t);
            let _ = tetgen::parse_ele(&t, &nodes, &mut mesh);
            let _ = tetgen::parse_face(&t, &nodes, &mut mesh);
        });
    }
}
