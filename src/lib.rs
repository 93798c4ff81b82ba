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

#![deny(clippy::undocumented_unsafe_blocks)]

pub mod api;
pub mod approx;
pub mod cdt;
pub mod delaunay;
pub mod ffi;
pub mod geom;
pub mod improve;
pub mod io;
pub mod mesh;
pub mod pipeline;
pub mod plc;
pub mod quadratic;
pub mod quality;
pub mod refine;
pub mod run;
pub mod surface;
mod union_find;

pub use glam::DVec3;
pub use mesh::TetMesh;
