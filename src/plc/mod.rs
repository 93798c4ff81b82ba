//! Piecewise linear complex: the domain description and its validation.
//!
//! `PlcInput` is what readers and the API build; [`validate`] turns it into a checked [`Plc`]
//! or a [`PlcError`] naming the offending item. Submodules, one job each:
//! `exact` (2D/3D incidence tests on `geom::orient3d`), `plane` (best-fit planes),
//! `facet` (one facet: polygons, holes, triangulation), `topology` (segments, closure),
//! `intersect` (facet–facet intersections), `cells` (enclosed volumes, seeds),
//! `angles` (acute-angle report), `error`.

use glam::DVec3;

mod angles;
mod cells;
pub mod coplanar;
mod error;
pub(crate) mod exact;
mod facet;
pub(crate) mod intersect;
mod plane;
mod topology;

pub use angles::{AcuteAngles, DihedralAngle, SegmentAngle, RIGHT_ANGLE_SLACK};
pub use cells::{Cell, CellKind};
pub use error::{PlcError, PolygonKind, PolygonRef, Seed};
pub use facet::{build_facet as check_facet, FacetLoop, PlcFacet};
pub use plane::{Plane, PLANARITY_TOLERANCE};
use topology::Topology;
pub use topology::{FanEntry, Segment};

/// One planar polygonal facet, possibly with polygonal holes inside it.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct Facet {
    /// Outer polygon(s): 0-based vertex ids in order around the polygon. TetGen facets may carry
    /// several polygons (e.g. a polygon and dangling segments); most have exactly one.
    pub polygons: Vec<Vec<u32>>,
    /// Points inside the facet's plane marking holes in the facet (TetGen style), if any.
    pub hole_points: Vec<DVec3>,
    /// Hole polygons given explicitly (C ABI `sm_add_facet_hole`).
    pub hole_polygons: Vec<Vec<u32>>,
    /// Boundary marker copied to every output boundary triangle of this facet.
    pub marker: i32,
}

/// A region seed: every tet in the connected component holding `point` gets `attribute`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Region {
    pub point: DVec3,
    pub attribute: i32,
    /// Maximum tet size (edge-length scale) in this region; `None` or non-positive = no limit.
    pub max_size: Option<f64>,
}

/// What the report compares each output region with (`Plc::input_regions`).
#[derive(Debug, Clone, Default, PartialEq)]
pub struct InputRegions {
    /// (attribute, volume), sorted by attribute.
    pub volumes: Vec<(i32, f64)>,
    /// Area of the faces between regions of different attributes.
    pub interface_area: f64,
}

/// The unvalidated domain description, as read from a file or built through the API.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct PlcInput {
    pub vertices: Vec<DVec3>,
    pub facets: Vec<Facet>,
    /// Volume hole seeds: the connected component holding each point is removed.
    pub holes: Vec<DVec3>,
    pub regions: Vec<Region>,
}

/// A checked piecewise linear complex: what refinement starts from.
#[derive(Debug, Clone, PartialEq)]
pub struct Plc {
    pub vertices: Vec<DVec3>,
    pub facets: Vec<PlcFacet>,
    /// Unique polygon edges, sorted by vertex pair, each with the facets that use it and the
    /// facet triangles around it in angular order.
    pub segments: Vec<Segment>,
    pub holes: Vec<DVec3>,
    pub regions: Vec<Region>,
    /// Connected components of space minus the surface; `cells[0]` is the exterior.
    pub cells: Vec<Cell>,
    /// Vertices on no facet (to be inserted into the mesh as they are).
    pub isolated_vertices: Vec<u32>,
}

impl Plc {
    /// Volume to be meshed: the bounded cells that are not holes.
    pub fn volume(&self) -> f64 {
        self.cells
            .iter()
            .filter(|c| matches!(c.kind, CellKind::Domain { .. }))
            .map(|c| c.volume)
            .sum()
    }

    /// The cells to be meshed (bounded, not holes), in cell order: what `region_of_cell`
    /// numbers 1, 2, ...
    pub fn domain_cells(&self) -> impl Iterator<Item = (usize, &Cell)> {
        self.cells
            .iter()
            .enumerate()
            .filter(|(_, c)| matches!(c.kind, CellKind::Domain { .. }))
    }

    /// Per cell: 0 for the exterior and holes, else the cell's place in `domain_cells` + 1.
    pub fn region_of_cell(&self) -> Vec<u32> {
        let mut out = vec![0; self.cells.len()];
        for (k, (c, _)) in self.domain_cells().enumerate() {
            out[c] = k as u32 + 1;
        }
        out
    }

    /// The attribute of each domain cell, in `domain_cells` order: its region seed's where
    /// one lies in it; else, when the input has no region seeds and more than one domain
    /// cell, its place in that order (1, 2, ...: the order in which the cells' outer
    /// boundaries first appear among the facets); else 0.
    pub fn region_attributes(&self) -> Vec<i32> {
        let n = self.domain_cells().count();
        let number = self.regions.is_empty() && n > 1;
        self.domain_cells()
            .enumerate()
            .map(|(k, (_, c))| match c.kind {
                CellKind::Domain { region: Some(r) } => self.regions[r].attribute,
                _ if number => k as i32 + 1,
                _ => 0,
            })
            .collect()
    }

