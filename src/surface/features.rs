//! Sharp features of a triangulated surface: which edges are creases, how they join into
//! polylines between corners, and the smooth patches they bound.
//!
//! An edge is a feature when
//! - it is a border or non-manifold edge (not exactly two triangles),
//! - its two triangles carry different labels (only when the input has labels of its own,
//!   [`FeatureParams::use_markers`]; the markers an .off reader invents per face are not
//!   labels), or
//! - its two triangles' normals, oriented consistently across the edge, differ by more than
//!   [`FeatureParams::feature_angle`] degrees.
//!
//! Triangles of one planar input facet never meet at a feature. A vertex is a corner when its
//! number of feature edges is not two, or when the feature curve through it turns by more than
//! the feature angle. Every traversal runs in vertex/triangle id order, so the result is
//! deterministic.
//!
//! Noise is not a feature ([`Features::detect_denoised`]): on a scan, bumps and coarse folds
//! over the feature angle make hundreds of short, ragged creases that no mesh at the user's
//! spacing can follow, and whose protection would refine without end (two creases meeting at
//! a few degrees leave a sliver of patch between them). A crease curve (between corners, made
//! of dihedral edges only) shorter than [`NOISE_SPACINGS`] local spacings is dropped when
//! - it is weak: its mean normal deviation is below [`WEAK_CREASE`] times the feature angle
//!   (a scan's folds: 40-60 degrees at the default 40; CAD creases: mostly 75 and more) and
//!   below [`WEAK_CONTRAST`] times that of the non-feature edges at its vertices, or
//!   it does not stand out from the surface around it (mean deviation below
//!   [`CREASE_CONTRAST`] times that of the non-feature edges at its vertices);
//! - it hangs free (an end on no other feature edge), is a closed loop, or belongs to a
//!   connected cluster of feature edges shorter than that length as a whole.
//!
//! Dropping repeats until nothing changes, so a ragged chain is worn away from its free ends.
//! Borders, non-manifold and label edges are always kept.

use super::InputSurface;
use glam::DVec3;
use rustc_hash::FxHashMap;
use std::cmp::Ordering;

/// How features are detected.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FeatureParams {
    /// Normal deviation (degrees) above which an edge is sharp. Default 40.
    pub feature_angle: f64,
    /// Whether a change of facet marker makes an edge a feature (true for inputs whose markers
    /// are labels: .poly/.smesh markers, named STL solids).
    pub use_markers: bool,
    /// Whether border and non-manifold edges are features (false for a repaired input's
    /// bounding triangles, whose borders are holes spanned smoothly and the edges where a
    /// hidden part was left out).
    pub borders: bool,
}

impl Default for FeatureParams {
    fn default() -> Self {
        FeatureParams {
            feature_angle: 40.0,
            use_markers: false,
            borders: true,
        }
    }
}

/// A chain of feature edges between two corners, or a closed loop with no corner on it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Polyline {
    /// Vertex ids along the curve; for a closed loop the first vertex is not repeated.
    pub vertices: Vec<u32>,
    pub closed: bool,
}

/// The feature graph and patches of a surface.
#[derive(Debug, Clone, PartialEq)]
pub struct Features {
    /// Sharp edges as sorted vertex pairs, ascending.
    pub edges: Vec<[u32; 2]>,
    pub polylines: Vec<Polyline>,
    /// Corner vertices, ascending.
    pub corners: Vec<u32>,
    /// Patch of each triangle: triangles connected across non-feature edges share one.
    pub patch_of: Vec<u32>,
    pub n_patches: usize,
}

/// The smallest angle at a corner: between two of its feature curves, or the angle a patch
/// spans there (the sum of its triangles' angles at the corner).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CornerAngle {
    pub vertex: u32,
    /// Degrees.
    pub angle: f64,
}

/// One use of an edge by a triangle: the edge (sorted ids), the triangle, and whether it
/// runs the edge from the smaller id up.
type EdgeUse = ([u32; 2], u32, bool);

fn sorted(a: u32, b: u32) -> [u32; 2] {
    [a.min(b), a.max(b)]
}

/// Every edge's uses, side by side: `uses` sorted by edge (triangles in order within an
/// edge), and for each triangle side (3 t + j, side j from corner j) the range of its edge.
struct EdgeUses {
    uses: Vec<EdgeUse>,
    range_of_side: Vec<(u32, u32)>,
}

