//! Domain marking: split the triangulation into components bounded by subfacets, drop the
//! ones touching the hull or holding a hole seed, and give each the attribute of its region
//! seed. Each tet's kernel tag names its component (0 = outside), so tets created later
//! inherit it.

use super::domain::{tri_key, Domain, VertexKind};
use super::MeshError;
use crate::delaunay::{tables::FACE, INFINITE};
use crate::plc::PlcInput;

/// Region attribute and size limit of each component tag (index 0 = outside, unused).
#[derive(Debug, Clone, Default)]
pub struct Regions {
    pub attribute: Vec<i32>,
    pub max_size: Vec<Option<f64>>,
}

impl Domain {
    pub fn mark_domain(&mut self, input: &PlcInput) -> Result<Regions, MeshError> {
        let cap = self.dt.tet_capacity();
        let mut comp = vec![u32::MAX; cap];
        let mut outside = vec![];
        let mut n_comp = 0u32;
        let mut stack = vec![];
        // Only a face whose three vertices lie on the boundary can be a subfacet: test that
        // before the hash lookup (most faces have a volume vertex).
        let on_boundary: Vec<bool> = self.kind.iter().map(|&k| k != VertexKind::Volume).collect();
        let is_subfacet_face = |t: u32, i: usize| {
            let v = self.dt.tet(t);
            let f = FACE[i].map(|k| v[k]);
            !f.contains(&INFINITE)
                && f.iter().all(|&x| on_boundary[x as usize])
                && self.subfacets.contains_key(&tri_key(f))
        };
        for start in 0..cap as u32 {
            if !self.dt.is_alive(start) || comp[start as usize] != u32::MAX {
                continue;
            }
            let id = n_comp;
            n_comp += 1;
            let mut touches_hull = false;
            comp[start as usize] = id;
            stack.push(start);
            while let Some(t) = stack.pop() {
                if !self.dt.is_finite(t) {
                    touches_hull = true;
                }
                let nb = self.dt.neighbors(t);
                for (i, &n) in nb.iter().enumerate() {
                    if comp[n as usize] == u32::MAX && !is_subfacet_face(t, i) {
                        comp[n as usize] = id;
                        stack.push(n);
                    }
                }
            }
            outside.push(touches_hull);
        }
        let mut attribute: Vec<Option<i32>> = vec![None; n_comp as usize];
        let mut max_size: Vec<Option<f64>> = vec![None; n_comp as usize];
        for (k, h) in input.holes.iter().enumerate() {
            let t = self.dt.locate_point(*h, None);
            let c = comp[t as usize] as usize;
            if outside[c] {
                return Err(MeshError::InvalidInput(format!(
                    "hole {k} at ({}, {}, {}) is outside the domain",
                    h.x, h.y, h.z
                )));
            }
            outside[c] = true;
        }
        for (k, r) in input.regions.iter().enumerate() {
            let t = self.dt.locate_point(r.point, None);
            let c = comp[t as usize] as usize;
            if outside[c] {
                return Err(MeshError::InvalidInput(format!(
                    "region {k} seed ({}, {}, {}) is outside the domain or in a hole",
                    r.point.x, r.point.y, r.point.z
                )));
            }
            attribute[c] = Some(r.attribute);
            max_size[c] = r.max_size.filter(|&s| s > 0.0);
        }
        // Tags: 0 outside, then one per inside component.
        let mut tag_of = vec![0u32; n_comp as usize];
        let mut regions = Regions {
            attribute: vec![0],
            max_size: vec![None],
        };
        for c in 0..n_comp as usize {
            if !outside[c] {
                tag_of[c] = regions.attribute.len() as u32;
                regions.attribute.push(attribute[c].unwrap_or(0));
                regions.max_size.push(max_size[c]);
            }
        }
        if regions.attribute.len() == 1 {
            return Err(MeshError::InvalidInput(
                "the boundary encloses no volume (every tet is outside)".into(),
            ));
        }
        for t in 0..cap as u32 {
            if self.dt.is_alive(t) {
                self.dt.set_tag(t, tag_of[comp[t as usize] as usize]);
            }
        }
        Ok(regions)
    }
}
