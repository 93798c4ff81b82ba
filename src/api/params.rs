//! Refinement parameters set and read by name (for the C ABI, the CLI and config files), with
//! range checks that say why a value is refused.

use super::error::{invalid, Error};
use crate::geom::{REGULAR_DIHEDRAL, REGULAR_RHO, REGULAR_SIGMA};
pub use crate::run::params::{Params, SurfaceMode};

/// Every name [`set_param`] accepts, in documentation order (`"B"` is an alias of
/// `"size_factor"`).
pub const PARAM_NAMES: &[&str] = &[
    "rho0",
    "sigma0",
    "min_dihedral",
    "delta",
    "b",
    "size_factor",
    "B",
    "seed",
    "max_vertices",
    "max_tries",
    "refine",
    "small_angle_reach",
    "improve",
    "surface_mode",
    "feature_angle",
    "surface_distance",
    "improve_target",
    "repair",
    "order",
    "threads",
    "spacing_thread_safe",
];

/// Smallest accepted `rho0` (the refiner's own limit, `Params::check`).
const MIN_RHO0: f64 = 0.7;

/// Upper end (exclusive) of `min_dihedral`, degrees: just below the regular tetrahedron's 70.53.
const MAX_MIN_DIHEDRAL: f64 = 70.5;

/// Largest integer an `f64` holds exactly: integer parameters above it are refused rather than
/// silently rounded.
const MAX_EXACT_INT: f64 = 9_007_199_254_740_992.0; // 2^53

/// Sets the parameter `name` to `value`, leaving `params` unchanged on error.
///
/// Names are case-sensitive: `rho0` (>= 0.7: no tetrahedron gets below sqrt(6)/4 = 0.612),
/// `sigma0` (in [0, 0.1179): 0 turns the sigma test off), `min_dihedral` (degrees, in
/// [0, 70.5): 0 turns the angle test off), `delta` (in (0, 1)), `b` (> 0), `size_factor` or `B`
/// (> 0), `seed` (integer in [0, 2^53]), `max_vertices` (integer >= 4), `max_tries`
/// (integer >= 1), `refine` (0 or 1), `small_angle_reach` (> 0, may be infinite), `improve`
/// (0 or 1), `surface_mode` (0 = keep the input facets, 1 = approximate the surface they
/// describe), `feature_angle` (degrees, in (0, 180): approximate mode's sharp-edge threshold),
/// `surface_distance` (finite, >= 0: approximate mode's distance bound; 0 = the default, 0.001 x
/// the bounding-box diagonal), `improve_target` (degrees in [0, 40]: improvement works on tets
/// with a smaller dihedral angle; 0 = the mode's default, 26 keep / 20 approximate), `repair`
/// (0 or 1: approximate mode meshes a dirty surface, open, self-intersecting or overlapping,
/// as the solid where its winding number is at least 1/2), `order` (1: four-node tets, 2:
/// ten-node tets with boundary nodes on the input surface), `threads` (integer >= 0: threads of
/// the run's parallel steps, 0 = all cores, at most 255 used; the mesh is the same for every
/// count), `spacing_thread_safe` (0 or 1: 1 declares that a C spacing callback may be called
/// from several threads at once). Integer and 0/1 parameters must be given as whole numbers.
/// The result also passes `Params::check` (the refiner's own validation), so a value accepted
/// here is never refused by `refine`.
pub fn set_param(params: &mut Params, name: &str, value: f64) -> Result<(), Error> {
    let mut candidate = params.clone();
    set_unchecked(&mut candidate, name, value)?;
    if let Err(e) = candidate.check() {
        return invalid(e);
    }
    *params = candidate;
    Ok(())
}

