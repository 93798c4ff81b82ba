//! Keep mode's judgement of a tet (the cell level's classes): too large for the spacing,
//! radius-edge ratio over rho0, or a sliver. Read-only, so the tets an insertion batch created
//! are judged on the run's threads (`quality.rs`), the spacing evaluated between the two
//! halves in one batch.

use super::domain::Domain;
use super::levels::Picker;
use super::quality::Bad;
use super::queue::Class;
use crate::geom::screen::{longest_edge_direct as longest_edge, sliver_measures};
use crate::geom::{circum_offset_crossed, orient3d};
use crate::run::params::Params;
use glam::DVec3;

const SIZE: Class = Class::Size;
const RATIO: Class = Class::Ratio;
const SLIVER: Class = Class::Sliver;

/// What judging a tet reads.
pub(super) struct Classifier<'a> {
    pub dom: &'a Domain,
    pub params: &'a Params,
    pub picker: &'a Picker,
}

/// A tet's classification before its spacing is known ([`Classifier::prepare`]).
pub(super) enum Step {
    Done(Option<Bad>),
    Need(Pending),
}

/// A tet waiting for the spacing at `query` (the centroid next to a small angle, where
/// `circum` is None; else the circumcentre, `circum` its offset from the first vertex and the
/// orientation determinant).
#[derive(Clone, Copy)]
pub(super) struct Pending {
    tet: u32,
    verts: [u32; 4],
    pub(super) tag: u32,
    pub(super) query: DVec3,
    circum: Option<(DVec3, f64)>,
}

impl Classifier<'_> {
    /// Classification of tet `t` up to the spacing it needs: done (not a domain tet, or a
    /// sliver without a circumsphere), or the point whose spacing decides the rest
    /// ([`Self::finish`]). Next to a small angle that point is the centroid (size
    /// by the longest edge), else the circumcentre.
    pub(super) fn prepare(&self, t: u32) -> Step {
        // Tets logged as created may have been deleted again by a later insertion.
        if !self.dom.dt.is_alive(t) {
            return Step::Done(None);
        }
        let tag = self.dom.dt.tag(t);
        if tag == 0 || !self.dom.dt.is_finite(t) {
            return Step::Done(None);
        }
        let verts = self.dom.dt.tet(t);
        let [a, b, c, d] = verts.map(|v| self.dom.point(v));
        let near = verts.iter().any(|&v| self.dom.near_small_angle(v));
        if near {
            // Next to a small input angle size is measured by the longest edge: the tets there
            // may stay flat, and a flat tet's circumradius says nothing about its size.
            return Step::Need(Pending {
                tet: t,
                verts,
                tag,
                query: (a + b + c + d) * 0.25,
                circum: None,
            });
        }
        let (u, v, w) = (b - a, c - a, d - a);
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let lu = [u.length_squared(), v.length_squared(), w.length_squared()];
        let det = orient3d(a, b, c, d);
        let Some(offset) = circum_offset_crossed([vw, wu, uv], lu, det) else {
            return Step::Done(Some(Bad {
                class: SLIVER,
                tet: t,
                verts,
            }));
        };
        Step::Need(Pending {
            tet: t,
            verts,
            tag,
            query: a + offset,
            circum: Some((offset, det)),
        })
    }

    /// The rest of [`Self::prepare`] given `f`, the spacing at the pending tet's
    /// query point (region cap applied): the tet's badness class, if any.
    pub(super) fn finish(&self, p: &Pending, f: f64) -> Option<Bad> {
        let Pending {
            tet: t,
            verts,
            circum,
            ..
        } = *p;
        let [a, b, c, d] = verts.map(|v| self.dom.point(v));
        let bad = |class| {
            Some(Bad {
                class,
                tet: t,
                verts,
            })
        };
        let near = circum.is_none();
        if near {
            let xi = longest_edge(a, b, c, d) / (EDGE_PER_RADIUS * f);
            if xi > self.params.size_factor {
                return bad(SIZE);
            }
        }
        // The measures, each computed only when the tests before it pass, sharing the edge
        // vectors and cross products: the circumsphere (geom's one formula), then the sliver
        // screen (geom::screen).
        let (u, v, w) = (b - a, c - a, d - a);
        let (vw, wu, uv) = (v.cross(w), w.cross(u), u.cross(v));
        let lu = [u.length_squared(), v.length_squared(), w.length_squared()];
        let (offset, det) = match circum {
            Some(known) => known,
            None => {
                let det = orient3d(a, b, c, d);
                let Some(offset) = circum_offset_crossed([vw, wu, uv], lu, det) else {
                    return bad(SLIVER);
                };
                (offset, det)
            }
        };
        let circumradius = offset.length();
        if !near {
            let xi = circumradius / f;
            if xi > self.params.size_factor {
                return bad(SIZE);
            }
        }
        let e = [
            lu[0],
            lu[1],
            lu[2],
            (c - b).length_squared(),
            (d - b).length_squared(),
            (d - c).length_squared(),
        ];
        let l2 = e[0].min(e[1]).min(e[2]).min(e[3]).min(e[4]).min(e[5]);
        let rho = circumradius / l2.sqrt();
        if rho > self.params.rho0 {
            return bad(RATIO);
        }
        let n = [
            (d - b).cross(c - b).length_squared(),
            vw.length_squared(),
            wu.length_squared(),
            uv.length_squared(),
        ];
        if self.picker.screen().clears(det, e, l2, n) {
            return None;
        }
        let (sigma, max_cos_dihedral) = sliver_measures(a, b, c, d, l2);
        if self.picker.slivers.is_sliver(sigma, max_cos_dihedral) {
            bad(SLIVER)
        } else {
            None
        }
    }
}

/// Longest edge over circumradius of a regular tet (sqrt(8/3)): the size measure next to small
/// angles compares the longest edge with this many times f.
const EDGE_PER_RADIUS: f64 = 1.632_993_161_855_452;
