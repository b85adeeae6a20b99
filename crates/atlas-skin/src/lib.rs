//! Atlas-based character skinning with automatic mesh decomposition
//! (Lu, Hétroy, Gérot, Thibert, INRIA RR-6406, 2008).
//!
//! The pipeline ([`pipeline::skin`]), one folder per stage, in order:
//!
//! | stage | paper | module |
//! | --- | --- | --- |
//! | the surface: welding, topology, spatial index, winding number | | [`mesh`] |
//! | bones as segments, nearest bones | | [`skeleton`] |
//! | boundaries at the joints: joint roles, plane search, plane sections, conflicts, split | §3.1 | [`cuts`] |
//! | regions of the split surface, the joints bound to them | §3.2 | [`regions`] |
//! | the decomposition driver (§3.1 then §3.2) and its result | §3.1–3.2 | [`decompose()`], [`decomposition`] |
//! | overlaps: surface distances from each cut, widths | §3.3 | [`overlap`] |
//! | weights: blending, chains, soft boundaries | §4, §5 | [`weights`] |
//! | what the report shows of a decomposition | | [`report`] |
//! | weights carried from a skinned surface onto other meshes (Abdrashitov et al. 2023) | | [`transfer`] |
//! | shapes with known answers and the demo character | | [`fixtures`] |

pub mod ablation;
pub mod cuts;
pub mod decompose;
pub mod decomposition;
pub mod fixtures;
pub mod geometry;
pub mod mesh;
pub mod overlap;
pub mod pipeline;
pub mod regions;
pub mod report;
pub mod rows;
pub mod skeleton;
pub mod tolerance;
pub mod transfer;
pub mod weights;

pub use decompose::{decompose, DecomposeError, DecomposeParams};
pub use decomposition::{
    Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, Region,
};
pub use mesh::{weld, MeshStats, SurfaceMesh, Topology, Welded};
pub use pipeline::{skin, SkinError, SkinInput, SkinParams, Skinned};
