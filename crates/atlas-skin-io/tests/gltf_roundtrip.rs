//! glTF read → write → read: everything but the weights is kept, the weights come back
//! normalised in float32, and every file written passes the Khronos validator.

mod gltf_support;

use atlas_skin_io::gltf::{self, debug_glb, write_skinned_glb, WriteOptions};
use atlas_skin_io::OutputPlan;
use atlas_skin_io::{Character, IoError};
use atlas_skin_runtime::{Clip, Interpolation, Property, Track, VertexWeights};
use glam::Vec3;
use gltf_support::{assert_valid, model_path, out_dir, resolve_accessors, GLTF_MODELS};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};

/// A 1×1 RGBA PNG.
const PIXEL_PNG: [u8; 70] = [
    0x89, 0x50, 0x4e, 0x47, 0x0d, 0x0a, 0x1a, 0x0a, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x48, 0x44, 0x52,
    0x00, 0x00, 0x00, 0x01, 0x00, 0x00, 0x00, 0x01, 0x08, 0x06, 0x00, 0x00, 0x00, 0x1f, 0x15, 0xc4,
    0x89, 0x00, 0x00, 0x00, 0x0d, 0x49, 0x44, 0x41, 0x54, 0x78, 0x9c, 0x63, 0xf8, 0xcf, 0xc0, 0xf0,
    0x1f, 0x00, 0x05, 0x00, 0x01, 0xff, 0x89, 0x99, 0x3d, 0x1d, 0x00, 0x00, 0x00, 0x00, 0x49, 0x45,
    0x4e, 0x44, 0xae, 0x42, 0x60, 0x82,
];

/// SimpleSkin with a material, an external PNG image, a texture, a sampler, extras and an
/// extension added, written into `dir`.
fn decorated_simpleskin(dir: &Path) -> PathBuf {
    let source = model_path("simpleskin", "SimpleSkin.gltf");
    let mut json: Value = serde_json::from_slice(&std::fs::read(source).unwrap()).unwrap();
    std::fs::write(dir.join("pixel.png"), PIXEL_PNG).unwrap();
    json["images"] = json!([{"uri": "pixel.png", "name": "pixel"}]);
    json["samplers"] = json!([{"magFilter": 9728}]);
    json["textures"] = json!([{"source": 0, "sampler": 0}]);
    json["materials"] = json!([{
        "name": "red",
        "pbrMetallicRoughness": {"baseColorFactor": [1, 0, 0, 1]},
        "extensions": {"KHR_materials_unlit": {}},
        "extras": {"note": "material extras"}
    }]);
    json["extensionsUsed"] = json!(["KHR_materials_unlit"]);
    json["meshes"][0]["primitives"][0]["material"] = json!(0);
    json["meshes"][0]["name"] = json!("strip");
    json["nodes"][1]["name"] = json!("root joint");
    json["nodes"][1]["extras"] = json!({"tag": 7});
    json["asset"]["extras"] = json!({"author": "test"});
    let path = dir.join("decorated.gltf");
    std::fs::write(&path, json.to_string()).unwrap();
    path
}

/// Reads `input`, writes it with its own reference weights and `options` to `out`, reads
/// the output back.
fn round_trip(input: &Path, out: &Path, options: &WriteOptions) -> (Character, Character) {
    let before = gltf::read(input).unwrap();
    let weights = before.reference_weights.clone().unwrap();
    write_skinned_glb(&before, &weights, options, out).unwrap();
    let after = gltf::read(out).unwrap();
    (before, after)
}

/// Bytes of image `index`: its bufferView, or the file its URI names beside `path`.
fn image_bytes(character: &Character, index: usize) -> Vec<u8> {
    let source = character.gltf.as_ref().unwrap();
    let image = &source.document["images"][index];
    match image["uri"].as_str() {
        Some(uri) => std::fs::read(character.path.parent().unwrap().join(uri)).unwrap(),
        None => {
            let view =
                &source.document["bufferViews"][image["bufferView"].as_u64().unwrap() as usize];
            let start = view["byteOffset"].as_u64().unwrap_or(0) as usize;
            let length = view["byteLength"].as_u64().unwrap() as usize;
            source.buffers[view["buffer"].as_u64().unwrap() as usize][start..start + length]
                .to_vec()
        }
    }
}

