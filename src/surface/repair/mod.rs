//! Dirty surfaces made meshable (`--repair`): open, self-intersecting, overlapping,
//! duplicated, inconsistently oriented. The solid is where the input's generalized winding
//! number is at least 1/2 (Jacobson, Kavan & Sorkine-Hornung 2013), which needs no repaired
//! surface at all: the surface mesher finds the solid's boundary along its Voronoi edges
//! through [`labels::SolidLabels`].
//!
//! What is done to the input first:
//! 1. one welded triangle soup (`soup`): polygons fanned, coincident vertices merged;
//! 2. orientation made consistent across manifold edges, the majority of each connected set
//!    deciding (`orient`), since w counts orientation and a few flipped triangles would
//!    otherwise each leave a dent of their own size;
//! 3. the holes' rims found as loops and closed by virtual fans (`holes`);
//! 4. every input triangle classified: part of the solid's boundary, or hidden (inside the
//!    solid, as an overlapping shell's inner half, or outside, as a fold's flap): only the
//!    boundary ones are the geometry the mesher approximates (samples, features, distances).

mod holes;
pub mod labels;
mod orient;
mod soup;

use super::oracle::{is_flat, SurfaceOracle};
use super::winding::WindingNumber;
use super::InputSurface;
use crate::plc::PlcInput;
use glam::DVec3;
use labels::SolidLabels;

/// Marks a triangle of the counting surface that is not part of the boundary surface.
pub const HIDDEN: u32 = u32::MAX;

/// What was wrong with the input, and what the repair made of it.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Defects {
    /// Triangles after fanning polygons and dropping degenerate ones.
    pub triangles: usize,
    /// Vertices that repeated an earlier vertex's coordinates (merged).
    pub duplicate_vertices: usize,
    /// Triangles with two corners at one point (dropped).
    pub degenerate_triangles: usize,
    /// Triangles turned to agree with their neighbours.
    pub flipped_triangles: usize,
    /// Edges of one triangle only (after merging vertices).
    pub open_edges: usize,
    /// Edges of more than two triangles.
    pub non_manifold_edges: usize,
    /// Pairs of triangles meeting in more than shared vertices and edges.
    pub intersecting_pairs: usize,
    /// Sets of triangles connected through edges.
    pub components: usize,
    /// Loops of unbalanced edges (holes, cracks) spanned by the solid's boundary.
    pub holes: usize,
    /// Input triangles on no part of the solid's boundary (inside or outside it).
    pub hidden_triangles: usize,
    /// What the output made of it: the area of its boundary, and of the part farther than
    /// the distance bound from the input (where it spans holes).
    pub boundary_area: f64,
    pub spanned_area: f64,
}

impl Defects {
    /// Whether anything needed repair.
    pub fn any(&self) -> bool {
        self.duplicate_vertices
            + self.degenerate_triangles
            + self.flipped_triangles
            + self.open_edges
            + self.non_manifold_edges
            + self.intersecting_pairs
            > 0
    }
}

/// A dirty input prepared for the surface mesher.
pub struct Repaired {
    /// The input triangles that bound the solid somewhere: what the mesher approximates.
    pub surface: InputSurface,
    /// Inside and outside, with the counting surface behind it (every input triangle, then
    /// the fans).
    pub labels: SolidLabels,
    /// Per triangle of the counting surface: its id in `surface`, or [`HIDDEN`].
    pub surface_id: Vec<u32>,
    pub defects: Defects,
    /// `SIDE_OFFSET` as a length.
    side_offset: f64,
    /// Pairs of `surface` triangles that intersect (other than at shared vertices and edges).
    clashing: Vec<[u32; 2]>,
}

/// Offset, as a share of the bounding-box diagonal, of the two points on either side of a
/// triangle whose labels say whether it bounds the solid.
const SIDE_OFFSET: f64 = 1e-7;

