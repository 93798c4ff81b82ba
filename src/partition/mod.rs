//! Partitioned meshing: the domain cut into parts that are refined and improved one at a time
//! (one per MPI rank in `crate::distributed`), with conforming interfaces between them.
//!
//! Every part calls [`plan`] with the same input and gets the same [`Plan`] (it is
//! deterministic); [`mesh_part`] then meshes one part. The parts' meshes share their interface
//! vertices bit for bit (the same coordinates), so gluing them by coordinates gives one
//! conforming mesh; each part's `boundary` holds only its share of the domain's boundary and
//! interface facets (not the faces between parts). docs/distributed.md has the scheme:
//!
//! 1. a coarse mesh of the domain (`coarse.rs`), its tets cut into parts of equal estimated
//!    final size along the Hilbert order of their centroids;
//! 2. the band of coarse tets around the interfaces meshed once with the interfaces as
//!    internal facets (`band.rs`): their triangles, sized for both sides, and the band's
//!    inner vertices;
//! 3. each part's PLC (`part_plc.rs`): its coarse tets' boundary with the band's interface
//!    triangles as frozen facets, the band's vertices on its side as seeds; meshed alone
//!    (`refine::mesh_frozen`) and improved with its boundary fixed;
//! 4. the interfaces moved (`zone.rs`): the tets around them cut out of the parts, shared
//!    out and improved again with the old interfaces free.

mod band;
mod coarse;
mod part_plc;
mod zone;

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::refine::AutoSpacing;
use crate::run::error::MeshError;
use crate::run::params::{Params, SurfaceMode};
use crate::run::report::Report;
use crate::run::spacing::Spacing;
use band::Band;
use coarse::Coarse;
use rustc_hash::FxHashSet;
pub use zone::{
    another_pass, bad_tets, corners, cut_zone, glue, improve_zone, move_interfaces, rejoin,
    share_zones, Corners, Cut, Seed, Share, MAX_INTERFACE_PASSES, RHO_REACH_LAYERS, ZONE_LAYERS,
};

/// One part as [`mesh_part`] gives it.
pub struct MeshedPart {
    pub mesh: TetMesh,
    pub report: Report,
    /// The part's triangles on its interfaces with other parts (vertex ids of `mesh`): faces
    /// of one tet of it, in `mesh.boundary` only where a region interface lies on them.
    pub interface: Vec<[u32; 3]>,
}

/// Marker of the interface triangles in a part's PLC (left out of its output).
const INTERFACE_MARKER: i32 = i32::MIN + 1;

/// The spacing every part refines for: the caller's, or the automatic one of the whole
/// domain (a part's own boundary would give another).
enum PartSpacing<'s> {
    Given(&'s dyn Spacing),
    Auto(AutoSpacing),
}

impl PartSpacing<'_> {
    fn get(&self) -> &dyn Spacing {
        match self {
            PartSpacing::Given(s) => *s,
            PartSpacing::Auto(a) => a,
        }
    }
}

/// What every part needs to mesh its share: the same on every part.
pub struct Plan<'s> {
    params: Params,
    spacing: PartSpacing<'s>,
    coarse: Coarse,
    band: Band,
}

impl Plan<'_> {
    /// The number of parts.
    pub fn parts(&self) -> usize {
        self.coarse.parts
    }

    /// The parameters the parts are meshed and improved with (keep mode: in approximate mode
    /// the parts mesh the boundary the plan made); the interfaces' zones are improved with
    /// them too.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Coarse tets, band tets and band vertices (for the report).
    pub fn sizes(&self) -> (usize, usize, usize) {
        (
            self.coarse.mesh.tets.len(),
            self.band.n_tets,
            self.band.mesh.vertices.len(),
        )
    }
}

/// Prepares the partition of `input` into `parts` parts. In approximate mode the surface is
/// made once here (`approx::boundary_only`: the new boundary and the cells' automatic spacing
/// graded from it) and the parts mesh that boundary in keep mode.
pub fn plan<'s>(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&'s dyn Spacing>,
    parts: usize,
) -> Result<Plan<'s>, MeshError> {
    plan_attempt(input, params, spacing, parts, 0)
}

/// How many partitions [`plan_attempt`] tries.
pub const PLAN_ATTEMPTS: u32 = 3;

/// The cut's shift along the Hilbert order per attempt (fractions of a part's share).
const CUT_SHIFTS: [f64; PLAN_ATTEMPTS as usize] = [0.0, -0.2, 0.2];

