//! The figures a run reports: the whole run's [`Report`] and the stage reports it is made of
//! (refinement's [`Refusals`], the improvement's [`ImproveStats`], the approximate mode's
//! [`SurfaceReport`], the regions' [`RegionReport`]), and `Shapes`, the shape figures that
//! refinement's measure and the improvement's re-measure take the same way. The stages fill
//! their parts; `pipeline` (and `approx` for its mode) puts them together.

use crate::geom::TetQuality;
use crate::mesh::TetMesh;

/// What a run achieved.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct Report {
    pub n_vertices: usize,
    pub n_tets: usize,
    pub n_boundary_faces: usize,
    pub seconds_recovery: f64,
    pub seconds_refinement: f64,
    pub seconds_total: f64,
    pub max_rho: f64,
    pub min_sigma: f64,
    pub min_dihedral_deg: f64,
    pub max_dihedral_deg: f64,
    /// Tets with a dihedral angle below 5, 10, 15, 20 degrees.
    pub tets_below_deg: [usize; 4],
    /// max over tets of R / f(circumcentre). This and the edge ratios describe the output
    /// mesh in approximate mode; in keep mode they (and `n_bad_near_acute`) are the refined
    /// mesh's before the improvement, which re-measures only the shape figures there.
    pub max_size_ratio: f64,
    /// edge length / f(midpoint): min, median, max
    pub edge_ratio_min: f64,
    pub edge_ratio_median: f64,
    pub edge_ratio_max: f64,
    /// Acute input angles found (segment pairs < 90 deg, facet pairs < 90 deg).
    pub n_acute_angles: usize,
    /// Tets left violating a bound because they are within the influence of an acute angle.
    pub n_bad_near_acute: usize,
    /// How often refinement left a bad tet as it was, per reason (see [`Refusals`]).
    pub refusals: Refusals,
    /// Tets whose region (or inside/outside status) the check after refinement corrected:
    /// refinement keeps the labels incrementally (`Domain::retag_created`), so this is 0 unless
    /// that invariant broke (then one more pass refined them). 0 on every shared model.
    pub n_relabelled: usize,
    /// Whether every bound holds everywhere it is enforced (false when a budget stopped it).
    pub complete: bool,
    /// Why refinement stopped early, if it did.
    pub stop_reason: Option<String>,
    /// Whether the output is the refinement's Delaunay mesh (false once improvement changed it).
    pub delaunay: bool,
    /// Smallest and largest dihedral angle before improvement, degrees.
    pub dihedral_before_improve_deg: [f64; 2],
    /// Time spent in the improvement pass (included in `seconds_total`).
    pub seconds_improvement: f64,
    /// What the improvement pass did.
    pub improvement: ImproveStats,
    /// Approximate surface mode only: how close the output boundary is to the input surface.
    pub surface: Option<SurfaceReport>,
    /// With `order` 2: the ten-node tets' curving and validity.
    pub quadratic: Option<crate::quadratic::QuadraticReport>,
    /// Per region attribute of the output (sorted): its tets and volume against the input's.
    pub regions: Vec<RegionReport>,
    /// Area of the output faces between tets of different regions, and of the input's.
    pub interface_area: f64,
    pub input_interface_area: f64,
    /// The input's regions, from the surface mode until `measure_regions` compares with them.
    #[serde(skip)]
    pub input_regions: Option<crate::plc::InputRegions>,
}

/// One region of the output (all tets of one attribute) against the input's.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct RegionReport {
    pub attribute: i32,
    pub tets: usize,
    pub volume: f64,
    pub input_volume: f64,
    /// (volume - input_volume) / input_volume.
    pub relative_volume_difference: f64,
}

