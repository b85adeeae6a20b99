//! Skeleton-driven decomposition of the surface (Lu et al. 2008 §3.1–3.2): which joints get
//! a boundary ([`crate::joint_roles`]), the cutting plane of each ([`crate::cut`]), conflicts
//! between cuts, the split along the kept curves ([`crate::split`]) and the regions
//! ([`crate::segment`]).
//!
//! Conflict rule. Two curves conflict when they cross or touch: they run through a common
//! vertex, or two of their chords in one face interleave or end within `snap_fraction` of
//! each other along the face's boundary. Curves that merely pass through the same faces
//! (parallel chords of a coarse mesh's large triangles) do not conflict. Joints are placed
//! in increasing order of their best perimeter, so the small cross-sections of fingers,
//! toes and distal limbs are placed before the palm, leg-root, neck and torso planes that
//! would cross them; branching joints on the mirror plane (a spine joint where the legs or
//! the arms branch) come after all others, whatever their perimeter. A joint whose best
//! curve conflicts with an already placed one tries its next-best closed sections (the
//! other sampled planes, by increasing perimeter); when none fits, it gets a soft boundary:
//! its plane restricted to the region that holds it (METHOD.md, "extensions"), which the
//! weights stage blends across; so does a joint that [`crate::joint_roles`] allows no cut.
//! A joint is left without a boundary only for the reasons of [`crate::joint_roles`], or
//! when no region holds it (an empty surface); the report says which.

use crate::cut::{find_cut_candidates, CutCandidate, CutSearch, CutSurface};
use crate::joint_roles::{plan_joints, JointFrame, JointPlan, Override};
use crate::plane_section::{diameter, vertex_snap_distances, Chord, CrossingPoint, SectionCurve};
use crate::proximity::FaceSpheres;
use crate::segment::{bind_regions, grow_regions, side_regions};
use crate::split::split_along_curves;
use crate::{
    Boundary, BoundaryKind, Decomposition, JointDecision, JointStatus, SurfaceMesh, Topology,
};
use atlas_skin_runtime::{RuntimeError, Skeleton};
use glam::DVec3;
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::collections::HashMap;

/// Settings of the decomposition; `Default` is what the corpus was tuned with. A config
/// file may carry any subset of the fields (serde, unknown fields rejected).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default, deny_unknown_fields)]
pub struct DecomposeParams {
    /// Coarse sampling step of the plane normal, in degrees (planar case; the cone uses
    /// twice this step).
    pub angle_step_deg: f64,
    /// Half-angle of the cone of normals around collinear bones, in degrees.
    pub cone_half_angle_deg: f64,
    /// Pattern-search iterations refining the best coarse normal.
    pub refine_iterations: usize,
    /// Radius of the faces tested around a joint, in units of max(surface distance,
    /// bone length / 10).
    pub neighbourhood_factor: f64,
    /// A vertex closer to a plane than this fraction of its longest edge is put on it.
    pub snap_fraction: f64,
    /// A leaf owns geometry when the surface beyond it along its bone is at least this
    /// many times its surface distance away.
    pub leaf_extent_ratio: f64,
    /// A joint outside the surface and farther from it than this many times its longest
    /// bone owns no geometry.
    pub outside_ratio: f64,
    /// Mirror-plane fit tolerance, relative to the skeleton's diagonal (a joint is on the
    /// plane within a quarter of it).
    pub symmetry_tolerance: f64,
    /// Joints (by name) that get a boundary whatever their role.
    pub force: Vec<String>,
    /// Joints (by name) that get no boundary.
    pub forbid: Vec<String>,
}

impl Default for DecomposeParams {
    fn default() -> Self {
        Self {
            angle_step_deg: 10.0,
            cone_half_angle_deg: 30.0,
            refine_iterations: 8,
            neighbourhood_factor: 4.0,
            snap_fraction: 0.01,
            leaf_extent_ratio: 1.5,
            outside_ratio: 0.5,
            symmetry_tolerance: 0.02,
            force: Vec::new(),
            forbid: Vec::new(),
        }
    }
}

