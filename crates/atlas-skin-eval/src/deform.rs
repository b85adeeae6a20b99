//! Deformation error: how far a candidate's skinned mesh lies from the reference's when
//! the same skeleton pose drives both.

use atlas_skin_runtime::pose::{palette_from_world, world_from_rotations};
use atlas_skin_runtime::random_pose::random_rotations;
use atlas_skin_runtime::reference::{dual_quaternion_positions, linear_blend_positions};
use atlas_skin_runtime::{Clip, Rig, Skeleton, Trs, VertexWeights};
use glam::{Mat4, Vec3};
use serde::{Deserialize, Serialize};

/// Mean and largest per-vertex distance, in units of the rest bounding-box diagonal.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct DeformError {
    pub mean: f64,
    pub max: f64,
}

/// How the palette moves the vertices.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Skinning {
    /// Linear blend skinning ([`linear_blend_positions`]).
    Linear,
    /// Dual quaternion skinning, Kavan et al. 2007 ([`dual_quaternion_positions`]).
    DualQuaternion,
}

/// Skinning palettes of `count` seeded random poses: pose i rotates every joint about a
/// random axis by an angle uniform in [0, `max_angle`] radians, in its own local frame
/// after its rest rotation ([`random_rotations`] with seed `seed + i`,
/// [`world_from_rotations`]).
pub fn random_pose_palettes(
    skeleton: &Skeleton,
    count: usize,
    max_angle: f32,
    seed: u64,
) -> Vec<Vec<Mat4>> {
    let rest_local = skeleton.rest_local();
    let order = skeleton.topological_order();
    let mut world = vec![Mat4::IDENTITY; skeleton.len()];
    (0..count as u64)
        .map(|i| {
            let rotations = random_rotations(skeleton.len(), max_angle, seed.wrapping_add(i));
            world_from_rotations(skeleton, &rest_local, &order, &rotations, &mut world);
            let mut palette = vec![Mat4::IDENTITY; skeleton.len()];
            palette_from_world(&world, &skeleton.inverse_bind, &mut palette);
            palette
        })
        .collect()
}

/// Skinning palettes of `frames` times evenly spread over `clip`, at the middles of equal
/// intervals: `t_k = duration · (k + ½) / frames` (the convention that reproduces the
/// BASELINES.md *anim* figures; it never samples the same pose twice at both ends of a
/// looping clip):
/// `palette[j] = joint_world[j](t_k) · inverse_bind[j]`.
///
/// The joint world matrices include the rig's non-joint ancestors (e.g. a Z-up to Y-up
/// root), as a glTF renderer applies them; they move both skinned meshes alike, so
/// distances are unchanged as long as those ancestors are rigid.
pub fn animation_palettes(
    skeleton: &Skeleton,
    rig: &Rig,
    clip: &Clip,
    frames: usize,
) -> Vec<Vec<Mat4>> {
    let mut local = vec![Trs::IDENTITY; rig.rest.len()];
    let mut node_world = vec![Mat4::IDENTITY; rig.rest.len()];
    let mut joint_world = vec![Mat4::IDENTITY; skeleton.len()];
    (0..frames)
        .map(|k| {
            let time = clip.duration * (k as f32 + 0.5) / frames as f32;
            clip.sample(time, &rig.rest, &mut local);
            rig.world(&local, &mut node_world);
            rig.joint_world(&node_world, &mut joint_world);
            let mut palette = vec![Mat4::IDENTITY; skeleton.len()];
            palette_from_world(&joint_world, &skeleton.inverse_bind, &mut palette);
            palette
        })
        .collect()
}

/// The largest error of one vertex over all palettes, and the palette where it occurs.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VertexError {
    pub max: f64,
    pub palette: usize,
}

/// What [`deformation_error`] measures: the mean and largest error over all vertices and
/// palettes, and each vertex's largest error.
#[derive(Debug, Clone, PartialEq)]
pub struct PerVertexErrors {
    pub total: DeformError,
    /// #V entries, in the order of `rest`.
    pub vertices: Vec<VertexError>,
}

