//! Whether the skeleton sits in the mesh, before the method runs: a skeleton entirely
//! beside the mesh is refused; all joints at one point, joints beside the mesh, duplicate
//! joints at one point and zero-length bones are warned about, never silent. What the
//! decomposition then made of the skeleton (most joints owning no skin, no boundary at
//! all) is warned about after it ([`crate::report::decomposition_warnings`]).

use crate::geometry::bounding_box;
use crate::skeleton::nearest_point::JointPoints;
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
    // Pairs counted by position and named from the first joints on: thousands of
    // joints at one point make millions of pairs, and a scan of every pair is quadratic
    // in the joints (5 · 10⁹ distances for 100,000).
    let points = JointPoints::within_radius(joints, same_point);
    let mut linked: Vec<(usize, usize)> = (0..skeleton.len())
        .filter_map(|j| {
            let parent = skeleton.parent(j)?;
            points
                .same_point(j, parent)
                .then_some((j.min(parent), j.max(parent)))
        })
        .collect();
    linked.sort_unstable();
    let pair_name = |&(a, b): &(usize, usize)| format!("{}/{}", name(a), name(b));
    let zero_bones = Listed {
        count: linked.len(),
        shown: linked.iter().take(LISTED).map(pair_name).collect(),
    };
    let unlinked = (0..skeleton.len())
        .flat_map(|a| points.after(a).into_iter().map(move |b| (a, b as usize)))
        .filter(|pair| linked.binary_search(pair).is_err());
    let duplicates = Listed {
        count: points.pair_count() - linked.len(),
        shown: unlinked.take(LISTED).map(|pair| pair_name(&pair)).collect(),
    };
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
struct Listed {
    count: usize,
    shown: Vec<String>,
}

impl Listed {
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

/// Up to [`LISTED`] items, comma-separated, and how many more.
pub(crate) fn listed(items: impl ExactSizeIterator<Item = String>) -> String {
    let count = items.len();
    Listed {
        count,
        shown: items.take(LISTED).collect(),
    }
    .text()
}

#[cfg(test)]
mod tests {
    use super::*;
    use atlas_skin_runtime::NO_PARENT;
    use glam::Vec3;

    /// The pairs at one point, counted and named as a scan of every pair in order finds
    /// them: a zero-length bone at the root, three siblings at one point, and 40 siblings at
    /// another with a child of the last one there (more pairs of each kind than are named).
    #[test]
    fn pairs_at_one_point_as_a_scan_of_every_pair() {
        let (a, b) = (Vec3::new(0.2, 0.5, 0.0), Vec3::new(0.4, 0.1, 0.3));
        let mut positions = vec![Vec3::ZERO, Vec3::ZERO, a, a, a];
        let mut parents = vec![NO_PARENT, 0, 1, 1, 1];
        for k in 0..40 {
            positions.push(b);
            parents.push(if k % 3 == 0 { 0 } else { 1 });
        }
        positions.push(b);
        parents.push(44);
        let names = (0..positions.len()).map(|j| format!("j{j}")).collect();
        let skeleton = Skeleton::from_positions(names, parents, &positions).unwrap();
        let box_corners = [DVec3::splat(-1.0), DVec3::splat(1.0)];
        let warnings = check_placement(&skeleton, &box_corners).unwrap();

        let same_point = NEGLIGIBLE * (box_corners[1] - box_corners[0]).length();
        let scan = |linked: bool| {
            let mut listed = Listed {
                count: 0,
                shown: Vec::new(),
            };
            for j in 0..positions.len() {
                for k in j + 1..positions.len() {
                    let close =
                        positions[j].as_dvec3().distance(positions[k].as_dvec3()) <= same_point;
                    let is_bone = skeleton.parent(k) == Some(j) || skeleton.parent(j) == Some(k);
                    if close && is_bone == linked {
                        if listed.shown.len() < LISTED {
                            listed.shown.push(format!("j{j}/j{k}"));
                        }
                        listed.count += 1;
                    }
                }
            }
            listed
        };
        let (duplicates, zero_bones) = (scan(false), scan(true));
        assert_eq!(
            (duplicates.count, zero_bones.count),
            (3 + 41 * 40 / 2 - 1, 2)
        );
        let expected = [
            format!(
                "{} pair(s) of joints that are not parent and child sit at one point: {}",
                duplicates.count,
                duplicates.text()
            ),
            format!(
                "{} bone(s) have zero length (no direction to cut across there): {}",
                zero_bones.count,
                zero_bones.text()
            ),
        ];
        assert_eq!(warnings, expected);
    }
}