impl EdgeUses {
    fn of(s: &InputSurface) -> EdgeUses {
        let mut keyed = Vec::with_capacity(3 * s.triangles.len());
        for (t, tri) in s.triangles.iter().enumerate() {
            for j in 0..3 {
                let (a, b) = (tri[j], tri[(j + 1) % 3]);
                let e = sorted(a, b);
                keyed.push((
                    (u64::from(e[0]) << 32) | u64::from(e[1]),
                    (3 * t + j) as u32,
                    a < b,
                ));
            }
        }
        keyed.sort_unstable();
        let mut range_of_side = vec![(0, 0); keyed.len()];
        let mut uses = Vec::with_capacity(keyed.len());
        for run in keyed.chunk_by(|x, y| x.0 == y.0) {
            let range = (uses.len() as u32, (uses.len() + run.len()) as u32);
            for &(key, side, up) in run {
                range_of_side[side as usize] = range;
                uses.push(([(key >> 32) as u32, key as u32], side / 3, up));
            }
        }
        EdgeUses {
            uses,
            range_of_side,
        }
    }

    /// The runs of uses of one edge, edges ascending.
    fn runs(&self) -> impl Iterator<Item = &[EdgeUse]> {
        self.uses.chunk_by(|a, b| a.0 == b.0)
    }

    /// The uses of the edge of side j of triangle t.
    fn of_side(&self, t: u32, j: usize) -> &[EdgeUse] {
        let (a, b) = self.range_of_side[3 * t as usize + j];
        &self.uses[a as usize..b as usize]
    }
}

fn angle_deg(u: DVec3, v: DVec3) -> f64 {
    // atan2 of |u x v| and u.v is accurate at every angle, unlike acos near 0 and 180.
    u.cross(v).length().atan2(u.dot(v)).to_degrees()
}

/// Normal deviation across a two-triangle edge, with the normals oriented consistently (a
/// consistently oriented pair runs the edge in opposite directions).
fn normal_deviation(s: &InputSurface, (_, t1, up1): EdgeUse, (_, t2, up2): EdgeUse) -> f64 {
    let n1 = s.normal(t1 as usize);
    let mut n2 = s.normal(t2 as usize);
    if up1 == up2 {
        n2 = -n2;
    }
    if n1 == DVec3::ZERO || n2 == DVec3::ZERO {
        return 180.0;
    }
    angle_deg(n1, n2)
}

/// Why an edge is a feature.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Sharp {
    No,
    /// A border, non-manifold or label edge: part of the input's structure, never noise.
    Structural,
    /// Normals deviating by more than the feature angle.
    Crease,
}

fn sharpness(s: &InputSurface, p: &FeatureParams, uses: &[EdgeUse]) -> Sharp {
    let [u1, u2] = match uses {
        [u1, u2] => [*u1, *u2],
        _ if p.borders => return Sharp::Structural,
        _ => return Sharp::No,
    };
    let (t1, t2) = (u1.1 as usize, u2.1 as usize);
    if s.facet_of[t1] == s.facet_of[t2] {
        return Sharp::No;
    }
    if p.use_markers && s.marker_of[t1] != s.marker_of[t2] {
        return Sharp::Structural;
    }
    if normal_deviation(s, u1, u2) > p.feature_angle {
        Sharp::Crease
    } else {
        Sharp::No
    }
}

/// How much more a crease must bend than the non-feature edges around it to be a feature
/// (mean normal deviations).
pub const CREASE_CONTRAST: f64 = 2.0;

/// A crease whose mean deviation is below this many feature angles is weak: short ones are
/// noise. On the shared models at the default 40 degrees: 34 of fandisk's 35 creases and 58
/// of anchor's 61 bend 75 degrees or more on average, dino's 739 crease curves 40-60 degrees
/// for 519 of them.
pub const WEAK_CREASE: f64 = 1.5;

/// A weak crease is noise only among bending edges: below this contrast with them (a crease
/// between flat facets, as a low-poly spike's, is kept however shallow).
pub const WEAK_CONTRAST: f64 = 4.0;

/// A noise curve is shorter than this many local spacings (at 1 or 2, dino and triceratops
/// keep enough short creases between small corners to end at 6-18 degrees).
pub const NOISE_SPACINGS: f64 = 3.0;

/// What [`Features::detect_denoised`] left out.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct Noise {
    /// Crease edges dropped as noise.
    pub edges: usize,
    /// Crease curves (between corners of the graph they were dropped from) dropped as noise.
    pub curves: usize,
}

