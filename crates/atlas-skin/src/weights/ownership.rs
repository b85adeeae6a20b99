//! Which bones a joint of a region owns: κ, the factor that keeps a joint's weight on the
//! part of its region nearest to its own bones (see [`crate::weights`], step 3).
//!
//! With a(p) the distance from p to the nearest of the joint's own bones (its child bones
//! and every bone below them) and b(p) to the nearest other bone of the region (bones of
//! joints whose bone lies in it, except the joint's own upper bone, which meets its child
//! bones at the joint), κ(p) = β(clamp(1 − (a − b) / w, 0, 1)), and 1 when the region has
//! no other bone: 1 wherever the own bones are the nearer, falling to 0 within one
//! half-width w past the surface equidistant from both.

use crate::decomposition::JointDecision;
use crate::weights::blend::beta;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;

/// The bones that decide κ for one joint of a region.
pub(crate) struct Ownership {
    /// The joint's own bones: its child bones and every bone below them.
    own_bones: Vec<Segment>,
    /// The other bones of the region (neither the joint's own nor its upper bone).
    other_bones: Vec<Segment>,
    half_width: f64,
}

/// A bone [a, b], prepared for many distance queries.
#[derive(Debug, Clone, Copy)]
struct Segment {
    start: DVec3,
    along: DVec3,
    /// 1 / |b − a|², 0 for a point.
    inverse_length_squared: f64,
    /// Midpoint and half length: no point of the segment is farther from the midpoint.
    middle: DVec3,
    half_length: f64,
}

impl Segment {
    fn new(start: DVec3, end: DVec3) -> Self {
        let along = end - start;
        let length_squared = along.length_squared();
        Self {
            start,
            along,
            inverse_length_squared: if length_squared > 0.0 {
                1.0 / length_squared
            } else {
                0.0
            },
            middle: start + 0.5 * along,
            half_length: 0.5 * length_squared.sqrt(),
        }
    }

    /// Squared distance from `p` to the segment (the same point as
    /// [`crate::skeleton::bones::point_segment_distance`]).
    fn distance_squared(&self, p: DVec3) -> f64 {
        let offset = p - self.start;
        let t = (offset.dot(self.along) * self.inverse_length_squared).clamp(0.0, 1.0);
        (offset - self.along * t).length_squared()
    }
}

impl Ownership {
    /// The bones κ compares for `joint` in `region`, as (start, end) segments of
    /// `segments` ([`crate::skeleton::bones::bone_segments`]): its own bones, those of the joint and the joints
    /// below it, and the other bones of the region, those of every other joint whose
    /// decision lies in the region except the parent's bones ending at the joint's
    /// position (its upper bone).
    pub(crate) fn new(
        skeleton: &Skeleton,
        decisions: &[JointDecision],
        segments: &[(u32, DVec3, DVec3)],
        joint: usize,
        region: u32,
        half_width: f64,
    ) -> Self {
        let below_joint = |j: usize| j == joint || skeleton.ancestors(j).any(|a| a == joint);
        let joint_position = skeleton.bind_positions()[joint].as_dvec3();
        let upper_parent = skeleton.parent(joint);
        let mut ownership = Self {
            own_bones: Vec::new(),
            other_bones: Vec::new(),
            half_width,
        };
        for &(j, start, end) in segments {
            let j = j as usize;
            if below_joint(j) {
                ownership.own_bones.push(Segment::new(start, end));
            } else if decisions[j].region == Some(region)
                && !(upper_parent == Some(j) && end == joint_position)
            {
                ownership.other_bones.push(Segment::new(start, end));
            }
        }
        ownership
    }

