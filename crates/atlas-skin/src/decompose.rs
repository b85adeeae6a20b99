//! The decomposition stage (Lu et al. 2008 §3.1–3.2): the boundaries at the joints
//! ([`crate::cuts`]: joint roles, plane search, conflicts, the split along the kept
//! curves), then the regions of the split surface and the joints bound to them
//! ([`crate::regions`]).
//!
//! Inputs: the welded surface and its [`Topology`], the [`Skeleton`] in the surface's bind
//! space, [`DecomposeParams`]. Output: a [`Decomposition`]: the split surface, its regions,
//! the boundaries and one [`JointDecision`] per joint with its reason.
//!
//! A joint is left without a boundary only for the reasons of
//! [`crate::cuts::joint_roles`], or when no region holds it (an empty surface); the report
//! says which.

use crate::cuts::conflicts::{place_cuts, Placement};
use crate::cuts::joint_roles::{plan_joints, JointFrame, JointPlan};
use crate::cuts::merged_joints::merge_dense_joints;
use crate::cuts::plane_search::{find_cut_candidates, CutCandidate, CutSearch, CutSurface};
use crate::cuts::plane_section::{diameter, vertex_snap_distances, ScratchPool};
use crate::cuts::split::split_along_curves;
use crate::decomposition::{Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus};
use crate::mesh::{FaceSpheres, SurfaceMesh, Topology};
use crate::regions::holding::{own_bone_points, HoldingRegions};
use crate::regions::shared_sides::{divide_shared_sides, ChildSide};
use crate::regions::{
    bind_parent_sides, bind_regions, faces_by_region, grow_regions, nearest_bone_joints,
    side_regions,
};
use crate::skeleton::bone_tree::BoneTree;
use crate::skeleton::bones::{bone_segments, joint_pairs, BoneIndex};
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use rayon::prelude::*;

