//! Atlas-based character skinning with automatic mesh decomposition
//! (Lu, Hétroy, Gérot, Thibert, INRIA RR-6406, 2008).
//!
//! The pipeline ([`pipeline::skin`]), one folder per stage, in order; each module imports
//! only the modules of the rows above its own (checked by `tests/module_cycles.rs`):
//!
//! | stage | paper | module |
//! | --- | --- | --- |
//! | what every stage shares: tolerances, boxes and segments, rows of a flat table, the developer switches that turn rules off | | [`tolerance`], [`geometry`], [`rows`], [`ablation`] |
//! | the surface: welding, topology, spatial index, winding number | | [`mesh`] |
//! | bones as segments, nearest bones, helper joints, whether the skeleton sits in the mesh | | [`skeleton`] |
//! | boundaries at the joints: joint roles, plane search, plane sections, conflicts, split | §3.1 | [`cuts`] |
//! | the decomposition's result as plain data: boundaries, regions, one decision per joint | §3.1–3.2 | [`decomposition`] |
//! | regions of the split surface, the joints bound to them | §3.2 | [`regions`] |
//! | the decomposition driver: §3.1, then §3.2 | §3.1–3.2 | [`decompose()`] |
//! | overlaps: surface distances from each cut, widths | §3.3 | [`overlap`] |
//! | weights: blending, chains, soft boundaries, pieces, rigid binding | §4, §5 | [`weights`] |
//! | what the report shows of a decomposition, and its warnings | | [`report`] |
//! | the whole method: weld, the stages, un-weld, timings | | [`pipeline`] |
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
pub mod weights;

pub use decompose::{decompose, DecomposeError, DecomposeParams};
pub use decomposition::{
    Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, Region,
};
pub use mesh::{weld, MeshStats, SurfaceMesh, Topology, Welded};
pub use pipeline::{skin, SkinError, SkinInput, SkinParams, Skinned};
