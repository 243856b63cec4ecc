//! Union-find (disjoint sets) over `0..n` with path halving: the components of faces joined
//! through edges (the chart cutter, the parameteriser's consistency check) and of boundary
//! edges (loops).
//!
//! A union always hangs the larger root under the smaller, so every set's root is its
//! smallest member and results do not depend on the order of unions.

/// Disjoint sets over `0..n`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnionFind {
    parent: Vec<usize>,
}

impl UnionFind {
    /// `n` singletons.
    pub fn new(n: usize) -> Self {
        UnionFind {
            parent: (0..n).collect(),
        }
    }

    /// The root of `x`'s set (its smallest member), halving the path on the way.
    pub fn find(&mut self, mut x: usize) -> usize {
        let parent = &mut self.parent;
        while parent[x] != x {
            parent[x] = parent[parent[x]];
            x = parent[x];
        }
        x
    }

    /// Join the sets of `a` and `b`; false when they were one already.
    pub fn union(&mut self, a: usize, b: usize) -> bool {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra == rb {
            return false;
        }
        self.parent[ra.max(rb)] = ra.min(rb);
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn roots_are_smallest_members() {
        let mut u = UnionFind::new(6);
        assert!(u.union(4, 2));
        assert!(u.union(5, 4));
        assert!(!u.union(2, 5));
        assert_eq!(u.find(5), 2);
        assert_eq!(u.find(3), 3);
        assert!(u.union(3, 0));
        assert_eq!(u.find(3), 0);
    }
}
