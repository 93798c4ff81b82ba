//! Input angles below 90°: where Delaunay refinement cannot promise quality (segments meeting
//! at a sharp angle encroach on each other; facets meeting at a sharp dihedral inside the
//! domain squeeze the tets between them). Reported, not rejected.
//!
//! Angles are computed in floating point, so a right angle between rounded or rotated
//! coordinates may come out a hair below 90°; angles within [`RIGHT_ANGLE_SLACK`] of 90° are
//! taken as right angles and not reported.

use super::cells::CellKind;
use super::Plc;
use glam::DVec3;

/// Degrees below 90° still counted as a right angle (floating-point noise, ~1e-13° in
/// practice, is far below this; a genuinely acute input angle is far above it).
pub const RIGHT_ANGLE_SLACK: f64 = 1e-7;

/// Two segments sharing a vertex at less than 90°.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SegmentAngle {
    pub vertex: u32,
    /// Indices into `Plc::segments`.
    pub segments: [usize; 2],
    pub degrees: f64,
}

/// Two facets around a segment enclosing a wedge of the domain narrower than 90°.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DihedralAngle {
    /// Index into `Plc::segments`.
    pub segment: usize,
    pub facets: [u32; 2],
    /// The domain cell inside the wedge.
    pub cell: u32,
    pub degrees: f64,
}

/// All acute input angles.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct AcuteAngles {
    pub segment_angles: Vec<SegmentAngle>,
    pub dihedral_angles: Vec<DihedralAngle>,
}

impl AcuteAngles {
    pub fn is_empty(&self) -> bool {
        self.segment_angles.is_empty() && self.dihedral_angles.is_empty()
    }
}

pub(crate) fn acute_angles(plc: &Plc) -> AcuteAngles {
    let p = |v: u32| plc.vertices[v as usize];
    let mut at_vertex: Vec<Vec<usize>> = vec![Vec::new(); plc.vertices.len()];
    for (i, s) in plc.segments.iter().enumerate() {
        at_vertex[s.vertices[0] as usize].push(i);
        at_vertex[s.vertices[1] as usize].push(i);
    }
    let mut segment_angles = Vec::new();
    for (v, segs) in at_vertex.iter().enumerate() {
        let v = v as u32;
        let dir = |s: usize| {
            let e = plc.segments[s].vertices;
            p(if e[0] == v { e[1] } else { e[0] }) - p(v)
        };
        for (i, &a) in segs.iter().enumerate() {
            for &b in &segs[i + 1..] {
                let (x, y) = (dir(a), dir(b));
                let degrees = x.cross(y).length().atan2(x.dot(y)).to_degrees();
                if degrees < 90.0 - RIGHT_ANGLE_SLACK {
                    segment_angles.push(SegmentAngle {
                        vertex: v,
                        segments: [a, b],
                        degrees,
                    });
                }
            }
        }
    }

    let mut dihedral_angles = Vec::new();
    for (si, s) in plc.segments.iter().enumerate() {
        let (u, v) = (p(s.vertices[0]), p(s.vertices[1]));
        let axis = (v - u).normalize();
        // Component of (third vertex - u) orthogonal to the segment: the half-plane direction.
        let half_plane = |facet: u32, triangle: u32| -> DVec3 {
            let t = plc.facets[facet as usize].triangles[triangle as usize];
            let w = t.into_iter().find(|x| !s.vertices.contains(x)).unwrap();
            let r = p(w) - u;
            r - axis * axis.dot(r)
        };
        let n = s.fan.len();
        for i in 0..n {
            let (a, b) = (s.fan[i], s.fan[(i + 1) % n]);
            let cell = a.cell_after;
            if !matches!(plc.cells[cell as usize].kind, CellKind::Domain { .. }) {
                continue;
            }
            let (ra, rb) = (
                half_plane(a.facet, a.triangle),
                half_plane(b.facet, b.triangle),
            );
            let mut rad = axis.dot(ra.cross(rb)).atan2(ra.dot(rb));
            if rad < 0.0 {
                rad += std::f64::consts::TAU;
            }
            let degrees = rad.to_degrees();
            if degrees < 90.0 - RIGHT_ANGLE_SLACK {
                dihedral_angles.push(DihedralAngle {
                    segment: si,
                    facets: [a.facet, b.facet],
                    cell,
                    degrees,
                });
            }
        }
    }
    AcuteAngles {
        segment_angles,
        dihedral_angles,
    }
}
