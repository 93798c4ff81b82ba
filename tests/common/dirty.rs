//! Dirty triangle surfaces built at test time from closed ones (deterministic, nothing stored):
//! the defects `slivermesh mesh --repair` is for. Each generator takes a closed,
//! outward-oriented [`Surface`] and returns a [`Dirty`] case: the dirty triangles, the file the
//! CLI reads, and the volume a repaired mesh should enclose.
//!
//! The generators: [`small_hole`] (an open hole), [`open_bottom`] (an open-bottomed scan),
//! [`overlapping_copies`] (two intersecting closed copies in one file), [`flipped`] (5% of the
//! triangles reversed), [`soup`] (every triangle on its own vertices), [`crack`] (a disk cut
//! loose and shrunk: a thin open crack around it), [`fold`] (a patch pushed through the far
//! side of a thin part: a closed, manifold surface that intersects itself). [`corpus`] applies
//! them to an icosphere, a flattened and a truncated icosphere, two scans (homer, bear_bis) and
//! a CAD model (fandisk).
//!
//! Volumes of self-intersecting or overlapping surfaces are measured by [`winding_volume`]:
//! the exact integral of the winding number's indicator along a grid of vertical lines (see
//! there for its accuracy).

use super::corpus::{self, Surface};
use slivermesh::geom::{orient2d, orient3d};
use slivermesh::DVec3;
use std::collections::{HashMap, HashSet, VecDeque};

/// Which generator made a case.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Kind {
    SmallHole,
    OpenBottom,
    OverlappingCopies,
    Flipped,
    Soup,
    Crack,
    Fold,
}

/// One dirty case.
#[derive(Debug, Clone)]
pub struct Dirty {
    /// Unique in the corpus; the file's stem.
    pub name: String,
    pub kind: Kind,
    /// The closed, outward-oriented surface the case was made from (for the checks).
    pub clean: Surface,
    /// The dirty triangles, written to the file as they are (no vertex is merged, none that no
    /// triangle uses is kept).
    pub surface: Surface,
    /// The clean surface's enclosed volume (divergence theorem).
    pub clean_volume: f64,
    /// The volume a repaired mesh should enclose: the clean volume, except for the cases whose
    /// generator says otherwise (open bottom: the solid cut at the plane; overlapping copies:
    /// the union; fold: the generalized winding number's {w >= 1/2}).
    pub expected_volume: f64,
    /// Area of the triangles deleted (small hole, open bottom), 0 for the other defects.
    pub hole_area: f64,
    /// Written as one ASCII STL solid instead of .off.
    pub stl: bool,
    /// Whether the dirty triangles lie on the boundary of the solid the repair should produce,
    /// so that the output boundary must pass near all of them: false for overlapping copies
    /// (the half of each copy that lies inside the other is not on the union's boundary); true
    /// for the fold, whose dent tip and the bottom inside its tube, 0.5% of the area, are off
    /// the boundary (within the 2% the tests allow).
    pub all_on_boundary: bool,
}

impl Dirty {
    pub fn file_name(&self) -> String {
        format!("{}.{}", self.name, if self.stl { "stl" } else { "off" })
    }

    pub fn file_text(&self) -> String {
        if self.stl {
            self.surface.stl_solid(&self.name)
        } else {
            self.surface.off_text()
        }
    }

    pub fn n_triangles(&self) -> usize {
        self.surface.triangles.len()
    }
}

// ---------------------------------------------------------------------------------------------
// The corpus.

/// Every case, in a fixed order (14 cases, each under 30,000 triangles).
pub fn corpus() -> Vec<Dirty> {
    CASES.iter().map(|(_, make)| make()).collect()
}

