//! Meshes one model file and prints the report: `cargo run --release --example mesh_model -- FILE [--no-refine] [--size H]`
use slivermesh::io::{read_plc, ReadOptions};
use slivermesh::refine::mesh;
use slivermesh::run::params::Params;
use slivermesh::run::spacing::{ConstantSpacing, Spacing};
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let path = std::path::Path::new(&args[1]);
    let merge = path.extension().is_some_and(|e| e == "off" || e == "stl");
    let input = read_plc(
        path,
        &ReadOptions {
            merge_coplanar: merge,
        },
    )
    .expect("read");
    let refine = !args.iter().any(|a| a == "--no-refine");
    let size = args
        .iter()
        .position(|a| a == "--size")
        .map(|i| args[i + 1].parse::<f64>().unwrap());
    let arg = |k: &str| {
        args.iter()
            .position(|a| a == k)
            .map(|i| args[i + 1].parse::<f64>().unwrap())
    };
    let mut params = Params {
        refine,
        ..Params::default()
    };
    if let Some(s) = arg("--sigma") {
        params.sigma0 = s;
    }
    if let Some(s) = arg("--theta") {
        params.min_dihedral = s;
    }
    if let Some(s) = arg("--rho") {
        params.rho0 = s;
    }
    if let Some(s) = arg("--delta") {
        params.delta = s;
    }
    if let Some(s) = arg("--b") {
        params.b = s;
    }
    if let Some(s) = arg("--tries") {
        params.max_tries = s as usize;
    }
    let h = size.map(ConstantSpacing);
    let sp = h.as_ref().map(|s| s as &dyn Spacing);
    match mesh(&input, &params, sp, None) {
        Ok((m, r)) => {
            println!("{}", r.table());
            if let Some(i) = args.iter().position(|a| a == "-o") {
                slivermesh::io::write_mesh(std::path::Path::new(&args[i + 1]), &m, &[]).unwrap();
            }
        }
        Err(e) => println!("error: {e}"),
    }
}
