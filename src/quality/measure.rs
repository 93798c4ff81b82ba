//! One pass over a mesh: every tet measured with `geom`'s definitions, then the summary figures.

use super::QualityError;
use crate::geom::{self, TetQuality};
use crate::mesh::TetMesh;
use serde::Serialize;

/// Thresholds of the "tets below" counts (per-tet minimum dihedral angle, degrees).
pub const BELOW_DEG: [f64; 4] = [5.0, 10.0, 15.0, 20.0];
/// Thresholds of the "tets above" counts (per-tet maximum dihedral angle, degrees).
pub const ABOVE_DEG: [f64; 4] = [160.0, 165.0, 170.0, 175.0];
/// Width (degrees) of the bins of [`MeshQuality::min_dihedral_histogram`].
pub const MIN_BIN_DEG: f64 = 5.0;
/// Number of those bins: a tet's smallest dihedral angle is at most arccos(1/3) = 70.53 degrees.
pub const MIN_BINS: usize = 15;

/// Quality figures of a tet mesh (see the module documentation for the definitions).
///
/// Percentiles are nearest-rank: `p5` is the smallest value with at least 5 % of the tets at or
/// below it. Medians and extremes of rho and aspect are +∞ when a zero-volume tet is among
/// them (serialised as `null` in JSON).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MeshQuality {
    /// Vertices in the mesh (referenced by a tet or not).
    pub n_vertices: usize,
    /// Vertices referenced by at least one tet.
    pub n_used_vertices: usize,
    pub n_tets: usize,
    pub n_boundary_faces: usize,
    /// Distinct tet region attributes.
    pub n_regions: usize,
    /// Tets with exact `orient3d < 0`.
    pub n_inverted: usize,
    /// Tets with exact `orient3d == 0` (flat, including repeated vertices).
    pub n_zero_volume: usize,
    /// Sum of the signed tet volumes.
    pub volume: f64,
    pub shortest_edge: f64,
    pub longest_edge: f64,
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// Per-tet minimum dihedral angle: 1st, 5th percentile and median.
    pub min_dihedral_p1_deg: f64,
    pub min_dihedral_p5_deg: f64,
    pub min_dihedral_median_deg: f64,
    /// Per-tet maximum dihedral angle: median, 95th and 99th percentile.
    pub max_dihedral_median_deg: f64,
    pub max_dihedral_p95_deg: f64,
    pub max_dihedral_p99_deg: f64,
    /// Tets whose minimum dihedral angle is below 5, 10, 15, 20 degrees ([`BELOW_DEG`]).
    pub tets_below_deg: [usize; 4],
    /// Tets whose maximum dihedral angle is above 160, 165, 170, 175 degrees ([`ABOVE_DEG`]).
    pub tets_above_deg: [usize; 4],
    /// Radius-edge ratio R/L.
    pub max_rho: f64,
    pub median_rho: f64,
    /// sigma = |V|/L³.
    pub min_sigma: f64,
    pub median_sigma: f64,
    /// Aspect ratio R/(3r).
    pub max_aspect: f64,
    pub median_aspect: f64,
    /// Index of the tet with the smallest minimum dihedral angle (the first one on ties).
    pub worst_tet: usize,
    /// Per-tet minimum dihedral angle in bins of [`MIN_BIN_DEG`] degrees from 0.
    pub min_dihedral_histogram: [usize; MIN_BINS],
}

/// Checks that every tet and boundary triangle refers to an existing vertex and that the
/// coordinates are finite, so measuring cannot index out of range or compute NaN.
pub fn check(mesh: &TetMesh) -> Result<(), QualityError> {
    let n = mesh.vertices.len();
    for (tet, t) in mesh.tets.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= n) {
            return Err(QualityError::VertexOutOfRange {
                element: "tet",
                index: tet,
                vertex,
                n_vertices: n,
            });
        }
    }
    for (tri, t) in mesh.boundary.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= n) {
            return Err(QualityError::VertexOutOfRange {
                element: "boundary triangle",
                index: tri,
                vertex,
                n_vertices: n,
            });
        }
    }
    if let Some(vertex) = mesh.vertices.iter().position(|p| !p.is_finite()) {
        return Err(QualityError::NotFinite { vertex });
    }
    if mesh.tets.is_empty() {
        return Err(QualityError::NoTets);
    }
    Ok(())
}

