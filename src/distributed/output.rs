//! Writing a distributed mesh: one `.vtu` piece per rank and the `.pvtu` naming them, or the
//! parts gathered into one mesh on rank 0 for any of `crate::io`'s writers.

use super::collect::{agree, gather_varcount};
use super::{Error, Part};
use crate::io::vtu::{write_pvtu, write_vtu_piece, GlobalIds};
use crate::mesh::TetMesh;
use glam::DVec3;
use mpi::traits::*;
use rustc_hash::FxHashSet;
use std::path::{Path, PathBuf};

/// Whether `path` asks for pieces (`.pvtu`) rather than one gathered file.
pub fn is_pvtu(path: &Path) -> bool {
    path.extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("pvtu"))
}

/// The piece of rank `rank` of `pvtu`: `STEM_<rank>.vtu` in the `.pvtu`'s folder, and its name
/// relative to that folder (as the `.pvtu` lists it).
pub fn piece_path(pvtu: &Path, rank: usize) -> (PathBuf, String) {
    let stem = pvtu
        .file_stem()
        .map_or("mesh".into(), |s| s.to_string_lossy().into_owned());
    let name = format!("{stem}_{rank}.vtu");
    (pvtu.with_file_name(&name), name)
}

/// Writes each rank's piece and, on rank 0, the `.pvtu` at `pvtu` (collective). The pieces
/// carry the region of each tet and the global ids (`GlobalNodeId`, `GlobalCellId`); there are
/// no ghost cells. `binary`: the pieces in VTK's binary appended form (about a third of the
/// ASCII size), else ASCII.
pub fn write_pieces<C: Communicator>(
    comm: &C,
    part: &Part,
    pvtu: &Path,
    binary: bool,
) -> Result<(), Error> {
    let (path, _) = piece_path(pvtu, part.rank);
    let points: Vec<i64> = part
        .numbering
        .vertex_ids
        .iter()
        .map(|&id| id as i64)
        .collect();
    let first = part.numbering.first_tet as i64;
    let cells: Vec<i64> = (0..part.mesh.tets.len() as i64)
        .map(|i| first + i)
        .collect();
    let ids = GlobalIds {
        points: &points,
        cells: &cells,
    };
    let written = write_vtu_piece(&path, &part.mesh, ids, &[], binary)
        .map_err(|e| Error::here(e.to_string()));
    agree(comm, written)?;
    // After every piece is there, so a reader never finds the .pvtu before its pieces.
    let listed = if part.rank == 0 {
        let names: Vec<String> = (0..part.size).map(|r| piece_path(pvtu, r).1).collect();
        write_pvtu(pvtu, &names, &[]).map_err(|e| Error::here(e.to_string()))
    } else {
        Ok(())
    };
    agree(comm, listed)
}

/// The whole mesh on rank 0 (`None` on the other ranks; collective): vertices by global id,
/// tets in global tet order, boundary triangles once each (a region-interface triangle on a
/// part interface comes from both parts; the first one, by rank, is kept).
pub fn gather<C: Communicator>(comm: &C, part: &Part) -> Result<Option<TetMesh>, Error> {
    let n = &part.numbering;
    let mesh = &part.mesh;
    let too_many = n.n_vertices > u32::MAX as u64 + 1;
    if too_many {
        // Every rank knows the same count, so all return here together.
        return Err(Error::everywhere(format!(
            "{} vertices do not fit one mesh's 32-bit vertex ids",
            n.n_vertices
        )));
    }
    let gid = |v: u32| n.vertex_ids[v as usize];
    // Owned vertices only: each global vertex comes once, from its owner.
    let mut vertices = Vec::new();
    for (v, p) in mesh.vertices.iter().enumerate() {
        if n.owned[v] {
            vertices.extend_from_slice(&[
                gid(v as u32),
                p.x.to_bits(),
                p.y.to_bits(),
                p.z.to_bits(),
            ]);
        }
    }
    let tets: Vec<u64> = mesh.tets.iter().flat_map(|t| t.map(gid)).collect();
    let boundary: Vec<u64> = mesh.boundary.iter().flat_map(|t| t.map(gid)).collect();
    let vertices = gather_varcount(comm, &vertices, "vertex words")?;
    let tets = gather_varcount(comm, &tets, "tet vertex ids")?;
    let regions = gather_varcount(comm, &mesh.tet_regions, "tet regions")?;
    let boundary = gather_varcount(comm, &boundary, "boundary vertex ids")?;
    let markers = gather_varcount(comm, &mesh.boundary_markers, "boundary markers")?;
    let assembled = match (vertices, tets, regions, boundary, markers) {
        (Some(v), Some(t), Some(r), Some(b), Some(m)) => {
            assemble(n.n_vertices as usize, &v.0, &t.0, r.0, &b.0, &m.0).map(Some)
        }
        _ => Ok(None),
    };
    // Rank 0 alone can find a broken numbering: the others learn it here.
    agree(comm, assembled)
}

/// The whole mesh from the gathered arrays: (global id, x, y, z bits) per vertex, 4 global ids
/// per tet, 3 per boundary triangle.
fn assemble(
    n_vertices: usize,
    vertices: &[u64],
    tets: &[u64],
    tet_regions: Vec<i32>,
    boundary: &[u64],
    markers: &[i32],
) -> Result<TetMesh, Error> {
    let mut whole = TetMesh {
        vertices: vec![DVec3::NAN; n_vertices],
        tets: tets
            .chunks_exact(4)
            .map(|t| [t[0] as u32, t[1] as u32, t[2] as u32, t[3] as u32])
            .collect(),
        tet_regions,
        ..TetMesh::default()
    };
    let mut filled = vec![false; n_vertices];
    for w in vertices.chunks_exact(4) {
        let id = w[0] as usize;
        whole.vertices[id] = DVec3::new(
            f64::from_bits(w[1]),
            f64::from_bits(w[2]),
            f64::from_bits(w[3]),
        );
        filled[id] = true;
    }
    if let Some(id) = filled.iter().position(|&f| !f) {
        return Err(Error::here(format!(
            "global vertex {id} came from no rank (the numbering is broken)"
        )));
    }
    let mut seen = FxHashSet::default();
    for (t, &m) in boundary.chunks_exact(3).zip(markers) {
        let tri = [t[0] as u32, t[1] as u32, t[2] as u32];
        let mut key = tri;
        key.sort_unstable();
        if seen.insert(key) {
            whole.boundary.push(tri);
            whole.boundary_markers.push(m);
        }
    }
    Ok(whole)
}
