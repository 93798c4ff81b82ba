//! The Jacobian determinant of a ten-node tet, and bounds on it.
//!
//! A ten-node tet maps the reference tet by quadratic shape functions, so its Jacobian
//! determinant is a cubic polynomial. Written in the Bernstein basis of degree 3, its 20
//! coefficients bound it from below and above over the whole element (a Bernstein
//! polynomial is a convex combination of its coefficients), and the four corner coefficients
//! are its values at the corners. A tet whose smallest coefficient has the sign of the
//! straight tet's determinant is valid everywhere; this is the test Gmsh's `minSJ` and
//! Johnen, Remacle and Geuzaine's "Geometrical validity of curvilinear finite elements" (2013)
//! build on. The bound is conservative: a few valid tets fail it.

use crate::mesh::TET_EDGES;
use glam::DVec3;
use std::sync::OnceLock;

/// Multi-indices of the degree-3 Bernstein polynomials on a tet (barycentric exponents).
pub(crate) fn cubic_indices() -> &'static [[u8; 4]; 20] {
    static INDICES: OnceLock<[[u8; 4]; 20]> = OnceLock::new();
    INDICES.get_or_init(|| {
        let mut out = [[0u8; 4]; 20];
        let mut n = 0;
        for i in 0..=3u8 {
            for j in 0..=3 - i {
                for k in 0..=3 - i - j {
                    out[n] = [3 - i - j - k, i, j, k];
                    n += 1;
                }
            }
        }
        out
    })
}

/// The degree-3 Bernstein polynomial of exponents `alpha` at barycentric point `l`.
pub(crate) fn bernstein(alpha: [u8; 4], l: [f64; 4]) -> f64 {
    let factorial = |n: u8| (1..=n as u32).product::<u32>() as f64;
    let multinomial = 6.0 / alpha.iter().map(|&a| factorial(a)).product::<f64>();
    multinomial
        * alpha
            .iter()
            .zip(l)
            .map(|(&a, x)| x.powi(a as i32))
            .product::<f64>()
}

/// The barycentric point of multi-index `alpha` on the degree-3 lattice.
fn lattice_point(alpha: [u8; 4]) -> [f64; 4] {
    alpha.map(|a| a as f64 / 3.0)
}

/// The matrix taking the determinant's values at the 20 lattice points to its Bernstein
/// coefficients (the inverse of the Bernstein polynomials' values there), computed once.
fn values_to_bernstein() -> &'static [[f64; 20]; 20] {
    static MATRIX: OnceLock<[[f64; 20]; 20]> = OnceLock::new();
    MATRIX.get_or_init(|| {
        let idx = cubic_indices();
        let mut a = [[0.0; 40]; 20];
        for (r, row) in a.iter_mut().enumerate() {
            for c in 0..20 {
                row[c] = bernstein(idx[c], lattice_point(idx[r]));
            }
            row[20 + r] = 1.0;
        }
        // Gauss-Jordan with partial pivoting; the matrix is well conditioned (entries of a
        // few units, determinant far from zero).
        for col in 0..20 {
            let pivot = (col..20)
                .max_by(|&x, &y| a[x][col].abs().total_cmp(&a[y][col].abs()))
                .unwrap_or(col);
            a.swap(col, pivot);
            let p = a[col][col];
            a[col].iter_mut().for_each(|x| *x /= p);
            for r in 0..20 {
                if r != col {
                    let f = a[r][col];
                    if f != 0.0 {
                        let pivot_row = a[col];
                        a[r].iter_mut()
                            .zip(pivot_row)
                            .for_each(|(x, y)| *x -= f * y);
                    }
                }
            }
        }
        let mut inv = [[0.0; 20]; 20];
        for (r, row) in inv.iter_mut().enumerate() {
            row.copy_from_slice(&a[r][20..]);
        }
        inv
    })
}

/// A ten-node tet: its corners and its mid-edge nodes in `TET_EDGES` order.
#[derive(Debug, Clone, Copy)]
pub struct Tet10 {
    pub corners: [DVec3; 4],
    pub mids: [DVec3; 6],
}

