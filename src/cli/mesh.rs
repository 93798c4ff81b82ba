//! `slivermesh mesh`: domain file in, quality mesh out, report printed; and the built-in demo.

use indicatif::{ProgressBar, ProgressStyle};
use slivermesh::api::{
    MeshOutput, Mesher, Params, QuadraticReport, Report, SurfaceMode, SurfaceReport,
};
use slivermesh::geom::TetQuality;
use slivermesh::io::{self, ReadOptions};
use slivermesh::mesh::{QuadraticNodes, TetMesh};
use slivermesh::plc::{Facet, PlcInput, Region};
use slivermesh::DVec3;
use std::io::IsTerminal;
use std::path::Path;

/// Options of `slivermesh mesh` beyond the input and output paths.
#[derive(Debug, Clone, Default, clap::Args)]
pub struct MeshOptions {
    /// Only recover the boundary (conforming Delaunay mesh, no quality refinement).
    #[arg(long)]
    pub no_refine: bool,
    /// Constant spacing H (bounds every tet's circumradius); default: automatic, graded
    /// from the input's local feature size.
    #[arg(long, value_name = "H")]
    pub size: Option<f64>,
    /// Spacing interpolated from a size field on a background mesh: MEDIT/MMG .sol (with the
    /// .mesh of the same stem beside it) or TetGen .mtr (with its .node/.ele); outside the
    /// background, the nearest tet's value. Conflicts with --size.
    #[arg(long, value_name = "FILE", conflicts_with = "size")]
    pub size_field: Option<std::path::PathBuf>,
    /// Maximum size H in the region of attribute ID (repeatable): its tets get spacing at
    /// most H, the smaller of H and the spacing (automatic, --size or --size-field) there.
    #[arg(long = "region-size", value_name = "ID:H", value_parser = parse_id_size,
          allow_hyphen_values = true)]
    pub region_size: Vec<(i32, f64)>,
    /// Maximum size H at the boundary facets of marker ID (repeatable): the spacing is at
    /// most H within a distance H of them and grows away as H + 0.5 x (distance - H), the
    /// smaller of that and the spacing (automatic, --size or --size-field).
    #[arg(long = "marker-size", value_name = "ID:H", value_parser = parse_id_size,
          allow_hyphen_values = true)]
    pub marker_size: Vec<(i32, f64)>,
    /// Radius-edge bound rho0 (default 2).
    #[arg(long, value_name = "R")]
    pub rho: Option<f64>,
    /// Sliver bound sigma0 = V / L^3 (default 0.02).
    #[arg(long, value_name = "S")]
    pub sigma: Option<f64>,
    /// Smallest dihedral angle allowed, in degrees (default 18).
    #[arg(long, value_name = "DEG")]
    pub min_dihedral: Option<f64>,
    /// Random seed (same input, parameters and seed: identical output; default 1).
    #[arg(long, value_name = "N")]
    pub seed: Option<u64>,
    /// Stop refining at this many vertices (the report then says complete: false; default
    /// 10000000).
    #[arg(long, value_name = "N")]
    pub max_vertices: Option<usize>,
    /// Reach of a small input angle's influence along its segments and facets, in
    /// protecting-ball radii (default: infinite, whole facets); 2 to 8 leave fewer bad tets
    /// next to small angles for more vertices and time.
    #[arg(long, value_name = "K")]
    pub small_angle_reach: Option<f64>,
    /// Keep .off/.stl/.ply/.obj faces as separate facets instead of merging coplanar ones.
    #[arg(long)]
    pub no_merge: bool,
    /// Keep the refinement's Delaunay mesh: no flips or smoothing afterwards (flat or
    /// inverted tets are still removed; the report says whether the output is Delaunay).
    #[arg(long)]
    pub no_improve: bool,
    /// Improvement works on tets whose smallest dihedral angle is below DEG degrees (in
    /// [0, 40]; 0 or absent: 26 in keep mode, 20 in approximate mode).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub improve_target: Option<f64>,
    /// keep: every input facet is preserved exactly; approximate: the input triangles describe
    /// a piecewise smooth surface, its sharp features are kept and the boundary is a new
    /// triangulation within --surface-distance of it. Default: approximate for .off, .stl,
    /// .ply and .obj, keep for .poly and .smesh.
    #[arg(long, value_enum, value_name = "MODE")]
    pub surface: Option<SurfaceArg>,
    /// Approximate mode: an edge whose two triangles' normals differ by more than DEG degrees
    /// is a sharp feature, kept in the output (in (0, 180); default 40).
    #[arg(long, value_name = "DEG", allow_negative_numbers = true)]
    pub feature_angle: Option<f64>,
    /// Approximate mode: how far the output boundary may lie from the input surface (absolute
    /// length; default 0.001 x the input's bounding-box diagonal).
    #[arg(long, value_name = "D", allow_negative_numbers = true)]
    pub surface_distance: Option<f64>,
    /// Approximate mode: mesh a dirty surface (holes, cracks, self-intersections, overlapping
    /// shells, flipped or duplicated triangles) as the solid where its generalized winding
    /// number is at least 1/2, instead of refusing it. The report says what was wrong.
    #[arg(long)]
    pub repair: bool,
    /// Write the binary form of the output format where it has one (.msh: gmsh 4.1 binary;
    /// .vtu: binary appended arrays); the other formats are written as usual.
    #[arg(long)]
    pub binary: bool,
    /// Element order: 1 (four-node tets) or 2 (ten-node tets; in approximate mode the boundary
    /// edges' nodes lie on the input surface, on the feature curve for feature edges; a tet
    /// that curving would fold keeps straight edges). Node order per format: docs/formats.md.
    #[arg(long, value_name = "N", default_value_t = 1, value_parser = clap::value_parser!(u8).range(1..=2))]
    pub order: u8,
    /// Threads of the run's parallel steps (measuring every tet for the report and the quality
    /// table, the final validity check, big batches of spacing values); refinement and
    /// improvement run on one. The mesh is the same for every count (default 0: all cores).
    #[arg(long, value_name = "N")]
    pub threads: Option<usize>,
}