impl Repaired {
    /// The solid of a dirty `input`. Several regions (region seeds: solids of a multi-solid
    /// STL, closed OBJ groups) are refused: each would need its own winding number, and the
    /// faces two of them share are written once.
    pub fn new(input: &PlcInput) -> Result<Repaired, String> {
        if input.regions.len() > 1 {
            return Err(format!(
                "the input has {} regions (solids or materials); repair meshes one solid, so \
                 a dirty input with several is not handled yet",
                input.regions.len()
            ));
        }
        let s = soup::Soup::of(input)?;
        let mut triangles = s.triangles;
        let flipped_triangles = orient::orient_consistently(&mut triangles);
        let uses = orient::edge_uses(&triangles);
        let (open_edges, non_manifold_edges) = orient::open_and_non_manifold(&uses);
        let components = orient::components(triangles.len(), &uses);
        drop(uses);
        let n_input = triangles.len();
        let mut vertices = s.vertices;
        let flat: Vec<bool> = triangles
            .iter()
            .map(|t| is_flat(t.map(|v| vertices[v as usize])))
            .collect();
        let clashing = crate::plc::intersect::clashing_pairs(&vertices, &triangles, &flat);

        let mut holes = Vec::new();
        let mut fan_triangles = Vec::new();
        for rim in holes::rim_loops(&triangles) {
            let apex = vertices.len() as u32;
            let (hole, fan) = holes::fan(&vertices, &rim, apex);
            vertices.push(hole.centre);
            fan_triangles.extend(fan);
            holes.push(hole);
        }
        let fans = WindingNumber::new(&vertices, &fan_triangles);
        let mut all = InputSurface::from_triangles(vertices.clone(), triangles.clone());
        all.triangles.extend(&fan_triangles);
        let n_all = all.triangles.len();
        all.facet_of = s.facet_of.clone();
        all.facet_of.resize(n_all, u32::MAX);
        all.marker_of = s.marker_of.clone();
        all.marker_of.resize(n_all, 0);
        all.sides = vec![[0, 0]; n_all];
        let labels = SolidLabels::new(SurfaceOracle::counting(&all), fans, holes, n_input);

        let bounding = bounding_triangles(&all, n_input, &flat, &clashing, &labels);
        let mut surface = InputSurface {
            vertices,
            triangles: vec![],
            facet_of: vec![],
            marker_of: vec![],
            sides: vec![],
        };
        let mut surface_id = vec![HIDDEN; n_all];
        for t in (0..n_input).filter(|&t| bounding[t]) {
            surface_id[t] = surface.triangles.len() as u32;
            surface.triangles.push(triangles[t]);
            surface.facet_of.push(s.facet_of[t]);
            surface.marker_of.push(s.marker_of[t]);
            surface.sides.push([1, 0]);
        }
        if surface.triangles.is_empty() {
            return Err(
                "no triangle bounds a solid: the input's winding number is below 1/2 \
                 everywhere (is it a single open sheet?)"
                    .into(),
            );
        }
        let defects = Defects {
            triangles: n_input,
            duplicate_vertices: s.welded_vertices,
            degenerate_triangles: s.degenerate_triangles,
            flipped_triangles,
            open_edges,
            non_manifold_edges,
            intersecting_pairs: clashing.len(),
            components,
            holes: labels.n_holes(),
            hidden_triangles: n_input - surface.triangles.len(),
            ..Defects::default()
        };
        let clashing = clashing
            .iter()
            .map(|p| p.map(|t| surface_id[t as usize]))
            .filter(|p| !p.contains(&HIDDEN))
            .collect();
        Ok(Repaired {
            clashing,
            side_offset: SIDE_OFFSET * all.bbox_diagonal(),
            surface,
            labels,
            surface_id,
            defects,
        })
    }

    /// Makes patches that meet where triangles intersect one patch: the solid's boundary
    /// passes from one to the other there with no feature curve between them, so a facet
    /// across that crease has vertices on both (features and their patches are otherwise the
    /// input's).
    pub fn join_patches_across_intersections(&self, features: &mut super::features::Features) {
        let mut sets = crate::union_find::UnionFind::new(features.n_patches);
        for &[a, b] in &self.clashing {
            sets.union(features.patch_of[a as usize], features.patch_of[b as usize]);
        }
        let mut number = vec![u32::MAX; features.n_patches];
        let mut n = 0;
        for p in 0..features.n_patches as u32 {
            let root = sets.find(p) as usize;
            if number[root] == u32::MAX {
                number[root] = n;
                n += 1;
            }
        }
        for p in &mut features.patch_of {
            *p = number[sets.find(*p) as usize];
        }
        features.n_patches = n as usize;
    }

