//! Binary-private parts of the `slivermesh` command line.

pub mod alloc;
pub mod gen;
pub mod mesh;
pub mod quality;
pub mod rss;
pub mod tri;
