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

/// The facet and curve distance criteria use this share of the bound: they measure the
/// distance at one point (circumcentre to surface centre, curve vertices to a chord), while a
/// flat triangle over a curved patch strays farther elsewhere (measured: 1.7x at the default).
const DISTANCE_SAFETY: f64 = 0.5;

/// Largest protecting-ball radius of a small corner, in distance bounds: the surface is not
/// refined inside the ball, so the boundary stays within about this of the input there.
const PROTECT_DISTANCES: f64 = 2.0;

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
    /// The vertices of `boundary` at small corners.
    pub small_corner_vertices: Vec<u32>,
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
    let (mesh, mut report) = crate::refine::mesh_remeshed(
        &remeshed.boundary,
        params,
        spacing,
        progress,
        &remeshed.small_corner_vertices,
    )?;
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
    let mut curves = FeatureCurves::new(&surface, &features);
    let diagonal = surface.bbox_diagonal();
    let distance = if params.surface_distance > 0.0 {
        params.surface_distance
    } else {
        DEFAULT_SURFACE_DISTANCE_FRACTION * diagonal
    };
    curves.cap_protect_radius(PROTECT_DISTANCES * distance);
    let default_spacing = ConstantSpacing(DEFAULT_SPACING_FRACTION * diagonal);
    let f: &dyn Spacing = spacing.unwrap_or(&default_spacing);
    let oracle = SurfaceOracle::new(&surface);
    let criteria = SurfaceCriteria {
        distance: DISTANCE_SAFETY * distance,
        min_angle_deg: FACET_MIN_ANGLE_DEG,
        max_vertices: params.max_vertices,
        seed: params.seed,
    };
    let mesher = SurfaceMesher::new(&surface, &oracle, &curves, &features.patch_of, f, criteria)?;
    let b = mesher.run()?;
    if std::env::var("SM_DEBUG").is_ok() {
        let mut angles: Vec<f64> = b
            .triangles
            .iter()
            .map(|t| {
                let [p, q, r] = t.map(|v| b.points[v as usize]);
                restricted::min_angle_deg(p, q, r)
            })
            .collect();
        angles.sort_by(f64::total_cmp);
        eprintln!(
            "surface: {} vertices {} triangles, blocked {}, stop {:?}, angles min {:?} p1 {:?}, below 1 deg {}, {:.2}s",
            b.points.len(),
            b.triangles.len(),
            b.n_blocked,
            b.stop_reason,
            angles.first(),
            angles.get(angles.len() / 100),
            angles.iter().filter(|&&a| a < 1.0).count(),
            start.elapsed().as_secs_f64()
        );
        let mut edges: rustc_hash::FxHashMap<[u32; 2], Vec<usize>> = Default::default();
        for (k, t) in b.triangles.iter().enumerate() {
            for j in 0..3 {
                let (x, y) = (t[j], t[(j + 1) % 3]);
                edges.entry([x.min(y), x.max(y)]).or_default().push(k);
            }
        }
        let normal = |k: usize| {
            let [p, q, r] = b.triangles[k].map(|v| b.points[v as usize]);
            (q - p).cross(r - p).normalize()
        };
        let mut sharp: Vec<(f64, [u32; 2])> = edges
            .iter()
            .filter(|(_, ts)| ts.len() == 2)
            .map(|(e, ts)| {
                let (n1, n2) = (normal(ts[0]), normal(ts[1]));
                (
                    180.0 - n1.cross(n2).length().atan2(n1.dot(n2)).to_degrees(),
                    *e,
                )
            })
            .filter(|(a, _)| *a < 60.0)
            .collect();
        sharp.sort_by(|x, y| x.0.total_cmp(&y.0));
        eprintln!("boundary edges with dihedral < 60: {} ", sharp.len());
        let probe = glam::DVec3::new(
            -0.15246885625507756,
            -0.2981650934351484,
            0.3930379523979265,
        );
        let mut near: Vec<(f64, usize)> = b
            .points
            .iter()
            .enumerate()
            .map(|(k, p)| ((*p - probe).length(), k))
            .collect();
        near.sort_by(|x, y| x.0.total_cmp(&y.0));
        for &(d, k) in near.iter().take(4) {
            let nb: Vec<u32> = edges
                .keys()
                .filter(|e| e[0] == k as u32 || e[1] == k as u32)
                .map(|e| if e[0] == k as u32 { e[1] } else { e[0] })
                .collect();
            let mut amin = 180.0f64;
            for i in 0..nb.len() {
                for j in i + 1..nb.len() {
                    let u = b.points[nb[i] as usize] - b.points[k];
                    let w = b.points[nb[j] as usize] - b.points[k];
                    amin = amin.min(u.cross(w).length().atan2(u.dot(w)).to_degrees());
                }
            }
            eprintln!(
                "  near: d {d:.3e} vertex {k} {:?} loc {:?} degree {} min edge angle {amin:.2}",
                b.points[k],
                b.loc[k],
                nb.len()
            );
        }
        for (a, e) in sharp.iter().take(5) {
            eprintln!(
                "  {a:.2} deg at {:?} locs {:?}",
                b.points[e[0] as usize],
                e.map(|v| b.loc[v as usize])
            );
        }
    }
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
    let small_corner_vertices = (0..b.loc.len() as u32)
        .filter(|&v| match b.loc[v as usize] {
            restricted::Loc::Corner(k) => curves.corners[k as usize].protect_radius > 0.0,
            _ => false,
        })
        .collect();
    Ok(Remeshed {
        small_corner_vertices,
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
