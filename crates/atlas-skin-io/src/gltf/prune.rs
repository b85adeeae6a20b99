//! Dropping the accessors and bufferViews that a rewrite orphaned (the replaced
//! JOINTS_n/WEIGHTS_n and their bytes), renumbering every reference to the ones kept.
//!
//! Only references glTF 2.0 defines are followed (§3.6–3.11: primitive attributes, indices
//! and morph targets, skins, animation samplers, accessors and their sparse parts, images).
//! A document using an extension not known to be free of such references, or holding a
//! reference that is not a valid index, is left exactly as it is.

use super::builder::GlbBuilder;
use serde_json::{json, Map, Value};

/// Extensions that hold no index into `accessors` or `bufferViews` (they name materials,
/// textures, images, nodes or meshes, which are never renumbered here).
const INDEX_FREE_EXTENSIONS: [&str; 28] = [
    "KHR_lights_punctual",
    "KHR_materials_anisotropy",
    "KHR_materials_clearcoat",
    "KHR_materials_diffuse_transmission",
    "KHR_materials_dispersion",
    "KHR_materials_emissive_strength",
    "KHR_materials_ior",
    "KHR_materials_iridescence",
    "KHR_materials_pbrSpecularGlossiness",
    "KHR_materials_sheen",
    "KHR_materials_specular",
    "KHR_materials_transmission",
    "KHR_materials_unlit",
    "KHR_materials_variants",
    "KHR_materials_volume",
    "KHR_mesh_quantization",
    "KHR_texture_basisu",
    "KHR_texture_transform",
    "KHR_xmp_json_ld",
    "EXT_texture_avif",
    "EXT_texture_webp",
    "VRM",
    "VRMC_materials_hdr_emissiveMultiplier",
    "VRMC_materials_mtoon",
    "VRMC_node_constraint",
    "VRMC_springBone",
    "VRMC_springBone_extended_collider",
    "VRMC_vrm",
];

