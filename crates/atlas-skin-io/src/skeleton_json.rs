//! The project's own JSON skeleton format (documented in docs/formats.md):
//!
//! ```json
//! { "joints": [
//!     { "name": "hips",  "parent": null,   "position": [0, 1, 0] },
//!     { "name": "spine", "parent": "hips", "position": [0, 1.2, 0], "rotation": [0, 0, 0, 1] }
//! ] }
//! ```
//!
//! `position` is the joint's bind position in the mesh's space, `rotation` its optional
//! bind orientation as a unit quaternion `[x, y, z, w]` (identity when absent), `tail` the
//! optional end of its bone ([`Skeleton::tails`]). Joints may be listed in any order;
//! parents are named.

use crate::text::read_json;
use crate::IoError;
use atlas_skin_runtime::{Skeleton, NO_PARENT};
use glam::{Mat4, Quat, Vec3};
use serde::Deserialize;
use std::collections::HashMap;
use std::path::Path;

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct Document {
    joints: Vec<JointEntry>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct JointEntry {
    name: String,
    parent: Option<String>,
    position: [f32; 3],
    #[serde(default)]
    rotation: Option<[f32; 4]>,
    #[serde(default)]
    tail: Option<[f32; 3]>,
}

/// Reads the JSON skeleton at `path`. The inverse bind matrix of a joint at position p with
/// orientation q is (T(p) · R(q))⁻¹. Duplicate names, unknown parents, cycles, non-finite
/// numbers and rotations that are not unit quaternions are errors.
pub fn read(path: &Path) -> Result<Skeleton, IoError> {
    let document: Document = read_json(path)?;
    let mut inverse_bind = Vec::with_capacity(document.joints.len());
    for joint in &document.joints {
        let position = Vec3::from_array(joint.position);
        let rotation = Quat::from_array(joint.rotation.unwrap_or([0.0, 0.0, 0.0, 1.0]));
        if !position.is_finite() || !rotation.is_finite() {
            return Err(IoError::invalid(
                path,
                format!(
                    "joint {:?} has a non-finite position or rotation",
                    joint.name
                ),
            ));
        }
        if (rotation.length() - 1.0).abs() > 1e-3 {
            return Err(IoError::invalid(
                path,
                format!(
                    "joint {:?}: rotation {:?} is not a unit quaternion [x, y, z, w]",
                    joint.name,
                    rotation.to_array()
                ),
            ));
        }
        let bind = Mat4::from_rotation_translation(rotation.normalize(), position);
        inverse_bind.push(bind.inverse());
    }
    let tails = document
        .joints
        .iter()
        .map(|joint| joint.tail.map(Vec3::from_array))
        .collect();
    let (names, parents): (Vec<String>, Vec<Option<String>>) = document
        .joints
        .into_iter()
        .map(|joint| (joint.name, joint.parent))
        .unzip();
    skeleton_from_parent_names(path, names, &parents, inverse_bind)?
        .with_tails(tails)
        .map_err(|cause| IoError::Skeleton {
            path: path.to_path_buf(),
            cause,
        })
}

/// Builds a skeleton whose parents are given by name (`None` for a root), rejecting empty
/// and duplicate names, unknown parents and cycles.
pub(crate) fn skeleton_from_parent_names(
    path: &Path,
    names: Vec<String>,
    parent_names: &[Option<String>],
    inverse_bind: Vec<Mat4>,
) -> Result<Skeleton, IoError> {
    let mut index_of: HashMap<&str, u32> = HashMap::new();
    for (j, name) in names.iter().enumerate() {
        if name.is_empty() {
            return Err(IoError::invalid(
                path,
                format!("joint {j} has an empty name"),
            ));
        }
        if index_of.insert(name, j as u32).is_some() {
            return Err(IoError::invalid(
                path,
                format!("joint name {name:?} appears twice"),
            ));
        }
    }
    let parents = names
        .iter()
        .zip(parent_names)
        .map(|(name, parent)| match parent {
            None => Ok(NO_PARENT),
            Some(parent) => index_of.get(parent.as_str()).copied().ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!("joint {name:?} has unknown parent {parent:?}"),
                )
            }),
        })
        .collect::<Result<Vec<u32>, IoError>>()?;
    Skeleton::new(names, parents, inverse_bind).map_err(|cause| IoError::Skeleton {
        path: path.to_path_buf(),
        cause,
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;

    #[test]
    fn joints_in_any_order_with_rotation() {
        let text = r#"{"joints": [
            {"name": "tip", "parent": "root", "position": [0, 2, 0], "rotation": [0, 0, 0.70710677, 0.70710677]},
            {"name": "root", "parent": null, "position": [0, 1, 0], "tail": [0, 1.5, 0]}
        ]}"#;
        let skeleton = read(&scratch_file("s.json", text)).unwrap();
        assert_eq!(skeleton.names, ["tip", "root"]);
        assert_eq!(skeleton.parents, [1, NO_PARENT]);
        assert_eq!(skeleton.tails, [None, Some(Vec3::new(0.0, 1.5, 0.0))]);
        assert!(skeleton.bind_positions()[0].abs_diff_eq(Vec3::new(0.0, 2.0, 0.0), 1e-6));
        let x_axis = skeleton.bind_world()[0].x_axis.truncate();
        assert!(x_axis.abs_diff_eq(Vec3::Y, 1e-6), "{x_axis}");
    }

    #[test]
    fn broken_skeletons_are_errors() {
        let joint = |name: &str, parent: &str| {
            format!(r#"{{"name": "{name}", "parent": {parent}, "position": [0, 0, 0]}}"#)
        };
        let doc = |joints: &[String]| format!(r#"{{"joints": [{}]}}"#, joints.join(","));
        let cases = [
            (doc(&[joint("a", "\"b\""), joint("b", "\"a\"")]), "cycle"),
            (doc(&[joint("a", "\"x\"")]), "joint \"a\" has unknown parent \"x\""),
            (doc(&[joint("a", "null"), joint("a", "null")]), "\"a\" appears twice"),
            (doc(&[joint("", "null")]), "joint 0 has an empty name"),
            ("{\"joints\": [\n{\"name\": 3}]}".to_string(), ":2: invalid type"),
            ("{\"bones\": []}".to_string(), ":1: unknown field `bones`"),
            (
                r#"{"joints": [{"name": "a", "parent": null, "position": [0, 0, 0], "rotation": [0, 0, 0, 2]}]}"#
                    .to_string(),
                "not a unit quaternion",
            ),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error = read(&scratch_file(&format!("bad{i}.json"), text)).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}
