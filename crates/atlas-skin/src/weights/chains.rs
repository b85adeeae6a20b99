//! Steps 2 and 3 of the weights for every vertex: the related regions blended (§4), each
//! region's weight shared along the chain of its joints (soft boundaries) (module
//! documentation of [`crate::weights`]).

use super::blend::{blend_regions, Blend};
use super::soft_sides::SoftSide;
use super::surface_weights::SurfaceWeights;
use crate::decomposition::Decomposition;
use crate::rows::{Rows, PAR_CHUNK};
use atlas_skin_runtime::Skeleton;
use std::collections::HashMap;

/// The joints of one region as a tree for step 3: node 0 is the bound joint, node i > 0
/// the soft boundary `softs[i − 1]`; nodes listed parents first.
#[derive(Debug, Default)]
pub struct RegionTree {
    joints: Vec<u32>,
    /// Index into the `softs` vector of every node after the root.
    softs: Vec<usize>,
    children: Vec<Vec<usize>>,
    /// Parent node of every node (0 for the root).
    parents: Vec<usize>,
    order: Vec<usize>,
    /// The position of every node in `order`.
    rank: Vec<usize>,
    /// Every node's depth below the root, and its subtree as an interval of a depth-first
    /// numbering: node a is an ancestor of (or is) node c when `enter[a]` ≤ `enter[c]` ≤
    /// `exit[a]`.
    depth: Vec<usize>,
    enter: Vec<usize>,
    exit: Vec<usize>,
}

impl RegionTree {
    /// Sets `order` (breadth first from the root, children in node order) and `rank` from
    /// `children`.
    fn list_in_order(&mut self) {
        self.order = vec![0];
        let mut i = 0;
        while i < self.order.len() {
            let node = self.order[i];
            self.order.extend(self.children[node].iter().copied());
            i += 1;
        }
        let n = self.joints.len();
        self.rank = vec![0; n];
        self.depth = vec![0; n];
        for (rank, &node) in self.order.iter().enumerate() {
            self.rank[node] = rank;
            if node != 0 {
                self.depth[node] = self.depth[self.parents[node]] + 1;
            }
        }
        // Subtree sizes, children before parents; then each child's interval after its
        // parent's number, the children in node order.
        let mut size = vec![1; n];
        for &node in self.order.iter().skip(1).rev() {
            size[self.parents[node]] += size[node];
        }
        self.enter = vec![0; n];
        for &node in &self.order {
            let mut next = self.enter[node] + 1;
            for &c in &self.children[node] {
                self.enter[c] = next;
                next += size[c];
            }
        }
        self.exit = (0..n)
            .map(|node| self.enter[node] + size[node] - 1)
            .collect();
    }

    /// Whether node `a` is node `c` or one of its ancestors.
    fn holds_below(&self, a: usize, c: usize) -> bool {
        (self.enter[a]..=self.exit[a]).contains(&self.enter[c])
    }
}

pub fn region_trees(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    softs: &[SoftSide],
) -> Vec<RegionTree> {
    decomposition
        .regions
        .iter()
        .enumerate()
        .map(|(r, region)| {
            let Some(&bound) = region.joints.first() else {
                return RegionTree::default();
            };
            let mut tree = RegionTree {
                joints: vec![bound],
                ..RegionTree::default()
            };
            for (s, soft) in softs.iter().enumerate() {
                if soft.region as usize == r && soft.joint != bound {
                    tree.joints.push(soft.joint);
                    tree.softs.push(s);
                }
            }
            tree.children = vec![Vec::new(); tree.joints.len()];
            tree.parents = vec![0; tree.joints.len()];
            // The first node of each joint.
            let mut node_of_joint = HashMap::new();
            for (node, &j) in tree.joints.iter().enumerate() {
                node_of_joint.entry(j as usize).or_insert(node);
            }
            for node in 1..tree.joints.len() {
                let parent = skeleton
                    .ancestors(tree.joints[node] as usize)
                    .find_map(|a| node_of_joint.get(&a).copied())
                    .unwrap_or(0);
                tree.children[parent].push(node);
                tree.parents[node] = parent;
            }
            tree.list_in_order();
            tree
        })
        .collect()
}

/// Per vertex, the (soft side, κ_c) of every soft side reaching it.
fn soft_reaches(softs: &[SoftSide], vertex_count: usize) -> Rows<(u32, f64)> {
    let entries = softs.iter().enumerate().flat_map(|(s, soft)| {
        soft.reached()
            .iter()
            .map(move |&(v, kappa)| (v as usize, (s as u32, kappa)))
    });
    Rows::group(vertex_count, entries)
}