    /// Whether the input surface through `p` (normal `normal`) bounds the solid there: the
    /// labels just in front and just behind differ.
    pub fn bounds_solid_at(&self, p: DVec3, normal: DVec3) -> bool {
        bounds_at(&self.labels, p, normal * self.side_offset)
    }
}

impl Defects {
    /// The counts a clean input (one that passed validation) gets with `--repair`: merged
    /// vertices, flipped triangles, components; nothing intersects, nothing is open.
    pub fn of_clean(input: &PlcInput) -> Result<Defects, String> {
        let s = soup::Soup::of(input)?;
        let mut triangles = s.triangles;
        let flipped_triangles = orient::orient_consistently(&mut triangles);
        let uses = orient::edge_uses(&triangles);
        Ok(Defects {
            triangles: triangles.len(),
            duplicate_vertices: s.welded_vertices,
            degenerate_triangles: s.degenerate_triangles,
            flipped_triangles,
            components: orient::components(triangles.len(), &uses),
            ..Defects::default()
        })
    }
}

/// Whether the labels at p + offset and p - offset differ.
fn bounds_at(labels: &SolidLabels, p: DVec3, offset: DVec3) -> bool {
    let (front, back) = (p + offset, p - offset);
    labels.inside(labels.count(front), front) != labels.inside(labels.count(back), back)
}

/// Whether each input triangle bounds the solid somewhere: the labels just in front of and
/// just behind it differ. Along a set of triangles joined by manifold edges that no other
/// triangle crosses and no fan comes near, w on either side is one integer throughout, so
/// one triangle of the set answers for all; a triangle near a fan is judged at its centroid,
/// and one that another triangle cuts is kept.
fn bounding_triangles(
    all: &InputSurface,
    n_input: usize,
    flat: &[bool],
    clashing: &[[u32; 2]],
    labels: &SolidLabels,
) -> Vec<bool> {
    let offset = SIDE_OFFSET * all.bbox_diagonal();
    let mut cut = vec![false; n_input];
    for &[a, b] in clashing {
        cut[a as usize] = true;
        cut[b as usize] = true;
    }
    let near_fans: Vec<bool> = (0..n_input)
        .map(|t| {
            let [a, b, c] = all.corners(t);
            let (centre, r) = ((a + b + c) / 3.0, (a - b).length().max((c - b).length()));
            !labels.clear_of_fans(centre, r)
        })
        .collect();
    let alone = |t: usize| !cut[t] && !near_fans[t];
    let bounds_at = |t: usize, x: DVec3| bounds_at(labels, x, all.normal(t) * offset);
    let input_triangles = &all.triangles[..n_input];
    let mut sets = crate::union_find::UnionFind::new(n_input);
    for u in orient::edge_uses(input_triangles).values() {
        if let [(t, _), (v, _)] = u[..] {
            if alone(t as usize) && alone(v as usize) {
                sets.union(t, v);
            }
        }
    }
    let mut answer_of_set: rustc_hash::FxHashMap<u32, bool> = Default::default();
    (0..n_input)
        .map(|t| {
            if flat[t] {
                return false;
            }
            // A triangle cut by another may bound the solid along a sliver that no sample
            // meets: it is kept (samples taken on it are still checked one by one).
            if cut[t] {
                return true;
            }
            let centroid = all.corners(t).iter().sum::<DVec3>() / 3.0;
            if near_fans[t] {
                return bounds_at(t, centroid);
            }
            let root = sets.find(t as u32);
            *answer_of_set
                .entry(root)
                .or_insert_with(|| bounds_at(t, centroid))
        })
        .collect()
}

#[cfg(test)]
mod tests;
