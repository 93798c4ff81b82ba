//! The report's surface figures, measured on the output mesh: two-sided sampled Hausdorff
//! distance between its boundary and the input surface, how far input feature edges are from
//! the output's feature edges, the volume difference, and the bad tets near small corners.

use super::curves::point_segment_distance;
use super::Remeshed;
use crate::delaunay::hilbert::hilbert_sort;
use crate::geom::{min_max_dihedral, radius_edge_ratio, volume};
use crate::mesh::TetMesh;
use crate::run::params::Params;
use crate::run::report::SurfaceReport;
use crate::surface::distance::samples_per_edge_at_least;
use crate::surface::oracle::SurfaceOracle;
use crate::surface::InputSurface;
use glam::DVec3;

/// Sample spacing of the Hausdorff distance as a share of the bounding-box diagonal (samples
/// as close as the distance bound would cost millions of closest-point queries); every
/// triangle is also cut into at least [`MIN_PIECES`] along each edge, so each output triangle
/// is sampled inside, where it is farthest from a curved input.
const HAUSDORFF_SPACING: f64 = 1.0 / 200.0;
const MIN_PIECES: usize = 3;

/// The points of `surface` where the Hausdorff distance is sampled.
pub(super) fn hausdorff_samples(surface: &InputSurface) -> Vec<DVec3> {
    let spacing = HAUSDORFF_SPACING * surface.bbox_diagonal();
    samples_per_edge_at_least(surface, spacing, MIN_PIECES)
}

/// Largest distance from `samples` (of one surface, [`hausdorff_samples`]) to the surface
/// behind `oracle`.
fn one_sided(samples: &[DVec3], oracle: &SurfaceOracle) -> f64 {
    let mut worst: f64 = 0.0;
    // Consecutive samples come from one triangle: the last triangle found is tried first.
    let mut hint = None;
    for &p in samples {
        if let Some(d) = oracle.distance_beyond_hinted(p, worst, &mut hint) {
            worst = worst.max(d);
        }
    }
    worst
}

/// Points per input feature edge where its distance to the output's feature edges is taken.
const FEATURE_EDGE_SAMPLES: usize = 8;

/// The surface figures of `mesh`.
pub fn surface_report(r: &Remeshed, mesh: &TetMesh) -> SurfaceReport {
    // The output boundary: the remeshed triangles where the improvement left their vertices.
    let out = output_surface(mesh);
    let out_volume: f64 = mesh
        .tets
        .iter()
        .map(|t| {
            let [a, b, c, d] = t.map(|v| mesh.vertices[v as usize]);
            volume(a, b, c, d)
        })
        .sum();
    let mut out_samples = hausdorff_samples(&out);
    if let Some(repaired) = &r.repaired {
        // Where the boundary spans a hole no input is near: those samples measure nothing.
        out_samples.retain(|&p| {
            r.oracle.distance_beyond(p, r.distance).is_none() || !repaired.labels.spans_at(p)
        });
    }
    let repair = r.repair_counts.as_ref().map(|counts| {
        let (boundary_area, spanned_area) = spanned_area(&out, &r.oracle, r.distance);
        crate::surface::repair::Defects {
            boundary_area,
            spanned_area,
            ..counts.clone()
        }
    });
    SurfaceReport {
        surface_distance: r.distance,
        hausdorff_input_to_output: one_sided(&r.input_samples, &SurfaceOracle::for_distances(&out)),
        hausdorff_output_to_input: one_sided(&out_samples, &r.oracle),
        feature_distance: feature_distance(r, &mesh.vertices),
        relative_volume_difference: if r.input_volume > 0.0 {
            (out_volume - r.input_volume) / r.input_volume
        } else {
            0.0
        },
        n_feature_edges: r.features.edges.len(),
        n_feature_polylines: r.features.polylines.len(),
        n_noise_edges: r.noise.edges,
        n_noise_curves: r.noise.curves,
        n_corners: r.n_corners,
        n_patches: r.features.n_patches,
        n_small_corners: r.small_corners.len(),
        n_bad_near_small_corners: 0,
        max_rho_away_from_small_corners: 0.0,
        n_surface_vertices: r.boundary.vertices.len(),
        n_surface_triangles: r.boundary.facets.len(),
        seconds_surface: r.seconds,
        repair,
    }
}

/// The area of `out`, and of its triangles whose centroid lies farther than `bound` from the
/// surface behind `oracle`.
fn spanned_area(out: &InputSurface, oracle: &SurfaceOracle, bound: f64) -> (f64, f64) {
    (0..out.triangles.len()).fold((0.0, 0.0), |(all, far), t| {
        let [a, b, c] = out.corners(t);
        let area = 0.5 * (b - a).cross(c - a).length();
        let spans = oracle.distance_beyond((a + b + c) / 3.0, bound).is_some();
        (all + area, far + if spans { area } else { 0.0 })
    })
}

