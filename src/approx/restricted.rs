//! The restricted Delaunay surface mesher: samples of the input surface in a 3D Delaunay
//! triangulation, refined until every restricted facet (a Delaunay face whose dual Voronoi
//! edge crosses the surface) is good, then the faces between tets whose circumcentres lie
//! inside and outside the domain are the new boundary.
//!
//! Feature curves are protected without weights (the unweighted equivalent of CGAL's
//! protecting balls): each curve is cut into subsegments that must stay Delaunay edges with
//! an empty diametric ball. A surface centre that would land in a subsegment's ball splits the
//! subsegment instead (Shewchuk's encroachment rule, at concentric shells next to corners
//! as in Ruppert's algorithm, so splits cannot cascade towards a corner), and a subsegment is
//! also split while it is longer than f or its chord leaves the curve by more than the
//! distance bound. Next to a small corner (below 60 degrees) nothing is split for being
//! encroached and no facet is refined for its angle: that is where the report says quality is
//! not enforced.
//!
//! A restricted facet is bad (CGAL Mesh_3's facet criteria) when a vertex is not on the patch
//! its surface centre lies on nor on a curve or corner of that patch, when its surface ball is
//! larger than f, when its smallest angle is below `min_angle_deg`, or when its circumcentre is
//! farther than the distance bound from its surface centre. Bad facets are refined largest
//! first, each at its surface centre.

mod extract;
mod facet_level;
mod sampling;
mod tracking;
#[cfg(test)]
pub(super) use tracking::CHECK_EVERY_INSERTION;
mod volume;

pub use volume::VolumeCriteria;

use super::curves::{Curve, FeatureCurves};
use crate::delaunay::tables::FACE;
use crate::delaunay::{Cavity, Delaunay, Inserted, Probe, INFINITE};
use crate::geom::tri_circumcenter;
use crate::refine::outcome::{BoundaryKind, Outcome, Refusal};
use crate::refine::{MarkerCaps, SPACING_BATCH};
use crate::run::error::MeshError;
use crate::run::spacing::Spacing;
use crate::surface::oracle::{Crossing, SurfaceOracle};
use crate::surface::repair::{Repaired, HIDDEN};
use crate::surface::thickness::Thickness;
use crate::surface::InputSurface;
use glam::DVec3;
use rand::{Rng, SeedableRng};
use rand_chacha::ChaCha8Rng;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Ordering;
use std::collections::BinaryHeap;

/// What the surface mesher aims for.
#[derive(Debug, Clone, Copy)]
pub struct SurfaceCriteria {
    /// Largest distance between a facet's circumcentre and its surface centre, and between a
    /// subsegment's chord and its curve.
    pub distance: f64,
    /// The distance bound itself: no sample of the input may lie farther from the extracted
    /// boundary (a valley of a noisy scan can stray from triangles whose circumcentres and
    /// centroids all lie close to the input).
    pub bound: f64,
    /// Smallest facet angle, degrees (CGAL's facet_angle; 30 is the guaranteed-terminating
    /// bound of Boissonnat & Oudot).
    pub min_angle_deg: f64,
    /// Stop (with a reason) past this many vertices.
    pub max_vertices: usize,
    /// Facets with a smaller surface ball are refined only for the distance bound: features
    /// closer together than this (two creases meeting at a tiny angle, a sliver patch between
    /// them) are not resolved, as inside a small corner's protecting ball.
    pub feature_floor: f64,
    /// With a thickness (`SurfaceMesher::new`), the surface spacing is at most this many
    /// times the input's thickness radius, never below `feature_floor`.
    pub thickness_spacing: f64,
    /// Seed of the random surface samples.
    pub seed: u64,
}

/// Where a vertex of the surface triangulation lies.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Loc {
    /// A corner of the bounding box around everything (never part of the output).
    Far,
    Corner(u32),
    Curve(u32),
    Patch(u32),
    /// Inserted by the cell level, inside the domain.
    Volume,
    /// On the boundary of a repaired solid where it spans a hole of the input (`--repair`).
    Span,
}

/// A piece of a feature curve between two consecutive vertices on it.
#[derive(Debug, Clone, Copy)]
struct SubSeg {
    curve: u32,
    /// Arc lengths of its ends (`ends` of the key in curve order).
    s: [f64; 2],
    /// Vertices in curve order.
    ends: [u32; 2],
}

/// A face of the triangulation whose Voronoi edge crosses the surface.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Restricted {
    vertices: [u32; 3],
    centre: DVec3,
    radius: f64,
    /// The input triangle the centre lies on (nearest to it when `span`).
    triangle: u32,
    /// The centre spans a hole of a repaired input: it lies on no input triangle.
    span: bool,
}

/// A face of the triangulation: a tet and the local index of the vertex opposite the face.
type FaceRef = (u32, usize);

/// A surface centre closer than this fraction of its facet's radius to a vertex is not
/// inserted (see `insert_surface_point`).
const EMPTY_BALL_FRACTION: f64 = 0.5;

/// Why a restricted facet is refined.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Bad {
    No,
    /// A vertex is off the patch its surface centre lies on (and off that patch's curves).
    Topology,
    /// Surface ball larger than f.
    Size,
    Angle,
    /// Circumcentre too far from the surface centre.
    Distance,
    /// It breaks the extracted boundary (a vertex off the surface, a non-manifold edge).
    Boundary,
}

/// A bad facet waiting in the queue: larger surface balls first, ties by vertices. `sized`:
/// the surface centre and the caller's spacing there when it was judged (reused when it is
/// judged again with the same centre; not part of the order).
#[derive(Debug, Clone, Copy)]
struct Queued {
    radius: f64,
    face: [u32; 3],
    sized: Option<(DVec3, f64)>,
}
impl PartialEq for Queued {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}
impl Eq for Queued {}
impl PartialOrd for Queued {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}
impl Ord for Queued {
    fn cmp(&self, other: &Self) -> Ordering {
        self.radius
            .total_cmp(&other.radius)
            .then_with(|| other.face.cmp(&self.face))
    }
}

