//! Skin data laid out for the hot loop: a fixed number K of influences per vertex.

use crate::{RuntimeError, VertexWeights};

/// Vertices per block of [`CompactSkin::block_influences`].
pub const INFLUENCE_BLOCK: usize = 8;

/// Per-vertex joint indices and weights with the same influence count K for every vertex,
/// built once from [`VertexWeights`] and validated then, so that skinning trusts it
/// (ozz-animation's SkinningJob layout).
///
/// - `joints`: #V × K joint indices, vertex-major; vertex v's influences are sorted by
///   decreasing weight, so the first one is the largest (the reference of the dual
///   quaternion sign fix). Rows with fewer than K influences are padded with their first
///   joint at weight 0.
/// - `weights`: #V × (K − 1) weights; the last influence's weight is implicit,
///   `ω_K = 1 − Σ_{i<K} ω_i` (rows sum to 1), which saves bandwidth and makes an identity
///   palette reproduce the rest positions bit for bit (the blended matrix's diagonal
///   rounds to exactly 1).
/// - `block_influences`: per block of [`INFLUENCE_BLOCK`] consecutive vertices, the
///   largest number of influences one of its rows has before padding (1 ≤ k_b ≤ K). Real
///   skins give most vertices one to three influences (the demo 1.9 on average, makehuman
///   2.7); the vector loops blend only the first k_b influences of a block, the last of
///   them with the implicit weight `1 − Σ_{i<k_b−1} ω_i`, so a padded weight of 0 costs
///   nothing and the diagonal property above still holds.
/// - `pairs`: every distinct (first joint, other joint) pair of a row, the pairs whose
///   dual quaternion signs the blend compares; `hemisphere_forest`: a spanning forest of
///   the graph these pairs make, as (aligned joint, joint to align) edges in breadth-first
///   order ([`crate::SkinningPalette::align_hemispheres`]).
#[derive(Debug, Clone, PartialEq)]
pub struct CompactSkin {
    influences: usize,
    joint_count: usize,
    joints: Vec<u16>,
    weights: Vec<f32>,
    block_influences: Vec<u32>,
    pairs: Vec<(u16, u16)>,
    hemisphere_forest: Vec<(u16, u16)>,
}

impl CompactSkin {
    /// Keeps the `max_influences` (at least 1) largest weights of every vertex, rescales each row to
    /// sum to 1 ([`VertexWeights::pruned`]) and lays them out with K = the largest
    /// remaining row length.
    ///
    /// Errors: the weights' own validation ([`VertexWeights::validate`] against
    /// `joint_count`), [`RuntimeError::TooManyJoints`] beyond 65536 joints,
    /// [`RuntimeError::UnweightedVertex`] for a vertex without a positive weight.
    pub fn new(
        weights: &VertexWeights,
        joint_count: usize,
        max_influences: usize,
    ) -> Result<Self, RuntimeError> {
        weights.validate(joint_count)?;
        if joint_count > usize::from(u16::MAX) + 1 {
            return Err(RuntimeError::TooManyJoints { count: joint_count });
        }
        let pruned = weights.pruned(max_influences.max(1));
        let influences = pruned.max_influences().max(1);
        let vertex_count = pruned.vertex_count();
        let mut skin = Self {
            influences,
            joint_count,
            joints: Vec::with_capacity(vertex_count * influences),
            weights: Vec::with_capacity(vertex_count * (influences - 1)),
            block_influences: vec![1; vertex_count.div_ceil(INFLUENCE_BLOCK)],
            pairs: Vec::new(),
            hemisphere_forest: Vec::new(),
        };
        for v in 0..vertex_count {
            // ≤ K, the longest row: far below u32::MAX.
            let used = pruned.row(v).count().min(influences) as u32;
            let block = &mut skin.block_influences[v / INFLUENCE_BLOCK];
            *block = (*block).max(used);
            let mut row = pruned.row(v).peekable();
            let &(first, _) = row
                .peek()
                .ok_or(RuntimeError::UnweightedVertex { vertex: v })?;
            let padded = row.chain(std::iter::repeat((first, 0.0))).take(influences);
            for (i, (joint, weight)) in padded.enumerate() {
                // `validate` bounded the joint count to u16 above.
                skin.joints.push(joint as u16);
                if i + 1 < influences {
                    skin.weights.push(weight);
                }
            }
        }
        skin.pairs = skin
            .joints
            .chunks_exact(influences)
            .flat_map(|row| row[1..].iter().map(move |&j| (row[0], j)))
            .filter(|&(first, other)| first != other)
            .collect();
        skin.pairs.sort_unstable();
        skin.pairs.dedup();
        skin.hemisphere_forest = spanning_forest(joint_count, &skin.pairs);
        Ok(skin)
    }

