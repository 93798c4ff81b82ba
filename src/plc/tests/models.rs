//! Every model in models/ validates and gives its known volume and area; structural checks on the
//! ones with holes, cavities and regions.

use super::super::{validate, CellKind, Plc, PlcInput};
use super::{add_box, facet, read_model, unit_cube};
use glam::DVec3;

fn close(a: f64, b: f64, rel: f64) -> bool {
    (a - b).abs() <= rel * b.abs().max(1.0)
}

fn check_triangulations(name: &str, plc: &Plc) {
    for (k, f) in plc.facets.iter().enumerate() {
        let poly = f.polygon_area(&plc.vertices);
        assert!(
            close(f.area, poly, 1e-12),
            "{name} facet {k}: triangles {} vs polygon {poly}",
            f.area
        );
        assert_eq!(f.triangle_cells.len(), f.triangles.len());
        // Triangles wind counter-clockwise about the facet normal.
        for t in &f.triangles {
            let [a, b, c] = t.map(|v| plc.vertices[v as usize]);
            assert!(
                (b - a).cross(c - a).dot(f.plane.normal) > 0.0,
                "{name} facet {k}"
            );
        }
    }
    for s in &plc.segments {
        assert!(s.fan.len() >= 2, "{name}: open segment {:?}", s.vertices);
    }
}

fn validated(name: &str, input: &PlcInput) -> Plc {
    let plc = validate(input).unwrap_or_else(|e| panic!("{name}: {e}"));
    check_triangulations(name, &plc);
    plc
}

#[test]
fn poly_models_have_known_volume_and_area() {
    // (file, volume, boundary area, relative tolerance of the README figure)
    let table = [
        ("cube.poly", 1.0, 6.0, 1e-12),
        ("lshape.poly", 3.0, 14.0, 1e-12),
        ("stairs.poly", 20.0, 52.0, 1e-12),
        ("box_with_cavity.poly", 63.0, 102.0, 1e-12),
        ("two_materials.poly", 2.0, 11.0, 1e-12),
        ("thin_plate.poly", 50.0, 220.0, 1e-12),
        ("tetgen_example.poly", 17.9375, 64.9721, 1e-6),
        ("drilled_block.poly", 8.0, 32.0, 1e-12),
    ];
    let dir = super::models_dir().join("poly");
    let mut seen: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".poly"))
        .collect();
    seen.sort();
    let mut listed: Vec<String> = table.iter().map(|t| t.0.to_string()).collect();
    listed.sort();
    assert_eq!(
        seen, listed,
        "a model without reference figures in this test"
    );
    for (name, volume, area, tol) in table {
        let plc = validated(name, &read_model(&format!("poly/{name}")));
        assert!(
            close(plc.volume(), volume, tol),
            "{name}: volume {}",
            plc.volume()
        );
        assert!(
            close(plc.boundary_area(), area, tol),
            "{name}: area {}",
            plc.boundary_area()
        );
        // Axis-aligned boxes have no acute angle; tetgen_example has a sloped facet.
        let acute = plc.acute_angles();
        assert_eq!(
            acute.is_empty(),
            name != "tetgen_example.poly",
            "{name}: {acute:?}"
        );
    }
}

