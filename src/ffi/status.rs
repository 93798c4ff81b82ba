//! Status codes (never renumbered: new codes get new numbers at the end) and their texts.

use crate::api::{Error, MeshError};
use std::ffi::{c_char, CStr};

/// The result of every fallible call: `SM_OK` (0) or one of the `SM_ERR_*` codes.
/// `sm_last_error()` then gives a message naming the offending input.
#[allow(non_camel_case_types)]
pub type sm_status = i32;

/// Success.
pub const SM_OK: sm_status = 0;
/// A required pointer argument (the handle, an array, a string, an output) was NULL.
pub const SM_ERR_NULL: sm_status = 1;
/// An argument was rejected: non-finite coordinate, vertex id out of range, unknown parameter
/// name, parameter value out of range, polygon with fewer than 3 vertices.
pub const SM_ERR_INVALID_ARGUMENT: sm_status = 2;
/// The domain failed validation in `sm_refine` (non-planar facet, intersecting facets, ...).
pub const SM_ERR_INVALID_INPUT: sm_status = 3;
/// The spacing function returned a value that is not finite and positive.
pub const SM_ERR_SPACING: sm_status = 4;
/// The progress callback returned non-zero.
pub const SM_ERR_CANCELLED: sm_status = 5;
/// An output buffer's capacity is smaller than the data; nothing was written.
pub const SM_ERR_BUFFER_TOO_SMALL: sm_status = 6;
/// An output was asked for before a successful `sm_refine` (or after a setter discarded it).
pub const SM_ERR_NOT_REFINED: sm_status = 7;
/// Writing a file failed (unknown extension, permissions, disk full).
pub const SM_ERR_IO: sm_status = 8;
/// A bug: the library panicked. The handle is poisoned; destroy it.
pub const SM_ERR_PANIC: sm_status = 9;
/// The handle panicked earlier and refuses further work; only `sm_last_error` and
/// `sm_destroy` still work on it.
pub const SM_ERR_POISONED: sm_status = 10;
/// A bug: an internal invariant failed (the message says which).
pub const SM_ERR_INTERNAL: sm_status = 11;
/// The handle is in use: a callback called a function on the handle that is running it.
pub const SM_ERR_BUSY: sm_status = 12;

/// Every code with its text, in numeric order (the tests check the numbering).
pub(crate) const STATUS_TEXTS: [(sm_status, &CStr); 13] = [
    (SM_OK, c"ok"),
    (SM_ERR_NULL, c"a required pointer argument is NULL"),
    (SM_ERR_INVALID_ARGUMENT, c"invalid argument"),
    (SM_ERR_INVALID_INPUT, c"invalid input domain"),
    (SM_ERR_SPACING, c"spacing value not finite and positive"),
    (SM_ERR_CANCELLED, c"cancelled by the progress callback"),
    (SM_ERR_BUFFER_TOO_SMALL, c"output buffer too small"),
    (SM_ERR_NOT_REFINED, c"no mesh: sm_refine has not succeeded"),
    (SM_ERR_IO, c"input/output error"),
    (SM_ERR_PANIC, c"internal panic: handle poisoned"),
    (SM_ERR_POISONED, c"handle poisoned by an earlier panic"),
    (SM_ERR_INTERNAL, c"internal error"),
    (SM_ERR_BUSY, c"handle busy: called from its own callback"),
];

/// A static, NUL-terminated description of a status code ("unknown status" for other values).
/// Never NULL; never freed by the caller.
#[no_mangle]
pub extern "C" fn sm_status_str(s: sm_status) -> *const c_char {
    super::guard::guard(c"unknown status".as_ptr(), || {
        STATUS_TEXTS
            .iter()
            .find(|(code, _)| *code == s)
            .map_or(c"unknown status", |(_, text)| text)
            .as_ptr()
    })
}

/// A failure on its way to C: the status and the message `sm_last_error` will return.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct FfiError {
    pub status: sm_status,
    pub message: String,
}

impl FfiError {
    pub(crate) fn new(status: sm_status, message: impl Into<String>) -> Self {
        FfiError {
            status,
            message: message.into(),
        }
    }

    /// A NULL pointer given for the argument `what`.
    pub(crate) fn null(what: &str) -> Self {
        FfiError::new(SM_ERR_NULL, format!("`{what}` is NULL"))
    }

    pub(crate) fn invalid(message: impl Into<String>) -> Self {
        FfiError::new(SM_ERR_INVALID_ARGUMENT, message)
    }
}

impl From<Error> for FfiError {
    fn from(e: Error) -> Self {
        let status = match &e {
            Error::InvalidArgument(_) => SM_ERR_INVALID_ARGUMENT,
            Error::Mesh(MeshError::InvalidInput(_)) => SM_ERR_INVALID_INPUT,
            Error::Mesh(MeshError::BadSpacing { .. }) => SM_ERR_SPACING,
            Error::Mesh(MeshError::Cancelled) => SM_ERR_CANCELLED,
            Error::Mesh(MeshError::Internal(_) | MeshError::DegenerateTet { .. }) => {
                SM_ERR_INTERNAL
            }
            Error::NotRefined => SM_ERR_NOT_REFINED,
            Error::Io(_) => SM_ERR_IO,
        };
        FfiError::new(status, e.to_string())
    }
}
