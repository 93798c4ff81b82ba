//! Li's REMOVE-SLIVER refinement (the paper, section 3) on top of the Delaunay kernel:
//! boundary recovery (empty encroachment), domain marking, then cleaning of size-bad,
//! radius-edge-bad and sliver tets from random points of picking regions.

pub mod background;
#[cfg(test)]
mod check;
mod domain;
pub mod existing;
pub(crate) mod levels;
mod mark;
mod marker_size;
pub(crate) mod outcome;
mod output;
mod plc_level;
mod quality;
mod recover;
pub mod report;
mod spacing;

pub(crate) use mark::unknown_region;
pub use marker_size::{MarkerCapped, MarkerCaps, MARKER_GRADING};
pub use outcome::Refusals;
pub use quality::SPACING_BATCH;
pub use spacing::AutoSpacing;

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use glam::DVec3;
use mark::Unseeded;
use recover::Settled;
use rustc_hash::FxHashSet;

/// Refinement parameters (names follow the paper).
#[derive(Debug, Clone, PartialEq)]
pub struct Params {
    /// Radius-edge bound rho0 = R / L (the paper needs > 2 for its proof; 2 works in practice).
    pub rho0: f64,
    /// Sliver bound sigma0 = V / L^3 (regular tet: 0.1179).
    pub sigma0: f64,
    /// Practical sliver bound in degrees: a tet whose smallest dihedral angle is below it is
    /// treated as a sliver too. sigma = V / L^3 uses the shortest edge, so a flat tet with one
    /// short edge can pass any sigma0; the dihedral angle catches it. 0 disables.
    pub min_dihedral: f64,
    /// Picking-region radius factor: points are drawn from the ball (c, delta * R).
    pub delta: f64,
    /// Small-sliver radius factor: a new sliver with circumradius <= b * R rejects the point.
    pub b: f64,
    /// Size factor: a tet with R / f(c) > B is size-bad.
    pub size_factor: f64,
    /// Random seed: same input, same parameters, same seed => identical output.
    pub seed: u64,
    /// Stop (report `complete: false`) once the mesh has this many vertices.
    pub max_vertices: usize,
    /// Candidate points drawn per bad element before the best one is taken.
    pub max_tries: usize,
    /// When false, only recover the boundary (no quality refinement).
    pub refine: bool,
    /// How far the influence of a vertex where segments meet below 60 degrees reaches along
    /// its segments and facets, in radii of its protecting ball (0.4 x the distance to its
    /// nearest input vertex). Within it shape is enforced only by circumcentres that break no
    /// boundary. Infinite (the default): whole segments and facets holding such a vertex.
    /// Smaller values (2 to 8) leave fewer bad tets next to small angles, at the price of more
    /// vertices and time on some models (docs/parameters.md).
    pub small_angle_reach: f64,
    /// Improve the mesh after refinement (`crate::improve`: flips, edge removal, smoothing).
    /// False keeps the refinement's Delaunay mesh, with only flat or inverted tets removed.
    pub improve: bool,
    /// What the input facets are: constraints kept exactly (`Keep`), or the description of a
    /// piecewise smooth surface that the output approximates (`Approximate`, `crate::approx`).
    pub surface_mode: SurfaceMode,
    /// Approximate mode: an edge whose two triangles' normals differ by more than this many
    /// degrees is a sharp feature. Default 40.
    pub feature_angle: f64,
    /// Approximate mode: how far the output boundary may lie from the input surface
    /// (absolute length; 0 = the default, 0.001 x the input's bounding-box diagonal).
    pub surface_distance: f64,
    /// Improvement works on tets whose smallest dihedral angle is below this many degrees (or
    /// whose radius-edge ratio exceeds rho0). 0 = the mode's default: 26 in keep mode, 20 in
    /// approximate mode, whose finer boundaries make 26 cost about 8x the improvement time
    /// (see `effective_improve_target`).
    pub improve_target: f64,
    /// Approximate mode: mesh a dirty surface (open, self-intersecting, overlapping, flipped,
    /// duplicated) as the solid where its generalized winding number is at least 1/2
    /// (`crate::surface::repair`) instead of refusing it.
    pub repair: bool,
    /// Element order of the output: 1 (four-node tets) or 2 (ten-node tets, boundary nodes on
    /// the input surface where the surface mode knows it; `crate::quadratic`).
    pub order: u8,
    /// Maximum sizes per region attribute (`--region-size ID:H`): the tets of region ID get
    /// spacing at most H (the smaller of it and the spacing's value). Each H finite and > 0;
    /// an ID the input does not have is an error. Not a parameter by name.
    pub region_sizes: Vec<(i32, f64)>,
    /// Maximum sizes per boundary marker (`--marker-size ID:H`): the spacing is at most
    /// H + [`MARKER_GRADING`] x max(0, d - H), d the distance to the input facets of marker ID
    /// (the smaller of it and the spacing's value; `MarkerCaps`). Each H finite and > 0; an
    /// ID no input facet has is an error. Not a parameter by name.
    pub marker_sizes: Vec<(i32, f64)>,
    /// Threads of the run's parallel steps (`crate::parallel`; 0 = all cores): the output is
    /// the same for every count. `spacing_thread_safe`: a C spacing callback may be called
    /// from several of them at once (the C ABI's declaration; Rust spacings say it by `Sync`).
    pub threads: usize,
    pub spacing_thread_safe: bool,
}

