//! Measuring candidate skinning weights against reference (artist) weights on the same
//! mesh and skeleton: weight difference, deformation error in random poses and in the
//! model's own animation, bleeding along the surface, and validity.
//!
//! The metrics follow the definitions of `shared/data/BASELINES.md` so that figures are
//! comparable with the other tools' rows there. Candidate vertices are matched to the
//! reference's by position ([`matching`]), after fitting the candidate's units and axes
//! onto the reference's when fewer than half pair as stored ([`fit`]); every metric is then computed over the
//! reference's stored vertices that found a match, with the reference skeleton.

pub mod bleeding;
pub mod deform;
pub mod fit;
pub mod matching;
pub mod rignet_metrics;
mod row_pair;
pub mod validity;
pub mod weights_l1;
pub mod worst;

pub use bleeding::Bleeding;
pub use deform::{DeformError, Skinning};
pub use fit::{AxisTurn, Fit, FitSource};
pub use rignet_metrics::RigNetMetrics;
pub use validity::Validity;
pub use weights_l1::WeightsL1;
pub use worst::{JointWeight, WorstVertex};

use atlas_skin::mesh::weld::UNREFERENCED;
use atlas_skin::mesh::{Topology, Welded};
use atlas_skin::skeleton::bones::bone_segments;
use atlas_skin_runtime::{Clip, Rig, RuntimeError, Skeleton, VertexWeights};
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};
use thiserror::Error;

/// Why two weightings cannot be compared.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum EvalError {
    #[error("the {which} has {rows} weight rows but {vertices} vertices")]
    RowCount {
        which: &'static str,
        rows: usize,
        vertices: usize,
    },
    #[error("invalid reference weights: {0}")]
    ReferenceWeights(RuntimeError),
    #[error("candidate vertex {vertex} refers to joint {joint}, but the candidate skeleton has {count} joints")]
    CandidateJointOutOfRange {
        vertex: usize,
        joint: u32,
        count: usize,
    },
    #[error("candidate vertex {vertex} has a non-finite weight {weight}")]
    CandidateWeightNotFinite { vertex: usize, weight: f32 },
    #[error("candidate joint {joint} ({name:?}) matches no reference joint by name nor by bind position (within {tolerance:.3e}): not the same skeleton?")]
    UnknownJoint {
        joint: usize,
        name: String,
        tolerance: f64,
    },
    #[error("invalid reference animation: {0}")]
    Animation(RuntimeError),
    #[error("the reference rig drives {rig} joints but the skeleton has {skeleton}")]
    RigJointCount { rig: usize, skeleton: usize },
    #[error("the reference mesh has no extent (bounding-box diagonal 0)")]
    DegenerateMesh,
    #[error("no reference vertex has a candidate vertex within {tolerance:.3e} of its position, as stored or after fitting a uniform scale, a Y-up/Z-up turn and a translation from the meshes' and the skeletons' bounding boxes: not the same mesh?")]
    NoVertexMatched { tolerance: f64 },
}

/// One weighted mesh: stored positions, the skeleton its weights refer to, the weights.
///
/// - `positions`: #V positions in bind space; `weights`: #V rows, joint indices into
///   `skeleton`.
#[derive(Debug, Clone, Copy)]
pub struct Weighted<'a> {
    pub positions: &'a [Vec3],
    pub skeleton: &'a Skeleton,
    pub weights: &'a VertexWeights,
}

/// What [`evaluate`] compares.
#[derive(Debug, Clone, Copy)]
pub struct EvalInput<'a> {
    /// The reference: artist (or precomputed) weights. Its skeleton is the one posed.
    pub reference: Weighted<'a>,
    /// The reference's welded surface (from its positions and triangles) and topology:
    /// bleeding distances run along its edges.
    pub surface: &'a Welded,
    pub topology: &'a Topology,
    /// The candidate: the same mesh (possibly reordered, welded or split) with weights to
    /// judge, on a skeleton whose joint names are among the reference's.
    pub candidate: Weighted<'a>,
    /// The reference's own animation, if it has one.
    pub animation: Option<Animation<'a>>,
}

/// An animation of the reference skeleton: a clip on a rig whose `joint_nodes` are the
/// skeleton's joints, in skeleton order.
#[derive(Debug, Clone, Copy)]
pub struct Animation<'a> {
    pub rig: &'a Rig,
    pub clip: &'a Clip,
}

