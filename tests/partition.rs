//! Partitioned meshing (`partition`): every part meshed alone from the same plan; glued by
//! coordinates the parts make one conforming mesh of the domain, with its volume and regions.

mod common;

use slivermesh::mesh::TetMesh;
use slivermesh::run::params::Params;
use slivermesh::run::spacing::ConstantSpacing;

/// Every face in at most two tets; the faces of one tet are boundary triangles, and so are
/// the faces between two regions (also where a region interface is a part interface).
fn check_conforming(m: &TetMesh) {
    let faces = m.face_counts();
    let boundary = common::boundary_keys(m);
    let mut region_of_face = std::collections::HashMap::new();
    for (t, &r) in m.tets.iter().zip(&m.tet_regions) {
        for skip in 0..4 {
            let mut f: Vec<u32> = (0..4).filter(|&i| i != skip).map(|i| t[i]).collect();
            f.sort_unstable();
            let f = [f[0], f[1], f[2]];
            if let Some(s) = region_of_face.insert(f, r) {
                assert!(
                    s == r || boundary.contains(&f),
                    "face {f:?} between regions {s} and {r} is not a boundary triangle"
                );
            }
        }
    }
    for (f, &k) in &faces {
        assert!(k <= 2, "face {f:?} in {k} tets");
        if k == 1 {
            let p = f.map(|v| m.vertices[v as usize]);
            assert!(
                boundary.contains(f),
                "open face {p:?} is not a boundary triangle"
            );
        }
    }
}

fn mesh_in_parts(model: &str, size: f64, parts: usize) -> (TetMesh, f64) {
    let spacing = ConstantSpacing(size);
    mesh_in_parts_with(model, Some(&spacing), parts)
}

fn mesh_in_parts_with(
    model: &str,
    spacing: Option<&dyn slivermesh::run::spacing::Spacing>,
    parts: usize,
) -> (TetMesh, f64) {
    let input = common::read_model(model);
    let params = Params::default();
    let plan = slivermesh::partition::plan(&input, &params, spacing, parts)
        .unwrap_or_else(|e| panic!("{model}: {e}"));
    let (coarse, band_tets, band_vertices) = plan.sizes();
    let mut meshes = vec![];
    let mut before = f64::MAX;
    for part in 0..parts {
        let meshed = slivermesh::partition::mesh_part(&plan, part)
            .unwrap_or_else(|e| panic!("{model} part {part}: {e}"));
        let (mesh, report) = (&meshed.mesh, &meshed.report);
        let q = slivermesh::quality::measure(mesh).unwrap();
        if std::env::var("PARTITION_WHERE").is_ok() {
            where_the_worst_are(mesh);
        }
        println!(
            "{model} {parts} parts: part {part}: {} tets, min dihedral {:.2}, refusals {}",
            mesh.tets.len(),
            q.min_dihedral_deg,
            report.refusals.summary()
        );
        before = before.min(q.min_dihedral_deg);
        meshes.push(meshed);
    }
    println!(
        "{model}: coarse {coarse} tets, band {band_tets} coarse tets, {band_vertices} vertices; \
         min dihedral {before:.2} before the interfaces move"
    );
    let (moved, passes) = slivermesh::partition::move_interfaces(meshes, plan.params())
        .unwrap_or_else(|e| panic!("{model}, moving the interfaces: {e}"));
    let mut worst = f64::MAX;
    for (part, mesh) in moved.iter().enumerate() {
        // A small part can go whole to a lower one with its zone.
        let Ok(q) = slivermesh::quality::measure(mesh) else {
            println!("{model} {parts} parts, interfaces moved: part {part} is empty");
            continue;
        };
        if std::env::var("PARTITION_WHERE").is_ok() {
            where_the_worst_are(mesh);
        }
        println!(
            "{model} {parts} parts, interfaces moved: part {part}: {} tets, min dihedral {:.2}",
            mesh.tets.len(),
            q.min_dihedral_deg
        );
        worst = worst.min(q.min_dihedral_deg);
    }
    println!("{model} {parts} parts: {passes} interface passes");
    (slivermesh::partition::glue(&moved).0, worst)
}