/// Default improvement target (degrees) in keep mode: every acute-free model reaches 25.
pub const KEEP_IMPROVE_TARGET: f64 = 26.0;
/// Default improvement target (degrees) in approximate mode: the surface mode's goal of 20
/// degrees; 26 there costs 1.4 s more on fandisk at 125k tets (0.2 s -> 1.6 s).
pub const APPROXIMATE_IMPROVE_TARGET: f64 = 20.0;

/// How the input facets bound the domain.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, serde::Serialize)]
pub enum SurfaceMode {
    /// Every input facet is preserved exactly (TetGen-style input).
    #[default]
    Keep,
    /// The facets describe a piecewise smooth surface: sharp features are kept, smooth
    /// patches are remeshed within `surface_distance`.
    Approximate,
}

/// Share of the bounding-box diagonal that is the default `surface_distance` (fTetWild's
/// default envelope).
pub const DEFAULT_SURFACE_DISTANCE_FRACTION: f64 = 1e-3;

impl Default for Params {
    fn default() -> Self {
        Params {
            rho0: 2.0,
            sigma0: 0.02,
            min_dihedral: 18.0,
            delta: 0.3,
            b: 4.0,
            size_factor: 1.0,
            seed: 1,
            max_vertices: 10_000_000,
            max_tries: 20,
            refine: true,
            small_angle_reach: f64::INFINITY,
            improve: true,
            surface_mode: SurfaceMode::Keep,
            feature_angle: 40.0,
            surface_distance: 0.0,
            improve_target: 0.0,
            repair: false,
            order: 1,
            region_sizes: Vec::new(),
            marker_sizes: Vec::new(),
            threads: 0,
            spacing_thread_safe: false,
        }
    }
}

/// Largest improvement target accepted, degrees (beyond it the passes rarely gain and cost
/// grows fast).
pub const MAX_IMPROVE_TARGET: f64 = 40.0;

impl Params {
    /// The improvement target in degrees: `improve_target`, or the mode's default when 0.
    pub fn effective_improve_target(&self) -> f64 {
        match (self.improve_target, self.surface_mode) {
            (t, _) if t > 0.0 => t,
            (_, SurfaceMode::Keep) => KEEP_IMPROVE_TARGET,
            (_, SurfaceMode::Approximate) => APPROXIMATE_IMPROVE_TARGET,
        }
    }

