//! Validation errors. Every message names the offending item; vertex ids are the 0-based
//! indices into `PlcInput::vertices`, facet/polygon/seed indices are 0-based positions in the
//! corresponding `PlcInput` lists.

use crate::geom::CoordError;
use glam::DVec3;
use std::fmt;

/// Which polygon list of a facet a polygon comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum PolygonKind {
    /// `Facet::polygons`
    Outer,
    /// `Facet::hole_polygons`
    Hole,
}

/// Names one input polygon: `Facet::polygons[index]` or `Facet::hole_polygons[index]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct PolygonRef {
    pub facet: usize,
    pub kind: PolygonKind,
    pub index: usize,
}

impl fmt::Display for PolygonRef {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self.kind {
            PolygonKind::Outer => write!(f, "polygon {} of facet {}", self.index, self.facet),
            PolygonKind::Hole => write!(f, "hole polygon {} of facet {}", self.index, self.facet),
        }
    }
}

/// A volume seed: `PlcInput::holes[i]` or `PlcInput::regions[i]`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Seed {
    Hole(usize),
    Region(usize),
}

impl fmt::Display for Seed {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Seed::Hole(i) => write!(f, "hole seed {i}"),
            Seed::Region(i) => write!(f, "region seed {i}"),
        }
    }
}

/// Why a `PlcInput` is not a valid piecewise linear complex.
#[derive(Debug, Clone, PartialEq)]
pub enum PlcError {
    /// The input has no facets, so it bounds no volume.
    NoFacets,
    /// A vertex coordinate is NaN/infinite or outside the exact-predicate range.
    BadCoordinate {
        vertex: usize,
        coords: DVec3,
        reason: CoordError,
    },
    /// Two input vertices have identical coordinates (`first < second`).
    DuplicateVertex {
        first: usize,
        second: usize,
        coords: DVec3,
    },
    /// A facet has no outer polygon.
    EmptyFacet { facet: usize },
    /// A polygon refers to a vertex id that does not exist.
    IndexOutOfRange {
        polygon: PolygonRef,
        position: usize,
        index: u32,
        num_vertices: usize,
    },
    /// A polygon with 2 vertices, or a hole polygon with fewer than 3 (an outer polygon of one
    /// vertex is a lone point of the facet).
    TooFewVertices { polygon: PolygonRef, count: usize },
    /// A lone point of a facet (a one-vertex polygon) lies on one of its polygon edges or
    /// outside the region the facet covers.
    LonePointOffFacet {
        polygon: PolygonRef,
        vertex: u32,
        on_edge: bool,
    },
    /// A vertex id appears twice in one polygon.
    RepeatedVertex { polygon: PolygonRef, vertex: u32 },
    /// The facet's vertices are (numerically) collinear: it has no plane.
    DegenerateFacet { facet: usize },
    /// A facet vertex is too far from the facet's best-fit plane.
    NonPlanarFacet {
        facet: usize,
        vertex: u32,
        coords: DVec3,
        distance: f64,
        tolerance: f64,
    },
    /// Two distinct vertices of a facet land on the same point of the facet's 2D projection.
    CoincidentInPlane {
        facet: usize,
        first: u32,
        second: u32,
    },
    /// Two polygon edges of one facet intersect other than at a shared endpoint.
    EdgesIntersect {
        first: (PolygonRef, [u32; 2]),
        second: (PolygonRef, [u32; 2]),
    },
    /// A hole polygon does not lie inside its facet's outer polygon(s).
    HoleOutsideFacet { polygon: PolygonRef },
    /// A facet hole point lies outside the facet (or in an already removed hole).
    HolePointOutsideFacet {
        facet: usize,
        hole: usize,
        point: DVec3,
    },
    /// A facet hole point is not finite or lies off the facet's plane (beyond the planarity
    /// tolerance): it probably belongs to another facet.
    HolePointOffPlane {
        facet: usize,
        hole: usize,
        point: DVec3,
        distance: f64,
    },
    /// A facet hole point lies on a polygon edge or vertex, so it marks no side.
    HolePointOnEdge {
        facet: usize,
        hole: usize,
        point: DVec3,
    },
    /// A polygon edge has the facet on neither side (e.g. a polygon inside a hole).
    EdgeOutsideFacet { polygon: PolygonRef, edge: [u32; 2] },
    /// Two facets intersect other than along shared edges and vertices.
    FacetsIntersect {
        facets: [usize; 2],
        /// A witness: a triangle of each facet's triangulation; they overlap.
        triangles: [[u32; 3]; 2],
    },
    /// Two facets share an edge that is a polygon edge of only one of them (or neither):
    /// one facet passes through the other's boundary.
    FacetsMeetOffSegment { facets: [usize; 2], edge: [u32; 2] },
    /// A vertex used by no facet lies on a facet (it would have to be one of its vertices).
    VertexOnFacet {
        vertex: usize,
        coords: DVec3,
        facet: usize,
    },
    /// A segment is used by only one facet: the surface is open there.
    SurfaceNotClosed { edge: [u32; 2], facet: usize },
    /// A hole or region seed lies outside the bounding box of the vertices.
    SeedOutsideBoundingBox { seed: Seed, point: DVec3 },
    /// A hole or region seed lies exactly on a facet.
    SeedOnFacet {
        seed: Seed,
        point: DVec3,
        facet: usize,
    },
    /// A hole or region seed lies outside every enclosed volume.
    SeedOutsideDomain { seed: Seed, point: DVec3 },
    /// A region seed lies in a volume removed by a hole seed.
    RegionInHole { region: usize, hole: usize },
    /// Two region seeds in the same volume disagree on attribute or size.
    ConflictingRegions { first: usize, second: usize },
    /// Every enclosed volume is a hole: nothing is left to mesh.
    EmptyDomain,
}

