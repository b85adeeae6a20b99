//! The bone axis of a rig's bind frames: the local axis along which its joints' frames run
//! toward their children, when the rig has one.
//!
//! A skeleton gives a leaf joint a position but no bone (glTF and FBX have no tails), so
//! the method guesses its direction: the parent's bone continued. Rigs made in Blender
//! (bones along their local +Y), Maya (+X) and most others orient every joint's frame along
//! its bone, leaves included, so their bind frames carry the leaf's real direction: a toe
//! pointing forward off a foot bone that points down, a jaw pointing forward and down off
//! a head bone that points up. Rigs whose frames are the world's (RigNet's, every TGF, BVH
//! and MakeHuman skeleton) carry none.
//!
//! With R_j the linear part of joint j's bind transform (`inverse_bind[j]⁻¹`), its column
//! k normalised (scale removed) the local axis e_k in bind space, and d_j = (p_c − p_j) /
//! |p_c − p_j| the direction to its child c for the joints with exactly one child at
//! another point: a signed axis s e_k *runs along* j's bone when s (R_j e_k)ˆ · d_j ≥
//! [`ALONG_COSINE`]. The rig's bone axis is the signed axis that runs along the most of
//! these bones, kept when it runs along at least [`RIG_SHARE`] of them and the bones it
//! runs along do not all point one way (one of them more than 60° from the first): frames
//! equal to the world's match a world direction only, which one way of pointing would
//! make look like a bone axis (a rig whose chains all hang down).
//!
//! On the benchmark the 4 KayKit characters (Blender, +Y along 14 of their 16 one-child
//! joints), RobotExpressive (23 of 23), CesiumMan and RiggedFigure (10 of 12) have one; no
//! RigNet character does (their frames are the world's). docs/measurements.md, "Leaf bones
//! from the bind frames", has what it changes.

use atlas_skin_runtime::Skeleton;
use glam::{DMat4, DVec3};

/// A signed axis runs along a bone when it is within about 11.5° of it (cos ≥ 0.98):
/// exporters write frames to single precision, and a bone's roll leaves its axis along it.
pub const ALONG_COSINE: f64 = 0.98;

/// The share of the one-child joints a signed axis must run along to be the rig's bone
/// axis. A joint whose child does not sit at its bone's tail (a Blender bone not connected
/// to its child) is not run along; three in four is the rule, not the exception.
pub const RIG_SHARE: f64 = 0.75;

/// The bones a bone axis runs along must not all lie within 60° of one direction.
const SPREAD_COSINE: f64 = 0.5;

/// A signed local axis of the joints' bind frames: `sign` × e_`axis`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BoneAxis {
    /// 0, 1 or 2: x, y or z of each joint's local frame.
    pub axis: usize,
    /// +1 or −1.
    pub sign: f64,
}

impl BoneAxis {
    /// The unit direction in bind space of this axis of `joint`'s bind frame:
    /// sign × (R_j e_axis) / |R_j e_axis|. `None` when it is not finite (a degenerate
    /// frame; validated skeletons have none).
    pub fn direction(&self, skeleton: &Skeleton, joint: usize) -> Option<DVec3> {
        self.in_frame(&bind_frame(skeleton, joint))
    }

    /// This axis of the bind transform `bind`, unit length.
    fn in_frame(&self, bind: &DMat4) -> Option<DVec3> {
        (self.sign * bind.col(self.axis).truncate())
            .try_normalize()
            .filter(|d| d.is_finite())
    }

    /// Names it as `+x`, `-y`, ...
    pub fn name(&self) -> String {
        let sign = if self.sign > 0.0 { '+' } else { '-' };
        format!("{sign}{}", ['x', 'y', 'z'][self.axis])
    }
}

/// The bind transform of `joint`: `inverse_bind[joint]⁻¹`.
fn bind_frame(skeleton: &Skeleton, joint: usize) -> DMat4 {
    skeleton.inverse_bind[joint].as_dmat4().inverse()
}

