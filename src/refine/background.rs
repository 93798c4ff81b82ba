//! A spacing given on a background tet mesh (adaptive loops: the size field computed on the
//! previous mesh): f(p) is the linear (barycentric) interpolation of the vertex values in the
//! background tet that contains p; outside every tet (or in a gap between tets) it is the
//! value at the closest point of the nearest tet, so f is continuous everywhere.
//!
//! Point location: a uniform grid over the background's bounding box, each cell listing the
//! tets whose bounding boxes overlap it (cells about half the mean tet extent). A query reads
//! one cell; a point outside every tet searches rings of cells around its cell until no
//! closer tet can remain.

use crate::run::spacing::Spacing;
use glam::{DMat3, DVec3};

/// Barycentric coordinates down to this (negative) value count as inside a tet.
const INSIDE_TOL: f64 = 1e-12;

/// A tet whose |det| is below this times its longest edge cubed is flat: it is never used
/// for containment (its faces still take part in the nearest-point search).
const FLAT_TOL: f64 = 1e-14;

/// Spacing interpolated linearly from values at the vertices of a background tet mesh.
pub struct BackgroundSpacing {
    vertices: Vec<DVec3>,
    tets: Vec<[u32; 4]>,
    values: Vec<f64>,
    /// Per tet: its first vertex and the inverse of [b - a, c - a, d - a] (barycentrics 1..3
    /// of p are `inv * (p - a)`), `None` for a flat tet.
    frames: Vec<Option<(DVec3, DMat3)>>,
    lo: DVec3,
    cell: f64,
    dims: [usize; 3],
    /// Tets overlapping cell i: `cell_tets[cell_start[i]..cell_start[i + 1]]`.
    cell_start: Vec<usize>,
    cell_tets: Vec<u32>,
    /// The boundary faces (faces of one tet only; the nearest point of the mesh to a point
    /// outside every tet lies on one), as vertex ids.
    faces: Vec<[u32; 3]>,
    /// Boundary faces overlapping cell i: `cell_faces[face_start[i]..face_start[i + 1]]`.
    face_start: Vec<usize>,
    cell_faces: Vec<u32>,
}

impl std::fmt::Debug for BackgroundSpacing {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "BackgroundSpacing({} vertices, {} tets, grid {:?})",
            self.vertices.len(),
            self.tets.len(),
            self.dims
        )
    }
}

impl BackgroundSpacing {
    /// Builds the spacing from a background mesh (`tets` index `vertices`, 0-based) and one
    /// value per vertex. Errors (vertex and tet numbers in them are 1-based, as in mesh
    /// files): an empty mesh, a vertex that is not finite, a tet index out of range, a count
    /// of values other than the count of vertices, a value that is not finite and positive.
    pub fn new(
        vertices: Vec<DVec3>,
        tets: Vec<[u32; 4]>,
        values: Vec<f64>,
    ) -> Result<BackgroundSpacing, String> {
        if vertices.is_empty() || tets.is_empty() {
            return Err(format!(
                "empty background mesh ({} vertices, {} tetrahedra): a size field needs at \
                 least one tetrahedron",
                vertices.len(),
                tets.len()
            ));
        }
        if values.len() < vertices.len() {
            return Err(format!(
                "fewer values ({}) than background vertices ({}): one value per vertex needed",
                values.len(),
                vertices.len()
            ));
        }
        if values.len() > vertices.len() {
            return Err(format!(
                "more values ({}) than background vertices ({}): one value per vertex needed",
                values.len(),
                vertices.len()
            ));
        }
        if let Some(i) = vertices.iter().position(|p| !p.is_finite()) {
            return Err(format!(
                "background vertex {} (1-based) has a coordinate that is not finite: {}",
                i + 1,
                vertices[i]
            ));
        }
        if let Some(i) = values.iter().position(|&v| !(v.is_finite() && v > 0.0)) {
            return Err(format!(
                "size value {} at background vertex {} (1-based) is not finite and positive",
                values[i],
                i + 1
            ));
        }
        let nv = vertices.len();
        for (t, tet) in tets.iter().enumerate() {
            if let Some(&v) = tet.iter().find(|&&v| v as usize >= nv) {
                return Err(format!(
                    "background tetrahedron {} (1-based) refers to vertex {} (1-based), but \
                     there are only {nv} vertices",
                    t + 1,
                    v as u64 + 1
                ));
            }
        }
        let frames = tets
            .iter()
            .map(|t| frame(t.map(|v| vertices[v as usize])))
            .collect();
        let mut s = BackgroundSpacing {
            vertices,
            tets,
            values,
            frames,
            lo: DVec3::ZERO,
            cell: 1.0,
            dims: [1; 3],
            cell_start: vec![],
            cell_tets: vec![],
            faces: vec![],
            face_start: vec![],
            cell_faces: vec![],
        };
        s.build_grid();
        Ok(s)
    }