/// The new boundary: triangles oriented outwards, each with the input triangle its surface
/// centre lies on.
#[derive(Debug, Clone, Default)]
pub struct Boundary {
    pub points: Vec<DVec3>,
    pub loc: Vec<Loc>,
    pub triangles: Vec<[u32; 3]>,
    pub input_triangle: Vec<u32>,
    /// Subsegments present in the boundary (feature edges of the output), as vertex pairs.
    pub feature_edges: Vec<[u32; 2]>,
    /// Why the mesher stopped before every facet was good, if it did.
    pub stop_reason: Option<String>,
    /// The input's Hausdorff samples if the mesher took them (the report takes the same).
    pub input_samples: Option<Vec<DVec3>>,
}

/// What the surface mesher approximates.
#[derive(Clone, Copy)]
pub struct Geometry<'a> {
    pub surface: &'a InputSurface,
    /// The oracle of `surface`.
    pub oracle: &'a SurfaceOracle,
    pub curves: &'a FeatureCurves,
    /// Smooth patch of each triangle of `surface`.
    pub patch_of: &'a [u32],
    /// A dirty input's solid (`--repair`): inside and outside come from its labels, and
    /// `surface` holds its triangles that bound it.
    pub repair: Option<&'a Repaired>,
}

pub struct SurfaceMesher<'a> {
    surface: &'a InputSurface,
    oracle: &'a SurfaceOracle,
    curves: &'a FeatureCurves,
    patch_of: &'a [u32],
    repair: Option<&'a Repaired>,
    spacing: &'a dyn Spacing,
    criteria: SurfaceCriteria,
    dt: Delaunay,
    loc: Vec<Loc>,
    /// The subsegment level (the feature curves).
    segs: SegmentLevel,
    /// The surface level (the restricted facets).
    surf: SurfaceLevel,
    bad_spacing: Option<MeshError>,
    min_length: f64,
    /// Sides, circumcentres and restricted facets, kept up to date (`tracking`).
    track: tracking::Tracking,
    /// The cell level, once the surface is good (`run_with_volume`).
    vol: Option<Box<volume::VolumeState>>,
    /// The small corners' protecting balls: centre and squared radius.
    small_balls: Vec<(DVec3, f64)>,
    /// The input's Hausdorff samples (`measure::hausdorff_samples`), once taken.
    input_samples: std::cell::OnceCell<Vec<DVec3>>,
    /// The thickness bound of the surface spacing, if a thickness was given.
    thin: Option<ThinBound>,
    /// Samples a repaired input's boundary was mended at (`rounds`), by coordinate bits.
    mended: FxHashSet<[u64; 3]>,
    /// Per region number the most spacing its cells get (`Params::region_sizes`; empty: none).
    region_caps: Vec<f64>,
    /// The caps of `Params::marker_sizes`, applied to the cells' automatic spacing (`spacing`
    /// holds them already).
    marker_caps: Option<&'a MarkerCaps>,
}

/// The subsegment level's state: the feature curves' subsegments and the ones to look at
/// (`SurfaceMesher::refine` works them off first).
#[derive(Default)]
struct SegmentLevel {
    /// Every subsegment, by its ends (`key2`).
    all: FxHashMap<[u32; 2], SubSeg>,
    /// Subsegments to check (a stack).
    queue: Vec<[u32; 2]>,
    /// Subsegments a facet or cell encroached: split when checked.
    force_split: FxHashSet<[u32; 2]>,
    /// Subsegments too short to split further (their ends would coincide in floating point).
    frozen: FxHashSet<[u32; 2]>,
}

/// The surface level's state: the bad restricted facets (largest first), refined once no
/// subsegment is queued.
#[derive(Default)]
struct SurfaceLevel {
    queue: BinaryHeap<Queued>,
    /// How often each facet waited for subsegment splits (see `MAX_DEFERRALS`).
    deferrals: FxHashMap<[u32; 3], u32>,
}

/// The surface spacing's bound by the input's thickness, per input triangle.
struct ThinBound {
    /// Thickness radius of each input triangle (its corners' smallest).
    per_triangle: Vec<f64>,
    scale: f64,
    floor: f64,
}

impl ThinBound {
    fn at(&self, triangle: u32) -> f64 {
        (self.scale * self.per_triangle[triangle as usize]).max(self.floor)
    }
}

/// Rounds of subsegment splits one facet may wait for before it is left alone.
const MAX_DEFERRALS: u32 = 8;