    /// Checks ranges; the message names the parameter.
    pub fn check(&self) -> Result<(), String> {
        let positive = [
            ("rho0", self.rho0),
            ("delta", self.delta),
            ("b", self.b),
            ("size_factor", self.size_factor),
        ];
        for (name, v) in positive {
            if !(v.is_finite() && v > 0.0) {
                return Err(format!(
                    "parameter {name} = {v} must be finite and positive"
                ));
            }
        }
        if !matches!(self.order, 1 | 2) {
            return Err(format!(
                "parameter order = {} must be 1 (four-node tets) or 2 (ten-node tets)",
                self.order
            ));
        }
        if self.small_angle_reach.is_nan() || self.small_angle_reach <= 0.0 {
            return Err(format!(
                "parameter small_angle_reach = {} must be > 0 (infinite: whole facets)",
                self.small_angle_reach
            ));
        }
        if !(self.sigma0.is_finite() && (0.0..crate::geom::REGULAR_SIGMA).contains(&self.sigma0)) {
            return Err(format!(
                "parameter sigma0 = {} must be in [0, {:.4}) (the regular tet's V/L^3)",
                self.sigma0,
                crate::geom::REGULAR_SIGMA
            ));
        }
        if !(self.min_dihedral.is_finite() && (0.0..70.5).contains(&self.min_dihedral)) {
            return Err(format!(
                "parameter min_dihedral = {} must be in [0, 70.5) degrees",
                self.min_dihedral
            ));
        }
        if !(self.feature_angle.is_finite()
            && self.feature_angle > 0.0
            && self.feature_angle < 180.0)
        {
            return Err(format!(
                "parameter feature_angle = {} must be in (0, 180) degrees",
                self.feature_angle
            ));
        }
        if !(self.surface_distance.is_finite() && self.surface_distance >= 0.0) {
            return Err(format!(
                "parameter surface_distance = {} must be finite and >= 0 (0: the default, \
                 0.001 x the bounding-box diagonal)",
                self.surface_distance
            ));
        }
        if !(self.improve_target.is_finite()
            && (0.0..=MAX_IMPROVE_TARGET).contains(&self.improve_target))
        {
            return Err(format!(
                "parameter improve_target = {} must be in [0, {MAX_IMPROVE_TARGET}] degrees (0: \
                 the mode's default, 26 keep / 20 approximate)",
                self.improve_target
            ));
        }
        for &(id, h) in &self.region_sizes {
            if !(h.is_finite() && h > 0.0) {
                return Err(format!(
                    "region size for region {id}: h = {h} must be finite and > 0"
                ));
            }
        }
        for &(id, h) in &self.marker_sizes {
            if !(h.is_finite() && h > 0.0) {
                return Err(format!(
                    "marker size for marker {id}: h = {h} must be finite and > 0"
                ));
            }
        }
        if self.delta >= 1.0 {
            return Err(format!("parameter delta = {} must be < 1", self.delta));
        }
        if self.rho0 < 0.7 {
            return Err(format!(
                "parameter rho0 = {} is below what a tet can reach (0.612)",
                self.rho0
            ));
        }
        Ok(())
    }
}

/// A spacing (target element size) function f(x) > 0.
pub trait Spacing {
    fn at(&self, p: DVec3) -> f64;
    /// Evaluates many points at once (callers across an FFI pay one call per batch).
    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        for (o, &p) in out.iter_mut().zip(points) {
            *o = self.at(p);
        }
    }
}

/// Constant spacing.
#[derive(Debug, Clone, Copy)]
pub struct ConstantSpacing(pub f64);
impl Spacing for ConstantSpacing {
    fn at(&self, _: DVec3) -> f64 {
        self.0
    }
}

/// Spacing from a closure.
pub struct FnSpacing<F: Fn(DVec3) -> f64>(pub F);
impl<F: Fn(DVec3) -> f64> Spacing for FnSpacing<F> {
    fn at(&self, p: DVec3) -> f64 {
        (self.0)(p)
    }
}

