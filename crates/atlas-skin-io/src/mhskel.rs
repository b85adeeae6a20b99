//! MakeHuman `.mhskel` skeletons (JSON): bones whose head and tail are given as lists of
//! base-mesh vertices rather than coordinates.

use crate::skeleton_json::skeleton_from_parent_names;
use crate::text::read_json;
use crate::IoError;
use atlas_skin_runtime::Skeleton;
use glam::{Mat4, Vec3};
use serde::Deserialize;
use std::collections::{BTreeMap, HashMap};
use std::path::Path;

#[derive(Deserialize)]
struct Document {
    bones: BTreeMap<String, Bone>,
    joints: HashMap<String, Vec<u64>>,
}

#[derive(Deserialize)]
struct Bone {
    head: String,
    #[serde(default)]
    tail: Option<String>,
    parent: Option<String>,
}

/// Reads the `.mhskel` at `path`. Each bone becomes a joint named after it (in name order)
/// at its head: `head = (1/n) Σ file_positions[v]` over the n vertices the file lists for
/// the head's joint entry; its tail, when the file gives one, is placed the same way
/// ([`Skeleton::tails`]). `file_positions` is the base mesh's full vertex list in file
/// order (base.obj, before any group selection).
pub fn read(path: &Path, file_positions: &[Vec3]) -> Result<Skeleton, IoError> {
    let document: Document = read_json(path)?;
    let mut names = Vec::with_capacity(document.bones.len());
    let mut parents = Vec::with_capacity(document.bones.len());
    let mut inverse_bind = Vec::with_capacity(document.bones.len());
    let mut tails = Vec::with_capacity(document.bones.len());
    for (name, bone) in &document.bones {
        let place = |joint: &str| joint_position(path, &document, file_positions, name, joint);
        let head = place(&bone.head)?;
        tails.push(bone.tail.as_deref().map(place).transpose()?);
        names.push(name.clone());
        parents.push(bone.parent.clone().filter(|p| !p.is_empty()));
        inverse_bind.push(Mat4::from_translation(-head));
    }
    skeleton_from_parent_names(path, names, &parents, inverse_bind)?
        .with_tails(tails)
        .map_err(|cause| IoError::Skeleton {
            path: path.to_path_buf(),
            cause,
        })
}

/// The mean of the base-mesh vertices listed for `joint`, an end of bone `bone`.
fn joint_position(
    path: &Path,
    document: &Document,
    file_positions: &[Vec3],
    bone: &str,
    joint: &str,
) -> Result<Vec3, IoError> {
    let vertices = document.joints.get(joint).ok_or_else(|| {
        IoError::invalid(
            path,
            format!("bone {bone:?}: joint {joint:?} is not in \"joints\""),
        )
    })?;
    if vertices.is_empty() {
        return Err(IoError::invalid(
            path,
            format!("bone {bone:?}: joint {joint:?} lists no vertex"),
        ));
    }
    let mut sum = Vec3::ZERO;
    for &v in vertices {
        let position = usize::try_from(v)
            .ok()
            .and_then(|v| file_positions.get(v))
            .ok_or_else(|| {
                IoError::invalid(
                    path,
                    format!(
                        "bone {bone:?}: vertex {v} is out of range (the mesh file has {} vertices)",
                        file_positions.len()
                    ),
                )
            })?;
        sum += *position;
    }
    Ok(sum / vertices.len() as f32)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::text::scratch_file;
    use atlas_skin_runtime::NO_PARENT;

    fn positions() -> Vec<Vec3> {
        vec![
            Vec3::ZERO,
            Vec3::new(2.0, 0.0, 0.0),
            Vec3::new(0.0, 4.0, 0.0),
        ]
    }

    #[test]
    fn heads_are_means_of_listed_vertices() {
        let text = r#"{"name": "test", "bones": {
            "upper": {"head": "upper____head", "tail": "t", "parent": "root", "reference": null},
            "root": {"head": "root____head", "tail": "t", "parent": null}
        }, "joints": {"upper____head": [2], "root____head": [0, 1], "t": [1]}}"#;
        let skeleton = read(&scratch_file("s.mhskel", text), &positions()).unwrap();
        assert_eq!(skeleton.names, ["root", "upper"]);
        assert_eq!(skeleton.parents, [NO_PARENT, 0]);
        assert_eq!(
            skeleton.bind_positions(),
            [Vec3::X, Vec3::new(0.0, 4.0, 0.0)]
        );
        let tail = Some(Vec3::new(2.0, 0.0, 0.0));
        assert_eq!(skeleton.tails, [tail, tail]);
    }

    #[test]
    fn broken_skeletons_are_errors() {
        let bone = |parent: &str, vertices: &str| {
            format!(
                r#"{{"bones": {{"a": {{"head": "h", "parent": {parent}}}, "b": {{"head": "h", "parent": "a"}}}},
                "joints": {{"h": {vertices}}}}}"#
            )
        };
        let cases = [
            (bone("\"b\"", "[0]"), "cycle"),
            (
                bone("null", "[7]"),
                "bone \"a\": vertex 7 is out of range (the mesh file has 3 vertices)",
            ),
            (bone("null", "[]"), "lists no vertex"),
            (bone("\"z\"", "[0]"), "unknown parent \"z\""),
            (
                r#"{"bones": {"a": {"head": "q", "parent": null}}, "joints": {}}"#.to_string(),
                "joint \"q\" is not in \"joints\"",
            ),
            (
                r#"{"bones": {"a": {"head": "h", "tail": "t", "parent": null}}, "joints": {"h": [0]}}"#
                    .to_string(),
                "bone \"a\": joint \"t\" is not in \"joints\"",
            ),
            ("{\"bones\": 1}".to_string(), ":1: invalid type"),
        ];
        for (i, (text, expected)) in cases.iter().enumerate() {
            let error =
                read(&scratch_file(&format!("bad{i}.mhskel"), text), &positions()).unwrap_err();
            assert!(
                error.to_string().contains(expected),
                "{error} lacks {expected}"
            );
        }
    }
}
