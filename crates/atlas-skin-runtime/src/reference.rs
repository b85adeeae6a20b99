//! Plain scalar skinning: the reference every fast path is tested against.

use crate::dual_quaternion::DualQuat;
use crate::VertexWeights;
use glam::{Mat4, Vec3};

/// Linear blend skinning (Magnenat-Thalmann et al. 1988), one vertex at a time:
/// `p'_v = Σ_i ω_vi · palette[j_vi] · p_v` for the influences (j_vi, ω_vi) of vertex v.
///
/// - `rest`: #V bind-space positions; `weights`: #V rows; `palette`: #J matrices;
///   `out`: #V posed positions. Rows need not sum to 1: they are used as given.
pub fn linear_blend_positions(
    rest: &[Vec3],
    weights: &VertexWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) {
    for (v, (p, o)) in rest.iter().zip(out.iter_mut()).enumerate() {
        *o = blended_matrix(weights, v, palette).transform_point3(*p);
    }
}

/// Linear blend skinning of direction vectors (normals, tangents):
/// `n'_v = (Σ_i ω_vi · palette[j_vi])₃ₓ₃ · n_v`, the blended matrix's linear part, not
/// renormalised (as ozz-animation's SkinningJob; exact for normals while the palette has no
/// non-uniform scale).
///
/// - `rest`: #V bind-space vectors; the other arguments as [`linear_blend_positions`].
pub fn linear_blend_vectors(
    rest: &[Vec3],
    weights: &VertexWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) {
    for (v, (n, o)) in rest.iter().zip(out.iter_mut()).enumerate() {
        *o = blended_matrix(weights, v, palette).transform_vector3(*n);
    }
}

/// `Σ_i ω_vi · palette[j_vi]` for vertex v.
fn blended_matrix(weights: &VertexWeights, v: usize, palette: &[Mat4]) -> Mat4 {
    weights
        .row(v)
        .fold(Mat4::ZERO, |sum, (j, w)| sum + palette[j as usize] * w)
}

/// Dual quaternion skinning (Kavan et al. 2007, §4 "DLB"), one vertex at a time:
/// `b̂ = Σ_i ω_vi · s_vi · q̂[j_vi]`, `p'_v = (b̂ / ‖b̂‖)(p_v)`, where `q̂[j]` is the unit dual
/// quaternion of `palette[j]` and `s_vi = ±1` makes the real part of each term lie in the
/// hemisphere of the vertex's first influence (`s_vi = sign(real(q̂[j_vi]) · real(q̂[j_v0]))`,
/// the shortest-arc fix of §4.1: without it the blend of q and -q, the same rotation, can
/// vanish).
///
/// - `rest`: #V bind-space positions; `weights`: #V rows; `palette`: #J rigid matrices
///   (rotation and translation only: scale is not represented by a unit dual quaternion);
///   `out`: #V posed positions. A vertex without influences is mapped to the origin, as
///   in [`linear_blend_positions`].
pub fn dual_quaternion_positions(
    rest: &[Vec3],
    weights: &VertexWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) {
    let dual_quats = dual_quaternions(palette);
    for (v, (p, o)) in rest.iter().zip(out.iter_mut()).enumerate() {
        *o = match blended_dual_quaternion(weights, v, &dual_quats) {
            Some(b) => b.transform_point(*p),
            None => Vec3::ZERO,
        };
    }
}

/// Dual quaternion skinning of direction vectors: `n'_v = rotation(b̂ / ‖b̂‖) · n_v`, with
/// `b̂` as in [`dual_quaternion_positions`]. Unit vectors stay unit.
pub fn dual_quaternion_vectors(
    rest: &[Vec3],
    weights: &VertexWeights,
    palette: &[Mat4],
    out: &mut [Vec3],
) {
    let dual_quats = dual_quaternions(palette);
    for (v, (n, o)) in rest.iter().zip(out.iter_mut()).enumerate() {
        *o = match blended_dual_quaternion(weights, v, &dual_quats) {
            Some(b) => b.transform_vector(*n),
            None => Vec3::ZERO,
        };
    }
}

fn dual_quaternions(palette: &[Mat4]) -> Vec<DualQuat> {
    palette.iter().map(DualQuat::from_rigid).collect()
}

