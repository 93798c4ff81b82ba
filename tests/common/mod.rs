//! Helpers shared by the integration tests: model paths and mesh invariant checkers.
#![allow(dead_code)]

pub mod corpus;
pub mod dirty;
pub mod size_caps;

use slivermesh::geom::{insphere, orient3d};
use slivermesh::mesh::TetMesh;
use slivermesh::plc::PlcInput;
use slivermesh::DVec3;
use std::collections::HashMap;
use std::path::PathBuf;

/// The test models, kept in the repository (`models/`, see its README).
pub fn models_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models")
}

pub fn read_model(rel: &str) -> PlcInput {
    let opts = slivermesh::io::ReadOptions {
        merge_coplanar: rel.ends_with(".off"),
    };
    slivermesh::io::read_plc(&models_dir().join(rel), &opts)
        .unwrap_or_else(|e| panic!("reading {rel}: {e}"))
}

pub fn tet_volume(m: &TetMesh, t: [u32; 4]) -> f64 {
    let p = t.map(|v| m.vertices[v as usize]);
    orient3d(p[0], p[1], p[2], p[3]) / 6.0
}

/// Every tet positively oriented.
pub fn check_orientation(m: &TetMesh) {
    for (i, &t) in m.tets.iter().enumerate() {
        assert!(
            tet_volume(m, t) > 0.0,
            "tet {i} {t:?} is not positively oriented"
        );
    }
}

/// Faces shared by two tets: the opposite vertex lies outside (or on) the circumsphere
/// (local Delaunay over every interior face implies the tets are Delaunay).
pub fn check_delaunay(m: &TetMesh) {
    let mut faces: HashMap<[u32; 3], Vec<(usize, u32)>> = HashMap::new();
    for (i, t) in m.tets.iter().enumerate() {
        for k in 0..4 {
            let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
            f.sort_unstable();
            faces.entry(f).or_default().push((i, t[k]));
        }
    }
    for (f, owners) in &faces {
        assert!(
            owners.len() <= 2,
            "face {f:?} shared by {} tets",
            owners.len()
        );
        if owners.len() == 2 {
            let (t, _) = owners[0];
            let (_, apex) = owners[1];
            let p = m.tets[t].map(|v| m.vertices[v as usize]);
            let s = insphere(p[0], p[1], p[2], p[3], m.vertices[apex as usize]);
            assert!(
                s <= 0.0,
                "face {f:?}: vertex {apex} inside the circumsphere of tet {t}"
            );
        }
    }
}

pub fn triangle_area(m: &TetMesh, t: [u32; 3]) -> f64 {
    let [a, b, c] = t.map(|v| m.vertices[v as usize]);
    0.5 * (b - a).cross(c - a).length()
}

/// Area of a planar polygon (3D vertex loop), by the vector area.
pub fn polygon_area(pts: &[DVec3]) -> f64 {
    let mut s = DVec3::ZERO;
    for k in 0..pts.len() {
        s += pts[k].cross(pts[(k + 1) % pts.len()]);
    }
    0.5 * s.length()
}

/// Area of each input facet bounding the domain (as the validator measures it: holes
/// removed), summed per marker.
pub fn facet_area_by_marker(input: &PlcInput) -> HashMap<i32, f64> {
    let plc = slivermesh::plc::validate(input).expect("valid input");
    let mut out: HashMap<i32, f64> = HashMap::new();
    for f in &plc.facets {
        // A facet with no domain on either side (e.g. between a hole and the outside) is not
        // part of the meshed boundary.
        let bounds_domain = f.triangle_cells.iter().flatten().any(|&c| {
            matches!(
                plc.cells[c as usize].kind,
                slivermesh::plc::CellKind::Domain { .. }
            )
        });
        if bounds_domain {
            *out.entry(f.marker).or_default() += f.area;
        }
    }
    out
}

pub fn boundary_area_by_marker(m: &TetMesh) -> HashMap<i32, f64> {
    let mut out: HashMap<i32, f64> = HashMap::new();
    for (t, &mk) in m.boundary.iter().zip(&m.boundary_markers) {
        *out.entry(mk).or_default() += triangle_area(m, *t);
    }
    out
}

pub fn total_volume(m: &TetMesh) -> f64 {
    m.tets.iter().map(|&t| tet_volume(m, t)).sum()
}

pub fn region_volume(m: &TetMesh, region: i32) -> f64 {
    m.tets
        .iter()
        .zip(&m.tet_regions)
        .filter(|(_, &r)| r == region)
        .map(|(&t, _)| tet_volume(m, t))
        .sum()
}

/// The surface is closed: each boundary edge of an external facet is shared by an even
/// number of boundary triangles, and every boundary triangle is a face of a tet.
pub fn check_boundary_faces_are_tet_faces(m: &TetMesh) {
    let mut faces = std::collections::HashSet::new();
    for t in &m.tets {
        for k in 0..4 {
            let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
            f.sort_unstable();
            faces.insert(f);
        }
    }
    for b in &m.boundary {
        let mut f = *b;
        f.sort_unstable();
        assert!(
            faces.contains(&f),
            "boundary triangle {b:?} is not a tet face"
        );
    }
}

