//! A vertex order for the skinning loops: vertices grouped by influence count, window by
//! window, applied once when a mesh is loaded.
//!
//! The vector loops blend, per block of [`INFLUENCE_BLOCK`] consecutive vertices, as many
//! influences as the block's longest row ([`CompactSkin::block_influences`]). In a mesh's
//! own order neighbouring vertices mix one to four influences, so a block pays for its
//! longest row: makehuman's body blends 3.2 influences per vertex where its rows have 2.7.
//! Sorting each window of [`ORDER_WINDOW`] consecutive vertices by influence count
//! (stably) makes almost every block uniform (makehuman: 2.7 blended) while a vertex moves
//! at most a window away from where it was, which keeps the mesh's locality (an index
//! buffer remapped by [`VertexOrder::positions`] reads vertices near each other as
//! before). ozz-animation's mesh parts group vertices by influence count for the same
//! reason, over the whole mesh.
//!
//! The order is the engine's choice, made once: it reorders its vertex streams and
//! weights by [`VertexOrder::apply`] and [`VertexOrder::apply_weights`] and remaps its index
//! buffer by [`VertexOrder::positions`]; skinning then runs on the reordered streams as on
//! any others.
//!
//! [`CompactSkin::block_influences`]: crate::CompactSkin::block_influences

use crate::compact_skin::INFLUENCE_BLOCK;
use crate::{RuntimeError, VertexWeights};

/// Vertices per window of [`VertexOrder::by_influence_count`]: a vertex moves by less
/// than this; a multiple of [`INFLUENCE_BLOCK`], so that no block straddles two windows.
pub const ORDER_WINDOW: usize = 256;
const _: () = assert!(ORDER_WINDOW.is_multiple_of(INFLUENCE_BLOCK));

/// A permutation of a mesh's vertices: position i of the new order holds vertex
/// `sources()[i]` of the old one.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct VertexOrder {
    sources: Vec<usize>,
}

impl VertexOrder {
    /// Within each window of [`ORDER_WINDOW`] vertices, the vertices sorted by the number
    /// of influences [`crate::CompactSkin::new`] keeps for them (positive weights of
    /// distinct joints, at most `max_influences`), fewest first; ties keep their order.
    pub fn by_influence_count(weights: &VertexWeights, max_influences: usize) -> Self {
        let pruned = weights.pruned(max_influences.max(1));
        let counts: Vec<usize> = (0..pruned.vertex_count())
            .map(|v| pruned.row(v).count())
            .collect();
        let mut sources: Vec<usize> = (0..counts.len()).collect();
        for window in sources.chunks_mut(ORDER_WINDOW) {
            window.sort_by_key(|&v| counts[v]);
        }
        Self { sources }
    }

    /// Number of vertices.
    pub fn len(&self) -> usize {
        self.sources.len()
    }

    /// True for an order of no vertices.
    pub fn is_empty(&self) -> bool {
        self.sources.is_empty()
    }

    /// For each position of the new order, the old vertex it holds.
    pub fn sources(&self) -> &[usize] {
        &self.sources
    }

    /// For each old vertex, its position in the new order (the inverse permutation): what
    /// an index buffer's entries become.
    pub fn positions(&self) -> Vec<usize> {
        let mut positions = vec![0; self.sources.len()];
        for (new, &old) in self.sources.iter().enumerate() {
            positions[old] = new;
        }
        positions
    }

    /// A per-vertex stream in the new order.
    ///
    /// Errors: [`RuntimeError::BufferSize`] when `stream` does not have one item per
    /// vertex.
    pub fn apply<T: Copy>(&self, stream: &[T]) -> Result<Vec<T>, RuntimeError> {
        self.check(stream.len(), "stream")?;
        Ok(self.sources.iter().map(|&old| stream[old]).collect())
    }

