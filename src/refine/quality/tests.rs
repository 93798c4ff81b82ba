//! Tests of the quality refinement's decisions and books.

use super::*;
use crate::refine::queue::book;

/// The unit cube meshed to a conforming boundary and marked: its domain and regions.
fn settled_cube() -> (Domain, Regions) {
    let input = crate::plc::tests::unit_cube();
    let plc = crate::plc::validate(&input).unwrap();
    let mut dom = Domain::new(&input, &plc).unwrap();
    dom.set_input_angles(&plc, f64::INFINITY);
    assert_eq!(
        dom.recover_boundary(&mut 1_000_000).unwrap(),
        Settled::Conforming
    );
    dom.check().unwrap();
    let regions = dom
        .mark_domain(&plc, super::super::mark::Unseeded::Domain)
        .unwrap();
    (dom, regions)
}

/// The unit cube meshed to a conforming boundary, then a volume vertex put in the
/// diametric ball of subsegment (0, 1) without restoring the boundary (the state a leak in
/// the incremental bookkeeping would leave): the subsegment stays an edge (a hull edge of
/// the cube), encroached. Returns the domain, its regions and an inside tet on the edge.
fn cube_with_unsettled_subsegment() -> (Domain, Regions, u32) {
    let (mut dom, regions) = settled_cube();
    let mid = dom.point(0).midpoint(dom.point(1));
    let p = mid + (DVec3::splat(0.5) - mid).normalize() * 0.2;
    dom.insert_point(p, VertexKind::Volume, None, None).unwrap();
    dom.dirty_segs.clear();
    dom.dirty_tris.clear();
    dom.created_log.clear();
    let t = dom
        .dt
        .vertex_star(0)
        .into_iter()
        .find(|&t| dom.dt.is_finite(t) && dom.dt.tag(t) != 0 && dom.dt.tet(t).contains(&1))
        .expect("an inside tet on the subsegment");
    (dom, regions, t)
}

/// The stale-element case of `yield_to_boundary`: a bad tet's centre encroaches a
/// subsegment much smaller than the tet, so the boundary around the tet is restored first
/// (`resettle_or_refuse`). When that split the very subsegment, the element found before the
/// change is gone and must not be split again: it used to be, which failed with an
/// internal error ("(0, 1) is not a subsegment"; a stale subfacet would have been split
/// at the centre of a triangle no longer in its facet).
#[test]
fn encroached_element_gone_after_resettling_is_not_split() {
    let params = Params::default();
    let spacing = crate::run::spacing::ConstantSpacing(10.0);
    // What restoring the boundary alone does.
    let (mut dom, regions, t) = cube_with_unsettled_subsegment();
    assert_eq!(
        Refiner::new(&mut dom, &params, &spacing, &regions)
            .resettle_or_refuse(t, Refusal::Cascade)
            .unwrap(),
        Outcome::Resettled
    );
    let expected = dom.dt.num_vertices();
    assert!(!dom.subsegs.contains_key(&(0, 1)));
    // A tet 20 times the subsegment's radius asks for it to be split: refused (much
    // smaller than the tet), the boundary is restored, and nothing else is split.
    let (mut dom, regions, t) = cube_with_unsettled_subsegment();
    let bad = Bad {
        class: RATIO,
        tet: t,
        verts: dom.dt.tet(t),
    };
    let mut refiner = Refiner::new(&mut dom, &params, &spacing, &regions);
    let conflict = refiner
        .dom
        .judge(Boundary::Segment(0, 1), 20.0 * 0.5, Request::Shape);
    let outcome = refiner
        .yield_to_boundary(bad.tet, conflict)
        .expect("no split of a subsegment that is gone");
    assert_eq!(outcome, Some(Outcome::Resettled));
    assert_eq!(dom.dt.num_vertices(), expected);
}