impl Features {
    /// Detects the features of `s`.
    pub fn detect(s: &InputSurface, p: &FeatureParams) -> Features {
        let uses = EdgeUses::of(s);
        let edges: Vec<[u32; 2]> = uses
            .runs()
            .filter(|run| sharpness(s, p, run) != Sharp::No)
            .map(|run| run[0].0)
            .collect();
        Self::from_edges(s, p, &uses, edges)
    }

    /// Detects the features of `s` without the creases that are noise (see the module
    /// comment): `spacing` is the length a curve must reach where it lies.
    pub fn detect_denoised(
        s: &InputSurface,
        p: &FeatureParams,
        spacing: &mut dyn FnMut(DVec3) -> f64,
    ) -> (Features, Noise) {
        let uses = EdgeUses::of(s);
        let mut structural = Vec::new();
        let mut creases = Vec::new();
        for run in uses.runs() {
            match sharpness(s, p, run) {
                Sharp::No => {}
                Sharp::Structural => structural.push(run[0].0),
                Sharp::Crease => creases.push(run[0].0),
            }
        }
        let bending = Bending::of(s, &uses);
        let mut noise = Noise::default();
        loop {
            let edges = merged(&structural, &creases);
            let dropped = noise_curves(s, p, &edges, &structural, &bending, spacing);
            if dropped.is_empty() {
                break;
            }
            noise.curves += dropped.len();
            let mut gone: Vec<[u32; 2]> = dropped
                .iter()
                .flat_map(|line| line.windows(2).map(|w| sorted(w[0], w[1])))
                .collect();
            gone.sort_unstable();
            gone.dedup();
            noise.edges += gone.len();
            creases.retain(|e| gone.binary_search(e).is_err());
        }
        let edges = merged(&structural, &creases);
        (Self::from_edges(s, p, &uses, edges), noise)
    }

    fn from_edges(
        s: &InputSurface,
        p: &FeatureParams,
        uses: &EdgeUses,
        edges: Vec<[u32; 2]>,
    ) -> Features {
        let graph = FeatureGraph::new(s.vertices.len(), &edges);
        let corners = graph.corners(s, p.feature_angle);
        let polylines = graph.polylines(&corners);
        let (patch_of, n_patches) = patches(s, uses, &edges);
        Features {
            edges,
            polylines,
            corners,
            patch_of,
            n_patches,
        }
    }

    /// For every corner, its smallest angle between feature curves or spanned by a patch.
    pub fn corner_angles(&self, s: &InputSurface) -> Vec<CornerAngle> {
        let graph = FeatureGraph::new(s.vertices.len(), &self.edges);
        let mut patch_angle: FxHashMap<(u32, u32), f64> = FxHashMap::default();
        let is_corner = |v: u32| self.corners.binary_search(&v).is_ok();
        for (t, tri) in s.triangles.iter().enumerate() {
            for j in 0..3 {
                let v = tri[j];
                if is_corner(v) {
                    let p = s.vertices[v as usize];
                    let a = s.vertices[tri[(j + 1) % 3] as usize] - p;
                    let b = s.vertices[tri[(j + 2) % 3] as usize] - p;
                    *patch_angle.entry((v, self.patch_of[t])).or_default() += angle_deg(a, b);
                }
            }
        }
        let mut smallest_patch: FxHashMap<u32, f64> = FxHashMap::default();
        for (&(v, _), &sum) in &patch_angle {
            let m = smallest_patch.entry(v).or_insert(f64::INFINITY);
            *m = m.min(sum);
        }
        self.corners
            .iter()
            .map(|&v| {
                let p = s.vertices[v as usize];
                let nb = graph.neighbours(v);
                let mut angle = f64::INFINITY;
                for (i, &a) in nb.iter().enumerate() {
                    for &b in &nb[i + 1..] {
                        let da = s.vertices[a as usize] - p;
                        let db = s.vertices[b as usize] - p;
                        angle = angle.min(angle_deg(da, db));
                    }
                }
                if let Some(&sum) = smallest_patch.get(&v) {
                    angle = angle.min(sum);
                }
                CornerAngle { vertex: v, angle }
            })
            .collect()
    }
}

/// Two ascending edge lists as one.
fn merged(a: &[[u32; 2]], b: &[[u32; 2]]) -> Vec<[u32; 2]> {
    let mut all = [a, b].concat();
    all.sort_unstable();
    all
}