/// How well the output boundary approximates the input surface (approximate mode).
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct SurfaceReport {
    /// The distance bound the boundary was built to (absolute).
    pub surface_distance: f64,
    /// Sampled one-sided distances: every input point to the output boundary, and back.
    pub hausdorff_input_to_output: f64,
    pub hausdorff_output_to_input: f64,
    /// The largest distance of a point of an input feature edge from the output's feature
    /// edges.
    pub feature_distance: f64,
    /// (output volume - input volume) / input volume.
    pub relative_volume_difference: f64,
    /// Sharp edges, feature polylines, corners and smooth patches found in the input.
    pub n_feature_edges: usize,
    pub n_feature_polylines: usize,
    /// Crease edges and curves left out as noise (short, free-hanging or isolated creases of
    /// a scan: `surface::features`).
    pub n_noise_edges: usize,
    pub n_noise_curves: usize,
    pub n_corners: usize,
    pub n_patches: usize,
    /// Feature corners whose angle (between feature curves, or spanned by a patch) is below
    /// 60 degrees, and the output tets with a vertex in their protecting balls that miss a
    /// bound.
    pub n_small_corners: usize,
    pub n_bad_near_small_corners: usize,
    /// The largest radius-edge ratio of the other tets (the ones `complete` is judged on).
    pub max_rho_away_from_small_corners: f64,
    /// Vertices and triangles of the remeshed boundary.
    pub n_surface_vertices: usize,
    pub n_surface_triangles: usize,
    /// Time spent building the boundary (feature protection and restricted Delaunay facets).
    pub seconds_surface: f64,
    /// With `--repair`: what was wrong with the input and what the output spans. The
    /// Hausdorff distance out->in then leaves the spanned holes out.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub repair: Option<crate::surface::repair::Defects>,
}

/// How many times refinement left a bad tet as it was, per reason (a tet looked at again and
/// left again counts again; many are removed later by other insertions), and how many bad
/// tets a budget left queued. Keep mode, existing meshes, and the approximate mode's cell
/// level.
#[derive(Debug, Clone, Default, PartialEq, Eq, serde::Serialize)]
pub struct Refusals {
    /// The sum of all the counts below.
    pub total: usize,
    /// Refused for a cascade before, left at once when looked at again.
    pub futile: usize,
    /// Flat by construction (three vertices on one segment, four in one facet).
    pub flat_by_construction: usize,
    /// No circumsphere in floating point.
    pub no_circumsphere: usize,
    /// Flat to rounding (the computed circumcentre is outside its own circumsphere).
    pub flat_to_rounding: usize,
    /// Circumcentre outside the domain's box and far away.
    pub far_centre: usize,
    /// Deferred, and its circumcentre outside the domain.
    pub centre_outside_domain: usize,
    /// Within a small input angle's influence.
    pub near_small_angle: usize,
    /// The point to insert was a vertex already.
    pub duplicate: usize,
    /// The circumcentre encroaches a much smaller boundary element (a cascade).
    pub cascade: usize,
    /// The same, the element within a small angle's influence.
    pub cascade_near_small_angle: usize,
    /// Size-bad next to a small angle, its centroid breaking a much smaller boundary element.
    pub centroid_cascade: usize,
    /// The subfacet to split has no circumcentre.
    pub flat_subfacet: usize,
    /// The subfacet's circumcentre lies outside its facet.
    pub subfacet_centre_outside: usize,
    /// The approximate mode's cell level: its point encroached the boundary, which was
    /// refined for it, each of the times allowed.
    pub waited_for_boundary: usize,
    /// Its point would remove a subfacet of a partition's frozen interface.
    pub frozen_interface: usize,
    /// Bad tets still queued when a budget (vertices, or boundary splits) stopped refinement.
    pub budget: usize,
}

impl Refusals {
    /// Counts `n` bad tets left queued by a budget.
    pub(crate) fn count_budget(&mut self, n: usize) {
        self.budget += n;
        self.total += n;
    }

    /// The total and the reasons counted, e.g. "1750 (near_small_angle 1585, cascade 165)".
    pub fn summary(&self) -> String {
        let reasons: Vec<String> = self
            .counts()
            .iter()
            .filter(|(_, n)| *n > 0)
            .map(|(name, n)| format!("{name} {n}"))
            .collect();
        if reasons.is_empty() {
            self.total.to_string()
        } else {
            format!("{} ({})", self.total, reasons.join(", "))
        }
    }

    /// Adds another pass's counts.
    pub fn add(&mut self, o: &Refusals) {
        let Refusals {
            total,
            futile,
            flat_by_construction,
            no_circumsphere,
            flat_to_rounding,
            far_centre,
            centre_outside_domain,
            near_small_angle,
            duplicate,
            cascade,
            cascade_near_small_angle,
            centroid_cascade,
            flat_subfacet,
            subfacet_centre_outside,
            waited_for_boundary,
            frozen_interface,
            budget,
        } = o;
        self.total += total;
        self.futile += futile;
        self.flat_by_construction += flat_by_construction;
        self.no_circumsphere += no_circumsphere;
        self.flat_to_rounding += flat_to_rounding;
        self.far_centre += far_centre;
        self.centre_outside_domain += centre_outside_domain;
        self.near_small_angle += near_small_angle;
        self.duplicate += duplicate;
        self.cascade += cascade;
        self.cascade_near_small_angle += cascade_near_small_angle;
        self.centroid_cascade += centroid_cascade;
        self.flat_subfacet += flat_subfacet;
        self.subfacet_centre_outside += subfacet_centre_outside;
        self.waited_for_boundary += waited_for_boundary;
        self.frozen_interface += frozen_interface;
        self.budget += budget;
    }

