//! The spacing a [`super::Mesher`] uses, and the guard that makes any spacing value that is not
//! finite and positive fail the run with the point that produced it.

use crate::run::error::MeshError;
use crate::run::spacing::Spacing;
use glam::DVec3;
use std::cell::Cell;

/// Which spacing function f(x) drives refinement.
#[derive(Default)]
pub enum SpacingChoice {
    /// Automatic (local-feature-size based) spacing chosen by the refiner.
    #[default]
    Automatic,
    /// The same target size everywhere (finite, > 0).
    Constant(f64),
    /// A user function (a Rust closure or any [`Spacing`] implementation).
    Custom(Box<dyn Spacing + Send>),
    /// A user function that may be evaluated from several threads at once (`Sync`): big
    /// batches are split across the run's threads (`crate::parallel::SplitSpacing`).
    Shared(Box<dyn Spacing + Send + Sync>),
}

impl SpacingChoice {
    /// Runs `f` with the spacing this choice stands for: `None` when automatic, a constant as
    /// `ConstantSpacing`, a `Shared` one split across the run's threads (`SplitSpacing`). For
    /// callers that mesh without a `Mesher` (`crate::distributed`).
    pub fn with_spacing<R>(&self, f: impl FnOnce(Option<&dyn Spacing>) -> R) -> R {
        match self {
            SpacingChoice::Automatic => f(None),
            SpacingChoice::Constant(h) => f(Some(&crate::run::spacing::ConstantSpacing(*h))),
            SpacingChoice::Custom(s) => f(Some(s.as_ref())),
            SpacingChoice::Shared(s) => f(Some(&crate::parallel::SplitSpacing(s.as_ref()))),
        }
    }
}

impl std::fmt::Debug for SpacingChoice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            SpacingChoice::Automatic => write!(f, "Automatic"),
            SpacingChoice::Constant(h) => write!(f, "Constant({h})"),
            SpacingChoice::Custom(_) => write!(f, "Custom(..)"),
            SpacingChoice::Shared(_) => write!(f, "Shared(..)"),
        }
    }
}

/// True when `v` is a usable spacing value.
pub(crate) fn valid_value(v: f64) -> bool {
    v.is_finite() && v > 0.0
}

/// Wraps a spacing function, passes every value through unchanged (so the refiner sees and
/// reports a bad one itself) and remembers the first bad value, so a run can never succeed on
/// one even if the refiner does not check.
pub(crate) struct Checked<'a> {
    inner: &'a dyn Spacing,
    first_bad: Cell<Option<(DVec3, f64)>>,
}

impl<'a> Checked<'a> {
    pub(crate) fn new(inner: &'a dyn Spacing) -> Self {
        Checked {
            inner,
            first_bad: Cell::new(None),
        }
    }

    fn note(&self, p: DVec3, v: f64) {
        if !valid_value(v) && self.first_bad.get().is_none() {
            self.first_bad.set(Some((p, v)));
        }
    }

    /// The error for the first bad value seen, if any.
    pub(crate) fn error(&self) -> Option<MeshError> {
        self.first_bad
            .get()
            .map(|(point, value)| MeshError::BadSpacing { point, value })
    }

    /// Evaluates the spacing at `points` in batches of at most `refine::SPACING_BATCH` and
    /// fails on the first bad value: run on the input vertices before meshing, so a broken
    /// callback is reported at once, naming the point, instead of after boundary recovery.
    pub(crate) fn precheck(&self, points: &[DVec3]) -> Result<(), MeshError> {
        if points.is_empty() {
            return Ok(());
        }
        let mut out = vec![f64::NAN; points.len()];
        let batch = crate::refine::SPACING_BATCH;
        for (p, o) in points.chunks(batch).zip(out.chunks_mut(batch)) {
            self.at_many(p, o);
        }
        match points.iter().zip(&out).find(|(_, &v)| !valid_value(v)) {
            Some((&point, &value)) => Err(MeshError::BadSpacing { point, value }),
            None => Ok(()),
        }
    }
}

impl Spacing for Checked<'_> {
    fn at(&self, p: DVec3) -> f64 {
        let v = self.inner.at(p);
        self.note(p, v);
        v
    }

    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        self.inner.at_many(points, out);
        for (&p, &v) in points.iter().zip(out.iter()) {
            self.note(p, v);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::spacing::FnSpacing;

    #[test]
    fn checked_passes_values_through_and_keeps_the_first_bad_one() {
        let f = FnSpacing(|p: DVec3| {
            if p.x > 0.5 {
                f64::NAN
            } else {
                1.0 / (1.0 + p.x)
            }
        });
        let c = Checked::new(&f);
        assert_eq!(c.at(DVec3::ZERO), 1.0);
        assert!(c.error().is_none());
        assert!(c.at(DVec3::new(0.75, 0.0, 0.0)).is_nan());
        assert!(c.at(DVec3::new(1.0, 0.0, 0.0)).is_nan());
        match c.error() {
            Some(MeshError::BadSpacing { point, value }) => {
                assert_eq!(point, DVec3::new(0.75, 0.0, 0.0));
                assert!(value.is_nan());
            }
            e => panic!("{e:?}"),
        }
    }

    #[test]
    fn precheck_names_the_point() {
        let f = FnSpacing(|p: DVec3| p.z);
        let c = Checked::new(&f);
        let pts = [DVec3::new(0.0, 0.0, 1.0), DVec3::new(1.0, 2.0, 0.0)];
        let e = c.precheck(&pts).unwrap_err();
        assert_eq!(
            e,
            MeshError::BadSpacing {
                point: pts[1],
                value: 0.0
            }
        );
        assert!(e.to_string().contains("(1, 2, 0)"), "{e}");
        assert!(c.precheck(&pts[..1]).is_ok());
        assert!(c.precheck(&[]).is_ok());
    }
}
