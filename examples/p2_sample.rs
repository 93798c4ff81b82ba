//! Writes a mesh of straight-sided ten-node tets in every output format, for the readback checks
//! of other programs (ctests/p2_readback.py, tests/p2_writers.rs):
//!
//!     cargo run --release --example p2_sample -- OUTDIR [MESH]
//!
//! MESH (any format `io::read_mesh` reads) gives the corners; without it, a 3x3x3 block of
//! cubes split into 6 tets each, one region per layer (1, 2, 3) and one boundary marker per
//! side (1..6). The mid-edge nodes are `QuadraticNodes::straight`, so every one lies at the
//! midpoint of its edge. Written to OUTDIR: `ascii.msh`, `binary.msh`, `ascii.vtu`,
//! `binary.vtu`, `p2.mesh`, `p2.inp`, `p2.node`/`p2.ele`/`p2.face`, and `counts.json` with
//! the node, tet, triangle, region and marker counts the files should hold.

use slivermesh::io::{read_mesh, write_output, CellField};
use slivermesh::mesh::{QuadraticNodes, TetMesh};
use slivermesh::DVec3;
use std::collections::BTreeSet;
use std::path::Path;

/// An n x n x n block of unit cubes (scaled by 0.5, shifted), 6 positively oriented tets per
/// cube around its main diagonal; region = layer + 1; the outer faces as boundary triangles,
/// oriented outwards, marker = side + 1 (x-, x+, y-, y+, z-, z+).
pub fn block(n: u32) -> TetMesh {
    let id = |i: u32, j: u32, k: u32| (k * (n + 1) + j) * (n + 1) + i;
    let mut m = TetMesh::default();
    for k in 0..=n {
        for j in 0..=n {
            for i in 0..=n {
                let p = DVec3::new(i as f64, j as f64, k as f64) * 0.5 + DVec3::new(0.1, -2.0, 3.0);
                m.vertices.push(p);
            }
        }
    }
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
                    let mut t = [c[t[0]], c[t[1]], c[t[2]], c[t[3]]];
                    let [a, b, cc, d] = t.map(|v| m.vertices[v as usize]);
                    if (b - a).cross(cc - a).dot(d - a) < 0.0 {
                        t.swap(2, 3);
                    }
                    m.tets.push(t);
                    m.tet_regions.push(k as i32 + 1);
                }
            }
        }
    }
    // Each tet face on the block's surface, oriented away from its tet.
    let centre = DVec3::splat(n as f64 * 0.25) + DVec3::new(0.1, -2.0, 3.0);
    let mut count = std::collections::HashMap::new();
    for t in &m.tets {
        for k in 0..4 {
            let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
            f.sort_unstable();
            *count.entry(f).or_insert(0) += 1;
        }
    }
    let mut faces: Vec<[u32; 3]> = count
        .into_iter()
        .filter(|&(_, c)| c == 1)
        .map(|(f, _)| f)
        .collect();
    faces.sort_unstable();
    for mut f in faces {
        let [a, b, c] = f.map(|v| m.vertices[v as usize]);
        let normal = (b - a).cross(c - a);
        if normal.dot((a + b + c) / 3.0 - centre) < 0.0 {
            f.swap(1, 2);
        }
        let nabs = normal.abs().to_array();
        let axis = (0..3).fold(0, |best, i| if nabs[i] > nabs[best] { i } else { best });
        let g = ((a + b + c) / 3.0 - centre)[axis];
        m.boundary.push(f);
        m.boundary_markers
            .push(2 * axis as i32 + if g > 0.0 { 2 } else { 1 });
    }
    m
}

/// Writes the files (see the module doc); returns the `counts.json` text.
pub fn write_sample(dir: &Path, mesh: &TetMesh) -> String {
    let q = QuadraticNodes::straight(mesh);
    let quality: Vec<f64> = (0..mesh.tets.len()).map(|i| i as f64).collect();
    let fields = [CellField {
        name: "index",
        values: &quality,
    }];
    for (name, binary) in [
        ("ascii.msh", false),
        ("binary.msh", true),
        ("ascii.vtu", false),
        ("binary.vtu", true),
        ("p2.mesh", false),
        ("p2.inp", false),
        ("p2.ele", false),
    ] {
        write_output(&dir.join(name), mesh, Some(&q), &fields, binary)
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let regions: BTreeSet<i32> = mesh.tet_regions.iter().copied().collect();
    let markers: BTreeSet<i32> = mesh.boundary_markers.iter().copied().collect();
    let counts = format!(
        "{{\"nodes\": {}, \"corners\": {}, \"tets\": {}, \"triangles\": {}, \"regions\": {}, \
         \"markers\": {}}}\n",
        q.n_nodes(mesh),
        mesh.vertices.len(),
        mesh.tets.len(),
        mesh.boundary.len(),
        regions.len(),
        markers.len()
    );
    std::fs::write(dir.join("counts.json"), &counts).unwrap();
    counts
}

#[allow(dead_code)]
fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let Some(out) = args.first() else {
        eprintln!("usage: p2_sample OUTDIR [MESH]");
        std::process::exit(2);
    };
    let mesh = match args.get(1) {
        Some(p) => read_mesh(Path::new(p)).unwrap_or_else(|e| {
            eprintln!("{e}");
            std::process::exit(1)
        }),
        None => block(3),
    };
    std::fs::create_dir_all(out).unwrap();
    print!("{}", write_sample(Path::new(out), &mesh));
}
