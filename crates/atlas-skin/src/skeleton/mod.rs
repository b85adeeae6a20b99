//! What the method reads from the skeleton beyond the runtime's [`Skeleton`]
//! (`atlas_skin_runtime`): bone segments and nearest bones ([`bones`]).
//!
//! [`Skeleton`]: atlas_skin_runtime::Skeleton

pub mod bones;