    pub fn vertices(&self) -> &[DVec3] {
        &self.vertices
    }

    pub fn tets(&self) -> &[[u32; 4]] {
        &self.tets
    }

    pub fn values(&self) -> &[f64] {
        &self.values
    }

    fn corners(&self, t: usize) -> [DVec3; 4] {
        self.tets[t].map(|v| self.vertices[v as usize])
    }

    fn bbox(&self, t: usize) -> (DVec3, DVec3) {
        let c = self.corners(t);
        (
            c[0].min(c[1]).min(c[2]).min(c[3]),
            c[0].max(c[1]).max(c[2]).max(c[3]),
        )
    }

    fn face_bbox(&self, f: usize) -> (DVec3, DVec3) {
        let [a, b, c] = self.faces[f].map(|v| self.vertices[v as usize]);
        (a.min(b).min(c), a.max(b).max(c))
    }

    /// The faces that are not interior (by vertex ids): all but those shared by exactly two
    /// tets that lie on opposite sides of them (duplicated or folded tets keep theirs).
    fn boundary_faces(&self) -> Vec<[u32; 3]> {
        let mut all: Vec<([u32; 3], [u32; 3], u32)> = Vec::with_capacity(4 * self.tets.len());
        for t in &self.tets {
            for (k, f) in FACES.iter().enumerate() {
                let face = f.map(|i| t[i]);
                let mut key = face;
                key.sort_unstable();
                all.push((key, face, t[k]));
            }
        }
        let side = |face: [u32; 3], opp: u32| {
            let [a, b, c] = face.map(|v| self.vertices[v as usize]);
            let d = self.vertices[opp as usize];
            (b - a).cross(c - a).dot(d - a).signum()
        };
        all.sort_unstable_by_key(|e| e.0);
        let mut out = Vec::new();
        let mut i = 0;
        while i < all.len() {
            let mut j = i + 1;
            while j < all.len() && all[j].0 == all[i].0 {
                j += 1;
            }
            let interior = j == i + 2 && {
                let (f, g) = (all[i], all[i + 1]);
                side(f.1, f.2) * side(f.1, g.2) < 0.0
            };
            if !interior {
                out.extend(all[i..j].iter().map(|e| e.1));
            }
            i = j;
        }
        out
    }

    /// Buckets items 0..n by the grid cells their bounding boxes overlap.
    fn bucket(&self, n: usize, bbox: impl Fn(usize) -> (DVec3, DVec3)) -> (Vec<usize>, Vec<u32>) {
        let ncell = self.dims[0] * self.dims[1] * self.dims[2];
        let mut start = vec![0usize; ncell + 1];
        for t in 0..n {
            self.for_cells_of(bbox(t), |c| start[c + 1] += 1);
        }
        for c in 0..ncell {
            start[c + 1] += start[c];
        }
        let mut next = start[..ncell].to_vec();
        let mut list = vec![0u32; start[ncell]];
        for t in 0..n {
            self.for_cells_of(bbox(t), |c| {
                list[next[c]] = t as u32;
                next[c] += 1;
            });
        }
        (start, list)
    }

