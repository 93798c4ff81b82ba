//! The invariants of keep mode's boundary complex against the 3D triangulation, checked from
//! scratch (for tests; refinement keeps them incrementally): the subsegment and subfacet maps
//! are exactly the facet triangulations' constrained edges and triangles, every vertex's kind
//! agrees with where it lies, every facet triangulation is valid (not necessarily Delaunay in
//! 2D: `recover::flip_to_match` takes the 3D triangulation's diagonal), and, once the queues are
//! worked off, every subsegment is an edge and every subfacet a face of the triangulation,
//! unencroached unless protected.

use super::domain::{seg_key, tri_key, Domain, VertexKind};
use super::recover::Status;
use rustc_hash::FxHashMap;

impl Domain {
    /// Checks the invariants above; names the first element that breaks one.
    pub fn check(&self) -> Result<(), String> {
        if !self.dirty_segs.is_empty() || !self.dirty_tris.is_empty() {
            return Err("boundary queues not worked off".into());
        }
        if self.kind.len() != self.dt.num_vertex_ids() {
            return Err(format!(
                "{} vertex kinds for {} vertices",
                self.kind.len(),
                self.dt.num_vertex_ids()
            ));
        }
        self.check_subfacets()?;
        self.check_subsegments()?;
        self.check_vertex_kinds()
    }

    /// The subfacet map is the facet triangulations' triangles, each a conforming face.
    fn check_subfacets(&self) -> Result<(), String> {
        let mut n = 0;
        for (f, fm) in self.facets.iter().enumerate() {
            fm.validate_structure()
                .map_err(|e| format!("facet {f}: {e}"))?;
            for t in fm.triangles() {
                n += 1;
                let key = tri_key(t);
                if self.subfacets.get(&key) != Some(&(f as u32)) {
                    return Err(format!("facet {f}'s triangle {key:?} is not its subfacet"));
                }
                match self.subfacet_status(key) {
                    Status::Ok => {}
                    s => return Err(format!("subfacet {key:?} of facet {f}: {s:?}")),
                }
            }
        }
        if n != self.subfacets.len() {
            return Err(format!(
                "{} subfacets, {n} facet triangles",
                self.subfacets.len()
            ));
        }
        Ok(())
    }

    /// The subsegment map is the facet triangulations' constrained edges, each a conforming
    /// edge whose ends lie on its segment.
    fn check_subsegments(&self) -> Result<(), String> {
        let mut edges: FxHashMap<(u32, u32), ()> = FxHashMap::default();
        for fm in &self.facets {
            edges.extend(
                fm.constrained_edges()
                    .iter()
                    .map(|e| (seg_key(e[0], e[1]), ())),
            );
        }
        if edges.len() != self.subsegs.len() {
            return Err(format!(
                "{} subsegments, {} constrained facet edges",
                self.subsegs.len(),
                edges.len()
            ));
        }
        for (&(a, b), &s) in &self.subsegs {
            if !edges.contains_key(&(a, b)) {
                return Err(format!(
                    "subsegment ({a}, {b}) is no facet's constrained edge"
                ));
            }
            for v in [a, b] {
                let on = match self.kind[v as usize] {
                    VertexKind::Segment(t) => t == s,
                    VertexKind::Input => self.segments[s as usize].ends.contains(&v),
                    _ => false,
                };
                if !on {
                    return Err(format!(
                        "subsegment ({a}, {b}): vertex {v} is off segment {s}"
                    ));
                }
            }
            match self.subsegment_status(a, b) {
                Status::Ok => {}
                st => return Err(format!("subsegment ({a}, {b}) of segment {s}: {st:?}")),
            }
        }
        Ok(())
    }

    /// A segment vertex ends two subsegments of its segment; a facet vertex is a vertex of
    /// its facet's triangulation.
    fn check_vertex_kinds(&self) -> Result<(), String> {
        let mut ends: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
        for (&(a, b), &s) in &self.subsegs {
            ends.entry(a).or_default().push(s);
            ends.entry(b).or_default().push(s);
        }
        for (v, kind) in self.kind.iter().enumerate() {
            let v = v as u32;
            let ok = match *kind {
                VertexKind::Segment(s) => ends.get(&v).is_some_and(|e| e == &[s, s]),
                VertexKind::Facet(f) => self.facets[f as usize].point(v).is_some(),
                VertexKind::Input | VertexKind::Volume => true,
            };
            if !ok {
                return Err(format!("vertex {v} ({kind:?}) is not where its kind says"));
            }
        }
        Ok(())
    }
}
