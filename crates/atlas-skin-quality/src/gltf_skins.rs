//! What a glTF file holds in skinned meshes, read from its JSON directly (not through the
//! project's reader): to tell when the reader took fewer vertices than the file skins.

use anyhow::{bail, Context, Result};
use serde_json::Value;
use std::path::Path;

/// The skinned meshes of a glTF document.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct SkinnedMeshes {
    /// Nodes that have both a mesh and a skin.
    pub nodes: usize,
    /// Distinct skins those nodes use.
    pub skins: usize,
    /// Vertices of their primitives (POSITION accessor counts), per node.
    pub vertices: usize,
}

/// Reads the JSON of a `.glb` (its first chunk) or a `.gltf` file.
pub fn skinned_meshes(path: &Path) -> Result<SkinnedMeshes> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    let json = if bytes.starts_with(b"glTF") {
        glb_json(&bytes).with_context(|| format!("{}: not a glTF binary", path.display()))?
    } else {
        &bytes[..]
    };
    let document: Value = serde_json::from_slice(json)
        .with_context(|| format!("{}: the glTF JSON does not parse", path.display()))?;
    Ok(count(&document))
}

/// The JSON chunk of a glTF binary: a 12-byte header, then chunk length, type `JSON`, data.
fn glb_json(bytes: &[u8]) -> Result<&[u8]> {
    let word = |at: usize| -> Result<u32> {
        let slice = bytes.get(at..at + 4).context("truncated header")?;
        Ok(u32::from_le_bytes(slice.try_into()?))
    };
    let length = word(12)? as usize;
    if &bytes.get(16..20).context("truncated header")? != b"JSON" {
        bail!("the first chunk is not JSON");
    }
    bytes.get(20..20 + length).context("truncated JSON chunk")
}

fn count(document: &Value) -> SkinnedMeshes {
    let empty = Vec::new();
    let list = |key: &str| document[key].as_array().unwrap_or(&empty);
    let accessors = list("accessors");
    let meshes = list("meshes");
    let mut skins: Vec<u64> = Vec::new();
    let mut result = SkinnedMeshes {
        nodes: 0,
        skins: 0,
        vertices: 0,
    };
    for node in list("nodes") {
        let (Some(mesh), Some(skin)) = (node["mesh"].as_u64(), node["skin"].as_u64()) else {
            continue;
        };
        result.nodes += 1;
        if !skins.contains(&skin) {
            skins.push(skin);
        }
        let primitives = meshes
            .get(mesh as usize)
            .and_then(|m| m["primitives"].as_array())
            .unwrap_or(&empty);
        result.vertices += primitives
            .iter()
            .filter_map(|p| p["attributes"]["POSITION"].as_u64())
            .filter_map(|a| accessors.get(a as usize)?["count"].as_u64())
            .sum::<u64>() as usize;
    }
    result.skins = skins.len();
    result
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn skinned_nodes_skins_and_vertices_are_counted() {
        let document = json!({
            "accessors": [{"count": 10}, {"count": 5}, {"count": 7}],
            "meshes": [
                {"primitives": [{"attributes": {"POSITION": 0}}, {"attributes": {"POSITION": 1}}]},
                {"primitives": [{"attributes": {"POSITION": 2}}]}
            ],
            "nodes": [
                {"mesh": 0, "skin": 0},
                {"mesh": 1, "skin": 1},
                {"mesh": 1, "skin": 0},
                {"mesh": 1},
                {"children": [0]}
            ]
        });
        assert_eq!(
            count(&document),
            SkinnedMeshes {
                nodes: 3,
                skins: 2,
                vertices: 29
            }
        );
    }

    #[test]
    fn the_robot_has_four_skinned_meshes() {
        let path = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/bench/robotexpressive/RobotExpressive.glb"
        );
        let robot = skinned_meshes(Path::new(path)).expect("../shared/data/bench is missing");
        assert_eq!((robot.nodes, robot.skins), (4, 4));
        assert!(robot.vertices > 256);
    }

    #[test]
    fn broken_files_are_errors_naming_them() {
        let dir = std::env::temp_dir().join(format!("gltf-skins-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("broken.glb");
        std::fs::write(&path, b"glTF\x02\0\0\0\x20\0\0\0\x10\0\0\0BIN\0").unwrap();
        let error = format!("{:#}", skinned_meshes(&path).unwrap_err());
        assert!(
            error.contains("broken.glb") && error.contains("not JSON"),
            "{error}"
        );
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
