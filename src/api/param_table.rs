//! One table of the parameters set by name: name, default, accepted range and meaning. The
//! API's checks ([`super::params::set_param`]), the defaults (`Params::default`), the C header's
//! list, the CLI's stated defaults and the table in `docs/parameters.md` are each tested
//! against it, so none of them can drift from the others unnoticed.

use crate::geom::REGULAR_SIGMA;

/// The values a parameter accepts.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Range {
    /// A real interval; an infinite end that is closed accepts infinity.
    Interval {
        lo: f64,
        lo_open: bool,
        hi: f64,
        hi_open: bool,
    },
    /// Whole numbers from `min` to 2^53.
    Whole { min: u64 },
    /// Exactly these values.
    Choice(&'static [f64]),
}

impl Range {
    /// Whether `value` is in the range.
    pub fn contains(&self, value: f64) -> bool {
        match *self {
            Range::Interval {
                lo,
                lo_open,
                hi,
                hi_open,
            } => {
                let above = if lo_open { value > lo } else { value >= lo };
                let below = if hi_open { value < hi } else { value <= hi };
                above && below
            }
            Range::Whole { min } => {
                value.is_finite()
                    && value.fract() == 0.0
                    && value >= min as f64
                    && value <= 2f64.powi(53)
            }
            Range::Choice(values) => values.contains(&value),
        }
    }
}

impl std::fmt::Display for Range {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let num = |x: f64| -> String {
            if x.is_infinite() {
                "inf".into()
            } else {
                let s = format!("{x:.4}");
                s.trim_end_matches('0').trim_end_matches('.').to_string()
            }
        };
        match *self {
            Range::Interval {
                lo,
                lo_open,
                hi,
                hi_open,
            } => write!(
                f,
                "{}{}, {}{}",
                if lo_open { "(" } else { "[" },
                num(lo),
                num(hi),
                if hi_open { ")" } else { "]" }
            ),
            Range::Whole { min } => write!(f, "whole, [{min}, 2^53]"),
            Range::Choice(values) => {
                let list: Vec<String> = values.iter().map(|&v| num(v)).collect();
                write!(f, "{}", list.join(" or "))
            }
        }
    }
}

/// One parameter settable by name (`set_param`, `sm_set_param`).
#[derive(Debug, Clone, Copy)]
pub struct ParamSpec {
    pub name: &'static str,
    /// Other names for it (`"B"` for `"size_factor"`).
    pub aliases: &'static [&'static str],
    pub default: f64,
    pub range: Range,
    /// What it does, one sentence (Markdown).
    pub doc: &'static str,
}

const fn interval(lo: f64, lo_open: bool, hi: f64, hi_open: bool) -> Range {
    Range::Interval {
        lo,
        lo_open,
        hi,
        hi_open,
    }
}

const FLAG: Range = Range::Choice(&[0.0, 1.0]);

