//! New skin weights into a copy of the input glTF document, everything else preserved.

use super::animation::append_clips;
use super::bindings::node_positions;
use super::builder::{component_bounds, point_bounds, GlbBuilder};
use super::container::view_span_limit;
use super::new_document::smooth_normals;
use super::prune::{drop_orphans, References};
use super::write::{
    merge_asset_extras, pack_weights, push_inverse_binds, push_weight_accessors, WriteOptions,
};
use super::{Binding, GltfSource};
use crate::{Character, IoError};
use atlas_skin_runtime::VertexWeights;
use serde_json::{json, Map, Value};
use std::collections::{BTreeMap, BTreeSet};
use std::ops::Range;
use std::path::Path;

/// The `.glb` bytes of the input document with new weights.
///
/// Every bufferView is copied into the single output buffer (its offset keeps its phase
/// modulo 4, so accessors inside stay aligned); images with a URI are embedded as
/// bufferViews. For each POSITION accessor of a skinned mesh read into `character.mesh`,
/// new JOINTS_n and WEIGHTS_n accessors (joint indices in the order of that mesh's skin)
/// are made once and put on every primitive of the skinned meshes using that POSITION
/// accessor (rigid meshes under joint nodes stay as they are); JOINTS_n/WEIGHTS_n sets beyond the new ones are removed.
/// The accessors, bufferViews and bytes only the old weights used are then dropped, and a
/// view they shared with other data is cut to what that data reads (see
/// [`drop_orphans`]); what the input itself left unreferenced stays.
pub(crate) fn rewrite_document(
    character: &Character,
    source: &GltfSource,
    document: Value,
    weights: &VertexWeights,
    options: &WriteOptions,
    out: &Path,
) -> Result<Vec<u8>, IoError> {
    let input = &character.path;
    let Value::Object(json) = document else {
        return Err(IoError::invalid(
            input,
            "the glTF document is not a JSON object",
        ));
    };
    let skinned_meshes: BTreeSet<usize> = source.primitives.iter().map(|p| p.mesh).collect();
    refuse_joints_with_skinned_meshes(&json, source.skin, &skinned_meshes, input)?;
    let capacity = output_capacity(&json, source, character, options);
    let mut builder = GlbBuilder::with_capacity(json, capacity);
    let input_references = References::of_input(builder.json_mut());
    copy_buffer_views(&mut builder, source, input)?;
    embed_images(&mut builder, source, input)?;

    // The skins are read from the output's document, which has them as the input had.
    let joint_nodes = skin_joint_nodes(builder.json_mut(), source.skin, input)?;
    let joint_count = character.skeleton.as_ref().map_or(0, |s| s.len());
    if joint_count != joint_nodes.len() {
        return Err(IoError::invalid(
            out,
            format!(
                "the skeleton has {joint_count} joints but the document's skin has {}",
                joint_nodes.len()
            ),
        ));
    }
    // New accessors per block of vertices read (a POSITION accessor in one bind space),
    // and the accessors of every (skinned mesh, POSITION accessor).
    let mut block_sets: BTreeMap<usize, Vec<(usize, usize)>> = BTreeMap::new();
    let mut new_sets: BTreeMap<(usize, usize), Vec<(usize, usize)>> = BTreeMap::new();
    for primitive in &source.primitives {
        let Binding::Skin(skin) = primitive.binding else {
            continue;
        };
        let first = primitive.vertices.start;
        if let std::collections::btree_map::Entry::Vacant(entry) = block_sets.entry(first) {
            let skin_nodes = skin_joint_nodes(builder.json_mut(), Some(skin), input)?;
            let skin_weights = in_skin_order(
                weights,
                primitive.vertices.clone(),
                &joint_nodes,
                &skin_nodes,
            );
            let packed = pack_weights(
                &skin_weights,
                0..primitive.vertices.len(),
                options.max_influences,
            );
            let accessors = push_weight_accessors(&mut builder, &packed, joint_count);
            entry.insert(accessors);
        }
        new_sets.insert(
            (primitive.mesh, primitive.position_accessor),
            block_sets[&first].clone(),
        );
    }
    replace_weight_attributes(builder.json_mut(), &new_sets);
    set_position_bounds(builder.json_mut(), character, source);
    let mut builder = repair_normals(builder, character, source);
    if let (true, Some(skeleton), Some(skin)) = (
        source.inverse_binds_cleaned,
        character.skeleton.as_ref(),
        source.skin,
    ) {
        let accessor = push_inverse_binds(&mut builder, skeleton);
        let skin = builder
            .json_mut()
            .get_mut("skins")
            .and_then(|skins| skins.get_mut(skin))
            .and_then(Value::as_object_mut);
        if let Some(skin) = skin {
            skin.insert("inverseBindMatrices".into(), json!(accessor));
        }
    }

    append_clips(&mut builder, &options.animations, &joint_nodes, out)?;
    if let Some(extras) = &options.extras {
        merge_asset_extras(builder.json_mut(), extras);
    }
    Ok(drop_orphans(builder, input_references.as_ref()).finish())
}

