//! The figures reported after every run: counts, achieved quality and size conformity.

use super::quality::SPACING_BATCH;
use super::{MeshError, Params, Report, Spacing};
use crate::geom::TetQuality;
use crate::mesh::TetMesh;

/// A mesh's counts and shape figures (rho, sigma, dihedral extremes, tets below 5/10/15/20
/// degrees), accumulated tet by tet: the refinement's report and the improvement's re-measure
/// ([`crate::improve::update_report`]) take them the same way.
pub(crate) struct Shapes {
    max_rho: f64,
    min_sigma: f64,
    min_dihedral: f64,
    max_dihedral: f64,
    below: [usize; 4],
}

impl Shapes {
    pub fn new() -> Shapes {
        Shapes {
            max_rho: 0.0,
            min_sigma: f64::INFINITY,
            min_dihedral: 180.0,
            max_dihedral: 0.0,
            below: [0; 4],
        }
    }

    pub fn add(&mut self, q: &TetQuality) {
        self.max_rho = self.max_rho.max(q.rho);
        self.min_sigma = self.min_sigma.min(q.sigma);
        self.min_dihedral = self.min_dihedral.min(q.min_dihedral);
        self.max_dihedral = self.max_dihedral.max(q.max_dihedral);
        for (k, limit) in [5.0, 10.0, 15.0, 20.0].iter().enumerate() {
            if q.min_dihedral < *limit {
                self.below[k] += 1;
            }
        }
    }

    /// Writes the figures, and `mesh`'s counts, into `r` (an empty mesh: sigma and the
    /// smallest dihedral angle 0).
    pub fn write(&self, mesh: &TetMesh, r: &mut Report) {
        let mut used = vec![false; mesh.vertices.len()];
        mesh.tets
            .iter()
            .flatten()
            .for_each(|&v| used[v as usize] = true);
        r.n_vertices = used.iter().filter(|&&u| u).count();
        r.n_tets = mesh.tets.len();
        r.n_boundary_faces = mesh.boundary.len();
        r.max_rho = self.max_rho;
        r.max_dihedral_deg = self.max_dihedral;
        r.tets_below_deg = self.below;
        (r.min_sigma, r.min_dihedral_deg) = if mesh.tets.is_empty() {
            (0.0, 0.0)
        } else {
            (self.min_sigma, self.min_dihedral)
        };
    }
}

/// Measures `mesh` (tets only; timings and completion are filled in by the caller). Tets that
/// miss a bound of `params` are counted in `n_bad_near_acute` when `near_small_angle(tet)` says so;
/// the others are returned.
pub fn measure(
    mesh: &TetMesh,
    spacing: &dyn Spacing,
    params: &Params,
    near_small_angle: &dyn Fn(&[u32; 4]) -> bool,
) -> Result<(Report, usize), MeshError> {
    let mut bad_elsewhere = 0;
    let mut r = Report::default();
    let mut shapes = Shapes::new();
    let p = |v: u32| mesh.vertices[v as usize];
    // The spacing is evaluated in batches of `SPACING_BATCH` points (one `at_many` call each).
    // The tets' measures are taken a block of batches at a time on the run's threads
    // (`crate::parallel::map_collect`: in tet order) and used in order, so every figure is the
    // same for every thread count.
    let mut centres = Vec::with_capacity(SPACING_BATCH);
    let mut radii = Vec::with_capacity(SPACING_BATCH);
    let mut f = Vec::with_capacity(SPACING_BATCH);
    for block in mesh.tets.chunks(MEASURE_BLOCK) {
        let measured = crate::parallel::map_collect(block, |t| {
            TetQuality::of(p(t[0]), p(t[1]), p(t[2]), p(t[3]))
        });
        for (chunk, qs) in block
            .chunks(SPACING_BATCH)
            .zip(measured.chunks(SPACING_BATCH))
        {
            centres.clear();
            radii.clear();
            for (t, q) in chunk.iter().zip(qs) {
                shapes.add(q);
                if q.rho > params.rho0
                    || q.sigma < params.sigma0
                    || q.min_dihedral < params.min_dihedral
                {
                    if near_small_angle(t) {
                        r.n_bad_near_acute += 1;
                    } else {
                        bad_elsewhere += 1;
                    }
                }
                if let Some(c) = q.circumcenter {
                    centres.push(c);
                    radii.push(q.circumradius);
                }
            }
            checked_batch(spacing, &centres, &mut f)?;
            for (&radius, &f) in radii.iter().zip(&f) {
                r.max_size_ratio = r.max_size_ratio.max(radius / f);
            }
        }
    }
    let edges = unique_edges(&mesh.tets, mesh.vertices.len());
    let mut ratios = Vec::with_capacity(edges.len());
    let mut mids = Vec::with_capacity(SPACING_BATCH);
    for chunk in edges.chunks(SPACING_BATCH) {
        mids.clear();
        mids.extend(chunk.iter().map(|&(a, b)| (p(a) + p(b)) * 0.5));
        checked_batch(spacing, &mids, &mut f)?;
        for (&(a, b), &f) in chunk.iter().zip(&f) {
            ratios.push(p(a).distance(p(b)) / f);
        }
    }
    if !ratios.is_empty() {
        // The element a full sort would put at len / 2, without the sort.
        let mid = ratios.len() / 2;
        let (below, median, above) = ratios.select_nth_unstable_by(mid, f64::total_cmp);
        r.edge_ratio_median = *median;
        r.edge_ratio_min = below.iter().copied().fold(*median, f64::min);
        r.edge_ratio_max = above.iter().copied().fold(*median, f64::max);
    }
    shapes.write(mesh, &mut r);
    Ok((r, bad_elsewhere))
}

