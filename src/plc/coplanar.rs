//! Merging edge-adjacent, exactly coplanar facets of a surface (.off/.stl) into polygon facets.
//!
//! Two facets are merged when they share an edge used by exactly those two facets, traversed in
//! opposite directions (a consistently oriented surface), every vertex of one lies exactly on
//! the plane of the other (`geom::orient3d == 0`, exact) and their normals point the same way.
//! Merging is transitive, so each group is a connected, flat, edge-connected patch.
//!
//! Each group's boundary is computed by cancelling its interior edges (an edge used in both
//! directions inside the group). The boundary edges are chained into loops: the loop whose
//! signed area along the group normal is positive becomes the facet's polygon, the others
//! (clockwise: inner boundaries) become `hole_polygons`, in the order they were traced.
//! Collinear intermediate vertices are kept: they are PLC vertices anyway. A vertex inside the
//! group (on no boundary loop) becomes a lone point of the merged facet (a one-vertex polygon):
//! the facet's triangulation keeps it as a vertex, with no segment attached to it.
//!
//! A group is left unmerged (its facets are kept as they were) when its boundary is not a set of
//! simple loops: a vertex with two outgoing boundary edges (patches touching at a vertex), or
//! not exactly one outer loop. Facets with several polygons, with holes, or that are not planar
//! or are degenerate (all vertices collinear) are never merged.
//!
//! Markers: every resulting facet gets marker = its 1-based index in the new facet list; facets
//! keep the order of their first member, so the numbering is deterministic.

use crate::geom::orient3d;
use crate::plc::{Facet, PlcInput};
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// Merges coplanar neighbouring facets of `plc` in place (see the module doc) and renumbers
/// all facet markers 1, 2, ... in facet order.
pub fn merge_coplanar_facets(plc: &mut PlcInput) {
    let verts = &plc.vertices;
    let mut facets = std::mem::take(&mut plc.facets);
    let planes: Vec<Option<Plane>> = facets.iter().map(|f| Plane::of(f, verts)).collect();

    // (undirected edge, facet, forward) of every polygon side, sorted: the two uses of an
    // edge are adjacent. Packed into one integer in that order (sorts 2-3x faster than the
    // tuple).
    let mut uses: Vec<u128> = Vec::new();
    for (fi, f) in facets.iter().enumerate() {
        if planes[fi].is_none() {
            continue;
        }
        let p = &f.polygons[0];
        for i in 0..p.len() {
            let (u, v) = (p[i], p[(i + 1) % p.len()]);
            let edge = (u128::from(u.min(v)) << 32) | u128::from(u.max(v));
            uses.push((edge << 64) | ((fi as u128) << 1) | u128::from(u < v));
        }
    }
    uses.sort_unstable();
    let unpack = |x: u128| (((x as u64) >> 1) as usize, x & 1 == 1);

    let mut uf = UnionFind::new(facets.len());
    for run in uses.chunk_by(|x, y| x >> 64 == y >> 64) {
        let &[a, b] = run else {
            continue;
        };
        let ((f, df), (g, dg)) = (unpack(a), unpack(b));
        if f == g || df == dg || uf.find(f as u32) == uf.find(g as u32) {
            continue;
        }
        let (pf, pg) = match (&planes[f], &planes[g]) {
            (Some(a), Some(b)) => (a, b),
            _ => continue,
        };
        if pf.normal.dot(pg.normal) <= 0.0 {
            continue;
        }
        let coplanar = facets[g].polygons[0]
            .iter()
            .all(|&v| pf.contains(verts[v as usize]));
        if coplanar {
            uf.union(f as u32, g as u32);
        }
    }

    // Groups in order of their first facet.
    let mut group_of_root: FxHashMap<usize, usize> = FxHashMap::default();
    let mut groups: Vec<Vec<usize>> = Vec::new();
    for fi in 0..facets.len() {
        let r = uf.find(fi as u32) as usize;
        let gi = *group_of_root.entry(r).or_insert_with(|| {
            groups.push(Vec::new());
            groups.len() - 1
        });
        groups[gi].push(fi);
    }

    let mut out: Vec<Facet> = Vec::with_capacity(groups.len());
    for g in &groups {
        if g.len() > 1 {
            let normal = planes[g[0]].as_ref().map_or(DVec3::ZERO, |p| p.normal);
            if let Some(f) = merge_group(g, &facets, verts, normal) {
                out.push(f);
                continue;
            }
        }
        // Each facet is in one group: moved, not copied.
        out.extend(g.iter().map(|&fi| std::mem::take(&mut facets[fi])));
    }
    for (i, f) in out.iter_mut().enumerate() {
        f.marker = i32::try_from(i + 1).unwrap_or(i32::MAX);
    }
    plc.facets = out;
}

