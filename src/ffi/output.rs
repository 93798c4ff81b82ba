//! Reading the mesh back (counts, then copies into caller buffers) and writing it to a file.

use super::guard::{handle_call, handle_query};
use super::mesher::sm_mesher;
use super::slices::{c_str, output};
use super::status::*;
use std::ffi::c_char;
use std::path::PathBuf;

/// Number of mesh vertices (input vertices first, in input order); 0 before a successful
/// `sm_refine` or for a NULL or poisoned handle.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_num_vertices(m: *const sm_mesher) -> usize {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_num_vertices", 0, |st| {
        st.mesher.mesh().map_or(0, |mesh| mesh.vertices.len())
    })
}

/// Number of tetrahedra; 0 before a successful `sm_refine`.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_num_tets(m: *const sm_mesher) -> usize {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_num_tets", 0, |st| {
        st.mesher.mesh().map_or(0, |mesh| mesh.tets.len())
    })
}

/// Number of boundary triangles (the input facets, subdivided); 0 before a successful
/// `sm_refine`.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_num_boundary_faces(m: *const sm_mesher) -> usize {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_num_boundary_faces", 0, |st| {
        st.mesher.mesh().map_or(0, |mesh| mesh.boundary.len())
    })
}

/// Copies the vertex coordinates into `xyz` (x0 y0 z0 x1 ...), which holds `capacity` vertices
/// (3 * capacity doubles). `SM_ERR_BUFFER_TOO_SMALL` if `capacity < sm_num_vertices(m)`;
/// nothing is written unless the call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `xyz` is NULL or points to `3 * capacity` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn sm_get_vertices(
    m: *const sm_mesher,
    xyz: *mut f64,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_vertices", |st| {
        let mesh = st.mesher.mesh()?;
        let n = mesh.vertices.len();
        // SAFETY: `xyz` is NULL or holds 3 * capacity doubles (contract above).
        let out = unsafe { output("xyz", xyz, capacity, n, 3) }?;
        for (o, v) in out.chunks_exact_mut(3).zip(&mesh.vertices) {
            o.copy_from_slice(&v.to_array());
        }
        Ok(())
    })
}

/// Copies the tetrahedra into `tets` (4 vertex ids per tet, 0-based, positively oriented) and,
/// if `regions` is not NULL, each tet's region attribute into `regions`: the region seed's
/// attribute (`sm_add_region`); without seeds 0 for a domain of one piece, else 1, 2, ... per
/// enclosed volume in the order their outer boundaries first appear among the facets (a
/// sphere inside a box: 1 the shell, 2 the sphere).
/// Both hold `capacity` tets. `SM_ERR_BUFFER_TOO_SMALL` if `capacity < sm_num_tets(m)`;
/// nothing is written unless the call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `tets` is NULL or points to `4 * capacity` writable ids;
/// `regions` is NULL or points to `capacity` writable ints.
#[no_mangle]
pub unsafe extern "C" fn sm_get_tets(
    m: *const sm_mesher,
    tets: *mut u32,
    regions: *mut i32,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_tets", |st| {
        let mesh = st.mesher.mesh()?;
        let n = mesh.tets.len();
        // SAFETY: `tets` is NULL or holds 4 * capacity ids (contract above).
        let out = unsafe { output("tets", tets, capacity, n, 4) }?;
        let regions_out = if regions.is_null() {
            None
        } else {
            // SAFETY: `regions` is non-null and holds `capacity` ints (contract above).
            Some(unsafe { output("regions", regions, capacity, n, 1) }?)
        };
        for (o, t) in out.chunks_exact_mut(4).zip(&mesh.tets) {
            o.copy_from_slice(t);
        }
        if let Some(r) = regions_out {
            r.copy_from_slice(&mesh.tet_regions);
        }
        Ok(())
    })
}

/// Number of nodes of the ten-node mesh (`sm_set_param(m, "order", 2)`): the vertices, then
/// one node per edge; `sm_num_vertices(m)` with order 1, and 0 before a successful
/// `sm_refine`.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_num_nodes(m: *const sm_mesher) -> usize {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_num_nodes", 0, |st| {
        st.mesher.output().map_or(0, |o| match &o.quadratic {
            Some(q) => q.n_nodes(&o.mesh),
            None => o.mesh.vertices.len(),
        })
    })
}

/// Copies the coordinates of every node into `xyz` (x0 y0 z0 x1 ...), which holds `capacity`
/// nodes: the vertices as `sm_get_vertices` gives them, then with order 2 the mid-edge nodes
/// (on the input surface for curved boundary edges). `SM_ERR_BUFFER_TOO_SMALL` if
/// `capacity < sm_num_nodes(m)`; nothing is written unless the call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `xyz` is NULL or points to `3 * capacity` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn sm_get_nodes(
    m: *const sm_mesher,
    xyz: *mut f64,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_nodes", |st| {
        let mesh = st.mesher.mesh()?;
        let mids: &[crate::DVec3] = st
            .mesher
            .output()
            .and_then(|o| o.quadratic.as_ref())
            .map_or(&[], |q| &q.points);
        let n = mesh.vertices.len() + mids.len();
        // SAFETY: `xyz` is NULL or holds 3 * capacity doubles (contract above).
        let out = unsafe { output("xyz", xyz, capacity, n, 3) }?;
        for (o, v) in out
            .chunks_exact_mut(3)
            .zip(mesh.vertices.iter().chain(mids))
        {
            o.copy_from_slice(&v.to_array());
        }
        Ok(())
    })
}