#[test]
fn cube_in_two_and_three_parts_is_conforming() {
    for parts in [2, 3] {
        let size = std::env::var("PARTITION_SIZE").map_or(0.08, |s| s.parse().unwrap());
        let (whole, worst) = mesh_in_parts("poly/cube.poly", size, parts);
        common::check_orientation(&whole);
        check_conforming(&whole);
        let volume = common::total_volume(&whole);
        assert!(common::rel_close(volume, 1.0, 1e-9), "volume {volume}");
        println!(
            "cube {parts} parts: {} tets, min dihedral {worst:.2}",
            whole.tets.len()
        );
        // With the interfaces moved, the serial run's 26.0 degrees (the improvement target);
        // measured 26.01 in 2 parts (two passes) and 3 (before moving them: 21.8 and 18.2).
        assert!(worst > 25.5, "cube in {parts} parts: {worst}");
        // And the radius-edge bound of a serial run (the tets the parts left over it next to
        // their frozen interfaces repaired in the zones): measured 1.971 / 1.996 at 0.08 in
        // 2 / 3 parts (2.363 / 1.994 before the repair).
        let rho = slivermesh::quality::measure(&whole).unwrap().max_rho;
        let rho0 = Params::default().rho0;
        assert!(rho <= rho0, "cube in {parts} parts: max rho {rho}");
    }
}

/// Every shared .poly model but the cube (holes, regions, thin parts, acute angles) in two
/// parts at its automatic spacing: conforming, and each region's volume is the serial run's.
#[test]
fn shared_poly_models_in_two_parts_keep_volume_and_regions() {
    let models = [
        "poly/box_with_cavity.poly",
        "poly/drilled_block.poly",
        "poly/lshape.poly",
        "poly/stairs.poly",
        "poly/tetgen_example.poly",
        "poly/thin_plate.poly",
        "poly/two_materials.poly",
    ];
    for model in models {
        let input = common::read_model(model);
        let (serial, _, _) = slivermesh::pipeline::mesh(&input, &Params::default(), None, None)
            .unwrap_or_else(|e| panic!("{model}: {e}"));
        let (whole, worst) = mesh_in_parts_with(model, None, 2);
        common::check_orientation(&whole);
        check_conforming(&whole);
        let mut regions: Vec<i32> = serial.tet_regions.clone();
        regions.sort_unstable();
        regions.dedup();
        for r in regions {
            let (a, b) = (
                common::region_volume(&serial, r),
                common::region_volume(&whole, r),
            );
            assert!(
                common::rel_close(a, b, 1e-9),
                "{model} region {r}: {a} serial, {b} in parts"
            );
        }
        // Measured with the interfaces moved: 24.1 (tetgen_example, serial 26.0) and
        // 26.05-31.01 on the others (serial 32.8-37.3); before moving them 23.9-31.0.
        assert!(worst > 23.5, "{model}: {worst}");
        let serial_min = slivermesh::quality::measure(&serial)
            .unwrap()
            .min_dihedral_deg;
        println!(
            "{model}: {} tets in parts (serial {}), min dihedral {worst:.2} (serial {serial_min:.2})",
            whole.tets.len(),
            serial.tets.len()
        );
    }
}