    /// The counts by reason (without the total), named as in the JSON report.
    pub fn counts(&self) -> [(&'static str, usize); 16] {
        let Refusals {
            total: _,
            futile,
            flat_by_construction,
            no_circumsphere,
            flat_to_rounding,
            far_centre,
            centre_outside_domain,
            near_small_angle,
            duplicate,
            cascade,
            cascade_near_small_angle,
            centroid_cascade,
            flat_subfacet,
            subfacet_centre_outside,
            waited_for_boundary,
            frozen_interface,
            budget,
        } = *self;
        [
            ("futile", futile),
            ("flat_by_construction", flat_by_construction),
            ("no_circumsphere", no_circumsphere),
            ("flat_to_rounding", flat_to_rounding),
            ("far_centre", far_centre),
            ("centre_outside_domain", centre_outside_domain),
            ("near_small_angle", near_small_angle),
            ("duplicate", duplicate),
            ("cascade", cascade),
            ("cascade_near_small_angle", cascade_near_small_angle),
            ("centroid_cascade", centroid_cascade),
            ("flat_subfacet", flat_subfacet),
            ("subfacet_centre_outside", subfacet_centre_outside),
            ("waited_for_boundary", waited_for_boundary),
            ("frozen_interface", frozen_interface),
            ("budget", budget),
        ]
    }
}

/// What the improvement pass (`improve`) did.
#[derive(Debug, Clone, Default, PartialEq, serde::Serialize)]
pub struct ImproveStats {
    pub edge_removals: usize,
    pub face_removals: usize,
    /// Face removals that took out more than one face.
    pub multi_face_removals: usize,
    pub boundary_flips: usize,
    pub smoothed: usize,
    /// Vertices inserted where flips and smoothing left a tet bad.
    pub insertions: usize,
    /// Free interior vertices removed: contracted onto a neighbour where that did better than
    /// an insertion, or swallowed by an insertion's cavity.
    pub deletions: usize,
    /// Vertices smoothing was tried on (`smoothed` of them moved).
    pub smooth_attempts: usize,
    pub passes: usize,
    /// Tets flat or inverted (exact orient3d <= 0) before the pass.
    pub degenerate_before: usize,
    /// Changes that would have raised the worst angle objective but were refused because a
    /// tet would have exceeded the radius-edge bound (`improve::Options::keep_rho`): where the dihedral
    /// target gave way to rho0.
    pub rho_vetoes: usize,
    /// Changes made although a new tet exceeds the bound, next to where refinement left it
    /// unmet (small input angles): where rho0 gave way to the dihedral target.
    pub rho_yields: usize,
    /// Vertices inserted at (or short of) the circumcentre of a tet over the radius-edge
    /// bound (`improve::Options::repair_rho`).
    pub rho_repairs: usize,
    pub seconds: f64,
    /// Of which planning topological changes, and smoothing.
    pub seconds_plans: f64,
    pub seconds_smooth: f64,
}

impl ImproveStats {
    /// Whether the mesh was changed at all.
    pub fn changed(&self) -> bool {
        self.edge_removals
            + self.face_removals
            + self.multi_face_removals
            + self.boundary_flips
            + self.smoothed
            + self.insertions
            + self.deletions
            + self.rho_repairs
            > 0
    }
}

/// A mesh's counts and shape figures (rho, sigma, dihedral extremes, tets below 5/10/15/20
/// degrees), accumulated tet by tet: the refinement's report and the improvement's re-measure
/// ([`Report::measure_shapes`]) take them the same way.
pub(crate) struct Shapes {
    max_rho: f64,
    min_sigma: f64,
    min_dihedral: f64,
    max_dihedral: f64,
    below: [usize; 4],
}

impl Shapes {
    pub fn new() -> Shapes {
        Shapes {
            max_rho: 0.0,
            min_sigma: f64::INFINITY,
            min_dihedral: 180.0,
            max_dihedral: 0.0,
            below: [0; 4],
        }
    }

