//! The paper's second kind of input: an "almost good" mesh whose slivers are to be removed.
//!
//! The mesh becomes a PLC and is meshed again without a size bound, keeping all its vertices:
//! - Facets: the listed boundary triangles (with their markers, duplicates dropped), plus the
//!   faces the file leaves out that the result needs: faces of exactly one tet (the boundary
//!   of the tet set) and faces between tets of different region attributes (interfaces). Those
//!   get marker 0. Every listed triangle must be a face of a tet. Flat patches of triangles with
//!   one marker become polygons again where they can (see `merge_flat_patches`).
//! - Seeds: the facets cut the tets into pieces (tets joined through faces that are not
//!   facets). Each piece gets one region seed with its attribute, at a tet centroid checked to
//!   lie strictly inside that tet with exact predicates, so it is on no facet. Components of the
//!   new triangulation with no seed — volume holes (cavities) and, for a non-convex mesh, the
//!   outside — are removed (`Unseeded::Hole`). So tets of the result exist exactly where the
//!   input had tets, and an attribute whose tets form several pieces keeps all of them.

use super::mark::Unseeded;
use super::mesh_domain;
use crate::geom::orient3d;
use crate::mesh::TetMesh;
use crate::plc::{Facet, PlcInput, Region};
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::Report;
use crate::run::spacing::ConstantSpacing;
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// Removes the slivers (and radius-edge-bad tets) of an existing mesh, keeping its boundary
/// and interface triangles (as facets with their markers), its holes and its region attributes.
pub fn remove_slivers(existing: &TetMesh, params: &Params) -> Result<(TetMesh, Report), MeshError> {
    let input = plc_of_mesh(existing)?;
    let (lo, hi) = existing.vertices.iter().fold(
        (DVec3::splat(f64::MAX), DVec3::splat(f64::MIN)),
        |(l, h), &p| (l.min(p), h.max(p)),
    );
    // No size bound: a spacing far above the domain's size.
    let unbounded = ConstantSpacing(1e3 * (hi - lo).length().max(1e-300));
    // The angles between boundary triangles are not input features: shape bounds are
    // enforced everywhere (the vertex budget still bounds the work).
    let choices = super::Choices {
        small_angles: super::SmallAngles::None,
        unseeded: Unseeded::Hole,
        ..super::Choices::plc()
    };
    mesh_domain(&input, params, Some(&unbounded), None, choices)
}

fn invalid(msg: String) -> MeshError {
    MeshError::InvalidInput(msg)
}