/// The plane of a mergeable facet: three exactly non-collinear vertices and a float normal.
struct Plane {
    a: DVec3,
    b: DVec3,
    c: DVec3,
    normal: DVec3,
}

impl Plane {
    /// `None` unless the facet is a single planar, non-degenerate polygon without holes whose
    /// indices are all valid and distinct between neighbours.
    fn of(f: &Facet, verts: &[DVec3]) -> Option<Plane> {
        if f.polygons.len() != 1 || !f.hole_points.is_empty() || !f.hole_polygons.is_empty() {
            return None;
        }
        let p = &f.polygons[0];
        if p.len() < 3 || p.iter().any(|&v| v as usize >= verts.len()) {
            return None;
        }
        if (0..p.len()).any(|i| p[i] == p[(i + 1) % p.len()]) {
            return None;
        }
        let pts: Vec<DVec3> = p.iter().map(|&v| verts[v as usize]).collect();
        let a = pts[0];
        let b = *pts.iter().find(|&&q| q != a)?;
        // a and b themselves are collinear with a and b: testing them would take the exact
        // predicate's slow path (a zero determinant is never clear to the fast filter).
        let c = *pts
            .iter()
            .find(|&&q| q != a && q != b && !collinear(a, b, q))?;
        let plane = Plane {
            a,
            b,
            c,
            normal: newell(&pts),
        };
        if plane.normal == DVec3::ZERO || !pts.iter().all(|&q| plane.contains(q)) {
            return None;
        }
        Some(plane)
    }

    /// Exactly: q lies in the plane.
    fn contains(&self, q: DVec3) -> bool {
        // The three points spanning the plane lie in it: testing them would only send the exact
        // predicate down its slow path (a zero determinant is never clear to the fast filter).
        // Neighbouring triangles share two of them, so this is most of the tests in the merge.
        let spanning = q == self.a || q == self.b || q == self.c;
        spanning || orient3d(self.a, self.b, self.c, q) == 0.0
    }
}

/// Exact collinearity: a, b, c are collinear iff the plane through them (if any) holds four
/// affinely independent points, i.e. orient3d vanishes for every one of them.
fn collinear(a: DVec3, b: DVec3, c: DVec3) -> bool {
    [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z]
        .iter()
        .all(|&d| orient3d(a, b, c, d) == 0.0)
}

/// Newell's polygon normal (twice the vector area), in floating point.
fn newell(pts: &[DVec3]) -> DVec3 {
    let mut n = DVec3::ZERO;
    for i in 0..pts.len() {
        let (p, q) = (pts[i], pts[(i + 1) % pts.len()]);
        n += DVec3::new(
            (p.y - q.y) * (p.z + q.z),
            (p.z - q.z) * (p.x + q.x),
            (p.x - q.x) * (p.y + q.y),
        );
    }
    n
}