    pub fn add(&mut self, q: &TetQuality) {
        self.max_rho = self.max_rho.max(q.rho);
        self.min_sigma = self.min_sigma.min(q.sigma);
        self.min_dihedral = self.min_dihedral.min(q.min_dihedral);
        self.max_dihedral = self.max_dihedral.max(q.max_dihedral);
        for (k, limit) in [5.0, 10.0, 15.0, 20.0].iter().enumerate() {
            if q.min_dihedral < *limit {
                self.below[k] += 1;
            }
        }
    }

    /// Writes the figures, and `mesh`'s counts, into `r` (an empty mesh: sigma and the
    /// smallest dihedral angle 0).
    pub fn write(&self, mesh: &TetMesh, r: &mut Report) {
        let mut used = vec![false; mesh.vertices.len()];
        mesh.tets
            .iter()
            .flatten()
            .for_each(|&v| used[v as usize] = true);
        r.n_vertices = used.iter().filter(|&&u| u).count();
        r.n_tets = mesh.tets.len();
        r.n_boundary_faces = mesh.boundary.len();
        r.max_rho = self.max_rho;
        r.max_dihedral_deg = self.max_dihedral;
        r.tets_below_deg = self.below;
        (r.min_sigma, r.min_dihedral_deg) = if mesh.tets.is_empty() {
            (0.0, 0.0)
        } else {
            (self.min_sigma, self.min_dihedral)
        };
    }
}

impl Report {
    /// Measures each region of `mesh` and its interfaces against the input's regions the
    /// surface mode left in `input_regions` (none: nothing measured).
    pub fn measure_regions(&mut self, mesh: &TetMesh) {
        let Some(input) = self.input_regions.take() else {
            return;
        };
        let mut regions: Vec<RegionReport> = input
            .volumes
            .iter()
            .map(|&(attribute, input_volume)| RegionReport {
                attribute,
                input_volume,
                ..Default::default()
            })
            .collect();
        // Interfaces only where there are two attributes (the face map costs 100 bytes a tet).
        let several = mesh.tet_regions.iter().any(|&a| a != mesh.tet_regions[0]);
        let mut faces: rustc_hash::FxHashMap<[u32; 3], i32> = Default::default();
        let mut interface_area = 0.0;
        for (t, &a) in mesh.tets.iter().zip(&mesh.tet_regions) {
            let p = t.map(|v| mesh.vertices[v as usize]);
            let r = match regions.iter().position(|r| r.attribute == a) {
                Some(r) => r,
                None => {
                    regions.push(RegionReport {
                        attribute: a,
                        ..Default::default()
                    });
                    regions.len() - 1
                }
            };
            regions[r].tets += 1;
            regions[r].volume += (p[1] - p[0]).dot((p[2] - p[0]).cross(p[3] - p[0])) / 6.0;
            for k in (0..4).filter(|_| several) {
                let mut f = [t[(k + 1) % 4], t[(k + 2) % 4], t[(k + 3) % 4]];
                f.sort_unstable();
                if let Some(b) = faces.insert(f, a) {
                    if b != a {
                        let [x, y, z] = f.map(|v| mesh.vertices[v as usize]);
                        interface_area += (y - x).cross(z - x).length() / 2.0;
                    }
                }
            }
        }
        for r in &mut regions {
            r.relative_volume_difference = if r.input_volume > 0.0 {
                (r.volume - r.input_volume) / r.input_volume
            } else {
                f64::NAN
            };
        }
        regions.sort_by_key(|r| r.attribute);
        self.regions = regions;
        self.interface_area = interface_area;
        self.input_interface_area = input.interface_area;
    }

    /// Takes the figures `refine::report::measure` fills in (counts, shapes, sizes, bad tets
    /// near small angles) from `m`, a report it made; the rest of `self` stays.
    pub fn take_measures(&mut self, m: Report) {
        self.n_vertices = m.n_vertices;
        self.n_tets = m.n_tets;
        self.n_boundary_faces = m.n_boundary_faces;
        self.max_rho = m.max_rho;
        self.min_sigma = m.min_sigma;
        self.min_dihedral_deg = m.min_dihedral_deg;
        self.max_dihedral_deg = m.max_dihedral_deg;
        self.tets_below_deg = m.tets_below_deg;
        self.max_size_ratio = m.max_size_ratio;
        self.edge_ratio_min = m.edge_ratio_min;
        self.edge_ratio_median = m.edge_ratio_median;
        self.edge_ratio_max = m.edge_ratio_max;
        self.n_bad_near_acute = m.n_bad_near_acute;
    }

