//! Bones as segments: the segments each joint moves, point-to-segment distances, the
//! nearest bone of a point, the distance to each joint's bones, and the rigid binding of
//! every vertex to its nearest bone (the simplest automatic weights: the fallback of the
//! weights stage and a baseline).

use crate::geometry::point_segment_distance;
use crate::skeleton::bone_tree::{BoneTree, Keys, Split};
use crate::tolerance::NEGLIGIBLE;
use atlas_skin_runtime::{Skeleton, VertexWeights};
use glam::DVec3;
use std::ops::ControlFlow;

/// A leaf's continued bone stops at the joint that is the `EXTENSION_JOINTS`-th other joint
/// lying on it past the leaf ([`bone_segments`]). On the benchmark's 75 skins no leaf's
/// continuation holds any other joint (docs/measurements.md); on thousands of sibling leaves of one root, each
/// continuing its bone along the bones of the siblings beyond it, every continuation would
/// hold hundreds, and the soft sides the weights follow along them overlap by the
/// thousand (work and memory growing with the square of the joint count). Where it binds
/// the pipeline warns ([`capped_extensions`]).
pub const EXTENSION_JOINTS: usize = 8;

/// Bone segments of every joint: joint j moves the segments from j to each of its children;
/// a leaf j has the segment to its tail when the skeleton gives one ([`Skeleton::tails`]),
/// and otherwise continues its parent's bone p→j by half its length (j, j + (j − p)/2), so
/// that what lies beyond an end joint binds to it rather than to the parent, but no farther
/// than the [`EXTENSION_JOINTS`]-th other joint lying on that continuation (within
/// [`NEGLIGIBLE`] × the joints' bounding-box diagonal of it, past j by as much); a lone
/// root without a tail has the point (j, j). Returns (joint, start, end) triples.
pub fn bone_segments(skeleton: &Skeleton) -> Vec<(u32, DVec3, DVec3)> {
    segments_and_capped(skeleton).0
}

/// The leaves whose continued bone [`EXTENSION_JOINTS`] shortened in [`bone_segments`].
pub fn capped_extensions(skeleton: &Skeleton) -> Vec<u32> {
    segments_and_capped(skeleton).1
}

fn segments_and_capped(skeleton: &Skeleton) -> (Vec<(u32, DVec3, DVec3)>, Vec<u32>) {
    let positions: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let children = skeleton.children();
    let joints = JointsOnSegments::new(&positions);
    let mut segments = Vec::new();
    let mut capped = Vec::new();
    for (j, kids) in children.iter().enumerate() {
        if kids.is_empty() {
            let beyond = match skeleton.tails[j] {
                Some(tail) => tail.as_dvec3(),
                None => skeleton.parent(j).map_or(positions[j], |p| {
                    let end = positions[j] + (positions[j] - positions[p]) * 0.5;
                    let stop = joints.kth_on(j, end, EXTENSION_JOINTS);
                    if stop.is_some() {
                        capped.push(j as u32);
                    }
                    stop.unwrap_or(end)
                }),
            };
            segments.push((j as u32, positions[j], beyond));
        }
        for &c in kids {
            segments.push((j as u32, positions[j], positions[c]));
        }
    }
    (segments, capped)
}

/// The joints as points, for the joints lying on a segment from one of them.
struct JointsOnSegments<'a> {
    positions: &'a [DVec3],
    /// The joints' points, keyed by joint.
    tree: BoneTree,
    /// [`NEGLIGIBLE`] × the joints' bounding-box diagonal.
    tolerance: f64,
}

impl<'a> JointsOnSegments<'a> {
    fn new(positions: &'a [DVec3]) -> Self {
        let (lo, hi) = crate::geometry::bounding_box(positions);
        Self {
            positions,
            tree: BoneTree::new(
                (0u32..).zip(positions).map(|(j, &p)| (j, p, p)),
                Split::Space,
            ),
            tolerance: NEGLIGIBLE * (hi - lo).length(),
        }
    }

    /// Whether joint k lies on the segment from joint j to `end`, past j.
    fn on_segment(&self, j: usize, end: DVec3, k: usize) -> Option<f64> {
        let (start, q) = (self.positions[j], self.positions[k]);
        let along = (q - start).dot((end - start).normalize_or_zero());
        (k != j
            && along > self.tolerance
            && point_segment_distance(q, start, end) <= self.tolerance)
            .then_some(along)
    }

