//! Settings: parameters by name, the spacing (constant or callback) and the progress callback.

use super::callbacks::{sm_progress_fn, sm_spacing_batch_fn, sm_spacing_fn, CProgress, CSpacing};
use super::guard::handle_call;
use super::mesher::sm_mesher;
use super::slices::{input, scaled, utf8};
use super::status::*;
use std::ffi::{c_char, c_void};

/// Sets a refinement parameter by name: "rho0" (radius-edge bound R/L, >= 0.7, default 2),
/// "sigma0" (sliver bound V/L^3 in [0, 0.1179), default 0.02; 0 = off), "min_dihedral" (degrees
/// in [0, 70.5): tets with a smaller dihedral angle count as slivers, default 18; 0 = off),
/// "delta" (picking-ball factor in (0, 1), default 0.3), "b" (small-sliver radius factor > 0,
/// default 4), "size_factor" or "B" (R/f(c) bound > 0, default 1), "seed" (whole number,
/// default 1), "max_vertices" (whole number, at least 4; refinement stops there, reporting
/// complete = 0), "max_tries" (whole number, at least 1), "refine" (1, or 0 for boundary
/// recovery only), "small_angle_reach" (> 0, default infinity: how far, in protecting-ball
/// radii, the influence of a vertex where segments meet below 60 degrees reaches along its
/// segments and facets; 2 to 8 leave fewer bad tets there for more vertices and time),
/// "improve" (1, the default: flips and smoothing after refinement; 0 keeps the Delaunay
/// mesh, removing only flat or inverted tets), "surface_mode" (0, the default: keep, every
/// input facet is preserved exactly; 1: approximate, the input triangles describe a piecewise
/// smooth surface whose sharp features are kept and whose boundary is a new triangulation
/// within surface_distance of it), "feature_angle" (approximate mode: degrees in (0, 180),
/// default 40; an edge whose two triangles' normals differ by more is a sharp feature),
/// "surface_distance" (approximate mode: finite, >= 0, absolute length; 0, the default, means
/// 0.001 x the input's bounding-box diagonal), "improve_target" (degrees in [0, 40]:
/// improvement works on tets with a smaller dihedral angle; 0, the default, means 26 in keep
/// mode and 20 in approximate mode), "repair" (approximate mode: 1 meshes a dirty surface,
/// open, self-intersecting, overlapping or with duplicated triangles, as the solid where its
/// generalized winding number is at least 1/2; 0, the default, refuses it with the error that
/// names the defect), "order" (1, the default: four-node tets; 2: ten-node tets as well, read
/// with `sm_num_nodes`, `sm_get_nodes` and `sm_get_tets10`; in approximate mode the boundary
/// edges' nodes lie on the input surface), "threads" (whole number >= 0, default 0 = all
/// cores, at most 255 used: threads of the run's parallel steps; refinement and improvement
/// run on the thread calling `sm_refine`; the mesh is the same for every count),
/// "spacing_thread_safe" (0, the default: the spacing callback is called only from the thread
/// calling `sm_refine`, one call at a time; 1: the caller declares that the callback, with its
/// `user_data`, may be called from several threads at the same time, and big batches are then
/// split across the run's threads).
/// An unknown name or out-of-range value gives `SM_ERR_INVALID_ARGUMENT`; `sm_last_error`
/// says why (and lists the valid names).
///
/// # Safety
/// `m` is NULL or a live handle; `name` is NULL or a NUL-terminated string.
#[no_mangle]
pub unsafe extern "C" fn sm_set_param(
    m: *mut sm_mesher,
    name: *const c_char,
    value: f64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_param", |st| {
        // SAFETY: `name` is NULL or NUL-terminated (contract above).
        let name = unsafe { utf8("name", name) }?;
        st.mesher.set_param(name, value)?;
        Ok(())
    })
}

/// Reads a refinement parameter by name (names as `sm_set_param`) into `*value`.
///
/// # Safety
/// `m` is NULL or a live handle; `name` is NULL or a NUL-terminated string; `value` is NULL or
/// points to a writable double.
#[no_mangle]
pub unsafe extern "C" fn sm_get_param(
    m: *const sm_mesher,
    name: *const c_char,
    value: *mut f64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_param", |st| {
        // SAFETY: `name` is NULL or NUL-terminated (contract above).
        let name = unsafe { utf8("name", name) }?;
        if value.is_null() {
            return Err(FfiError::null("value"));
        }
        let v = st.mesher.param(name)?;
        // SAFETY: `value` is non-null and writable (contract above).
        unsafe { value.write(v) };
        Ok(())
    })
}

/// Uses the same target element size `h` (finite, > 0) everywhere; replaces any spacing
/// callback.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_set_spacing_const(m: *mut sm_mesher, h: f64) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_spacing_const", |st| {
        st.mesher.set_spacing_constant(h)?;
        st.spacing_cb = None;
        Ok(())
    })
}