    /// The input's regions: the volume of each attribute (`region_attributes`; cells with the
    /// same attribute summed, sorted by attribute) and the area of the facet triangles between
    /// two domain cells of different attributes.
    pub fn input_regions(&self) -> InputRegions {
        let attributes = self.region_attributes();
        let mut volumes: Vec<(i32, f64)> = vec![];
        for (&a, (_, c)) in attributes.iter().zip(self.domain_cells()) {
            match volumes.iter_mut().find(|v| v.0 == a) {
                Some(v) => v.1 += c.volume,
                None => volumes.push((a, c.volume)),
            }
        }
        volumes.sort_by_key(|v| v.0);
        let region_of_cell = self.region_of_cell();
        let attribute = |c: u32| match region_of_cell[c as usize] {
            0 => None,
            r => Some(attributes[r as usize - 1]),
        };
        let mut interface_area = 0.0;
        for f in &self.facets {
            for (t, cells) in f.triangles.iter().zip(&f.triangle_cells) {
                if let (Some(x), Some(y)) = (attribute(cells[0]), attribute(cells[1])) {
                    if x != y {
                        let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                        interface_area += (b - a).cross(c - a).length() / 2.0;
                    }
                }
            }
        }
        InputRegions {
            volumes,
            interface_area,
        }
    }

    /// Sum of all facet areas.
    pub fn total_facet_area(&self) -> f64 {
        self.facets.iter().map(|f| f.area).sum()
    }

    /// Area of the facets (or parts of facets) with the domain on at least one side: the
    /// boundary of the meshed volume plus internal facets between domain cells.
    pub fn boundary_area(&self) -> f64 {
        let in_domain = |c: u32| matches!(self.cells[c as usize].kind, CellKind::Domain { .. });
        let mut area = 0.0;
        for f in &self.facets {
            for (t, cells) in f.triangles.iter().zip(&f.triangle_cells) {
                if in_domain(cells[0]) || in_domain(cells[1]) {
                    let [a, b, c] = t.map(|v| self.vertices[v as usize]);
                    area += (b - a).cross(c - a).length() / 2.0;
                }
            }
        }
        area
    }

    /// The segment joining vertices a and b, if any.
    pub fn segment(&self, a: u32, b: u32) -> Option<&Segment> {
        let key = [a.min(b), a.max(b)];
        self.segments
            .binary_search_by(|s| s.vertices.cmp(&key))
            .ok()
            .map(|i| &self.segments[i])
    }

    /// Input angles below 90° between segments and between facets (inside the domain).
    pub fn acute_angles(&self) -> AcuteAngles {
        angles::acute_angles(self)
    }
}

/// Checks a domain description and builds the checked complex: vertices, planar facets with
/// holes and their triangulations, segments, cells with holes and regions applied.
///
/// Checks, in order: vertex coordinates, duplicate vertices, each facet (indices, polygon
/// sizes, repeated vertices, planarity, simple polygons, holes inside the facet), a closed
/// surface, facets meeting only along shared edges and vertices, isolated vertices off the
/// facets, and seeds inside the enclosed volume. The first failure is returned.
pub fn validate(input: &PlcInput) -> Result<Plc, PlcError> {
    if input.facets.is_empty() {
        return Err(PlcError::NoFacets);
    }
    let vertices = &input.vertices;
    for (i, &p) in vertices.iter().enumerate() {
        crate::geom::check_coordinate(p).map_err(|reason| PlcError::BadCoordinate {
            vertex: i,
            coords: p,
            reason,
        })?;
    }
    check_duplicates(vertices)?;
    let mut facets = input
        .facets
        .iter()
        .enumerate()
        .map(|(k, f)| check_facet(k, f, vertices))
        .collect::<Result<Vec<_>, _>>()?;
    let mut topo = Topology::build(&facets);
    topo.check_closed()?;
    intersect::check_facet_intersections(vertices, &topo)?;
    let mut used = vec![false; vertices.len()];
    for &(_, _, t) in &topo.tris {
        t.iter().for_each(|&v| used[v as usize] = true);
    }
    let isolated_vertices: Vec<u32> = (0..vertices.len() as u32)
        .filter(|&v| !used[v as usize])
        .collect();
    intersect::check_isolated_vertices(vertices, &isolated_vertices, &topo)?;

    let map = cells::build_cells(vertices, &mut topo, &input.holes, &input.regions)?;
    for (t, &(k, _, _)) in topo.tris.iter().enumerate() {
        facets[k as usize]
            .triangle_cells
            .push(map.triangle_cells[t]);
    }
    let mut segments = topo.segments;
    segments.sort_by_key(|s| s.vertices);
    Ok(Plc {
        vertices: vertices.clone(),
        facets,
        segments,
        holes: input.holes.clone(),
        regions: input.regions.clone(),
        cells: map.cells,
        isolated_vertices,
    })
}

/// Two vertices at the same coordinates (sorted by coordinates; -0 equals 0).
fn check_duplicates(vertices: &[DVec3]) -> Result<(), PlcError> {
    let key = |p: &DVec3| p.to_array();
    let mut order: Vec<usize> = (0..vertices.len()).collect();
    // Coordinates are finite here, so partial_cmp is total.
    order.sort_by(|&i, &j| {
        let (a, b) = (key(&vertices[i]), key(&vertices[j]));
        a.partial_cmp(&b).unwrap().then(i.cmp(&j))
    });
    for w in order.windows(2) {
        if vertices[w[0]] == vertices[w[1]] {
            return Err(PlcError::DuplicateVertex {
                first: w[0].min(w[1]),
                second: w[0].max(w[1]),
                coords: vertices[w[0]],
            });
        }
    }
    Ok(())
}

#[cfg(test)]
pub(crate) mod tests;
