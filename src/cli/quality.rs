//! `slivermesh quality MESH`: the quality table and a histogram of any tet mesh we read, an SVG
//! picture, a side-by-side comparison with another mesh; and the same table for `mesh`.

use slivermesh::geom::TetQuality;
use slivermesh::io;
use slivermesh::mesh::TetMesh;
use slivermesh::quality::{self, MeshQuality, SvgSeries};
use std::borrow::Cow;
use std::path::{Path, PathBuf};

/// Arguments of `slivermesh quality`.
#[derive(Debug, Clone, clap::Args)]
pub struct QualityArgs {
    /// The mesh (.mesh, .vtu, .msh, or .node/.ele/.face: any of the three names the TetGen set).
    pub mesh: PathBuf,
    /// Write a histogram picture of the dihedral angles (SVG) to this file.
    #[arg(long, value_name = "FILE")]
    pub svg: Option<PathBuf>,
    /// Show a second mesh side by side (and in the picture, as an outline).
    #[arg(long, value_name = "OTHER")]
    pub compare: Option<PathBuf>,
    /// Write the figures as JSON to this file ({"mesh": ..., "other": ...} with --compare).
    #[arg(long, value_name = "FILE")]
    pub stats_json: Option<PathBuf>,
}

/// A mesh read and measured, with the name it is shown under.
struct Measured<'a> {
    name: String,
    mesh: Cow<'a, TetMesh>,
    quality: MeshQuality,
}

fn load(path: &Path) -> Result<Measured<'static>, String> {
    let mesh = io::read_mesh(path).map_err(|e| e.to_string())?;
    let quality = quality::measure(&mesh).map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(Measured {
        name: path.display().to_string(),
        mesh: Cow::Owned(mesh),
        quality,
    })
}

/// A line about invalid tets, or nothing when there are none.
fn validity_note(m: &Measured) -> String {
    let q = &m.quality;
    if q.n_inverted + q.n_zero_volume == 0 {
        return String::new();
    }
    format!(
        "note: {}: {} inverted and {} zero-volume tets (exact orient3d); FEM codes reject them\n",
        m.name, q.n_inverted, q.n_zero_volume
    )
}

/// Runs `slivermesh quality`.
pub fn run(args: &QualityArgs) -> Result<(), String> {
    let a = load(&args.mesh)?;
    let b = args.compare.as_deref().map(load).transpose()?;
    match &b {
        None => {
            println!("quality of {}\n", a.name);
            print!("{}", quality::table(&a.quality));
            println!();
            print!("{}", quality::histogram_text(&a.quality));
        }
        Some(b) => {
            print!(
                "{}",
                quality::compare_table(&a.name, &a.quality, &b.name, &b.quality)
            );
            println!();
            print!(
                "{}",
                quality::compare_histogram_text(&a.name, &a.quality, &b.name, &b.quality)
            );
        }
    }
    for m in std::iter::once(&a).chain(&b) {
        print!("{}", validity_note(m));
    }
    if let Some(path) = &args.svg {
        let mut series = vec![&a];
        series.extend(&b);
        write_svg(path, &series)?;
        println!("wrote {}", path.display());
    }
    if let Some(path) = &args.stats_json {
        let json = match &b {
            None => serde_json::to_string_pretty(&a.quality),
            Some(b) => serde_json::to_string_pretty(
                &serde_json::json!({"mesh": &a.quality, "other": &b.quality}),
            ),
        }
        .map_err(|e| e.to_string())?;
        std::fs::write(path, json).map_err(|e| format!("{}: cannot write: {e}", path.display()))?;
    }
    Ok(())
}

fn write_svg(path: &Path, meshes: &[&Measured]) -> Result<(), String> {
    let bins: Vec<Vec<usize>> = meshes
        .iter()
        .map(|m| quality::dihedral_histogram(&m.mesh).map_err(|e| format!("{}: {e}", m.name)))
        .collect::<Result<_, _>>()?;
    let series: Vec<SvgSeries> = meshes
        .iter()
        .zip(&bins)
        .map(|(m, b)| SvgSeries {
            name: &m.name,
            bins: b,
            quality: &m.quality,
        })
        .collect();
    let names: Vec<&str> = meshes.iter().map(|m| file_name(&m.name)).collect();
    let title = format!("Dihedral angles: {}", names.join(" vs "));
    std::fs::write(path, quality::svg(&title, &series))
        .map_err(|e| format!("{}: cannot write: {e}", path.display()))
}

fn file_name(path: &str) -> &str {
    Path::new(path)
        .file_name()
        .and_then(|f| f.to_str())
        .unwrap_or(path)
}

/// The `mesh` command's part: the quality table of the mesh it writes (measured on that mesh,
/// as `slivermesh quality` would), and the picture when `svg` is given.
/// `per_tet`: the tets' measures (`quality::per_tet`) when the caller has them.
pub fn report_output(
    mesh: &TetMesh,
    name: &str,
    svg: Option<&Path>,
    per_tet: Option<&[TetQuality]>,
) -> Result<(), String> {
    let measured = match per_tet {
        Some(per_tet) => quality::measure_with(mesh, per_tet),
        None => quality::measure(mesh),
    };
    let q = match measured {
        Ok(q) => q,
        Err(e) => {
            // An empty result is reported by the mesher itself; there is no table to print.
            println!("\nquality of {name}: {e}");
            return match svg {
                Some(p) => Err(format!("{}: no picture: {e}", p.display())),
                None => Ok(()),
            };
        }
    };
    println!("\nquality of {name}\n");
    print!("{}", quality::table(&q));
    let m = Measured {
        name: name.to_string(),
        mesh: Cow::Borrowed(mesh),
        quality: q,
    };
    print!("{}", validity_note(&m));
    if let Some(path) = svg {
        write_svg(path, &[&m])?;
        println!("wrote {}", path.display());
    }
    Ok(())
}
