//! Step 4 of the weights: every vertex no region with joints reaches (a loose piece, a
//! degenerate bit, a region without joints) gets the weights of the nearest weighted vertex
//! along the edges, or of its nearest bone.

use super::surface_weights::{SurfaceWeights, WeightCounts};
use crate::decomposition::Decomposition;
use crate::mesh::edge_distance::EdgeDistances;
use crate::skeleton::bones::{bone_segments, nearest_bone};
use atlas_skin_runtime::Skeleton;

/// Step 4: gives every vertex without weights the weights of the nearest weighted vertex
/// along the edges, or of the nearest bone; returns the counts.
pub fn fill_unweighted(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    weights: &mut SurfaceWeights,
) -> WeightCounts {
    let n = weights.vertex_count();
    let empty = |v: usize| weights.offsets[v] == weights.offsets[v + 1];
    let unreachable = (0..n).filter(|&v| empty(v)).count();
    if unreachable == 0 {
        return WeightCounts::default();
    }
    // Every vertex without weights copies the row of its nearest weighted vertex along the
    // edges (multi-source Dijkstra from every weighted vertex).
    let positions = &decomposition.surface.positions;
    let mut nearest = EdgeDistances::new(n);
    nearest.search(
        &decomposition.surface,
        &decomposition.topology,
        (0..n).filter(|&v| !empty(v)).map(|v| v as u32),
        f64::INFINITY,
    );
    let segments = bone_segments(skeleton);
    let mut counts = WeightCounts {
        unreachable,
        ..WeightCounts::default()
    };
    let mut filled = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    for (v, &p) in positions.iter().enumerate().take(n) {
        if !empty(v) {
            filled.extend_row(weights.row(v));
        } else if let Some(source) = nearest.source(v as u32) {
            counts.from_surface += 1;
            filled.extend_row(weights.row(source as usize));
        } else {
            counts.from_bone += 1;
            filled.extend_row(nearest_bone(&segments, p).map(|j| (j, 1.0)));
        }
    }
    *weights = filled;
    counts
}
