//! Shared helpers of the glTF integration tests: corpus paths, output folders, the Khronos
//! validator, raw accessor bytes.

#![allow(dead_code)] // each test binary uses a subset

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The corpus folder (`../shared/data` beside the repository); panics when it is missing.
pub fn data_dir() -> PathBuf {
    let dir = PathBuf::from(concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"));
    assert!(
        dir.join("models").is_dir(),
        "the corpus is missing: {} (tests never skip)",
        dir.display()
    );
    dir
}

/// The glTF models of the corpus: (model name, file name).
pub const GLTF_MODELS: [(&str, &str); 4] = [
    ("cesiumman", "CesiumMan.glb"),
    ("riggedfigure", "RiggedFigure.glb"),
    ("riggedsimple", "RiggedSimple.glb"),
    ("simpleskin", "SimpleSkin.gltf"),
];

pub fn model_path(model: &str, file: &str) -> PathBuf {
    data_dir().join("models").join(model).join(file)
}

pub fn manifest(model: &str) -> Value {
    let path = model_path(model, "manifest.json");
    let text = std::fs::read_to_string(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_str(&text).unwrap()
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

/// Runs the Khronos glTF-Validator (tests/js/validate.mjs) on `files` and fails unless
/// every file has 0 errors.
pub fn assert_valid(files: &[PathBuf]) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR")).join("../..");
    assert!(
        root.join("tests/js/node_modules/gltf-validator").is_dir(),
        "tests/js/node_modules is missing: run scripts/install-test-deps"
    );
    let output = Command::new("node")
        .current_dir(&root)
        .arg("tests/js/validate.mjs")
        .args(files)
        .output()
        .expect("cannot run node");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let mut reports = 0;
    for line in stdout.lines() {
        let report: Value = serde_json::from_str(line).expect("validator output is JSON");
        assert_eq!(report["errors"], 0, "validator errors: {report}");
        reports += 1;
    }
    assert_eq!(reports, files.len(), "{stdout}");
    assert!(
        output.status.success(),
        "validator failed: {stdout}{}",
        String::from_utf8_lossy(&output.stderr)
    );
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
