//! Joints merged for cutting: a skeleton denser than its body can be served is cut at
//! fewer joints, so that the cost of every later stage is bounded by the input.
//!
//! A joint J that would get a boundary lies at depth r_J in the body (its surface distance,
//! [`super::joint_roles::JointFrame::surface_distance`]). Its cut's section has a diameter D of about 2 r_J and
//! its overlap band a half-width w = ½ D ≈ r_J on each side (§3.3). Boundaries whose joints
//! are closer together than a small part of r_J along a chain stack their bands: a vertex
//! lies in 2 w / s bands for joints s apart, and the plane search of each joint scans the
//! faces within 4 r_J of it (a ball that holds 8 r_J / s other joints). A chain of
//! 10,000 joints 0.4 mm apart in a capsule of radius 0.1 (issue 45) put every vertex in
//! about 500 bands and made the weights quadratic in the joints.
//!
//! The rule: visiting the joints parents first, a joint that would get a boundary is
//! *merged* into its nearest kept ancestor K (the nearest ancestor not itself merged) when
//! |p_J − p_K| < r_J / [`MERGE_DIVISOR`] and the user did not force it. It then gets no
//! boundary: it lies in K's region (§3.2: a joint without a cut lies in its parent's
//! region) and moves no skin of its own; the skin around it follows K, and through the
//! hierarchy every joint between K and the next kept joint moves what lies past them.
//! Kept joints of one chain are therefore at least r / 8 apart: a vertex lies in at most
//! about 2 w / (r / 8) = 16 bands of one chain, and a point of the surface in the search
//! balls of at most about 8 r / (r / 8) = 64 joints, whatever the skeleton's density.
//!
//! No joint of the 113 real characters compared in docs/measurements.md ("Many joints") is
//! merged: their weights are unchanged.

use super::joint_roles::JointPlan;
use super::params::Override;
use crate::warning::{Warning, WarningTopic};
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use serde::Serialize;

/// Kept joints of a chain are at least 1/`MERGE_DIVISOR` of their surface distance apart.
pub const MERGE_DIVISOR: f64 = 8.0;

/// A joint merged for cutting into a kept ancestor.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct MergedJoint {
    pub joint: u32,
    /// The nearest ancestor of `joint` that is not merged: `joint` lies in its region.
    pub into: u32,
    /// |p_J − p_K|.
    pub distance: f64,
    /// The joint's surface distance r_J.
    pub surface_distance: f64,
}

/// The warning for `merged` (from [`merge_dense_joints`] on `skeleton`), when any joint
/// was merged: how many, the first, and what was done.
pub fn merge_warning(merged: &[MergedJoint], skeleton: &Skeleton) -> Option<Warning> {
    let first = merged.first()?;
    let name = |j: u32| &skeleton.names[j as usize];
    Some(Warning::new(
        WarningTopic::Skeleton,
        format!(
            "{} joint(s) lie closer to the joint above them than 1/{MERGE_DIVISOR} of their \
         depth in the body, too close for a boundary of their own (the first: {}, {:.3e} \
         from {}): merged for cutting, each lies in the region of the joint it was merged \
         into and moves no skin of its own",
            merged.len(),
            name(first.joint),
            first.distance,
            name(first.into)
        ),
    ))
}

/// Merges the joints of `plans` that lie too close to their kept ancestor (module
/// documentation): their plans become [`JointPlan::Skip`] with the reason, and they are
/// returned in the order of `skeleton.topological_order()`.
///
/// - `positions`: bind positions of the joints of `skeleton`.
/// - `overrides`: one per joint; a forced joint is never merged.
pub fn merge_dense_joints(
    skeleton: &Skeleton,
    positions: &[DVec3],
    overrides: &[Option<Override>],
    plans: &mut [JointPlan],
) -> Vec<MergedJoint> {
    debug_assert_eq!(plans.len(), skeleton.len());
    let mut kept: Vec<u32> = (0..skeleton.len() as u32).collect();
    let mut merged = Vec::new();
    for j in skeleton.topological_order() {
        let Some(parent) = skeleton.parent(j) else {
            continue;
        };
        let anchor = kept[parent] as usize;
        let frame = match &plans[j] {
            JointPlan::Boundary(frame) | JointPlan::Soft(frame, _) => frame,
            JointPlan::Skip(_) | JointPlan::Exclude(_) => continue,
        };
        if overrides[j] == Some(Override::Force) {
            continue;
        }
        let distance = positions[j].distance(positions[anchor]);
        let r = frame.surface_distance;
        if distance >= r / MERGE_DIVISOR {
            continue;
        }
        plans[j] = JointPlan::Skip(format!(
            "merged for cutting into {}: {distance:.3e} from it, under 1/{MERGE_DIVISOR} of \
             its depth in the body ({r:.3e}); it lies in that joint's region and moves no \
             skin of its own",
            skeleton.names[anchor]
        ));
        kept[j] = anchor as u32;
        merged.push(MergedJoint {
            joint: j as u32,
            into: anchor as u32,
            distance,
            surface_distance: r,
        });
    }
    merged
}