pub use crate::cuts::params::{DecomposeError, DecomposeParams};
/// regions. Never panics on a valid input: open, multi-piece and degenerate surfaces and
/// joints outside the mesh end in soft or skipped joints, each with its reason.
pub fn decompose(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    params: &DecomposeParams,
) -> Result<Decomposition, DecomposeError> {
    validate_input(mesh, topology, skeleton)?;
    params.validate()?;
    let overrides = params.overrides(skeleton)?;
    let positions: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let spheres = FaceSpheres::new(mesh);
    let vertex_snap = vertex_snap_distances(mesh, topology, params.snap_fraction);
    let bones = BoneIndex::new(joint_pairs(skeleton, &positions), &positions);
    let children = skeleton.children();
    let mut plans = plan_joints(
        mesh,
        &topology.vertex_component,
        &spheres,
        skeleton,
        &positions,
        &bones,
        &overrides,
        params,
    );
    let merged_joints = merge_dense_joints(skeleton, &positions, &overrides, &mut plans);
    let cut_surface = CutSurface {
        mesh,
        topology,
        spheres: &spheres,
        vertex_snap: &vertex_snap,
        max_snap: vertex_snap.iter().copied().fold(0.0, f64::max),
        params,
    };
    let searches = search_all_cuts(&cut_surface, &bones, &plans);
    let placements = place_cuts(
        mesh,
        topology,
        skeleton,
        &plans,
        &searches,
        params.snap_fraction,
        &params.rules_off,
    );

    let curves: Vec<_> = placements
        .iter()
        .enumerate()
        .filter_map(|(j, p)| match p {
            Placement::Cut { candidate, .. } => Some(&searches[j].candidates[*candidate].curve),
            _ => None,
        })
        .collect();
    let split = split_along_curves(mesh, topology, &curves);
    let surface = split.mesh;
    let split_topology = Topology::new(&surface);
    let (mut face_region, mut region_count) = grow_regions(&surface, &split_topology, &split.loops);

    let sides_from = |outcomes: &mut [Outcome], face_region: &[u32]| {
        assign_sides(outcomes, &searches, &surface, &split_topology, face_region);
    };
    let mut outcomes = settle_cuts(placements, split.loops);
    sides_from(&mut outcomes, &face_region);
    let child_sides: Vec<ChildSide> = outcomes
        .iter()
        .enumerate()
        .filter_map(|(j, o)| match o {
            Outcome::Cut { child, curve, .. } => Some(ChildSide {
                joint: j as u32,
                region: *child,
                curve,
            }),
            _ => None,
        })
        .collect();
    let shared_sides = divide_shared_sides(
        &surface,
        &split_topology,
        skeleton,
        &mut face_region,
        &mut region_count,
        &child_sides,
    );
    if !shared_sides.is_empty() {
        sides_from(&mut outcomes, &face_region);
    }
    let sides = |want_child: bool| -> Vec<Option<u32>> {
        outcomes
            .iter()
            .map(|o| match o {
                Outcome::Cut { parent, child, .. } => {
                    Some(if want_child { *child } else { *parent })
                }
                _ => None,
            })
            .collect()
    };
    let cut_parent = sides(false);
    let owns_skin: Vec<bool> = plans
        .iter()
        .map(|plan| !matches!(plan, JointPlan::Exclude(_)))
        .collect();
    // On one connected surface a joint without a cut lies in its parent's region (§3.2);
    // the faces of the split surface are indexed here only for a surface of several pieces
    // with a soft joint (the index is kept for the weights).
    let surface_spheres = std::sync::OnceLock::new();
    let holders = (outcomes.iter().any(|o| matches!(o, Outcome::Soft { .. }))
        && topology.component_count > 1)
        .then(|| {
            let spheres = surface_spheres.get_or_init(|| FaceSpheres::new(&surface));
            HoldingRegions::new(&surface, &face_region, spheres)
        });
    let holding = |j: usize, parent_region: Option<u32>| match (&outcomes[j], &holders) {
        (Outcome::Soft { frame, .. }, Some(holders)) => {
            let section = searches[j].candidates.first();
            let (_, _, diameter) = section_geometry(frame, section);
            let points = section.map_or(&[][..], |c| &c.points[..]);
            let own = own_bone_points(frame.position, children[j].iter().map(|&c| positions[c]));
            holders.holding_region(frame.position, points, diameter, parent_region, &own)
        }
        _ => parent_region,
    };
    let region_faces = faces_by_region(&face_region, region_count);
    let (joint_region, mut regions) = bind_regions(
        &surface,
        &face_region,
        &region_faces,
        skeleton,
        &positions,
        &sides(true),
        &cut_parent,
        holding,
    );

    let (boundaries, mut joints) = decide_joints(skeleton, outcomes, &joint_region, &searches);
    for (decision, &owns) in joints.iter_mut().zip(&owns_skin) {
        decision.owns_skin = owns;
    }
    // The bones are indexed only when some region without joints lies on a parent side.
    let bones = std::cell::OnceCell::new();
    bind_parent_sides(&mut regions, skeleton, &cut_parent, &owns_skin, |r| {
        let (segments, tree) = bones.get_or_init(|| {
            let segments = bone_segments(skeleton);
            let ends: Vec<[DVec3; 2]> = segments.iter().map(|&(_, a, b)| [a, b]).collect();
            (segments, BoneTree::of_segments(&ends))
        });
        nearest_bone_joints(&surface, region_faces.row(r as usize), tree, segments)
    });
    Ok(Decomposition {
        topology: split_topology,
        welded_vertex_count: mesh.vertex_count(),
        surface,
        face_region,
        regions,
        boundaries,
        joints,
        shared_sides,
        merged_joints,
        surface_spheres,
    })
}

