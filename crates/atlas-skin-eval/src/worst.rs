//! The vertices where a candidate deforms farthest from the reference: where to look first
//! when a weighting goes wrong.

use super::deform::VertexError;
use atlas_skin_runtime::VertexWeights;
use glam::Vec3;
use serde::{Deserialize, Serialize};

/// One joint's weight in a row, by name.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct JointWeight {
    pub joint: String,
    pub weight: f32,
}

/// A vertex with a large deformation error, and the two weight rows that cause it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct WorstVertex {
    /// Index of the vertex in the reference file's stored vertices.
    pub vertex: usize,
    /// Its rest position.
    pub position: [f32; 3],
    /// Its largest error over the random poses, in units of the diagonal.
    pub error: f64,
    /// The random pose (0-based, seed + pose) where that error occurs.
    pub pose: usize,
    /// Reference and candidate rows, heaviest first.
    pub reference: Vec<JointWeight>,
    pub candidate: Vec<JointWeight>,
}

/// The aligned rows [`worst_vertices`] reads: #M entries each.
pub struct Rows<'a> {
    pub stored: &'a [usize],
    pub positions: &'a [Vec3],
    pub reference: &'a VertexWeights,
    pub candidate: &'a VertexWeights,
    /// Joint names of the reference skeleton, which both rows index.
    pub names: &'a [String],
}

/// The `count` rows with the largest `errors[m].max`, worst first (ties by row order).
pub fn worst_vertices(errors: &[VertexError], rows: &Rows, count: usize) -> Vec<WorstVertex> {
    let mut order: Vec<usize> = (0..errors.len()).collect();
    order.sort_by(|&a, &b| errors[b].max.total_cmp(&errors[a].max).then(a.cmp(&b)));
    order
        .into_iter()
        .take(count)
        .map(|m| WorstVertex {
            vertex: rows.stored[m],
            position: rows.positions[m].to_array(),
            error: errors[m].max,
            pose: errors[m].palette,
            reference: named_row(rows.reference, m, rows.names),
            candidate: named_row(rows.candidate, m, rows.names),
        })
        .collect()
}

/// Row `m` of `weights` with joint names, heaviest first, zero weights dropped.
fn named_row(weights: &VertexWeights, m: usize, names: &[String]) -> Vec<JointWeight> {
    let mut row: Vec<JointWeight> = weights
        .row(m)
        .filter(|&(_, w)| w != 0.0)
        .map(|(j, weight)| JointWeight {
            joint: names[j as usize].clone(),
            weight,
        })
        .collect();
    row.sort_by(|a, b| b.weight.total_cmp(&a.weight));
    row
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lists_the_largest_errors_first_with_named_rows() {
        let errors = [0.1, 0.5, 0.3].map(|max| VertexError { max, palette: 2 });
        let weights =
            VertexWeights::from_rows([vec![(0, 1.0)], vec![(0, 0.25), (1, 0.75)], vec![(1, 1.0)]]);
        let candidate = VertexWeights::from_rows(vec![vec![(1, 1.0)]; 3]);
        let names = ["a".to_string(), "b".to_string()];
        let rows = Rows {
            stored: &[7, 8, 9],
            positions: &[Vec3::X, Vec3::Y, Vec3::Z],
            reference: &weights,
            candidate: &candidate,
            names: &names,
        };
        let worst = worst_vertices(&errors, &rows, 2);
        assert_eq!(worst.len(), 2);
        assert_eq!((worst[0].vertex, worst[1].vertex), (8, 9));
        assert_eq!(worst[0].position, [0.0, 1.0, 0.0]);
        assert_eq!((worst[0].error, worst[0].pose), (0.5, 2));
        assert_eq!(worst[0].reference[0].joint, "b");
        assert_eq!(worst[0].reference[1].weight, 0.25);
        assert_eq!(worst[0].candidate.len(), 1);
        assert!(worst_vertices(&errors, &rows, 0).is_empty());
    }
}