    /// The point of the segment from joint j to `end` at the `count`-th other joint lying
    /// on it, counted from j; `None` when fewer lie on it. Joints are visited nearest to j
    /// first, so a leaf among thousands of joints on one line visits about 2 · `count`.
    ///
    /// A segment no longer than the tolerance (a leaf at its parent's point) is never cut
    /// short: a stop on it would lie within twice the tolerance of j, and the visit would
    /// see every joint at that point (all of a skeleton bound at one point, for each leaf).
    fn kth_on(&self, j: usize, end: DVec3, count: usize) -> Option<DVec3> {
        let start = self.positions[j];
        if start.distance(end) <= self.tolerance {
            return None;
        }
        let direction = (end - start).normalize_or_zero();
        let reach = start.distance(end) + self.tolerance;
        let mut seen = 0;
        match self.tree.visit_nearest_first(start, reach, |k, _| {
            if let Some(along) = self.on_segment(j, end, k as usize) {
                seen += 1;
                if seen == count {
                    return ControlFlow::Break(start + direction * along);
                }
            }
            ControlFlow::Continue(())
        }) {
            ControlFlow::Break(stop) => Some(stop),
            ControlFlow::Continue(()) => None,
        }
    }
}

/// The bone segments of every joint in a tree keyed by joint ([`Split::Keys`]), for d_j:
/// the distance from a point to the nearest bone segment of joint j, in one descent rather
/// than a scan of the joint's bones (a root may have thousands of child bones).
#[derive(Debug, Clone)]
pub struct JointBones {
    tree: BoneTree,
}

impl JointBones {
    /// - `segments`: (joint, start, end) triples, as [`bone_segments`] gives them.
    pub fn new(segments: &[(u32, DVec3, DVec3)]) -> Self {
        Self {
            tree: BoneTree::new(segments.iter().copied(), Split::Keys),
        }
    }

    /// d_j: the distance from `p` to the nearest bone segment of `joint` (infinity when it
    /// has none), the minimum of a scan of its segments to rounding
    /// ([`BoneTree::nearest_distance`]).
    pub fn distance(&self, p: DVec3, joint: u32) -> f64 {
        self.tree
            .nearest_distance(p, Keys::Inside(joint, joint + 1), |_, _| true)
    }
}

/// Bones as (parent, child) joint pairs, skipping those whose two ends coincide.
///
/// - `positions`: #J bind positions of `skeleton`'s joints.
pub fn joint_pairs(skeleton: &Skeleton, positions: &[DVec3]) -> Vec<(usize, usize)> {
    (0..skeleton.len())
        .filter_map(|c| skeleton.parent(c).map(|p| (p, c)))
        .filter(|&(p, c)| positions[p] != positions[c])
        .collect()
}

/// The bones of a skeleton ([`joint_pairs`]) as segments, with a tree for the bones near a
/// point: what a cut or a leaf's reach at a joint must keep clear of.
#[derive(Debug, Clone)]
pub struct BoneIndex {
    /// (parent, child) joints of every bone.
    pairs: Vec<(usize, usize)>,
    segments: Vec<[DVec3; 2]>,
    tree: BoneTree,
}

impl BoneIndex {
    /// - `positions`: #J bind positions of the joints of `pairs`.
    pub fn new(pairs: Vec<(usize, usize)>, positions: &[DVec3]) -> Self {
        let segments: Vec<[DVec3; 2]> = pairs
            .iter()
            .map(|&(p, c)| [positions[p], positions[c]])
            .collect();
        let tree = BoneTree::of_segments(&segments);
        Self {
            pairs,
            segments,
            tree,
        }
    }

    /// (parent, child) joints of every bone.
    pub fn pairs(&self) -> &[(usize, usize)] {
        &self.pairs
    }

    /// The bones, increasing, within (1 + `tie`) times the distance of the nearest bone to
    /// `p` (every bone at that distance, and those a rounding away), when there are at most
    /// `most` of them; none without bones.
    pub fn nearest_bones(&self, p: DVec3, tie: f64, most: usize) -> Option<Vec<u32>> {
        let nearest = self.tree.nearest(p);
        if nearest.is_finite() {
            self.tree.within_at_most(p, nearest * (1.0 + tie), most)
        } else {
            Some(Vec::new())
        }
    }

