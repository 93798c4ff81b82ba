//! The collectives the distributed run is made of, with MPI's 32-bit counts checked the same
//! way on every rank (a rank that returned early alone would leave the others waiting).

use super::Error;
use mpi::collective::SystemOperation;
use mpi::datatype::PartitionMut;
use mpi::traits::*;
use mpi::Count;

/// Whether every rank succeeded: all ranks return an error when one failed (the failing ranks
/// their own, the others one naming the lowest failing rank), so they leave the collectives
/// together.
pub fn agree<C: Communicator, T>(comm: &C, local: Result<T, Error>) -> Result<T, Error> {
    let size = comm.size();
    let mine = if local.is_err() { comm.rank() } else { size };
    let mut first = size;
    comm.all_reduce_into(&mine, &mut first, SystemOperation::min());
    match local {
        Err(e) => Err(e),
        Ok(_) if first < size => Err(Error::elsewhere(first)),
        Ok(v) => Ok(v),
    }
}

/// The smallest of every rank's `x`, on every rank.
pub fn all_min<C: Communicator>(comm: &C, x: f64) -> f64 {
    let mut min = x;
    comm.all_reduce_into(&x, &mut min, SystemOperation::min());
    min
}

/// The largest of every rank's `x`, on every rank.
pub fn all_max<C: Communicator>(comm: &C, x: u32) -> u32 {
    let mut max = x;
    comm.all_reduce_into(&x, &mut max, SystemOperation::max());
    max
}

/// Every rank's `n`, on every rank.
pub fn all_counts<C: Communicator>(comm: &C, n: usize) -> Vec<u64> {
    let mut all = vec![0u64; comm.size() as usize];
    comm.all_gather_into(&(n as u64), &mut all[..]);
    all
}

/// MPI counts and displacements of `counts` (the same on every rank, so the check fails on all
/// ranks alike), or an error when the total passes MPI's 32-bit count.
fn layout(counts: &[u64], what: &str) -> Result<(Vec<Count>, Vec<Count>), Error> {
    let total: u64 = counts.iter().sum();
    if total > Count::MAX as u64 {
        return Err(Error::everywhere(format!(
            "{total} {what} over all ranks exceed MPI's 32-bit count ({})",
            Count::MAX
        )));
    }
    let mut displs = Vec::with_capacity(counts.len());
    let mut at = 0;
    for &c in counts {
        displs.push(at as Count);
        at += c;
    }
    Ok((counts.iter().map(|&c| c as Count).collect(), displs))
}

/// Offsets of each rank's items in the concatenation (one more than ranks).
fn offsets(counts: &[u64]) -> Vec<usize> {
    let mut out = vec![0];
    for &c in counts {
        out.push(out[out.len() - 1] + c as usize);
    }
    out
}

/// Every rank's data concatenated in rank order, and the offsets of each rank's share (one
/// more than ranks).
pub type Gathered<T> = (Vec<T>, Vec<usize>);

/// Every rank's `data`, concatenated in rank order on every rank, and the offsets of each
/// rank's share.
pub fn all_gather_varcount<C, T>(comm: &C, data: &[T], what: &str) -> Result<Gathered<T>, Error>
where
    C: Communicator,
    T: Equivalence + Copy + Default,
{
    let counts = all_counts(comm, data.len());
    let (c, d) = layout(&counts, what)?;
    let offs = offsets(&counts);
    let mut all = vec![T::default(); offs[offs.len() - 1]];
    {
        let mut part = PartitionMut::new(&mut all[..], c, &d[..]);
        comm.all_gather_varcount_into(data, &mut part);
    }
    Ok((all, offs))
}

/// Every rank's `data` concatenated in rank order on rank 0 (`None` elsewhere), and the
/// offsets of each rank's share.
pub fn gather_varcount<C, T>(comm: &C, data: &[T], what: &str) -> Result<Option<Gathered<T>>, Error>
where
    C: Communicator,
    T: Equivalence + Copy + Default,
{
    // Counts on every rank (not only the root), so the size check fails everywhere alike.
    let counts = all_counts(comm, data.len());
    let (c, d) = layout(&counts, what)?;
    let root = comm.process_at_rank(0);
    if comm.rank() != 0 {
        root.gather_varcount_into(data);
        return Ok(None);
    }
    let offs = offsets(&counts);
    let mut all = vec![T::default(); offs[offs.len() - 1]];
    {
        let mut part = PartitionMut::new(&mut all[..], c, &d[..]);
        root.gather_varcount_into_root(data, &mut part);
    }
    Ok(Some((all, offs)))
}

/// Every rank's `mesh`, on every rank, in rank order.
pub fn all_gather_meshes<C: Communicator>(
    comm: &C,
    mesh: &crate::mesh::TetMesh,
) -> Result<Vec<crate::mesh::TetMesh>, Error> {
    let coords: Vec<f64> = mesh.vertices.iter().flat_map(|p| p.to_array()).collect();
    let tets: Vec<u32> = mesh.tets.iter().flatten().copied().collect();
    let boundary: Vec<u32> = mesh.boundary.iter().flatten().copied().collect();
    let (coords, c_at) = all_gather_varcount(comm, &coords, "vertex coordinates")?;
    let (tets, t_at) = all_gather_varcount(comm, &tets, "tet vertex ids")?;
    let (regions, r_at) = all_gather_varcount(comm, &mesh.tet_regions, "tet regions")?;
    let (boundary, b_at) = all_gather_varcount(comm, &boundary, "boundary vertex ids")?;
    let (markers, m_at) = all_gather_varcount(comm, &mesh.boundary_markers, "boundary markers")?;
    Ok((0..comm.size() as usize)
        .map(|r| crate::mesh::TetMesh {
            vertices: coords[c_at[r]..c_at[r + 1]]
                .chunks_exact(3)
                .map(|p| glam::DVec3::new(p[0], p[1], p[2]))
                .collect(),
            tets: tets[t_at[r]..t_at[r + 1]]
                .chunks_exact(4)
                .map(|t| [t[0], t[1], t[2], t[3]])
                .collect(),
            tet_regions: regions[r_at[r]..r_at[r + 1]].to_vec(),
            boundary: boundary[b_at[r]..b_at[r + 1]]
                .chunks_exact(3)
                .map(|t| [t[0], t[1], t[2]])
                .collect(),
            boundary_markers: markers[m_at[r]..m_at[r + 1]].to_vec(),
        })
        .collect())
}
