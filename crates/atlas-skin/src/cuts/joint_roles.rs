//! Which joints get a boundary (Lu et al. 2008 §3.1, and METHOD.md "Measured on real rigs").
//!
//! The rules, in the order they are applied to joint J at bind position p_J:
//! 1. Forbidden by the user, or named as a helper that deforms nothing (an attachment
//!    slot, a locator, an IK target: [`crate::skeleton::helpers`]) and not forced: no
//!    boundary, and no skin at all ([`JointPlan::Exclude`]). A helper's bone still keeps
//!    the sections of other joints clear of it, and it still counts among its parent's
//!    child bones (a head's lower bone points toward its locators): leaving it out of
//!    either lost on the benchmark (rignet-val/7571's shoulders cut through the neck beside
//!    its locators; docs/measurements.md, "Helper joints by name"). Forced by the user: a
//!    boundary, whatever follows.
//! 2. A root has no upper bone to cut: its region is the root region. A joint whose bones
//!    all have zero length has no direction to cut across: no boundary.
//! 3. A joint lies outside the mesh and owns no geometry when it is farther from the
//!    surface than `outside_ratio` × its longest bone and outside it: most of six rays from
//!    it (±x, ±y, ±z, slightly turned) first meet the surface from outside, or not at all.
//!    Then: no boundary and no skin ([`JointPlan::Exclude`]). A joint near the surface (a
//!    face bone in an eye socket) keeps its boundary: the skin around it is its to move. A
//!    winding number is not used: it fails on open and multi-piece meshes; the ray vote
//!    needs only a locally outward surface.
//! 4. A branching joint (two or more children) on the skeleton's mirror plane (pelvis,
//!    chest, head, jaw). The paper gives it no boundary; here (METHOD.md, "extensions") it
//!    gets one when it owns a part of the trunk (docs/measurements.md says what this rule
//!    is worth, and why a joint near the skin is not exempt: a head in a thin neck is).
//!    Where its branches start is judged against its section's diameter
//!    D = 2 × surface distance. Most child bones (the median) shorter than D: it sits at
//!    the junction (a chest between shoulders and neck), its children's boundaries enclose
//!    most of it, so no cut fits; but the trunk below them bends with it, as artists weight
//!    it: a soft boundary only (its branches take their parts from the whole chain below
//!    it, see [`crate::weights`]). Some child bone shorter than D: any plane through it
//!    slices that branch's root: a soft boundary only. Otherwise its cut is searched like any other but placed after all
//!    others ([`JointFrame::on_mirror_plane`]), and it is soft when no clean cut fits.
//!    Off the plane (a clavicle with a breast bone, a wrist with five finger bones) a
//!    branching joint is cut like a chain joint whose lower bone is the mean of its unit
//!    child directions — for a wrist, the average finger direction (rule 7).
//! 5. A leaf owns geometry when the surface runs on past it. Its bone's direction b is
//!    its upper bone u; b is also its lower bone l. Either test suffices:
//!    (a) the ray from p_J along b leaves the surface from inside (hit face
//!    normal along the ray on an outward-oriented surface) at a distance ≥
//!    `leaf_extent_ratio` × r, r the joint's surface distance; (b) for a joint inside the
//!    body (r ≥ a tenth of its bone), the part of the surface nearest to it — vertices v past
//!    it within 60° of b, (v − p_J) · b ≥ ½ |v − p_J|, nearer to p_J than to every bone not
//!    at J — reaches farther than 2 r from p_J. (b) finds toes beyond the ball of a foot, which (a) misses when the foot
//!    bone points down into the sole. It is then cut with lower bone l = b.
//!    (c) When (a) does not hold, for a joint at any depth: that part (within 60° of b),
//!    taken on the piece around the leaf's upper bone (the connected piece of the surface
//!    nearest to that bone's middle), reaches at least the joint's bone length ℓ from p_J. The joint
//!    is then cut like (a) and (b), and where no cut fits its soft boundary is seeded
//!    farther than at other leaves ([`JointFrame::leaf_part_past`]). This finds leaves in the
//!    skin, where r is about 0 and (b) does not apply: a tail tip in a flat sheet that runs
//!    on past it, feet whose leaves sit in the ankles. A piece of its own past the joint (a
//!    head modelled apart over its neck, a bag hanging from a belt) is left to the weighting
//!    of pieces ([`crate::weights::pieces`]), which weights it as a whole
//!    (docs/measurements.md, "Leaves whose part runs on past them").
//!    Otherwise it is an end site (a fingertip cap reaches about 1.4–1.7 r): no boundary.
//! 6. Twist and helper joints on a straight bone are chain joints with collinear bones: they
//!    are cut perpendicular to the bone (the cone search), and the weights stage blends the
//!    regions of one limb; nothing tells them apart from a straight elbow geometrically.
//! 7. The lower bone l of a joint with several children is the mean m̂ of their unit
//!    directions.
//!
//! The mirror plane is inferred from joint positions alone (names are not used): the plane
//! x · n = c, among the coordinate planes and the bisector planes of sibling pairs of equal
//! bone length, that maps the joint set best onto itself.

