//! `mpirun -np P slivermesh mesh IN -o OUT ...` (cargo feature `mpi`): the same command on P
//! ranks, one part of the mesh each (`slivermesh::distributed`). `-o X.pvtu` writes one piece
//! per rank beside X.pvtu; any other output is gathered on rank 0 and written there as the serial
//! command writes it. Rank 0 prints the report and each rank's tets, seconds and peak memory
//! (`--stats-json`: the key `ranks`).

use super::mesh::{finish_with, is_existing_mesh, prepare, write_stats_json, MeshOptions, Written};
use slivermesh::api::Params;
use slivermesh::distributed::{self, output, Error, RankStats};
use std::path::Path;
use std::time::Instant;

/// MPI, when this process was started by an MPI launcher (Open MPI's mpirun, MPICH's hydra,
/// a PMIx launcher such as srun); otherwise `None` and the command runs serially without
/// touching MPI (an MPI singleton start can be slow or fail where no launcher runs).
pub fn initialize() -> Option<mpi::environment::Universe> {
    let launched = ["OMPI_COMM_WORLD_SIZE", "PMI_SIZE", "PMIX_RANK"]
        .iter()
        .any(|k| std::env::var_os(k).is_some());
    if launched {
        mpi::initialize()
    } else {
        None
    }
}

/// Runs `slivermesh mesh` on every rank of `comm` (collective; `params` checked).
pub fn run_mesh<C: mpi::traits::Communicator>(
    comm: &C,
    input: &Path,
    out: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
    opts: &MeshOptions,
    params: &Params,
) -> Result<(), String> {
    let rank = comm.rank();
    run(comm, input, out, stats_json, quality_svg, opts, params).map_err(|e| {
        if e.here {
            e.message
        } else if rank == 0 {
            // A failure every rank found alike (or another rank's): printed once, by rank 0.
            e.message
        } else {
            format!("rank {rank} stopped: {}", e.message)
        }
    })
}

fn run<C: mpi::traits::Communicator>(
    comm: &C,
    input: &Path,
    out: Option<&Path>,
    stats_json: Option<&Path>,
    quality_svg: Option<&Path>,
    opts: &MeshOptions,
    params: &Params,
) -> Result<(), Error> {
    let start = Instant::now();
    let rank = comm.rank() as usize;
    // The same on every rank: every rank stops here alike.
    if is_existing_mesh(input) {
        return Err(Error::everywhere(format!(
            "{}: an existing mesh's sliver removal does not run distributed; run it without \
             mpirun",
            input.display()
        )));
    }
    if params.order != 1 {
        return Err(Error::everywhere(
            "--order 2 does not run distributed (yet); run it without mpirun",
        ));
    }
    let pvtu = out.is_some_and(output::is_pvtu);
    if rank == 0 && pvtu && quality_svg.is_some() {
        eprintln!(
            "warning: the .pvtu pieces are written without a quality picture (--quality-svg \
             applies to a gathered output)"
        );
    }
    let mesher = distributed::collect::agree(
        comm,
        prepare(input, opts, params).map_err(|e| Error::here(format!("rank {rank}: {e}"))),
    )?;
    // The run's parallel steps on `--threads` threads per rank; MPI is called from this thread.
    let part = slivermesh::parallel::with_threads(params.threads, || {
        mesher.spacing().with_spacing(|spacing| {
            distributed::mesh_on(comm, mesher.input(), mesher.params(), spacing)
        })
    })?;
    let whole = match out {
        Some(path) if pvtu => {
            output::write_pieces(comm, &part, path, opts.binary)?;
            None
        }
        Some(_) => output::gather(comm, &part)?,
        None => None,
    };
    let stats = RankStats {
        tets: part.mesh.tets.len() as u64,
        seconds: start.elapsed().as_secs_f64(),
        peak_rss_mb: super::rss::peak_rss_bytes().map_or(0.0, |b| b as f64 / 1e6),
        min_dihedral_deg: part.report.dihedral_range()[0],
        max_dihedral_deg: part.report.dihedral_range()[1],
        min_dihedral_before_move_deg: part.min_dihedral_before_move_deg,
    };
    let Some(ranks) = distributed::gather_stats(comm, stats)? else {
        return Ok(());
    };
    // Rank 0 alone from here.
    let n = &part.numbering;
    let (min_dihedral, max_dihedral) = global_dihedral_range(&ranks);
    let extra = [
        ("ranks", serde_json::to_value(&ranks).map_err(here)?),
        ("global_vertices", n.n_vertices.into()),
        ("global_tets", n.n_tets.into()),
        ("global_min_dihedral_deg", min_dihedral.into()),
        ("global_max_dihedral_deg", max_dihedral.into()),
        ("interface_passes", part.interface_passes.into()),
        ("plan_attempt", part.plan_attempt.into()),
    ];
    println!(
        "{}",
        ranks_table(&ranks, n.n_vertices, n.n_tets, part.interface_passes)
    );
    if part.plan_attempt > 0 {
        println!(
            "  (a part could not be meshed on the first partition: partition {} of {} was)\n",
            part.plan_attempt + 1,
            slivermesh::partition::PLAN_ATTEMPTS
        );
    }
    match (whole, out) {
        (Some(mesh), out) => {
            let written = Written {
                mesh: &mesh,
                quadratic: None,
                binary: opts.binary,
            };
            finish_with(written, &part.report, out, stats_json, quality_svg, &extra)
                .map_err(here)?;
        }
        (None, out) => {
            println!("{}", part.report.table());
            if let Some(path) = out {
                println!("wrote {} ({} pieces)", path.display(), part.size);
            }
            if let Some(path) = stats_json {
                let json = serde_json::to_value(&part.report).map_err(here)?;
                write_stats_json(path, json, &extra).map_err(here)?;
            }
        }
    }
    Ok(())
}

fn here(e: impl std::fmt::Display) -> Error {
    Error::here(e.to_string())
}

/// The smallest and largest dihedral angles over all ranks.
fn global_dihedral_range(ranks: &[RankStats]) -> (f64, f64) {
    ranks.iter().fold((f64::MAX, f64::MIN), |(lo, hi), s| {
        (lo.min(s.min_dihedral_deg), hi.max(s.max_dihedral_deg))
    })
}

/// Rank 0's table of the ranks: tets, seconds, peak memory, dihedral range, and the global
/// counts and dihedral range (the report below it is rank 0's part's).
fn ranks_table(ranks: &[RankStats], vertices: u64, tets: u64, passes: u32) -> String {
    let mut out = format!(
        "distributed run: {} ranks, {vertices} vertices, {tets} tets\n  rank {:>12} {:>10} {:>14} {:>16}\n",
        ranks.len(),
        "tets",
        "seconds",
        "peak RSS (MB)",
        "dihedral (deg)"
    );
    for (r, s) in ranks.iter().enumerate() {
        out.push_str(&format!(
            "  {r:>4} {:>12} {:>10.3} {:>14.1} {:>7.2} / {:>6.2}\n",
            s.tets, s.seconds, s.peak_rss_mb, s.min_dihedral_deg, s.max_dihedral_deg
        ));
    }
    let (lo, hi) = global_dihedral_range(ranks);
    let before = (ranks.iter()).fold(f64::MAX, |m, s| m.min(s.min_dihedral_before_move_deg));
    out.push_str(&format!(
        "  all ranks: dihedral min / max {lo:.2} / {hi:.2} (min {before:.2} before the interfaces \
         moved, {passes} pass{}); the report below is rank 0's part\n",
        if passes == 1 { "" } else { "es" }
    ));
    out
}
