//! Several solids in one surface file (the `solid` blocks of an ASCII STL, the groups of an
//! OBJ): a polygon that two solids share (the same vertices, listed once by each) is one
//! interface facet,
//! and each solid gets a region seed with its 1-based place in the file as attribute, so
//! that the regions are labelled the way the file names them.

use crate::plc::Region;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// The polygons of a soup (triangles, or any polygon fanned from its first corner in the
/// geometric tests), each with the solid (0-based, file order) it was read in.
pub struct Solids {
    pub polygons: Vec<Vec<u32>>,
    pub solid_of: Vec<u32>,
}

impl Solids {
    /// Whether solid `s` is a closed surface: every edge of its polygons used by two of them.
    pub fn is_closed(&self, s: u32) -> bool {
        let mut count: FxHashMap<[u32; 2], u32> = FxHashMap::default();
        for (p, _) in self
            .polygons
            .iter()
            .zip(&self.solid_of)
            .filter(|x| *x.1 == s)
        {
            for (i, &a) in p.iter().enumerate() {
                let b = p[(i + 1) % p.len()];
                *count.entry([a.min(b), a.max(b)]).or_default() += 1;
            }
        }
        count.values().all(|&n| n == 2)
    }

    /// Drops every triangle that an earlier solid already listed with the same vertices (an
    /// interface: one facet, two regions). Triangles repeated within one solid are kept, for
    /// the validator to name.
    pub fn merge_shared(&mut self) {
        let mut first: FxHashMap<Vec<u32>, u32> = FxHashMap::default();
        let mut keep = vec![true; self.polygons.len()];
        for (i, t) in self.polygons.iter().enumerate() {
            let mut key = t.clone();
            key.sort_unstable();
            match first.get(&key) {
                Some(&j) if self.solid_of[j as usize] != self.solid_of[i] => keep[i] = false,
                Some(_) => {}
                None => {
                    first.insert(key, i as u32);
                }
            }
        }
        let mut k = keep.iter();
        self.polygons.retain(|_| *k.next().unwrap_or(&true));
        let mut k = keep.iter();
        self.solid_of.retain(|_| *k.next().unwrap_or(&true));
    }

    /// One region seed per solid of `n_solids` (attribute = its 1-based place): the point
    /// half-way between the centroid of the solid's largest triangle and the first triangle
    /// of the whole soup that a ray from there into the solid meets. Which way is into the
    /// solid comes from the sign of its enclosed volume. `triangles` are those of each solid
    /// as read (before `merge_shared`). A solid whose ray meets nothing (not closed) gets no
    /// seed; the validator places seeds exactly.
    pub fn region_seeds(&self, vertices: &[DVec3], n_solids: usize) -> Vec<Region> {
        // Every polygon as the triangles of its fan.
        let fan = |p: &[u32]| -> Vec<[DVec3; 3]> {
            (1..p.len() - 1)
                .map(|i| [p[0], p[i], p[i + 1]].map(|v| vertices[v as usize]))
                .collect()
        };
        let all: Vec<[DVec3; 3]> = self.polygons.iter().flat_map(|p| fan(p)).collect();
        let mut seeds = vec![];
        for s in 0..n_solids as u32 {
            let own: Vec<[DVec3; 3]> = self
                .polygons
                .iter()
                .zip(&self.solid_of)
                .filter(|(_, &k)| k == s)
                .flat_map(|(p, _)| fan(p))
                .collect();
            let volume: f64 = own.iter().map(|[a, b, c]| a.dot(b.cross(*c))).sum();
            let area = |[a, b, c]: &[DVec3; 3]| (*b - *a).cross(*c - *a).length();
            let Some(&[a, b, c]) = own.iter().max_by(|x, y| area(x).total_cmp(&area(y))) else {
                continue;
            };
            let normal = (b - a).cross(c - a).normalize_or_zero();
            let inwards = if volume >= 0.0 { -normal } else { normal };
            let from = (a + b + c) / 3.0;
            let nearest = all
                .iter()
                .filter_map(|&t| ray_hit(from, inwards, t))
                .filter(|&d| d > 0.0)
                .fold(f64::INFINITY, f64::min);
            if nearest.is_finite() {
                seeds.push(Region {
                    point: from + inwards * (nearest / 2.0),
                    attribute: s as i32 + 1,
                    max_size: None,
                });
            }
        }
        seeds
    }
}

/// Distance along the unit direction `dir` from `from` to triangle `[a, b, c]`, if the ray
/// meets it away from `from` (Möller–Trumbore; only a seed's construction depends on it).
fn ray_hit(from: DVec3, dir: DVec3, [a, b, c]: [DVec3; 3]) -> Option<f64> {
    let (e1, e2) = (b - a, c - a);
    let p = dir.cross(e2);
    let det = e1.dot(p);
    if det.abs() <= 1e-300 {
        return None;
    }
    let s = from - a;
    let u = s.dot(p) / det;
    let q = s.cross(e1);
    let v = dir.dot(q) / det;
    if !(0.0..=1.0).contains(&u) || v < 0.0 || u + v > 1.0 {
        return None;
    }
    let d = e2.dot(q) / det;
    (d > 1e-12 * (e1.length() + e2.length())).then_some(d)
}