/// The same models turned by an arbitrary rotation: facets are then planar only up to
/// rounding and no coordinate is axis-aligned, so the exact predicates see general input.
#[test]
fn rotated_poly_models_keep_volume_and_area() {
    let rot = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.7);
    for name in [
        "cube.poly",
        "lshape.poly",
        "stairs.poly",
        "box_with_cavity.poly",
        "two_materials.poly",
        "thin_plate.poly",
        "tetgen_example.poly",
        "drilled_block.poly",
    ] {
        let input = read_model(&format!("poly/{name}"));
        let plain = validated(name, &input);
        let mut turned = input.clone();
        let turn = |p: &mut DVec3| *p = rot * *p;
        turned.vertices.iter_mut().for_each(turn);
        turned.holes.iter_mut().for_each(turn);
        turned.regions.iter_mut().for_each(|r| turn(&mut r.point));
        for f in &mut turned.facets {
            f.hole_points.iter_mut().for_each(turn);
        }
        let plc = validated(&format!("rotated {name}"), &turned);
        assert!(close(plc.volume(), plain.volume(), 1e-9), "{name}");
        assert!(
            close(plc.boundary_area(), plain.boundary_area(), 1e-9),
            "{name}"
        );
        assert_eq!(plc.cells.len(), plain.cells.len(), "{name}");
        let (a, b) = (plc.acute_angles(), plain.acute_angles());
        assert_eq!(a.segment_angles.len(), b.segment_angles.len(), "{name}");
        assert_eq!(a.dihedral_angles.len(), b.dihedral_angles.len(), "{name}");
    }
}

fn domain_cells(plc: &Plc) -> Vec<(f64, Option<usize>)> {
    plc.cells
        .iter()
        .filter_map(|c| match c.kind {
            CellKind::Domain { region } => Some((c.volume, region)),
            _ => None,
        })
        .collect()
}

#[test]
fn cavity_is_a_hole_cell() {
    let plc = validated("box_with_cavity", &read_model("poly/box_with_cavity.poly"));
    assert_eq!(plc.cells.len(), 3);
    let hole = plc
        .cells
        .iter()
        .find(|c| matches!(c.kind, CellKind::Hole { seed: 0 }));
    assert!(close(hole.unwrap().volume, 1.0, 1e-12));
    let cells = domain_cells(&plc);
    assert!(cells.len() == 1 && close(cells[0].0, 63.0, 1e-12) && cells[0].1.is_none());
    // Without the hole seed the cavity is meshed too.
    let mut input = read_model("poly/box_with_cavity.poly");
    input.holes.clear();
    let plc = validated("box_with_cavity without hole", &input);
    assert!(close(plc.volume(), 64.0, 1e-12));
    assert!(close(plc.boundary_area(), 102.0, 1e-12));
}

#[test]
fn two_materials_regions_and_internal_facet() {
    let plc = validated("two_materials", &read_model("poly/two_materials.poly"));
    let mut cells = domain_cells(&plc);
    cells.sort_by_key(|c| c.1);
    assert_eq!(cells.len(), 2);
    for (i, c) in cells.iter().enumerate() {
        assert!(close(c.0, 1.0, 1e-12) && c.1 == Some(i), "{cells:?}");
    }
    // The internal facet (index 9, marker 2) has a different region on each side.
    let f = &plc.facets[9];
    assert_eq!(f.marker, 2);
    let [a, b] = f.triangle_cells[0];
    assert_ne!(a, b);
    assert!(a != 0 && b != 0);
    // Its edges are shared by three facets each.
    let s = plc.segment(1, 7).unwrap();
    assert_eq!(s.facets.len(), 3);
    assert_eq!(s.fan.len(), 3);
}

#[test]
fn drilled_block_facets_have_hole_loops() {
    let plc = validated("drilled_block", &read_model("poly/drilled_block.poly"));
    for k in [0, 1] {
        let f = &plc.facets[k];
        assert_eq!(f.loops.len(), 2);
        assert_eq!(f.loops.iter().filter(|l| l.is_hole).count(), 1);
        assert!(close(f.area, 8.0, 1e-12));
    }
    // The same block with explicit hole polygons instead of hole points.
    let mut input = read_model("poly/drilled_block.poly");
    for k in [0, 1] {
        let f = &mut input.facets[k];
        f.hole_points.clear();
        f.hole_polygons = vec![f.polygons.pop().unwrap()];
    }
    let plc = validated("drilled_block with hole polygons", &input);
    assert!(close(plc.volume(), 8.0, 1e-12));
    assert!(close(plc.boundary_area(), 32.0, 1e-12));
}

