//! The skinning runtime an engine embeds.
//!
//! Data flows one way: a [`Skeleton`] (joint hierarchy and bind pose) and a pose (local joint
//! rotations) give world matrices, world × inverse bind gives the skinning palette, and the
//! palette with per-vertex [`VertexWeights`] deforms the rest mesh by linear blend skinning
//! or dual quaternion skinning (Kavan et al. 2007).

pub mod animation;
pub mod error;
pub mod pose;
pub mod random_pose;
pub mod reference;
pub mod skeleton;
pub mod weights;

pub use animation::{Clip, Interpolation, Property, Rig, Track, Trs};
pub use error::RuntimeError;
pub use skeleton::{Skeleton, NO_PARENT};
pub use weights::VertexWeights;
