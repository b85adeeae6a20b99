//! The whole method, from the mesh as stored to weights per stored vertex:
//! weld ([`crate::mesh::weld()`], duplicate faces removed) → topology (inside-out closed
//! pieces turned outward) → the skeleton
//! checked against the mesh ([`crate::skeleton::placement`]) and given a hierarchy when it
//! has several roots ([`crate::skeleton::hierarchy`]) → decomposition (§3.1 cuts, §3.2 regions:
//! [`crate::decompose()`]) → overlaps (§3.3: [`crate::overlap`]) → weights (§4, §5:
//! [`crate::weights`], with the guard against far bones, [`crate::weights::guard`]; one
//! joint per vertex when bound rigidly, [`crate::weights::rigid`]) → un-weld (weights per stored vertex, pruned to `max_influences`).
//! Settings are validated once, before any work; each stage's wall time is measured here.
//!
//! Inputs: a [`SkinInput`] (stored positions and triangles, the skeleton in the mesh's bind
//! space, the joints the input marks as end points) and [`SkinParams`]. Output: [`Skinned`].

use crate::ablation::RulesOff;
use crate::cuts::merged_joints::merge_warning;
use crate::decompose::{decompose, DecomposeError, DecomposeParams};
use crate::decomposition::Decomposition;
use crate::mesh::duplicate_faces::remove_duplicate_faces;
use crate::mesh::inside_out::turn_inside_out_pieces;
use crate::mesh::weld::DEFAULT_WELD_TOLERANCE;
use crate::mesh::{weld, Topology, Welded};
use crate::overlap::{compute_overlaps, OverlapError, OverlapParams, Overlaps};
use crate::report::decomposition_warnings;
use crate::rows::{Rows, PAR_CHUNK};
use crate::skeleton::bones::{bone_segments, capped_extensions, nearest_bone, EXTENSION_JOINTS};
use crate::skeleton::hierarchy::infer_hierarchy;
use crate::skeleton::placement::{check_placement, PlacementError};
use crate::warning::{Warning, WarningTopic};
use crate::weights::blend::Blend;
use crate::weights::crowding::crowding_warning;
use crate::weights::pieces_by_transfer::{transfer_to_loose_pieces, LoosePieces};
use crate::weights::rigid::{bind_rigidly, Binding};
use crate::weights::{compute_weights, SurfaceWeights, WeightCounts, WeightsError};
use atlas_skin_runtime::{RuntimeError, Skeleton, VertexWeights};
use glam::{DVec3, Vec3};
use serde::{Deserialize, Serialize};
use std::time::Instant;
use thiserror::Error;