/// A corpus case's name and constructor.
pub type Case = (&'static str, fn() -> Dirty);

/// The corpus cases by name, with their constructors (so that one case is built alone).
pub const CASES: [Case; 14] = [
    ("small_hole_sphere", small_hole_sphere),
    ("small_hole_homer", small_hole_homer),
    ("small_hole_bear", small_hole_bear),
    ("open_bottom_dome", open_bottom_dome),
    ("open_bottom_fandisk", open_bottom_fandisk),
    ("overlap_sphere", overlap_sphere),
    ("overlap_homer", overlap_homer),
    ("flipped_bear", flipped_bear),
    ("flipped_fandisk", flipped_fandisk),
    ("soup_fandisk", soup_fandisk),
    ("soup_homer", soup_homer),
    ("crack_sphere", crack_sphere),
    ("crack_bear", crack_bear),
    ("fold_slab", fold_slab),
];

fn named(mut d: Dirty, name: &str) -> Dirty {
    d.name = name.to_string();
    d
}

/// 60 triangles removed from the 5,120 of a sphere of diameter 1.
pub fn small_hole_sphere() -> Dirty {
    named(small_hole(&sphere(), 60), "small_hole_sphere")
}

/// 120 triangles removed from homer (9,856).
pub fn small_hole_homer() -> Dirty {
    named(small_hole(&homer(), 120), "small_hole_homer")
}

/// 200 triangles removed from bear_bis (20,188).
pub fn small_hole_bear() -> Dirty {
    named(small_hole(&bear(), 200), "small_hole_bear")
}

/// The flat base (26% of the area) of a sphere truncated by a plane: the rim is planar, so the
/// flat fill is the clean surface.
pub fn open_bottom_dome() -> Dirty {
    named(open_bottom(&dome(), 0.25), "open_bottom_dome")
}

/// Fandisk turned so that its largest flat face (24.5% of the area) is at the bottom, that face
/// removed: its rim is planar, so the flat fill is the clean surface.
pub fn open_bottom_fandisk() -> Dirty {
    named(
        open_bottom(&fandisk_flat_face_down(), 0.24),
        "open_bottom_fandisk",
    )
}

pub fn overlap_sphere() -> Dirty {
    named(overlapping_copies(&sphere()), "overlap_sphere")
}

pub fn overlap_homer() -> Dirty {
    named(overlapping_copies(&homer()), "overlap_homer")
}

pub fn flipped_bear() -> Dirty {
    named(flipped(&bear(), 0.05), "flipped_bear")
}

pub fn flipped_fandisk() -> Dirty {
    named(flipped(&fandisk(), 0.05), "flipped_fandisk")
}

pub fn soup_fandisk() -> Dirty {
    named(soup(&fandisk()), "soup_fandisk")
}

pub fn soup_homer() -> Dirty {
    named(soup(&homer()), "soup_homer")
}

pub fn crack_sphere() -> Dirty {
    named(crack(&sphere()), "crack_sphere")
}

pub fn crack_bear() -> Dirty {
    named(crack(&bear()), "crack_bear")
}

/// A flattened sphere whose top is pushed through its bottom.
pub fn fold_slab() -> Dirty {
    named(fold(&slab()), "fold_slab")
}

// ---------------------------------------------------------------------------------------------
// The closed models.

/// A closed triangle surface from an .off file under `models/` (triangles only).
pub fn read_off(rel: &str) -> Surface {
    let path = super::models_dir().join(rel);
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut tokens = text
        .lines()
        .map(|l| l.split('#').next().unwrap_or(""))
        .flat_map(str::split_whitespace);
    let header = tokens.next().expect("empty file");
    assert_eq!(header, "OFF", "{rel}: plain OFF expected");
    let mut number = || -> f64 {
        let t = tokens.next().unwrap_or_else(|| panic!("{rel}: truncated"));
        t.parse()
            .unwrap_or_else(|e| panic!("{rel}: {t:?} is not a number: {e}"))
    };
    let (nv, nf) = (number() as usize, number() as usize);
    number(); // edge count
    let vertices = (0..nv)
        .map(|_| DVec3::new(number(), number(), number()))
        .collect();
    let triangles = (0..nf)
        .map(|_| {
            assert_eq!(number(), 3.0, "{rel}: triangles only");
            [number() as u32, number() as u32, number() as u32]
        })
        .collect();
    Surface {
        vertices,
        triangles,
    }
}

/// A level-4 icosphere of diameter 1 (5,120 triangles).
pub fn sphere() -> Surface {
    scaled(corpus::icosphere(4), DVec3::splat(0.5))
}

/// [`sphere`] turned by 0.4 rad about (1, 2, 3) and flattened to a thickness of a quarter of
/// its width (semi-axes 0.5, 0.5, 0.125). (Turned so that no vertex sits at a pole: the
/// icosphere's vertices are symmetric about its centre, and with a vertex straight above
/// another a dent pushed down from one meets the other's edges exactly, edge on edge, instead
/// of crossing its triangles.)
pub fn slab() -> Surface {
    let turn = glam::DQuat::from_axis_angle(DVec3::new(1.0, 2.0, 3.0).normalize(), 0.4);
    let mut s = corpus::icosphere(4);
    for p in &mut s.vertices {
        *p = turn * *p;
    }
    scaled(s, DVec3::new(0.5, 0.5, 0.125))
}

/// [`sphere`] with every vertex below z = -0.15 raised onto that plane: a sphere truncated 0.35
/// below its centre, whose flat base (the triangles with three raised vertices) holds 26% of
/// the area. (The lower cap is a graph over the base disk, so the raised triangles keep their
/// orientation and do not overlap.)
pub fn dome() -> Surface {
    let mut s = sphere();
    for p in &mut s.vertices {
        p.z = p.z.max(-0.15);
    }
    s
}

pub fn homer() -> Surface {
    read_off("scans/homer.off")
}

pub fn bear() -> Surface {
    read_off("scans/bear_bis.off")
}

pub fn fandisk() -> Surface {
    read_off("off/fandisk.off")
}

/// Fandisk rotated by a quarter turn about x, (x, y, z) -> (x, z, -y) (exact), which takes its
/// flat face y = 0.25555 to z = -0.25555, the bottom.
pub fn fandisk_flat_face_down() -> Surface {
    let mut s = fandisk();
    for p in &mut s.vertices {
        *p = DVec3::new(p.x, p.z, -p.y);
    }
    s
}

fn scaled(mut s: Surface, f: DVec3) -> Surface {
    for p in &mut s.vertices {
        *p *= f;
    }
    s
}

// ---------------------------------------------------------------------------------------------
// Generators.

fn case(kind: Kind, clean: &Surface, surface: Surface) -> Dirty {
    let v = clean.volume();
    Dirty {
        name: String::new(),
        kind,
        clean: clean.clone(),
        surface,
        clean_volume: v,
        expected_volume: v,
        hole_area: 0.0,
        stl: false,
        all_on_boundary: true,
    }
}

/// Deletes a connected patch of `n` triangles (a topological disk: one boundary loop), grown
/// from the triangle that lies farthest along the fixed direction (0.36, 0.48, 0.8) (an extreme
/// point, so the patch lies on a convex part and a smooth fill is close to the clean surface).
/// The patch grows one edge-adjacent triangle at a time: first any triangle that shares two
/// edges with it (closing a notch), else the one nearest the seed among those whose third
/// vertex is not yet in the patch (which keeps it a disk). Expected volume: the clean one.
pub fn small_hole(s: &Surface, n: usize) -> Dirty {
    assert!((20..=200).contains(&n), "hole of {n} triangles");
    let dir = DVec3::new(0.36, 0.48, 0.8);
    let centroid = |t: usize| s.corners(t).iter().sum::<DVec3>() / 3.0;
    let seed = (0..s.triangles.len())
        .max_by(|&a, &b| centroid(a).dot(dir).total_cmp(&centroid(b).dot(dir)))
        .unwrap();
    let adjacent = edge_adjacency(s);
    let mut removed = vec![false; s.triangles.len()];
    let mut in_patch = vec![false; s.vertices.len()];
    let mut patch: Vec<usize> = Vec::new();
    let origin = centroid(seed);
    let mut next = Some(seed);
    while let Some(t) = next {
        removed[t] = true;
        for v in s.triangles[t] {
            in_patch[v as usize] = true;
        }
        patch.push(t);
        if patch.len() == n {
            break;
        }
        // (shared edges, distance, triangle): most shared edges, then nearest, then lowest id.
        let mut best: Option<(usize, f64, usize)> = None;
        let mut candidates: Vec<usize> = patch
            .iter()
            .flat_map(|&t| adjacent[t].iter().copied())
            .filter(|&u| !removed[u])
            .collect();
        candidates.sort_unstable();
        candidates.dedup();
        for u in candidates {
            let shared = adjacent[u].iter().filter(|&&w| removed[w]).count();
            let fresh = s.triangles[u]
                .iter()
                .filter(|&&v| !in_patch[v as usize])
                .count();
            if !(shared == 2 || (shared == 1 && fresh == 1)) {
                continue;
            }
            let d = centroid(u).distance(origin);
            let better = best.is_none_or(|(bs, bd, _)| shared > bs || (shared == bs && d < bd));
            if better {
                best = Some((shared, d, u));
            }
        }
        next = Some(best.expect("the patch can grow").2);
    }
    let hole_area: f64 = patch.iter().map(|&t| triangle_area(s, t)).sum();
    let dirty = keep_triangles(s, |t| !removed[t]);
    let mut d = case(Kind::SmallHole, s, dirty);
    d.hole_area = hole_area;
    d
}

/// Deletes every triangle whose centroid lies at or below the horizontal plane z = h, where h
/// is the centroid height at which the triangles sorted by centroid height first reach
/// `fraction` of the area (triangles at that height all go: a flat bottom face goes whole).
/// Expected volume: the clean solid above the plane, {z >= h}, by [`winding_volume`] (what a
/// flat fill of the opening encloses; for a planar rim that is also where the generalized
/// winding number of the open surface is 1/2). A smooth fill of a curved bottom encloses more,
/// up to the clean volume: the corpus uses bottoms that are flat (a truncated sphere, fandisk's
/// flat face), where the two agree.
pub fn open_bottom(s: &Surface, fraction: f64) -> Dirty {
    let height = |t: usize| s.corners(t).iter().map(|p| p.z).sum::<f64>() / 3.0;
    let mut order: Vec<usize> = (0..s.triangles.len()).collect();
    order.sort_by(|&a, &b| height(a).total_cmp(&height(b)));
    let total = s.area();
    let mut cumulative = 0.0;
    let mut plane = f64::NAN;
    for &t in &order {
        cumulative += triangle_area(s, t);
        if cumulative >= fraction * total {
            plane = height(t);
            break;
        }
    }
    let gone: Vec<bool> = (0..s.triangles.len()).map(|t| height(t) <= plane).collect();
    let hole_area = (0..s.triangles.len())
        .filter(|&t| gone[t])
        .map(|t| triangle_area(s, t))
        .sum();
    let dirty = keep_triangles(s, |t| !gone[t]);
    let mut d = case(Kind::OpenBottom, s, dirty);
    d.hole_area = hole_area;
    d.expected_volume = winding_volume(s, WINDING_GRID, plane).volume;
    d
}

/// Two copies in one .off, the second moved by 1% of the diagonal along (1, 1, 1) / sqrt(3):
/// two closed surfaces crossing each other. Expected volume: the union's, by
/// [`winding_volume`] on both copies (the winding number is the number of copies around a
/// point; the union is where it is at least 1).
pub fn overlapping_copies(s: &Surface) -> Dirty {
    let shift = DVec3::ONE.normalize() * (0.01 * s.diagonal());
    let mut second = s.clone();
    for p in &mut second.vertices {
        *p += shift;
    }
    let mut both = s.clone();
    both.append(&second);
    let union = winding_volume(&both, WINDING_GRID, f64::MIN).volume;
    let mut d = case(Kind::OverlappingCopies, s, both);
    d.expected_volume = union;
    d.all_on_boundary = false;
    d
}

/// Reverses `fraction` of the triangles (rounded), chosen by a seeded xorshift generator (a
/// partial Fisher-Yates shuffle: spread over the surface, no clusters built on purpose).
/// Expected volume: the clean one.
pub fn flipped(s: &Surface, fraction: f64) -> Dirty {
    let mut dirty = s.clone();
    for t in flipped_set(s.triangles.len(), fraction) {
        dirty.triangles[t].swap(1, 2);
    }
    case(Kind::Flipped, s, dirty)
}

/// The triangles [`flipped`] reverses, sorted.
pub fn flipped_set(n: usize, fraction: f64) -> Vec<usize> {
    let k = (fraction * n as f64).round() as usize;
    let mut rng = XorShift(0x2545_f491_4f6c_dd1d);
    let mut ids: Vec<usize> = (0..n).collect();
    for i in 0..k {
        let j = i + (rng.next() % (n - i) as u64) as usize;
        ids.swap(i, j);
    }
    let mut chosen = ids[..k].to_vec();
    chosen.sort_unstable();
    chosen
}

/// Every triangle on its own three vertices (duplicates at identical coordinates), as STL
/// exporters write them; in a .off file, whose reader takes the vertex list as it is (an STL
/// file would not do: the STL reader merges vertices at equal coordinates, so a soup written as
/// STL reads back as the clean surface). Expected volume: the clean one.
pub fn soup(s: &Surface) -> Dirty {
    let mut dirty = Surface::default();
    for k in 0..s.triangles.len() {
        let base = dirty.vertices.len() as u32;
        dirty.vertices.extend_from_slice(&s.corners(k));
        dirty.triangles.push([base, base + 1, base + 2]);
    }
    case(Kind::Soup, s, dirty)
}

/// Cuts the surface open along the boundary loop of the 3-ring disk around a vertex: the
/// disk's triangles (those with a vertex at most 2 edges from the centre) get their own copies
/// of the loop's vertices, and the disk is scaled towards the centre vertex so that the loop
/// moves in by 0.2% of the diagonal on average: a thin open crack around a loose disk (two
/// components, two boundary loops). The centre is the first vertex, farthest along the fixed
/// direction (-0.6, 0, 0.8) first, whose 3-ring disk is a topological disk with one simple
/// boundary loop. Expected volume: the clean one (the disk moves by less than the crack's
/// width).
pub fn crack(s: &Surface) -> Dirty {
    let (centre, disk, lp) = ring_disk(s, DVec3::new(-0.6, 0.0, 0.8), 3);
    let c = s.vertices[centre as usize];
    let radius = lp
        .iter()
        .map(|&v| s.vertices[v as usize].distance(c))
        .sum::<f64>()
        / lp.len() as f64;
    let factor = 1.0 - 0.002 * s.diagonal() / radius;
    let mut dirty = s.clone();
    let mut copy: HashMap<u32, u32> = HashMap::new();
    for &v in &lp {
        dirty.vertices.push(s.vertices[v as usize]);
        copy.insert(v, dirty.vertices.len() as u32 - 1);
    }
    let mut moved: HashSet<u32> = HashSet::new();
    for &t in &disk {
        let tri = s.triangles[t].map(|v| *copy.get(&v).unwrap_or(&v));
        dirty.triangles[t] = tri;
        moved.extend(tri);
    }
    for v in moved {
        let p = &mut dirty.vertices[v as usize];
        *p = c + (*p - c) * factor;
    }
    case(Kind::Crack, s, dirty)
}

/// Pushes a patch through the far side of the body: the top vertex (largest z) and its
/// neighbours move along minus the top vertex's normal by 1.25 times the body's thickness
/// there (where the ray from the top vertex along minus the normal leaves the body), so the
/// triangles joining them to the 2-ring (the dent's walls) cross the bottom and the dent's
/// tip sticks out below it. The surface stays closed, manifold and consistently oriented.
///
/// Winding numbers: 1 in the body outside the dent, 0 inside the dent's tube between the top
/// and the bottom (the tube is outside the surface), -1 in the tip below the bottom (enclosed
/// the wrong way round), 0 elsewhere outside. So {w >= 1/2} is the clean body less the tube
/// where it runs through it: a body with a tapered through hole. Expected volume: that, by
/// [`winding_volume`] on the dirty surface (1.9% below the clean volume on the slab).
pub fn fold(s: &Surface) -> Dirty {
    let (p, n, thickness) = fold_axis(s);
    let top = s.vertices.iter().position(|&q| q == p).unwrap() as u32;
    let mut dirty = s.clone();
    let mut patch: HashSet<u32> = HashSet::from([top]);
    for t in &s.triangles {
        if t.contains(&top) {
            patch.extend(t);
        }
    }
    for v in patch {
        dirty.vertices[v as usize] -= n * (1.25 * thickness);
    }
    let mut d = case(Kind::Fold, s, dirty);
    d.expected_volume = winding_volume(&d.surface, WINDING_GRID, f64::MIN).volume;
    d
}

/// The top vertex of `s` (largest z, first of equals), its area-weighted unit normal, and the
/// distance from it along minus the normal to the first triangle not around it: the axis and
/// depth [`fold`] pushes along.
pub fn fold_axis(s: &Surface) -> (DVec3, DVec3, f64) {
    let top = (0..s.vertices.len())
        .max_by(|&a, &b| s.vertices[a].z.total_cmp(&s.vertices[b].z).then(b.cmp(&a)))
        .unwrap() as u32;
    let n = vertex_normal(s, top);
    let p = s.vertices[top as usize];
    let thickness = (0..s.triangles.len())
        .filter(|&t| !s.triangles[t].contains(&top))
        .filter_map(|t| ray_hit(p, -n, s.corners(t)))
        .fold(f64::MAX, f64::min);
    assert!(thickness < f64::MAX, "no far side below the top vertex");
    (p, n, thickness)
}

// ---------------------------------------------------------------------------------------------
// Winding-number volume.

/// Columns per axis of [`winding_volume`] in the generators.
pub const WINDING_GRID: usize = 1024;

/// What [`winding_volume`] measured.
#[derive(Debug, Clone, Copy)]
pub struct WindingVolume {
    pub volume: f64,
    /// Columns whose winding number did not come back to 0 above the surface (an open surface:
    /// the result is then meaningless).
    pub unbalanced_columns: usize,
    /// Columns that met an edge or vertex exactly and were measured again slightly moved.
    pub moved_columns: usize,
}

/// Volume of {p : w(p) >= 1, p.z >= z_min}, w the winding number of the closed (possibly
/// self-intersecting, possibly several-component) triangle surface `s`: the number of times it
/// wraps around p, counted with orientation.
///
/// A grid of `grid` x `grid` vertical lines over the bounding box's xy rectangle, at the cell
/// centres (offset by a small fixed fraction of a cell, so that the grid-aligned coordinates
/// of CAD models are not met exactly). Along each line the crossings with the triangles are
/// found with exact orientation tests (a line that meets an edge or a vertex exactly is moved
/// by 1e-4 of a cell and measured again) and sorted; w changes by +1 through a triangle facing
/// down and by -1 through one facing up, and the length where w >= 1 is summed exactly. The
/// only approximation is the midpoint rule across the lines, whose error comes from the cells
/// the solid's outline (seen from above) crosses, with random signs.
///
/// Measured at 1024 x 1024 (`corpus_winding_volume_matches_divergence_volume`, which allows
/// 2e-4): against the divergence-theorem volume of the clean models, 2e-6 to 4e-6 (relative)
/// on the smooth ones and -7e-5 on fandisk, whose vertical walls the lines cut; the union of
/// the two spheres of `overlap_sphere` against the lens formula for balls, 3e-5 of the union
/// (the polyhedral sphere's own difference included); two axis-aligned cubes whose walls all
/// fall at the same offset in the grid's pitch (the worst case: every wall cell errs the same
/// way), 8e-4. The 0.2% aimed at holds with a wide margin.
pub fn winding_volume(s: &Surface, grid: usize, z_min: f64) -> WindingVolume {
    let (lo, hi) = s.bbox();
    let (hx, hy) = ((hi.x - lo.x) / grid as f64, (hi.y - lo.y) / grid as f64);
    // Line (i, j) at (x0 + i hx, y0 + j hy).
    let (x0, y0) = (lo.x + 0.5037 * hx, lo.y + 0.4969 * hy);
    let xy = |p: DVec3| [p.x, p.y];
    // Each triangle that is not vertical in projection, in the rows of lines its y-range spans.
    let mut rows: Vec<Vec<u32>> = vec![Vec::new(); grid];
    let index_range = |a: f64, b: f64, origin: f64, h: f64| {
        let first = ((a - origin) / h).ceil().max(0.0) as usize;
        let last = ((b - origin) / h).floor().min(grid as f64 - 1.0);
        (first, last)
    };
    for (k, t) in s.triangles.iter().enumerate() {
        let [a, b, c] = t.map(|v| s.vertices[v as usize]);
        if orient2d(xy(a), xy(b), xy(c)) == 0.0 {
            continue;
        }
        let (ylo, yhi) = (a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y));
        let (first, last) = index_range(ylo, yhi, y0, hy);
        if last < 0.0 {
            continue;
        }
        for row in rows.iter_mut().take(last as usize + 1).skip(first) {
            row.push(k as u32);
        }
    }
    // The crossing of the line at q with triangle k: Some((z, change of w going up)), None
    // for no crossing, Err(()) when the line meets the triangle's boundary.
    let crossing = |k: usize, q: [f64; 2]| -> Result<Option<(f64, i32)>, ()> {
        let [a, b, c] = s.corners(k);
        let (oc, oa, ob) = (
            orient2d(xy(a), xy(b), q),
            orient2d(xy(b), xy(c), q),
            orient2d(xy(c), xy(a), q),
        );
        let pos = (oc > 0.0) as u8 + (oa > 0.0) as u8 + (ob > 0.0) as u8;
        let neg = (oc < 0.0) as u8 + (oa < 0.0) as u8 + (ob < 0.0) as u8;
        if pos == 3 || neg == 3 {
            let z = (oa * a.z + ob * b.z + oc * c.z) / (oa + ob + oc);
            // Counter-clockwise seen from above: facing up, left going up.
            Ok(Some((z, if pos == 3 { -1 } else { 1 })))
        } else if pos + neg < 3 && (pos == 0 || neg == 0) {
            Err(())
        } else {
            Ok(None)
        }
    };
    // Length of {w >= 1, z >= z_min} along one line's sorted crossings; false if unbalanced.
    let length = |crossings: &mut [(f64, i32)]| -> (f64, bool) {
        crossings.sort_by(|a, b| a.0.total_cmp(&b.0));
        let (mut w, mut len) = (0, 0.0);
        for k in 0..crossings.len() {
            w += crossings[k].1;
            if w >= 1 && k + 1 < crossings.len() {
                let (from, to) = (crossings[k].0.max(z_min), crossings[k + 1].0);
                len += (to - from).max(0.0);
            }
        }
        (len, w == 0)
    };
    let mut out = WindingVolume {
        volume: 0.0,
        unbalanced_columns: 0,
        moved_columns: 0,
    };
    let mut total_length = 0.0;
    let mut hits: Vec<(u32, f64, i32)> = Vec::new();
    for (j, row) in rows.iter().enumerate() {
        let y = y0 + j as f64 * hy;
        hits.clear();
        let mut degenerate: Vec<usize> = Vec::new();
        for &k in row {
            let [a, b, c] = s.corners(k as usize);
            let (xlo, xhi) = (a.x.min(b.x).min(c.x), a.x.max(b.x).max(c.x));
            let (first, last) = index_range(xlo, xhi, x0, hx);
            if last < 0.0 {
                continue;
            }
            for i in first..=last as usize {
                match crossing(k as usize, [x0 + i as f64 * hx, y]) {
                    Ok(Some((z, dw))) => hits.push((i as u32, z, dw)),
                    Ok(None) => {}
                    Err(()) => degenerate.push(i),
                }
            }
        }
        degenerate.sort_unstable();
        degenerate.dedup();
        hits.sort_by_key(|h| h.0);
        let mut column: Vec<(f64, i32)> = Vec::new();
        let mut start = 0;
        while start < hits.len() {
            let i = hits[start].0;
            let end = start + hits[start..].iter().take_while(|h| h.0 == i).count();
            if degenerate.binary_search(&(i as usize)).is_err() {
                column.clear();
                column.extend(hits[start..end].iter().map(|h| (h.1, h.2)));
                let (len, balanced) = length(&mut column);
                total_length += len;
                out.unbalanced_columns += usize::from(!balanced);
            }
            start = end;
        }
        // Lines through an edge or a vertex: moved a little, against every triangle.
        for &i in &degenerate {
            out.moved_columns += 1;
            let mut attempt = 1.0;
            loop {
                let q = [
                    x0 + (i as f64 + 1e-4 * attempt * std::f64::consts::SQRT_2) * hx,
                    y + 1e-4 * attempt * 3f64.sqrt() * hy,
                ];
                let found: Result<Vec<Option<(f64, i32)>>, ()> =
                    (0..s.triangles.len()).map(|k| crossing(k, q)).collect();
                if let Ok(found) = found {
                    column = found.into_iter().flatten().collect();
                    let (len, balanced) = length(&mut column);
                    total_length += len;
                    out.unbalanced_columns += usize::from(!balanced);
                    break;
                }
                attempt += 1.0;
            }
        }
    }
    out.volume = total_length * hx * hy;
    out
}

