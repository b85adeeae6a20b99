//! Disjoint sets over `0..n` (union–find with path halving), for grouping vertices:
//! coincident ones when welding, those of one boundary loop in the mesh statistics.

/// Disjoint sets over `0..n`; each set is represented by its smallest element.
#[derive(Debug, Clone)]
pub struct UnionFind {
    parent: Vec<u32>,
}

impl UnionFind {
    /// `n` singleton sets.
    pub fn new(n: usize) -> Self {
        Self {
            parent: (0..n as u32).collect(),
        }
    }

    /// The representative of `v`'s set (its smallest element).
    pub fn find(&mut self, mut v: u32) -> u32 {
        let parent = &mut self.parent;
        while parent[v as usize] != v {
            parent[v as usize] = parent[parent[v as usize] as usize];
            v = parent[v as usize];
        }
        v
    }

    /// Merges the sets of `a` and `b`.
    pub fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sets_merge_and_keep_their_smallest_element() {
        let mut sets = UnionFind::new(6);
        sets.union(4, 2);
        sets.union(5, 4);
        sets.union(1, 3);
        assert_eq!(
            (0..6).map(|v| sets.find(v)).collect::<Vec<_>>(),
            [0, 1, 2, 1, 2, 2]
        );
    }
}
