//! Combinatorics of the checked facets: the global triangle list, which triangles use each
//! edge, the segment list, and the closed-surface check.

use super::error::PlcError;
use super::facet::PlcFacet;
use rustc_hash::FxHashMap;

/// An input segment: a polygon edge, shared by every facet that has it as a polygon edge.
#[derive(Debug, Clone, PartialEq)]
pub struct Segment {
    /// Endpoint vertex ids, smaller first.
    pub vertices: [u32; 2],
    /// Facets with this segment as a polygon edge, ascending.
    pub facets: Vec<u32>,
    /// The facet triangles around the segment, counter-clockwise about the axis
    /// `vertices[0] → vertices[1]` (right-hand rule). A facet that has the segment inside
    /// (an interior polygon edge) appears twice.
    pub fan: Vec<FanEntry>,
}

/// One facet triangle in a segment's fan, and the cell in the wedge that follows it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FanEntry {
    pub facet: u32,
    /// Index into that facet's `triangles`.
    pub triangle: u32,
    /// Cell between this triangle and the next one counter-clockwise.
    pub cell_after: u32,
}

/// Flattened view of all facet triangles plus edge incidence.
pub(crate) struct Topology {
    /// Global triangle list: (facet, index in facet, vertices).
    pub tris: Vec<(u32, u32, [u32; 3])>,
    /// Sorted edge → global triangle ids using it.
    pub edge_tris: FxHashMap<[u32; 2], Vec<u32>>,
    pub segments: Vec<Segment>,
    /// Sorted edge → index in `segments`.
    pub segment_of: FxHashMap<[u32; 2], usize>,
}

pub(crate) fn sorted(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

impl Topology {
    pub fn build(facets: &[PlcFacet]) -> Topology {
        let mut tris = Vec::new();
        let mut edge_tris: FxHashMap<[u32; 2], Vec<u32>> = FxHashMap::default();
        for (k, f) in facets.iter().enumerate() {
            for (i, &t) in f.triangles.iter().enumerate() {
                let id = tris.len() as u32;
                tris.push((k as u32, i as u32, t));
                for j in 0..3 {
                    edge_tris
                        .entry(sorted(t[j], t[(j + 1) % 3]))
                        .or_default()
                        .push(id);
                }
            }
        }
        let mut segments: Vec<Segment> = Vec::new();
        let mut segment_of: FxHashMap<[u32; 2], usize> = FxHashMap::default();
        for (k, f) in facets.iter().enumerate() {
            for e in f.segments() {
                let s = *segment_of.entry(e).or_insert_with(|| {
                    segments.push(Segment {
                        vertices: e,
                        facets: Vec::new(),
                        fan: Vec::new(),
                    });
                    segments.len() - 1
                });
                if segments[s].facets.last() != Some(&(k as u32)) {
                    segments[s].facets.push(k as u32);
                }
            }
        }
        Topology {
            tris,
            edge_tris,
            segments,
            segment_of,
        }
    }

    /// True iff `edge` is a polygon edge of facet `facet`.
    pub fn is_segment_of(&self, edge: [u32; 2], facet: u32) -> bool {
        self.segment_of
            .get(&edge)
            .is_some_and(|&s| self.segments[s].facets.contains(&facet))
    }

    /// Every segment must border at least two facet triangles, or the surface has a free
    /// edge and encloses no volume there.
    pub fn check_closed(&self) -> Result<(), PlcError> {
        for s in &self.segments {
            let users = &self.edge_tris[&s.vertices];
            if users.len() < 2 {
                return Err(PlcError::SurfaceNotClosed {
                    edge: s.vertices,
                    facet: self.tris[users[0] as usize].0 as usize,
                });
            }
        }
        Ok(())
    }
}