/// Per-chunk working memory of [`blend_vertices`].
#[derive(Default)]
struct BlendScratch {
    depths: Vec<f64>,
    region_weights: Vec<f64>,
    /// One mass per node of the largest region tree, 0 between vertices.
    mass: Vec<f64>,
    /// The (node, s_c) of the soft sides of one region at one vertex with s_c > 0.
    shares: Vec<(usize, f64)>,
    parents: Vec<usize>,
    /// The nodes with mass on one node's path to the root.
    path: Vec<usize>,
}

/// Steps 2 and 3 for every vertex.
pub fn blend_vertices(
    decomposition: &Decomposition,
    related: &Rows<(u32, f64)>,
    softs: &[SoftSide],
    trees: &[RegionTree],
    blend: Blend,
) -> SurfaceWeights {
    let soft_reaches = soft_reaches(softs, decomposition.surface.vertex_count());
    // The node of every soft side in its region's tree.
    let mut node_of_soft = vec![None; softs.len()];
    for tree in trees {
        for (i, &s) in tree.softs.iter().enumerate() {
            node_of_soft[s] = Some(i + 1);
        }
    }
    let largest_tree = trees.iter().map(|t| t.joints.len()).max().unwrap_or(0);
    let positions = &decomposition.surface.positions;
    let rows = Rows::par_build(
        positions.len(),
        PAR_CHUNK,
        |v, scratch: &mut BlendScratch, out| {
            let regions = related.row(v);
            scratch.depths.clear();
            scratch.depths.extend(regions.iter().map(|&(_, l)| l));
            scratch.region_weights.clear();
            scratch.region_weights.resize(regions.len(), 0.0);
            blend_regions(blend, &scratch.depths, &mut scratch.region_weights);
            scratch.mass.resize(largest_tree, 0.0);
            let start = out.len();
            for (&(r, _), &omega) in regions.iter().zip(&scratch.region_weights) {
                let tree = &trees[r as usize];
                scratch.shares.clear();
                scratch
                    .shares
                    .extend(soft_reaches.row(v).iter().filter_map(|&(s, kappa)| {
                        let soft = &softs[s as usize];
                        let node = node_of_soft[s as usize].filter(|_| soft.region == r)?;
                        let share = soft.share(positions[v], kappa);
                        (share > 0.0).then_some((node, share))
                    }));
                scratch.shares.sort_unstable_by_key(|&(node, _)| node);
                let mass = &mut scratch.mass;
                let work = (&mut scratch.parents, &mut scratch.path);
                share_along_chain(tree, &scratch.shares, omega, mass, work);
                // The nodes with mass: the root and those with shares, in node order.
                let nodes = std::iter::once(0).chain(scratch.shares.iter().map(|&(c, _)| c));
                for c in nodes {
                    let (joint, m) = (tree.joints[c], std::mem::take(&mut mass[c]));
                    if m <= 0.0 {
                        continue;
                    }
                    match out[start..].iter_mut().find(|(j, _)| *j == joint) {
                        Some(entry) => entry.1 += m,
                        None => out.push((joint, m)),
                    }
                }
            }
        },
    );
    let (joints, weights) = rows.values.into_iter().unzip();
    SurfaceWeights {
        offsets: rows.offsets,
        joints,
        weights,
    }
}

/// Step 3 at one vertex: the region's weight `omega` shared among the joints of its `tree`
/// (module documentation of [`crate::weights`]); `shares` holds (c, s_c) for the nodes
/// c > 0 with s_c > 0, by increasing node (s_c is 0 at the others). Sets `mass[0]` and
/// `mass[c]` of those nodes, non-negative and summing to `omega`; every other entry of
/// `mass` (at least one per node) must be 0 and stays 0. `parents`, `path`: working
/// memory.
///
/// Only the parents of nodes with shares move mass, in the tree's order (a node whose
/// children have no share passes its mass on unchanged), and only the root and the nodes
/// with shares hold mass ([`take_pool`]): the cost follows the shares at the vertex, not
/// the size or the depth of the tree (one region with 10,000 soft joints; a chain of
/// 3,670 soft joints in one region walked its whole length per vertex, issue 45).
fn share_along_chain(
    tree: &RegionTree,
    shares: &[(usize, f64)],
    omega: f64,
    mass: &mut [f64],
    (parents, path): (&mut Vec<usize>, &mut Vec<usize>),
) {
    mass[0] = omega;
    parents.clear();
    parents.extend(shares.iter().map(|&(c, _)| tree.parents[c]));
    parents.sort_unstable_by_key(|&node| tree.rank[node]);
    parents.dedup();
    for &node in parents.iter() {
        let children = shares.iter().filter(|&&(c, _)| tree.parents[c] == node);
        let total: f64 = children.clone().map(|&(_, share)| share).sum();
        if total <= 0.0 {
            continue;
        }
        let pool = take_pool(tree, node, total, shares, mass, path);
        for &(c, share) in children {
            mass[c] = pool * share / total.max(1.0);
        }
    }
}

