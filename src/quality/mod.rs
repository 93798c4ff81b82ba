//! Quality statistics of any tet mesh — ours or another tool's, valid or not — as a table, a
//! terminal histogram, an SVG picture and a side-by-side comparison of two meshes.
//!
//! Every per-tet measure is `geom`'s ([`crate::geom::TetQuality`]): rho = R/L, sigma = |V|/L³,
//! aspect = R/(3r), dihedral angles in degrees. Shape measures use |V|, so an inverted tet
//! measures like its mirror image; it is counted as inverted instead, by the sign of the exact
//! [`crate::geom::orient3d`] (zero: a zero-volume tet, which measures min 0° / max 180°,
//! rho = aspect = +∞, sigma = 0). "Below 5°" counts tets whose smallest dihedral angle is
//! < 5°; "above 160°" those whose largest is > 160°.
//!
//! - `measure` → [`MeshQuality`] (counts, extremes, percentiles, a 5° histogram of the
//!   per-tet minimum dihedral angle); `dihedral_histogram`: all six angles per tet, 1° bins;
//! - `table`, `histogram_text`, `compare_table`: the text the CLI prints;
//! - `svg`: the histogram picture with the 5/10/15/20° lines.

mod measure;
mod svg;
mod table;
#[cfg(test)]
mod tests;

pub use measure::{
    check, dihedral_histogram, measure, measure_with, per_tet, percentile, MeshQuality, ABOVE_DEG,
    BELOW_DEG, MIN_BINS, MIN_BIN_DEG,
};
pub use svg::{svg, SvgSeries};
pub use table::{compare_histogram_text, compare_table, histogram_text, rows, table};

/// Why a mesh cannot be measured.
#[derive(Debug, Clone, PartialEq)]
pub enum QualityError {
    /// A tet or boundary triangle refers to a vertex id beyond the vertex list (0-based ids).
    VertexOutOfRange {
        element: &'static str,
        index: usize,
        vertex: u32,
        n_vertices: usize,
    },
    /// A vertex coordinate is NaN or infinite.
    NotFinite { vertex: usize },
    /// The mesh has no tetrahedra (a surface mesh, or an empty file).
    NoTets,
}

impl std::fmt::Display for QualityError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            QualityError::VertexOutOfRange {
                element,
                index,
                vertex,
                n_vertices,
            } => write!(
                f,
                "{element} {index} (0-based) refers to vertex {vertex} (0-based), but the mesh \
                 has {n_vertices} vertices"
            ),
            QualityError::NotFinite { vertex } => {
                write!(f, "vertex {vertex} (0-based) has a non-finite coordinate")
            }
            QualityError::NoTets => write!(f, "the mesh has no tetrahedra"),
        }
    }
}

impl std::error::Error for QualityError {}
