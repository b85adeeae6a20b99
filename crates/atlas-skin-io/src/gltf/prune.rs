//! Dropping the accessors and bufferViews that a rewrite orphaned (the replaced
//! JOINTS_n/WEIGHTS_n and their bytes), renumbering every reference to the ones kept.
//!
//! Only references glTF 2.0 defines are followed (§3.6–3.11: primitive attributes, indices
//! and morph targets, skins, animation samplers, accessors and their sparse parts, images).
//! A document using an extension not known to be free of such references, or holding a
//! reference that is not a valid index, is left exactly as it is.

use super::builder::{keep_ranges, GlbBuilder};
use super::view_span::used_spans;
use serde_json::{json, Map, Value};
use std::ops::Range;

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
#[rustfmt::skip]
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
/// index below `used.len()`. (`value` is only read; `&mut` shares the walker with
/// [`renumber`].)
fn mark(value: &mut Value, paths: &[&[Step]], used: &mut [bool]) -> bool {
    let mut valid = true;
    for path in paths {
        for_each_at(value, path, &mut |reference| match reference
            .as_u64()
            .and_then(|i| used.get_mut(i as usize))
        {
            Some(slot) => *slot = true,
            None => valid = false,
        });
    }
    valid
}

/// Replaces every index at `paths` under `value` by `new_index[index]`. Only called on
/// references [`mark`] accepted, whose targets are kept.
fn renumber(value: &mut Value, paths: &[&[Step]], new_index: &[Option<usize>]) {
    for path in paths {
        for_each_at(value, path, &mut |reference| {
            if let Some(&Some(new)) = reference.as_u64().and_then(|i| new_index.get(i as usize)) {
                *reference = json!(new);
            }
        });
    }
}

/// True when every extension named in `extensionsUsed` or in an `extensions` object
/// anywhere in `value` is in [`INDEX_FREE_EXTENSIONS`].
///
/// The tree is walked with a stack of its objects and arrays (numbers and strings, most of
/// a document's values, are never pushed); [`only_index_free_extensions_recursive`], the
/// reference, gives the same answer.
fn only_index_free_extensions(value: &Value) -> bool {
    let known = |name: &str| INDEX_FREE_EXTENSIONS.contains(&name);
    let is_container = |v: &&Value| matches!(v, Value::Object(_) | Value::Array(_));
    let mut stack = vec![value];
    while let Some(value) = stack.pop() {
        match value {
            Value::Object(map) => {
                for (key, child) in map {
                    let names_known = match (key.as_str(), child) {
                        ("extensions", Value::Object(extensions)) => {
                            extensions.keys().all(|k| known(k))
                        }
                        ("extensionsUsed", Value::Array(names)) => {
                            names.iter().all(|n| n.as_str().is_some_and(known))
                        }
                        _ => true,
                    };
                    if !names_known {
                        return false;
                    }
                    if is_container(&child) {
                        stack.push(child);
                    }
                }
            }
            Value::Array(items) => stack.extend(items.iter().filter(is_container)),
            _ => {}
        }
    }
    true
}

/// [`only_index_free_extensions`] by recursion over every value (the reference).
#[cfg(test)]
fn only_index_free_extensions_recursive(value: &Value) -> bool {
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
            names_known && only_index_free_extensions_recursive(child)
        }),
        Value::Array(items) => items.iter().all(only_index_free_extensions_recursive),
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
/// references of the document before the rewrite) used and nothing uses any more; a kept
/// view that a dropped accessor also used is cut to the span the kept accessors read
/// ([`used_spans`]). All other items keep their order and bytes, and every reference is
/// renumbered. Items the rewrite appended (indices past `input`'s) are kept when
/// referenced, which they all are. The builder comes back unchanged when `input` is
/// `None` or the rewritten document cannot be followed.
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
    let spans = used_spans(
        &json,
        &output.accessors,
        &views_of_dropped_accessors(&json, input, &output),
    );
    let Some(view_bytes) = view_ranges(&json, &keep_views, &spans, bin.len()) else {
        return GlbBuilder::from_parts(json, bin);
    };
    let accessor_index = keep_and_number(&mut json, "accessors", &output.accessors);
    shift_accessors(&mut json, &spans);
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
    let (bin, offsets) = keep_ranges(bin, &view_bytes);
    let mut pruned = GlbBuilder::from_parts(json, bin);
    for (view, (range, offset)) in view_bytes.iter().zip(offsets).enumerate() {
        let view = &mut pruned.json_mut()["bufferViews"][view];
        view["byteOffset"] = json!(offset);
        view["byteLength"] = json!(range.len());
    }
    pruned
}

