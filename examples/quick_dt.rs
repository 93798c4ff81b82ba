use rand::{Rng, SeedableRng};
fn main() {
    let n: usize = std::env::args()
        .nth(1)
        .map(|s| s.parse().unwrap())
        .unwrap_or(1_000_000);
    let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(1);
    let pts: Vec<slivermesh::DVec3> = (0..n)
        .map(|_| slivermesh::DVec3::new(rng.gen(), rng.gen(), rng.gen()))
        .collect();
    let t = std::time::Instant::now();
    let (dt, _) = slivermesh::delaunay::Delaunay::from_points(&pts).unwrap();
    let s = t.elapsed().as_secs_f64();
    println!(
        "n={n} tets={} secs={s:.3} bytes/tet={:.1}",
        dt.num_finite_tets(),
        dt.memory_bytes() as f64 / dt.num_finite_tets() as f64
    );
}
