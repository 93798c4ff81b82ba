//! Consistent orientation: across every edge of exactly two triangles, the two should run the
//! edge in opposite directions. Within each set of triangles joined by such edges, the
//! orientation most of its triangles already have wins, and the others are turned (a few
//! flipped triangles of an exported mesh are mistakes; a shell turned inside out as a whole,
//! such as a cavity's, is meant).

use rustc_hash::FxHashMap;

/// Undirected key of the edge (a, b).
pub(super) fn edge_key(a: u32, b: u32) -> u64 {
    (u64::from(a.min(b)) << 32) | u64::from(a.max(b))
}

/// The triangles using each edge, with whether they run it from its lower vertex.
pub(super) fn edge_uses(triangles: &[[u32; 3]]) -> FxHashMap<u64, Vec<(u32, bool)>> {
    let mut uses: FxHashMap<u64, Vec<(u32, bool)>> = FxHashMap::default();
    for (t, tri) in triangles.iter().enumerate() {
        for k in 0..3 {
            let (a, b) = (tri[k], tri[(k + 1) % 3]);
            uses.entry(edge_key(a, b))
                .or_default()
                .push((t as u32, a < b));
        }
    }
    uses
}

/// Turns the triangles that disagree with the majority of their manifold-connected set;
/// returns how many were turned.
pub(super) fn orient_consistently(triangles: &mut [[u32; 3]]) -> usize {
    let uses = edge_uses(triangles);
    let n = triangles.len();
    // Per triangle: its neighbours across manifold edges, and whether they agree now (run
    // the shared edge in opposite directions).
    let mut across: Vec<Vec<(u32, bool)>> = vec![vec![]; n];
    let mut keys: Vec<&u64> = uses.keys().collect();
    keys.sort_unstable();
    for key in keys {
        if let [(t, dt), (u, du)] = uses[key][..] {
            across[t as usize].push((u, dt != du));
            across[u as usize].push((t, dt != du));
        }
    }
    let mut turn: Vec<Option<bool>> = vec![None; n];
    let mut turned = 0;
    for start in 0..n {
        if turn[start].is_some() {
            continue;
        }
        turn[start] = Some(false);
        let mut set = vec![start as u32];
        let mut next = 0;
        while next < set.len() {
            let t = set[next] as usize;
            next += 1;
            let mine = turn[t].unwrap_or(false);
            for &(u, agree) in &across[t] {
                if turn[u as usize].is_none() {
                    turn[u as usize] = Some(mine ^ !agree);
                    set.push(u);
                }
            }
        }
        let flipped = set
            .iter()
            .filter(|&&t| turn[t as usize] == Some(true))
            .count();
        // Ties keep the first triangle's orientation.
        let majority_turned = 2 * flipped > set.len();
        for &t in &set {
            if turn[t as usize] != Some(majority_turned) {
                triangles[t as usize].swap(1, 2);
                turned += 1;
            }
        }
    }
    turned
}

/// The edges used by exactly one triangle and by more than two.
pub(super) fn open_and_non_manifold(uses: &FxHashMap<u64, Vec<(u32, bool)>>) -> (usize, usize) {
    uses.values().fold((0, 0), |(open, many), u| match u.len() {
        1 => (open + 1, many),
        2 => (open, many),
        _ => (open, many + 1),
    })
}

/// Connected sets of triangles joined by edges (any number of triangles at an edge).
pub(super) fn components(n: usize, uses: &FxHashMap<u64, Vec<(u32, bool)>>) -> usize {
    let mut sets = crate::union_find::UnionFind::new(n);
    for u in uses.values() {
        for w in u.windows(2) {
            sets.union(w[0].0, w[1].0);
        }
    }
    (0..n as u32).filter(|&t| sets.find(t) == t).count()
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The eight faces of an octahedron, outward.
    fn octahedron() -> Vec<[u32; 3]> {
        crate::surface::test_shapes::octahedron_sphere(0).1
    }

    #[test]
    fn a_few_flipped_triangles_are_turned_back() {
        let clean = octahedron();
        let mut t = clean.clone();
        t[3].swap(0, 1);
        t[6].swap(1, 2);
        assert_eq!(orient_consistently(&mut t), 2);
        for (a, b) in t.iter().zip(&clean) {
            // Same cyclic order.
            let rot = |x: [u32; 3], k: usize| [x[k], x[(k + 1) % 3], x[(k + 2) % 3]];
            assert!((0..3).any(|k| rot(*a, k) == *b), "{a:?} vs {b:?}");
        }
    }

    #[test]
    fn a_shell_turned_as_a_whole_stays_turned() {
        let mut t: Vec<[u32; 3]> = octahedron()
            .into_iter()
            .map(|[a, b, c]| [a, c, b])
            .collect();
        let before = t.clone();
        assert_eq!(orient_consistently(&mut t), 0);
        assert_eq!(t, before);
    }

    #[test]
    fn open_edges_and_components_are_counted() {
        let mut t = octahedron();
        t.pop();
        t.push([10, 11, 12]);
        let uses = edge_uses(&t);
        assert_eq!(open_and_non_manifold(&uses), (6, 0));
        assert_eq!(components(t.len(), &uses), 2);
    }
}