/// Everything but JOINTS_n/WEIGHTS_n, the accessor numbering and the buffer layout is the
/// same in both documents, down to the bytes of every accessor still used and every image.
fn assert_document_preserved(before: &Character, after: &Character, model: &str) {
    let (a, b) = (before.gltf.as_ref().unwrap(), after.gltf.as_ref().unwrap());
    let (resolved_a, resolved_b) = (
        resolve_accessors(&a.document, &a.buffers),
        resolve_accessors(&b.document, &b.buffers),
    );
    for key in [
        "nodes",
        "scenes",
        "scene",
        "skins",
        "materials",
        "textures",
        "samplers",
        "extensionsUsed",
    ] {
        assert_eq!(resolved_a.get(key), resolved_b.get(key), "{model}: {key}");
    }
    assert_eq!(
        a.document["asset"]["version"],
        b.document["asset"]["version"]
    );
    assert_eq!(
        a.document["asset"]["generator"],
        b.document["asset"]["generator"]
    );
    let animations = resolved_a["animations"].as_array().unwrap();
    assert_eq!(
        &resolved_b["animations"].as_array().unwrap()[..animations.len()],
        &animations[..],
        "{model}: animations"
    );
    let meshes_b = &resolved_b["meshes"];
    for (m, mesh) in resolved_a["meshes"].as_array().unwrap().iter().enumerate() {
        for (p, primitive) in mesh["primitives"].as_array().unwrap().iter().enumerate() {
            let other = &meshes_b[m]["primitives"][p];
            for (key, value) in primitive.as_object().unwrap() {
                if key != "attributes" {
                    assert_eq!(&other[key], value, "{model}: primitive {key}");
                }
            }
            for (name, value) in primitive["attributes"].as_object().unwrap() {
                if !(name.starts_with("JOINTS_") || name.starts_with("WEIGHTS_")) {
                    assert_eq!(&other["attributes"][name], value, "{model}: {name}");
                }
            }
        }
    }
    let images = a
        .document
        .get("images")
        .and_then(Value::as_array)
        .map_or(0, Vec::len);
    for index in 0..images {
        assert_eq!(
            image_bytes(before, index),
            image_bytes(after, index),
            "{model}: image {index}"
        );
        assert_eq!(
            a.document["images"][index]["name"],
            b.document["images"][index]["name"]
        );
    }
}

/// The weights written are the input's `max_influences` largest, normalised; each stored
/// row sums to 1 within 1e-6.
fn assert_weights_normalised(input: &VertexWeights, output: &VertexWeights, max_influences: usize) {
    let expected = input.pruned(max_influences);
    assert_eq!(expected.vertex_count(), output.vertex_count());
    for v in 0..output.vertex_count() {
        let mut a: Vec<(u32, f32)> = expected.row(v).collect();
        let mut b: Vec<(u32, f32)> = output.row(v).collect();
        a.sort_by_key(|e| e.0);
        b.sort_by_key(|e| e.0);
        assert_eq!(a.len(), b.len(), "vertex {v}: {a:?} vs {b:?}");
        for ((ja, wa), (jb, wb)) in a.iter().zip(&b) {
            assert_eq!(ja, jb, "vertex {v}");
            assert!((wa - wb).abs() <= 1e-6, "vertex {v}: {wa} vs {wb}");
        }
        let sum: f32 = b.iter().map(|e| e.1).sum();
        assert!((sum - 1.0).abs() <= 1e-6, "vertex {v} sums to {sum}");
    }
}

