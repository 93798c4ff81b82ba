//! One part's PLC: the boundary of its coarse tets (the domain's facets and region
//! interfaces, flat patches merged), closed where it meets other parts by the band's
//! interface triangles, each a frozen facet. The domain's facets along the interface's rim
//! get the band's rim vertices in their polygon edges (no T-junctions), and the band's inner
//! vertices on the part's side come in as isolated vertices.

use super::band::Band;
use super::coarse::Coarse;
use crate::mesh::TetMesh;
use crate::plc::{Facet, PlcInput};
use crate::run::error::MeshError;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// The exact coordinates of a point, as a hash key.
fn key(p: DVec3) -> [u64; 3] {
    p.to_array().map(f64::to_bits)
}

/// A part's PLC.
pub(super) struct PartPlc {
    pub input: PlcInput,
    /// Its frozen facets (the interface's triangles): indices into `input.facets`.
    pub frozen: Vec<u32>,
    /// Its vertices on facets come first: this many (the others are isolated vertices).
    pub on_facets: usize,
}

/// Part `part`'s PLC.
pub(super) fn build(coarse: &Coarse, band: &Band, part: usize) -> Result<PartPlc, MeshError> {
    let m = &coarse.mesh;
    let mut face_parts: FxHashMap<[u32; 3], Vec<u32>> = FxHashMap::default();
    for t in 0..m.tets.len() {
        for f in coarse.faces(t) {
            face_parts.entry(f).or_default().push(coarse.part_of[t]);
        }
    }
    let is_interface = |f: &[u32; 3]| {
        face_parts
            .get(f)
            .is_some_and(|ps| ps.len() == 2 && ps[0] != ps[1])
    };
    // The part's coarse tets, renumbered.
    let mut sub = TetMesh::default();
    let mut local = vec![u32::MAX; m.vertices.len()];
    for (t, &tv) in m.tets.iter().enumerate() {
        if coarse.part_of[t] as usize != part {
            continue;
        }
        sub.tets.push(tv.map(|v| {
            if local[v as usize] == u32::MAX {
                local[v as usize] = sub.vertices.len() as u32;
                sub.vertices.push(m.vertices[v as usize]);
            }
            local[v as usize]
        }));
        sub.tet_regions.push(m.tet_regions[t]);
    }
    if sub.tets.is_empty() {
        return Err(MeshError::InvalidInput(format!(
            "part {part} got no coarse tets: too many parts for this size"
        )));
    }
    let part_faces: FxHashSet<[u32; 3]> = (0..m.tets.len())
        .filter(|&t| coarse.part_of[t] as usize == part)
        .flat_map(|t| coarse.faces(t))
        .collect();
    for (b, &marker) in m.boundary.iter().zip(&m.boundary_markers) {
        let mut k = *b;
        k.sort_unstable();
        // A region interface on a part interface is closed by the band's triangles.
        if part_faces.contains(&k) && !is_interface(&k) {
            sub.boundary.push(b.map(|v| local[v as usize]));
            sub.boundary_markers.push(marker);
        }
    }
    let global: Vec<u32> = {
        let mut g = vec![0; sub.vertices.len()];
        for (v, &l) in local.iter().enumerate() {
            if l != u32::MAX {
                g[l as usize] = v as u32;
            }
        }
        g
    };
    let open = |f: &[u32; 3]| {
        let mut k = f.map(|v| global[v as usize]);
        k.sort_unstable();
        is_interface(&k)
    };
    let mut input = crate::refine::existing::plc_of_mesh_except(&sub, &open)?;

    // The band's vertices: the coarse ones are the part's already (same coordinates).
    let mut index: FxHashMap<[u64; 3], u32> = (input.vertices.iter().enumerate())
        .map(|(i, &p)| (key(p), i as u32))
        .collect();
    let bv = &band.mesh.vertices;
    let mut vertices = std::mem::take(&mut input.vertices);
    let mut id_of = |v: u32| -> u32 {
        let p = bv[v as usize];
        *index.entry(key(p)).or_insert_with(|| {
            vertices.push(p);
            vertices.len() as u32 - 1
        })
    };
    let tris: Vec<([u32; 3], i32)> = band.interface[part]
        .iter()
        .map(|(t, marker)| (t.map(&mut id_of), *marker))
        .collect();
    for &s in &band.seeds[part] {
        id_of(s);
    }
    insert_chains(&mut input.facets, &global, &band.chains, &mut id_of);
    input.vertices = vertices;
    add_facet_points(&mut input, band, &index);
    let first_frozen = input.facets.len() as u32;
    input.facets.extend(tris.iter().map(|(t, marker)| Facet {
        polygons: vec![t.to_vec()],
        marker: *marker,
        ..Default::default()
    }));
    let frozen = (first_frozen..input.facets.len() as u32).collect();
    let on_facets = facet_vertices_first(&mut input);
    Ok(PartPlc {
        input,
        frozen,
        on_facets,
    })
}

/// Renumbers `input`'s vertices so that those of its facets come first (in their order),
/// the isolated ones (coarse interior vertices, the band's seeds) after; returns how many
/// are on facets.
fn facet_vertices_first(input: &mut PlcInput) -> usize {
    let mut on_facet = vec![false; input.vertices.len()];
    for f in &input.facets {
        for p in f.polygons.iter().chain(&f.hole_polygons) {
            p.iter().for_each(|&v| on_facet[v as usize] = true);
        }
    }
    let order: Vec<u32> = (0..input.vertices.len() as u32)
        .filter(|&v| on_facet[v as usize])
        .chain((0..input.vertices.len() as u32).filter(|&v| !on_facet[v as usize]))
        .collect();
    let mut new_id = vec![0u32; order.len()];
    for (i, &v) in order.iter().enumerate() {
        new_id[v as usize] = i as u32;
    }
    input.vertices = order.iter().map(|&v| input.vertices[v as usize]).collect();
    for f in &mut input.facets {
        for p in f.polygons.iter_mut().chain(f.hole_polygons.iter_mut()) {
            p.iter_mut().for_each(|v| *v = new_id[*v as usize]);
        }
    }
    on_facet.iter().filter(|&&b| b).count()
}

