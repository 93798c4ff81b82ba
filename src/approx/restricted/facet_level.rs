//! The approximate mode's facet level ([`FacetLevel`] on [`SurfaceMesher`]): the restricted
//! Delaunay facets of the input surface and the feature subsegments, the boundary a cell's
//! refinement point must respect. A point inside a restricted facet's surface ball would change
//! the restricted surface: that facet is refined at its surface centre instead (the surface
//! level's own rule). A point inside a feature subsegment's diametric ball queues the
//! subsegment, split before the cell is looked at again. Nothing is refused: next to a small
//! corner the cell level leaves the cells alone before asking.

use super::{key3, Bad, Loc, Restricted, SurfaceMesher};
use crate::delaunay::tables::FACE;
use crate::delaunay::{Cavity, Delaunay, INFINITE};
use crate::refine::levels::{Conflict, FacetLevel, Picker, Request};
use crate::refine::outcome::{BoundaryKind, Outcome};
use crate::run::error::MeshError;

/// What a cell's point would break.
#[derive(Debug)]
pub(crate) enum Encroached {
    /// A restricted facet (the largest surface ball holding the point), and a cavity tet next
    /// to it (a walk hint).
    Facet(Restricted, u32),
    /// Feature subsegments whose diametric balls hold the point.
    Subsegments(Vec<[u32; 2]>),
}

impl FacetLevel for SurfaceMesher<'_> {
    type Element = Encroached;

    fn triangulation(&mut self) -> &mut Delaunay {
        &mut self.dt
    }

    /// What inserting probed point p would break: a restricted facet whose surface ball holds
    /// p (the largest), else feature subsegments whose diametric ball does.
    fn encroached(&self, probed: &Cavity) -> Option<Encroached> {
        let p = probed.point();
        let (cavity, _) = self.dt.cavity(probed);
        let on_surface =
            |v: u32| v != INFINITE && !matches!(self.loc[v as usize], Loc::Volume | Loc::Far);
        let mut best: Option<([u32; 3], f64, u32)> = None;
        for &t in cavity {
            let tv = self.dt.tet(t);
            let n_surface = tv.iter().filter(|&&v| on_surface(v)).count();
            if n_surface < 3 {
                continue;
            }
            for (i, f) in FACE.iter().enumerate() {
                if !self.track.is_restricted(t, i) {
                    continue;
                }
                let face = f.map(|k| tv[k]);
                if !face.iter().all(|&v| on_surface(v)) {
                    continue;
                }
                let key = key3(face);
                if let Some(&(centre, radius, _, _)) = self.track.restricted.get(&key) {
                    if (p - centre).length_squared() < radius * radius
                        && best.is_none_or(|b| radius > b.1)
                    {
                        best = Some((key, radius, t));
                    }
                }
            }
        }
        if let Some((key, _, t)) = best {
            if let Some([(ft, i), _]) = self.dt.find_face(key[0], key[1], key[2]) {
                if let Some(r) = self.facet_at(ft, i) {
                    return Some(Encroached::Facet(r, t));
                }
            }
        }
        let segs = self.encroached_by_cavity(probed);
        (!segs.is_empty()).then_some(Encroached::Subsegments(segs))
    }

    fn judge(&self, e: Encroached, _r: f64, _request: Request) -> Conflict<Encroached> {
        Conflict::Encroaches(e)
    }

    /// A facet is refined now (its surface centre, or the subsegments that centre
    /// encroaches are queued); subsegments are queued for `SurfaceMesher::refine`, which runs
    /// before the next cell. The surface centres need no small-sliver count: `_picker` is
    /// unused.
    fn refine_encroached(
        &mut self,
        e: Encroached,
        _picker: &mut Picker,
    ) -> Result<Outcome, MeshError> {
        Ok(match e {
            Encroached::Facet(r, hint) => self.insert_surface_point(r, hint, Bad::Size),
            Encroached::Subsegments(keys) => {
                for k in keys {
                    self.segs.force_split.insert(k);
                    self.segs.queue.push(k);
                }
                Outcome::Queued(BoundaryKind::Segment)
            }
        })
    }
}

