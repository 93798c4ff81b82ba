//! The input's polygons as one welded triangle soup: no check but that every index and
//! coordinate is usable, because a dirty surface is what `--repair` is for.

use crate::plc::{Facet, PlcInput};
use glam::DVec3;
use rustc_hash::FxHashMap;

/// Welded triangles of the input.
pub(super) struct Soup {
    /// Distinct points, in order of first appearance.
    pub vertices: Vec<DVec3>,
    pub triangles: Vec<[u32; 3]>,
    /// The input facet of each triangle.
    pub facet_of: Vec<u32>,
    pub marker_of: Vec<i32>,
    /// Input vertices that repeated an earlier one's coordinates.
    pub welded_vertices: usize,
    /// Triangles left out because welding (or the input) made two of their corners one.
    pub degenerate_triangles: usize,
}

impl Soup {
    /// Every facet's triangles (`facet_triangles`) over welded vertices.
    pub fn of(input: &PlcInput) -> Result<Soup, String> {
        for (i, &p) in input.vertices.iter().enumerate() {
            crate::geom::check_coordinate(p)
                .map_err(|reason| format!("vertex {i} at {p:?}: {reason}"))?;
        }
        let mut id_of: FxHashMap<[u64; 3], u32> = FxHashMap::default();
        let mut vertices = Vec::new();
        let weld: Vec<u32> = input
            .vertices
            .iter()
            .map(|p| {
                // -0.0 and 0.0 are one point.
                let key = (*p + DVec3::ZERO).to_array().map(f64::to_bits);
                *id_of.entry(key).or_insert_with(|| {
                    vertices.push(*p);
                    vertices.len() as u32 - 1
                })
            })
            .collect();
        let mut soup = Soup {
            welded_vertices: input.vertices.len() - vertices.len(),
            vertices,
            triangles: vec![],
            facet_of: vec![],
            marker_of: vec![],
            degenerate_triangles: 0,
        };
        let n = input.vertices.len();
        for (k, f) in input.facets.iter().enumerate() {
            for (j, poly) in f.polygons.iter().enumerate() {
                if let Some(&bad) = poly.iter().find(|&&v| v as usize >= n) {
                    return Err(format!(
                        "polygon {j} of facet {k}: vertex id {bad} is out of range (there are \
                         {n} vertices)"
                    ));
                }
            }
            for t in facet_triangles(k, f, &input.vertices) {
                let t = t.map(|v| weld[v as usize]);
                if t[0] == t[1] || t[1] == t[2] || t[2] == t[0] {
                    soup.degenerate_triangles += 1;
                    continue;
                }
                soup.triangles.push(t);
                soup.facet_of.push(k as u32);
                soup.marker_of.push(f.marker);
            }
        }
        if soup.triangles.is_empty() {
            return Err("the input has no triangle with three distinct corners".into());
        }
        Ok(soup)
    }
}

/// The triangles of facet `k`: its constrained triangulation where it is a valid planar
/// polygon (with holes), else a fan over each outer polygon of three or more corners.
fn facet_triangles(k: usize, f: &Facet, vertices: &[DVec3]) -> Vec<[u32; 3]> {
    if let Ok(checked) = crate::plc::check_facet(k, f, vertices) {
        return checked.triangles;
    }
    f.polygons
        .iter()
        .filter(|p| p.len() >= 3)
        .flat_map(|p| p.windows(2).skip(1).map(|w| [p[0], w[0], w[1]]))
        .collect()
}
