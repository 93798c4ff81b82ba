//! Facets may meet only along shared polygon edges and shared vertices. Checked on the facet
//! triangulations: a uniform grid over triangle bounding boxes finds the pairs whose boxes
//! overlap (no O(n²) on large surfaces), then an exact triangle–triangle test for each pair
//! from different facets. Should one fail, a sort-and-sweep over the same pairs finds the
//! error to report, so that the reported pair does not depend on the grid.

use super::error::PlcError;
use super::exact::{point_in_triangle_3d, triangle_contact, Contact};
use super::topology::Topology;
use glam::DVec3;

type Box3 = (DVec3, DVec3);
/// First and last cell along each axis.
type CellRange = [[usize; 2]; 3];

/// Checks every pair of triangles from different facets whose boxes overlap.
pub(crate) fn check_facet_intersections(
    vertices: &[DVec3],
    topo: &Topology,
) -> Result<(), PlcError> {
    let boxes: Vec<Box3> = topo
        .tris
        .iter()
        .map(|&(_, _, t)| {
            let [a, b, c] = t.map(|v| vertices[v as usize]);
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    // The grid visits the pairs in its own order; the sweep's order names the error.
    let mut clean = true;
    BoxGrid::new(&boxes).for_each_overlap(&boxes, |i, j| {
        clean = clean && check_pair(vertices, topo, i, j).is_ok();
    });
    if clean {
        return Ok(());
    }
    first_error_by_sweep(vertices, topo, &boxes)
}

/// Every pair of `triangles` (ids into `vertices`) that meet in more than their shared
/// vertices and edges, lower id first, sorted; the `flat` ones (collinear corners) take no
/// part.
pub(crate) fn clashing_pairs(
    vertices: &[DVec3],
    triangles: &[[u32; 3]],
    flat: &[bool],
) -> Vec<[u32; 2]> {
    let pts = |t: [u32; 3]| t.map(|v| vertices[v as usize]);
    let boxes: Vec<Box3> = triangles
        .iter()
        .map(|&t| {
            let [a, b, c] = pts(t);
            (a.min(b).min(c), a.max(b).max(c))
        })
        .collect();
    let mut pairs = Vec::new();
    BoxGrid::new(&boxes).for_each_overlap(&boxes, |i, j| {
        if flat[i] || flat[j] {
            return;
        }
        let (ti, tj) = (triangles[i], triangles[j]);
        if matches!(triangle_contact(ti, pts(ti), tj, pts(tj)), Contact::Clash) {
            pairs.push([i.min(j) as u32, i.max(j) as u32]);
        }
    });
    pairs.sort_unstable();
    pairs
}

/// The exact test of triangles i and j (boxes overlapping), nothing if they share a facet.
fn check_pair(vertices: &[DVec3], topo: &Topology, i: usize, j: usize) -> Result<(), PlcError> {
    let pts = |t: [u32; 3]| t.map(|v| vertices[v as usize]);
    let (fi, _, ti) = topo.tris[i];
    let (fj, _, tj) = topo.tris[j];
    if fi == fj {
        return Ok(());
    }
    // Report the pair in a fixed order: lower facet first.
    let ((fa, ta), (fb, tb)) = if fi < fj {
        ((fi, ti), (fj, tj))
    } else {
        ((fj, tj), (fi, ti))
    };
    match triangle_contact(ta, pts(ta), tb, pts(tb)) {
        Contact::Clean => Ok(()),
        Contact::Clash => Err(PlcError::FacetsIntersect {
            facets: [fa as usize, fb as usize],
            triangles: [ta, tb],
        }),
        Contact::SharedEdge(e) => {
            if topo.is_segment_of(e, fa) && topo.is_segment_of(e, fb) {
                Ok(())
            } else {
                Err(PlcError::FacetsMeetOffSegment {
                    facets: [fa as usize, fb as usize],
                    edge: e,
                })
            }
        }
    }
}

fn boxes_overlap(a: &Box3, b: &Box3) -> bool {
    !(b.0.cmpgt(a.1).any() || b.1.cmplt(a.0).any())
}

/// The first failing pair in sort-and-sweep order along the axis of largest spread (the
/// order the error messages have always followed).
fn first_error_by_sweep(
    vertices: &[DVec3],
    topo: &Topology,
    boxes: &[Box3],
) -> Result<(), PlcError> {
    let axis = sweep_axis(boxes);
    let mut order: Vec<usize> = (0..boxes.len()).collect();
    order.sort_by(|&i, &j| boxes[i].0[axis].total_cmp(&boxes[j].0[axis]));
    let mut active: Vec<usize> = Vec::new();
    for &i in &order {
        let lo = boxes[i].0;
        active.retain(|&j| boxes[j].1[axis] >= lo[axis]);
        for &j in &active {
            if boxes_overlap(&boxes[i], &boxes[j]) {
                check_pair(vertices, topo, i, j)?;
            }
        }
        active.push(i);
    }
    Ok(())
}

/// A uniform grid of cells about the mean box size; each box listed in every cell it meets.
struct BoxGrid {
    lo: DVec3,
    /// Cells per unit length along each axis.
    scale: DVec3,
    dims: [usize; 3],
    /// Each box's cells.
    ranges: Vec<CellRange>,
    /// Box ids by cell (cell c holds `ids[start[c]..start[c + 1]]`).
    start: Vec<usize>,
    ids: Vec<u32>,
}

impl BoxGrid {
    fn new(boxes: &[Box3]) -> BoxGrid {
        let (lo, hi) = boxes.iter().fold(
            (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
            |(lo, hi), b| (lo.min(b.0), hi.max(b.1)),
        );
        let n = boxes.len().max(1);
        let mean_size = boxes.iter().map(|b| (b.1 - b.0).max_element()).sum::<f64>() / n as f64;
        let extent = (hi - lo).max(DVec3::ZERO);
        // Cells of about the mean box size, at most ~4 per box in all.
        let mut cell = mean_size.max(extent.max_element() * 1e-6);
        let cells_for = |cell: f64| {
            extent
                .to_array()
                .map(|e| ((e / cell).ceil() as usize).max(1))
        };
        while cell > 0.0 && cells_for(cell).iter().product::<usize>() > 4 * n {
            cell *= 1.5;
        }
        let dims = if cell > 0.0 {
            cells_for(cell)
        } else {
            [1, 1, 1]
        };
        let scale = DVec3::from_array(std::array::from_fn(|a| {
            if extent[a] > 0.0 {
                dims[a] as f64 / extent[a]
            } else {
                0.0
            }
        }));
        let mut grid = BoxGrid {
            lo,
            scale,
            dims,
            ranges: Vec::new(),
            start: vec![0; dims.iter().product::<usize>() + 1],
            ids: Vec::new(),
        };
        grid.ranges = boxes.iter().map(|b| grid.range(b)).collect();
        grid.fill();
        grid
    }

    /// Lists every box in the cells it meets (counting sort by cell).
    fn fill(&mut self) {
        let mut count = vec![0; self.start.len()];
        for r in &self.ranges {
            for_cells(self.dims, r, |c| count[c + 1] += 1);
        }
        for c in 1..count.len() {
            count[c] += count[c - 1];
        }
        self.ids = vec![0; count[count.len() - 1]];
        self.start.clone_from(&count);
        for (i, r) in self.ranges.iter().enumerate() {
            for_cells(self.dims, r, |c| {
                self.ids[count[c]] = i as u32;
                count[c] += 1;
            });
        }
    }

    /// The cell range of a box along each axis (inclusive), clamped to the grid.
    fn range(&self, b: &Box3) -> CellRange {
        std::array::from_fn(|a| {
            let cell = |x: f64| {
                let c = ((x - self.lo[a]) * self.scale[a]).floor();
                (c.max(0.0) as usize).min(self.dims[a] - 1)
            };
            [cell(b.0[a]), cell(b.1[a])]
        })
    }

    fn index(&self, x: usize, y: usize, z: usize) -> usize {
        x + self.dims[0] * (y + self.dims[1] * z)
    }

    /// Calls `f(i, j)` once for every pair of overlapping boxes: in the first cell (lowest
    /// index along each axis) that both ranges share.
    fn for_each_overlap(&self, boxes: &[Box3], mut f: impl FnMut(usize, usize)) {
        for z in 0..self.dims[2] {
            for y in 0..self.dims[1] {
                for x in 0..self.dims[0] {
                    let c = self.index(x, y, z);
                    let here = &self.ids[self.start[c]..self.start[c + 1]];
                    for (k, &i) in here.iter().enumerate() {
                        for &j in &here[k + 1..] {
                            let (i, j) = (i as usize, j as usize);
                            let (ri, rj) = (&self.ranges[i], &self.ranges[j]);
                            let first = [x, y, z]
                                .iter()
                                .enumerate()
                                .all(|(a, &at)| at == ri[a][0].max(rj[a][0]));
                            if first && boxes_overlap(&boxes[i], &boxes[j]) {
                                f(i, j);
                            }
                        }
                    }
                }
            }
        }
    }
}

/// Calls `f` with every cell of a range.
fn for_cells(dims: [usize; 3], r: &CellRange, mut f: impl FnMut(usize)) {
    for z in r[2][0]..=r[2][1] {
        for y in r[1][0]..=r[1][1] {
            for x in r[0][0]..=r[0][1] {
                f(x + dims[0] * (y + dims[1] * z));
            }
        }
    }
}

/// The axis along which the boxes are most spread out (fewest overlaps to sweep).
fn sweep_axis(boxes: &[Box3]) -> usize {
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

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The grid yields every overlapping pair exactly once: against all pairs, on boxes of
    /// mixed sizes, flat ones and ones touching exactly (shared grid coordinates).
    #[test]
    fn grid_finds_every_overlapping_pair_once() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(3);
        for round in 0..20 {
            let n = 50 + 40 * round;
            let boxes: Vec<Box3> = (0..n)
                .map(|_| {
                    let lo = DVec3::new(
                        rng.gen_range(0..20) as f64 * 0.5,
                        rng.gen_range(0..20) as f64 * 0.5,
                        if round % 4 == 0 {
                            0.0
                        } else {
                            rng.gen_range(0.0..10.0)
                        },
                    );
                    let size = DVec3::new(
                        rng.gen_range(0..4) as f64 * 0.5,
                        rng.gen_range(0.0..2.0),
                        if round % 4 == 0 {
                            0.0
                        } else {
                            rng.gen_range(0.0..3.0)
                        },
                    );
                    (lo, lo + size)
                })
                .collect();
            let mut got = Vec::new();
            BoxGrid::new(&boxes).for_each_overlap(&boxes, |i, j| got.push([i.min(j), i.max(j)]));
            got.sort_unstable();
            let mut expected = Vec::new();
            for i in 0..n {
                for j in i + 1..n {
                    if boxes_overlap(&boxes[i], &boxes[j]) {
                        expected.push([i, j]);
                    }
                }
            }
            assert_eq!(got, expected, "round {round}");
        }
    }
}