/// `--surface`: how the input facets bound the domain (`run::params::SurfaceMode`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, clap::ValueEnum)]
pub enum SurfaceArg {
    /// Every input facet is preserved exactly.
    Keep,
    /// The input triangles describe a piecewise smooth surface that the boundary approximates.
    Approximate,
}

impl From<SurfaceArg> for SurfaceMode {
    fn from(a: SurfaceArg) -> Self {
        match a {
            SurfaceArg::Keep => SurfaceMode::Keep,
            SurfaceArg::Approximate => SurfaceMode::Approximate,
        }
    }
}

impl MeshOptions {
    /// The surface mode for `input`: `--surface` when given, else approximate for a surface
    /// file (.off/.stl/.ply/.obj) and keep for anything else (.poly/.smesh, and an existing
    /// .mesh, whose boundary is always kept).
    pub fn surface_mode(&self, input: &Path) -> SurfaceMode {
        match self.surface {
            Some(a) => a.into(),
            None if io::is_surface_file(input) => SurfaceMode::Approximate,
            None => SurfaceMode::Keep,
        }
    }

    fn params(&self, input: &Path) -> Params {
        let mut p = Params {
            refine: !self.no_refine,
            improve: !self.no_improve,
            surface_mode: self.surface_mode(input),
            repair: self.repair,
            order: self.order,
            ..Params::default()
        };
        if let Some(v) = self.feature_angle {
            p.feature_angle = v;
        }
        if let Some(v) = self.improve_target {
            p.improve_target = v;
        }
        if let Some(v) = self.surface_distance {
            p.surface_distance = v;
        }
        if let Some(v) = self.rho {
            p.rho0 = v;
        }
        if let Some(v) = self.sigma {
            p.sigma0 = v;
        }
        if let Some(v) = self.min_dihedral {
            p.min_dihedral = v;
        }
        if let Some(v) = self.seed {
            p.seed = v;
        }
        if let Some(v) = self.max_vertices {
            p.max_vertices = v;
        }
        if let Some(v) = self.small_angle_reach {
            p.small_angle_reach = v;
        }
        if let Some(v) = self.threads {
            p.threads = v;
        }
        p.region_sizes = self.region_size.clone();
        p.marker_sizes = self.marker_size.clone();
        p
    }
}

