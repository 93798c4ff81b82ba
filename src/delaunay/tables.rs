//! Static local-index tables for a tetrahedron (v0, v1, v2, v3), positively oriented.

/// `FACE[i]` lists the three local vertices of the face opposite vertex `i`, ordered so that
/// `(FACE[i][0], FACE[i][1], FACE[i][2], i)` is an even permutation of (0, 1, 2, 3). Hence for a
/// positively oriented tet, `orient3d(face i, v_i) > 0`: a point p with `orient3d(face i, p) < 0`
/// lies beyond face i. For a hull tet whose vertex i is the infinite vertex, points strictly
/// outside the convex hull through that face have `orient3d(face i, p) > 0`.
pub const FACE: [[usize; 3]; 4] = [[1, 3, 2], [0, 2, 3], [3, 1, 0], [0, 1, 2]];

#[cfg(test)]
mod tests {
    use super::*;

    fn parity(p: [usize; 4]) -> bool {
        let mut inv = 0;
        for i in 0..4 {
            for j in i + 1..4 {
                if p[i] > p[j] {
                    inv += 1;
                }
            }
        }
        inv % 2 == 0
    }

    #[test]
    fn faces_are_even_permutations() {
        for (i, f) in FACE.iter().enumerate() {
            assert!(parity([f[0], f[1], f[2], i]), "face {i}");
        }
    }
}
