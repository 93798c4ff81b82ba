//! Moving the interfaces (the scheme's step 5). The worst tets of a part are next to its
//! frozen interface triangles: refinement refuses the points that would encroach them, and
//! the improver may not move their vertices nor flip them. So after every part is meshed, the
//! zone around each interface (the tets of both parts within [`ZONE_LAYERS`] vertex layers of
//! it) is cut out of the parts, glued, and improved again with the old interface free inside
//! it and the zone's outer faces fixed: those are faces of the parts' tets away from the
//! interface, which met the serial run's bounds. In effect the interface moves to the zone's
//! outer faces, where the mesh is already good.
//!
//! Each connected piece of the glued zone goes to the lowest part among its tets' parts, so
//! every piece has one owner and the result is the same whichever rank computes it.

use super::MeshedPart;
use crate::mesh::{tet_face as face, TetMesh};
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::ImproveStats;
use crate::union_find::UnionFind;
use rustc_hash::{FxHashMap, FxHashSet};

/// Vertex layers of tets on each side of an interface that are improved again: one, the tets
/// with a vertex on the interface. (Measured on the cube at size 0.03 in 3 parts: 26.00
/// degrees with one layer or two, the serial run's; two moved 16% more tets to the lowest
/// part.)
pub const ZONE_LAYERS: usize = 1;

/// Marker of the zone's outer faces while it is improved (fixed, then left out).
const ZONE_MARKER: i32 = i32::MIN + 2;

/// A part's mesh cut in two.
pub struct Cut {
    /// The tets away from the part's interfaces.
    pub rest: TetMesh,
    /// The tets within [`ZONE_LAYERS`] of them.
    pub zone: TetMesh,
}

