//! Whether a set of weights is usable as it stands in the file.

use atlas_skin_runtime::VertexWeights;
use serde::{Deserialize, Serialize};

/// Tolerance on a row sum: rows summing to 1 ± this are normalised.
pub const SUM_TOLERANCE: f64 = 1e-4;

/// Counts of defects in weights, over every row.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Validity {
    /// Influences with a weight < 0.
    pub negative_weights: usize,
    /// Weighted rows (see `unweighted_vertices`) whose sum is off 1 by more than
    /// [`SUM_TOLERANCE`].
    pub sums_off_one: usize,
    /// Rows without any positive weight (a renderer leaves them at the origin or on the
    /// root).
    pub unweighted_vertices: usize,
    /// Most non-zero influences on one row.
    pub max_influences: usize,
    /// Mean number of non-zero influences per row.
    pub mean_influences: f64,
}

/// Defect counts of `weights` (#V rows; repeated joints in a row count separately).
pub fn validity(weights: &VertexWeights) -> Validity {
    let mut out = Validity {
        negative_weights: 0,
        sums_off_one: 0,
        unweighted_vertices: 0,
        max_influences: 0,
        mean_influences: 0.0,
    };
    let mut influences = 0usize;
    for v in 0..weights.vertex_count() {
        let (mut sum, mut count, mut any_positive) = (0.0f64, 0usize, false);
        for (_, w) in weights.row(v) {
            sum += f64::from(w);
            count += usize::from(w != 0.0);
            any_positive |= w > 0.0;
            out.negative_weights += usize::from(w < 0.0);
        }
        if !any_positive {
            out.unweighted_vertices += 1;
        } else if (sum - 1.0).abs() > SUM_TOLERANCE {
            out.sums_off_one += 1;
        }
        out.max_influences = out.max_influences.max(count);
        influences += count;
    }
    if weights.vertex_count() > 0 {
        out.mean_influences = influences as f64 / weights.vertex_count() as f64;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_defect_is_counted_once() {
        let w = VertexWeights::from_rows([
            vec![(0, 0.5), (1, 0.5)],
            vec![(0, 1.2), (1, -0.2), (2, 0.0)],
            vec![(0, 0.5)],
            vec![],
            vec![(1, 0.0)],
        ]);
        let v = validity(&w);
        assert_eq!(v.negative_weights, 1);
        assert_eq!(v.sums_off_one, 1);
        assert_eq!(v.unweighted_vertices, 2);
        assert_eq!(v.max_influences, 2);
        assert!((v.mean_influences - 5.0 / 5.0).abs() < 1e-12);
    }
}