use super::leaf_reach::LeafReach;
use super::params::{DecomposeParams, Override};
use crate::ablation::Rule;
use crate::mesh::spatial_index::FaceSpheres;
use crate::mesh::SurfaceMesh;
use crate::skeleton::bones::BoneIndex;
use crate::skeleton::nearest_point::PointGrid;
use crate::tolerance::NEGLIGIBLE;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;
use std::collections::HashSet;

/// The skeleton's mirror plane: points x with n · x = `offset`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SymmetryPlane {
    pub normal: DVec3,
    pub offset: f64,
    /// Mean distance from a reflected joint to the nearest joint, relative to the
    /// skeleton's bounding-box diagonal.
    pub mismatch: f64,
}

/// The bones around a joint that gets a boundary.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct JointFrame {
    /// p_J.
    pub position: DVec3,
    /// Unit direction of the upper bone (parent → J).
    pub upper: DVec3,
    /// Unit direction of the lower bone (J → child, see the rules).
    pub lower: DVec3,
    /// Length of the shortest non-zero adjacent bone.
    pub bone_length: f64,
    /// Distance from p_J to the nearest surface point.
    pub surface_distance: f64,
    /// A branching joint on the skeleton's mirror plane (pelvis, chest, head): its plane
    /// crosses the trunk where limbs branch, so it is placed after every other cut.
    pub on_mirror_plane: bool,
    /// The joint at this one's reflection through the mirror plane ([`mirror_twins`]): the
    /// other side's knee of a knee. A joint keeps its cut only when its twin gets one
    /// ([`crate::cuts::conflicts`]).
    pub mirror_twin: Option<u32>,
    /// A leaf whose part runs on past it, on the piece around its bone, for at least its
    /// bone's length (rule 5 (c)). Its
    /// soft boundary, where it gets one, is seeded as far as that of a joint with child
    /// bones, and across a face that spans its band there too (step 3 of
    /// [`crate::weights`]): in the skin or in a sheet, its band is as thin as its depth.
    pub leaf_part_past: bool,
}

/// What the decomposition does at one joint.
#[derive(Debug, Clone, PartialEq)]
pub enum JointPlan {
    /// Search a cut (and fall back to a soft boundary).
    Boundary(JointFrame),
    /// A soft boundary only, never a cut, with the reason for the report.
    Soft(JointFrame, String),
    /// No boundary, with the reason for the report.
    Skip(String),
    /// No boundary and no skin at all (forbidden by the user, or outside the mesh), with
    /// the reason for the report.
    Exclude(String),
}

/// The report's reason for a joint named as a helper (rule 1).
pub const HELPER_REASON: &str =
    "named as a helper that deforms nothing (an attachment slot, a locator, an IK target): \
     moves no skin";

/// A joint is on the mirror plane within this fraction of the fit tolerance: a pelvis or
/// chest sits on it to rounding, while the branching joints of an eye or a cheek lie a
/// few percent of the skeleton's size off it.
const ON_PLANE: f64 = 0.25;

/// Rule 5 (b): the part of the surface nearest to a leaf owns geometry when it reaches this
/// many times the joint's surface distance past it (a toe beyond the ball of a foot reaches
/// 2–7 times; a fingertip cap around an end site about 1.4–1.7 times).
const LEAF_REACH_RATIO: f64 = 2.0;

/// Rule 5 (b) applies to a joint at least this fraction of its bone from the surface; one
/// nearer lies in the skin (a face bone): the part nearest to it is a patch of skin, not a
/// part of the body past it.
const INTERIOR_RADIUS: f64 = 0.1;

