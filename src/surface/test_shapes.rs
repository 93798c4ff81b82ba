//! Test surfaces shared by the surface modules' unit tests.

use glam::DVec3;

/// An octahedron subdivided `levels` times (each triangle into four at its edge midpoints)
/// and pushed onto the unit sphere, outward; new vertices in order of first use.
pub(crate) fn octahedron_sphere(levels: u32) -> (Vec<DVec3>, Vec<[u32; 3]>) {
    let mut v = vec![
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ];
    let mut t: Vec<[u32; 3]> = vec![
        [0, 2, 4],
        [2, 1, 4],
        [1, 3, 4],
        [3, 0, 4],
        [2, 0, 5],
        [1, 2, 5],
        [3, 1, 5],
        [0, 3, 5],
    ];
    for _ in 0..levels {
        let mut mid = std::collections::HashMap::new();
        let mut next = vec![];
        for [a, b, c] in t {
            let mut m = |x: u32, y: u32| {
                *mid.entry((x.min(y), x.max(y))).or_insert_with(|| {
                    v.push(((v[x as usize] + v[y as usize]) / 2.0).normalize());
                    v.len() as u32 - 1
                })
            };
            let (ab, bc, ca) = (m(a, b), m(b, c), m(c, a));
            next.extend([[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]);
        }
        t = next;
    }
    (v, t)
}