/// The outcome of every joint once the surface is split along the placed cuts: each cut
/// takes its loop (`loops` holds one per placed cut, in placement order); its sides are
/// set by [`assign_sides`].
fn settle_cuts(placements: Vec<Placement>, loops: Vec<Vec<u32>>) -> Vec<Outcome> {
    let mut loops = loops.into_iter();
    placements
        .into_iter()
        .map(|placement| match placement {
            Placement::Cut { candidate, frame } => {
                let curve = loops.next();
                debug_assert!(curve.is_some(), "one split loop per placed cut");
                Outcome::Cut {
                    candidate,
                    curve: curve.unwrap_or_default(),
                    parent: 0,
                    child: 0,
                    frame,
                }
            }
            Placement::Soft { reason, frame } => Outcome::Soft { reason, frame },
            Placement::Skip(reason) => Outcome::Skip(reason),
        })
        .collect()
}

/// Sets the regions on the two sides of every cut from `face_region`; a cut that does not
/// separate the surface becomes a soft boundary.
fn assign_sides(
    outcomes: &mut [Outcome],
    searches: &[CutSearch],
    surface: &SurfaceMesh,
    topology: &Topology,
    face_region: &[u32],
) {
    for (j, outcome) in outcomes.iter_mut().enumerate() {
        let Outcome::Cut {
            candidate,
            curve,
            parent,
            child,
            frame,
        } = outcome
        else {
            continue;
        };
        let plane = &searches[j].candidates[*candidate].plane;
        match side_regions(surface, topology, face_region, curve, plane) {
            Some((p, c)) if p != c => (*parent, *child) = (p, c),
            _ => {
                *outcome = Outcome::Soft {
                    reason: "its closed cut does not separate the surface".into(),
                    frame: *frame,
                }
            }
        }
    }
}

/// The boundaries and the per-joint decisions, in skeleton order. A cut's plane,
/// perimeter and diameter are those of its placed section; a soft boundary's those of the
/// joint's best section (see [`boundary_geometry`]).
fn decide_joints(
    skeleton: &Skeleton,
    outcomes: Vec<Outcome>,
    joint_region: &[Option<u32>],
    searches: &[CutSearch],
) -> (Vec<Boundary>, Vec<JointDecision>) {
    let mut boundaries = Vec::new();
    let joints = outcomes
        .into_iter()
        .enumerate()
        .map(|(j, outcome)| {
            let name = skeleton.names[j].clone();
            let region = joint_region[j];
            let skipped = |name: String, reason: String| JointDecision {
                name,
                status: JointStatus::Skipped(reason),
                boundary: None,
                region,
                owns_skin: true,
            };
            let (status, kind, frame, section, parent_region, child_region) = match outcome {
                Outcome::Cut {
                    candidate,
                    curve,
                    parent,
                    child,
                    frame,
                } => (
                    JointStatus::Cut,
                    BoundaryKind::Cut { curve },
                    frame,
                    searches[j].candidates.get(candidate),
                    parent,
                    child,
                ),
                Outcome::Soft { reason, frame } => match region {
                    Some(r) => (
                        JointStatus::Soft(held_elsewhere(skeleton, joint_region, j, reason)),
                        BoundaryKind::Soft,
                        frame,
                        searches[j].candidates.first(),
                        r,
                        r,
                    ),
                    None => {
                        return skipped(
                            name,
                            format!("{reason}; no surface region holds the joint"),
                        )
                    }
                },
                Outcome::Skip(reason) => return skipped(name, reason),
            };
            boundaries.push(boundary_geometry(
                j,
                &frame,
                &searches[j],
                section,
                kind,
                parent_region,
                child_region,
            ));
            JointDecision {
                name,
                status,
                boundary: Some(boundaries.len() as u32 - 1),
                region,
                owns_skin: true,
            }
        })
        .collect();
    (boundaries, joints)
}

/// The reason of soft joint `j`, with what [`HoldingRegions`] did when it moved the joint
/// out of its parent's region.
fn held_elsewhere(
    skeleton: &Skeleton,
    joint_region: &[Option<u32>],
    j: usize,
    reason: String,
) -> String {
    match skeleton.parent(j).map(|p| joint_region[p]) {
        Some(Some(parent_region)) if joint_region[j] != Some(parent_region) => format!(
            "{reason}; its parent's region {parent_region} does not hold its section: it \
             acts in the region around it, {}",
            joint_region[j].map_or("none".to_string(), |r| r.to_string())
        ),
        _ => reason,
    }
}

