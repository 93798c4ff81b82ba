//! The figures reported after every run: counts, achieved quality and size conformity.

use super::{MeshError, Params, Report, Spacing};
use crate::geom::TetQuality;
use crate::mesh::TetMesh;

/// Measures `mesh` (tets only; timings and completion are filled in by the caller).
pub fn measure(
    mesh: &TetMesh,
    spacing: &dyn Spacing,
    _params: &Params,
) -> Result<Report, MeshError> {
    let mut r = Report {
        n_vertices: mesh
            .tets
            .iter()
            .flatten()
            .collect::<std::collections::BTreeSet<_>>()
            .len(),
        n_tets: mesh.tets.len(),
        n_boundary_faces: mesh.boundary.len(),
        min_sigma: f64::INFINITY,
        min_dihedral_deg: 180.0,
        ..Default::default()
    };
    let p = |v: u32| mesh.vertices[v as usize];
    let mut edges = vec![];
    for t in &mesh.tets {
        let q = TetQuality::of(p(t[0]), p(t[1]), p(t[2]), p(t[3]));
        r.max_rho = r.max_rho.max(q.rho);
        r.min_sigma = r.min_sigma.min(q.sigma);
        r.min_dihedral_deg = r.min_dihedral_deg.min(q.min_dihedral);
        r.max_dihedral_deg = r.max_dihedral_deg.max(q.max_dihedral);
        for (k, limit) in [5.0, 10.0, 15.0, 20.0].iter().enumerate() {
            if q.min_dihedral < *limit {
                r.tets_below_deg[k] += 1;
            }
        }
        if let Some(c) = q.circumcenter {
            let f = checked(spacing, c)?;
            r.max_size_ratio = r.max_size_ratio.max(q.circumradius / f);
        }
        for i in 0..4 {
            for j in i + 1..4 {
                edges.push((t[i].min(t[j]), t[i].max(t[j])));
            }
        }
    }
    edges.sort_unstable();
    edges.dedup();
    let mut ratios = Vec::with_capacity(edges.len());
    for (a, b) in edges {
        let mid = (p(a) + p(b)) * 0.5;
        ratios.push(p(a).distance(p(b)) / checked(spacing, mid)?);
    }
    ratios.sort_unstable_by(f64::total_cmp);
    if !ratios.is_empty() {
        r.edge_ratio_min = ratios[0];
        r.edge_ratio_median = ratios[ratios.len() / 2];
        r.edge_ratio_max = ratios[ratios.len() - 1];
    }
    if mesh.tets.is_empty() {
        r.min_sigma = 0.0;
        r.min_dihedral_deg = 0.0;
    }
    Ok(r)
}

fn checked(spacing: &dyn Spacing, p: glam::DVec3) -> Result<f64, MeshError> {
    let f = spacing.at(p);
    if f.is_finite() && f > 0.0 {
        Ok(f)
    } else {
        Err(MeshError::BadSpacing { point: p, value: f })
    }
}

impl Report {
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