    fn build_grid(&mut self) {
        let n = self.tets.len();
        let (mut lo, mut hi) = (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN));
        let mut side_sum = 0.0;
        for t in 0..n {
            let (a, b) = self.bbox(t);
            lo = lo.min(a);
            hi = hi.max(b);
            side_sum += (b - a).max_element();
        }
        let ext = hi - lo;
        // Half the mean tet extent, but no more than about 8 cells per tet in all.
        let vol = ext.x.max(1e-300) * ext.y.max(1e-300) * ext.z.max(1e-300);
        let mut cell = (0.5 * side_sum / n as f64).max((vol / (8.0 * n as f64)).cbrt());
        if !(cell.is_finite() && cell > 0.0) {
            cell = ext.max_element().max(1.0);
        }
        // Never more than 2^10 cells along an axis (a few huge outlier tets).
        cell = cell.max(ext.max_element() / 1024.0);
        let dims = (ext / cell).to_array().map(|d| (d as usize + 1).min(1025));
        self.lo = lo;
        self.cell = cell;
        self.dims = dims;
        (self.cell_start, self.cell_tets) = self.bucket(n, |t| self.bbox(t));
        self.faces = self.boundary_faces();
        (self.face_start, self.cell_faces) = self.bucket(self.faces.len(), |f| self.face_bbox(f));
    }

    /// Calls `f` on every cell that the box (a, b) overlaps.
    fn for_cells_of(&self, (a, b): (DVec3, DVec3), mut f: impl FnMut(usize)) {
        let (i0, i1) = (self.coords(a), self.coords(b));
        for k in i0[2]..=i1[2] {
            for j in i0[1]..=i1[1] {
                for i in i0[0]..=i1[0] {
                    f(self.index([i, j, k]));
                }
            }
        }
    }

    /// Grid coordinates of the cell holding p (clamped to the grid).
    fn coords(&self, p: DVec3) -> [usize; 3] {
        let c = ((p - self.lo) / self.cell).max(DVec3::ZERO);
        [
            (c.x as usize).min(self.dims[0] - 1),
            (c.y as usize).min(self.dims[1] - 1),
            (c.z as usize).min(self.dims[2] - 1),
        ]
    }

    fn index(&self, [i, j, k]: [usize; 3]) -> usize {
        (k * self.dims[1] + j) * self.dims[0] + i
    }

    fn cell_list(&self, c: usize) -> &[u32] {
        &self.cell_tets[self.cell_start[c]..self.cell_start[c + 1]]
    }

    /// The interpolated value at p if tet t contains it.
    fn inside(&self, t: usize, p: DVec3) -> Option<f64> {
        let (a, inv) = self.frames[t]?;
        let l = inv * (p - a);
        let l0 = 1.0 - l.x - l.y - l.z;
        if l0 < -INSIDE_TOL || l.min_element() < -INSIDE_TOL {
            return None;
        }
        let v = self.tets[t].map(|i| self.values[i as usize]);
        Some(l0 * v[0] + l.x * v[1] + l.y * v[2] + l.z * v[3])
    }

    /// (squared distance, value) at the point of boundary face f closest to p.
    fn closest(&self, f: usize, p: DVec3) -> (f64, f64) {
        let ids = self.faces[f];
        let [a, b, c] = ids.map(|v| self.vertices[v as usize]);
        let v = ids.map(|i| self.values[i as usize]);
        let (q, w) = closest_on_triangle(p, a, b, c);
        (
            p.distance_squared(q),
            w[0] * v[0] + w[1] * v[1] + w[2] * v[2],
        )
    }

    /// The value at the mesh point nearest to p (p lies in no tet, so that point lies on a
    /// boundary face): rings of cells around p's (clamped) cell, until the ring's distance
    /// bound exceeds the best distance found.
    fn nearest(&self, p: DVec3) -> f64 {
        let centre = self.coords(p);
        // p's offset from the grid box: every point of the grid is at least this far.
        let box_hi = self.lo + DVec3::from_array(self.dims.map(|d| d as f64)) * self.cell;
        let off2 = (p - p.clamp(self.lo, box_hi)).length_squared();
        let mut best = (f64::INFINITY, self.values[self.tets[0][0] as usize]);
        let kmax = *self.dims.iter().max().expect("three dims");
        for k in 0..=kmax {
            let range = |d: usize| {
                (
                    centre[d].saturating_sub(k),
                    (centre[d] + k).min(self.dims[d] - 1),
                )
            };
            let ((x0, x1), (y0, y1), (z0, z1)) = (range(0), range(1), range(2));
            for z in z0..=z1 {
                for y in y0..=y1 {
                    let zy_edge = z.abs_diff(centre[2]) == k || y.abs_diff(centre[1]) == k;
                    // Off the ring's z and y faces only its two x ends belong to ring k.
                    let ends = [centre[0].checked_sub(k), Some(centre[0] + k)];
                    let mut visit = |x: usize| {
                        let c = self.index([x, y, z]);
                        for &f in &self.cell_faces[self.face_start[c]..self.face_start[c + 1]] {
                            let r = self.closest(f as usize, p);
                            if r.0 < best.0 {
                                best = r;
                            }
                        }
                    };
                    if zy_edge {
                        (x0..=x1).for_each(&mut visit);
                    } else {
                        let mut ends = ends.into_iter().flatten().filter(|x| (x0..=x1).contains(x));
                        let first = ends.next();
                        first.into_iter().for_each(&mut visit);
                        ends.filter(|&x| Some(x) != first).for_each(&mut visit);
                    }
                }
            }
            // Points of rings beyond k are at least k cells from p's (clamped) cell.
            let bound = (k as f64 * self.cell).powi(2) + off2;
            if best.0 <= bound {
                break;
            }
        }
        best.1
    }
}