/// A joint's boundary once the surface is split.
#[derive(Debug, Clone, PartialEq)]
enum Outcome {
    Cut {
        /// Index of the placed candidate.
        candidate: usize,
        curve: Vec<u32>,
        parent: u32,
        child: u32,
        frame: JointFrame,
    },
    Soft {
        reason: String,
        frame: JointFrame,
    },
    Skip(String),
}

/// The cut search of every joint that gets a boundary (in parallel over joints, the
/// scratch maps lent from job to job by a [`ScratchPool`]); the other bones a section must
/// not enclose are all bones not at the joint.
fn search_all_cuts(surface: &CutSurface, bones: &BoneIndex, plans: &[JointPlan]) -> Vec<CutSearch> {
    let pool = ScratchPool::default();
    plans
        .par_iter()
        .enumerate()
        .map_init(
            || pool.lend(),
            |scratch, (j, plan)| match plan {
                JointPlan::Boundary(frame) | JointPlan::Soft(frame, _) => {
                    find_cut_candidates(surface, j, frame, bones, scratch)
                }
                JointPlan::Skip(_) | JointPlan::Exclude(_) => CutSearch::default(),
            },
        )
        .collect()
}

/// Plane, perimeter and diameter of a boundary from `section`: the placed section of a cut,
/// the best closed section of a soft boundary. Without one the normal is the bisector of
/// the bones and the section a circle of the joint's surface distance r (perimeter 2πr,
/// diameter 2r). `search`: the joint's cut search, which says whether a bone runs through
/// the joint.
fn boundary_geometry(
    joint: usize,
    frame: &JointFrame,
    search: &CutSearch,
    section: Option<&CutCandidate>,
    kind: BoundaryKind,
    parent_region: u32,
    child_region: u32,
) -> Boundary {
    let (normal, perimeter, diameter) = section_geometry(frame, section);
    Boundary {
        joint: joint as u32,
        kind,
        point: frame.position,
        normal,
        perimeter,
        diameter,
        parent_region,
        child_region,
        leaf_part_past: frame.leaf_part_past,
        bone_through: search.through_joint.is_some(),
    }
}

/// (normal, perimeter, diameter) of a boundary with `section` (see [`boundary_geometry`]).
fn section_geometry(frame: &JointFrame, section: Option<&CutCandidate>) -> (DVec3, f64, f64) {
    match section {
        Some(c) => (c.plane.normal, c.perimeter, diameter(&c.points)),
        None => {
            let r = frame.surface_distance;
            let normal = (frame.upper + frame.lower)
                .try_normalize()
                .unwrap_or(frame.upper);
            (normal, std::f64::consts::TAU * r, 2.0 * r)
        }
    }
}

/// The surface and the skeleton are fit for the method: the topology is the mesh's,
/// every index is in range, every position finite, the skeleton valid.
fn validate_input(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
) -> Result<(), DecomposeError> {
    skeleton.validate()?;
    if topology.face_edges.len() != mesh.triangle_count()
        || topology.vertex_component.len() != mesh.vertex_count()
    {
        return Err(DecomposeError::TopologyMismatch {
            faces: mesh.triangle_count(),
            vertices: mesh.vertex_count(),
            topology_faces: topology.face_edges.len(),
            topology_vertices: topology.vertex_component.len(),
        });
    }
    let count = mesh.vertex_count();
    for (face, t) in mesh.triangles.iter().enumerate() {
        if let Some(&vertex) = t.iter().find(|&&v| v as usize >= count) {
            return Err(DecomposeError::VertexOutOfRange {
                face,
                vertex,
                count,
            });
        }
    }
    if let Some(vertex) = mesh.positions.iter().position(|p| !p.is_finite()) {
        return Err(DecomposeError::NonFinitePosition { vertex });
    }
    Ok(())
}
