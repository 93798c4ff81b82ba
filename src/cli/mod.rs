//! Binary-private parts of the `slivermesh` command line.

pub mod alloc;
#[cfg(feature = "mpi")]
pub mod distributed;
pub mod gen;
pub mod mesh;
pub mod quality;
pub mod rss;
pub mod tri;