fn key2(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

fn key3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// Smallest angle of triangle (a, b, c), degrees.
pub fn min_angle_deg(a: DVec3, b: DVec3, c: DVec3) -> f64 {
    let angle = |p: DVec3, q: DVec3, r: DVec3| {
        let (u, v) = (q - p, r - p);
        u.cross(v).length().atan2(u.dot(v)).to_degrees()
    };
    angle(a, b, c).min(angle(b, c, a)).min(angle(c, a, b))
}

/// Cosines this far from the bound's decide [`has_angle_below`] alone (their rounding is
/// about 1e-16).
const COSINE_CLEARANCE: f64 = 1e-9;

/// Whether `min_angle_deg(a, b, c) < min_deg`: from the corners' cosines when all are clear
/// of the bound's, else from the angles (most facets are far from the bound either way).
fn has_angle_below(a: DVec3, b: DVec3, c: DVec3, min_deg: f64) -> bool {
    let cos_min = min_deg.to_radians().cos();
    let cosine = |p: DVec3, q: DVec3, r: DVec3| {
        let (u, v) = (q - p, r - p);
        u.dot(v) / (u.length_squared() * v.length_squared()).sqrt()
    };
    let cosines = [cosine(a, b, c), cosine(b, c, a), cosine(c, a, b)];
    if cosines.iter().any(|&x| x > cos_min + COSINE_CLEARANCE) {
        return true;
    }
    if cosines.iter().all(|&x| x < cos_min - COSINE_CLEARANCE) {
        return false;
    }
    min_angle_deg(a, b, c) < min_deg
}

impl<'a> SurfaceMesher<'a> {
    /// Samples the corners, curves and patches and triangulates the samples.
    pub fn new(
        geometry: Geometry<'a>,
        spacing: &'a dyn Spacing,
        thickness: Option<&Thickness>,
        criteria: SurfaceCriteria,
    ) -> Result<SurfaceMesher<'a>, MeshError> {
        let Geometry {
            surface,
            oracle,
            curves,
            patch_of,
            repair,
        } = geometry;
        let diagonal = surface.bbox_diagonal();
        let mut m = SurfaceMesher {
            surface,
            oracle,
            curves,
            patch_of,
            repair,
            spacing,
            criteria,
            dt: Delaunay::default(),
            loc: vec![],
            segs: SegmentLevel::default(),
            surf: SurfaceLevel::default(),
            bad_spacing: None,
            min_length: 1e-9 * diagonal,
            track: tracking::Tracking::default(),
            vol: None,
            input_samples: std::cell::OnceCell::new(),
            mended: FxHashSet::default(),
            region_caps: vec![],
            marker_caps: None,
            thin: thickness.map(|t| ThinBound {
                per_triangle: t.per_triangle(surface),
                scale: criteria.thickness_spacing,
                floor: criteria.feature_floor,
            }),
            small_balls: curves
                .small_corners()
                .map(|c| (c.point, c.protect_radius * c.protect_radius))
                .collect(),
        };
        let mut points = sampling::far_box(surface, diagonal);
        m.loc = vec![Loc::Far; points.len()];
        let mut grid = sampling::SampleGrid::new(m.typical_spacing(), surface);
        for (k, c) in curves.corners.iter().enumerate() {
            points.push(c.point);
            m.loc.push(Loc::Corner(k as u32));
            grid.add(c.point);
        }
        for (ci, curve) in curves.curves.iter().enumerate() {
            m.sample_curve(ci as u32, curve, &mut points, &mut grid);
        }
        m.sample_patches(&mut points, &mut grid, criteria.seed);
        if let Some(e) = m.bad_spacing.take() {
            return Err(e);
        }
        let (dt, _) = Delaunay::from_points(&points)
            .map_err(|e| MeshError::InvalidInput(format!("surface samples: {e}")))?;
        m.dt = dt;
        m.segs.queue = {
            let mut keys: Vec<[u32; 2]> = m.segs.all.keys().copied().collect();
            keys.sort_unstable();
            keys.reverse();
            keys
        };
        m.start_tracking();
        Ok(m)
    }

    /// Caps the cells' spacing per region number (see `approx::region_caps`).
    pub fn set_region_caps(&mut self, caps: Vec<f64>) {
        self.region_caps = caps;
    }

    /// Caps the cells' automatic spacing by marker sizes (`spacing` must be capped by the
    /// same: the surface and a caller's cell spacing read it).
    pub fn set_marker_caps(&mut self, caps: Option<&'a MarkerCaps>) {
        self.marker_caps = caps;
    }

    /// The surface spacing at `p`: the caller's, bounded by the thickness of the input
    /// triangle nearest to `p`.
    fn f(&mut self, p: DVec3) -> f64 {
        let triangle = match self.thin {
            Some(_) => self.oracle.closest(p).map(|c| c.triangle),
            None => None,
        };
        self.f_on(p, triangle)
    }

    /// The surface spacing at `p`, a point of input triangle `triangle`.
    fn f_on(&mut self, p: DVec3, triangle: Option<u32>) -> f64 {
        let v = self.spacing.at(p);
        self.f_value(p, v, triangle)
    }

    /// [`Self::f_on`] given `v`, the caller's spacing at `p` (evaluated in a batch).
    fn f_value(&mut self, p: DVec3, v: f64, triangle: Option<u32>) -> f64 {
        if !(v.is_finite() && v > 0.0) {
            self.bad_spacing
                .get_or_insert(MeshError::BadSpacing { point: p, value: v });
        }
        self.bounded(v, triangle)
    }

    /// [`Self::f_value`] without noting a bad value: infinite for one, else `v` bounded by
    /// the thickness of `triangle`.
    fn bounded(&self, v: f64, triangle: Option<u32>) -> f64 {
        if !(v.is_finite() && v > 0.0) {
            return f64::INFINITY;
        }
        match (&self.thin, triangle) {
            (Some(thin), Some(t)) => v.min(thin.at(t)),
            _ => v,
        }
    }

    /// Refines the surface until every restricted facet is good, then the cells (`volume`) in
    /// the same triangulation; after each, extracts the boundary and repeats while it is not a
    /// closed 2-manifold of surface vertices. Returns the boundary and the tets inside it.
    pub fn run_with_volume(
        mut self,
        crit: VolumeCriteria,
        mut progress: Option<crate::run::progress::Progress>,
    ) -> Result<(Boundary, VolumeMesh), MeshError> {
        let start = std::time::Instant::now();
        let (faces, stop_reason) = self.rounds(&mut Self::refine)?;
        let seconds_surface = start.elapsed().as_secs_f64();
        if stop_reason.is_some() {
            return Err(MeshError::InvalidInput(format!(
                "surface mode approximate: {}",
                stop_reason.unwrap_or_default()
            )));
        }
        self.start_volume(crit, &faces);
        let mut cancelled = false;
        let (faces, stop_reason) = self.rounds(&mut |m: &mut Self| {
            let reason = m.refine_volume(&mut progress);
            cancelled |= reason.is_none() && m.vol.as_ref().is_some_and(|v| v.cancelled());
            reason
        })?;
        if cancelled {
            return Err(MeshError::Cancelled);
        }
        let mut boundary = self.boundary(faces, stop_reason);
        self.input_samples();
        boundary.input_samples = self.input_samples.take();
        // The cell level's queues and maps are freed before the output is built.
        let (spacing, refusals) = match self.vol.take() {
            Some(v) => (v.spacing, v.refusals),
            None => (None, Default::default()),
        };
        let mut volume = self.volume_mesh(&boundary)?;
        volume.spacing = spacing;
        volume.refusals = refusals;
        volume.seconds_surface = seconds_surface;
        volume.seconds_volume = start.elapsed().as_secs_f64() - seconds_surface;
        Ok((boundary, volume))
    }

    /// The surface level alone (no cell refined): the boundary, and in an otherwise empty
    /// volume the cells' automatic spacing unless the caller gave one (`user_spacing`).
    pub fn run_surface_only(
        mut self,
        user_spacing: bool,
    ) -> Result<(Boundary, VolumeMesh), MeshError> {
        let start = std::time::Instant::now();
        let (faces, stop_reason) = self.rounds(&mut Self::refine)?;
        if let Some(reason) = stop_reason {
            return Err(MeshError::InvalidInput(format!(
                "surface mode approximate: {reason}"
            )));
        }
        let spacing = (!user_spacing).then(|| self.surface_sizes(&faces));
        let boundary = self.boundary(faces, None);
        let volume = VolumeMesh {
            vertices: vec![],
            tets: vec![],
            regions: vec![],
            spacing,
            refusals: Default::default(),
            seconds_surface: start.elapsed().as_secs_f64(),
            seconds_volume: 0.0,
        };
        Ok((boundary, volume))
    }

    /// Runs `refine` and extracts the boundary, fixing what breaks it, until it is a closed
    /// 2-manifold of surface vertices (and, before the cell level, within the distance bound
    /// of every input sample): CGAL's manifold criterion, driven to the end. Each round must
    /// insert a point, so the loop ends, at the latest at `max_vertices`.
    fn rounds(
        &mut self,
        refine: &mut dyn FnMut(&mut Self) -> Option<String>,
    ) -> Result<(Vec<FaceRef>, Option<String>), MeshError> {
        loop {
            let stop_reason = refine(self);
            if let Some(e) = self.bad_spacing.take() {
                return Err(e);
            }
            let (faces, problems) = self.extract();
            let far = if problems.is_empty() && stop_reason.is_none() {
                let mut far = self.far_from_input(&faces);
                if far.is_empty() {
                    far = self.far_from_surface(&faces);
                }
                if self.repair.is_some() {
                    // An intersection's crease or sliver may stay beyond the bound where its
                    // own points went in: each sample is mended once.
                    far.retain(|f| self.mended.insert(f.2.to_array().map(f64::to_bits)));
                }
                far
            } else {
                vec![]
            };
            if problems.is_empty() && far.is_empty() {
                return Ok((faces, stop_reason));
            }
            let not_closed = |n: usize, why: &str| {
                MeshError::InvalidInput(format!(
                    "surface mode approximate: the remeshed boundary is not a closed manifold \
                     ({n} faces in the way; {why})"
                ))
            };
            if let Some(reason) = stop_reason {
                return Err(not_closed(problems.len(), &reason));
            }
            // Faces by their vertices: an insertion may remove the tets that held the next.
            let face_of = |m: &Self, (t, i): FaceRef| FACE[i].map(|k| m.dt.tet(t)[k]);
            let mut mend: Vec<([u32; 3], Option<DVec3>)> =
                problems.iter().map(|&f| (face_of(self, f), None)).collect();
            mend.extend(
                far.iter()
                    .map(|&(t, i, p)| (face_of(self, (t, i)), Some(p))),
            );
            let before = self.dt.num_vertex_ids();
            for (face, sample) in mend {
                let Some([(t, i), _]) = self.dt.find_face(face[0], face[1], face[2]) else {
                    continue;
                };
                // A repaired input's sample far from the boundary lies on a bounding piece of
                // the input (an overlap's thin sliver): the sample itself goes in.
                let repaired_sample = sample.filter(|_| self.repair.is_some());
                if let (Some(p), Some(c)) = (
                    repaired_sample,
                    repaired_sample.and_then(|p| self.oracle.closest(p)),
                ) {
                    self.insert_input_point(p, c.triangle, face, t);
                } else if let Some(r) = self.facet_at(t, i) {
                    self.insert_surface_point(r, t, Bad::Boundary);
                } else if let Some(c) = self
                    .oracle
                    .closest(sample.unwrap_or_else(|| centroid(&self.dt, face)))
                {
                    self.insert_input_point(c.point, c.triangle, face, t);
                }
            }
            if self.dt.num_vertex_ids() == before {
                return Err(not_closed(
                    problems.len(),
                    "no point of the input could be inserted to mend them",
                ));
            }
        }
    }

    /// Inserts a point of the input surface (on input triangle `triangle`) to mend boundary
    /// face `face`, which is not a restricted facet, as if it were that facet's centre.
    fn insert_input_point(&mut self, p: DVec3, triangle: u32, face: [u32; 3], hint: u32) {
        let r = Restricted {
            vertices: face,
            centre: p,
            radius: 0.0,
            triangle,
            span: false,
        };
        self.insert_surface_point(r, hint, Bad::Boundary);
    }

    /// The refinement loop: subsegments first, then the largest bad facet.
    fn refine(&mut self) -> Option<String> {
        loop {
            if self.dt.num_vertices() > self.criteria.max_vertices {
                return Some(format!(
                    "the mesh reached max_vertices = {} vertices while refining the surface",
                    self.criteria.max_vertices
                ));
            }
            if self.bad_spacing.is_some() {
                return None;
            }
            if let Some(k) = self.segs.queue.pop() {
                self.check_subseg(k);
                continue;
            }
            // Both queues empty: done, no stop reason.
            let q = self.surf.queue.pop()?;
            self.refine_facet(q.face, q.sized);
        }
    }

    fn near_small_corner(&self, p: DVec3) -> bool {
        self.small_balls
            .iter()
            .any(|&(c, r2)| (p - c).length_squared() < r2)
    }

    fn check_subseg(&mut self, k: [u32; 2]) {
        let Some(ss) = self.segs.all.get(&k).copied() else {
            return;
        };
        if self.segs.frozen.contains(&k) {
            return;
        }
        let forced = self.segs.force_split.remove(&k);
        let [a, b] = ss.ends.map(|v| self.dt.point(v));
        let curve = &self.curves.curves[ss.curve as usize];
        let split = forced
            || self.dt.find_edge(k[0], k[1]).is_none()
            || (a - b).length() > self.f((a + b) / 2.0)
            || curve.chord_deviation(ss.s[0], ss.s[1]) > self.criteria.distance
            || (!self.near_small_corner((a + b) / 2.0) && self.encroached(k, a, b));
        if split {
            self.split_subseg(k, ss);
        }
    }

    /// Whether a vertex next to edge k lies inside its diametric ball.
    fn encroached(&self, k: [u32; 2], a: DVec3, b: DVec3) -> bool {
        let (m, r2) = ((a + b) / 2.0, (a - b).length_squared() / 4.0);
        self.dt.vertex_star(k[0]).into_iter().any(|t| {
            let tv = self.dt.tet(t);
            tv.contains(&k[1])
                && tv.iter().any(|&w| {
                    w != INFINITE
                        && w != k[0]
                        && w != k[1]
                        && (self.dt.point(w) - m).length_squared() < r2
                })
        })
    }

    /// Splits at the middle, or next to a corner at a power-of-two distance from it
    /// (concentric shells: two curves leaving a corner are split at the same distances).
    fn split_subseg(&mut self, k: [u32; 2], ss: SubSeg) {
        let len = ss.s[1] - ss.s[0];
        let curve = &self.curves.curves[ss.curve as usize];
        if (self.dt.point(k[0]) - self.dt.point(k[1])).length() < self.min_length {
            self.segs.frozen.insert(k);
            return;
        }
        let is_corner = |v: u32| matches!(self.loc[v as usize], Loc::Corner(_));
        let shell = |d: f64| {
            2f64.powf((d / 2.0).log2().round())
                .clamp(0.25 * d, 0.75 * d)
        };
        let s = match (is_corner(ss.ends[0]), is_corner(ss.ends[1])) {
            (true, false) => ss.s[0] + shell(len),
            (false, true) => ss.s[1] - shell(len),
            _ => ss.s[0] + 0.5 * len,
        };
        let p = curve.point_at(s);
        let hint = self.dt.vertex_tet(k[0]);
        let id = match self.dt.insert(p, hint) {
            Ok(Inserted::New(id)) => id,
            _ => {
                self.segs.frozen.insert(k);
                return;
            }
        };
        self.loc.push(Loc::Curve(ss.curve));
        debug_assert_eq!(self.loc.len(), id as usize + 1);
        self.segs.all.remove(&k);
        for (e, sp) in [
            ([ss.ends[0], id], [ss.s[0], s]),
            ([id, ss.ends[1]], [s, ss.s[1]]),
        ] {
            self.segs.all.insert(
                key2(e[0], e[1]),
                SubSeg {
                    curve: ss.curve,
                    s: sp,
                    ends: e,
                },
            );
            self.segs.queue.push(key2(e[0], e[1]));
        }
        self.after_insertion();
    }

    /// Queues what an insertion may have made bad: subsegments among the removed and created
    /// tets' edges, and the faces of the created tets.
    fn after_insertion(&mut self) {
        let created = self.dt.last_created().to_vec();
        let mut quads = self.dt.last_removed().to_vec();
        quads.extend(created.iter().map(|&t| self.dt.tet(t)));
        let mut seen = FxHashSet::default();
        for tv in &quads {
            let on_curve = tv.map(|v| self.on_curve(v));
            for i in 0..4 {
                for j in i + 1..4 {
                    if !(on_curve[i] && on_curve[j]) {
                        continue; // subsegments join curve and corner vertices only
                    }
                    let k = key2(tv[i], tv[j]);
                    if self.segs.all.contains_key(&k) && seen.insert(k) {
                        self.segs.queue.push(k);
                    }
                }
            }
        }
        self.track_insertion(self.dt.num_vertex_ids() as u32 - 1, &created);
        self.queue_cells(&created);
    }

    /// Face `i` of tet `t` if its Voronoi edge crosses the surface, with the crossing farthest
    /// from its vertices as surface centre: the tracking's record of it (the Voronoi edge was
    /// crossed when the face appeared; crossing it again from the other end could move the
    /// centre by a rounding error).
    fn facet_at(&self, t: u32, i: usize) -> Option<Restricted> {
        if !self.track.is_restricted(t, i) {
            return None;
        }
        let face = FACE[i].map(|k| self.dt.tet(t)[k]);
        let &(centre, radius, triangle, span) = self.track.restricted.get(&key3(face))?;
        Some(Restricted {
            vertices: face,
            centre,
            radius,
            triangle,
            span,
        })
    }

    /// Face `face` as a restricted facet, given where its Voronoi edge crosses the surface
    /// (`crossings`, from the segment's start `ends.0` in region `ends.1` to its end `ends.2`
    /// in region `ends.3`): the crossing farthest from its vertices is its surface centre.
    /// For a repaired input only the points where the label changes count.
    fn facet_from(
        &self,
        face: [u32; 3],
        crossings: Vec<Crossing>,
        ends: Option<(DVec3, u32, DVec3, u32)>,
    ) -> Option<Restricted> {
        let a = self.dt.point(face[0]);
        let farthest = |points: Vec<(DVec3, Option<u32>)>| {
            points
                .into_iter()
                .map(|(p, t)| ((p - a).length(), p, t))
                .max_by(|x, y| x.0.total_cmp(&y.0))
        };
        let Some(repair) = self.repair else {
            let points = crossings
                .iter()
                .map(|x| (x.point, Some(x.triangle)))
                .collect();
            let (radius, centre, triangle) = farthest(points)?;
            return Some(Restricted {
                vertices: face,
                centre,
                radius,
                triangle: triangle.unwrap_or(0),
                span: false,
            });
        };
        let (c, rc, cn, rn) = ends?;
        let labels = &repair.labels;
        let points = match labels.boundary_points(c, cn, &crossings, tracking::count_of(rc)) {
            Some(b) => b.into_iter().map(|b| (b.point, b.triangle)).collect(),
            // Crossings through edges: the labels at the ends say whether it is restricted.
            None if tracking::label_of(rc) != tracking::label_of(rn) => crossings
                .iter()
                .map(|x| (x.point, labels.is_input(x.triangle).then_some(x.triangle)))
                .collect(),
            None => vec![],
        };
        let (radius, centre, on) = farthest(points)?;
        let triangle = on
            .map(|t| repair.surface_id[t as usize])
            .filter(|&t| t != HIDDEN)
            .or_else(|| self.oracle.closest(centre).map(|c| c.triangle))
            .unwrap_or(0);
        Some(Restricted {
            vertices: face,
            centre,
            radius,
            triangle,
            span: on.is_none(),
        })
    }

    /// Whether vertex `v` lies on a feature curve or at a corner (a subsegment may end there).
    fn on_curve(&self, v: u32) -> bool {
        v != INFINITE && matches!(self.loc[v as usize], Loc::Curve(_) | Loc::Corner(_))
    }

    fn on_patch(&self, v: u32, patch: u32) -> bool {
        match self.loc[v as usize] {
            Loc::Far | Loc::Volume => false,
            Loc::Span => true,
            Loc::Patch(p) => p == patch,
            Loc::Curve(c) => self.curves.curves[c as usize].patches.contains(&patch),
            Loc::Corner(k) => self.curves.corners[k as usize].patches.contains(&patch),
        }
    }

    /// Queues the bad ones of restricted facets `found`, in their order. The caller's
    /// spacing at their surface centres is evaluated in batches (one `Spacing::at_many` call
    /// per [`SPACING_BATCH`] facets: after an insertion, one for the facets it made), at the
    /// same points as one by one.
    fn queue_bad(&mut self, found: &[Restricted]) {
        let (mut centres, mut values) = (vec![], vec![]);
        for chunk in found.chunks(SPACING_BATCH) {
            centres.clear();
            centres.extend(
                chunk
                    .iter()
                    .filter(|r| !self.topology_bad(r))
                    .map(|r| r.centre),
            );
            values.clear();
            values.resize(centres.len(), f64::NAN);
            if !centres.is_empty() {
                self.spacing.at_many(&centres, &mut values);
            }
            let mut k = 0;
            for r in chunk {
                let (bad, sized) = match self.topology_bad(r) {
                    true => (Bad::Topology, None),
                    false => {
                        let v = values[k];
                        k += 1;
                        (self.badness_given(r, v), Some((r.centre, v)))
                    }
                };
                if bad != Bad::No {
                    self.surf.queue.push(Queued {
                        radius: r.radius,
                        face: key3(r.vertices),
                        sized,
                    });
                }
            }
        }
    }

    /// Which criterion a restricted facet fails first (angles are not enforced next to a
    /// small corner); `sized`: a surface centre and the caller's spacing there, used when the
    /// centre is `r`'s (else the spacing is evaluated).
    fn badness(&mut self, r: &Restricted, sized: Option<(DVec3, f64)>) -> Bad {
        if self.topology_bad(r) {
            return Bad::Topology;
        }
        let v = match sized {
            Some((c, v)) if c == r.centre => v,
            _ => self.spacing.at(r.centre),
        };
        self.badness_given(r, v)
    }

    /// Whether restricted facet `r` has a vertex off its patch (a hole's span belongs to no
    /// patch; facets below the feature floor are not checked).
    fn topology_bad(&self, r: &Restricted) -> bool {
        let patch = self.patch_of[r.triangle as usize];
        let above_floor = r.radius >= self.criteria.feature_floor;
        above_floor && !r.span && !r.vertices.iter().all(|&v| self.on_patch(v, patch))
    }

    /// [`Self::badness`] of a facet without a topology fault, given `v`, the caller's spacing
    /// at its surface centre.
    fn badness_given(&mut self, r: &Restricted, v: f64) -> Bad {
        let above_floor = r.radius >= self.criteria.feature_floor;
        if r.radius > self.f_value(r.centre, v, (!r.span).then_some(r.triangle)) {
            return Bad::Size;
        }
        let [a, b, c] = r.vertices.map(|v| self.dt.point(v));
        let protected = !above_floor || [a, b, c].iter().any(|&p| self.near_small_corner(p));
        if !protected && has_angle_below(a, b, c, self.criteria.min_angle_deg) {
            return Bad::Angle;
        }
        let far = |cc: DVec3| (cc - r.centre).length() > self.criteria.distance;
        if tri_circumcenter(a, b, c).is_some_and(far) {
            return Bad::Distance;
        }
        // The circumcentre sees the surface along one line only; across a crease below the
        // feature angle the triangle strays farther elsewhere (measured on spool: 1.13x the
        // bound at a 13-degree ridge). Its centroid's distance catches that (not over a
        // hole, where no input is near).
        if !r.span
            && self
                .oracle
                .distance_beyond_hinted(
                    (a + b + c) / 3.0,
                    self.criteria.distance,
                    &mut Some(r.triangle),
                )
                .is_some()
        {
            return Bad::Distance;
        }
        Bad::No
    }

    fn refine_facet(&mut self, face: [u32; 3], sized: Option<(DVec3, f64)>) {
        let Some([(t, i), _]) = self.dt.find_face(face[0], face[1], face[2]) else {
            return;
        };
        let Some(r) = self.facet_at(t, i) else {
            return;
        };
        let why = self.badness(&r, sized);
        if why != Bad::No {
            self.insert_surface_point(r, t, why);
        }
    }

    /// Inserts a facet's surface centre, or queues the subsegments it would encroach (and the
    /// facet again), or says why it does neither.
    fn insert_surface_point(&mut self, r: Restricted, hint: u32, why: Bad) -> Outcome {
        // Next to a small corner refinement would go on towards the apex (the curves alone
        // are refined there, for length and distance).
        if why != Bad::Boundary && self.near_small_corner(r.centre) {
            return Outcome::Refused(Refusal::NearSmallAngle);
        }
        let Probe::Cavity(cavity) = self.dt.probe(r.centre, Some(hint)) else {
            return Outcome::Refused(Refusal::Duplicate);
        };
        // A restricted facet's surface ball is empty. A vertex well inside it means the facet
        // was judged on ill-conditioned circumcentres (nearly flat tets of coplanar samples),
        // and its centre may sit on that vertex: two vertices 1e-16 apart, a zero-angle facet
        // and a cascade (star.off at sizes 0.05-0.3). Such a centre is not inserted.
        if self.nearest_in_cavity(&cavity) < EMPTY_BALL_FRACTION * r.radius {
            return Outcome::Refused(Refusal::FlatToRounding);
        }
        let encroached = self.encroached_by_cavity(&cavity);
        if !encroached.is_empty() {
            // A centre on a feature curve encroaches its subsegments at every scale: after
            // MAX_DEFERRALS rounds of splits the facet is left as it is.
            let n = self.surf.deferrals.entry(key3(r.vertices)).or_default();
            *n += 1;
            if *n > MAX_DEFERRALS {
                return Outcome::Refused(Refusal::Cascade);
            }
            for k in encroached {
                self.segs.force_split.insert(k);
                self.segs.queue.push(k);
            }
            self.surf.queue.push(Queued {
                radius: r.radius,
                face: key3(r.vertices),
                sized: None,
            });
            return Outcome::Queued(BoundaryKind::Segment);
        }
        let Ok(Inserted::New(id)) = self.dt.insert_cavity(cavity) else {
            return Outcome::Refused(Refusal::Duplicate);
        };
        self.loc.push(if r.span {
            Loc::Span
        } else {
            Loc::Patch(self.patch_of[r.triangle as usize])
        });
        debug_assert_eq!(self.loc.len(), id as usize + 1);
        self.after_insertion();
        Outcome::Split(BoundaryKind::Facet)
    }

    /// Distance from the probed point to the nearest vertex of its cavity (its nearest vertex).
    fn nearest_in_cavity(&self, cavity: &Cavity) -> f64 {
        let p = cavity.point();
        let (removed, _) = self.dt.cavity(cavity);
        removed
            .iter()
            .flat_map(|&t| self.dt.tet(t))
            .filter(|&v| v != INFINITE)
            .map(|v| self.dt.point(v).distance(p))
            .fold(f64::INFINITY, f64::min)
    }

    /// Subsegments (splittable, outside small corners' balls) among the probed cavity's edges
    /// whose diametric ball holds the probed point.
    fn encroached_by_cavity(&self, cavity: &Cavity) -> Vec<[u32; 2]> {
        let p = cavity.point();
        let (removed, _) = self.dt.cavity(cavity);
        let mut out = vec![];
        for &t in removed {
            let tv = self.dt.tet(t);
            let on_curve = tv.map(|v| self.on_curve(v));
            for i in 0..4 {
                for j in i + 1..4 {
                    if !(on_curve[i] && on_curve[j]) {
                        continue;
                    }
                    let k = key2(tv[i], tv[j]);
                    if out.contains(&k) || self.segs.frozen.contains(&k) {
                        continue;
                    }
                    if !self.segs.all.contains_key(&k) {
                        continue;
                    }
                    let (a, b) = (self.dt.point(k[0]), self.dt.point(k[1]));
                    let m = (a + b) / 2.0;
                    if !self.near_small_corner(m)
                        && (p - m).length_squared() < (a - b).length_squared() / 4.0
                    {
                        out.push(k);
                    }
                }
            }
        }
        out
    }

    /// The boundary from the extracted faces, oriented outwards, vertices renumbered.
    fn boundary(&self, faces: Vec<FaceRef>, stop_reason: Option<String>) -> Boundary {
        let mut out = Boundary {
            stop_reason,
            ..Boundary::default()
        };
        let mut new_id: FxHashMap<u32, u32> = FxHashMap::default();
        for (t, i) in faces {
            let tv = self.dt.tet(t);
            // FACE[i] turns its normal into tet t (inside): reversed, it points out of t's
            // region (the lower one at an interface).
            let f = FACE[i].map(|k| tv[k]);
            let tri = [f[0], f[2], f[1]].map(|v| {
                *new_id.entry(v).or_insert_with(|| {
                    out.points.push(self.dt.point(v));
                    out.loc.push(self.loc[v as usize]);
                    (out.points.len() - 1) as u32
                })
            });
            let triangle = self.facet_at(t, i).map_or_else(
                || {
                    self.oracle
                        .closest(centroid(&self.dt, f))
                        .map_or(0, |c| c.triangle)
                },
                |r| r.triangle,
            );
            out.triangles.push(tri);
            out.input_triangle.push(triangle);
        }
        let mut edges: Vec<[u32; 2]> = self
            .segs
            .all
            .keys()
            .filter_map(|k| Some(key2(*new_id.get(&k[0])?, *new_id.get(&k[1])?)))
            .collect();
        edges.sort_unstable();
        out.feature_edges = edges;
        out
    }
}