/// Settings of an evaluation; [`Default`] gives BASELINES.md's.
#[derive(Debug, Clone, PartialEq)]
pub struct EvalOptions {
    /// Number of random poses.
    pub poses: usize,
    /// Seed of the first random pose (pose i uses `seed + i`).
    pub seed: u64,
    /// Largest joint rotation of a random pose, radians (60°).
    pub max_angle: f32,
    /// Number of animation frames, evenly spread over the clip.
    pub anim_frames: usize,
    /// Bleeding radius as a fraction of the rest bounding-box diagonal (0.05).
    pub bleeding_radius: f64,
    /// Vertex matching tolerance as a fraction of the diagonal (1e-5).
    pub match_tolerance: f64,
    /// Joint matching tolerance by bind position, as a fraction of the diagonal (1e-3),
    /// for joints whose names match none of the reference's.
    pub joint_tolerance: f64,
    /// Keep only this many largest reference weights per vertex before renormalising
    /// (BASELINES.md prunes MakeHuman's to 4); `None` keeps them all.
    pub reference_max_influences: Option<usize>,
    /// How many of the vertices with the largest LBS random-pose error to list
    /// ([`Evaluation::worst_vertices`]); 0 lists none.
    pub worst: usize,
}

impl Default for EvalOptions {
    fn default() -> Self {
        Self {
            poses: 10,
            seed: 0,
            max_angle: 60f32.to_radians(),
            anim_frames: 8,
            bleeding_radius: 0.05,
            match_tolerance: 1e-5,
            joint_tolerance: 1e-3,
            reference_max_influences: None,
            worst: 0,
        }
    }
}

/// The figures of one evaluation. Field names are the JSON contract of
/// `atlas-skin eval --json`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Evaluation {
    /// Reference vertices compared: stored vertices some triangle references.
    pub vertices: usize,
    /// Reference joints.
    pub joints: usize,
    /// Reference vertices that found a candidate vertex at their position.
    pub matched: usize,
    /// The candidate's units and axes fitted onto the reference's before matching its
    /// vertices ([`fit`]); `None`: matched as stored (and in JSON written before fits).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub fit: Option<Fit>,
    pub candidate_vertices: usize,
    pub candidate_joints: usize,
    /// How each candidate joint was matched to a reference joint, in candidate order
    /// (empty in JSON written before this field existed).
    #[serde(default)]
    pub joint_matches: Vec<matching::JointPair>,
    pub weights_l1: WeightsL1,
    /// RigNet's precision, recall and L1 of the weights as written ([`rignet_metrics`];
    /// absent from JSON written before it was measured).
    #[serde(default)]
    pub rignet: Option<RigNetMetrics>,
    /// LBS in random poses.
    pub deform_random: DeformError,
    /// DQS in the same random poses.
    pub deform_random_dqs: DeformError,
    /// LBS in frames of the reference's animation; `None` without one.
    pub deform_anim: Option<DeformError>,
    pub bleeding: Bleeding,
    /// Of the candidate's weights as stored (all its rows).
    pub validity: Validity,
    /// The `options.worst` vertices with the largest LBS random-pose error, worst first
    /// (absent from the JSON when none was asked for).
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub worst_vertices: Vec<WorstVertex>,
}

