//! The C ABI (`include/slivermesh.h`, generated from this module by cbindgen): the only module
//! with `unsafe`. Thin: every function checks its pointers, calls `api`, and turns the outcome
//! into an `sm_status` plus a message for `sm_last_error`.
//!
//! One module per C "class":
//! - `status`: `sm_status` codes (never renumbered) and `sm_status_str`;
//! - `mesher`: the opaque `sm_mesher` handle, `sm_create`, `sm_destroy`, `sm_last_error`,
//!   `sm_version`;
//! - `callbacks`: the callback types and their `Spacing` / progress wrappers;
//! - `input`: `sm_add_*` (the domain);
//! - `settings`: `sm_set_param`, `sm_get_param`, `sm_set_spacing_*`, `sm_set_progress_cb`;
//! - `run`: `sm_refine`;
//! - `mpi` (cargo feature `mpi`): `sm_refine_mpi`, `sm_get_global_vertex_ids`,
//!   `sm_global_counts`;
//! - `quality`: the `sm_quality` struct and `sm_get_quality`;
//! - `output`: `sm_num_*`, `sm_get_*` (copies into caller buffers), `sm_write`, `sm_stop_reason`.
//!
//! Plumbing: `guard` (the panic boundary around every exported body, NULL / poison / busy
//! checks, last-error bookkeeping) and `slices` (pointer + count to slices and strings).
//!
//! Rules kept everywhere: a panic never crosses the boundary (it becomes `SM_ERR_PANIC` and
//! poisons the handle); NULL is checked wherever a pointer is taken; outputs are written only on
//! success; a too-small capacity is an error, never a partial write.
//!
//! The header is checked in: `cargo test --lib ffi::header` fails when it is stale, and
//! `SLIVERMESH_BLESS=1 cargo test --lib ffi::header` regenerates it.

#![deny(unsafe_op_in_unsafe_fn)]
#![deny(clippy::undocumented_unsafe_blocks)]

mod callbacks;
mod guard;
mod input;
mod mesher;
#[cfg(feature = "mpi")]
mod mpi;
mod output;
mod quality;
mod run;
mod settings;
mod slices;
mod status;

pub use callbacks::{sm_progress_fn, sm_spacing_batch_fn, sm_spacing_fn};
pub use input::*;
pub use mesher::*;
#[cfg(feature = "mpi")]
pub use mpi::*;
pub use output::*;
pub use quality::*;
pub use run::*;
pub use settings::*;
pub use status::*;

#[cfg(test)]
mod header;
#[cfg(test)]
mod tests;
