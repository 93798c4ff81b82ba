//! Per-marker maximum sizes (`Params::marker_sizes`, `--marker-size ID:H`): near the input
//! facets of marker ID the spacing is at most H, and it grows away from them at the grading
//! [`MARKER_GRADING`]: f'(x) = min(f(x), H + MARKER_GRADING * max(0, d(x) - H)), d(x) the
//! distance from x to the facets of marker ID. The cap stays H up to a distance H: the
//! spacing is read at the circumcentres of the tets on a facet, which lie inside, about a
//! spacing away (with the cap growing from d = 0, keep mode's boundary triangles there came
//! out 1.47 H on average, with the plateau 1.1 H, as with `--size H`). Both surface modes wrap
//! their spacing (the caller's, or the automatic one) in [`MarkerCapped`]; the distance is the
//! closest-point query of a [`SurfaceOracle`] on the triangles of that marker's input facets.

use crate::run::error::MeshError;
use crate::run::spacing::Spacing;
use crate::surface::oracle::SurfaceOracle;
use crate::surface::InputSurface;
use glam::DVec3;

/// How fast the spacing capped by a marker size may grow with the distance from that
/// marker's facets beyond H: H + MARKER_GRADING * (distance - H).
pub const MARKER_GRADING: f64 = 0.5;

/// The caps of `Params::marker_sizes`: per marker given, its size and a distance oracle over
/// its input triangles.
pub struct MarkerCaps {
    caps: Vec<(f64, SurfaceOracle)>,
}

impl MarkerCaps {
    /// The caps of `sizes` (marker id, H) on the triangles of `surface` (by
    /// `InputSurface::marker_of`); None when `sizes` is empty. A marker none of the triangles
    /// has is an error naming it and listing the input's markers.
    pub fn new(
        surface: &InputSurface,
        sizes: &[(i32, f64)],
    ) -> Result<Option<MarkerCaps>, MeshError> {
        if sizes.is_empty() {
            return Ok(None);
        }
        let mut caps = Vec::with_capacity(sizes.len());
        for &(id, h) in sizes {
            let triangles: Vec<[u32; 3]> = surface
                .triangles
                .iter()
                .zip(&surface.marker_of)
                .filter(|(_, &m)| m == id)
                .map(|(&t, _)| t)
                .collect();
            if triangles.is_empty() {
                return Err(unknown_marker(id, &surface.marker_of));
            }
            let part = InputSurface::from_triangles(surface.vertices.clone(), triangles);
            caps.push((h, SurfaceOracle::for_distances(&part)));
        }
        Ok(Some(MarkerCaps { caps }))
    }

    /// `f` capped at `p`: the smallest of `f` and every marker's
    /// H + MARKER_GRADING x max(0, distance - H).
    /// A value that is not finite and positive is passed on as it is (the run fails naming
    /// the point).
    pub fn cap(&self, p: DVec3, f: f64) -> f64 {
        if !(f.is_finite() && f > 0.0) {
            return f;
        }
        let mut f = f;
        for (h, oracle) in &self.caps {
            if *h >= f {
                continue;
            }
            if let Some(c) = oracle.closest(p) {
                f = f.min(h + MARKER_GRADING * (c.distance - h).max(0.0));
            }
        }
        f
    }
}

/// The error for a marker size given for marker `id`, which no facet of `markers` has.
fn unknown_marker(id: i32, markers: &[i32]) -> MeshError {
    let mut known: Vec<i32> = markers.to_vec();
    known.sort_unstable();
    known.dedup();
    MeshError::InvalidInput(format!(
        "marker size given for marker {id}, but no input facet has that marker (its markers: \
         {})",
        ranges(&known)
    ))
}

/// Sorted distinct integers as a list with runs of three or more written as ranges
/// ("1, 2, 5-9"): a surface reader numbers thousands of facets 1, 2, 3, ...
fn ranges(sorted: &[i32]) -> String {
    let mut parts: Vec<String> = vec![];
    let mut i = 0;
    while i < sorted.len() {
        let mut j = i;
        while j + 1 < sorted.len() && sorted[j + 1] as i64 == sorted[j] as i64 + 1 {
            j += 1;
        }
        if j >= i + 2 {
            parts.push(format!("{}-{}", sorted[i], sorted[j]));
        } else {
            parts.extend(sorted[i..=j].iter().map(|m| m.to_string()));
        }
        i = j + 1;
    }
    parts.join(", ")
}

/// A spacing capped by marker sizes ([`MarkerCaps::cap`]); without caps, `inner` as it is.
pub struct MarkerCapped<'a> {
    pub inner: &'a dyn Spacing,
    pub caps: Option<&'a MarkerCaps>,
}

impl Spacing for MarkerCapped<'_> {
    fn at(&self, p: DVec3) -> f64 {
        let f = self.inner.at(p);
        match self.caps {
            Some(caps) => caps.cap(p, f),
            None => f,
        }
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        self.inner.at_many(points, out);
        if let Some(caps) = self.caps {
            for (o, &p) in out.iter_mut().zip(points) {
                *o = caps.cap(p, *o);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::spacing::ConstantSpacing;

    fn square() -> InputSurface {
        // Two triangles of the unit square in z = 0 (marker 3), one far away (marker 1).
        let mut s = InputSurface::from_triangles(
            vec![
                DVec3::new(0.0, 0.0, 0.0),
                DVec3::new(1.0, 0.0, 0.0),
                DVec3::new(1.0, 1.0, 0.0),
                DVec3::new(0.0, 1.0, 0.0),
                DVec3::new(0.0, 0.0, 5.0),
                DVec3::new(1.0, 0.0, 5.0),
                DVec3::new(0.0, 1.0, 5.0),
            ],
            vec![[0, 1, 2], [0, 2, 3], [4, 5, 6]],
        );
        s.marker_of = vec![3, 3, 1];
        s
    }

    #[test]
    fn cap_grows_with_the_distance_from_the_marker() {
        let caps = MarkerCaps::new(&square(), &[(3, 0.1)]).unwrap().unwrap();
        let f = MarkerCapped {
            inner: &ConstantSpacing(1.0),
            caps: Some(&caps),
        };
        assert_eq!(f.at(DVec3::new(0.5, 0.5, 0.0)), 0.1);
        assert_eq!(f.at(DVec3::new(0.5, 0.5, 0.08)), 0.1);
        let d = f.at(DVec3::new(0.5, 0.5, 0.4));
        assert!((d - (0.1 + MARKER_GRADING * 0.3)).abs() < 1e-12, "{d}");
        assert_eq!(f.at(DVec3::new(0.5, 0.5, 4.0)), 1.0);
        let pts = [DVec3::new(0.5, 0.5, 0.0), DVec3::new(2.0, 0.5, 0.0)];
        let mut out = [0.0; 2];
        f.at_many(&pts, &mut out);
        assert_eq!(out[0], 0.1);
        assert!((out[1] - (0.1 + MARKER_GRADING * 0.9)).abs() < 1e-12);
        assert!(MarkerCaps::new(&square(), &[]).unwrap().is_none());
    }

    #[test]
    fn unknown_marker_lists_the_markers() {
        let e = MarkerCaps::new(&square(), &[(7, 0.1)]).err().unwrap();
        let e = e.to_string();
        assert!(
            e.contains("marker 7") && e.contains("its markers: 1, 3"),
            "{e}"
        );
        assert_eq!(ranges(&[1, 2, 3, 5, 7, 8, 9, 10]), "1-3, 5, 7-10");
        assert_eq!(ranges(&[1, 2]), "1, 2");
    }
}
