//! The skinning metrics of RigNet (Xu et al., "RigNet: Neural Rigging for Articulated
//! Characters", SIGGRAPH 2020, §6 "Skinning evaluation"), as the learned methods report them
//! on the ModelsResource-RigNetv1 dataset (MagicArticulate, Song et al. 2025, Table 2, uses
//! the same three): the influence sets' precision and recall, and the per-vertex L1 of the
//! weights.
//!
//! Over the vertices whose reference row sums to 1 within [`VALID_SUM_TOLERANCE`] (the
//! dataset's FBX-to-glTF conversion kept at most 4 influences without always renormalising,
//! and RigNet's script leaves out the rows that do not sum to 1), with R(v) = {j : w_ref(v, j)
//! > 0} and P(v) = {j : w(v, j) > 0} the candidate's influences *as written* (no pruning):
//!
//! - precision = Σ_v |P(v) ∩ R(v)| / Σ_v |P(v)|,
//! - recall = Σ_v |P(v) ∩ R(v)| / Σ_v |R(v)| (both pooled over vertex × joint),
//! - L1 = (1 / n) Σ_v Σ_j |w(v, j) − w_ref(v, j)|.
//!
//! A benchmark averages each over characters.

use crate::row_pair::RowPair;
use atlas_skin_runtime::VertexWeights;
use serde::{Deserialize, Serialize};

/// A reference row counts when its sum is within this of 1.
pub const VALID_SUM_TOLERANCE: f64 = 0.01;

/// RigNet's three skinning figures of one character.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct RigNetMetrics {
    /// Reference rows that sum to 1 within [`VALID_SUM_TOLERANCE`]: the vertices measured.
    pub vertices: usize,
    /// Share of the candidate's influences that the reference has too (1 when the candidate
    /// has none on the measured vertices).
    pub precision: f64,
    /// Share of the reference's influences that the candidate has too (1 when the reference
    /// has none).
    pub recall: f64,
    /// Mean per-vertex Σ_j |w − w_ref| (0 when no vertex is measured).
    pub l1: f64,
}

/// RigNet's metrics of `candidate` against `reference` (module documentation).
///
/// - `reference`, `candidate`: #V rows each, on the same joints (indices below
///   `joint_count`; repeated joints in a row are summed); the reference as stored, not
///   renormalised, so that the rows off 1 are left out.
pub fn rignet_metrics(
    reference: &VertexWeights,
    candidate: &VertexWeights,
    joint_count: usize,
) -> RigNetMetrics {
    debug_assert_eq!(reference.vertex_count(), candidate.vertex_count());
    let mut rows = RowPair::new(joint_count);
    let (mut vertices, mut both, mut predicted, mut expected) = (0usize, 0usize, 0usize, 0usize);
    let mut l1_sum = 0.0f64;
    for v in 0..reference.vertex_count() {
        let sum: f64 = reference.row(v).map(|(_, w)| f64::from(w)).sum();
        if (sum - 1.0).abs() > VALID_SUM_TOLERANCE {
            continue;
        }
        vertices += 1;
        rows.load(reference, candidate, v);
        for (_, r, c) in rows.joints() {
            l1_sum += (r - c).abs();
            predicted += usize::from(c > 0.0);
            expected += usize::from(r > 0.0);
            both += usize::from(c > 0.0 && r > 0.0);
        }
    }
    let share = |part: usize, whole: usize| {
        if whole == 0 {
            1.0
        } else {
            part as f64 / whole as f64
        }
    };
    RigNetMetrics {
        vertices,
        precision: share(both, predicted),
        recall: share(both, expected),
        l1: if vertices == 0 {
            0.0
        } else {
            l1_sum / vertices as f64
        },
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;

    #[test]
    fn figures_by_hand() {
        // Row 0: same joints, other shares: P = R = {0, 1}, L1 0.4.
        // Row 1: candidate adds joint 2: P = {0, 2}, R = {0}, L1 0.5 + 0.5.
        // Row 2: the reference sums to 0.9: left out.
        // Row 3: candidate misses joint 1: P = {0}, R = {0, 1}, L1 0.5 + 0.5.
        let reference = VertexWeights::from_rows([
            vec![(0, 0.5), (1, 0.5)],
            vec![(0, 1.0)],
            vec![(0, 0.9)],
            vec![(0, 0.5), (1, 0.5)],
        ]);
        let candidate = VertexWeights::from_rows([
            vec![(0, 0.3), (1, 0.7)],
            vec![(0, 0.5), (2, 0.5)],
            vec![(2, 1.0)],
            vec![(0, 1.0)],
        ]);
        let m = rignet_metrics(&reference, &candidate, 3);
        assert_eq!(m.vertices, 3);
        // Influences: predicted 2 + 2 + 1 = 5, expected 2 + 1 + 2 = 5, both 2 + 1 + 1 = 4.
        assert_relative_eq!(m.precision, 4.0 / 5.0, epsilon = 1e-12);
        assert_relative_eq!(m.recall, 4.0 / 5.0, epsilon = 1e-12);
        assert_relative_eq!(m.l1, (0.4 + 1.0 + 1.0) / 3.0, epsilon = 1e-6);
    }

    #[test]
    fn zero_weights_as_written_are_no_influence() {
        // A padded influence of weight 0 is not an influence; a tiny positive one is.
        let reference = VertexWeights::from_rows([vec![(0, 1.0)]]);
        let padded = VertexWeights::from_rows([vec![(0, 1.0), (1, 0.0)]]);
        let tiny = VertexWeights::from_rows([vec![(0, 0.999), (1, 0.001)]]);
        assert_eq!(rignet_metrics(&reference, &padded, 2).precision, 1.0);
        assert_relative_eq!(
            rignet_metrics(&reference, &tiny, 2).precision,
            0.5,
            epsilon = 1e-12
        );
    }

    #[test]
    fn identical_rows_are_perfect_and_no_row_is_neutral() {
        let w = VertexWeights::from_rows([vec![(0, 0.25), (1, 0.75)], vec![(2, 1.0)]]);
        let m = rignet_metrics(&w, &w, 3);
        assert_eq!(
            (m.vertices, m.precision, m.recall, m.l1),
            (2, 1.0, 1.0, 0.0)
        );
        let empty = VertexWeights::from_rows([vec![(0, 0.5)]]);
        let m = rignet_metrics(&empty, &empty, 1);
        assert_eq!(
            (m.vertices, m.precision, m.recall, m.l1),
            (0, 1.0, 1.0, 0.0)
        );
    }
}
