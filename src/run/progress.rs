//! The progress callback a run calls while it refines.

/// Progress callback: (fraction done estimate in [0, 1], current vertex count) -> keep going?
pub type Progress<'a> = &'a mut dyn FnMut(f64, usize) -> bool;