/// `ID:H` of `--region-size` and `--marker-size`: an integer id and a size, finite and > 0.
fn parse_id_size(s: &str) -> Result<(i32, f64), String> {
    let (id, h) = s
        .split_once(':')
        .ok_or_else(|| format!("\"{s}\" is not ID:H (e.g. 2:0.05)"))?;
    let id: i32 = id
        .trim()
        .parse()
        .map_err(|e| format!("ID \"{id}\" of \"{s}\" is not an integer: {e}"))?;
    let h: f64 = h
        .trim()
        .parse()
        .map_err(|e| format!("H \"{h}\" of \"{s}\" is not a number: {e}"))?;
    if !(h.is_finite() && h > 0.0) {
        return Err(format!("H = {h} of \"{s}\" must be finite and > 0"));
    }
    Ok((id, h))
}

/// Meshes `input` (.poly/.smesh/.off/.stl/.ply/.obj, or an existing .mesh whose slivers are
/// removed).
pub fn run_mesh(
    input: &Path,
    output: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
    opts: &MeshOptions,
) -> Result<(), String> {
    let params = opts.params(input);
    params.check()?;
    // Under an MPI launcher with more than one rank, the same command runs distributed; MPI is
    // finalized when `universe` drops, after the serial run of a single rank too.
    #[cfg(feature = "mpi")]
    let universe = super::distributed::initialize();
    #[cfg(feature = "mpi")]
    if let Some(universe) = &universe {
        use mpi::traits::Communicator;
        let world = universe.world();
        if world.size() > 1 {
            return super::distributed::run_mesh(
                &world,
                input,
                output,
                stats_json,
                quality_svg,
                opts,
                &params,
            );
        }
    }
    // One pool of `--threads` threads for the whole run (`pipeline::mesh` enters the same one),
    // the quality measures of the output and its writing included.
    slivermesh::parallel::with_threads(params.threads, || {
        run_mesh_with(input, output, stats_json, quality_svg, opts, &params)
    })
}

fn run_mesh_with(
    input: &Path,
    output: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
    opts: &MeshOptions,
    params: &Params,
) -> Result<(), String> {
    let mesher = prepare(input, opts, params)?;
    let MeshOutput {
        mesh,
        quadratic,
        report,
    } = mesh_with_progress(mesher)?;
    let written = Written {
        mesh: &mesh,
        quadratic: quadratic.as_ref(),
        binary: opts.binary,
    };
    finish(written, &report, output, stats_json, quality_svg)
}

/// Whether `input` is an existing mesh (.mesh) whose slivers are removed, rather than a domain.
pub fn is_existing_mesh(input: &Path) -> bool {
    input
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("mesh"))
}

/// The mesher of `slivermesh mesh`: the input read (a domain, or an existing mesh), `params`
/// and the spacing the options choose (--size, --size-field, else automatic).
pub fn prepare(input: &Path, opts: &MeshOptions, params: &Params) -> Result<Mesher, String> {
    if params.surface_mode == SurfaceMode::Keep
        && (opts.feature_angle.is_some() || opts.surface_distance.is_some())
    {
        eprintln!(
            "warning: --feature-angle and --surface-distance only apply to --surface approximate \
             (this run keeps the input facets)"
        );
    }
    if opts.size.is_some() && opts.size_field.is_some() {
        return Err("--size and --size-field cannot be used together".to_string());
    }
    let field = match &opts.size_field {
        Some(p) => Some(io::sizefield::read_size_field(p)?),
        None => None,
    };
    let mut mesher = if is_existing_mesh(input) {
        if opts.surface == Some(SurfaceArg::Approximate) {
            return Err(format!(
                "{}: --surface approximate does not apply to an existing mesh (.mesh): its \
                 boundary is kept as it is",
                input.display()
            ));
        }
        let existing = io::read_mesh(input).map_err(|e| e.to_string())?;
        let mut mesher = Mesher::new().with_params(params.clone());
        mesher
            .set_existing_mesh(existing)
            .map_err(|e| e.to_string())?;
        mesher
    } else {
        let merge = !opts.no_merge && io::is_surface_file(input);
        let plc = io::read_plc(
            input,
            &ReadOptions {
                merge_coplanar: merge,
            },
        )
        .map_err(|e| e.to_string())?;
        Mesher::from_plc(plc)
            .map_err(|e| e.to_string())?
            .with_params(params.clone())
    };
    if let Some(h) = opts.size {
        mesher.set_spacing_constant(h).map_err(|e| e.to_string())?;
    } else if let Some(f) = field {
        // Each value is a point location in the background mesh: big batches of them are
        // split across the run's threads.
        mesher.set_spacing_sync(f);
    }
    Ok(mesher)
}

