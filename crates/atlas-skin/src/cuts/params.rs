//! Settings of the decomposition (§3.1 plane search, joint roles, conflicts; §3.2 has
//! none), their validation, and the per-joint overrides: the user's, and helper names.

use crate::ablation::{Rule, RulesOff};
use crate::skeleton::helpers::helper_joints;
use atlas_skin_runtime::{RuntimeError, Skeleton};
use serde::{Deserialize, Serialize};

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
    /// Rules of this stage switched off, to measure each alone (a developer setting:
    /// [`crate::ablation`]).
    pub rules_off: RulesOff,
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
            rules_off: RulesOff::default(),
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
    #[error(
        "the topology has {topology_faces} faces and {topology_vertices} vertices but the mesh \
         {faces} and {vertices}"
    )]
    TopologyMismatch {
        faces: usize,
        vertices: usize,
        topology_faces: usize,
        topology_vertices: usize,
    },
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

/// What overrides the rules at one joint: the user, or the joint's name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Override {
    Force,
    Forbid,
    /// Named as a helper that deforms nothing ([`crate::skeleton::helpers`]), and not
    /// forced by the user.
    Helper,
}

impl DecomposeParams {
    /// Checks every numeric setting against its range.
    pub fn validate(&self) -> Result<(), DecomposeError> {
        let params = self;
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

    /// Per joint: forced, forbidden, a helper by its name, or none of these; names not in the
    /// skeleton are errors.
    pub fn overrides(&self, skeleton: &Skeleton) -> Result<Vec<Option<Override>>, DecomposeError> {
        let mut overrides = vec![None; skeleton.len()];
        for (list, names, value) in [
            ("force", &self.force, Override::Force),
            ("forbid", &self.forbid, Override::Forbid),
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
        let helpers_by_name = self.rules_off.on(Rule::HelperNames);
        for (o, helper) in overrides.iter_mut().zip(helper_joints(skeleton)) {
            if helpers_by_name && helper && o.is_none() {
                *o = Some(Override::Helper);
            }
        }
        Ok(overrides)
    }
}
