//! The improvement gives the same mesh and the same figures for every thread count (issue 39):
//! with several threads its plans are made ahead in batches on the run's threads and used only
//! where still valid (`improve::batch`), so the changes must be those of the one-thread run.
//! On refined meshes with thousands of tets below the target, so that many batches are planned
//! on several threads and many plans go stale.

mod common;

use slivermesh::improve::{self, quality::min_sin, Options};
use slivermesh::parallel::with_threads;
use slivermesh::pipeline;
use slivermesh::run::params::{Params, SurfaceMode};
use slivermesh::TetMesh;

/// The refinement's mesh of `rel` in keep mode, unimproved.
fn refined(rel: &str) -> TetMesh {
    let params = Params {
        surface_mode: SurfaceMode::Keep,
        improve: false,
        threads: 1,
        ..Params::default()
    };
    let input = common::read_model(rel);
    pipeline::mesh(&input, &params, None, None)
        .unwrap_or_else(|e| panic!("{rel}: {e}"))
        .0
}

fn below_target(m: &TetMesh, target_deg: f64) -> usize {
    let floor = target_deg.to_radians().sin();
    m.tets
        .iter()
        .filter(|t| {
            let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
            min_sin(a, b, c, d) < floor
        })
        .count()
}

/// `improve::improve` of `rel`'s refined mesh (the input's facets known) on 1, 2, 3 and 4
/// threads: the same mesh, bit for bit, and the same counts.
fn same_improvement(rel: &str, opts: &Options, min_bad: usize) {
    let input = common::read_model(rel);
    let mesh = refined(rel);
    let bad = below_target(&mesh, opts.target_deg);
    assert!(bad >= min_bad, "{rel}: only {bad} tets below the target");
    let run =
        |threads: usize| with_threads(threads, || improve::improve(&mesh, Some(&input), opts));
    let (want, stats) = run(1);
    assert!(want != mesh, "{rel}: the improvement changed nothing");
    let counts = |s: &slivermesh::run::report::ImproveStats| {
        let mut s = s.clone();
        (s.seconds, s.seconds_plans, s.seconds_smooth) = (0.0, 0.0, 0.0);
        format!("{s:?}")
    };
    for threads in [2, 3, 4] {
        let (got, s) = run(threads);
        assert!(
            got == want,
            "{rel}: the mesh differs with {threads} threads"
        );
        assert_eq!(counts(&s), counts(&stats), "{rel}: {threads} threads");
    }
}

#[test]
fn joint_same_mesh_for_every_thread_count() {
    same_improvement("off/joint.off", &Options::default(), 4000);
}

/// With the radius-edge bound kept (its vetoes are counted by plans made ahead too) and a
/// higher target, so that smoothing, insertion and deletion are planned ahead as well.
#[test]
fn tetgen_example_same_mesh_for_every_thread_count() {
    let opts = Options {
        target_deg: 30.0,
        keep_rho: 2.0,
        ..Options::default()
    };
    same_improvement("poly/tetgen_example.poly", &opts, 1000);
}
