//! The `approximate` surface mode: the input triangles describe a piecewise smooth surface.
//! (Work in progress: the restricted Delaunay surface mesher lands here.)

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::refine::{MeshError, Params, Progress, Report, Spacing};

/// Meshes the domain bounded by the surface `input` describes (see the module comment).
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Report), MeshError> {
    let _ = (input, params, spacing, progress);
    Err(MeshError::InvalidInput(
        "surface mode approximate is not available yet".into(),
    ))
}