/// The tets inside the boundary, numbered with the boundary's vertices first.
#[derive(Default)]
pub struct VolumeMesh {
    /// The boundary's points, then the vertices inside.
    pub vertices: Vec<DVec3>,
    pub tets: Vec<[u32; 4]>,
    /// The region of each tet (`InputSurface::sides`' numbering, from 1).
    pub regions: Vec<u32>,
    /// The cells' spacing when the caller gave none (graded from the surface).
    pub spacing: Option<crate::refine::AutoSpacing>,
    /// How often the cell level left a bad cell as it was, per reason.
    pub refusals: crate::run::report::Refusals,
    /// Time spent on the surface alone, then on the cells (with the surface refinement they
    /// caused).
    pub seconds_surface: f64,
    pub seconds_volume: f64,
}

impl SurfaceMesher<'_> {
    /// The inside tets, renumbered after `boundary` (built from the same triangulation).
    fn volume_mesh(&self, boundary: &Boundary) -> Result<VolumeMesh, MeshError> {
        const NEW: u32 = u32::MAX;
        let mut id = vec![NEW; self.dt.num_vertex_ids()];
        let mut vertices = boundary.points.clone();
        // The boundary's numbering: its points are the triangulation's in first-seen order,
        // matched back by position (they are distinct vertices).
        let by_point: FxHashMap<[u64; 3], u32> = boundary
            .points
            .iter()
            .enumerate()
            .map(|(i, p)| (p.to_array().map(f64::to_bits), i as u32))
            .collect();
        // Counted first so that the output is allocated once (it is the run's peak).
        let inside = self
            .dt
            .finite_tet_ids()
            .filter(|&t| self.region_of(t) != 0)
            .count();
        let (mut tets, mut regions) = (Vec::with_capacity(inside), Vec::with_capacity(inside));
        for t in self.dt.finite_tet_ids() {
            let region = self.region_of(t);
            if region == 0 {
                continue;
            }
            regions.push(region);
            let tv = self.dt.tet(t);
            if tv.iter().any(|&v| self.loc[v as usize] == Loc::Far) {
                return Err(MeshError::Internal(
                    "surface mode approximate: an inside tet reaches the far box".into(),
                ));
            }
            tets.push(tv.map(|v| {
                if id[v as usize] == NEW {
                    let p = self.dt.point(v);
                    id[v as usize] = by_point
                        .get(&p.to_array().map(f64::to_bits))
                        .copied()
                        .unwrap_or_else(|| {
                            vertices.push(p);
                            (vertices.len() - 1) as u32
                        });
                }
                id[v as usize]
            }));
        }
        Ok(VolumeMesh {
            vertices,
            tets,
            regions,
            ..VolumeMesh::default()
        })
    }
}

