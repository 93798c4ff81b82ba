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
//! 4. the cells inside refined in the same triangulation (`restricted::volume`: Li's picking
//!    ball; a point in a restricted facet's surface ball refines that facet instead), the
//!    boundary faces marked per patch or input label, then improved;
//! 5. the report's surface figures measured on the written boundary (`measure`).

mod curves;
mod curving;
mod measure;
mod restricted;
#[cfg(test)]
mod tests;

use crate::mesh::{QuadraticNodes, TetMesh};
use crate::plc::{Facet, PlcInput};
use crate::refine::{AutoSpacing, MarkerCapped, MarkerCaps};
use crate::run::error::MeshError;
use crate::run::params::{Params, DEFAULT_SURFACE_DISTANCE_FRACTION};
use crate::run::progress::Progress;
use crate::run::report::Report;
use crate::run::spacing::{ConstantSpacing, Spacing};
use crate::surface::features::{FeatureParams, Features};
use crate::surface::oracle::SurfaceOracle;
use crate::surface::repair::{Defects, Repaired};
use crate::surface::thickness::Thickness;
use crate::surface::InputSurface;
use curves::FeatureCurves;
use restricted::{Geometry, SurfaceCriteria, SurfaceMesher, VolumeCriteria, VolumeMesh};

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

/// The surface spacing is at most this many times the local thickness radius (half the
/// thickness of a thin part, half the gap between two parts: `surface::thickness`).
const THICKNESS_SPACING: f64 = 1.0;

/// Largest thickness radius estimated, as a share of the bounding-box diagonal (thicker
/// parts never bound the spacing). Measured: starting the balls at the default spacing
/// instead makes the estimate 5x cheaper on bear_bis (0.57 -> 0.12 s) but moves dino and
/// cheese to 14-15 degrees (other radii where the shrinking converges elsewhere).
const THICKNESS_CAP: f64 = 0.25;

/// Smallest angle of a boundary triangle, degrees (CGAL's facet_angle; 30 guarantees
/// termination in Boissonnat & Oudot's analysis).
const FACET_MIN_ANGLE_DEG: f64 = 30.0;

/// What the approximate mode built before the volume: the input's surface and features, and
/// the new boundary as a PLC.
pub struct Remeshed {
    pub surface: InputSurface,
    /// `surface`'s Hausdorff samples (`measure::hausdorff_samples`).
    pub input_samples: Vec<glam::DVec3>,
    /// The oracle of `surface`.
    pub oracle: SurfaceOracle,
    pub features: Features,
    /// The creases left out as noise.
    pub noise: crate::surface::features::Noise,
    pub boundary: PlcInput,
    /// Feature edges of the new boundary (vertex pairs of `boundary.vertices`).
    pub feature_edges: Vec<[u32; 2]>,
    pub distance: f64,
    /// Volume enclosed by the input (`Plc::volume`).
    pub input_volume: f64,
    /// Per region (`InputSurface::sides` numbering, from 1, at index - 1): its attribute in
    /// the output (`Plc::region_attributes`).
    pub region_attributes: Vec<i32>,
    /// The input's region volumes and interface area (`Plc::input_regions`).
    pub input_regions: crate::plc::InputRegions,
    /// A repaired input's solid (`--repair` on a dirty input).
    pub repaired: Option<Box<Repaired>>,
    /// With `--repair`, what was wrong with the input (nothing but merged vertices or flipped
    /// triangles when it was clean).
    pub repair_counts: Option<Defects>,
    pub n_corners: usize,
    /// Small corners: point and protecting radius (the influence the report counts in).
    pub small_corners: Vec<(glam::DVec3, f64)>,
    /// The vertices of `boundary` at small corners.
    pub small_corner_vertices: Vec<u32>,
    /// Per vertex of `boundary`: where the improvement may slide it (none at corners and in
    /// small corners' balls).
    pub vertex_slide: Vec<Slide>,
    /// Per vertex of `boundary`: whether it lies on a span across a hole of a repaired input
    /// (where the surface is virtual: edges there stay straight in ten-node tets).
    pub on_span: Vec<bool>,
    /// The feature curves (`Slide::Curve` indexes them).
    pub curves: FeatureCurves,
    pub stop_reason: Option<String>,
    pub seconds: f64,
    /// The caps of `Params::marker_sizes` on the input's triangles (None without any).
    pub marker_caps: Option<MarkerCaps>,
}