#[test]
fn corpus_round_trip_keeps_everything_but_the_weights() {
    let dir = out_dir("round_trip");
    let mut inputs: Vec<(String, PathBuf)> = GLTF_MODELS
        .iter()
        .map(|(model, file)| (model.to_string(), model_path(model, file)))
        .collect();
    inputs.push(("decorated".into(), decorated_simpleskin(&dir)));
    let mut outputs = Vec::new();
    for (model, input) in inputs {
        let out = dir.join(format!("{model}.glb"));
        let options = WriteOptions {
            extras: Some(json!({"atlas_skin": {"model": model}})),
            ..WriteOptions::default()
        };
        let (before, after) = round_trip(&input, &out, &options);
        if input.extension().is_some_and(|e| e == "glb") {
            // The old weights' bytes are dropped, and the new ones (one byte per joint
            // index) are no larger than the corpus's: the file does not grow.
            let size = |path: &Path| std::fs::metadata(path).unwrap().len();
            assert!(
                size(&out) <= size(&input),
                "{model}: {} bytes written for {} read",
                size(&out),
                size(&input)
            );
        }
        assert_eq!(before.mesh, after.mesh, "{model}");
        assert_eq!(before.skeleton, after.skeleton, "{model}");
        assert_eq!(before.rig, after.rig, "{model}");
        assert_eq!(before.clips, after.clips, "{model}");
        assert_document_preserved(&before, &after, &model);
        let extras = &after.gltf.as_ref().unwrap().document["asset"]["extras"];
        assert_eq!(extras["atlas_skin"]["model"], json!(model));
        assert_weights_normalised(
            before.reference_weights.as_ref().unwrap(),
            after.reference_weights.as_ref().unwrap(),
            4,
        );
        if model == "decorated" {
            let document = &after.gltf.as_ref().unwrap().document;
            assert_eq!(extras["author"], "test", "asset extras merged");
            assert!(document["images"][0].get("uri").is_none(), "image embedded");
            assert_eq!(document["images"][0]["mimeType"], "image/png");
            assert_eq!(document["buffers"].as_array().unwrap().len(), 1);
        }
        outputs.push(out);
    }
    assert_valid(&outputs);
}

/// The writer that takes the input's document instead of copying it writes the same bytes,
/// and leaves no document behind.
#[test]
fn taking_the_document_writes_the_same_bytes() {
    let dir = out_dir("taking_the_document");
    let mut inputs: Vec<PathBuf> = GLTF_MODELS
        .iter()
        .map(|(model, file)| model_path(model, file))
        .collect();
    inputs.push(decorated_simpleskin(&dir));
    for input in inputs {
        let mut character = gltf::read(&input).unwrap();
        let weights = character.reference_weights.clone().unwrap();
        let out = dir.join("out.glb");
        let options = WriteOptions::default();
        let copied = gltf::skinned_glb(&character, &weights, &options, &out).unwrap();
        let taken =
            gltf::skinned_glb_taking_document(&mut character, &weights, &options, &out).unwrap();
        assert!(copied == taken, "{}", input.display());
        assert_eq!(character.gltf.unwrap().document, Value::Null);
    }
}

/// Eight influences per vertex go into JOINTS_0/1 and WEIGHTS_0/1; with four, the input's
/// second set is removed.
#[test]
fn more_than_four_influences_use_a_second_set() {
    let dir = out_dir("eight_influences");
    let character = gltf::read(&model_path("cesiumman", "CesiumMan.glb")).unwrap();
    let joints = character.skeleton.as_ref().unwrap().len() as u32;
    let weights = VertexWeights::from_rows(
        (0..character.mesh.positions.len() as u32)
            .map(|v| (0..6).map(move |k| ((v + 3 * k) % joints, 1.0 + k as f32))),
    );
    let wide = dir.join("wide.glb");
    let options = WriteOptions {
        max_influences: 8,
        ..WriteOptions::default()
    };
    write_skinned_glb(&character, &weights, &options, &wide).unwrap();
    let read_wide = gltf::read(&wide).unwrap();
    assert_weights_normalised(&weights, read_wide.reference_weights.as_ref().unwrap(), 8);
    let attributes =
        &read_wide.gltf.as_ref().unwrap().document["meshes"][0]["primitives"][0]["attributes"];
    assert!(attributes.get("JOINTS_1").is_some() && attributes.get("WEIGHTS_1").is_some());

    let narrow = dir.join("narrow.glb");
    write_skinned_glb(&read_wide, &weights, &WriteOptions::default(), &narrow).unwrap();
    let read_narrow = gltf::read(&narrow).unwrap();
    assert_weights_normalised(&weights, read_narrow.reference_weights.as_ref().unwrap(), 4);
    let attributes =
        &read_narrow.gltf.as_ref().unwrap().document["meshes"][0]["primitives"][0]["attributes"];
    assert!(attributes.get("JOINTS_1").is_none() && attributes.get("WEIGHTS_1").is_none());
    assert_valid(&[wide, narrow]);
}

/// A clip on skeleton joint 1: one rotation track.
fn bend_clip() -> Clip {
    let half = std::f32::consts::FRAC_1_SQRT_2;
    Clip {
        name: "bend".into(),
        duration: 1.0,
        tracks: vec![Track {
            node: 1,
            property: Property::Rotation,
            interpolation: Interpolation::Linear,
            times: vec![0.0, 1.0],
            values: vec![0.0, 0.0, 0.0, 1.0, half, 0.0, 0.0, half],
        }],
    }
}

