//! Step 4 of the weights: the guard against gross misassignment (issue 13). A region, a
//! cut or a soft boundary can hand a vertex to a joint whose bones are far from it while
//! nearer bones run through the body beside it (a forearm vertex bound to a finger joint
//! whose plane crosses the forearm; a neck vertex bound to an ear). Such a weight moves
//! the vertex with a bone it has nothing to do with.
//!
//! For a vertex p, let d_j be the distance from p to the nearest bone segment of joint j
//! ([`bone_segments`]) and d* the distance to the nearest bone *reached through the body*:
//! the nearest segment whose nearest point q is seen from p along a straight line that
//! does not leave the surface first (a ray from p to q hits no face before q), so that a
//! thigh bone behind the skin of a touching arm does not count. A joint is far from p when
//!
//!   d_j > R · max(d*, ε · D)
//!
//! with R = [`FAR_BONE_RATIO`], D the surface's bounding-box diagonal and ε =
//! [`NEAR_FLOOR`] (bones lying in the skin, such as lip bones, do not make every other bone
//! far). The weights of far joints are removed and the rest renormalised; when every
//! weighted joint is far, p is bound to the joint of the nearest bone reached through the
//! body. The partition of unity holds afterwards as before.

use super::surface_weights::SurfaceWeights;
use crate::decomposition::Decomposition;
use crate::geometry::{point_segment_distance, segment_parameter};
use crate::mesh::FaceSpheres;
use crate::rows::{Rows, PAR_CHUNK};
use crate::skeleton::bone_tree::{BoneTree, Split};
use crate::skeleton::bones::{bone_segments, JointBones};
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use std::ops::ControlFlow;

/// R: a joint whose bones are this many times farther than the nearest bone reached
/// through the body is far (chosen on the benchmark, docs/measurements.md).
pub const FAR_BONE_RATIO: f64 = 2.5;

/// ε: distances below this fraction of the diagonal count as this fraction, about a limb's
/// radius: a bone in the skin (a breast or lip bone) does not make the trunk's bones far.
pub const NEAR_FLOOR: f64 = 0.05;

/// How many of the nearest bones are tried for a line of sight through the body.
const SIGHT_TRIES: usize = 8;

/// Removes the weights of far joints at every vertex of `weights` (module documentation);
/// returns how many vertices changed. Joints that own no skin take part only where they
/// already have weight.
///
/// - `joint_bones`: the [`bone_segments`] of `skeleton` keyed by joint, for the d_j.
pub fn guard_far_bones(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
    joint_bones: &JointBones,
    weights: &mut SurfaceWeights,
) -> usize {
    let surface = &decomposition.surface;
    let segments: Vec<(u32, DVec3, DVec3)> = bone_segments(skeleton)
        .into_iter()
        .filter(|&(j, _, _)| decomposition.joints[j as usize].owns_skin)
        .collect();
    if segments.is_empty() {
        return 0;
    }
    let floor = NEAR_FLOOR * surface.diagonal();
    let far = FarJoints::new(&segments, joint_bones, skeleton.len(), floor);
    // Vertices with a joint that is far even from the nearest bone by straight line: only
    // they need the line-of-sight test.
    let suspects: Vec<usize> = (0..weights.vertex_count())
        .filter(|&v| far.any_far(surface.positions[v], weights.row(v).map(|(j, _)| j)))
        .collect();
    if suspects.is_empty() {
        return 0;
    }
    let sight = SightLines::new(surface, decomposition.surface_spheres());
    let segment_tree = segment_tree(&segments);
    let mut changed = 0;
    let replaced: Rows<(u32, f64)> = Rows::par_build(
        suspects.len(),
        PAR_CHUNK,
        |k, _: &mut (), out: &mut Vec<(u32, f64)>| {
            let v = suspects[k];
            let p = surface.positions[v];
            let Some((near_joint, near)) = nearest_seen_bone(&sight, &segments, &segment_tree, p)
            else {
                out.extend(weights.row(v));
                return;
            };
            let limit = FAR_BONE_RATIO * near.max(floor);
            let kept: Vec<(u32, f64)> = weights
                .row(v)
                .filter(|&(j, _)| far.joint_distance(p, j) <= limit)
                .collect();
            let total: f64 = kept.iter().map(|&(_, w)| w).sum();
            if total > 0.0 {
                out.extend(kept.into_iter().map(|(j, w)| (j, w / total)));
            } else {
                out.push((near_joint, 1.0));
            }
        },
    );
    let mut result = SurfaceWeights {
        offsets: vec![0],
        ..SurfaceWeights::default()
    };
    let mut next = 0;
    for v in 0..weights.vertex_count() {
        if next < suspects.len() && suspects[next] == v {
            let new_row = replaced.row(next);
            if new_row.len() != weights.row(v).count()
                || new_row.iter().zip(weights.row(v)).any(|(a, b)| *a != b)
            {
                changed += 1;
            }
            result.extend_row(new_row.iter().copied());
            next += 1;
        } else {
            result.extend_row(weights.row(v));
        }
    }
    *weights = result;
    changed
}