/// The normalised blend `b̂ / ‖b̂‖` of vertex v's influences with the sign fix, or `None`
/// when the vertex has no influence (or all weights are zero).
fn blended_dual_quaternion(
    weights: &VertexWeights,
    v: usize,
    dual_quats: &[DualQuat],
) -> Option<DualQuat> {
    let mut row = weights.row(v);
    let (first_joint, first_weight) = row.next()?;
    let first = dual_quats[first_joint as usize];
    let blend = row.fold(first.scaled(first_weight), |sum, (j, w)| {
        let q = dual_quats[j as usize];
        let sign = if q.real.dot(first.real) < 0.0 {
            -1.0
        } else {
            1.0
        };
        sum.add(&q.scaled(sign * w))
    });
    (blend.real.length_squared() > 0.0).then(|| blend.normalized())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Quat;

    fn rigid(axis: Vec3, angle: f32, t: Vec3) -> Mat4 {
        Mat4::from_rotation_translation(Quat::from_axis_angle(axis.normalize(), angle), t)
    }

    #[test]
    fn one_influence_is_the_rigid_transform_in_both_methods() {
        let palette = [
            rigid(Vec3::X, 0.4, Vec3::ZERO),
            rigid(Vec3::new(1.0, 1.0, 0.0), 2.0, Vec3::new(1.0, -2.0, 0.5)),
        ];
        let rest = [Vec3::new(0.5, 1.0, -2.0), Vec3::new(3.0, 0.0, 1.0)];
        let weights = VertexWeights::from_rows([vec![(1, 1.0)], vec![(1, 1.0)]]);
        let mut lbs = [Vec3::ZERO; 2];
        let mut dqs = [Vec3::ZERO; 2];
        linear_blend_positions(&rest, &weights, &palette, &mut lbs);
        dual_quaternion_positions(&rest, &weights, &palette, &mut dqs);
        for v in 0..2 {
            let expected = palette[1].transform_point3(rest[v]);
            assert!(lbs[v].abs_diff_eq(expected, 1e-5));
            assert!(dqs[v].abs_diff_eq(expected, 1e-5));
        }
    }

    #[test]
    fn antipodal_quaternions_blend_to_the_shared_rotation() {
        // q and -q are the same rotation; without the sign fix their equal blend vanishes.
        let m = rigid(Vec3::Z, 1.0, Vec3::new(0.0, 1.0, 0.0));
        let dq = DualQuat::from_rigid(&m);
        let flipped = DualQuat {
            real: -dq.real,
            dual: -dq.dual,
        };
        let weights = VertexWeights::from_rows([vec![(0, 0.5), (1, 0.5)]]);
        let blended = blended_dual_quaternion(&weights, 0, &[dq, flipped]).unwrap();
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert!(blended
            .transform_point(p)
            .abs_diff_eq(m.transform_point3(p), 1e-5));
    }

    #[test]
    fn dual_quaternion_blend_of_two_rotations_is_the_halfway_rotation() {
        // Joint 0 still, joint 1 rotated 90° about z through the origin: the even blend is
        // the 45° rotation (LBS would instead shrink the point towards the axis).
        let palette = [
            Mat4::IDENTITY,
            rigid(Vec3::Z, std::f32::consts::FRAC_PI_2, Vec3::ZERO),
        ];
        let weights = VertexWeights::from_rows([vec![(0, 0.5), (1, 0.5)]]);
        let rest = [Vec3::X];
        let mut dqs = [Vec3::ZERO];
        let mut lbs = [Vec3::ZERO];
        dual_quaternion_positions(&rest, &weights, &palette, &mut dqs);
        linear_blend_positions(&rest, &weights, &palette, &mut lbs);
        let half = std::f32::consts::FRAC_1_SQRT_2;
        assert!(dqs[0].abs_diff_eq(Vec3::new(half, half, 0.0), 1e-6));
        assert!(lbs[0].abs_diff_eq(Vec3::new(0.5, 0.5, 0.0), 1e-6));
        let mut normal = [Vec3::ZERO];
        dual_quaternion_vectors(&rest, &weights, &palette, &mut normal);
        assert!((normal[0].length() - 1.0).abs() < 1e-6);
    }
}
