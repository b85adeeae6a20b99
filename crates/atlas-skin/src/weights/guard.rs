//! Step 5 of the weights: the guard against gross misassignment (issue 13). A region, a
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
use crate::geometry::segment_parameter;
use crate::mesh::FaceSpheres;
use crate::rows::{Rows, PAR_CHUNK};
use crate::skeleton::bone_tree::{BoneTree, Keys, Split};
use crate::skeleton::bones::bone_segments;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;

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
pub fn guard_far_bones(
    decomposition: &Decomposition,
    skeleton: &Skeleton,
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
    // All the segments in one tree for the nearest, and keyed by joint for each joint's
    // nearest (a descent each, instead of a scan of every bone, or of the hundreds of child
    // bones of one joint, per vertex).
    let bone_tree =
        BoneTree::of_segments(&segments.iter().map(|&(_, a, b)| [a, b]).collect::<Vec<_>>());
    let joint_tree = BoneTree::new(segments.iter().copied(), Split::Keys);
    let joint_distance = |p: DVec3, joint: u32| {
        joint_tree.nearest_distance(p, Keys::Inside(joint, joint + 1), |_, _| true)
    };
    // Vertices with a joint that is far even from the nearest bone by straight line: only
    // they need the line-of-sight test.
    let suspects: Vec<usize> = (0..weights.vertex_count())
        .filter(|&v| {
            let p = surface.positions[v];
            let nearest = bone_tree.nearest(p);
            let limit = FAR_BONE_RATIO * nearest.max(floor);
            weights.row(v).any(|(j, _)| joint_distance(p, j) > limit)
        })
        .collect();
    if suspects.is_empty() {
        return 0;
    }
    let spheres = FaceSpheres::new(surface);
    let mut changed = 0;
    let replaced: Rows<(u32, f64)> = Rows::par_build(
        suspects.len(),
        PAR_CHUNK,
        |k, _: &mut (), out: &mut Vec<(u32, f64)>| {
            let v = suspects[k];
            let p = surface.positions[v];
            let Some((near_joint, near)) = nearest_seen_bone(surface, &spheres, &segments, p)
            else {
                out.extend(weights.row(v));
                return;
            };
            let limit = FAR_BONE_RATIO * near.max(floor);
            let kept: Vec<(u32, f64)> = weights
                .row(v)
                .filter(|&(j, _)| joint_distance(p, j) <= limit)
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

/// The joint and distance of the nearest bone segment whose nearest point to `p` is seen
/// from `p` through the body (no face hit before it), among the [`SIGHT_TRIES`] nearest;
/// the nearest of all when none of them is seen (a vertex on a thin shell).
fn nearest_seen_bone(
    surface: &crate::mesh::SurfaceMesh,
    spheres: &FaceSpheres,
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
    let first = by_distance.first().map(|&(d, j, _)| (j, d))?;
    let step = 1e-6 * surface.diagonal();
    for &(d, j, q) in by_distance.iter().take(SIGHT_TRIES) {
        if d <= step {
            return Some((j, d));
        }
        let direction = (q - p) / d;
        let blocked = spheres.hit_before(surface, p + direction * step, direction, d - 2.0 * step);
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
    use crate::mesh::Topology;
    use crate::skeleton::bones::nearest_bone;

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
        let changed = guard_far_bones(&decomposition, &skeleton, &mut weights);
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
