//! [`Mesher`]: a domain, parameters, a spacing and a progress callback in; a mesh and its report
//! out.

use super::error::{invalid, Error};
use super::output::MeshOutput;
use super::params::{get_param, set_param, Params};
use super::spacing::{valid_value, Checked, SpacingChoice};
use crate::geom::MAX_COORD;
use crate::mesh::TetMesh;
use crate::parallel::SplitSpacing;
use crate::plc::{Facet, PlcInput, Region};
use crate::run::error::MeshError;
use crate::run::progress::Progress;
use crate::run::report::Report;
use crate::run::spacing::{ConstantSpacing, FnSpacing, Spacing};
use glam::DVec3;
use std::path::Path;

/// A boxed progress callback: (fraction done in [0, 1], vertex count) -> keep going?
pub type ProgressFn = Box<dyn FnMut(f64, usize) -> bool + Send>;

/// Builds a domain, runs the mesher, holds the result.
///
/// ```no_run
/// use slivermesh::api::Mesher;
/// use slivermesh::DVec3;
/// let mut m = Mesher::new();
/// m.add_vertices(&[DVec3::ZERO, DVec3::X, DVec3::Y, DVec3::Z])?
///     .add_facet(&[0, 2, 1], 1)?
///     .add_facet(&[0, 1, 3], 2)?
///     .add_facet(&[1, 2, 3], 3)?
///     .add_facet(&[0, 3, 2], 4)?
///     .set_param("rho0", 1.8)?
///     .set_spacing_fn(|p: DVec3| 0.05 + 0.1 * p.length());
/// let report = m.refine()?;
/// println!("{} tets, min dihedral {:.1} deg", report.n_tets, report.min_dihedral_deg);
/// m.write("tet.vtu".as_ref())?;
/// # Ok::<(), slivermesh::api::Error>(())
/// ```
///
/// Builder arguments are checked when given (coordinates finite and within
/// `geom::MAX_COORD`, vertex ids below the number of vertices added so far, parameter names and
/// ranges); the domain as a whole (planarity, intersections) is checked by [`Mesher::refine`].
/// Every setter of the domain, the parameters or the spacing discards a previous result: outputs
/// always match the current input and settings.
#[derive(Default)]
pub struct Mesher {
    input: PlcInput,
    /// An existing mesh whose slivers `refine` removes instead of meshing `input`.
    existing: Option<TetMesh>,
    params: Params,
    spacing: SpacingChoice,
    progress: Option<ProgressFn>,
    output: Option<MeshOutput>,
}

impl std::fmt::Debug for Mesher {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("Mesher")
            .field("input", &self.input)
            .field("existing", &self.existing)
            .field("params", &self.params)
            .field("spacing", &self.spacing)
            .field("progress", &self.progress.as_ref().map(|_| ".."))
            .field("output", &self.output)
            .finish()
    }
}

fn check_point(what: &str, p: DVec3) -> Result<(), Error> {
    if !p.is_finite() {
        return invalid(format!(
            "{what} has a non-finite coordinate ({}, {}, {})",
            p.x, p.y, p.z
        ));
    }
    if p.abs().max_element() > MAX_COORD {
        return invalid(format!(
            "{what} ({}, {}, {}) is outside the accepted range |coordinate| <= {MAX_COORD:e}",
            p.x, p.y, p.z
        ));
    }
    Ok(())
}

impl Mesher {
    /// An empty domain with default parameters and automatic spacing.
    pub fn new() -> Self {
        Self::default()
    }

    /// A mesher for an existing domain description (e.g. from `io::read_plc`); its coordinates
    /// and ids are checked like those given through the builder.
    pub fn from_plc(input: PlcInput) -> Result<Self, Error> {
        let mut m = Mesher::new();
        m.add_vertices(&input.vertices)?;
        for (i, f) in input.facets.iter().enumerate() {
            for poly in f.polygons.iter().chain(&f.hole_polygons) {
                m.check_ids(&format!("facet {i}"), poly, 1)?;
            }
            for &p in &f.hole_points {
                check_point(&format!("facet {i} hole point"), p)?;
            }
        }
        for &h in &input.holes {
            m.add_hole(h)?;
        }
        for r in &input.regions {
            m.add_region(r.point, r.attribute, r.max_size.unwrap_or(0.0))?;
        }
        m.input = input;
        Ok(m)
    }

    /// Replaces the parameters wholesale.
    pub fn with_params(mut self, params: Params) -> Self {
        self.params = params;
        self.output = None;
        self
    }

    fn changed(&mut self) -> &mut Self {
        self.output = None;
        self
    }