/// No boundary triangle lies off the input surface: each one lies on an input facet with its
/// marker (its vertices in the facet's plane, its centroid inside the facet's triangulated
/// polygon), up to a tolerance relative to the model's size.
pub fn check_on_input_surface(rel: &str, input: &PlcInput, m: &TetMesh) {
    let plc = slivermesh::plc::validate(input).expect("valid input");
    let (lo, hi) = plc.vertices.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(l, h), &p| (l.min(p), h.max(p)),
    );
    let tol = 1e-8 * (hi - lo).length();
    let mut by_marker: HashMap<i32, Vec<usize>> = HashMap::new();
    for (i, f) in plc.facets.iter().enumerate() {
        by_marker.entry(f.marker).or_default().push(i);
    }
    let inside = |f: &slivermesh::plc::PlcFacet, q: DVec3| {
        f.triangles.iter().any(|t| {
            let [a, b, c] = t.map(|v| plc.vertices[v as usize]);
            // Barycentric coordinates in the facet plane, each >= -tol (relative).
            let n = (b - a).cross(c - a);
            let nn = n.length_squared();
            let w = [
                (c - b).cross(q - b).dot(n) / nn,
                (a - c).cross(q - c).dot(n) / nn,
                (b - a).cross(q - a).dot(n) / nn,
            ];
            w.iter().all(|&x| x >= -1e-9)
        })
    };
    for (k, (t, mk)) in m.boundary.iter().zip(&m.boundary_markers).enumerate() {
        let p = t.map(|v| m.vertices[v as usize]);
        let centroid = (p[0] + p[1] + p[2]) / 3.0;
        let on_facet = by_marker.get(mk).into_iter().flatten().any(|&i| {
            let f = &plc.facets[i];
            p.iter().all(|&q| f.plane.distance(q).abs() <= tol) && inside(f, centroid)
        });
        assert!(
            on_facet,
            "{rel}: boundary triangle {k} {t:?} (marker {mk}) is not on an input facet with that marker"
        );
    }
}

pub fn rel_close(a: f64, b: f64, tol: f64) -> bool {
    (a - b).abs() <= tol * b.abs().max(1e-300)
}

/// The invariants every mesh of `input` must satisfy: positive orientation, Delaunay, boundary
/// triangles are tet faces and tile each facet marker's area, the expected volume if known.
pub fn check_conforming(rel: &str, input: &PlcInput, m: &TetMesh, volume: Option<f64>) {
    check_orientation(m);
    check_delaunay(m);
    check_boundary_faces_are_tet_faces(m);
    let want = facet_area_by_marker(input);
    let got = boundary_area_by_marker(m);
    for (mk, a) in &want {
        let g = got.get(mk).copied().unwrap_or(0.0);
        assert!(
            rel_close(g, *a, 1e-9),
            "{rel}: marker {mk}: boundary area {g}, facets {a}"
        );
    }
    assert_eq!(want.len(), got.len(), "{rel}: markers");
    check_on_input_surface(rel, input, m);
    if let Some(v) = volume.or_else(|| enclosed_volume(input)) {
        let vol = total_volume(m);
        assert!(rel_close(vol, v, 1e-9), "{rel}: volume {vol}, expected {v}");
    }
}

/// The volume a closed, consistently oriented surface of simple polygons encloses (divergence
/// theorem over fan triangles), or None when the input has holes or internal facets' regions.
pub fn enclosed_volume(input: &PlcInput) -> Option<f64> {
    if !input.holes.is_empty() || !input.regions.is_empty() {
        return None;
    }
    let mut six_v = 0.0;
    for f in &input.facets {
        if !f.hole_polygons.is_empty() || f.polygons.len() != 1 {
            return None;
        }
        let p: Vec<DVec3> = f.polygons[0]
            .iter()
            .map(|&i| input.vertices[i as usize])
            .collect();
        for k in 1..p.len().saturating_sub(1) {
            six_v += p[0].dot(p[k].cross(p[k + 1]));
        }
    }
    Some(six_v.abs() / 6.0)
}

/// A scratch directory under the system's temporary one, removed when dropped (also when a
/// check panics): `slivermesh-{prefix}-{name}-{pid}`.
pub struct ScratchDir(pub PathBuf);

impl ScratchDir {
    pub fn new(prefix: &str, name: &str) -> ScratchDir {
        let dir =
            std::env::temp_dir().join(format!("slivermesh-{prefix}-{name}-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        ScratchDir(dir)
    }
}

impl Drop for ScratchDir {
    fn drop(&mut self) {
        std::fs::remove_dir_all(&self.0).ok();
    }
}

/// The last `n` lines of a text.
pub fn tail(s: &str, n: usize) -> String {
    let lines: Vec<&str> = s.lines().collect();
    lines[lines.len().saturating_sub(n)..].join("\n")
}

/// The sorted vertex triples of a mesh's boundary triangles.
pub fn boundary_keys(m: &TetMesh) -> std::collections::HashSet<[u32; 3]> {
    (m.boundary.iter())
        .map(|b| {
            let mut k = *b;
            k.sort_unstable();
            k
        })
        .collect()
}

/// Meshes meshed apart glued into one by their vertices' exact coordinates; boundary
/// triangles once each.
pub fn glue_by_coordinates(parts: &[TetMesh]) -> TetMesh {
    let mut out = TetMesh::default();
    let mut index: HashMap<[u64; 3], u32> = HashMap::new();
    let mut seen = std::collections::HashSet::new();
    for m in parts {
        let ids: Vec<u32> = (m.vertices.iter())
            .map(|p| {
                *index
                    .entry(p.to_array().map(f64::to_bits))
                    .or_insert_with(|| {
                        out.vertices.push(*p);
                        out.vertices.len() as u32 - 1
                    })
            })
            .collect();
        out.tets
            .extend(m.tets.iter().map(|t| t.map(|v| ids[v as usize])));
        out.tet_regions.extend(&m.tet_regions);
        for (b, &marker) in m.boundary.iter().zip(&m.boundary_markers) {
            let b = b.map(|v| ids[v as usize]);
            let mut k = b;
            k.sort_unstable();
            if seen.insert(k) {
                out.boundary.push(b);
                out.boundary_markers.push(marker);
            }
        }
    }
    out
}
