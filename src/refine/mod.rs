//! Li's REMOVE-SLIVER refinement (the paper, section 3) on top of the Delaunay kernel:
//! boundary recovery (empty encroachment), domain marking, then cleaning of size-bad,
//! radius-edge-bad and sliver tets from random points of picking regions.

pub mod background;
#[cfg(test)]
mod check;
mod domain;
pub mod existing;
pub(crate) mod levels;
mod mark;
mod marker_size;
pub(crate) mod outcome;
mod output;
mod plc_level;
mod quality;
pub(crate) mod queue;
mod recover;
pub mod report;
mod spacing;

pub(crate) use mark::unknown_region;
pub use mark::Unseeded;
pub use marker_size::{MarkerCapped, MarkerCaps, MARKER_GRADING};
pub use quality::SPACING_BATCH;
pub use spacing::AutoSpacing;

use crate::mesh::TetMesh;
use crate::plc::PlcInput;
use crate::run::error::MeshError;
use crate::run::params::Params;
use crate::run::progress::Progress;
use crate::run::report::{Refusals, Report};
use crate::run::spacing::Spacing;
use recover::Settled;
use rustc_hash::FxHashSet;

/// The region of every tet slot as the output would give it: its attribute, None outside the
/// domain (and for dead slots).
fn tet_labels(dom: &domain::Domain, regions: &mark::Regions) -> Vec<Option<i32>> {
    (0..dom.dt.tet_capacity() as u32)
        .map(|t| {
            let tag = if dom.dt.is_alive(t) { dom.dt.tag(t) } else { 0 };
            (tag != 0).then(|| regions.attribute[tag as usize])
        })
        .collect()
}

/// Meshes a domain: validation, boundary recovery, marking, and (if `params.refine`) quality
/// refinement. `spacing` None = automatic (local-feature-size based) spacing.
pub fn mesh(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
) -> Result<(TetMesh, Report), MeshError> {
    mesh_domain(input, params, spacing, progress, Choices::plc())
}

/// [`mesh`] with `frozen` facets (indices into `input.facets`) never split nor flipped: no
/// point goes where its cavity would remove one of their triangles, and bad tets that would
/// need one are left (`Refusals::frozen_interface`). For a partition's interfaces
/// (`crate::partition`): each side meshed alone keeps the same triangles there. Delaunay ties
/// are broken by the points' coordinates, so that every mesh holding some of the same points
/// breaks them alike. `unseeded`: what a component without a region seed becomes (`Unseeded::Hole` for a set of
/// tets, whose pieces are all seeded).
pub fn mesh_frozen(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    frozen: &[u32],
    unseeded: Unseeded,
) -> Result<(TetMesh, Report), MeshError> {
    let choices = Choices {
        unseeded,
        frozen,
        ties_by_coordinates: true,
        ..Choices::plc()
    };
    mesh_domain(input, params, spacing, None, choices)
}

/// [`mesh_frozen`], also giving per vertex of the mesh the input segment it was inserted on
/// (its end vertices), if any.
pub fn mesh_frozen_tracing_segments(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    frozen: &[u32],
    unseeded: Unseeded,
) -> Result<(TetMesh, Report, SegmentEnds), MeshError> {
    let mut ends = vec![];
    let choices = Choices {
        unseeded,
        frozen,
        segment_ends: Some(&mut ends),
        ties_by_coordinates: true,
        ..Choices::plc()
    };
    let (mesh, report) = mesh_domain(input, params, spacing, None, choices)?;
    Ok((mesh, report, ends))
}

/// The automatic spacing of `input` ([`mesh`]'s with no spacing given): the Lipschitz
/// extension of its recovered boundary's edge lengths.
pub fn auto_spacing(input: &PlcInput, params: &Params) -> Result<AutoSpacing, MeshError> {
    params.check().map_err(MeshError::InvalidInput)?;
    let plc = crate::plc::validate(input).map_err(|e| MeshError::InvalidInput(e.to_string()))?;
    let mut dom = domain::Domain::new(input, &plc)?;
    dom.set_input_angles(&plc, params.small_angle_reach);
    let mut budget = recover::MAX_RECOVERY_SPLITS.min(params.max_vertices.saturating_mul(4));
    if dom.recover_boundary(&mut budget)? == Settled::BudgetSpent {
        return Err(recovery_budget_spent(params));
    }
    Ok(AutoSpacing::from_boundary(&dom))
}

/// Per vertex, the input segment (its end vertices) it was inserted on, if any.
pub type SegmentEnds = Vec<Option<[u32; 2]>>;

