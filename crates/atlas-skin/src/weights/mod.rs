//! Skinning weights from a decomposition (Lu et al. 2008, §4 and §5), with the extensions
//! METHOD.md measured: soft boundaries with weights that change along the chain inside a
//! region, and weights for every vertex.
//!
//! For a vertex p of the split surface:
//!
//! 1. **Related regions and depths.** A region V_i is related to p when p lies in V_i (a
//!    face of p belongs to it) or within the overlap band of one of V_i's cut curves. Its
//!    normalised depth ([`crate::weights::blend`]) is, with g_k the surface distance from p to the
//!    curve of boundary k and w_k its overlap half-width ([`crate::overlap`]):
//!    λ_i = min_k (w_k + g_k) / (2 w_k) when p lies in V_i (∞ when no band reaches p),
//!    λ_i = max_k (w_k − g_k) / (2 w_k) when it does not (k over V_i's cuts reaching p).
//!    Both give ½ on a curve, so λ_i is continuous across it; regions with λ_i ≤ 0 are not
//!    related.
//! 2. **Blend** the related regions: ω_i from the λ_i by [`blend::blend_regions`].
//! 3. **Chain weights inside a region.** A region is bound to its first joint; each other
//!    joint of the region with a soft boundary also moves part of it. Joint c's soft boundary
//!    (plane point o_c, normal n_c toward its child, half-width w_c) gives
//!    s_c(p) = β(clamp((w_c + n_c·(p − o_c)) / (2 w_c), 0, 1)) · κ_c(p) on its
//!    child side and 0 elsewhere. κ_c ([`crate::weights::ownership`]) keeps the joint on its own
//!    part: with a(p) the distance from p to the nearest of the joint's own bones (its child
//!    bones and every bone below them) and b(p) to the nearest other bone of the region
//!    (bones of joints whose bone lies in it, except the joint's own upper bone, which meets
//!    its child bones at the joint), κ_c(p) = β(clamp(1 − (a − λ b) / w_c, 0, 1)), and 1
//!    when the region has no other bone, with λ = 0.7 for a joint with child bones and 1
//!    for a leaf (whose bone is a guess). It is 1 wherever the own bones are clearly the
//!    nearer (a ≤ λ b) and falls to 0 within one half-width past that surface, as a cut's
//!    weight falls within its overlap band: a plane whose child side holds a sibling's part
//!    (a jaw's, the front of the neck) leaves that part to the bones that run inside it,
//!    and a clavicle leaves the chest, about as near to the spine as to the clavicle, to
//!    the spine.
//!    The region's joints form a tree (each soft joint under its nearest ancestor among
//!    them, the bound joint at the root). Visiting the nodes parents first, the children c
//!    of a node take, with S = Σ_c s_c, the share min(1, S) of the mass of every node on
//!    the chain from the root to that node; child c receives the pooled amount times
//!    s_c / max(1, S). Taking from the whole chain rather than the node alone lets the
//!    head take the chin from the neck where the upper neck's plane does not reach it, and
//!    a shoulder take its arm from the spine where the chest's plane, beside it, does not.
//!    Masses are non-negative, sum to the region's weight ω, and are continuous.
//!
//!    The child side is not a half-space: it is the set of vertices reached *along the
//!    surface* from the joint's own cross-section (vertices within the plane's band and
//!    near the joint) without crossing the far edge of the band (n_c·(p − o_c) ≤ −w_c),
//!    leaving the region and its overlaps, or reaching κ_c = 0. A plane
//!    through a shoulder therefore never reaches a thigh that the hand touches, and a soft
//!    boundary acts only inside its own region: the surface-distance guarantee of §3.3
//!    holds for soft boundaries too (κ_c, a Euclidean nearest-bone test, only ever
//!    removes vertices from the flood). A soft boundary with no cross-section near its
//!    joint is inactive (see `soft_sides`).
//!
//!    **3b. Sibling blends.** Where two joints of which neither is an ancestor of the other
//!    share a vertex (two thighs at a crotch, a neck and a clavicle), part of their common
//!    weight goes to their lowest common ancestor when its bones are about as near
//!    ([`siblings`]).
//! 4. **Guard.** A weight on a joint whose bones are far from the vertex, many times
//!    farther than the nearest bone reached through the body, is removed and the row
//!    renormalised ([`guard`]), on the weights of steps 1–3.
//! 5. **Pieces.** A piece of the surface (connected component) that no region with joints
//!    reaches is weighted as a whole by its geometry ([`crate::weights::pieces`]): attached
//!    to the body surface it sits on (weights of the nearest body point, interpolated over
//!    its face), rigid to one joint when it spans none, or bent at its joints by the
//!    nearest bone. The vertices of a decomposed piece that no region reaches (its gaps)
//!    are weighted as a whole by the same rules. The guard does not touch them: its
//!    correction, vertex by vertex, would tear a piece apart that these rules keep whole
//!    (a rigid hood whose flared edge lies over the upper arm; docs/measurements.md, "The
//!    guard against far bones"). A setting weights the pieces that hold no bone instead by
//!    weight transfer from the pieces that do ([`pieces_by_transfer`]; not the default).
//!
//! 7. **Rigid binding.** When the user asks for it ([`rigid::Binding::Rigid`]), each vertex
//!    then takes one joint with weight 1: the deepest joint whose subtree holds more than
//!    half of its row ([`rigid`]; the pipeline applies it to the weights of steps 1–6).
//!
//! Inputs: a [`Decomposition`], the decomposed skeleton, its [`Overlaps`]
//! ([`crate::overlap`]) and the [`Blend`]. Output: [`SurfaceWeights`], weights of every
//! vertex of the split surface, with [`WeightCounts`] for the report; the pipeline turns
//! them into weights per stored vertex ([`crate::pipeline::unweld_weights`]).