/// Why the decomposition cannot run.
#[derive(Debug, thiserror::Error)]
pub enum DecomposeError {
    #[error("joint `{name}` named in `{list}` is not in the skeleton")]
    UnknownJoint { name: String, list: &'static str },
    #[error("joint `{name}` is both forced and forbidden")]
    ForcedAndForbidden { name: String },
    #[error("parameter `{name}` = {value} is out of range: {expected}")]
    BadParameter {
        name: &'static str,
        value: f64,
        expected: &'static str,
    },
    #[error("the topology has {topology_faces} faces but the mesh {faces}")]
    TopologyMismatch { faces: usize, topology_faces: usize },
    #[error("triangle {face} refers to vertex {vertex}, the mesh has {count}")]
    VertexOutOfRange {
        face: usize,
        vertex: u32,
        count: usize,
    },
    #[error("vertex {vertex} has a non-finite position")]
    NonFinitePosition { vertex: usize },
    #[error("invalid skeleton: {0}")]
    Skeleton(#[from] RuntimeError),
}

/// Cuts `mesh` (welded, with its `topology`) at the joints of `skeleton` and grows the
/// regions. Never panics on a valid input: open, multi-piece and degenerate surfaces and
/// joints outside the mesh end in soft or skipped joints, each with its reason.
pub fn decompose(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    params: &DecomposeParams,
) -> Result<Decomposition, DecomposeError> {
    validate(mesh, topology, skeleton, params)?;
    let overrides = resolve_overrides(skeleton, params)?;
    let positions: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let spheres = FaceSpheres::new(mesh);
    let vertex_snap = vertex_snap_distances(mesh, topology, params.snap_fraction);
    let plans = plan_joints(mesh, &spheres, skeleton, &positions, &overrides, params);
    let cut_surface = CutSurface {
        mesh,
        topology,
        spheres: &spheres,
        vertex_snap: &vertex_snap,
        params,
    };
    let searches = search_all_cuts(&cut_surface, skeleton, &positions, &plans);
    let placements = place_cuts(
        mesh,
        topology,
        skeleton,
        &plans,
        &searches,
        params.snap_fraction,
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
    let (face_region, region_count) = grow_regions(&surface, &split_topology, &split.loops);

    // Each placed cut takes its loop (in placement order) and its two sides.
    let mut loops = split.loops.into_iter();
    let outcomes: Vec<Outcome> = placements
        .into_iter()
        .enumerate()
        .map(|(j, placement)| match placement {
            Placement::Cut { candidate, frame } => {
                let curve = loops.next().unwrap_or_default();
                let plane = &searches[j].candidates[candidate].plane;
                match side_regions(&surface, &split_topology, &face_region, &curve, plane) {
                    Some((parent, child)) if parent != child => Outcome::Cut {
                        candidate,
                        curve,
                        parent,
                        child,
                        frame,
                    },
                    _ => Outcome::Soft {
                        reason: "its closed cut does not separate the surface".into(),
                        frame,
                    },
                }
            }
            Placement::Soft { reason, frame } => Outcome::Soft { reason, frame },
            Placement::Skip(reason) => Outcome::Skip(reason),
        })
        .collect();
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
    let (joint_region, regions) = bind_regions(
        &surface,
        &face_region,
        region_count,
        skeleton,
        &positions,
        &sides(true),
        &sides(false),
    );

    let (boundaries, mut joints) = decide_joints(skeleton, outcomes, &joint_region, &searches);
    for (decision, plan) in joints.iter_mut().zip(&plans) {
        decision.owns_skin = !matches!(plan, JointPlan::Exclude(_));
    }
    Ok(Decomposition {
        topology: split_topology,
        welded_vertex_count: mesh.vertex_count(),
        surface,
        face_region,
        regions,
        boundaries,
        joints,
    })
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
                        JointStatus::Soft(reason),
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

/// The cut search of every joint that gets a boundary (in parallel over joints); the
/// other bones a section must not enclose are all bones not at the joint.
fn search_all_cuts(
    surface: &CutSurface,
    skeleton: &Skeleton,
    positions: &[DVec3],
    plans: &[JointPlan],
) -> Vec<CutSearch> {
    let bones: Vec<(usize, usize)> = (0..skeleton.len())
        .filter_map(|j| skeleton.parent(j).map(|p| (p, j)))
        .filter(|&(p, j)| positions[p] != positions[j])
        .collect();
    plans
        .par_iter()
        .enumerate()
        .map(|(j, plan)| match plan {
            JointPlan::Boundary(frame) | JointPlan::Soft(frame, _) => {
                let other_bones: Vec<[DVec3; 2]> = bones
                    .iter()
                    .filter(|&&(p, c)| p != j && c != j)
                    .map(|&(p, c)| [positions[p], positions[c]])
                    .collect();
                find_cut_candidates(surface, frame, &other_bones)
            }
            JointPlan::Skip(_) | JointPlan::Exclude(_) => CutSearch::default(),
        })
        .collect()
}

/// Where the conflict rule put a joint's boundary.
#[derive(Debug, Clone, PartialEq)]
enum Placement {
    /// Index of the placed candidate.
    Cut {
        candidate: usize,
        frame: JointFrame,
    },
    Soft {
        reason: String,
        frame: JointFrame,
    },
    Skip(String),
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

/// The conflict rule of the module doc. Returns one placement per joint.
fn place_cuts(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    plans: &[JointPlan],
    searches: &[CutSearch],
    gap: f64,
) -> Vec<Placement> {
    let candidates: Vec<&[CutCandidate]> = searches.iter().map(|s| &s.candidates[..]).collect();
    let on_mirror_plane =
        |j: usize| matches!(&plans[j], JointPlan::Boundary(frame) if frame.on_mirror_plane);
    let mut order: Vec<usize> = (0..plans.len())
        .filter(|&j| matches!(plans[j], JointPlan::Boundary(_)) && !candidates[j].is_empty())
        .collect();
    order.sort_by(|&a, &b| {
        on_mirror_plane(a).cmp(&on_mirror_plane(b)).then(
            candidates[a][0]
                .perimeter
                .total_cmp(&candidates[b][0].perimeter),
        )
    });
    let mut placed_chords: HashMap<u32, Vec<(u32, Chord)>> = HashMap::new();
    let mut vertex_owner: HashMap<u32, u32> = HashMap::new();
    let mut placed: Vec<Option<Result<usize, Vec<u32>>>> = vec![None; plans.len()];
    for j in order {
        let mut blockers: Vec<u32> = Vec::new();
        let mut accepted = None;
        for (k, candidate) in candidates[j].iter().enumerate() {
            let chords: Vec<Chord> = candidate.curve.chords(mesh, topology).collect();
            let vertices = curve_vertices(&candidate.curve);
            let before = blockers.len();
            blockers.extend(vertices.iter().filter_map(|v| vertex_owner.get(v).copied()));
            for chord in &chords {
                if let Some(others) = placed_chords.get(&chord.face) {
                    blockers.extend(
                        others
                            .iter()
                            .filter(|(_, other)| chord.crosses_or_touches(other, gap))
                            .map(|(owner, _)| *owner),
                    );
                }
            }
            if blockers.len() == before {
                for chord in chords {
                    placed_chords
                        .entry(chord.face)
                        .or_default()
                        .push((j as u32, chord));
                }
                vertex_owner.extend(vertices.into_iter().map(|v| (v, j as u32)));
                accepted = Some(k);
                break;
            }
        }
        placed[j] = Some(accepted.ok_or(blockers));
    }
    plans
        .iter()
        .zip(placed)
        .zip(searches)
        .map(|((plan, placed), search)| {
            let frame = match plan {
                JointPlan::Skip(reason) | JointPlan::Exclude(reason) => {
                    return Placement::Skip(reason.clone())
                }
                JointPlan::Soft(frame, reason) => {
                    return Placement::Soft {
                        reason: reason.clone(),
                        frame: *frame,
                    }
                }
                JointPlan::Boundary(frame) => *frame,
            };
            let reason = match placed {
                Some(Ok(candidate)) => return Placement::Cut { candidate, frame },
                Some(Err(mut blockers)) => {
                    blockers.sort_unstable();
                    blockers.dedup();
                    let names: Vec<&str> = blockers
                        .iter()
                        .map(|&b| skeleton.names[b as usize].as_str())
                        .collect();
                    format!(
                        "every closed section found crosses or touches the cut of {}",
                        names.join(", ")
                    )
                }
                None if search.enclosing_other_bones > 0 => format!(
                    "each of the {} closed sections around the joint also encloses another bone \
                     (a plane across a palm, a foot or the torso)",
                    search.enclosing_other_bones
                ),
                None => "no closed cross-section around the joint near it (open surface, \
                         joint outside, or a section reaching far from the joint)"
                    .into(),
            };
            Placement::Soft { reason, frame }
        })
        .collect()
}

/// The surface vertices a curve runs through.
fn curve_vertices(curve: &SectionCurve) -> Vec<u32> {
    let mut vertices: Vec<u32> = curve
        .crossings
        .iter()
        .filter_map(|c| match c.point {
            CrossingPoint::Vertex(v) => Some(v),
            CrossingPoint::Interior(_) => None,
        })
        .collect();
    vertices.sort_unstable();
    vertices.dedup();
    vertices
}

/// Plane, perimeter and diameter of a boundary from `section`: the placed section of a cut,
/// the best closed section of a soft boundary. Without one the normal is the bisector of
/// the bones and the section a circle of the joint's surface distance r (perimeter 2πr,
/// diameter 2r).
fn boundary_geometry(
    joint: usize,
    frame: &JointFrame,
    section: Option<&CutCandidate>,
    kind: BoundaryKind,
    parent_region: u32,
    child_region: u32,
) -> Boundary {
    let (normal, perimeter, diameter) = match section {
        Some(c) => (c.plane.normal, c.perimeter, diameter(&c.points)),
        None => {
            let r = frame.surface_distance;
            let normal = (frame.upper + frame.lower)
                .try_normalize()
                .unwrap_or(frame.upper);
            (normal, std::f64::consts::TAU * r, 2.0 * r)
        }
    };
    Boundary {
        joint: joint as u32,
        kind,
        point: frame.position,
        normal,
        perimeter,
        diameter,
        parent_region,
        child_region,
    }
}

fn validate(
    mesh: &SurfaceMesh,
    topology: &Topology,
    skeleton: &Skeleton,
    params: &DecomposeParams,
) -> Result<(), DecomposeError> {
    skeleton.validate()?;
    if topology.face_edges.len() != mesh.triangle_count() {
        return Err(DecomposeError::TopologyMismatch {
            faces: mesh.triangle_count(),
            topology_faces: topology.face_edges.len(),
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
    let checks: [(&'static str, f64, bool, &'static str); 7] = [
        (
            "angle_step_deg",
            params.angle_step_deg,
            params.angle_step_deg >= 0.1 && params.angle_step_deg <= 45.0,
            "0.1 ..= 45",
        ),
        (
            "cone_half_angle_deg",
            params.cone_half_angle_deg,
            (0.0..=80.0).contains(&params.cone_half_angle_deg),
            "0 ..= 80",
        ),
        (
            "neighbourhood_factor",
            params.neighbourhood_factor,
            params.neighbourhood_factor > 0.0 && params.neighbourhood_factor.is_finite(),
            "> 0",
        ),
        (
            "snap_fraction",
            params.snap_fraction,
            (0.0..0.5).contains(&params.snap_fraction),
            "0 ..< 0.5",
        ),
        (
            "leaf_extent_ratio",
            params.leaf_extent_ratio,
            params.leaf_extent_ratio >= 0.0 && params.leaf_extent_ratio.is_finite(),
            ">= 0",
        ),
        (
            "outside_ratio",
            params.outside_ratio,
            params.outside_ratio > 0.0,
            "> 0",
        ),
        (
            "symmetry_tolerance",
            params.symmetry_tolerance,
            (0.0..1.0).contains(&params.symmetry_tolerance),
            "0 ..< 1",
        ),
    ];
    for (name, value, ok, expected) in checks {
        if !ok {
            return Err(DecomposeError::BadParameter {
                name,
                value,
                expected,
            });
        }
    }
    Ok(())
}

/// Per joint: forced, forbidden or neither; names not in the skeleton are errors.
fn resolve_overrides(
    skeleton: &Skeleton,
    params: &DecomposeParams,
) -> Result<Vec<Option<Override>>, DecomposeError> {
    let mut overrides = vec![None; skeleton.len()];
    for (list, names, value) in [
        ("force", &params.force, Override::Force),
        ("forbid", &params.forbid, Override::Forbid),
    ] {
        for name in names {
            let j = skeleton
                .find(name)
                .ok_or_else(|| DecomposeError::UnknownJoint {
                    name: name.clone(),
                    list,
                })?;
            if overrides[j].is_some_and(|o| o != value) {
                return Err(DecomposeError::ForcedAndForbidden { name: name.clone() });
            }
            overrides[j] = Some(value);
        }
    }
    Ok(overrides)
}
