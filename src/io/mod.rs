//! Readers and writers. No meshing logic lives here.
//!
//! STUB: signatures are fixed; the io helper fills them in.

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use std::path::Path;

pub mod points;

/// An I/O or parse failure, naming the file and (when known) the 1-based line.
#[derive(Debug, Clone, PartialEq)]
pub struct IoError {
    pub path: String,
    pub line: Option<usize>,
    pub message: String,
}

impl std::fmt::Display for IoError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self.line {
            Some(l) => write!(f, "{}:{}: {}", self.path, l, self.message),
            None => write!(f, "{}: {}", self.path, self.message),
        }
    }
}
impl std::error::Error for IoError {}

/// A per-tet scalar field written as cell data (e.g. quality measures).
#[derive(Debug, Clone, Copy)]
pub struct CellField<'a> {
    pub name: &'a str,
    pub values: &'a [f64],
}

/// Options for reading domain files.
#[derive(Debug, Clone, Copy, Default)]
pub struct ReadOptions {
    /// Merge coplanar neighbouring triangles of .off/.stl surfaces into polygon facets.
    pub merge_coplanar: bool,
}

/// Reads a domain (.poly, .smesh, .off, .stl), format chosen by extension.
pub fn read_plc(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    let _ = (path, options);
    todo!()
}

/// Writes a mesh (.vtu, .mesh, .msh, .node/.ele/.face), format chosen by extension.
pub fn write_mesh(path: &Path, mesh: &TetMesh, cell_fields: &[CellField]) -> Result<(), IoError> {
    let _ = (path, mesh, cell_fields);
    todo!()
}
