//! Insertion order: BRIO (biased randomized insertion order, Amenta–Choi–Rote) with each round
//! sorted along a 3D Hilbert curve, as CGAL's `spatial_sort` does. Randomness keeps the expected
//! cavity sizes small; the curve keeps consecutive points close so the walk from the previous
//! insertion is short.

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::SeedableRng;

/// Cell resolution per axis: 2^30 cells separate far more points than we ever sort.
const BITS: u32 = 10;
/// Rounds shrink by this factor (CGAL's multiscale ratio is 1/8).
const ROUND_RATIO: usize = 8;
/// Below this size a round is not split further.
const MIN_ROUND: usize = 1024;

/// Hilbert index of a cell with `bits`-bit coordinates (Skilling, "Programming the Hilbert
/// curve", AIP Conf. Proc. 707, 2004: axes to transpose, then bit interleave).
pub fn hilbert_index(cell: [u32; 3], bits: u32) -> u64 {
    let mut x = cell;
    let m = 1u32 << (bits - 1);
    let mut q = m;
    while q > 1 {
        let p = q - 1;
        for i in 0..3 {
            if x[i] & q != 0 {
                x[0] ^= p;
            } else {
                let t = (x[0] ^ x[i]) & p;
                x[0] ^= t;
                x[i] ^= t;
            }
        }
        q >>= 1;
    }
    for i in 1..3 {
        x[i] ^= x[i - 1];
    }
    let mut t = 0;
    let mut q = m;
    while q > 1 {
        if x[2] & q != 0 {
            t ^= q - 1;
        }
        q >>= 1;
    }
    for xi in &mut x {
        *xi ^= t;
    }
    let mut h = 0u64;
    for b in (0..bits).rev() {
        for xi in &x {
            h = (h << 1) | ((xi >> b) & 1) as u64;
        }
    }
    h
}

/// Sorts `ids` (indices into `points`) along the Hilbert curve of `points`' bounding box.
pub fn hilbert_sort(points: &[DVec3], ids: &mut [u32]) {
    if ids.len() < 2 {
        return;
    }
    let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
    for &i in ids.iter() {
        lo = lo.min(points[i as usize]);
        hi = hi.max(points[i as usize]);
    }
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let scale = ((1u32 << BITS) - 1) as f64 / extent;
    let mut keyed: Vec<(u64, u32)> = ids
        .iter()
        .map(|&i| {
            let c = (points[i as usize] - lo) * scale;
            (hilbert_index([c.x as u32, c.y as u32, c.z as u32], BITS), i)
        })
        .collect();
    keyed.sort_unstable();
    for (slot, (_, i)) in ids.iter_mut().zip(keyed) {
        *slot = i;
    }
}

/// BRIO order of all point ids: a seeded shuffle, then rounds of geometrically growing size,
/// each Hilbert-sorted.
pub fn brio_order(points: &[DVec3], seed: u64) -> Vec<u32> {
    let mut ids: Vec<u32> = (0..points.len() as u32).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    ids.shuffle(&mut rng);
    let mut end = ids.len();
    while end > 0 {
        let start = if end > MIN_ROUND {
            end / ROUND_RATIO
        } else {
            0
        };
        hilbert_sort(points, &mut ids[start..end]);
        end = start;
    }
    ids
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn hilbert_curve_visits_neighbouring_cells() {
        let bits = 3;
        let n = 1u32 << bits;
        let mut cells = vec![];
        for x in 0..n {
            for y in 0..n {
                for z in 0..n {
                    cells.push((hilbert_index([x, y, z], bits), [x, y, z]));
                }
            }
        }
        cells.sort();
        for (k, w) in cells.windows(2).enumerate() {
            assert_eq!(w[0].0 + 1, w[1].0, "indices form a permutation");
            let d: u32 = (0..3).map(|i| w[0].1[i].abs_diff(w[1].1[i])).sum();
            assert_eq!(d, 1, "step {k}: {:?} -> {:?}", w[0].1, w[1].1);
        }
    }

    #[test]
    fn brio_is_a_permutation() {
        let pts: Vec<DVec3> = (0..5000)
            .map(|i| DVec3::new((i * 7 % 13) as f64, (i * 3 % 17) as f64, i as f64))
            .collect();
        let mut order = brio_order(&pts, 7);
        order.sort_unstable();
        assert!(order.iter().enumerate().all(|(i, &v)| v == i as u32));
    }
}