/// Debug formatting of f64 keeps huge and tiny values short (1e31, not 31 digits).
fn fmt_point(p: DVec3) -> String {
    format!("({:?}, {:?}, {:?})", p.x, p.y, p.z)
}

impl fmt::Display for PlcError {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        use PlcError::*;
        match self {
            NoFacets => write!(f, "the input has no facets, so it encloses no volume"),
            BadCoordinate {
                vertex,
                coords,
                reason,
            } => write!(f, "vertex {vertex} at {}: {reason}", fmt_point(*coords)),
            DuplicateVertex {
                first,
                second,
                coords,
            } => write!(
                f,
                "vertices {first} and {second} are duplicates: both at {}",
                fmt_point(*coords)
            ),
            EmptyFacet { facet } => write!(f, "facet {facet} has no polygon"),
            IndexOutOfRange {
                polygon,
                position,
                index,
                num_vertices,
            } => write!(
                f,
                "{polygon}: vertex id {index} at position {position} is out of range \
                 (there are {num_vertices} vertices)"
            ),
            TooFewVertices { polygon, count } => {
                write!(
                    f,
                    "{polygon} has {count} vertices; a polygon needs at least 3 (or 1: a \
                     point inside the facet)"
                )
            }
            LonePointOffFacet {
                polygon,
                vertex,
                on_edge,
            } => write!(
                f,
                "{polygon} is the single vertex {vertex}, which lies {} the facet: a lone \
                 point must be strictly inside it",
                if *on_edge {
                    "on a polygon edge of"
                } else {
                    "outside"
                }
            ),
            RepeatedVertex { polygon, vertex } => {
                write!(f, "{polygon} repeats vertex {vertex}")
            }
            DegenerateFacet { facet } => {
                write!(f, "facet {facet} is degenerate: its vertices are collinear")
            }
            NonPlanarFacet {
                facet,
                vertex,
                coords,
                distance,
                tolerance,
            } => write!(
                f,
                "facet {facet} is not planar: vertex {vertex} at {} is {distance:e} from the \
                 best-fit plane (tolerance {tolerance:e})",
                fmt_point(*coords)
            ),
            CoincidentInPlane {
                facet,
                first,
                second,
            } => write!(
                f,
                "facet {facet}: vertices {first} and {second} coincide in the facet's plane"
            ),
            EdgesIntersect { first, second } => write!(
                f,
                "non-simple polygon: edge ({}, {}) of {} intersects edge ({}, {}) of {}",
                first.1[0], first.1[1], first.0, second.1[0], second.1[1], second.0
            ),
            HoleOutsideFacet { polygon } => {
                write!(f, "{polygon} is not inside the facet's outer polygon")
            }
            HolePointOutsideFacet { facet, hole, point } => write!(
                f,
                "facet {facet}: hole point {hole} at {} is not inside the facet",
                fmt_point(*point)
            ),
            HolePointOffPlane {
                facet,
                hole,
                point,
                distance,
            } => write!(
                f,
                "facet {facet}: hole point {hole} at {} is {distance:e} off the facet's plane",
                fmt_point(*point)
            ),
            HolePointOnEdge { facet, hole, point } => write!(
                f,
                "facet {facet}: hole point {hole} at {} lies on a polygon edge",
                fmt_point(*point)
            ),
            EdgeOutsideFacet { polygon, edge } => write!(
                f,
                "edge ({}, {}) of {polygon} borders no part of the facet (is it inside a hole?)",
                edge[0], edge[1]
            ),
            FacetsIntersect { facets, triangles } => write!(
                f,
                "facets {} and {} intersect other than along shared edges or vertices \
                 (their triangles {:?} and {:?} overlap)",
                facets[0], facets[1], triangles[0], triangles[1]
            ),
            FacetsMeetOffSegment { facets, edge } => write!(
                f,
                "facets {} and {} meet along ({}, {}), which is not a polygon edge of both",
                facets[0], facets[1], edge[0], edge[1]
            ),
            VertexOnFacet {
                vertex,
                coords,
                facet,
            } => write!(
                f,
                "vertex {vertex} at {} lies on facet {facet} but is not one of its vertices",
                fmt_point(*coords)
            ),
            SurfaceNotClosed { edge, facet } => write!(
                f,
                "surface not closed at edge ({}, {}) of facet {facet}: no other facet uses it",
                edge[0], edge[1]
            ),
            SeedOutsideBoundingBox { seed, point } => write!(
                f,
                "{seed} at {} lies outside the bounding box of the vertices",
                fmt_point(*point)
            ),
            SeedOnFacet { seed, point, facet } => {
                write!(f, "{seed} at {} lies on facet {facet}", fmt_point(*point))
            }
            SeedOutsideDomain { seed, point } => write!(
                f,
                "{seed} at {} lies outside every enclosed volume",
                fmt_point(*point)
            ),
            RegionInHole { region, hole } => write!(
                f,
                "region seed {region} lies in the volume removed by hole seed {hole}"
            ),
            ConflictingRegions { first, second } => write!(
                f,
                "region seeds {first} and {second} lie in the same volume with different \
                 attributes or sizes"
            ),
            EmptyDomain => write!(f, "every enclosed volume is a hole: nothing to mesh"),
        }
    }
}

impl std::error::Error for PlcError {}