/// Why skinning failed: the stage, with the stage's error as the source (not repeated in
/// the message, so that chain printers show it once).
#[derive(Debug, Error)]
pub enum SkinError {
    #[error("invalid settings")]
    Settings(#[from] SettingsError),
    #[error("decomposition failed")]
    Decompose(#[from] DecomposeError),
    #[error("overlaps failed")]
    Overlap(#[from] OverlapError),
    #[error("weights failed")]
    Weights(#[from] WeightsError),
    #[error("the skeleton does not sit in the mesh")]
    Placement(#[from] PlacementError),
}

/// What is wrong with [`SkinParams`] or with the input as the pipeline receives it.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum SettingsError {
    #[error("--max-influences must be at least 1")]
    NoInfluences,
    #[error("{found} stored positions, but the triangles use vertex {vertex}")]
    TriangleVertexOutOfRange { vertex: u32, found: usize },
    #[error("end joint {joint} is not in the skeleton of {count} joints")]
    EndJointOutOfRange { joint: u32, count: usize },
    #[error("invalid skeleton: {0}")]
    Skeleton(#[from] RuntimeError),
}

/// Every setting of the method, one field per stage; a config file may carry any subset
/// (serde, unknown fields rejected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct SkinParams {
    /// §3.1–3.2: plane search, joint roles, forced and forbidden joints.
    pub decompose: DecomposeParams,
    /// §3.3: overlap widths.
    pub overlap: OverlapParams,
    /// §4: how overlapping regions are blended.
    pub blend: Blend,
    /// Blended weights, or one joint per vertex ([`crate::weights::rigid`]).
    pub binding: Binding,
    /// §5: how the pieces that hold no bone are weighted
    /// ([`crate::weights::pieces_by_transfer`]).
    pub loose_pieces: LoosePieces,
    /// Influences kept per stored vertex, the largest, renormalised (at least 1).
    pub max_influences: usize,
    /// §4–5: rules of the weights stage switched off, to measure each alone (a developer
    /// setting: [`crate::ablation`]).
    pub weights_rules_off: RulesOff,
}

impl Default for SkinParams {
    fn default() -> Self {
        Self {
            decompose: DecomposeParams::default(),
            overlap: OverlapParams::default(),
            blend: Blend::default(),
            binding: Binding::default(),
            loose_pieces: LoosePieces::default(),
            max_influences: 4,
            weights_rules_off: RulesOff::default(),
        }
    }
}

/// A character as the method reads it.
#[derive(Debug, Clone, Copy)]
pub struct SkinInput<'a> {
    /// #stored vertex positions, as the file stores them (seams split, duplicates kept).
    pub positions: &'a [Vec3],
    /// #F triangles indexing `positions`.
    pub triangles: &'a [[u32; 3]],
    /// The skeleton in the mesh's bind space.
    pub skeleton: &'a Skeleton,
    /// Joints the input marks as end points that move nothing (the leaves of a TGF
    /// skeleton, libigl's handles): forbidden a boundary unless the settings force them.
    pub end_joints: &'a [u32],
}

/// The stages [`skin`] reports to its progress callback as it starts them.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    Weld,
    Topology,
    Decompose,
    Overlap,
    Weights,
}

impl Stage {
    /// Name of the stage, as in the report's `timings_ms`.
    pub fn name(self) -> &'static str {
        match self {
            Stage::Weld => "weld",
            Stage::Topology => "topology",
            Stage::Decompose => "decompose",
            Stage::Overlap => "overlap",
            Stage::Weights => "weights",
        }
    }
}

/// Wall time of each stage, in milliseconds, in pipeline order.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct StageTimings(pub Vec<(Stage, f64)>);

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
    /// Triangles removed before the method because an earlier one has the same welded
    /// vertices ([`remove_duplicate_faces`]).
    pub duplicate_faces: usize,
    /// Closed pieces wound inward, turned outward before the method
    /// ([`turn_inside_out_pieces`]).
    pub inside_out_pieces: usize,
}

/// Everything [`skin`] computed.
#[derive(Debug, Clone)]
pub struct Skinned {
    /// #stored: the welded vertex of every stored vertex ([`Welded::welded_of_stored`]).
    pub welded_of_stored: Vec<u32>,
    pub decomposition: Decomposition,
    pub overlaps: Overlaps,
    /// Weights of every split-surface vertex, before pruning (one joint each when bound
    /// rigidly).
    pub surface_weights: SurfaceWeights,
    /// How the vertices were bound (the settings' [`Binding`]).
    pub binding: Binding,
    /// Weights of every stored vertex: at most `max_influences`, summing to 1.
    pub weights: VertexWeights,
    pub timings: StageTimings,
    pub counts: SkinCounts,
    /// The skeleton the method used: the input's, or with an inferred hierarchy when the
    /// input's had several roots (same joints, names and bind pose).
    pub skeleton: Skeleton,
    /// What the method noticed and handled, each with its topic: an inferred hierarchy,
    /// duplicate faces, joints beside or outside the mesh, duplicate joints, zero-length
    /// bones, no boundary.
    pub warnings: Vec<Warning>,
}

/// A welded surface with its topology: what every analysis of the mesh starts from.
#[derive(Debug, Clone)]
pub struct WeldedSurface {
    pub welded: Welded,
    pub topology: Topology,
}

impl WeldedSurface {
    /// Welds coincident vertices of the stored mesh (within [`DEFAULT_WELD_TOLERANCE`] of
    /// its diagonal) and builds the topology of the result.
    pub fn new(positions: &[Vec3], triangles: &[[u32; 3]]) -> Self {
        let welded = weld(positions, triangles, DEFAULT_WELD_TOLERANCE);
        let topology = Topology::new(&welded.mesh);
        Self { welded, topology }
    }
}