/// The faces of a tet [a, b, c, d], by local index, oriented alike.
const FACES: [[usize; 3]; 4] = [[1, 2, 3], [0, 3, 2], [0, 1, 3], [0, 2, 1]];

/// The barycentric frame of a tet, `None` when flat.
fn frame(c: [DVec3; 4]) -> Option<(DVec3, DMat3)> {
    let m = DMat3::from_cols(c[1] - c[0], c[2] - c[0], c[3] - c[0]);
    let det = m.determinant();
    let longest = [(0, 1), (0, 2), (0, 3), (1, 2), (1, 3), (2, 3)]
        .iter()
        .map(|&(i, j)| c[i].distance(c[j]))
        .fold(0.0f64, f64::max);
    if det.is_nan() || det.abs() <= FLAT_TOL * longest.powi(3) {
        return None;
    }
    Some((c[0], m.inverse()))
}

/// The point of triangle abc closest to p, with its barycentric weights (Ericson, Real-Time
/// Collision Detection, 5.1.5).
fn closest_on_triangle(p: DVec3, a: DVec3, b: DVec3, c: DVec3) -> (DVec3, [f64; 3]) {
    let (ab, ac, ap) = (b - a, c - a, p - a);
    let (d1, d2) = (ab.dot(ap), ac.dot(ap));
    if d1 <= 0.0 && d2 <= 0.0 {
        return (a, [1.0, 0.0, 0.0]);
    }
    let bp = p - b;
    let (d3, d4) = (ab.dot(bp), ac.dot(bp));
    if d3 >= 0.0 && d4 <= d3 {
        return (b, [0.0, 1.0, 0.0]);
    }
    let vc = d1 * d4 - d3 * d2;
    if vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0 {
        let v = d1 / (d1 - d3);
        return (a + v * ab, [1.0 - v, v, 0.0]);
    }
    let cp = p - c;
    let (d5, d6) = (ab.dot(cp), ac.dot(cp));
    if d6 >= 0.0 && d5 <= d6 {
        return (c, [0.0, 0.0, 1.0]);
    }
    let vb = d5 * d2 - d1 * d6;
    if vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0 {
        let w = d2 / (d2 - d6);
        return (a + w * ac, [1.0 - w, 0.0, w]);
    }
    let va = d3 * d6 - d5 * d4;
    if va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0 {
        let w = (d4 - d3) / ((d4 - d3) + (d5 - d6));
        return (b + w * (c - b), [0.0, 1.0 - w, w]);
    }
    let denom = va + vb + vc;
    if denom == 0.0 || !denom.is_finite() {
        // A degenerate triangle: its nearest vertex.
        let d = [a, b, c].map(|q| p.distance_squared(q));
        let i = (0..3).min_by(|&i, &j| d[i].total_cmp(&d[j])).unwrap_or(0);
        let mut w = [0.0; 3];
        w[i] = 1.0;
        return ([a, b, c][i], w);
    }
    let (v, w) = (vb / denom, vc / denom);
    (a + ab * v + ac * w, [1.0 - v - w, v, w])
}