/// Measures `mesh`. Errors: an out-of-range vertex id, a non-finite coordinate, no tets.
pub fn measure(mesh: &TetMesh) -> Result<MeshQuality, QualityError> {
    check(mesh)?;
    Ok(measure_each(mesh, None))
}

/// Every tet's measures, in tet order (errors as [`measure`]): for a caller that needs them
/// too, to measure them once ([`measure_with`]).
pub fn per_tet(mesh: &TetMesh) -> Result<Vec<TetQuality>, QualityError> {
    check(mesh)?;
    let p = |v: u32| mesh.vertices[v as usize];
    // On the run's threads (`crate::parallel`), in tet order.
    Ok(crate::parallel::map_collect(&mesh.tets, |t| {
        TetQuality::of(p(t[0]), p(t[1]), p(t[2]), p(t[3]))
    }))
}

/// [`measure`] from the tets' measures [`per_tet`] took (measured again if they are not as
/// many as the tets).
pub fn measure_with(mesh: &TetMesh, per_tet: &[TetQuality]) -> Result<MeshQuality, QualityError> {
    check(mesh)?;
    if per_tet.len() != mesh.tets.len() {
        return measure(mesh);
    }
    Ok(measure_each(mesh, Some(per_tet)))
}

/// The figures of [`MeshQuality`] from each tet's measures (`per_tet`, or measured here a block
/// at a time on the run's threads), in one pass over the tets. The percentiles are taken from f32 copies of the five measures that
/// have them (20 bytes a tet instead of keeping every `TetQuality`, 80): exact to about 7
/// digits, more than the tables print.
fn measure_each(mesh: &TetMesh, per_tet: Option<&[TetQuality]>) -> MeshQuality {
    let n = mesh.tets.len();
    let p = |v: u32| mesh.vertices[v as usize];
    let mut used = vec![false; mesh.vertices.len()];
    let (mut min_d, mut max_d) = (Vec::with_capacity(n), Vec::with_capacity(n));
    let (mut rho, mut sigma, mut aspect) = (
        Vec::with_capacity(n),
        Vec::with_capacity(n),
        Vec::with_capacity(n),
    );
    let mut q = MeshQuality {
        n_vertices: mesh.vertices.len(),
        n_used_vertices: 0,
        n_tets: n,
        n_boundary_faces: mesh.boundary.len(),
        n_regions: {
            let mut r = mesh.tet_regions.clone();
            r.sort_unstable();
            r.dedup();
            r.len()
        },
        n_inverted: 0,
        n_zero_volume: 0,
        volume: 0.0,
        shortest_edge: f64::INFINITY,
        longest_edge: 0.0,
        min_dihedral_deg: 180.0,
        max_dihedral_deg: 0.0,
        min_dihedral_p1_deg: 0.0,
        min_dihedral_p5_deg: 0.0,
        min_dihedral_median_deg: 0.0,
        max_dihedral_median_deg: 0.0,
        max_dihedral_p95_deg: 0.0,
        max_dihedral_p99_deg: 0.0,
        tets_below_deg: [0; 4],
        tets_above_deg: [0; 4],
        max_rho: 0.0,
        median_rho: 0.0,
        min_sigma: f64::INFINITY,
        median_sigma: 0.0,
        max_aspect: 0.0,
        median_aspect: 0.0,
        worst_tet: 0,
        min_dihedral_histogram: [0; MIN_BINS],
    };
    // The sign decides validity, so it comes from the exact predicate itself. It, the longest
    // edge and the measures are taken on the run's threads (`crate::parallel`), a block at a
    // time in tet order; the sums below run in tet order.
    const BLOCK: usize = 1 << 16;
    for (b, block) in mesh.tets.chunks(BLOCK).enumerate() {
        let measured = crate::parallel::map_collect(block, |t| {
            let [a, b, c, d] = t.map(p);
            let m = per_tet.is_none().then(|| TetQuality::of(a, b, c, d));
            (
                geom::orient3d(a, b, c, d),
                geom::longest_edge(a, b, c, d),
                m,
            )
        });
        for (k, (t, &(det, longest, m))) in block.iter().zip(&measured).enumerate() {
            let i = b * BLOCK + k;
            t.iter().for_each(|&v| used[v as usize] = true);
            if det < 0.0 {
                q.n_inverted += 1;
            } else if det == 0.0 {
                q.n_zero_volume += 1;
            }
            let m = match (per_tet, m) {
                (Some(given), _) => given[i],
                (None, Some(m)) => m,
                (None, None) => TetQuality::of(p(t[0]), p(t[1]), p(t[2]), p(t[3])),
            };
            q.volume += m.volume;
            q.shortest_edge = q.shortest_edge.min(m.shortest_edge);
            q.longest_edge = q.longest_edge.max(longest);
            if m.min_dihedral < q.min_dihedral_deg {
                q.min_dihedral_deg = m.min_dihedral;
                q.worst_tet = i;
            }
            q.max_dihedral_deg = q.max_dihedral_deg.max(m.max_dihedral);
            for k in 0..4 {
                q.tets_below_deg[k] += usize::from(m.min_dihedral < BELOW_DEG[k]);
                q.tets_above_deg[k] += usize::from(m.max_dihedral > ABOVE_DEG[k]);
            }
            let bin = ((m.min_dihedral / MIN_BIN_DEG) as usize).min(MIN_BINS - 1);
            q.min_dihedral_histogram[bin] += 1;
            q.max_rho = q.max_rho.max(m.rho);
            q.min_sigma = q.min_sigma.min(m.sigma);
            q.max_aspect = q.max_aspect.max(m.aspect);
            min_d.push(m.min_dihedral as f32);
            max_d.push(m.max_dihedral as f32);
            rho.push(m.rho as f32);
            sigma.push(m.sigma as f32);
            aspect.push(m.aspect as f32);
        }
    }
    q.n_used_vertices = used.iter().filter(|&&u| u).count();
    q.median_rho = percentile_f32(&mut rho, 50.0);
    q.median_sigma = percentile_f32(&mut sigma, 50.0);
    q.median_aspect = percentile_f32(&mut aspect, 50.0);
    q.min_dihedral_p1_deg = percentile_f32(&mut min_d, 1.0);
    q.min_dihedral_p5_deg = percentile_f32(&mut min_d, 5.0);
    q.min_dihedral_median_deg = percentile_f32(&mut min_d, 50.0);
    q.max_dihedral_median_deg = percentile_f32(&mut max_d, 50.0);
    q.max_dihedral_p95_deg = percentile_f32(&mut max_d, 95.0);
    q.max_dihedral_p99_deg = percentile_f32(&mut max_d, 99.0);
    q
}

