//! Skin data laid out for the hot loop: a fixed number K of influences per vertex.

use crate::{RuntimeError, VertexWeights};

/// Vertices per block of [`CompactSkin::block_influences`].
pub const INFLUENCE_BLOCK: usize = 8;

/// Most influences per vertex of a skin with quantised weights (the job widens the
/// weights of a few blocks at a time into a buffer of fixed size on the stack).
pub const MAX_QUANTISED_INFLUENCES: usize = 8;

/// How the explicit weights are stored.
///
/// The normalised integers of glTF 2.0 (`KHR_mesh_quantization` and core `WEIGHTS_n`):
/// weight `q / (2^b − 1)` for a b-bit `q`. A row's explicit weights are rounded by their
/// running sums (`q_i = round(S_i · (2^b − 1)) − round(S_{i−1} · (2^b − 1))`, `S_i` the sum
/// of the first i weights), so every stored weight is within `1 / (2^b − 1)` of the
/// original, their sum within half of that and at most 1, so that the implicit last weight
/// `1 − Σ` stays within a step too and is not negative (beyond float round-off, as with
/// float weights). Frames read 2 (16-bit) or 3 (8-bit) fewer bytes per explicit weight.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum WeightFormat {
    /// 32-bit floats, as given.
    #[default]
    Float32,
    /// 16-bit normalised integers: weights within 1.5e-5.
    Unorm16,
    /// 8-bit normalised integers: weights within 3.9e-3.
    Unorm8,
}

impl WeightFormat {
    /// Bytes per stored weight.
    pub fn bytes(self) -> usize {
        match self {
            Self::Float32 => 4,
            Self::Unorm16 => 2,
            Self::Unorm8 => 1,
        }
    }

    /// The format named `f32`, `unorm16` or `unorm8`, if any.
    pub fn from_name(name: &str) -> Option<Self> {
        match name {
            "f32" => Some(Self::Float32),
            "unorm16" => Some(Self::Unorm16),
            "unorm8" => Some(Self::Unorm8),
            _ => None,
        }
    }
}

/// The explicit weights as stored ([`WeightFormat`]).
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum StoredWeights {
    Float32(Vec<f32>),
    Unorm16(Vec<u16>),
    Unorm8(Vec<u8>),
}

/// `q / 65535`, as the loops widen it.
pub(crate) fn unorm16(q: u16) -> f32 {
    f32::from(q) * (1.0 / 65535.0)
}

/// `q / 255`, as the loops widen it.
pub(crate) fn unorm8(q: u8) -> f32 {
    f32::from(q) * (1.0 / 255.0)
}

impl StoredWeights {
    /// Weight `i` as a float.
    fn get(&self, i: usize) -> f32 {
        match self {
            Self::Float32(w) => w[i],
            Self::Unorm16(w) => unorm16(w[i]),
            Self::Unorm8(w) => unorm8(w[i]),
        }
    }

    /// Appends a row's explicit weights, quantised ones rounded by their running sums.
    fn push_row(&mut self, row: &[f32]) {
        let rounded = |scale: f64| {
            row.iter().scan((0.0f64, 0.0f64), move |(sum, before), &w| {
                *sum += f64::from(w);
                let rounded = (sum.min(1.0) * scale).round();
                let q = rounded - *before;
                *before = rounded;
                Some(q)
            })
        };
        match self {
            Self::Float32(w) => w.extend_from_slice(row),
            // The running sums stay in [0, scale], so do their differences.
            Self::Unorm16(w) => w.extend(rounded(65535.0).map(|q| q as u16)),
            Self::Unorm8(w) => w.extend(rounded(255.0).map(|q| q as u8)),
        }
    }
}