/// The mass the children of `node` share, whose shares sum to `total`: the mass of the
/// whole chain from the root to `node`, each of whose masses keeps 1 − min(total, 1),
/// summed from `node` up. Only the root and the nodes of `shares` hold mass (the rest are
/// 0, and adding or scaling a 0 changes nothing), so only those on the chain are visited,
/// deepest first: the same sum in the same order as the walk up every node of the chain
/// (`take_pool_by_walk`, the reference of the tests). `path`: working memory.
fn take_pool(
    tree: &RegionTree,
    node: usize,
    total: f64,
    shares: &[(usize, f64)],
    mass: &mut [f64],
    path: &mut Vec<usize>,
) -> f64 {
    path.clear();
    path.extend(
        shares
            .iter()
            .map(|&(c, _)| c)
            .filter(|&c| tree.holds_below(c, node)),
    );
    path.push(0);
    path.sort_unstable_by_key(|&a| std::cmp::Reverse(tree.depth[a]));
    path.dedup();
    let mut pool = 0.0;
    for &a in path.iter() {
        pool += mass[a];
        mass[a] *= 1.0 - total.min(1.0);
    }
    pool
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::random_pose::SplitMix64;

    /// Step 3 by its definition: every node of the tree in order, with every child's share
    /// (0 included).
    fn reference_masses(tree: &RegionTree, share: impl Fn(usize) -> f64, omega: f64) -> Vec<f64> {
        let mut mass = vec![0.0; tree.joints.len()];
        mass[0] = omega;
        for &node in &tree.order {
            let total: f64 = tree.children[node].iter().map(|&c| share(c)).sum();
            if total <= 0.0 {
                continue;
            }
            let pool = take_pool_by_walk(tree, node, total, &mut mass);
            for &c in &tree.children[node] {
                mass[c] = pool * share(c) / total.max(1.0);
            }
        }
        mass
    }

    /// [`take_pool`] by its definition: every node from `node` up to the root.
    fn take_pool_by_walk(tree: &RegionTree, node: usize, total: f64, mass: &mut [f64]) -> f64 {
        let mut pool = 0.0;
        let mut a = node;
        loop {
            pool += mass[a];
            mass[a] *= 1.0 - total.min(1.0);
            if a == 0 {
                return pool;
            }
            a = tree.parents[a];
        }
    }

    /// Random trees (chains, fans of siblings, mixtures; a few thousands of nodes deep) and
    /// random shares, most of them 0: the same masses, to the bit, as the reference, and
    /// the working masses left at 0.
    #[test]
    fn sparse_chain_sharing_gives_the_reference_masses() {
        let mut rng = SplitMix64::new(5);
        for case in 0..200 {
            // Every 50th a chain or a tree thousands of nodes deep.
            let n = if case % 50 < 2 {
                3000
            } else {
                1 + (rng.next_f64() * 40.0) as usize
            };
            let mut tree = RegionTree {
                joints: (0..n as u32).collect(),
                softs: (0..n.saturating_sub(1)).collect(),
                children: vec![Vec::new(); n],
                parents: vec![0; n],
                ..RegionTree::default()
            };
            for node in 1..n {
                let parent = match case % 3 {
                    0 => node - 1,
                    1 => 0,
                    _ => (rng.next_f64() * node as f64) as usize,
                };
                tree.parents[node] = parent;
                tree.children[parent].push(node);
            }
            tree.list_in_order();
            let all_shares: Vec<f64> = (0..n)
                .map(|c| {
                    let roll = rng.next_f64();
                    if c == 0 || roll < 0.6 {
                        0.0
                    } else if roll < 0.7 {
                        1.0
                    } else {
                        rng.next_f64() * 0.8
                    }
                })
                .collect();
            let omega = rng.next_f64();
            let expected = reference_masses(&tree, |c| all_shares[c], omega);
            let shares: Vec<(usize, f64)> = (1..n)
                .filter(|&c| all_shares[c] > 0.0)
                .map(|c| (c, all_shares[c]))
                .collect();
            let mut mass = vec![0.0; n + 3];
            let work = (&mut Vec::new(), &mut Vec::new());
            share_along_chain(&tree, &shares, omega, &mut mass, work);
            for c in 0..n {
                assert_eq!(
                    mass[c].to_bits(),
                    expected[c].to_bits(),
                    "case {case}, node {c}"
                );
            }
            // The masses of nodes without share are 0, as the caller's reset assumes.
            for (c, &m) in mass.iter().enumerate() {
                assert!(c == 0 || m == 0.0 || all_shares.get(c).is_some_and(|&s| s > 0.0));
            }
        }
    }
}