/// The smallest of several spacings at every point (e.g. a fine zone's f and a global one).
/// A value that is not finite and positive is passed on as it is (not dropped by the minimum),
/// so the run fails naming the point.
pub struct MinSpacing(pub Vec<Box<dyn Spacing + Send>>);
impl Spacing for MinSpacing {
    fn at(&self, p: DVec3) -> f64 {
        let mut f = f64::INFINITY;
        for s in &self.0 {
            let v = s.at(p);
            if !(v.is_finite() && v > 0.0) {
                return v;
            }
            f = f.min(v);
        }
        f
    }
}

/// What a run achieved.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Report {
    pub n_vertices: usize,
    pub n_tets: usize,
    pub n_boundary_faces: usize,
    pub seconds_recovery: f64,
    pub seconds_refinement: f64,
    pub seconds_total: f64,
    pub max_rho: f64,
    pub min_sigma: f64,
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// Tets with a dihedral angle below 5, 10, 15, 20 degrees.
    pub tets_below_deg: [usize; 4],
    /// max over tets of R / f(circumcentre). This and the edge ratios describe the output
    /// mesh in approximate mode; in keep mode they (and `n_bad_near_acute`) are the refined
    /// mesh's before the improvement, which re-measures only the shape figures there.
    pub max_size_ratio: f64,
    /// edge length / f(midpoint): min, median, max
    pub edge_ratio_min: f64,
    pub edge_ratio_median: f64,
    pub edge_ratio_max: f64,
    /// Acute input angles found (segment pairs < 90 deg, facet pairs < 90 deg).
    pub n_acute_angles: usize,
    /// Tets left violating a bound because they are within the influence of an acute angle.
    pub n_bad_near_acute: usize,
    /// How often refinement left a bad tet as it was, per reason (see [`Refusals`]).
    pub refusals: Refusals,
    /// Tets whose region (or inside/outside status) the check after refinement corrected:
    /// refinement keeps the labels incrementally (`Domain::retag_created`), so this is 0 unless
    /// that invariant broke (then one more pass refined them). 0 on every shared model.
    pub n_relabelled: usize,
    /// Whether every bound holds everywhere it is enforced (false when a budget stopped it).
    pub complete: bool,
    /// Why refinement stopped early, if it did.
    pub stop_reason: Option<String>,
    /// Whether the output is the refinement's Delaunay mesh (false once improvement changed it).
    pub delaunay: bool,
    /// Smallest and largest dihedral angle before improvement, degrees.
    pub dihedral_before_improve_deg: [f64; 2],
    /// Time spent in the improvement pass (included in `seconds_total`).
    pub seconds_improvement: f64,
    /// What the improvement pass did.
    pub improvement: crate::improve::Stats,
    /// Approximate surface mode only: how close the output boundary is to the input surface.
    pub surface: Option<SurfaceReport>,
    /// With `order` 2: the ten-node tets' curving and validity.
    pub quadratic: Option<crate::quadratic::QuadraticReport>,
    /// Per region attribute of the output (sorted): its tets and volume against the input's.
    pub regions: Vec<RegionReport>,
    /// Area of the output faces between tets of different regions, and of the input's.
    pub interface_area: f64,
    pub input_interface_area: f64,
    /// The input's regions, from the surface mode until `measure_regions` compares with them.
    #[serde(skip)]
    pub input_regions: Option<crate::plc::InputRegions>,
}

/// One region of the output (all tets of one attribute) against the input's.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RegionReport {
    pub attribute: i32,
    pub tets: usize,
    pub volume: f64,
    pub input_volume: f64,
    /// (volume - input_volume) / input_volume.
    pub relative_volume_difference: f64,
}

