//! The parameters of a run: [`Params`] (every stage reads them), the surface mode and the
//! improvement targets' defaults.

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
    /// Improve the mesh after refinement (`improve`: flips, edge removal, smoothing).
    /// False keeps the refinement's Delaunay mesh, with only flat or inverted tets removed.
    pub improve: bool,
    /// What the input facets are: constraints kept exactly (`Keep`), or the description of a
    /// piecewise smooth surface that the output approximates (`Approximate`, `approx`).
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
    /// H + `refine::MARKER_GRADING` x max(0, d - H), d the distance to the input facets of marker ID
    /// (the smaller of it and the spacing's value; `refine::MarkerCaps`). Each H finite and > 0; an
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
