//! Plain scalar skinning: the reference every fast path is tested against.

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
        let mut sum = Vec3::ZERO;
        for (j, w) in weights.row(v) {
            sum += w * palette[j as usize].transform_point3(*p);
        }
        *o = sum;
    }
}
