//! Domain marking: split the triangulation into components bounded by subfacets, drop the
//! ones touching the hull or holding a hole seed (and, for an existing mesh, the ones without
//! a region seed), and give each the attribute of its region seed. Each tet's kernel tag names
//! its component (0 = outside), so tets created later inherit it.

use super::domain::{tri_key, Domain, VertexKind};
use crate::delaunay::{tables::FACE, INFINITE};
use crate::plc::{CellKind, Plc};
use crate::run::error::MeshError;
use crate::surface::oracle::SurfaceOracle;
use crate::surface::InputSurface;
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// Region attribute and size limit of each component tag (index 0 = outside, unused).
#[derive(Debug, Clone, Default)]
pub struct Regions {
    pub attribute: Vec<i32>,
    pub max_size: Vec<Option<f64>>,
}

impl Regions {
    /// Caps the size limit of every component whose attribute is a region id of `sizes`
    /// (`Params::region_sizes`) by its size; an id no component has is an error listing the
    /// input's region attributes.
    pub fn limit_sizes(&mut self, sizes: &[(i32, f64)]) -> Result<(), MeshError> {
        for &(id, h) in sizes {
            let mut found = false;
            for (a, m) in self.attribute.iter().zip(&mut self.max_size).skip(1) {
                if *a == id {
                    found = true;
                    *m = Some(m.map_or(h, |m| m.min(h)));
                }
            }
            if !found {
                return Err(unknown_region(id, &self.attribute[1..]));
            }
        }
        Ok(())
    }
}

/// The error for a region size given for region `id`, which none of `attributes` is.
pub(crate) fn unknown_region(id: i32, attributes: &[i32]) -> MeshError {
    let mut known: Vec<i32> = attributes.to_vec();
    known.sort_unstable();
    known.dedup();
    let list: Vec<String> = known.iter().map(|a| a.to_string()).collect();
    MeshError::InvalidInput(format!(
        "region size given for region {id}, but the input has no such region (its regions: {})",
        list.join(", ")
    ))
}

/// What a component without a region seed becomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Unseeded {
    /// Part of the domain, with attribute 0 (a PLC: seeds are optional).
    Domain,
    /// A hole (an existing mesh: it seeds every piece it has tets in).
    Hole,
}