/// Every parameter settable by name, in documentation order.
pub const PARAMS: &[ParamSpec] = &[
    ParamSpec {
        name: "rho0",
        aliases: &[],
        default: 2.0,
        range: interval(0.7, false, f64::INFINITY, true),
        doc: "Radius-edge bound R/L: a tet above it is refined (the regular tet has 0.612).",
    },
    ParamSpec {
        name: "sigma0",
        aliases: &[],
        default: 0.02,
        range: interval(0.0, false, REGULAR_SIGMA, true),
        doc: "Sliver bound V/L^3 (regular tet: 0.1179); 0 turns the test off.",
    },
    ParamSpec {
        name: "min_dihedral",
        aliases: &[],
        default: 18.0,
        range: interval(0.0, false, 70.5, true),
        doc: "Degrees: a tet with a smaller dihedral angle is treated as a sliver; 0 turns it off.",
    },
    ParamSpec {
        name: "delta",
        aliases: &[],
        default: 0.3,
        range: interval(0.0, true, 1.0, true),
        doc: "Picking-ball radius factor: points are drawn from the ball (c, delta R).",
    },
    ParamSpec {
        name: "b",
        aliases: &[],
        default: 4.0,
        range: interval(0.0, true, f64::INFINITY, true),
        doc: "Small-sliver factor: a new sliver of circumradius at most b R rejects the point.",
    },
    ParamSpec {
        name: "size_factor",
        aliases: &["B"],
        default: 1.0,
        range: interval(0.0, true, f64::INFINITY, true),
        doc: "Size factor B: a tet with R / f(circumcentre) > B is refined.",
    },
    ParamSpec {
        name: "seed",
        aliases: &[],
        default: 1.0,
        range: Range::Whole { min: 0 },
        doc: "Random seed: same input, parameters and seed give the same mesh.",
    },
    ParamSpec {
        name: "max_vertices",
        aliases: &[],
        default: 10_000_000.0,
        range: Range::Whole { min: 4 },
        doc: "Vertex budget: refinement stops there and the report says it is incomplete.",
    },
    ParamSpec {
        name: "max_tries",
        aliases: &[],
        default: 20.0,
        range: Range::Whole { min: 1 },
        doc: "Candidate points drawn per bad element before the best one is taken.",
    },
    ParamSpec {
        name: "refine",
        aliases: &[],
        default: 1.0,
        range: FLAG,
        doc: "1: quality refinement; 0: boundary recovery only.",
    },
    ParamSpec {
        name: "small_angle_reach",
        aliases: &[],
        default: f64::INFINITY,
        range: interval(0.0, true, f64::INFINITY, false),
        doc: "How far a small input angle's influence reaches, in protecting-ball radii \
              (infinite: whole segments and facets).",
    },
    ParamSpec {
        name: "improve",
        aliases: &[],
        default: 1.0,
        range: FLAG,
        doc: "1: flips, smoothing, insertion and deletion after refinement; 0: keep the Delaunay \
              mesh.",
    },
    ParamSpec {
        name: "surface_mode",
        aliases: &[],
        default: 0.0,
        range: FLAG,
        doc: "0: keep every input facet exactly; 1: approximate the surface the facets describe.",
    },
    ParamSpec {
        name: "feature_angle",
        aliases: &[],
        default: 40.0,
        range: interval(0.0, true, 180.0, true),
        doc: "Approximate mode, degrees: an edge whose triangles' normals differ by more is a \
              sharp feature.",
    },
    ParamSpec {
        name: "surface_distance",
        aliases: &[],
        default: 0.0,
        range: interval(0.0, false, f64::INFINITY, true),
        doc: "Approximate mode: how far the boundary may lie from the input surface (absolute; \
              0: 0.001 x the bounding-box diagonal).",
    },
    ParamSpec {
        name: "improve_target",
        aliases: &[],
        default: 0.0,
        range: interval(0.0, false, 40.0, false),
        doc: "Degrees: improvement works on tets with a smaller dihedral angle (0: 26 in keep \
              mode, 20 in approximate mode).",
    },
    ParamSpec {
        name: "repair",
        aliases: &[],
        default: 0.0,
        range: FLAG,
        doc: "Approximate mode, 1: mesh a dirty surface as the solid where its winding number is \
              at least 1/2; 0: refuse it.",
    },
    ParamSpec {
        name: "order",
        aliases: &[],
        default: 1.0,
        range: Range::Choice(&[1.0, 2.0]),
        doc: "1: four-node tets; 2: ten-node tets, boundary nodes on the input surface.",
    },
    ParamSpec {
        name: "threads",
        aliases: &[],
        default: 0.0,
        range: Range::Whole { min: 0 },
        doc: "Threads of the run's parallel steps (0: all cores; at most 255 used); the mesh is \
              the same for every count (docs/parallel.md).",
    },
    ParamSpec {
        name: "spacing_thread_safe",
        aliases: &[],
        default: 0.0,
        range: FLAG,
        doc: "C ABI, 1: the spacing callback may be called from several threads at once; 0: \
              from one thread at a time (the one that called `sm_refine`).",
    },
];

/// The parameter called `name` (or one of its aliases).
pub fn spec(name: &str) -> Option<&'static ParamSpec> {
    PARAMS
        .iter()
        .find(|p| p.name == name || p.aliases.contains(&name))
}

/// The Markdown table of [`PARAMS`] that `docs/parameters.md` holds between its
/// `<!-- params:begin -->` and `<!-- params:end -->` lines.
pub fn markdown_table() -> String {
    let mut out =
        String::from("| name (C, Rust) | default | accepts | meaning |\n|---|---|---|---|\n");
    for p in PARAMS {
        let names = std::iter::once(p.name)
            .chain(p.aliases.iter().copied())
            .map(|n| format!("`{n}`"))
            .collect::<Vec<_>>()
            .join(", ");
        let default = if p.default.is_infinite() {
            "inf".to_string()
        } else {
            format!("{}", p.default)
        };
        out += &format!("| {names} | {default} | {} | {} |\n", p.range, p.doc);
    }
    out
}

