//! Insertion order: BRIO (biased randomized insertion order, Amenta–Choi–Rote) with each round
//! sorted along a 3D Hilbert curve, as CGAL's `spatial_sort` does. Randomness keeps the expected
//! cavity sizes small; the curve keeps consecutive points close so the walk from the previous
//! insertion is short.

use glam::DVec3;
use rand::seq::SliceRandom;
use rand::SeedableRng;
use rayon::prelude::*;

/// Cell resolution per axis: 2^30 cells separate far more points than we ever sort.
const BITS: u32 = 10;
/// Rounds shrink by this factor (CGAL's multiscale ratio is 1/8).
const ROUND_RATIO: usize = 8;
/// Below this size a round is not split further.
const MIN_ROUND: usize = 1024;

/// Hilbert index of a cell with `bits`-bit coordinates (Skilling, "Programming the Hilbert
/// curve", AIP Conf. Proc. 707, 2004: axes to transpose, then bit interleave). Branch-free
/// (the data-dependent branches of the textbook loop mispredict half the time).
#[inline]
pub fn hilbert_index(cell: [u32; 3], bits: u32) -> u64 {
    let [mut x0, mut x1, mut x2] = cell;
    // Inverse undo: for each level q (high to low), per axis i: if bit q of x[i] is set,
    // invert the low bits of x[0]; else exchange the low bits of x[0] and x[i].
    let mut b = bits - 1;
    while b > 0 {
        let p = (1u32 << b) - 1;
        // axis 0: set -> x0 ^= p; clear -> exchange with itself (no-op)
        x0 ^= p & ((x0 >> b) & 1).wrapping_neg();
        let m1 = ((x1 >> b) & 1).wrapping_neg();
        let t1 = (x0 ^ x1) & p & !m1;
        x0 ^= (p & m1) ^ t1;
        x1 ^= t1;
        let m2 = ((x2 >> b) & 1).wrapping_neg();
        let t2 = (x0 ^ x2) & p & !m2;
        x0 ^= (p & m2) ^ t2;
        x2 ^= t2;
        b -= 1;
    }
    // Gray encode.
    x1 ^= x0;
    x2 ^= x1;
    let mut t = 0;
    let mut b = bits - 1;
    while b > 0 {
        t ^= ((1u32 << b) - 1) & ((x2 >> b) & 1).wrapping_neg();
        b -= 1;
    }
    x0 ^= t;
    x1 ^= t;
    x2 ^= t;
    // Interleave: bit b of x0, x1, x2 -> bits 3b+2, 3b+1, 3b of the index.
    (spread3(x0) << 2) | (spread3(x1) << 1) | spread3(x2)
}

/// Morton (Z-order) index of a cell with 21-bit coordinates: bit b of x, y, z at bits 3b+2,
/// 3b+1, 3b.
#[inline]
pub fn morton_index(cell: [u32; 3]) -> u64 {
    (spread3(cell[0]) << 2) | (spread3(cell[1]) << 1) | spread3(cell[2])
}

/// Spreads the low 21 bits of `x` to every third bit.
#[inline(always)]
fn spread3(x: u32) -> u64 {
    let mut v = (x & 0x1f_ffff) as u64;
    v = (v | (v << 32)) & 0x001f_0000_0000_ffff;
    v = (v | (v << 16)) & 0x001f_0000_ff00_00ff;
    v = (v | (v << 8)) & 0x100f_00f0_0f00_f00f;
    v = (v | (v << 4)) & 0x10c3_0c30_c30c_30c3;
    v = (v | (v << 2)) & 0x1249_2492_4924_9249;
    v
}

/// Sorts `ids` (indices into `points`) along the Hilbert curve of `points`' bounding box.
pub fn hilbert_sort(points: &[DVec3], ids: &mut [u32]) {
    let mut buf = vec![];
    hilbert_sort_with(points, ids, &mut buf);
}

/// [`hilbert_sort`] with a reusable buffer. Equal cells keep id order.
fn hilbert_sort_with(points: &[DVec3], ids: &mut [u32], keyed: &mut Vec<u64>) {
    hilbert_sort_impl(points, ids, keyed, false);
}

