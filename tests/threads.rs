//! The `threads` parameter changes no mesh and no report figure: keep mode with the automatic
//! spacing and with a `Sync` spacing function (report measures, spacing batches split,
//! degeneracy check, the improver's first objectives) and approximate mode (also the thickness
//! estimate of fandisk's 6,475 input vertices), each on 1, 2 and 3 threads (docs/parallel.md).

mod common;

use slivermesh::parallel::SplitSpacing;
use slivermesh::pipeline;
use slivermesh::run::params::{Params, SurfaceMode};
use slivermesh::run::spacing::{FnSpacing, Spacing};
use slivermesh::DVec3;

/// `report` (a report as JSON) without its timings.
fn untimed(report: &mut serde_json::Value) {
    match report {
        serde_json::Value::Object(fields) => {
            fields.retain(|k, _| !k.starts_with("seconds"));
            fields.values_mut().for_each(untimed);
        }
        serde_json::Value::Array(items) => items.iter_mut().for_each(untimed),
        _ => {}
    }
}

fn same_for_every_thread_count(
    rel: &str,
    mode: SurfaceMode,
    spacing: Option<&dyn Spacing>,
    min_tets: usize,
) {
    let input = common::read_model(rel);
    let run = |threads: usize| {
        let params = Params {
            surface_mode: mode,
            threads,
            ..Params::default()
        };
        let (mesh, _, report) = pipeline::mesh(&input, &params, spacing, None)
            .unwrap_or_else(|e| panic!("{rel}, {threads} threads: {e}"));
        let mut json = serde_json::to_value(&report).unwrap();
        untimed(&mut json);
        (mesh, json)
    };
    let (mesh, report) = run(1);
    assert!(
        mesh.tets.len() >= min_tets,
        "{rel}: {} tets",
        mesh.tets.len()
    );
    for threads in [2, 3] {
        let (m, r) = run(threads);
        assert!(m == mesh, "{rel}: the mesh differs with {threads} threads");
        assert_eq!(
            r, report,
            "{rel}: the report differs with {threads} threads"
        );
    }
}

#[test]
fn keep_mode_meshes_do_not_depend_on_threads() {
    same_for_every_thread_count("poly/tetgen_example.poly", SurfaceMode::Keep, None, 4096);
    let graded = FnSpacing(|p: DVec3| 0.04 + 0.05 * p.x);
    let split = SplitSpacing(&graded);
    same_for_every_thread_count(
        "poly/two_materials.poly",
        SurfaceMode::Keep,
        Some(&split),
        4096,
    );
}

#[test]
fn approximate_mode_meshes_do_not_depend_on_threads() {
    same_for_every_thread_count("off/fandisk.off", SurfaceMode::Approximate, None, 4096);
}
