use slivermesh::geom::*;
use slivermesh::io::*;
use slivermesh::refine::*;
fn main() {
    let input = read_plc(
        std::path::Path::new("../shared/models/poly/cube.poly"),
        &ReadOptions::default(),
    )
    .unwrap();
    let p = Params {
        sigma0: 0.05,
        ..Params::default()
    };
    let (m, _) = mesh(&input, &p, Some(&ConstantSpacing(0.1)), None).unwrap();
    let mut worst = (180.0, 0);
    for (i, t) in m.tets.iter().enumerate() {
        let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
        let q = TetQuality::of(a, b, c, d);
        if q.min_dihedral < worst.0 {
            worst = (q.min_dihedral, i);
        }
    }
    let t = m.tets[worst.1];
    let [a, b, c, d] = t.map(|v| m.vertices[v as usize]);
    let q = TetQuality::of(a, b, c, d);
    println!(
        "{:?}\n{:?}\nangles {:?}\nrho {} sigma {}",
        t,
        q,
        dihedral_angles(a, b, c, d),
        radius_edge_ratio(a, b, c, d),
        sigma(a, b, c, d)
    );
    println!("{a} {b} {c} {d}");
}
