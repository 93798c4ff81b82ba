use super::*;
use crate::io::{read_plc, ReadOptions};
use crate::refine::SurfaceMode;
use std::path::Path;

fn model(name: &str) -> PlcInput {
    let path = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("models")
        .join(name);
    read_plc(
        &path,
        &ReadOptions {
            merge_coplanar: true,
        },
    )
    .unwrap()
}

fn approximate() -> Params {
    Params {
        surface_mode: SurfaceMode::Approximate,
        ..Params::default()
    }
}

/// Prints the figures of one model (`SM_MODEL=off/fandisk.off cargo test --release
/// approx::tests::explore -- --ignored --nocapture`).
#[test]
#[ignore]
fn explore() {
    let name = std::env::var("SM_MODEL").unwrap_or_else(|_| "off/cube.off".into());
    let input = model(&name);
    let t = std::time::Instant::now();
    let (mesh, report) = mesh(&input, &approximate(), None, None).unwrap();
    let q = crate::quality::measure(&mesh).unwrap();
    println!(
        "{name}: {} tets in {:.2}s",
        mesh.tets.len(),
        t.elapsed().as_secs_f64()
    );
    println!("{report:#?}");
    println!("{}", crate::quality::table(&q));
}
