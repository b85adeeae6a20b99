//! Broken glTF inputs, built from the corpus files: each gives an error of the expected kind
//! whose message names the file and the problem, and no input makes the reader panic.

mod gltf_support;

use atlas_skin_io::gltf::{self, WriteOptions};
use atlas_skin_io::IoError;
use gltf_support::{model_path, out_dir, simpleskin};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// The expected kind of error.
#[derive(Debug, Clone, Copy)]
enum Kind {
    Invalid,
    Empty,
    IsDirectory,
    Skeleton,
}

fn kind_matches(error: &IoError, kind: Kind) -> bool {
    matches!(
        (error, kind),
        (IoError::Invalid { .. }, Kind::Invalid)
            | (IoError::Empty { .. }, Kind::Empty)
            | (IoError::IsDirectory { .. }, Kind::IsDirectory)
            | (IoError::Skeleton { .. }, Kind::Skeleton)
    )
}

fn riggedsimple_glb() -> Vec<u8> {
    std::fs::read(model_path("riggedsimple", "RiggedSimple.glb")).unwrap()
}

/// SimpleSkin with buffer 0 replaced by `buffer0`.
fn with_buffer0(mut json: Value, buffer0: &[u8]) -> Vec<u8> {
    use base64::Engine;
    json["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(buffer0)
    ));
    json.to_string().into_bytes()
}

