//! Which bones a joint of a region owns: κ, the factor that keeps a joint's weight on the
//! part of its region nearest to its own bones (see [`crate::weights`], step 3).
//!
//! With a(p) the distance from p to the nearest of the joint's own bones (its child bones
//! and every bone below them) and b(p) to the nearest other bone of the region (bones of
//! joints whose bone lies in it, except the joint's own upper bone, which meets its child
//! bones at the joint), κ(p) = β(clamp(1 − (a − λ b) / w, 0, 1)), and 1 when the region
//! has no other bone: 1 wherever the own bones are clearly the nearer, a ≤ λ b, falling to
//! 0 within one half-width w past that surface. λ = [`OWN_BONE_RATIO`] for a joint with
//! child bones; 1 for a leaf, whose own bone is a guess (half its parent's).
//!
//! Why λ < 1: near a soft joint the artists' weight follows the bones that are clearly
//! nearer, not the surface equidistant from two bones. Over the soft joints with child
//! bones of the 65 bench characters, the artist's weight on the joint averages .50–.55
//! where a/b < 0.8 and drops to .25–.30 where 0.8 ≤ a/b < 1.2 (b there over every bone
//! outside the joint's subtree; at clavicles and shoulders .27 → .07 → .02 for a/b in
//! 0.5–0.8, 0.8–1, 1–1.2), while λ = 1 gave the joint .47 where 0.8 ≤ a/b < 1. Measured on
//! the whole benchmark, docs/measurements.md ("Own bones clearly nearer").
//!
//! The bones are indexed once for every joint (`OwnershipBones`): the joints numbered in
//! depth-first order, so that the bones of a joint's subtree are one range of numbers, in
//! hierarchies of bone boxes ([`crate::skeleton::bone_tree`]): one over every bone, one per
//! region. A distance costs a descent of a tree, not a
//! scan of the region's bones (10,000 siblings of one root: 10,000 collinear bones in one
//! region).

use crate::decomposition::JointDecision;
use crate::skeleton::bone_tree::{BoneTree, Keys, Split};
use crate::weights::blend::beta;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use std::collections::HashMap;

/// λ: a joint with child bones keeps a vertex only where its own bones are at most this
/// fraction of the distance to the region's other bones (module documentation; 0.6–0.8
/// measure alike on the benchmark, 0.5 and 1 worse: docs/measurements.md).
pub const OWN_BONE_RATIO: f64 = 0.7;

/// The bones of a skeleton, indexed for the κ of any joint and region.
pub(crate) struct OwnershipBones {
    /// #J depth-first position of every joint: the joints below j (j included) are the
    /// positions `order[j]..subtree_end[j]`.
    order: Vec<u32>,
    subtree_end: Vec<u32>,
    positions: Vec<DVec3>,
    parents: Vec<Option<usize>>,
    /// Every bone keyed by its joint's depth-first position, split by keys.
    all: BoneTree,
    /// Per region: the bones of the joints whose bone lies in it, keyed likewise.
    regions: HashMap<u32, BoneTree>,
}

impl OwnershipBones {
    /// The index of `segments` ([`crate::skeleton::bones::bone_segments`] of `skeleton`),
    /// with the regions of `decisions`.
    pub(crate) fn new(
        skeleton: &Skeleton,
        decisions: &[JointDecision],
        segments: &[(u32, DVec3, DVec3)],
    ) -> Self {
        let (order, subtree_end) = depth_first_ranges(skeleton);
        let keyed = |&(j, start, end): &(u32, DVec3, DVec3)| (order[j as usize], start, end);
        let mut by_region: HashMap<u32, Vec<(u32, DVec3, DVec3)>> = HashMap::new();
        for segment in segments {
            if let Some(region) = decisions[segment.0 as usize].region {
                by_region.entry(region).or_default().push(keyed(segment));
            }
        }
        Self {
            all: BoneTree::new(segments.iter().map(keyed), Split::Keys),
            regions: by_region
                .into_iter()
                .map(|(region, bones)| (region, BoneTree::new(bones, Split::Space)))
                .collect(),
            positions: skeleton
                .bind_positions()
                .iter()
                .map(|p| p.as_dvec3())
                .collect(),
            parents: (0..skeleton.len()).map(|j| skeleton.parent(j)).collect(),
            order,
            subtree_end,
        }
    }
}

