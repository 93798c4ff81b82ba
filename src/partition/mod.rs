//! Partitioned meshing: the domain cut into parts that are refined and improved one at a time
//! (one per MPI rank in `crate::distributed`), with conforming interfaces between them.
//!
//! Every part calls [`plan`] with the same input and gets the same [`Plan`] (it is
//! deterministic); [`mesh_part`] then meshes one part. The parts' meshes share their interface
//! vertices bit for bit (the same coordinates), so gluing them by coordinates gives one
//! conforming mesh; each part's `boundary` holds only its share of the domain's boundary and
//! interface facets (not the faces between parts).
//!
//! FIRST STEP (to be replaced in this session): the plan meshes the whole domain serially and
//! each part is a contiguous run of its tets in Hilbert order of their centroids.

use crate::delaunay::hilbert::hilbert_sort;
use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::run::error::MeshError;
use crate::run::params::{Params, SurfaceMode};
use crate::run::report::Report;
use crate::run::spacing::Spacing;
use glam::DVec3;

/// What every part needs to mesh its share: the same on every part.
pub struct Plan {
    parts: usize,
    whole: TetMesh,
    report: Report,
    /// Tets of each part (indices into `whole.tets`).
    part_tets: Vec<Vec<u32>>,
}

impl Plan {
    /// The number of parts.
    pub fn parts(&self) -> usize {
        self.parts
    }
}

/// Prepares the partition of `input` into `parts` parts (keep mode only for now).
pub fn plan(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    parts: usize,
) -> Result<Plan, MeshError> {
    if parts == 0 {
        return Err(MeshError::InvalidInput(
            "a partition needs at least one part".into(),
        ));
    }
    if params.surface_mode != SurfaceMode::Keep {
        return Err(MeshError::InvalidInput(
            "partitioned meshing supports the keep surface mode only (so far)".into(),
        ));
    }
    let (whole, _, report) = crate::pipeline::mesh(input, params, spacing, None)?;
    let centroids: Vec<DVec3> = whole
        .tets
        .iter()
        .map(|t| t.iter().map(|&v| whole.vertices[v as usize]).sum::<DVec3>() / 4.0)
        .collect();
    let mut order: Vec<u32> = (0..whole.tets.len() as u32).collect();
    hilbert_sort(&centroids, &mut order);
    let n = order.len();
    let part_tets = (0..parts)
        .map(|k| order[k * n / parts..(k + 1) * n / parts].to_vec())
        .collect();
    Ok(Plan {
        parts,
        whole,
        report,
        part_tets,
    })
}

/// Meshes part `part` of `plan`: its tets, vertices numbered from 0, region attributes, and
/// the domain's boundary triangles (with markers) that are faces of its tets.
pub fn mesh_part(plan: &Plan, part: usize) -> Result<(TetMesh, Report), MeshError> {
    let tets = plan.part_tets.get(part).ok_or_else(|| {
        MeshError::InvalidInput(format!("part {part} of a plan of {} parts", plan.parts))
    })?;
    let whole = &plan.whole;
    let mut local = vec![u32::MAX; whole.vertices.len()];
    let mut mesh = TetMesh::default();
    for &t in tets {
        let tv = whole.tets[t as usize].map(|v| {
            if local[v as usize] == u32::MAX {
                local[v as usize] = mesh.vertices.len() as u32;
                mesh.vertices.push(whole.vertices[v as usize]);
            }
            local[v as usize]
        });
        mesh.tets.push(tv);
        mesh.tet_regions.push(whole.tet_regions[t as usize]);
    }
    let mut faces = rustc_hash::FxHashSet::default();
    for t in &mesh.tets {
        for skip in 0..4 {
            let mut f = [0; 3];
            let mut k = 0;
            for (i, &v) in t.iter().enumerate() {
                if i != skip {
                    f[k] = v;
                    k += 1;
                }
            }
            f.sort_unstable();
            faces.insert(f);
        }
    }
    for (b, &m) in whole.boundary.iter().zip(&whole.boundary_markers) {
        let lb = b.map(|v| local[v as usize]);
        if lb.contains(&u32::MAX) {
            continue;
        }
        let mut key = lb;
        key.sort_unstable();
        if faces.contains(&key) {
            mesh.boundary.push(lb);
            mesh.boundary_markers.push(m);
        }
    }
    Ok((mesh, plan.report.clone()))
}
