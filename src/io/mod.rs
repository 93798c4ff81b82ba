//! Readers and writers. No meshing logic lives here.
//!
//! One module per format, each documenting the subset it supports:
//!
//! | format | read | write | module |
//! |---|---|---|---|
//! | TetGen `.poly`, `.smesh` (+ `.node`) | domain ([`PlcInput`]) | | [`poly`] |
//! | `.off` | domain | | [`off`] |
//! | `.stl` (ASCII, binary) | domain | | [`stl`] |
//! | `.ply` (ASCII, binary either endian) | domain | | [`ply`] |
//! | Wavefront `.obj` | domain | | [`obj`] |
//! | medit `.mesh` | mesh ([`TetMesh`]) | mesh | [`medit`] |
//! | VTK `.vtu` | mesh + cell fields | mesh + cell fields | [`vtu`] |
//! | gmsh `.msh` 4.1 (read: also 2.x) | mesh | mesh | [`gmsh`] |
//! | TetGen `.node`/`.ele`/`.face` | mesh | mesh | [`tetgen`] |
//!
//! Every mesh writer also writes ten-node tets ([`write_output`] with
//! [`QuadraticNodes`]): the element names and node order of each format are in
//! docs/formats.md.
//!
//! [`read_plc`], [`read_mesh`] and [`write_mesh`] choose the format by extension
//! (case-insensitive). Errors are [`IoError`]s naming the file and, for text formats, the
//! 1-based line. Floats are written in shortest round-trip form, so a written mesh reads back
//! bit for bit. Marker conventions: a `.poly`/`.smesh` facet without a marker gets 1; `.off`,
//! `.stl`, `.ply` and `.obj` facets get their 1-based facet index (after the optional coplanar merge); mesh
//! readers use 0 for a missing region or marker.

use crate::mesh::{QuadraticNodes, TetMesh};
use crate::plc::PlcInput;
use std::path::Path;

pub use crate::plc::coplanar;
pub mod abaqus;
mod elements;
pub mod gmsh;
pub mod gmsh_binary;
pub mod medit;
pub mod obj;
pub mod off;
pub mod ply;
pub mod points;
pub mod poly;
pub mod sizefield;
mod solids;
pub mod stl;
pub mod tetgen;
mod text;
pub mod vtu;
pub mod vtu_binary;
pub mod xdmf;

#[cfg(test)]
pub(crate) mod tests;

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
    /// Merge coplanar neighbouring faces of surface formats ([`SURFACE_EXTENSIONS`]) into
    /// polygon facets.
    pub merge_coplanar: bool,
}

/// Extensions accepted by [`read_plc`].
pub const PLC_EXTENSIONS: &[&str] = &["poly", "smesh", "off", "stl", "ply", "obj"];
/// The [`PLC_EXTENSIONS`] that hold bare surfaces (one facet per face, no markers), whose
/// coplanar faces are usually merged.
pub const SURFACE_EXTENSIONS: &[&str] = &["off", "stl", "ply", "obj"];

/// True if `path` has one of the [`SURFACE_EXTENSIONS`] (case-insensitive).
pub fn is_surface_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| SURFACE_EXTENSIONS.iter().any(|s| e.eq_ignore_ascii_case(s)))
}
/// Extensions accepted by [`write_mesh`] and [`read_mesh`].
pub const MESH_EXTENSIONS: &[&str] = &["vtu", "mesh", "msh", "node", "ele", "face"];

/// Extensions accepted by [`write_mesh`]: [`MESH_EXTENSIONS`] and Abaqus `.inp` (written only).
pub const WRITE_EXTENSIONS: &[&str] = &["vtu", "mesh", "msh", "node", "ele", "face", "inp", "xdmf"];

/// The lower-cased extension of `path`, or an error listing the supported ones.
fn extension(path: &Path, supported: &[&str], what: &str) -> Result<String, IoError> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .map(|e| e.to_ascii_lowercase())
        .unwrap_or_default();
    if supported.contains(&ext.as_str()) {
        return Ok(ext);
    }
    let list = supported
        .iter()
        .map(|e| format!(".{e}"))
        .collect::<Vec<_>>()
        .join(", ");
    let found = if ext.is_empty() {
        "no extension".to_string()
    } else {
        format!("extension '.{ext}'")
    };
    Err(IoError {
        path: path.display().to_string(),
        line: None,
        message: format!("unsupported {what} format ({found}); supported: {list}"),
    })
}

/// Reads a domain (.poly, .smesh, .off, .stl, .ply, .obj), format chosen by extension.
pub fn read_plc(path: &Path, options: &ReadOptions) -> Result<PlcInput, IoError> {
    match extension(path, PLC_EXTENSIONS, "domain")?.as_str() {
        "poly" => poly::read_poly(path),
        "smesh" => poly::read_smesh(path),
        "off" => off::read_off(path, options),
        "ply" => ply::read_ply(path, options),
        "obj" => obj::read_obj(path, options),
        _ => stl::read_stl(path, options),
    }
}