impl Spacing for BackgroundSpacing {
    fn at(&self, p: DVec3) -> f64 {
        if !p.is_finite() {
            return f64::NAN;
        }
        let c = self.index(self.coords(p));
        for &t in self.cell_list(c) {
            if let Some(v) = self.inside(t as usize, p) {
                return v;
            }
        }
        self.nearest(p)
    }
}

/// A structured background: the box [lo, hi] split into n^3 cubes of 6 tets each, for tests.
#[cfg(test)]
pub(crate) fn grid_background(
    lo: DVec3,
    hi: DVec3,
    n: usize,
    f: impl Fn(DVec3) -> f64,
) -> BackgroundSpacing {
    let (vertices, tets) = grid_mesh(lo, hi, n);
    let values = vertices.iter().map(|&p| f(p)).collect();
    BackgroundSpacing::new(vertices, tets, values).expect("valid grid background")
}

/// The vertices and tets of [lo, hi] split into n^3 cubes, 6 tets each (Kuhn split).
#[cfg(test)]
pub(crate) fn grid_mesh(lo: DVec3, hi: DVec3, n: usize) -> (Vec<DVec3>, Vec<[u32; 4]>) {
    let m = n + 1;
    let id = |i: usize, j: usize, k: usize| ((k * m + j) * m + i) as u32;
    let mut vertices = Vec::with_capacity(m * m * m);
    for k in 0..m {
        for j in 0..m {
            for i in 0..m {
                let s = DVec3::new(i as f64, j as f64, k as f64) / n as f64;
                vertices.push(lo + (hi - lo) * s);
            }
        }
    }
    let mut tets = Vec::with_capacity(6 * n * n * n);
    for k in 0..n {
        for j in 0..n {
            for i in 0..n {
                let c = |d: usize| id(i + (d & 1), j + ((d >> 1) & 1), k + ((d >> 2) & 1));
                // Kuhn: the 6 monotone paths from corner 0 to corner 7.
                for perm in [
                    [1, 2, 4],
                    [1, 4, 2],
                    [2, 1, 4],
                    [2, 4, 1],
                    [4, 1, 2],
                    [4, 2, 1],
                ] {
                    let a = perm[0];
                    let b = a | perm[1];
                    tets.push([c(0), c(a), c(b), c(7)]);
                }
            }
        }
    }
    (vertices, tets)
}

#[cfg(test)]
mod tests {
    use super::*;
    use rand::{Rng, SeedableRng};
    use rand_chacha::ChaCha8Rng;

    fn linear(p: DVec3) -> f64 {
        0.3 + 0.7 * p.x - 0.2 * p.y + 0.45 * p.z
    }