/// Compares `input.candidate`'s weights with `input.reference`'s (see the module docs and
/// each metric's function for the formulas).
///
/// Reference rows are renormalised to sum to 1 (after pruning to
/// `options.reference_max_influences` when set); candidate rows are used as stored, so a
/// candidate that does not sum to 1 pays for it in every figure. Errors: row counts that
/// do not match the vertex counts, invalid weights, a candidate joint missing from the
/// reference, a degenerate mesh, no vertex matched.
pub fn evaluate(input: &EvalInput, options: &EvalOptions) -> Result<Evaluation, EvalError> {
    let reference = input.reference;
    let candidate = input.candidate;
    check_rows("reference", reference)?;
    check_rows("candidate", candidate)?;
    reference
        .weights
        .validate(reference.skeleton.len())
        .map_err(EvalError::ReferenceWeights)?;
    check_candidate_weights(candidate)?;
    if let Some(animation) = input.animation {
        check_animation(animation, reference.skeleton)?;
    }
    if input.surface.welded_of_stored.len() != reference.positions.len() {
        return Err(EvalError::RowCount {
            which: "reference surface",
            rows: input.surface.welded_of_stored.len(),
            vertices: reference.positions.len(),
        });
    }
    let diagonal = input.surface.mesh.diagonal();
    if diagonal.is_nan() || diagonal <= 0.0 {
        return Err(EvalError::DegenerateMesh);
    }

    let aligned = align(input, options, diagonal)?;
    let joints = reference.skeleton.len();
    let random_palettes = deform::random_pose_palettes(
        reference.skeleton,
        options.poses,
        options.max_angle,
        options.seed,
    );
    let deform_with = |palettes: &[Vec<Mat4>], skinning| {
        deform::deformation_error(
            &aligned.rest_positions,
            &aligned.reference,
            &aligned.candidate,
            palettes,
            skinning,
            diagonal,
        )
    };
    let random_lbs = deform_with(&random_palettes, Skinning::Linear);
    let sources = bleeding::joint_sources(
        &aligned.reference_stored,
        &input.surface.welded_of_stored,
        joints,
    );
    Ok(Evaluation {
        vertices: aligned.compared,
        joints,
        matched: aligned.rest_positions.len(),
        candidate_vertices: candidate.positions.len(),
        candidate_joints: candidate.skeleton.len(),
        joint_matches: aligned.joint_matches,
        fit: aligned.fit,
        weights_l1: weights_l1::weights_l1(&aligned.reference, &aligned.candidate, joints),
        rignet: Some(rignet_metrics::rignet_metrics(
            &aligned.reference_as_stored,
            &aligned.candidate,
            joints,
        )),
        deform_random: random_lbs.total,
        deform_random_dqs: deform_with(&random_palettes, Skinning::DualQuaternion).total,
        deform_anim: input.animation.map(|animation| {
            let palettes = deform::animation_palettes(
                reference.skeleton,
                animation.rig,
                animation.clip,
                options.anim_frames,
            );
            deform_with(&palettes, Skinning::Linear).total
        }),
        bleeding: bleeding::bleeding(
            &input.surface.mesh,
            input.topology,
            &sources,
            &aligned.candidate,
            &aligned.surface_of_row,
            options.bleeding_radius * diagonal,
        ),
        validity: validity::validity(candidate.weights),
        worst_vertices: worst::worst_vertices(
            &random_lbs.vertices,
            &worst::Rows {
                stored: &aligned.stored_of_row,
                positions: &aligned.rest_positions,
                reference: &aligned.reference,
                candidate: &aligned.candidate,
                names: &reference.skeleton.names,
                segments: &bone_segments(reference.skeleton),
                diagonal,
            },
            options.worst,
        ),
    })
}

/// The reference vertices that found a candidate vertex, with both weightings on the
/// reference's joints.
struct Aligned {
    /// Reference stored vertices some triangle references.
    compared: usize,
    /// #M stored index of each matched reference vertex.
    stored_of_row: Vec<usize>,
    /// #M positions of the matched reference vertices.
    rest_positions: Vec<Vec3>,
    /// #M reference rows, pruned and renormalised.
    reference: VertexWeights,
    /// #M reference rows as stored (neither pruned nor renormalised).
    reference_as_stored: VertexWeights,
    /// #M candidate rows as stored, joints renumbered to the reference's.
    candidate: VertexWeights,
    /// #M welded surface vertex of each row.
    surface_of_row: Vec<u32>,
    /// The pruned, renormalised reference rows of every stored vertex.
    reference_stored: VertexWeights,
    /// The reference joint of every candidate joint and how it was found.
    joint_matches: Vec<matching::JointPair>,
    /// The fit of the candidate onto the reference, when its positions as stored paired
    /// fewer than half of the compared vertices.
    fit: Option<Fit>,
}