    /// Weights in the new order.
    ///
    /// Errors: [`RuntimeError::BufferSize`] when `weights` does not have a row per vertex.
    pub fn apply_weights(&self, weights: &VertexWeights) -> Result<VertexWeights, RuntimeError> {
        self.check(weights.vertex_count(), "weights")?;
        Ok(VertexWeights::from_rows(
            self.sources.iter().map(|&old| weights.row(old)),
        ))
    }

    fn check(&self, len: usize, what: &str) -> Result<(), RuntimeError> {
        if len == self.sources.len() {
            Ok(())
        } else {
            Err(RuntimeError::BufferSize {
                what: format!(
                    "{what} has {len} vertices, the vertex order {}",
                    self.sources.len()
                ),
            })
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::CompactSkin;

    /// Rows of 1 + (v · 7 mod 4) influences: every count in every window.
    fn mixed(vertices: usize) -> VertexWeights {
        VertexWeights::from_rows((0..vertices).map(|v| {
            (0..1 + (v * 7) % 4)
                .map(|i| (i as u32, 1.0 + i as f32))
                .collect::<Vec<_>>()
        }))
    }

    #[test]
    fn windows_are_sorted_stably_and_vertices_stay_in_their_window() {
        let weights = mixed(600);
        let order = VertexOrder::by_influence_count(&weights, 4);
        let count = |v: usize| weights.row(v).count();
        let mut seen = vec![false; 600];
        for (window, sources) in order.sources().chunks(ORDER_WINDOW).enumerate() {
            for pair in sources.windows(2) {
                let (a, b) = (pair[0], pair[1]);
                assert!(count(a) < count(b) || (count(a) == count(b) && a < b));
            }
            for &v in sources {
                assert_eq!(v / ORDER_WINDOW, window, "vertex {v} left its window");
                seen[v] = true;
            }
        }
        assert!(seen.into_iter().all(|s| s), "not a permutation");
        // A block mixes counts only where its window's sorted counts change (≤ 3 per
        // window here), against nearly every block in the mesh's order.
        let grouped = CompactSkin::new(&order.apply_weights(&weights).unwrap(), 4, 4).unwrap();
        let plain = CompactSkin::new(&weights, 4, 4).unwrap();
        let blended = |skin: &CompactSkin| skin.block_influences().iter().sum::<u32>();
        assert!(blended(&grouped) < blended(&plain));
    }

    #[test]
    fn max_influences_caps_the_count_it_sorts_by() {
        // Vertex 0 has 3 influences, vertex 1 two: capped at 2 they tie and keep their order.
        let weights = VertexWeights::from_rows([
            vec![(0, 1.0), (1, 1.0), (2, 1.0)],
            vec![(0, 1.0), (1, 1.0)],
        ]);
        assert_eq!(
            VertexOrder::by_influence_count(&weights, 4).sources(),
            [1, 0]
        );
        assert_eq!(
            VertexOrder::by_influence_count(&weights, 2).sources(),
            [0, 1]
        );
    }

    #[test]
    fn positions_invert_sources_and_apply_reorders() {
        let weights = mixed(300);
        let order = VertexOrder::by_influence_count(&weights, 4);
        let positions = order.positions();
        for (new, &old) in order.sources().iter().enumerate() {
            assert_eq!(positions[old], new);
        }
        let ids: Vec<usize> = (0..300).collect();
        assert_eq!(order.apply(&ids).unwrap(), order.sources());
        let reordered = order.apply_weights(&weights).unwrap();
        for (new, &old) in order.sources().iter().enumerate() {
            assert!(reordered.row(new).eq(weights.row(old)));
        }
    }

    #[test]
    fn streams_of_another_length_are_refused() {
        let order = VertexOrder::by_influence_count(&mixed(10), 4);
        assert!(matches!(
            order.apply(&[0u8; 9]),
            Err(RuntimeError::BufferSize { .. })
        ));
        assert!(matches!(
            order.apply_weights(&mixed(11)),
            Err(RuntimeError::BufferSize { .. })
        ));
    }
}
