//! The panic boundary and handle access every exported function goes through.
//!
//! - [`guard`]: runs a closure under `catch_unwind`, returning a fixed value if it panics (for the
//!   functions without a handle).
//! - [`handle_call`]: NULL check, poison check, exclusive borrow of the handle's state (a
//!   callback re-entering its own handle gets `SM_ERR_BUSY`, never an aliased `&mut`),
//!   `catch_unwind`, last-error bookkeeping; a panic poisons the handle.
//! - [`handle_query`]: the same for the count queries that return a number, not a status.
//!
//! Closures rather than a macro, so rustfmt formats the bodies (the rustls-ffi advice).

use super::mesher::{sm_mesher, State};
use super::status::*;
use std::any::Any;
use std::panic::{catch_unwind, AssertUnwindSafe};

/// Runs `f`; if it panics, returns `on_panic` instead of unwinding into C.
pub(crate) fn guard<T>(on_panic: T, f: impl FnOnce() -> T) -> T {
    catch_unwind(AssertUnwindSafe(f)).unwrap_or(on_panic)
}

/// The text of a panic payload.
fn panic_text(payload: &(dyn Any + Send)) -> &str {
    if let Some(s) = payload.downcast_ref::<&str>() {
        s
    } else if let Some(s) = payload.downcast_ref::<String>() {
        s
    } else {
        "(non-string panic payload)"
    }
}

impl sm_mesher {
    /// Marks the handle unusable after a panic inside `function`.
    fn poison(&self, function: &str, payload: &(dyn Any + Send)) {
        self.poisoned.set(true);
        self.set_error(&format!(
            "{function}: internal panic: {}; this handle is poisoned: sm_destroy it and start over",
            panic_text(payload)
        ));
    }
}

fn busy(function: &str) -> FfiError {
    FfiError::new(
        SM_ERR_BUSY,
        format!(
            "{function}: the handle is running sm_refine: callbacks must not call functions on \
             the handle that calls them"
        ),
    )
}

/// Runs `f` on the state of the handle `h` and turns its outcome into a status: `SM_OK` (the last
/// error becomes ""), the error's status (its message, prefixed with `function`, becomes the last
/// error), or `SM_ERR_PANIC` (the handle is poisoned). NULL gives `SM_ERR_NULL`, a poisoned handle
/// `SM_ERR_POISONED`, a handle whose state is borrowed (re-entry from a callback) `SM_ERR_BUSY`.
///
/// The exported function makes `h` from its `m` with `m.as_ref()` (NULL gives `None`), under its
/// own contract that `m` is NULL or a live handle.
pub(crate) fn handle_call(
    h: Option<&sm_mesher>,
    function: &str,
    f: impl FnOnce(&mut State) -> Result<(), FfiError>,
) -> sm_status {
    guard(SM_ERR_PANIC, || {
        let Some(h) = h else {
            return SM_ERR_NULL;
        };
        if h.poisoned.get() {
            return SM_ERR_POISONED;
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| {
            let mut state = h.state.try_borrow_mut().map_err(|_| busy(function))?;
            f(&mut state)
        }));
        if h.poisoned.get() {
            // A callback poisoned the handle during the call (sm_destroy from inside it): keep
            // that message.
            return SM_ERR_POISONED;
        }
        match outcome {
            Ok(Ok(())) => {
                h.set_error("");
                SM_OK
            }
            Ok(Err(e)) => {
                h.set_error(&format!("{function}: {}", e.message));
                e.status
            }
            Err(payload) => {
                h.poison(function, payload.as_ref());
                SM_ERR_PANIC
            }
        }
    })
}

/// Runs the query `f` on the state of the handle `h`; `default` when `h` is NULL, poisoned or
/// busy, or when `f` panics (which poisons the handle). Leaves the last error alone.
///
/// As [`handle_call`], `h` comes from the exported function's `m.as_ref()`.
pub(crate) fn handle_query<T: Copy>(
    h: Option<&sm_mesher>,
    function: &str,
    default: T,
    f: impl FnOnce(&State) -> T,
) -> T {
    guard(default, || {
        let Some(h) = h else {
            return default;
        };
        if h.poisoned.get() {
            return default;
        }
        let outcome = catch_unwind(AssertUnwindSafe(|| match h.state.try_borrow() {
            Ok(state) => f(&state),
            Err(_) => default,
        }));
        outcome.unwrap_or_else(|payload| {
            h.poison(function, payload.as_ref());
            default
        })
    })
}