/// Puts the band's points inside the domain's facets (`Band::facet_points`) into the part's
/// facets that hold them, as lone points: a facet of the same marker whose plane the point is
/// on (within 1e-9 of the facet's size: they were snapped to it) and inside whose polygon
/// (holes left out) it lies in the facet's projection. This only picks where a point goes;
/// the PLC's validation checks the result exactly.
fn add_facet_points(input: &mut PlcInput, band: &Band, index: &FxHashMap<[u64; 3], u32>) {
    let shapes: Vec<Option<FacetShape>> = (input.facets.iter())
        .map(|f| FacetShape::of(f, &input.vertices))
        .collect();
    for &(v, marker) in &band.facet_points {
        let p = band.mesh.vertices[v as usize];
        if index.contains_key(&key(p)) {
            continue;
        }
        let found = (input.facets.iter().zip(&shapes)).position(|(f, shape)| {
            f.marker == marker
                && shape
                    .as_ref()
                    .is_some_and(|s| s.holds(p, f, &input.vertices))
        });
        if let Some(k) = found {
            input.vertices.push(p);
            let id = input.vertices.len() as u32 - 1;
            input.facets[k].polygons.push(vec![id]);
        }
    }
}

/// A facet's plane and bounding box, for [`add_facet_points`].
struct FacetShape {
    origin: DVec3,
    normal: DVec3,
    /// The coordinate axes of the projection (the normal's largest component dropped).
    axes: [usize; 2],
    lo: DVec3,
    hi: DVec3,
    size: f64,
}

impl FacetShape {
    fn of(f: &Facet, vertices: &[DVec3]) -> Option<FacetShape> {
        let outer = f.polygons.iter().find(|p| p.len() >= 3)?;
        let pts: Vec<DVec3> = outer.iter().map(|&v| vertices[v as usize]).collect();
        // Newell's normal: robust for a non-convex polygon.
        let mut normal = DVec3::ZERO;
        for (i, a) in pts.iter().enumerate() {
            let b = pts[(i + 1) % pts.len()];
            normal += DVec3::new(
                (a.y - b.y) * (a.z + b.z),
                (a.z - b.z) * (a.x + b.x),
                (a.x - b.x) * (a.y + b.y),
            );
        }
        let normal = normal.try_normalize()?;
        let m = normal.abs();
        let drop = if m.x >= m.y && m.x >= m.z {
            0
        } else if m.y >= m.z {
            1
        } else {
            2
        };
        let axes = [[1, 2], [0, 2], [0, 1]][drop];
        let (lo, hi) = pts
            .iter()
            .fold((pts[0], pts[0]), |(l, h), &q| (l.min(q), h.max(q)));
        Some(FacetShape {
            origin: pts[0],
            normal,
            axes,
            lo,
            hi,
            size: (hi - lo).length(),
        })
    }

    /// Whether `p` lies in facet `f`: on its plane, inside its polygons' even-odd area.
    fn holds(&self, p: DVec3, f: &Facet, vertices: &[DVec3]) -> bool {
        let margin = 1e-9 * self.size;
        if (p - self.origin).dot(self.normal).abs() > margin
            || p.cmplt(self.lo - DVec3::splat(margin)).any()
            || p.cmpgt(self.hi + DVec3::splat(margin)).any()
        {
            return false;
        }
        let [u, w] = self.axes;
        let mut inside = false;
        for poly in f.polygons.iter().chain(&f.hole_polygons) {
            if poly.len() < 3 {
                continue;
            }
            for i in 0..poly.len() {
                let a = vertices[poly[i] as usize];
                let b = vertices[poly[(i + 1) % poly.len()] as usize];
                if (a[w] > p[w]) != (b[w] > p[w]) {
                    let x = a[u] + (p[w] - a[w]) / (b[w] - a[w]) * (b[u] - a[u]);
                    if p[u] < x {
                        inside = !inside;
                    }
                }
            }
        }
        inside
    }
}

/// Puts the band's vertices on coarse edges (`Band::chains`) into the polygon edges of
/// `facets` along those edges (`global`: a PLC vertex's coarse id, for the first ones), so
/// that the interface's triangles meet them at vertices.
fn insert_chains(
    facets: &mut [Facet],
    global: &[u32],
    chains: &FxHashMap<(u32, u32), Vec<u32>>,
    id_of: &mut dyn FnMut(u32) -> u32,
) {
    for f in facets.iter_mut() {
        for polygon in f.polygons.iter_mut().chain(f.hole_polygons.iter_mut()) {
            let n = polygon.len();
            if n < 3 {
                continue; // a lone point, or a segment (no coarse mesh has those)
            }
            let mut out = Vec::with_capacity(n);
            for k in 0..n {
                let (a, b) = (polygon[k], polygon[(k + 1) % n]);
                out.push(a);
                let (Some(&ga), Some(&gb)) = (global.get(a as usize), global.get(b as usize))
                else {
                    continue;
                };
                if let Some(chain) = chains.get(&(ga.min(gb), ga.max(gb))) {
                    let ids = chain.iter().map(|&v| id_of(v));
                    if ga < gb {
                        out.extend(ids);
                    } else {
                        out.extend(ids.collect::<Vec<_>>().into_iter().rev());
                    }
                }
            }
            *polygon = out;
        }
    }
}