/// [`plan`] with the cuts between the parts moved by attempt number (0: `plan`'s; 1 and 2:
/// moved back and forth by a fifth of a part's share). For another try when a part could not
/// be meshed: a part's refinement can fail next to its frozen interface (a boundary element
/// that no point may split without removing an interface triangle), and elsewhere the
/// interface meets the boundary otherwise.
pub fn plan_attempt<'s>(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&'s dyn Spacing>,
    parts: usize,
    attempt: u32,
) -> Result<Plan<'s>, MeshError> {
    let cut_shift = *CUT_SHIFTS.get(attempt as usize).ok_or_else(|| {
        MeshError::InvalidInput(format!("plan attempt {attempt} of {PLAN_ATTEMPTS}"))
    })?;
    if parts == 0 {
        return Err(MeshError::InvalidInput(
            "a partition needs at least one part".into(),
        ));
    }
    let (boundary, spacing, params) = match params.surface_mode {
        SurfaceMode::Keep => {
            let spacing = match spacing {
                Some(s) => PartSpacing::Given(s),
                None => PartSpacing::Auto(crate::refine::auto_spacing(input, params)?),
            };
            (None, spacing, params.clone())
        }
        SurfaceMode::Approximate => {
            let (boundary, auto) = crate::approx::boundary_only(input, params, spacing)?;
            let spacing = match (spacing, auto) {
                (Some(s), _) => PartSpacing::Given(s),
                (None, Some(a)) => PartSpacing::Auto(a),
                (None, None) => PartSpacing::Auto(crate::refine::auto_spacing(&boundary, params)?),
            };
            let keep = Params {
                surface_mode: SurfaceMode::Keep,
                ..params.clone()
            };
            (Some(boundary), spacing, keep)
        }
    };
    let input = boundary.as_ref().unwrap_or(input);
    let coarse = Coarse::new(input, &params, spacing.get(), parts, cut_shift)?;
    let band = Band::new(&coarse, &params, spacing.get())?;
    Ok(Plan {
        params,
        spacing,
        coarse,
        band,
    })
}

/// What meshing one part needs once its PLC is built: [`Plan::into_part`] gives it without
/// the coarse mesh and the band, so a rank does not hold them while it refines.
pub struct PartPlan<'s> {
    params: Params,
    spacing: PartSpacing<'s>,
    plc: part_plc::PartPlc,
}

impl<'s> Plan<'s> {
    /// Part `part`'s share of the plan, the rest of the plan dropped.
    pub fn into_part(self, part: usize) -> Result<PartPlan<'s>, MeshError> {
        let plc = self.part_plc(part)?;
        Ok(PartPlan {
            params: self.params,
            spacing: self.spacing,
            plc,
        })
    }

    fn part_plc(&self, part: usize) -> Result<part_plc::PartPlc, MeshError> {
        if part >= self.parts() {
            return Err(MeshError::InvalidInput(format!(
                "part {part} of a plan of {} parts",
                self.parts()
            )));
        }
        part_plc::build(&self.coarse, &self.band, part)
    }
}

impl PartPlan<'_> {
    /// Meshes the part (as [`mesh_part`]).
    pub fn mesh(self) -> Result<MeshedPart, MeshError> {
        mesh_plc(self.plc, &self.params, self.spacing.get())
    }
}

/// Meshes part `part` of `plan`: its tets, vertices numbered from 0, region attributes, and
/// the domain's boundary and region-interface triangles (with markers) that are faces of its
/// tets; the interface triangles it shares with other parts are the band's. The report's
/// region figures are left to [`measure_part`], once the interfaces have moved.
pub fn mesh_part(plan: &Plan, part: usize) -> Result<MeshedPart, MeshError> {
    mesh_plc(plan.part_plc(part)?, &plan.params, plan.spacing.get())
}

fn mesh_plc(
    plc: part_plc::PartPlc,
    params: &Params,
    spacing: &dyn Spacing,
) -> Result<MeshedPart, MeshError> {
    let part_plc::PartPlc {
        input,
        frozen,
        on_facets,
    } = plc;
    let refine_params = Params {
        improve: false,
        ..params.clone()
    };
    let (mesh, mut report) = crate::refine::mesh_frozen(
        &input,
        &refine_params,
        Some(spacing),
        &frozen,
        crate::refine::Unseeded::Hole,
    )?;
    // Improved with its PLC's facets and their vertices (the isolated ones, last, are free to
    // move like Steiner vertices): the interface's vertices are input vertices (fixed) and
    // each of its triangles a facet of its own (no flip joins two), so it stays the band's;
    // Steiner vertices on the domain's facets slide in them.
    let facets_only = PlcInput {
        vertices: input.vertices[..on_facets].to_vec(),
        ..input
    };
    let frozen_corners: FxHashSet<Corners> = (frozen.iter())
        .map(|&f| {
            zone::corners(
                &facets_only.facets[f as usize].polygons[0],
                &facets_only.vertices,
            )
        })
        .collect();
    let mut mesh = crate::pipeline::improve(mesh, &mut report, Some(&facets_only), params)?;
    if !report.improvement.changed() {
        // `mesh_frozen` without improvement leaves the shape figures unmeasured: the report
        // would say 0 degrees for a part that needed no improvement.
        report.measure_shapes(&mesh);
    }
    let interface: Vec<[u32; 3]> = (mesh.boundary.iter())
        .filter(|b| frozen_corners.contains(&zone::corners(&b[..], &mesh.vertices)))
        .copied()
        .collect();
    mesh.remove_boundary_marker(INTERFACE_MARKER);
    Ok(MeshedPart {
        mesh,
        report,
        interface,
    })
}

/// The report's shape and region figures for the part's final mesh.
pub fn measure_part(report: &mut Report, mesh: &TetMesh) {
    report.measure_shapes(mesh);
    report.measure_regions(mesh);
}
