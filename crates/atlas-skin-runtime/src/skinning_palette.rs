//! The per-frame palette in the forms the skinning loops read.

use crate::dual_quaternion::DualQuat;
use crate::{CompactSkin, RuntimeError};
use glam::{Mat3, Mat4};

/// Largest accepted deviation of a palette matrix's linear part from a rotation,
/// `max |Mᵀ M − I|`, for dual quaternion skinning: covers f32 round-off of composed
/// hierarchies, rejects any real scale (1.001 already exceeds it).
pub const RIGID_TOLERANCE: f32 = 1e-3;

/// Which blend deforms the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum SkinningMethod {
    /// Linear blend skinning: blend the matrices, then transform.
    #[default]
    LinearBlend,
    /// Dual quaternion skinning (Kavan et al. 2007): blend unit dual quaternions with the
    /// sign fix, normalise, then transform. Needs a rigid palette.
    DualQuaternion,
}

/// A palette matrix on a cache line of its own: a 64-byte `Mat4` at a 64-byte boundary, so
/// that a 512-bit load of it (or two 256-bit loads) never straddles two lines.
#[derive(Debug, Clone, Copy, PartialEq)]
#[repr(C, align(64))]
struct CacheLineMat4(Mat4);

/// A skinning palette (`world[j] · inverse_bind[j]` per joint) prepared for a
/// [`crate::skinning_job::SkinningJob`]: sized once for #J joints, then refilled every
/// frame by [`SkinningPalette::update`] without allocating.
#[derive(Debug, Clone, PartialEq)]
pub struct SkinningPalette {
    matrices: Vec<CacheLineMat4>,
    dual_quaternions: Vec<DualQuat>,
    method: SkinningMethod,
}

impl SkinningPalette {
    /// A palette of `joint_count` identity transforms, ready for either method.
    pub fn new(joint_count: usize) -> Self {
        Self {
            matrices: vec![CacheLineMat4(Mat4::IDENTITY); joint_count],
            dual_quaternions: vec![DualQuat::from_rigid(&Mat4::IDENTITY); joint_count],
            method: SkinningMethod::DualQuaternion,
        }
    }

    /// Copies `palette` (#J matrices, the length given to [`SkinningPalette::new`]) and,
    /// for [`SkinningMethod::DualQuaternion`], converts each to a unit dual quaternion.
    ///
    /// Errors: [`RuntimeError::BufferSize`] for a wrong length,
    /// [`RuntimeError::NonFinitePalette`], and for dual quaternions
    /// [`RuntimeError::NonRigid`] when a matrix's linear part is not a rotation within
    /// [`RIGID_TOLERANCE`] (scale is rejected, not approximated: a unit dual quaternion
    /// cannot carry it); [`RuntimeError::ProjectivePalette`] when a bottom row is not
    /// (0, 0, 0, 1), for both methods.
    pub fn update(&mut self, palette: &[Mat4], method: SkinningMethod) -> Result<(), RuntimeError> {
        if palette.len() != self.matrices.len() {
            return Err(RuntimeError::BufferSize {
                what: format!(
                    "palette has {} matrices, the skinning palette was made for {}",
                    palette.len(),
                    self.matrices.len()
                ),
            });
        }
        for (joint, m) in palette.iter().enumerate() {
            if !m.is_finite() {
                return Err(RuntimeError::NonFinitePalette { joint });
            }
            if m.row(3) != glam::Vec4::W {
                return Err(RuntimeError::ProjectivePalette {
                    joint,
                    row: m.row(3).to_array(),
                });
            }
        }
        for (slot, m) in self.matrices.iter_mut().zip(palette) {
            slot.0 = *m;
        }
        self.method = method;
        if method == SkinningMethod::DualQuaternion {
            for (joint, (m, dq)) in palette.iter().zip(&mut self.dual_quaternions).enumerate() {
                check_rigid(joint, m)?;
                *dq = DualQuat::from_rigid(m);
            }
        }
        Ok(())
    }

    /// Number of joints.
    pub fn len(&self) -> usize {
        self.matrices.len()
    }

    /// True for a palette of no joint.
    pub fn is_empty(&self) -> bool {
        self.matrices.is_empty()
    }