/// Every edge's normal deviation (180 where it is not used by exactly two triangles), and the
/// edges at each vertex.
struct Bending {
    edges: Vec<[u32; 2]>,
    deviation: Vec<f64>,
    at: FeatureGraph,
}

impl Bending {
    fn of(s: &InputSurface, uses: &EdgeUses) -> Bending {
        let (edges, deviation): (Vec<[u32; 2]>, Vec<f64>) = uses
            .runs()
            .map(|run| {
                let d = match run {
                    [u1, u2] => normal_deviation(s, *u1, *u2),
                    _ => 180.0,
                };
                (run[0].0, d)
            })
            .unzip();
        let at = FeatureGraph::new(s.vertices.len(), &edges);
        Bending {
            edges,
            deviation,
            at,
        }
    }

    fn deviation(&self, a: u32, b: u32) -> f64 {
        self.edges
            .binary_search(&sorted(a, b))
            .map_or(0.0, |i| self.deviation[i])
    }

    /// Mean deviation of the edges along `vertices`.
    fn mean_along(&self, vertices: &[u32]) -> f64 {
        vertices
            .windows(2)
            .map(|w| self.deviation(w[0], w[1]))
            .sum::<f64>()
            / (vertices.len() - 1) as f64
    }

    /// How many times more the curve through `vertices` bends than the edges at its vertices
    /// that are not in `features`, on average (infinite where there are none, or they are
    /// flat: a crease between planar facets).
    fn contrast(&self, vertices: &[u32], features: &[[u32; 2]]) -> f64 {
        let along = self.mean_along(vertices);
        let (mut sum, mut n) = (0.0, 0usize);
        for &v in vertices {
            for &w in self.at.neighbours(v) {
                if features.binary_search(&sorted(v, w)).is_err() {
                    sum += self.deviation(v, w);
                    n += 1;
                }
            }
        }
        if n == 0 || sum == 0.0 {
            f64::INFINITY
        } else {
            along / (sum / n as f64)
        }
    }
}

/// The crease curves of the feature graph `edges` that are noise (see the module comment),
/// each given as its vertices (closed loops with the first repeated at the end).
fn noise_curves(
    s: &InputSurface,
    p: &FeatureParams,
    edges: &[[u32; 2]],
    structural: &[[u32; 2]],
    bending: &Bending,
    spacing: &mut dyn FnMut(DVec3) -> f64,
) -> Vec<Vec<u32>> {
    let graph = FeatureGraph::new(s.vertices.len(), edges);
    let corners = graph.corners(s, p.feature_angle);
    let point = |v: u32| s.vertices[v as usize];
    let length = |w: &[u32]| -> f64 {
        w.windows(2)
            .map(|e| point(e[0]).distance(point(e[1])))
            .sum()
    };
    // Total length of each connected cluster of feature edges, by its smallest vertex.
    let mut cluster = crate::union_find::UnionFind::new(s.vertices.len());
    for e in edges {
        cluster.union(e[0], e[1]);
    }
    let mut cluster_length: FxHashMap<u32, f64> = FxHashMap::default();
    for e in edges {
        *cluster_length.entry(cluster.find(e[0])).or_default() += point(e[0]).distance(point(e[1]));
    }
    let free = |v: u32| graph.neighbours(v).len() == 1;
    let mut out = Vec::new();
    for line in graph.polylines(&corners) {
        let mut vertices = line.vertices;
        if line.closed {
            vertices.push(vertices[0]);
        }
        if vertices
            .windows(2)
            .any(|w| structural.binary_search(&sorted(w[0], w[1])).is_ok())
        {
            continue;
        }
        let contrast = bending.contrast(&vertices, edges);
        if contrast < CREASE_CONTRAST {
            out.push(vertices);
            continue;
        }
        let len = length(&vertices);
        let middle = vertices[vertices.len() / 2];
        let h = NOISE_SPACINGS * spacing(point(middle));
        // A spacing that is not a number keeps the curve.
        if len.partial_cmp(&h) != Some(Ordering::Less) {
            continue;
        }
        let ends = [vertices[0], vertices[vertices.len() - 1]];
        let small_cluster = cluster_length[&cluster.find(ends[0])] < h;
        let weak = bending.mean_along(&vertices) < WEAK_CREASE * p.feature_angle
            && contrast < WEAK_CONTRAST;
        if weak || line.closed || ends.iter().any(|&v| free(v)) || small_cluster {
            out.push(vertices);
        }
    }
    out
}

/// Feature edges as a vertex adjacency (neighbours sorted ascending).
struct FeatureGraph {
    start: Vec<usize>,
    adjacent: Vec<u32>,
}