/// How [`mesh_domain`] treats its input.
struct Choices<'a> {
    small_angles: SmallAngles,
    unseeded: Unseeded,
    /// Facets never split nor flipped (`Domain::frozen`).
    frozen: &'a [u32],
    /// Where to put each vertex's input segment.
    segment_ends: Option<&'a mut SegmentEnds>,
    /// Delaunay ties broken by coordinates (`Domain::new_with_ties`).
    ties_by_coordinates: bool,
}

impl Choices<'_> {
    /// A PLC's: its small angles, unseeded cells in the domain, nothing frozen.
    fn plc() -> Self {
        Choices {
            small_angles: SmallAngles::Input,
            unseeded: Unseeded::Domain,
            frozen: &[],
            segment_ends: None,
            ties_by_coordinates: false,
        }
    }
}

/// Which input angles refinement treats as small.
#[derive(Clone, Copy)]
enum SmallAngles {
    /// Those the validator finds (keep mode).
    Input,
    /// None (the boundary of an existing mesh).
    None,
}

/// [`mesh`], optionally treating every input angle as large (for the boundary of an existing
/// mesh, whose flat sides are tiled by triangles meeting at angles that are not features), and
/// with a choice for components without a region seed (an existing mesh seeds all its pieces:
/// the others are holes).
fn mesh_domain(
    input: &PlcInput,
    params: &Params,
    spacing: Option<&dyn Spacing>,
    progress: Option<Progress>,
    choices: Choices,
) -> Result<(TetMesh, Report), MeshError> {
    let Choices {
        small_angles,
        unseeded,
        frozen,
        segment_ends,
        ties_by_coordinates,
    } = choices;
    let start = std::time::Instant::now();
    params.check().map_err(MeshError::InvalidInput)?;
    let plc = crate::plc::validate(input).map_err(|e| MeshError::InvalidInput(e.to_string()))?;
    let marker_caps = if params.marker_sizes.is_empty() {
        None
    } else {
        let surface = crate::surface::InputSurface::from_plc(&plc);
        MarkerCaps::new(&surface, &params.marker_sizes)?
    };
    let mut dom = domain::Domain::new_with_ties(input, &plc, ties_by_coordinates)?;
    if let Some(&f) = frozen.iter().find(|&&f| f as usize >= input.facets.len()) {
        return Err(MeshError::InvalidInput(format!(
            "frozen facet {f}: the input has {} facets",
            input.facets.len()
        )));
    }
    dom.freeze_facets(frozen);
    match small_angles {
        SmallAngles::Input => dom.set_input_angles(&plc, params.small_angle_reach),
        SmallAngles::None => {}
    }
    let mut budget = recover::MAX_RECOVERY_SPLITS.min(params.max_vertices.saturating_mul(4));
    if dom.recover_boundary(&mut budget)? == Settled::BudgetSpent {
        return Err(recovery_budget_spent(params));
    }
    let mut regions = dom.mark_domain(&plc, unseeded)?;
    regions.limit_sizes(&params.region_sizes)?;
    let seconds_recovery = start.elapsed().as_secs_f64();
    let (auto, split_auto);
    let spacing: &dyn Spacing = match spacing {
        Some(s) => s,
        None => {
            auto = spacing::AutoSpacing::from_boundary(&dom);
            split_auto = crate::parallel::SplitSpacing(&auto);
            &split_auto
        }
    };
    let capped;
    let spacing: &dyn Spacing = match &marker_caps {
        Some(caps) => {
            capped = MarkerCapped {
                inner: spacing,
                caps: Some(caps),
            };
            &capped
        }
        None => spacing,
    };
    let mut passes = Passes::default();
    if params.refine {
        let mut ctx = PassContext {
            plc: &plc,
            params,
            spacing,
            unseeded,
            budget: &mut budget,
        };
        passes = refine_passes(&mut dom, &mut ctx, &mut regions, progress)?;
    }
    let Passes {
        mut stop_reason,
        blocked,
        n_relabelled,
        refusals,
    } = passes;
    let seconds_refinement = start.elapsed().as_secs_f64() - seconds_recovery;
    dom.check_frozen_present()?;
    let mesh = dom.to_mesh(&regions);
    if let Some(ends) = segment_ends {
        *ends = (dom.kind.iter())
            .map(|k| match *k {
                domain::VertexKind::Segment(s) => Some(dom.segments[s as usize].ends),
                _ => None,
            })
            .collect();
    }
    // The triangulation is freed before the report measures the mesh: the two together were
    // the run's peak memory.
    let acute: Vec<bool> = (0..mesh.vertices.len() as u32)
        .map(|v| dom.influenced_by_acute_angle(v))
        .collect();
    let n_acute_angles = dom.acute_vertices.len();
    drop(dom);
    let near_acute = |t: &[u32; 4]| {
        t.iter().any(|&v| acute[v as usize]) || blocked.contains(&quality::sorted4(*t))
    };
    let (mut report, bad_elsewhere) = report::measure(&mesh, spacing, params, &near_acute)?;
    report.seconds_recovery = seconds_recovery;
    report.seconds_refinement = seconds_refinement;
    report.seconds_total = start.elapsed().as_secs_f64();
    report.n_acute_angles = n_acute_angles;
    report.n_relabelled = n_relabelled;
    report.refusals = refusals;
    report.complete = stop_reason.is_none() && (bad_elsewhere == 0 || !params.refine);
    if params.refine && stop_reason.is_none() && bad_elsewhere > 0 {
        stop_reason = Some(format!(
            "{bad_elsewhere} tets away from acute input angles still violate a bound"
        ));
    }
    report.stop_reason = stop_reason;
    report.input_regions = Some(plc.input_regions());
    Ok((mesh, report))
}

