//! One small input per validation error; each checks the variant and that the message names
//! the offending item.

use super::super::{validate, PlcError, PlcInput, PolygonKind, PolygonRef, Region, Seed};
use super::{add_box, facet, read_model, unit_cube};
use glam::DVec3;

fn fails(input: &PlcInput) -> (PlcError, String) {
    let e = validate(input).expect_err("input should be rejected");
    let msg = e.to_string();
    (e, msg)
}

fn has(msg: &str, parts: &[&str]) {
    for p in parts {
        assert!(msg.contains(p), "message {msg:?} lacks {p:?}");
    }
}

fn outer(facet: usize, index: usize) -> PolygonRef {
    PolygonRef {
        facet,
        kind: PolygonKind::Outer,
        index,
    }
}

/// A unit square facet in z = 0 with vertices 0..4.
fn square() -> PlcInput {
    PlcInput {
        vertices: vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ],
        facets: vec![facet(&[&[0, 1, 2, 3]])],
        ..PlcInput::default()
    }
}

#[test]
fn no_facets() {
    let (e, msg) = fails(&PlcInput::default());
    assert_eq!(e, PlcError::NoFacets);
    has(&msg, &["no facets"]);
}

#[test]
fn coordinate_not_finite_or_out_of_range() {
    let mut input = unit_cube();
    input.vertices[3].y = f64::NAN;
    let (e, msg) = fails(&input);
    assert!(matches!(e, PlcError::BadCoordinate { vertex: 3, .. }));
    has(&msg, &["vertex 3", "not finite"]);
    let mut input = unit_cube();
    input.vertices[5].z = 1e31;
    let (_, msg) = fails(&input);
    has(&msg, &["vertex 5", "1e31", "exceeds"]);
}

#[test]
fn duplicate_vertices() {
    let mut input = unit_cube();
    input.vertices.push(DVec3::new(0.0, 1.0, 0.0)); // same as vertex 2
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::DuplicateVertex {
            first: 2,
            second: 8,
            ..
        }
    ));
    has(&msg, &["vertices 2 and 8", "(0.0, 1.0, 0.0)"]);
}

#[test]
fn facet_without_polygon() {
    let mut input = unit_cube();
    input.facets[4].polygons.clear();
    let (e, msg) = fails(&input);
    assert_eq!(e, PlcError::EmptyFacet { facet: 4 });
    has(&msg, &["facet 4"]);
}

#[test]
fn vertex_index_out_of_range() {
    let mut input = unit_cube();
    input.facets[2].polygons[0][1] = 99;
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::IndexOutOfRange { polygon, position: 1, index: 99, num_vertices: 8 }
            if polygon == outer(2, 0)
    ));
    has(&msg, &["polygon 0 of facet 2", "99", "8 vertices"]);
}

#[test]
fn polygon_with_fewer_than_three_vertices() {
    let mut input = unit_cube();
    input.facets[1].polygons.push(vec![4, 5]);
    let (e, msg) = fails(&input);
    assert_eq!(
        e,
        PlcError::TooFewVertices {
            polygon: outer(1, 1),
            count: 2
        }
    );
    has(&msg, &["polygon 1 of facet 1", "2 vertices"]);
}

/// The unit cube with vertex 8 at `p` added to facet 0 (z = 0) as a lone point.
fn cube_with_lone_point(p: DVec3) -> PlcInput {
    let mut input = unit_cube();
    input.vertices.push(p);
    input.facets[0].polygons.push(vec![8]);
    input
}

#[test]
fn lone_point_inside_a_facet_is_a_triangulation_vertex() {
    let plc = validate(&cube_with_lone_point(DVec3::new(0.25, 0.5, 0.0))).unwrap();
    let f = &plc.facets[0];
    assert_eq!(f.triangles.iter().filter(|t| t.contains(&8)).count(), 4);
    assert!(f.segments().all(|s| !s.contains(&8)));
    assert!(plc.isolated_vertices.is_empty());
    assert!((plc.volume() - 1.0).abs() < 1e-12);
}

#[test]
fn lone_point_on_an_edge_or_outside_its_facet() {
    for (p, on_edge, place) in [
        (DVec3::new(0.5, 0.0, 0.0), true, "on a polygon edge"),
        (DVec3::new(2.0, 0.5, 0.0), false, "outside"),
    ] {
        let (e, msg) = fails(&cube_with_lone_point(p));
        assert_eq!(
            e,
            PlcError::LonePointOffFacet {
                polygon: outer(0, 1),
                vertex: 8,
                on_edge
            }
        );
        has(&msg, &["polygon 1 of facet 0", "vertex 8", place]);
    }
}

