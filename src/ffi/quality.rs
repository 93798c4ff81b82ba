//! `sm_quality`: the figures of the last run's report.

use super::guard::{handle_call, handle_query};
use super::mesher::sm_mesher;
use super::slices::output;
use super::status::*;
use crate::run::report::Report;

/// What the last `sm_refine` achieved (the report's figures). Measures: rho = R/L (circumradius
/// over shortest edge; regular tet 0.612), sigma = V/L^3 (regular 0.1179), dihedral angles in
/// degrees (regular 70.53), size ratio R/f(circumcentre).
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct sm_quality {
    pub n_vertices: usize,
    pub n_tets: usize,
    pub n_boundary_faces: usize,
    pub seconds_recovery: f64,
    pub seconds_refinement: f64,
    pub seconds_total: f64,
    /// Largest radius-edge ratio R/L.
    pub max_rho: f64,
    /// Smallest V/L^3.
    pub min_sigma: f64,
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// Number of tets with a dihedral angle below 5, 10, 15 and 20 degrees.
    pub tets_below_deg: [usize; 4],
    /// Largest R / f(circumcentre).
    pub max_size_ratio: f64,
    /// Edge length / f(midpoint): smallest, median, largest.
    pub edge_ratio_min: f64,
    pub edge_ratio_median: f64,
    pub edge_ratio_max: f64,
    /// Acute input angles found (they limit where quality can be enforced).
    pub n_acute_angles: usize,
    /// Tets left violating a bound near an acute input angle.
    pub n_bad_near_acute: usize,
    /// 1 if every bound holds wherever it is enforced, 0 if a budget stopped refinement early
    /// (`sm_stop_reason` says which).
    pub complete: i32,
}

impl From<&Report> for sm_quality {
    fn from(r: &Report) -> Self {
        sm_quality {
            n_vertices: r.n_vertices,
            n_tets: r.n_tets,
            n_boundary_faces: r.n_boundary_faces,
            seconds_recovery: r.seconds_recovery,
            seconds_refinement: r.seconds_refinement,
            seconds_total: r.seconds_total,
            max_rho: r.max_rho,
            min_sigma: r.min_sigma,
            min_dihedral_deg: r.min_dihedral_deg,
            max_dihedral_deg: r.max_dihedral_deg,
            tets_below_deg: r.tets_below_deg,
            max_size_ratio: r.max_size_ratio,
            edge_ratio_min: r.edge_ratio_min,
            edge_ratio_median: r.edge_ratio_median,
            edge_ratio_max: r.edge_ratio_max,
            n_acute_angles: r.n_acute_angles,
            n_bad_near_acute: r.n_bad_near_acute,
            complete: i32::from(r.complete),
        }
    }
}

/// Copies the last run's figures into `*out`. `SM_ERR_NOT_REFINED` before a successful
/// `sm_refine`; `*out` is written only on success.
///
/// # Safety
/// `m` is NULL or a live handle; `out` is NULL or points to a writable `sm_quality`.
#[no_mangle]
pub unsafe extern "C" fn sm_get_quality(m: *const sm_mesher, out: *mut sm_quality) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_quality", |st| {
        if out.is_null() {
            return Err(FfiError::null("out"));
        }
        let q = sm_quality::from(st.mesher.report()?);
        // SAFETY: `out` is non-null and writable (contract above).
        unsafe { out.write(q) };
        Ok(())
    })
}

/// One region of the last run's mesh (all tets of one attribute) against the input's.
#[allow(non_camel_case_types)]
#[repr(C)]
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct sm_region {
    /// The attribute `sm_get_tets` gives its tets.
    pub attribute: i32,
    pub tets: usize,
    pub volume: f64,
    /// The input region's volume (0 when the input has no region of this attribute).
    pub input_volume: f64,
    /// (volume - input_volume) / input_volume.
    pub relative_volume_difference: f64,
}

/// Number of regions (distinct tet attributes) of the last run's mesh; 0 before a successful
/// `sm_refine`.
///
/// # Safety
/// `m` is NULL or a live handle.
#[no_mangle]
pub unsafe extern "C" fn sm_num_regions(m: *const sm_mesher) -> usize {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_query(handle, "sm_num_regions", 0, |st| {
        st.mesher.report().map_or(0, |r| r.regions.len())
    })
}

/// Copies each region's figures into `regions` (sorted by attribute), and the area of the faces
/// between tets of different regions, and the input's, into `*interface_area` and
/// `*input_interface_area` when they are not NULL. `SM_ERR_BUFFER_TOO_SMALL` if
/// `capacity < sm_num_regions(m)`; nothing is written unless the call succeeds.
///
/// # Safety
/// `m` is NULL or a live handle; `regions` is NULL or points to `capacity` writable
/// `sm_region`s; the areas are NULL or point to writable doubles.
#[no_mangle]
pub unsafe extern "C" fn sm_get_regions(
    m: *const sm_mesher,
    regions: *mut sm_region,
    capacity: usize,
    interface_area: *mut f64,
    input_interface_area: *mut f64,
) -> sm_status {
    // SAFETY: `m` is NULL or a live handle (contract above).
    let handle = unsafe { m.as_ref() };
    handle_call(handle, "sm_get_regions", |st| {
        let report = st.mesher.report()?;
        // SAFETY: `regions` is NULL or holds `capacity` items (contract above).
        let out = unsafe { output("regions", regions, capacity, report.regions.len(), 1) }?;
        for (o, r) in out.iter_mut().zip(&report.regions) {
            *o = sm_region {
                attribute: r.attribute,
                tets: r.tets,
                volume: r.volume,
                input_volume: r.input_volume,
                relative_volume_difference: r.relative_volume_difference,
            };
        }
        for (p, v) in [
            (interface_area, report.interface_area),
            (input_interface_area, report.input_interface_area),
        ] {
            if !p.is_null() {
                // SAFETY: non-null and writable (contract above).
                unsafe { p.write(v) };
            }
        }
        Ok(())
    })
}