pub mod blend;
pub mod carriers;
pub mod chains;
pub mod crowding;
pub mod guard;
pub mod ownership;
pub mod pieces;
pub mod pieces_by_transfer;
pub mod related;
pub mod rigid;
pub mod siblings;
pub mod soft_sides;
pub mod surface_weights;

use crate::ablation::{Rule, RulesOff};
use crate::decomposition::{BoundaryKind, Decomposition};
use crate::overlap::Overlaps;
use crate::skeleton::bones::{bone_segments, JointBones};
use atlas_skin_runtime::Skeleton;
use blend::Blend;
use chains::{blend_vertices, region_trees};
use guard::guard_far_bones;
use pieces::weight_pieces;
use related::{related_regions, vertex_bands};
use siblings::merge_sibling_blends;
use soft_sides::soft_sides;
use thiserror::Error;

pub use surface_weights::{SurfaceWeights, WeightCounts};

/// What can be wrong with the inputs of the weights stage.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum WeightsError {
    #[error("the decomposition refers to joint {joint}, the skeleton has {count} joints")]
    JointOutOfRange { joint: u32, count: usize },
    #[error(
        "the decomposition has {decomposition} joint decisions, the skeleton {skeleton} joints"
    )]
    SkeletonMismatch {
        decomposition: usize,
        skeleton: usize,
    },
    #[error("the decomposition refers to region {region}, it has {count} regions")]
    RegionOutOfRange { region: u32, count: usize },
    #[error("an overlap band holds vertex {vertex}, the surface has {count}")]
    BandVertexOutOfRange { vertex: u32, count: usize },
    #[error("{what}: {found} entries, expected {expected}")]
    LengthMismatch {
        what: &'static str,
        found: usize,
        expected: usize,
    },
}

/// Weights of every vertex of `decomposition.surface` (module documentation).
///
/// - `skeleton`: the decomposed skeleton (#J joints, one decision each).
/// - `overlaps`: from [`crate::overlap::compute_overlaps`] on the same decomposition.
///
/// - `rules_off`: rules of this stage switched off ([`crate::ablation`]; none by default).
pub fn compute_weights(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    blend: Blend,
    rules_off: &RulesOff,
) -> Result<(SurfaceWeights, WeightCounts), WeightsError> {
    let RegionWeights {
        mut weights,
        inactive_soft_joints,
        crowded_vertices,
    } = region_weights(decomposition, skeleton, overlaps, blend, rules_off)?;
    let owns_skin: Vec<bool> = decomposition.joints.iter().map(|d| d.owns_skin).collect();
    let joint_bones = JointBones::new(&bone_segments(skeleton));
    let sibling_blend_vertices = if rules_off.on(Rule::SiblingBlends) {
        merge_sibling_blends(
            skeleton,
            &decomposition.surface.positions,
            &joint_bones,
            &owns_skin,
            &mut weights,
        )
    } else {
        0
    };
    let far_bone_vertices = if rules_off.on(Rule::FarBoneGuard) {
        guard_far_bones(decomposition, skeleton, &joint_bones, &mut weights)
    } else {
        0
    };
    let mut counts = weight_pieces(decomposition, skeleton, overlaps, &mut weights, rules_off);
    counts.far_bone_vertices = far_bone_vertices;
    counts.sibling_blend_vertices = sibling_blend_vertices;
    counts.inactive_soft_joints = inactive_soft_joints;
    counts.crowded_vertices = crowded_vertices;
    Ok((weights, counts))
}

