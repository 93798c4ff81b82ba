//! Meshes the unit cube through the safe Rust API (`slivermesh::api::Mesher`) with a graded
//! spacing closure, writes it as .vtu with per-tet quality, and prints the report.
//!
//!     cargo run --release --example rust_cube -- [output.vtu]
use slivermesh::api::{Error, Mesher};
use slivermesh::DVec3;

fn main() -> Result<(), Error> {
    let out = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "cube_rust.vtu".into());
    let corners: Vec<DVec3> = (0..8)
        .map(|i| DVec3::new((i & 1) as f64, ((i >> 1) & 1) as f64, ((i >> 2) & 1) as f64))
        .collect();
    let mut m = Mesher::new();
    m.add_vertices(&corners)?;
    // Vertex ids are 0-based; one planar polygon per facet, with a boundary marker.
    let faces = [
        [0, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    for (k, f) in faces.iter().enumerate() {
        m.add_facet(f, k as i32 + 1)?;
    }
    m.set_param("rho0", 2.0)?
        .set_spacing_fn(|p: DVec3| 0.06 + 0.2 * p.length() / 3f64.sqrt())
        .set_progress(|_, n| {
            if n.is_power_of_two() {
                println!("  {n} vertices");
            }
            true
        });
    let r = m.refine()?.clone();
    m.write(out.as_ref())?;
    println!("wrote {out}");
    println!(
        "vertices {}, tets {}, boundary triangles {}",
        r.n_vertices, r.n_tets, r.n_boundary_faces
    );
    println!(
        "max radius-edge {:.3}, min sigma {:.4}, dihedral angles [{:.2}, {:.2}] deg, complete: {}",
        r.max_rho, r.min_sigma, r.min_dihedral_deg, r.max_dihedral_deg, r.complete
    );
    Ok(())
}