impl OwnershipBones {
    /// Whether joint `d` lies strictly below joint `c` in the skeleton.
    pub(crate) fn strictly_below(&self, d: usize, c: usize) -> bool {
        self.order[c] < self.order[d] && self.order[d] < self.subtree_end[c]
    }
}

/// Test decisions: `count` joints named j0, j1, …, every one's bone in `region`.
#[cfg(test)]
pub(crate) fn one_region_decisions(count: usize, region: u32) -> Vec<JointDecision> {
    (0..count)
        .map(|k| JointDecision {
            name: format!("j{k}"),
            status: crate::decomposition::JointStatus::Skipped(String::new()),
            boundary: None,
            region: Some(region),
            owns_skin: true,
        })
        .collect()
}

/// The depth-first position of every joint of `skeleton` and the end of its subtree's
/// positions (roots in index order, children in index order).
fn depth_first_ranges(skeleton: &Skeleton) -> (Vec<u32>, Vec<u32>) {
    let children = skeleton.children();
    let (mut order, mut end) = (vec![0u32; skeleton.len()], vec![0u32; skeleton.len()]);
    let mut next = 0u32;
    // (joint, whether its subtree is finished)
    let mut stack: Vec<(usize, bool)> = (0..skeleton.len())
        .rev()
        .filter(|&j| skeleton.parent(j).is_none())
        .map(|j| (j, false))
        .collect();
    while let Some((j, finished)) = stack.pop() {
        if finished {
            end[j] = next;
            continue;
        }
        order[j] = next;
        next += 1;
        stack.push((j, true));
        stack.extend(children[j].iter().rev().map(|&c| (c, false)));
    }
    (order, end)
}

/// Some bones of an [`OwnershipBones`]: those of `tree` whose keys `keys` admits, except
/// those keyed `upper.0` that end at `upper.1` (a joint's upper bones).
#[derive(Clone, Copy)]
struct BoneSet<'a> {
    tree: Option<&'a BoneTree>,
    keys: Keys,
    upper: Option<(u32, DVec3)>,
}

impl BoneSet<'_> {
    fn nearest_distance(&self, p: DVec3) -> f64 {
        self.tree.map_or(f64::INFINITY, |tree| {
            tree.nearest_distance(p, self.keys, |key, end| self.upper != Some((key, end)))
        })
    }
}

/// The bones that decide κ for one joint of a region.
pub(crate) struct Ownership<'a> {
    /// The joint's own bones: its child bones and every bone below them.
    own: BoneSet<'a>,
    /// The other bones of the region (neither the joint's own nor its upper bone).
    other: BoneSet<'a>,
    half_width: f64,
    /// λ of the module documentation.
    ratio: f64,
}

impl<'a> Ownership<'a> {
    /// The bones κ compares for `joint` in `region`: its own bones, those of the joint and
    /// the joints below it, and the other bones of the region, those of every other joint
    /// whose decision lies in the region except the parent's bones ending at the joint's
    /// position (its upper bone); λ = [`OWN_BONE_RATIO`] when the joint has child joints.
    pub(crate) fn new(
        bones: &'a OwnershipBones,
        joint: usize,
        region: u32,
        half_width: f64,
    ) -> Self {
        let below = (bones.order[joint], bones.subtree_end[joint]);
        let upper = bones.parents[joint].map(|p| (bones.order[p], bones.positions[joint]));
        Self {
            own: BoneSet {
                tree: Some(&bones.all),
                keys: Keys::Inside(below.0, below.1),
                upper: None,
            },
            other: BoneSet {
                tree: bones.regions.get(&region),
                keys: Keys::Outside(below.0, below.1),
                upper,
            },
            half_width,
            ratio: if below.1 - below.0 > 1 {
                OWN_BONE_RATIO
            } else {
                1.0
            },
        }
    }