impl Domain {
    /// Tags every tet with its component: 0 outside (touching the hull, or a hole), else one
    /// tag per inside component with its region's attribute and size limit. Which cells are
    /// holes and which region seed selects a cell are the checked PLC's decisions
    /// (`plc::Plc::cells`); each selecting seed is located in the triangulation to find its
    /// component.
    pub fn mark_domain(&mut self, plc: &Plc, unseeded: Unseeded) -> Result<Regions, MeshError> {
        let (comp, mut outside) = self.components();
        let n_comp = outside.len() as u32;
        let cap = self.dt.tet_capacity();
        let mut attribute: Vec<Option<i32>> = vec![None; n_comp as usize];
        let mut max_size: Vec<Option<f64>> = vec![None; n_comp as usize];
        for cell in &plc.cells {
            let (seed, point) = match cell.kind {
                CellKind::Hole { seed } => (format!("hole {seed}"), plc.holes[seed]),
                CellKind::Domain { region: Some(r) } => {
                    (format!("region {r} seed"), plc.regions[r].point)
                }
                CellKind::Exterior | CellKind::Domain { region: None } => continue,
            };
            let c = comp[self.dt.locate_point(point, None) as usize] as usize;
            if outside[c] {
                // The validator placed the seed in a bounded cell: the triangulation disagrees.
                return Err(MeshError::Internal(format!(
                    "{seed} at ({}, {}, {}) lies in the triangulation's outside",
                    point.x, point.y, point.z
                )));
            }
            match cell.kind {
                CellKind::Domain { region: Some(r) } => {
                    attribute[c] = Some(plc.regions[r].attribute);
                    max_size[c] = plc.regions[r].max_size.filter(|&s| s > 0.0);
                }
                _ => outside[c] = true,
            }
        }
        if unseeded == Unseeded::Hole {
            for (out, a) in outside.iter_mut().zip(&attribute) {
                *out |= a.is_none();
            }
        } else {
            self.number_unseeded(plc, &comp, &outside, &mut attribute);
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

    /// Gives each inside component without a region seed the attribute its PLC cell has in
    /// `Plc::region_attributes` (1, 2, ... when the input has no seeds and several cells):
    /// the cell is the input region holding the centroid of one of its tets, found by the
    /// exact ray crossings of `surface::oracle`.
    fn number_unseeded(
        &self,
        plc: &Plc,
        comp: &[u32],
        outside: &[bool],
        attribute: &mut [Option<i32>],
    ) {
        let attributes = plc.region_attributes();
        if !attributes.iter().any(|&a| a != 0) || !plc.regions.is_empty() {
            return;
        }
        let oracle = SurfaceOracle::new(&InputSurface::from_plc(plc));
        for t in self.dt.finite_tet_ids() {
            let c = comp[t as usize] as usize;
            if outside[c] || attribute[c].is_some() {
                continue;
            }
            let centroid = self
                .dt
                .tet(t)
                .map(|v| self.dt.point(v))
                .iter()
                .sum::<DVec3>()
                / 4.0;
            let region = oracle.region(centroid) as usize;
            attribute[c] = Some(attributes.get(region.wrapping_sub(1)).copied().unwrap_or(0));
        }
    }

    /// Gives the tets in `created` (made since the boundary was last complete) the tag of the
    /// old tets they touch: each group of them joined across faces that are not subfacets takes
    /// the tag of an old neighbour across such a face. A new tet inherits the tag of the cavity
    /// tet that held its outer face, which is wrong where the cavity crossed a subfacet that a
    /// boundary split had deleted for a moment; without this, region labels leak (thousands of
    /// exterior tets labelled inside on the curved models) until the next whole re-marking.
    /// A group whose old neighbours disagree keeps its tags. Returns the tets re-tagged.
    pub fn retag_created(&mut self, created: &[u32]) -> usize {
        let mut index: FxHashMap<u32, u32> = FxHashMap::default();
        let mut tets = Vec::with_capacity(created.len());
        for &t in created {
            if self.dt.is_alive(t) && !index.contains_key(&t) {
                index.insert(t, tets.len() as u32);
                tets.push(t);
            }
        }
        let mut uf = UnionFind::new(tets.len());
        for (i, &t) in tets.iter().enumerate() {
            for (k, n) in self.dt.neighbors(t).into_iter().enumerate() {
                if let Some(&j) = index.get(&n) {
                    if !self.is_subfacet(FACE[k].map(|x| self.dt.tet(t)[x])) {
                        uf.union(i as u32, j);
                    }
                }
            }
        }
        // Per group root: the tag its old neighbours agree on (None: they disagree).
        let mut tag_of: FxHashMap<u32, Option<u32>> = FxHashMap::default();
        for (i, &t) in tets.iter().enumerate() {
            let v = self.dt.tet(t);
            for (k, n) in self.dt.neighbors(t).into_iter().enumerate() {
                if index.contains_key(&n) || self.is_subfacet(FACE[k].map(|x| v[x])) {
                    continue;
                }
                let tag = self.dt.tag(n);
                tag_of
                    .entry(uf.find(i as u32))
                    .and_modify(|g| {
                        if *g != Some(tag) {
                            *g = None;
                        }
                    })
                    .or_insert(Some(tag));
            }
        }
        let mut changed = 0;
        for (i, &t) in tets.iter().enumerate() {
            if let Some(&Some(tag)) = tag_of.get(&uf.find(i as u32)) {
                if self.dt.tag(t) != tag {
                    self.dt.set_tag(t, tag);
                    changed += 1;
                }
            }
        }
        changed
    }

    /// Whether face f (three vertex ids) is a subfacet. Only a face whose three vertices lie
    /// on the boundary can be one: that is tested before the hash lookup (most faces have a
    /// volume vertex).
    fn is_subfacet(&self, f: [u32; 3]) -> bool {
        !f.contains(&INFINITE)
            && f.iter()
                .all(|&x| self.kind[x as usize] != VertexKind::Volume)
            && self.subfacets.contains_key(&tri_key(f))
    }

    /// The components of the triangulation bounded by subfacets: the component of every tet
    /// slot (numbered in the order of their smallest tet id; dead slots: whatever) and, per
    /// component, whether it touches the hull.
    fn components(&self) -> (Vec<u32>, Vec<bool>) {
        let cap = self.dt.tet_capacity();
        // Union-find over the faces that are not subfacets, scanning the tets in memory order
        // (a flood fill would visit them in a cache-hostile order). Each face once: from the
        // tet with the smaller id.
        let mut uf = UnionFind::new(cap);
        for t in 0..cap as u32 {
            if !self.dt.is_alive(t) {
                continue;
            }
            let v = self.dt.tet(t);
            for (i, n) in self.dt.neighbors(t).into_iter().enumerate() {
                if n > t && !self.is_subfacet(FACE[i].map(|k| v[k])) {
                    uf.union(t, n);
                }
            }
        }
        // Components numbered in the order of their smallest tet id.
        let mut comp = vec![u32::MAX; cap];
        let mut outside = vec![];
        let mut n_comp = 0u32;
        for t in 0..cap as u32 {
            if !self.dt.is_alive(t) {
                continue;
            }
            let r = uf.find(t) as usize;
            if comp[r] == u32::MAX {
                comp[r] = n_comp;
                n_comp += 1;
                outside.push(false);
            }
            let c = comp[r];
            comp[t as usize] = c;
            if !self.dt.is_finite(t) {
                outside[c as usize] = true; // touches the hull
            }
        }
        (comp, outside)
    }
}