#[test]
fn repeated_vertex_in_polygon() {
    let mut input = unit_cube();
    input.facets[0].polygons[0] = vec![0, 2, 3, 2, 1];
    let (e, msg) = fails(&input);
    assert_eq!(
        e,
        PlcError::RepeatedVertex {
            polygon: outer(0, 0),
            vertex: 2
        }
    );
    has(&msg, &["polygon 0 of facet 0", "repeats vertex 2"]);
}

#[test]
fn degenerate_facet() {
    let mut input = square();
    input.vertices.push(DVec3::new(2.0, 0.0, 0.0));
    input.facets.push(facet(&[&[0, 1, 4]]));
    let (e, msg) = fails(&input);
    assert_eq!(e, PlcError::DegenerateFacet { facet: 1 });
    has(&msg, &["facet 1", "collinear"]);
}

#[test]
fn non_planar_facet() {
    let mut input = unit_cube();
    input.vertices[7].z = 1.001; // top facet (1) bends
    let (e, msg) = fails(&input);
    match e {
        PlcError::NonPlanarFacet {
            facet,
            distance,
            tolerance,
            ..
        } => {
            assert_eq!(facet, 1);
            assert!(distance > 1e-4 && tolerance < 1e-8);
        }
        e => panic!("{e}"),
    }
    has(&msg, &["facet 1 is not planar", "best-fit plane"]);
    // Rounding-level noise is accepted.
    let mut input = unit_cube();
    input.vertices[7].z = 1.0 + 1e-12;
    assert!(validate(&input).is_ok());
}

#[test]
fn vertices_coincide_in_the_facet_plane() {
    let mut input = square();
    // 1e-13 above vertex 1: planar within tolerance, but the same point once projected.
    input.vertices.push(DVec3::new(1.0, 0.0, 1e-13));
    input.facets[0].polygons[0] = vec![0, 1, 4, 2, 3];
    let (e, msg) = fails(&input);
    assert_eq!(
        e,
        PlcError::CoincidentInPlane {
            facet: 0,
            first: 1,
            second: 4
        }
    );
    has(&msg, &["facet 0", "vertices 1 and 4 coincide"]);
}

#[test]
fn non_simple_polygon() {
    let mut input = square();
    input.facets[0].polygons[0] = vec![0, 2, 1, 3]; // bow tie
    let (e, msg) = fails(&input);
    assert!(matches!(e, PlcError::EdgesIntersect { .. }), "{e}");
    has(
        &msg,
        &[
            "non-simple",
            "edge (0, 2)",
            "edge (1, 3)",
            "polygon 0 of facet 0",
        ],
    );
    // A vertex touching another edge of the same polygon is not simple either.
    let mut input = square();
    input.vertices.push(DVec3::new(0.5, 0.0, 0.0)); // on edge (0, 1)
    input.facets[0].polygons[0] = vec![0, 1, 2, 4, 3];
    let (e, msg) = fails(&input);
    assert!(matches!(e, PlcError::EdgesIntersect { .. }), "{e}");
    has(&msg, &["edge (0, 1)"]);
    assert!(
        msg.contains("edge (2, 4)") || msg.contains("edge (4, 3)"),
        "{msg}"
    );
}

#[test]
fn hole_polygon_outside_its_facet() {
    let mut input = square();
    for p in [[2.0, 0.0], [3.0, 0.0], [3.0, 1.0]] {
        input.vertices.push(DVec3::new(p[0], p[1], 0.0));
    }
    input.facets[0].hole_polygons.push(vec![4, 5, 6]);
    let (e, msg) = fails(&input);
    let hole = PolygonRef {
        facet: 0,
        kind: PolygonKind::Hole,
        index: 0,
    };
    assert_eq!(e, PlcError::HoleOutsideFacet { polygon: hole });
    has(&msg, &["hole polygon 0 of facet 0", "not inside"]);
}

#[test]
fn facet_hole_point_outside_or_on_edge() {
    let mut input = square();
    input.facets[0].hole_points.push(DVec3::new(0.5, 0.5, 0.0));
    input.facets[0].hole_points.push(DVec3::new(2.0, 0.5, 0.0));
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::HolePointOutsideFacet {
            facet: 0,
            hole: 1,
            ..
        }
    ));
    has(&msg, &["facet 0", "hole point 1", "(2.0, 0.5, 0.0)"]);
    let mut input = square();
    input.facets[0].hole_points.push(DVec3::new(1.0, 0.5, 0.0));
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::HolePointOnEdge {
            facet: 0,
            hole: 0,
            ..
        }
    ));
    has(&msg, &["hole point 0", "on a polygon edge"]);
}