    #[test]
    fn reproduces_a_linear_field_inside() {
        let bg = grid_background(DVec3::splat(-1.0), DVec3::new(2.0, 1.0, 1.5), 7, |p| {
            linear(p) + 2.0
        });
        let mut rng = ChaCha8Rng::seed_from_u64(1);
        for _ in 0..20_000 {
            let p = DVec3::new(
                rng.gen_range(-1.0..2.0),
                rng.gen_range(-1.0..1.0),
                rng.gen_range(-1.0..1.5),
            );
            let v = bg.at(p);
            assert!((v - linear(p) - 2.0).abs() < 1e-12, "{p}: {v}");
        }
        // Vertices and points on shared faces too.
        for &p in bg.vertices() {
            assert!((bg.at(p) - linear(p) - 2.0).abs() < 1e-12, "{p}");
        }
    }

    #[test]
    fn outside_points_take_the_nearest_value() {
        // The unit cube, f = 1 + x + 2y + 3z.
        let f = |p: DVec3| 1.0 + p.x + 2.0 * p.y + 3.0 * p.z;
        let bg = grid_background(DVec3::ZERO, DVec3::ONE, 4, f);
        let mut rng = ChaCha8Rng::seed_from_u64(2);
        for _ in 0..5_000 {
            let p = DVec3::new(
                rng.gen_range(-3.0..4.0),
                rng.gen_range(-3.0..4.0),
                rng.gen_range(-3.0..4.0),
            );
            let q = p.clamp(DVec3::ZERO, DVec3::ONE);
            assert!(
                (bg.at(p) - f(q)).abs() < 1e-12,
                "{p}: {} vs {}",
                bg.at(p),
                f(q)
            );
        }
        assert!((bg.at(DVec3::new(1e6, -1e6, 0.5)) - f(DVec3::new(1.0, 0.0, 0.5))).abs() < 1e-9);
    }