/// The books `run` keeps, from the outcomes: on the settled unit cube, a tet asked to
/// split a subsegment a fifth of its size finds nothing to restore around it: refused for
/// a cascade and remembered, so looked at again it is futile at once; a centroid on a
/// vertex is a duplicate. Each is counted under its reason and in the total.
#[test]
fn refusals_are_counted_and_cascades_remembered() {
    let (mut dom, regions) = settled_cube();
    let t = dom
        .dt
        .vertex_star(0)
        .into_iter()
        .find(|&t| dom.dt.is_finite(t) && dom.dt.tag(t) != 0)
        .expect("an inside tet at vertex 0");
    let seg = *dom.subsegs.keys().min().unwrap();
    let rb = 0.5 * dom.point(seg.0).distance(dom.point(seg.1));
    let bad = Bad {
        class: RATIO,
        tet: t,
        verts: dom.dt.tet(t),
    };
    let (params, spacing) = (
        Params::default(),
        crate::run::spacing::ConstantSpacing(10.0),
    );
    let mut refiner = Refiner::new(&mut dom, &params, &spacing, &regions);
    let n = refiner.dom.dt.num_vertices();
    let conflict = refiner
        .dom
        .judge(Boundary::Segment(seg.0, seg.1), 5.0 * rb, Request::Shape);
    let outcome = refiner.yield_to_boundary(t, conflict).unwrap().unwrap();
    assert_eq!(outcome, Outcome::Refused(Refusal::Cascade));
    assert!(book(&mut refiner, bad, outcome, n).unwrap());
    let again = refiner.refine_tet(bad, true).unwrap();
    assert_eq!(again, Outcome::Refused(Refusal::Futile));
    assert!(book(&mut refiner, bad, again, n).unwrap());
    let on_vertex = refiner.dom.point(0);
    let duplicate = refiner.insert_volume_point(on_vertex, 1.0, t).unwrap();
    assert_eq!(duplicate, Outcome::Refused(Refusal::Duplicate));
    assert!(book(&mut refiner, bad, duplicate, n).unwrap());
    assert_eq!(refiner.dom.dt.num_vertices(), n);
    let r = &refiner.refusals;
    assert_eq!((r.cascade, r.futile, r.duplicate, r.total), (1, 1, 1, 3));
    assert!(refiner.blocked_by_small_angle.is_empty());
}

/// Tets that are flat by construction (three vertices on one segment, or four in one
/// facet, one of them inserted) are named so; one reaching across the cube is not. (Four
/// input vertices are exact: the predicates see their flatness.)
#[test]
fn flat_by_construction_names_collinear_and_coplanar_tets() {
    let input = crate::plc::tests::unit_cube();
    let plc = crate::plc::validate(&input).unwrap();
    let mut dom = Domain::new(&input, &plc).unwrap();
    assert_eq!(
        dom.recover_boundary(&mut 1_000_000).unwrap(),
        Settled::Conforming
    );
    let s = dom
        .segments
        .iter()
        .position(|s| s.ends.contains(&0) && s.ends.contains(&1))
        .unwrap();
    let mid = dom.segment_split_point(0, 1);
    let m = dom.split_subsegment(0, 1, mid, None).unwrap();
    assert_eq!(dom.kind[m as usize], VertexKind::Segment(s as u32));
    let f = dom.segments[s].facets[0];
    let in_f: Vec<u32> = dom.facets[f as usize]
        .vertices()
        .filter(|&v| v < 8)
        .collect();
    assert_eq!(in_f.len(), 4);
    let off_f = (0..8).find(|v| !in_f.contains(v)).unwrap();
    assert!(dom.flat_by_construction([0, m, 1, off_f]));
    assert!(dom.flat_by_construction([m, in_f[1], in_f[2], in_f[3]]));
    let [a, b, c] = [in_f[0], in_f[1], in_f[2]];
    assert!(!dom.flat_by_construction([a, b, c, off_f]));
    let x = dom
        .insert_point(DVec3::splat(0.5), VertexKind::Volume, None, None)
        .unwrap();
    assert!(!dom.flat_by_construction([0, m, x, off_f]));
}

