//! The band: the whole coarse domain meshed once with each tet's region paired with its part,
//! so that the interfaces are internal facets refined from both sides, for a spacing that is
//! the run's next to the interfaces and grows away from them (so the band costs about a layer
//! of final tets on each side of an interface, and its mesh there is a serial run's, with no
//! artificial side of its own next to the interface). Its interface triangles become every
//! part's frozen facets and its vertices next to an interface the parts' seeds (the tets
//! next to an interface start as the band's).

use super::coarse::{sorted_faces, Coarse};
use super::INTERFACE_MARKER;
use crate::mesh::TetMesh;
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::spacing::Spacing;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};

/// A band triangle between two parts (band vertex ids) and its marker.
pub(super) type InterfaceTriangle = ([u32; 3], i32);

pub(super) struct Band {
    /// The band's tets.
    pub n_tets: usize,
    /// The refined band's vertices (its tets are dropped once the parts' shares are known).
    pub mesh: TetMesh,
    /// Per part: the band's triangles between it and another part (band vertex ids), with
    /// their marker: `INTERFACE_MARKER`, or the region interface's where one lies there (the
    /// parts keep those triangles in their output).
    pub interface: Vec<Vec<InterfaceTriangle>>,
    /// Per part: band vertices inside it, on no facet of the band.
    pub seeds: Vec<Vec<u32>>,
    /// The band's vertices on each coarse edge it split (coarse vertex ids, smaller first),
    /// from the smaller end to the larger.
    pub chains: FxHashMap<(u32, u32), Vec<u32>>,
    /// Its vertices inside the domain's facets next to the interfaces, with the facet's
    /// marker (`facet_points`).
    pub facet_points: Vec<(u32, i32)>,
}