    /// The bones with neither end at `joint` within `radius` of `point`, in bone order.
    pub fn near(&self, joint: usize, point: DVec3, radius: f64) -> Vec<[DVec3; 2]> {
        self.tree
            .within(point, radius)
            .into_iter()
            .filter(|&k| self.not_at(k, joint))
            .map(|k| self.segments[k as usize])
            .collect()
    }

    /// A bone, as its (parent, child) joints, with neither end at `joint` within `radius`
    /// of `point` for whose segment `admit` holds; `None` when there is none.
    pub fn find_near(
        &self,
        joint: usize,
        point: DVec3,
        radius: f64,
        admit: impl Fn([DVec3; 2]) -> bool,
    ) -> Option<(usize, usize)> {
        self.tree
            .find_within(point, radius, |k| {
                self.not_at(k, joint) && admit(self.segments[k as usize])
            })
            .map(|k| self.pairs[k as usize])
    }

    fn not_at(&self, bone: u32, joint: usize) -> bool {
        let (p, c) = self.pairs[bone as usize];
        p != joint && c != joint
    }
}

/// Weight 1 on the joint owning the bone segment nearest to each position (Euclidean, not
/// along the surface: it can bind an arm vertex to a touching thigh).
///
/// - `positions`: #V points; returns #V rows of one influence each (none for an empty
///   skeleton).
pub fn nearest_bone_weights(positions: &[DVec3], skeleton: &Skeleton) -> VertexWeights {
    let segments = bone_segments(skeleton);
    VertexWeights::from_rows(
        positions
            .iter()
            .map(|&p| nearest_bone(&segments, p).map(|j| (j, 1.0))),
    )
}

/// The joint owning the bone segment nearest to `p`, argmin_j dist(p, segment_j)
/// (`segments` from [`bone_segments`]; `None` when there is none).
pub fn nearest_bone(segments: &[(u32, DVec3, DVec3)], p: DVec3) -> Option<u32> {
    nearest_bone_with_distance(segments, p).map(|b| b.joint)
}

/// The nearest bone of a point: the joint owning the segment and the distance to it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NearestBone {
    pub joint: u32,
    pub distance: f64,
}