/// Marks the bufferViews (dense data) of the accessors `input` used and `output` drops:
/// those may keep bytes nothing reads any more.
fn views_of_dropped_accessors(
    json: &Map<String, Value>,
    input: &References,
    output: &References,
) -> Vec<bool> {
    let mut views = vec![false; output.views.len()];
    let Some(Value::Array(accessors)) = json.get("accessors") else {
        return views;
    };
    for (accessor, (&used, &kept)) in accessors
        .iter()
        .zip(input.accessors.iter().zip(&output.accessors))
    {
        let view = accessor.get("bufferView").and_then(Value::as_u64);
        if let (true, false, Some(slot)) =
            (used, kept, view.and_then(|v| views.get_mut(v as usize)))
        {
            *slot = true;
        }
    }
    views
}

/// Moves every accessor reading a view of `spans` back by the bytes cut off the view's
/// start. Called on the kept accessors only (before their views are renumbered): each
/// starts at or after its view's span.
fn shift_accessors(json: &mut Map<String, Value>, spans: &[Option<Range<usize>>]) {
    let Some(Value::Array(accessors)) = json.get_mut("accessors") else {
        return;
    };
    for accessor in accessors {
        let view = accessor.get("bufferView").and_then(Value::as_u64);
        let Some(Some(span)) = view.and_then(|v| spans.get(v as usize)) else {
            continue;
        };
        if span.start > 0 {
            let offset = accessor
                .get("byteOffset")
                .and_then(Value::as_u64)
                .unwrap_or(0) as usize;
            accessor["byteOffset"] = json!(offset - span.start);
        }
    }
}