/// (file name, bytes, expected kind, text the message must contain).
fn broken_files() -> Vec<(&'static str, Vec<u8>, Kind, &'static str)> {
    let glb = riggedsimple_glb();
    let (skin_json, buffer0) = simpleskin();
    let edited = |edit: &dyn Fn(&mut Value)| {
        let mut json = skin_json.clone();
        edit(&mut json);
        json.to_string().into_bytes()
    };
    let mut wrong_magic = glb.clone();
    wrong_magic[..4].copy_from_slice(b"GLTF");
    let mut bad_chunk = glb.clone();
    bad_chunk[12..16].copy_from_slice(&(glb.len() as u32).to_le_bytes());
    let mut nan_position = buffer0.clone();
    // POSITION is bufferView 1 (byte 48 of buffer 0): vertex 2's x.
    nan_position[48 + 24..48 + 28].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut nan_y = buffer0.clone();
    // Vertex 1 is (1, 0, 0): its y.
    nan_y[48 + 16..48 + 20].copy_from_slice(&f32::NAN.to_le_bytes());
    let mut unskinned = skin_json.clone();
    unskinned.as_object_mut().unwrap().remove("skins");
    unskinned["nodes"][0]
        .as_object_mut()
        .unwrap()
        .remove("skin");
    let mut huge_scale = unskinned.clone();
    // Vertex 6 is (0, 1.5, 0): 1.5 × 3e38 overflows float32.
    huge_scale["nodes"][0]["scale"] = json!([3e38, 3e38, 3e38]);
    let mut bad_index = buffer0.clone();
    bad_index[2..4].copy_from_slice(&99u16.to_le_bytes());
    vec![
        (
            "truncated.glb",
            glb[..glb.len() / 2].to_vec(),
            Kind::Invalid,
            "truncated glb",
        ),
        (
            "header.glb",
            glb[..7].to_vec(),
            Kind::Invalid,
            "truncated glb",
        ),
        ("magic.glb", wrong_magic, Kind::Invalid, "magic"),
        ("chunk.glb", bad_chunk, Kind::Invalid, "chunk length"),
        (
            "notgltf.gltf",
            br#"{"hello": "world"}"#.to_vec(),
            Kind::Invalid,
            "not a glTF document",
        ),
        (
            "badjson.gltf",
            b"{\"asset\": ".to_vec(),
            Kind::Invalid,
            "invalid glTF JSON",
        ),
        (
            "version.gltf",
            br#"{"asset": {"version": "1.0"}}"#.to_vec(),
            Kind::Invalid,
            "not supported",
        ),
        (
            "accessor.gltf",
            edited(&|j| j["accessors"][1]["count"] = json!(11)),
            Kind::Invalid,
            "out of range of bufferViews[1]",
        ),
        (
            "view.gltf",
            edited(&|j| j["bufferViews"][1]["byteLength"] = json!(1000)),
            Kind::Invalid,
            "out of range of buffers[0]",
        ),
        (
            "component.gltf",
            edited(&|j| j["accessors"][1]["componentType"] = json!(5130)),
            Kind::Invalid,
            "not a glTF component type",
        ),
        (
            "type.gltf",
            edited(&|j| j["accessors"][1]["type"] = json!("VEC3X")),
            Kind::Invalid,
            "not a glTF type",
        ),
        (
            "nan.gltf",
            with_buffer0(skin_json.clone(), &nan_position),
            Kind::Invalid,
            "vertex 2 is not finite",
        ),
        (
            "nan_unskinned.gltf",
            with_buffer0(unskinned, &nan_y),
            Kind::Invalid,
            "vertex 1 is not finite: [1, NaN, 0]",
        ),
        (
            "overflow.gltf",
            huge_scale.to_string().into_bytes(),
            Kind::Invalid,
            "vertex 6 [0, 1.5, 0] is not finite after its node's world transform: [0, inf, 0]",
        ),
        (
            "index.gltf",
            with_buffer0(skin_json.clone(), &bad_index),
            Kind::Invalid,
            "index 99 is out of range",
        ),
        (
            "missing.gltf",
            edited(&|j| j["buffers"][0]["uri"] = json!("missing.bin")),
            Kind::Invalid,
            "cannot read",
        ),
        (
            "base64.gltf",
            edited(&|j| {
                j["buffers"][0]["uri"] = json!("data:application/octet-stream;base64,@@@@")
            }),
            Kind::Invalid,
            "bad base64",
        ),
        (
            "short.gltf",
            edited(&|j| j["buffers"][0]["byteLength"] = json!(1000)),
            Kind::Invalid,
            "less than its byteLength",
        ),
        (
            // 100 channels each reading 1M zero key times and translations (16 MB): 1.6 GB
            // from a tiny file.
            "budget.gltf",
            edited(&|j| {
                let accessors = j["accessors"].as_array_mut().unwrap();
                let times = accessors.len();
                accessors.push(json!({"componentType": 5126, "count": 1 << 20, "type": "SCALAR"}));
                accessors.push(json!({"componentType": 5126, "count": 1 << 20, "type": "VEC3"}));
                let channels: Vec<Value> = (0..100)
                    .map(|_| json!({"sampler": 0, "target": {"node": 0, "path": "translation"}}))
                    .collect();
                j["animations"] = json!([{
                    "samplers": [{"input": times, "output": times + 1}],
                    "channels": channels
                }]);
            }),
            Kind::Invalid,
            "budget",
        ),
        (
            "cycle.gltf",
            edited(&|j| {
                j["nodes"][0]["children"] = json!([]);
                j["nodes"][2]["children"] = json!([1]);
            }),
            Kind::Invalid,
            "cycle through node",
        ),
        (
            "twoparents.gltf",
            edited(&|j| j["nodes"][2]["children"] = json!([1])),
            Kind::Invalid,
            "child of both",
        ),
        (
            "ibmtype.gltf",
            edited(&|j| {
                j["skins"][0]
                    .as_object_mut()
                    .unwrap()
                    .remove("inverseBindMatrices");
                j["accessors"][4]["count"] = json!(1);
                j["skins"][0]["inverseBindMatrices"] = json!(0);
            }),
            Kind::Invalid,
            "has type SCALAR, expected MAT4",
        ),
        (
            "joint.gltf",
            edited(&|j| j["skins"][0]["joints"] = json!([1, 7])),
            Kind::Invalid,
            "skins[0].joints has node 7",
        ),
        (
            // The animation's first two key times swapped: the skinned file would copy them.
            "keys.gltf",
            edited(&|j| {
                use base64::Engine;
                let engine = base64::engine::general_purpose::STANDARD;
                let uri = j["buffers"][3]["uri"].as_str().unwrap();
                let (head, data) = uri.split_once(',').unwrap();
                let mut bytes = engine.decode(data).unwrap();
                let (first, second) = bytes[..8].split_at_mut(4);
                first.swap_with_slice(second);
                j["buffers"][3]["uri"] = json!(format!("{head},{}", engine.encode(&bytes)));
            }),
            Kind::Invalid,
            "key times are not finite and ascending",
        ),
        ("empty.glb", Vec::new(), Kind::Empty, "empty"),
    ]
}