/// Writes a mesh (.vtu, .mesh, .msh, .node/.ele/.face, .inp), format chosen by extension.
///
/// `cell_fields` are written as cell data by `.vtu` only; the other formats have no place for
/// them and ignore them (their lengths are still checked). A TetGen extension writes all three
/// of `X.node`, `X.ele` and `X.face`.
pub fn write_mesh(path: &Path, mesh: &TetMesh, cell_fields: &[CellField]) -> Result<(), IoError> {
    let ext = extension(path, WRITE_EXTENSIONS, "mesh")?;
    let lens: Vec<(&str, usize)> = cell_fields
        .iter()
        .map(|f| (f.name, f.values.len()))
        .collect();
    text::check_mesh(mesh, &lens).map_err(|e| text::with_path(e, path))?;
    match ext.as_str() {
        "vtu" => vtu::write_vtu(path, mesh, cell_fields),
        "mesh" => medit::write_medit(path, mesh),
        "msh" => gmsh::write_msh(path, mesh),
        "inp" => abaqus::write_inp(path, mesh),
        "xdmf" => xdmf::write_xdmf(path, mesh, None),
        _ => tetgen::write_tetgen(path, mesh),
    }
}

/// [`write_mesh`], or where the format has a binary form (.msh: gmsh 4.1 binary, .vtu: binary
/// appended arrays) and `binary` is set, that form.
pub fn write_mesh_in(
    path: &Path,
    mesh: &TetMesh,
    cell_fields: &[CellField],
    binary: bool,
) -> Result<(), IoError> {
    match extension(path, WRITE_EXTENSIONS, "mesh")?.as_str() {
        "vtu" if binary => vtu_binary::write_vtu_binary(path, mesh, cell_fields),
        "msh" if binary => gmsh_binary::write_msh_binary(path, mesh),
        _ => write_mesh(path, mesh, cell_fields),
    }
}

/// [`write_mesh_in`] for a mesh of ten-node tets when `quadratic` is given (`--order 2`),
/// else of four-node tets. Node order per format: docs/formats.md.
///
/// With `quadratic`: gmsh `.msh` (ASCII or, with `binary`, binary) of 10-node tets (type 11)
/// and 6-node triangles (type 9); `.vtu` (ASCII or binary appended) of `VTK_QUADRATIC_TETRA`;
/// medit `.mesh` with `TetrahedraP2` and `TrianglesP2`; Abaqus `.inp` of C3D10; TetGen
/// `.node/.ele/.face` as `tetgen -o2` writes them. Every format lists the corners first, then
/// the mid-edge nodes (node `mesh.vertices.len() + k` is `quadratic.points[k]`); regions and
/// boundary markers go where the four-node writers put them. A `quadratic` that does not fit
/// `mesh` (list counts, node ids) is an error naming the mismatch.
pub fn write_output(
    path: &Path,
    mesh: &TetMesh,
    quadratic: Option<&QuadraticNodes>,
    cell_fields: &[CellField],
    binary: bool,
) -> Result<(), IoError> {
    let Some(q) = quadratic else {
        return write_mesh_in(path, mesh, cell_fields, binary);
    };
    let ext = extension(path, WRITE_EXTENSIONS, "mesh")?;
    let lens: Vec<(&str, usize)> = cell_fields
        .iter()
        .map(|f| (f.name, f.values.len()))
        .collect();
    text::check_mesh(mesh, &lens).map_err(|e| text::with_path(e, path))?;
    text::check_quadratic(mesh, q).map_err(|e| text::with_path(e, path))?;
    match ext.as_str() {
        "vtu" if binary => vtu_binary::write_vtu_binary_quadratic(path, mesh, q, cell_fields),
        "vtu" => vtu::write_vtu_quadratic(path, mesh, q, cell_fields),
        "msh" if binary => gmsh_binary::write_msh_binary_quadratic(path, mesh, q),
        "msh" => gmsh::write_msh_quadratic(path, mesh, q),
        "mesh" => medit::write_medit_quadratic(path, mesh, q),
        "inp" => abaqus::write_inp_quadratic(path, mesh, q),
        "xdmf" => xdmf::write_xdmf(path, mesh, Some(q)),
        _ => tetgen::write_tetgen_quadratic(path, mesh, q),
    }
}

/// Reads a mesh (.mesh, .vtu, .msh, .node/.ele/.face), format chosen by extension.
///
/// A medit `.mesh` is the "existing mesh" input. A `.vtu` holds no boundary triangles, and its
/// cell fields other than `region` are dropped here (use [`vtu::read_vtu`] to get them).
pub fn read_mesh(path: &Path) -> Result<TetMesh, IoError> {
    match extension(path, MESH_EXTENSIONS, "mesh")?.as_str() {
        "vtu" => vtu::read_vtu(path).map(|d| d.mesh),
        "mesh" => medit::read_medit(path),
        "msh" => gmsh::read_msh(path),
        _ => tetgen::read_tetgen(path),
    }
}