#[test]
fn facet_hole_point_off_the_plane() {
    let mut input = square();
    input.facets[0].hole_points.push(DVec3::new(0.5, 0.5, 0.25));
    let (e, msg) = fails(&input);
    assert!(
        matches!(
            e,
            PlcError::HolePointOffPlane {
                facet: 0,
                hole: 0,
                ..
            }
        ),
        "{e}"
    );
    has(
        &msg,
        &[
            "facet 0",
            "hole point 0",
            "(0.5, 0.5, 0.25)",
            "off the facet's plane",
        ],
    );
    let mut input = square();
    input.facets[0]
        .hole_points
        .push(DVec3::new(0.5, f64::NAN, 0.0));
    let (e, _) = fails(&input);
    assert!(matches!(e, PlcError::HolePointOffPlane { .. }), "{e}");
}

#[test]
fn polygon_inside_a_hole_borders_nothing() {
    let mut input = read_model("poly/drilled_block.poly");
    // A small square inside the drilled hole of the bottom facet (facet 0).
    let base = input.vertices.len() as u32;
    for p in [[1.4, 1.4], [1.6, 1.4], [1.6, 1.6], [1.4, 1.6]] {
        input.vertices.push(DVec3::new(p[0], p[1], 0.0));
    }
    input.facets[0].polygons.push((base..base + 4).collect());
    // Hole points in the ring around it and in it: both sides of its edges are removed.
    input.facets[0].hole_points[0] = DVec3::new(1.2, 1.2, 0.0);
    input.facets[0].hole_points.push(DVec3::new(1.5, 1.5, 0.0));
    let (e, msg) = fails(&input);
    assert!(
        matches!(e, PlcError::EdgeOutsideFacet { polygon, .. } if polygon == outer(0, 2)),
        "{e}"
    );
    has(&msg, &["polygon 2 of facet 0", "borders no part"]);
}

#[test]
fn overlapping_boxes_intersect() {
    let mut input = unit_cube();
    add_box(&mut input, DVec3::splat(0.5), DVec3::splat(1.5));
    let (e, msg) = fails(&input);
    match e {
        PlcError::FacetsIntersect { facets, .. } => {
            assert!(facets[0] < 6 && facets[1] >= 6, "{facets:?}")
        }
        e => panic!("{e}"),
    }
    has(&msg, &["intersect other than along shared edges"]);
}

#[test]
fn duplicate_facet_intersects() {
    let mut input = unit_cube();
    input.facets.push(input.facets[2].clone());
    let (e, msg) = fails(&input);
    assert!(
        matches!(e, PlcError::FacetsIntersect { facets: [2, 6], .. }),
        "{e}"
    );
    has(&msg, &["facets 2 and 6"]);
}

#[test]
fn box_touching_another_box_face_intersects() {
    // A small box standing on the top face of the unit cube, sharing no vertex: its bottom
    // lies inside the cube's top facet.
    let mut input = unit_cube();
    add_box(
        &mut input,
        DVec3::new(0.25, 0.25, 1.0),
        DVec3::new(0.75, 0.75, 2.0),
    );
    let (e, msg) = fails(&input);
    assert!(
        matches!(e, PlcError::FacetsIntersect { facets: [1, 6], .. }),
        "{e}"
    );
    has(&msg, &["facets 1 and 6"]);
}

#[test]
fn facets_meeting_along_a_diagonal() {
    // A dart-shaped prism: the bottom facet's only diagonal is (0, 2). A tetrahedron below
    // it has (0, 2) as an edge, so it touches the bottom facet along a non-segment.
    let dart = [[0.0, 0.0], [4.0, 0.0], [1.0, 1.0], [0.0, 4.0]];
    let mut input = PlcInput::default();
    for z in [0.0, 1.0] {
        for p in dart {
            input.vertices.push(DVec3::new(p[0], p[1], z));
        }
    }
    input.facets.push(facet(&[&[0, 1, 2, 3]]));
    input.facets.push(facet(&[&[4, 5, 6, 7]]));
    for i in 0..4u32 {
        let j = (i + 1) % 4;
        input.facets.push(facet(&[&[i, j, j + 4, i + 4]]));
    }
    input.vertices.push(DVec3::new(0.2, 0.6, -1.0)); // 8
    input.vertices.push(DVec3::new(0.6, 0.2, -1.0)); // 9
    for t in [[0, 2, 8], [0, 9, 2], [0, 8, 9], [2, 9, 8]] {
        input.facets.push(facet(&[&t]));
    }
    let (e, msg) = fails(&input);
    assert!(
        matches!(
            e,
            PlcError::FacetsMeetOffSegment {
                facets: [0, _],
                edge: [0, 2]
            }
        ),
        "{e}"
    );
    has(
        &msg,
        &["facets 0 and", "along (0, 2)", "not a polygon edge of both"],
    );
}

