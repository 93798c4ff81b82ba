//! The one error type of the safe API.

use crate::io::IoError;
use crate::run::error::MeshError;

/// Why an [`super::Mesher`] call failed. Every message names the offending item (vertex index,
/// facet index, parameter name, point).
#[derive(Debug, Clone, PartialEq)]
pub enum Error {
    /// A builder argument was rejected before any meshing: a non-finite coordinate, a vertex id
    /// out of range, an unknown parameter name or an out-of-range parameter value.
    InvalidArgument(String),
    /// Meshing failed (invalid domain, bad spacing value, cancelled, internal error).
    Mesh(MeshError),
    /// An output was asked for before a successful [`super::Mesher::refine`], or after a setter
    /// discarded it.
    NotRefined,
    /// Writing the mesh failed.
    Io(IoError),
}

impl std::fmt::Display for Error {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Error::InvalidArgument(m) => write!(f, "invalid argument: {m}"),
            Error::Mesh(e) => e.fmt(f),
            Error::NotRefined => write!(
                f,
                "no mesh: refine() has not succeeded since the input or settings last changed"
            ),
            Error::Io(e) => e.fmt(f),
        }
    }
}

impl std::error::Error for Error {
    fn source(&self) -> Option<&(dyn std::error::Error + 'static)> {
        match self {
            Error::Mesh(e) => Some(e),
            Error::Io(e) => Some(e),
            _ => None,
        }
    }
}

impl From<MeshError> for Error {
    fn from(e: MeshError) -> Self {
        Error::Mesh(e)
    }
}

impl From<IoError> for Error {
    fn from(e: IoError) -> Self {
        Error::Io(e)
    }
}

/// Shorthand for `Err(Error::InvalidArgument(..))`.
pub(crate) fn invalid<T>(message: impl Into<String>) -> Result<T, Error> {
    Err(Error::InvalidArgument(message.into()))
}