/// Uses `f(x, y, z, user_data)` as the spacing function (see `sm_spacing_fn`); replaces a
/// constant or batched spacing. `f` == NULL removes it: spacing becomes automatic. `user_data` is
/// passed back untouched; it must stay valid while the handle may call `f` (during `sm_refine`).
///
/// Threads: `f` is called only from the thread that calls `sm_refine`, one call at a time,
/// unless the parameter "spacing_thread_safe" is 1: then `f` may also be called from the run's
/// other threads ("threads"), several calls at the same time, and must be safe for that.
///
/// # Safety
/// `m` is NULL or a live handle; `f` is NULL or a function with the `sm_spacing_fn` signature
/// that does not unwind (no C++ exception, no Fortran error stop escaping it).
#[no_mangle]
pub unsafe extern "C" fn sm_set_spacing_cb(
    m: *mut sm_mesher,
    f: sm_spacing_fn,
    user_data: *mut c_void,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_spacing_cb", |st| {
        st.mesher.set_spacing_automatic();
        st.spacing_cb = f.map(|f| CSpacing::point(f, user_data));
        Ok(())
    })
}

/// Uses the batched `f(n, xyz, out, user_data)` as the spacing function (see
/// `sm_spacing_batch_fn`: one call per batch of points); replaces any other spacing. `f` == NULL
/// removes it: spacing becomes automatic.
///
/// Batches: the input vertices, once before meshing; during refinement, all the tets (keep
/// mode) or cells and surface facets (approximate mode) that one insertion created, in one
/// call (typically 20 to 40 points; 34 on average on a graded cube of 900,000 tets); the
/// first classification of the whole triangulation, the approximate mode's surface samples and
/// the report's size figures in calls of at most 4,096 points. A few evaluations stay single
/// points: a tet looked at again after a boundary split, the approximate mode's feature-curve
/// sampling and subsegment lengths (each step depends on the previous value). The values are
/// the same as with `sm_set_spacing_cb` and the same function, and so is the mesh.
///
/// Threads: as for `sm_set_spacing_cb`, `f` is called only from the thread that calls
/// `sm_refine`, one call at a time, unless "spacing_thread_safe" is 1: then a batch of 512
/// points or more (the first classification, the surface samples, the report's figures) is
/// split into one part per thread of the run ("threads"), each part of at least 256 points one
/// call, made at the same time from those threads. Every point gets the same value, and the
/// mesh is the same, however the batches are split.
///
/// # Safety
/// As `sm_set_spacing_cb`, with the `sm_spacing_batch_fn` signature.
#[no_mangle]
pub unsafe extern "C" fn sm_set_spacing_batch_cb(
    m: *mut sm_mesher,
    f: sm_spacing_batch_fn,
    user_data: *mut c_void,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_spacing_batch_cb", |st| {
        st.mesher.set_spacing_automatic();
        st.spacing_cb = f.map(|f| CSpacing::batch(f, user_data));
        Ok(())
    })
}

/// Limits the spacing in the region of attribute `id` to at most `h` (finite, > 0;
/// `SM_ERR_INVALID_ARGUMENT` otherwise): its tets get the smaller of `h` and the spacing there
/// (CLI `--region-size ID:H`). Again for the same `id`, the new `h` replaces the old. An `id`
/// the input has no region of makes `sm_refine` fail with `SM_ERR_INVALID_INPUT`, the message
/// naming it and listing the input's regions.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_set_region_size(m: *mut sm_mesher, id: i32, h: f64) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_region_size", |st| {
        st.mesher.set_region_size(id, h)?;
        Ok(())
    })
}

/// Limits the spacing near the input facets of boundary marker `id` (`h` finite and positive;
/// `SM_ERR_INVALID_ARGUMENT` otherwise): within a distance `h` of them the spacing is at most
/// `h`, farther away at most `h + 0.5 * (distance - h)`, the smaller of that and the spacing
/// there (CLI `--marker-size ID:H`). Again for the same `id`, the new `h` replaces the old. An
/// `id` no input facet has makes `sm_refine` fail with `SM_ERR_INVALID_INPUT`, the message
/// naming it and listing the input's markers.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_set_marker_size(m: *mut sm_mesher, id: i32, h: f64) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_marker_size", |st| {
        st.mesher.set_marker_size(id, h)?;
        Ok(())
    })
}