impl Tet10 {
    /// The straight-sided tet on `corners`.
    pub fn straight(corners: [DVec3; 4]) -> Self {
        Tet10 {
            corners,
            mids: TET_EDGES.map(|(i, j)| (corners[i] + corners[j]) * 0.5),
        }
    }

    /// The Jacobian determinant of the map from the reference tet at barycentric point `l`
    /// (the straight tet's: `det[x1 - x0, x2 - x0, x3 - x0]`, everywhere).
    pub fn det_at(&self, l: [f64; 4]) -> f64 {
        // dx/dl_i of x = sum_i l_i (2 l_i - 1) x_i + sum_{i<j} 4 l_i l_j m_ij.
        let mut d: [DVec3; 4] = std::array::from_fn(|i| self.corners[i] * (4.0 * l[i] - 1.0));
        for (e, &(i, j)) in TET_EDGES.iter().enumerate() {
            d[i] += self.mids[e] * (4.0 * l[j]);
            d[j] += self.mids[e] * (4.0 * l[i]);
        }
        let (c1, c2, c3) = (d[1] - d[0], d[2] - d[0], d[3] - d[0]);
        c1.dot(c2.cross(c3))
    }

    /// The determinant of the straight tet on the same corners.
    pub fn straight_det(&self) -> f64 {
        let [a, b, c, d] = self.corners;
        (b - a).dot((c - a).cross(d - a))
    }

    /// The smallest Bernstein coefficient of the Jacobian determinant divided by the straight
    /// tet's determinant: a lower bound of `det J / det J_straight` over the element. Above
    /// zero, the element is valid everywhere; 1 for a straight tet.
    pub fn jacobian_ratio_bound(&self) -> f64 {
        let straight = self.straight_det();
        if straight == 0.0 {
            return 0.0;
        }
        self.bernstein_coefficients()
            .iter()
            .map(|c| c / straight)
            .fold(f64::INFINITY, f64::min)
    }

    /// The Jacobian determinant's coefficients in the degree-3 Bernstein basis, in
    /// [`cubic_indices`] order.
    pub fn bernstein_coefficients(&self) -> [f64; 20] {
        let idx = cubic_indices();
        let values: [f64; 20] = std::array::from_fn(|r| self.det_at(lattice_point(idx[r])));
        values_to_bernstein().map(|row| row.iter().zip(values).map(|(m, v)| m * v).sum())
    }

    /// The smallest scaled Jacobian at the four corners: the determinant of the three edge
    /// tangents leaving a corner over the product of their lengths, scaled so that a regular
    /// tet gives 1 (for a straight tet this is Gmsh's `minSJ`), signed by the straight tet's
    /// orientation.
    pub fn min_corner_scaled_jacobian(&self) -> f64 {
        // Per corner, the other three corners in the order that gives the straight tet's
        // determinant its sign.
        const FRAMES: [(usize, [usize; 3]); 4] = [
            (0, [1, 2, 3]),
            (1, [0, 3, 2]),
            (2, [0, 1, 3]),
            (3, [0, 2, 1]),
        ];
        let sign = self.straight_det().signum();
        FRAMES
            .iter()
            .map(|&(i, others)| {
                let t = others.map(|j| self.tangent(i, j));
                let lengths = t[0].length() * t[1].length() * t[2].length();
                if lengths == 0.0 {
                    return 0.0;
                }
                sign * std::f64::consts::SQRT_2 * t[0].dot(t[1].cross(t[2])) / lengths
            })
            .fold(f64::INFINITY, f64::min)
    }

    /// The tangent at corner `i` of the curved edge towards corner `j`.
    fn tangent(&self, i: usize, j: usize) -> DVec3 {
        let e = TET_EDGES
            .iter()
            .position(|&(a, b)| (a, b) == (i, j) || (a, b) == (j, i))
            .expect("two distinct corners make an edge");
        self.mids[e] * 4.0 - self.corners[i] * 3.0 - self.corners[j]
    }
}