fn key(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// The faces of one tet of `mesh` that are not boundary triangles, each as its tet's face.
fn open_faces(mesh: &TetMesh) -> Vec<[u32; 3]> {
    let counts = mesh.face_counts();
    let boundary: FxHashSet<[u32; 3]> = mesh.boundary.iter().map(|&b| key(b)).collect();
    let mut out = vec![];
    for t in &mesh.tets {
        for skip in 0..4 {
            let f = face(t, skip);
            let k = key(f);
            if counts[&k] == 1 && !boundary.contains(&k) {
                out.push(f);
            }
        }
    }
    out
}

/// The tets of `mesh` where `keep` is true, with the vertices they use (numbered from 0 in
/// order) and the boundary triangles that are faces of them.
fn sub_mesh(mesh: &TetMesh, keep: &[bool]) -> TetMesh {
    let boundary_index: FxHashMap<[u32; 3], u32> = (mesh.boundary.iter().enumerate())
        .map(|(i, &b)| (key(b), i as u32))
        .collect();
    let mut boundary_kept = vec![false; mesh.boundary.len()];
    let mut id = vec![u32::MAX; mesh.vertices.len()];
    let mut out = TetMesh::default();
    for (t, tv) in mesh.tets.iter().enumerate() {
        if !keep[t] {
            continue;
        }
        let new = tv.map(|v| {
            if id[v as usize] == u32::MAX {
                id[v as usize] = out.vertices.len() as u32;
                out.vertices.push(mesh.vertices[v as usize]);
            }
            id[v as usize]
        });
        if !boundary_index.is_empty() {
            for skip in 0..4 {
                if let Some(&b) = boundary_index.get(&key(face(tv, skip))) {
                    boundary_kept[b as usize] = true;
                }
            }
        }
        out.tets.push(new);
        out.tet_regions.push(mesh.tet_regions[t]);
    }
    for ((b, &m), _) in (mesh.boundary.iter().zip(&mesh.boundary_markers))
        .zip(&boundary_kept)
        .filter(|(_, &kept)| kept)
    {
        out.boundary.push(b.map(|v| id[v as usize]));
        out.boundary_markers.push(m);
    }
    out
}

/// Cuts a part's mesh into its zone and the rest; `interface` holds its triangles on its
/// interfaces (`MeshedPart::interface`).
pub fn cut_zone(part: &TetMesh, interface: &[[u32; 3]]) -> Cut {
    let mut near = vec![false; part.vertices.len()];
    for f in interface {
        f.iter().for_each(|&v| near[v as usize] = true);
    }
    let mut in_zone = vec![false; part.tets.len()];
    for _ in 0..ZONE_LAYERS {
        for (t, tv) in part.tets.iter().enumerate() {
            in_zone[t] |= tv.iter().any(|&v| near[v as usize]);
        }
        for (t, tv) in part.tets.iter().enumerate() {
            if in_zone[t] {
                tv.iter().for_each(|&v| near[v as usize] = true);
            }
        }
    }
    let away: Vec<bool> = in_zone.iter().map(|&z| !z).collect();
    Cut {
        rest: sub_mesh(part, &away),
        zone: sub_mesh(part, &in_zone),
    }
}

/// `meshes` glued into one by their vertices' exact coordinates (vertices no tet uses are
/// left out; a boundary triangle given twice is kept once), and the index of the mesh each
/// tet came from.
pub fn glue(meshes: &[TetMesh]) -> (TetMesh, Vec<u32>) {
    let mut out = TetMesh::default();
    let mut source = vec![];
    let mut index: FxHashMap<[u64; 3], u32> = FxHashMap::default();
    let mut seen = FxHashSet::default();
    for (i, m) in meshes.iter().enumerate() {
        let mut id = vec![u32::MAX; m.vertices.len()];
        for (tv, &r) in m.tets.iter().zip(&m.tet_regions) {
            let new = tv.map(|v| {
                if id[v as usize] == u32::MAX {
                    let p = m.vertices[v as usize];
                    id[v as usize] =
                        *index
                            .entry(p.to_array().map(f64::to_bits))
                            .or_insert_with(|| {
                                out.vertices.push(p);
                                out.vertices.len() as u32 - 1
                            });
                }
                id[v as usize]
            });
            out.tets.push(new);
            out.tet_regions.push(r);
            source.push(i as u32);
        }
        for (b, &marker) in m.boundary.iter().zip(&m.boundary_markers) {
            if b.iter().any(|&v| id[v as usize] == u32::MAX) {
                continue;
            }
            let b = b.map(|v| id[v as usize]);
            if seen.insert(key(b)) {
                out.boundary.push(b);
                out.boundary_markers.push(marker);
            }
        }
    }
    (out, source)
}

/// The zones of all parts (`zones[p]` is part p's) glued and cut into connected pieces
/// (through faces), each given to the lowest part among its tets' parts: what each part
/// improves, one mesh per part (empty where a part owns no piece).
pub fn share_zones(zones: &[TetMesh]) -> Vec<TetMesh> {
    let (zone, source) = glue(zones);
    let mut pieces = UnionFind::new(zone.tets.len());
    let mut first: FxHashMap<[u32; 3], u32> = FxHashMap::default();
    for (t, tv) in zone.tets.iter().enumerate() {
        for skip in 0..4 {
            match first.entry(key(face(tv, skip))) {
                std::collections::hash_map::Entry::Occupied(o) => pieces.union(*o.get(), t as u32),
                std::collections::hash_map::Entry::Vacant(v) => {
                    v.insert(t as u32);
                }
            }
        }
    }
    let mut owner = vec![u32::MAX; zone.tets.len()];
    for (t, &from) in source.iter().enumerate() {
        let r = pieces.find(t as u32) as usize;
        owner[r] = owner[r].min(from);
    }
    let owner: Vec<u32> = (0..zone.tets.len())
        .map(|t| owner[pieces.find(t as u32) as usize])
        .collect();
    (0..zones.len() as u32)
        .map(|p| {
            let mine: Vec<bool> = owner.iter().map(|&o| o == p).collect();
            sub_mesh(&zone, &mine)
        })
        .collect()
}

/// Improves `zone` with its outer faces fixed (the vertices on them do not move, no flip
/// crosses them): only the tets inside change, and the vertices on the domain's facets slide
/// in them where a facet is flat around them, as in the parts' own improvement.
pub fn improve_zone(zone: TetMesh, params: &Params) -> Result<(TetMesh, ImproveStats), MeshError> {
    if zone.tets.is_empty() {
        return Ok((zone, ImproveStats::default()));
    }
    let outer = open_faces(&zone);
    // The improver fixes the vertices its input lists first: the outer faces' vertices.
    let mut first = vec![false; zone.vertices.len()];
    outer
        .iter()
        .flatten()
        .for_each(|&v| first[v as usize] = true);
    let mut order: Vec<u32> = (0..zone.vertices.len() as u32).collect();
    order.sort_by_key(|&v| !first[v as usize]);
    let mut id = vec![0; order.len()];
    for (new, &old) in order.iter().enumerate() {
        id[old as usize] = new as u32;
    }
    let renumber = |t: &[u32; 3]| t.map(|v| id[v as usize]);
    let mut mesh = TetMesh {
        vertices: order.iter().map(|&v| zone.vertices[v as usize]).collect(),
        tets: zone
            .tets
            .iter()
            .map(|t| t.map(|v| id[v as usize]))
            .collect(),
        tet_regions: zone.tet_regions,
        boundary: zone.boundary.iter().map(renumber).collect(),
        boundary_markers: zone.boundary_markers,
    };
    mesh.boundary.extend(outer.iter().map(renumber));
    mesh.boundary_markers
        .extend(std::iter::repeat_n(ZONE_MARKER, outer.len()));
    let fixed = crate::plc::PlcInput {
        vertices: mesh.vertices[..first.iter().filter(|&&f| f).count()].to_vec(),
        ..Default::default()
    };
    let (mut mesh, stats) = crate::improve::finish(mesh, Some(&fixed), params, None)?;
    mesh.remove_boundary_marker(ZONE_MARKER);
    Ok((mesh, stats))
}

/// The parts with their interfaces moved, in one process (`crate::distributed` does the
/// same with the zones exchanged between ranks): each part's zone cut out, the zones shared
/// out, improved, and glued to the rests.
pub fn move_interfaces(parts: &[MeshedPart], params: &Params) -> Result<Vec<TetMesh>, MeshError> {
    let cuts: Vec<Cut> = (parts.iter())
        .map(|p| cut_zone(&p.mesh, &p.interface))
        .collect();
    let zones: Vec<TetMesh> = cuts.iter().map(|c| c.zone.clone()).collect();
    let shares = share_zones(&zones);
    let mut out = vec![];
    for (cut, share) in cuts.into_iter().zip(shares) {
        let (improved, _) = improve_zone(share, params)?;
        out.push(glue(&[cut.rest, improved]).0);
    }
    Ok(out)
}