/// Runs `mesher` (`api::Mesher::refine_with`: the surface mode, refinement and improvement, or
/// an existing mesh's sliver removal) with a spinner on a terminal, and takes its output.
fn mesh_with_progress(mut mesher: Mesher) -> Result<MeshOutput, String> {
    let bar = if std::io::stderr().is_terminal() {
        let b = ProgressBar::new_spinner();
        b.set_style(
            ProgressStyle::with_template("{spinner} refining: {msg} vertices, {elapsed}")
                .expect("valid template"),
        );
        Some(b)
    } else {
        None
    };
    let mut progress = |_: f64, n: usize| {
        if let Some(b) = &bar {
            b.set_message(n.to_string());
            b.tick();
        }
        true
    };
    let r = mesher.refine_with(None, Some(&mut progress)).map(|_| ());
    if let Some(b) = bar {
        b.finish_and_clear();
    }
    r.map_err(|e| e.to_string())?;
    Ok(mesher
        .take_output()
        .expect("a successful refine keeps its output"))
}

/// The output as written: the tets, their mid-edge nodes with `--order 2`, and `--binary`.
#[derive(Clone, Copy)]
pub struct Written<'a> {
    pub mesh: &'a TetMesh,
    pub quadratic: Option<&'a QuadraticNodes>,
    pub binary: bool,
}

fn finish(
    written: Written,
    report: &Report,
    output: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
) -> Result<(), String> {
    finish_with(written, report, output, stats_json, quality_svg, &[])
}

/// [`finish`], with `extra` (name, value) pairs added to the `--stats-json` object (the
/// distributed run's `ranks`).
pub fn finish_with(
    written: Written,
    report: &Report,
    output: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
    extra: &[(&str, serde_json::Value)],
) -> Result<(), String> {
    let mesh = written.mesh;
    println!("{}", report.table());
    if let Some(surface) = &report.surface {
        println!("{}", surface_table(surface));
    }
    if let Some(q) = &report.quadratic {
        println!("{}", quadratic_table(q));
    }
    // Every tet measured once when the .vtu's cell data needs the measures (the quality table
    // reuses them); otherwise the table measures as it goes, without a per-tet copy.
    let per_tet = output
        .filter(|p| has_cell_data(p))
        .and_then(|_| slivermesh::quality::per_tet(mesh).ok());
    if let Some(path) = output {
        write_with_quality(path, written, per_tet.as_deref())?;
        println!("wrote {}", path.display());
    }
    // Measured on the mesh as written, the table `slivermesh quality` prints for that file.
    let name = output.map_or("the output mesh".to_string(), |p| p.display().to_string());
    super::quality::report_output(mesh, &name, quality_svg, per_tet.as_deref())?;
    drop(per_tet);
    // Last, so that the peak covers the whole run: meshing, writing and measuring.
    let peak = super::rss::peak_rss_bytes();
    if let Some(bytes) = peak {
        println!(
            "\npeak memory: {:.1} MB, {:.0} bytes a tet",
            bytes as f64 / 1e6,
            bytes as f64 / mesh.tets.len().max(1) as f64
        );
    }
    if let Some(path) = stats_json {
        let mut json = serde_json::to_value(report).map_err(|e| e.to_string())?;
        if let (Some(bytes), Some(fields)) = (peak, json.as_object_mut()) {
            let per_tet = bytes as f64 / mesh.tets.len().max(1) as f64;
            fields.insert("peak_rss_mb".into(), (bytes as f64 / 1e6).into());
            fields.insert("bytes_per_tet".into(), per_tet.into());
        }
        write_stats_json(path, json, extra)?;
    }
    Ok(())
}