fn set_unchecked(params: &mut Params, name: &str, value: f64) -> Result<(), Error> {
    if value.is_nan() {
        return invalid(format!("parameter \"{name}\" is NaN"));
    }
    match name {
        "rho0" => {
            finite(name, value)?;
            if value < MIN_RHO0 {
                return invalid(format!(
                    "rho0 = {value} is out of reach: no tetrahedron has a radius-edge ratio below \
                     sqrt(6)/4 = {REGULAR_RHO:.4} (the regular one), and a bound that close cannot \
                     be met on a whole mesh; use rho0 >= {MIN_RHO0} (2 is the usual choice)"
                ));
            }
            params.rho0 = value;
        }
        "sigma0" => {
            finite(name, value)?;
            if !(0.0..REGULAR_SIGMA).contains(&value) {
                return invalid(format!(
                    "sigma0 = {value} is out of range [0, {REGULAR_SIGMA:.4}): sigma = V/L^3 is at \
                     most {REGULAR_SIGMA:.4} (the regular tetrahedron); 0 turns sliver removal off"
                ));
            }
            params.sigma0 = value;
        }
        "min_dihedral" => {
            finite(name, value)?;
            if !(0.0..MAX_MIN_DIHEDRAL).contains(&value) {
                return invalid(format!(
                    "min_dihedral = {value} is out of range [0, {MAX_MIN_DIHEDRAL}) degrees: the \
                     regular tetrahedron's dihedral angle is {REGULAR_DIHEDRAL:.2}, the largest \
                     smallest angle a tet can have; 0 turns the angle test off"
                ));
            }
            params.min_dihedral = value;
        }
        "delta" => {
            finite(name, value)?;
            if !(value > 0.0 && value < 1.0) {
                return invalid(format!(
                    "delta = {value} is out of range (0, 1): the picking ball (c, delta*R) must \
                     lie inside the circumsphere and have room to pick from"
                ));
            }
            params.delta = value;
        }
        "b" => params.b = positive(name, value, "the small-sliver radius factor")?,
        "size_factor" | "B" => {
            params.size_factor = positive(name, value, "the size factor R/f(c) <= B")?
        }
        "seed" => params.seed = whole(name, value, 0.0)? as u64,
        "max_vertices" => params.max_vertices = whole(name, value, 4.0)? as usize,
        "max_tries" => params.max_tries = whole(name, value, 1.0)? as usize,
        "small_angle_reach" => {
            if value.is_nan() || value <= 0.0 {
                return invalid(format!(
                    "small_angle_reach = {value} must be > 0: the reach of a small input \
                     angle's influence in protecting-ball radii (infinity: whole facets)"
                ));
            }
            params.small_angle_reach = value;
        }
        "improve" => {
            params.improve = match value {
                0.0 => false,
                1.0 => true,
                _ => {
                    return invalid(format!(
                        "improve = {value}: must be 1 (flips and smoothing after refinement) \
                         or 0 (keep the Delaunay mesh; only flat or inverted tets are removed)"
                    ))
                }
            }
        }
        "surface_mode" => {
            params.surface_mode = match value {
                0.0 => SurfaceMode::Keep,
                1.0 => SurfaceMode::Approximate,
                _ => {
                    return invalid(format!(
                        "surface_mode = {value}: must be 0 (keep: every input facet is preserved \
                         exactly) or 1 (approximate: the input triangles describe a piecewise \
                         smooth surface, remeshed within surface_distance)"
                    ))
                }
            }
        }
        "feature_angle" => {
            if !(value > 0.0 && value < 180.0) {
                return invalid(format!(
                    "feature_angle = {value} is out of range (0, 180) degrees: an edge whose two \
                     triangles' normals differ by more than this is a sharp feature (default 40)"
                ));
            }
            params.feature_angle = value;
        }
        "surface_distance" => {
            if !(value.is_finite() && value >= 0.0) {
                return invalid(format!(
                    "surface_distance = {value}: must be finite and >= 0: how far the \
                     approximate mode's boundary may lie from the input surface (absolute \
                     length; 0 = the default, 0.001 x the bounding-box diagonal)"
                ));
            }
            params.surface_distance = value;
        }
        "improve_target" => {
            if !(value.is_finite()
                && (0.0..=crate::run::params::MAX_IMPROVE_TARGET).contains(&value))
            {
                return invalid(format!(
                    "improve_target = {value} is out of range [0, 40] degrees: improvement works \
                     on tets with a smaller dihedral angle (0 = the mode's default, 26 keep / \
                     20 approximate)"
                ));
            }
            params.improve_target = value;
        }
        "repair" => {
            params.repair = match value {
                0.0 => false,
                1.0 => true,
                _ => {
                    return invalid(format!(
                        "repair = {value}: must be 1 (mesh a dirty surface as the solid where \
                         its winding number is at least 1/2; approximate mode) or 0 (refuse it)"
                    ))
                }
            }
        }
        "order" => {
            params.order = match value {
                1.0 => 1,
                2.0 => 2,
                _ => {
                    return invalid(format!(
                        "order = {value}: must be 1 (four-node tets) or 2 (ten-node tets, \
                         boundary nodes on the input surface)"
                    ))
                }
            }
        }
        "threads" => params.threads = whole(name, value, 0.0)? as usize,
        "spacing_thread_safe" => {
            params.spacing_thread_safe = match value {
                0.0 => false,
                1.0 => true,
                _ => {
                    return invalid(format!(
                        "spacing_thread_safe = {value}: must be 1 (the C spacing callback may be \
                         called from several threads at once) or 0 (one thread at a time)"
                    ))
                }
            }
        }
        "refine" => {
            params.refine = match value {
                0.0 => false,
                1.0 => true,
                _ => {
                    return invalid(format!(
                        "refine = {value}: must be 1 (quality refinement) or 0 (boundary \
                         recovery only)"
                    ))
                }
            }
        }
        _ => {
            return invalid(format!(
                "unknown parameter \"{name}\"; valid names: {}",
                PARAM_NAMES.join(", ")
            ))
        }
    }
    Ok(())
}