    #[test]
    fn gaps_between_tets_take_the_nearest_tet() {
        // Two separate tets; a point between them takes the closer one's face value.
        let vertices = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(3.0, 0.0, 0.0),
            DVec3::new(4.0, 0.0, 0.0),
            DVec3::new(3.0, 1.0, 0.0),
            DVec3::new(3.0, 0.0, 1.0),
        ];
        let tets = vec![[0, 1, 2, 3], [4, 5, 6, 7]];
        let values = vec![1.0, 1.0, 1.0, 1.0, 5.0, 5.0, 5.0, 5.0];
        let bg = BackgroundSpacing::new(vertices, tets, values).unwrap();
        assert_eq!(bg.at(DVec3::new(0.2, 0.2, 0.2)), 1.0);
        assert_eq!(bg.at(DVec3::new(1.5, 0.1, 0.1)), 1.0);
        assert_eq!(bg.at(DVec3::new(2.6, 0.1, 0.1)), 5.0);
        assert_eq!(bg.at(DVec3::new(3.2, 0.2, 0.2)), 5.0);
        // A tet listed twice keeps its faces for the nearest search.
        let vertices = vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let bg = BackgroundSpacing::new(vertices, vec![[0, 1, 2, 3]; 2], vec![1.0, 2.0, 1.0, 1.0])
            .unwrap();
        assert_eq!(bg.at(DVec3::new(3.0, 0.0, 0.0)), 2.0);
    }

    #[test]
    fn errors_name_the_offender() {
        let v = || vec![DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        let t = || vec![[0u32, 1, 2, 3]];
        let err = |r: Result<BackgroundSpacing, String>| r.unwrap_err();
        let e = err(BackgroundSpacing::new(
            v(),
            vec![[0, 1, 2, 4]],
            vec![1.0; 4],
        ));
        assert!(
            e.contains("tetrahedron 1") && e.contains("vertex 5") && e.contains("4 vertices"),
            "{e}"
        );
        let e = err(BackgroundSpacing::new(v(), t(), vec![1.0, 1.0, -2.0, 1.0]));
        assert!(e.contains("vertex 3") && e.contains("-2"), "{e}");
        let e = err(BackgroundSpacing::new(
            v(),
            t(),
            vec![1.0, f64::NAN, 1.0, 1.0],
        ));
        assert!(e.contains("vertex 2") && e.contains("NaN"), "{e}");
        let e = err(BackgroundSpacing::new(v(), t(), vec![1.0, 1.0, 0.0, 1.0]));
        assert!(e.contains("vertex 3"), "{e}");
        let e = err(BackgroundSpacing::new(v(), t(), vec![1.0; 3]));
        assert!(e.contains("fewer values (3)") && e.contains("(4)"), "{e}");
        let e = err(BackgroundSpacing::new(v(), t(), vec![1.0; 5]));
        assert!(e.contains("more values (5)"), "{e}");
        let e = err(BackgroundSpacing::new(vec![], vec![], vec![]));
        assert!(e.contains("empty"), "{e}");
        let e = err(BackgroundSpacing::new(v(), vec![], vec![1.0; 4]));
        assert!(e.contains("empty"), "{e}");
        let mut bad = v();
        bad[1].y = f64::INFINITY;
        let e = err(BackgroundSpacing::new(bad, t(), vec![1.0; 4]));
        assert!(e.contains("vertex 2"), "{e}");
    }

    #[test]
    fn flat_tets_are_tolerated() {
        // A flat tet next to a good one: points inside the good one interpolate, others
        // take the nearest face.
        let vertices = vec![
            DVec3::ZERO,
            DVec3::X,
            DVec3::Y,
            DVec3::Z,
            DVec3::new(1.0, 1.0, 0.0),
        ];
        let tets = vec![[0, 1, 2, 3], [0, 1, 4, 2]];
        let bg = BackgroundSpacing::new(vertices, tets, vec![1.0, 2.0, 3.0, 4.0, 5.0]).unwrap();
        let p = DVec3::new(0.1, 0.2, 0.3);
        assert!((bg.at(p) - (1.0 + 0.1 + 0.4 + 0.9)).abs() < 1e-12);
        assert!(bg.at(DVec3::new(0.8, 0.8, -0.5)).is_finite());
    }

    /// Queries per second on a 100k-tet background (run with --ignored --nocapture).
    #[test]
    #[ignore]
    fn query_speed() {
        // 26^3 cubes x 6 = 105,456 tets.
        let bg = grid_background(DVec3::ZERO, DVec3::ONE, 26, |p| 0.02 + 0.18 * p.x);
        let mut rng = ChaCha8Rng::seed_from_u64(3);
        let inside: Vec<DVec3> = (0..2_000_000)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()))
            .collect();
        let outside: Vec<DVec3> = (0..200_000)
            .map(|_| DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 1.2 - DVec3::splat(0.1))
            .collect();
        let time = |pts: &[DVec3]| {
            let t0 = std::time::Instant::now();
            let mut out = vec![0.0; pts.len()];
            bg.at_many(pts, &mut out);
            let s = t0.elapsed().as_secs_f64();
            assert!(out.iter().all(|v| v.is_finite() && *v > 0.0));
            pts.len() as f64 / s
        };
        let t0 = std::time::Instant::now();
        let _ = grid_background(DVec3::ZERO, DVec3::ONE, 26, |p| 0.02 + 0.18 * p.x);
        println!(
            "build {:.3} s for {} tets; inside {:.2e} queries/s; 1.2x box (42% outside) {:.2e} \
             queries/s; grid {:?}, {} tet entries, {} boundary faces",
            t0.elapsed().as_secs_f64(),
            bg.tets().len(),
            time(&inside),
            time(&outside),
            bg.dims,
            bg.cell_tets.len(),
            bg.faces.len()
        );
    }
}
