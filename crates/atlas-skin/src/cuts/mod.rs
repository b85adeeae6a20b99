//! Boundaries at the joints (Lu et al. 2008 §3.1): which joints get one
//! ([`joint_roles`], with [`leaf_reach`] for its leaves; joints too close to the boundary above them merged for cutting:
//! [`merged_joints`]), the plane search through each ([`plane_search`]) over the closed
//! sections of the surface by a plane ([`plane_section`]), the conflict rule between cuts
//! ([`conflicts`]) and the split of the surface along the kept curves ([`split`]).
//!
//! Inputs: the welded surface and its topology, the skeleton in bind space,
//! [`DecomposeParams`]. Output: per joint a placed cut, a soft boundary or a reason to
//! skip it; the split surface. [`crate::decompose()`] runs these steps and then grows the
//! regions (§3.2, [`crate::regions`]).

pub mod conflicts;
pub mod joint_roles;
pub mod leaf_reach;
pub mod merged_joints;
pub mod params;
pub mod plane_search;
pub mod plane_section;
pub mod split;

pub use params::{DecomposeError, DecomposeParams};