/// Meshes the domain bounded by the surface `input` describes (see the module comment).
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Option<QuadraticNodes>, Report), MeshError> {
    let start = std::time::Instant::now();
    let (remeshed, mesh, mut report, cell_spacing) =
        mesh_restricted(input, params, spacing, progress)?;
    let oracle = &remeshed.oracle;
    let slide = SurfaceSlide {
        oracle,
        patch_of: &remeshed.features.patch_of,
        curves: &remeshed.curves,
        vertex_slide: &remeshed.vertex_slide,
        distance: DISTANCE_SAFETY * remeshed.distance,
    };
    let default_spacing =
        ConstantSpacing(DEFAULT_SPACING_FRACTION * remeshed.surface.bbox_diagonal());
    let f: &dyn Spacing = match (spacing, &cell_spacing) {
        (Some(s), _) => s,
        (None, Some(s)) => s,
        (None, None) => &default_spacing,
    };
    let capped = MarkerCapped {
        inner: f,
        caps: remeshed.marker_caps.as_ref(),
    };
    let f: &dyn Spacing = match remeshed.marker_caps {
        Some(_) => &capped,
        None => f,
    };
    let before = report.dihedral_range();
    let (mesh, stats) = crate::improve::finish(mesh, None, params, Some(&slide))?;
    measure_volume(&mesh, f, params, &remeshed.small_corners, &mut report)?;
    report.record_improvement(stats, before);
    let mut surface_report = measure::surface_report(&remeshed, &mesh);
    (
        surface_report.n_bad_near_small_corners,
        surface_report.max_rho_away_from_small_corners,
    ) = measure::small_corner_figures(&mesh, &remeshed.small_corners, params);
    report.surface = Some(surface_report);
    report.input_regions = Some(remeshed.input_regions.clone());
    let quadratic = (params.order == 2).then(|| {
        let curving = curving::OnInputSurface {
            oracle,
            patch_of: &remeshed.features.patch_of,
            curves: &remeshed.curves,
            vertex_slide: &remeshed.vertex_slide,
            on_span: &remeshed.on_span,
            feature_edges: remeshed
                .feature_edges
                .iter()
                .map(|&[a, b]| (a.min(b), a.max(b)))
                .collect(),
        };
        let (nodes, quadratic_report) = crate::quadratic::elevate(&mesh, Some(&curving));
        report.quadratic = Some(quadratic_report);
        nodes
    });
    report.seconds_total = start.elapsed().as_secs_f64();
    Ok((mesh, quadratic, report))
}

/// The report's figures of the final `mesh` (sizes against `f`), and whether it is complete:
/// the surface was finished and every tet away from the small corners' protecting balls
/// meets the bounds.
fn measure_volume(
    mesh: &TetMesh,
    f: &dyn Spacing,
    params: &Params,
    small_corners: &[(glam::DVec3, f64)],
    report: &mut Report,
) -> Result<(), MeshError> {
    let near = |t: &[u32; 4]| {
        t.iter().any(|&v| {
            let p = mesh.vertices[v as usize];
            small_corners
                .iter()
                .any(|&(c, r)| (p - c).length_squared() <= r * r)
        })
    };
    let (measured, bad_elsewhere) = crate::refine::report::measure(mesh, f, params, &near)?;
    report.take_measures(measured);
    report.complete = report.stop_reason.is_none() && bad_elsewhere == 0;
    if report.stop_reason.is_none() && bad_elsewhere > 0 {
        report.stop_reason = Some(format!(
            "{bad_elsewhere} tets away from small corners still violate a bound"
        ));
    }
    Ok(())
}