fn centroid(dt: &Delaunay, f: [u32; 3]) -> DVec3 {
    f.iter().map(|&v| dt.point(v)).sum::<DVec3>() / 3.0
}

#[cfg(test)]
mod angle_tests {
    use super::{has_angle_below, min_angle_deg};
    use glam::DVec3;
    use rand::{Rng, SeedableRng};

    /// The cosine shortcut decides as the angles do: on random triangles, on ones with an
    /// angle within rounding of the bound, and on degenerate ones.
    #[test]
    fn angle_test_through_cosines_agrees_with_the_angles() {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(41);
        let mut near = 0;
        for k in 0..20000 {
            let a = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            let b = DVec3::new(rng.gen(), rng.gen(), rng.gen());
            let c = if k % 3 == 0 {
                // An angle at a of 30 degrees give or take a few ulps (in the plane of a, b
                // and a random direction).
                let u = (b - a).normalize();
                let w = DVec3::new(rng.gen(), rng.gen(), rng.gen())
                    .cross(u)
                    .normalize();
                let t = (30.0f64 + rng.gen_range(-1e-12..1e-12)).to_radians();
                a + (u * t.cos() + w * t.sin()) * rng.gen_range(0.5..2.0)
            } else if k % 7 == 0 {
                a + (b - a) * rng.gen::<f64>() // collinear
            } else {
                DVec3::new(rng.gen(), rng.gen(), rng.gen())
            };
            let exact = min_angle_deg(a, b, c) < 30.0;
            near += usize::from((min_angle_deg(a, b, c) - 30.0).abs() < 1e-6);
            assert_eq!(has_angle_below(a, b, c, 30.0), exact, "{a} {b} {c}");
        }
        assert!(near > 2000, "{near} triangles near the bound");
        assert!(
            has_angle_below(DVec3::ZERO, DVec3::ZERO, DVec3::X, 30.0)
                == (min_angle_deg(DVec3::ZERO, DVec3::ZERO, DVec3::X) < 30.0)
        );
    }
}
