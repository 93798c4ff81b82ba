//! Global numbering of the parts' vertices and tets.
//!
//! Parts share interface vertices with bit-identical coordinates and nothing else identifies
//! them, so shared vertices are matched by their coordinate bits: every rank publishes its
//! candidates (the vertices of faces of exactly one of its tets: the part's whole surface,
//! domain boundary included, since a region-interface triangle on a part interface is listed as
//! boundary and parts may touch at an edge or a vertex only), and each shared vertex is owned
//! by the lowest rank holding it. Global vertex ids: owners number their owned vertices in
//! local order after the owned vertices of the lower ranks; global tet ids: local order after
//! the tets of the lower ranks.

use super::collect::{all_counts, all_gather_varcount};
use super::Error;
use crate::mesh::TetMesh;
use mpi::traits::*;
use rustc_hash::FxHashMap;

/// Where one part's vertices and tets are in the global mesh.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Numbering {
    /// Global id of each local vertex.
    pub vertex_ids: Vec<u64>,
    /// Global id of local tet 0 (local tet `i` is `first_tet + i`).
    pub first_tet: u64,
    /// Vertices and tets of the whole mesh.
    pub n_vertices: u64,
    pub n_tets: u64,
    /// Whether this rank owns each local vertex (it holds the global vertex's coordinates in
    /// the gathered output).
    pub owned: Vec<bool>,
    /// Per neighbour rank (ascending), the local ids of the vertices shared with it, in
    /// ascending global id (so both sides list the shared vertices in the same order).
    pub neighbours: Vec<(usize, Vec<u32>)>,
}

/// Local ids of the vertices that other parts may share, ascending: those on the part's
/// boundary triangles (the domain's boundary and region interfaces) and on its `interface`
/// triangles with other parts. Every face of one tet of a part is one or the other, so every
/// vertex a part shares (through a face, an edge or a vertex) is there; no face count of the
/// whole part is needed.
fn surface_vertices(mesh: &TetMesh, interface: &[[u32; 3]]) -> Vec<u32> {
    let mut on = vec![false; mesh.vertices.len()];
    mesh.boundary
        .iter()
        .chain(interface)
        .flatten()
        .for_each(|&v| on[v as usize] = true);
    (0..mesh.vertices.len() as u32)
        .filter(|&v| on[v as usize])
        .collect()
}

/// The exact bits of a vertex's coordinates: how parts recognize a shared vertex.
fn key(p: glam::DVec3) -> [u64; 3] {
    [p.x.to_bits(), p.y.to_bits(), p.z.to_bits()]
}

/// Numbers `mesh`, this rank's part, in the mesh of all ranks of `comm` (collective);
/// `interface` holds its triangles on the interfaces with the other parts.
pub fn number<C: Communicator>(
    comm: &C,
    mesh: &TetMesh,
    interface: &[[u32; 3]],
) -> Result<Numbering, Error> {
    let rank = comm.rank() as usize;
    let size = comm.size() as usize;
    let nv = mesh.vertices.len();
    let candidates = surface_vertices(mesh, interface);
    let mut mine: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    let mut send = Vec::with_capacity(3 * candidates.len());
    let mut duplicate = None;
    for &v in &candidates {
        let k = key(mesh.vertices[v as usize]);
        if let Some(&w) = mine.get(&k) {
            duplicate.get_or_insert((w, v));
        }
        mine.insert(k, v);
        send.extend_from_slice(&k);
    }
    let duplicate = match duplicate {
        Some((w, v)) => Err(Error::here(format!(
            "vertices {w} and {v} of rank {rank}'s part have the same coordinates"
        ))),
        None => Ok(()),
    };
    super::collect::agree(comm, duplicate)?;
    let (all, offs) = all_gather_varcount(comm, &send, "shared-vertex candidate coordinates")?;

    // Per other rank, the (local vertex, index in that rank's candidates) pairs it shares.
    let mut shared: Vec<Vec<(u32, u32)>> = vec![Vec::new(); size];
    let mut owner = vec![rank; nv];
    for (q, pairs) in shared.iter_mut().enumerate() {
        if q == rank {
            continue;
        }
        for (j, k) in all[offs[q]..offs[q + 1]].chunks_exact(3).enumerate() {
            if let Some(&v) = mine.get(&[k[0], k[1], k[2]]) {
                pairs.push((v, j as u32));
                owner[v as usize] = owner[v as usize].min(q);
            }
        }
    }
    drop(all);

    let owned: Vec<bool> = owner.iter().map(|&o| o == rank).collect();
    let n_owned = owned.iter().filter(|&&o| o).count();
    let owned_counts = all_counts(comm, n_owned);
    let first: u64 = owned_counts[..rank].iter().sum();
    let n_vertices: u64 = owned_counts.iter().sum();
    let mut vertex_ids = vec![u64::MAX; nv];
    let owned_ids = vertex_ids.iter_mut().zip(&owned).filter(|(_, &o)| o);
    for (next, (id, _)) in (first..).zip(owned_ids) {
        *id = next;
    }

    // Owners tell the others: each rank publishes the ids of its candidates that it owns, in
    // the order of its candidates, so a holder finds its id at the index it matched.
    let published: Vec<u64> = candidates.iter().map(|&v| vertex_ids[v as usize]).collect();
    let (ids, id_offs) = all_gather_varcount(comm, &published, "shared-vertex ids")?;
    for (q, pairs) in shared.iter().enumerate() {
        for &(v, j) in pairs {
            if owner[v as usize] == q {
                vertex_ids[v as usize] = ids[id_offs[q] + j as usize];
            }
        }
    }
    let unnumbered = vertex_ids.iter().position(|&id| id == u64::MAX);
    let unnumbered = match unnumbered {
        Some(v) => Err(Error::here(format!(
            "vertex {v} of rank {rank}'s part got no global id from its owner, rank {} (the \
             parts disagree on the shared vertices)",
            owner[v]
        ))),
        None => Ok(()),
    };
    super::collect::agree(comm, unnumbered)?;

    let tet_counts = all_counts(comm, mesh.tets.len());
    let first_tet = tet_counts[..rank].iter().sum();
    let n_tets = tet_counts.iter().sum();
    let neighbours = shared
        .into_iter()
        .enumerate()
        .filter(|(_, pairs)| !pairs.is_empty())
        .map(|(q, pairs)| {
            let mut local: Vec<u32> = pairs.into_iter().map(|(v, _)| v).collect();
            local.sort_unstable_by_key(|&v| vertex_ids[v as usize]);
            (q, local)
        })
        .collect();
    Ok(Numbering {
        vertex_ids,
        first_tet,
        n_vertices,
        n_tets,
        owned,
        neighbours,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shared_vertex_candidates_are_on_boundary_and_interface_triangles() {
        let mesh = TetMesh {
            vertices: vec![
                glam::DVec3::ZERO,
                glam::DVec3::X,
                glam::DVec3::Y,
                glam::DVec3::Z,
                glam::DVec3::ONE,
                glam::DVec3::splat(0.3),
            ],
            tets: vec![[0, 1, 2, 3], [1, 2, 3, 4]],
            boundary: vec![[0, 1, 2]],
            boundary_markers: vec![1],
            ..TetMesh::default()
        };
        assert_eq!(surface_vertices(&mesh, &[[1, 3, 4]]), vec![0, 1, 2, 3, 4]);
        assert_eq!(surface_vertices(&mesh, &[]), vec![0, 1, 2]);
    }
}