#[test]
fn tetgen_example_regions_and_acute_angles() {
    let plc = validated("tetgen_example", &read_model("poly/tetgen_example.poly"));
    let mut cells = domain_cells(&plc);
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    assert_eq!(cells.len(), 2);
    assert!(close(cells[0].0, 6.0, 1e-12) && cells[0].1 == Some(1));
    assert!(close(cells[1].0, 14.0 - 0.9375 - 1.125, 1e-12) && cells[1].1 == Some(0));
    // The sloped facet meets the vertical walls at atan(2) = 63.43° on the segments.
    let acute = plc.acute_angles();
    assert!(!acute.segment_angles.is_empty());
    for a in &acute.segment_angles {
        assert!((a.degrees - 2f64.atan().to_degrees()).abs() < 1e-9, "{a:?}");
    }
    // The sloped facet (z = 4 at y = 0 down to z = 3 at y = 2) makes a 63.4° wedge with the
    // wall below it at y = 0 (lower region) and with the wall above it at y = 2 (upper one).
    assert_eq!(
        acute.dihedral_angles.len(),
        2,
        "{:?}",
        acute.dihedral_angles
    );
    for d in &acute.dihedral_angles {
        assert!((d.degrees - 2f64.atan().to_degrees()).abs() < 1e-9, "{d:?}");
    }
}

#[test]
fn boxes_touching_along_an_edge_or_a_vertex() {
    let mut input = unit_cube();
    // Shares only the edge x = 1, y = 1 (vertices 3 and 7 of the first box).
    add_box(
        &mut input,
        DVec3::new(1.0, 1.0, 0.0),
        DVec3::new(2.0, 2.0, 1.0),
    );
    // Reuse the shared corner ids instead of duplicates.
    let (dup_a, dup_b) = (8u32, 12u32); // (1,1,0) and (1,1,1) of the second box
    for f in &mut input.facets[6..] {
        for v in &mut f.polygons[0] {
            *v = match *v {
                x if x == dup_a => 3,
                x if x == dup_b => 7,
                x if x > dup_b => x - 2,
                x if x > dup_a => x - 1,
                x => x,
            };
        }
    }
    input.vertices.remove(12);
    input.vertices.remove(8);
    let plc = validated("edge-touching boxes", &input);
    assert!(close(plc.volume(), 2.0, 1e-12));
    assert_eq!(domain_cells(&plc).len(), 2);
    let s = plc.segment(3, 7).unwrap();
    assert_eq!(s.fan.len(), 4);
    // The four wedges around the shared edge alternate box / outside / box / outside.
    let outside = s.fan.iter().filter(|e| e.cell_after == 0).count();
    assert_eq!(outside, 2);
}

#[test]
fn boxes_touching_at_a_vertex() {
    let mut input = unit_cube();
    add_box(&mut input, DVec3::ONE, DVec3::splat(2.0));
    // The second box's corner (1,1,1) is vertex 8: reuse the first box's vertex 7.
    for f in &mut input.facets[6..] {
        for v in &mut f.polygons[0] {
            *v = match *v {
                8 => 7,
                x if x > 8 => x - 1,
                x => x,
            };
        }
    }
    input.vertices.remove(8);
    let plc = validated("vertex-touching boxes", &input);
    assert!(close(plc.volume(), 2.0, 1e-12));
    assert_eq!(domain_cells(&plc).len(), 2);
}

