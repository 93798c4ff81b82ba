//! VTK XML UnstructuredGrid (`.vtu`) writer in the binary appended form: the same arrays as
//! [`super::vtu::format_vtu`] (points, connectivity, offsets, types, `region`, the cell fields),
//! each `format="appended"` with its `offset` into one `<AppendedData encoding="raw">` block,
//! where it is stored as a `UInt64` byte count followed by its little-endian values
//! (`header_type="UInt64"`). No number formatting or parsing; about the ASCII file's
//! size (the Int64 connectivity takes as many bytes as short decimal ids: 134 against 131 MB
//! for the pieces of 2.4e6 tets).
//! Ten-node tets: [`format_vtu_binary_quadratic`], the arrays of
//! [`super::vtu::format_vtu_quadratic`]. This module's reader does not read it back
//! (`super::vtu` reads ASCII arrays only); VTK does (the ctest `vtk_readback_binary_*`).

use super::elements::Elements;
use super::text::{
    check_mesh, check_mesh_io, check_quadratic, check_quadratic_io, create, with_path, write_err,
};
use super::vtu::{
    cell_type, field_lens, write_prologue, GlobalIds, GLOBAL_CELL_ID, GLOBAL_NODE_ID,
};
use super::{CellField, IoError};
use crate::mesh::{QuadraticNodes, TetMesh};
use std::io::Write;
use std::path::Path;

/// Writes `mesh` with `cell_fields` as a binary appended `.vtu` file.
pub fn write_vtu_binary(
    path: &Path,
    mesh: &TetMesh,
    cell_fields: &[CellField],
) -> Result<(), IoError> {
    check_mesh(mesh, &field_lens(cell_fields)).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_vtu_binary(&mut w, mesh, cell_fields)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// Writes `mesh` with its mid-edge nodes and `cell_fields` as a binary appended `.vtu` file of
/// `VTK_QUADRATIC_TETRA` cells (the arrays of [`super::vtu::format_vtu_quadratic`]).
pub fn write_vtu_binary_quadratic(
    path: &Path,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
    cell_fields: &[CellField],
) -> Result<(), IoError> {
    check_mesh(mesh, &field_lens(cell_fields)).map_err(|e| with_path(e, path))?;
    check_quadratic(mesh, quadratic).map_err(|e| with_path(e, path))?;
    let mut w = create(path)?;
    format_vtu_binary_quadratic(&mut w, mesh, quadratic, cell_fields)
        .and_then(|_| w.flush())
        .map_err(|e| write_err(path, e))
}

/// One appended array: its XML attributes and its byte length.
struct Array {
    attributes: String,
    bytes: usize,
}

/// Writes `mesh` in the binary appended `.vtu` form to any writer.
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_vtu_binary<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    cell_fields: &[CellField],
) -> std::io::Result<()> {
    check_mesh_io(mesh, &field_lens(cell_fields))?;
    format_elements(w, &Elements::new(mesh, None), cell_fields, None)
}

/// [`format_vtu_binary`] of ten-node tets (`VTK_QUADRATIC_TETRA`).
/// An inconsistent mesh is an `InvalidInput` error.
pub fn format_vtu_binary_quadratic<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    quadratic: &QuadraticNodes,
    cell_fields: &[CellField],
) -> std::io::Result<()> {
    check_mesh_io(mesh, &field_lens(cell_fields))?;
    check_quadratic_io(mesh, quadratic)?;
    format_elements(w, &Elements::new(mesh, Some(quadratic)), cell_fields, None)
}

/// One piece of a distributed mesh in the binary appended form: [`format_vtu_binary`]'s
/// arrays plus the global ids, as [`super::vtu::write_vtu_piece`] writes them (which checks
/// the mesh and the ids first).
pub(super) fn format_piece<W: Write>(
    w: &mut W,
    mesh: &TetMesh,
    ids: GlobalIds,
    cell_fields: &[CellField],
) -> std::io::Result<()> {
    format_elements(w, &Elements::new(mesh, None), cell_fields, Some(ids))
}

