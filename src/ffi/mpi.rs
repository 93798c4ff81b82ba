//! Distributed meshing from inside the caller's MPI program (cargo feature `mpi`; the
//! functions exist only in a library built with it, and the header declares them when
//! `SLIVERMESH_MPI` is defined).

use super::guard::handle_call;
use super::mesher::sm_mesher;
use super::slices::output;
use super::status::*;
use crate::run::spacing::Spacing;
use mpi::traits::FromRaw;

/// This rank's share of the last `sm_refine_mpi`: global numbers.
#[derive(Debug, Clone, Default)]
pub(crate) struct PartIds {
    /// Global id of each of the part's vertices (local order).
    pub vertex_ids: Vec<u64>,
    /// Global id of the part's first tet (its tets are numbered on from there).
    pub first_tet: u64,
    pub n_vertices: u64,
    pub n_tets: u64,
}

/// Meshes the domain on every rank of the communicator `fortran_comm` (a Fortran handle: from
/// C pass `MPI_Comm_c2f(comm)`, from Fortran the communicator itself). Collective: every rank
/// of the communicator calls it with the same domain and settings; MPI must be initialized.
/// The domain is cut into one part per rank, each rank refines and improves its part with the
/// interfaces between parts as constraints, then the interfaces are moved and the zones along
/// them improved again (docs/distributed.md). Afterwards `sm_num_vertices`, `sm_get_tets`,
/// ... give this rank's part (local vertex ids from 0, its share of the boundary triangles),
/// and `sm_get_global_vertex_ids` / `sm_global_counts` its global numbering: a vertex on an
/// interface has one global id on every rank that holds it. The library communicates on a
/// duplicate of the communicator, so it never mixes with the caller's messages. A failure on
/// any rank fails the call on every rank (the others' `sm_last_error` names the failing rank).
/// A spacing callback is called on every rank; `sm_write` writes this rank's part.
///
/// # Safety
/// `m` is NULL or a live handle; registered callbacks and their `user_data` are valid.
#[cfg(feature = "mpi")] // (for cbindgen: the header guards it with SLIVERMESH_MPI)
#[no_mangle]
pub unsafe extern "C" fn sm_refine_mpi(m: *mut sm_mesher, fortran_comm: i32) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_refine_mpi", |st| {
        st.stop_reason = None;
        st.part_ids = None;
        let mut initialized = 0;
        // SAFETY: MPI_Initialized may be called at any time.
        unsafe { mpi::ffi::MPI_Initialized(&mut initialized) };
        if initialized == 0 {
            return Err(FfiError::invalid("MPI is not initialized"));
        }
        let mut dup = std::mem::MaybeUninit::uninit();
        // SAFETY: MPI is initialized; a handle that is not a communicator makes MPI report an
        // error through its error handler (by default it aborts, as MPI programs expect).
        let comm = unsafe {
            let raw = mpi::ffi::MPI_Comm_f2c(fortran_comm);
            mpi::ffi::MPI_Comm_dup(raw, dup.as_mut_ptr());
            // The duplicate is ours: freed when `comm` drops.
            mpi::topology::SimpleCommunicator::from_raw(dup.assume_init())
        };
        let mesher = &st.mesher;
        let run = |spacing: Option<&dyn Spacing>| {
            crate::distributed::mesh_on(&comm, mesher.input(), mesher.params(), spacing)
        };
        let part =
            crate::parallel::with_threads(mesher.params().threads, || match &st.spacing_cb {
                Some(c) => run(Some(c)),
                None => mesher.spacing().with_spacing(run),
            })
            .map_err(|e| FfiError::new(SM_ERR_INTERNAL, e.to_string()))?;
        st.part_ids = Some(PartIds {
            vertex_ids: part.numbering.vertex_ids.clone(),
            first_tet: part.numbering.first_tet,
            n_vertices: part.numbering.n_vertices,
            n_tets: part.numbering.n_tets,
        });
        st.mesher.install_output(part.mesh, part.report);
        Ok(())
    })
}

/// Copies the global id of each of this rank's vertices (in `sm_get_vertices`' order) into
/// `ids`, which holds `capacity` values; after `sm_refine_mpi` only (`SM_ERR_NOT_REFINED`
/// otherwise).
///
/// # Safety
/// `m` is NULL or a live handle; `ids` is NULL or points to `capacity` writable values.
#[cfg(feature = "mpi")] // (for cbindgen: the header guards it with SLIVERMESH_MPI)
#[no_mangle]
pub unsafe extern "C" fn sm_get_global_vertex_ids(
    m: *const sm_mesher,
    ids: *mut u64,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_global_vertex_ids", |st| {
        let part = st.part_ids.as_ref().ok_or_else(not_distributed)?;
        let n = part.vertex_ids.len();
        // SAFETY: `ids` is NULL or holds `capacity` values (contract above).
        let out = unsafe { output("ids", ids, capacity, n, 1) }?;
        out.copy_from_slice(&part.vertex_ids);
        Ok(())
    })
}

/// The global counts of the last `sm_refine_mpi` (vertices and tets over all ranks, each
/// once) and the global id of this rank's first tet (its tets follow in `sm_get_tets`' order).
/// Any pointer may be NULL (that value is not written).
///
/// # Safety
/// `m` is NULL or a live handle; each pointer is NULL or writable.
#[cfg(feature = "mpi")] // (for cbindgen: the header guards it with SLIVERMESH_MPI)
#[no_mangle]
pub unsafe extern "C" fn sm_global_counts(
    m: *const sm_mesher,
    n_vertices: *mut u64,
    n_tets: *mut u64,
    first_tet: *mut u64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_global_counts", |st| {
        let part = st.part_ids.as_ref().ok_or_else(not_distributed)?;
        for (p, v) in [
            (n_vertices, part.n_vertices),
            (n_tets, part.n_tets),
            (first_tet, part.first_tet),
        ] {
            // SAFETY: each pointer is NULL or writable (contract above).
            if let Some(p) = unsafe { p.as_mut() } {
                *p = v;
            }
        }
        Ok(())
    })
}

fn not_distributed() -> FfiError {
    FfiError::new(
        SM_ERR_NOT_REFINED,
        "no distributed mesh: call sm_refine_mpi first",
    )
}