/// Uses a size field on a background tet mesh as the spacing (adaptive loops: the field computed
/// on the previous mesh): `n_vertices` points `xyz` (3 doubles each), `n_tets` tets `tets` (4
/// 0-based vertex ids each) and one value per vertex (finite, > 0). The spacing at a point is the
/// linear interpolation of the values in the background tet holding it; outside every tet, the
/// value at the nearest point of the background. The arrays are copied. Replaces any other
/// spacing. `SM_ERR_INVALID_ARGUMENT` names a bad vertex, value or tet.
///
/// # Safety
/// `m` is NULL or a live handle; `xyz` points to `3 * n_vertices` doubles, `tets` to
/// `4 * n_tets` ids and `values` to `n_vertices` doubles (each may be NULL only when its count
/// is 0).
#[no_mangle]
pub unsafe extern "C" fn sm_set_spacing_mesh(
    m: *mut sm_mesher,
    xyz: *const f64,
    n_vertices: usize,
    tets: *const u32,
    n_tets: usize,
    values: *const f64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_spacing_mesh", |st| {
        let xyz_len = scaled("xyz", n_vertices, 3)?;
        let tets_len = scaled("tets", n_tets, 4)?;
        // SAFETY: the pointers hold the counts the contract above says.
        let (xyz, tets, values) = unsafe {
            (
                input("xyz", xyz, xyz_len)?,
                input("tets", tets, tets_len)?,
                input("values", values, n_vertices)?,
            )
        };
        let field = crate::refine::background::BackgroundSpacing::new(
            xyz.chunks_exact(3).map(glam::DVec3::from_slice).collect(),
            tets.chunks_exact(4)
                .map(|t| [t[0], t[1], t[2], t[3]])
                .collect(),
            values.to_vec(),
        )
        .map_err(|e| FfiError::invalid(format!("size field: {e}")))?;
        st.mesher.set_spacing(field);
        st.spacing_cb = None;
        Ok(())
    })
}

/// Makes `sm_refine` remove the slivers of an existing tet mesh instead of meshing the domain
/// (the CLI's `.mesh` input): `n_vertices` points `xyz` (3 doubles each), `n_tets` tets `tets` (4
/// 0-based vertex ids each, positively oriented) with their region attributes `regions` (NULL:
/// all 0), and `n_tris` boundary and interface triangles `tris` (3 ids each) with their markers
/// `markers` (NULL: all 0). Its boundary is kept as it is (keep mode only), its tets refined and
/// improved to the parameters' bounds; the spacing is the mesh's own. The arrays are copied.
/// `SM_ERR_INVALID_ARGUMENT` names a non-finite vertex or an id beyond the vertices;
/// `sm_refine` reports the rest (an open boundary, an inverted tet).
///
/// # Safety
/// `m` is NULL or a live handle; `xyz` points to `3 * n_vertices` doubles, `tets` to
/// `4 * n_tets` ids, `regions` is NULL or points to `n_tets` ints, `tris` to `3 * n_tris` ids,
/// `markers` is NULL or points to `n_tris` ints (an array may be NULL when its count is 0).
#[no_mangle]
#[allow(clippy::too_many_arguments)]
pub unsafe extern "C" fn sm_set_existing_mesh(
    m: *mut sm_mesher,
    xyz: *const f64,
    n_vertices: usize,
    tets: *const u32,
    regions: *const i32,
    n_tets: usize,
    tris: *const u32,
    markers: *const i32,
    n_tris: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_existing_mesh", |st| {
        let xyz_len = scaled("xyz", n_vertices, 3)?;
        let tets_len = scaled("tets", n_tets, 4)?;
        let tris_len = scaled("tris", n_tris, 3)?;
        // SAFETY: the pointers hold the counts the contract above says.
        let (xyz, tets, tris) = unsafe {
            (
                input("xyz", xyz, xyz_len)?,
                input("tets", tets, tets_len)?,
                input("tris", tris, tris_len)?,
            )
        };
        let labels = |p: *const i32, n: usize, what: &str| -> Result<Vec<i32>, FfiError> {
            if p.is_null() {
                Ok(vec![0; n])
            } else {
                // SAFETY: non-null, and holds `n` ints (contract above).
                Ok(unsafe { input(what, p, n) }?.to_vec())
            }
        };
        let mesh = crate::mesh::TetMesh {
            vertices: xyz.chunks_exact(3).map(glam::DVec3::from_slice).collect(),
            tets: tets
                .chunks_exact(4)
                .map(|t| [t[0], t[1], t[2], t[3]])
                .collect(),
            tet_regions: labels(regions, n_tets, "regions")?,
            boundary: tris.chunks_exact(3).map(|t| [t[0], t[1], t[2]]).collect(),
            boundary_markers: labels(markers, n_tris, "markers")?,
        };
        st.mesher.set_existing_mesh(mesh)?;
        Ok(())
    })
}

/// Calls `f(fraction, n_vertices, user_data)` during `sm_refine` (once with 0 before any work);
/// a non-zero return cancels it with `SM_ERR_CANCELLED`. `f` == NULL removes the callback.
///
/// # Safety
/// `m` is NULL or a live handle; `f` is NULL or a function with the `sm_progress_fn` signature
/// that does not unwind.
#[no_mangle]
pub unsafe extern "C" fn sm_set_progress_cb(
    m: *mut sm_mesher,
    f: sm_progress_fn,
    user_data: *mut c_void,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_set_progress_cb", |st| {
        st.progress_cb = f.map(|f| CProgress::new(f, user_data));
        Ok(())
    })
}