    /// K: influences stored per vertex.
    pub fn influences(&self) -> usize {
        self.influences
    }

    /// Number of joints the indices refer to (the palette length a job needs).
    pub fn joint_count(&self) -> usize {
        self.joint_count
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.joints.len() / self.influences
    }

    /// #V × K joint indices.
    pub fn joints(&self) -> &[u16] {
        &self.joints
    }

    /// #V × (K − 1) explicit weights.
    pub fn weights(&self) -> &[f32] {
        &self.weights
    }

    /// Per block of [`INFLUENCE_BLOCK`] vertices, the influences its rows use (≤ K).
    pub fn block_influences(&self) -> &[u32] {
        &self.block_influences
    }

    /// Every distinct (first joint, other joint) pair of a row, first ≠ other.
    pub fn pairs(&self) -> &[(u16, u16)] {
        &self.pairs
    }

    /// Edges (aligned joint, joint to align) of a spanning forest of [`CompactSkin::pairs`]
    /// in breadth-first order: following them in order, each joint is aligned against one
    /// whose sign is already settled.
    pub fn hemisphere_forest(&self) -> &[(u16, u16)] {
        &self.hemisphere_forest
    }

    /// The rows as [`VertexWeights`] (padding dropped, implicit weights written out): what
    /// the scalar reference in [`crate::reference`] needs to reproduce this skin.
    pub fn to_vertex_weights(&self) -> VertexWeights {
        let k = self.influences;
        VertexWeights::from_rows((0..self.vertex_count()).map(|v| {
            let joints = &self.joints[v * k..(v + 1) * k];
            let explicit = &self.weights[v * (k - 1)..(v + 1) * (k - 1)];
            let last = 1.0 - explicit.iter().sum::<f32>();
            joints
                .iter()
                .zip(explicit.iter().chain([last].iter()))
                .filter(|&(_, &w)| w > 0.0)
                .map(|(&j, &w)| (u32::from(j), w))
                .collect::<Vec<_>>()
        }))
    }
}

