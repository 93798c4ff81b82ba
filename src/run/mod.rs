//! The vocabulary of a whole meshing run, shared by every stage: the parameters
//! ([`params::Params`], the surface mode), the error ([`error::MeshError`]), the spacing
//! ([`spacing::Spacing`] and the spacings that need no mesher), the progress callback
//! ([`progress::Progress`]) and the report ([`report::Report`] and the stage reports it is made
//! of).
//!
//! It sits below every stage (`refine`, `improve`, `approx`) and above the geometry: it uses
//! only `geom`, `mesh`, `plc`, `surface` and `quadratic` (the data their reports carry), never
//! a stage or anything above one (`tests/layering.rs` checks this).

pub mod error;
pub mod params;
pub mod progress;
pub mod report;
pub mod spacing;
