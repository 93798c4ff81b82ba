//! Pure geometry: exact predicates (the only caller of `robust`), coordinate validation,
//! constructions (circumcentres) and quality measures.

pub mod measures;
pub mod predicates;
pub mod screen;
mod wide;

pub use measures::*;
pub use predicates::*;