impl FeatureGraph {
    fn new(n_vertices: usize, edges: &[[u32; 2]]) -> FeatureGraph {
        let mut degree = vec![0usize; n_vertices + 1];
        for e in edges {
            degree[e[0] as usize + 1] += 1;
            degree[e[1] as usize + 1] += 1;
        }
        for i in 1..degree.len() {
            degree[i] += degree[i - 1];
        }
        let start = degree.clone();
        let mut fill = degree;
        let mut adjacent = vec![0u32; edges.len() * 2];
        for e in edges {
            for (v, w) in [(e[0], e[1]), (e[1], e[0])] {
                adjacent[fill[v as usize]] = w;
                fill[v as usize] += 1;
            }
        }
        for v in 0..n_vertices {
            adjacent[start[v]..start[v + 1]].sort_unstable();
        }
        FeatureGraph { start, adjacent }
    }

    fn neighbours(&self, v: u32) -> &[u32] {
        &self.adjacent[self.start[v as usize]..self.start[v as usize + 1]]
    }

    fn corners(&self, s: &InputSurface, feature_angle: f64) -> Vec<u32> {
        (0..s.vertices.len() as u32)
            .filter(|&v| match self.neighbours(v) {
                [] => false,
                [a, b] => {
                    let p = s.vertices[v as usize];
                    let into = p - s.vertices[*a as usize];
                    let out = s.vertices[*b as usize] - p;
                    angle_deg(into, out) > feature_angle
                }
                _ => true,
            })
            .collect()
    }

    fn polylines(&self, corners: &[u32]) -> Vec<Polyline> {
        let mut used: FxHashMap<[u32; 2], ()> = FxHashMap::default();
        let is_corner = |v: u32| corners.binary_search(&v).is_ok();
        let mut lines = Vec::new();
        for &c in corners {
            for &next in self.neighbours(c) {
                if used.insert(sorted(c, next), ()).is_none() {
                    let mut vertices = vec![c, next];
                    self.walk(&mut vertices, &mut used, &is_corner);
                    lines.push(Polyline {
                        vertices,
                        closed: false,
                    });
                }
            }
        }
        let n = self.start.len() - 1;
        for v in 0..n as u32 {
            for &next in self.neighbours(v) {
                if used.insert(sorted(v, next), ()).is_none() {
                    let mut vertices = vec![v, next];
                    self.walk(&mut vertices, &mut used, &|w| w == v);
                    vertices.pop();
                    lines.push(Polyline {
                        vertices,
                        closed: true,
                    });
                }
            }
        }
        lines
    }

    /// Extends `vertices` through degree-2 vertices until `stop` holds at its end.
    fn walk(
        &self,
        vertices: &mut Vec<u32>,
        used: &mut FxHashMap<[u32; 2], ()>,
        stop: &dyn Fn(u32) -> bool,
    ) {
        loop {
            let v = *vertices.last().expect("a walk starts with an edge");
            if stop(v) {
                return;
            }
            let next = self
                .neighbours(v)
                .iter()
                .copied()
                .find(|&w| !used.contains_key(&sorted(v, w)));
            match next {
                Some(w) => {
                    used.insert(sorted(v, w), ());
                    vertices.push(w);
                }
                None => return,
            }
        }
    }
}

/// Patch of each triangle (flood fill across non-feature edges, seeds in triangle order).
fn patches(s: &InputSurface, uses: &EdgeUses, feature_edges: &[[u32; 2]]) -> (Vec<u32>, usize) {
    let n = s.triangles.len();
    let mut patch_of = vec![u32::MAX; n];
    let mut n_patches = 0u32;
    let mut stack = Vec::new();
    for seed in 0..n {
        if patch_of[seed] != u32::MAX {
            continue;
        }
        patch_of[seed] = n_patches;
        stack.push(seed as u32);
        while let Some(t) = stack.pop() {
            let tri = s.triangles[t as usize];
            for j in 0..3 {
                let e = sorted(tri[j], tri[(j + 1) % 3]);
                if feature_edges.binary_search(&e).is_ok() {
                    continue;
                }
                for &(_, u, _) in uses.of_side(t, j) {
                    if patch_of[u as usize] == u32::MAX {
                        patch_of[u as usize] = n_patches;
                        stack.push(u);
                    }
                }
            }
        }
        n_patches += 1;
    }
    (patch_of, n_patches as usize)
}