/// Room for the output's bytes, so that its buffer is allocated once (see
/// [`GlbBuilder::with_capacity`]; an estimate: too little only costs a copy): the input's
/// bufferViews and images with their alignment, the new weights (at most 32 bytes per
/// vertex and set of 4), inverse bind matrices, and [`JSON_BYTES_PER_ITEM`] per item of
/// the document's top-level arrays for the header and JSON put in front at the end.
fn output_capacity(
    json: &Map<String, Value>,
    source: &GltfSource,
    character: &Character,
    options: &WriteOptions,
) -> usize {
    let items = |key: &str| {
        json.get(key)
            .and_then(Value::as_array)
            .map_or(&[][..], Vec::as_slice)
    };
    // Declared lengths, but never more than the reader lets views span (a document built
    // by hand with absurd lengths fails in the copy, not in reserving memory).
    let buffer_bytes = source.buffers.iter().map(|b| b.len() as u64).sum::<u64>();
    let views = items("bufferViews")
        .iter()
        .filter_map(|view| view.get("byteLength").and_then(Value::as_u64))
        .fold(0u64, |sum, length| {
            sum.saturating_add(length.saturating_add(3))
        })
        .min(view_span_limit(buffer_bytes)) as usize;
    let images: usize = source
        .images
        .iter()
        .flatten()
        .map(|i| i.bytes.len() + 3)
        .sum();
    let weights = 32 * options.max_influences.div_ceil(4) * character.mesh.positions.len();
    let inverse_binds = 64 * character.skeleton.as_ref().map_or(0, |s| s.len());
    let json_items: usize = json
        .values()
        .filter_map(Value::as_array)
        .map(Vec::len)
        .sum();
    views + images + weights + inverse_binds + JSON_BYTES_PER_ITEM * (json_items + 16)
}

/// Room per item of the document's top-level arrays (accessors, nodes, ...) for the
/// output's JSON in [`output_capacity`]: more than an accessor with its bounds takes.
const JSON_BYTES_PER_ITEM: usize = 256;

/// Refuses a document where a joint of `skin` instantiates one of the skinned `meshes`: the
/// mesh would move with a joint that its own weights move (and a node with a skinned mesh
/// but no skin is invalid glTF).
fn refuse_joints_with_skinned_meshes(
    json: &Map<String, Value>,
    skin: Option<usize>,
    meshes: &BTreeSet<usize>,
    input: &Path,
) -> Result<(), IoError> {
    let joints = skin
        .and_then(|skin| json.get("skins")?.get(skin)?.get("joints")?.as_array())
        .into_iter()
        .flatten()
        .filter_map(Value::as_u64);
    for node in joints {
        let mesh = json
            .get("nodes")
            .and_then(|nodes| nodes.get(node as usize)?.get("mesh")?.as_u64());
        if let Some(mesh) = mesh.filter(|m| meshes.contains(&(*m as usize))) {
            return Err(IoError::invalid(
                input,
                format!(
                    "nodes[{node}] is a joint of the skin and also instantiates the skinned \
                     meshes[{mesh}]: cannot write a valid skinned glTF (move the mesh to a \
                     node of its own)"
                ),
            ));
        }
    }
    Ok(())
}

/// Sets `min`/`max` of every float POSITION accessor read into the character (glTF 2.0
/// requires them) from the positions as read, where they are missing or wrong.
fn set_position_bounds(json: &mut Map<String, Value>, character: &Character, source: &GltfSource) {
    let Some(Value::Array(accessors)) = json.get_mut("accessors") else {
        return;
    };
    for primitive in source
        .primitives
        .iter()
        .filter(|p| stored_as_read(p, source))
    {
        let Some(Value::Object(accessor)) = accessors.get_mut(primitive.position_accessor) else {
            continue;
        };
        if accessor.get("componentType").and_then(Value::as_u64) != Some(FLOAT) {
            continue;
        }
        let Some(positions) = character.mesh.positions.get(primitive.vertices.clone()) else {
            continue;
        };
        if positions.is_empty() {
            continue;
        }
        let (min, max) = point_bounds(positions);
        for (key, bound) in [("min", min), ("max", max)] {
            if !same_numbers(accessor.get(key), &bound) {
                accessor.insert(key.into(), json!(bound));
            }
        }
    }
}