    fn check_ids(&self, what: &str, ids: &[u32], min_len: usize) -> Result<(), Error> {
        if ids.len() < min_len {
            return invalid(format!(
                "{what} has {} vertices; a polygon needs at least {min_len}",
                ids.len()
            ));
        }
        let n = self.input.vertices.len();
        if let Some((k, &id)) = ids.iter().enumerate().find(|(_, &id)| id as usize >= n) {
            return invalid(format!(
                "{what}: vertex id {id} (position {k} in the polygon) is out of range: \
                 {n} vertices have been added (ids are 0-based)"
            ));
        }
        Ok(())
    }

    /// Appends vertices; their ids continue from the number already added (0-based, in order).
    /// All-or-nothing: a non-finite or out-of-range coordinate rejects the whole batch.
    pub fn add_vertices(&mut self, points: &[DVec3]) -> Result<&mut Self, Error> {
        let base = self.input.vertices.len();
        if base + points.len() > u32::MAX as usize {
            return invalid(format!(
                "too many vertices: {} + {} exceeds the id range (u32)",
                base,
                points.len()
            ));
        }
        for (i, &p) in points.iter().enumerate() {
            check_point(&format!("vertex {} (index {i} in this batch)", base + i), p)?;
        }
        self.input.vertices.extend_from_slice(points);
        Ok(self.changed())
    }

    /// Appends a planar polygonal facet (vertex ids in order around it, at least 3) carrying
    /// `marker` onto its boundary triangles.
    pub fn add_facet(&mut self, ids: &[u32], marker: i32) -> Result<&mut Self, Error> {
        let what = format!("facet {}", self.input.facets.len());
        self.check_ids(&what, ids, 3)?;
        self.input.facets.push(Facet {
            polygons: vec![ids.to_vec()],
            marker,
            ..Facet::default()
        });
        Ok(self.changed())
    }

    /// Adds a hole polygon to the last facet added.
    pub fn add_facet_hole(&mut self, ids: &[u32]) -> Result<&mut Self, Error> {
        let Some(last) = self.input.facets.len().checked_sub(1) else {
            return invalid("facet hole given before any facet: add the facet first");
        };
        self.check_ids(&format!("hole polygon of facet {last}"), ids, 3)?;
        self.input.facets[last].hole_polygons.push(ids.to_vec());
        Ok(self.changed())
    }

    /// Adds a volume hole seed: the connected component holding `p` is not meshed.
    pub fn add_hole(&mut self, p: DVec3) -> Result<&mut Self, Error> {
        check_point(&format!("hole {}", self.input.holes.len()), p)?;
        self.input.holes.push(p);
        Ok(self.changed())
    }

    /// Adds a region seed: tets of the component holding `p` get `attribute`; `max_size` > 0
    /// (and finite) limits their size, <= 0 or +inf means no limit.
    pub fn add_region(
        &mut self,
        p: DVec3,
        attribute: i32,
        max_size: f64,
    ) -> Result<&mut Self, Error> {
        let what = format!("region {}", self.input.regions.len());
        check_point(&what, p)?;
        if max_size.is_nan() {
            return invalid(format!("{what}: max_size is NaN"));
        }
        self.input.regions.push(Region {
            point: p,
            attribute,
            max_size: (max_size > 0.0 && max_size.is_finite()).then_some(max_size),
        });
        Ok(self.changed())
    }

    /// Sets a parameter by name (see [`super::params::set_param`] for names and ranges).
    pub fn set_param(&mut self, name: &str, value: f64) -> Result<&mut Self, Error> {
        set_param(&mut self.params, name, value)?;
        Ok(self.changed())
    }

    /// Reads a parameter by name.
    pub fn param(&self, name: &str) -> Result<f64, Error> {
        get_param(&self.params, name)
    }

    /// Automatic (local-feature-size based) spacing: the default.
    pub fn set_spacing_automatic(&mut self) -> &mut Self {
        self.spacing = SpacingChoice::Automatic;
        self.changed()
    }

    /// The same target element size `h` (finite, > 0) everywhere.
    pub fn set_spacing_constant(&mut self, h: f64) -> Result<&mut Self, Error> {
        if !valid_value(h) {
            return invalid(format!("constant spacing h = {h}: must be finite and > 0"));
        }
        self.spacing = SpacingChoice::Constant(h);
        Ok(self.changed())
    }

