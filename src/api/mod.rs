//! The safe Rust API: what Rust users, the CLI and the C ABI (`ffi`) call.
//!
//! - [`Mesher`] (`mesher.rs`): builder for a domain, parameters, spacing and progress; runs
//!   `pipeline::mesh` (the surface mode, refinement, improvement) and keeps the result.
//! - [`params`]: parameters set and read by name, with range checks that give a reason.
//! - [`SpacingChoice`] (`spacing.rs`): automatic, constant or user spacing, and the guard that
//!   turns any spacing value that is not finite and positive into an error naming the point.
//! - [`MeshOutput`], [`QualityFields`] (`output.rs`): the result and its writing with per-tet
//!   quality as cell data.
//! - [`Error`] (`error.rs`): the one error type.
//! - [`read_plc`] and [`read_mesh`]: the input files the CLI reads (a domain for
//!   [`Mesher::from_plc`], an existing mesh for [`Mesher::set_existing_mesh`]).
//!
//! This module and the types it names (re-exported here) are the crate's documented Rust API;
//! the other modules are internals.
//!
//! No `unsafe` here: the C ABI's raw pointers stay in `ffi`.

#![deny(unsafe_code)]

mod error;
mod mesher;
mod output;
pub mod param_table;
pub mod params;
mod spacing;

pub use error::Error;
pub use mesher::{Mesher, ProgressFn};
pub use output::{MeshOutput, QualityFields};
pub use params::{Params, SurfaceMode, PARAM_NAMES};
pub use spacing::SpacingChoice;

pub use crate::geom::TetQuality;
pub use crate::io::{read_mesh, read_plc, IoError, ReadOptions};
pub use crate::mesh::{QuadraticNodes, TetMesh};
pub use crate::plc::{Facet, InputRegions, PlcInput, Region};
pub use crate::quadratic::QuadraticReport;
pub use crate::run::error::MeshError;
pub use crate::run::progress::Progress;
pub use crate::run::report::{ImproveStats, Refusals, RegionReport, Report, SurfaceReport};
pub use crate::run::spacing::{ConstantSpacing, FnSpacing, MinSpacing, Spacing};
pub use crate::surface::repair::Defects;

#[cfg(test)]
mod tests;
