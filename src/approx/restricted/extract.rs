//! The boundary extracted from the restricted Delaunay triangulation, and what breaks it: the
//! faces between tets of different regions, checked per region for manifoldness, and their
//! distance to the input both ways (the faces the rounds of `SurfaceMesher::rounds` mend).

use super::{key2, FaceRef, Loc, SurfaceMesher};
use crate::delaunay::tables::FACE;
use crate::delaunay::INFINITE;
use crate::surface::oracle::SurfaceOracle;
use crate::surface::InputSurface;
use glam::DVec3;
use rustc_hash::{FxHashMap, FxHashSet};
use std::cmp::Ordering;

/// A boundary face and the sample that finds it too far from the other surface.
type Far = (FaceRef, f64, DVec3);

impl SurfaceMesher<'_> {
    /// The faces between tets whose circumcentres lie in different regions, one of them not
    /// outside: the boundary and the interfaces, each once (as (tet, face index), the tet in
    /// the lower region of the two that is not outside); and those of them that break some
    /// region's boundary: a vertex off the surface, an edge of that boundary not shared by
    /// exactly two of its faces, or a vertex whose faces there do not make one disk (two
    /// sheets touching at a point, as across a thin part). Each region is checked alone, so
    /// the edges where three regions meet are not in the way.
    pub(super) fn extract(&self) -> (Vec<FaceRef>, Vec<FaceRef>) {
        let mut region = vec![0u32; self.dt.tet_capacity()];
        for t in self.dt.finite_tet_ids() {
            region[t as usize] = self.region_of(t);
        }
        // Every region's side of every face of its boundary.
        let mut sides: Vec<(u32, FaceRef)> = vec![];
        for t in self.dt.finite_tet_ids() {
            let r = region[t as usize];
            if r == 0 {
                continue;
            }
            for (i, n) in self.dt.neighbors(t).iter().enumerate() {
                if region[*n as usize] != r {
                    sides.push((r, (t, i)));
                }
            }
        }
        let face_of = |(t, i): FaceRef| FACE[i].map(|k| self.dt.tet(t)[k]);
        let mut edge_count: FxHashMap<(u32, [u32; 2]), u32> = FxHashMap::default();
        for &(r, f) in &sides {
            let f = face_of(f);
            for j in 0..3 {
                *edge_count
                    .entry((r, key2(f[j], f[(j + 1) % 3])))
                    .or_default() += 1;
            }
        }
        let n_regions = sides.iter().map(|s| s.0).max().unwrap_or(0);
        let mut pinched: FxHashSet<u32> = FxHashSet::default();
        for r in 1..=n_regions {
            let of_region = sides.iter().filter(|s| s.0 == r).map(|s| face_of(s.1));
            pinched.extend(pinched_vertices(of_region));
        }
        let breaks = |&(r, f): &(u32, FaceRef)| {
            let f = face_of(f);
            f.iter().any(|&v| {
                v == INFINITE
                    || matches!(self.loc[v as usize], Loc::Far | Loc::Volume)
                    || pinched.contains(&v)
            }) || (0..3).any(|j| edge_count[&(r, key2(f[j], f[(j + 1) % 3]))] != 2)
        };
        let problems = sides.iter().filter(|s| breaks(s)).map(|s| s.1).collect();
        let faces = sides
            .iter()
            .filter(|&&(r, (t, i))| {
                let other = region[self.dt.neighbors(t)[i] as usize];
                other == 0 || r < other
            })
            .map(|s| s.1)
            .collect();
        (faces, problems)
    }

    /// The boundary faces nearest to the samples of the input the report's Hausdorff
    /// distance takes (`measure::hausdorff_samples`) that lie farther than the bound from
    /// them, away from small corners, where the surface is left coarse on purpose.
    pub(super) fn far_from_input(&self, faces: &[FaceRef]) -> Vec<(u32, usize, DVec3)> {
        let extracted = self.extracted_surface(faces);
        let near = SurfaceOracle::for_distances(&extracted);
        let points = self.input_samples();
        // Consecutive samples come from one input triangle: the last face found is tried first.
        let mut hint = None;
        let far: Vec<Far> = points
            .iter()
            .copied()
            .filter(|&p| {
                near.distance_beyond_hinted(p, self.criteria.bound, &mut hint)
                    .is_some()
            })
            .filter(|&p| !self.near_small_corner(p))
            .filter_map(|p| {
                near.closest(p)
                    .map(|c| (faces[c.triangle as usize], c.distance, p))
            })
            .collect();
        farthest_per_face(far)
    }

    /// The other way: the boundary faces holding a sample of the report's (the boundary's
    /// `measure::hausdorff_samples`) farther than the bound from the input, away from small
    /// corners, each with its farthest such sample (the input point nearest to it mends the
    /// face). The facet criteria measure at the surface centre and the centroid; a flat face
    /// over a fold of the input can stray farther elsewhere.
    pub(super) fn far_from_surface(&self, faces: &[FaceRef]) -> Vec<(u32, usize, DVec3)> {
        let extracted = self.extracted_surface(faces);
        let mut hint = None;
        let far_samples: Vec<DVec3> = crate::approx::measure::hausdorff_samples(&extracted)
            .into_iter()
            .filter(|&p| {
                self.oracle
                    .distance_beyond_hinted(p, self.criteria.bound, &mut hint)
                    .is_some()
            })
            .filter(|&p| !self.near_small_corner(p))
            .filter(|&p| self.repair.is_none_or(|r| !r.labels.spans_at(p)))
            .collect();
        if far_samples.is_empty() {
            return vec![];
        }
        let near = SurfaceOracle::for_distances(&extracted);
        let far: Vec<Far> = far_samples
            .into_iter()
            .filter_map(|p| {
                let d = self.oracle.closest(p)?.distance;
                near.closest(p).map(|c| (faces[c.triangle as usize], d, p))
            })
            .collect();
        farthest_per_face(far)
    }

    /// The input's Hausdorff samples (`measure::hausdorff_samples`), once taken; of a repaired
    /// input, those where it bounds the solid.
    pub(super) fn input_samples(&self) -> &[DVec3] {
        self.input_samples.get_or_init(|| {
            let all = crate::approx::measure::hausdorff_samples(self.surface);
            match self.repair {
                None => all,
                Some(r) => all
                    .into_iter()
                    .filter(|&p| {
                        self.oracle.closest(p).is_some_and(|c| {
                            r.bounds_solid_at(p, self.surface.normal(c.triangle as usize))
                        })
                    })
                    .collect(),
            }
        })
    }

    /// The faces as a surface over the triangulation's points (for distance queries).
    fn extracted_surface(&self, faces: &[FaceRef]) -> InputSurface {
        let triangles = faces
            .iter()
            .map(|&(t, i)| FACE[i].map(|k| self.dt.tet(t)[k]))
            .collect();
        InputSurface::from_triangles(self.dt.points().to_vec(), triangles)
    }
}

