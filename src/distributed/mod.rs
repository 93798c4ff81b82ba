//! Distributed meshing on MPI (cargo feature `mpi`): every rank of a communicator meshes one
//! part of `crate::partition`'s plan, then the parts are numbered globally and written.
//!
//! - [`mesh_on`]: `partition::plan` (the same on every rank) and `partition::mesh_part` for
//!   this rank, the interfaces moved (the zones around them exchanged and improved again),
//!   then [`numbering::number`]: global vertex and tet ids, and the vertices shared
//!   with each neighbour rank.
//! - [`output`]: one `.vtu` piece per rank with the global ids and the `.pvtu` naming them,
//!   or the parts gathered on rank 0 into one mesh for any writer.
//! - [`gather_stats`]: each rank's tets, seconds and peak memory on rank 0.
//!
//! Every function here is collective: all ranks call it, in the same order. A failure on one
//! rank makes every rank return an error ([`collect::agree`]), so none waits forever.

pub mod collect;
pub mod numbering;
pub mod output;

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::run::params::Params;
use crate::run::report::Report;
use crate::run::spacing::Spacing;
use mpi::traits::*;
pub use numbering::Numbering;

/// A failed distributed step, on this rank (`here`) or on another one.
#[derive(Debug, Clone, PartialEq)]
pub struct Error {
    pub message: String,
    /// Whether this rank failed (else another rank did, and `message` names it).
    pub here: bool,
}

impl Error {
    /// This rank's failure.
    pub fn here(message: impl Into<String>) -> Self {
        Error {
            message: message.into(),
            here: true,
        }
    }

    /// A failure every rank finds alike (rank 0's copy is the one to print).
    pub fn everywhere(message: impl Into<String>) -> Self {
        Error {
            message: message.into(),
            here: false,
        }
    }

    /// Rank `rank` failed; this one stops with it.
    pub fn elsewhere(rank: i32) -> Self {
        Error {
            message: format!("rank {rank} failed (its error is printed by that rank)"),
            here: false,
        }
    }
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message)
    }
}

impl std::error::Error for Error {}

/// One rank's share of a distributed run.
#[derive(Debug, Clone)]
pub struct Part {
    pub rank: usize,
    /// The number of ranks (parts).
    pub size: usize,
    /// This rank's part: local vertex ids from 0, its tets and regions, the domain boundary
    /// triangles that are faces of its tets.
    pub mesh: TetMesh,
    /// The part's report (`partition::mesh_part`, measured again after the interfaces moved).
    pub report: Report,
    /// The smallest dihedral angle of the part before its interfaces moved, degrees.
    pub min_dihedral_before_move_deg: f64,
    /// How many times the interfaces were moved (the same on every rank).
    pub interface_passes: u32,
    /// Which partition the parts were meshed from (0: the first; another when a part's
    /// refinement failed, `partition::plan_attempt`).
    pub plan_attempt: u32,
    pub numbering: Numbering,
}

/// Meshes `input` on all ranks of `comm` (collective): plans the partition into one part per
/// rank, meshes this rank's part and numbers it globally.
pub fn mesh_on<C: Communicator>(
    comm: &C,
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
) -> Result<Part, Error> {
    let rank = comm.rank() as usize;
    let size = comm.size() as usize;
    let mut attempt = 0;
    let (part, part_params) = loop {
        let meshed = mesh_part(input, params, spacing, size, rank, attempt);
        // Another partition when a part's refinement failed on some rank (not when planning
        // did: every rank plans alike).
        let retry = matches!(meshed, Err((_, true))) as u32;
        if collect::all_max(comm, retry) == 1 && attempt + 1 < crate::partition::PLAN_ATTEMPTS {
            attempt += 1;
            continue;
        }
        let meshed = meshed.map_err(|(e, _)| match attempt {
            0 => Error::here(format!("rank {rank}: {e}")),
            _ => Error::here(format!(
                "rank {rank}, partition {} of {}: {e}",
                attempt + 1,
                crate::partition::PLAN_ATTEMPTS
            )),
        });
        break collect::agree(comm, meshed)?;
    };
    let mut report = part.report;
    let min_dihedral_before_move_deg = report.dihedral_range()[0];
    let (mesh, interface, interface_passes) =
        move_interfaces(comm, part.mesh, part.interface, &part_params)?;
    crate::partition::measure_part(&mut report, &mesh);
    let numbering = numbering::number(comm, &mesh, &interface)?;
    Ok(Part {
        rank,
        size,
        mesh,
        report,
        min_dihedral_before_move_deg,
        interface_passes,
        plan_attempt: attempt,
        numbering,
    })
}

