//! Measures what (rho0, sigma0, delta, b) combinations reach on the acute-free models and what
//! they cost; prints a Markdown table (docs/parameters.md holds a run of it).
//!
//!     cargo run --release --example param_study [size]

use slivermesh::io::{read_plc, ReadOptions};
use slivermesh::refine::mesh;
use slivermesh::run::params::Params;
use slivermesh::run::spacing::ConstantSpacing;
use std::path::PathBuf;

fn main() {
    let size: f64 = std::env::args()
        .nth(1)
        .map_or(0.08, |s| s.parse().expect("size"));
    let models = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("models");
    let inputs = [
        "poly/cube.poly",
        "poly/lshape.poly",
        "poly/two_materials.poly",
        "poly/drilled_block.poly",
        "poly/box_with_cavity.poly",
        "poly/stairs.poly",
        "poly/thin_plate.poly",
        "poly/tetgen_example.poly",
        "off/cube.off",
        "off/cross.off",
    ];
    // (rho0, sigma0, min_dihedral, delta, b)
    let combos: &[(f64, f64, f64, f64, f64)] = &[
        (2.0, 0.0, 0.0, 0.3, 4.0),
        (2.0, 0.02, 0.0, 0.3, 4.0),
        (2.0, 0.05, 0.0, 0.3, 4.0),
        (2.0, 0.08, 0.0, 0.3, 4.0),
        (2.0, 0.02, 10.0, 0.3, 4.0),
        (2.0, 0.02, 15.0, 0.3, 4.0),
        (2.0, 0.02, 20.0, 0.3, 4.0),
        (2.0, 0.02, 25.0, 0.3, 4.0),
        (2.0, 0.02, 28.0, 0.3, 4.0),
        (2.0, 0.02, 30.0, 0.3, 4.0),
        (1.5, 0.02, 15.0, 0.3, 4.0),
        (2.0, 0.02, 20.0, 0.1, 4.0),
        (2.0, 0.02, 20.0, 0.5, 4.0),
        (2.0, 0.02, 20.0, 0.3, 2.0),
        (2.0, 0.02, 20.0, 0.3, 8.0),
        (2.0, 0.02, 20.0, 0.3, 1.0), // b = 1: reject only very local slivers
    ];
    println!("size h = {size} (R <= h)\n");
    println!("| model | rho0 | sigma0 | min dihedral bound | delta | b | vertices | tets | max rho | min sigma | min dihedral | complete | seconds |");
    println!("|---|---|---|---|---|---|---|---|---|---|---|---|---|");
    for rel in inputs {
        // As the CLI does: coplanar triangles of a surface become polygon facets.
        let merge_coplanar = rel.ends_with(".off");
        let input = read_plc(&models.join(rel), &ReadOptions { merge_coplanar }).expect("read");
        for &(rho0, sigma0, min_dihedral, delta, b) in combos {
            let params = Params {
                rho0,
                sigma0,
                min_dihedral,
                delta,
                b,
                max_vertices: 150_000,
                ..Params::default()
            };
            let h = ConstantSpacing(size);
            match mesh(&input, &params, Some(&h), None) {
                Ok((_, r)) => println!(
                    "| {rel} | {rho0} | {sigma0} | {min_dihedral} | {delta} | {b} | {} | {} | {:.3} | {:.4} | {:.2} | {} | {:.2} |",
                    r.n_vertices, r.n_tets, r.max_rho, r.min_sigma, r.min_dihedral_deg, r.complete, r.seconds_total
                ),
                Err(e) => println!(
                    "| {rel} | {rho0} | {sigma0} | {min_dihedral} | {delta} | {b} | error: {e} |||||||"
                ),
            }
        }
    }
}