impl Band {
    pub fn new(coarse: &Coarse, params: &Params, spacing: &dyn Spacing) -> Result<Band, MeshError> {
        let m = &coarse.mesh;
        let mut face_tets: FxHashMap<[u32; 3], Vec<u32>> = FxHashMap::default();
        for t in 0..m.tets.len() {
            for f in coarse.faces(t) {
                face_tets.entry(f).or_default().push(t as u32);
            }
        }
        let mut on_interface = vec![false; m.vertices.len()];
        let mut interface_faces = FxHashSet::default();
        for (f, ts) in &face_tets {
            if ts.len() == 2 && coarse.part_of[ts[0] as usize] != coarse.part_of[ts[1] as usize] {
                f.iter().for_each(|&v| on_interface[v as usize] = true);
                interface_faces.insert(*f);
            }
        }
        let in_band: Vec<u32> = (0..m.tets.len() as u32).collect();
        let near = NearInterfaces::new(m, &on_interface, spacing);
        // (region, part) -> code, in first-seen order (deterministic).
        let mut codes: FxHashMap<(i32, u32), i32> = FxHashMap::default();
        let mut part_of_code = vec![];
        let mut region_of_code = vec![];
        let mut sub = TetMesh::default();
        let mut local = vec![u32::MAX; m.vertices.len()];
        for &t in &in_band {
            let tv = m.tets[t as usize].map(|v| {
                if local[v as usize] == u32::MAX {
                    local[v as usize] = sub.vertices.len() as u32;
                    sub.vertices.push(m.vertices[v as usize]);
                }
                local[v as usize]
            });
            sub.tets.push(tv);
            let part = coarse.part_of[t as usize];
            let key = (m.tet_regions[t as usize], part);
            let next = codes.len() as i32 + 1;
            let code = *codes.entry(key).or_insert_with(|| {
                part_of_code.push(part);
                region_of_code.push(key.0);
                next
            });
            sub.tet_regions.push(code);
        }
        let band_faces: FxHashSet<[u32; 3]> = in_band
            .iter()
            .flat_map(|&t| coarse.faces(t as usize))
            .collect();
        // The interfaces first, with a marker of their own (listed first, they keep it where
        // a region interface lies on them): their refined triangles are the ones with it.
        let mut interfaces: Vec<&[u32; 3]> = interface_faces.iter().collect();
        interfaces.sort_unstable();
        for f in interfaces {
            sub.boundary.push(f.map(|v| local[v as usize]));
            sub.boundary_markers.push(INTERFACE_MARKER);
        }
        for (b, &marker) in m.boundary.iter().zip(&m.boundary_markers) {
            let mut key = *b;
            key.sort_unstable();
            if band_faces.contains(&key) {
                sub.boundary.push(b.map(|v| local[v as usize]));
                sub.boundary_markers.push(marker);
            }
        }
        let input = crate::refine::existing::plc_of_mesh_except(&sub, &|_| false)?;
        let band_params = Params {
            improve: false,
            order: 1,
            ..params.clone()
        };
        let (mesh, _, segment_ends) = crate::refine::mesh_frozen_tracing_segments(
            &input,
            &band_params,
            Some(&near),
            &[],
            crate::refine::Unseeded::Hole,
        )
        .map_err(|e| MeshError::Internal(format!("meshing the partition's band: {e}")))?;
        let mut coarse_of = vec![u32::MAX; sub.vertices.len()];
        for (v, &l) in local.iter().enumerate() {
            if l != u32::MAX {
                coarse_of[l as usize] = v as u32;
            }
        }
        let chains = chains(&mesh, &segment_ends, &coarse_of);
        let part_of_tet: Vec<u32> = (mesh.tet_regions.iter())
            .map(|&c| part_of_code[(c - 1) as usize])
            .collect();
        let region_interfaces = RegionInterfaces::new(m, &interface_faces);
        let marker_of = |f: [u32; 3], tets: &[u32]| -> i32 {
            let region = |t: u32| region_of_code[(mesh.tet_regions[t as usize] - 1) as usize];
            match tets {
                [a, b] if region(*a) != region(*b) => region_interfaces.marker(
                    f.map(|v| mesh.vertices[v as usize]),
                    region(*a),
                    region(*b),
                ),
                _ => INTERFACE_MARKER,
            }
        };
        let (interface, mut seeds) = split_by_part(&mesh, &part_of_tet, coarse.parts, &marker_of);
        // Seeds only where the band is at the run's spacing.
        for part_seeds in &mut seeds {
            part_seeds.retain(|&v| near.is_fine(mesh.vertices[v as usize]));
        }
        let facet_points = facet_points(&mesh, &segment_ends, sub.vertices.len(), &near);
        let n_tets = mesh.tets.len();
        // The parts need the band's points only: its tets go now.
        let mesh = TetMesh {
            vertices: mesh.vertices,
            ..TetMesh::default()
        };
        Ok(Band {
            n_tets,
            mesh,
            interface,
            seeds,
            chains,
            facet_points,
        })
    }
}

/// The markers of the coarse mesh's region interfaces that lie on part interfaces, to give
/// them back to the band's triangles there (the band marks every part interface alike).
struct RegionInterfaces {
    /// Per pair of regions (smaller first): the coarse faces between them, with their marker.
    faces: FxHashMap<(i32, i32), Vec<MarkedTriangle>>,
}

/// A triangle's corners and its marker.
type MarkedTriangle = ([DVec3; 3], i32);

impl RegionInterfaces {
    fn new(m: &TetMesh, part_interfaces: &FxHashSet<[u32; 3]>) -> Self {
        let mut region_across: FxHashMap<[u32; 3], Vec<i32>> = FxHashMap::default();
        for (t, tv) in m.tets.iter().enumerate() {
            for f in sorted_faces(*tv) {
                if part_interfaces.contains(&f) {
                    region_across.entry(f).or_default().push(m.tet_regions[t]);
                }
            }
        }
        let mut faces: FxHashMap<(i32, i32), Vec<MarkedTriangle>> = FxHashMap::default();
        for (b, &marker) in m.boundary.iter().zip(&m.boundary_markers) {
            let mut k = *b;
            k.sort_unstable();
            if let Some(&[r, s]) = region_across.get(&k).map(|r| &r[..]) {
                let pair = (r.min(s), r.max(s));
                let corners = b.map(|v| m.vertices[v as usize]);
                faces.entry(pair).or_default().push((corners, marker));
            }
        }
        RegionInterfaces { faces }
    }