/// Per-vertex joint indices and weights with the same influence count K for every vertex,
/// built once from [`VertexWeights`] and validated then, so that skinning trusts it
/// (ozz-animation's SkinningJob layout).
///
/// - `joints`: #V × K joint indices, vertex-major; vertex v's influences are sorted by
///   decreasing weight, so the first one is the largest (the reference of the dual
///   quaternion sign fix). Rows with fewer than K influences are padded with their first
///   joint at weight 0.
/// - `weights`: #V × (K − 1) weights, as floats or normalised integers
///   ([`WeightFormat`]); the last influence's weight is implicit,
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
    weights: StoredWeights,
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
        Self::with_format(weights, joint_count, max_influences, WeightFormat::Float32)
    }

    /// As [`CompactSkin::new`], the explicit weights stored in `format`.
    ///
    /// Errors: those of [`CompactSkin::new`], and
    /// [`RuntimeError::TooManyQuantisedInfluences`] for a quantised format with more than
    /// [`MAX_QUANTISED_INFLUENCES`] influences per vertex after pruning.
    pub fn with_format(
        weights: &VertexWeights,
        joint_count: usize,
        max_influences: usize,
        format: WeightFormat,
    ) -> Result<Self, RuntimeError> {
        weights.validate(joint_count)?;
        if joint_count > usize::from(u16::MAX) + 1 {
            return Err(RuntimeError::TooManyJoints { count: joint_count });
        }
        let pruned = weights.pruned(max_influences.max(1));
        let influences = pruned.max_influences().max(1);
        if format != WeightFormat::Float32 && influences > MAX_QUANTISED_INFLUENCES {
            return Err(RuntimeError::TooManyQuantisedInfluences {
                influences,
                max: MAX_QUANTISED_INFLUENCES,
            });
        }
        let vertex_count = pruned.vertex_count();
        let explicit = vertex_count * (influences - 1);
        let mut skin = Self {
            influences,
            joint_count,
            joints: Vec::with_capacity(vertex_count * influences),
            weights: match format {
                WeightFormat::Float32 => StoredWeights::Float32(Vec::with_capacity(explicit)),
                WeightFormat::Unorm16 => StoredWeights::Unorm16(Vec::with_capacity(explicit)),
                WeightFormat::Unorm8 => StoredWeights::Unorm8(Vec::with_capacity(explicit)),
            },
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
            let mut explicit = [0.0f32; MAX_QUANTISED_INFLUENCES];
            for (i, (joint, weight)) in padded.enumerate() {
                // `validate` bounded the joint count to u16 above.
                skin.joints.push(joint as u16);
                match &mut skin.weights {
                    StoredWeights::Float32(w) if i + 1 < influences => w.push(weight),
                    _ if i + 1 < influences => explicit[i] = weight,
                    _ => {}
                }
            }
            if format != WeightFormat::Float32 {
                skin.weights.push_row(&explicit[..influences - 1]);
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

    /// How the explicit weights are stored.
    pub fn weight_format(&self) -> WeightFormat {
        match self.weights {
            StoredWeights::Float32(_) => WeightFormat::Float32,
            StoredWeights::Unorm16(_) => WeightFormat::Unorm16,
            StoredWeights::Unorm8(_) => WeightFormat::Unorm8,
        }
    }

    /// The K − 1 explicit weights of vertex `v` as the loops read them (quantised ones
    /// widened to floats).
    pub fn explicit_weights(&self, v: usize) -> impl Iterator<Item = f32> + '_ {
        let k = self.influences;
        (v * (k - 1)..(v + 1) * (k - 1)).map(|i| self.weights.get(i))
    }

    /// The explicit weights as stored.
    pub(crate) fn stored_weights(&self) -> &StoredWeights {
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
            let explicit: Vec<f32> = self.explicit_weights(v).collect();
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

    /// Quantised rows: each weight within one step `1 / (2^b − 1)` of the float one, their
    /// sum at most 1 (to float round-off); more than 8 influences refused.
    #[test]
    fn quantised_weights_stay_within_one_step() {
        let rows = (0..200u32).map(|v| {
            let x = (v as f32 * 0.618).fract();
            vec![
                (0, 1.0 + x),
                (1, 1.0 - x),
                (2, 0.3 * x),
                (3, 1e-4 * (v % 5) as f32),
            ]
        });
        let weights = VertexWeights::from_rows(rows);
        let float = CompactSkin::new(&weights, 4, 4).unwrap();
        for (format, step) in [
            (WeightFormat::Unorm16, 1.0 / 65535.0),
            (WeightFormat::Unorm8, 1.0 / 255.0),
        ] {
            let skin = CompactSkin::with_format(&weights, 4, 4, format).unwrap();
            assert_eq!(skin.weight_format(), format);
            assert_eq!(skin.joints(), float.joints());
            for v in 0..200 {
                let (mut sum, mut float_sum) = (0.0, 0.0);
                for (q, w) in skin.explicit_weights(v).zip(float.explicit_weights(v)) {
                    assert!(
                        (q - w).abs() <= step * 1.0001,
                        "{format:?} vertex {v}: {q} for {w}"
                    );
                    sum += q;
                    float_sum += w;
                }
                assert!(
                    sum <= 1.0 + 1e-6 && (sum - float_sum).abs() <= 0.5 * step * 1.0001,
                    "{format:?} vertex {v}: {sum} for {float_sum}"
                );
            }
        }
        let nine = VertexWeights::from_rows([(0..9).map(|j| (j, 1.0)).collect::<Vec<_>>()]);
        assert!(CompactSkin::new(&nine, 9, 9).is_ok());
        assert_eq!(
            CompactSkin::with_format(&nine, 9, 9, WeightFormat::Unorm16),
            Err(RuntimeError::TooManyQuantisedInfluences {
                influences: 9,
                max: 8
            })
        );
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
        let explicit: Vec<f32> = (0..2).flat_map(|v| skin.explicit_weights(v)).collect();
        assert_eq!(explicit, [0.75, 0.25, 0.0, 1.0, 0.0, 0.0]);
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