/// Where a boundary vertex may move during the improvement.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Slide {
    Fixed,
    /// On this patch of the input surface.
    Patch(u32),
    /// Along this feature curve.
    Curve(u32),
}

/// The improvement's view of the input: boundary vertices inside a patch slide on that patch,
/// those on a feature curve along the curve; a boundary triangle must keep its centroid and
/// edge midpoints within the surface mesher's own distance criterion (half the bound).
struct SurfaceSlide<'a> {
    oracle: &'a SurfaceOracle,
    patch_of: &'a [u32],
    curves: &'a FeatureCurves,
    vertex_slide: &'a [Slide],
    distance: f64,
}

impl SurfaceSlide<'_> {
    fn slide(&self, v: u32) -> Slide {
        self.vertex_slide
            .get(v as usize)
            .copied()
            .unwrap_or(Slide::Fixed)
    }
}

impl crate::improve::SurfaceSlide for SurfaceSlide<'_> {
    fn slides(&self, v: u32) -> bool {
        self.slide(v) != Slide::Fixed
    }

    fn along(&self, v: u32, at: glam::DVec3) -> Option<glam::DVec3> {
        match self.slide(v) {
            Slide::Curve(c) => self.curves.curves[c as usize]
                .closest(at)
                .map(|(_, dir)| dir),
            _ => None,
        }
    }

    fn project(&self, v: u32, x: glam::DVec3) -> Option<glam::DVec3> {
        match self.slide(v) {
            Slide::Fixed => None,
            Slide::Patch(patch) => {
                let c = self.oracle.closest(x)?;
                (self.patch_of[c.triangle as usize] == patch).then_some(c.point)
            }
            Slide::Curve(c) => self.curves.curves[c as usize].closest(x).map(|(p, _)| p),
        }
    }

    fn keeps_close(&self, [a, b, c]: [glam::DVec3; 3]) -> bool {
        [
            (a + b + c) / 3.0,
            (a + b) / 2.0,
            (b + c) / 2.0,
            (c + a) / 2.0,
        ]
        .into_iter()
        .all(|p| self.oracle.distance_beyond(p, self.distance).is_none())
    }
}

/// Steps 3 and 4 in one triangulation: the restricted Delaunay surface, then its cells
/// refined (`restricted::volume`). The report holds what is known before the improvement (its
/// dihedral range, times, the surface's stop reason); the cells' automatic spacing, if any,
/// comes along.
fn mesh_restricted(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(Remeshed, TetMesh, Report, Option<AutoSpacing>), MeshError> {
    let crit = VolumeCriteria {
        rho0: params.rho0,
        sigma0: params.sigma0,
        min_dihedral_deg: params.min_dihedral,
        delta: params.delta,
        b: params.b,
        max_tries: params.max_tries,
        size_factor: params.size_factor,
        user_spacing: spacing.is_some(),
        seed: params.seed,
    };
    let start = std::time::Instant::now();
    let (mut remeshed, volume) = remesh(input, params, spacing, crit, progress)?;
    remeshed.seconds -= volume.seconds_volume;
    let mesh = TetMesh {
        tet_regions: volume
            .regions
            .iter()
            .map(|&r| remeshed.region_attributes[r as usize - 1])
            .collect(),
        vertices: volume.vertices,
        tets: volume.tets,
        boundary: remeshed
            .boundary
            .facets
            .iter()
            .map(|f| [f.polygons[0][0], f.polygons[0][1], f.polygons[0][2]])
            .collect(),
        boundary_markers: remeshed.boundary.facets.iter().map(|f| f.marker).collect(),
    };
    let (min_dihedral_deg, max_dihedral_deg) = dihedral_range(&mesh);
    let report = Report {
        min_dihedral_deg,
        max_dihedral_deg,
        seconds_refinement: volume.seconds_volume,
        seconds_total: start.elapsed().as_secs_f64(),
        n_acute_angles: remeshed.small_corner_vertices.len(),
        stop_reason: remeshed.stop_reason.clone(),
        refusals: volume.refusals,
        ..Report::default()
    };
    Ok((remeshed, mesh, report, volume.spacing))
}

/// Smallest and largest dihedral angle of `mesh`'s tets, degrees.
fn dihedral_range(mesh: &TetMesh) -> (f64, f64) {
    mesh.tets.iter().fold((180.0, 0.0), |(lo, hi), t| {
        let [a, b, c, d] = t.map(|v| mesh.vertices[v as usize]);
        let (l, h) = crate::geom::min_max_dihedral(a, b, c, d);
        (lo.min(l), hi.max(h))
    })
}

/// Steps 1-4: the new boundary and the tets inside it.
pub fn remesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    crit: VolumeCriteria,
    progress: Option<Progress>,
) -> Result<(Remeshed, VolumeMesh), MeshError> {
    remesh_with(input, params, spacing, |mesher| {
        mesher.run_with_volume(crit, progress)
    })
}