/// How well the output boundary approximates the input surface (approximate mode).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct SurfaceReport {
    /// The distance bound the boundary was built to (absolute).
    pub surface_distance: f64,
    /// Sampled one-sided distances: every input point to the output boundary, and back.
    pub hausdorff_input_to_output: f64,
    pub hausdorff_output_to_input: f64,
    /// The largest distance of a point of an input feature edge from the output's feature
    /// edges.
    pub feature_distance: f64,
    /// (output volume - input volume) / input volume.
    pub relative_volume_difference: f64,
    /// Sharp edges, feature polylines, corners and smooth patches found in the input.
    pub n_feature_edges: usize,
    pub n_feature_polylines: usize,
    /// Crease edges and curves left out as noise (short, free-hanging or isolated creases of
    /// a scan: `surface::features`).
    pub n_noise_edges: usize,
    pub n_noise_curves: usize,
    pub n_corners: usize,
    pub n_patches: usize,
    /// Feature corners whose angle (between feature curves, or spanned by a patch) is below
    /// 60 degrees, and the output tets with a vertex in their protecting balls that miss a
    /// bound.
    pub n_small_corners: usize,
    pub n_bad_near_small_corners: usize,
    /// The largest radius-edge ratio of the other tets (the ones `complete` is judged on).
    pub max_rho_away_from_small_corners: f64,
    /// Vertices and triangles of the remeshed boundary.
    pub n_surface_vertices: usize,
    pub n_surface_triangles: usize,
    /// Time spent building the boundary (feature protection and restricted Delaunay facets).
    pub seconds_surface: f64,
    /// With `--repair`: what was wrong with the input and what the output spans. The
    /// Hausdorff distance out->in then leaves the spanned holes out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub repair: Option<crate::surface::repair::Defects>,
}

/// Why meshing failed.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshError {
    /// The input failed validation; the message names the offending item.
    InvalidInput(String),
    /// The spacing function returned a value that is not finite and positive.
    BadSpacing { point: DVec3, value: f64 },
    /// The progress callback asked to stop.
    Cancelled,
    /// A bug: an internal invariant failed.
    Internal(String),
    /// A tet of the result is flat or inverted (exact orientation <= 0) and could not be
    /// removed: the mesh is not returned.
    DegenerateTet {
        /// Its index in the output's tets.
        index: usize,
        vertices: [u32; 4],
        points: Box<[DVec3; 4]>,
        inverted: bool,
    },
}

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshError::InvalidInput(m) => write!(f, "invalid input: {m}"),
            MeshError::BadSpacing { point, value } => write!(
                f,
                "spacing function returned {value} at ({}, {}, {}): it must be finite and positive",
                point.x, point.y, point.z
            ),
            MeshError::Cancelled => write!(f, "cancelled by the progress callback"),
            MeshError::Internal(m) => write!(f, "internal error: {m}"),
            MeshError::DegenerateTet {
                index,
                vertices,
                points,
                inverted,
            } => {
                write!(
                    f,
                    "output tet {index} (vertices {vertices:?}, 0-based) is {}; no flip or \
                     move removed it, so the mesh is not written. Its corners:",
                    if *inverted {
                        "inverted"
                    } else {
                        "flat (zero volume)"
                    }
                )?;
                for p in points.iter() {
                    write!(f, " ({}, {}, {})", p.x, p.y, p.z)?;
                }
                Ok(())
            }
        }
    }
}
impl std::error::Error for MeshError {}

/// The region of every tet slot as the output would give it: its attribute, None outside the
/// domain (and for dead slots).
fn tet_labels(dom: &domain::Domain, regions: &mark::Regions) -> Vec<Option<i32>> {
    (0..dom.dt.tet_capacity() as u32)
        .map(|t| {
            let tag = if dom.dt.is_alive(t) { dom.dt.tag(t) } else { 0 };
            (tag != 0).then(|| regions.attribute[tag as usize])
        })
        .collect()
}

/// Progress callback: (fraction done estimate in [0, 1], current vertex count) -> keep going?
pub type Progress<'a> = &'a mut dyn FnMut(f64, usize) -> bool;