    /// Re-measures the shape figures (counts, rho, sigma, dihedral angles, tets below
    /// 5/10/15/20 degrees) on `mesh`; the size figures stay as they are.
    pub fn measure_shapes(&mut self, mesh: &TetMesh) {
        let mut shapes = Shapes::new();
        for t in &mesh.tets {
            let p = t.map(|v| mesh.vertices[v as usize]);
            shapes.add(&TetQuality::of(p[0], p[1], p[2], p[3]));
        }
        shapes.write(mesh, self);
    }

    /// The smallest and largest dihedral angle measured, degrees.
    pub fn dihedral_range(&self) -> [f64; 2] {
        [self.min_dihedral_deg, self.max_dihedral_deg]
    }

    /// Records what the improvement pass did (`stats`, its time added to the total);
    /// `dihedral_before` is the mesh's dihedral range before it.
    pub fn record_improvement(&mut self, stats: ImproveStats, dihedral_before: [f64; 2]) {
        self.delaunay = !stats.changed();
        self.dihedral_before_improve_deg = dihedral_before;
        self.seconds_improvement = stats.seconds;
        self.seconds_total += stats.seconds;
        self.improvement = stats;
    }

    /// A human-readable table.
    pub fn table(&self) -> String {
        let mut s = String::new();
        let mut row = |k: &str, v: String| s.push_str(&format!("  {k:<28} {v}\n"));
        row("vertices", self.n_vertices.to_string());
        row("tets", self.n_tets.to_string());
        row("boundary triangles", self.n_boundary_faces.to_string());
        row(
            "time recovery / refine (s)",
            format!(
                "{:.3} / {:.3}",
                self.seconds_recovery, self.seconds_refinement
            ),
        );
        row(
            "time improvement (s)",
            format!(
                "{:.3} (flips {}, moves {}, insertions {}, deletions {}, rho0 vetoes {} / gave way {}{})",
                self.seconds_improvement,
                self.improvement.edge_removals
                    + self.improvement.face_removals
                    + self.improvement.multi_face_removals
                    + self.improvement.boundary_flips,
                self.improvement.smoothed,
                self.improvement.insertions,
                self.improvement.deletions,
                self.improvement.rho_vetoes,
                self.improvement.rho_yields,
                if self.delaunay { ", Delaunay" } else { "" }
            ),
        );
        row(
            "dihedral before improvement",
            format!(
                "{:.2} / {:.2}",
                self.dihedral_before_improve_deg[0], self.dihedral_before_improve_deg[1]
            ),
        );
        row("max radius-edge rho", format!("{:.4}", self.max_rho));
        row("min sigma V/L^3", format!("{:.4}", self.min_sigma));
        row(
            "dihedral min / max (deg)",
            format!(
                "{:.2} / {:.2}",
                self.min_dihedral_deg, self.max_dihedral_deg
            ),
        );
        row(
            "tets below 5/10/15/20 deg",
            format!("{:?}", self.tets_below_deg),
        );
        row("max R / f(c)", format!("{:.3}", self.max_size_ratio));
        row(
            "edge / f(mid) min/med/max",
            format!(
                "{:.3} / {:.3} / {:.3}",
                self.edge_ratio_min, self.edge_ratio_median, self.edge_ratio_max
            ),
        );
        row("acute input vertices", self.n_acute_angles.to_string());
        row(
            "bad tets left near acute",
            self.n_bad_near_acute.to_string(),
        );
        row("refinement refusals", self.refusals.summary());
        if self.regions.len() > 1 {
            for r in &self.regions {
                row(
                    &format!("region {}: tets / volume", r.attribute),
                    format!(
                        "{} / {:.6e} (input {:.6e}, {:+.3e})",
                        r.tets, r.volume, r.input_volume, r.relative_volume_difference
                    ),
                );
            }
            row(
                "interface area / input",
                format!(
                    "{:.6e} / {:.6e}",
                    self.interface_area, self.input_interface_area
                ),
            );
        }
        row(
            "complete",
            match &self.stop_reason {
                None => "true".to_string(),
                Some(r) => format!("{} ({r})", self.complete),
            },
        );
        s
    }
}
