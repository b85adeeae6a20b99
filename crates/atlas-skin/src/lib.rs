//! Atlas-based character skinning with automatic mesh decomposition
//! (Lu, Hétroy, Gérot, Thibert, INRIA RR-6406, 2008).
//!
//! The pipeline, one module per stage:
//! mesh analysis ([`weld`], [`topology`], [`winding`]) → cuts at joints (§3.1) →
//! regions (§3.2) → surface distances and overlaps (§3.3) → weights (§4, §5).

pub mod decomposition;
pub mod mesh;
pub mod topology;
pub mod weld;
pub mod winding;

pub use decomposition::{Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, Region};
pub use mesh::SurfaceMesh;
pub use topology::{MeshStats, Topology};
pub use weld::{weld, Welded};
