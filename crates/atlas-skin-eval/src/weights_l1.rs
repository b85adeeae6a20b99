//! How far candidate weights are from the reference's, vertex by vertex.

use crate::row_pair::RowPair;
use atlas_skin_runtime::VertexWeights;
use serde::{Deserialize, Serialize};

/// Summary of the per-vertex L1 weight difference.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct WeightsL1 {
    /// Mean over vertices of `d_v = Σ_j |w_ref(v, j) − w_cand(v, j)|` (0 = same, 2 = disjoint
    /// rows summing to 1).
    pub mean: f64,
    /// 95th percentile of `d_v` (nearest rank: the `⌈0.95 n⌉`-th smallest).
    pub p95: f64,
    /// Largest `d_v`.
    pub max: f64,
    /// Share of vertices whose candidate heaviest joint is one of the reference's heaviest
    /// joints (ties within 1e-6 all count); two empty rows agree.
    pub dominant_agreement: f64,
}

/// Weight differences between two weightings of the same vertices.
///
/// - `reference`, `candidate`: #V rows each, joint indices below `joint_count` (repeated
///   joints in a row are summed). Rows are compared as given: renormalise the reference
///   first when it should sum to 1.
pub fn weights_l1(
    reference: &VertexWeights,
    candidate: &VertexWeights,
    joint_count: usize,
) -> WeightsL1 {
    debug_assert_eq!(reference.vertex_count(), candidate.vertex_count());
    let n = reference.vertex_count();
    if n == 0 {
        return WeightsL1 {
            mean: 0.0,
            p95: 0.0,
            max: 0.0,
            dominant_agreement: 1.0,
        };
    }
    let mut rows = RowPair::new(joint_count);
    let mut distances = Vec::with_capacity(n);
    let mut agreeing = 0usize;
    for v in 0..n {
        rows.load(reference, candidate, v);
        distances.push(
            rows.joints()
                .fold(0.0, |sum, (_, r, c)| sum + (r - c).abs()),
        );
        if dominant_joints_agree(&rows) {
            agreeing += 1;
        }
    }
    let mean = distances.iter().fold(0.0, |sum, d| sum + d) / n as f64;
    distances.sort_unstable_by(f64::total_cmp);
    let rank = (0.95 * n as f64).ceil() as usize;
    WeightsL1 {
        mean,
        p95: distances[rank.clamp(1, n) - 1],
        max: distances[n - 1],
        dominant_agreement: agreeing as f64 / n as f64,
    }
}

/// Tolerance under which two weights of one row count as tied for heaviest.
const TIE: f64 = 1e-6;

/// True when the candidate's heaviest joint is one of the reference's heaviest (only
/// joints with a positive weight count; two rows without any agree).
fn dominant_joints_agree(rows: &RowPair) -> bool {
    // The heaviest joint of one side (the lower index among exact ties) and its weight.
    let heaviest = |weight: fn(&(usize, f64, f64)) -> f64| {
        rows.joints()
            .filter(|x| weight(x) > 0.0)
            .max_by(|a, b| weight(a).total_cmp(&weight(b)).then(b.0.cmp(&a.0)))
    };
    match (heaviest(|x| x.1), heaviest(|x| x.2)) {
        (None, None) => true,
        (Some((_, r, _)), Some((_, reference_at_c, _))) => reference_at_c >= r - TIE,
        _ => false,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use proptest::prelude::*;

    /// Rows of up to 4 influences on 6 joints, normalised to sum to 1.
    fn normalised_rows() -> impl Strategy<Value = Vec<Vec<(u32, f32)>>> {
        prop::collection::vec(
            prop::collection::vec((0u32..6, 0.01f32..1.0), 1..=4).prop_map(|row| {
                let sum: f32 = row.iter().map(|&(_, w)| w).sum();
                row.into_iter().map(|(j, w)| (j, w / sum)).collect()
            }),
            1..20,
        )
    }

    proptest! {
        #[test]
        fn the_difference_is_symmetric_and_between_0_and_2(
            a in normalised_rows(),
            b in normalised_rows(),
        ) {
            let n = a.len().min(b.len());
            let a = VertexWeights::from_rows(a.into_iter().take(n));
            let b = VertexWeights::from_rows(b.into_iter().take(n));
            let ab = weights_l1(&a, &b, 6);
            let ba = weights_l1(&b, &a, 6);
            prop_assert!((ab.mean - ba.mean).abs() < 1e-9 && (ab.max - ba.max).abs() < 1e-9);
            prop_assert!(0.0 <= ab.mean && ab.mean <= ab.max + 1e-9);
            prop_assert!(ab.p95 <= ab.max && ab.max <= 2.0 + 1e-6);
            prop_assert_eq!(weights_l1(&a, &a, 6).max, 0.0);
        }
    }

    #[test]
    fn identical_rows_give_zero() {
        let w = VertexWeights::from_rows([vec![(0, 0.3), (1, 0.7)], vec![(2, 1.0)], vec![]]);
        let l1 = weights_l1(&w, &w, 3);
        assert_eq!((l1.mean, l1.p95, l1.max), (0.0, 0.0, 0.0));
        // +0, not the -0 of an empty float sum, which JSON would print as -0.0.
        assert!(l1.mean.is_sign_positive() && l1.max.is_sign_positive());
        assert_eq!(l1.dominant_agreement, 1.0);
    }

    #[test]
    fn differences_by_hand() {
        // Row 0: |0.3 − 0.7| + |0.7 − 0.3| = 0.8; row 1: disjoint, 2; row 2: 0.
        let reference =
            VertexWeights::from_rows([vec![(0, 0.3), (1, 0.7)], vec![(2, 1.0)], vec![(1, 1.0)]]);
        let candidate = VertexWeights::from_rows([
            vec![(1, 0.3), (0, 0.7)],
            vec![(0, 1.0)],
            vec![(1, 0.5), (1, 0.5)],
        ]);
        let l1 = weights_l1(&reference, &candidate, 3);
        assert_relative_eq!(l1.mean, 2.8 / 3.0, epsilon = 1e-6);
        assert_relative_eq!(l1.max, 2.0, epsilon = 1e-6);
        assert_relative_eq!(l1.p95, 2.0, epsilon = 1e-6);
        assert_relative_eq!(l1.dominant_agreement, 1.0 / 3.0, epsilon = 1e-12);
    }

    #[test]
    fn a_tie_in_the_reference_accepts_either_joint() {
        let reference = VertexWeights::from_rows([vec![(0, 0.5), (1, 0.5)]]);
        let candidate = VertexWeights::from_rows([vec![(1, 0.6), (0, 0.4)]]);
        assert_eq!(
            weights_l1(&reference, &candidate, 2).dominant_agreement,
            1.0
        );
    }
}
