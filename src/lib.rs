//! slivermesh: quality, sliver-free Delaunay tetrahedral meshing.
//!
//! Layers, top to bottom (each knows only the ones below it):
//! `ffi` (C ABI) → `api` (safe Rust API) → `pipeline` (the whole run: stages composed, their
//! reports put together) → `approx` (approximate surface mode) → `refine` (Li's REMOVE-SLIVER)
//! and `improve` (flips, smoothing; neither names the other) → `run` (the run's vocabulary:
//! parameters, error, spacing, progress, report) → `plc` (input validation), `surface`, `cdt`
//! → `delaunay` (3D kernel) → `geom` (exact predicates, measures).
//! `io` (file formats) reads and writes for `api`; `mesh` holds the output model shared by
//! writers and meshers. `tests/layering.rs` checks the imports of `run`, `refine` and
//! `improve`. See ARCHITECTURE.md.
//!
//! The documented Rust API is [`api`] and the types it names, which it re-exports; the other
//! public modules are `#[doc(hidden)]` internals (for the `slivermesh` binary, the integration
//! tests, the examples and the benchmarks), and `approx`, `quadratic` and `union_find` are
//! private.

#![deny(clippy::undocumented_unsafe_blocks)]

pub mod api;

// Internals: not part of the documented Rust API (that is `api` and the types it names, which
// it re-exports). Public only for the `slivermesh` binary, the integration tests, the examples
// and the benchmarks; `ffi` is the C ABI (include/slivermesh.h).
#[doc(hidden)]
pub mod cdt;
#[doc(hidden)]
pub mod delaunay;
// Distributed meshing on MPI (cargo feature `mpi`): every rank meshes one part of
// `partition`'s plan; global numbering, output and the per-rank report.
#[cfg(feature = "mpi")]
#[doc(hidden)]
pub mod distributed;
#[doc(hidden)]
pub mod ffi;
#[doc(hidden)]
pub mod geom;
#[doc(hidden)]
pub mod improve;
#[doc(hidden)]
pub mod io;
#[doc(hidden)]
pub mod mesh;
#[doc(hidden)]
pub mod parallel;
#[doc(hidden)]
pub mod partition;
#[doc(hidden)]
pub mod pipeline;
#[doc(hidden)]
pub mod plc;
#[doc(hidden)]
pub mod quality;
#[doc(hidden)]
pub mod refine;
#[doc(hidden)]
pub mod run;
#[doc(hidden)]
pub mod surface;

mod approx;
mod quadratic;
mod union_find;

pub use glam::DVec3;
pub use mesh::TetMesh;
