mod common;
use slivermesh::geom::{circumcenter, radius_edge_ratio};
#[test]
fn diag() {
    let m = slivermesh::io::read_mesh(std::path::Path::new(&std::env::var("F").unwrap())).unwrap();
    let faces = m.face_counts();
    let boundary = common::boundary_keys(&m);
    let mut on_boundary = vec![false; m.vertices.len()];
    for b in &m.boundary {
        b.iter().for_each(|&v| on_boundary[v as usize] = true);
    }
    let mut on_interface = vec![false; m.vertices.len()];
    for (f, &k) in &faces {
        if k == 1 && !boundary.contains(f) {
            f.iter().for_each(|&v| on_interface[v as usize] = true);
        }
    }
    let mut n = 0;
    for t in &m.tets {
        let p = t.map(|v| m.vertices[v as usize]);
        let rho = radius_edge_ratio(p[0], p[1], p[2], p[3]);
        if rho > 2.0 {
            n += 1;
            let c = circumcenter(p[0], p[1], p[2], p[3]).unwrap();
            let ni = t.iter().filter(|&&v| on_interface[v as usize]).count();
            let nb = t.iter().filter(|&&v| on_boundary[v as usize]).count();
            let cen = (p[0] + p[1] + p[2] + p[3]) / 4.0;
            if n < 30 {
                println!(
                    "rho {rho:.3} centroid {cen:.4} cc {c:.4} iface verts {ni} boundary verts {nb}"
                );
            }
        }
    }
    println!("{n} tets over 2");
}