    /// The marker of the coarse face between regions `r` and `s` that holds the triangle
    /// `tri` (the nearest to its centroid where the regions share several).
    fn marker(&self, tri: [DVec3; 3], r: i32, s: i32) -> i32 {
        let Some(faces) = self.faces.get(&(r.min(s), r.max(s))) else {
            return INTERFACE_MARKER;
        };
        if faces.iter().all(|f| f.1 == faces[0].1) {
            return faces[0].1;
        }
        let c = (tri[0] + tri[1] + tri[2]) / 3.0;
        let distance = |[a, b, d]: [DVec3; 3]| {
            crate::surface::oracle::closest_on_triangle(c, a, b, d).distance_squared(c)
        };
        (faces.iter())
            .min_by(|x, y| distance(x.0).total_cmp(&distance(y.0)))
            .map_or(INTERFACE_MARKER, |f| f.1)
    }
}

/// The band's vertices inside a domain facet (not coarse, on no segment) where its spacing is
/// the run's, with the facet's marker: a part's facet gets those inside it, so that its
/// triangles next to the interface are the band's (without them a part's subfacet there can
/// be one that no point may split without removing an interface triangle).
fn facet_points(
    mesh: &TetMesh,
    segment_ends: &[Option<[u32; 2]>],
    n_coarse: usize,
    near: &NearInterfaces,
) -> Vec<(u32, i32)> {
    let mut marker_of: Vec<Option<i32>> = vec![None; mesh.vertices.len()];
    let mut mixed = vec![false; mesh.vertices.len()];
    for (b, &m) in mesh.boundary.iter().zip(&mesh.boundary_markers) {
        for &v in b {
            let v = v as usize;
            if m == INTERFACE_MARKER || marker_of[v].is_some_and(|x| x != m) {
                mixed[v] = true;
            }
            marker_of[v] = Some(m);
        }
    }
    (0..mesh.vertices.len())
        .filter(|&v| v >= n_coarse && !mixed[v] && segment_ends.get(v).is_some_and(|e| e.is_none()))
        .filter_map(|v| Some((v as u32, marker_of[v]?)))
        .filter(|&(v, _)| near.is_fine(mesh.vertices[v as usize]))
        .collect()
}

/// The band's spacing: the run's `f` next to the interfaces, growing away from them as the
/// automatic spacing grades (the larger of `f` and the Lipschitz extension of f from the
/// interfaces' coarse vertices).
struct NearInterfaces<'a> {
    f: &'a dyn Spacing,
    grown: crate::refine::AutoSpacing,
}

/// How far above f the band's spacing may be at a seed: about one final layer from an
/// interface.
const SEED_SPACING_RATIO: f64 = 1.25;

impl<'a> NearInterfaces<'a> {
    fn new(m: &TetMesh, on_interface: &[bool], f: &'a dyn Spacing) -> Self {
        let points: Vec<glam::DVec3> = (m.vertices.iter().zip(on_interface))
            .filter(|(_, &on)| on)
            .map(|(&p, _)| p)
            .collect();
        let mut h = vec![0.0; points.len()];
        f.at_many(&points, &mut h);
        let sized: Vec<(glam::DVec3, f64)> = points.into_iter().zip(h).collect();
        NearInterfaces {
            f,
            grown: crate::refine::AutoSpacing::from_sizes(&sized),
        }
    }

    /// Whether the band's spacing at `p` is close to the run's.
    fn is_fine(&self, p: glam::DVec3) -> bool {
        self.at(p) <= SEED_SPACING_RATIO * self.f.at(p)
    }
}

