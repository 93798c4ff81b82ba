//! Facets may meet only along shared polygon edges and shared vertices. Checked on the facet
//! triangulations: sort-and-sweep over triangle bounding boxes (no O(n²) on large surfaces),
//! then an exact triangle–triangle test for each overlapping pair from different facets.

use super::error::PlcError;
use super::exact::{point_in_triangle_3d, triangle_contact, Contact};
use super::topology::Topology;
use glam::DVec3;

/// Checks every pair of triangles from different facets whose boxes overlap.
pub(crate) fn check_facet_intersections(
    vertices: &[DVec3],
    topo: &Topology,
) -> Result<(), PlcError> {
    let pts = |t: [u32; 3]| t.map(|v| vertices[v as usize]);
    let boxes: Vec<(DVec3, DVec3)> = topo
        .tris
        .iter()
        .map(|&(_, _, t)| {
            let [a, b, c] = pts(t);
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    let axis = sweep_axis(&boxes);
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0[axis].total_cmp(&boxes[j].0[axis]));
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        let (lo, hi) = boxes[i];
        active.retain(|&j| boxes[j].1[axis] >= lo[axis]);
        for &j in &active {
            let (fi, _, ti) = topo.tris[i];
            let (fj, _, tj) = topo.tris[j];
            if fi == fj || boxes[j].0.cmpgt(hi).any() || boxes[j].1.cmplt(lo).any() {
                continue;
            }
            // Report the pair in a fixed order: lower facet first.
            let ((fa, ta), (fb, tb)) = if fi < fj {
                ((fi, ti), (fj, tj))
            } else {
                ((fj, tj), (fi, ti))
            };
            match triangle_contact(ta, pts(ta), tb, pts(tb)) {
                Contact::Clean => {}
                Contact::Clash => {
                    return Err(PlcError::FacetsIntersect {
                        facets: [fa as usize, fb as usize],
                        triangles: [ta, tb],
                    })
                }
                Contact::SharedEdge(e) => {
                    if !(topo.is_segment_of(e, fa) && topo.is_segment_of(e, fb)) {
                        return Err(PlcError::FacetsMeetOffSegment {
                            facets: [fa as usize, fb as usize],
                            edge: e,
                        });
                    }
                }
            }
        }
        active.push(i);
    }
    Ok(())
}

/// The axis along which the boxes are most spread out (fewest overlaps to sweep).
fn sweep_axis(boxes: &[(DVec3, DVec3)]) -> usize {
    let (lo, hi) = boxes.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), b| (lo.min(b.0), hi.max(b.0)),
    );
    let spread = hi - lo;
    if spread.x >= spread.y && spread.x >= spread.z {
        0
    } else if spread.y >= spread.z {
        1
    } else {
        2
    }
}

/// A vertex that belongs to no facet must not lie on one: the facet's triangulation could
/// not contain it. Points sorted by x; each triangle tests only the points in its x-range.
pub(crate) fn check_isolated_vertices(
    vertices: &[DVec3],
    isolated: &[u32],
    topo: &Topology,
) -> Result<(), PlcError> {
    let mut pts: Vec<u32> = isolated.to_vec();
    pts.sort_by(|&a, &b| vertices[a as usize].x.total_cmp(&vertices[b as usize].x));
    let mut hit: Option<(u32, u32)> = None;
    for &(f, _, t) in &topo.tris {
        let [a, b, c] = t.map(|i| vertices[i as usize]);
        let (lo, hi) = (a.min(b).min(c), a.max(b).max(c));
        let start = pts.partition_point(|&v| vertices[v as usize].x < lo.x);
        for &v in &pts[start..] {
            let p = vertices[v as usize];
            if p.x > hi.x {
                break;
            }
            if p.cmpge(lo).all() && p.cmple(hi).all() && point_in_triangle_3d(p, a, b, c) {
                // Report the lowest vertex id for a stable message.
                hit = Some(hit.map_or((v, f), |h| if v < h.0 { (v, f) } else { h }));
            }
        }
    }
    match hit {
        Some((v, f)) => Err(PlcError::VertexOnFacet {
            vertex: v as usize,
            coords: vertices[v as usize],
            facet: f as usize,
        }),
        None => Ok(()),
    }
}