/// Decides, for every joint of `skeleton` (bind positions `positions`, bones `bones`),
/// whether it gets a boundary; `overrides` has one entry per joint, `pieces` the connected
/// piece of every vertex of `mesh` ([`crate::mesh::Topology::vertex_component`]).
#[allow(clippy::too_many_arguments)]
pub fn plan_joints(
    mesh: &SurfaceMesh,
    pieces: &[u32],
    spheres: &FaceSpheres,
    skeleton: &Skeleton,
    positions: &[DVec3],
    bones: &BoneIndex,
    overrides: &[Option<Override>],
    params: &DecomposeParams,
) -> Vec<JointPlan> {
    let symmetry = infer_symmetry_plane(skeleton, positions, params.symmetry_tolerance);
    let rig = Rig {
        mesh,
        pieces,
        spheres,
        skeleton,
        positions,
        children: skeleton.children(),
        overrides,
        scale: diagonal(positions).max(f64::MIN_POSITIVE),
        symmetry,
        twins: mirror_twins(symmetry, positions, params.symmetry_tolerance),
        orientation: orientation_sign(mesh),
        leaf_reach: LeafReach::new(mesh, spheres, bones, skeleton.len()),
        params,
    };
    (0..skeleton.len())
        .into_par_iter()
        .map(|j| rig.plan(j, rig.overrides[j]))
        .collect()
}

/// What every joint's rules read: the surface, the skeleton and facts derived from both.
struct Rig<'a> {
    mesh: &'a SurfaceMesh,
    /// The connected piece of every vertex.
    pieces: &'a [u32],
    spheres: &'a FaceSpheres,
    skeleton: &'a Skeleton,
    positions: &'a [DVec3],
    children: Vec<Vec<usize>>,
    /// The user's and the helper names' overrides, one per joint.
    overrides: &'a [Option<Override>],
    /// Diagonal of the joints' bounding box.
    scale: f64,
    symmetry: Option<SymmetryPlane>,
    /// [`mirror_twins`] of the joints.
    twins: Vec<Option<u32>>,
    /// [`orientation_sign`] of the surface.
    orientation: f64,
    /// Rule 5's question at the leaves, with the skeleton's bones
    /// ([`crate::skeleton::bones::joint_pairs`]).
    leaf_reach: LeafReach<'a>,
    params: &'a DecomposeParams,
}

/// A joint's frame with the vectors of its non-zero child bones and its longest bone.
struct Bones {
    frame: JointFrame,
    child_vectors: Vec<DVec3>,
    longest_bone: f64,
}

impl Rig<'_> {
    /// The rules of the module documentation, in order, for joint `j`.
    fn plan(&self, j: usize, user: Option<Override>) -> JointPlan {
        let forced = user == Some(Override::Force);
        match user {
            Some(Override::Forbid) => return JointPlan::Exclude("forbidden by the user".into()),
            Some(Override::Helper) => return JointPlan::Exclude(HELPER_REASON.into()),
            _ => {}
        }
        if self.skeleton.parent(j).is_none() && !forced {
            return JointPlan::Skip("root joint: no upper bone to cut".into());
        }
        let Some(bones) = self.bones_at(j) else {
            return JointPlan::Skip("zero-length bones: no direction to cut across".into());
        };
        let frame = bones.frame;
        if forced {
            return JointPlan::Boundary(frame);
        }
        let surface_distance = frame.surface_distance;
        if surface_distance > self.params.outside_ratio * bones.longest_bone
            && !is_inside_by_rays(self.mesh, self.spheres, frame.position, self.orientation)
        {
            return JointPlan::Exclude(format!(
                "outside the mesh, owns no geometry: nearest surface {surface_distance:.4} \
                 away, longest bone {:.4}",
                bones.longest_bone
            ));
        }
        if frame.on_mirror_plane && self.params.rules_off.on(Rule::MirrorBranching) {
            if let Some(plan) = branching_plan(&frame, &bones.child_vectors) {
                return plan;
            }
        }
        let mut frame = frame;
        if self.children[j].is_empty() {
            let end_site = "end site: the surface does not run on past the joint";
            match leaf_part(
                self.mesh,
                self.pieces,
                self.spheres,
                &frame,
                (&self.leaf_reach, j),
                self.orientation,
                self.params.leaf_extent_ratio,
            ) {
                LeafPart::Owned => {}
                LeafPart::PastBone if self.params.rules_off.on(Rule::LeafPartPast) => {
                    frame.leaf_part_past = true
                }
                LeafPart::None | LeafPart::PastBone => return JointPlan::Skip(end_site.into()),
            }
        }
        JointPlan::Boundary(frame)
    }

    /// The frame of joint `j` (rules 1–3 and 7): upper and lower directions, bone lengths, the
    /// surface distance and whether it branches on the mirror plane; `None` when all its
    /// bones have zero length.
    fn bones_at(&self, j: usize) -> Option<Bones> {
        let (positions, scale) = (self.positions, self.scale);
        let p = positions[j];
        let upper_vector = self
            .skeleton
            .parent(j)
            .map_or(DVec3::ZERO, |q| p - positions[q]);
        let child_vectors: Vec<DVec3> = self.children[j]
            .iter()
            .map(|&c| positions[c] - p)
            .filter(|v| v.length() > NEGLIGIBLE * scale)
            .collect();
        let upper = if upper_vector.length() > NEGLIGIBLE * scale {
            upper_vector.normalize()
        } else {
            child_vectors
                .iter()
                .map(|v| v.normalize())
                .sum::<DVec3>()
                .normalize_or_zero()
        };
        let lower = lower_direction(upper, &child_vectors);
        if upper == DVec3::ZERO {
            return None;
        }
        let bone_length = std::iter::once(upper_vector.length())
            .chain(child_vectors.iter().map(|v| v.length()))
            .filter(|&l| l > NEGLIGIBLE * scale)
            .fold(f64::INFINITY, f64::min);
        let longest_bone = std::iter::once(upper_vector.length())
            .chain(child_vectors.iter().map(|v| v.length()))
            .fold(0.0, f64::max);
        let on_mirror_plane = child_vectors.len() >= 2
            && self.symmetry.is_some_and(|plane| {
                (plane.normal.dot(p) - plane.offset).abs()
                    <= ON_PLANE * self.params.symmetry_tolerance * scale
            });
        Some(Bones {
            frame: JointFrame {
                on_mirror_plane,
                mirror_twin: self.twins[j],
                leaf_part_past: false,
                position: p,
                upper,
                lower,
                bone_length,
                surface_distance: self.spheres.nearest_distance(self.mesh, p),
            },
            child_vectors,
            longest_bone,
        })
    }
}