/// Writes `json` (an object) with `extra` (name, value) pairs added to `path`.
pub fn write_stats_json(
    path: &Path,
    mut json: serde_json::Value,
    extra: &[(&str, serde_json::Value)],
) -> Result<(), String> {
    if let Some(fields) = json.as_object_mut() {
        for (k, v) in extra {
            fields.insert((*k).into(), v.clone());
        }
    }
    let text = serde_json::to_string_pretty(&json).map_err(|e| e.to_string())?;
    std::fs::write(path, text).map_err(|e| format!("{}: {e}", path.display()))
}

/// Whether the output format has a place for per-tet cell data (.vtu).
fn has_cell_data(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("vtu"))
}

/// The report's "surface" section (approximate mode), in the style of `Report::table`.
fn surface_table(s: &SurfaceReport) -> String {
    let mut out = String::from("surface (approximate mode)\n");
    let mut row = |k: &str, v: String| out.push_str(&format!("  {k:<28} {v}\n"));
    row("distance bound", format!("{:.4e}", s.surface_distance));
    row(
        "hausdorff in->out / out->in",
        format!(
            "{:.4e} / {:.4e}",
            s.hausdorff_input_to_output, s.hausdorff_output_to_input
        ),
    );
    row("feature distance", format!("{:.4e}", s.feature_distance));
    row(
        "relative volume difference",
        format!("{:+.4e}", s.relative_volume_difference),
    );
    row(
        "feature edges / polylines",
        format!("{} / {}", s.n_feature_edges, s.n_feature_polylines),
    );
    row(
        "noise edges / curves",
        format!("{} / {}", s.n_noise_edges, s.n_noise_curves),
    );
    row(
        "corners / patches",
        format!("{} / {}", s.n_corners, s.n_patches),
    );
    row(
        "small corners / bad near",
        format!("{} / {}", s.n_small_corners, s.n_bad_near_small_corners),
    );
    row(
        "max rho away from them",
        format!("{:.4}", s.max_rho_away_from_small_corners),
    );
    row(
        "surface vertices / triangles",
        format!("{} / {}", s.n_surface_vertices, s.n_surface_triangles),
    );
    row("time surface (s)", format!("{:.3}", s.seconds_surface));
    if let Some(r) = &s.repair {
        row(
            "repair: duplicates / flipped",
            format!(
                "{} vertices / {} triangles",
                r.duplicate_vertices, r.flipped_triangles
            ),
        );
        row(
            "repair: open / non-manifold",
            format!("{} / {} edges", r.open_edges, r.non_manifold_edges),
        );
        row(
            "repair: intersecting pairs",
            format!("{} ({} components)", r.intersecting_pairs, r.components),
        );
        row(
            "repair: holes / hidden",
            format!("{} spanned / {} triangles", r.holes, r.hidden_triangles),
        );
        row(
            "repair: spanned area",
            format!("{:.4e} of {:.4e}", r.spanned_area, r.boundary_area),
        );
    }
    out
}

/// The report's "quadratic" section (`--order 2`).
fn quadratic_table(q: &QuadraticReport) -> String {
    format!(
        "ten-node tets (--order 2)\n  \
         mid-edge nodes                   {}\n  \
         boundary edges / curved          {} / {}\n  \
         curved edges straightened        {}\n  \
         interior nodes moved             {}\n  \
         min scaled Jacobian (corners)    {:.4}\n  \
         min Jacobian ratio (bound)       {:.4}",
        q.n_edge_nodes,
        q.n_boundary_edges,
        q.n_curved_edges,
        q.n_straightened_edges,
        q.n_moved_interior_nodes,
        q.min_scaled_jacobian,
        q.min_jacobian_ratio
    )
}

