//! Atlas-based character skinning with automatic mesh decomposition
//! (Lu, Hétroy, Gérot, Thibert, INRIA RR-6406, 2008).
//!
//! The pipeline, one module per stage:
//! mesh analysis ([`weld`](mod@weld), [`topology`], [`winding`]) → cuts at joints (§3.1) →
//! regions (§3.2) → surface distances and overlaps (§3.3) → weights (§4, §5).

pub mod blend;
pub mod cut;
pub mod decompose;
pub mod decomposition;
pub mod decomposition_report;
pub mod demo;
pub mod eval;
pub mod geodesic;
pub mod joint_roles;
pub mod mesh;
pub mod nearest_bone;
pub mod overlap;
pub mod ownership;
pub mod patches;
pub mod pipeline;
pub mod plane_section;
pub mod proximity;
pub mod segment;
pub mod shapes;
pub mod split;
pub mod topology;
pub mod weights;
pub mod weld;
pub mod winding;

pub use decompose::{decompose, DecomposeError, DecomposeParams};
pub use decomposition::{
    Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, Region,
};
pub use mesh::SurfaceMesh;
pub use topology::{MeshStats, Topology};
pub use weld::{weld, Welded};
