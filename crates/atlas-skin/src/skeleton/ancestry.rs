//! Ancestors in the joint forest in O(1) and lowest common ancestors in O(log J), for
//! skeletons of any depth: walking up a chain of 10,000 joints from each of many pairs of
//! joints costs the square of the chain (issue 45).
//!
//! Each joint gets its entry and exit time in one depth-first walk of the forest: a is an
//! ancestor of j (or j itself) exactly when enter(a) ≤ enter(j) and exit(j) ≤ exit(a). The
//! lowest common ancestor of j and k climbs from j by binary lifting (up_i(j), the 2^i-th
//! ancestor, a root being its own) to the highest ancestor of j that is not an ancestor of
//! k; its parent is the answer (Bender and Farach-Colton, "The LCA Problem Revisited",
//! LATIN 2000, §2, the sparse ancestor table).

use atlas_skin_runtime::Skeleton;

/// Ancestor tests and lowest common ancestors of one skeleton's joints.
#[derive(Debug, Clone)]
pub struct Ancestry {
    enter: Vec<u32>,
    exit: Vec<u32>,
    /// `up[i][j]`: the 2^i-th ancestor of j, or its root when it has fewer.
    up: Vec<Vec<u32>>,
}

impl Ancestry {
    pub fn new(skeleton: &Skeleton) -> Self {
        let n = skeleton.len();
        let children = skeleton.children();
        let (mut enter, mut exit) = (vec![0; n], vec![0; n]);
        let mut clock = 0;
        // (joint, whether its children were pushed): iterative, for chains of any depth.
        let mut stack: Vec<(usize, bool)> = (0..n)
            .filter(|&j| skeleton.parent(j).is_none())
            .map(|j| (j, false))
            .collect();
        while let Some((j, expanded)) = stack.pop() {
            if expanded {
                exit[j] = clock;
                clock += 1;
                continue;
            }
            enter[j] = clock;
            clock += 1;
            stack.push((j, true));
            stack.extend(children[j].iter().map(|&c| (c, false)));
        }
        let first: Vec<u32> = (0..n)
            .map(|j| skeleton.parent(j).unwrap_or(j) as u32)
            .collect();
        let mut up = vec![first];
        while (1usize << (up.len() - 1)) < n {
            let last = &up[up.len() - 1];
            let next = last.iter().map(|&a| last[a as usize]).collect();
            up.push(next);
        }
        Self { enter, exit, up }
    }

    /// Whether `a` is `j` or one of its ancestors.
    pub fn is_ancestor_or_self(&self, a: u32, j: u32) -> bool {
        let (a, j) = (a as usize, j as usize);
        self.enter[a] <= self.enter[j] && self.exit[j] <= self.exit[a]
    }

    /// The lowest common ancestor of `j` and `k` when neither is the other nor one of its
    /// ancestors (two siblings' joints); `None` otherwise, and when they lie in different
    /// trees of the forest.
    pub fn sibling_ancestor(&self, j: u32, k: u32) -> Option<u32> {
        if self.is_ancestor_or_self(j, k) || self.is_ancestor_or_self(k, j) {
            return None;
        }
        let mut x = j;
        for level in self.up.iter().rev() {
            let above = level[x as usize];
            if !self.is_ancestor_or_self(above, k) {
                x = above;
            }
        }
        let a = self.up[0][x as usize];
        self.is_ancestor_or_self(a, k).then_some(a)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    fn forest(parents: Vec<u32>) -> Skeleton {
        let names = (0..parents.len()).map(|j| format!("j{j}")).collect();
        let positions = vec![Vec3::ZERO; parents.len()];
        Skeleton::from_positions(names, parents, &positions).expect("a forest")
    }

    /// The reference: walk up from both joints.
    fn walked_sibling_ancestor(skeleton: &Skeleton, j: usize, k: usize) -> Option<u32> {
        let up_j: Vec<usize> = std::iter::once(j).chain(skeleton.ancestors(j)).collect();
        let up_k: Vec<usize> = std::iter::once(k).chain(skeleton.ancestors(k)).collect();
        if up_j.contains(&k) || up_k.contains(&j) {
            return None;
        }
        up_j.into_iter()
            .find(|a| up_k.contains(a))
            .map(|a| a as u32)
    }

    #[test]
    fn sibling_ancestors_are_those_a_walk_finds_on_random_forests() {
        let mut state = 0x2545_f491_4f6c_dd1du64;
        let mut next = |bound: usize| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (state % bound as u64) as usize
        };
        for size in [1, 2, 3, 7, 40, 130] {
            for _ in 0..6 {
                // Joints listed in a shuffled order, each under an earlier one of the
                // shuffle or a root; deep chains when the parent is usually the last.
                let order: Vec<usize> = {
                    let mut o: Vec<usize> = (0..size).collect();
                    for i in (1..size).rev() {
                        o.swap(i, next(i + 1));
                    }
                    o
                };
                let mut parents = vec![NO_PARENT; size];
                for i in 1..size {
                    parents[order[i]] = match next(8) {
                        0 => NO_PARENT,
                        1..=4 => order[i - 1] as u32,
                        _ => order[next(i)] as u32,
                    };
                }
                let skeleton = forest(parents);
                let ancestry = Ancestry::new(&skeleton);
                for j in 0..size {
                    for k in 0..size {
                        assert_eq!(
                            ancestry.sibling_ancestor(j as u32, k as u32),
                            walked_sibling_ancestor(&skeleton, j, k),
                            "{j} {k} in {:?}",
                            skeleton.parents
                        );
                        let is_ancestor = j == k || skeleton.ancestors(k).any(|a| a == j);
                        assert_eq!(
                            ancestry.is_ancestor_or_self(j as u32, k as u32),
                            is_ancestor
                        );
                    }
                }
            }
        }
    }

    #[test]
    fn a_deep_chain_with_a_branch_at_its_root() {
        // 0 → 1 → … → 9,999, and 10,000 under 0.
        let mut parents: Vec<u32> = (0..10_000u32).map(|j| j.wrapping_sub(1)).collect();
        parents[0] = NO_PARENT;
        parents.push(0);
        let ancestry = Ancestry::new(&forest(parents));
        assert_eq!(ancestry.sibling_ancestor(9_999, 10_000), Some(0));
        assert_eq!(ancestry.sibling_ancestor(9_999, 17), None);
        assert!(ancestry.is_ancestor_or_self(3, 9_999));
        assert!(!ancestry.is_ancestor_or_self(9_999, 3));
    }
}