/// Writes the mesh, with per-tet quality as cell data (`api::QualityFields`)
/// when the format is .vtu: from `per_tet` (`quality::per_tet`) when given.
pub fn write_with_quality(
    path: &Path,
    written: Written,
    per_tet: Option<&[TetQuality]>,
) -> Result<(), String> {
    let Written {
        mesh,
        quadratic,
        binary,
    } = written;
    // Only .vtu has a place for cell data: measuring every tet for another format is wasted.
    if !has_cell_data(path) {
        return io::write_output(path, mesh, quadratic, &[], binary).map_err(|e| e.to_string());
    }
    let measured;
    let per_tet = match per_tet {
        Some(q) if q.len() == mesh.tets.len() => q,
        _ => {
            measured = slivermesh::quality::per_tet(mesh).map_err(|e| e.to_string())?;
            &measured
        }
    };
    let fields = slivermesh::api::QualityFields::from_measures(per_tet);
    io::write_output(path, mesh, quadratic, &fields.cell_fields(), binary)
        .map_err(|e| e.to_string())
}

/// The built-in model: a 2 x 1 x 1 box of two materials (x < 1: region 1, x > 1: region 2)
/// split by an internal facet, with a spacing graded from 0.04 at the origin corner.
pub fn demo_model() -> PlcInput {
    let mut vertices = vec![];
    for z in [0.0, 1.0] {
        for y in [0.0, 1.0] {
            for x in [0.0, 1.0, 2.0] {
                vertices.push(DVec3::new(x, y, z));
            }
        }
    }
    // id = x + 3 y + 6 z
    let quad = |ids: [u32; 4], marker| Facet {
        polygons: vec![ids.to_vec()],
        marker,
        ..Default::default()
    };
    let facets = vec![
        quad([0, 1, 4, 3], 1),
        quad([1, 2, 5, 4], 1),
        quad([6, 7, 10, 9], 1),
        quad([7, 8, 11, 10], 1),
        quad([0, 1, 7, 6], 1),
        quad([1, 2, 8, 7], 1),
        quad([3, 4, 10, 9], 1),
        quad([4, 5, 11, 10], 1),
        quad([0, 3, 9, 6], 1),
        quad([2, 5, 11, 8], 1),
        quad([1, 4, 10, 7], 2),
    ];
    PlcInput {
        vertices,
        facets,
        holes: vec![],
        regions: vec![
            Region {
                point: DVec3::new(0.5, 0.5, 0.5),
                attribute: 1,
                max_size: None,
            },
            Region {
                point: DVec3::new(1.5, 0.5, 0.5),
                attribute: 2,
                max_size: None,
            },
        ],
    }
}

