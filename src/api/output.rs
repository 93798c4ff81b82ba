//! What a successful run produced, and writing it with per-tet quality as cell data.

use super::error::Error;
use crate::geom::TetQuality;
use crate::io::CellField;
use crate::mesh::{QuadraticNodes, TetMesh};
use crate::run::report::Report;
use std::path::Path;

/// The mesh and the report of one successful [`super::Mesher::refine`].
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MeshOutput {
    pub mesh: TetMesh,
    /// With the `order` parameter 2: the mid-edge nodes of the ten-node tets.
    pub quadratic: Option<QuadraticNodes>,
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
        let measures: Vec<TetQuality> = mesh
            .tets
            .iter()
            .map(|t| {
                let [a, b, c, d] = t.map(|i| mesh.vertices[i as usize]);
                TetQuality::of(a, b, c, d)
            })
            .collect();
        Self::from_measures(&measures)
    }

    /// The fields of tets measured already (`quality::per_tet`).
    pub fn from_measures(measures: &[TetQuality]) -> Self {
        QualityFields {
            rho: measures.iter().map(|m| m.rho).collect(),
            sigma: measures.iter().map(|m| m.sigma).collect(),
            aspect: measures.iter().map(|m| m.aspect).collect(),
            min_dihedral: measures.iter().map(|m| m.min_dihedral).collect(),
            max_dihedral: measures.iter().map(|m| m.max_dihedral).collect(),
        }
    }

    /// The fields as writer cell data, named as they appear in ParaView: the one set of names
    /// every `.vtu` we write uses (the API's, the CLI's, the C ABI's `sm_write`).
    pub fn cell_fields(&self) -> [CellField<'_>; 5] {
        [
            CellField {
                name: "radius_edge_ratio",
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
                name: "min_dihedral_deg",
                values: &self.min_dihedral,
            },
            CellField {
                name: "max_dihedral_deg",
                values: &self.max_dihedral,
            },
        ]
    }
}

impl MeshOutput {
    /// Writes the mesh (format by extension: .vtu, .mesh, .msh, .node, .inp), ten-node tets
    /// with `order` 2, with the per-tet quality measures (of the corner tets) as cell data
    /// where the format has room for them.
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        self.write_in(path, false)
    }

    /// [`Self::write`], in the format's binary form where it has one and `binary` is set
    /// (.msh: gmsh 4.1 binary; .vtu: binary appended arrays).
    pub fn write_in(&self, path: &Path, binary: bool) -> Result<(), Error> {
        let q = QualityFields::of(&self.mesh);
        crate::io::write_output(
            path,
            &self.mesh,
            self.quadratic.as_ref(),
            &q.cell_fields(),
            binary,
        )?;
        Ok(())
    }
}