#[test]
fn island_inside_a_cavity() {
    // Box [0,4]^3, cavity [1,3]^3 (a hole), and a solid island [1.5,2.5]^3 inside the cavity.
    let mut input = PlcInput::default();
    add_box(&mut input, DVec3::ZERO, DVec3::splat(4.0));
    add_box(&mut input, DVec3::splat(1.0), DVec3::splat(3.0));
    add_box(&mut input, DVec3::splat(1.5), DVec3::splat(2.5));
    input.holes.push(DVec3::splat(1.2));
    let plc = validated("island in cavity", &input);
    let hole = plc
        .cells
        .iter()
        .find(|c| matches!(c.kind, CellKind::Hole { .. }));
    assert!(close(hole.unwrap().volume, 7.0, 1e-12));
    let mut cells: Vec<f64> = domain_cells(&plc).iter().map(|c| c.0).collect();
    cells.sort_by(f64::total_cmp);
    assert!(
        close(cells[0], 1.0, 1e-12) && close(cells[1], 56.0, 1e-12),
        "{cells:?}"
    );
    assert!(close(plc.volume(), 57.0, 1e-12));
    // Every facet borders the domain on one side.
    assert!(close(plc.boundary_area(), plc.total_facet_area(), 1e-12));
}

#[test]
fn dart_prism_with_reflex_vertex() {
    // A non-convex prism: its bottom and top facets need the constrained triangulation.
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
    let plc = validated("dart prism", &input);
    // area of the dart: triangles (A,B,C) + (A,C,D) = 2 + 2
    assert!(close(plc.facets[0].area, 4.0, 1e-12));
    assert!(close(plc.volume(), 4.0, 1e-12));
    // The side walls meet at the dart's polygon angles: the tips at (4,0) and (0,4) are
    // atan(1/3) = 18.43°, the reflex corner 270° and the corner at the origin 90°.
    let tip = (1.0f64 / 3.0).atan().to_degrees();
    let acute = plc.acute_angles();
    assert_eq!(
        acute.dihedral_angles.len(),
        2,
        "{:?}",
        acute.dihedral_angles
    );
    for d in &acute.dihedral_angles {
        assert!((d.degrees - tip).abs() < 1e-9, "{d:?}");
        let s = plc.segments[d.segment].vertices;
        assert!(s == [1, 5] || s == [3, 7], "{s:?}");
    }
    assert!(acute
        .segment_angles
        .iter()
        .any(|a| a.vertex == 1 && (a.degrees - tip).abs() < 1e-9));
}

/// Surfaces in off/: every triangle is a facet (no merging). They must validate as closed,
/// non-self-intersecting surfaces; the volume equals the divergence-theorem volume.
#[test]
fn off_models_validate() {
    let dir = super::models_dir().join("off");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().into_string().unwrap())
        .filter(|n| n.ends_with(".off"))
        .collect();
    names.sort();
    assert!(names.len() >= 11);
    for name in names {
        let input = read_model(&format!("off/{name}"));
        let t = std::time::Instant::now();
        let plc = validated(&name, &input);
        let elapsed = t.elapsed();
        // Closed triangle surfaces: all facets bound the domain; one outside cell.
        assert!(
            close(plc.boundary_area(), plc.total_facet_area(), 1e-12),
            "{name}"
        );
        assert!(plc.volume() > 0.0, "{name}");
        let acute = plc.acute_angles();
        eprintln!(
            "{name}: {} facets, volume {:.6}, area {:.6}, {} cells, {} acute segment pairs, \
             {} acute dihedrals, {elapsed:?}",
            plc.facets.len(),
            plc.volume(),
            plc.boundary_area(),
            plc.cells.len(),
            acute.segment_angles.len(),
            acute.dihedral_angles.len()
        );
        // Independent figure: the signed volume of the faces as wound in the file.
        let signed: f64 = input
            .facets
            .iter()
            .map(|f| {
                let p = |i: usize| input.vertices[f.polygons[0][i] as usize];
                (1..f.polygons[0].len() - 1)
                    .map(|i| p(0).dot(p(i).cross(p(i + 1))) / 6.0)
                    .sum::<f64>()
            })
            .sum();
        assert!(close(plc.volume(), signed.abs(), 1e-9), "{name}: {signed}");
        if name == "cube.off" {
            assert!(close(plc.volume(), 8.0, 1e-12) && close(plc.boundary_area(), 24.0, 1e-12));
        }
    }
}