/// One step of a path to reference fields: an object key, every item of an array, or every
/// value of an object (a primitive's attribute map).
#[derive(Clone, Copy)]
enum Step {
    Key(&'static str),
    Items,
    Values,
}

use Step::{Items, Key, Values};

/// Where an accessor index can occur, from the document root.
const ACCESSOR_REFERENCES: [&[Step]; 6] = [
    &[Key("meshes"), Items, Key("primitives"), Items, Key("attributes"), Values],
    &[Key("meshes"), Items, Key("primitives"), Items, Key("indices")],
    &[Key("meshes"), Items, Key("primitives"), Items, Key("targets"), Items, Values],
    &[Key("skins"), Items, Key("inverseBindMatrices")],
    &[Key("animations"), Items, Key("samplers"), Items, Key("input")],
    &[Key("animations"), Items, Key("samplers"), Items, Key("output")],
];

/// Where a bufferView index can occur, from an accessor.
const VIEW_REFERENCES_OF_ACCESSOR: [&[Step]; 3] = [
    &[Key("bufferView")],
    &[Key("sparse"), Key("indices"), Key("bufferView")],
    &[Key("sparse"), Key("values"), Key("bufferView")],
];

/// Where a bufferView index can occur, from the document root, besides accessors.
const IMAGE_VIEW_REFERENCES: &[Step] = &[Key("images"), Items, Key("bufferView")];

/// Calls `visit` on every value at the end of `path` under `value`.
fn for_each_at(value: &mut Value, path: &[Step], visit: &mut dyn FnMut(&mut Value)) {
    let Some((step, rest)) = path.split_first() else {
        visit(value);
        return;
    };
    match (step, value) {
        (Key(key), Value::Object(map)) => {
            if let Some(child) = map.get_mut(*key) {
                for_each_at(child, rest, visit);
            }
        }
        (Items, Value::Array(items)) => {
            for item in items {
                for_each_at(item, rest, visit);
            }
        }
        (Values, Value::Object(map)) => {
            for child in map.values_mut() {
                for_each_at(child, rest, visit);
            }
        }
        _ => {}
    }
}

/// Sets `used[i]` for every index found at `paths` under `value`; false when one is not an
/// index below `used.len()`.
fn mark(value: &mut Value, paths: &[&[Step]], used: &mut [bool]) -> bool {
    let mut valid = true;
    for path in paths {
        for_each_at(value, path, &mut |reference| {
            match reference.as_u64().and_then(|i| used.get_mut(i as usize)) {
                Some(slot) => *slot = true,
                None => valid = false,
            }
        });
    }
    valid
}

/// Replaces every index at `paths` under `value` by `new_index[index]`. Only called on
/// references [`mark`] accepted, whose targets are kept.
fn renumber(value: &mut Value, paths: &[&[Step]], new_index: &[Option<usize>]) {
    for path in paths {
        for_each_at(value, path, &mut |reference| {
            if let Some(&Some(new)) = reference
                .as_u64()
                .and_then(|i| new_index.get(i as usize))
            {
                *reference = json!(new);
            }
        });
    }
}

/// True when every extension named in `extensionsUsed` or in an `extensions` object
/// anywhere in `value` is in [`INDEX_FREE_EXTENSIONS`].
fn only_index_free_extensions(value: &Value) -> bool {
    let known = |name: &str| INDEX_FREE_EXTENSIONS.contains(&name);
    match value {
        Value::Object(map) => map.iter().all(|(key, child)| {
            let names_known = match (key.as_str(), child) {
                ("extensions", Value::Object(extensions)) => extensions.keys().all(|k| known(k)),
                ("extensionsUsed", Value::Array(names)) => {
                    names.iter().all(|n| n.as_str().is_some_and(known))
                }
                _ => true,
            };
            names_known && only_index_free_extensions(child)
        }),
        Value::Array(items) => items.iter().all(only_index_free_extensions),
        _ => true,
    }
}

/// Number of items of the top-level array `key`; `None` when it is not an array.
fn count(json: &Map<String, Value>, key: &str) -> Option<usize> {
    match json.get(key) {
        None => Some(0),
        Some(Value::Array(items)) => Some(items.len()),
        Some(_) => None,
    }
}

/// Which accessors and bufferViews a document references.
///
/// - `accessors`: #accessors, true for the referenced ones and those in `also_accessors`.
/// - `views`: #bufferViews, true for those referenced by images or by the accessors marked
///   in `accessors`.
pub(crate) struct References {
    accessors: Vec<bool>,
    views: Vec<bool>,
}

impl References {
    /// The references of `json`, counting the accessors marked in `also_accessors` as
    /// referenced; `None` when the document may hold references this module cannot follow.
    fn of(json: &mut Map<String, Value>, also_accessors: &[bool]) -> Option<Self> {
        let mut accessors = vec![false; count(json, "accessors")?];
        let mut views = vec![false; count(json, "bufferViews")?];
        let mut document = Value::Object(std::mem::take(json));
        let valid = only_index_free_extensions(&document)
            && mark(&mut document, &ACCESSOR_REFERENCES, &mut accessors)
            && mark(&mut document, &[IMAGE_VIEW_REFERENCES], &mut views);
        for (slot, &also) in accessors.iter_mut().zip(also_accessors) {
            *slot |= also;
        }
        let mut accessors_valid = true;
        if let Some(Value::Array(items)) = document.get_mut("accessors") {
            for (item, _) in items.iter_mut().zip(&accessors).filter(|(_, &used)| used) {
                accessors_valid &= mark(item, &VIEW_REFERENCES_OF_ACCESSOR, &mut views);
            }
        }
        if let Value::Object(map) = document {
            *json = map;
        }
        (valid && accessors_valid).then_some(Self { accessors, views })
    }

