//! Ten-node tets (`order` 2) on a fine icosphere: the boundary edges' nodes lie on the sphere
//! much closer than the straight edges' midpoints would, and no element folds. In keep mode
//! every node is its edge's midpoint.
//!
//! The sphere test runs in release builds only (`cargo test --release --test quadratic`).

mod common;

use common::corpus;
use common::ScratchDir;
use slivermesh::mesh::{QuadraticNodes, TET_EDGES, TRIANGLE_EDGES};
use slivermesh::pipeline;
use slivermesh::run::params::{Params, SurfaceMode};
use slivermesh::run::spacing::ConstantSpacing;
use slivermesh::{DVec3, TetMesh};

/// The icosphere's level: 20 * 4^6 = 81,920 triangles.
const ICOSPHERE_LEVEL: u32 = 6;

/// How many times closer to the sphere the curved boundary nodes must be, on average, than
/// the straight edges' midpoints.
const CLOSER_AT_LEAST: f64 = 5.0;

fn write_off(path: &std::path::Path, s: &corpus::Surface) {
    let mut text = format!("OFF\n{} {} 0\n", s.vertices.len(), s.triangles.len());
    for v in &s.vertices {
        text += &format!("{:.17e} {:.17e} {:.17e}\n", v.x, v.y, v.z);
    }
    for t in &s.triangles {
        text += &format!("3 {} {} {}\n", t[0], t[1], t[2]);
    }
    std::fs::write(path, text).unwrap();
}

/// Every boundary edge once: its two corners and its node.
fn boundary_edges(mesh: &TetMesh, q: &QuadraticNodes) -> Vec<(u32, u32, u32)> {
    let mut edges: Vec<(u32, u32, u32)> = mesh
        .boundary
        .iter()
        .zip(&q.boundary_edges)
        .flat_map(|(t, e)| {
            TRIANGLE_EDGES
                .iter()
                .zip(e)
                .map(|(&(i, j), &n)| (t[i].min(t[j]), t[i].max(t[j]), n))
        })
        .collect();
    edges.sort_unstable();
    edges.dedup();
    edges
}

/// The corner ids of each tet's six edges and its nodes agree with the boundary triangles':
/// one node per edge, whichever element names it.
fn check_one_node_per_edge(mesh: &TetMesh, q: &QuadraticNodes) {
    let mut node_of = std::collections::HashMap::new();
    for (t, e) in mesh.tets.iter().zip(&q.tet_edges) {
        for (&(i, j), &n) in TET_EDGES.iter().zip(e) {
            let key = (t[i].min(t[j]), t[i].max(t[j]));
            assert_eq!(*node_of.entry(key).or_insert(n), n, "edge {key:?}");
        }
    }
    for (a, b, n) in boundary_edges(mesh, q) {
        assert_eq!(node_of.get(&(a, b)), Some(&n), "boundary edge ({a}, {b})");
    }
    assert_eq!(node_of.len(), q.points.len());
}

#[test]
fn curved_nodes_lie_on_a_fine_sphere() {
    if cfg!(debug_assertions) {
        eprintln!("skipped in debug builds: run `cargo test --release --test quadratic`");
        return;
    }
    let dir = ScratchDir::new("quadratic", "icosphere");
    let path = dir.0.join("icosphere.off");
    write_off(&path, &corpus::icosphere(ICOSPHERE_LEVEL));
    let input = slivermesh::io::read_plc(
        &path,
        &slivermesh::io::ReadOptions {
            merge_coplanar: true,
        },
    )
    .unwrap();
    let params = Params {
        surface_mode: SurfaceMode::Approximate,
        order: 2,
        ..Params::default()
    };
    let (mesh, quadratic, report) =
        pipeline::mesh(&input, &params, Some(&ConstantSpacing(0.1)), None).unwrap();
    let q = quadratic.expect("order 2 gives the mid-edge nodes");
    check_one_node_per_edge(&mesh, &q);
    let qr = report.quadratic.as_ref().unwrap();
    assert!(qr.min_jacobian_ratio > 0.0, "{qr:?}");

    let off_sphere = |p: DVec3| (p.length() - 1.0).abs();
    let edges = boundary_edges(&mesh, &q);
    let (mut curved, mut straight) = (0.0, 0.0);
    for &(a, b, n) in &edges {
        curved += off_sphere(q.position(&mesh, n));
        straight += off_sphere((mesh.vertices[a as usize] + mesh.vertices[b as usize]) * 0.5);
    }
    let ratio = straight / curved;
    println!(
        "{} boundary edges: mean distance to the sphere {:.3e} (nodes) vs {:.3e} (midpoints), \
         {ratio:.1}x closer; {} curved, {} straightened, min Jacobian ratio {:.3}",
        edges.len(),
        curved / edges.len() as f64,
        straight / edges.len() as f64,
        qr.n_curved_edges,
        qr.n_straightened_edges,
        qr.min_jacobian_ratio
    );
    assert!(ratio >= CLOSER_AT_LEAST, "only {ratio:.2}x closer");
}

#[test]
fn keep_mode_nodes_are_midpoints() {
    let input = common::read_model("poly/two_materials.poly");
    let params = Params {
        order: 2,
        ..Params::default()
    };
    let (mesh, quadratic, report) =
        pipeline::mesh(&input, &params, Some(&ConstantSpacing(0.3)), None).unwrap();
    let q = quadratic.unwrap();
    check_one_node_per_edge(&mesh, &q);
    for (t, e) in mesh.tets.iter().zip(&q.tet_edges) {
        for (&(i, j), &n) in TET_EDGES.iter().zip(e) {
            let mid = (mesh.vertices[t[i] as usize] + mesh.vertices[t[j] as usize]) * 0.5;
            assert_eq!(q.position(&mesh, n), mid);
        }
    }
    let qr = report.quadratic.unwrap();
    assert_eq!((qr.n_curved_edges, qr.min_jacobian_ratio), (0, 1.0));
}
