//! Skinned meshes added to a finished skinned glb: meshes that were not in the character's
//! file (the targets of `atlas-skin transfer`: clothes, hair, props), bound to its skin.

use super::builder::{GlbBuilder, ARRAY_BUFFER};
use super::container::split_glb;
use super::new_document::smooth_normals;
use super::write::{pack_weights, push_weight_accessors};
use crate::IoError;
use atlas_skin_runtime::VertexWeights;
use glam::Vec3;
use serde_json::{json, Value};
use std::path::Path;

/// A mesh to add: its name, vertices in the skin's bind space (the space of the skinned
/// meshes' positions), triangles and one weight row per vertex (joints of the skin).
#[derive(Debug, Clone, Copy)]
pub struct AddedMesh<'a> {
    pub name: &'a str,
    pub positions: &'a [Vec3],
    pub triangles: &'a [[u32; 3]],
    pub weights: &'a VertexWeights,
}

/// `glb` (a skinned glTF binary as [`super::skinned_glb`] writes it) with `meshes` added:
/// each a mesh (POSITION with bounds, smooth NORMAL, JOINTS_n/WEIGHTS_n packed as the
/// skinned writer packs them: the `max_influences` largest, summing to 1 in float32,
/// indices) instantiated by a new node with the skin of the document's first skinned
/// node, listed in the default scene. `out` names the output in errors.
///
/// # Errors
/// [`IoError::Invalid`] when `glb` is not a glb with a skinned node, or a mesh's weight
/// rows do not match its vertices or the skin's joints, or a triangle is out of range.
pub fn with_added_meshes(
    glb: &[u8],
    meshes: &[AddedMesh],
    max_influences: usize,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let (json_range, bin_range) = split_glb(out, glb)?;
    let json: Value = serde_json::from_slice(&glb[json_range])
        .map_err(|e| IoError::invalid(out, format!("bad glb JSON: {e}")))?;
    let Value::Object(json) = json else {
        return Err(IoError::invalid(out, "the glb's JSON is not an object"));
    };
    let bin = bin_range.map(|r| glb[r].to_vec()).unwrap_or_default();
    let nodes = json.get("nodes").and_then(Value::as_array);
    let skin = nodes
        .and_then(|nodes| nodes.iter().find_map(|n| n.get("skin")?.as_u64()))
        .ok_or_else(|| IoError::invalid(out, "the glb has no skinned node"))?
        as usize;
    let joint_count = json
        .get("skins")
        .and_then(|s| s.get(skin)?.get("joints")?.as_array().map(Vec::len))
        .ok_or_else(|| IoError::invalid(out, format!("skin {skin} has no joints")))?;
    let scene = json.get("scene").and_then(Value::as_u64).unwrap_or(0) as usize;
    let mut builder = GlbBuilder::from_parts(json, bin);
    for mesh in meshes {
        let invalid =
            |message: String| IoError::invalid(out, format!("mesh {}: {message}", mesh.name));
        let n = mesh.positions.len();
        if mesh.weights.vertex_count() != n {
            return Err(invalid(format!(
                "{} weight rows for {n} vertices",
                mesh.weights.vertex_count()
            )));
        }
        mesh.weights
            .validate(joint_count)
            .map_err(|e| invalid(format!("bad weights: {e}")))?;
        if let Some(&v) = mesh.triangles.iter().flatten().find(|&&v| v as usize >= n) {
            return Err(invalid(format!("triangle vertex {v} is out of range")));
        }
        let flat =
            |vectors: &[Vec3]| -> Vec<f32> { vectors.iter().flat_map(|p| p.to_array()).collect() };
        let position =
            builder.push_f32_accessor(&flat(mesh.positions), "VEC3", true, Some(ARRAY_BUFFER));
        let normals = smooth_normals(mesh.positions, mesh.triangles);
        let normal = builder.push_f32_accessor(&flat(&normals), "VEC3", false, Some(ARRAY_BUFFER));
        let packed = pack_weights(mesh.weights, 0..n, max_influences);
        let mut attributes = json!({"POSITION": position, "NORMAL": normal});
        for (set, (joints, weights)) in push_weight_accessors(&mut builder, &packed, joint_count)
            .into_iter()
            .enumerate()
        {
            attributes[format!("JOINTS_{set}")] = json!(joints);
            attributes[format!("WEIGHTS_{set}")] = json!(weights);
        }
        let indices = builder.push_indices(mesh.triangles, n);
        let index = builder.push_item(
            "meshes",
            json!({"name": mesh.name, "primitives": [{"attributes": attributes, "indices": indices}]}),
        );
        let node = builder.push_item(
            "nodes",
            json!({"name": mesh.name, "mesh": index, "skin": skin}),
        );
        let json = builder.json_mut();
        let scenes = json
            .entry("scenes")
            .or_insert_with(|| json!([{"nodes": []}]));
        let Some(scene) = scenes.get_mut(scene) else {
            return Err(IoError::invalid(
                out,
                format!("the glb has no scene {scene}"),
            ));
        };
        match scene.get_mut("nodes").and_then(Value::as_array_mut) {
            Some(list) => list.push(json!(node)),
            None => scene["nodes"] = json!([node]),
        }
    }
    Ok(builder.finish())
}