/// The weights of steps 1–3 (module documentation): of the vertices that regions with
/// joints reach, the others left without weights.
pub struct RegionWeights {
    pub weights: SurfaceWeights,
    /// Joints whose soft boundary is inactive (no cross-section near the joint).
    pub inactive_soft_joints: Vec<u32>,
    /// Vertices that more soft sides would have reached than act at one
    /// ([`crowding`]).
    pub crowded_vertices: usize,
}

/// Steps 1–3 alone (module documentation), with the arguments of [`compute_weights`].
pub fn region_weights(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
    blend: Blend,
    rules_off: &RulesOff,
) -> Result<RegionWeights, WeightsError> {
    validate(decomposition, skeleton, overlaps)?;
    let vertex_count = decomposition.surface.vertex_count();
    let bands = vertex_bands(&overlaps.bands, vertex_count);
    let related = related_regions(decomposition, overlaps, &bands);
    let (softs, crowded_vertices) =
        soft_sides(decomposition, skeleton, overlaps, &related, rules_off);
    let mut has_soft_side = vec![false; skeleton.len()];
    for s in &softs {
        has_soft_side[s.joint as usize] = true;
    }
    let trees = region_trees(decomposition, skeleton, &softs);
    let weights = blend_vertices(decomposition, &related, &softs, &trees, blend);
    Ok(RegionWeights {
        weights,
        inactive_soft_joints: decomposition
            .boundaries
            .iter()
            .filter(|b| b.kind == BoundaryKind::Soft && !has_soft_side[b.joint as usize])
            .map(|b| b.joint)
            .collect(),
        crowded_vertices,
    })
}

/// The decomposition, the skeleton and the overlaps belong together: one decision per
/// joint, one entry per face, boundary and vertex, every index in range.
fn validate(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
) -> Result<(), WeightsError> {
    validate_lengths(decomposition, skeleton, overlaps)?;
    validate_indices(decomposition, skeleton, overlaps)
}

/// Lengths of the per-joint, per-face, per-boundary and per-vertex lists.
fn validate_lengths(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
) -> Result<(), WeightsError> {
    let d = decomposition;
    let length = |what, found, expected| {
        if found == expected {
            Ok(())
        } else {
            Err(WeightsError::LengthMismatch {
                what,
                found,
                expected,
            })
        }
    };
    if d.joints.len() != skeleton.len() {
        return Err(WeightsError::SkeletonMismatch {
            decomposition: d.joints.len(),
            skeleton: skeleton.len(),
        });
    }
    length(
        "face regions",
        d.face_region.len(),
        d.surface.triangle_count(),
    )?;
    length(
        "overlap widths",
        overlaps.half_widths.len(),
        d.boundaries.len(),
    )?;
    length("overlap bands", overlaps.bands.len(), d.boundaries.len())?;
    length(
        "topology vertices",
        d.topology.vertex_face_offsets.len().saturating_sub(1),
        d.surface.vertex_count(),
    )?;
    Ok(())
}

/// Every region, joint and vertex index of the decomposition and the overlap bands is in
/// range.
fn validate_indices(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    overlaps: &Overlaps,
) -> Result<(), WeightsError> {
    let d = decomposition;
    let region_count = d.regions.len();
    let region_ok = |region: u32| {
        if (region as usize) < region_count {
            Ok(())
        } else {
            Err(WeightsError::RegionOutOfRange {
                region,
                count: region_count,
            })
        }
    };
    let joint_ok = |joint: u32| {
        if (joint as usize) < skeleton.len() {
            Ok(())
        } else {
            Err(WeightsError::JointOutOfRange {
                joint,
                count: skeleton.len(),
            })
        }
    };
    for &r in &d.face_region {
        region_ok(r)?;
    }
    for b in &d.boundaries {
        region_ok(b.parent_region)?;
        region_ok(b.child_region)?;
        joint_ok(b.joint)?;
    }
    for r in &d.regions {
        for &j in &r.joints {
            joint_ok(j)?;
        }
    }
    for band in &overlaps.bands {
        if let Some(&v) = band
            .vertices
            .iter()
            .find(|&&v| v as usize >= d.surface.vertex_count())
        {
            return Err(WeightsError::BandVertexOutOfRange {
                vertex: v,
                count: d.surface.vertex_count(),
            });
        }
    }
    Ok(())
}