/// Extra clips are appended with their tracks moved from joint indices to joint nodes.
#[test]
fn extra_clips_target_the_joint_nodes() {
    let dir = out_dir("extra_clips");
    let out = dir.join("bend.glb");
    let options = WriteOptions {
        animations: vec![bend_clip()],
        ..WriteOptions::default()
    };
    let (before, after) = round_trip(
        &model_path("riggedsimple", "RiggedSimple.glb"),
        &out,
        &options,
    );
    assert_eq!(after.clips.len(), before.clips.len() + 1);
    let added = after.clips.last().unwrap();
    let mut expected = bend_clip();
    expected.tracks[0].node = before.rig.as_ref().unwrap().joint_nodes[1];
    assert_eq!(added, &expected);
    assert_valid(&[out]);
}

/// A character that did not come from glTF gets a new document: the same mesh, skeleton,
/// weights (normalised) and clips come back.
#[test]
fn non_gltf_characters_get_a_new_document() {
    let dir = out_dir("new_document");
    let mut character = gltf::read(&model_path("riggedsimple", "RiggedSimple.glb")).unwrap();
    character.gltf = None;
    character.path = dir.join("cylinder.obj");
    let weights = character.reference_weights.clone().unwrap();
    let out = dir.join("cylinder.glb");
    let options = WriteOptions {
        animations: vec![bend_clip()],
        ..WriteOptions::default()
    };
    write_skinned_glb(&character, &weights, &options, &out).unwrap();
    let after = gltf::read(&out).unwrap();
    assert_eq!(after.mesh, character.mesh);
    let (skeleton, read_skeleton) = (
        character.skeleton.as_ref().unwrap(),
        after.skeleton.as_ref().unwrap(),
    );
    assert_eq!(read_skeleton.names, skeleton.names);
    assert_eq!(read_skeleton.parents, skeleton.parents);
    for (a, b) in read_skeleton
        .inverse_bind
        .iter()
        .zip(&skeleton.inverse_bind)
    {
        assert!(a.abs_diff_eq(*b, 1e-6));
    }
    assert_weights_normalised(&weights, after.reference_weights.as_ref().unwrap(), 4);
    let rig = after.rig.as_ref().unwrap();
    let rest_world: Vec<Vec3> = (0..skeleton.len())
        .map(|j| {
            let mut node = rig.joint_nodes[j] as usize;
            let mut world = rig.rest[node].matrix();
            while rig.parents[node] != u32::MAX {
                node = rig.parents[node] as usize;
                world = rig.rest[node].matrix() * world;
            }
            world.w_axis.truncate()
        })
        .collect();
    for (a, b) in rest_world.iter().zip(skeleton.bind_positions()) {
        assert!(a.distance(b) < 1e-4, "rest pose = bind pose: {a} vs {b}");
    }
    assert_eq!(after.clips.len(), 1);
    assert_eq!(after.clips[0].tracks[0].node, rig.joint_nodes[1]);
    assert_valid(&[out]);
}

#[test]
fn debug_glb_is_valid() {
    let dir = out_dir("debug");
    let positions = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let triangles = [[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]];
    let colors = [
        [1.0, 0.0, 0.0, 1.0],
        [0.0, 1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0, 1.0],
        [1.0; 4],
    ];
    let lines = [[Vec3::ZERO, Vec3::ONE], [Vec3::X, Vec3::Y]];
    let out = dir.join("debug.glb");
    let lines_only = dir.join("lines.glb");
    let plan = OutputPlan::new([], [out.as_path(), lines_only.as_path()]).unwrap();
    let full = debug_glb(
        &positions,
        &triangles,
        &colors,
        &lines,
        [1.0, 1.0, 0.0, 1.0],
        &out,
    )
    .unwrap();
    plan.write(&out, &full).unwrap();
    let bytes = debug_glb(&[], &[], &[], &lines, [0.0, 0.0, 0.0, 1.0], &lines_only).unwrap();
    plan.write(&lines_only, &bytes).unwrap();
    let bad = dir.join("bad.glb");
    let error = debug_glb(&positions, &[[0, 1, 4]], &[], &[], [1.0; 4], &bad).unwrap_err();
    assert!(error.to_string().contains("bad.glb"), "{error}");
    assert_valid(&[out, lines_only]);
}