/// Skins a character: the stages of the module documentation.
///
/// - `progress`: called with each stage as it starts (not at all when the settings or the
///   input are refused).
pub fn skin(
    input: SkinInput,
    params: &SkinParams,
    progress: &mut dyn FnMut(Stage),
) -> Result<Skinned, SkinError> {
    let params = validate(input, params)?;
    let mut timings = StageTimings::default();
    let mut run = |stage: Stage| {
        progress(stage);
        let start = Instant::now();
        move |timings: &mut StageTimings| timings.0.push((stage, elapsed_ms(start)))
    };

    let done = run(Stage::Weld);
    let mut welded = weld(input.positions, input.triangles, DEFAULT_WELD_TOLERANCE);
    let duplicate_faces = remove_duplicate_faces(&mut welded.mesh);
    done(&mut timings);
    let mut warnings = Vec::new();
    if duplicate_faces > 0 {
        warnings.push(Warning::new(
            WarningTopic::Mesh,
            format!(
                "{duplicate_faces} duplicate faces (the same three vertices as an earlier \
                 face) were left out of the method"
            ),
        ));
    }

    let done = run(Stage::Topology);
    let mut topology = Topology::new(&welded.mesh);
    let inside_out = turn_inside_out_pieces(&mut welded.mesh, &mut topology);
    if inside_out > 0 {
        warnings.push(Warning::new(
            WarningTopic::Mesh,
            format!(
                "{inside_out} closed piece(s) were wound inside out: turned outward for the \
                 method"
            ),
        ));
    }
    done(&mut timings);

    let done = run(Stage::Decompose);
    warnings.extend(
        check_placement(input.skeleton, &welded.mesh.positions)?
            .into_iter()
            .map(|message| Warning::new(WarningTopic::Placement, message)),
    );
    let skeleton = method_skeleton(input.skeleton, &welded.mesh.positions, &mut warnings);
    let capped = capped_extensions(&skeleton);
    if let Some(&first) = capped.first() {
        warnings.push(Warning::new(
            WarningTopic::Skeleton,
            format!(
                "{} leaf joint(s) without a tail (the first: {}) continue their bone past \
                 {EXTENSION_JOINTS} or more other joints: each continuation stops at the \
                 {EXTENSION_JOINTS}th (a rig of many siblings on one line; on no benchmark \
                 character does this happen)",
                capped.len(),
                skeleton.names[first as usize]
            ),
        ));
    }
    let decomposition = decompose(&welded.mesh, &topology, &skeleton, &params.decompose)?;
    warnings.extend(merge_warning(&decomposition.merged_joints, &skeleton));
    warnings.extend(decomposition_warnings(
        &decomposition,
        &params.decompose.forbid,
    ));
    done(&mut timings);

    let done = run(Stage::Overlap);
    let overlaps = compute_overlaps(&decomposition, &skeleton, &params.overlap)?;
    done(&mut timings);

    let done = run(Stage::Weights);
    let (mut surface_weights, mut weight_counts) = compute_weights(
        &decomposition,
        &skeleton,
        &overlaps,
        params.blend,
        &params.weights_rules_off,
    )?;
    warnings.extend(crowding_warning(weight_counts.crowded_vertices));
    if params.loose_pieces == LoosePieces::Transfer {
        match transfer_to_loose_pieces(
            &decomposition,
            &weight_counts.pieces,
            skeleton.len(),
            &mut surface_weights,
        ) {
            Ok(transferred) => weight_counts.transferred = transferred,
            Err(warning) => warnings.push(Warning::new(WarningTopic::Weights, warning)),
        }
    }
    if params.binding == Binding::Rigid {
        surface_weights = bind_rigidly(&surface_weights, &skeleton);
    }
    let weights = unweld_weights(
        &surface_weights,
        &welded.welded_of_stored,
        input.positions,
        &skeleton,
        params.max_influences,
    );
    done(&mut timings);

    let counts = SkinCounts {
        stored_vertices: input.positions.len(),
        welded_vertices: welded.mesh.vertex_count(),
        surface_vertices: decomposition.surface.vertex_count(),
        joints: input.skeleton.len(),
        weights: weight_counts,
        unreferenced_stored_vertices: input
            .positions
            .len()
            .saturating_sub(welded.referenced_stored),
        duplicate_faces,
        inside_out_pieces: inside_out,
    };
    Ok(Skinned {
        welded_of_stored: welded.welded_of_stored,
        decomposition,
        overlaps,
        surface_weights,
        binding: params.binding,
        weights,
        timings,
        counts,
        skeleton,
        warnings,
    })
}

