//! The figures refinement (and the approximate mode) measure on a mesh: counts, achieved
//! quality and size conformity against the spacing, into a `run::report::Report`.

use super::quality::SPACING_BATCH;
use crate::geom::TetQuality;
use crate::mesh::TetMesh;
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::{Report, Shapes};
use crate::run::spacing::Spacing;

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
    let (start, ends) = unique_edges(&mesh.tets, mesh.vertices.len());
    let mut ratios = Vec::with_capacity(ends.len());
    let mut chunk = Vec::with_capacity(SPACING_BATCH);
    let mut mids = Vec::with_capacity(SPACING_BATCH);
    let mut edges = (0..mesh.vertices.len())
        .flat_map(|a| {
            ends[start[a]..start[a + 1]]
                .iter()
                .map(move |&b| (a as u32, b))
        })
        .peekable();
    while edges.peek().is_some() {
        chunk.clear();
        chunk.extend(edges.by_ref().take(SPACING_BATCH));
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

/// Every edge of `tets` once, as lists of larger vertex ids per smaller one: the edges of
/// vertex `a` are `(a, ends[k])` for `k` in `start[a]..start[a + 1]`, in lexicographic order. A
/// counting sort by the smaller id, then each vertex's few larger neighbours sorted and
/// deduplicated in place (a third of the instructions of sorting all six edges of every tet, and
/// no second list of the edges).
fn unique_edges(tets: &[[u32; 4]], n_vertices: usize) -> (Vec<usize>, Vec<u32>) {
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
    let mut larger = vec![0u32; start[n_vertices]];
    {
        // start[a] is advanced past each id written; start[a] ends where a + 1's list begins.
        for t in tets {
            for pair in PAIRS {
                let (a, b) = ends(t, pair);
                larger[start[a as usize]] = b;
                start[a as usize] += 1;
            }
        }
        start.rotate_right(1);
        start[0] = 0;
    }
    // Compact: each list sorted and deduplicated, moved down to follow the previous one.
    let mut kept = 0;
    for a in 0..n_vertices {
        let (from, to) = (start[a], start[a + 1]);
        larger[from..to].sort_unstable();
        start[a] = kept;
        let mut last = None;
        for k in from..to {
            let b = larger[k];
            if last != Some(b) {
                larger[kept] = b;
                kept += 1;
                last = Some(b);
            }
        }
    }
    start[n_vertices] = kept;
    larger.truncate(kept);
    (start, larger)
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

#[cfg(test)]
mod tests {
    use super::unique_edges;

    #[test]
    fn unique_edges_lists_each_edge_once_in_order() {
        // Two tets sharing face (1, 2, 3), vertex 5 unused: 9 edges.
        let tets = [[0, 1, 2, 3], [3, 2, 1, 4]];
        let (start, ends) = unique_edges(&tets, 6);
        let edges: Vec<(u32, u32)> = (0..6)
            .flat_map(|a| {
                ends[start[a]..start[a + 1]]
                    .iter()
                    .map(move |&b| (a as u32, b))
            })
            .collect();
        let expected = [
            (0, 1),
            (0, 2),
            (0, 3),
            (1, 2),
            (1, 3),
            (1, 4),
            (2, 3),
            (2, 4),
            (3, 4),
        ];
        assert_eq!(edges, expected);
        assert_eq!(start.len(), 7);
        assert_eq!(start[6], ends.len());
    }
}
