//! How rigid a weighting is: the share of vertices bound to a single joint.

use atlas_skin_runtime::VertexWeights;

/// A row counts as bound to a single joint when one joint carries at least this share of
/// its weight: the others move the vertex by at most 0.1% of their displacement.
pub const SINGLE_JOINT_SHARE: f32 = 0.999;

/// The share of rows (of those with any weight) whose largest weight is at least
/// [`SINGLE_JOINT_SHARE`] of the row's sum, repeated joints merged; `None` for no rows.
pub fn single_joint_share(weights: &VertexWeights) -> Option<f64> {
    let merged = weights.pruned(usize::MAX);
    let mut rows = 0usize;
    let mut single = 0usize;
    for v in 0..merged.vertex_count() {
        let (sum, largest) = merged.row(v).fold((0f32, 0f32), |(sum, largest), (_, w)| {
            (sum + w, largest.max(w))
        });
        if sum > 0.0 {
            rows += 1;
            single += usize::from(largest >= SINGLE_JOINT_SHARE * sum);
        }
    }
    (rows > 0).then(|| single as f64 / rows as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_with_one_joint_are_counted() {
        let weights = VertexWeights::from_rows([
            vec![(0, 1.0)],
            vec![(0, 0.5), (1, 0.5)],
            vec![(2, 0.9995), (1, 0.0005)],
            // Unnormalised, as the benchmark's artist rows can be; repeated joint merged.
            vec![(3, 0.3), (3, 0.3)],
            vec![],
        ]);
        assert_eq!(single_joint_share(&weights), Some(0.75));
        assert_eq!(
            single_joint_share(&VertexWeights::from_rows([Vec::<(u32, f32)>::new()])),
            None
        );
    }
}
