//! [`MeshError`]: why a run failed, whichever stage failed it.

use glam::DVec3;

/// Why meshing failed.
#[derive(Debug, Clone, PartialEq)]
pub enum MeshError {
    /// The input failed validation; the message names the offending item.
    InvalidInput(String),
    /// The spacing function returned a value that is not finite and positive.
    BadSpacing { point: DVec3, value: f64 },
    /// The progress callback asked to stop.
    Cancelled,
    /// A bug: an internal invariant failed.
    Internal(String),
    /// A tet of the result is flat or inverted (exact orientation <= 0) and could not be
    /// removed: the mesh is not returned.
    DegenerateTet {
        /// Its index in the output's tets.
        index: usize,
        vertices: [u32; 4],
        points: Box<[DVec3; 4]>,
        inverted: bool,
    },
}

impl std::fmt::Display for MeshError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            MeshError::InvalidInput(m) => write!(f, "invalid input: {m}"),
            MeshError::BadSpacing { point, value } => write!(
                f,
                "spacing function returned {value} at ({}, {}, {}): it must be finite and positive",
                point.x, point.y, point.z
            ),
            MeshError::Cancelled => write!(f, "cancelled by the progress callback"),
            MeshError::Internal(m) => write!(f, "internal error: {m}"),
            MeshError::DegenerateTet {
                index,
                vertices,
                points,
                inverted,
            } => {
                write!(
                    f,
                    "output tet {index} (vertices {vertices:?}, 0-based) is {}; no flip or \
                     move removed it, so the mesh is not written. Its corners:",
                    if *inverted {
                        "inverted"
                    } else {
                        "flat (zero volume)"
                    }
                )?;
                for p in points.iter() {
                    write!(f, " ({}, {}, {})", p.x, p.y, p.z)?;
                }
                Ok(())
            }
        }
    }
}
impl std::error::Error for MeshError {}
