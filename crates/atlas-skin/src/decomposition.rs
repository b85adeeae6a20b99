//! The result of the decomposition stages (§3.1 cuts, §3.2 regions): what the weights stage
//! (§3.3–§5) reads. Plain data; [`crate::decompose()`] builds it.

use crate::cuts::merged_joints::MergedJoint;
use crate::mesh::{FaceSpheres, SurfaceMesh, Topology};
use glam::DVec3;
use serde::Serialize;
use std::sync::OnceLock;

/// The surface split along the cut curves, its regions and the boundaries between them.
#[derive(Debug, Clone)]
pub struct Decomposition {
    /// The welded surface with every cut curve inserted as a chain of edges. Vertices
    /// `0..welded_vertex_count` are the welded mesh's, unchanged and in order; the vertices
    /// after them lie on cut curves.
    pub surface: SurfaceMesh,
    /// Topology of `surface`.
    pub topology: Topology,
    /// Number of welded-mesh vertices at the start of `surface.positions`.
    pub welded_vertex_count: usize,
    /// #F(surface): region index of every face.
    pub face_region: Vec<u32>,
    pub regions: Vec<Region>,
    pub boundaries: Vec<Boundary>,
    /// One decision per skeleton joint, in skeleton order.
    pub joints: Vec<JointDecision>,
    /// Regions that were the child side of the cuts of unrelated joints (a hand fused to
    /// the hip) and were divided among them ([`crate::regions::shared_sides`]).
    pub shared_sides: Vec<SharedSide>,
    /// Joints merged for cutting into a kept ancestor, too close to it for a boundary of
    /// their own ([`crate::cuts::merged_joints`]), parents first.
    pub merged_joints: Vec<MergedJoint>,
    /// The face index of `surface`, built by the first [`Decomposition::surface_spheres`]
    /// (the holding regions of soft joints and the guard against far bones share it);
    /// empty (`OnceLock::new()`) when the decomposition is made.
    pub surface_spheres: OnceLock<FaceSpheres>,
}

impl Decomposition {
    /// The face index of the split surface, built on first use.
    pub fn surface_spheres(&self) -> &FaceSpheres {
        self.surface_spheres
            .get_or_init(|| FaceSpheres::new(&self.surface))
    }
}

/// A region that was divided ([`crate::regions::shared_sides`]): the head joint of each
/// family of cuts that shared it (in the skeleton's topological order) and the region of each family's part (the first keeps
/// the divided region).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SharedSide {
    pub joints: Vec<u32>,
    pub regions: Vec<u32>,
}

/// A connected part of the split surface.
#[derive(Debug, Clone, Serialize)]
pub struct Region {
    /// Joints that move this region, ordered along the chain from the root side; the first
    /// is the joint the region is bound to. Empty when no joint reaches the region and it
    /// lies on the parent side of no cut (a loose piece, a sliver between cut loops): the
    /// weights stage then weights it as a piece or from the nearest weighted surface.
    pub joints: Vec<u32>,
    pub faces: usize,
    pub vertices: usize,
}

/// How a boundary separates its two sides.
#[derive(Debug, Clone, PartialEq)]
pub enum BoundaryKind {
    /// An exact closed cut curve (§3.1): a loop of `surface` vertex indices, consecutive
    /// ones joined by an edge of `surface`. It separates `parent_region` from `child_region`.
    Cut { curve: Vec<u32> },
    /// No closed, conflict-free cut exists: the joint's plane restricted to the region that
    /// holds it stands in for the curve, and the signed distance to the plane for the
    /// surface distance (METHOD.md, "extensions"). `parent_region == child_region`.
    Soft,
}

/// The boundary of one joint.
#[derive(Debug, Clone)]
pub struct Boundary {
    /// The skeleton joint at which the surface is cut.
    pub joint: u32,
    pub kind: BoundaryKind,
    /// A point of the cutting plane (the joint's bind position).
    pub point: DVec3,
    /// Unit plane normal, pointing to the child side: n · (upper + lower) > 0.
    pub normal: DVec3,
    /// Length of the closed curve (for a soft boundary, of the plane's section estimate).
    pub perimeter: f64,
    /// Approximate diameter D of the curve: the largest distance between two curve points.
    pub diameter: f64,
    /// Region on the parent bone's side.
    pub parent_region: u32,
    /// Region on the child bone's side.
    pub child_region: u32,
    /// The joint is a leaf whose part runs on past it for at least its bone's length (rule
    /// 5 (c) of [`crate::cuts::joint_roles`]): a soft boundary of it is seeded farther
    /// ([`crate::cuts::joint_roles::JointFrame::leaf_part_past`]).
    pub leaf_part_past: bool,
    /// Another bone runs through the joint (or from it) and crosses every plane searched
    /// there ([`crate::cuts::plane_search::CutSearch::through_joint`]): nothing in the
    /// geometry places the joint's own part apart from that bone's.
    pub bone_through: bool,
}

/// Why a joint has the boundary it has, for the report.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(rename_all = "snake_case", tag = "status", content = "reason")]
pub enum JointStatus {
    /// An exact closed cut: index into [`Decomposition::boundaries`] in `boundary`.
    Cut,
    /// A soft boundary, with why no cut was placed.
    Soft(String),
    /// No boundary, with why (root, end site, branching joint on the mirror plane at the
    /// skin, outside the mesh and owning no geometry, forbidden by the user, named as a
    /// helper, ...).
    Skipped(String),
}

/// The decision for one joint.
#[derive(Debug, Clone, Serialize)]
pub struct JointDecision {
    pub name: String,
    #[serde(flatten)]
    pub status: JointStatus,
    /// Index into [`Decomposition::boundaries`] when the joint has a boundary.
    pub boundary: Option<u32>,
    /// The region the joint's bone lies in.
    pub region: Option<u32>,
    /// False when the joint must move no skin: forbidden by the user, or outside the mesh
    /// owning no geometry (then it moves only what the nearest-bone fallback gives it).
    #[serde(skip)]
    pub owns_skin: bool,
}