/// The new boundary alone, as a PLC of triangles, and the cells' automatic spacing (graded
/// from the surface) when `spacing` is None: what partitioned meshing meshes in keep mode.
/// The cell level's refinement of the surface is left out, so its triangles are the surface
/// level's.
pub fn boundary_only(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
) -> Result<(PlcInput, Option<AutoSpacing>), MeshError> {
    let user_spacing = spacing.is_some();
    let (remeshed, volume) = remesh_with(input, params, spacing, |mesher| {
        mesher.run_surface_only(user_spacing)
    })?;
    Ok((remeshed.boundary, volume.spacing))
}

/// Steps 1-3, then `run` on the surface mesher.
fn remesh_with(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    run: impl FnOnce(SurfaceMesher) -> Result<(restricted::Boundary, VolumeMesh), MeshError>,
) -> Result<(Remeshed, VolumeMesh), MeshError> {
    let start = std::time::Instant::now();
    params.check().map_err(MeshError::InvalidInput)?;
    let source = Source::read(input, params)?;
    let surface = source.surface();
    let diagonal = surface.bbox_diagonal();
    let default_spacing = ConstantSpacing(DEFAULT_SPACING_FRACTION * diagonal);
    let f: &dyn Spacing = spacing.unwrap_or(&default_spacing);
    // Per-marker sizes cap the spacing next to the input triangles of each marker given
    // (whether or not the markers survive as the output's labels), the surface's and, through
    // `SurfaceMesher::set_marker_caps`, the cells' automatic one.
    let marker_caps = MarkerCaps::new(&surface, &params.marker_sizes)?;
    let capped = MarkerCapped {
        inner: f,
        caps: marker_caps.as_ref(),
    };
    let f: &dyn Spacing = match marker_caps {
        Some(_) => &capped,
        None => f,
    };
    // A bad spacing value keeps every crease here; the surface mesher reports it.
    let (features, noise) = Features::detect_denoised(
        &surface,
        &FeatureParams {
            feature_angle: params.feature_angle,
            use_markers: source.repaired().is_none() && has_labels(input),
            borders: source.repaired().is_none(),
        },
        &mut |p| f.at(p),
    );
    let (mut features, noise) = (features, noise);
    if let Some(r) = source.repaired() {
        r.join_patches_across_intersections(&mut features);
    }
    let mut curves = FeatureCurves::new(&surface, &features);
    let distance = if params.surface_distance > 0.0 {
        params.surface_distance
    } else {
        DEFAULT_SURFACE_DISTANCE_FRACTION * diagonal
    };
    curves.cap_protect_radius(PROTECT_DISTANCES * distance);
    let oracle = SurfaceOracle::new(&surface);
    let thickness = Thickness::estimate(&surface, &oracle, THICKNESS_CAP * diagonal);
    let criteria = SurfaceCriteria {
        distance: DISTANCE_SAFETY * distance,
        bound: distance,
        min_angle_deg: FACET_MIN_ANGLE_DEG,
        max_vertices: params.max_vertices,
        feature_floor: PROTECT_DISTANCES * distance,
        thickness_spacing: THICKNESS_SPACING,
        seed: params.seed,
    };
    let geometry = Geometry {
        surface: &surface,
        oracle: &oracle,
        curves: &curves,
        patch_of: &features.patch_of,
        repair: source.repaired(),
    };
    let mut mesher = SurfaceMesher::new(geometry, f, Some(&thickness), criteria)?;
    mesher.set_region_caps(region_caps(
        &source.region_attributes(),
        &params.region_sizes,
    )?);
    mesher.set_marker_caps(marker_caps.as_ref());
    let (mut b, volume) = run(mesher)?;

    let boundary = boundary_plc(input, &b, &surface, &features);
    let small_corners: Vec<_> = curves
        .small_corners()
        .map(|c| (c.point, c.protect_radius))
        .collect();
    let (small_corner_vertices, vertex_slide) = slides(&b, &curves);
    let on_span = b
        .loc
        .iter()
        .map(|l| matches!(l, restricted::Loc::Span))
        .collect();
    let input_samples = b
        .input_samples
        .take()
        .unwrap_or_else(|| measure::hausdorff_samples(&surface));
    let (input_volume, region_attributes, input_regions) = (
        source.volume(),
        source.region_attributes(),
        source.input_regions(),
    );
    let (repaired, repair_counts) = source.into_repaired();
    let remeshed = Remeshed {
        marker_caps,
        input_samples,
        small_corner_vertices,
        vertex_slide,
        on_span,
        input_volume,
        region_attributes,
        input_regions,
        repaired,
        repair_counts,
        n_corners: curves.corners.len(),
        curves,
        small_corners,
        surface,
        oracle,
        features,
        noise,
        boundary,
        feature_edges: b.feature_edges,
        distance,
        stop_reason: b.stop_reason,
        seconds: start.elapsed().as_secs_f64(),
    };
    Ok((remeshed, volume))
}