/// How many of a joint's bone segments [`FarJoints`] keeps for its upper bound.
const BOUND_SEGMENTS: usize = 4;

/// The straight-line test of the guard: whether a weighted joint j of a vertex p is far
/// even from the nearest bone of all, d_j > R · max(d_min, ε · D) with d_min the distance
/// to the nearest bone segment (a vertex passing it is then tested for a line of sight).
/// Only the segments it is given count: a joint with none is at infinity.
struct FarJoints<'a> {
    /// All the segments in one tree, for d_min.
    bone_tree: BoneTree,
    /// Every joint's segments keyed by joint, for each d_j (a descent each, instead of a
    /// scan of every bone, or of the hundreds of child bones of one joint, per vertex).
    joint_bones: &'a JointBones,
    /// Whether the joint has segments among those given.
    has_segments: Vec<bool>,
    /// Up to [`BOUND_SEGMENTS`] segments of each joint: the distance to the nearest of
    /// them bounds d_j from above.
    bound_segments: Vec<Vec<[DVec3; 2]>>,
    /// ε · D.
    floor: f64,
}

impl<'a> FarJoints<'a> {
    /// - `segments`: the segments that count, (joint, start, end) triples.
    /// - `joint_bones`: segments keyed by joint, of every joint of `segments` with the same
    ///   segments (and maybe of other joints, which do not count).
    fn new(
        segments: &[(u32, DVec3, DVec3)],
        joint_bones: &'a JointBones,
        joint_count: usize,
        floor: f64,
    ) -> Self {
        let mut has_segments = vec![false; joint_count];
        let mut bound_segments = vec![Vec::new(); joint_count];
        for &(j, a, b) in segments {
            has_segments[j as usize] = true;
            let kept: &mut Vec<[DVec3; 2]> = &mut bound_segments[j as usize];
            if kept.len() < BOUND_SEGMENTS {
                kept.push([a, b]);
            }
        }
        Self {
            bone_tree: BoneTree::of_segments(
                &segments.iter().map(|&(_, a, b)| [a, b]).collect::<Vec<_>>(),
            ),
            joint_bones,
            has_segments,
            bound_segments,
            floor,
        }
    }

    /// d_j: the distance from `p` to the nearest bone segment of `joint` (infinity without).
    fn joint_distance(&self, p: DVec3, joint: u32) -> f64 {
        if self.has_segments[joint as usize] {
            self.joint_bones.distance(p, joint)
        } else {
            f64::INFINITY
        }
    }

    /// Whether a joint of `joints` is far from `p`: the same answer as
    /// [`FarJoints::any_far_by_trees`], with fewer tree descents. A joint is far only when
    /// d_j > R · max(d_min, ε · D) ≥ R ε D (the rounded product is monotonic in its
    /// factor), so a joint with a segment nearer than R ε D is not far and needs no
    /// descent: d_j is at most the distance u_j to its nearest segment of
    /// `bound_segments`, up to the tree's rounding (it skips a box whose computed distance
    /// equals its best, while a segment in it may compute a few units in the last place
    /// less), which a slack of 10⁻⁹ of the coordinates' size covers: the test is
    /// u_j + slack ≤ R ε D. d_min is found only when some d_j exceeds R ε D.
    fn any_far(&self, p: DVec3, joints: impl IntoIterator<Item = u32>) -> bool {
        let reach = FAR_BONE_RATIO * self.floor;
        let mut limit: Option<f64> = None;
        joints.into_iter().any(|j| {
            let near_segment = self.bound_segments[j as usize].iter().any(|&[a, b]| {
                let slack = 1e-9 * (p.abs() + a.abs() + b.abs()).max_element();
                point_segment_distance(p, a, b) + slack <= reach
            });
            if near_segment {
                return false;
            }
            let distance = self.joint_distance(p, j);
            distance > reach
                && distance
                    > *limit.get_or_insert_with(|| {
                        FAR_BONE_RATIO * self.bone_tree.nearest(p).max(self.floor)
                    })
        })
    }