/// Meshes a domain: validation, boundary recovery, marking, and (if `params.refine`) quality
/// refinement. `spacing` None = automatic (local-feature-size based) spacing.
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Report), MeshError> {
    mesh_domain(
        input,
        params,
        spacing,
        progress,
        SmallAngles::Input,
        Unseeded::Domain,
    )
}

/// Which input angles refinement treats as small.
#[derive(Clone, Copy)]
enum SmallAngles {
    /// Those the validator finds (keep mode).
    Input,
    /// None (the boundary of an existing mesh).
    None,
}

/// [`mesh`], optionally treating every input angle as large (for the boundary of an existing
/// mesh, whose flat sides are tiled by triangles meeting at angles that are not features), and
/// with a choice for components without a region seed (an existing mesh seeds all its pieces:
/// the others are holes).
fn mesh_domain(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
    small_angles: SmallAngles,
    unseeded: Unseeded,
) -> Result<(TetMesh, Report), MeshError> {
    let start = std::time::Instant::now();
    params.check().map_err(MeshError::InvalidInput)?;
    let plc = crate::plc::validate(input).map_err(|e| MeshError::InvalidInput(e.to_string()))?;
    let marker_caps = if params.marker_sizes.is_empty() {
        None
    } else {
        let surface = crate::surface::InputSurface::from_plc(&plc);
        MarkerCaps::new(&surface, &params.marker_sizes)?
    };
    let mut dom = domain::Domain::new(input, &plc)?;
    match small_angles {
        SmallAngles::Input => dom.set_input_angles(&plc, params.small_angle_reach),
        SmallAngles::None => {}
    }
    let mut budget = recover::MAX_RECOVERY_SPLITS.min(params.max_vertices.saturating_mul(4));
    if dom.recover_boundary(&mut budget)? == Settled::BudgetSpent {
        return Err(recovery_budget_spent(params));
    }
    let mut regions = dom.mark_domain(&plc, unseeded)?;
    regions.limit_sizes(&params.region_sizes)?;
    let seconds_recovery = start.elapsed().as_secs_f64();
    let (auto, split_auto);
    let spacing: &dyn Spacing = match spacing {
        Some(s) => s,
        None => {
            auto = spacing::AutoSpacing::from_boundary(&dom);
            split_auto = crate::parallel::SplitSpacing(&auto);
            &split_auto
        }
    };
    let capped;
    let spacing: &dyn Spacing = match &marker_caps {
        Some(caps) => {
            capped = MarkerCapped {
                inner: spacing,
                caps: Some(caps),
            };
            &capped
        }
        None => spacing,
    };
    let mut passes = Passes::default();
    if params.refine {
        let mut ctx = PassContext {
            plc: &plc,
            params,
            spacing,
            unseeded,
            budget: &mut budget,
        };
        passes = refine_passes(&mut dom, &mut ctx, &mut regions, progress)?;
    }
    let Passes {
        mut stop_reason,
        blocked,
        n_relabelled,
        refusals,
    } = passes;
    let seconds_refinement = start.elapsed().as_secs_f64() - seconds_recovery;
    let mesh = dom.to_mesh(&regions);
    let near_acute = |t: &[u32; 4]| {
        t.iter().any(|&v| dom.influenced_by_acute_angle(v))
            || blocked.contains(&quality::sorted4(*t))
    };
    let (mut report, bad_elsewhere) = report::measure(&mesh, spacing, params, &near_acute)?;
    report.seconds_recovery = seconds_recovery;
    report.seconds_refinement = seconds_refinement;
    report.seconds_total = start.elapsed().as_secs_f64();
    report.n_acute_angles = dom.acute_vertices.len();
    report.n_relabelled = n_relabelled;
    report.refusals = refusals;
    report.complete = stop_reason.is_none() && (bad_elsewhere == 0 || !params.refine);
    if params.refine && stop_reason.is_none() && bad_elsewhere > 0 {
        stop_reason = Some(format!(
            "{bad_elsewhere} tets away from acute input angles still violate a bound"
        ));
    }
    report.stop_reason = stop_reason;
    report.input_regions = Some(plc.input_regions());
    Ok((mesh, report))
}