/// The byte range in `bin` of every bufferView kept by `keep`, in order, narrowed to its
/// used span when `spans` has one; `None` when a view is not a range of buffer 0 (all views
/// of a rewritten document are) or a span does not lie inside its view.
fn view_ranges(
    json: &Map<String, Value>,
    keep: &[bool],
    spans: &[Option<Range<usize>>],
    bin_length: usize,
) -> Option<Vec<Range<usize>>> {
    let views = match json.get("bufferViews") {
        Some(Value::Array(views)) => views.as_slice(),
        _ => &[],
    };
    views
        .iter()
        .zip(keep.iter().zip(spans))
        .filter(|(_, (&kept, _))| kept)
        .map(|(view, (_, span))| {
            let field = |key: &str| view.get(key).and_then(Value::as_u64);
            let start = field("byteOffset").unwrap_or(0) as usize;
            let length = field("byteLength")? as usize;
            let used = span.clone().unwrap_or(0..length);
            let end = start.checked_add(used.end)?;
            let valid = field("buffer") == Some(0) && used.end <= length && end <= bin_length;
            valid.then_some(start + used.start..end)
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

#[cfg(test)]
mod tests {
    use super::*;

    /// A document as a rewrite leaves it, with `extra` merged in: views 0..=7 over 4-byte
    /// blocks of the BIN (block i filled with i); accessor 1 (the old JOINTS_0, the only user
    /// of view 1) replaced by accessor 4 (view 7); accessor 3 and view 6 unused by the input
    /// itself. Returns the builder and the input's references.
    fn rewritten(extra: Value) -> (GlbBuilder, Option<References>) {
        let views: Vec<Value> = (0..7)
            .map(|i| json!({"buffer": 0, "byteOffset": 4 * i, "byteLength": 4}))
            .collect();
        let mut input = json!({
            "accessors": [
                {"bufferView": 0},
                {"bufferView": 1},
                {"bufferView": 2, "sparse": {"count": 1, "indices": {"bufferView": 3},
                                            "values": {"bufferView": 2}}},
                {"bufferView": 4}
            ],
            "bufferViews": views,
            "meshes": [{"primitives": [{
                "attributes": {"POSITION": 0, "JOINTS_0": 1},
                "targets": [{"POSITION": 2}]
            }]}],
            "skins": [{"joints": [0], "inverseBindMatrices": 0}],
            "animations": [{"samplers": [{"input": 0, "output": 2, "interpolation": "LINEAR"}]}],
            "images": [{"bufferView": 5}]
        });
        if let (Value::Object(input), Value::Object(extra)) = (&mut input, extra) {
            input.extend(extra);
        }
        let Value::Object(json) = input else {
            unreachable!()
        };
        let mut builder = GlbBuilder::new(json);
        let references = References::of_input(builder.json_mut());
        for i in 0..7u8 {
            builder.append_bytes(&[i; 4], 0);
        }
        let view = builder.push_view(&[7; 4], None);
        let accessor = builder.push_item("accessors", json!({"bufferView": view}));
        builder.json_mut()["meshes"][0]["primitives"][0]["attributes"]["JOINTS_0"] =
            json!(accessor);
        (builder, references)
    }

    #[test]
    fn orphans_are_dropped_and_references_renumbered() {
        let (builder, references) = rewritten(json!({}));
        let (json, bin) = drop_orphans(builder, references.as_ref()).into_parts();
        let accessor_views: Vec<&Value> = json["accessors"]
            .as_array()
            .unwrap()
            .iter()
            .map(|a| &a["bufferView"])
            .collect();
        assert_eq!(accessor_views, [&json!(0), &json!(1), &json!(3), &json!(6)]);
        assert_eq!(json["accessors"][1]["sparse"]["indices"]["bufferView"], 2);
        assert_eq!(json["accessors"][1]["sparse"]["values"]["bufferView"], 1);
        let primitive = &json["meshes"][0]["primitives"][0];
        assert_eq!(
            primitive["attributes"],
            json!({"POSITION": 0, "JOINTS_0": 3})
        );
        assert_eq!(primitive["targets"][0]["POSITION"], 1);
        assert_eq!(json["skins"][0]["inverseBindMatrices"], 0);
        assert_eq!(json["animations"][0]["samplers"][0]["output"], 1);
        assert_eq!(json["images"][0]["bufferView"], 4);
        let kept_blocks = [0u8, 2, 3, 4, 5, 6, 7];
        let expected: Vec<u8> = kept_blocks.iter().flat_map(|&b| [b; 4]).collect();
        assert_eq!(bin, expected);
        for (view, offset) in json["bufferViews"].as_array().unwrap().iter().zip(0..) {
            assert_eq!(view["byteOffset"], 4 * offset);
        }
    }

    #[test]
    fn documents_that_cannot_be_followed_are_kept_whole() {
        let unknown_extension = json!({
            "nodes": [{"extensions": {"EXT_mesh_gpu_instancing": {"attributes": {"SCALE": 1}}}}]
        });
        let bad_reference = json!({"skins": [{"inverseBindMatrices": 0.5}]});
        for extra in [unknown_extension, bad_reference] {
            let unchanged = rewritten(extra.clone()).0.into_parts();
            let (builder, references) = rewritten(extra);
            assert_eq!(
                drop_orphans(builder, references.as_ref()).into_parts(),
                unchanged
            );
        }
    }

    /// The walk with a stack answers as the recursion does: documents with known and unknown
    /// extensions at the root, deep in objects and arrays, in `extensionsUsed` (also with a
    /// non-string name), in extras, and the corpus's glTF documents.
    #[test]
    fn the_stack_walk_answers_as_the_recursion() {
        let mut documents = vec![
            json!({}),
            json!([]),
            json!(3),
            json!({"extensionsUsed": ["KHR_materials_unlit"]}),
            json!({"extensionsUsed": ["EXT_mesh_gpu_instancing"]}),
            json!({"extensionsUsed": [7]}),
            json!({"extensionsUsed": "KHR_materials_unlit"}),
            json!({"extensions": "not an object"}),
            json!({"nodes": [{"extensions": {"KHR_lights_punctual": {"light": 0}}}]}),
            json!({"nodes": [{"extensions": {"EXT_mesh_gpu_instancing": {}}}]}),
            json!({"a": [[[{"b": {"extensions": {"VRM": {}}}}]]], "c": [1, "x", null]}),
            json!({"a": [[[{"b": {"extensions": {"VRM": {}, "X": {}}}}]]]}),
            json!({"asset": {"extras": {"extensions": {"unknown": 1}}}}),
            json!({"meshes": [{"primitives": [{"extensions": {}}]}], "x": [{"extensionsUsed": []}]}),
        ];
        let corpus = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");
        for file in [
            "models/cesiumman/CesiumMan.glb",
            "bench/robotexpressive/RobotExpressive.glb",
            "bench/kaykit/Barbarian.glb",
        ] {
            let path = std::path::Path::new(corpus).join(file);
            if let Ok(character) = crate::gltf::read(&path) {
                documents.extend(character.gltf.map(|g| g.document));
            }
        }
        assert!(documents.len() > 14, "no corpus document read");
        for document in &documents {
            assert_eq!(
                only_index_free_extensions(document),
                only_index_free_extensions_recursive(document),
                "{document}"
            );
        }
        assert!(!only_index_free_extensions(&documents[4]));
        assert!(only_index_free_extensions(&documents[8]));
    }
}
