//! Disjoint sets over `0..n` (path halving; the smaller id is always the root, so a set's root
//! is its smallest member and results do not depend on the order of unions). The crate's one
//! union-find: plc (cells, coplanar merging), refine (domain marking, existing meshes) and
//! improve (boundary patches).

#[derive(Debug, Clone)]
pub(crate) struct UnionFind(Vec<u32>);

impl UnionFind {
    /// `n` singletons.
    pub(crate) fn new(n: usize) -> Self {
        UnionFind((0..n as u32).collect())
    }

    /// The root (smallest member) of `x`'s set.
    #[inline]
    pub(crate) fn find(&mut self, mut x: u32) -> u32 {
        while self.0[x as usize] != x {
            let g = self.0[self.0[x as usize] as usize];
            self.0[x as usize] = g;
            x = g;
        }
        x
    }

    /// Merges the sets of `a` and `b`.
    #[inline]
    pub(crate) fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.0[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::UnionFind;

    #[test]
    fn roots_are_smallest_members_whatever_the_order() {
        let mut uf = UnionFind::new(6);
        uf.union(5, 3);
        uf.union(3, 4);
        uf.union(1, 2);
        uf.union(4, 2);
        assert_eq!((1..6).map(|x| uf.find(x)).collect::<Vec<_>>(), [1; 5]);
        assert_eq!(uf.find(0), 0);
    }
}
