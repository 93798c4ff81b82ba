use slivermesh::io::*;
fn main() {
    let m = read_mesh(std::path::Path::new("/tmp/slivermesh-demo.vtu")).unwrap();
    let mut e = vec![];
    for t in &m.tets {
        for i in 0..4 {
            for j in i + 1..4 {
                let (a, b) = (t[i], t[j]);
                e.push((
                    m.vertices[a as usize].distance(m.vertices[b as usize]),
                    a.min(b),
                    a.max(b),
                ));
            }
        }
    }
    e.sort_by(|x, y| x.0.total_cmp(&y.0));
    e.dedup();
    for x in &e[..6] {
        println!(
            "{:?} {} {}",
            x, m.vertices[x.1 as usize], m.vertices[x.2 as usize]
        );
    }
}