/// Reads the parameter `name` (same names as [`set_param`]; integers and booleans as `f64`).
pub fn get_param(params: &Params, name: &str) -> Result<f64, Error> {
    Ok(match name {
        "rho0" => params.rho0,
        "sigma0" => params.sigma0,
        "min_dihedral" => params.min_dihedral,
        "delta" => params.delta,
        "b" => params.b,
        "size_factor" | "B" => params.size_factor,
        "seed" => params.seed as f64,
        "max_vertices" => params.max_vertices as f64,
        "max_tries" => params.max_tries as f64,
        "refine" => f64::from(u8::from(params.refine)),
        "improve" => f64::from(u8::from(params.improve)),
        "small_angle_reach" => params.small_angle_reach,
        "surface_mode" => match params.surface_mode {
            SurfaceMode::Keep => 0.0,
            SurfaceMode::Approximate => 1.0,
        },
        "feature_angle" => params.feature_angle,
        "surface_distance" => params.surface_distance,
        "improve_target" => params.improve_target,
        "repair" => f64::from(u8::from(params.repair)),
        "order" => f64::from(params.order),
        "threads" => params.threads as f64,
        "spacing_thread_safe" => f64::from(u8::from(params.spacing_thread_safe)),
        _ => {
            return invalid(format!(
                "unknown parameter \"{name}\"; valid names: {}",
                PARAM_NAMES.join(", ")
            ))
        }
    })
}

fn finite(name: &str, value: f64) -> Result<(), Error> {
    if value.is_finite() {
        Ok(())
    } else {
        invalid(format!("{name} = {value}: must be finite"))
    }
}

fn positive(name: &str, value: f64, what: &str) -> Result<f64, Error> {
    finite(name, value)?;
    if value > 0.0 {
        Ok(value)
    } else {
        invalid(format!("{name} = {value}: {what} must be > 0"))
    }
}