/// `slivermesh` with no arguments: meshes the built-in model, writes slivermesh-demo.vtu.
pub fn run_demo() -> Result<(), String> {
    println!("slivermesh demo: two-material 2x1x1 box, spacing f = 0.02 + 0.1 |x|, rho0 = 2");
    let mut mesher = Mesher::from_plc(demo_model()).map_err(|e| e.to_string())?;
    mesher.set_spacing_fn(|p: DVec3| 0.02 + 0.1 * p.length());
    let MeshOutput { mesh, report, .. } = mesh_with_progress(mesher)?;
    let written = Written {
        mesh: &mesh,
        quadratic: None,
        binary: false,
    };
    finish(
        written,
        &report,
        Some(Path::new("slivermesh-demo.vtu")),
        None,
        None,
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use clap::Parser;

    #[derive(clap::Parser)]
    struct Opts {
        #[command(flatten)]
        mesh: MeshOptions,
    }

    fn parse(args: &[&str]) -> Result<MeshOptions, clap::Error> {
        Opts::try_parse_from(std::iter::once("mesh").chain(args.iter().copied())).map(|o| o.mesh)
    }

    /// The defaults the options' help states are the library's (`Params::default()`).
    #[test]
    fn help_states_the_library_defaults() {
        use clap::CommandFactory;
        let cmd = Opts::command();
        let d = Params::default();
        let stated = |long: &str| -> f64 {
            let arg = cmd
                .get_arguments()
                .find(|a| a.get_long() == Some(long))
                .unwrap_or_else(|| panic!("--{long}"));
            let help = arg.get_help().map(|h| h.to_string()).unwrap_or_default();
            let after = help
                .split("default ")
                .nth(1)
                .unwrap_or_else(|| panic!("--{long}: no default in {help:?}"));
            let number: String = after
                .chars()
                .take_while(|c| c.is_ascii_digit() || *c == '.')
                .collect();
            number.trim_end_matches('.').parse().unwrap()
        };
        // Each option against the library's one table of parameters.
        for (long, name) in [
            ("rho", "rho0"),
            ("sigma", "sigma0"),
            ("min-dihedral", "min_dihedral"),
            ("feature-angle", "feature_angle"),
            ("seed", "seed"),
            ("max-vertices", "max_vertices"),
            ("threads", "threads"),
        ] {
            let spec = slivermesh::api::param_table::spec(name).unwrap();
            assert_eq!(stated(long), spec.default, "--{long} vs {name}");
        }
        assert_eq!(d.order as f64, {
            let arg = cmd.get_arguments().find(|a| a.get_long() == Some("order"));
            arg.and_then(|a| a.get_default_values().first())
                .and_then(|v| v.to_str())
                .and_then(|v| v.parse::<f64>().ok())
                .expect("--order's default")
        });
    }

    #[test]
    fn surface_mode_defaults_by_file_type_and_the_flag_wins() {
        let none = parse(&[]).unwrap();
        for f in ["a.off", "a.STL", "a.ply", "a.obj"] {
            assert_eq!(
                none.surface_mode(Path::new(f)),
                SurfaceMode::Approximate,
                "{f}"
            );
        }
        for f in ["a.poly", "a.smesh", "a.mesh"] {
            assert_eq!(none.surface_mode(Path::new(f)), SurfaceMode::Keep, "{f}");
        }
        let keep = parse(&["--surface", "keep"]).unwrap();
        assert_eq!(keep.surface_mode(Path::new("a.off")), SurfaceMode::Keep);
        let approx = parse(&["--surface=approximate"]).unwrap();
        assert_eq!(
            approx.surface_mode(Path::new("a.poly")),
            SurfaceMode::Approximate
        );
        assert!(parse(&["--surface", "smooth"]).is_err());
    }

    #[test]
    fn surface_flags_reach_the_parameters() {
        let o = parse(&["--feature-angle", "30", "--surface-distance", "0.01"]).unwrap();
        let p = o.params(Path::new("a.off"));
        assert_eq!(p.surface_mode, SurfaceMode::Approximate);
        assert_eq!(p.feature_angle, 30.0);
        assert_eq!(p.surface_distance, 0.01);
        p.check().unwrap();
        let d = parse(&[]).unwrap().params(Path::new("a.off"));
        assert_eq!(d.feature_angle, Params::default().feature_angle);
        assert_eq!(d.surface_distance, 0.0);
        for (flag, value, name) in [
            ("--feature-angle", "200", "feature_angle"),
            ("--feature-angle", "0", "feature_angle"),
            ("--surface-distance", "-1", "surface_distance"),
        ] {
            let bad = parse(&[flag, value]).unwrap();
            let e = bad.params(Path::new("a.off")).check().unwrap_err();
            assert!(e.contains(name), "{e}");
        }
    }

    #[test]
    fn surface_section_lists_the_figures() {
        let t = surface_table(&SurfaceReport {
            surface_distance: 0.0017,
            n_feature_edges: 12,
            n_feature_polylines: 12,
            n_corners: 8,
            n_patches: 6,
            n_surface_triangles: 345,
            ..SurfaceReport::default()
        });
        assert!(t.starts_with("surface"), "{t}");
        for needle in [
            "distance bound",
            "1.7000e-3",
            "hausdorff",
            "feature distance",
            "relative volume difference",
            "12 / 12",
            "8 / 6",
            "/ 345",
            "time surface",
        ] {
            assert!(t.contains(needle), "{t} lacks {needle}");
        }
    }
}