    /// A spacing function given as a closure. A value that is not finite and positive makes
    /// [`Mesher::refine`] fail with [`MeshError::BadSpacing`] naming the point.
    pub fn set_spacing_fn<F: Fn(DVec3) -> f64 + Send + 'static>(&mut self, f: F) -> &mut Self {
        self.set_spacing(FnSpacing(f))
    }

    /// Any [`Spacing`] implementation (override `at_many` for batched evaluation).
    pub fn set_spacing<S: Spacing + Send + 'static>(&mut self, s: S) -> &mut Self {
        self.spacing = SpacingChoice::Custom(Box::new(s));
        self.changed()
    }

    /// A spacing that may be evaluated from several threads at once: like [`Self::set_spacing`],
    /// but its batches of 512 points or more (the first classification, the report's
    /// figures) are split across the run's threads (parameter `threads`). The values, and the
    /// mesh, are the same.
    pub fn set_spacing_sync<S: Spacing + Send + Sync + 'static>(&mut self, s: S) -> &mut Self {
        self.spacing = SpacingChoice::Shared(Box::new(s));
        self.changed()
    }

    /// Limits the spacing in the region of attribute `id` to at most `h` (finite, > 0): its tets
    /// get the smaller of `h` and the spacing there (CLI `--region-size ID:H`). Given again
    /// for the same id, the new `h` replaces the old. An id the input has no region of fails
    /// [`Mesher::refine`], naming the id and listing the input's regions.
    pub fn set_region_size(&mut self, id: i32, h: f64) -> Result<&mut Self, Error> {
        if !valid_value(h) {
            return invalid(format!(
                "region size for region {id}: h = {h} must be finite and > 0"
            ));
        }
        let sizes = &mut self.params.region_sizes;
        match sizes.iter_mut().find(|(i, _)| *i == id) {
            Some(entry) => entry.1 = h,
            None => sizes.push((id, h)),
        }
        Ok(self.changed())
    }

    /// Limits the spacing near the input facets of boundary marker `id` (`h` finite and
    /// positive): within a distance `h` of them the spacing is at most `h`, farther away at
    /// most `h + MARKER_GRADING * (distance - h)` ([`crate::refine::MARKER_GRADING`], 0.5),
    /// the smaller of that and the spacing there (CLI `--marker-size ID:H`). Given again for
    /// the same id, the new `h` replaces the old. An id no input facet has fails
    /// [`Mesher::refine`], naming the id and listing the input's markers.
    pub fn set_marker_size(&mut self, id: i32, h: f64) -> Result<&mut Self, Error> {
        if !valid_value(h) {
            return invalid(format!(
                "marker size for marker {id}: h = {h} must be finite and > 0"
            ));
        }
        let sizes = &mut self.params.marker_sizes;
        match sizes.iter_mut().find(|(i, _)| *i == id) {
            Some(entry) => entry.1 = h,
            None => sizes.push((id, h)),
        }
        Ok(self.changed())
    }

    /// Called with (fraction done, vertex count), once with 0 before any work and then as the
    /// refiner reports; returning `false` cancels the run ([`MeshError::Cancelled`]).
    pub fn set_progress<F: FnMut(f64, usize) -> bool + Send + 'static>(
        &mut self,
        f: F,
    ) -> &mut Self {
        self.progress = Some(Box::new(f));
        self
    }

    /// Removes the progress callback.
    pub fn clear_progress(&mut self) -> &mut Self {
        self.progress = None;
        self
    }

    /// Makes `refine` remove the slivers of `mesh` instead of meshing the domain
    /// (`pipeline::remove_slivers`): its boundary and interface triangles are kept with their
    /// markers, its regions and holes too, and the tets between are refined and improved to
    /// the parameters' bounds (keep mode only; the spacing is the mesh's own). Checks that every
    /// vertex is finite and in range and every id names a vertex; `refine` checks the rest
    /// (orientation, a closed boundary).
    pub fn set_existing_mesh(&mut self, mesh: TetMesh) -> Result<&mut Self, Error> {
        for (i, &p) in mesh.vertices.iter().enumerate() {
            check_point(&format!("existing mesh vertex {i}"), p)?;
        }
        let n = mesh.vertices.len() as u64;
        let bad_tet = mesh
            .tets
            .iter()
            .position(|t| t.iter().any(|&v| v as u64 >= n));
        if let Some(t) = bad_tet {
            return invalid(format!(
                "existing mesh tet {t} {:?} names a vertex beyond the {n} given",
                mesh.tets[t]
            ));
        }
        let bad_tri = mesh
            .boundary
            .iter()
            .position(|t| t.iter().any(|&v| v as u64 >= n));
        if let Some(t) = bad_tri {
            return invalid(format!(
                "existing mesh boundary triangle {t} {:?} names a vertex beyond the {n} given",
                mesh.boundary[t]
            ));
        }
        if mesh.tet_regions.len() != mesh.tets.len()
            || mesh.boundary_markers.len() != mesh.boundary.len()
        {
            return invalid(format!(
                "existing mesh: {} regions for {} tets, {} markers for {} boundary triangles",
                mesh.tet_regions.len(),
                mesh.tets.len(),
                mesh.boundary_markers.len(),
                mesh.boundary.len()
            ));
        }
        self.existing = Some(mesh);
        self.output = None;
        Ok(self)
    }

    /// Meshes the domain with the stored spacing and progress callback: `pipeline::mesh`, in the
    /// parameters' `surface_mode` (default keep), then the improvement pass (`improve`).
    pub fn refine(&mut self) -> Result<&Report, Error> {
        self.refine_with(None, None)
    }

    /// Meshes the domain; `spacing` / `progress`, when given, are used instead of the stored ones
    /// for this run (borrowed, so they need not be `Send` nor `'static`: the C ABI passes its
    /// callbacks this way).
    ///
    /// Before meshing, the spacing is evaluated at every input vertex (one batch) and the
    /// progress callback is called with (0, number of input vertices). A spacing value that is
    /// not finite and positive anywhere during the run fails it with [`MeshError::BadSpacing`];
    /// a progress callback that returned `false` at any point fails it with
    /// [`MeshError::Cancelled`]. On error the previous result is gone as well.
    pub fn refine_with(
        &mut self,
        spacing: Option<&dyn Spacing>,
        mut progress: Option<Progress>,
    ) -> Result<&Report, Error> {
        self.output = None;
        let (constant, split);
        let chosen: Option<&dyn Spacing> = match (spacing, &self.spacing) {
            (Some(s), _) => Some(s),
            (None, SpacingChoice::Automatic) => None,
            (None, SpacingChoice::Constant(h)) => {
                constant = ConstantSpacing(*h);
                Some(&constant)
            }
            (None, SpacingChoice::Custom(s)) => Some(s.as_ref()),
            (None, SpacingChoice::Shared(s)) => {
                split = SplitSpacing(s.as_ref());
                Some(&split)
            }
        };
        let checked = chosen.map(Checked::new);
        let stored = &mut self.progress;
        let mut cancelled = false;
        let mut relay = |fraction: f64, n: usize| -> bool {
            let go = match (progress.as_deref_mut(), stored.as_deref_mut()) {
                (Some(p), _) => p(fraction, n),
                (None, Some(p)) => p(fraction, n),
                (None, None) => true,
            };
            cancelled |= !go;
            go
        };

        let result = (|| {
            if !relay(0.0, self.input.vertices.len()) {
                return Err(MeshError::Cancelled);
            }
            if let Some(existing) = &self.existing {
                return crate::pipeline::remove_slivers(existing, &self.params);
            }
            if let Some(c) = &checked {
                c.precheck(&self.input.vertices)?;
            }
            crate::pipeline::mesh(
                &self.input,
                &self.params,
                checked.as_ref().map(|c| c as &dyn Spacing),
                Some(&mut relay),
            )
        })();
        let bad_spacing = checked.as_ref().and_then(Checked::error);
        let result = match (result, bad_spacing) {
            (Err(e @ MeshError::BadSpacing { .. }), _) => Err(e),
            (_, Some(e)) => Err(e),
            (Ok(_), None) if cancelled => Err(MeshError::Cancelled),
            (r, None) => r,
        };
        let (mesh, quadratic, report) = result?;
        Ok(&self
            .output
            .insert(MeshOutput {
                mesh,
                quadratic,
                report,
            })
            .report)
    }

    /// The domain as given so far.
    pub fn input(&self) -> &PlcInput {
        &self.input
    }

    /// The current parameters.
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// The current spacing choice.
    pub fn spacing(&self) -> &SpacingChoice {
        &self.spacing
    }

    /// The result of the last successful refine, if still current.
    pub fn output(&self) -> Option<&MeshOutput> {
        self.output.as_ref()
    }

    /// The mesh of the last successful refine.
    pub fn mesh(&self) -> Result<&TetMesh, Error> {
        self.output
            .as_ref()
            .map(|o| &o.mesh)
            .ok_or(Error::NotRefined)
    }

    /// The report of the last successful refine.
    pub fn report(&self) -> Result<&Report, Error> {
        self.output
            .as_ref()
            .map(|o| &o.report)
            .ok_or(Error::NotRefined)
    }

    /// Takes the result out, leaving the mesher without one.
    pub fn take_output(&mut self) -> Option<MeshOutput> {
        self.output.take()
    }

    /// Writes the mesh (format by extension) with per-tet quality as cell data.
    pub fn write(&self, path: &Path) -> Result<(), Error> {
        self.write_in(path, false)
    }

    /// [`Self::write`], in the format's binary form where it has one and `binary` is set
    /// (.msh: gmsh 4.1 binary; .vtu: binary appended arrays).
    pub fn write_in(&self, path: &Path, binary: bool) -> Result<(), Error> {
        self.output
            .as_ref()
            .ok_or(Error::NotRefined)?
            .write_in(path, binary)
    }

    /// Installs a result meshed elsewhere (a distributed run's part, the tests of the output
    /// paths).
    #[cfg(any(test, feature = "mpi"))]
    pub(crate) fn install_output(&mut self, mesh: TetMesh, report: Report) {
        self.output = Some(MeshOutput {
            mesh,
            quadratic: None,
            report,
        });
    }
}