fn whole(name: &str, value: f64, min: f64) -> Result<f64, Error> {
    if !value.is_finite() || value.fract() != 0.0 {
        return invalid(format!("{name} = {value}: must be a whole number"));
    }
    if value < min || value > MAX_EXACT_INT {
        return invalid(format!("{name} = {value} is out of range [{min}, 2^53]"));
    }
    Ok(value)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn err(name: &str, value: f64) -> String {
        let mut p = Params::default();
        let e = set_param(&mut p, name, value).unwrap_err().to_string();
        assert_eq!(
            p,
            Params::default(),
            "{name} = {value} changed params on error"
        );
        e
    }

    #[test]
    fn every_name_round_trips() {
        let mut p = Params::default();
        let values = [
            ("rho0", 1.5),
            ("sigma0", 0.05),
            ("min_dihedral", 12.0),
            ("delta", 0.25),
            ("b", 3.0),
            ("size_factor", 1.5),
            ("B", 2.5),
            ("seed", 42.0),
            ("max_vertices", 1000.0),
            ("max_tries", 7.0),
            ("refine", 0.0),
            ("small_angle_reach", 2.0),
            ("improve", 0.0),
            ("surface_mode", 1.0),
            ("feature_angle", 30.0),
            ("surface_distance", 0.01),
            ("improve_target", 30.0),
            ("repair", 1.0),
            ("order", 2.0),
            ("threads", 3.0),
            ("spacing_thread_safe", 1.0),
        ];
        assert_eq!(values.len(), PARAM_NAMES.len());
        for (name, v) in values {
            set_param(&mut p, name, v).unwrap();
            assert_eq!(get_param(&p, name).unwrap(), v, "{name}");
        }
        assert_eq!(p.size_factor, 2.5);
        assert_eq!(p.seed, 42);
        assert!(!p.refine);
        assert!(!p.improve);
        assert_eq!(p.surface_mode, SurfaceMode::Approximate);
        assert!(p.repair);
        assert!(set_param(&mut p, "improve", 0.5).is_err());
        assert!(set_param(&mut p, "repair", 2.0).is_err());
        assert!(set_param(&mut p, "order", 3.0).is_err());
        assert!(set_param(&mut p, "order", 1.5).is_err());
        assert_eq!(p.threads, 3);
        assert!(p.spacing_thread_safe);
        assert!(set_param(&mut p, "threads", -1.0).is_err());
        assert!(set_param(&mut p, "threads", 1.5).is_err());
        assert!(set_param(&mut p, "spacing_thread_safe", 2.0).is_err());
    }

    #[test]
    fn unknown_name_lists_valid_ones() {
        let e = err("rho", 2.0);
        assert!(e.contains("\"rho\""), "{e}");
        for n in PARAM_NAMES {
            assert!(e.contains(n), "{e} lacks {n}");
        }
        assert!(get_param(&Params::default(), "Rho0").is_err());
    }

    #[test]
    fn out_of_range_values_give_a_reason() {
        assert!(err("rho0", 0.5).contains("sqrt(6)/4"));
        assert!(err("rho0", 0.69).contains(">= 0.7"));
        assert!(err("min_dihedral", 70.5).contains("regular"));
        assert!(err("min_dihedral", -1.0).contains("out of range"));
        assert!(err("delta", 0.0).contains("(0, 1)"));
        assert!(err("rho0", f64::INFINITY).contains("finite"));
        assert!(err("rho0", f64::NAN).contains("NaN"));
        assert!(err("sigma0", 0.2).contains("regular"));
        assert!(err("sigma0", -0.1).contains("out of range"));
        assert!(err("delta", 1.0).contains("circumsphere"));
        assert!(err("b", 0.0).contains("> 0"));
        assert!(err("B", -1.0).contains("> 0"));
        assert!(err("seed", 1.5).contains("whole"));
        assert!(err("seed", -1.0).contains("out of range"));
        assert!(err("seed", 1e300).contains("2^53"));
        assert!(err("max_vertices", 3.0).contains("out of range"));
        assert!(err("max_tries", 0.0).contains("out of range"));
        assert!(err("refine", 0.5).contains("0"));
        assert!(err("small_angle_reach", 0.0).contains("> 0"));
        assert!(err("small_angle_reach", -1.0).contains("> 0"));
        let mut p = Params::default();
        set_param(&mut p, "small_angle_reach", f64::INFINITY).unwrap();
    }

    #[test]
    fn accepted_values_pass_the_refiners_check() {
        for (name, v) in [
            ("rho0", 0.7),
            ("delta", 0.999),
            ("sigma0", 0.1178),
            ("B", 1e-6),
        ] {
            let mut p = Params::default();
            set_param(&mut p, name, v).unwrap();
            p.check().unwrap();
        }
    }

    #[test]
    fn boundary_values_accepted() {
        let mut p = Params::default();
        set_param(&mut p, "sigma0", 0.0).unwrap();
        set_param(&mut p, "min_dihedral", 0.0).unwrap();
        set_param(&mut p, "rho0", 0.7).unwrap();
        set_param(&mut p, "delta", 1e-9).unwrap();
        set_param(&mut p, "seed", 0.0).unwrap();
        set_param(&mut p, "seed", MAX_EXACT_INT).unwrap();
        assert_eq!(p.seed, 1 << 53);
        set_param(&mut p, "max_vertices", 4.0).unwrap();
        set_param(&mut p, "max_tries", 1.0).unwrap();
    }
}
