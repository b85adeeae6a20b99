//! The skinning runtime an engine embeds.
//!
//! Data flows one way: a [`Skeleton`] (joint hierarchy and bind pose) and a pose (local joint
//! rotations) give world matrices, world × inverse bind gives the skinning palette, and the
//! palette with per-vertex [`VertexWeights`] deforms the rest mesh by linear blend skinning
//! or dual quaternion skinning (Kavan et al. 2007).

pub mod animation;
pub mod compact_skin;
pub mod dual_quaternion;
pub mod error;
pub mod forest;
pub mod instruction_set;
pub mod pose;
pub mod random_pose;
pub mod reference;
pub mod retarget;
pub mod rig;
pub mod sampling;
pub mod skeleton;
#[cfg(target_arch = "x86_64")]
mod skinning_avx2;
#[cfg(target_arch = "x86_64")]
mod skinning_avx512;
pub mod skinning_job;
pub mod skinning_palette;
pub mod vertex_order;
pub mod weights;

pub use animation::{Clip, Interpolation, Property, Rig, Track, Trs};
pub use compact_skin::{CompactSkin, WeightFormat};
pub use dual_quaternion::DualQuat;
pub use error::RuntimeError;
pub use instruction_set::InstructionSet;
pub use skeleton::{Skeleton, NO_PARENT};
pub use skinning_job::{SkinningJob, Threading};
pub use skinning_palette::{SkinningMethod, SkinningPalette};
pub use vertex_order::VertexOrder;
pub use weights::VertexWeights;