/// The rig's bone axis (module documentation), `None` when its frames have none.
/// `positions`: #J bind positions of `skeleton`'s joints; `children`: its
/// [`Skeleton::children`]. O(J).
pub fn infer_bone_axis(
    skeleton: &Skeleton,
    positions: &[DVec3],
    children: &[Vec<usize>],
) -> Option<BoneAxis> {
    let candidates: Vec<BoneAxis> = (0..3)
        .flat_map(|axis| [1.0, -1.0].map(|sign| BoneAxis { axis, sign }))
        .collect();
    // Per signed axis: how many bones it runs along, and whether they spread.
    let mut along = [0usize; 6];
    let mut first: [Option<DVec3>; 6] = [None; 6];
    let mut spread = [false; 6];
    let mut bones = 0;
    for (j, kids) in children.iter().enumerate() {
        let [child] = kids[..] else {
            continue;
        };
        let Some(bone) = (positions[child] - positions[j]).try_normalize() else {
            continue;
        };
        bones += 1;
        let bind = bind_frame(skeleton, j);
        for (c, candidate) in candidates.iter().enumerate() {
            let runs_along = candidate
                .in_frame(&bind)
                .is_some_and(|d| d.dot(bone) >= ALONG_COSINE);
            if !runs_along {
                continue;
            }
            along[c] += 1;
            match first[c] {
                None => first[c] = Some(bone),
                Some(f) => spread[c] |= f.dot(bone) < SPREAD_COSINE,
            }
        }
    }
    // The first of equal counts wins (x before y before z, + before −).
    let best = (0..6).rev().max_by_key(|&c| along[c])?;
    (spread[best] && along[best] as f64 >= RIG_SHARE * bones as f64).then_some(candidates[best])
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::{DQuat, Mat4, Quat, Vec3};

    /// A skeleton of `positions` and `parents` whose joint j has the bind frame of
    /// rotation `rotations[j]` at its position.
    fn framed(positions: &[Vec3], parents: &[u32], rotations: &[Quat]) -> Skeleton {
        let names = (0..positions.len()).map(|j| format!("j{j}")).collect();
        let inverse_bind = positions
            .iter()
            .zip(rotations)
            .map(|(&p, &q)| Mat4::from_rotation_translation(q, p).inverse())
            .collect();
        Skeleton::new(names, parents.to_vec(), inverse_bind).unwrap()
    }

    /// A stick figure: hips (0) with a spine (1) and a head leaf (2) above it, two legs
    /// (3–4, 5–6) down to foot leaves, two arms (7–8, 9–10) from the spine out to hand
    /// leaves.
    fn stick_figure() -> (Vec<Vec3>, Vec<u32>) {
        let positions = vec![
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.0, 1.5, 0.0),
            Vec3::new(0.0, 1.8, 0.0),
            Vec3::new(0.1, 0.9, 0.0),
            Vec3::new(0.1, 0.5, 0.0),
            Vec3::new(-0.1, 0.9, 0.0),
            Vec3::new(-0.1, 0.5, 0.0),
            Vec3::new(0.2, 1.4, 0.0),
            Vec3::new(0.5, 1.4, 0.0),
            Vec3::new(-0.2, 1.4, 0.0),
            Vec3::new(-0.5, 1.4, 0.0),
        ];
        let parents = vec![NO_PARENT, 0, 1, 0, 3, 0, 5, 1, 7, 1, 9];
        (positions, parents)
    }

    /// Frames whose `local` axis points along `direction[j]` (any roll).
    fn along(local: Vec3, directions: &[Vec3]) -> Vec<Quat> {
        directions
            .iter()
            .map(|d| Quat::from_rotation_arc(local, d.normalize()))
            .collect()
    }

    /// Each joint's direction toward its only child, and for the others (leaves, the
    /// hips) `leaf`.
    fn bone_directions(positions: &[Vec3], parents: &[u32], leaf: Vec3) -> Vec<Vec3> {
        (0..positions.len())
            .map(|j| {
                let kids: Vec<usize> = (0..parents.len())
                    .filter(|&c| parents[c] == j as u32)
                    .collect();
                match kids[..] {
                    [c] => positions[c] - positions[j],
                    _ => leaf,
                }
            })
            .collect()
    }

    fn infer(skeleton: &Skeleton) -> Option<BoneAxis> {
        let positions: Vec<DVec3> = skeleton
            .bind_positions()
            .iter()
            .map(|p| p.as_dvec3())
            .collect();
        infer_bone_axis(skeleton, &positions, &skeleton.children())
    }

    #[test]
    fn frames_along_their_bones_give_the_axis_and_each_leafs_direction() {
        let (positions, parents) = stick_figure();
        // Leaves point forward (+z), off their parents' bones.
        let directions = bone_directions(&positions, &parents, Vec3::Z);
        for (local, expected) in [
            (Vec3::Y, BoneAxis { axis: 1, sign: 1.0 }),
            (Vec3::X, BoneAxis { axis: 0, sign: 1.0 }),
            (
                Vec3::NEG_Z,
                BoneAxis {
                    axis: 2,
                    sign: -1.0,
                },
            ),
        ] {
            let skeleton = framed(&positions, &parents, &along(local, &directions));
            let axis = infer(&skeleton).expect("frames along their bones");
            assert_eq!(axis, expected);
            for leaf in [2, 4, 6, 8, 10] {
                let d = axis.direction(&skeleton, leaf).unwrap();
                assert!(d.abs_diff_eq(DVec3::Z, 1e-6), "{leaf}: {d}");
            }
        }
        assert_eq!(
            BoneAxis {
                axis: 2,
                sign: -1.0
            }
            .name(),
            "-z"
        );
    }

    #[test]
    fn world_frames_have_no_axis() {
        let (positions, parents) = stick_figure();
        let identity = vec![Quat::IDENTITY; positions.len()];
        assert_eq!(infer(&framed(&positions, &parents, &identity)), None);
        // Every chain hanging down: −y runs along all of them, but frames equal to the
        // world's only say which way is down.
        let hanging = [
            Vec3::new(0.0, 2.0, 0.0),
            Vec3::new(0.0, 1.5, 0.0),
            Vec3::new(0.0, 1.0, 0.0),
            Vec3::new(0.3, 1.5, 0.0),
            Vec3::new(0.3, 1.0, 0.0),
        ];
        let parents = [NO_PARENT, 0, 1, 0, 3];
        let skeleton = framed(&hanging, &parents, &[Quat::IDENTITY; 5]);
        assert_eq!(infer(&skeleton), None);
    }

    #[test]
    fn an_axis_needs_three_in_four_of_the_bones() {
        let (positions, parents) = stick_figure();
        let directions = bone_directions(&positions, &parents, Vec3::Z);
        // The one-child joints: 3, 5 (thighs), 7, 9 (upper arms); the spine carries the
        // head and the arms.
        let one_child = [3, 5, 7, 9];
        for turned in 0..=3 {
            let mut rotations = along(Vec3::Y, &directions);
            for &j in &one_child[..turned] {
                // Turned 45° about its local x: no axis within 45° of its bone.
                rotations[j] *= Quat::from_rotation_x(std::f32::consts::FRAC_PI_4);
            }
            let found = infer(&framed(&positions, &parents, &rotations));
            let share = (4 - turned) as f64 / 4.0;
            assert_eq!(found.is_some(), share >= RIG_SHARE, "{turned} turned");
        }
    }

    /// A bind frame with scale: the direction is the axis's, unit length.
    #[test]
    fn a_scaled_frame_gives_a_unit_direction() {
        let q = DQuat::from_rotation_x(0.7);
        let bind = glam::DMat4::from_scale_rotation_translation(
            glam::DVec3::new(2.0, 3.0, 0.5),
            q,
            glam::DVec3::new(1.0, 2.0, 3.0),
        );
        let skeleton = Skeleton::new(
            vec!["a".into()],
            vec![NO_PARENT],
            vec![bind.inverse().as_mat4()],
        )
        .unwrap();
        let d = BoneAxis { axis: 1, sign: 1.0 }
            .direction(&skeleton, 0)
            .unwrap();
        assert!(d.abs_diff_eq(q * DVec3::Y, 1e-6), "{d}");
    }
}
