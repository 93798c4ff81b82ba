use super::*;
use crate::plc::Facet;

/// The twelve triangles of the box [lo, hi], outward, as a PLC input (one facet each).
fn cube(lo: DVec3, hi: DVec3) -> PlcInput {
    let v: Vec<DVec3> = (0..8)
        .map(|i| {
            DVec3::new(
                if i & 1 == 0 { lo.x } else { hi.x },
                if i & 2 == 0 { lo.y } else { hi.y },
                if i & 4 == 0 { lo.z } else { hi.z },
            )
        })
        .collect();
    // Quads outward (counter-clockwise seen from outside).
    let quads = [
        [0, 2, 3, 1], // z = lo
        [4, 5, 7, 6], // z = hi
        [0, 1, 5, 4], // y = lo
        [2, 6, 7, 3], // y = hi
        [0, 4, 6, 2], // x = lo
        [1, 3, 7, 5], // x = hi
    ];
    let facets = quads
        .iter()
        .flat_map(|q| [[q[0], q[1], q[2]], [q[0], q[2], q[3]]])
        .enumerate()
        .map(|(k, t)| Facet {
            polygons: vec![t.to_vec()],
            marker: k as i32 + 1,
            ..Facet::default()
        })
        .collect();
    PlcInput {
        vertices: v,
        facets,
        holes: vec![],
        regions: vec![],
    }
}

fn inside(r: &Repaired, p: DVec3) -> bool {
    r.labels.inside(r.labels.count(p), p)
}

fn append(a: &mut PlcInput, b: PlcInput) {
    let n = a.vertices.len() as u32;
    a.vertices.extend(b.vertices);
    a.facets.extend(b.facets.into_iter().map(|mut f| {
        f.polygons[0].iter_mut().for_each(|v| *v += n);
        f
    }));
}

#[test]
fn a_clean_cube_needs_nothing() {
    let r = Repaired::new(&cube(DVec3::ZERO, DVec3::ONE)).unwrap();
    assert!(!r.defects.any(), "{:?}", r.defects);
    assert_eq!(r.defects.holes, 0);
    assert!(inside(&r, DVec3::splat(0.5)));
    assert!(!inside(&r, DVec3::splat(1.5)));
    assert_eq!(r.surface.triangles.len(), 12);
}

#[test]
fn a_missing_face_is_spanned_in_its_plane() {
    let mut input = cube(DVec3::ZERO, DVec3::ONE);
    input.facets.truncate(10); // the x = hi face gone
    let r = Repaired::new(&input).unwrap();
    assert_eq!(r.defects.open_edges, 4);
    assert_eq!(r.defects.holes, 1);
    assert!(inside(&r, DVec3::new(0.99, 0.5, 0.5)));
    assert!(!inside(&r, DVec3::new(1.01, 0.5, 0.5)));
    // A segment out through the hole passes the boundary once, in the missing face's plane.
    let (p, q) = (DVec3::new(0.7, 0.4, 0.45), DVec3::new(1.6, 0.5, 0.55));
    let x = r.labels.segments.crossings(p, q);
    let b = r
        .labels
        .boundary_points(p, q, &x, r.labels.count(p))
        .unwrap();
    assert_eq!(b.len(), 1, "{b:?}");
    assert!(b[0].triangle.is_none());
    assert!((b[0].point.x - 1.0).abs() < 1e-6, "{b:?}");
    // Through a face that is there: one boundary point on that input triangle.
    let q = DVec3::new(0.5, 0.5, -0.5);
    let x = r.labels.segments.crossings(p, q);
    let b = r
        .labels
        .boundary_points(p, q, &x, r.labels.count(p))
        .unwrap();
    assert_eq!(b.len(), 1, "{b:?}");
    assert!(b[0].triangle.is_some_and(|t| r.labels.is_input(t)));
}

#[test]
fn overlapping_cubes_are_their_union() {
    let mut input = cube(DVec3::ZERO, DVec3::ONE);
    append(&mut input, cube(DVec3::splat(0.5), DVec3::splat(1.5)));
    let r = Repaired::new(&input).unwrap();
    assert!(r.defects.intersecting_pairs > 0);
    assert_eq!(r.defects.components, 2);
    for p in [0.25, 0.75, 1.25].map(DVec3::splat) {
        assert!(inside(&r, p), "{p}");
    }
    assert!(!inside(&r, DVec3::new(1.25, 0.25, 0.25)));
    // Inside the union, a segment crossing both inner walls passes no boundary.
    let (p, q) = (DVec3::new(0.25, 0.3, 0.35), DVec3::new(1.25, 1.2, 1.3));
    let x = r.labels.segments.crossings(p, q);
    assert_eq!(x.len(), 2);
    let b = r
        .labels
        .boundary_points(p, q, &x, r.labels.count(p))
        .unwrap();
    assert!(b.is_empty(), "{b:?}");
    // Every triangle bounds the union somewhere (each is cut by the other cube).
    assert_eq!(r.defects.hidden_triangles, 0);
}

#[test]
fn a_shell_inside_another_is_hidden() {
    let mut input = cube(DVec3::ZERO, DVec3::splat(3.0));
    append(&mut input, cube(DVec3::ONE, DVec3::splat(2.0)));
    let r = Repaired::new(&input).unwrap();
    assert_eq!(r.defects.hidden_triangles, 12);
    assert_eq!(r.surface.triangles.len(), 12);
    assert!(inside(&r, DVec3::splat(1.5)));
}

#[test]
fn flipped_and_duplicated_input_is_cleaned() {
    let mut input = cube(DVec3::ZERO, DVec3::ONE);
    input.facets[3].polygons[0].swap(1, 2);
    // Every triangle with its own copies of its corners (an STL soup).
    let mut soup = PlcInput::default();
    for f in &input.facets {
        let n = soup.vertices.len() as u32;
        soup.vertices
            .extend(f.polygons[0].iter().map(|&v| input.vertices[v as usize]));
        soup.facets.push(Facet {
            polygons: vec![vec![n, n + 1, n + 2]],
            ..Facet::default()
        });
    }
    let r = Repaired::new(&soup).unwrap();
    assert_eq!(r.defects.duplicate_vertices, 36 - 8);
    assert_eq!(r.defects.flipped_triangles, 1);
    assert_eq!((r.defects.open_edges, r.defects.holes), (0, 0));
    assert!(inside(&r, DVec3::splat(0.5)));
    assert_eq!(r.surface.triangles.len(), 12);
}
