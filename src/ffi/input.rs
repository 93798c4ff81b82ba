//! Building the domain: vertices, facets, facet holes, volume holes, regions.

use super::guard::handle_call;
use super::mesher::sm_mesher;
use super::slices::{input, scaled};
use super::status::*;
use glam::DVec3;

/// Appends `n` vertices from `xyz` (3n doubles: x0 y0 z0 x1 ...). Ids are 0-based and continue
/// in order from the vertices already added. All-or-nothing: a non-finite coordinate (or one
/// beyond 1e30) rejects the whole batch with `SM_ERR_INVALID_ARGUMENT` naming the vertex.
/// `xyz` may be NULL when `n` is 0.
///
/// # Safety
/// `m` is NULL or a live handle; `xyz` is NULL or points to `3 * n` readable doubles.
#[no_mangle]
pub unsafe extern "C" fn sm_add_vertices(
    m: *mut sm_mesher,
    xyz: *const f64,
    n: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_add_vertices", |st| {
        let len = scaled("xyz", n, 3)?;
        // SAFETY: `xyz` is NULL or holds `3 * n` doubles (contract above).
        let flat = unsafe { input("xyz", xyz, len) }?;
        let points: Vec<DVec3> = flat.chunks_exact(3).map(DVec3::from_slice).collect();
        st.mesher.add_vertices(&points)?;
        Ok(())
    })
}

/// Appends a planar polygonal facet: `n` >= 3 vertex ids (0-based, each below the number of
/// vertices added so far) in order around the polygon. `marker` is copied to every boundary
/// triangle of the facet. Planarity and intersections are checked by `sm_refine`.
///
/// # Safety
/// `m` is NULL or a live handle; `ids` is NULL or points to `n` readable ids.
#[no_mangle]
pub unsafe extern "C" fn sm_add_facet(
    m: *mut sm_mesher,
    ids: *const u32,
    n: usize,
    marker: i32,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_add_facet", |st| {
        // SAFETY: `ids` is NULL or holds `n` ids (contract above).
        let ids = unsafe { input("ids", ids, n) }?;
        st.mesher.add_facet(ids, marker)?;
        Ok(())
    })
}

/// Adds a hole polygon (`n` >= 3 vertex ids) to the facet added last: the facet is not meshed
/// inside it.
///
/// # Safety
/// `m` is NULL or a live handle; `ids` is NULL or points to `n` readable ids.
#[no_mangle]
pub unsafe extern "C" fn sm_add_facet_hole(
    m: *mut sm_mesher,
    ids: *const u32,
    n: usize,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_add_facet_hole", |st| {
        // SAFETY: `ids` is NULL or holds `n` ids (contract above).
        let ids = unsafe { input("ids", ids, n) }?;
        st.mesher.add_facet_hole(ids)?;
        Ok(())
    })
}

/// Adds a volume hole seed: the connected part of the domain holding (x, y, z) is not meshed.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_add_hole(m: *mut sm_mesher, x: f64, y: f64, z: f64) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_add_hole", |st| {
        st.mesher.add_hole(DVec3::new(x, y, z))?;
        Ok(())
    })
}

/// Adds a region seed: the tets of the connected part holding (x, y, z) get `attribute`
/// (`sm_get_tets` regions); `max_size` > 0 limits their size there, <= 0 means no limit.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_add_region(
    m: *mut sm_mesher,
    x: f64,
    y: f64,
    z: f64,
    attribute: i32,
    max_size: f64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_add_region", |st| {
        st.mesher
            .add_region(DVec3::new(x, y, z), attribute, max_size)?;
        Ok(())
    })
}
