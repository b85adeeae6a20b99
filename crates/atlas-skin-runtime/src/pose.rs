//! Poses: local joint rotations applied on top of the rest pose, and the world matrices and
//! skinning palette they give.

use crate::Skeleton;
use glam::{Mat4, Quat};

/// World transform of every joint for a pose given as one local rotation per joint:
/// `world[j] = world[parent(j)] · rest_local[j] · R(rotations[j])` (roots: no parent term).
///
/// - `rest_local`: #J rest local transforms ([`Skeleton::rest_local`]).
/// - `order`: joints with parents first ([`Skeleton::topological_order`]).
/// - `rotations`: #J local rotations; the identity everywhere gives the bind pose.
/// - `world`: #J output matrices.
pub fn world_from_rotations(
    skeleton: &Skeleton,
    rest_local: &[Mat4],
    order: &[usize],
    rotations: &[Quat],
    world: &mut [Mat4],
) {
    debug_assert_eq!(rotations.len(), skeleton.len());
    debug_assert_eq!(world.len(), skeleton.len());
    for &j in order {
        let local = rest_local[j] * Mat4::from_quat(rotations[j]);
        world[j] = match skeleton.parent(j) {
            Some(p) => world[p] * local,
            None => local,
        };
    }
}

/// Skinning palette `palette[j] = world[j] · inverse_bind[j]`: takes a bind-space point to
/// its posed position if it moved rigidly with joint j.
pub fn palette_from_world(world: &[Mat4], inverse_bind: &[Mat4], palette: &mut [Mat4]) {
    debug_assert_eq!(world.len(), inverse_bind.len());
    for ((out, w), ib) in palette.iter_mut().zip(world).zip(inverse_bind) {
        *out = *w * *ib;
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::NO_PARENT;
    use glam::Vec3;

    #[test]
    fn identity_pose_gives_identity_palette() {
        let s = Skeleton::from_positions(
            vec!["a".into(), "b".into()],
            vec![NO_PARENT, 0],
            &[Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, 2.0, 1.0)],
        )
        .unwrap();
        let mut world = vec![Mat4::IDENTITY; 2];
        let mut palette = vec![Mat4::ZERO; 2];
        world_from_rotations(
            &s,
            &s.rest_local(),
            &s.topological_order(),
            &[Quat::IDENTITY; 2],
            &mut world,
        );
        palette_from_world(&world, &s.inverse_bind, &mut palette);
        for m in palette {
            assert!(m.abs_diff_eq(Mat4::IDENTITY, 1e-6));
        }
    }
}