/// Per region number (0 outside, then `attributes[r - 1]`'s region) the most spacing its cells
/// get (`Params::region_sizes`): empty when no size is given. An id no region has is an error
/// listing the input's.
fn region_caps(attributes: &[i32], sizes: &[(i32, f64)]) -> Result<Vec<f64>, MeshError> {
    if sizes.is_empty() {
        return Ok(vec![]);
    }
    let mut caps = vec![f64::INFINITY; attributes.len() + 1];
    for &(id, h) in sizes {
        if !attributes.contains(&id) {
            return Err(crate::refine::unknown_region(id, attributes));
        }
        for (cap, _) in caps[1..]
            .iter_mut()
            .zip(attributes)
            .filter(|(_, &a)| a == id)
        {
            *cap = cap.min(h);
        }
    }
    Ok(caps)
}

/// The input as the approximate mode reads it: a checked PLC, or with `--repair` a dirty
/// surface's solid.
enum Source {
    /// With `--repair`, what was counted of the clean input.
    Checked(Box<crate::plc::Plc>, Option<Defects>),
    Repaired(Box<Repaired>),
}

impl Source {
    /// A clean input is meshed as it is, `--repair` or not (its mesh does not change, and the
    /// faces that several regions share stay interfaces).
    fn read(input: &PlcInput, params: &Params) -> Result<Source, MeshError> {
        let repair_error = |e: String| MeshError::InvalidInput(format!("repair: {e}"));
        match crate::plc::validate(input) {
            Ok(plc) if params.repair => {
                let counts = Defects::of_clean(input).map_err(repair_error)?;
                Ok(Source::Checked(Box::new(plc), Some(counts)))
            }
            Ok(plc) => Ok(Source::Checked(Box::new(plc), None)),
            Err(_) if params.repair => Repaired::new(input)
                .map(|r| Source::Repaired(Box::new(r)))
                .map_err(repair_error),
            Err(e) => Err(MeshError::InvalidInput(with_repair_hint(e))),
        }
    }

