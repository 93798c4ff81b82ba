//! The whole meshing run as the API calls it: the surface mode's boundary (kept as given, or
//! approximated by `crate::approx`), refinement, then the improvement pass and the check that
//! no tet is degenerate. Each stage reports its own part (refinement the `Report` of the refined
//! mesh, the improvement its `ImproveStats`); the whole run's report is put together here.

use crate::mesh::{QuadraticNodes, TetMesh};
use crate::plc::PlcInput;
use crate::refine;
use crate::run::error::MeshError;
use crate::run::params::{Params, SurfaceMode};
use crate::run::progress::Progress;
use crate::run::report::Report;
use crate::run::spacing::Spacing;

/// Meshes `input` in `params.surface_mode`, improves the result (`params.improve`) and checks
/// that no tet is flat or inverted; the report gets each region's figures. `spacing` None =
/// automatic. With `params.order` 2, the mid-edge nodes of ten-node tets come along
/// (`crate::quadratic`): on the input surface in approximate mode, at the midpoints in keep
/// mode, whose facets are planar.
///
/// The run's parallel steps use `params.threads` threads (`crate::parallel::with_threads`);
/// everything else, `spacing` and `progress` included, runs on the calling thread. A spacing
/// that may be evaluated on several threads at once comes wrapped in
/// `crate::parallel::SplitSpacing`.
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Option<QuadraticNodes>, Report), MeshError> {
    crate::parallel::with_threads(params.threads, || {
        mesh_here(input, params, spacing, progress)
    })
}

fn mesh_here(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Option<QuadraticNodes>, Report), MeshError> {
    let (mesh, quadratic, mut report) = match params.surface_mode {
        SurfaceMode::Keep if params.repair => {
            return Err(MeshError::InvalidInput(
                "repair needs the approximate surface mode: keep mode preserves every input \
                 facet exactly, which a dirty surface does not allow"
                    .into(),
            ))
        }
        SurfaceMode::Keep => {
            let (mesh, mut report) = refine::mesh(input, params, spacing, progress)?;
            let mesh = improve(mesh, &mut report, Some(input), params)?;
            let quadratic = (params.order == 2).then(|| {
                let (nodes, quadratic_report) = crate::quadratic::elevate(&mesh, None);
                report.quadratic = Some(quadratic_report);
                nodes
            });
            (mesh, quadratic, report)
        }
        SurfaceMode::Approximate => crate::approx::mesh(input, params, spacing, progress)?,
    };
    report.measure_regions(&mesh);
    Ok((mesh, quadratic, report))
}

/// Removes the slivers of an existing mesh (`refine::existing`), keeping its boundary and
/// interface triangles, holes and regions, then improves it with that boundary fixed (there is
/// no facet description to slide on). With `params.order` 2, the mid-edge nodes at the
/// midpoints. Keep mode only: an existing mesh's boundary is kept as it is. On
/// `params.threads` threads, as [`mesh`].
pub fn remove_slivers(
    existing: &TetMesh,
    params: &Params,
) -> Result<(TetMesh, Option<QuadraticNodes>, Report), MeshError> {
    crate::parallel::with_threads(params.threads, || remove_slivers_here(existing, params))
}

fn remove_slivers_here(
    existing: &TetMesh,
    params: &Params,
) -> Result<(TetMesh, Option<QuadraticNodes>, Report), MeshError> {
    if params.surface_mode == SurfaceMode::Approximate {
        return Err(MeshError::InvalidInput(
            "the approximate surface mode does not apply to an existing mesh: its boundary is \
             kept as it is"
                .into(),
        ));
    }
    let (mesh, mut report) = refine::existing::remove_slivers(existing, params)?;
    let mesh = improve(mesh, &mut report, None, params)?;
    let quadratic = (params.order == 2).then(|| {
        let (nodes, quadratic_report) = crate::quadratic::elevate(&mesh, None);
        report.quadratic = Some(quadratic_report);
        nodes
    });
    Ok((mesh, quadratic, report))
}

/// The improvement pass (`improve::finish`) on a refined mesh, recorded in its `report`: the
/// shape figures re-measured when the mesh changed (the size figures stay the refinement's),
/// the dihedral range before, the stats and the time.
pub(crate) fn improve(
    mesh: TetMesh,
    report: &mut Report,
    input: Option<&PlcInput>,
    params: &Params,
) -> Result<TetMesh, MeshError> {
    let before = report.dihedral_range();
    let (mesh, stats) = crate::improve::finish(mesh, input, params, None)?;
    if stats.changed() {
        report.measure_shapes(&mesh);
    }
    report.record_improvement(stats, before);
    Ok(mesh)
}
