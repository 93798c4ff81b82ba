//! Moving the interfaces (the scheme's step 5). The worst tets of a part are next to its
//! frozen interface triangles: refinement refuses the points that would encroach them, and
//! the improver may not move their vertices nor flip them. So after every part is meshed, the
//! zone around each interface (the tets of both parts within [`ZONE_LAYERS`] vertex layers of
//! it, and of the tets below the improvement target) is cut out of the parts, glued, and
//! improved again with the old interface free inside it and the zone's outer faces fixed:
//! those are faces of the parts' tets away from the interface, which met the serial run's
//! bounds. In effect the interface moves to the zone's outer faces, where the mesh is already
//! good; [`share_zones`] says which of them are the parts' new interfaces, and the next pass
//! starts from those ([`another_pass`] says whether one is due).
//!
//! Each connected piece of the glued zone goes to the lowest part among its tets' parts, so
//! every piece has one owner and the result is the same whichever rank computes it.

use super::MeshedPart;
use crate::mesh::{tet_face as face, TetMesh};
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::report::ImproveStats;
use crate::union_find::UnionFind;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// Vertex layers of tets on each side of an interface that are improved again: one, the tets
/// with a vertex on the interface. (Measured on the cube at size 0.03 in 3 parts: 26.00
/// degrees with one layer or two, the serial run's; two moved 16% more tets to the lowest
/// part.)
pub const ZONE_LAYERS: usize = 1;

/// Vertex layers more around a tet over rho0 at an interface: its circumcentre, which the
/// part's refinement refused next to the frozen interface and the zone's radius-edge repair
/// puts in, is about a circumradius (a spacing or two) away, and must be inside the zone.
pub const RHO_REACH_LAYERS: usize = 2;

/// Marker of the zone's outer faces while it is improved (held as they are, then left out).
const ZONE_MARKER: i32 = crate::improve::HELD_MARKER;

/// A part's mesh cut in two.
pub struct Cut {
    /// The tets away from the part's interfaces and bad tets.
    pub rest: TetMesh,
    /// The tets within [`ZONE_LAYERS`] of them.
    pub zone: TetMesh,
}

fn key(mut f: [u32; 3]) -> [u32; 3] {
    f.sort_unstable();
    f
}

/// A triangle by its corners' exact coordinates, sorted: how the parts name the interface
/// triangles they share (their vertex ids differ).
pub type Corners = [[u64; 3]; 3];

/// Triangle `tri`'s [`Corners`].
pub fn corners(tri: &[u32], vertices: &[DVec3]) -> Corners {
    let mut k = [0, 1, 2].map(|i| vertices[tri[i] as usize].to_array().map(f64::to_bits));
    k.sort_unstable();
    k
}

/// Why a part's tet seeds its zone ([`bad_tets`], [`cut_zone`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum Seed {
    #[default]
    No,
    /// Its smallest dihedral angle is below the improvement target.
    BelowTarget,
    /// Its radius-edge ratio is over rho0 (and its angles may be fine).
    OverRho,
}