    /// κ(p) = β(clamp(1 − (a − λ b) / w, 0, 1)), a and b the distances from p to the
    /// nearest own and other bone (1 without other bones, 0 without own bones).
    pub(crate) fn at(&self, position: DVec3) -> f64 {
        let own = self.own.nearest_distance(position);
        if own == f64::INFINITY {
            return 0.0;
        }
        let other = self.other.nearest_distance(position);
        if other == f64::INFINITY {
            return 1.0;
        }
        let w = self.half_width.max(f64::MIN_POSITIVE);
        beta((1.0 - (own - self.ratio * other) / w).clamp(0.0, 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decomposition::JointStatus;
    use crate::geometry::point_segment_distance;
    use crate::skeleton::bones::bone_segments;
    use atlas_skin_runtime::random_pose::SplitMix64;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    type Bones = Vec<[DVec3; 2]>;

    /// κ's bones for `joint` in `region` by their definition, each joint's ancestors walked:
    /// (own, other).
    fn reference_bones(
        skeleton: &Skeleton,
        decisions: &[JointDecision],
        segments: &[(u32, DVec3, DVec3)],
        joint: usize,
        region: u32,
    ) -> (Bones, Bones) {
        let below_joint = |j: usize| j == joint || skeleton.ancestors(j).any(|a| a == joint);
        let joint_position = skeleton.bind_positions()[joint].as_dvec3();
        let (mut own, mut other) = (Vec::new(), Vec::new());
        for &(j, start, end) in segments {
            let j = j as usize;
            if below_joint(j) {
                own.push([start, end]);
            } else if decisions[j].region == Some(region)
                && !(skeleton.parent(joint) == Some(j) && end == joint_position)
            {
                other.push([start, end]);
            }
        }
        (own, other)
    }

    /// κ by the formula with plain point–segment distances, every bone scanned.
    fn reference_kappa(
        own: &[[DVec3; 2]],
        other: &[[DVec3; 2]],
        ratio: f64,
        w: f64,
        p: DVec3,
    ) -> f64 {
        let nearest = |bones: &[[DVec3; 2]]| {
            bones
                .iter()
                .map(|&[a, b]| point_segment_distance(p, a, b))
                .fold(f64::INFINITY, f64::min)
        };
        let (a, b) = (nearest(own), nearest(other));
        if a == f64::INFINITY {
            0.0
        } else if b == f64::INFINITY {
            1.0
        } else {
            beta((1.0 - (a - ratio * b) / w).clamp(0.0, 1.0))
        }
    }

    /// A random tree of `n` joints (one or two roots); about a third of them children of
    /// joint 0 on one line through it (siblings whose bones overlap, equally far from the
    /// points around the line), a few at their parent's position (zero-length bones).
    fn random_skeleton(rng: &mut SplitMix64, n: usize) -> Skeleton {
        let mut parents = vec![NO_PARENT];
        let mut positions = vec![Vec3::ZERO];
        for k in 1..n {
            let roll = rng.next_f64();
            let (parent, position) = if roll < 0.35 {
                (0, Vec3::Y * (rng.next_f64() as f32) * 2.0)
            } else if k == n / 2 && roll < 0.5 {
                (NO_PARENT, Vec3::X)
            } else {
                let parent = (rng.next_f64() * k as f64) as usize;
                let offset = if roll > 0.95 {
                    Vec3::ZERO
                } else {
                    Vec3::new(
                        rng.next_f64() as f32 - 0.5,
                        rng.next_f64() as f32 - 0.5,
                        rng.next_f64() as f32 - 0.5,
                    )
                };
                (parent as u32, positions[parent] + offset)
            };
            parents.push(parent);
            positions.push(position);
        }
        Skeleton::from_positions(
            (0..n).map(|k| format!("j{k}")).collect(),
            parents,
            &positions,
        )
        .unwrap()
    }

    /// A spine bone up from the root and a clavicle with an arm bone out along x, all in one
    /// region: the clavicle keeps the points clearly nearer to its bones (a ≤ λ b) and
    /// leaves those about as near to the spine (the chest) to it; a leaf keeps every
    /// point nearer to its guessed bone.
    #[test]
    fn a_joint_keeps_only_what_lies_clearly_nearer_its_own_bones() {
        // 0 root, 1 neck (spine bone 0 → 1), 2 clavicle (its upper bone 0 → 2), 3 arm
        // (the clavicle's own bone 2 → 3), 4 hand (a leaf below the arm).
        let skeleton = Skeleton::from_positions(
            (0..5).map(|k| format!("j{k}")).collect(),
            vec![NO_PARENT, 0, 0, 2, 3],
            &[
                Vec3::ZERO,
                Vec3::new(0.0, 2.0, 0.0),
                Vec3::new(0.5, 1.5, 0.0),
                Vec3::new(1.5, 1.5, 0.0),
                Vec3::new(2.5, 1.5, 0.0),
            ],
        )
        .unwrap();
        let decisions = one_region_decisions(5, 0);
        let segments = bone_segments(&skeleton);
        let bones = OwnershipBones::new(&skeleton, &decisions, &segments);
        let w = 0.05;
        let clavicle = Ownership::new(&bones, 2, 0, w);
        // Above the clavicle's bone, 0.2 from it and 0.7 from the spine: kept.
        assert_eq!(clavicle.at(DVec3::new(0.7, 1.7, 0.0)), 1.0);
        // The chest below it: 0.5 from the clavicle's bone, 0.6 from the spine. Nearer to
        // the clavicle, but not clearly: left to the spine.
        let chest = DVec3::new(0.6, 1.0, 0.0);
        assert!(chest.distance(DVec3::new(0.6, 1.5, 0.0)) < chest.x);
        assert_eq!(clavicle.at(chest), 0.0);
        // A leaf compares plain distances: the hand keeps what is nearer to its guessed
        // bone (2.5 → 3 along x), here 0.85 times as far as the arm's end.
        let hand = Ownership::new(&bones, 4, 0, w);
        let beside = DVec3::new(2.6, 3.275, 0.0);
        let ratio = (beside.y - 1.5) / beside.distance(DVec3::new(1.5, 1.5, 0.0));
        assert!(ratio > OWN_BONE_RATIO && ratio < 1.0, "{ratio}");
        assert_eq!(hand.at(beside), 1.0);
    }

    #[test]
    fn indexed_bones_give_the_reference_kappa() {
        let mut rng = SplitMix64::new(7);
        for case in 0..24 {
            let n = [1, 2, 3, 8, 30, 90][case % 6];
            let skeleton = random_skeleton(&mut rng, n);
            let decisions: Vec<JointDecision> = (0..n)
                .map(|k| JointDecision {
                    name: format!("j{k}"),
                    status: JointStatus::Skipped(String::new()),
                    boundary: None,
                    region: [None, Some(0), Some(1), Some(1)][(rng.next_f64() * 4.0) as usize],
                    owns_skin: true,
                })
                .collect();
            let segments = bone_segments(&skeleton);
            let bones = OwnershipBones::new(&skeleton, &decisions, &segments);
            let w = 0.3;
            for joint in 0..n {
                for region in 0..2 {
                    let (own, other) =
                        reference_bones(&skeleton, &decisions, &segments, joint, region);
                    let owner = Ownership::new(&bones, joint, region, w);
                    for q in 0..40 {
                        let (u, v, t) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
                        let p = if q % 2 == 0 {
                            // Around the line of the root's collinear children.
                            let angle = u * std::f64::consts::TAU;
                            DVec3::new(0.2 * angle.cos(), 2.2 * v - 0.1, 0.2 * angle.sin())
                        } else {
                            DVec3::new(3.0 * u - 1.5, 3.0 * v - 1.0, 3.0 * t - 1.5)
                        };
                        let close = |got: f64, expected: f64| (got - expected).abs() < 1e-9;
                        let ratio = if skeleton.children()[joint].is_empty() {
                            1.0
                        } else {
                            OWN_BONE_RATIO
                        };
                        let expected = reference_kappa(&own, &other, ratio, w, p);
                        let got = owner.at(p);
                        assert!(
                            close(got, expected),
                            "case {case}, joint {joint}, region {region} at {p}: {got} vs {expected}"
                        );
                    }
                }
            }
        }
    }
}