#[test]
fn open_surface() {
    let (e, msg) = fails(&square());
    assert_eq!(
        e,
        PlcError::SurfaceNotClosed {
            edge: [0, 1],
            facet: 0
        }
    );
    has(&msg, &["surface not closed at edge (0, 1) of facet 0"]);
    let mut input = unit_cube();
    input.facets.remove(3); // the y = 1 side
    let (e, msg) = fails(&input);
    assert!(matches!(e, PlcError::SurfaceNotClosed { .. }), "{e}");
    has(&msg, &["surface not closed"]);
}

#[test]
fn isolated_vertex_on_a_facet() {
    let mut input = unit_cube();
    input.vertices.push(DVec3::new(0.5, 0.5, 0.0));
    let (e, msg) = fails(&input);
    assert!(
        matches!(
            e,
            PlcError::VertexOnFacet {
                vertex: 8,
                facet: 0,
                ..
            }
        ),
        "{e}"
    );
    has(&msg, &["vertex 8", "(0.5, 0.5, 0.0)", "facet 0"]);
    // Off the surface it is simply kept.
    let mut input = unit_cube();
    input.vertices.push(DVec3::splat(0.5));
    assert_eq!(validate(&input).unwrap().isolated_vertices, vec![8]);
}

fn region(p: DVec3, attribute: i32) -> Region {
    Region {
        point: p,
        attribute,
        max_size: None,
    }
}

#[test]
fn seed_outside_bounding_box() {
    let mut input = unit_cube();
    input.holes.push(DVec3::splat(5.0));
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::SeedOutsideBoundingBox {
            seed: Seed::Hole(0),
            ..
        }
    ));
    has(&msg, &["hole seed 0", "(5.0, 5.0, 5.0)", "bounding box"]);
}

#[test]
fn seed_on_facet() {
    let mut input = unit_cube();
    input.regions.push(region(DVec3::splat(0.5), 1));
    input.regions.push(region(DVec3::new(0.5, 0.5, 1.0), 2));
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::SeedOnFacet {
            seed: Seed::Region(1),
            facet: 1,
            ..
        }
    ));
    has(&msg, &["region seed 1", "lies on facet 1"]);
}

#[test]
fn seed_outside_domain() {
    let mut input = read_model("poly/lshape.poly");
    input.regions.push(region(DVec3::new(1.5, 1.5, 0.5), 7)); // in the L's notch
    let (e, msg) = fails(&input);
    assert!(matches!(
        e,
        PlcError::SeedOutsideDomain {
            seed: Seed::Region(0),
            ..
        }
    ));
    has(
        &msg,
        &[
            "region seed 0",
            "(1.5, 1.5, 0.5)",
            "outside every enclosed volume",
        ],
    );
}

#[test]
fn region_in_a_hole() {
    let mut input = read_model("poly/box_with_cavity.poly");
    input.regions.push(region(DVec3::splat(1.0), 1));
    input.regions.push(region(DVec3::splat(2.2), 2));
    let (e, msg) = fails(&input);
    assert_eq!(e, PlcError::RegionInHole { region: 1, hole: 0 });
    has(&msg, &["region seed 1", "hole seed 0"]);
}

#[test]
fn conflicting_regions() {
    let mut input = unit_cube();
    input.regions.push(region(DVec3::splat(0.25), 1));
    input.regions.push(region(DVec3::splat(0.5), 1)); // same attribute: fine
    assert!(validate(&input).is_ok());
    input.regions.push(region(DVec3::splat(0.75), 2));
    let (e, msg) = fails(&input);
    assert_eq!(
        e,
        PlcError::ConflictingRegions {
            first: 0,
            second: 2
        }
    );
    has(&msg, &["region seeds 0 and 2"]);
}

#[test]
fn everything_is_a_hole() {
    let mut input = unit_cube();
    input.holes.push(DVec3::splat(0.5));
    let (e, msg) = fails(&input);
    assert_eq!(e, PlcError::EmptyDomain);
    has(&msg, &["every enclosed volume is a hole"]);
}