/// Whether `primitive`'s vertices are stored in `Character::mesh` as the file has them:
/// only the first skin's primitives (and unskinned ones) are; those of other skins and
/// rigid meshes were moved into its bind space when read, and keep their own data.
fn stored_as_read(primitive: &super::PrimitiveSource, source: &GltfSource) -> bool {
    match (primitive.binding, source.skin) {
        (Binding::Skin(skin), Some(first)) => skin == first,
        (Binding::Unskinned, _) => true,
        _ => false,
    }
}

/// Makes every NORMAL of the primitives stored as read unit length, as glTF 2.0 requires
/// (§3.7.2.1): a vector of another length is normalised, a zero or non-finite one replaced
/// by the smooth normal of its vertex ([`smooth_normals`]). The copied bytes are repaired
/// in place and the accessor's declared `min`/`max` follow; a sparse or non-float NORMAL
/// accessor is left as it is.
fn repair_normals(builder: GlbBuilder, character: &Character, source: &GltfSource) -> GlbBuilder {
    let (mut json, mut bin) = builder.into_parts();
    let mut smooth: Option<Vec<glam::Vec3>> = None;
    for primitive in source
        .primitives
        .iter()
        .filter(|p| stored_as_read(p, source))
    {
        let Some((accessor, offset, stride, count)) = normal_layout(&json, primitive) else {
            continue;
        };
        if count != primitive.vertices.len() || count == 0 {
            continue;
        }
        let Some(end) = offset.checked_add((count - 1) * stride + 12) else {
            continue;
        };
        if end > bin.len() {
            continue;
        }
        let mut values = Vec::with_capacity(3 * count);
        let mut repaired_any = false;
        for k in 0..count {
            let at = offset + k * stride;
            let read = |i: usize| {
                let bytes: [u8; 4] = bin[at + 4 * i..at + 4 * i + 4].try_into().unwrap_or([0; 4]);
                f32::from_le_bytes(bytes)
            };
            let n = glam::Vec3::new(read(0), read(1), read(2));
            let length = n.length();
            if (length - 1.0).abs() <= UNIT_TOLERANCE {
                values.extend_from_slice(&n.to_array());
                continue;
            }
            repaired_any = true;
            let repaired = if length.is_finite() && length > 0.0 {
                n / length
            } else {
                smooth.get_or_insert_with(|| {
                    smooth_normals(&character.mesh.positions, &character.mesh.triangles)
                })[primitive.vertices.start + k]
            };
            for (i, value) in repaired.to_array().iter().enumerate() {
                bin[at + 4 * i..at + 4 * i + 4].copy_from_slice(&value.to_le_bytes());
            }
            values.extend_from_slice(&repaired.to_array());
        }
        // Bounds the accessor declares follow its repaired values.
        let object = json
            .get_mut("accessors")
            .and_then(|a| a.get_mut(accessor))
            .and_then(Value::as_object_mut);
        if let (true, Some(object)) = (repaired_any, object) {
            let (min, max) = component_bounds(&values, 3);
            for (key, bound) in [("min", min), ("max", max)] {
                if object.contains_key(key) {
                    object.insert(key.into(), json!(bound));
                }
            }
        }
    }
    GlbBuilder::from_parts(json, bin)
}

/// How far from 1 a normal's length may be before [`repair_normals`] rescales it (the
/// Khronos validator allows 0.0005).
const UNIT_TOLERANCE: f32 = 1e-4;

