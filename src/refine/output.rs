//! Extraction of the FEM-ready mesh: inside tets with their region attribute and the
//! subfacets as boundary triangles with their facet marker, oriented outwards.
//!
//! One exception to "every inside tet of the triangulation": four cocircular vertices of one
//! outer facet (a rectangle of segment splits on a strip facet, say) that sit a rounding error
//! off the facet's plane make a Delaunay tet of no volume lying on the facet, two of its faces
//! subfacets. Such a tet is a singular element for any solver, and refinement cannot split it
//! away next to a small angle without a cascade; it is left out, and its two other faces (the
//! quad's other diagonal, on the same plane up to rounding) become the boundary triangles
//! instead. The facet is still tiled exactly and every remaining tet is still Delaunay.

use super::domain::{tri_key, Domain, VertexKind};
use super::mark::Regions;
use crate::delaunay::tables::FACE;
use crate::geom::{shortest_edge, volume};
use crate::mesh::TetMesh;
use rustc_hash::FxHashSet;

/// sigma = V / L^3 below which a tet is numerically flat (a regular tet has 0.118; four
/// coplanar points rounded to doubles give about 1e-15).
const FLAT_SIGMA: f64 = 1e-9;

/// A flat tet lying on an outer facet: left out of the output (see the module comment).
struct FlatOnFacet {
    tet: u32,
    /// Its two subfacets (sorted keys), replaced by `boundary`.
    subfacets: [[u32; 3]; 2],
    /// The tet's two other faces, oriented out of the domain that remains.
    boundary: [[u32; 3]; 2],
    marker: i32,
}

impl Domain {
    pub fn to_mesh(&self, regions: &Regions) -> TetMesh {
        let mut mesh = TetMesh {
            vertices: self.dt.points().to_vec(),
            ..Default::default()
        };
        let flat = self.flat_tets_on_facets();
        let dropped: FxHashSet<u32> = flat.iter().map(|f| f.tet).collect();
        let replaced: FxHashSet<[u32; 3]> = flat.iter().flat_map(|f| f.subfacets).collect();
        // At most every finite tet: reserved once instead of doubling (the peak of a big run).
        mesh.tets.reserve_exact(self.dt.num_finite_tets());
        mesh.tet_regions.reserve_exact(self.dt.num_finite_tets());
        for t in self.dt.finite_tet_ids() {
            let tag = self.dt.tag(t);
            if tag != 0 && !dropped.contains(&t) {
                mesh.tets.push(self.dt.tet(t));
                mesh.tet_regions.push(regions.attribute[tag as usize]);
            }
        }
        let mut subfacets: Vec<([u32; 3], u32)> =
            self.subfacets.iter().map(|(&k, &f)| (k, f)).collect();
        subfacets.sort_unstable();
        for (k, f) in subfacets {
            if replaced.contains(&k) {
                continue;
            }
            let Some(sides) = self.dt.find_face(k[0], k[1], k[2]) else {
                continue;
            };
            // FACE order makes the face's normal point into the tet: reverse it for an outward
            // normal, taking the first side that is inside the domain.
            let Some(&(t, i)) = sides
                .iter()
                .find(|&&(t, _)| self.dt.is_finite(t) && self.dt.tag(t) != 0)
            else {
                continue;
            };
            let v = self.dt.tet(t);
            let tri = FACE[i].map(|l| v[l]);
            mesh.boundary.push([tri[1], tri[0], tri[2]]);
            mesh.boundary_markers.push(self.markers[f as usize]);
        }
        for f in &flat {
            for tri in f.boundary {
                mesh.boundary.push(tri);
                mesh.boundary_markers.push(f.marker);
            }
        }
        mesh
    }

    /// The numerically flat inside tets with exactly two faces that are subfacets of one facet
    /// with the outside (or a hole) beyond them, and inside tets, none of them such a tet
    /// themselves, beyond the other two faces. In tet id order.
    fn flat_tets_on_facets(&self) -> Vec<FlatOnFacet> {
        let inside = |t: u32| self.dt.is_finite(t) && self.dt.tag(t) != 0;
        let mut found = vec![];
        for t in self.dt.finite_tet_ids() {
            let v = self.dt.tet(t);
            // Two faces on one facet: all four vertices on the boundary (cheap test first).
            if self.dt.tag(t) == 0
                || v.iter()
                    .any(|&k| self.kind[k as usize] == VertexKind::Volume)
            {
                continue;
            }
            let [a, b, c, d] = self.dt.tet_points(t);
            if volume(a, b, c, d).abs() >= FLAT_SIGMA * shortest_edge(a, b, c, d).powi(3) {
                continue;
            }
            let nb = self.dt.neighbors(t);
            let (mut on_facet, mut other) = (vec![], vec![]);
            for (i, face) in FACE.iter().enumerate() {
                let key = tri_key(face.map(|k| v[k]));
                match self.subfacets.get(&key) {
                    Some(&f) if !inside(nb[i]) => on_facet.push((key, f)),
                    _ => other.push(i),
                }
            }
            if on_facet.len() != 2
                || on_facet[0].1 != on_facet[1].1
                || !other.iter().all(|&i| inside(nb[i]))
            {
                continue;
            }
            // Out of the remaining domain = into this tet: FACE order as it is.
            let boundary = [other[0], other[1]].map(|i| FACE[i].map(|k| v[k]));
            found.push(FlatOnFacet {
                tet: t,
                subfacets: [on_facet[0].0, on_facet[1].0],
                boundary,
                marker: self.markers[on_facet[0].1 as usize],
            });
        }
        // A flat tet next to another one would leave a face between them without a tet.
        let all: FxHashSet<u32> = found.iter().map(|f| f.tet).collect();
        found.retain(|f| self.dt.neighbors(f.tet).iter().all(|n| !all.contains(n)));
        found
    }
}
