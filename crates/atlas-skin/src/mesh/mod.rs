//! The input surface and what is derived from it before the method runs: the triangle mesh
//! ([`SurfaceMesh`]), welding of coincident vertices ([`weld()`]), duplicate faces
//! ([`duplicate_faces`]), inside-out pieces ([`inside_out`]), edge and face adjacency
//! ([`Topology`]) with component and genus statistics ([`MeshStats`]), a spatial index of
//! the faces for nearest-surface and ray queries ([`FaceSpheres`]), the generalized
//! winding number ([`winding`]) and shortest distances along edges ([`edge_distance`]).

pub mod duplicate_faces;
pub mod edge_distance;
pub mod inside_out;
pub mod spatial_index;
pub mod surface;
pub mod topology;
pub mod union_find;
pub mod weld;
pub mod winding;

pub use spatial_index::{FaceSpheres, NearestPoint};
pub use surface::SurfaceMesh;
pub use topology::{MeshStats, Topology};
pub use weld::{weld, Welded};