/// One sample per face: the farthest (ties by position, for determinism), as (tet, face index,
/// sample).
fn farthest_per_face(mut far: Vec<Far>) -> Vec<(u32, usize, DVec3)> {
    far.sort_unstable_by(|a, b| {
        a.0.cmp(&b.0).then(b.1.total_cmp(&a.1)).then(
            a.2.to_array()
                .partial_cmp(&b.2.to_array())
                .unwrap_or(Ordering::Equal),
        )
    });
    far.dedup_by_key(|x| x.0);
    far.into_iter().map(|((t, i), _, p)| (t, i, p)).collect()
}

/// The vertices of `faces` whose faces around them do not form one fan: the edges opposite
/// them (their link) make more than one connected piece.
fn pinched_vertices(faces: impl Iterator<Item = [u32; 3]>) -> FxHashSet<u32> {
    let mut link: FxHashMap<u32, Vec<[u32; 2]>> = FxHashMap::default();
    for f in faces {
        for j in 0..3 {
            link.entry(f[j])
                .or_default()
                .push([f[(j + 1) % 3], f[(j + 2) % 3]]);
        }
    }
    link.into_iter()
        .filter(|(_, edges)| link_pieces(edges) > 1)
        .map(|(v, _)| v)
        .collect()
}

/// Connected pieces of a small graph given by its edges.
fn link_pieces(edges: &[[u32; 2]]) -> usize {
    let mut ids: Vec<u32> = edges.iter().flatten().copied().collect();
    ids.sort_unstable();
    ids.dedup();
    let local = |v: u32| ids.binary_search(&v).unwrap_or(0) as u32;
    let mut sets = crate::union_find::UnionFind::new(ids.len());
    for e in edges {
        sets.union(local(e[0]), local(e[1]));
    }
    (0..ids.len() as u32).filter(|&x| sets.find(x) == x).count()
}
