//! Shared helpers of the glTF integration tests (also included by the CLI's): corpus paths,
//! output folders, the Khronos validator, raw accessor bytes.

#![allow(dead_code)] // each test binary uses a subset

use atlas_skin_corpus::{node_check, CESIUMMAN, RIGGEDFIGURE, RIGGEDSIMPLE, SIMPLESKIN};
use serde_json::Value;
use std::path::{Path, PathBuf};

/// The corpus folder (`../shared/data` beside the repository); panics when it is missing.
pub fn data_dir() -> PathBuf {
    atlas_skin_corpus::data_dir()
}

/// The glTF models of the corpus: (model name, file name).
pub const GLTF_MODELS: [(&str, &str); 4] = [
    (CESIUMMAN.name, CESIUMMAN.input),
    (RIGGEDFIGURE.name, RIGGEDFIGURE.input),
    (RIGGEDSIMPLE.name, RIGGEDSIMPLE.input),
    (SIMPLESKIN.name, SIMPLESKIN.input),
];

/// The file `file` of the corpus model `model`.
pub fn model_path(model: &str, file: &str) -> PathBuf {
    atlas_skin_corpus::models_dir().join(model).join(file)
}

/// SimpleSkin.gltf's JSON with its (embedded) buffer 0 decoded.
pub fn simpleskin() -> (Value, Vec<u8>) {
    use base64::Engine;
    let json: Value = serde_json::from_slice(
        &std::fs::read(model_path("simpleskin", "SimpleSkin.gltf")).unwrap(),
    )
    .unwrap();
    let uri = json["buffers"][0]["uri"].as_str().unwrap();
    let buffer0 = base64::engine::general_purpose::STANDARD
        .decode(uri.split_once(',').unwrap().1)
        .unwrap();
    (json, buffer0)
}

/// The manifest.json of the corpus model `model`.
pub fn manifest(model: &str) -> Value {
    atlas_skin_corpus::find(model)
        .unwrap_or_else(|| panic!("no corpus model {model}"))
        .manifest()
}

/// A fresh, empty output folder for one test under the target's test temp dir.
pub fn out_dir(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("gltf_tests")
        .join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// The Khronos glTF-Validator's report (tests/js/validate.mjs: counts, first messages and
/// `codes`, the count of every "severity:CODE") on every file of `files`, in order.
pub fn validator_reports(files: &[PathBuf]) -> Vec<Value> {
    node_check("validate.mjs", files)
}

/// Runs the Khronos glTF-Validator on `files` and fails unless every file has 0 errors.
pub fn assert_valid(files: &[PathBuf]) {
    for report in validator_reports(files) {
        assert_eq!(report["errors"], 0, "validator errors: {report}");
    }
}

/// Fails when `output` (a validator report) has an error, or more messages of some
/// "severity:CODE" than `input` (the report of the file it was made from; `None` when it
/// was not made from a glTF file, so it may have none).
pub fn assert_no_new_issues(output: &Value, input: Option<&Value>) {
    assert_eq!(output["errors"], 0, "{output}");
    let codes = output["codes"]
        .as_object()
        .expect("the report counts its codes");
    for (code, count) in codes {
        let allowed = input
            .and_then(|input| input["codes"].get(code))
            .and_then(Value::as_u64)
            .unwrap_or(0);
        assert!(
            count.as_u64().expect("a count") <= allowed,
            "{}: {count} × {code}, the input has {allowed}: {output}",
            output["file"]
        );
    }
}

/// The raw bytes of every element of accessor `index` (following bufferView strides;
/// accessors without a bufferView or with sparse data are not used by the corpus).
pub fn accessor_elements(document: &Value, buffers: &[Vec<u8>], index: usize) -> Vec<Vec<u8>> {
    let accessor = &document["accessors"][index];
    assert!(accessor.get("sparse").is_none());
    let component_size = match accessor["componentType"].as_u64().unwrap() {
        5120 | 5121 => 1,
        5122 | 5123 => 2,
        _ => 4,
    };
    let components = match accessor["type"].as_str().unwrap() {
        "SCALAR" => 1,
        "VEC2" => 2,
        "VEC3" => 3,
        "VEC4" | "MAT2" => 4,
        "MAT3" => 9,
        _ => 16,
    };
    let element_size = component_size * components;
    let view = &document["bufferViews"][accessor["bufferView"].as_u64().unwrap() as usize];
    let stride = view["byteStride"]
        .as_u64()
        .map_or(element_size, |s| s as usize);
    let start = view["byteOffset"].as_u64().unwrap_or(0) as usize
        + accessor["byteOffset"].as_u64().unwrap_or(0) as usize;
    let buffer = &buffers[view["buffer"].as_u64().unwrap() as usize];
    (0..accessor["count"].as_u64().unwrap() as usize)
        .map(|i| buffer[start + i * stride..][..element_size].to_vec())
        .collect()
}

/// `document` with every accessor index (primitive attributes, indices and morph targets,
/// inverse bind matrices, animation samplers) replaced by the accessor it names: its JSON
/// without `bufferView` and `byteOffset`, plus the bytes of its elements. Two documents
/// resolved this way compare equal whatever their accessor numbering and buffer layout.
pub fn resolve_accessors(document: &Value, buffers: &[Vec<u8>]) -> Value {
    let resolve = |reference: &mut Value| {
        let index = reference.as_u64().expect("an accessor index") as usize;
        let mut accessor = document["accessors"][index].clone();
        let object = accessor.as_object_mut().expect("an accessor object");
        object.remove("bufferView");
        object.remove("byteOffset");
        object.insert(
            "elements".into(),
            serde_json::json!(accessor_elements(document, buffers, index)),
        );
        *reference = accessor;
    };
    let mut resolved = document.clone();
    for mesh in array_mut(&mut resolved, "meshes") {
        for primitive in array_mut(mesh, "primitives") {
            for attribute in primitive["attributes"]
                .as_object_mut()
                .into_iter()
                .flat_map(|a| a.values_mut())
            {
                resolve(attribute);
            }
            if let Some(indices) = primitive.get_mut("indices") {
                resolve(indices);
            }
            for target in array_mut(primitive, "targets") {
                target
                    .as_object_mut()
                    .into_iter()
                    .flat_map(|t| t.values_mut())
                    .for_each(resolve);
            }
        }
    }
    for skin in array_mut(&mut resolved, "skins") {
        if let Some(matrices) = skin.get_mut("inverseBindMatrices") {
            resolve(matrices);
        }
    }
    for animation in array_mut(&mut resolved, "animations") {
        for sampler in array_mut(animation, "samplers") {
            resolve(&mut sampler["input"]);
            resolve(&mut sampler["output"]);
        }
    }
    resolved
}

/// The items of the array `key` of `value`; none when it has no such array.
fn array_mut<'a>(value: &'a mut Value, key: &str) -> impl Iterator<Item = &'a mut Value> {
    value
        .get_mut(key)
        .and_then(Value::as_array_mut)
        .into_iter()
        .flatten()
}
