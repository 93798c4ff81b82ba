//! Extraction of the FEM-ready mesh: inside tets with their region attribute and the
//! subfacets as boundary triangles with their facet marker, oriented outwards.

use super::domain::Domain;
use super::mark::Regions;
use crate::delaunay::tables::FACE;
use crate::mesh::TetMesh;

impl Domain {
    pub fn to_mesh(&self, regions: &Regions) -> TetMesh {
        let mut mesh = TetMesh {
            vertices: self.dt.points().to_vec(),
            ..Default::default()
        };
        for t in self.dt.finite_tet_ids() {
            let tag = self.dt.tag(t);
            if tag != 0 {
                mesh.tets.push(self.dt.tet(t));
                mesh.tet_regions.push(regions.attribute[tag as usize]);
            }
        }
        let mut subfacets: Vec<([u32; 3], u32)> =
            self.subfacets.iter().map(|(&k, &f)| (k, f)).collect();
        subfacets.sort_unstable();
        for (k, f) in subfacets {
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
        mesh
    }
}