/// The merged facet of a group, or `None` when its boundary is not a set of simple loops with
/// exactly one outer loop.
fn merge_group(group: &[usize], facets: &[Facet], verts: &[DVec3], normal: DVec3) -> Option<Facet> {
    let directed = || {
        group.iter().flat_map(|&fi| {
            let p = &facets[fi].polygons[0];
            (0..p.len()).map(move |i| (p[i], p[(i + 1) % p.len()]))
        })
    };
    // Net count of each directed edge after cancelling opposite pairs.
    let mut count: FxHashMap<(u32, u32), i64> = FxHashMap::default();
    for (u, v) in directed() {
        match count.get_mut(&(v, u)) {
            Some(c) if *c > 0 => *c -= 1,
            _ => *count.entry((u, v)).or_insert(0) += 1,
        }
    }
    let mut boundary: Vec<(u32, u32)> = Vec::new();
    for (u, v) in directed() {
        if let Some(c) = count.get_mut(&(u, v)) {
            if *c > 0 {
                *c -= 1;
                boundary.push((u, v));
            }
        }
    }
    let mut next: FxHashMap<u32, u32> = FxHashMap::default();
    for &(u, v) in &boundary {
        if next.insert(u, v).is_some() {
            return None; // two outgoing boundary edges: patches touch at a vertex
        }
    }
    let mut used: FxHashMap<u32, bool> = FxHashMap::default();
    let mut outer: Option<Vec<u32>> = None;
    let mut holes = Vec::new();
    for &(start, _) in &boundary {
        if used.contains_key(&start) {
            continue;
        }
        let mut lp = vec![start];
        used.insert(start, true);
        let mut cur = *next.get(&start)?;
        while cur != start {
            if used.insert(cur, true).is_some() || lp.len() > boundary.len() {
                return None;
            }
            lp.push(cur);
            cur = *next.get(&cur)?;
        }
        if lp.len() < 3 {
            return None;
        }
        let pts: Vec<DVec3> = lp.iter().map(|&v| verts[v as usize]).collect();
        if newell(&pts).dot(normal) > 0.0 {
            if outer.is_some() {
                return None;
            }
            outer = Some(lp);
        } else {
            holes.push(lp);
        }
    }
    // A vertex inside the patch (on no boundary loop) stays a vertex of the facet as a lone
    // point (a one-vertex polygon), in order of first use.
    let mut polygons = vec![outer?];
    for &v in group.iter().flat_map(|&fi| facets[fi].polygons[0].iter()) {
        if used.insert(v, true).is_none() {
            polygons.push(vec![v]);
        }
    }
    Some(Facet {
        polygons,
        hole_points: Vec::new(),
        hole_polygons: holes,
        marker: 0,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tri(a: u32, b: u32, c: u32) -> Facet {
        Facet {
            polygons: vec![vec![a, b, c]],
            marker: 9,
            ..Facet::default()
        }
    }

    /// A 3x3 grid of unit squares in z = 0, each split into two CCW triangles.
    fn grid(skip_centre: bool) -> PlcInput {
        let mut plc = PlcInput::default();
        for j in 0..4 {
            for i in 0..4 {
                plc.vertices.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        for j in 0..3u32 {
            for i in 0..3u32 {
                if skip_centre && i == 1 && j == 1 {
                    continue;
                }
                let v = j * 4 + i;
                plc.facets.push(tri(v, v + 1, v + 5));
                plc.facets.push(tri(v, v + 5, v + 4));
            }
        }
        plc
    }

    #[test]
    fn flat_grid_keeps_its_interior_vertices_as_lone_points() {
        // One facet: the 12 boundary vertices in a loop, the 4 interior ones as lone points,
        // which the checked facet's triangulation uses (18 triangles, no segment at them).
        let mut plc = grid(false);
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 1);
        let f = &plc.facets[0];
        assert_eq!(f.polygons[0].len(), 12);
        let mut lone: Vec<u32> = f.polygons[1..].iter().map(|p| p[0]).collect();
        lone.sort_unstable();
        assert_eq!(lone, vec![5, 6, 9, 10]);
        assert!(f.polygons[1..].iter().all(|p| p.len() == 1));
        let checked = crate::plc::check_facet(0, f, &plc.vertices).unwrap();
        assert_eq!(checked.triangles.len(), 18);
        assert!(checked
            .segments()
            .all(|s| !lone.contains(&s[0]) && !lone.contains(&s[1])));
    }

    #[test]
    fn ring_gets_a_hole_polygon() {
        let mut plc = grid(true);
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 1);
        let f = &plc.facets[0];
        assert_eq!(f.polygons[0].len(), 12);
        assert_eq!(f.hole_polygons.len(), 1);
        let mut hole = f.hole_polygons[0].clone();
        hole.sort_unstable();
        assert_eq!(hole, vec![5, 6, 9, 10]);
    }

    #[test]
    fn bent_or_flipped_neighbours_are_not_merged() {
        let mut plc = PlcInput {
            vertices: vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(1.0, -1.0, 1e-300),
                DVec3::new(0.5, 0.5, 0.0),
            ],
            facets: vec![tri(0, 1, 2), tri(1, 0, 3)],
            ..PlcInput::default()
        };
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 2, "1e-300 off the plane is not coplanar");
        assert_eq!(plc.facets[1].marker, 2);
        // Same edge direction (inconsistent orientation): not merged.
        plc.vertices[3].z = 0.0;
        plc.facets = vec![tri(0, 1, 2), tri(0, 1, 3)];
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 2);
        // Degenerate (collinear) facet is never merged.
        plc.facets = vec![tri(0, 1, 2), tri(1, 0, 4), tri(0, 1, 3)];
        plc.vertices[4] = DVec3::new(2.0, 0.0, 0.0);
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 3);
    }

    #[test]
    fn patch_touching_itself_at_a_vertex_is_left_alone() {
        // The grid without its centre and its first corner square: the hole and the notch
        // touch at vertex 5, which then has two outgoing boundary edges.
        let mut plc = grid(true);
        plc.facets.drain(0..2);
        assert_eq!(plc.facets.len(), 14);
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 14);
        assert_eq!(plc.facets[13].marker, 14);
    }

    #[test]
    fn bad_indices_do_not_panic() {
        let mut plc = PlcInput {
            vertices: vec![DVec3::ZERO, DVec3::X, DVec3::Y],
            facets: vec![tri(0, 1, 7), tri(0, 0, 1), Facet::default()],
            ..PlcInput::default()
        };
        merge_coplanar_facets(&mut plc);
        assert_eq!(plc.facets.len(), 3);
    }
}