    /// The factor that carries a soft joint's part past the far edge of its plane's band
    /// (weights, step 3): the same formula as κ with, as own bones, the bones of the
    /// joint's descendants that no other soft boundary of the region takes
    /// (`handled[d]` true: such a joint's bones and those below it are left out), and as
    /// other bones, the joint's own child bones and the other bones of `self`. It is 1
    /// where such a descendant bone is the nearest: a chin below the plane of the neck
    /// joint above it, nearest to a jaw bone that has no boundary of its own.
    pub(crate) fn beyond(
        &self,
        skeleton: &Skeleton,
        segments: &[(u32, DVec3, DVec3)],
        joint: usize,
        handled: &[bool],
    ) -> Self {
        // Whether j lies strictly below `joint` with no handled joint on the way.
        let free_descendant = |j: usize| {
            j != joint
                && std::iter::once(j)
                    .chain(skeleton.ancestors(j))
                    .find(|&a| a == joint || handled[a])
                    == Some(joint)
        };
        let mut beyond = Self {
            own_bones: Vec::new(),
            other_bones: self.other_bones.clone(),
            half_width: self.half_width,
        };
        for &(j, start, end) in segments {
            if j as usize == joint {
                beyond.other_bones.push(Segment::new(start, end));
            } else if free_descendant(j as usize) {
                beyond.own_bones.push(Segment::new(start, end));
            }
        }
        beyond
    }

    /// κ(p) = β(clamp(1 − (a − b) / w, 0, 1)), a and b the distances from p to the
    /// nearest own and other bone (1 without other bones, 0 without own bones).
    pub(crate) fn at(&self, position: DVec3) -> f64 {
        // The nearest bone's distance; a bone whose bounding sphere lies farther than the
        // best distance so far cannot be nearer and is skipped.
        let nearest = |bones: &[Segment]| {
            let mut best = f64::INFINITY;
            for bone in bones {
                let reach = best + bone.half_length;
                if position.distance_squared(bone.middle) >= reach * reach {
                    continue;
                }
                best = best.min(bone.distance_squared(position).sqrt());
            }
            best
        };
        let own = nearest(&self.own_bones);
        if own == f64::INFINITY {
            return 0.0;
        }
        let other = nearest(&self.other_bones);
        if other == f64::INFINITY {
            return 1.0;
        }
        let w = self.half_width.max(f64::MIN_POSITIVE);
        beta((1.0 - (own - other) / w).clamp(0.0, 1.0))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::geometry::point_segment_distance;
    use atlas_skin_runtime::random_pose::SplitMix64;

    /// κ by the formula with plain point–segment distances, no pruning.
    fn reference_kappa(own: &[[DVec3; 2]], other: &[[DVec3; 2]], w: f64, p: DVec3) -> f64 {
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
            beta((1.0 - (a - b) / w).clamp(0.0, 1.0))
        }
    }

    #[test]
    fn pruned_nearest_bones_give_the_reference_kappa() {
        let mut rng = SplitMix64::new(7);
        let mut point = || {
            DVec3::new(
                rng.next_f64() * 4.0 - 2.0,
                rng.next_f64() * 4.0 - 2.0,
                rng.next_f64() * 4.0 - 2.0,
            )
        };
        for case in 0..20 {
            let mut bones = |n: usize| -> Vec<[DVec3; 2]> {
                (0..n)
                    .map(|k| {
                        let a = point();
                        // Every fifth bone is a point.
                        [a, if k % 5 == 0 { a } else { point() }]
                    })
                    .collect()
            };
            let own = bones(case % 4);
            let other = bones(case % 7);
            let ownership = Ownership {
                own_bones: own.iter().map(|&[a, b]| Segment::new(a, b)).collect(),
                other_bones: other.iter().map(|&[a, b]| Segment::new(a, b)).collect(),
                half_width: 0.3,
            };
            for _ in 0..200 {
                let p = point();
                let expected = reference_kappa(&own, &other, 0.3, p);
                let got = ownership.at(p);
                assert!(
                    (got - expected).abs() < 1e-12,
                    "case {case} at {p}: {got} vs {expected}"
                );
            }
        }
    }
}