#[cfg(test)]
mod tests {
    use super::super::params::{get_param, set_param, PARAM_NAMES};
    use super::*;
    use crate::run::params::Params;

    #[test]
    fn names_are_the_apis() {
        let mut names: Vec<&str> = PARAMS
            .iter()
            .flat_map(|p| std::iter::once(p.name).chain(p.aliases.iter().copied()))
            .collect();
        let mut api: Vec<&str> = PARAM_NAMES.to_vec();
        names.sort_unstable();
        api.sort_unstable();
        assert_eq!(names, api);
    }

    #[test]
    fn defaults_are_params_default() {
        let d = Params::default();
        for p in PARAMS {
            assert_eq!(get_param(&d, p.name).unwrap(), p.default, "{}", p.name);
            assert!(
                p.range.contains(p.default),
                "{}'s default is out of its range",
                p.name
            );
        }
    }

    /// `set_param` accepts what the table's range holds and refuses what it does not, probed at
    /// and just beyond each end.
    #[test]
    fn set_param_checks_the_tables_ranges() {
        let probes = |r: &Range| -> Vec<f64> {
            match *r {
                Range::Interval { lo, hi, .. } => {
                    let mut v = vec![f64::NAN, f64::INFINITY, f64::NEG_INFINITY];
                    for x in [lo, hi] {
                        if x.is_finite() {
                            let step = x.abs().max(1.0) * 1e-9;
                            v.extend([x - step, x, x + step]);
                        }
                    }
                    v.push(if hi.is_finite() {
                        (lo + hi) / 2.0
                    } else {
                        lo + 1.0
                    });
                    v
                }
                Range::Whole { min } => {
                    let m = min as f64;
                    vec![
                        m - 1.0,
                        m,
                        m + 0.5,
                        m + 1.0,
                        2f64.powi(53),
                        2f64.powi(53) * 2.0,
                    ]
                }
                Range::Choice(values) => {
                    let mut v: Vec<f64> = values.to_vec();
                    v.extend(values.iter().map(|x| x + 0.5));
                    v.extend([-1.0, 3.0, f64::NAN]);
                    v
                }
            }
        };
        for p in PARAMS {
            for value in probes(&p.range) {
                let mut params = Params::default();
                let accepted = set_param(&mut params, p.name, value).is_ok();
                assert_eq!(
                    accepted,
                    p.range.contains(value),
                    "{} = {value}: set_param {} it, the table says {}",
                    p.name,
                    if accepted { "accepts" } else { "refuses" },
                    p.range
                );
            }
        }
    }

    /// The C header's `sm_set_param` documentation names every parameter.
    #[test]
    fn the_c_header_lists_every_parameter() {
        let header = include_str!("../../include/slivermesh.h");
        let decl = header
            .find("sm_status sm_set_param(")
            .expect("sm_set_param in the header");
        let doc_start = header[..decl]
            .rfind("/**")
            .expect("sm_set_param's documentation");
        let doc = &header[doc_start..decl];
        for p in PARAMS {
            assert!(
                doc.contains(&format!("\"{}\"", p.name)),
                "the header's sm_set_param documentation lacks \"{}\"",
                p.name
            );
        }
    }

    /// `docs/parameters.md` holds the table as [`markdown_table`] writes it
    /// (`SLIVERMESH_BLESS=1 cargo test --lib param_table` rewrites it).
    #[test]
    fn the_docs_table_is_current() {
        let path = concat!(env!("CARGO_MANIFEST_DIR"), "/docs/parameters.md");
        let text = std::fs::read_to_string(path).unwrap();
        let (begin, end) = ("<!-- params:begin -->\n", "<!-- params:end -->");
        let (Some(b), Some(e)) = (text.find(begin), text.find(end)) else {
            panic!("docs/parameters.md lacks the {begin:?} ... {end:?} lines");
        };
        let current = &text[b + begin.len()..e];
        let want = markdown_table();
        if current != want {
            if std::env::var_os("SLIVERMESH_BLESS").is_some() {
                let fresh = format!("{}{want}{}", &text[..b + begin.len()], &text[e..]);
                std::fs::write(path, fresh).unwrap();
            } else {
                panic!("docs/parameters.md's table is stale: SLIVERMESH_BLESS=1 cargo test --lib param_table");
            }
        }
    }
}
