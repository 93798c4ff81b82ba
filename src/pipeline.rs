//! The whole meshing run as the API, the CLI and the C ABI call it: the surface mode's boundary
//! (kept as given, or approximated by `crate::approx`), refinement, then the improvement pass
//! and the check that no tet is degenerate.

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::refine::{self, MeshError, Params, Progress, Report, Spacing, SurfaceMode};

/// Meshes `input` in `params.surface_mode`, improves the result (`params.improve`) and checks
/// that no tet is flat or inverted; the report gets each region's figures. `spacing` None =
/// automatic.
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Report), MeshError> {
    let (mesh, mut report) = match params.surface_mode {
        SurfaceMode::Keep if params.repair => {
            return Err(MeshError::InvalidInput(
                "repair needs the approximate surface mode: keep mode preserves every input \
                 facet exactly, which a dirty surface does not allow"
                    .into(),
            ))
        }
        SurfaceMode::Keep => {
            let (mesh, mut report) = refine::mesh(input, params, spacing, progress)?;
            let mesh = crate::improve::finish(mesh, &mut report, Some(input), params, None)?;
            (mesh, report)
        }
        SurfaceMode::Approximate => crate::approx::mesh(input, params, spacing, progress)?,
    };
    report.measure_regions(&mesh);
    Ok((mesh, report))
}
