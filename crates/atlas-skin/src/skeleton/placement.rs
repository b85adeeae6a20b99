//! Whether the skeleton sits in the mesh, before the method and after its decomposition:
//! a skeleton entirely beside the mesh is refused; all joints at one point, joints beside
//! the mesh, duplicate joints at one point, zero-length bones, a majority of joints
//! outside the surface (a skeleton moved, flipped or scaled against its mesh) and a
//! decomposition without any boundary are warned about, never silent.

use crate::cuts::joint_roles::HELPER_REASON;
use crate::decomposition::{Decomposition, JointDecision, JointStatus};
use crate::geometry::bounding_box;
use crate::skeleton::nearest_point::PointGrid;
use crate::tolerance::NEGLIGIBLE;
use atlas_skin_runtime::Skeleton;
use glam::DVec3;
use thiserror::Error;

/// A skeleton the method cannot use on this mesh.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum PlacementError {
    #[error(
        "no joint lies within the mesh's bounding box: the skeleton's centre is {distance:.3} \
         from the mesh's ({ratio:.2} × the mesh diagonal); is it in another space or scale \
         than the mesh?"
    )]
    BesideMesh { distance: f64, ratio: f64 },
}

/// How far past the mesh's bounding box a joint may lie before it counts as beside the
/// mesh, as a fraction of the mesh diagonal (a toe tip or a head-top end joint may stick
/// out a little).
const BOX_MARGIN: f64 = 0.05;

/// Joint names listed in a warning.
const LISTED: usize = 8;

/// Checks the skeleton against the mesh (`vertices`: the welded mesh's positions) and
/// returns the warnings.
///
/// Joints within [`NEGLIGIBLE`] × the mesh diagonal of each other sit at one point.
///
/// # Errors
/// [`PlacementError::BesideMesh`] when every joint lies farther than `BOX_MARGIN` × the diagonal outside the mesh's
/// bounding box.
pub fn check_placement(
    skeleton: &Skeleton,
    vertices: &[DVec3],
) -> Result<Vec<String>, PlacementError> {
    let joints: Vec<DVec3> = skeleton
        .bind_positions()
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let (lo, hi) = bounding_box(vertices);
    let diagonal = (hi - lo).length();
    let same_point = NEGLIGIBLE * diagonal;
    let (joint_lo, joint_hi) = bounding_box(&joints);
    if joints.len() >= 2 && (joint_hi - joint_lo).length() <= same_point {
        // Nothing else to say of such a skeleton (Khronos' SimpleSkin binds both joints
        // at one point): the method runs, and this says why it cuts nothing.
        return Ok(vec![format!(
            "all {} joints sit at one point {:.4}: the skeleton has no bones, so no joint \
             gets a boundary (check the bind pose or inverse bind matrices)",
            joints.len(),
            joints[0]
        )]);
    }
    let margin = BOX_MARGIN * diagonal;
    let beside: Vec<usize> = (0..joints.len())
        .filter(|&j| {
            let p = joints[j];
            p.cmplt(lo - margin).any() || p.cmpgt(hi + margin).any()
        })
        .collect();
    if !joints.is_empty() && beside.len() == joints.len() {
        let distance = ((joint_lo + joint_hi) * 0.5).distance((lo + hi) * 0.5);
        return Err(PlacementError::BesideMesh {
            distance,
            ratio: distance / diagonal.max(f64::MIN_POSITIVE),
        });
    }
    let name = |j: usize| skeleton.names[j].as_str();
    let mut warnings = Vec::new();
    if !beside.is_empty() {
        warnings.push(format!(
            "{} of {} joints lie beside the mesh (outside its bounding box by more than {}% of \
             its diagonal): {}",
            beside.len(),
            joints.len(),
            BOX_MARGIN * 100.0,
            listed(beside.iter().map(|&j| name(j).to_string()))
        ));
    }
    let mut duplicates = Listed::default();
    let mut zero_bones = Listed::default();
    // Pairs found through a grid of the joints: a scan of every pair is quadratic in the
    // joints (5 · 10⁹ distances for 100,000). Only the listed pairs are named: thousands
    // of joints at one point make millions of pairs.
    let grid = PointGrid::new(&joints);
    for (a, &point) in joints.iter().enumerate() {
        for b in grid.within(point, same_point) {
            let b = b as usize;
            if b <= a {
                continue;
            }
            let linked = skeleton.parent(a) == Some(b) || skeleton.parent(b) == Some(a);
            let pairs = if linked {
                &mut zero_bones
            } else {
                &mut duplicates
            };
            pairs.push(|| format!("{}/{}", name(a), name(b)));
        }
    }
    if duplicates.count > 0 {
        warnings.push(format!(
            "{} pair(s) of joints that are not parent and child sit at one point: {}",
            duplicates.count,
            duplicates.text()
        ));
    }
    if zero_bones.count > 0 {
        warnings.push(format!(
            "{} bone(s) have zero length (no direction to cut across there): {}",
            zero_bones.count,
            zero_bones.text()
        ));
    }
    Ok(warnings)
}