/// This rank's part of the partition's `attempt`-th plan (`partition::plan_attempt`) and the
/// parameters it was meshed with, or the error and whether it came from the part's
/// refinement (after planning, which every rank does alike).
fn mesh_part(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    size: usize,
    rank: usize,
    attempt: u32,
) -> Result<(crate::partition::MeshedPart, Params), (crate::run::error::MeshError, bool)> {
    let plan = crate::partition::plan_attempt(input, params, spacing, size, attempt)
        .map_err(|e| (e, false))?;
    let params = plan.params().clone();
    // The coarse mesh and the band are dropped before the part is refined.
    let part = plan.into_part(rank).map_err(|e| (e, false))?;
    let meshed = part.mesh().map_err(|e| {
        let internal = matches!(e, crate::run::error::MeshError::Internal(_));
        (e, internal)
    })?;
    Ok((meshed, params))
}

/// This rank's part with the interfaces moved (`partition::move_interfaces`, collective),
/// its triangles on its interfaces then, and how many passes that took: every rank's zone around its interfaces and bad tets goes
/// to every rank, each improves the pieces it owns and puts them back into its part; again
/// while the worst tet of all ranks is below the improvement target and the last pass raised
/// it. (The zones are a layer of tets along the interfaces; every rank holds all of them for
/// now, see docs/distributed.md.)
fn move_interfaces<C: Communicator>(
    comm: &C,
    mut mesh: TetMesh,
    mut interface: Vec<[u32; 3]>,
    params: &Params,
) -> Result<(TetMesh, Vec<[u32; 3]>, u32), Error> {
    use crate::partition as p;
    let rank = comm.rank() as usize;
    let target = params.effective_improve_target();
    let (worst, over_rho, mut seeds) = p::bad_tets(&mesh, target, params.rho0);
    let mut worst = collect::all_min(comm, worst);
    let over_rho = collect::all_max(comm, over_rho as u32) > 0;
    let (mut passes, mut before) = (0, worst);
    while p::another_pass(passes, before, worst, target, over_rho) {
        let cut = p::cut_zone(mesh, &interface, &seeds);
        let zones = collect::all_gather_meshes(comm, &cut.zone)?;
        let share = p::share_zones(&zones).swap_remove(rank);
        drop(zones);
        let improved = p::improve_zone(share.zone, params)
            .map_err(|e| Error::here(format!("rank {rank}, moving the interfaces: {e}")));
        let (improved, _) = collect::agree(comm, improved)?;
        (mesh, interface) = p::rejoin(cut.rest, improved, &share.next_interface);
        let (mine, _, b) = p::bad_tets(&mesh, target, params.rho0);
        (passes, before, seeds) = (passes + 1, worst, b);
        worst = collect::all_min(comm, mine);
    }
    Ok((mesh, interface, passes))
}

/// What rank 0 reports of each rank.
#[derive(Debug, Clone, Copy, Default, PartialEq, serde::Serialize)]
pub struct RankStats {
    pub tets: u64,
    /// Wall time of the rank's run.
    pub seconds: f64,
    /// Peak resident memory of the rank's process, in MB (0 where unknown).
    pub peak_rss_mb: f64,
    /// The smallest and largest dihedral angles of the rank's tets, in degrees.
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// The smallest dihedral angle of the rank's part before the interfaces moved.
    pub min_dihedral_before_move_deg: f64,
}

/// Every rank's `stats` on rank 0, in rank order (`None` on the other ranks; collective).
pub fn gather_stats<C: Communicator>(
    comm: &C,
    stats: RankStats,
) -> Result<Option<Vec<RankStats>>, Error> {
    let row = [
        stats.tets as f64,
        stats.seconds,
        stats.peak_rss_mb,
        stats.min_dihedral_deg,
        stats.max_dihedral_deg,
        stats.min_dihedral_before_move_deg,
    ];
    let rows = collect::gather_varcount(comm, &row[..], "statistics")?;
    Ok(rows.map(|(rows, _)| {
        rows.chunks_exact(row.len())
            .map(|r| RankStats {
                tets: r[0] as u64,
                seconds: r[1],
                peak_rss_mb: r[2],
                min_dihedral_deg: r[3],
                max_dihedral_deg: r[4],
                min_dihedral_before_move_deg: r[5],
            })
            .collect()
    }))
}
