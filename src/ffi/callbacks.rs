//! C callbacks (spacing, batched spacing, progress) and their Rust wrappers.
//!
//! The wrappers hold the caller's `user_data` pointer, so they are neither `Send` nor `Sync`:
//! they live in the handle and are lent to `Mesher::refine_with` for one run on the calling
//! thread, never stored in the (`Send`) `Mesher` itself. Not being `Sync`, a spacing callback
//! is only ever called from the thread that called `sm_refine` (the run's parallel steps,
//! `crate::parallel`, cannot reach it), one call at a time; only a callback its caller declared
//! thread-safe (parameter "spacing_thread_safe" = 1) is wrapped as [`ThreadSafeCSpacing`],
//! which is `Sync`, and called from the run's threads at once.

use crate::run::spacing::Spacing;
use glam::DVec3;
use std::ffi::c_void;

/// Spacing callback: the target element size at (x, y, z), finite and > 0. Any other value
/// (0, negative, NaN, infinite) makes `sm_refine` fail with `SM_ERR_SPACING`, and
/// `sm_last_error` names the point.
#[allow(non_camel_case_types)]
pub type sm_spacing_fn =
    Option<unsafe extern "C" fn(x: f64, y: f64, z: f64, user_data: *mut c_void) -> f64>;

/// Batched spacing callback: writes the spacing at the `n` points `xyz[3*i..3*i+3]` into
/// `out[i]`. Entries left unwritten count as NaN (an error). `n` >= 1, at most 4,096 (see
/// `sm_set_spacing_batch_cb` for how the points are grouped, and which threads call it).
#[allow(non_camel_case_types)]
pub type sm_spacing_batch_fn =
    Option<unsafe extern "C" fn(n: usize, xyz: *const f64, out: *mut f64, user_data: *mut c_void)>;

/// Progress callback: fraction done (an estimate in [0, 1]) and the current vertex count.
/// Called once with fraction 0 before any work. Returning non-zero cancels `sm_refine`
/// (`SM_ERR_CANCELLED`).
#[allow(non_camel_case_types)]
pub type sm_progress_fn =
    Option<unsafe extern "C" fn(fraction: f64, n_vertices: usize, user_data: *mut c_void) -> i32>;

#[derive(Clone, Copy)]
enum SpacingKind {
    Point(unsafe extern "C" fn(f64, f64, f64, *mut c_void) -> f64),
    Batch(unsafe extern "C" fn(usize, *const f64, *mut f64, *mut c_void)),
}

/// A C spacing callback as a [`Spacing`].
#[derive(Clone, Copy)]
pub(crate) struct CSpacing {
    kind: SpacingKind,
    user_data: *mut c_void,
}

impl CSpacing {
    pub(crate) fn point(
        f: unsafe extern "C" fn(f64, f64, f64, *mut c_void) -> f64,
        user_data: *mut c_void,
    ) -> Self {
        CSpacing {
            kind: SpacingKind::Point(f),
            user_data,
        }
    }

    pub(crate) fn batch(
        f: unsafe extern "C" fn(usize, *const f64, *mut f64, *mut c_void),
        user_data: *mut c_void,
    ) -> Self {
        CSpacing {
            kind: SpacingKind::Batch(f),
            user_data,
        }
    }
}

impl Spacing for CSpacing {
    fn at(&self, p: DVec3) -> f64 {
        match self.kind {
            // SAFETY: `f` is the non-null function the caller registered for this signature;
            // `user_data` is passed back untouched, as the C contract says.
            SpacingKind::Point(f) => unsafe { f(p.x, p.y, p.z, self.user_data) },
            SpacingKind::Batch(_) => {
                let mut out = [f64::NAN];
                self.at_many(&[p], &mut out);
                out[0]
            }
        }
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        let n = points.len().min(out.len());
        match self.kind {
            SpacingKind::Point(_) => {
                for (o, &p) in out.iter_mut().zip(points) {
                    *o = self.at(p);
                }
            }
            SpacingKind::Batch(f) => {
                if n == 0 {
                    return;
                }
                let xyz: Vec<f64> = points[..n].iter().flat_map(|p| p.to_array()).collect();
                let out = &mut out[..n];
                out.fill(f64::NAN);
                // SAFETY: `f` is the registered non-null function; `xyz` holds 3n readable
                // doubles and `out` n writable ones, both alive for the call.
                unsafe { f(n, xyz.as_ptr(), out.as_mut_ptr(), self.user_data) };
            }
        }
    }
}

/// A C spacing callback whose caller declared it thread-safe (parameter
/// "spacing_thread_safe" = 1): it may be called from several threads at once.
#[derive(Clone, Copy)]
pub(crate) struct ThreadSafeCSpacing(pub(crate) CSpacing);

// SAFETY: the only state is the function pointer and `user_data`, which this crate never
// dereferences; it only passes them to the callback. The caller declared through
// "spacing_thread_safe" = 1 that the callback may be called with this `user_data` from several
// threads at the same time, which is all that sharing a `&ThreadSafeCSpacing` between threads
// allows. Without that declaration a `CSpacing` (not `Sync`) is used instead.
unsafe impl Sync for ThreadSafeCSpacing {}

impl Spacing for ThreadSafeCSpacing {
    fn at(&self, p: DVec3) -> f64 {
        self.0.at(p)
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        self.0.at_many(points, out)
    }
}

/// A C progress callback.
#[derive(Clone, Copy)]
pub(crate) struct CProgress {
    f: unsafe extern "C" fn(f64, usize, *mut c_void) -> i32,
    user_data: *mut c_void,
}

impl CProgress {
    pub(crate) fn new(
        f: unsafe extern "C" fn(f64, usize, *mut c_void) -> i32,
        user_data: *mut c_void,
    ) -> Self {
        CProgress { f, user_data }
    }

    /// Calls the callback: true = keep going.
    pub(crate) fn call(&self, fraction: f64, n_vertices: usize) -> bool {
        // SAFETY: `f` is the registered non-null function; `user_data` is passed back as given.
        unsafe { (self.f)(fraction, n_vertices, self.user_data) == 0 }
    }
}