    /// The reference of [`FarJoints::any_far`]: d_min and every d_j by a tree descent.
    #[cfg(test)]
    fn any_far_by_trees(&self, p: DVec3, joints: impl IntoIterator<Item = u32>) -> bool {
        let limit = FAR_BONE_RATIO * self.bone_tree.nearest(p).max(self.floor);
        joints
            .into_iter()
            .any(|j| self.joint_distance(p, j) > limit)
    }
}

/// The tree of `segments` that [`nearest_seen_bone`] reads: each keyed by its index.
fn segment_tree(segments: &[(u32, DVec3, DVec3)]) -> BoneTree {
    let keyed = segments.iter().enumerate();
    BoneTree::new(keyed.map(|(i, &(_, a, b))| (i as u32, a, b)), Split::Space)
}

/// The surface that lines of sight are cast through, with the step a ray starts off
/// its origin: 10⁻⁶ of the surface's bounding-box diagonal, found once (found per vertex,
/// it was a pass over every vertex for each suspect one: 93,000 suspects of a 100,000-vertex
/// capsule around a folded chain spent 30% of their time there, issue 45).
struct SightLines<'a> {
    surface: &'a crate::mesh::SurfaceMesh,
    spheres: &'a FaceSpheres,
    step: f64,
}

impl<'a> SightLines<'a> {
    fn new(surface: &'a crate::mesh::SurfaceMesh, spheres: &'a FaceSpheres) -> Self {
        Self {
            surface,
            spheres,
            step: 1e-6 * surface.diagonal(),
        }
    }
}

/// The joint and distance of the nearest bone segment whose nearest point to `p` is seen
/// from `p` through the body (no face hit before it), among the [`SIGHT_TRIES`] nearest;
/// the nearest of all when none of them is seen (a vertex on a thin shell). Segments at one
/// distance are taken in their order in `segments`.
///
/// The nearest come from `tree` (the segments keyed by their index), nearest first, with
/// every segment as near as the last of them: a few descents per vertex where a scan of
/// every segment cost vertices × bones (10,000 joints folded up and down a capsule of
/// 100,000 vertices: 45 s of CPU, issue 45). The distances are
/// [`point_segment_distance`]'s, the scan's, so the result is the scan's
/// (`nearest_seen_bone_by_scan`, compared in a test).
fn nearest_seen_bone(
    sight: &SightLines,
    segments: &[(u32, DVec3, DVec3)],
    tree: &BoneTree,
    p: DVec3,
) -> Option<(u32, f64)> {
    let mut nearest: Vec<(f64, u32)> = Vec::with_capacity(SIGHT_TRIES);
    let _ = tree.visit_nearest_first(p, f64::INFINITY, |i, d| {
        if nearest.len() >= SIGHT_TRIES && nearest.last().is_some_and(|&(last, _)| d > last) {
            return ControlFlow::Break(());
        }
        nearest.push((d, i));
        ControlFlow::Continue(())
    });
    nearest.sort_by(|x, y| x.0.total_cmp(&y.0).then(x.1.cmp(&y.1)));
    let by_distance = nearest.into_iter().map(|(d, i)| {
        let (j, a, b) = segments[i as usize];
        (d, j, a + (b - a) * segment_parameter(p, a, b))
    });
    first_seen(sight, by_distance, p)
}

/// The reference of [`nearest_seen_bone`]: every segment's distance, sorted.
#[cfg(test)]
fn nearest_seen_bone_by_scan(
    sight: &SightLines,
    segments: &[(u32, DVec3, DVec3)],
    p: DVec3,
) -> Option<(u32, f64)> {
    let mut by_distance: Vec<(f64, u32, DVec3)> = segments
        .iter()
        .map(|&(j, a, b)| {
            let q = a + (b - a) * segment_parameter(p, a, b);
            (p.distance(q), j, q)
        })
        .collect();
    by_distance.sort_by(|x, y| x.0.total_cmp(&y.0));
    first_seen(sight, by_distance.into_iter(), p)
}