/// Items counted, of which the first [`LISTED`] are named.
#[derive(Default)]
struct Listed {
    count: usize,
    shown: Vec<String>,
}

impl Listed {
    /// Counts an item, named by `name` if it is among the first [`LISTED`].
    fn push(&mut self, name: impl FnOnce() -> String) {
        if self.shown.len() < LISTED {
            self.shown.push(name());
        }
        self.count += 1;
    }

    /// The names, comma-separated, and how many more.
    fn text(&self) -> String {
        let more = self.count - self.shown.len();
        if more > 0 {
            format!("{}, and {more} more", self.shown.join(", "))
        } else {
            self.shown.join(", ")
        }
    }
}

/// Warnings about what the decomposition made of the skeleton: most joints outside the
/// surface owning nothing (`forbidden`: the joints the user or the input forbade, which
/// are not counted), or no boundary at all on a skeleton of several joints.
pub fn decomposition_warnings(decomposition: &Decomposition, forbidden: &[String]) -> Vec<String> {
    let joints = &decomposition.joints;
    let mut warnings = Vec::new();
    let is_helper =
        |j: &JointDecision| matches!(&j.status, JointStatus::Skipped(r) if r == HELPER_REASON);
    let helpers: Vec<String> = joints
        .iter()
        .filter(|j| is_helper(j))
        .map(|j| j.name.clone())
        .collect();
    if !helpers.is_empty() {
        warnings.push(format!(
            "{} joint(s) named as helpers that deform nothing (attachment slots, locators, IK \
             targets) move no skin; `--force JOINT` weights one: {}",
            helpers.len(),
            listed(helpers.into_iter())
        ));
    }
    let outside: Vec<String> = joints
        .iter()
        .filter(|j| !j.owns_skin && !forbidden.contains(&j.name) && !is_helper(j))
        .map(|j| j.name.clone())
        .collect();
    if joints.len() >= 2 && 2 * outside.len() >= joints.len() {
        warnings.push(format!(
            "{} of {} joints lie outside the surface and own none of it: the skeleton may not \
             sit in the body (moved, flipped or scaled against the mesh?): {}",
            outside.len(),
            joints.len(),
            listed(outside.into_iter())
        ));
    }
    for shared in &decomposition.shared_sides {
        warnings.push(format!(
            "the surface joins the sides of the cuts of {} (a higher genus: a hand fused to \
             the body, a part welded across a joint): their region was divided among them by \
             the bones behind each face",
            listed(
                shared
                    .joints
                    .iter()
                    .map(|&j| joints[j as usize].name.clone())
            )
        ));
    }
    if joints.len() >= 2 && decomposition.boundaries.is_empty() {
        warnings.push(format!(
            "no joint got a boundary: the whole mesh is {} region(s), with no transition \
             between joints (see each joint's reason in the decomposition)",
            decomposition.regions.len()
        ));
    }
    warnings
}

/// Up to [`LISTED`] items, comma-separated, and how many more.
pub(crate) fn listed(items: impl ExactSizeIterator<Item = String>) -> String {
    let count = items.len();
    Listed {
        count,
        shown: items.take(LISTED).collect(),
    }
    .text()
}