/// The sort of [`hilbert_sort_with`], its gather, keys and sort on the current rayon pool when
/// `parallel`: the keys are distinct (the id is in their low half), so the order is the same.
fn hilbert_sort_impl(points: &[DVec3], ids: &mut [u32], keyed: &mut Vec<u64>, parallel: bool) {
    if ids.len() < 2 {
        return;
    }
    let (lo, hi) = if parallel {
        let (lo, hi) = ids
            .par_iter()
            .fold(
                || (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                |(lo, hi), &i| (lo.min(points[i as usize]), hi.max(points[i as usize])),
            )
            .reduce(
                || (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
                |a, b| (a.0.min(b.0), a.1.max(b.1)),
            );
        (lo, hi)
    } else {
        // One (random-access) gather; then bounding box and keys stream over the copy.
        let local: Vec<DVec3> = ids.iter().map(|&i| points[i as usize]).collect();
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        for &p in &local {
            lo = lo.min(p);
            hi = hi.max(p);
        }
        let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
        let scale = ((1u32 << BITS) - 1) as f64 / extent;
        keyed.clear();
        keyed.extend(local.iter().zip(ids.iter()).map(|(&p, &i)| {
            let c = (p - lo) * scale;
            (hilbert_index([c.x as u32, c.y as u32, c.z as u32], BITS) << 32) | i as u64
        }));
        keyed.sort_unstable();
        for (slot, &k) in ids.iter_mut().zip(keyed.iter()) {
            *slot = k as u32;
        }
        return;
    };
    let extent = (hi - lo).max_element().max(f64::MIN_POSITIVE);
    let scale = ((1u32 << BITS) - 1) as f64 / extent;
    keyed.clear();
    ids.par_iter()
        .map(|&i| {
            let c = (points[i as usize] - lo) * scale;
            (hilbert_index([c.x as u32, c.y as u32, c.z as u32], BITS) << 32) | i as u64
        })
        .collect_into_vec(keyed);
    keyed.par_sort_unstable();
    ids.par_iter_mut()
        .zip(keyed.par_iter())
        .for_each(|(slot, &k)| *slot = k as u32);
}

/// BRIO order of all point ids: a seeded shuffle, then rounds of geometrically growing size,
/// each Hilbert-sorted.
pub fn brio_order(points: &[DVec3], seed: u64) -> Vec<u32> {
    brio_order_impl(points, seed, false)
}

/// [`brio_order`] with its sorts on the current rayon pool: the same order.
pub fn brio_order_parallel(points: &[DVec3], seed: u64) -> Vec<u32> {
    brio_order_impl(points, seed, true)
}

fn brio_order_impl(points: &[DVec3], seed: u64, parallel: bool) -> Vec<u32> {
    let mut ids: Vec<u32> = (0..points.len() as u32).collect();
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
    ids.shuffle(&mut rng);
    let mut keyed = Vec::with_capacity(points.len());
    for round in brio_rounds(points.len()).into_iter().rev() {
        hilbert_sort_impl(points, &mut ids[round], &mut keyed, parallel);
    }
    ids
}

/// The rounds of [`brio_order`] for `n` points, as ranges of positions in the order, first
/// round first: each round is `ROUND_RATIO` times the points before it, the first at most
/// `MIN_ROUND`.
pub fn brio_rounds(n: usize) -> Vec<std::ops::Range<usize>> {
    let mut rounds = vec![];
    let mut end = n;
    while end > 0 {
        let start = if end > MIN_ROUND {
            end / ROUND_RATIO
        } else {
            0
        };
        rounds.push(start..end);
        end = start;
    }
    rounds.reverse();
    rounds
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The textbook (branching) transcription of Skilling's algorithm.
    fn reference_index(cell: [u32; 3], bits: u32) -> u64 {
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

    #[test]
    fn branch_free_index_matches_reference() {
        for bits in 1..=5 {
            let n = 1u32 << bits;
            for c in 0..n * n * n {
                let cell = [c % n, (c / n) % n, c / (n * n)];
                assert_eq!(
                    hilbert_index(cell, bits),
                    reference_index(cell, bits),
                    "{cell:?}"
                );
            }
        }
        let mut s = 12345u64;
        for _ in 0..200_000 {
            s = s
                .wrapping_mul(6364136223846793005)
                .wrapping_add(1442695040888963407);
            let cell = [
                (s >> 10) as u32 & 1023,
                (s >> 25) as u32 & 1023,
                (s >> 40) as u32 & 1023,
            ];
            assert_eq!(
                hilbert_index(cell, 10),
                reference_index(cell, 10),
                "{cell:?}"
            );
            let cell = [
                (s >> 2) as u32 & 0x1f_ffff,
                (s >> 22) as u32 & 0x1f_ffff,
                (s >> 42) as u32,
            ];
            assert_eq!(
                hilbert_index(cell, 21),
                reference_index(cell, 21),
                "{cell:?}"
            );
        }
    }

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
    fn parallel_brio_is_the_same_order() {
        let mut pts: Vec<DVec3> = (0..30_000)
            .map(|i| {
                let f = |k: u64| ((i as u64 * k) % 1009) as f64 / 1009.0;
                DVec3::new(f(7919), f(104_729), f(1_299_709))
            })
            .collect();
        // Equal cells and equal points too.
        pts.extend_from_within(..3000);
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(3)
            .build()
            .unwrap();
        let parallel = pool.install(|| brio_order_parallel(&pts, 9));
        assert_eq!(parallel, brio_order(&pts, 9));
        let rounds = brio_rounds(pts.len());
        assert_eq!(rounds.first().unwrap().start, 0);
        assert_eq!(rounds.last().unwrap().end, pts.len());
        assert!(rounds.windows(2).all(|w| w[0].end == w[1].start));
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
