//! Unit dual quaternions: the rigid transforms dual quaternion skinning blends
//! (Kavan, Collins, Žára, O'Sullivan 2007, "Skinning with dual quaternions", §3).

use glam::{Mat4, Quat, Vec3, Vec4};

/// A rigid transform as a unit dual quaternion `q̂ = real + ε·dual`.
///
/// For a rotation `r` followed by a translation `t`: `real = r`, `dual = ½ (t, 0) · r`;
/// then `t = 2 · dual · real*` (Kavan et al. 2007 §3, Eq. 3).
///
/// `repr(C)`: real then dual, eight contiguous floats (the SIMD skinning loop loads a
/// dual quaternion as one 256-bit vector).
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C)]
pub struct DualQuat {
    pub real: Quat,
    pub dual: Quat,
}

impl DualQuat {
    /// The dual quaternion of a rigid matrix (rotation and translation only). The rotation is
    /// read from the upper 3×3 block, which must be orthonormal (callers check rigidity
    /// once, at validation).
    pub fn from_rigid(m: &Mat4) -> Self {
        let real = Quat::from_mat4(m).normalize();
        let t = m.w_axis.truncate();
        let dual = Quat::from_xyzw(t.x, t.y, t.z, 0.0) * real * 0.5;
        Self { real, dual }
    }

    /// `self` scaled by `s` in both parts (a term of the blend `Σ w_i q̂_i`).
    pub fn scaled(&self, s: f32) -> Self {
        Self {
            real: self.real * s,
            dual: self.dual * s,
        }
    }

    /// Sum of both parts (accumulates the blend).
    pub fn add(&self, other: &Self) -> Self {
        Self {
            real: self.real + other.real,
            dual: self.dual + other.dual,
        }
    }

    /// Divides both parts by `|real|`, making a blended dual quaternion a unit one again
    /// (Kavan et al. 2007 §4, DLB: `q̂ / ‖q̂‖`). Only the real part's norm is divided out;
    /// the tiny non-orthogonality of `dual` to `real` left by blending does not affect
    /// [`DualQuat::transform_point`], which reads the translation as `2 (r₀ d − d₀ r + r × d)`.
    pub fn normalized(&self) -> Self {
        let inv = self.real.length_recip();
        self.scaled(inv)
    }

    /// Applies the rigid transform to a point: `R p + t` with
    /// `t = 2 (r₀ d⃗ − d₀ r⃗ + r⃗ × d⃗)` (vector part of `2 · dual · real*`).
    pub fn transform_point(&self, p: Vec3) -> Vec3 {
        self.real * p + self.translation()
    }

    /// Applies the rotation only (for normals and tangents).
    pub fn transform_vector(&self, v: Vec3) -> Vec3 {
        self.real * v
    }

    /// The rigid matrix of the unit dual quaternion `q̂ / ‖q̂‖` (for any non-zero blend
    /// `q̂`), without a square root: with `s = 2 / ‖real‖²`,
    /// `R = I + s·[[−(y²+z²), xy−wz, xz+wy], [xy+wz, −(x²+z²), yz−wx], [xz−wy, yz+wx, −(x²+y²)]]`
    /// and `t = s (r₀ d⃗ − d₀ r⃗ + r⃗ × d⃗)`: both parts scale by `1/‖q̂‖`, their products by
    /// `1/‖q̂‖²` (Kavan et al. 2007 §4, DLB followed by the conversion of §3).
    pub fn normalized_matrix(&self) -> Mat4 {
        let [x, y, z, w] = self.real.to_array();
        let s = 2.0 / self.real.length_squared();
        let (xs, ys, zs) = (x * s, y * s, z * s);
        let (xx, yy, zz) = (x * xs, y * ys, z * zs);
        let (xy, xz, yz) = (x * ys, x * zs, y * zs);
        let (wx, wy, wz) = (w * xs, w * ys, w * zs);
        let r = self.real.xyz();
        let d = self.dual.xyz();
        let t = s * (w * d - self.dual.w * r + r.cross(d));
        Mat4::from_cols(
            Vec4::new(1.0 - (yy + zz), xy + wz, xz - wy, 0.0),
            Vec4::new(xy - wz, 1.0 - (xx + zz), yz + wx, 0.0),
            Vec4::new(xz + wy, yz - wx, 1.0 - (xx + yy), 0.0),
            t.extend(1.0),
        )
    }

    /// The translation `t = 2 (r₀ d⃗ − d₀ r⃗ + r⃗ × d⃗)`.
    pub fn translation(&self) -> Vec3 {
        let r = self.real.xyz();
        let d = self.dual.xyz();
        2.0 * (self.real.w * d - self.dual.w * r + r.cross(d))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn round_trips_a_rigid_matrix() {
        let r = Quat::from_axis_angle(Vec3::new(1.0, 2.0, -0.5).normalize(), 2.3);
        let t = Vec3::new(0.3, -4.0, 2.5);
        let m = Mat4::from_rotation_translation(r, t);
        let dq = DualQuat::from_rigid(&m);
        assert!(dq.translation().abs_diff_eq(t, 1e-5));
        let p = Vec3::new(-1.0, 0.5, 3.0);
        assert!(dq
            .transform_point(p)
            .abs_diff_eq(m.transform_point3(p), 1e-5));
        let scaled = dq.scaled(3.0).normalized();
        assert!(scaled
            .transform_point(p)
            .abs_diff_eq(m.transform_point3(p), 1e-5));
    }
}
