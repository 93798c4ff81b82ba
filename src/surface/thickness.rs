//! How thin the domain is near each point of its surface: the radius of the largest ball that
//! touches the surface at an input vertex and holds no other point of it, on the inside (half
//! the local thickness) and on the outside (half the gap to another part), whichever is
//! smaller. It bounds the surface spacing of the approximate mode, so that thin parts and
//! narrow gaps are sampled densely enough from the start.
//!
//! Estimated per input vertex by the shrinking-ball method (Ma, Bae, Choi, Chen and Shim,
//! "3D medial axis point approximation using nearest neighbors and the normal field", 2012),
//! with closest-point queries on the input triangles instead of sample points: a ball tangent
//! at the vertex (centre along its normal) is shrunk to pass through the surface point nearest
//! its centre until that point is the vertex's own neighbourhood. A ball is only shrunk for a
//! point across the smaller ball (separation angle, at its centre, between the vertex and that
//! point of at least [`MIN_SEPARATION_DEG`]): a noise bump, a fillet or a sharp edge next to the vertex
//! has a small angle and does not count, the opposite wall of a plate or of a tube does.
//! Finally the radii are made 1-Lipschitz along the input edges (a vertex's value is at most
//! its neighbour's plus their distance), so the spacing they bound grades smoothly.
//!
//! Cost: at most [`MAX_STEPS`] closest-point queries per vertex and side (measured: 2-4 on
//! most vertices, since balls start at the largest radius that matters and most stay there).

use super::oracle::SurfaceOracle;
use super::InputSurface;
use glam::DVec3;
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// Smallest angle at the ball's centre between the vertex and the point that shrinks it,
/// degrees: 90 would count a quarter-round fillet as thin, 120 leaves it.
pub const MIN_SEPARATION_DEG: f64 = 120.0;

/// Largest angle between a vertex's normal and the normal of a triangle around it, degrees,
/// for the vertex to count as a smooth point of the surface.
pub const MAX_TILT_DEG: f64 = 30.0;

/// Shrinking steps per vertex and side.
pub const MAX_STEPS: usize = 24;

/// Per input vertex, the radius of the largest empty ball touching the surface there, inside
/// or outside, capped (the caller's largest radius of interest).
#[derive(Debug, Clone)]
pub struct Thickness {
    pub radius: Vec<f64>,
}

impl Thickness {
    /// Estimates the radii of `surface`'s vertices, none above `cap`. A vertex where the
    /// surface is not smooth (a triangle around it turns more than [`MAX_TILT_DEG`] from its
    /// normal: a corner, a crease, a noise spike) gets its radius from its neighbours only:
    /// its normal is no tangent plane's, and a ball along it would shrink into the corner.
    pub fn estimate(surface: &InputSurface, oracle: &SurfaceOracle, cap: f64) -> Thickness {
        let normals = vertex_normals(surface);
        let cos_tilt = MAX_TILT_DEG.to_radians().cos();
        let mut smooth: Vec<bool> = normals.iter().map(|n| *n != DVec3::ZERO).collect();
        for (t, tri) in surface.triangles.iter().enumerate() {
            let nt = surface.normal(t);
            for &v in tri {
                if nt.dot(normals[v as usize]) < cos_tilt {
                    smooth[v as usize] = false;
                }
            }
        }
        // Each vertex's balls on their own, on the run's threads (`crate::parallel`, in vertex
        // order).
        let vertices: Vec<(DVec3, DVec3, bool)> = surface
            .vertices
            .iter()
            .zip(&normals)
            .zip(&smooth)
            .map(|((&p, &n), &smooth)| (p, n, smooth))
            .collect();
        let mut radius = crate::parallel::map_collect(&vertices, |&(p, n, smooth)| {
            if !smooth {
                return cap;
            }
            shrink(oracle, p, -n, cap).min(shrink(oracle, p, n, cap))
        });
        lipschitz(surface, &mut radius);
        Thickness { radius }
    }

    /// The radius of each triangle of `surface`: its corners' smallest.
    pub fn per_triangle(&self, surface: &InputSurface) -> Vec<f64> {
        surface
            .triangles
            .iter()
            .map(|t| {
                t.iter()
                    .map(|&v| self.radius[v as usize])
                    .fold(f64::INFINITY, f64::min)
            })
            .collect()
    }
}