/// The skeleton the method runs on: `skeleton` itself, or a copy with the hierarchy
/// [`infer_hierarchy`] gives when it has several roots (its warning added to `warnings`).
fn method_skeleton(
    skeleton: &Skeleton,
    vertices: &[DVec3],
    warnings: &mut Vec<Warning>,
) -> Skeleton {
    let centroid = vertices.iter().sum::<DVec3>() / vertices.len().max(1) as f64;
    let Some(inferred) = infer_hierarchy(skeleton, centroid) else {
        return skeleton.clone();
    };
    let had_links = skeleton
        .parents
        .iter()
        .any(|&p| p != atlas_skin_runtime::NO_PARENT);
    warnings.push(Warning::new(
        WarningTopic::Skeleton,
        inferred.warning(skeleton, had_links),
    ));
    Skeleton {
        parents: inferred.parents,
        ..skeleton.clone()
    }
}

/// Checks the settings and the input once, and returns the settings the stages run with:
/// `params` with the input's end joints forbidden unless forced.
fn validate(input: SkinInput, params: &SkinParams) -> Result<SkinParams, SkinError> {
    if params.max_influences == 0 {
        return Err(SettingsError::NoInfluences.into());
    }
    input.skeleton.validate().map_err(SettingsError::from)?;
    let found = input.positions.len();
    if let Some(&vertex) = input
        .triangles
        .iter()
        .flatten()
        .find(|&&v| v as usize >= found)
    {
        return Err(SettingsError::TriangleVertexOutOfRange { vertex, found }.into());
    }
    params.decompose.validate()?;
    params.overlap.validate(input.skeleton)?;
    let mut params = params.clone();
    for &j in input.end_joints {
        let name =
            input
                .skeleton
                .names
                .get(j as usize)
                .ok_or(SettingsError::EndJointOutOfRange {
                    joint: j,
                    count: input.skeleton.len(),
                })?;
        let decompose = &mut params.decompose;
        if !decompose.force.contains(name) && !decompose.forbid.contains(name) {
            decompose.forbid.push(name.clone());
        }
    }
    Ok(params)
}

/// Weights per stored vertex of the input mesh: surface vertex `welded_of_stored[s]` for
/// stored vertex s (the split surface starts with the welded vertices), keeping the
/// `max_influences` (≥ 1) largest weights and rescaling them to sum to 1. A stored vertex
/// no triangle uses ([`crate::mesh::weld::UNREFERENCED`]) is bound to its nearest bone.
///
/// - `surface_weights`: from [`compute_weights`].
/// - `welded_of_stored`, `stored_positions`: #stored entries each ([`Welded`] and the input
///   mesh).
pub fn unweld_weights(
    surface_weights: &SurfaceWeights,
    welded_of_stored: &[u32],
    stored_positions: &[Vec3],
    skeleton: &Skeleton,
    max_influences: usize,
) -> VertexWeights {
    debug_assert!(max_influences >= 1);
    debug_assert_eq!(stored_positions.len(), welded_of_stored.len());
    let segments = bone_segments(skeleton);
    // Rows built in chunks, each vertex's row sorted in one scratch list (a list per vertex
    // and another for its result cost more than the sorting on a small character).
    let rows: Rows<(u32, f32)> = Rows::par_build(
        welded_of_stored.len(),
        PAR_CHUNK,
        |v, row: &mut Vec<(u32, f64)>, out| {
            let w = welded_of_stored[v] as usize;
            row.clear();
            if w < surface_weights.vertex_count() {
                row.extend(surface_weights.row(w));
            } else {
                let p = stored_positions[v].as_dvec3();
                row.extend(nearest_bone(&segments, p).map(|j| (j, 1.0)));
            }
            row.sort_by(|a, b| b.1.total_cmp(&a.1).then(a.0.cmp(&b.0)));
            row.truncate(max_influences);
            let total: f64 = row.iter().map(|&(_, x)| x).sum();
            if total > 0.0 {
                out.extend(row.iter().map(|&(j, x)| (j, (x / total) as f32)));
            }
        },
    );
    VertexWeights {
        joints: rows.values.iter().map(|&(j, _)| j).collect(),
        weights: rows.values.iter().map(|&(_, x)| x).collect(),
        offsets: rows.offsets,
    }
}

fn elapsed_ms(start: Instant) -> f64 {
    start.elapsed().as_secs_f64() * 1e3
}