#[test]
fn broken_inputs_give_clear_errors() {
    let dir = out_dir("broken");
    let mut cases: Vec<(PathBuf, Kind, &str)> = Vec::new();
    for (name, bytes, kind, needle) in broken_files() {
        let path = dir.join(name);
        std::fs::write(&path, bytes).unwrap();
        cases.push((path, kind, needle));
    }
    let folder = dir.join("folder.glb");
    std::fs::create_dir_all(&folder).unwrap();
    cases.push((folder, Kind::IsDirectory, "directory"));
    // What `skin` reads (all but the stored weights) refuses the same files.
    let skinning = |path: &Path| gltf::read_contents(path, atlas_skin_io::Contents::ForSkinning);
    for (path, kind, needle) in cases {
        for read in [gltf::read, skinning] {
            let error = match read(&path) {
                Ok(_) => panic!("{} was accepted", path.display()),
                Err(error) => error,
            };
            let message = error.to_string();
            assert!(
                kind_matches(&error, kind),
                "{}: expected {kind:?}, got {error:?}",
                path.display()
            );
            assert!(message.contains(&path.display().to_string()), "{message}");
            assert!(message.contains(needle), "{message} (expected {needle:?})");
        }
    }
}

/// A skin whose bind matrix is singular is rejected by the skeleton check.
#[test]
fn singular_bind_matrices_are_rejected() {
    let (mut json, _) = simpleskin();
    // inverseBindMatrices live in buffer 2; zero them through a fresh data: URI.
    use base64::Engine;
    json["buffers"][2]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode([0u8; 128])
    ));
    let path = out_dir("singular").join("singular.gltf");
    std::fs::write(&path, json.to_string()).unwrap();
    let error = gltf::read(&path).unwrap_err();
    assert!(kind_matches(&error, Kind::Skeleton), "{error:?}");
    assert!(error.to_string().contains("singular"), "{error}");
}

/// Truncations and random bit flips of corpus files: the reader returns, never panics.
#[test]
fn damaged_files_never_panic() {
    let dir = out_dir("fuzz");
    let glb = riggedsimple_glb();
    let gltf_text = std::fs::read(model_path("simpleskin", "SimpleSkin.gltf")).unwrap();
    let mut checked = 0;
    for (name, original) in [("fuzz.glb", &glb), ("fuzz.gltf", &gltf_text)] {
        let path: &Path = &dir.join(name);
        let variants = atlas_skin_corpus::damaged_copies(original, 200, 600, 2008);
        for bytes in variants {
            std::fs::write(path, &bytes).unwrap();
            if let Err(error) = gltf::read(path) {
                assert!(error.to_string().contains(name), "{error}");
            }
            checked += 1;
        }
    }
    assert!(checked > 1000);
}

/// Every number of SimpleSkin's JSON (indices, counts, offsets, types, transforms) set to
/// values that break it in many ways: the reader returns, never panics.
#[test]
fn damaged_json_values_never_panic() {
    fn number_pointers(value: &Value, pointer: String, out: &mut Vec<String>) {
        match value {
            Value::Number(_) => out.push(pointer),
            Value::Array(items) => {
                for (i, item) in items.iter().enumerate() {
                    number_pointers(item, format!("{pointer}/{i}"), out);
                }
            }
            Value::Object(map) => {
                for (key, item) in map {
                    number_pointers(item, format!("{pointer}/{key}"), out);
                }
            }
            _ => {}
        }
    }
    let (json, _) = simpleskin();
    let mut pointers = Vec::new();
    number_pointers(&json, String::new(), &mut pointers);
    let replacements = [
        json!(0),
        json!(1),
        json!(-1),
        json!(3),
        json!(7),
        json!(0.5),
        json!(4_294_967_296u64),
        json!(1e30),
        json!(5121),
        json!(5126),
    ];
    let dir = out_dir("fuzz_json");
    let (path, out) = (dir.join("fuzz.gltf"), dir.join("out.glb"));
    for pointer in &pointers {
        for replacement in &replacements {
            let mut damaged = json.clone();
            *damaged.pointer_mut(pointer).unwrap() = replacement.clone();
            std::fs::write(&path, damaged.to_string()).unwrap();
            match gltf::read(&path) {
                Err(error) => assert!(error.to_string().contains("fuzz.gltf"), "{error}"),
                Ok(character) => {
                    // Whatever was accepted can be written back.
                    if let Some(weights) = &character.reference_weights {
                        let options = WriteOptions::default();
                        let _ = gltf::write_skinned_glb(&character, weights, &options, &out);
                    }
                }
            }
        }
    }
    assert!(pointers.len() > 50);
}