/// The lower bone's unit direction of a joint with upper bone `upper` and bones
/// `child_vectors` to its children (rule 7): the mean m̂ of the children's unit directions,
/// or `upper` when there are none.
fn lower_direction(upper: DVec3, child_vectors: &[DVec3]) -> DVec3 {
    let sum: DVec3 = child_vectors.iter().map(|v| v.normalize()).sum();
    sum.try_normalize().unwrap_or(upper)
}

/// Rule 4 for a branching joint on the mirror plane: a soft boundary where its branches
/// start within its cross-section, `None` (a cut) otherwise.
fn branching_plan(frame: &JointFrame, child_vectors: &[DVec3]) -> Option<JointPlan> {
    let mut child_lengths: Vec<f64> = child_vectors.iter().map(|v| v.length()).collect();
    child_lengths.sort_unstable_by(f64::total_cmp);
    let section_diameter = 2.0 * frame.surface_distance;
    let median = child_lengths[child_lengths.len() / 2];
    if median < section_diameter {
        return Some(JointPlan::Soft(
            *frame,
            format!(
                "branching joint on the mirror plane at the junction of its branches: \
                 most of them start within its cross-section (median child bone \
                 {median:.4}, section diameter about {section_diameter:.4}): no cut fits"
            ),
        ));
    }
    if child_lengths[0] < section_diameter {
        return Some(JointPlan::Soft(
            *frame,
            format!(
                "branching joint on the mirror plane with a branch starting within \
                 its cross-section (child bone {:.4}, section diameter about \
                 {section_diameter:.4}): a plane there would cut across it",
                child_lengths[0]
            ),
        ));
    }
    None
}

/// What rule 5 says of the surface past a leaf joint.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LeafPart {
    /// The surface runs on past the joint, along its bone: (a) or (b).
    Owned,
    /// It runs on past the joint along its bone for at least the bone's length: (c).
    PastBone,
    /// An end site.
    None,
}