/// A breadth-first spanning forest of the undirected graph on `joint_count` joints whose
/// edges are `pairs`, as (reached from, reached) edges in the order reached; roots are the
/// lowest-numbered joints of their components.
fn spanning_forest(joint_count: usize, pairs: &[(u16, u16)]) -> Vec<(u16, u16)> {
    // Adjacency in compressed rows: both directions of every pair.
    let mut offsets = vec![0usize; joint_count + 1];
    for &(a, b) in pairs {
        offsets[usize::from(a) + 1] += 1;
        offsets[usize::from(b) + 1] += 1;
    }
    for j in 0..joint_count {
        offsets[j + 1] += offsets[j];
    }
    let mut next = offsets.clone();
    let mut neighbours = vec![0u16; offsets[joint_count]];
    for &(a, b) in pairs {
        for (from, to) in [(a, b), (b, a)] {
            neighbours[next[usize::from(from)]] = to;
            next[usize::from(from)] += 1;
        }
    }
    let mut reached = vec![false; joint_count];
    let mut forest = Vec::new();
    let mut queue = std::collections::VecDeque::new();
    for root in 0..joint_count {
        if reached[root] {
            continue;
        }
        reached[root] = true;
        queue.push_back(root);
        while let Some(j) = queue.pop_front() {
            for &n in &neighbours[offsets[j]..offsets[j + 1]] {
                if !reached[usize::from(n)] {
                    reached[usize::from(n)] = true;
                    // Joint indices come from the u16 rows.
                    forest.push((j as u16, n));
                    queue.push_back(usize::from(n));
                }
            }
        }
    }
    forest
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn invalid_weights_are_rejected() {
        use RuntimeError::*;
        // Each case breaks one rule and is refused for that rule.
        type Case = (VertexWeights, usize, fn(&RuntimeError) -> bool);
        let cases: [Case; 6] = [
            (VertexWeights::from_rows([vec![(5, 1.0)]]), 2, |e| {
                matches!(e, JointOutOfRange { .. })
            }),
            (VertexWeights::from_rows([vec![(0, -1.0)]]), 2, |e| {
                matches!(e, BadWeight { vertex: 0, .. })
            }),
            (VertexWeights::from_rows([vec![(0, f32::NAN)]]), 2, |e| {
                matches!(e, BadWeight { vertex: 0, .. })
            }),
            (VertexWeights::from_rows([vec![(0, 1.0)], vec![]]), 2, |e| {
                matches!(e, UnweightedVertex { vertex: 1 })
            }),
            (VertexWeights::from_rows([vec![(0, 0.0)]]), 2, |e| {
                matches!(e, UnweightedVertex { vertex: 0 })
            }),
            (VertexWeights::from_rows([vec![(0, 1.0)]]), 70_000, |e| {
                matches!(e, TooManyJoints { count: 70_000 })
            }),
        ];
        for (weights, joints, expected) in cases {
            match CompactSkin::new(&weights, joints, 4) {
                Err(e) => assert!(
                    expected(&e),
                    "{weights:?}: refused for another reason: {e:?}"
                ),
                Ok(_) => panic!("accepted {weights:?}"),
            }
        }
    }

    /// A block's count is its longest row's, before padding to K.
    #[test]
    fn blocks_count_the_influences_their_rows_use() {
        let rows = (0..10).map(|v| {
            if v < INFLUENCE_BLOCK {
                vec![(v as u32 % 3, 1.0)]
            } else {
                vec![(0, 1.0), (1, 2.0), (2, 3.0)]
            }
        });
        let skin = CompactSkin::new(&VertexWeights::from_rows(rows), 3, 4).unwrap();
        assert_eq!(skin.influences(), 3);
        assert_eq!(skin.block_influences(), &[1, 3]);
    }

    #[test]
    fn rows_are_sorted_padded_and_normalised() {
        let weights = VertexWeights::from_rows([
            vec![(2, 1.0), (0, 3.0)],
            vec![(1, 2.0)],
            vec![(0, 1.0), (1, 1.0), (2, 1.0), (3, 5.0), (4, 1.0)],
        ]);
        let skin = CompactSkin::new(&weights, 5, 4).unwrap();
        assert_eq!(skin.influences(), 4);
        assert_eq!(skin.vertex_count(), 3);
        assert_eq!(&skin.joints()[..8], &[0, 2, 0, 0, 1, 1, 1, 1]);
        assert_eq!(&skin.weights()[..6], &[0.75, 0.25, 0.0, 1.0, 0.0, 0.0]);
        assert_eq!(skin.block_influences(), &[4]);
        assert_eq!(skin.pairs(), &[(0, 2), (3, 0), (3, 1), (3, 2)]);
        assert_eq!(skin.hemisphere_forest(), &[(0, 2), (0, 3), (3, 1)]);
        let back = skin.to_vertex_weights();
        assert_eq!(back.row(1).collect::<Vec<_>>(), vec![(1, 1.0)]);
        let row: Vec<_> = back.row(2).collect();
        assert_eq!(row.len(), 4);
        assert_eq!(row[0], (3, 5.0 / 8.0));
    }
}