    /// The method of the last [`SkinningPalette::update`].
    pub fn method(&self) -> SkinningMethod {
        self.method
    }

    /// #J matrices, each at a 64-byte boundary.
    pub fn matrices(&self) -> &[Mat4] {
        const _: () = assert!(std::mem::size_of::<CacheLineMat4>() == std::mem::size_of::<Mat4>());
        // SAFETY: `CacheLineMat4` is `repr(C)` around one `Mat4` and, as asserted, adds no
        // padding, so #J of them are #J consecutive `Mat4`s (whose alignment, 16, 64 meets).
        unsafe {
            std::slice::from_raw_parts(self.matrices.as_ptr().cast::<Mat4>(), self.matrices.len())
        }
    }

    /// #J unit dual quaternions (valid after an update for dual quaternion skinning).
    pub fn dual_quaternions(&self) -> &[DualQuat] {
        &self.dual_quaternions
    }

    /// Chooses the sign of each dual quaternion (`q̂` and `−q̂` are the same rigid
    /// transform) so that joints sharing a vertex of `skin` lie in one hemisphere: along
    /// [`CompactSkin::hemisphere_forest`], `q̂_b ← −q̂_b` when `real(q̂_a) · real(q̂_b) < 0`.
    /// O(#J); allocates nothing. Call after [`SkinningPalette::update`] for dual
    /// quaternions, with the skin of the job.
    ///
    /// Then the blend's sign fix (Kavan et al. 2007 §4.1: each influence turned into the
    /// hemisphere of the vertex's first) is the identity for every pair of the skin unless
    /// the pose closes a loop of pairs the other way, and the vector loops blend without
    /// it ([`SkinningPalette::hemispheres_agree`] decides per job). The result is the same
    /// either way: flipping every term's sign with the first's changes neither the
    /// normalised blend's rotation nor its translation.
    pub fn align_hemispheres(&mut self, skin: &CompactSkin) {
        for &(a, b) in skin.hemisphere_forest() {
            let (a, b) = (usize::from(a), usize::from(b));
            let reference = self.dual_quaternions[a].real;
            let q = &mut self.dual_quaternions[b];
            if q.real.dot(reference) < 0.0 {
                *q = q.scaled(-1.0);
            }
        }
    }

    /// True when every pair of joints sharing a vertex of `skin`
    /// ([`CompactSkin::pairs`]) has real parts with a positive dot product, so that
    /// blending without the sign fix gives the blend with it. O(pairs).
    pub fn hemispheres_agree(&self, skin: &CompactSkin) -> bool {
        let quaternions = &self.dual_quaternions;
        skin.joint_count() == quaternions.len()
            && skin.pairs().iter().all(|&(a, b)| {
                quaternions[usize::from(a)]
                    .real
                    .dot(quaternions[usize::from(b)].real)
                    > 0.0
            })
    }
}