fn sorted3(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// The faces of tet `t` (any orientation).
fn faces(t: [u32; 4]) -> [[u32; 3]; 4] {
    [
        [t[1], t[2], t[3]],
        [t[0], t[2], t[3]],
        [t[0], t[1], t[3]],
        [t[0], t[1], t[2]],
    ]
}

/// The tets (at most two) sharing a face.
#[derive(Clone, Copy)]
struct FaceTets {
    first: u32,
    second: Option<u32>,
}

fn check_consistent(m: &TetMesh) -> Result<(), MeshError> {
    if m.tet_regions.len() != m.tets.len() || m.boundary_markers.len() != m.boundary.len() {
        return Err(invalid(format!(
            "{} tets with {} region attributes, {} boundary triangles with {} markers",
            m.tets.len(),
            m.tet_regions.len(),
            m.boundary.len(),
            m.boundary_markers.len()
        )));
    }
    if m.tets.is_empty() {
        return Err(invalid("the mesh has no tetrahedra".into()));
    }
    let nv = m.vertices.len();
    if u32::try_from(nv).is_err() {
        return Err(invalid(format!("{nv} vertices exceed the 32-bit id range")));
    }
    let bad = |v: &[u32]| {
        v.iter().any(|&i| i as usize >= nv) || (1..v.len()).any(|k| v[..k].contains(&v[k]))
    };
    if let Some((i, t)) = m.tets.iter().enumerate().find(|(_, t)| bad(&t[..])) {
        return Err(invalid(format!(
            "tetrahedron {i} {t:?} repeats a vertex or refers to one beyond the {nv} vertices"
        )));
    }
    if let Some((i, t)) = m.boundary.iter().enumerate().find(|(_, t)| bad(&t[..])) {
        return Err(invalid(format!(
            "boundary triangle {i} {t:?} repeats a vertex or refers to one beyond the {nv} \
             vertices"
        )));
    }
    Ok(())
}

fn plc_of_mesh(m: &TetMesh) -> Result<PlcInput, MeshError> {
    plc_of_mesh_except(m, &|_| false)
}

/// The PLC of a tet set as [`remove_slivers`] builds it, except that the faces of one tet for
/// which `left_open` (of the sorted vertex triple) holds are no facets: the caller closes the
/// surface there with facets of its own (a partition's refined interface).
pub(crate) fn plc_of_mesh_except(
    m: &TetMesh,
    left_open: &dyn Fn(&[u32; 3]) -> bool,
) -> Result<PlcInput, MeshError> {
    check_consistent(m)?;
    // Sorted face -> the tets sharing it.
    let mut face_tets: FxHashMap<[u32; 3], FaceTets> = FxHashMap::default();
    face_tets.reserve(2 * m.tets.len() + m.boundary.len());
    for (i, &t) in m.tets.iter().enumerate() {
        for f in faces(t) {
            let i = i as u32;
            let e = face_tets.entry(sorted3(f)).or_insert(FaceTets {
                first: i,
                second: None,
            });
            if e.first != i {
                if e.second.is_some() {
                    return Err(invalid(format!(
                        "face {f:?} is shared by more than two tetrahedra"
                    )));
                }
                e.second = Some(i);
            }
        }
    }

    // Facet triangles: listed ones first (file order, first marker of a duplicate wins), then
    // the missing boundary and interface faces in tet order.
    let mut is_facet: FxHashSet<[u32; 3]> = FxHashSet::default();
    let mut open_edges: FxHashSet<(u32, u32)> = FxHashSet::default();
    let mut triangles: Vec<([u32; 3], i32)> = vec![];
    for (k, (&t, &marker)) in m.boundary.iter().zip(&m.boundary_markers).enumerate() {
        let key = sorted3(t);
        if !face_tets.contains_key(&key) {
            return Err(invalid(format!(
                "boundary triangle {k} {t:?} is not a face of any tetrahedron"
            )));
        }
        if is_facet.insert(key) {
            triangles.push((t, marker));
        }
    }
    for &t in &m.tets {
        for f in faces(t) {
            let key = sorted3(f);
            let ft = face_tets[&key];
            let open = ft.second.is_none() && left_open(&key);
            if open {
                for k in 0..3 {
                    let (u, v) = (key[k], key[(k + 1) % 3]);
                    open_edges.insert((u.min(v), u.max(v)));
                }
            }
            let needed = match ft.second {
                None => !open,
                Some(s) => m.tet_regions[ft.first as usize] != m.tet_regions[s as usize],
            };
            if needed && is_facet.insert(key) {
                triangles.push((f, 0));
            }
        }
    }

    let regions = region_seeds(m, &face_tets, &is_facet);
    let facets = merge_flat_patches(&m.vertices, triangles, &open_edges);
    Ok(PlcInput {
        vertices: m.vertices.clone(),
        facets,
        holes: vec![],
        regions,
    })
}

/// One region seed per piece of the tet set cut by the facets (tets joined through faces that
/// are not facets): the centroid of its first tet that strictly contains its own (rounded)
/// centroid, by exact orientation tests. A piece of flat tets only gets no seed.
fn region_seeds(
    m: &TetMesh,
    face_tets: &FxHashMap<[u32; 3], FaceTets>,
    is_facet: &FxHashSet<[u32; 3]>,
) -> Vec<Region> {
    let mut uf = UnionFind::new(m.tets.len());
    for (key, ft) in face_tets {
        if let Some(s) = ft.second {
            if !is_facet.contains(key) {
                uf.union(ft.first, s);
            }
        }
    }
    let mut seeded = vec![false; m.tets.len()];
    let mut regions = vec![];
    for (i, (&t, &attribute)) in m.tets.iter().zip(&m.tet_regions).enumerate() {
        let root = uf.find(i as u32) as usize;
        if seeded[root] {
            continue;
        }
        let p = t.map(|v| m.vertices[v as usize]);
        let c = p.iter().sum::<DVec3>() / 4.0;
        if strictly_inside(p, c) {
            seeded[root] = true;
            regions.push(Region {
                point: c,
                attribute,
                max_size: None,
            });
        }
    }
    regions
}

/// Whether `x` lies strictly inside the (either way oriented) tet `p`: exact.
fn strictly_inside(p: [DVec3; 4], x: DVec3) -> bool {
    let s = orient3d(p[0], p[1], p[2], p[3]);
    if s == 0.0 {
        return false;
    }
    (0..4).all(|k| {
        let mut q = p;
        q[k] = x;
        orient3d(q[0], q[1], q[2], q[3]) * s > 0.0
    })
}

/// Facets from the triangles: each flat patch (triangles with one marker joined through edges
/// that exactly two facet triangles share, exactly coplanar) goes through
/// [`crate::plc::coplanar::merge_coplanar_facets`] on its own, so markers are kept and no
/// merge crosses a marker change or an edge where a third facet (an interface) meets. A patch
/// whose own triangles share an edge another facet also uses (an interface ending inside a
/// flat side) is left as triangles: merging would drop that edge.
///
/// `other_edges`: edges of facets the caller adds (they count as a third user).
fn merge_flat_patches(
    vertices: &[DVec3],
    mut triangles: Vec<([u32; 3], i32)>,
    other_edges: &FxHashSet<(u32, u32)>,
) -> Vec<Facet> {
    orient_by_largest_normal_component(vertices, &mut triangles);
    let mut edge_users: FxHashMap<(u32, u32), Vec<u32>> = FxHashMap::default();
    for &e in other_edges {
        edge_users.entry(e).or_default().push(u32::MAX);
    }
    for (i, (t, _)) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (u, v) = (t[k], t[(k + 1) % 3]);
            edge_users
                .entry((u.min(v), u.max(v)))
                .or_default()
                .push(i as u32);
        }
    }
    let mut facets = Vec::with_capacity(triangles.len());
    for patch in flat_patches(vertices, &triangles, &edge_users) {
        let marker = triangles[patch[0] as usize].1;
        // An edge two triangles of the patch share but a third facet also uses.
        let crossed = || {
            let mut seen: FxHashMap<(u32, u32), usize> = FxHashMap::default();
            patch.iter().any(|&i| {
                let t = triangles[i as usize].0;
                (0..3).any(|k| {
                    let (u, v) = (t[k], t[(k + 1) % 3]);
                    let key = (u.min(v), u.max(v));
                    let n = seen.entry(key).or_insert(0);
                    *n += 1;
                    *n == 2 && edge_users[&key].len() > 2
                })
            })
        };
        if patch.len() == 1 || crossed() {
            facets.extend(patch.iter().map(|&i| Facet {
                polygons: vec![triangles[i as usize].0.to_vec()],
                marker,
                ..Default::default()
            }));
        } else {
            facets.extend(merge_patch(vertices, &triangles, &patch, marker));
        }
    }
    facets
}