/// `primitive`'s NORMAL accessor, its byte offset in the output buffer, stride and count,
/// when it is a plain (not sparse) float VEC3 accessor on a bufferView.
fn normal_layout(
    json: &Map<String, Value>,
    primitive: &super::PrimitiveSource,
) -> Option<(usize, usize, usize, usize)> {
    let index = json
        .get("meshes")?
        .get(primitive.mesh)?
        .get("primitives")?
        .get(primitive.primitive)?
        .get("attributes")?
        .get("NORMAL")?
        .as_u64()? as usize;
    let accessor = json.get("accessors")?.get(index)?;
    if accessor.get("componentType")?.as_u64()? != FLOAT
        || accessor.get("type")?.as_str()? != "VEC3"
        || accessor.get("sparse").is_some()
    {
        return None;
    }
    let view = json
        .get("bufferViews")?
        .get(accessor.get("bufferView")?.as_u64()? as usize)?;
    let offset = |v: &Value| v.get("byteOffset").and_then(Value::as_u64).unwrap_or(0) as usize;
    let stride = view
        .get("byteStride")
        .and_then(Value::as_u64)
        .map_or(12, |s| s as usize);
    let count = accessor.get("count")?.as_u64()? as usize;
    Some((
        index,
        offset(view) + offset(accessor),
        stride.max(12),
        count,
    ))
}

/// True when `value` is an array of the numbers `expected` (as float32: `1` and `1.0`
/// are the same bound).
fn same_numbers(value: Option<&Value>, expected: &[f32]) -> bool {
    let Some(Value::Array(items)) = value else {
        return false;
    };
    items.len() == expected.len()
        && items
            .iter()
            .zip(expected)
            .all(|(item, &e)| item.as_f64().is_some_and(|v| v as f32 == e))
}

/// glTF's code of the FLOAT component type.
const FLOAT: u64 = 5126;

/// Copies every bufferView's bytes into the output buffer and points the view at it.
fn copy_buffer_views(
    builder: &mut GlbBuilder,
    source: &GltfSource,
    input: &Path,
) -> Result<(), IoError> {
    let Some(Value::Array(mut views)) = builder.json_mut().remove("bufferViews") else {
        return Ok(());
    };
    for (index, view) in views.iter_mut().enumerate() {
        let field = |key: &str| view.get(key).and_then(Value::as_u64).map(|v| v as usize);
        let (buffer, offset, length) = (
            field("buffer").unwrap_or(usize::MAX),
            field("byteOffset").unwrap_or(0),
            field("byteLength").unwrap_or(0),
        );
        let bytes = source
            .buffers
            .get(buffer)
            .and_then(|data| data.get(offset..offset.checked_add(length)?))
            .ok_or_else(|| {
                IoError::invalid(
                    input,
                    format!("bufferViews[{index}] is out of range of its buffer"),
                )
            })?;
        let new_offset = builder.append_bytes(bytes, offset);
        view["buffer"] = json!(0);
        view["byteOffset"] = json!(new_offset);
    }
    builder
        .json_mut()
        .insert("bufferViews".into(), Value::Array(views));
    Ok(())
}

/// Embeds every image given by URI (read with the document: a file beside the input or a
/// `data:` URI) as a bufferView with its `mimeType`. Images the reader left out are
/// removed, with the textures' `source` references renumbered (a texture whose image was
/// left out keeps no `source`).
fn embed_images(
    builder: &mut GlbBuilder,
    source: &GltfSource,
    input: &Path,
) -> Result<(), IoError> {
    let Some(Value::Array(images)) = builder.json_mut().remove("images") else {
        return Ok(());
    };
    let mut kept = Vec::with_capacity(images.len());
    let mut new_index = Vec::with_capacity(images.len());
    for (index, mut image) in images.into_iter().enumerate() {
        let Some(uri) = image.get("uri").and_then(Value::as_str).map(str::to_string) else {
            new_index.push(Some(kept.len()));
            kept.push(image);
            continue;
        };
        let Some(Some(read)) = source.images.get(index) else {
            new_index.push(None);
            continue;
        };
        let mime_type = sniff_image_type(&read.bytes)
            .map(str::to_string)
            .or_else(|| {
                image
                    .get("mimeType")
                    .and_then(Value::as_str)
                    .map(str::to_string)
            })
            .or_else(|| read.media_type.clone())
            .ok_or_else(|| {
                IoError::invalid(
                    input,
                    format!("images[{index}] ({uri}) has an unknown type"),
                )
            })?;
        let view = builder.push_view(&read.bytes, None);
        if let Value::Object(object) = &mut image {
            object.remove("uri");
            object.insert("bufferView".into(), json!(view));
            object.insert("mimeType".into(), json!(mime_type));
        }
        new_index.push(Some(kept.len()));
        kept.push(image);
    }
    if let Some(Value::Array(textures)) = builder.json_mut().get_mut("textures") {
        for texture in textures {
            renumber_image_sources(texture, &new_index);
        }
    }
    // glTF does not allow an empty top-level array.
    if !kept.is_empty() {
        builder
            .json_mut()
            .insert("images".into(), Value::Array(kept));
    }
    Ok(())
}

