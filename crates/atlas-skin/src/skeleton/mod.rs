//! What the method reads from the skeleton beyond the runtime's [`Skeleton`]
//! (`atlas_skin_runtime`): ancestors and lowest common ancestors ([`ancestry`]), bone
//! segments and nearest bones ([`bones`], [`bone_tree`]), a hierarchy for
//! skeletons with several roots ([`hierarchy`]), joints named as helpers that deform nothing
//! ([`helpers`]), the nearest joint ([`nearest_point`]), whether the skeleton sits in the mesh
//! ([`placement`]).
//!
//! [`Skeleton`]: atlas_skin_runtime::Skeleton

pub mod ancestry;
pub mod bone_tree;
pub mod bones;
pub mod helpers;
pub mod hierarchy;
pub mod nearest_point;
pub mod placement;