/// Rule 5 of the module documentation for the leaf `leaf` of `frame`. `pieces`: the
/// connected piece of every vertex; `reach`: the surface and the bones (its question of
/// (b) and (c)); `orientation` as from [`orientation_sign`].
#[allow(clippy::too_many_arguments)]
fn leaf_part(
    mesh: &SurfaceMesh,
    pieces: &[u32],
    spheres: &FaceSpheres,
    frame: &JointFrame,
    (reach, leaf): (&LeafReach, usize),
    orientation: f64,
    extent_ratio: f64,
) -> LeafPart {
    let (p, bone, radius) = (frame.position, frame.lower, frame.surface_distance);
    let threshold = extent_ratio * radius;
    let exit_along_bone = spheres
        .first_hit(mesh, p, bone)
        .filter(|hit| orientation * mesh.scaled_normal(hit.face as usize).dot(bone) >= 0.0);
    if exit_along_bone.is_some_and(|hit| hit.distance >= threshold) {
        return LeafPart::Owned;
    }
    // (c), on the piece around the leaf's bone: the one nearest to the bone's middle.
    let bone_piece = spheres
        .nearest_point(mesh, p - 0.5 * frame.bone_length * frame.upper)
        .map(|nearest| pieces[mesh.triangles[nearest.face as usize][0] as usize]);
    if let Some(piece) = bone_piece {
        let on_piece = Some((pieces, piece));
        if reach.reaches(leaf, p, bone, frame.bone_length, on_piece) {
            return LeafPart::PastBone;
        }
    }
    if radius < INTERIOR_RADIUS * frame.bone_length {
        return LeafPart::None;
    }
    if reach.reaches(leaf, p, bone, LEAF_REACH_RATIO * radius, None) {
        LeafPart::Owned
    } else {
        LeafPart::None
    }
}

/// Whether at least four of six rays from `p` first meet the surface leaving it (the hit
/// face's normal, times `orientation`, along the ray). The directions are the axes turned
/// by a small irrational rotation so that they do not run along axis-aligned edges.
fn is_inside_by_rays(
    mesh: &SurfaceMesh,
    spheres: &FaceSpheres,
    p: DVec3,
    orientation: f64,
) -> bool {
    let turn = glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.1234, 0.2345, 0.3456);
    let exits = [
        DVec3::X,
        -DVec3::X,
        DVec3::Y,
        -DVec3::Y,
        DVec3::Z,
        -DVec3::Z,
    ]
    .into_iter()
    .filter(|&axis| {
        let direction = turn * axis;
        spheres.first_hit(mesh, p, direction).is_some_and(|hit| {
            orientation * mesh.scaled_normal(hit.face as usize).dot(direction) > 0.0
        })
    })
    .count();
    exits >= 4
}

/// +1 for an outward-oriented closed surface, −1 for an inward one, 0 when the signed
/// volume Σ a · (b × c) / 6 is negligible (open strips): ray hits are then not filtered.
pub(crate) fn orientation_sign(mesh: &SurfaceMesh) -> f64 {
    let volume = mesh.signed_volume();
    if volume.abs() <= NEGLIGIBLE * mesh.diagonal().powi(3) {
        0.0
    } else {
        volume.signum()
    }
}

fn diagonal(points: &[DVec3]) -> f64 {
    let (lo, hi) = crate::geometry::bounding_box(points);
    (hi - lo).length()
}