/// [`percentile`] of f32 values, as f64.
fn percentile_f32(values: &mut [f32], p: f64) -> f64 {
    let n = values.len();
    let rank = ((p / 100.0 * n as f64).ceil() as usize).clamp(1, n);
    f64::from(*values.select_nth_unstable_by(rank - 1, f32::total_cmp).1)
}

/// Nearest-rank percentile of a non-empty slice (reorders it): the value at rank
/// ceil(p/100 · n) of the sorted values, rank 1 at least.
pub fn percentile(values: &mut [f64], p: f64) -> f64 {
    let n = values.len();
    let rank = ((p / 100.0 * n as f64).ceil() as usize).clamp(1, n);
    *values.select_nth_unstable_by(rank - 1, f64::total_cmp).1
}

/// Counts of all six dihedral angles of every tet in 1-degree bins [k, k+1), k = 0..179
/// (180 itself falls in the last bin): the picture's histogram.
pub fn dihedral_histogram(mesh: &TetMesh) -> Result<Vec<usize>, QualityError> {
    check(mesh)?;
    let mut bins = vec![0usize; 180];
    for t in &mesh.tets {
        let [a, b, c, d] = t.map(|v| mesh.vertices[v as usize]);
        for x in geom::dihedral_angles(a, b, c, d) {
            bins[(x.max(0.0) as usize).min(179)] += 1;
        }
    }
    Ok(bins)
}
