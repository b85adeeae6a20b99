//! Animation data: keyframe tracks on the nodes of a rig (glTF's animation model; BVH
//! motion is converted to it).

use glam::{Mat4, Quat, Vec3};

/// Sentinel parent index of a root node.
pub const NO_PARENT_NODE: u32 = u32::MAX;

/// A local transform: translation, rotation, scale (applied scale first).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Trs {
    pub translation: Vec3,
    pub rotation: Quat,
    pub scale: Vec3,
}

impl Default for Trs {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Trs {
    pub const IDENTITY: Self = Self {
        translation: Vec3::ZERO,
        rotation: Quat::IDENTITY,
        scale: Vec3::ONE,
    };

    /// The matrix T · R · S.
    pub fn matrix(&self) -> Mat4 {
        Mat4::from_scale_rotation_translation(self.scale, self.rotation, self.translation)
    }
}

/// The node hierarchy animations drive: all nodes of a glTF scene (joints and their
/// non-joint ancestors), or just the joints for other inputs.
///
/// - `parents`: #N parent node indices, [`NO_PARENT_NODE`] for roots.
/// - `rest`: #N local transforms when no animation plays.
/// - `names`: #N node names.
/// - `joint_nodes`: #J node index of every skeleton joint.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Rig {
    pub names: Vec<String>,
    pub parents: Vec<u32>,
    pub rest: Vec<Trs>,
    pub joint_nodes: Vec<u32>,
}

/// Which part of a node's local transform a track animates.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Property {
    Translation,
    Rotation,
    Scale,
}

/// How values between keys are found (glTF `sampler.interpolation`).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Interpolation {
    Step,
    Linear,
    CubicSpline,
}

/// Keyframes of one property of one node.
///
/// - `times`: #K ascending key times in seconds.
/// - `values`: #K × C floats (C = 3 for translation and scale, 4 for a rotation quaternion
///   x, y, z, w); for [`Interpolation::CubicSpline`], #K × 3 × C: in-tangent, value,
///   out-tangent per key, as glTF stores them.
#[derive(Debug, Clone, PartialEq)]
pub struct Track {
    pub node: u32,
    pub property: Property,
    pub interpolation: Interpolation,
    pub times: Vec<f32>,
    pub values: Vec<f32>,
}

/// A named animation: tracks over the nodes of a [`Rig`].
#[derive(Debug, Clone, PartialEq)]
pub struct Clip {
    pub name: String,
    /// Last key time of any track, seconds.
    pub duration: f32,
    pub tracks: Vec<Track>,
}
