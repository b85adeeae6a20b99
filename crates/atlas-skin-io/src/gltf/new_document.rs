//! A new skinned glTF document for a character that was not read from glTF.

use super::animation::append_clips;
use super::builder::{GlbBuilder, ARRAY_BUFFER};
use super::write::{
    merge_asset_extras, pack_weights, push_inverse_binds, push_weight_accessors, WriteOptions,
};
use crate::{Character, IoError};
use atlas_skin_runtime::{Skeleton, VertexWeights};
use glam::Vec3;
use serde_json::{json, Map};
use std::path::Path;

/// The `.glb` bytes of a document with one skinned mesh and the skeleton as joint nodes.
///
/// - Mesh: the vertices used by a triangle, in stored order (so their weight rows keep
///   their order), POSITION with min/max, smooth NORMAL, JOINTS_n/WEIGHTS_n, one
///   primitive (indices) per material of the character ([`Character::materials`]: base
///   colour, not metallic), or one without material.
/// - Joints: nodes 0..#J named as in the skeleton, with the rest local transform
///   `bind_world[parent]⁻¹ · bind_world[j]` as T/R/S; the skin's inverseBindMatrices are the
///   skeleton's; `skin.skeleton` is the root joint when there is one root.
/// - Scene: the mesh node (after the joints) and the root joints.
pub(crate) fn new_document(
    character: &Character,
    skeleton: &Skeleton,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let mesh = &character.mesh;
    let mut used = vec![false; mesh.positions.len()];
    for &v in mesh.triangles.iter().flatten() {
        let slot = used.get_mut(v as usize).ok_or_else(|| {
            IoError::invalid(
                &character.path,
                format!("triangle vertex {v} is out of range"),
            )
        })?;
        *slot = true;
    }
    let kept: Vec<usize> = (0..used.len()).filter(|&v| used[v]).collect();
    if kept.is_empty() {
        return Err(IoError::invalid(
            &character.path,
            "the mesh has no triangle",
        ));
    }
    let mut new_index = vec![0u32; used.len()];
    for (new, &old) in kept.iter().enumerate() {
        new_index[old] = new as u32;
    }
    let positions: Vec<Vec3> = kept.iter().map(|&v| mesh.positions[v]).collect();
    let triangles: Vec<[u32; 3]> = mesh
        .triangles
        .iter()
        .map(|t| t.map(|v| new_index[v as usize]))
        .collect();

    let mut builder = GlbBuilder::new(Map::new());
    builder.json_mut().insert(
        "asset".into(),
        json!({"version": "2.0", "generator": "atlas-skin"}),
    );
    let flat =
        |vectors: &[Vec3]| -> Vec<f32> { vectors.iter().flat_map(|p| p.to_array()).collect() };
    let position_values: Vec<f32> = flat(&positions);
    let position = builder.push_f32_accessor(&position_values, "VEC3", true, Some(ARRAY_BUFFER));
    let normals = smooth_normals(&positions, &triangles);
    let normal = builder.push_f32_accessor(&flat(&normals), "VEC3", false, Some(ARRAY_BUFFER));
    let packed = pack_weights(weights, kept.iter().copied(), options.max_influences);
    let sets = push_weight_accessors(&mut builder, &packed, skeleton.len());
    let mut attributes = json!({"POSITION": position, "NORMAL": normal});
    for (set, (joints, weights)) in sets.into_iter().enumerate() {
        attributes[format!("JOINTS_{set}")] = json!(joints);
        attributes[format!("WEIGHTS_{set}")] = json!(weights);
    }
    let mut primitives = Vec::new();
    for (material, group) in material_groups(character, &triangles) {
        let indices = builder.push_indices(&group, positions.len());
        let mut primitive = json!({"attributes": attributes, "indices": indices});
        if let Some(material) = material {
            primitive["material"] = json!(material);
        }
        primitives.push(primitive);
    }
    for material in &character.materials {
        builder.push_item(
            "materials",
            json!({
                "name": material.name,
                "pbrMetallicRoughness": {
                    "baseColorFactor": material.base_color,
                    "metallicFactor": 0.0,
                },
            }),
        );
    }
    let name = character
        .path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| "mesh".into());
    builder.push_item("meshes", json!({"name": name, "primitives": primitives}));

    let children = skeleton.children();
    for (j, local) in skeleton.rest_local().iter().enumerate() {
        let (scale, rotation, translation) = local.to_scale_rotation_translation();
        let mut node = json!({
            "name": skeleton.names[j],
            "translation": translation.to_array(),
            "rotation": rotation.normalize().to_array(),
            "scale": scale.to_array(),
        });
        if !children[j].is_empty() {
            node["children"] = json!(children[j]);
        }
        builder.push_item("nodes", node);
    }
    let inverse_bind = push_inverse_binds(&mut builder, skeleton);
    let roots: Vec<usize> = (0..skeleton.len())
        .filter(|&j| skeleton.parent(j).is_none())
        .collect();
    let mut skin = json!({
        "joints": (0..skeleton.len()).collect::<Vec<_>>(),
        "inverseBindMatrices": inverse_bind,
    });
    if let [root] = roots[..] {
        skin["skeleton"] = json!(root);
    }
    builder.push_item("skins", skin);
    let mesh_node = builder.push_item("nodes", json!({"name": name, "mesh": 0, "skin": 0}));
    let scene_nodes: Vec<usize> = std::iter::once(mesh_node).chain(roots).collect();
    builder.push_item("scenes", json!({"nodes": scene_nodes}));
    builder.json_mut().insert("scene".into(), json!(0));

    let joint_nodes: Vec<usize> = (0..skeleton.len()).collect();
    append_clips(&mut builder, &options.animations, &joint_nodes, out)?;
    if let Some(extras) = &options.extras {
        merge_asset_extras(builder.json_mut(), extras);
    }
    Ok(builder.finish())
}

/// The triangles of each material in order of first use (`None`: no material); all
/// triangles in one group when the character has no materials (or not one per triangle).
fn material_groups(
    character: &Character,
    triangles: &[[u32; 3]],
) -> Vec<(Option<u32>, Vec<[u32; 3]>)> {
    if character.materials.is_empty() || character.triangle_materials.len() != triangles.len() {
        return vec![(None, triangles.to_vec())];
    }
    let mut groups: Vec<(Option<u32>, Vec<[u32; 3]>)> = Vec::new();
    for (&material, &triangle) in character.triangle_materials.iter().zip(triangles) {
        match groups.iter_mut().find(|(m, _)| *m == material) {
            Some((_, group)) => group.push(triangle),
            None => groups.push((material, vec![triangle])),
        }
    }
    groups
}

/// Smooth vertex normals: `n_v = normalize(Σ_{t ∋ v} (p_b − p_a) × (p_c − p_a))`, the
/// area-weighted mean of the incident face normals; +Y where that sum vanishes (isolated or
/// degenerate fans), since glTF requires unit normals.
pub(crate) fn smooth_normals(positions: &[Vec3], triangles: &[[u32; 3]]) -> Vec<Vec3> {
    let mut sums = vec![Vec3::ZERO; positions.len()];
    for &[a, b, c] in triangles {
        let (pa, pb, pc) = (
            positions[a as usize],
            positions[b as usize],
            positions[c as usize],
        );
        let area_normal = (pb - pa).cross(pc - pa);
        for v in [a, b, c] {
            sums[v as usize] += area_normal;
        }
    }
    sums.into_iter()
        .map(|n| n.try_normalize().unwrap_or(Vec3::Y))
        .collect()
}