impl Spacing for NearInterfaces<'_> {
    fn at(&self, p: glam::DVec3) -> f64 {
        self.f.at(p).max(self.grown.at(p))
    }

    fn at_many(&self, points: &[glam::DVec3], out: &mut [f64]) {
        self.f.at_many(points, out);
        for (o, &p) in out.iter_mut().zip(points) {
            *o = o.max(self.grown.at(p));
        }
    }
}

/// Per part, the band's faces between it and another part, and its vertices on no facet
/// whose tets are all in it.
fn split_by_part(
    mesh: &TetMesh,
    part_of_tet: &[u32],
    parts: usize,
    marker_of: &dyn Fn([u32; 3], &[u32]) -> i32,
) -> (Vec<Vec<InterfaceTriangle>>, Vec<Vec<u32>>) {
    let mut face_tets: FxHashMap<[u32; 3], Vec<u32>> = FxHashMap::default();
    for (t, &tv) in mesh.tets.iter().enumerate() {
        for f in sorted_faces(tv) {
            face_tets.entry(f).or_default().push(t as u32);
        }
    }
    // The interface's refined triangles, each given to the parts of the tets on its sides.
    let mut interface: Vec<Vec<InterfaceTriangle>> = vec![vec![]; parts];
    for (b, &marker) in mesh.boundary.iter().zip(&mesh.boundary_markers) {
        if marker != INTERFACE_MARKER {
            continue;
        }
        let mut f = *b;
        f.sort_unstable();
        let tets = face_tets.get(&f).map_or(&[][..], |t| &t[..]);
        let marker = marker_of(f, tets);
        for &t in tets {
            let p = part_of_tet[t as usize] as usize;
            if interface[p].last().map(|l| l.0) != Some(f) {
                interface[p].push((f, marker));
            }
        }
    }
    let mut on_facet = vec![false; mesh.vertices.len()];
    for b in &mesh.boundary {
        b.iter().for_each(|&v| on_facet[v as usize] = true);
    }
    // u32::MAX: no tet yet; u32::MAX - 1: tets in several parts.
    let mut part_of_vertex = vec![u32::MAX; mesh.vertices.len()];
    for (tv, &p) in mesh.tets.iter().zip(part_of_tet) {
        for &v in tv {
            let s = &mut part_of_vertex[v as usize];
            *s = if *s == u32::MAX || *s == p {
                p
            } else {
                u32::MAX - 1
            };
        }
    }
    let mut seeds = vec![vec![]; parts];
    for (v, &p) in part_of_vertex.iter().enumerate() {
        if (p as usize) < parts && !on_facet[v] {
            seeds[p as usize].push(v as u32);
        }
    }
    (interface, seeds)
}

/// The band's vertices on each input segment of its PLC (a coarse edge), in order along it:
/// keyed by the coarse ends (smaller first), ordered from the smaller end.
fn chains(
    mesh: &TetMesh,
    segment_ends: &[Option<[u32; 2]>],
    coarse_of: &[u32],
) -> FxHashMap<(u32, u32), Vec<u32>> {
    let mut along: FxHashMap<(u32, u32), Vec<(f64, u32)>> = FxHashMap::default();
    for (v, ends) in segment_ends.iter().enumerate() {
        let Some([a, b]) = *ends else {
            continue;
        };
        let (ca, cb) = (coarse_of[a as usize], coarse_of[b as usize]);
        let (lo, hi, from) = if ca < cb { (ca, cb, a) } else { (cb, ca, b) };
        let origin = mesh.vertices[from as usize];
        let t = mesh.vertices[v].distance_squared(origin);
        along.entry((lo, hi)).or_default().push((t, v as u32));
    }
    along
        .into_iter()
        .map(|(k, mut pts)| {
            pts.sort_unstable_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
            (k, pts.into_iter().map(|(_, v)| v).collect())
        })
        .collect()
}
