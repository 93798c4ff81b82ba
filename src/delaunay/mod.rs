//! Incremental 3D Delaunay tetrahedralization (Bowyer–Watson) over flat arrays.
//!
//! STUB: the public interface is fixed; bodies are being written.

use glam::DVec3;

/// Id of the vertex at infinity (hull tets carry it).
pub const INFINITE: u32 = u32::MAX;

#[derive(Debug, Clone, PartialEq)]
pub enum DelaunayError {
    /// Point `index` has a coordinate the exact predicates cannot handle.
    BadCoordinate { index: usize, point: DVec3, reason: crate::geom::CoordError },
    /// Fewer than four affinely independent points: no tetrahedron exists.
    Degenerate { reason: String },
}

impl std::fmt::Display for DelaunayError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            DelaunayError::BadCoordinate { index, point, reason } => {
                write!(f, "point {index} ({}, {}, {}): {reason}", point.x, point.y, point.z)
            }
            DelaunayError::Degenerate { reason } => write!(f, "degenerate input: {reason}"),
        }
    }
}
impl std::error::Error for DelaunayError {}

/// What bulk insertion did.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct InsertStats {
    /// Points that became vertices.
    pub inserted: usize,
    /// Points equal to an earlier point: skipped (their ids stay unused).
    pub duplicates: usize,
}

/// Result of inserting one point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Inserted {
    /// A new vertex with this id.
    New(u32),
    /// The point equals existing vertex `0`; nothing changed.
    Duplicate(u32),
}

pub struct Delaunay {
    points: Vec<DVec3>,
}

impl Delaunay {
    /// Triangulates `points`; vertex id i is `points[i]` (duplicates are skipped, ids unused).
    /// Inserts in BRIO / Hilbert order.
    pub fn from_points(points: &[DVec3]) -> Result<(Self, InsertStats), DelaunayError> {
        let _ = points;
        todo!()
    }
    /// Inserts one point (locating from `hint`, a tet id, when given). Needs a triangulation
    /// with at least one tet (use `from_points` first).
    pub fn insert(&mut self, p: DVec3, hint: Option<u32>) -> Result<Inserted, DelaunayError> {
        let _ = (p, hint);
        todo!()
    }
    /// Number of vertex ids handed out (including skipped duplicates).
    pub fn num_vertex_ids(&self) -> usize {
        self.points.len()
    }
    /// Number of vertices actually in the triangulation.
    pub fn num_vertices(&self) -> usize {
        todo!()
    }
    pub fn num_finite_tets(&self) -> usize {
        todo!()
    }
    /// Coordinates of vertex `v`.
    pub fn point(&self, v: u32) -> DVec3 {
        self.points[v as usize]
    }
    /// Positively oriented finite tets as vertex id quadruples.
    pub fn finite_tets(&self) -> impl Iterator<Item = [u32; 4]> + '_ {
        std::iter::empty()
    }
    /// Heap bytes held by the triangulation (arrays' capacities).
    pub fn memory_bytes(&self) -> usize {
        todo!()
    }
    /// Full structural + Delaunay check (tests only; O(n)).
    pub fn validate(&self) -> Result<(), String> {
        todo!()
    }
}
