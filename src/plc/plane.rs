//! Facet planes: least-squares fit, the planarity tolerance, and the 2D projection.

use super::exact::{drop_axis, P2};
use glam::{DMat3, DVec3};

/// Relative planarity tolerance: file coordinates are rounded decimals, so facet vertices are
/// only coplanar up to rounding. The one tolerance in validation.
pub const PLANARITY_TOLERANCE: f64 = 1e-9;

/// A facet's plane and the 2D frame its polygons are triangulated in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Plane {
    /// Unit normal, right-handed with respect to the facet's first polygon.
    pub normal: DVec3,
    /// A point on the plane (the centroid of the facet's vertices).
    pub point: DVec3,
    /// The dominant axis of `normal` (0 = x, 1 = y, 2 = z): projection drops it.
    pub axis: usize,
}

impl Plane {
    /// Projects onto the coordinate plane orthogonal to `axis`. No arithmetic, so exact
    /// predicates on the result are exact statements about the projection. Counter-clockwise
    /// in 2D means counter-clockwise seen from the tip of `normal`.
    pub fn project(&self, p: DVec3) -> P2 {
        let q = drop_axis(p, self.axis);
        if self.normal[self.axis] < 0.0 {
            [q[1], q[0]]
        } else {
            q
        }
    }

    /// Signed distance of p from the plane (positive on the normal's side).
    pub fn distance(&self, p: DVec3) -> f64 {
        (p - self.point).dot(self.normal)
    }
}

/// Result of fitting a plane to a facet's vertices.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Fit {
    pub plane: Plane,
    /// Index (into the fitted points) and distance of the vertex farthest from the plane.
    pub worst: (usize, f64),
    /// Allowed distance: `PLANARITY_TOLERANCE` × facet diameter (bounding-box diagonal).
    pub tolerance: f64,
    /// True when the points are collinear (within the tolerance): no plane is defined.
    pub degenerate: bool,
}

/// Least-squares plane through `points`; `first_loop` (points in polygon order) orients it.
pub(crate) fn fit_plane(points: &[DVec3], first_loop: &[DVec3]) -> Fit {
    let n = points.len() as f64;
    let centroid = points.iter().copied().sum::<DVec3>() / n;
    let (lo, hi) = points.iter().fold(
        (DVec3::splat(f64::INFINITY), DVec3::splat(f64::NEG_INFINITY)),
        |(lo, hi), &p| (lo.min(p), hi.max(p)),
    );
    let diameter = (hi - lo).length();
    let mut cov = DMat3::ZERO;
    for &p in points {
        let d = p - centroid;
        cov += DMat3::from_cols(d * d.x, d * d.y, d * d.z);
    }
    let (values, vectors) = symmetric_eigen(cov);
    // values ascending: the smallest eigenvector is the normal; a tiny middle one = a line.
    let tolerance = PLANARITY_TOLERANCE * diameter;
    let degenerate = diameter == 0.0 || (values[1] / n).max(0.0).sqrt() <= tolerance;
    let mut normal = vectors[0].normalize_or_zero();
    if normal == DVec3::ZERO {
        normal = DVec3::Z;
    }
    // Newell's vector area of the first polygon fixes the right-handed direction.
    let mut newell = DVec3::ZERO;
    for i in 0..first_loop.len() {
        let (a, b) = (
            first_loop[i] - centroid,
            first_loop[(i + 1) % first_loop.len()] - centroid,
        );
        newell += a.cross(b);
    }
    if newell.dot(normal) < 0.0 {
        normal = -normal;
    }
    let a = normal.abs();
    let axis = if a.x >= a.y && a.x >= a.z {
        0
    } else if a.y >= a.z {
        1
    } else {
        2
    };
    let plane = Plane {
        normal,
        point: centroid,
        axis,
    };
    let worst = points
        .iter()
        .enumerate()
        .map(|(i, &p)| (i, plane.distance(p).abs()))
        .fold((0, -1.0), |w, c| if c.1 > w.1 { c } else { w });
    Fit {
        plane,
        worst,
        tolerance,
        degenerate,
    }
}

