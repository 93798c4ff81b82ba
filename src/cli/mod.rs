//! Binary-private parts of the `slivermesh` command line.

pub mod gen;
pub mod rss;
pub mod tri;
