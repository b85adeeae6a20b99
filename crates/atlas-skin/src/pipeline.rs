//! The whole method after welding: decomposition (§3.1–3.2) → surface distances and
//! overlaps (§3.3) → weights (§4, §5) → weights per stored vertex, with per-stage timings
//! and counts for the report.

use crate::decompose::{decompose, DecomposeError, DecomposeParams};
use crate::overlap::{compute_overlaps, Overlaps};
use crate::weights::{
    compute_weights, stored_weights, SurfaceWeights, WeightCounts, WeightParams, WeightsError,
};
use crate::{Decomposition, Topology, Welded};
use atlas_skin_runtime::{Skeleton, VertexWeights};
use glam::Vec3;
use serde::{Deserialize, Serialize};
use std::time::Instant;
use thiserror::Error;

/// Why skinning failed: the stage, with the stage's error as the source (not repeated in
/// the message, so that chain printers show it once).
#[derive(Debug, Error)]
pub enum SkinError {
    #[error("decomposition failed")]
    Decompose(#[from] DecomposeError),
    #[error("weights failed")]
    Weights(#[from] WeightsError),
}

/// Every setting of the method; a config file may carry any subset (serde, unknown fields
/// rejected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkinParams {
    pub decompose: DecomposeParams,
    pub weights: WeightParams,
    /// Influences kept per vertex, the largest, renormalised (at least 1).
    pub max_influences: usize,
}

impl Default for SkinParams {
    fn default() -> Self {
        Self {
            decompose: DecomposeParams::default(),
            weights: WeightParams::default(),
            max_influences: 4,
        }
    }
}

/// The stages [`skin`] reports to its progress callback as it starts them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    Decompose,
    Distances,
    Weights,
}

impl Stage {
    /// Name of the stage, as in the report's `timings_ms`.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Decompose => "decompose",
            Stage::Distances => "distances",
            Stage::Weights => "weights",
        }
    }
}

/// Wall time of each stage, in milliseconds.
#[derive(Debug, Clone, Copy, Default, PartialEq, Serialize)]
pub struct StageTimings {
    pub decompose: f64,
    pub distances: f64,
    pub weights: f64,
}

/// Sizes and fallbacks, for the report.
#[derive(Debug, Clone, Default, PartialEq, Serialize)]
pub struct SkinCounts {
    /// Vertices of the input mesh as stored.
    pub stored_vertices: usize,
    /// Vertices after welding.
    pub welded_vertices: usize,
    /// Vertices of the split surface (welded + on cut curves).
    pub surface_vertices: usize,
    pub joints: usize,
    /// Unreachable vertices and how they were weighted, inactive soft boundaries.
    pub weights: WeightCounts,
    /// Stored vertices no triangle uses, bound to their nearest bone.
    pub unreferenced_stored_vertices: usize,
}

/// Everything [`skin`] computed.
#[derive(Debug, Clone)]
pub struct Skinned {
    pub decomposition: Decomposition,
    pub overlaps: Overlaps,
    /// Weights of every split-surface vertex, before pruning.
    pub surface_weights: SurfaceWeights,
    /// Weights of every stored vertex: at most `max_influences`, summing to 1.
    pub weights: VertexWeights,
    pub timings: StageTimings,
    pub counts: SkinCounts,
}

/// Skins a welded character.
///
/// - `welded`, `topology`: the welded input mesh ([`crate::weld()`]) and its topology.
/// - `stored_positions`: the input mesh's vertices as stored (#stored, as `welded` maps).
/// - `skeleton`: in the mesh's bind space.
/// - `progress`: called with each stage as it starts.
pub fn skin(
    welded: &Welded,
    topology: &Topology,
    stored_positions: &[Vec3],
    skeleton: &Skeleton,
    params: &SkinParams,
    progress: &mut dyn FnMut(Stage),
) -> Result<Skinned, SkinError> {
    if params.max_influences == 0 {
        return Err(WeightsError::NoInfluences.into());
    }
    params.weights.overlap.validate(skeleton)?;
    let mut timings = StageTimings::default();

    progress(Stage::Decompose);
    let start = Instant::now();
    let decomposition = decompose(&welded.mesh, topology, skeleton, &params.decompose)?;
    timings.decompose = elapsed_ms(start);

    progress(Stage::Distances);
    let start = Instant::now();
    let overlaps = compute_overlaps(&decomposition, skeleton, &params.weights.overlap)?;
    timings.distances = elapsed_ms(start);

    progress(Stage::Weights);
    let start = Instant::now();
    let (surface_weights, weight_counts) =
        compute_weights(&decomposition, skeleton, &overlaps, params.weights.blend)?;
    let weights = stored_weights(
        &surface_weights,
        &welded.welded_of_stored,
        stored_positions,
        skeleton,
        params.max_influences,
    )?;
    timings.weights = elapsed_ms(start);

    let counts = SkinCounts {
        stored_vertices: stored_positions.len(),
        welded_vertices: welded.mesh.vertex_count(),
        surface_vertices: decomposition.surface.vertex_count(),
        joints: skeleton.len(),
        weights: weight_counts,
        unreferenced_stored_vertices: stored_positions
            .len()
            .saturating_sub(welded.referenced_stored),
    };
    Ok(Skinned {
        decomposition,
        overlaps,
        surface_weights,
        weights,
        timings,
        counts,
    })
}

fn elapsed_ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