/// What the refinement passes leave for the report.
#[derive(Default)]
struct Passes {
    /// Why refinement stopped early, if it did.
    stop_reason: Option<String>,
    /// Bad tets left within a small angle's influence (sorted vertex quadruples).
    blocked: FxHashSet<[u32; 4]>,
    /// Tets whose region the check after refinement corrected (`Report::n_relabelled`).
    n_relabelled: usize,
    /// Bad tets refinement left alone, per reason (`Report::refusals`).
    refusals: Refusals,
}

/// Boundary recovery (before refinement, or the check after it) ran out of splits: there is
/// no conforming mesh to report on. The budget is 4 x `max_vertices` when that is the smaller
/// one, else the safety net against a recovery that cannot terminate.
fn recovery_budget_spent(params: &Params) -> MeshError {
    let limit = recover::MAX_RECOVERY_SPLITS;
    MeshError::InvalidInput(if params.max_vertices.saturating_mul(4) < limit {
        format!(
            "boundary recovery needs more than {} splits (4 x max_vertices = {}): \
             max_vertices is too small for this input",
            params.max_vertices.saturating_mul(4),
            params.max_vertices
        )
    } else {
        format!(
            "boundary recovery did not finish within {limit} splits (an input angle too \
             small to protect in floating point?)"
        )
    })
}

/// The inputs of [`refine_passes`].
struct PassContext<'a> {
    plc: &'a crate::plc::Plc,
    params: &'a Params,
    spacing: &'a dyn Spacing,
    unseeded: Unseeded,
    budget: &'a mut usize,
}

/// Runs refinement (the bad-tet queues), then checks what it keeps incrementally: the whole
/// boundary is present and unencroached (`recover_boundary` inserts nothing) and every tet
/// carries its region (`Domain::retag_created`: the re-marking from the seeds, which updates
/// `regions`, changes no label). Should the check change something (it never has on the shared
/// models; the tests assert it), one more refinement pass looks at every tet again, and the
/// report counts the relabelled tets.
fn refine_passes(
    dom: &mut domain::Domain,
    ctx: &mut PassContext,
    regions: &mut mark::Regions,
    progress: Option<Progress>,
) -> Result<Passes, MeshError> {
    let mut out = Passes::default();
    let mut noop = |_: f64, _: usize| true;
    let progress: &mut dyn FnMut(f64, usize) -> bool = match progress {
        Some(p) => p,
        None => &mut noop,
    };
    let max_v = ctx.params.max_vertices.max(1) as f64;
    let mut on_step = |n: usize| progress((n as f64 / max_v).min(1.0), n);
    for _ in 0..2 {
        dom.created_log.clear();
        dom.boundary_inserted = false;
        let mut r = quality::Refiner::new(dom, ctx.params, ctx.spacing, regions);
        r.run(&mut on_step)?;
        out.stop_reason = r.stop_reason.take();
        out.blocked.extend(r.blocked_by_small_angle.drain());
        out.refusals.add(&r.refusals);
        let refined = dom.dt.num_vertices();
        let labels = tet_labels(dom, regions);
        if dom.recover_boundary(ctx.budget)? == Settled::BudgetSpent {
            return Err(recovery_budget_spent(ctx.params));
        }
        *regions = dom.mark_domain(ctx.plc, ctx.unseeded)?;
        regions.limit_sizes(&ctx.params.region_sizes)?;
        let relabelled = labels
            .iter()
            .zip(tet_labels(dom, regions))
            .filter(|(old, new)| **old != *new)
            .count();
        out.n_relabelled += relabelled;
        if out.stop_reason.is_some() || (dom.dt.num_vertices() == refined && relabelled == 0) {
            break;
        }
    }
    Ok(out)
}