fn format_elements<W: Write>(
    w: &mut W,
    el: &Elements,
    cell_fields: &[CellField],
    ids: Option<GlobalIds>,
) -> std::io::Result<()> {
    let mesh = el.mesh;
    let (nv, nt) = (el.n_nodes(), mesh.tets.len());
    let (ty, k) = cell_type(el);
    let array = |attributes: String, bytes: usize| Array { attributes, bytes };
    let points = array(
        "type=\"Float64\" Name=\"Points\" NumberOfComponents=\"3\"".into(),
        24 * nv,
    );
    let cells = [
        array("type=\"Int64\" Name=\"connectivity\"".into(), 8 * k * nt),
        array("type=\"Int64\" Name=\"offsets\"".into(), 8 * nt),
        array("type=\"UInt8\" Name=\"types\"".into(), nt),
    ];
    let point_ids = array(format!("type=\"Int64\" Name=\"{GLOBAL_NODE_ID}\""), 8 * nv);
    let mut cell_data = vec![array("type=\"Int32\" Name=\"region\"".into(), 4 * nt)];
    if ids.is_some() {
        cell_data.push(array(
            format!("type=\"Int64\" Name=\"{GLOBAL_CELL_ID}\""),
            8 * nt,
        ));
    }
    for f in cell_fields {
        cell_data.push(array(
            format!(
                "type=\"Float64\" Name=\"{}\"",
                super::vtu::xml_escape(f.name)
            ),
            8 * f.values.len(),
        ));
    }
    let mut offset = 0usize;
    let mut tag = |w: &mut W, a: &Array| -> std::io::Result<()> {
        writeln!(
            w,
            "<DataArray {} format=\"appended\" offset=\"{offset}\"/>",
            a.attributes
        )?;
        offset += 8 + a.bytes;
        Ok(())
    };
    write_prologue(w, nv, nt)?;
    tag(w, &points)?;
    writeln!(w, "</Points>\n<Cells>")?;
    for a in &cells {
        tag(w, a)?;
    }
    writeln!(w, "</Cells>")?;
    if ids.is_some() {
        writeln!(w, "<PointData GlobalIds=\"{GLOBAL_NODE_ID}\">")?;
        tag(w, &point_ids)?;
        writeln!(w, "</PointData>")?;
        writeln!(
            w,
            "<CellData Scalars=\"region\" GlobalIds=\"{GLOBAL_CELL_ID}\">"
        )?;
    } else {
        writeln!(w, "<CellData Scalars=\"region\">")?;
    }
    for a in &cell_data {
        tag(w, a)?;
    }
    writeln!(w, "</CellData>\n</Piece>\n</UnstructuredGrid>")?;
    w.write_all(b"<AppendedData encoding=\"raw\">\n_")?;
    let header = |w: &mut W, bytes: usize| w.write_all(&(bytes as u64).to_le_bytes());
    header(w, points.bytes)?;
    for p in el.nodes() {
        for x in p.to_array() {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    header(w, cells[0].bytes)?;
    for i in 0..nt {
        for &v in &el.tet(i)[..k] {
            w.write_all(&i64::from(v).to_le_bytes())?;
        }
    }
    header(w, cells[1].bytes)?;
    for i in 1..=nt {
        w.write_all(&((k * i) as i64).to_le_bytes())?;
    }
    header(w, cells[2].bytes)?;
    w.write_all(&vec![ty; nt])?;
    if let Some(ids) = ids {
        header(w, point_ids.bytes)?;
        for x in ids.points {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    header(w, cell_data[0].bytes)?;
    for r in &mesh.tet_regions {
        w.write_all(&r.to_le_bytes())?;
    }
    if let Some(ids) = ids {
        header(w, cell_data[1].bytes)?;
        for x in ids.cells {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    let fields_from = if ids.is_some() { 2 } else { 1 };
    for (f, a) in cell_fields.iter().zip(&cell_data[fields_from..]) {
        header(w, a.bytes)?;
        for x in f.values {
            w.write_all(&x.to_le_bytes())?;
        }
    }
    w.write_all(b"\n</AppendedData>\n</VTKFile>\n")
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::DVec3;

    /// The XML offsets point at each array's byte-count header in the appended block.
    #[test]
    fn offsets_point_at_the_arrays() {
        let m = TetMesh {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z],
            tets: vec![[0, 1, 2, 3]],
            tet_regions: vec![7],
            boundary: vec![],
            boundary_markers: vec![],
        };
        let values = [0.5];
        let fields = [CellField {
            name: "sigma",
            values: &values,
        }];
        let mut out = Vec::new();
        format_vtu_binary(&mut out, &m, &fields).unwrap();
        let start = out.windows(2).position(|w| w == b"\n_").unwrap() + 2;
        let text = String::from_utf8_lossy(&out[..start]).to_string();
        let offsets: Vec<usize> = text
            .split("offset=\"")
            .skip(1)
            .map(|s| s[..s.find('"').unwrap()].parse().unwrap())
            .collect();
        assert_eq!(offsets.len(), 6, "points, 3 cell arrays, region, sigma");
        let u64_at = |o: usize| u64::from_le_bytes(out[o..o + 8].try_into().unwrap()) as usize;
        let sizes = [96, 32, 8, 1, 4, 8];
        for (o, size) in offsets.iter().zip(sizes) {
            assert_eq!(u64_at(start + o), size);
        }
        // region 7, then sigma 0.5.
        let region = start + offsets[4] + 8;
        assert_eq!(&out[region..region + 4], &7i32.to_le_bytes());
        let sigma = start + offsets[5] + 8;
        assert_eq!(&out[sigma..sigma + 8], &0.5f64.to_le_bytes());
        assert!(out.ends_with(b"\n</AppendedData>\n</VTKFile>\n"));
    }
}
