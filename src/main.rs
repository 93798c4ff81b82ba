//! The `slivermesh` command line.
//!
//! `slivermesh` with no arguments runs the built-in demo (`cli::mesh::run_demo`);
//! `slivermesh mesh` meshes a domain file; `slivermesh quality` measures any tet mesh;
//! `slivermesh delaunay`
//! triangulates a point file; `slivermesh gen-points` writes the seeded point sets the
//! benchmarks and the CGAL comparison (ctests/) share.

#![deny(clippy::undocumented_unsafe_blocks)]

mod cli;

// mimalloc for the many small allocations, the system allocator for arrays of tens of megabytes
// (cli/alloc.rs says why). Set here only: the library uses its caller's allocator.
#[global_allocator]
static GLOBAL: cli::alloc::LargeToSystem = cli::alloc::LargeToSystem;

use clap::{Parser, Subcommand};
use cli::gen::{self, Kind};
use cli::tri;
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Parser, Debug)]
#[command(
    name = "slivermesh",
    version,
    about = "Quality, sliver-free Delaunay tetrahedral meshing",
    long_about = "Quality, sliver-free Delaunay tetrahedral meshing.\n\n\
                  Without a subcommand, runs a built-in demo."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

// `Mesh` holds every mesh option; the value is parsed once per run, so its size does not matter.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand, Debug)]
enum Command {
    /// Delaunay-tetrahedralize a point file (one `x y z` per line, `#` comments).
    Delaunay {
        /// Input point file.
        points: PathBuf,
        /// Write the mesh here (.vtu, .mesh, .msh, .node/.ele or Abaqus .inp, chosen by extension).
        #[arg(short, long, value_name = "OUT")]
        output: Option<PathBuf>,
        /// Write the run's statistics as JSON to this file.
        #[arg(long, value_name = "FILE")]
        stats_json: Option<PathBuf>,
        /// Threads for the triangulation (0: all cores). The tets are the same for any count.
        #[arg(long, value_name = "N", default_value_t = 0)]
        threads: usize,
    },
    /// Mesh a domain (.poly, .smesh, .off, .stl, .ply, .obj) with quality refinement, or remove the
    /// slivers of an existing mesh (.mesh). Output format by extension (.vtu, .mesh, .msh,
    /// .node/.ele, .inp). Surfaces (.off, .stl, .ply, .obj) are approximated by default, .poly/.smesh
    /// facets kept (--surface).
    Mesh {
        /// Input domain or existing mesh.
        input: PathBuf,
        /// Write the mesh here.
        #[arg(short, long, value_name = "OUTPUT")]
        output: Option<PathBuf>,
        #[command(flatten)]
        options: cli::mesh::MeshOptions,
        /// Write the report as JSON to this file.
        #[arg(long, value_name = "FILE")]
        stats_json: Option<PathBuf>,
        /// Write a histogram picture (SVG) of the output mesh's dihedral angles to this file.
        #[arg(long, value_name = "FILE")]
        quality_svg: Option<PathBuf>,
    },
    /// Quality of any tet mesh (.mesh, .vtu, .msh, .node/.ele), ours or another tool's: the
    /// table, a histogram of the per-tet minimum dihedral angle, --svg, --compare.
    Quality(cli::quality::QualityArgs),
    /// Write a seeded point set (the inputs of the benchmarks and the CGAL comparison).
    GenPoints {
        /// uniform (unit cube), grid (integer k^3 grid, k = round(cbrt(n))), sphere (unit
        /// sphere), clustered (gaussian blobs).
        #[arg(long, value_parser = parse_kind, default_value = "uniform")]
        kind: Kind,
        /// Number of points (grid: about n, rounded to a cube).
        #[arg(long)]
        n: usize,
        /// Random seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// Output file.
        #[arg(short, long, value_name = "FILE")]
        output: PathBuf,
    },
}

fn parse_kind(s: &str) -> Result<Kind, String> {
    Kind::from_name(s).ok_or_else(|| {
        let names: Vec<&str> = Kind::ALL.iter().map(|k| k.name()).collect();
        format!("unknown kind `{s}` (expected one of: {})", names.join(", "))
    })
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    let result = match cli.command {
        None => cli::mesh::run_demo(),
        Some(Command::Mesh {
            input,
            output,
            options,
            stats_json,
            quality_svg,
        }) => cli::mesh::run_mesh(
            &input,
            output.as_deref(),
            stats_json.as_deref(),
            quality_svg.as_deref(),
            &options,
        ),
        Some(Command::Quality(args)) => cli::quality::run(&args),
        Some(Command::Delaunay {
            points,
            output,
            stats_json,
            threads,
        }) => run_delaunay(&points, output.as_deref(), stats_json.as_deref(), threads),
        Some(Command::GenPoints {
            kind,
            n,
            seed,
            output,
        }) => run_gen_points(kind, n, seed, &output),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(msg) => {
            eprintln!("error: {msg}");
            ExitCode::from(1)
        }
    }
}

fn run_delaunay(
    points_path: &std::path::Path,
    output: Option<&std::path::Path>,
    stats_json: Option<&std::path::Path>,
    threads: usize,
) -> Result<(), String> {
    let t0 = std::time::Instant::now();
    let points = slivermesh::io::points::read_points(points_path).map_err(|e| e.to_string())?;
    let read_seconds = t0.elapsed().as_secs_f64();
    let (del, mut stats) = tri::triangulate(&points, threads)
        .map_err(|e| format!("{}: cannot triangulate: {e}", points_path.display()))?;
    stats.read_seconds = Some(read_seconds);
    print!("{}", tri::summary(&stats));
    if let Some(path) = stats_json {
        tri::write_stats_json(path, &stats)?;
    }
    if let Some(path) = output {
        tri::write(path, &points, &del)?;
        println!("wrote            {}", path.display());
    }
    Ok(())
}

fn run_gen_points(kind: Kind, n: usize, seed: u64, output: &std::path::Path) -> Result<(), String> {
    let points = gen::generate(kind, n, seed);
    let file = std::fs::File::create(output)
        .map_err(|e| format!("{}: cannot create: {e}", output.display()))?;
    let mut w = std::io::BufWriter::with_capacity(1 << 20, file);
    let werr = |e: std::io::Error| format!("{}: write failed: {e}", output.display());
    // `{}` prints the shortest decimal that round-trips, so readers get the exact doubles.
    for p in &points {
        writeln!(w, "{} {} {}", p.x, p.y, p.z).map_err(werr)?;
    }
    w.flush().map_err(werr)?;
    eprintln!(
        "wrote {} {} points (seed {seed}) to {}",
        points.len(),
        kind.name(),
        output.display()
    );
    Ok(())
}
