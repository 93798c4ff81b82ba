//! Running the mesher.

use super::callbacks::ThreadSafeCSpacing;
use super::guard::handle_call;
use super::mesher::sm_mesher;
use super::status::*;
use crate::parallel::SplitSpacing;
use crate::run::spacing::Spacing;
use std::ffi::CString;

/// Meshes the domain: validation, boundary recovery (the input facets as given when
/// "surface_mode" is 0, the default; a new boundary approximating the surface they describe when
/// it is 1), quality refinement (unless the "refine" parameter is 0), then the improvement pass
/// (unless "improve" is 0). On success the mesh replaces any previous one; on failure there is
/// no mesh and `sm_last_error` says why: `SM_ERR_INVALID_INPUT` (the domain, naming the facet or
/// vertex), `SM_ERR_SPACING` (a spacing value that is not finite and positive, naming the point),
/// `SM_ERR_CANCELLED` (the progress callback), `SM_ERR_INTERNAL`.
///
/// Threads: the parallel steps of the run (measuring the tets, the final validity check, the
/// batches of a spacing callback declared thread-safe) use the "threads" parameter's count
/// (0, the default: all cores); refinement and improvement run on the calling thread, and so
/// do the progress callback and a spacing callback not declared thread-safe
/// ("spacing_thread_safe" 0, the default). The mesh is the same for every thread count.
///
/// # Safety
/// `m` is NULL or a live handle; registered callbacks and their `user_data` are valid.
#[no_mangle]
pub unsafe extern "C" fn sm_refine(m: *mut sm_mesher) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_refine", |st| {
        st.stop_reason = None;
        #[cfg(feature = "mpi")]
        {
            st.part_ids = None;
        }
        // A callback declared thread-safe has its big batches split across the run's threads;
        // any other is called only from this thread (`CSpacing` is not `Sync`).
        let shared = st
            .spacing_cb
            .filter(|_| st.mesher.params().spacing_thread_safe)
            .map(ThreadSafeCSpacing);
        let split = shared.as_ref().map(|s| SplitSpacing(s));
        let spacing = match (&split, &st.spacing_cb) {
            (Some(s), _) => Some(s as &dyn Spacing),
            (None, Some(c)) => Some(c as &dyn Spacing),
            (None, None) => None,
        };
        let progress_cb = st.progress_cb;
        let mut relay = |fraction: f64, n: usize| progress_cb.is_none_or(|p| p.call(fraction, n));
        let report = st.mesher.refine_with(spacing, Some(&mut relay))?;
        st.stop_reason = report
            .stop_reason
            .as_deref()
            .map(|r| CString::new(r.replace('\0', " ")).unwrap_or_default());
        Ok(())
    })
}