// ---------------------------------------------------------------------------------------------
// Checks used by the tests.

/// Pairs (edge, triangle) of `s` whose edge crosses the triangle's interior (exact: the edge's
/// ends strictly on both sides of the triangle's plane, the line through it strictly inside
/// the triangle's three edges), the triangle not sharing a vertex id with the edge; counted up
/// to `limit`.
pub fn count_crossings(s: &Surface, limit: usize) -> usize {
    let (lo, hi) = s.bbox();
    let mut edges: Vec<[u32; 2]> = s
        .triangles
        .iter()
        .flat_map(|t| (0..3).map(move |i| [t[i].min(t[(i + 1) % 3]), t[i].max(t[(i + 1) % 3])]))
        .collect();
    edges.sort_unstable();
    edges.dedup();
    let mean_edge = edges
        .iter()
        .map(|e| s.vertices[e[0] as usize].distance(s.vertices[e[1] as usize]))
        .sum::<f64>()
        / edges.len().max(1) as f64;
    let longest = edges
        .iter()
        .map(|e| s.vertices[e[0] as usize].distance(s.vertices[e[1] as usize]))
        .fold(0.0, f64::max);
    let cell = (2.0 * mean_edge)
        .max(longest / 8.0)
        .max((hi - lo).max_element() / 512.0);
    let key = |p: DVec3| ((p - lo) / cell).floor().as_ivec3().to_array();
    let cells_of = |ps: &[DVec3]| {
        let (a, b) = ps.iter().fold(
            (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
            |(l, h), &p| (l.min(p), h.max(p)),
        );
        let (a, b) = (key(a), key(b));
        let mut out = Vec::new();
        for x in a[0]..=b[0] {
            for y in a[1]..=b[1] {
                for z in a[2]..=b[2] {
                    out.push([x, y, z]);
                }
            }
        }
        out
    };
    let mut grid: HashMap<[i32; 3], Vec<u32>> = HashMap::new();
    for k in 0..s.triangles.len() {
        for c in cells_of(&s.corners(k)) {
            grid.entry(c).or_default().push(k as u32);
        }
    }
    let mut found: HashSet<(usize, u32)> = HashSet::new();
    for (ei, e) in edges.iter().enumerate() {
        let (p, q) = (s.vertices[e[0] as usize], s.vertices[e[1] as usize]);
        for c in cells_of(&[p, q]) {
            for &k in grid.get(&c).into_iter().flatten() {
                let t = s.triangles[k as usize];
                if t.contains(&e[0]) || t.contains(&e[1]) || found.contains(&(ei, k)) {
                    continue;
                }
                let [a, b, cc] = s.corners(k as usize);
                if segment_crosses_triangle(p, q, [a, b, cc]) {
                    found.insert((ei, k));
                    if found.len() >= limit {
                        return found.len();
                    }
                }
            }
        }
    }
    found.len()
}

/// Whether the segment pq crosses the interior of triangle t (exact orientation tests;
/// touching does not count).
pub fn segment_crosses_triangle(p: DVec3, q: DVec3, t: [DVec3; 3]) -> bool {
    let [a, b, c] = t;
    let (sp, sq) = (orient3d(a, b, c, p), orient3d(a, b, c, q));
    if !(sp > 0.0 && sq < 0.0 || sp < 0.0 && sq > 0.0) {
        return false;
    }
    let s = [
        orient3d(p, q, a, b),
        orient3d(p, q, b, c),
        orient3d(p, q, c, a),
    ];
    s.iter().all(|&x| x > 0.0) || s.iter().all(|&x| x < 0.0)
}

/// The boundary loops of `s` (edges used by one triangle), each as its vertex sequence; None
/// if some vertex has other than two boundary edges (loops touching) or an edge is used by
/// more than two triangles.
pub fn boundary_loops(s: &Surface) -> Option<Vec<Vec<u32>>> {
    let mut count: HashMap<[u32; 2], u32> = HashMap::new();
    for t in &s.triangles {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            *count.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    if count.values().any(|&n| n > 2) {
        return None;
    }
    let mut next: HashMap<u32, Vec<u32>> = HashMap::new();
    for (e, &n) in &count {
        if n == 1 {
            next.entry(e[0]).or_default().push(e[1]);
            next.entry(e[1]).or_default().push(e[0]);
        }
    }
    if next.values().any(|v| v.len() != 2) {
        return None;
    }
    let mut starts: Vec<u32> = next.keys().copied().collect();
    starts.sort_unstable();
    let mut seen: HashSet<u32> = HashSet::new();
    let mut loops = Vec::new();
    for s0 in starts {
        if seen.contains(&s0) {
            continue;
        }
        let mut lp = vec![s0];
        seen.insert(s0);
        let mut prev = s0;
        let mut cur = next[&s0][0];
        while cur != s0 {
            lp.push(cur);
            seen.insert(cur);
            let n = &next[&cur];
            let nxt = if n[0] == prev { n[1] } else { n[0] };
            prev = cur;
            cur = nxt;
        }
        loops.push(lp);
    }
    Some(loops)
}

/// The winding number of the closed surface `s` at `p` (signed crossings of the ray from p
/// along a fixed generic direction; exact tests; brute force over the triangles).
pub fn winding_number(s: &Surface, p: DVec3) -> i32 {
    let far = p + DVec3::new(0.3141, 0.5926, 0.7421).normalize() * (4.0 * s.diagonal());
    (0..s.triangles.len())
        .map(|k| {
            let t = s.corners(k);
            if segment_crosses_triangle(p, far, t) {
                // The ray leaves through the triangle's outer side: p is on its inner side.
                if orient3d(t[0], t[1], t[2], far) < 0.0 {
                    -1
                } else {
                    1
                }
            } else {
                0
            }
        })
        .sum()
}

// ---------------------------------------------------------------------------------------------
// Building blocks.

fn triangle_area(s: &Surface, t: usize) -> f64 {
    let [a, b, c] = s.corners(t);
    (b - a).cross(c - a).length() / 2.0
}

/// `s` restricted to the triangles `keep` accepts (`Surface::keep_triangles`).
fn keep_triangles(s: &Surface, keep: impl Fn(usize) -> bool) -> Surface {
    s.keep_triangles(keep)
}

/// For each triangle, the triangles sharing an edge with it.
fn edge_adjacency(s: &Surface) -> Vec<Vec<usize>> {
    let mut by_edge: HashMap<[u32; 2], Vec<usize>> = HashMap::new();
    for (k, t) in s.triangles.iter().enumerate() {
        for i in 0..3 {
            let (a, b) = (t[i], t[(i + 1) % 3]);
            by_edge.entry([a.min(b), a.max(b)]).or_default().push(k);
        }
    }
    let mut adj = vec![Vec::new(); s.triangles.len()];
    for ts in by_edge.values() {
        for &a in ts {
            for &b in ts {
                if a != b {
                    adj[a].push(b);
                }
            }
        }
    }
    adj
}

/// Area-weighted unit normal at vertex `v`.
fn vertex_normal(s: &Surface, v: u32) -> DVec3 {
    (0..s.triangles.len())
        .filter(|&t| s.triangles[t].contains(&v))
        .map(|t| {
            let [a, b, c] = s.corners(t);
            (b - a).cross(c - a)
        })
        .sum::<DVec3>()
        .normalize()
}

/// Distance along the unit direction `d` from `p` to triangle `t` (Moller-Trumbore), if the
/// ray meets it.
fn ray_hit(p: DVec3, d: DVec3, t: [DVec3; 3]) -> Option<f64> {
    let [a, b, c] = t;
    let (e1, e2) = (b - a, c - a);
    let h = d.cross(e2);
    let det = e1.dot(h);
    if det.abs() < 1e-300 {
        return None;
    }
    let s = p - a;
    let u = s.dot(h) / det;
    let q = s.cross(e1);
    let v = d.dot(q) / det;
    let dist = e2.dot(q) / det;
    (u >= 0.0 && v >= 0.0 && u + v <= 1.0 && dist > 0.0).then_some(dist)
}

/// The disk of triangles within `rings` rings of a vertex (those with a vertex fewer than
/// `rings` edges away): the first vertex in decreasing order along `dir` whose disk is a
/// topological disk (Euler characteristic 1) bounded by one simple loop of vertices exactly
/// `rings` edges away. Returns (centre, triangles, boundary loop).
fn ring_disk(s: &Surface, dir: DVec3, rings: u32) -> (u32, Vec<usize>, Vec<u32>) {
    let mut neighbours: Vec<Vec<u32>> = vec![Vec::new(); s.vertices.len()];
    for t in &s.triangles {
        for i in 0..3 {
            neighbours[t[i] as usize].push(t[(i + 1) % 3]);
        }
    }
    let mut order: Vec<u32> = (0..s.vertices.len() as u32).collect();
    order.sort_by(|&a, &b| {
        let (pa, pb) = (
            s.vertices[a as usize].dot(dir),
            s.vertices[b as usize].dot(dir),
        );
        pb.total_cmp(&pa).then(a.cmp(&b))
    });
    for &centre in &order {
        let mut dist: HashMap<u32, u32> = HashMap::from([(centre, 0)]);
        let mut queue = VecDeque::from([centre]);
        while let Some(v) = queue.pop_front() {
            let d = dist[&v];
            if d == rings {
                continue;
            }
            for &w in &neighbours[v as usize] {
                if let std::collections::hash_map::Entry::Vacant(e) = dist.entry(w) {
                    e.insert(d + 1);
                    queue.push_back(w);
                }
            }
        }
        let disk: Vec<usize> = (0..s.triangles.len())
            .filter(|&t| {
                s.triangles[t]
                    .iter()
                    .any(|v| dist.get(v).is_some_and(|&d| d < rings))
            })
            .collect();
        let sub = Surface {
            vertices: s.vertices.clone(),
            triangles: disk.iter().map(|&t| s.triangles[t]).collect(),
        };
        let (_, euler) = sub.topology();
        let Some(loops) = boundary_loops(&sub) else {
            continue;
        };
        if euler == 1 && loops.len() == 1 && loops[0].iter().all(|v| dist[v] == rings) {
            let lp = loops.into_iter().next().unwrap();
            return (centre, disk, lp);
        }
    }
    panic!("no vertex has a {rings}-ring disk");
}

/// Deterministic noise (xorshift64*).
struct XorShift(u64);

impl XorShift {
    fn next(&mut self) -> u64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        self.0.wrapping_mul(0x2545_f491_4f6c_dd1d)
    }
}