    /// The triangles the boundary approximates.
    fn surface(&self) -> InputSurface {
        match self {
            Source::Checked(plc, _) => InputSurface::from_plc(plc),
            Source::Repaired(r) => r.surface.clone(),
        }
    }

    fn repaired(&self) -> Option<&Repaired> {
        match self {
            Source::Checked(..) => None,
            Source::Repaired(r) => Some(r),
        }
    }

    /// The enclosed volume (0, unknown, for a repaired input: the report then gives no
    /// relative difference).
    fn volume(&self) -> f64 {
        match self {
            Source::Checked(plc, _) => plc.volume(),
            Source::Repaired(_) => 0.0,
        }
    }

    /// Per region, its output attribute (a repaired input's solid is one region, 0).
    fn region_attributes(&self) -> Vec<i32> {
        match self {
            Source::Checked(plc, _) => plc.region_attributes(),
            Source::Repaired(_) => vec![0],
        }
    }

    fn input_regions(&self) -> crate::plc::InputRegions {
        match self {
            Source::Checked(plc, _) => plc.input_regions(),
            Source::Repaired(_) => crate::plc::InputRegions {
                volumes: vec![(0, 0.0)],
                interface_area: 0.0,
            },
        }
    }

    /// The repaired solid, and what `--repair` counted of the input.
    fn into_repaired(self) -> (Option<Box<Repaired>>, Option<Defects>) {
        match self {
            Source::Checked(_, counts) => (None, counts),
            Source::Repaired(r) => {
                let counts = r.defects.clone();
                (Some(r), Some(counts))
            }
        }
    }
}

/// A validation error's message, with the hint that `--repair` meshes such a surface where
/// it would (the surface is open, self-intersecting or has duplicate vertices).
fn with_repair_hint(e: crate::plc::PlcError) -> String {
    use crate::plc::PlcError::*;
    let message = e.to_string();
    match e {
        DuplicateVertex { .. }
        | FacetsIntersect { .. }
        | FacetsMeetOffSegment { .. }
        | SurfaceNotClosed { .. }
        | VertexOnFacet { .. }
        | NonPlanarFacet { .. }
        | DegenerateFacet { .. }
        | RepeatedVertex { .. }
        | EdgesIntersect { .. } => format!(
            "{message} (--repair meshes open, self-intersecting and overlapping surfaces as \
             the solid their winding number encloses)"
        ),
        _ => message,
    }
}

/// The boundary vertices in a small corner's protecting ball, where the surface mesher left
/// facet angles alone and the cells are not refined (the report counts them), and how each
/// boundary vertex may slide in the improvement (not at all in such a ball).
fn slides(b: &restricted::Boundary, curves: &FeatureCurves) -> (Vec<u32>, Vec<Slide>) {
    let in_small_corner = |p: glam::DVec3| {
        curves
            .small_corners()
            .any(|c| (p - c.point).length_squared() <= c.protect_radius * c.protect_radius)
    };
    let small_corner_vertices = (0..b.loc.len() as u32)
        .filter(|&v| in_small_corner(b.points[v as usize]))
        .collect();
    let vertex_slide = b
        .loc
        .iter()
        .zip(&b.points)
        .map(|(loc, &p)| match loc {
            _ if in_small_corner(p) => Slide::Fixed,
            restricted::Loc::Patch(k) => Slide::Patch(*k),
            restricted::Loc::Curve(c) => Slide::Curve(*c),
            _ => Slide::Fixed,
        })
        .collect();
    (small_corner_vertices, vertex_slide)
}

/// The new boundary as a PLC: one facet per triangle, marked with the input's label of the
/// input triangle it approximates, else with its smooth patch (numbered from 1).
fn boundary_plc(
    input: &PlcInput,
    b: &restricted::Boundary,
    surface: &InputSurface,
    features: &Features,
) -> PlcInput {
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
    PlcInput {
        vertices: b.points.clone(),
        facets,
        holes: input.holes.clone(),
        regions: input.regions.clone(),
    }
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