/// Eigen-decomposition of a symmetric 3×3 matrix by cyclic Jacobi rotations: eigenvalues in
/// ascending order with their unit eigenvectors.
fn symmetric_eigen(m: DMat3) -> ([f64; 3], [DVec3; 3]) {
    let mut a = m.to_cols_array_2d(); // a[col][row]; symmetric, so either reading works
    let mut v = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]; // v[col] = eigenvector
    for _sweep in 0..50 {
        let off = a[0][1].powi(2) + a[0][2].powi(2) + a[1][2].powi(2);
        let scale = a[0][0].powi(2) + a[1][1].powi(2) + a[2][2].powi(2);
        if off <= 1e-30 * scale || off == 0.0 {
            break;
        }
        for (p, q) in [(0, 1), (0, 2), (1, 2)] {
            if a[p][q] == 0.0 {
                continue;
            }
            let theta = (a[q][q] - a[p][p]) / (2.0 * a[p][q]);
            let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
            let t = if theta == 0.0 { 1.0 } else { t };
            let c = 1.0 / (t * t + 1.0).sqrt();
            let s = t * c;
            // A <- J^T A J with the rotation J in the (p, q) plane.
            for ak in a.iter_mut() {
                let (akp, akq) = (ak[p], ak[q]);
                ak[p] = c * akp - s * akq;
                ak[q] = s * akp + c * akq;
            }
            let (ap, aq) = (a[p], a[q]);
            for k in 0..3 {
                a[p][k] = c * ap[k] - s * aq[k];
                a[q][k] = s * ap[k] + c * aq[k];
            }
            for vk in v.iter_mut() {
                let (vp, vq) = (vk[p], vk[q]);
                vk[p] = c * vp - s * vq;
                vk[q] = s * vp + c * vq;
            }
        }
    }
    // v is stored row-major as v[row][col]; eigenvector j is column j.
    let mut pairs: Vec<(f64, DVec3)> = (0..3)
        .map(|j| (a[j][j], DVec3::new(v[0][j], v[1][j], v[2][j])))
        .collect();
    pairs.sort_by(|x, y| x.0.total_cmp(&y.0));
    (
        [pairs[0].0, pairs[1].0, pairs[2].0],
        [pairs[0].1, pairs[1].1, pairs[2].1],
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn eigen_of_diagonal_and_rotated() {
        let (vals, vecs) = symmetric_eigen(DMat3::from_diagonal(DVec3::new(3.0, 1.0, 2.0)));
        assert_eq!(vals, [1.0, 2.0, 3.0]);
        assert!((vecs[0].dot(DVec3::Y)).abs() > 1.0 - 1e-12);
        // points on the plane x + y + z = 1: the normal is (1,1,1)/sqrt 3
        let pts = [
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.0, 0.0, 1.0),
            DVec3::new(0.5, 0.5, 0.0),
            DVec3::new(-1.0, 1.0, 1.0),
        ];
        let fit = fit_plane(&pts, &pts[..3]);
        assert!((fit.plane.normal - DVec3::ONE.normalize()).length() < 1e-12);
        assert!(fit.worst.1 < 1e-15);
        assert!(!fit.degenerate);
    }

    #[test]
    fn projection_keeps_orientation() {
        // A square in the plane y = 0 wound so its normal is -y.
        let pts = [
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 1.0),
            DVec3::new(0.0, 0.0, 1.0),
        ];
        let fit = fit_plane(&pts, &pts);
        assert_eq!(fit.plane.axis, 1);
        assert!(fit.plane.normal.y < 0.0);
        let p: Vec<P2> = pts.iter().map(|&p| fit.plane.project(p)).collect();
        assert_eq!(
            super::super::exact::orient2d(p[0], p[1], p[2]),
            std::cmp::Ordering::Greater
        );
    }

    #[test]
    fn collinear_points_are_degenerate() {
        let pts = [DVec3::ZERO, DVec3::X, DVec3::X * 2.0];
        assert!(fit_plane(&pts, &pts).degenerate);
    }
}