/// The smallest dihedral angle of `mesh` (degrees; `f64::MAX` for no tet), whether a tet is
/// over radius-edge ratio `rho0`, and which of its tets seed the zone: below `target_deg`,
/// or over `rho0`.
pub fn bad_tets(mesh: &TetMesh, target_deg: f64, rho0: f64) -> (f64, bool, Vec<Seed>) {
    let measures: Vec<(f64, bool)> = crate::parallel::map_collect(&mesh.tets, |t| {
        let p = t.map(|v| mesh.vertices[v as usize]);
        let angle = crate::geom::measures::min_max_dihedral(p[0], p[1], p[2], p[3]).0;
        (
            angle,
            crate::geom::radius_edge_ratio(p[0], p[1], p[2], p[3]) > rho0,
        )
    });
    let worst = measures.iter().map(|m| m.0).fold(f64::MAX, f64::min);
    let over_rho = measures.iter().any(|m| m.1);
    let seeds = (measures.iter())
        .map(|&(angle, over)| match (over, angle < target_deg) {
            (true, _) => Seed::OverRho,
            (false, true) => Seed::BelowTarget,
            (false, false) => Seed::No,
        })
        .collect();
    (worst, over_rho, seeds)
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
/// order) and the boundary triangles that are faces of them; and which of `mesh`'s boundary
/// triangles those are.
fn sub_mesh(mesh: &TetMesh, keep: &[bool]) -> (TetMesh, Vec<bool>) {
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
    (out, boundary_kept)
}

/// Cuts a part's mesh into its zone and the rest. The zone grows [`ZONE_LAYERS`] from the
/// part's triangles on its interfaces (`interface`, vertex ids of `part`) and from its seed
/// tets, and [`RHO_REACH_LAYERS`] more from the seeds over rho0 that touch an interface. The
/// rest is `part` itself with the zone's tets taken out (no copy of the part).
pub fn cut_zone(part: TetMesh, interface: &[[u32; 3]], seeds: &[Seed]) -> Cut {
    let mut on_interface = vec![false; part.vertices.len()];
    interface
        .iter()
        .flatten()
        .for_each(|&v| on_interface[v as usize] = true);
    let mut near = on_interface.clone();
    let mut reach = vec![false; part.vertices.len()];
    for (tv, &seed) in part.tets.iter().zip(seeds) {
        if seed != Seed::No {
            tv.iter().for_each(|&v| near[v as usize] = true);
        }
        if seed == Seed::OverRho && tv.iter().any(|&v| on_interface[v as usize]) {
            tv.iter().for_each(|&v| reach[v as usize] = true);
        }
    }
    grow_layers(&part.tets, &mut reach, RHO_REACH_LAYERS);
    near.iter_mut().zip(&reach).for_each(|(n, &r)| *n |= r);
    grow_layers(&part.tets, &mut near, ZONE_LAYERS - 1);
    let in_zone: Vec<bool> = (part.tets.iter())
        .map(|tv| tv.iter().any(|&v| near[v as usize]))
        .collect();
    let (zone, zone_boundary) = sub_mesh(&part, &in_zone);
    let rest = without_tets(part, &in_zone, &zone_boundary);
    Cut { rest, zone }
}

/// `marked` vertices grown by `layers` layers of tets (every vertex of a tet with a marked
/// one is marked).
fn grow_layers(tets: &[[u32; 4]], marked: &mut [bool], layers: usize) {
    if !marked.contains(&true) {
        return;
    }
    for _ in 0..layers {
        let touched: Vec<bool> = tets
            .iter()
            .map(|tv| tv.iter().any(|&v| marked[v as usize]))
            .collect();
        for (tv, _) in tets.iter().zip(&touched).filter(|(_, &t)| t) {
            tv.iter().for_each(|&v| marked[v as usize] = true);
        }
    }
}

/// `mesh` without the tets where `drop` is true, in place: the vertices no tet uses any more
/// and the boundary triangles that are no face of a kept tet are left out. `touched` tells
/// which boundary triangles are faces of dropped tets (the others are faces of kept ones).
fn without_tets(mut mesh: TetMesh, drop: &[bool], touched: &[bool]) -> TetMesh {
    // A touched triangle stays where it is also a kept tet's face (a region interface with
    // the zone on one side): only kept tets with three vertices on dropped tets can have it.
    let mut on_dropped = vec![false; mesh.vertices.len()];
    for (tv, _) in mesh.tets.iter().zip(drop).filter(|(_, &d)| d) {
        tv.iter().for_each(|&v| on_dropped[v as usize] = true);
    }
    let touched_keys: FxHashSet<[u32; 3]> = (mesh.boundary.iter().zip(touched))
        .filter(|(_, &t)| t)
        .map(|(&b, _)| key(b))
        .collect();
    let mut also_kept: FxHashSet<[u32; 3]> = FxHashSet::default();
    for (tv, _) in mesh.tets.iter().zip(drop).filter(|(_, &d)| !d) {
        if tv.iter().filter(|&&v| on_dropped[v as usize]).count() >= 3 {
            for skip in 0..4 {
                let k = key(face(tv, skip));
                if touched_keys.contains(&k) {
                    also_kept.insert(k);
                }
            }
        }
    }
    let mut t = 0;
    mesh.tets.retain(|_| {
        t += 1;
        !drop[t - 1]
    });
    let mut t = 0;
    mesh.tet_regions.retain(|_| {
        t += 1;
        !drop[t - 1]
    });
    let keep_boundary: Vec<bool> = (mesh.boundary.iter().zip(touched))
        .map(|(&b, &t)| !t || also_kept.contains(&key(b)))
        .collect();
    let mut i = 0;
    mesh.boundary.retain(|_| {
        i += 1;
        keep_boundary[i - 1]
    });
    let mut i = 0;
    mesh.boundary_markers.retain(|_| {
        i += 1;
        keep_boundary[i - 1]
    });
    // Vertices renumbered in order, the unused ones left out.
    let mut id = vec![u32::MAX; mesh.vertices.len()];
    mesh.tets.iter().flatten().for_each(|&v| id[v as usize] = 0);
    let mut n = 0;
    for (v, new) in id.iter_mut().enumerate() {
        if *new == 0 {
            *new = n;
            mesh.vertices[n as usize] = mesh.vertices[v];
            n += 1;
        }
    }
    mesh.vertices.truncate(n as usize);
    mesh.vertices.shrink_to_fit();
    for tv in mesh.tets.iter_mut() {
        *tv = tv.map(|v| id[v as usize]);
    }
    for b in mesh.boundary.iter_mut() {
        *b = b.map(|v| id[v as usize]);
    }
    mesh
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

/// What one part gets of the glued zones.
pub struct Share {
    /// The pieces it improves.
    pub zone: TetMesh,
    /// Its triangles on the interfaces once the pieces are back in the parts: the pieces'
    /// outer faces between the piece's owner and the part whose rest is on their other side,
    /// where those differ.
    pub next_interface: Vec<Corners>,
}

/// The zones of all parts (`zones[p]` is part p's) glued and cut into connected pieces
/// (through faces), each given to the lowest part among its tets' parts: what each part
/// improves and its interfaces afterwards (empty where a part owns no piece).
pub fn share_zones(zones: &[TetMesh]) -> Vec<Share> {
    let (zone, source) = glue(zones);
    let mut pieces = UnionFind::new(zone.tets.len());
    // Each face: its first tet, and whether a second one has it.
    let mut faces: FxHashMap<[u32; 3], (u32, bool)> = FxHashMap::default();
    for (t, tv) in zone.tets.iter().enumerate() {
        for skip in 0..4 {
            match faces.entry(key(face(tv, skip))) {
                std::collections::hash_map::Entry::Occupied(mut o) => {
                    pieces.union(o.get().0, t as u32);
                    o.get_mut().1 = true;
                }
                std::collections::hash_map::Entry::Vacant(v) => {
                    v.insert((t as u32, false));
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
    // An outer face (one tet, no boundary triangle) is a cut face of its tet's source part,
    // whose rest is on its other side.
    let boundary: FxHashSet<[u32; 3]> = zone.boundary.iter().map(|&b| key(b)).collect();
    let mut next_interface = vec![vec![]; zones.len()];
    let mut outer: Vec<(&[u32; 3], u32)> = (faces.iter())
        .filter(|(k, &(_, twice))| !twice && !boundary.contains(*k))
        .map(|(k, &(t, _))| (k, t))
        .collect();
    outer.sort_unstable();
    for (f, t) in outer {
        let (o, s) = (owner[t as usize], source[t as usize]);
        if o != s {
            let c = corners(f, &zone.vertices);
            next_interface[o as usize].push(c);
            next_interface[s as usize].push(c);
        }
    }
    (0..zones.len() as u32)
        .zip(next_interface)
        .map(|(p, next_interface)| {
            let mine: Vec<bool> = owner.iter().map(|&o| o == p).collect();
            Share {
                zone: sub_mesh(&zone, &mine).0,
                next_interface,
            }
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
    let opts = crate::improve::finish_options(params);
    let (plain, plain_stats) =
        crate::improve::finish_with(mesh.clone(), Some(&fixed), &opts, None)?;
    let (mut mesh, stats) = match repaired_if_better(mesh, &fixed, plain, params)? {
        Ok(repaired) => repaired,
        Err(plain) => (plain, plain_stats),
    };
    mesh.remove_boundary_marker(ZONE_MARKER);
    Ok((mesh, stats))
}

/// A zone improved with the radius-edge repair (`improve::Options::repair_rho`), if `plain`
/// (the zone improved without it) has a tet over rho0 and the repair lowers its largest ratio
/// without a smaller angle than `plain`'s, or than the improvement target. Such tets are the
/// parts' tets next to their frozen interface whose circumcentres were refused there; in the
/// zone the old interface is free. Else `plain` back.
#[allow(clippy::type_complexity)]
fn repaired_if_better(
    zone: TetMesh,
    fixed: &crate::plc::PlcInput,
    plain: TetMesh,
    params: &Params,
) -> Result<Result<(TetMesh, ImproveStats), TetMesh>, MeshError> {
    let q = crate::quality::measure(&plain)
        .map_err(|e| MeshError::Internal(format!("measuring a zone: {e}")))?;
    if q.max_rho <= params.rho0 {
        return Ok(Err(plain));
    }
    let opts = crate::improve::Options {
        repair_rho: params.rho0,
        ..crate::improve::finish_options(params)
    };
    let (repaired, stats) = crate::improve::finish_with(zone, Some(fixed), &opts, None)?;
    let r = crate::quality::measure(&repaired)
        .map_err(|e| MeshError::Internal(format!("measuring a zone: {e}")))?;
    let floor = q.min_dihedral_deg.min(params.effective_improve_target());
    Ok(
        if r.max_rho <= q.max_rho && r.min_dihedral_deg >= floor && stats.rho_repairs > 0 {
            Ok((repaired, stats))
        } else {
            Err(plain)
        },
    )
}

/// `improved` (a part's pieces of the zones) put back into `rest` (the part without its
/// zone), glued by the coordinates of their shared vertices, and the part's triangles on its
/// new interfaces (`next`, from [`share_zones`]) as vertex ids of the result.
pub fn rejoin(mut rest: TetMesh, improved: TetMesh, next: &[Corners]) -> (TetMesh, Vec<[u32; 3]>) {
    let bits = |p: DVec3| p.to_array().map(f64::to_bits);
    let index: FxHashMap<[u64; 3], u32> = (improved.vertices.iter().enumerate())
        .map(|(i, &p)| (bits(p), i as u32))
        .collect();
    let mut id = vec![u32::MAX; improved.vertices.len()];
    let mut shared = vec![false; rest.vertices.len()];
    for (v, &p) in rest.vertices.iter().enumerate() {
        if let Some(&i) = index.get(&bits(p)) {
            id[i as usize] = v as u32;
            shared[v] = true;
        }
    }
    for (i, &p) in improved.vertices.iter().enumerate() {
        if id[i] == u32::MAX {
            id[i] = rest.vertices.len() as u32;
            rest.vertices.push(p);
        }
    }
    let old = |v: u32| (v as usize) < shared.len() && shared[v as usize];
    let rest_boundary: FxHashSet<[u32; 3]> = (rest.boundary.iter())
        .filter(|b| b.iter().all(|&v| shared[v as usize]))
        .map(|&b| key(b))
        .collect();
    rest.tets
        .extend(improved.tets.iter().map(|t| t.map(|v| id[v as usize])));
    rest.tet_regions.extend(&improved.tet_regions);
    for (b, &m) in improved.boundary.iter().zip(&improved.boundary_markers) {
        let b = b.map(|v| id[v as usize]);
        // A region interface between the rest and the piece is in both.
        if b.iter().all(|&v| old(v)) && rest_boundary.contains(&key(b)) {
            continue;
        }
        rest.boundary.push(b);
        rest.boundary_markers.push(m);
    }
    let wanted: FxHashSet<[u64; 3]> = next.iter().flatten().copied().collect();
    let found: FxHashMap<[u64; 3], u32> = (rest.vertices.iter().enumerate())
        .filter(|(_, &p)| wanted.contains(&bits(p)))
        .map(|(v, &p)| (bits(p), v as u32))
        .collect();
    let interface = (next.iter())
        .filter_map(|c| Some([found.get(&c[0])?, found.get(&c[1])?, found.get(&c[2])?].map(|&v| v)))
        .collect();
    (rest, interface)
}

/// The most times the interfaces are moved.
pub const MAX_INTERFACE_PASSES: u32 = 3;

/// Whether the interfaces move (again) after `passes` passes: the worst tet of all parts
/// (`worst`, degrees) is below `target_deg`, and the last pass raised it (from
/// `worst_before_last`); or, for the first pass, a tet is over rho0 (`over_rho`).
pub fn another_pass(
    passes: u32,
    worst_before_last: f64,
    worst: f64,
    target_deg: f64,
    over_rho: bool,
) -> bool {
    passes < MAX_INTERFACE_PASSES
        && ((worst < target_deg && (passes == 0 || worst > worst_before_last))
            || (passes == 0 && over_rho))
}

/// The parts with their interfaces moved, in one process (`crate::distributed` does the
/// same with the zones exchanged between ranks), and how many passes that took.
pub fn move_interfaces(
    parts: Vec<MeshedPart>,
    params: &Params,
) -> Result<(Vec<TetMesh>, u32), MeshError> {
    let target = params.effective_improve_target();
    let mut parts: Vec<(TetMesh, Vec<[u32; 3]>)> =
        parts.into_iter().map(|p| (p.mesh, p.interface)).collect();
    // The worst tet of all parts, whether one is over rho0, and each part's seed tets.
    let measure = |parts: &[(TetMesh, Vec<[u32; 3]>)]| {
        let (mut worst, mut over_rho, mut seeds) = (f64::MAX, false, vec![]);
        for (mesh, _) in parts {
            let (w, o, s) = bad_tets(mesh, target, params.rho0);
            (worst, over_rho) = (worst.min(w), over_rho || o);
            seeds.push(s);
        }
        (worst, over_rho, seeds)
    };
    let (mut worst, mut over_rho, mut seeds) = measure(&parts);
    let (mut passes, mut before) = (0, worst);
    while another_pass(passes, before, worst, target, over_rho) {
        let (rests, zones): (Vec<TetMesh>, Vec<TetMesh>) = (parts.into_iter().zip(&seeds))
            .map(|((mesh, interface), seeds)| {
                let cut = cut_zone(mesh, &interface, seeds);
                (cut.rest, cut.zone)
            })
            .unzip();
        let shares = share_zones(&zones);
        parts = vec![];
        for (rest, share) in rests.into_iter().zip(shares) {
            let (improved, _) = improve_zone(share.zone, params)?;
            parts.push(rejoin(rest, improved, &share.next_interface));
        }
        (passes, before) = (passes + 1, worst);
        (worst, over_rho, seeds) = measure(&parts);
    }
    Ok((parts.into_iter().map(|(m, _)| m).collect(), passes))
}