/// Deformation error of `candidate` against `reference` over `palettes`:
/// `e_vp = ‖S(reference, P_p)(v) − S(candidate, P_p)(v)‖ / diagonal` for every vertex v and
/// palette p, where S skins the rest mesh with the given weights; returns the mean and
/// the largest `e_vp` (zeros when there is no vertex or no palette), and per vertex its
/// largest `e_vp` with the palette where it occurs.
///
/// - `rest`: #V bind-space positions; `reference`, `candidate`: #V rows with joint indices
///   into every palette; `palettes`: #P palettes of #J matrices; `diagonal` > 0.
pub fn deformation_error(
    rest: &[Vec3],
    reference: &VertexWeights,
    candidate: &VertexWeights,
    palettes: &[Vec<Mat4>],
    skinning: Skinning,
    diagonal: f64,
) -> PerVertexErrors {
    let skin = match skinning {
        Skinning::Linear => linear_blend_positions,
        Skinning::DualQuaternion => dual_quaternion_positions,
    };
    let mut posed_ref = vec![Vec3::ZERO; rest.len()];
    let mut posed_cand = vec![Vec3::ZERO; rest.len()];
    let mut vertices = vec![
        VertexError {
            max: 0.0,
            palette: 0
        };
        rest.len()
    ];
    let (mut sum, mut max) = (0.0f64, 0.0f64);
    for (p, palette) in palettes.iter().enumerate() {
        skin(rest, reference, palette, &mut posed_ref);
        skin(rest, candidate, palette, &mut posed_cand);
        for ((a, b), vertex) in posed_ref.iter().zip(&posed_cand).zip(&mut vertices) {
            let e = a.as_dvec3().distance(b.as_dvec3()) / diagonal;
            sum += e;
            max = max.max(e);
            if e > vertex.max {
                *vertex = VertexError { max: e, palette: p };
            }
        }
    }
    let samples = rest.len() * palettes.len();
    PerVertexErrors {
        total: DeformError {
            mean: if samples > 0 {
                sum / samples as f64
            } else {
                0.0
            },
            max,
        },
        vertices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use approx::assert_relative_eq;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Quat;

    fn two_bone_chain() -> Skeleton {
        Skeleton::from_positions(
            vec!["root".into(), "tip".into()],
            vec![NO_PARENT, 0],
            &[Vec3::ZERO, Vec3::X],
        )
        .unwrap()
    }

    #[test]
    fn same_weights_give_zero_and_a_known_swap_gives_the_bend_distance() {
        let skeleton = two_bone_chain();
        let rest = [Vec3::new(2.0, 0.0, 0.0)];
        let on_tip = VertexWeights::from_rows([vec![(1, 1.0)]]);
        let on_root = VertexWeights::from_rows([vec![(0, 1.0)]]);
        // Bend the tip joint by 90° about Z: (2, 0, 0) moves to (1, 1, 0) with the tip and
        // stays with the root: distance √2.
        let mut world = vec![Mat4::IDENTITY; 2];
        let rotations = [
            Quat::IDENTITY,
            Quat::from_rotation_z(std::f32::consts::FRAC_PI_2),
        ];
        world_from_rotations(
            &skeleton,
            &skeleton.rest_local(),
            &skeleton.topological_order(),
            &rotations,
            &mut world,
        );
        let mut palette = vec![Mat4::IDENTITY; 2];
        palette_from_world(&world, &skeleton.inverse_bind, &mut palette);
        let palettes = [palette];
        for skinning in [Skinning::Linear, Skinning::DualQuaternion] {
            let same = deformation_error(&rest, &on_tip, &on_tip, &palettes, skinning, 2.0).total;
            assert_eq!(
                same,
                DeformError {
                    mean: 0.0,
                    max: 0.0
                }
            );
            let swapped =
                deformation_error(&rest, &on_tip, &on_root, &palettes, skinning, 2.0).total;
            assert_relative_eq!(swapped.max, 2f64.sqrt() / 2.0, epsilon = 1e-6);
            assert_relative_eq!(swapped.mean, swapped.max, epsilon = 1e-12);
        }
    }

    #[test]
    fn animation_frames_span_the_clip_and_rigid_ancestors_do_not_count() {
        use atlas_skin_runtime::{Interpolation, Property, Track};
        let skeleton = two_bone_chain();
        // Node 0 turns the whole figure (Z-up to Y-up), nodes 1 and 2 are the joints.
        let up = Trs {
            rotation: Quat::from_rotation_x(-std::f32::consts::FRAC_PI_2),
            ..Trs::IDENTITY
        };
        let tip = Trs {
            translation: Vec3::X,
            ..Trs::IDENTITY
        };
        let rig = Rig {
            names: vec!["up".into(), "root".into(), "tip".into()],
            parents: vec![u32::MAX, 0, 1],
            rest: vec![up, Trs::IDENTITY, tip],
            joint_nodes: vec![1, 2],
        };
        let quarter = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
        let clip = Clip {
            name: "bend".into(),
            duration: 2.0,
            tracks: vec![Track {
                node: 2,
                property: Property::Rotation,
                interpolation: Interpolation::Linear,
                times: vec![0.0, 2.0],
                values: [Quat::IDENTITY, quarter]
                    .iter()
                    .flat_map(|q| q.to_array())
                    .collect(),
            }],
        };
        let palettes = animation_palettes(&skeleton, &rig, &clip, 3);
        // Frames at t = 1/3, 1, 5/3: the tip bent by 15°, 45°, 75°; (2, 0, 0) on the tip
        // against on the root moves by 2 sin(θ/2).
        let rest = [Vec3::new(2.0, 0.0, 0.0)];
        let on_tip = VertexWeights::from_rows([vec![(1, 1.0)]]);
        let on_root = VertexWeights::from_rows([vec![(0, 1.0)]]);
        let e = deformation_error(&rest, &on_tip, &on_root, &palettes, Skinning::Linear, 1.0).total;
        let expected = [7.5f64, 22.5, 37.5].map(|half| 2.0 * half.to_radians().sin());
        assert_relative_eq!(e.max, expected[2], epsilon = 1e-5);
        assert_relative_eq!(e.mean, expected.iter().sum::<f64>() / 3.0, epsilon = 1e-5);
    }

    #[test]
    fn random_poses_are_seeded_and_move_the_joints() {
        let skeleton = two_bone_chain();
        let a = random_pose_palettes(&skeleton, 3, 1.0, 5);
        assert_eq!(a, random_pose_palettes(&skeleton, 3, 1.0, 5));
        assert_eq!(a[1], random_pose_palettes(&skeleton, 1, 1.0, 6)[0]);
        assert!(!a[0][1].abs_diff_eq(Mat4::IDENTITY, 1e-3));
    }
}
