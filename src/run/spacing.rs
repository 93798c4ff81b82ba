//! The spacing (target element size) a run meshes to: the [`Spacing`] trait and the spacings
//! that need nothing from a mesher (constant, a closure, the minimum of several). Refinement's
//! own spacings (automatic, background mesh, marker caps) live in `refine`.

use glam::DVec3;

/// A spacing (target element size) function f(x) > 0.
pub trait Spacing {
    fn at(&self, p: DVec3) -> f64;
    /// Evaluates many points at once (callers across an FFI pay one call per batch).
    fn at_many(&self, points: &[DVec3], out: &mut [f64]) {
        for (o, &p) in out.iter_mut().zip(points) {
            *o = self.at(p);
        }
    }
}

/// Constant spacing.
#[derive(Debug, Clone, Copy)]
pub struct ConstantSpacing(pub f64);
impl Spacing for ConstantSpacing {
    fn at(&self, _: DVec3) -> f64 {
        self.0
    }
}

/// Spacing from a closure.
pub struct FnSpacing<F: Fn(DVec3) -> f64>(pub F);
impl<F: Fn(DVec3) -> f64> Spacing for FnSpacing<F> {
    fn at(&self, p: DVec3) -> f64 {
        (self.0)(p)
    }
}

/// The smallest of several spacings at every point (e.g. a fine zone's f and a global one).
/// A value that is not finite and positive is passed on as it is (not dropped by the minimum),
/// so the run fails naming the point.
pub struct MinSpacing(pub Vec<Box<dyn Spacing + Send>>);
impl Spacing for MinSpacing {
    fn at(&self, p: DVec3) -> f64 {
        let mut f = f64::INFINITY;
        for s in &self.0 {
            let v = s.at(p);
            if !(v.is_finite() && v > 0.0) {
                return v;
            }
            f = f.min(v);
        }
        f
    }
}