/// Tets measured on the run's threads at a time in [`measure`] (16 spacing batches).
const MEASURE_BLOCK: usize = 16 * SPACING_BATCH;

/// Every edge of `tets` once, as (smaller, larger) vertex id, in lexicographic order: a counting
/// sort by the smaller id, then each vertex's few larger neighbours sorted (a third of the
/// instructions of sorting all six edges of every tet).
fn unique_edges(tets: &[[u32; 4]], n_vertices: usize) -> Vec<(u32, u32)> {
    const PAIRS: [(usize, usize); 6] = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)];
    let ends = |t: &[u32; 4], (i, j): (usize, usize)| (t[i].min(t[j]), t[i].max(t[j]));
    let mut start = vec![0usize; n_vertices + 1];
    for t in tets {
        for pair in PAIRS {
            start[ends(t, pair).0 as usize + 1] += 1;
        }
    }
    for v in 0..n_vertices {
        start[v + 1] += start[v];
    }
    let mut next = start.clone();
    let mut larger = vec![0u32; start[n_vertices]];
    for t in tets {
        for pair in PAIRS {
            let (a, b) = ends(t, pair);
            larger[next[a as usize]] = b;
            next[a as usize] += 1;
        }
    }
    let mut edges = Vec::with_capacity(larger.len() / 4);
    for a in 0..n_vertices {
        let list = &mut larger[start[a]..start[a + 1]];
        list.sort_unstable();
        let mut last = None;
        for &b in list.iter() {
            if last != Some(b) {
                edges.push((a as u32, b));
                last = Some(b);
            }
        }
    }
    edges
}

/// The spacing at `points` into `out`, in one `at_many` call; the first value that is not
/// finite and positive is an error naming its point.
fn checked_batch(
    spacing: &dyn Spacing,
    points: &[glam::DVec3],
    out: &mut Vec<f64>,
) -> Result<(), MeshError> {
    out.clear();
    out.resize(points.len(), f64::NAN);
    if !points.is_empty() {
        spacing.at_many(points, out);
    }
    match points
        .iter()
        .zip(out.iter())
        .find(|(_, &f)| !(f.is_finite() && f > 0.0))
    {
        Some((&point, &value)) => Err(MeshError::BadSpacing { point, value }),
        None => Ok(()),
    }
}