/// Gives coplanar triangles the same orientation (the merge needs it): their float normal's
/// largest component positive.
fn orient_by_largest_normal_component(vertices: &[DVec3], triangles: &mut [([u32; 3], i32)]) {
    for (t, _) in triangles {
        let [a, b, c] = t.map(|v| vertices[v as usize]);
        let n = (b - a).cross(c - a);
        let m = n.abs();
        let k = if m.x >= m.y && m.x >= m.z {
            0
        } else if m.y >= m.z {
            1
        } else {
            2
        };
        if n[k] < 0.0 {
            t.swap(1, 2);
        }
    }
}

/// The flat patches: triangles with one marker joined through edges that exactly two
/// triangles share, exactly coplanar. Each patch lists its triangles in index order, patches
/// in the order of their root (the union-find's) first seen.
fn flat_patches(
    vertices: &[DVec3],
    triangles: &[([u32; 3], i32)],
    edge_users: &FxHashMap<(u32, u32), Vec<u32>>,
) -> Vec<Vec<u32>> {
    let mut uf = UnionFind::new(triangles.len());
    for users in edge_users.values() {
        if let &[f, g] = &users[..] {
            if f == u32::MAX || g == u32::MAX {
                continue; // an edge of a facet the caller adds
            }
            let ((tf, mf), (tg, mg)) = (triangles[f as usize], triangles[g as usize]);
            let [a, b, c] = tf.map(|v| vertices[v as usize]);
            let coplanar = tg
                .iter()
                .all(|&v| orient3d(a, b, c, vertices[v as usize]) == 0.0);
            if mf == mg && coplanar {
                uf.union(f, g);
            }
        }
    }
    let mut patches: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    let mut order = vec![];
    for i in 0..triangles.len() as u32 {
        let root = uf.find(i);
        patches
            .entry(root)
            .or_insert_with(|| {
                order.push(root);
                vec![]
            })
            .push(i);
    }
    order
        .into_iter()
        .map(|root| patches.remove(&root).unwrap_or_default())
        .collect()
}