/// (Diagnosis) The smallest dihedral angles of the tets with a vertex on the part's open
/// faces (the interface), on its boundary triangles, and elsewhere.
fn where_the_worst_are(m: &TetMesh) {
    let faces = m.face_counts();
    let mut on_boundary = vec![false; m.vertices.len()];
    for b in &m.boundary {
        b.iter().for_each(|&v| on_boundary[v as usize] = true);
    }
    let mut on_interface = vec![false; m.vertices.len()];
    let boundary = common::boundary_keys(m);
    for (f, &k) in &faces {
        if k == 1 && !boundary.contains(f) {
            f.iter().for_each(|&v| on_interface[v as usize] = true);
        }
    }
    let mut worst = [f64::MAX; 3];
    for t in &m.tets {
        let one = TetMesh {
            vertices: t.iter().map(|&v| m.vertices[v as usize]).collect(),
            tets: vec![[0, 1, 2, 3]],
            tet_regions: vec![0],
            ..Default::default()
        };
        let d = slivermesh::quality::measure(&one).unwrap().min_dihedral_deg;
        let k = if t.iter().any(|&v| on_interface[v as usize]) {
            0
        } else if t.iter().any(|&v| on_boundary[v as usize]) {
            1
        } else {
            2
        };
        worst[k] = worst[k].min(d);
    }
    println!(
        "  worst at the interface {:.2}, at the boundary {:.2}, elsewhere {:.2}",
        worst[0], worst[1], worst[2]
    );
}

/// Approximate mode: `plan` makes the surface once and the parts mesh it in keep mode; with
/// the interfaces moved every part is at the approximate mode's improvement target or above.
/// In 2 parts a subsegment of fandisk's surface next to the interface is one that a frozen
/// interface triangle keeps from being split: the parts' refinement must not remove it.
#[test]
fn fandisk_approximate_in_two_and_three_parts() {
    let input = common::read_model("off/fandisk.off");
    let params = Params {
        surface_mode: slivermesh::run::params::SurfaceMode::Approximate,
        ..Params::default()
    };
    for n in [2, 3] {
        let plan = slivermesh::partition::plan(&input, &params, None, n).unwrap();
        let parts: Vec<_> = (0..n)
            .map(|p| slivermesh::partition::mesh_part(&plan, p).unwrap())
            .collect();
        let (moved, _) = slivermesh::partition::move_interfaces(parts, plan.params()).unwrap();
        let whole = slivermesh::partition::glue(&moved).0;
        common::check_orientation(&whole);
        check_conforming(&whole);
        // Measured 22.90 / 25.84 degrees in 2 / 3 parts after moving the interfaces, 16.51 /
        // 14.45 before (serial 20.00).
        let min = slivermesh::quality::measure(&whole)
            .unwrap()
            .min_dihedral_deg;
        println!(
            "fandisk in {n} parts: {} tets, min dihedral {min:.2}",
            whole.tets.len()
        );
        assert!(
            min >= slivermesh::run::params::APPROXIMATE_IMPROVE_TARGET,
            "{n} parts: {min}"
        );
    }
}

/// Boundary triangles with their markers, by their corners' coordinates.
fn boundary_by_corners(m: &TetMesh) -> Vec<(slivermesh::partition::Corners, i32)> {
    let mut out: Vec<_> = (m.boundary.iter().zip(&m.boundary_markers))
        .map(|(b, &marker)| (slivermesh::partition::corners(b, &m.vertices), marker))
        .collect();
    out.sort_unstable();
    out
}