/// The output boundary, its triangles along a Hilbert curve: consecutive samples then lie
/// close together, so the last triangle found mostly holds the next one too (the mesh's own
/// order jumps about) and the distance queries keep their memory warm. The samples, and so
/// the distances, do not depend on the order.
fn output_surface(mesh: &TetMesh) -> InputSurface {
    let centroids: Vec<DVec3> = mesh
        .boundary
        .iter()
        .map(|t| t.iter().map(|&v| mesh.vertices[v as usize]).sum::<DVec3>() / 3.0)
        .collect();
    let mut order: Vec<u32> = (0..mesh.boundary.len() as u32).collect();
    hilbert_sort(&centroids, &mut order);
    let triangles = order.iter().map(|&t| mesh.boundary[t as usize]).collect();
    InputSurface::from_triangles(mesh.vertices.clone(), triangles)
}

/// Largest distance from a sample of an input feature edge to the nearest output feature edge.
fn feature_distance(r: &Remeshed, positions: &[DVec3]) -> f64 {
    let segs: Vec<(DVec3, DVec3)> = r
        .feature_edges
        .iter()
        .map(|e| e.map(|v| positions[v as usize]))
        .map(|[a, b]| (a, b))
        .collect();
    let grid = SegmentGrid::new(&segs);
    let mut worst: f64 = 0.0;
    for e in &r.features.edges {
        let [a, b] = e.map(|v| r.surface.vertices[v as usize]);
        for k in 0..=FEATURE_EDGE_SAMPLES {
            let p = a.lerp(b, k as f64 / FEATURE_EDGE_SAMPLES as f64);
            worst = worst.max(grid.nearest(&segs, p));
        }
    }
    if segs.is_empty() && !r.features.edges.is_empty() {
        return f64::INFINITY;
    }
    worst
}

/// Of the tets with a vertex in a small corner's protecting ball (its influence: the ball the
/// surface mesher leaves alone and the report's completeness excludes): how many miss the
/// refinement's radius-edge or dihedral bound; and the largest radius-edge ratio of all the
/// other tets.
pub fn small_corner_figures(
    mesh: &TetMesh,
    corners: &[(DVec3, f64)],
    params: &Params,
) -> (usize, f64) {
    let mut bad_near = 0;
    let mut max_rho_away: f64 = 0.0;
    for t in &mesh.tets {
        let p = t.map(|v| mesh.vertices[v as usize]);
        let rho = radius_edge_ratio(p[0], p[1], p[2], p[3]);
        let near = p.iter().any(|q| {
            corners
                .iter()
                .any(|(c, r)| (*q - *c).length_squared() <= r * r)
        });
        if !near {
            max_rho_away = max_rho_away.max(rho);
            continue;
        }
        let (lo, _) = min_max_dihedral(p[0], p[1], p[2], p[3]);
        if lo < params.min_dihedral || rho > params.rho0 {
            bad_near += 1;
        }
    }
    (bad_near, max_rho_away)
}

/// Segments bucketed in a uniform grid (each in every cell its bounding box meets), for the
/// distance from a point to the nearest of them.
struct SegmentGrid {
    lo: DVec3,
    cell: f64,
    dims: [i64; 3],
    cells: rustc_hash::FxHashMap<[i64; 3], Vec<u32>>,
}