/// The mirror plane of the joint set, if one maps it onto itself within `tolerance` × the
/// skeleton's diagonal (mean nearest-joint distance of the reflected joints) and reflects at
/// least one pair of joints onto each other.
///
/// Candidates: normals ±x, ±y, ±z and p_i − p_j for sibling joints i, j whose bones have
/// equal length (within 5%), sibling groups in order until there are more than
/// `SYMMETRY_CANDIDATES` (a group of many equal siblings is cut there, and each group after
/// `SYMMETRY_PAIRS_IN_GROUP` pairs); offset c = median
/// of n · p over the joints. Nearest joints from a grid ([`PointGrid`]): about
/// O(J log J · candidates).
pub fn infer_symmetry_plane(
    skeleton: &Skeleton,
    positions: &[DVec3],
    tolerance: f64,
) -> Option<SymmetryPlane> {
    let scale = diagonal(positions);
    if positions.len() < 3 || scale <= 0.0 {
        return None;
    }
    let mut normals = vec![DVec3::X, DVec3::Y, DVec3::Z];
    'groups: for siblings in skeleton.children() {
        let mut examined = 0;
        'pairs: for (k, &a) in siblings.iter().enumerate() {
            for &b in &siblings[k + 1..] {
                examined += 1;
                if examined > SYMMETRY_PAIRS_IN_GROUP {
                    break 'pairs;
                }
                let Some(p) = skeleton.parent(a) else {
                    continue;
                };
                let (la, lb) = (
                    positions[a].distance(positions[p]),
                    positions[b].distance(positions[p]),
                );
                if (la - lb).abs() <= 0.05 * la.max(lb) {
                    if let Some(n) = (positions[a] - positions[b]).try_normalize() {
                        normals.push(n);
                    }
                }
                if normals.len() > SYMMETRY_CANDIDATES_IN_GROUP {
                    break 'groups;
                }
            }
        }
        if normals.len() > SYMMETRY_CANDIDATES {
            break;
        }
    }
    // Equal normals give equal planes: each is tried once (the first kept, so that the
    // first of equal minima still wins). 100 siblings on one line give one normal.
    let mut tried = HashSet::new();
    normals.retain(|n| tried.insert(n.to_array().map(f64::to_bits)));
    // Nearest distances from the distinct points: the same minima, and thousands of joints
    // at one point (a broken bind pose) do not fill one cell that every query scans.
    let mut distinct: Vec<DVec3> = positions.to_vec();
    distinct.sort_unstable_by(|a, b| {
        (a.x.total_cmp(&b.x))
            .then(a.y.total_cmp(&b.y))
            .then(a.z.total_cmp(&b.z))
    });
    distinct.dedup();
    let joints = PointGrid::new(&distinct);
    normals
        .into_iter()
        .filter_map(|normal| {
            let mut heights: Vec<f64> = positions.iter().map(|p| normal.dot(*p)).collect();
            heights.sort_unstable_by(f64::total_cmp);
            let offset = heights[heights.len() / 2];
            let mut paired = 0;
            let mut total = 0.0;
            for p in positions {
                let height = normal.dot(*p) - offset;
                let mirrored = *p - 2.0 * height * normal;
                total += joints.nearest_distance(mirrored);
                if height.abs() > tolerance * scale {
                    paired += 1;
                }
            }
            let mismatch = total / positions.len() as f64 / scale;
            (paired >= 2 && mismatch <= tolerance).then_some(SymmetryPlane {
                normal,
                offset,
                mismatch,
            })
        })
        .min_by(|a, b| a.mismatch.total_cmp(&b.mismatch))
}

/// Candidate normals of [`infer_symmetry_plane`]: sibling groups are read until there are
/// more than this many.
const SYMMETRY_CANDIDATES: usize = 24;

/// And within one group, candidates stop past this many (a hand's fingers give 10 pairs;
/// 10,000 sibling joints would give 50 million).
const SYMMETRY_CANDIDATES_IN_GROUP: usize = 100;

/// And a group's pairs are examined up to this many (siblings bound at one point, or of
/// unequal bones, give no candidate however many pairs are tried).
const SYMMETRY_PAIRS_IN_GROUP: usize = 10_000;