/// Cutting a zone out (around bad tets here, across a region interface) and putting it back
/// unchanged gives the mesh back: its tets, vertices, and boundary and region-interface
/// triangles, none lost or doubled.
#[test]
fn a_zone_cut_out_and_put_back_gives_the_mesh_back() {
    let input = common::read_model("poly/two_materials.poly");
    let (mesh, _, _) = slivermesh::pipeline::mesh(&input, &Params::default(), None, None).unwrap();
    let regions: std::collections::BTreeSet<i32> = mesh.tet_regions.iter().copied().collect();
    assert!(regions.len() >= 2, "{regions:?}");
    // Every other tet of the first region counts as bad: the zone has tets on both sides of
    // the region interface, and the rest keeps region-interface triangles it shares with it.
    let first = *regions.iter().next().unwrap();
    let bad: Vec<bool> = (mesh.tet_regions.iter().enumerate())
        .map(|(t, &r)| r == first && t % 2 == 0)
        .collect();
    let seeds: Vec<slivermesh::partition::Seed> = (bad.iter())
        .map(|&b| match b {
            true => slivermesh::partition::Seed::BelowTarget,
            false => slivermesh::partition::Seed::No,
        })
        .collect();
    let cut = slivermesh::partition::cut_zone(mesh.clone(), &[], &seeds);
    assert!(!cut.zone.tets.is_empty() && !cut.rest.tets.is_empty());
    assert_eq!(cut.zone.tets.len() + cut.rest.tets.len(), mesh.tets.len());
    let shares = slivermesh::partition::share_zones(&[cut.zone]);
    assert_eq!(shares.len(), 1);
    assert!(
        shares[0].next_interface.is_empty(),
        "one part has no interface"
    );
    let share = shares.into_iter().next().unwrap();
    let (back, interface) = slivermesh::partition::rejoin(cut.rest, share.zone, &[]);
    assert!(interface.is_empty());
    assert_eq!(back.tets.len(), mesh.tets.len());
    assert_eq!(back.vertices.len(), mesh.vertices.len());
    assert_eq!(boundary_by_corners(&back), boundary_by_corners(&mesh));
    common::check_orientation(&back);
    check_conforming(&back);
    for &r in &regions {
        let (a, b) = (
            common::region_volume(&mesh, r),
            common::region_volume(&back, r),
        );
        assert!(common::rel_close(a, b, 1e-12), "region {r}: {a} vs {b}");
    }
}

/// After a pass of moving the interfaces, each part's interface triangles (which the next
/// pass grows its zone from) are exactly the faces it shares with the other parts.
#[test]
fn the_moved_interfaces_are_the_faces_between_the_parts() {
    let input = common::read_model("poly/cube.poly");
    let spacing = ConstantSpacing(0.1);
    let params = Params::default();
    let plan = slivermesh::partition::plan(&input, &params, Some(&spacing), 3).unwrap();
    let parts: Vec<_> = (0..3)
        .map(|p| slivermesh::partition::mesh_part(&plan, p).unwrap())
        .collect();
    let target = plan.params().effective_improve_target();
    let cuts: Vec<_> = (parts.into_iter())
        .map(|p| {
            let (_, _, seeds) = slivermesh::partition::bad_tets(&p.mesh, target, params.rho0);
            slivermesh::partition::cut_zone(p.mesh, &p.interface, &seeds)
        })
        .collect();
    let zones: Vec<TetMesh> = cuts.iter().map(|c| c.zone.clone()).collect();
    let shares = slivermesh::partition::share_zones(&zones);
    let moved: Vec<(TetMesh, Vec<[u32; 3]>)> = (cuts.into_iter().zip(shares))
        .map(|(cut, share)| {
            let (improved, _) =
                slivermesh::partition::improve_zone(share.zone, plan.params()).unwrap();
            slivermesh::partition::rejoin(cut.rest, improved, &share.next_interface)
        })
        .collect();
    // Each face of each part by corners, with the parts that have it.
    let mut face_parts: std::collections::HashMap<_, Vec<usize>> = Default::default();
    for (p, (mesh, _)) in moved.iter().enumerate() {
        let mut faces: Vec<_> = mesh.face_counts().into_keys().collect();
        faces.sort_unstable();
        for f in faces {
            (face_parts.entry(slivermesh::partition::corners(&f, &mesh.vertices)))
                .or_default()
                .push(p);
        }
    }
    for (p, (mesh, interface)) in moved.iter().enumerate() {
        let mut listed: Vec<_> = (interface.iter())
            .map(|f| slivermesh::partition::corners(f, &mesh.vertices))
            .collect();
        listed.sort_unstable();
        let mut shared: Vec<_> = (face_parts.iter())
            .filter(|(_, parts)| parts.len() == 2 && parts.contains(&p))
            .map(|(c, _)| *c)
            .collect();
        shared.sort_unstable();
        assert!(!shared.is_empty(), "part {p} shares no face");
        assert_eq!(listed, shared, "part {p}");
    }
}
