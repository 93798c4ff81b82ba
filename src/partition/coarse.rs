//! The coarse mesh a partition is cut from, and the cut: runs of equal estimated final size
//! along the Hilbert order of the tets' centroids.

use crate::delaunay::hilbert::hilbert_sort;
use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::spacing::Spacing;
use glam::DVec3;

/// The coarse mesh's spacing, as a multiple of the final one: about 64 final tets a coarse
/// one, so that the coarse mesh is cheap and its tets still follow the grading.
const COARSE_FACTOR: f64 = 4.0;

/// The spacing times a factor.
struct Scaled<'a>(&'a dyn Spacing, f64);

impl Spacing for Scaled<'_> {
    fn at(&self, p: DVec3) -> f64 {
        self.0.at(p) * self.1
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        self.0.at_many(points, out);
        out.iter_mut().for_each(|f| *f *= self.1);
    }
}

pub(super) struct Coarse {
    pub parts: usize,
    /// The coarse mesh (refined and improved, its boundary on the input's facets).
    pub mesh: TetMesh,
    /// The part of each coarse tet.
    pub part_of: Vec<u32>,
}

impl Coarse {
    pub fn new(
        input: &PlcInput,
        params: &Params,
        spacing: &dyn Spacing,
        parts: usize,
        cut_shift: f64,
    ) -> Result<Coarse, MeshError> {
        let coarse_params = Params {
            order: 1,
            ..params.clone()
        };
        let scaled = Scaled(spacing, COARSE_FACTOR);
        let (mesh, mut report) = crate::refine::mesh(input, &coarse_params, Some(&scaled), None)?;
        let mut mesh = crate::pipeline::improve(mesh, &mut report, Some(input), &coarse_params)?;
        // The coarse vertices become the band's and the parts' input vertices. A vertex slid
        // in a facet on a coordinate plane can keep a residue far below the predicates' range
        // (5e-33 where the plane is x = 0), which input validation rejects: it is that plane.
        for p in &mut mesh.vertices {
            for c in [&mut p.x, &mut p.y, &mut p.z] {
                if c.abs() < crate::geom::MIN_COORD {
                    *c = 0.0;
                }
            }
        }
        if mesh.tets.len() < parts {
            return Err(MeshError::InvalidInput(format!(
                "{parts} parts from a coarse mesh of {} tets: too many parts for this size",
                mesh.tets.len()
            )));
        }
        let mut part_of = cut(&mesh, spacing, parts, cut_shift);
        smooth(&mesh, &mut part_of);
        Ok(Coarse {
            parts,
            mesh,
            part_of,
        })
    }

    /// The sorted faces of tet `t`.
    pub fn faces(&self, t: usize) -> [[u32; 3]; 4] {
        sorted_faces(self.mesh.tets[t])
    }
}

/// The four faces of a tet, each as its sorted vertex triple.
pub(super) fn sorted_faces(t: [u32; 4]) -> [[u32; 3]; 4] {
    [[1, 2, 3], [0, 2, 3], [0, 1, 3], [0, 1, 2]].map(|f| {
        let mut k = f.map(|i| t[i]);
        k.sort_unstable();
        k
    })
}

/// Each tet's part: the tets in Hilbert order of their centroids, cut into `parts` runs of
/// equal estimated final tet count (volume / f(centroid)^3), the cuts moved along the order by
/// `shift` (a fraction of a part's share, below one half: the first and last parts are that
/// much smaller or larger).
fn cut(mesh: &TetMesh, spacing: &dyn Spacing, parts: usize, shift: f64) -> Vec<u32> {
    let corners = |t: &[u32; 4]| t.map(|v| mesh.vertices[v as usize]);
    let centroids: Vec<DVec3> = (mesh.tets.iter())
        .map(|t| corners(t).iter().sum::<DVec3>() / 4.0)
        .collect();
    let mut f = vec![0.0; centroids.len()];
    spacing.at_many(&centroids, &mut f);
    let weight: Vec<f64> = (mesh.tets.iter().zip(&f))
        .map(|(t, &f)| {
            let [a, b, c, d] = corners(t);
            ((b - a).cross(c - a).dot(d - a).abs() / 6.0) / (f * f * f).max(f64::MIN_POSITIVE)
        })
        .collect();
    let mut order: Vec<u32> = (0..mesh.tets.len() as u32).collect();
    hilbert_sort(&centroids, &mut order);
    let total: f64 = weight.iter().sum();
    let mut part_of = vec![0u32; mesh.tets.len()];
    let mut done = 0.0;
    for (k, &t) in order.iter().enumerate() {
        // The part whose share the middle of this tet's weight falls in, but never fewer
        // tets left than parts to fill.
        let share = ((done + 0.5 * weight[t as usize]) / total * parts as f64 + shift) as usize;
        let left = order.len() - k;
        let part = share.min(parts - 1).max(parts.saturating_sub(left));
        part_of[t as usize] = part as u32;
        done += weight[t as usize];
    }
    part_of
}

/// Passes of [`smooth`].
const SMOOTHING_PASSES: usize = 4;

/// Makes the interfaces smoother: a tet whose face neighbours are mostly (three of four) in
/// one other part joins it. Spikes and notches of the cut make acute ridges on an interface,
/// where refinement cannot enforce shape next to the frozen triangles. Deterministic: each
/// pass decides from the parts as they were before it, in tet order; a part is never emptied.
fn smooth(mesh: &TetMesh, part_of: &mut [u32]) {
    let mut face_tets: rustc_hash::FxHashMap<[u32; 3], Vec<u32>> = Default::default();
    for (t, &tv) in mesh.tets.iter().enumerate() {
        for f in sorted_faces(tv) {
            face_tets.entry(f).or_default().push(t as u32);
        }
    }
    let neighbors: Vec<Vec<u32>> = (mesh.tets.iter().enumerate())
        .map(|(t, &tv)| {
            sorted_faces(tv)
                .iter()
                .flat_map(|f| face_tets[f].iter().copied().filter(|&u| u != t as u32))
                .collect()
        })
        .collect();
    let parts = part_of.iter().max().map_or(0, |&p| p as usize + 1);
    for _ in 0..SMOOTHING_PASSES {
        let before = part_of.to_vec();
        let mut count = vec![0usize; parts];
        before.iter().for_each(|&p| count[p as usize] += 1);
        let mut changed = false;
        for (t, around) in neighbors.iter().enumerate() {
            let own = before[t];
            let mut votes: Vec<(u32, usize)> = vec![];
            for &u in around {
                let q = before[u as usize];
                if q == own {
                    continue;
                }
                match votes.iter_mut().find(|(p, _)| *p == q) {
                    Some(v) => v.1 += 1,
                    None => votes.push((q, 1)),
                }
            }
            if let Some(&(q, _)) = votes.iter().find(|(_, n)| *n >= 3) {
                if count[own as usize] > 1 {
                    part_of[t] = q;
                    count[own as usize] -= 1;
                    count[q as usize] += 1;
                    changed = true;
                }
            }
        }
        if !changed {
            break;
        }
    }
}
