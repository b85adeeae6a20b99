//! Sparse per-vertex skinning weights.

use crate::RuntimeError;

/// Skinning weights in compressed rows: vertex v's influences are
/// `joints[offsets[v]..offsets[v + 1]]` with `weights[...]` at the same positions.
///
/// - `offsets`: #V + 1 ascending offsets, `offsets[0] == 0`.
/// - `joints`, `weights`: #influences joint indices and weights.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct VertexWeights {
    pub offsets: Vec<u32>,
    pub joints: Vec<u32>,
    pub weights: Vec<f32>,
}

impl VertexWeights {
    /// Builds weights from one list of (joint, weight) pairs per vertex.
    pub fn from_rows<I, R>(rows: I) -> Self
    where
        I: IntoIterator<Item = R>,
        R: IntoIterator<Item = (u32, f32)>,
    {
        let mut out = Self {
            offsets: vec![0],
            ..Self::default()
        };
        for row in rows {
            for (j, w) in row {
                out.joints.push(j);
                out.weights.push(w);
            }
            out.offsets.push(out.joints.len() as u32);
        }
        out
    }

    /// Number of vertices.
    pub fn vertex_count(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// The (joint, weight) pairs of vertex `v`.
    pub fn row(&self, v: usize) -> impl Iterator<Item = (u32, f32)> + '_ {
        let range = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        self.joints[range.clone()]
            .iter()
            .copied()
            .zip(self.weights[range].iter().copied())
    }

    /// Largest number of influences of any vertex.
    pub fn max_influences(&self) -> usize {
        self.offsets
            .windows(2)
            .map(|w| (w[1] - w[0]) as usize)
            .max()
            .unwrap_or(0)
    }

    /// Checks that offsets are consistent, joints are below `joint_count` and weights are
    /// finite and non-negative.
    pub fn validate(&self, joint_count: usize) -> Result<(), RuntimeError> {
        if self.offsets.first() != Some(&0)
            || self.offsets.windows(2).any(|w| w[0] > w[1])
            || self.offsets.last().map(|&last| last as usize) != Some(self.joints.len())
            || self.joints.len() != self.weights.len()
        {
            return Err(RuntimeError::BufferSize {
                what: "weight offsets do not match the joint and weight arrays".into(),
            });
        }
        for v in 0..self.vertex_count() {
            for (joint, weight) in self.row(v) {
                if joint as usize >= joint_count {
                    return Err(RuntimeError::JointOutOfRange {
                        vertex: v,
                        joint,
                        count: joint_count,
                    });
                }
                if !weight.is_finite() || weight < 0.0 {
                    return Err(RuntimeError::BadWeight { vertex: v, weight });
                }
            }
        }
        Ok(())
    }

    /// Keeps at most `max_influences` largest weights per vertex, drops zeros, merges
    /// repeated joints and rescales every non-empty row to sum to 1 ([`prune_row`]).
    pub fn pruned(&self, max_influences: usize) -> Self {
        let mut out = Self {
            offsets: Vec::with_capacity(self.offsets.len().max(1)),
            joints: Vec::with_capacity(self.joints.len()),
            weights: Vec::with_capacity(self.weights.len()),
        };
        out.offsets.push(0);
        let mut row = Vec::new();
        for v in 0..self.vertex_count() {
            prune_row(self.row(v), max_influences, &mut row);
            for &(j, w) in &row {
                out.joints.push(j);
                out.weights.push(w);
            }
            out.offsets.push(out.joints.len() as u32);
        }
        out
    }

    /// Dense #V × `joint_count` matrix, row-major.
    pub fn to_dense(&self, joint_count: usize) -> Vec<f32> {
        let mut dense = vec![0.0; self.vertex_count() * joint_count];
        for v in 0..self.vertex_count() {
            for (j, w) in self.row(v) {
                dense[v * joint_count + j as usize] += w;
            }
        }
        dense
    }
}

/// One row of [`VertexWeights::pruned`] into `row` (cleared first): repeated joints of
/// `entries` merged (their weights added in order), zeros dropped, sorted by decreasing
/// weight (then joint), cut to `max_influences` and divided by its sum when positive.
/// Callers packing rows one at a time reuse `row` instead of building a pruned copy.
pub fn prune_row(
    entries: impl Iterator<Item = (u32, f32)>,
    max_influences: usize,
    row: &mut Vec<(u32, f32)>,
) {
    row.clear();
    for (j, w) in entries {
        match row.iter_mut().find(|(k, _)| *k == j) {
            Some(entry) => entry.1 += w,
            None => row.push((j, w)),
        }
    }
    row.retain(|&(_, w)| w > 0.0);
    row.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
    row.truncate(max_influences);
    let sum: f32 = row.iter().map(|&(_, w)| w).sum();
    if sum > 0.0 {
        for entry in row.iter_mut() {
            entry.1 /= sum;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pruning_keeps_largest_and_renormalises() {
        let w = VertexWeights::from_rows([vec![(0, 0.1), (1, 0.5), (2, 0.3), (1, 0.1)], vec![]]);
        let p = w.pruned(2);
        let row: Vec<_> = p.row(0).collect();
        assert_eq!(row[0].0, 1);
        assert_eq!(row[1].0, 2);
        assert!((row[0].1 + row[1].1 - 1.0).abs() < 1e-6);
        assert_eq!(p.row(1).count(), 0);
        assert!(p.validate(3).is_ok());
        assert!(p.validate(2).is_err());
    }
}