/// [`nearest_bone`] with the distance.
pub fn nearest_bone_with_distance(
    segments: &[(u32, DVec3, DVec3)],
    p: DVec3,
) -> Option<NearestBone> {
    segments
        .iter()
        .map(|&(joint, a, b)| NearestBone {
            joint,
            distance: point_segment_distance(p, a, b),
        })
        .min_by(|x, y| x.distance.total_cmp(&y.distance))
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::random_pose::SplitMix64;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    /// The reference of [`BoneIndex::near`]: every bone of `pairs` with neither end at `j`
    /// within `radius` of `point`, by a scan.
    fn bones_near_by_scan(
        pairs: &[(usize, usize)],
        positions: &[DVec3],
        j: usize,
        point: DVec3,
        radius: f64,
    ) -> Vec<[DVec3; 2]> {
        pairs
            .iter()
            .filter(|&&(p, c)| p != j && c != j)
            .map(|&(p, c)| [positions[p], positions[c]])
            .filter(|&[a, b]| point_segment_distance(point, a, b) <= radius)
            .collect()
    }

    /// The reference of `JointsOnSegments::kth_on`: every joint on the segment by a scan,
    /// sorted along it.
    fn kth_on_by_scan(
        joints: &JointsOnSegments,
        j: usize,
        end: DVec3,
        count: usize,
    ) -> Option<f64> {
        let mut along: Vec<f64> = (0..joints.positions.len())
            .filter_map(|k| joints.on_segment(j, end, k))
            .collect();
        along.sort_unstable_by(f64::total_cmp);
        along.get(count - 1).copied()
    }

    /// Siblings of a root on one line (some at one height), with joints off the line: the
    /// joint where a continuation stops is the one a scan finds.
    #[test]
    fn a_continuation_stops_at_the_joint_a_scan_finds() {
        let mut rng = SplitMix64::new(7);
        for case in 0..10 {
            let count = 5 + case * 40;
            let mut positions = vec![DVec3::ZERO];
            for k in 1..count {
                let height = (rng.next_f64() * 50.0).round() / 10.0;
                positions.push(if k % 5 == 0 {
                    DVec3::new(rng.next_f64(), height, 0.0)
                } else {
                    DVec3::Y * height
                });
            }
            let joints = JointsOnSegments::new(&positions);
            for (j, &start) in positions.iter().enumerate().skip(1) {
                let end = start * 1.5;
                for wanted in [1, 3, EXTENSION_JOINTS] {
                    let got = joints.kth_on(j, end, wanted).map(|p| p.distance(start));
                    let expected = kth_on_by_scan(&joints, j, end, wanted);
                    assert_eq!(got.is_some(), expected.is_some(), "case {case}, joint {j}");
                    if let (Some(got), Some(expected)) = (got, expected) {
                        assert!((got - expected).abs() < 1e-9, "{got} vs {expected}");
                    }
                }
            }
        }
    }

    /// 100 siblings along one line: the continuation of each runs along the bones of the
    /// siblings beyond it and stops at the [`EXTENSION_JOINTS`]-th; a leaf with a few
    /// joints on its continuation keeps half its parent's bone.
    #[test]
    fn a_continuation_along_many_siblings_is_capped() {
        let count = 101;
        let positions: Vec<Vec3> = (0..count).map(|k| Vec3::Y * k as f32).collect();
        let parents: Vec<u32> = (0..count)
            .map(|k| if k == 0 { NO_PARENT } else { 0 })
            .collect();
        let names = (0..count).map(|k| format!("j{k}")).collect();
        let skeleton = Skeleton::from_positions(names, parents, &positions).unwrap();
        let segments = bone_segments(&skeleton);
        let leaf = |j: u32| {
            segments
                .iter()
                .find(|s| s.0 == j && s.1 == positions[j as usize].as_dvec3())
                .map(|s| s.2.y)
                .unwrap()
        };
        // j10 continues to 15 (5 joints on it), j40 (20 on it) to its 8th, j100 to 150.
        let k = EXTENSION_JOINTS as u32;
        assert_eq!(leaf(10), 15.0);
        assert_eq!(leaf(40), (40 + k) as f32 as f64);
        assert_eq!(leaf(100), 150.0);
        // Leaf j has min(j / 2, 100 − j) joints on its continuation.
        let capped = capped_extensions(&skeleton);
        assert_eq!(capped, (2 * k..=100 - k).collect::<Vec<u32>>());
    }

    /// Random trees with sibling bones on one line (a root with many children), queried
    /// at joints: the index finds what a scan finds.
    #[test]
    fn the_bone_index_finds_what_a_scan_finds() {
        let mut rng = SplitMix64::new(18);
        for case in 0..20 {
            let count = 2 + case * 7;
            let mut positions = vec![DVec3::ZERO];
            let mut pairs = Vec::new();
            for j in 1..count {
                let sibling = j % 3 == 0;
                let parent = if sibling {
                    0
                } else {
                    (rng.next_f64() * j as f64) as usize
                };
                let p = if sibling {
                    DVec3::Y * rng.next_f64()
                } else {
                    DVec3::new(rng.next_f64(), rng.next_f64(), rng.next_f64())
                };
                positions.push(p);
                if positions[parent] != p {
                    pairs.push((parent, j));
                }
            }
            let index = BoneIndex::new(pairs.clone(), &positions);
            for j in 0..count {
                for radius in [0.0, 1e-9, 0.1, 0.5] {
                    let point = positions[j];
                    let expected = bones_near_by_scan(&pairs, &positions, j, point, radius);
                    assert_eq!(index.near(j, point, radius), expected);
                    let long = |[a, b]: [DVec3; 2]| a.distance(b) > 0.5;
                    let found = index.find_near(j, point, radius, long);
                    assert_eq!(found.is_some(), expected.iter().any(|&s| long(s)));
                    if let Some((p, c)) = found {
                        assert!(p != j && c != j && long([positions[p], positions[c]]));
                    }
                }
            }
        }
    }

    #[test]
    fn vertices_bind_to_the_bone_they_lie_along() {
        let skeleton = Skeleton::from_positions(
            vec!["root".into(), "elbow".into(), "tip".into()],
            vec![NO_PARENT, 0, 1],
            &[Vec3::ZERO, Vec3::X, Vec3::X * 2.0],
        )
        .unwrap();
        let w = nearest_bone_weights(
            &[
                DVec3::new(0.4, 0.1, 0.0),
                DVec3::new(1.6, -0.1, 0.0),
                DVec3::new(2.5, 0.0, 0.0),
            ],
            &skeleton,
        );
        let dominant: Vec<u32> = (0..3).map(|v| w.row(v).next().unwrap().0).collect();
        assert_eq!(dominant, vec![0, 1, 2]);
    }
}
