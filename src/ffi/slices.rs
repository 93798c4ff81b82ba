//! Raw pointer + count to Rust slices and strings, with the NULL and overflow checks in one place.

use super::status::{FfiError, SM_ERR_BUFFER_TOO_SMALL};
use std::ffi::{c_char, CStr};

/// `n * k` elements, or an error naming `what` if that overflows.
pub(crate) fn scaled(what: &str, n: usize, k: usize) -> Result<usize, FfiError> {
    n.checked_mul(k)
        .ok_or_else(|| FfiError::invalid(format!("`{what}` count {n} is too large")))
}

/// The `len` elements at `p`. A NULL `p` is allowed only when `len` is 0.
///
/// # Safety
/// `p` is NULL or valid for reads of `len` elements of `T`, unchanged for `'a`.
pub(crate) unsafe fn input<'a, T>(
    what: &str,
    p: *const T,
    len: usize,
) -> Result<&'a [T], FfiError> {
    if len == 0 {
        return Ok(&[]);
    }
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: non-null and, by the caller's contract, valid for `len` reads for `'a`.
    Ok(unsafe { std::slice::from_raw_parts(p, len) })
}

/// The first `len` elements of a caller buffer of `capacity` elements (counts in items of
/// `per_item` values), after checking that it is large enough and not NULL. Nothing is written
/// here: the caller fills the slice only once every check has passed.
///
/// # Safety
/// `p` is NULL or valid for writes of `capacity * per_item` elements of `T`, not aliased for `'a`.
pub(crate) unsafe fn output<'a, T>(
    what: &str,
    p: *mut T,
    capacity: usize,
    count: usize,
    per_item: usize,
) -> Result<&'a mut [T], FfiError> {
    if capacity < count {
        return Err(FfiError::new(
            SM_ERR_BUFFER_TOO_SMALL,
            format!(
                "`{what}`: capacity {capacity} is smaller than the {count} items to write (nothing written)"
            ),
        ));
    }
    if count == 0 {
        return Ok(&mut []);
    }
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: non-null; `count * per_item <= capacity * per_item` elements, which the caller
    // guarantees are writable and unaliased for `'a` (the product cannot overflow: the mesh
    // holds that many values in memory).
    Ok(unsafe { std::slice::from_raw_parts_mut(p, count * per_item) })
}

/// The NUL-terminated UTF-8 string at `p`.
///
/// # Safety
/// `p` is NULL or points to a NUL-terminated string valid for `'a`.
pub(crate) unsafe fn c_str<'a>(what: &str, p: *const c_char) -> Result<&'a CStr, FfiError> {
    if p.is_null() {
        return Err(FfiError::null(what));
    }
    // SAFETY: non-null and NUL-terminated by the caller's contract.
    Ok(unsafe { CStr::from_ptr(p) })
}

/// [`c_str`] as `&str`; invalid UTF-8 is an invalid argument.
///
/// # Safety
/// As [`c_str`].
pub(crate) unsafe fn utf8<'a>(what: &str, p: *const c_char) -> Result<&'a str, FfiError> {
    // SAFETY: forwarded contract.
    let s = unsafe { c_str(what, p) }?;
    s.to_str().map_err(|_| {
        FfiError::invalid(format!(
            "`{what}` is not valid UTF-8: {}",
            s.to_string_lossy()
        ))
    })
}