#[cfg(test)]
mod tests {
    use super::super::SurfaceCriteria;
    use super::*;
    use crate::approx::curves::FeatureCurves;
    use crate::delaunay::Probe;
    use crate::io::{read_plc, ReadOptions};
    use crate::run::spacing::ConstantSpacing;
    use crate::surface::features::{FeatureParams, Features};
    use crate::surface::oracle::SurfaceOracle;
    use crate::surface::InputSurface;
    use glam::DVec3;

    /// The approximate mode's facet level, through the interface the cell level uses, on the
    /// remeshed cube ([-1, 1]^3): a point just inside a restricted facet's surface centre is
    /// in its surface ball, so the facet is refined first (never refused); the cube's centre
    /// breaks nothing; refining the facet inserts its surface centre.
    #[test]
    fn restricted_facets_are_refined_before_the_cell_that_encroaches_them() {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("models/off/cube.off");
        let input = read_plc(&path, &ReadOptions::default()).unwrap();
        let plc = crate::plc::validate(&input).unwrap();
        let surface = InputSurface::from_plc(&plc);
        let params = FeatureParams {
            feature_angle: 40.0,
            use_markers: false,
            borders: true,
        };
        let features = Features::detect(&surface, &params);
        let curves = FeatureCurves::new(&surface, &features);
        let oracle = SurfaceOracle::new(&surface);
        let spacing = ConstantSpacing(0.5);
        let criteria = SurfaceCriteria {
            distance: 1e-3,
            bound: 1e-3,
            min_angle_deg: 30.0,
            max_vertices: 100_000,
            feature_floor: 0.0,
            thickness_spacing: 1.0,
            seed: 1,
        };
        let geometry = crate::approx::restricted::Geometry {
            surface: &surface,
            oracle: &oracle,
            curves: &curves,
            patch_of: &features.patch_of,
            repair: None,
        };
        let mut m = SurfaceMesher::new(geometry, &spacing, None, criteria).unwrap();
        let (_, stop) = m.rounds(&mut SurfaceMesher::refine).unwrap();
        assert!(stop.is_none());
        let probe = |m: &mut SurfaceMesher, p: DVec3| match m.dt.probe(p, None) {
            Probe::Cavity(c) => c,
            Probe::Duplicate(_) => panic!("a vertex at {p}"),
        };
        let centre = probe(&mut m, DVec3::ZERO);
        assert!(matches!(
            m.conflict(&centre, 1.0, Request::Shape),
            Conflict::Free
        ));
        // The largest restricted facet, and a point just inside its surface centre.
        let (&face, &(c, radius, _, _)) = m
            .track
            .restricted
            .iter()
            .max_by(|a, b| a.1 .1.total_cmp(&b.1 .1).then(b.0.cmp(a.0)))
            .unwrap();
        let inside = probe(&mut m, c * (1.0 - 0.1 * radius));
        let Conflict::Encroaches(e) = m.conflict(&inside, 10.0 * radius, Request::Shape) else {
            panic!("a point in facet {face:?}'s surface ball conflicts with nothing");
        };
        let Encroached::Facet(r, _) = e else {
            panic!("not the facet: {e:?}");
        };
        assert!(r.radius >= radius, "the largest ball holding the point");
        let n = m.dt.num_vertices();
        let mut picker = Picker::new(
            rand::SeedableRng::seed_from_u64(1),
            0.1,
            20,
            2.0,
            0.05,
            15.0,
        );
        let outcome = m.refine_encroached(e, &mut picker).unwrap();
        assert_eq!(outcome, Outcome::Split(BoundaryKind::Facet));
        assert_eq!(m.dt.num_vertices(), n + 1);
    }
}
