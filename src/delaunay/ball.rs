//! Estimated cavities for many points drawn from one small ball (refinement's picking ball):
//! the tets whose circumball may meet the ball are gathered once, with their circumspheres,
//! and each point's cavity is then a flood over them with a float in-sphere test.
//!
//! An estimate decides nothing about the triangulation: refinement scores its random draws
//! with it and probes exactly ([`Delaunay::probe_watched`]) only the draws whose estimate beats
//! the best so far, and inserts only exactly probed cavities. The estimate is the exact cavity
//! unless rounding misjudges a tet (a draw within rounding of a circumsphere, or a nearly flat
//! tet with a poor float circumcentre); then a draw may be chosen differently, never a cavity
//! wrongly. (A float test with an error band and an exact fallback gave the same meshes on
//! every shared model and cost 1.5% of a fandisk run: the band needs each tet's corners.)

use super::cavity::{BoundaryFace, CavityWatch};
use super::tables::FACE;
use super::{has_infinite, Delaunay};
use glam::DVec3;
use rustc_hash::FxHashMap;

/// A local neighbour outside the region (no point of the ball conflicts with it).
const NONE: u32 = u32::MAX;

/// More tets than this and the ball gets no region (the exact probes are used).
const MAX_REGION_TETS: usize = 1024;

/// Relative slack of the region's float tests: a tet is gathered when its circumball comes
/// within this share of the radii of the ball, so rounding never leaves out a tet a point of
/// the ball may conflict with.
const SLACK: f64 = 1e-9;

/// See the module documentation. Valid until the triangulation is next edited.
pub struct BallRegion {
    tets: Vec<RegionTet>,
    /// Per region tet while a cavity is estimated: 0 untested, `IN`, `OUT`.
    mark: Vec<u8>,
    queue: Vec<u32>,
    faces: Vec<BoundaryFace>,
    generation: u64,
}

const IN: u8 = 1;
const OUT: u8 = 2;

struct RegionTet {
    id: u32,
    v: [u32; 4],
    /// The triangulation's neighbour references (tet << 2 | face).
    n: [u32; 4],
    /// The neighbours' indices in the region (`NONE` outside it).
    local: [u32; 4],
    centre: DVec3,
    radius: f64,
}

impl Delaunay {
    /// The region of the ball (`centre`, `radius`) from finite tet `start`, whose circumsphere
    /// must hold the whole ball; `sphere` gives a finite tet's circumsphere (a caller that
    /// keeps them passes its own). None when the ball is not inside, when a tet there has no
    /// circumsphere, when the ball may reach beyond the convex hull, or when the region is
    /// too large.
    pub fn ball_region(
        &self,
        start: u32,
        centre: DVec3,
        radius: f64,
        sphere: impl Fn(u32) -> Option<(DVec3, f64)>,
    ) -> Option<BallRegion> {
        if !self.is_alive(start) || has_infinite(self.tet_ref(start).v) {
            return None;
        }
        let region_tet = |t: u32| {
            let (c, r) = sphere(t)?;
            let tet = self.tet_ref(t);
            Some(RegionTet {
                id: t,
                v: tet.v,
                n: tet.n,
                local: [NONE; 4],
                centre: c,
                radius: r,
            })
        };
        let first = region_tet(start)?;
        if first.centre.distance(centre) + radius >= first.radius * (1.0 - SLACK) {
            return None;
        }
        let mut index: FxHashMap<u32, u32> =
            FxHashMap::with_capacity_and_hasher(256, Default::default());
        index.insert(start, 0);
        // Typical sizes (fandisk: ~120 tets, cavities of ~30 tets and ~50 faces).
        let mut tets = Vec::with_capacity(128);
        tets.push(first);
        let mut k = 0;
        while k < tets.len() {
            for i in 0..4 {
                let n = tets[k].n[i] >> 2;
                if let Some(&j) = index.get(&n) {
                    tets[k].local[i] = j;
                    continue;
                }
                if has_infinite(self.tet_ref(n).v) {
                    // A hull tet conflicts with the points beyond its hull face (the face
                    // shared with tet k): the ball must stay clear of that plane.
                    let v = tets[k].v;
                    let [a, b, c] = FACE[i].map(|f| self.point_ref(v[f]));
                    let mut normal = (b - a).cross(c - a);
                    if normal.dot(self.point_ref(v[i]) - a) > 0.0 {
                        normal = -normal;
                    }
                    let beyond = normal.dot(centre - a) / normal.length();
                    // (A NaN from a flat face is not clear either.)
                    let clear = beyond < -radius * (1.0 + SLACK);
                    if !clear {
                        return None;
                    }
                    continue;
                }
                let tet = region_tet(n)?;
                if tet.centre.distance(centre) < (tet.radius + radius) * (1.0 + SLACK) {
                    if tets.len() == MAX_REGION_TETS {
                        return None;
                    }
                    let j = tets.len() as u32;
                    index.insert(n, j);
                    tets[k].local[i] = j;
                    tets.push(tet);
                }
            }
            k += 1;
        }
        Some(BallRegion {
            mark: vec![0; tets.len()],
            tets,
            queue: Vec::with_capacity(64),
            faces: Vec::with_capacity(64),
            generation: self.generation,
        })
    }

    /// Shows `watch` the boundary faces of the estimated cavity of `p` (a point of the
    /// region's ball), as [`Self::probe_watched`] would show those of the exact one; false
    /// when `watch` stopped. The region must be of the current triangulation.
    pub fn estimate_cavity_watched<W: CavityWatch>(
        &self,
        region: &mut BallRegion,
        p: DVec3,
        watch: &mut W,
    ) -> bool {
        debug_assert_eq!(region.generation, self.generation, "stale ball region");
        region.mark.fill(0);
        region.queue.clear();
        region.faces.clear();
        region.mark[0] = IN;
        region.queue.push(0);
        let mut head = 0;
        let mut watched = 0;
        while head < region.queue.len() {
            if region.faces.len() - watched >= W::BATCH {
                let upto = region.faces.len() - (region.faces.len() - watched) % W::BATCH;
                if !watch.faces(&region.faces[watched..upto], &self.points) {
                    return false;
                }
                watched = upto;
            }
            let k = region.queue[head] as usize;
            head += 1;
            let tet = &region.tets[k];
            for (i, face) in FACE.iter().enumerate() {
                let j = tet.local[i];
                let inside = j != NONE && {
                    let m = &mut region.mark[j as usize];
                    if *m == 0 {
                        let o = &region.tets[j as usize];
                        let inside = p.distance_squared(o.centre) < o.radius * o.radius;
                        *m = if inside { IN } else { OUT };
                        if *m == IN {
                            region.queue.push(j);
                        }
                    }
                    *m == IN
                };
                if !inside {
                    let v = tet.v;
                    region
                        .faces
                        .push(BoundaryFace::new(face.map(|f| v[f]), tet.n[i], tet.id));
                }
            }
        }
        watch.faces(&region.faces[watched..], &self.points)
    }
}