/// Copies the ten-node tets into `tets10` (10 node ids per tet, 0-based, indices into
/// `sm_get_nodes`): the four corners as `sm_get_tets` gives them, then the nodes of edges
/// 01, 12, 02, 03, 13, 23 (VTK's VTK_QUADRATIC_TETRA and Abaqus C3D10 order). Holds `capacity`
/// tets. `SM_ERR_NOT_REFINED` unless the last `sm_refine` ran with `"order"` 2;
/// `SM_ERR_BUFFER_TOO_SMALL` if `capacity < sm_num_tets(m)`; nothing is written unless the
/// call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `tets10` is NULL or points to `10 * capacity` writable ids.
#[no_mangle]
pub unsafe extern "C" fn sm_get_tets10(
    m: *const sm_mesher,
    tets10: *mut u32,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_tets10", |st| {
        let mesh = st.mesher.mesh()?;
        let quadratic = st
            .mesher
            .output()
            .and_then(|o| o.quadratic.as_ref())
            .ok_or_else(|| {
                FfiError::new(
                    SM_ERR_NOT_REFINED,
                    "no ten-node tets: set the parameter \"order\" to 2 before sm_refine",
                )
            })?;
        let n = mesh.tets.len();
        // SAFETY: `tets10` is NULL or holds 10 * capacity ids (contract above).
        let out = unsafe { output("tets10", tets10, capacity, n, 10) }?;
        for ((o, t), e) in out
            .chunks_exact_mut(10)
            .zip(&mesh.tets)
            .zip(&quadratic.tet_edges)
        {
            o[..4].copy_from_slice(t);
            o[4..].copy_from_slice(e);
        }
        Ok(())
    })
}

/// Copies the boundary triangles into `tris` (3 vertex ids each) and, if `markers` is not NULL,
/// each triangle's input facet marker into `markers`. Both hold `capacity` triangles. An
/// interface between two regions is among them once (its face is shared by one tet of each
/// region), oriented out of one of the two (approximate mode: the one of lower region number).
/// `SM_ERR_BUFFER_TOO_SMALL` if `capacity < sm_num_boundary_faces(m)`; nothing is written
/// unless the call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `tris` is NULL or points to `3 * capacity` writable ids;
/// `markers` is NULL or points to `capacity` writable ints.
#[no_mangle]
pub unsafe extern "C" fn sm_get_boundary_faces(
    m: *const sm_mesher,
    tris: *mut u32,
    markers: *mut i32,
    capacity: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_boundary_faces", |st| {
        let mesh = st.mesher.mesh()?;
        let n = mesh.boundary.len();
        // SAFETY: `tris` is NULL or holds 3 * capacity ids (contract above).
        let out = unsafe { output("tris", tris, capacity, n, 3) }?;
        let markers_out = if markers.is_null() {
            None
        } else {
            // SAFETY: `markers` is non-null and holds `capacity` ints (contract above).
            Some(unsafe { output("markers", markers, capacity, n, 1) }?)
        };
        for (o, t) in out.chunks_exact_mut(3).zip(&mesh.boundary) {
            o.copy_from_slice(t);
        }
        if let Some(k) = markers_out {
            k.copy_from_slice(&mesh.boundary_markers);
        }
        Ok(())
    })
}

/// Writes the mesh to `path`, format by extension: .vtu (ParaView, with per-tet rho, sigma,
/// aspect and dihedral angles as cell data), .mesh (medit), .msh (gmsh 4.1), .node (TetGen
/// .node/.ele/.face), .inp (Abaqus: C3D4, an element set per region, a surface per boundary
/// marker). `SM_ERR_IO` names the file on failure.
///
/// # Safety
/// `m` is NULL or a live handle; `path` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sm_write(m: *const sm_mesher, path: *const c_char) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_write", |st| {
        // SAFETY: `path` is NULL or NUL-terminated (contract above).
        let path = path_of(unsafe { c_str("path", path) }?)?;
        st.mesher.write(&path)?;
        Ok(())
    })
}

/// `sm_write`, in the format's binary form where it has one: .msh as gmsh 4.1 binary, .vtu with
/// binary appended arrays (raw little-endian, UInt64 header); the other formats as `sm_write`
/// writes them.
///
/// # Safety
/// `m` is NULL or a live handle; `path` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sm_write_binary(m: *const sm_mesher, path: *const c_char) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_write_binary", |st| {
        // SAFETY: `path` is NULL or NUL-terminated (contract above).
        let path = path_of(unsafe { c_str("path", path) }?)?;
        st.mesher.write_in(&path, true)?;
        Ok(())
    })
}

/// A C path as a `PathBuf`: any bytes on Unix, UTF-8 elsewhere.
fn path_of(s: &std::ffi::CStr) -> Result<PathBuf, FfiError> {
    #[cfg(unix)]
    {
        use std::os::unix::ffi::OsStrExt;
        Ok(PathBuf::from(std::ffi::OsStr::from_bytes(s.to_bytes())))
    }
    #[cfg(not(unix))]
    {
        s.to_str()
            .map(PathBuf::from)
            .map_err(|_| FfiError::invalid("`path` is not valid UTF-8"))
    }
}

/// Why the last `sm_refine` stopped before every bound held (e.g. the vertex budget), or NULL
/// when it completed, has not run, or the handle is NULL. Owned by the handle, valid until the
/// next `sm_refine` or `sm_destroy`.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_stop_reason(m: *const sm_mesher) -> *const c_char {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_stop_reason", std::ptr::null(), |st| {
        match (st.mesher.output(), &st.stop_reason) {
            (Some(_), Some(r)) => r.as_ptr(),
            _ => std::ptr::null(),
        }
    })
}
