use super::jacobian::{bernstein, cubic_indices, Tet10};
use super::*;
use crate::mesh::TET_EDGES;
use rand::{Rng, SeedableRng};

fn regular() -> [DVec3; 4] {
    [
        DVec3::new(1.0, 1.0, 1.0),
        DVec3::new(1.0, -1.0, -1.0),
        DVec3::new(-1.0, 1.0, -1.0),
        DVec3::new(-1.0, -1.0, 1.0),
    ]
}

fn random_barycentric(rng: &mut impl Rng) -> [f64; 4] {
    let mut l: [f64; 4] = std::array::from_fn(|_| rng.gen::<f64>());
    let s: f64 = l.iter().sum();
    l.iter_mut().for_each(|x| *x /= s);
    l
}

#[test]
fn a_straight_tet_has_its_linear_determinant_everywhere() {
    let tet = Tet10::straight(regular());
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    for _ in 0..20 {
        let l = random_barycentric(&mut rng);
        assert!((tet.det_at(l) - tet.straight_det()).abs() < 1e-12);
    }
    assert!((tet.jacobian_ratio_bound() - 1.0).abs() < 1e-12);
    assert!((tet.min_corner_scaled_jacobian() - 1.0).abs() < 1e-12);
}

#[test]
fn bernstein_coefficients_reproduce_the_determinant_and_bound_it() {
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
    let mut tet = Tet10::straight(regular());
    for m in tet.mids.iter_mut() {
        *m += DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 0.3 - 0.15;
    }
    let c = tet.bernstein_coefficients();
    let bound = tet.jacobian_ratio_bound();
    for _ in 0..200 {
        let l = random_barycentric(&mut rng);
        let expanded: f64 = cubic_indices()
            .iter()
            .zip(c)
            .map(|(&alpha, ci)| ci * bernstein(alpha, l))
            .sum();
        let det = tet.det_at(l);
        assert!((expanded - det).abs() < 1e-9 * det.abs().max(1.0));
        assert!(det / tet.straight_det() >= bound - 1e-12);
    }
}

#[test]
fn a_node_pushed_through_the_opposite_face_folds_the_tet() {
    let corners = regular();
    let mut tet = Tet10::straight(corners);
    // Edge 01's node pushed far past corners 2 and 3.
    let (i, j) = TET_EDGES[0];
    let mid = (corners[i] + corners[j]) * 0.5;
    tet.mids[0] = mid + (corners[2] + corners[3] - corners[0] - corners[1]) * 1.5;
    assert!(tet.jacobian_ratio_bound() < 0.0);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
    let negative = (0..2000)
        .map(|_| random_barycentric(&mut rng))
        .any(|l| tet.det_at(l) * tet.straight_det() < 0.0);
    assert!(negative, "the fold is real, not only the bound's");
}

/// The unit cube cut into six tets around its diagonal, with its twelve boundary triangles.
fn cube() -> TetMesh {
    let vertices: Vec<DVec3> = (0..8)
        .map(|k| DVec3::new((k & 1) as f64, ((k >> 1) & 1) as f64, ((k >> 2) & 1) as f64))
        .collect();
    let mut tets = Vec::new();
    for path in [[1, 3], [1, 5], [2, 3], [2, 6], [4, 5], [4, 6]] {
        let t = [0, path[0], path[0] | path[1], 7];
        let [a, b, c, d] = t.map(|v: u32| vertices[v as usize]);
        let det = (b - a).dot((c - a).cross(d - a));
        tets.push(if det > 0.0 {
            t
        } else {
            [t[1], t[0], t[2], t[3]]
        });
    }
    let mut boundary = Vec::new();
    for axis in 0..3 {
        for side in 0..2u32 {
            let on: Vec<u32> = (0..8u32).filter(|v| (v >> axis) & 1 == side).collect();
            boundary.push([on[0], on[1], on[3]]);
            boundary.push([on[0], on[3], on[2]]);
        }
    }
    let n = boundary.len();
    TetMesh {
        vertices,
        tet_regions: vec![0; tets.len()],
        tets,
        boundary,
        boundary_markers: vec![1; n],
    }
}

/// Pushes every boundary node away from the cube's centre by `amount` of the edge length.
struct Bulge(f64);

impl BoundaryCurving for Bulge {
    fn curve(&self, _a: u32, _b: u32, mid: DVec3, _triangles: &[u32]) -> Option<DVec3> {
        let out = (mid - DVec3::splat(0.5)).normalize();
        Some(mid + out * self.0)
    }
}

#[test]
fn straight_elevation_puts_every_node_at_its_midpoint() {
    let mesh = cube();
    let (nodes, report) = elevate(&mesh, None);
    assert_eq!(report.n_edge_nodes, nodes.points.len());
    // 12 cube edges + 6 face diagonals + 1 body diagonal.
    assert_eq!(nodes.points.len(), 19);
    assert_eq!(report.n_boundary_edges, 18);
    assert_eq!(report.n_curved_edges, 0);
    assert_eq!(report.min_jacobian_ratio, 1.0);
    for (t, tet) in mesh.tets.iter().enumerate() {
        for (e, &(i, j)) in TET_EDGES.iter().enumerate() {
            let mid = (mesh.vertices[tet[i] as usize] + mesh.vertices[tet[j] as usize]) * 0.5;
            assert_eq!(nodes.position(&mesh, nodes.tet_edges[t][e]), mid);
        }
    }
}

#[test]
fn a_mild_bulge_curves_every_boundary_edge_and_folds_nothing() {
    let mesh = cube();
    let (_, report) = elevate(&mesh, Some(&Bulge(0.05)));
    assert_eq!(report.n_curved_edges, 18);
    assert_eq!(report.n_straightened_edges, 0);
    assert!(report.min_jacobian_ratio > 0.0);
}

/// Pushes every boundary node up by a fixed amount.
struct Lift(f64);

impl BoundaryCurving for Lift {
    fn curve(&self, _a: u32, _b: u32, mid: DVec3, _triangles: &[u32]) -> Option<DVec3> {
        Some(mid + DVec3::Z * self.0)
    }
}

#[test]
fn a_dent_that_would_fold_is_straightened() {
    // A flat tet: its base edges lifted above its apex would fold it.
    let corners = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(0.3, 0.3, 0.1)];
    let mesh = TetMesh {
        vertices: corners,
        tets: vec![[0, 1, 2, 3]],
        tet_regions: vec![0],
        boundary: vec![[0, 2, 1], [0, 1, 3], [1, 2, 3], [2, 0, 3]],
        boundary_markers: vec![1; 4],
    };
    let (nodes, report) = elevate(&mesh, Some(&Lift(0.2)));
    assert!(report.n_straightened_edges > 0, "{report:?}");
    assert!(report.min_jacobian_ratio > 0.0, "{report:?}");
    assert!(tet10(&mesh, &nodes, 0).jacobian_ratio_bound() > 0.0);
    // A lift well below the apex folds nothing.
    let (_, report) = elevate(&mesh, Some(&Lift(0.01)));
    assert_eq!(report.n_straightened_edges, 0, "{report:?}");
    assert_eq!(report.n_curved_edges, 6);
}

#[test]
fn a_projection_far_from_the_edge_is_not_taken() {
    let mesh = cube();
    let (_, report) = elevate(&mesh, Some(&Bulge(0.8)));
    assert_eq!(report.n_curved_edges, 0);
}