impl SegmentGrid {
    fn new(segs: &[(DVec3, DVec3)]) -> SegmentGrid {
        let (lo, hi) = segs.iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(l, h), &(a, b)| (l.min(a).min(b), h.max(a).max(b)),
        );
        let mean = segs.iter().map(|&(a, b)| a.distance(b)).sum::<f64>() / segs.len().max(1) as f64;
        // About two segments across a cell, and at most 128 cells along an axis.
        let cell = (2.0 * mean)
            .max((hi - lo).max_element() / 128.0)
            .max(1e-300);
        let mut grid = SegmentGrid {
            lo,
            cell,
            dims: [0; 3],
            cells: Default::default(),
        };
        if segs.is_empty() {
            return grid;
        }
        grid.dims = grid.at(hi).map(|c| c + 1);
        for (i, &(a, b)) in segs.iter().enumerate() {
            let (c0, c1) = (grid.at(a.min(b)), grid.at(a.max(b)));
            for x in c0[0]..=c1[0] {
                for y in c0[1]..=c1[1] {
                    for z in c0[2]..=c1[2] {
                        grid.cells.entry([x, y, z]).or_default().push(i as u32);
                    }
                }
            }
        }
        grid
    }

    fn at(&self, p: DVec3) -> [i64; 3] {
        let c = ((p - self.lo) / self.cell).floor();
        [c.x as i64, c.y as i64, c.z as i64]
    }

    /// Distance from `p` to the nearest segment (infinite when there is none): the cells in
    /// growing shells around p's cell, until the shells searched cover the distance found.
    fn nearest(&self, segs: &[(DVec3, DVec3)], p: DVec3) -> f64 {
        if self.cells.is_empty() {
            return f64::INFINITY;
        }
        let c = self.at(p);
        let mut best = f64::INFINITY;
        // Cells a point may be from the grid's box, so that the shells reach every cell.
        let reach = (0..3)
            .map(|k| c[k].abs().max((c[k] - self.dims[k]).abs()))
            .max()
            .unwrap_or(0)
            + self.dims.iter().copied().max().unwrap_or(0);
        for ring in 0..=reach {
            for x in c[0] - ring..=c[0] + ring {
                for y in c[1] - ring..=c[1] + ring {
                    for z in c[2] - ring..=c[2] + ring {
                        let on_shell = [x - c[0], y - c[1], z - c[2]]
                            .iter()
                            .any(|d| d.abs() == ring);
                        let Some(list) = on_shell.then(|| self.cells.get(&[x, y, z])).flatten()
                        else {
                            continue;
                        };
                        for &i in list {
                            let (a, b) = segs[i as usize];
                            best = best.min(point_segment_distance(p, a, b));
                        }
                    }
                }
            }
            // A segment in no cell searched lies beyond the shell: at least ring cells away.
            if best <= ring as f64 * self.cell {
                break;
            }
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};

    /// The small-corner figures split the tets at the protecting ball, as the report's
    /// completeness does: a bad tet just outside the ball is away from the corner (its rho is
    /// the largest away), one with a vertex on the ball's sphere is near it.
    #[test]
    fn small_corner_figures_split_at_the_protecting_ball() {
        // A needle (rho far above 2) and a regular tet.
        let needle = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 0.01),
        ];
        let regular = [
            DVec3::new(10.0, 0.0, 0.0),
            DVec3::new(11.0, 0.0, 0.0),
            DVec3::new(10.5, 0.75f64.sqrt(), 0.0),
            DVec3::new(10.5, 0.75f64.sqrt() / 3.0, (2.0f64 / 3.0).sqrt()),
        ];
        let vertices: Vec<DVec3> = needle.iter().chain(&regular).copied().collect();
        let mesh = TetMesh {
            vertices,
            tets: vec![[0, 1, 2, 3], [4, 5, 6, 7]],
            ..TetMesh::default()
        };
        let params = Params::default();
        let rho_needle = radius_edge_ratio(needle[0], needle[1], needle[2], needle[3]);
        let rho_regular = radius_edge_ratio(regular[0], regular[1], regular[2], regular[3]);
        assert!(rho_needle > 2.0 && rho_regular < 1.0);
        // The corner 1.5 protecting radii from the needle's nearest vertex: away.
        let corner = [(DVec3::new(-1.5, 0.0, 0.0), 1.0)];
        assert_eq!(
            small_corner_figures(&mesh, &corner, &params),
            (0, rho_needle)
        );
        // Its vertex on the ball's sphere: near, and bad.
        let corner = [(DVec3::new(-1.0, 0.0, 0.0), 1.0)];
        assert_eq!(
            small_corner_figures(&mesh, &corner, &params),
            (1, rho_regular)
        );
    }

    /// The grid's nearest distance is the brute-force minimum, bit for bit, for points near
    /// the segments and far from them.
    #[test]
    fn segment_grid_matches_brute_force() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(7);
        let mut p = || DVec3::new(rng.gen(), rng.gen(), rng.gen());
        let segs: Vec<(DVec3, DVec3)> = (0..300)
            .map(|_| {
                let a = p();
                (a, a + (p() - DVec3::splat(0.5)) * 0.1)
            })
            .collect();
        let grid = SegmentGrid::new(&segs);
        for k in 0..500 {
            let q = if k % 5 == 0 {
                p() * 6.0 - DVec3::splat(3.0)
            } else {
                p()
            };
            let brute = segs
                .iter()
                .map(|&(a, b)| point_segment_distance(q, a, b))
                .fold(f64::INFINITY, f64::min);
            assert_eq!(grid.nearest(&segs, q), brute, "{q}");
        }
        assert_eq!(
            SegmentGrid::new(&[]).nearest(&[], DVec3::ZERO),
            f64::INFINITY
        );
    }
}