/// Area-weighted normals of the triangles around each vertex, normalised (zero where they
/// cancel).
fn vertex_normals(s: &InputSurface) -> Vec<DVec3> {
    let mut n = vec![DVec3::ZERO; s.vertices.len()];
    for (t, tri) in s.triangles.iter().enumerate() {
        let [a, b, c] = s.corners(t);
        let w = (b - a).cross(c - a);
        for &v in tri {
            n[v as usize] += w;
        }
    }
    n.iter().map(|v| v.normalize_or_zero()).collect()
}

/// The radius of the empty ball touching the surface at `p` with its centre along `dir`
/// (unit), starting from `cap`.
fn shrink(oracle: &SurfaceOracle, p: DVec3, dir: DVec3, cap: f64) -> f64 {
    let cos_min = MIN_SEPARATION_DEG.to_radians().cos();
    let mut r = cap;
    for _ in 0..MAX_STEPS {
        let centre = p + dir * r;
        let Some(q) = oracle.closest(centre) else {
            return r;
        };
        if q.distance >= r * (1.0 - 1e-9) {
            return r;
        }
        // The ball tangent at p (centre along dir) through q.
        let d = q.point - p;
        let along = d.dot(dir);
        if along <= 0.0 {
            return r;
        }
        let next = d.length_squared() / (2.0 * along);
        if next.partial_cmp(&r) != Some(Ordering::Less) {
            return r;
        }
        let c = p + dir * next;
        let (u, v) = (p - c, q.point - c);
        if u.dot(v) > cos_min * u.length() * v.length() {
            return r; // q is next to p on the smaller ball, not across it
        }
        r = next;
    }
    r
}

/// Makes `radius` 1-Lipschitz along the input edges (Dijkstra from the smallest values).
fn lipschitz(s: &InputSurface, radius: &mut [f64]) {
    let mut adjacent: Vec<Vec<u32>> = vec![Vec::new(); s.vertices.len()];
    for tri in &s.triangles {
        for j in 0..3 {
            adjacent[tri[j] as usize].push(tri[(j + 1) % 3]);
            adjacent[tri[(j + 1) % 3] as usize].push(tri[j]);
        }
    }
    #[derive(PartialEq)]
    struct Item(f64, u32);
    impl Eq for Item {}
    impl PartialOrd for Item {
        fn partial_cmp(&self, o: &Self) -> Option<Ordering> {
            Some(self.cmp(o))
        }
    }
    impl Ord for Item {
        // Smallest radius first, ties by vertex.
        fn cmp(&self, o: &Self) -> Ordering {
            o.0.total_cmp(&self.0).then(o.1.cmp(&self.1))
        }
    }
    let mut heap: BinaryHeap<Item> = (0..radius.len() as u32)
        .map(|v| Item(radius[v as usize], v))
        .collect();
    while let Some(Item(r, v)) = heap.pop() {
        if r > radius[v as usize] {
            continue;
        }
        let p = s.vertices[v as usize];
        for &w in &adjacent[v as usize] {
            let candidate = r + p.distance(s.vertices[w as usize]);
            if candidate < radius[w as usize] {
                radius[w as usize] = candidate;
                heap.push(Item(candidate, w));
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::Thickness;
    use crate::surface::oracle::SurfaceOracle;
    use crate::surface::InputSurface;
    use glam::DVec3;

    /// An octahedron subdivided `levels` times and pushed onto the unit sphere, then scaled.
    fn ellipsoid(levels: u32, scale: DVec3) -> InputSurface {
        let (v, t) = crate::surface::test_shapes::octahedron_sphere(levels);
        InputSurface::from_triangles(v.iter().map(|p| *p * scale).collect(), t)
    }

    /// A sphere's inside ball is the sphere; a flat ellipsoid's at its pole is half its
    /// thickness, not its curvature radius (20 there); nothing exceeds the cap.
    #[test]
    fn radii_of_a_sphere_and_a_thin_disk() {
        let s = ellipsoid(4, DVec3::ONE);
        let r = Thickness::estimate(&s, &SurfaceOracle::new(&s), 5.0).radius;
        assert!(r.iter().all(|&x| (x - 1.0).abs() < 0.02), "{r:?}");
        let s = ellipsoid(4, DVec3::new(1.0, 1.0, 0.05));
        let r = Thickness::estimate(&s, &SurfaceOracle::new(&s), 5.0).radius;
        let pole = s.vertices.iter().position(|p| p.z > 0.0499).unwrap();
        assert!((r[pole] - 0.05).abs() < 0.005, "{}", r[pole]);
        let s = ellipsoid(4, DVec3::ONE);
        let r = Thickness::estimate(&s, &SurfaceOracle::new(&s), 0.5).radius;
        assert!(r.iter().all(|&x| x <= 0.5), "{r:?}");
    }
}
