//! The oracle's occupancy grid: which cells may hold part of the surface.

use super::Piece;
use glam::DVec3;

/// Which cells of a uniform grid may hold part of the surface (the cell, slightly widened,
/// meets a piece's box and its triangle's plane): a short segment whose box touches no such
/// cell meets no triangle, answered without walking the tree (most Voronoi edges of a volume
/// mesh lie off the surface).
pub(super) struct Occupancy {
    origin: DVec3,
    cell: f64,
    dims: [usize; 3],
    bits: Vec<u64>,
}

/// Segments whose box spans more cells than this along an axis walk the tree directly.
const GRID_SPAN: usize = 6;

/// Grid cells are this share of the bounding-box diagonal.
pub(super) const GRID_FRACTION: f64 = 1.0 / 128.0;

impl Occupancy {
    /// No cells: every segment goes to the tree.
    pub(super) fn empty() -> Occupancy {
        Occupancy {
            origin: DVec3::ZERO,
            cell: 1.0,
            dims: [0; 3],
            bits: vec![],
        }
    }

    pub(super) fn new(pieces: &[Piece], corners: &[[DVec3; 3]], cell: f64) -> Occupancy {
        let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY));
        for p in pieces {
            lo = lo.min(p.lo);
            hi = hi.max(p.hi);
        }
        if pieces.is_empty() || cell.is_nan() || cell <= 0.0 {
            return Occupancy::empty();
        }
        // One cell of margin on each side, so that rounding at the box never matters.
        let origin = lo - DVec3::splat(cell);
        let dims = ((hi - origin) / cell)
            .to_array()
            .map(|x| (x.ceil() as usize + 2).min(256));
        let cell = ((hi - origin)
            / DVec3::new(
                dims[0] as f64 - 1.0,
                dims[1] as f64 - 1.0,
                dims[2] as f64 - 1.0,
            ))
        .max_element()
        .max(cell);
        let mut g = Occupancy {
            origin,
            cell,
            dims,
            bits: vec![0; (dims[0] * dims[1] * dims[2]).div_ceil(64)],
        };
        for p in pieces {
            let [a, b, c] = corners[p.triangle as usize];
            let normal = (b - a).cross(c - a);
            // A cell is marked when its box, widened a little, meets the triangle's plane:
            // rounding in the test is far below the widening.
            let reach = 0.5 * g.cell * (1.0 + 1e-6) * normal.abs().element_sum();
            let (lo, hi) = (g.index(p.lo, -1), g.index(p.hi, 1));
            for k in lo[2]..=hi[2] {
                for j in lo[1]..=hi[1] {
                    for i in lo[0]..=hi[0] {
                        let centre = g.origin
                            + DVec3::new(i as f64 + 0.5, j as f64 + 0.5, k as f64 + 0.5) * g.cell;
                        if normal.dot(centre - a).abs() > reach {
                            continue;
                        }
                        let x = (k * dims[1] + j) * dims[0] + i;
                        g.bits[x / 64] |= 1 << (x % 64);
                    }
                }
            }
        }
        g
    }

    /// The cell of `x`, widened by one cell towards `side` (-1 low, +1 high) when `x` is within
    /// a tiny margin of the cell's border, clamped to the grid.
    fn index(&self, x: DVec3, side: i32) -> [usize; 3] {
        let f = (x - self.origin) / self.cell;
        let margin = 1e-6 * f64::from(side);
        let mut out = [0usize; 3];
        for k in 0..3 {
            // Truncation is the floor for the non-negative values kept (and a function call
            // less than `floor` on the baseline x86-64 target); NaN fails the test. Through u32
            // (saturating like usize, and the clamp below is far under 2^32): the conversion to
            // usize takes several more instructions.
            let v = f[k] + margin;
            out[k] = if v > 0.0 {
                (v as u32 as usize).min(self.dims[k] - 1)
            } else {
                0
            };
        }
        out
    }

    /// Whether segment [p, q] surely touches no piece box (false when unsure or too long).
    pub(super) fn surely_clear(&self, p: DVec3, q: DVec3) -> bool {
        if self.bits.is_empty() {
            return false;
        }
        let (lo, hi) = (p.min(q), p.max(q));
        let inside_grid = |x: DVec3| {
            let f = (x - self.origin) / self.cell;
            (0..3).all(|k| f[k] >= 1.0 && f[k] < (self.dims[k] - 1) as f64)
        };
        if !inside_grid(lo) || !inside_grid(hi) {
            // Outside the grid's margin there is no surface, but a segment from there may
            // cross the grid: the tree decides.
            return !self.overlaps_grid(lo, hi);
        }
        let (a, b) = (self.index(lo, -1), self.index(hi, 1));
        if (0..3).any(|k| b[k] - a[k] >= GRID_SPAN) {
            return false;
        }
        let run = b[0] - a[0] + 1;
        for k in a[2]..=b[2] {
            for j in a[1]..=b[1] {
                if self.any_in_run((k * self.dims[1] + j) * self.dims[0] + a[0], run) {
                    return false;
                }
            }
        }
        true
    }

    /// Whether any of the `len` (at most 64) consecutive cells from `start` is marked.
    fn any_in_run(&self, start: usize, len: usize) -> bool {
        let (word, offset) = (start / 64, start % 64);
        let mask = |n: usize| if n >= 64 { u64::MAX } else { (1u64 << n) - 1 };
        if (self.bits[word] >> offset) & mask(len) != 0 {
            return true;
        }
        offset + len > 64 && self.bits[word + 1] & mask(offset + len - 64) != 0
    }

    /// Whether the box [lo, hi] overlaps the grid's extent.
    fn overlaps_grid(&self, lo: DVec3, hi: DVec3) -> bool {
        let top = self.origin
            + DVec3::new(
                self.dims[0] as f64,
                self.dims[1] as f64,
                self.dims[2] as f64,
            ) * self.cell;
        (0..3).all(|k| hi[k] >= self.origin[k] && lo[k] <= top[k])
    }
}