/// One flat patch as a PLC of its own (local vertex ids), merged into polygons, mapped back.
fn merge_patch(
    vertices: &[DVec3],
    triangles: &[([u32; 3], i32)],
    patch: &[u32],
    marker: i32,
) -> Vec<Facet> {
    let mut local: FxHashMap<u32, u32> = FxHashMap::default();
    let mut global = vec![];
    let mut sub = PlcInput::default();
    for &i in patch {
        let t = triangles[i as usize].0.map(|v| {
            *local.entry(v).or_insert_with(|| {
                global.push(v);
                sub.vertices.push(vertices[v as usize]);
                global.len() as u32 - 1
            })
        });
        sub.facets.push(Facet {
            polygons: vec![t.to_vec()],
            ..Default::default()
        });
    }
    crate::plc::coplanar::merge_coplanar_facets(&mut sub);
    let to_global = |p: Vec<u32>| p.into_iter().map(|v| global[v as usize]).collect();
    sub.facets
        .into_iter()
        .map(|f| Facet {
            polygons: f.polygons.into_iter().map(to_global).collect(),
            hole_polygons: f.hole_polygons.into_iter().map(to_global).collect(),
            hole_points: f.hole_points,
            marker,
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The unit square in z = 0.
    fn square() -> Vec<DVec3> {
        vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
        ]
    }

    #[test]
    fn flat_patch_with_one_marker_is_merged_keeping_it() {
        // (0,3,2) is the other orientation: reoriented before merging.
        let f = merge_flat_patches(
            &square(),
            vec![([0, 1, 2], 5), ([0, 3, 2], 5)],
            &FxHashSet::default(),
        );
        assert_eq!(f.len(), 1);
        assert_eq!(f[0].polygons[0].len(), 4);
        assert_eq!(f[0].marker, 5);
    }

    #[test]
    fn marker_change_is_not_merged() {
        let f = merge_flat_patches(
            &square(),
            vec![([0, 1, 2], 5), ([0, 2, 3], 6)],
            &FxHashSet::default(),
        );
        let markers: Vec<i32> = f.iter().map(|f| f.marker).collect();
        assert_eq!(markers, vec![5, 6]);
    }

    /// A flat ring: the 3x3 grid of unit squares in z = 0 without its centre, two triangles per
    /// square (vertex j * 4 + i at (i, j)), marker 5.
    fn ring() -> (Vec<DVec3>, Vec<([u32; 3], i32)>) {
        let mut v = vec![];
        for j in 0..4 {
            for i in 0..4 {
                v.push(DVec3::new(i as f64, j as f64, 0.0));
            }
        }
        let mut t = vec![];
        for j in 0..3u32 {
            for i in 0..3u32 {
                if (i, j) != (1, 1) {
                    let a = j * 4 + i;
                    t.push(([a, a + 1, a + 5], 5));
                    t.push(([a, a + 5, a + 4], 5));
                }
            }
        }
        (v, t)
    }

    #[test]
    fn fin_across_a_flat_ring_is_not_merged_away() {
        let (mut v, mut t) = ring();
        assert_eq!(
            merge_flat_patches(&v, t.clone(), &FxHashSet::default()).len(),
            1
        );
        // A fin on edge (1, 5), from the outer to the inner boundary: the ring is still one
        // patch, but merging it would drop that edge. It stays as triangles.
        v.push(DVec3::new(1.0, 0.5, 1.0));
        t.push(([1, 5, 16], 7));
        let f = merge_flat_patches(&v, t, &FxHashSet::default());
        assert_eq!(f.len(), 17);
        assert!(f.iter().all(|f| f.polygons[0].len() == 3));
    }

    #[test]
    fn seed_strictly_inside() {
        let p = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z];
        assert!(strictly_inside(p, DVec3::splat(0.25)));
        assert!(strictly_inside(
            [p[1], p[0], p[2], p[3]],
            DVec3::splat(0.25)
        ));
        assert!(!strictly_inside(p, DVec3::new(0.25, 0.25, 0.0)));
        let flat = [DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::new(1.0, 1.0, 0.0)];
        assert!(!strictly_inside(flat, DVec3::new(0.5, 0.5, 0.0)));
    }
}