/// Rejects a matrix whose linear part `L` has `max |Lᵀ L − I| > RIGID_TOLERANCE` or a
/// negative determinant (a reflection); the reported scale is the column length furthest
/// from 1.
fn check_rigid(joint: usize, m: &Mat4) -> Result<(), RuntimeError> {
    let linear = Mat3::from_mat4(*m);
    let gram = linear.transpose() * linear - Mat3::IDENTITY;
    let deviation = gram
        .to_cols_array()
        .iter()
        .fold(0.0f32, |a, &e| a.max(e.abs()));
    if deviation > RIGID_TOLERANCE || linear.determinant() < 0.0 {
        let lengths = [
            linear.x_axis.length(),
            linear.y_axis.length(),
            linear.z_axis.length(),
        ];
        let scale = lengths
            .into_iter()
            .max_by(|a, b| (a - 1.0).abs().total_cmp(&(b - 1.0).abs()))
            .unwrap_or(1.0);
        let scale = if linear.determinant() < 0.0 {
            -scale
        } else {
            scale
        };
        return Err(RuntimeError::NonRigid { joint, scale });
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::{Quat, Vec3};

    #[test]
    fn invalid_palettes_are_rejected() {
        let rigid = Mat4::from_rotation_translation(Quat::from_rotation_x(1.0), Vec3::ONE);
        let mut projective = rigid;
        projective.x_axis.w = 0.5;
        use RuntimeError::*;
        // Each case breaks one rule and is refused for that rule.
        type Case = (Vec<Mat4>, SkinningMethod, fn(&RuntimeError) -> bool);
        let cases: [Case; 5] = [
            (vec![rigid], SkinningMethod::LinearBlend, |e| {
                matches!(e, BufferSize { .. })
            }),
            (
                vec![rigid, Mat4::from_translation(Vec3::NAN)],
                SkinningMethod::LinearBlend,
                |e| matches!(e, NonFinitePalette { joint: 1 }),
            ),
            (vec![rigid, projective], SkinningMethod::LinearBlend, |e| {
                matches!(e, ProjectivePalette { joint: 1, .. })
            }),
            (
                vec![rigid, Mat4::from_scale(Vec3::splat(1.01))],
                SkinningMethod::DualQuaternion,
                |e| matches!(e, NonRigid { joint: 1, .. }),
            ),
            (
                vec![rigid, Mat4::from_scale(Vec3::new(-1.0, 1.0, 1.0))],
                SkinningMethod::DualQuaternion,
                |e| matches!(e, NonRigid { joint: 1, .. }),
            ),
        ];
        for (matrices, method, expected) in cases {
            let mut palette = SkinningPalette::new(2);
            match palette.update(&matrices, method) {
                Err(e) => assert!(
                    expected(&e),
                    "{matrices:?}: refused for another reason: {e:?}"
                ),
                Ok(()) => panic!("accepted {matrices:?}"),
            }
        }
        let mut palette = SkinningPalette::new(2);
        let scaled = [rigid, Mat4::from_scale(Vec3::splat(2.0))];
        assert!(palette.hemispheres_agree(
            &CompactSkin::new(&crate::VertexWeights::from_rows([vec![(0, 1.0)]]), 2, 1).unwrap()
        ));
        assert!(palette.update(&scaled, SkinningMethod::LinearBlend).is_ok());
        assert_eq!(
            palette.update(&scaled, SkinningMethod::DualQuaternion),
            Err(RuntimeError::NonRigid {
                joint: 1,
                scale: 2.0
            })
        );
    }
}

#[cfg(test)]
mod hemisphere_tests {
    use super::*;
    use crate::VertexWeights;
    use glam::{Quat, Vec3};

    /// Joints 0–1, 1–2 and 0–2 share vertices: aligning along the forest makes the chain
    /// agree for small turns; three quarter turns about one axis (0°, 120°, 240°) cannot
    /// all agree (the loop of pairs closes the other way).
    #[test]
    fn alignment_makes_pairs_agree_unless_a_loop_closes_the_other_way() {
        let weights = VertexWeights::from_rows([
            vec![(0, 0.6), (1, 0.4)],
            vec![(1, 0.6), (2, 0.4)],
            vec![(2, 0.6), (0, 0.4)],
        ]);
        let skin = CompactSkin::new(&weights, 3, 2).unwrap();
        let turn = |degrees: f32| Mat4::from_quat(Quat::from_rotation_z(degrees.to_radians()));
        let mut palette = SkinningPalette::new(3);
        // Signs as converted: glam may give either hemisphere; flip one on purpose.
        palette
            .update(
                &[turn(0.0), turn(30.0), turn(60.0)],
                SkinningMethod::DualQuaternion,
            )
            .unwrap();
        palette.dual_quaternions[1] = palette.dual_quaternions[1].scaled(-1.0);
        assert!(!palette.hemispheres_agree(&skin));
        palette.align_hemispheres(&skin);
        assert!(palette.hemispheres_agree(&skin));
        let p = Vec3::new(1.0, 2.0, 3.0);
        assert!(palette.dual_quaternions[1]
            .transform_point(p)
            .abs_diff_eq(turn(30.0).transform_point3(p), 1e-5));
        palette
            .update(
                &[turn(0.0), turn(120.0), turn(240.0)],
                SkinningMethod::DualQuaternion,
            )
            .unwrap();
        palette.align_hemispheres(&skin);
        assert!(!palette.hemispheres_agree(&skin));
    }
}
