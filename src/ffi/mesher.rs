//! The `sm_mesher` handle: creation, destruction, last error, library version.

use super::callbacks::{CProgress, CSpacing};
use super::guard::guard;
use crate::api::Mesher;
use std::alloc::{alloc, Layout};
use std::cell::{Cell, RefCell};
use std::ffi::{c_char, CStr, CString};

/// An opaque mesher: a domain, parameters, a spacing, callbacks, and after `sm_refine` a mesh.
///
/// Created by `sm_create`, freed by `sm_destroy`. Handles are independent: different handles may
/// be used from different threads at the same time; one handle must not be used from two
/// threads at once. Callbacks run on the thread that calls `sm_refine` and must not call
/// functions on the handle that is running them (they get `SM_ERR_BUSY`).
#[allow(non_camel_case_types)]
pub struct sm_mesher {
    pub(crate) state: RefCell<State>,
    /// The message `sm_last_error` returns ("" after a successful call).
    pub(crate) last_error: RefCell<CString>,
    /// Set by a panic: the state may be inconsistent, so every later call is refused.
    pub(crate) poisoned: Cell<bool>,
}

/// What a handle holds besides its bookkeeping.
#[derive(Default)]
pub(crate) struct State {
    pub mesher: Mesher,
    /// A C spacing callback; when set it is used instead of the mesher's own spacing.
    pub spacing_cb: Option<CSpacing>,
    pub progress_cb: Option<CProgress>,
    /// `Report::stop_reason` of the last successful refine, for `sm_stop_reason`.
    pub stop_reason: Option<CString>,
    /// This rank's global numbers after `sm_refine_mpi`.
    #[cfg(feature = "mpi")]
    pub part_ids: Option<super::mpi::PartIds>,
}

impl sm_mesher {
    fn new() -> Self {
        sm_mesher {
            state: RefCell::new(State::default()),
            last_error: RefCell::new(CString::default()),
            poisoned: Cell::new(false),
        }
    }

    /// Replaces the last-error message (interior NULs, which C cannot see, become spaces).
    pub(crate) fn set_error(&self, message: &str) {
        let text = CString::new(message.replace('\0', " ")).unwrap_or_default();
        *self.last_error.borrow_mut() = text;
    }
}

/// Creates a handle with an empty domain, default parameters and automatic spacing.
/// Returns NULL only if memory is exhausted. Free it with `sm_destroy`.
#[no_mangle]
pub extern "C" fn sm_create() -> *mut sm_mesher {
    guard(std::ptr::null_mut(), || {
        let layout = Layout::new::<sm_mesher>();
        // SAFETY: `sm_mesher` is not zero-sized, so `layout` has a non-zero size.
        let p = unsafe { alloc(layout) }.cast::<sm_mesher>();
        if !p.is_null() {
            // SAFETY: `p` is non-null, freshly allocated for `sm_mesher`'s layout, so valid and
            // aligned for one write; `sm_destroy` frees it with `Box::from_raw`, which the
            // global allocator and `Layout::new::<sm_mesher>()` allow.
            unsafe { p.write(sm_mesher::new()) };
        }
        p
    })
}

/// Frees a handle and everything it owns (strings from `sm_last_error` and `sm_stop_reason`
/// included). NULL is a no-op. Called from a callback of the same handle it does nothing but
/// poison the handle: destroy it after `sm_refine` returns.
///
/// # Safety
/// `m` is NULL or a pointer returned by `sm_create` and not yet destroyed; it is invalid
/// afterwards.
#[no_mangle]
pub unsafe extern "C" fn sm_destroy(m: *mut sm_mesher) {
    guard((), || {
        if m.is_null() {
            return;
        }
        // SAFETY: `m` is a live handle (contract above); shared access only, to check whether
        // a caller up the stack (sm_refine) still borrows it.
        let busy = unsafe { &*m }.state.try_borrow_mut().is_err();
        if busy {
            // SAFETY: as above.
            let h = unsafe { &*m };
            h.poisoned.set(true);
            h.set_error(
                "sm_destroy: called from a callback of this handle: ignored, handle poisoned",
            );
            return;
        }
        // SAFETY: `m` came from `sm_create` (allocated for `sm_mesher` by the global allocator,
        // initialised), is not borrowed by any frame (checked above), and the caller gives up
        // ownership.
        drop(unsafe { Box::from_raw(m) });
    })
}

/// The message of the last fallible call on `m`: "" if it succeeded, otherwise what failed,
/// naming the offending input (vertex, facet, parameter, point). The string is owned by the
/// handle and valid until the next call on it. Never NULL: a NULL handle gives a static message.
///
/// # Safety
/// `m` is NULL or a live handle from `sm_create`.
#[no_mangle]
pub unsafe extern "C" fn sm_last_error(m: *const sm_mesher) -> *const c_char {
    const NULL_HANDLE: &CStr =
        c"sm_last_error: the handle is NULL (sm_create failed or was not called)";
    guard(NULL_HANDLE.as_ptr(), || {
        // SAFETY: the caller guarantees `m` is NULL or live; shared access only.
        match unsafe { m.as_ref() } {
            // The pointer stays valid after the borrow ends: the CString is only replaced by the
            // next call on the handle.
            Some(h) => h.last_error.borrow().as_ptr(),
            None => NULL_HANDLE.as_ptr(),
        }
    })
}

/// Major version of the header (the library's is in sm_version()). From 1.0 on, the ABI may
/// break only when this changes; the shared library's SONAME is libslivermesh.so.MAJOR.
pub const SM_VERSION_MAJOR: u32 = 0;
/// Minor version of the header. While MAJOR is 0 a new minor version may break the ABI, so the
/// SONAME is libslivermesh.so.0.MINOR.
pub const SM_VERSION_MINOR: u32 = 1;
/// Patch version of the header.
pub const SM_VERSION_PATCH: u32 = 0;

/// The library version ("MAJOR.MINOR.PATCH", the SM_VERSION_* of the header it was built with),
/// a static string.
#[no_mangle]
pub extern "C" fn sm_version() -> *const c_char {
    const VERSION: &CStr =
        match CStr::from_bytes_with_nul(concat!(env!("CARGO_PKG_VERSION"), "\0").as_bytes()) {
            Ok(v) => v,
            Err(_) => panic!("version has an interior NUL"),
        };
    guard(VERSION.as_ptr(), || VERSION.as_ptr())
}
