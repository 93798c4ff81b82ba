//! The holes of a surface as loops of edges, each spanned by a fan of virtual triangles.
//!
//! An oriented surface's boundary is the set of edges its triangles do not run as often in one
//! direction as in the other (a hole's rim, a crack's two lips, a flipped triangle's edges
//! when orientation could not be fixed). Those edges, each taken as often as it is unbalanced
//! and against the surface's direction, form closed loops (at every vertex as many leave as
//! arrive), found here by walking them. A fan from each loop's centre then closes the surface
//! as an oriented cycle, so that a winding count carried across triangles is exact.
//!
//! The fans are bookkeeping, not geometry: their winding number is subtracted again
//! (`labels::SolidLabels`), so where a fan lies does not change which points are inside.

use super::orient::edge_key;
use glam::DVec3;
use rustc_hash::FxHashMap;

/// The fan closing one hole.
#[derive(Debug, Clone)]
pub struct Hole {
    /// The fan's apex (appended to the vertices): the rim's length-weighted centre.
    pub centre: DVec3,
    /// The largest distance from `centre` to the rim.
    pub radius: f64,
}

/// The loops of unbalanced edges of `triangles`, each ordered so that a fan over it balances
/// them; in vertex id order from the smallest unbalanced vertex (deterministic).
pub(super) fn rim_loops(triangles: &[[u32; 3]]) -> Vec<Vec<u32>> {
    let mut net: FxHashMap<u64, i32> = FxHashMap::default();
    for t in triangles {
        for k in 0..3 {
            let (a, b) = (t[k], t[(k + 1) % 3]);
            *net.entry(edge_key(a, b)).or_default() += if a < b { 1 } else { -1 };
        }
    }
    // The fan runs each unbalanced edge against the surface's net direction.
    let mut out: FxHashMap<u32, Vec<u32>> = FxHashMap::default();
    for (&key, &k) in &net {
        let (lo, hi) = ((key >> 32) as u32, key as u32);
        let (from, to) = if k > 0 { (hi, lo) } else { (lo, hi) };
        for _ in 0..k.unsigned_abs() {
            out.entry(from).or_default().push(to);
        }
    }
    for targets in out.values_mut() {
        // Popped from the end: the smallest target first.
        targets.sort_unstable_by(|a, b| b.cmp(a));
    }
    let mut starts: Vec<u32> = out.keys().copied().collect();
    starts.sort_unstable();
    let mut loops = Vec::new();
    for s in starts {
        while out.get(&s).is_some_and(|l| !l.is_empty()) {
            // Walk until a vertex repeats; the part of the path since its first visit is a
            // loop, cut off, and the walk goes on from there.
            let mut path = vec![s];
            let mut at: FxHashMap<u32, usize> = FxHashMap::default();
            at.insert(s, 0);
            while let Some(w) = path
                .last()
                .and_then(|v| out.get_mut(v))
                .and_then(|l| l.pop())
            {
                if let Some(&i) = at.get(&w) {
                    for v in &path[i + 1..] {
                        at.remove(v);
                    }
                    loops.push(path.split_off(i));
                    path.push(w);
                    if path.len() == 1 {
                        break;
                    }
                } else {
                    at.insert(w, path.len());
                    path.push(w);
                }
            }
        }
    }
    loops
}

/// The fan over `rim` (vertex ids into `points`): its apex, and its triangles with the apex
/// numbered `apex`.
pub(super) fn fan(points: &[DVec3], rim: &[u32], apex: u32) -> (Hole, Vec<[u32; 3]>) {
    let m = rim.len();
    let (mut sum, mut weight) = (DVec3::ZERO, 0.0);
    for i in 0..m {
        let (a, b) = (points[rim[i] as usize], points[rim[(i + 1) % m] as usize]);
        let l = (b - a).length();
        sum += l * (a + b) / 2.0;
        weight += l;
    }
    let centre = if weight > 0.0 {
        sum / weight
    } else {
        points[rim[0] as usize]
    };
    let radius = rim
        .iter()
        .map(|&v| (points[v as usize] - centre).length())
        .fold(0.0, f64::max);
    let triangles = (0..m).map(|i| [rim[i], rim[(i + 1) % m], apex]).collect();
    (Hole { centre, radius }, triangles)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Net uses of each directed edge, for checking that a set of triangles is a cycle.
    fn unbalanced(triangles: &[[u32; 3]]) -> usize {
        let mut net: FxHashMap<u64, i32> = FxHashMap::default();
        for t in triangles {
            for k in 0..3 {
                let (a, b) = (t[k], t[(k + 1) % 3]);
                *net.entry(edge_key(a, b)).or_default() += if a < b { 1 } else { -1 };
            }
        }
        net.values().filter(|&&k| k != 0).count()
    }

    #[test]
    fn fans_over_the_loops_close_an_open_surface() {
        // A square pyramid without its base and with one side missing, plus a lone triangle.
        let points = vec![
            DVec3::new(0.0, 0.0, 0.0),
            DVec3::new(1.0, 0.0, 0.0),
            DVec3::new(1.0, 1.0, 0.0),
            DVec3::new(0.0, 1.0, 0.0),
            DVec3::new(0.5, 0.5, 1.0),
            DVec3::new(5.0, 0.0, 0.0),
            DVec3::new(6.0, 0.0, 0.0),
            DVec3::new(5.0, 1.0, 0.0),
        ];
        let mut triangles = vec![[0, 1, 4], [1, 2, 4], [2, 3, 4], [5, 6, 7]];
        let loops = rim_loops(&triangles);
        assert_eq!(loops.len(), 2);
        let mut points = points;
        for rim in &loops {
            let apex = points.len() as u32;
            let (hole, fan) = fan(&points, rim, apex);
            points.push(hole.centre);
            triangles.extend(fan);
        }
        assert_eq!(unbalanced(&triangles), 0);
    }

    #[test]
    fn two_loops_through_one_vertex_are_split() {
        // Two triangles touching at vertex 0 only.
        let triangles = vec![[0, 1, 2], [0, 3, 4]];
        let loops = rim_loops(&triangles);
        assert_eq!(loops.len(), 2);
        assert!(loops.iter().all(|l| l.len() == 3));
    }
}
