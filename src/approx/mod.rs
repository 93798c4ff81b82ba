//! The `approximate` surface mode: the input triangles describe a piecewise smooth surface,
//! not constraints. The run:
//!
//! 1. validation as in keep mode (`plc::validate`: open, non-manifold, self-intersecting
//!    surfaces are refused with the same errors);
//! 2. sharp features (`surface::features`: normals differing by more than `feature_angle`,
//!    label changes, borders) joined into curves between corners (`curves`);
//! 3. a new boundary: the restricted Delaunay surface of samples of the input, refined for
//!    topology, size f, facet angle and the distance bound, with the feature curves protected
//!    (`restricted`);
//! 4. the volume inside that boundary meshed by REMOVE-SLIVER (`refine::mesh_remeshed`, the
//!    new triangles as facets, one marker per patch or input label), then improved;
//! 5. the report's surface figures measured on the written boundary (`measure`).

mod curves;
mod measure;
mod restricted;
#[cfg(test)]
mod tests;

pub use curves::SMALL_CORNER_DEG;

use crate::mesh::TetMesh;
use crate::plc::{CellKind, Facet, PlcInput};
use crate::refine::{
    ConstantSpacing, MeshError, Params, Progress, Report, Spacing,
    DEFAULT_SURFACE_DISTANCE_FRACTION,
};
use crate::surface::features::{FeatureParams, Features};
use crate::surface::oracle::SurfaceOracle;
use crate::surface::InputSurface;
use curves::FeatureCurves;
use restricted::{SurfaceCriteria, SurfaceMesher};

/// Default spacing of the boundary when the caller gives none, as a share of the bounding-box
/// diagonal (curved patches get finer through the distance bound, the volume is graded from
/// the boundary).
pub const DEFAULT_SPACING_FRACTION: f64 = 1.0 / 25.0;

/// Smallest angle of a boundary triangle, degrees (CGAL's facet_angle; 30 guarantees
/// termination in Boissonnat & Oudot's analysis).
const FACET_MIN_ANGLE_DEG: f64 = 30.0;

/// What the approximate mode built before the volume: the input's surface and features, and
/// the new boundary as a PLC.
pub struct Remeshed {
    pub surface: InputSurface,
    pub features: Features,
    pub boundary: PlcInput,
    /// Feature edges of the new boundary (vertex pairs of `boundary.vertices`).
    pub feature_edges: Vec<[u32; 2]>,
    pub distance: f64,
    /// Volume enclosed by the input (`Plc::volume`).
    pub input_volume: f64,
    pub n_corners: usize,
    /// Small corners: point and protecting radius (the influence the report counts in).
    pub small_corners: Vec<(glam::DVec3, f64)>,
    pub stop_reason: Option<String>,
    pub seconds: f64,
}

/// Meshes the domain bounded by the surface `input` describes (see the module comment).
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Report), MeshError> {
    let start = std::time::Instant::now();
    let remeshed = remesh(input, params, spacing)?;
    let (mesh, mut report) =
        crate::refine::mesh_remeshed(&remeshed.boundary, params, spacing, progress)?;
    let mesh = crate::improve::finish(mesh, &mut report, Some(&remeshed.boundary), params.improve)?;
    let mut surface_report = measure::surface_report(&remeshed, &mesh);
    if report.stop_reason.is_none() {
        report.stop_reason = remeshed.stop_reason.clone();
    }
    surface_report.n_bad_near_small_corners =
        measure::bad_near_corners(&mesh, &remeshed.small_corners, params);
    report.surface = Some(surface_report);
    report.seconds_total = start.elapsed().as_secs_f64();
    Ok((mesh, report))
}

/// Steps 1-3: the new boundary.
pub fn remesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
) -> Result<Remeshed, MeshError> {
    let start = std::time::Instant::now();
    params.check().map_err(MeshError::InvalidInput)?;
    let plc = crate::plc::validate(input).map_err(|e| MeshError::InvalidInput(e.to_string()))?;
    let domains = plc
        .cells
        .iter()
        .filter(|c| matches!(c.kind, CellKind::Domain { .. }))
        .count();
    if domains > 1 || plc.regions.len() > 1 {
        return Err(MeshError::InvalidInput(format!(
            "surface mode approximate meshes one volume bounded by closed surfaces; this input \
             has {domains} separate volumes or regions (facets inside the domain): use \
             surface mode keep"
        )));
    }
    let surface = InputSurface::from_plc(&plc);
    let features = Features::detect(
        &surface,
        &FeatureParams {
            feature_angle: params.feature_angle,
            use_markers: has_labels(input),
        },
    );
    let curves = FeatureCurves::new(&surface, &features);
    let diagonal = surface.bbox_diagonal();
    let distance = if params.surface_distance > 0.0 {
        params.surface_distance
    } else {
        DEFAULT_SURFACE_DISTANCE_FRACTION * diagonal
    };
    let default_spacing = ConstantSpacing(DEFAULT_SPACING_FRACTION * diagonal);
    let f: &dyn Spacing = spacing.unwrap_or(&default_spacing);
    let oracle = SurfaceOracle::new(&surface);
    let criteria = SurfaceCriteria {
        distance,
        min_angle_deg: FACET_MIN_ANGLE_DEG,
        max_vertices: params.max_vertices,
        seed: params.seed,
    };
    let mesher = SurfaceMesher::new(&surface, &oracle, &curves, &features.patch_of, f, criteria)?;
    let b = mesher.run()?;
    let labels = has_labels(input);
    let facets = b
        .triangles
        .iter()
        .zip(&b.input_triangle)
        .map(|(t, &it)| Facet {
            polygons: vec![t.to_vec()],
            marker: if labels {
                surface.marker_of[it as usize]
            } else {
                features.patch_of[it as usize] as i32 + 1
            },
            ..Facet::default()
        })
        .collect();
    let boundary = PlcInput {
        vertices: b.points.clone(),
        facets,
        holes: input.holes.clone(),
        regions: input.regions.clone(),
    };
    let small_corners: Vec<_> = curves
        .small_corners()
        .map(|c| (c.point, c.protect_radius))
        .collect();
    Ok(Remeshed {
        input_volume: plc.volume(),
        n_corners: curves.corners.len(),
        small_corners,
        surface,
        features,
        boundary,
        feature_edges: b.feature_edges,
        distance,
        stop_reason: b.stop_reason,
        seconds: start.elapsed().as_secs_f64(),
    })
}

/// Whether the facet markers are the input's own labels: readers of plain surfaces number
/// the facets 1, 2, 3, ... (`io::off`, `io::stl`), which labels nothing.
fn has_labels(input: &PlcInput) -> bool {
    !input
        .facets
        .iter()
        .enumerate()
        .all(|(i, f)| f.marker as i64 == i as i64 + 1)
}
