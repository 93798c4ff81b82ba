//! slivermesh: quality, sliver-free Delaunay tetrahedral meshing.
//!
//! Layers, top to bottom (each knows only the ones below it):
//! `ffi` (C ABI) → `api` (safe Rust API) → `io` (file formats) → `plc` (input validation)
//! → `refine` (Li's REMOVE-SLIVER) → `delaunay` (3D kernel) → `geom` (exact predicates, measures).
//! `improve` (flips, smoothing) works on refine's output mesh.
//! `mesh` holds the output model shared by writers and meshers. See ARCHITECTURE.md.

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
pub mod parallel;
pub mod pipeline;
pub mod plc;
pub mod quadratic;
pub mod quality;
pub mod refine;
pub mod surface;
mod union_find;

pub use glam::DVec3;
pub use mesh::TetMesh;