/// Of the (distance, joint, nearest point) `by_distance`, nearest first, the first of the
/// [`SIGHT_TRIES`] nearest seen from `p`, else the nearest.
fn first_seen(
    sight: &SightLines,
    mut by_distance: impl Iterator<Item = (f64, u32, DVec3)>,
    p: DVec3,
) -> Option<(u32, f64)> {
    let (d, j, q) = by_distance.next()?;
    let first = (j, d);
    let step = sight.step;
    for (d, j, q) in std::iter::once((d, j, q))
        .chain(by_distance)
        .take(SIGHT_TRIES)
    {
        if d <= step {
            return Some((j, d));
        }
        let direction = (q - p) / d;
        let blocked = sight.spheres.hit_before(
            sight.surface,
            p + direction * step,
            direction,
            d - 2.0 * step,
        );
        if !blocked {
            return Some((j, d));
        }
    }
    Some(first)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::decompose::{decompose, DecomposeParams};
    use crate::fixtures::shapes::capsule_chain;
    use crate::mesh::{SurfaceMesh, Topology};
    use crate::skeleton::bones::nearest_bone;

    /// The far-joint test with its bounds against every distance by the trees: every vertex
    /// of cesiumman and makehuman's body with each joint alone and with all of them, and
    /// points around a bone at R ε D and a few units in the last place either side of it.
    #[test]
    fn far_joints_match_the_trees() {
        for (file, mesh, skeleton) in crate::fixtures::corpus::welded_humans() {
            let segments = bone_segments(&skeleton);
            let joint_bones = JointBones::new(&segments);
            let far = FarJoints::new(
                &segments,
                &joint_bones,
                skeleton.len(),
                NEAR_FLOOR * mesh.diagonal(),
            );
            let all = 0..skeleton.len() as u32;
            let mut far_count = 0;
            for &p in &mesh.positions {
                for j in all.clone() {
                    let expected = far.any_far_by_trees(p, [j]);
                    assert_eq!(far.any_far(p, [j]), expected, "{file}: {p} joint {j}");
                    far_count += usize::from(expected);
                }
                assert_eq!(
                    far.any_far(p, all.clone()),
                    far.any_far_by_trees(p, all.clone())
                );
            }
            assert!(far_count > 0, "{file}: some joints are far");
        }
        // One bone along X and a far one: points at R ε D from the first bone and a few
        // units in the last place either side, where the bound and the tree must agree.
        let segments = [
            (0, DVec3::new(-1.0, 0.0, 0.0), DVec3::new(1.0, 0.0, 0.0)),
            (1, DVec3::new(0.0, 50.0, 0.0), DVec3::new(0.0, 60.0, 0.0)),
        ];
        let floor = 0.04;
        let joint_bones = JointBones::new(&segments);
        let far = FarJoints::new(&segments, &joint_bones, 2, floor);
        let reach = FAR_BONE_RATIO * floor;
        let mut checked = 0;
        for x in [-1.5, -1.0, 0.0, 0.3, 1.0, 1.2] {
            for ulps in -4i64..=4 {
                let y = f64::from_bits((reach.to_bits() as i64 + ulps) as u64);
                for p in [DVec3::new(x, y, 0.0), DVec3::new(x, 0.0, -y)] {
                    for joints in [vec![0], vec![1], vec![0, 1]] {
                        assert_eq!(
                            far.any_far(p, joints.iter().copied()),
                            far.any_far_by_trees(p, joints.iter().copied()),
                            "{p} {joints:?}"
                        );
                        checked += 1;
                    }
                }
            }
        }
        assert_eq!(checked, 6 * 9 * 2 * 3);
        // The guard counts only the bones of joints that own skin: the tree of every
        // joint's bones does not bring a bone of another joint back, even at the vertex.
        let owning = FarJoints::new(&segments[..1], &joint_bones, 2, floor);
        let on_bone_1 = DVec3::new(0.0, 55.0, 0.0);
        assert_eq!(owning.joint_distance(on_bone_1, 1), f64::INFINITY);
        assert!(owning.any_far(on_bone_1, [1]));
        assert!(!far.any_far(on_bone_1, [1]));
    }

    /// A bone segment: its joint and ends.
    type Segment = (u32, DVec3, DVec3);

    /// The nearest seen bone by the tree is the scan's at every vertex of cesiumman and
    /// makehuman's body, of a tube around a chain folded up and down it (bones beside one
    /// another, many at one distance) and at points off the surfaces.
    #[test]
    fn nearest_seen_bones_by_the_tree_are_the_scans() {
        let folded: Vec<DVec3> = (0..40)
            .map(|k| DVec3::new(0.05 * (k / 10) as f64, 0.1 * (k % 10) as f64, 0.0))
            .collect();
        let (tube, _) = capsule_chain(&[DVec3::ZERO, DVec3::Y], &[], 0.3, 12, 20);
        let mut cases: Vec<(String, SurfaceMesh, Vec<Segment>)> =
            crate::fixtures::corpus::welded_humans()
                .into_iter()
                .map(|(file, mesh, skeleton)| (file.to_string(), mesh, bone_segments(&skeleton)))
                .collect();
        // Straight passes up and down, and the same bone repeated (equal distances).
        let mut passes: Vec<Segment> = folded
            .windows(2)
            .enumerate()
            .map(|(k, w)| (k as u32, w[0], w[1]))
            .collect();
        passes.extend((0..12).map(|k| (100 + k, DVec3::ZERO, DVec3::Y)));
        cases.push(("folded".into(), tube, passes));
        for (name, mesh, segments) in cases {
            let spheres = FaceSpheres::new(&mesh);
            let sight = SightLines::new(&mesh, &spheres);
            let tree = segment_tree(&segments);
            let offsets = [DVec3::ZERO, DVec3::new(0.3, -0.2, 0.1), DVec3::splat(-2.0)];
            for (v, &p) in mesh.positions.iter().enumerate() {
                for offset in offsets {
                    let q = p + offset;
                    assert_eq!(
                        nearest_seen_bone(&sight, &segments, &tree, q),
                        nearest_seen_bone_by_scan(&sight, &segments, q),
                        "{name}: vertex {v} + {offset}"
                    );
                }
            }
        }
    }

    #[test]
    fn weight_on_a_far_bone_goes_to_the_bones_near_the_vertex() {
        // A straight tube from y = 0 to y = 12 around the chain root (0) → 1 (y = 4) →
        // 2 (y = 8) → tip (y = 12), radius 0.5: every bone is seen from every vertex.
        let points: Vec<DVec3> = (0..4).map(|k| DVec3::Y * 4.0 * k as f64).collect();
        let (mesh, skeleton) = capsule_chain(&points, &[], 0.5, 12, 8);
        let decomposition = decompose(
            &mesh,
            &Topology::new(&mesh),
            &skeleton,
            &DecomposeParams::default(),
        )
        .expect("a tube decomposes");
        let surface = &decomposition.surface;
        let n = surface.vertex_count();
        // Vertices near the root: half on the root's bone, half on joint 2's bone (from
        // y = 8 to 12, at least 6 away where the root's bone is 0.5 away: far); every other
        // vertex on the joint of its nearest bone.
        let segments = bone_segments(&skeleton);
        let near_root = |v: usize| surface.positions[v].y < 2.0;
        let mut weights = SurfaceWeights {
            offsets: vec![0],
            ..SurfaceWeights::default()
        };
        for v in 0..n {
            if near_root(v) {
                weights.extend_row([(0, 0.5), (2, 0.5)]);
            } else {
                let nearest = nearest_bone(&segments, surface.positions[v]).expect("bones");
                weights.extend_row([(nearest, 1.0)]);
            }
        }
        let before = weights.clone();
        let changed = guard_far_bones(
            &decomposition,
            &skeleton,
            &JointBones::new(&segments),
            &mut weights,
        );
        assert_eq!(changed, (0..n).filter(|&v| near_root(v)).count());
        for v in 0..n {
            let row: Vec<(u32, f64)> = weights.row(v).collect();
            if near_root(v) {
                assert_eq!(row, vec![(0, 1.0)], "vertex {v}");
            } else {
                assert_eq!(row, before.row(v).collect::<Vec<_>>(), "vertex {v}");
            }
        }
    }
}