impl Report {
    /// Measures each region of `mesh` and its interfaces against the input's regions the
    /// surface mode left in `input_regions` (none: nothing measured).
    pub fn measure_regions(&mut self, mesh: &TetMesh) {
        let Some(input) = self.input_regions.take() else {
            return;
        };
        let mut regions: Vec<super::RegionReport> = input
            .volumes
            .iter()
            .map(|&(attribute, input_volume)| super::RegionReport {
                attribute,
                input_volume,
                ..Default::default()
            })
            .collect();
        // Interfaces only where there are two attributes (the face map costs 100 bytes a tet).
        let several = mesh.tet_regions.iter().any(|&a| a != mesh.tet_regions[0]);
        let mut faces: rustc_hash::FxHashMap<[u32; 3], i32> = Default::default();
        let mut interface_area = 0.0;
        for (t, &a) in mesh.tets.iter().zip(&mesh.tet_regions) {
            let p = t.map(|v| mesh.vertices[v as usize]);
            let r = match regions.iter().position(|r| r.attribute == a) {
                Some(r) => r,
                None => {
                    regions.push(super::RegionReport {
                        attribute: a,
                        ..Default::default()
                    });
                    regions.len() - 1
                }
            };
            regions[r].tets += 1;
            regions[r].volume += (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
            for k in (0..4).filter(|_| several) {
                let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
                f.sort_unstable();
                if let Some(b) = faces.insert(f, a) {
                    if b != a {
                        let [x, y, z] = f.map(|v| mesh.vertices[v as usize]);
                        interface_area += (y - x).cross(z - x).length() / 2.0;
                    }
                }
            }
        }
        for r in &mut regions {
            r.relative_volume_difference = if r.input_volume > 0.0 {
                (r.volume - r.input_volume) / r.input_volume
            } else {
                f64::NAN
            };
        }
        regions.sort_by_key(|r| r.attribute);
        self.regions = regions;
        self.interface_area = interface_area;
        self.input_interface_area = input.interface_area;
    }

    /// Takes the figures [`measure`] fills in (counts, shapes, sizes, bad tets near small
    /// angles) from `m`, a report it made; the rest of `self` stays.
    pub fn take_measures(&mut self, m: Report) {
        self.n_vertices = m.n_vertices;
        self.n_tets = m.n_tets;
        self.n_boundary_faces = m.n_boundary_faces;
        self.max_rho = m.max_rho;
        self.min_sigma = m.min_sigma;
        self.min_dihedral_deg = m.min_dihedral_deg;
        self.max_dihedral_deg = m.max_dihedral_deg;
        self.tets_below_deg = m.tets_below_deg;
        self.max_size_ratio = m.max_size_ratio;
        self.edge_ratio_min = m.edge_ratio_min;
        self.edge_ratio_median = m.edge_ratio_median;
        self.edge_ratio_max = m.edge_ratio_max;
        self.n_bad_near_acute = m.n_bad_near_acute;
    }

    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let mut row = |k: &str, v: String| s.push_str(&format!("  {k:<28} {v}\n"));
        row("vertices", self.n_vertices.to_string());
        row("tets", self.n_tets.to_string());
        row("boundary triangles", self.n_boundary_faces.to_string());
        row(
            "time recovery / refine (s)",
            format!(
                "{:.3} / {:.3}",
                self.seconds_recovery, self.seconds_refinement
            ),
        );
        row(
            "time improvement (s)",
            format!(
                "{:.3} (flips {}, moves {}, insertions {}, deletions {}, rho0 vetoes {} / gave way {}{})",
                self.seconds_improvement,
                self.improvement.edge_removals
                    + self.improvement.face_removals
                    + self.improvement.multi_face_removals
                    + self.improvement.boundary_flips,
                self.improvement.smoothed,
                self.improvement.insertions,
                self.improvement.deletions,
                self.improvement.rho_vetoes,
                self.improvement.rho_yields,
                if self.delaunay { ", Delaunay" } else { "" }
            ),
        );
        row(
            "dihedral before improvement",
            format!(
                "{:.2} / {:.2}",
                self.dihedral_before_improve_deg[0], self.dihedral_before_improve_deg[1]
            ),
        );
        row("max radius-edge rho", format!("{:.4}", self.max_rho));
        row("min sigma V/L^3", format!("{:.4}", self.min_sigma));
        row(
            "dihedral min / max (deg)",
            format!(
                "{:.2} / {:.2}",
                self.min_dihedral_deg, self.max_dihedral_deg
            ),
        );
        row(
            "tets below 5/10/15/20 deg",
            format!("{:?}", self.tets_below_deg),
        );
        row("max R / f(c)", format!("{:.3}", self.max_size_ratio));
        row(
            "edge / f(mid) min/med/max",
            format!(
                "{:.3} / {:.3} / {:.3}",
                self.edge_ratio_min, self.edge_ratio_median, self.edge_ratio_max
            ),
        );
        row("acute input vertices", self.n_acute_angles.to_string());
        row(
            "bad tets left near acute",
            self.n_bad_near_acute.to_string(),
        );
        row("refinement refusals", self.refusals.summary());
        if self.regions.len() > 1 {
            for r in &self.regions {
                row(
                    &format!("region {}: tets / volume", r.attribute),
                    format!(
                        "{} / {:.6e} (input {:.6e}, {:+.3e})",
                        r.tets, r.volume, r.input_volume, r.relative_volume_difference
                    ),
                );
            }
            row(
                "interface area / input",
                format!(
                    "{:.6e} / {:.6e}",
                    self.interface_area, self.input_interface_area
                ),
            );
        }
        row(
            "complete",
            match &self.stop_reason {
                None => "true".to_string(),
                Some(r) => format!("{} ({r})", self.complete),
            },
        );
        s
    }
}