/// Each joint's mirror twin: the other joint nearest to its reflection through `plane`,
/// when that lies within `tolerance` × the skeleton's diagonal of the reflection (the
/// tolerance of [`infer_symmetry_plane`]'s fit) and the two are each other's nearest. A
/// joint on the plane reflects onto itself and has none; so does every joint when there is
/// no plane. Nearest joints from a grid: O(J log J).
pub fn mirror_twins(
    plane: Option<SymmetryPlane>,
    positions: &[DVec3],
    tolerance: f64,
) -> Vec<Option<u32>> {
    let Some(plane) = plane else {
        return vec![None; positions.len()];
    };
    let reach = tolerance * diagonal(positions);
    let joints = PointGrid::new(positions);
    let nearest_to_reflection: Vec<Option<u32>> = positions
        .iter()
        .map(|&p| {
            let mirrored = p - 2.0 * (plane.normal.dot(p) - plane.offset) * plane.normal;
            joints
                .nearest(mirrored)
                .filter(|&(_, distance)| distance <= reach)
                .map(|(k, _)| k as u32)
        })
        .collect();
    nearest_to_reflection
        .iter()
        .enumerate()
        .map(|(j, &twin)| {
            twin.filter(|&t| t as usize != j && nearest_to_reflection[t as usize] == Some(j as u32))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;

    /// A stick figure: pelvis (root) with spine and two legs, chest with neck and two arms.
    fn stick_figure(tilt: f64) -> (Skeleton, Vec<DVec3>) {
        let raw = [
            ("pelvis", NO_PARENT, [0.0, 1.0, 0.0]),
            ("chest", 0, [0.0, 1.5, 0.0]),
            ("neck", 1, [0.0, 1.7, 0.0]),
            ("arm.L", 1, [0.3, 1.5, 0.0]),
            ("hand.L", 3, [0.8, 1.4, 0.0]),
            ("arm.R", 1, [-0.3, 1.5, 0.0]),
            ("hand.R", 5, [-0.8, 1.4, 0.0]),
            ("leg.L", 0, [0.1, 0.9, 0.0]),
            ("foot.L", 7, [0.1, 0.0, 0.1]),
            ("leg.R", 0, [-0.1, 0.9, 0.0]),
            ("foot.R", 9, [-0.1, 0.0, 0.1]),
        ];
        let rotation = glam::DQuat::from_rotation_y(tilt);
        let positions: Vec<DVec3> = raw
            .iter()
            .map(|r| rotation * DVec3::from_array(r.2))
            .collect();
        let skeleton = Skeleton::from_positions(
            raw.iter().map(|r| r.0.to_string()).collect(),
            raw.iter().map(|r| r.1).collect(),
            &positions.iter().map(|p| p.as_vec3()).collect::<Vec<_>>(),
        )
        .expect("valid skeleton");
        (skeleton, positions)
    }

    #[test]
    fn mirror_plane_of_a_stick_figure_is_found_even_when_rotated() {
        for tilt in [0.0, 0.4] {
            let (skeleton, positions) = stick_figure(tilt);
            let plane = infer_symmetry_plane(&skeleton, &positions, 0.02).expect("symmetric");
            let expected = glam::DQuat::from_rotation_y(tilt) * DVec3::X;
            assert!(plane.normal.dot(expected).abs() > 0.999, "{plane:?}");
            assert!(plane.offset.abs() < 1e-6 && plane.mismatch < 1e-6);
        }
    }

    #[test]
    fn mirror_twins_of_a_stick_figure_are_its_left_and_right_limbs() {
        for tilt in [0.0, 0.4] {
            let (skeleton, positions) = stick_figure(tilt);
            let plane = infer_symmetry_plane(&skeleton, &positions, 0.02);
            let twins = mirror_twins(plane, &positions, 0.02);
            let name = |j: Option<u32>| j.map(|j| skeleton.names[j as usize].as_str());
            let of = |n: &str| name(twins[skeleton.names.iter().position(|m| m == n).unwrap()]);
            assert_eq!(of("arm.L"), Some("arm.R"));
            assert_eq!(of("hand.R"), Some("hand.L"));
            assert_eq!(of("foot.L"), Some("foot.R"));
            for on_plane in ["pelvis", "chest", "neck"] {
                assert_eq!(of(on_plane), None);
            }
        }
        // Without a plane there are no twins.
        let (_, positions) = stick_figure(0.0);
        assert!(mirror_twins(None, &positions, 0.02)
            .iter()
            .all(Option::is_none));
    }

    #[test]
    fn a_lopsided_skeleton_has_no_mirror_plane() {
        let (mut skeleton, mut positions) = stick_figure(0.0);
        positions[4] = DVec3::new(0.6, 2.0, 0.5);
        positions[8] = DVec3::new(0.5, 0.3, -0.6);
        skeleton.inverse_bind[4] = glam::Mat4::from_translation(-positions[4].as_vec3());
        assert!(infer_symmetry_plane(&skeleton, &positions, 0.02).is_none());
    }

    /// Rule 5 at the bend of a tube of radius ½ bent by `bend` degrees, the leaf's upper
    /// bone coming up the first segment: the second segment is the part past the leaf. The
    /// bone is taken as 4 long, longer than that part (3 and a cap), as a leg bone is longer
    /// than the foot past its ankle: (c) does not apply.
    fn leaf_part_at_bend(bend: f64) -> LeafPart {
        let (mesh, _) = crate::fixtures::shapes::bent_cylinder(0.5, 3.0, bend, 24, 16);
        let pieces = vec![0; mesh.vertex_count()];
        leaf_part_of(&mesh, &pieces, DVec3::Y * 3.0, DVec3::Y, 4.0)
    }

    /// Rule 5 for a leaf at `position` of `mesh` (pieces `pieces`), its upper bone of length
    /// `bone_length` along the unit `upper` (also its own direction), with no other bone
    /// near.
    fn leaf_part_of(
        mesh: &SurfaceMesh,
        pieces: &[u32],
        position: DVec3,
        upper: DVec3,
        bone_length: f64,
    ) -> LeafPart {
        let spheres = FaceSpheres::new(mesh);
        let frame = JointFrame {
            position,
            upper,
            lower: upper,
            bone_length,
            surface_distance: spheres.nearest_distance(mesh, position),
            on_mirror_plane: false,
            mirror_twin: None,
            leaf_part_past: false,
        };
        let ratio = crate::DecomposeParams::default().leaf_extent_ratio;
        // The leaf (joint 1) and its parent: its bone is the only one.
        let positions = [position - bone_length * upper, position];
        let bones = BoneIndex::new(vec![(0, 1)], &positions);
        let reach = LeafReach::new(mesh, &spheres, &bones, 2);
        leaf_part(
            mesh,
            pieces,
            &spheres,
            &frame,
            (&reach, 1),
            orientation_sign(mesh),
            ratio,
        )
    }

    #[test]
    fn a_part_within_60_degrees_of_the_leafs_bone_is_the_leafs() {
        // Toes beyond the ball of a foot: within 60° of the bone.
        assert_eq!(leaf_part_at_bend(45.0), LeafPart::Owned);
        // A foot forward of an ankle whose leg bone points down into the sole: an end site.
        assert_eq!(leaf_part_at_bend(90.0), LeafPart::None);
        // A straight tube ends at its cap: the ray along the bone leaves it a radius away.
        assert_eq!(leaf_part_at_bend(0.0), LeafPart::Owned);
    }

    /// Rule 5 at a leaf lying just above a flat sheet (a tail modelled as one layer of
    /// faces in the plane y = 0, 0.4 wide, from z = 0 to z = −`length`), its bone of length
    /// 1 coming along the sheet from z = 0 to z = −1. With `apart`, the sheet past
    /// z = −1.05 is a piece of its own (its first row moved there, unjoined).
    fn leaf_part_on_sheet(length: f64, apart: bool) -> LeafPart {
        let mut mesh = SurfaceMesh {
            positions: Vec::new(),
            triangles: Vec::new(),
        };
        let mut pieces = Vec::new();
        // A strip from z = −`from` to z = −`to`, in rows 0.1 apart, as piece `piece`.
        let mut strip = |from: f64, to: f64, piece: u32| {
            let rows = ((to - from) * 10.0).round() as u32;
            let first = mesh.positions.len() as u32;
            for i in 0..=rows {
                let z = -(from + (to - from) * f64::from(i) / f64::from(rows));
                mesh.positions
                    .extend([DVec3::new(-0.2, 0.0, z), DVec3::new(0.2, 0.0, z)]);
                pieces.extend([piece, piece]);
            }
            for a in (0..rows).map(|i| first + 2 * i) {
                mesh.triangles
                    .extend([[a, a + 1, a + 2], [a + 1, a + 3, a + 2]]);
            }
        };
        if apart {
            strip(0.0, 1.0, 0);
            strip(1.05, length, 1);
        } else {
            strip(0.0, length, 0);
        }
        let position = DVec3::new(0.0, 0.001, -1.0);
        leaf_part_of(&mesh, &pieces, position, DVec3::NEG_Z, 1.0)
    }

    #[test]
    fn a_leaf_in_a_sheet_owns_the_sheet_that_runs_on_past_it_for_its_bones_length() {
        // The ray along the bone meets no face and the joint lies in the skin (rule 5 (b)
        // does not apply): only (c) tells a tail tip from the end of the sheet.
        assert_eq!(leaf_part_on_sheet(2.5, false), LeafPart::PastBone);
        assert_eq!(leaf_part_on_sheet(2.1, false), LeafPart::PastBone);
        assert_eq!(leaf_part_on_sheet(1.8, false), LeafPart::None);
        assert_eq!(leaf_part_on_sheet(1.0, false), LeafPart::None);
        // A piece of its own past the joint (a head modelled apart over a neck) is left to
        // the weighting of pieces.
        assert_eq!(leaf_part_on_sheet(2.5, true), LeafPart::None);
    }

    #[test]
    fn the_lower_bone_is_the_mean_child_direction() {
        let unit = |x: f64, y: f64, z: f64| DVec3::new(x, y, z).normalize();
        // A chest: neck up, arms to both sides; the mean points on along the spine.
        let up = DVec3::Y;
        let chest = [DVec3::Y, DVec3::X, DVec3::NEG_X];
        assert!(lower_direction(up, &chest).abs_diff_eq(up, 1e-12));
        // A wrist: fingers spread a little; the mean finger direction.
        let fingers = [
            unit(1.0, 0.2, 0.0),
            unit(1.0, 0.0, 0.0),
            unit(1.0, -0.2, 0.0),
        ];
        assert!(lower_direction(DVec3::X, &fingers).abs_diff_eq(DVec3::X, 1e-12));
        // No children: the upper bone.
        assert_eq!(lower_direction(DVec3::NEG_Y, &[]), DVec3::NEG_Y);
    }
}
