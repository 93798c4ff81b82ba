//! What a successful run produced, and writing it with per-tet quality as cell data.

use super::error::Error;
use crate::geom::TetQuality;
use crate::io::{write_mesh, CellField};
use crate::mesh::TetMesh;
use crate::refine::Report;
use std::path::Path;

/// The mesh and the report of one successful [`super::Mesher::refine`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshOutput {
    pub mesh: TetMesh,
    pub report: Report,
}

/// Per-tet quality measures, one `Vec` per measure, in tet order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct QualityFields {
    /// Radius-edge ratio R/L.
    pub rho: Vec<f64>,
    /// V/L^3.
    pub sigma: Vec<f64>,
    /// R/(3r).
    pub aspect: Vec<f64>,
    /// Smallest dihedral angle, degrees.
    pub min_dihedral: Vec<f64>,
    /// Largest dihedral angle, degrees.
    pub max_dihedral: Vec<f64>,
}

impl QualityFields {
    /// Computes every measure of every tet of `mesh`.
    pub fn of(mesh: &TetMesh) -> Self {
        let n = mesh.tets.len();
        let mut q = QualityFields {
            rho: Vec::with_capacity(n),
            sigma: Vec::with_capacity(n),
            aspect: Vec::with_capacity(n),
            min_dihedral: Vec::with_capacity(n),
            max_dihedral: Vec::with_capacity(n),
        };
        for t in &mesh.tets {
            let [a, b, c, d] = t.map(|i| mesh.vertices[i as usize]);
            let m = TetQuality::of(a, b, c, d);
            q.rho.push(m.rho);
            q.sigma.push(m.sigma);
            q.aspect.push(m.aspect);
            q.min_dihedral.push(m.min_dihedral);
            q.max_dihedral.push(m.max_dihedral);
        }
        q
    }

    /// The fields as writer cell data (names as they appear in ParaView).
    pub fn cell_fields(&self) -> [CellField<'_>; 5] {
        [
            CellField {
                name: "rho",
                values: &self.rho,
            },
            CellField {
                name: "sigma",
                values: &self.sigma,
            },
            CellField {
                name: "aspect",
                values: &self.aspect,
            },
            CellField {
                name: "min_dihedral",
                values: &self.min_dihedral,
            },
            CellField {
                name: "max_dihedral",
                values: &self.max_dihedral,
            },
        ]
    }
}

impl MeshOutput {
    /// Writes the mesh (format by extension: .vtu, .mesh, .msh, .node) with the per-tet quality
    /// measures as cell data where the format has room for them.
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        let q = QualityFields::of(&self.mesh);
        write_mesh(path, &self.mesh, &q.cell_fields())?;
        Ok(())
    }
}