/// Matches the candidate's vertices and joints to the reference's and lines up their rows.
fn align(input: &EvalInput, options: &EvalOptions, diagonal: f64) -> Result<Aligned, EvalError> {
    let (reference, candidate) = (input.reference, input.candidate);
    let (reference_at, candidate_at) = (
        reference.skeleton.bind_positions(),
        candidate.skeleton.bind_positions(),
    );
    let joint_matches = matching::match_joints(
        matching::JointSet {
            names: &reference.skeleton.names,
            positions: &reference_at,
        },
        matching::JointSet {
            names: &candidate.skeleton.names,
            positions: &candidate_at,
        },
        options.joint_tolerance * diagonal,
    )?;
    let joint_of_candidate = matching::reference_indices(&reference.skeleton.names, &joint_matches);
    let surface_of_stored = &input.surface.welded_of_stored;
    let compared: Vec<usize> = (0..reference.positions.len())
        .filter(|&v| surface_of_stored[v] != UNREFERENCED)
        .collect();
    let compared_positions: Vec<Vec3> = compared.iter().map(|&v| reference.positions[v]).collect();
    let tolerance = options.match_tolerance * diagonal;
    let mut candidate_of =
        matching::match_vertices(&compared_positions, candidate.positions, tolerance);
    let paired = |of: &[u32]| of.iter().filter(|&&c| c != matching::UNMATCHED).count();
    let mut fit = None;
    let as_stored = paired(&candidate_of);
    if 2 * as_stored < compared.len() {
        // Other units or axes: fit them from the boxes of the meshes or of the joints
        // paired by name (never by position, which assumes the same units).
        let joint_of_candidate_index: Vec<(usize, usize)> = joint_of_candidate
            .iter()
            .enumerate()
            .filter(|&(k, _)| joint_matches[k].how != matching::JointMatch::Position)
            .map(|(k, &j)| (j as usize, k))
            .collect();
        let reference_joints: Vec<Vec3> = joint_of_candidate_index
            .iter()
            .map(|&(j, _)| reference_at[j])
            .collect();
        let candidate_joints: Vec<Vec3> = joint_of_candidate_index
            .iter()
            .map(|&(_, k)| candidate_at[k])
            .collect();
        let best = fit::best_fit(
            fit::Side {
                positions: &compared_positions,
                named_joints: &reference_joints,
            },
            fit::Side {
                positions: candidate.positions,
                named_joints: &candidate_joints,
            },
            tolerance,
        );
        if let Some((found, of)) = best.filter(|(_, of)| paired(of) > as_stored) {
            fit = Some(found);
            candidate_of = of;
        }
    }
    let pairs: Vec<(usize, usize)> = compared
        .iter()
        .zip(&candidate_of)
        .filter(|(_, &c)| c != matching::UNMATCHED)
        .map(|(&r, &c)| (r, c as usize))
        .collect();
    if pairs.is_empty() {
        return Err(EvalError::NoVertexMatched { tolerance });
    }
    let reference_stored = normalized_rows(&match options.reference_max_influences {
        Some(n) => reference.weights.pruned(n),
        None => reference.weights.clone(),
    });
    Ok(Aligned {
        compared: compared.len(),
        stored_of_row: pairs.iter().map(|&(r, _)| r).collect(),
        rest_positions: pairs.iter().map(|&(r, _)| reference.positions[r]).collect(),
        reference: VertexWeights::from_rows(pairs.iter().map(|&(r, _)| reference_stored.row(r))),
        reference_as_stored: VertexWeights::from_rows(
            pairs.iter().map(|&(r, _)| reference.weights.row(r)),
        ),
        candidate: VertexWeights::from_rows(pairs.iter().map(|&(_, c)| {
            candidate
                .weights
                .row(c)
                .map(|(j, w)| (joint_of_candidate[j as usize], w))
        })),
        surface_of_row: pairs.iter().map(|&(r, _)| surface_of_stored[r]).collect(),
        reference_stored,
        joint_matches,
        fit,
    })
}

fn check_rows(which: &'static str, weighted: Weighted) -> Result<(), EvalError> {
    let rows = weighted.weights.vertex_count();
    let vertices = weighted.positions.len();
    if rows != vertices || !offsets_are_consistent(weighted.weights) {
        return Err(EvalError::RowCount {
            which,
            rows,
            vertices,
        });
    }
    Ok(())
}

/// True when `offsets` starts at 0, never decreases and ends at the length of both arrays
/// (so that every [`VertexWeights::row`] is in range).
fn offsets_are_consistent(weights: &VertexWeights) -> bool {
    weights.offsets.first() == Some(&0)
        && weights.offsets.windows(2).all(|w| w[0] <= w[1])
        && weights.offsets.last().map(|&end| end as usize) == Some(weights.joints.len())
        && weights.joints.len() == weights.weights.len()
}

/// Candidate weights may be negative (validity counts them) but must be finite and refer to
/// existing joints.
fn check_candidate_weights(candidate: Weighted) -> Result<(), EvalError> {
    let count = candidate.skeleton.len();
    for v in 0..candidate.weights.vertex_count() {
        for (joint, weight) in candidate.weights.row(v) {
            if joint as usize >= count {
                return Err(EvalError::CandidateJointOutOfRange {
                    vertex: v,
                    joint,
                    count,
                });
            }
            if !weight.is_finite() {
                return Err(EvalError::CandidateWeightNotFinite { vertex: v, weight });
            }
        }
    }
    Ok(())
}

fn check_animation(animation: Animation, skeleton: &Skeleton) -> Result<(), EvalError> {
    animation.rig.validate().map_err(EvalError::Animation)?;
    animation
        .clip
        .validate(animation.rig.len())
        .map_err(EvalError::Animation)?;
    if animation.rig.joint_nodes.len() != skeleton.len() {
        return Err(EvalError::RigJointCount {
            rig: animation.rig.joint_nodes.len(),
            skeleton: skeleton.len(),
        });
    }
    Ok(())
}

/// Every row with a positive sum divided by that sum; other rows unchanged.
fn normalized_rows(weights: &VertexWeights) -> VertexWeights {
    VertexWeights::from_rows((0..weights.vertex_count()).map(|v| {
        let sum: f32 = weights.row(v).map(|(_, w)| w).sum();
        let scale = if sum > 0.0 { 1.0 / sum } else { 1.0 };
        weights.row(v).map(move |(j, w)| (j, w * scale))
    }))
}

#[cfg(test)]
mod tests;