/// Keep mode's facet level, through the interface the cell level uses, on the unit cube
/// refined to spacing 0.3: a point well inside breaks nothing; a point just above the middle
/// of the bottom facet encroaches a subfacet there, and the policy decides by the request and
/// the asking tet's size. Refining that subfacet splits it and leaves the boundary conforming;
/// Li's choice in a ball around an inside point keeps a point that breaks nothing.
#[test]
fn plc_facet_level_conflicts_follow_the_request() {
    use super::super::levels::pick_in_ball;
    let (mut dom, regions) = settled_cube();
    let params = Params::default();
    let spacing = crate::run::spacing::ConstantSpacing(0.3);
    Refiner::new(&mut dom, &params, &spacing, &regions)
        .run(&mut |_| true)
        .unwrap();
    dom.check().unwrap();
    let probe = |dom: &mut Domain, p: DVec3| match dom.dt.probe(p, None) {
        Probe::Cavity(c) => c,
        Probe::Duplicate(_) => panic!("a vertex at {p}"),
    };
    let all = [
        Request::Shape,
        Request::ShapeNearSmallAngle,
        Request::SizeNearSmallAngle,
    ];
    let inside = DVec3::new(0.45, 0.52, 0.48);
    let inside_cavity = probe(&mut dom, inside);
    for request in all {
        let conflict = dom.conflict(&inside_cavity, 0.2, request);
        assert!(matches!(conflict, Conflict::Free), "{conflict:?}");
    }
    let low = probe(&mut dom, DVec3::new(0.5, 0.5, 1e-3));
    let Some(b @ Boundary::Facet(_, t)) = dom.encroached(&low) else {
        panic!("no subfacet encroached");
    };
    let [x, y, z] = t.map(|v| dom.point(v));
    let rb = crate::geom::equatorial_ball(x, y, z).unwrap().1;
    let verdict = |r: f64, request| format!("{:?}", dom.conflict(&low, r, request));
    assert_eq!(
        verdict(2.0 * rb, Request::Shape),
        format!("Encroaches({b:?})")
    );
    assert_eq!(verdict(10.0 * rb, Request::Shape), "Refused(Cascade)");
    assert_eq!(
        verdict(2.0 * rb, Request::ShapeNearSmallAngle),
        "Refused(NearSmallAngle)"
    );
    assert_eq!(
        verdict(2.0 * rb, Request::SizeNearSmallAngle),
        format!("Encroaches({b:?})")
    );
    assert_eq!(
        verdict(10.0 * rb, Request::SizeNearSmallAngle),
        "Refused(CentroidCascade)"
    );
    let rng = rand::SeedableRng::seed_from_u64(1);
    let mut picker = Picker::new(rng, params.delta, 20, params.b, params.sigma0, 15.0);
    let n = dom.dt.num_vertices();
    let outcome = dom.refine_encroached(b, &mut picker).unwrap();
    assert!(matches!(outcome, Outcome::Split(_)), "{outcome:?}");
    assert!(dom.dt.num_vertices() > n);
    assert!(dom.dirty_segs.is_empty() && dom.dirty_tris.is_empty());
    let before = dom.dt.num_vertices();
    assert_eq!(
        dom.recover_boundary(&mut 1_000_000).unwrap(),
        Settled::Conforming
    );
    assert_eq!(
        dom.dt.num_vertices(),
        before,
        "the split left it conforming"
    );
    let inside_cavity = probe(&mut dom, inside);
    let t = dom.dt.locate_point(inside, None);
    let chosen = pick_in_ball(&mut dom, &mut picker, inside, Some(inside_cavity), 0.2, t);
    let chosen = chosen.expect("a point that breaks nothing");
    assert!(chosen.point().distance(inside) <= params.delta * 0.2);
    assert!(dom.encroached(&chosen).is_none());
}

/// The boundary complex's invariants (`Domain::check`) hold after boundary recovery and after
/// refinement on the small models of both kinds and on part.off (small input angles). Before
/// a subfacet that yielded to a subsegment split was queued again, tetgen_example.poly was left
/// with an encroached subfacet after recovery. tetgen_example and drilled_block have facet hole
/// points: the facet triangulations must leave the validator's hole loops uncovered (their area
/// is checked against the validator's). And the check can fail: a volume vertex left
/// in a subsegment's diametric ball (and its subfacets' equatorial balls) is found.
#[test]
fn boundary_complex_invariants_hold_through_refinement() {
    let (dom, _, _) = cube_with_unsettled_subsegment();
    let err = dom.check().unwrap_err();
    assert!(err.contains("Encroached"), "{err}");
    let params = Params::default();
    for name in [
        "poly/cube.poly",
        "poly/lshape.poly",
        "poly/box_with_cavity.poly",
        "poly/two_materials.poly",
        "poly/tetgen_example.poly",
        "poly/drilled_block.poly",
        "off/cross.off",
        "off/star.off",
        "off/part.off",
    ] {
        let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("models")
            .join(name);
        let options = crate::io::ReadOptions {
            merge_coplanar: true,
        };
        let input = crate::io::read_plc(&path, &options).unwrap();
        let plc = crate::plc::validate(&input).unwrap();
        let mut dom = Domain::new(&input, &plc).unwrap();
        dom.set_input_angles(&plc, params.small_angle_reach);
        assert_eq!(
            dom.recover_boundary(&mut 1_000_000).unwrap(),
            Settled::Conforming
        );
        dom.check()
            .unwrap_or_else(|e| panic!("{name} after recovery: {e}"));
        let regions = dom
            .mark_domain(&plc, super::super::mark::Unseeded::Domain)
            .unwrap();
        let spacing = super::super::AutoSpacing::from_boundary(&dom);
        let mut refiner = Refiner::new(&mut dom, &params, &spacing, &regions);
        refiner.run(&mut |_| true).unwrap();
        assert!(refiner.stop_reason.is_none(), "{name}");
        dom.check()
            .unwrap_or_else(|e| panic!("{name} after refinement: {e}"));
    }
}
