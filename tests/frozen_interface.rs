//! Frozen facets (`refine::mesh_frozen`), the primitive of partitioned meshing: the two halves
//! of a box, each meshed alone with their shared side given as the same triangles, frozen,
//! glue into one conforming mesh.

mod common;

use slivermesh::plc::{Facet, PlcInput};
use slivermesh::run::params::Params;
use slivermesh::run::spacing::ConstantSpacing;
use slivermesh::DVec3;
use spade::{DelaunayTriangulation, Point2, Triangulation};

/// The interface x = 0.5 of the box [0, 1]^3: an `n` x `n` grid on the square [0, 1]^2 (y, z),
/// jittered (inside along both axes, on a side along it) so that no four points are
/// cocircular, and their Delaunay triangles. Returns the points and the triangles.
fn interface(n: usize) -> (Vec<DVec3>, Vec<[usize; 3]>) {
    let jitter = |i: usize, j: usize, salt: usize| {
        let h = (i * 73_856_093) ^ (j * 19_349_663) ^ (salt * 83_492_791);
        ((h % 1001) as f64 / 1000.0 - 0.5) * 0.3 / n as f64
    };
    let mut points = vec![];
    for i in 0..=n {
        for j in 0..=n {
            let mut y = i as f64 / n as f64;
            let mut z = j as f64 / n as f64;
            if i > 0 && i < n {
                y += jitter(i, j, 1);
            }
            if j > 0 && j < n {
                z += jitter(i, j, 2);
            }
            points.push(DVec3::new(0.5, y, z));
        }
    }
    // The Delaunay triangles of the points in their plane: the faces a triangulation of
    // the points on one side has there.
    let mut dt: DelaunayTriangulation<Point2<f64>> = DelaunayTriangulation::new();
    for p in &points {
        dt.insert(Point2::new(p.y, p.z)).unwrap();
    }
    let tris = dt
        .inner_faces()
        .map(|f| f.vertices().map(|v| v.fix().index()))
        .collect();
    (points, tris)
}

/// The half x in [x0, 0.5] or [0.5, x1] of the box as a PLC whose side on x = 0.5 is the
/// interface's triangles (facets 0..): returns it with the number of interface facets.
fn half(left: bool, n: usize) -> (PlcInput, usize) {
    let (mut vertices, tris) = interface(n);
    let id = |i: usize, j: usize| (i * (n + 1) + j) as u32;
    let x = if left { 0.0 } else { 1.0 };
    let far = vertices.len() as u32;
    for (y, z) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
        vertices.push(DVec3::new(x, y, z));
    }
    let facet = |polygon: Vec<u32>, marker: i32| Facet {
        polygons: vec![polygon],
        hole_points: vec![],
        hole_polygons: vec![],
        marker,
    };
    let mut facets: Vec<Facet> = tris
        .iter()
        .map(|t| facet(t.map(|v| v as u32).to_vec(), 7))
        .collect();
    let frozen = facets.len();
    facets.push(facet((0..4).map(|k| far + k).collect(), 1));
    // The four sides between x = 0.5 and the far side, each with the interface's points on
    // its edge at x = 0.5.
    let sides: [(Vec<u32>, [u32; 2]); 4] = [
        ((0..=n).map(|i| id(i, 0)).collect(), [far, far + 1]), // z = 0
        ((0..=n).map(|j| id(n, j)).collect(), [far + 1, far + 2]), // y = 1
        (
            (0..=n).rev().map(|i| id(i, n)).collect(),
            [far + 2, far + 3],
        ), // z = 1
        ((0..=n).rev().map(|j| id(0, j)).collect(), [far + 3, far]), // y = 0
    ];
    for (edge, [a, b]) in sides {
        let mut polygon = edge;
        polygon.push(b);
        polygon.push(a);
        facets.push(facet(polygon, 2));
    }
    let input = PlcInput {
        vertices,
        facets,
        holes: vec![],
        regions: vec![],
    };
    (input, frozen)
}

#[test]
fn two_halves_meshed_alone_conform_on_their_frozen_interface() {
    let n = 16;
    let params = Params {
        improve: false,
        ..Params::default()
    };
    let spacing = ConstantSpacing(0.09);
    let mut parts = vec![];
    let mut frozen_refusals = 0;
    for left in [true, false] {
        let (input, n_frozen) = half(left, n);
        let frozen: Vec<u32> = (0..n_frozen as u32).collect();
        let (mesh, report) = slivermesh::refine::mesh_frozen(
            &input,
            &params,
            Some(&spacing),
            &frozen,
            slivermesh::refine::Unseeded::Domain,
        )
        .unwrap_or_else(|e| panic!("left {left}: {e}"));
        common::check_orientation(&mesh);
        // The interface keeps exactly its triangles.
        let on_interface: usize = mesh.boundary_markers.iter().filter(|&&m| m == 7).count();
        assert_eq!(on_interface, n_frozen, "left {left}");
        assert!(mesh.tets.len() > 1000, "{} tets", mesh.tets.len());
        frozen_refusals += report.refusals.frozen_interface;
        // Improved with its whole boundary fixed (no facet description to slide on): the
        // interface stays as it is.
        let improve = Params::default();
        let (mesh, _) = slivermesh::improve::finish(mesh, None, &improve, None).unwrap();
        let improved = slivermesh::quality::measure(&mesh).unwrap();
        println!(
            "left {left}: {} tets, min dihedral {:.2} refined, {:.2} improved; refusals {}",
            improved.n_tets,
            report.dihedral_range()[0],
            improved.min_dihedral_deg,
            report.refusals.summary()
        );
        // Measured 23.7 and 27.8 degrees (the serial cube: about 26).
        assert!(improved.min_dihedral_deg > 15.0, "left {left}");
        parts.push(mesh);
    }
    let whole = common::glue_by_coordinates(&parts);
    common::check_orientation(&whole);
    assert!(common::rel_close(common::total_volume(&whole), 1.0, 1e-9));
    // Conforming: every face in at most two tets, and the faces of one tet are on the box's
    // sides (none left open on x = 0.5).
    let faces = whole.face_counts();
    let on_box = |v: u32| {
        let p = whole.vertices[v as usize];
        p.to_array().iter().any(|&c| c == 0.0 || c == 1.0)
    };
    for (f, &k) in &faces {
        assert!(k <= 2, "face {f:?} in {k} tets");
        if k == 1 {
            let p = f.map(|v| whole.vertices[v as usize]);
            let on_one_side = (0..3).any(|axis| {
                (p.iter().all(|q| q[axis] == 0.0)) || (p.iter().all(|q| q[axis] == 1.0))
            });
            assert!(
                on_one_side && f.iter().all(|&v| on_box(v)),
                "open face {p:?}"
            );
        }
    }
    println!("refusals at the frozen interface: {frozen_refusals}");
}