/// Renumbers the `source` of a texture and of its extensions (`EXT_texture_webp`,
/// `KHR_texture_basisu`, ...) by `new_index`, removing a `source` whose image is gone.
fn renumber_image_sources(texture: &mut Value, new_index: &[Option<usize>]) {
    let Value::Object(object) = texture else {
        return;
    };
    let renumber = |object: &mut Map<String, Value>| {
        let Some(old) = object.get("source").and_then(Value::as_u64) else {
            return;
        };
        match new_index.get(old as usize).copied().flatten() {
            Some(new) => {
                object.insert("source".into(), json!(new));
            }
            None => {
                object.remove("source");
            }
        }
    };
    renumber(object);
    if let Some(Value::Object(extensions)) = object.get_mut("extensions") {
        for extension in extensions.values_mut() {
            if let Value::Object(extension) = extension {
                renumber(extension);
            }
        }
    }
}

/// The media type of image bytes recognised by their signature.
fn sniff_image_type(bytes: &[u8]) -> Option<&'static str> {
    if bytes.starts_with(b"\x89PNG\r\n\x1a\n") {
        Some("image/png")
    } else if bytes.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Some("image/jpeg")
    } else if bytes.len() >= 12 && &bytes[0..4] == b"RIFF" && &bytes[8..12] == b"WEBP" {
        Some("image/webp")
    } else if bytes.starts_with(b"\xABKTX 20\xBB") {
        Some("image/ktx2")
    } else {
        None
    }
}

/// On every primitive whose (mesh, POSITION accessor) has new weights: JOINTS_k and
/// WEIGHTS_k set to the new accessors, and sets beyond them removed.
fn replace_weight_attributes(
    json: &mut Map<String, Value>,
    new_sets: &BTreeMap<(usize, usize), Vec<(usize, usize)>>,
) {
    let Some(Value::Array(all_meshes)) = json.get_mut("meshes") else {
        return;
    };
    let meshes: BTreeSet<usize> = new_sets.keys().map(|&(mesh, _)| mesh).collect();
    for mesh in meshes {
        let Some(Value::Array(primitives)) = all_meshes
            .get_mut(mesh)
            .and_then(|m| m.get_mut("primitives"))
        else {
            continue;
        };
        for primitive in primitives {
            let Some(Value::Object(attributes)) = primitive.get_mut("attributes") else {
                continue;
            };
            let position = attributes.get("POSITION").and_then(Value::as_u64);
            let Some(sets) = position.and_then(|p| new_sets.get(&(mesh, p as usize))) else {
                continue;
            };
            attributes.retain(|name, _| {
                let set = name
                    .strip_prefix("JOINTS_")
                    .or_else(|| name.strip_prefix("WEIGHTS_"))
                    .and_then(|n| n.parse::<usize>().ok());
                !matches!(set, Some(set) if set >= sets.len())
            });
            for (set, &(joints, weights)) in sets.iter().enumerate() {
                attributes.insert(format!("JOINTS_{set}"), json!(joints));
                attributes.insert(format!("WEIGHTS_{set}"), json!(weights));
            }
        }
    }
}

/// Rows `vertices` of `weights` (joint indices into the skeleton, whose joint nodes are
/// `skeleton_nodes`) with joint indices into a skin over the same nodes `skin_nodes`.
fn in_skin_order(
    weights: &VertexWeights,
    vertices: Range<usize>,
    skeleton_nodes: &[usize],
    skin_nodes: &[usize],
) -> VertexWeights {
    let skin_index = node_positions(skin_nodes);
    let index_in_skin: Vec<u32> = skeleton_nodes
        .iter()
        .map(|node| skin_index.get(node).copied().unwrap_or(0))
        .collect();
    VertexWeights::from_rows(
        vertices.map(|v| weights.row(v).map(|(j, w)| (index_in_skin[j as usize], w))),
    )
}

/// Node index of every joint of `skin`.
fn skin_joint_nodes(
    document: &Map<String, Value>,
    skin: Option<usize>,
    input: &Path,
) -> Result<Vec<usize>, IoError> {
    let joints = skin
        .and_then(|skin| document.get("skins")?.get(skin)?.get("joints")?.as_array())
        .ok_or_else(|| IoError::invalid(input, "the document's skin has no joints"))?;
    Ok(joints
        .iter()
        .filter_map(|j| j.as_u64().map(|j| j as usize))
        .collect())
}