/// What the refinement passes leave for the report.
#[derive(Default)]
struct Passes {
    /// Why refinement stopped early, if it did.
    stop_reason: Option<String>,
    /// Bad tets left within a small angle's influence (sorted vertex quadruples).
    blocked: FxHashSet<[u32; 4]>,
    /// Tets whose region the check after refinement corrected (`Report::n_relabelled`).
    n_relabelled: usize,
    /// Bad tets refinement left alone, per reason (`Report::refusals`).
    refusals: Refusals,
}

/// Boundary recovery (before refinement, or the check after it) ran out of splits: there is
/// no conforming mesh to report on. The budget is 4 x `max_vertices` when that is the smaller
/// one, else the safety net against a recovery that cannot terminate.
fn recovery_budget_spent(params: &Params) -> MeshError {
    let limit = recover::MAX_RECOVERY_SPLITS;
    MeshError::InvalidInput(if params.max_vertices.saturating_mul(4) < limit {
        format!(
            "boundary recovery needs more than {} splits (4 x max_vertices = {}): \
             max_vertices is too small for this input",
            params.max_vertices.saturating_mul(4),
            params.max_vertices
        )
    } else {
        format!(
            "boundary recovery did not finish within {limit} splits (an input angle too \
             small to protect in floating point?)"
        )
    })
}

/// The inputs of [`refine_passes`].
struct PassContext<'a> {
    plc: &'a crate::plc::Plc,
    params: &'a Params,
    spacing: &'a dyn Spacing,
    unseeded: Unseeded,
    budget: &'a mut usize,
}

/// Runs refinement (the bad-tet queues), then checks what it keeps incrementally: the whole
/// boundary is present and unencroached (`recover_boundary` inserts nothing) and every tet
/// carries its region (`Domain::retag_created`: the re-marking from the seeds, which updates
/// `regions`, changes no label). Should the check change something (it never has on the shared
/// models; the tests assert it), one more refinement pass looks at every tet again, and the
/// report counts the relabelled tets.
fn refine_passes(
    dom: &mut domain::Domain,
    ctx: &mut PassContext,
    regions: &mut mark::Regions,
    progress: Option<Progress>,
) -> Result<Passes, MeshError> {
    let mut out = Passes::default();
    let mut noop = |_: f64, _: usize| true;
    let progress: &mut dyn FnMut(f64, usize) -> bool = match progress {
        Some(p) => p,
        None => &mut noop,
    };
    let max_v = ctx.params.max_vertices.max(1) as f64;
    let mut on_step = |n: usize| progress((n as f64 / max_v).min(1.0), n);
    for _ in 0..2 {
        dom.created_log.clear();
        dom.boundary_inserted = false;
        let mut r = quality::Refiner::new(dom, ctx.params, ctx.spacing, regions);
        r.run(&mut on_step)?;
        out.stop_reason = r.stop_reason.take();
        out.blocked.extend(r.blocked_by_small_angle.drain());
        out.refusals.add(&r.refusals);
        let refined = dom.dt.num_vertices();
        let labels = tet_labels(dom, regions);
        if dom.recover_boundary(ctx.budget)? == Settled::BudgetSpent {
            return Err(recovery_budget_spent(ctx.params));
        }
        *regions = dom.mark_domain(ctx.plc, ctx.unseeded)?;
        regions.limit_sizes(&ctx.params.region_sizes)?;
        let relabelled = labels
            .iter()
            .zip(tet_labels(dom, regions))
            .filter(|(old, new)| **old != *new)
            .count();
        out.n_relabelled += relabelled;
        if out.stop_reason.is_some() || (dom.dt.num_vertices() == refined && relabelled == 0) {
            break;
        }
    }
    Ok(out)
}