/// The writer refuses to overwrite its input and leaves no file when it fails.
#[test]
fn failed_writes_leave_nothing_behind() {
    let dir = out_dir("failed_writes");
    let input = dir.join("RiggedSimple.glb");
    std::fs::copy(model_path("riggedsimple", "RiggedSimple.glb"), &input).unwrap();
    let original = std::fs::read(&input).unwrap();
    let character = gltf::read(&input).unwrap();
    let weights = character.reference_weights.clone().unwrap();
    let options = WriteOptions::default();

    let error = write_skinned_glb(&character, &weights, &options, &input).unwrap_err();
    assert!(
        matches!(error, IoError::WouldOverwriteInput { .. }),
        "{error}"
    );
    let same_file_other_spelling = dir.join(".").join("RiggedSimple.glb");
    let error =
        write_skinned_glb(&character, &weights, &options, &same_file_other_spelling).unwrap_err();
    assert!(
        matches!(error, IoError::WouldOverwriteInput { .. }),
        "{error}"
    );
    assert_eq!(std::fs::read(&input).unwrap(), original);

    let out = dir.join("out.glb");
    let short = VertexWeights::from_rows(vec![vec![(0u32, 1.0f32)]; 3]);
    assert!(matches!(
        write_skinned_glb(&character, &short, &options, &out),
        Err(IoError::Invalid { message, .. }) if message.contains("weight rows")
    ));
    let bad_joint =
        VertexWeights::from_rows(vec![vec![(9u32, 1.0f32)]; character.mesh.positions.len()]);
    assert!(matches!(
        write_skinned_glb(&character, &bad_joint, &options, &out),
        Err(IoError::Invalid { message, .. }) if message.contains("bad weights")
    ));
    // A missing output folder is created, but not below a file.
    let below_a_file = input.join("out.glb");
    let error = write_skinned_glb(&character, &weights, &options, &below_a_file).unwrap_err();
    assert!(matches!(error, IoError::Write { .. }), "{error}");
    let left: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    assert_eq!(left, vec![std::ffi::OsString::from("RiggedSimple.glb")]);
    let in_new_folder = dir.join("new folder").join("out.glb");
    write_skinned_glb(&character, &weights, &options, &in_new_folder).unwrap();
    assert!(in_new_folder.is_file());
}

/// Two primitives sharing SimpleSkin's POSITION accessor share their vertices in the
/// mesh, and both get the same new weight accessors.
#[test]
fn primitives_sharing_positions_share_vertices_and_weights() {
    let dir = out_dir("shared_positions");
    let source = model_path("simpleskin", "SimpleSkin.gltf");
    let mut json: Value = serde_json::from_slice(&std::fs::read(source).unwrap()).unwrap();
    let accessors = json["accessors"].as_array_mut().unwrap();
    let first_half = accessors.len();
    accessors.push(json!({"bufferView": 0, "componentType": 5123, "count": 12, "type": "SCALAR"}));
    accessors.push(json!({"bufferView": 0, "byteOffset": 24, "componentType": 5123, "count": 12, "type": "SCALAR"}));
    let mut second = json["meshes"][0]["primitives"][0].clone();
    json["meshes"][0]["primitives"][0]["indices"] = json!(first_half);
    second["indices"] = json!(first_half + 1);
    json["meshes"][0]["primitives"]
        .as_array_mut()
        .unwrap()
        .push(second);
    let input = dir.join("split.gltf");
    std::fs::write(&input, json.to_string()).unwrap();

    let out = dir.join("split.glb");
    let (before, after) = round_trip(&input, &out, &WriteOptions::default());
    assert_eq!(before.mesh.positions.len(), 10);
    assert_eq!(before.mesh.triangles.len(), 8);
    let primitives = &before.gltf.as_ref().unwrap().primitives;
    assert_eq!(primitives.len(), 2);
    assert_eq!(primitives[0].vertices, primitives[1].vertices);
    assert_eq!(
        (
            primitives[0].triangles.clone(),
            primitives[1].triangles.clone()
        ),
        (0..4, 4..8)
    );
    assert_eq!(before.mesh, after.mesh);
    let written = &after.gltf.as_ref().unwrap().document["meshes"][0]["primitives"];
    assert_eq!(written[0]["attributes"], written[1]["attributes"]);
    assert_valid(&[out]);
}