    /// The references of a document about to be rewritten: what it leaves unreferenced
    /// itself is kept by [`drop_orphans`]. `None` when it cannot be pruned.
    pub fn of_input(json: &mut Map<String, Value>) -> Option<Self> {
        Self::of(json, &[])
    }
}

/// `builder` without the accessors and bufferViews (and their bytes) that `input` (the
/// references of the document before the rewrite) used and nothing uses any more; all
/// other items keep their order, and every reference is renumbered. Items appended by the
/// rewrite (indices past `input`'s) are referenced by construction and kept. The builder
/// comes back unchanged when `input` is `None` or the rewritten document cannot be
/// followed.
pub(crate) fn drop_orphans(mut builder: GlbBuilder, input: Option<&References>) -> GlbBuilder {
    let Some(input) = input else {
        return builder;
    };
    let unused_in_input: Vec<bool> = input.accessors.iter().map(|used| !used).collect();
    let Some(output) = References::of(builder.json_mut(), &unused_in_input) else {
        return builder;
    };
    let keep_views: Vec<bool> = output
        .views
        .iter()
        .enumerate()
        .map(|(i, &used)| used || input.views.get(i) == Some(&false))
        .collect();
    let (mut json, bin) = builder.into_parts();
    let Some(view_bytes) = view_ranges(&json, &keep_views, bin.len()) else {
        return GlbBuilder::from_parts(json, bin);
    };
    let accessor_index = keep_and_number(&mut json, "accessors", &output.accessors);
    let view_index = keep_and_number(&mut json, "bufferViews", &keep_views);
    let mut document = Value::Object(json);
    renumber(&mut document, &ACCESSOR_REFERENCES, &accessor_index);
    renumber(&mut document, &[IMAGE_VIEW_REFERENCES], &view_index);
    if let Some(Value::Array(accessors)) = document.get_mut("accessors") {
        for accessor in accessors {
            renumber(accessor, &VIEW_REFERENCES_OF_ACCESSOR, &view_index);
        }
    }
    let Value::Object(json) = document else {
        unreachable!("the document was made an object above")
    };
    let mut pruned = GlbBuilder::new(json);
    for (view, range) in view_bytes.into_iter().enumerate() {
        let offset = pruned.append_bytes(&bin[range.clone()], range.start);
        pruned.json_mut()["bufferViews"][view]["byteOffset"] = json!(offset);
    }
    pruned
}

/// The byte range in `bin` of every bufferView kept by `keep`, in order; `None` when one
/// is not a range of buffer 0 (all views of a rewritten document are).
fn view_ranges(
    json: &Map<String, Value>,
    keep: &[bool],
    bin_length: usize,
) -> Option<Vec<std::ops::Range<usize>>> {
    let views = match json.get("bufferViews") {
        Some(Value::Array(views)) => views.as_slice(),
        _ => &[],
    };
    views
        .iter()
        .zip(keep)
        .filter(|(_, &kept)| kept)
        .map(|(view, _)| {
            let field = |key: &str| view.get(key).and_then(Value::as_u64);
            let start = field("byteOffset").unwrap_or(0) as usize;
            let end = start.checked_add(field("byteLength")? as usize)?;
            (field("buffer") == Some(0) && end <= bin_length).then_some(start..end)
        })
        .collect()
}

/// Keeps the items of the top-level array `key` marked in `keep` and returns the new index
/// of every old item (`None` for those dropped).
fn keep_and_number(json: &mut Map<String, Value>, key: &str, keep: &[bool]) -> Vec<Option<usize>> {
    let mut next = 0;
    let new_index: Vec<Option<usize>> = keep
        .iter()
        .map(|&kept| {
            kept.then(|| {
                next += 1;
                next - 1
            })
        })
        .collect();
    if let Some(Value::Array(items)) = json.get_mut(key) {
        *items = std::mem::take(items)
            .into_iter()
            .zip(keep)
            .filter_map(|(item, &kept)| kept.then_some(item))
            .collect();
    }
    new_index
}
