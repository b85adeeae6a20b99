//! Reading the corpus glTF models: counts, joints, bind pose, weights and animations match
//! each model's manifest.json.

mod gltf_support;

use atlas_skin_io::gltf;
use glam::Vec3;
use gltf_support::{manifest, model_path, out_dir, GLTF_MODELS};
use serde_json::Value;

fn vec3(value: &Value) -> Vec3 {
    let a: Vec<f32> = value
        .as_array()
        .unwrap()
        .iter()
        .map(|v| v.as_f64().unwrap() as f32)
        .collect();
    Vec3::from_slice(&a)
}

#[test]
fn corpus_models_match_their_manifests() {
    for (model, file) in GLTF_MODELS {
        let manifest = manifest(model);
        let character = gltf::read(&model_path(model, file)).unwrap();
        let mesh = &character.mesh;

        let mut referenced = vec![false; mesh.positions.len()];
        for &v in mesh.triangles.iter().flatten() {
            referenced[v as usize] = true;
        }
        let stored = referenced.iter().filter(|&&r| r).count();
        assert_eq!(stored as u64, manifest["stored_vertex_count"], "{model}");
        assert_eq!(
            mesh.triangles.len() as u64,
            manifest["triangle_count"],
            "{model}"
        );

        let skeleton = character.skeleton.as_ref().expect("a skin");
        let names: Vec<&str> = manifest["joint_names"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap())
            .collect();
        assert_eq!(skeleton.names, names, "{model}");

        let diagonal = vec3(&manifest["bbox_max"]).distance(vec3(&manifest["bbox_min"]));
        let bind = skeleton.bind_positions();
        let rig = character.rig.as_ref().unwrap();
        for (j, joint) in manifest["joints"].as_array().unwrap().iter().enumerate() {
            let expected = vec3(&joint["bind_position"]);
            assert!(
                bind[j].distance(expected) <= 1e-3 * diagonal,
                "{model} joint {j}: {} vs {expected}",
                bind[j]
            );
            let parent = skeleton.parent(j).map(|p| skeleton.names[p].as_str());
            assert_eq!(parent, joint["parent"].as_str(), "{model} joint {j} parent");
            assert_eq!(
                rig.joint_nodes[j] as u64, joint["gltf_node"],
                "{model} joint {j}"
            );
        }

        let weights = character
            .reference_weights
            .as_ref()
            .expect("artist weights");
        assert_eq!(weights.vertex_count(), mesh.positions.len(), "{model}");
        assert!(weights.validate(skeleton.len()).is_ok(), "{model}");
        assert_eq!(
            weights.max_influences() as u64,
            manifest["weights"]["max_influences_per_vertex"],
            "{model}"
        );

        let animations = manifest["animations"].as_array().unwrap();
        assert_eq!(character.clips.len(), animations.len(), "{model}");
        for (clip, expected) in character.clips.iter().zip(animations) {
            assert_eq!(clip.tracks.len() as u64, expected["channels"], "{model}");
            let duration = expected["duration_s"].as_f64().unwrap() as f32;
            assert!((clip.duration - duration).abs() < 1e-3, "{model} duration");
        }
        let source = character.gltf.as_ref().unwrap();
        assert_eq!(source.skin, Some(0));
        assert_eq!(source.primitives.len(), 1, "{model}");
        assert!(
            character.warnings.is_empty(),
            "{model}: {:?}",
            character.warnings
        );
    }
}

/// SimpleSkin with its base64 buffers moved to files beside the document (one with a
/// space in its name, percent-encoded in the URI) reads exactly like the embedded file.
#[test]
fn external_buffers_read_like_embedded_ones() {
    let embedded_path = model_path("simpleskin", "SimpleSkin.gltf");
    let mut json: Value = serde_json::from_slice(&std::fs::read(&embedded_path).unwrap()).unwrap();
    let dir = out_dir("external_buffers");
    for (i, buffer) in json["buffers"]
        .as_array_mut()
        .unwrap()
        .iter_mut()
        .enumerate()
    {
        let uri = buffer["uri"].as_str().unwrap();
        let payload = uri.split_once(',').unwrap().1;
        use base64::Engine;
        let bytes = base64::engine::general_purpose::STANDARD
            .decode(payload)
            .unwrap();
        let name = format!("buffer {i}.bin");
        std::fs::write(dir.join(&name), bytes).unwrap();
        buffer["uri"] = Value::from(name.replace(' ', "%20"));
    }
    let external_path = dir.join("SimpleSkin.gltf");
    std::fs::write(&external_path, json.to_string()).unwrap();

    let embedded = gltf::read(&embedded_path).unwrap();
    let external = gltf::read(&external_path).unwrap();
    assert_eq!(embedded.mesh, external.mesh);
    assert_eq!(embedded.skeleton, external.skeleton);
    assert_eq!(embedded.reference_weights, external.reference_weights);
    assert_eq!(embedded.clips, external.clips);
}

/// Without a skin, every mesh node is read with its world transform; a TRIANGLE_STRIP
/// primitive is converted, and points are skipped with a warning.
#[test]
fn unskinned_documents_apply_node_transforms_and_convert_strips() {
    use base64::Engine;
    let positions: [[f32; 3]; 4] = [[0., 0., 0.], [1., 0., 0.], [0., 1., 0.], [1., 1., 0.]];
    let bytes: Vec<u8> = positions
        .iter()
        .flatten()
        .flat_map(|v| v.to_le_bytes())
        .collect();
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bytes)
    );
    let json = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": 48}],
        "bufferViews": [{"buffer": 0, "byteLength": 48}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3"}],
        "meshes": [{"primitives": [
            {"attributes": {"POSITION": 0}, "mode": 5},
            {"attributes": {"POSITION": 0}, "mode": 0}
        ]}],
        "nodes": [
            {"children": [1], "translation": [0, 0, 5]},
            {"mesh": 0, "scale": [2, 2, 2]}
        ],
        "scenes": [{"nodes": [0]}]
    });
    let path = out_dir("unskinned").join("strip.gltf");
    std::fs::write(&path, json.to_string()).unwrap();
    let character = gltf::read(&path).unwrap();
    assert!(character.skeleton.is_none());
    assert!(character.reference_weights.is_none());
    assert_eq!(character.mesh.triangles, vec![[0, 1, 2], [2, 1, 3]]);
    assert_eq!(character.mesh.positions[3], Vec3::new(2.0, 2.0, 5.0));
    assert_eq!(character.warnings.len(), 1, "{:?}", character.warnings);
}

/// The UTF-8 byte-order mark glTF forbids but some exporters write before the JSON (of a
/// `.gltf`, or of a `.glb`'s JSON chunk): the file reads like the one without it, with a
/// warning that names the mark.
#[test]
fn a_byte_order_mark_is_accepted_with_a_warning() {
    const BOM: &[u8] = b"\xEF\xBB\xBF";
    let dir = out_dir("byte_order_mark");
    let text_path = model_path("simpleskin", "SimpleSkin.gltf");
    let text_with_mark = dir.join("SimpleSkin.gltf");
    std::fs::write(
        &text_with_mark,
        [BOM, &std::fs::read(&text_path).unwrap()].concat(),
    )
    .unwrap();

    let glb_path = model_path("riggedsimple", "RiggedSimple.glb");
    let glb = std::fs::read(&glb_path).unwrap();
    let json_length = u32::from_le_bytes(glb[12..16].try_into().unwrap()) as usize;
    // The chunk again: the mark, the JSON without its padding, padding to 4 bytes.
    let json = glb[20..20 + json_length].trim_ascii_end();
    let mut chunk = [BOM, json].concat();
    chunk.resize(chunk.len().next_multiple_of(4), b' ');
    let rest = &glb[20 + json_length..];
    let total = (20 + chunk.len() + rest.len()) as u32;
    let binary_with_mark = dir.join("RiggedSimple.glb");
    std::fs::write(
        &binary_with_mark,
        [
            &glb[..8],
            &total.to_le_bytes(),
            &(chunk.len() as u32).to_le_bytes(),
            &glb[16..20],
            &chunk,
            rest,
        ]
        .concat(),
    )
    .unwrap();

    for (plain, marked) in [(text_path, text_with_mark), (glb_path, binary_with_mark)] {
        let plain = gltf::read(&plain).unwrap();
        let marked = gltf::read(&marked).unwrap();
        assert_eq!(plain.mesh, marked.mesh);
        assert_eq!(plain.skeleton, marked.skeleton);
        assert_eq!(plain.reference_weights, marked.reference_weights);
        let mentions_mark = |w: &Vec<String>| w.iter().any(|w| w.contains("byte-order mark"));
        assert!(!mentions_mark(&plain.warnings));
        assert!(mentions_mark(&marked.warnings), "{:?}", marked.warnings);
    }
}

/// What skinning reads ([`gltf::read_contents`] with `Contents::ForSkinning`) is what
/// [`gltf::read`] reads but the stored weights: the same mesh, skeleton, rig, warnings
/// (RobotExpressive's animations have channels that are ignored with a warning), source
/// document and clips.
#[test]
fn reading_for_skinning_skips_only_the_stored_weights() {
    let robot = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../../shared/data/bench/robotexpressive/RobotExpressive.glb"
    );
    let files = GLTF_MODELS
        .iter()
        .map(|(model, file)| model_path(model, file))
        .chain([std::path::PathBuf::from(robot)]);
    for path in files {
        let whole = gltf::read(&path).unwrap();
        let skinning = gltf::read_contents(&path, atlas_skin_io::Contents::ForSkinning).unwrap();
        let name = path.display();
        assert_eq!(skinning.mesh, whole.mesh, "{name}");
        assert_eq!(skinning.skeleton, whole.skeleton, "{name}");
        assert_eq!(skinning.rig, whole.rig, "{name}");
        assert_eq!(skinning.warnings, whole.warnings, "{name}");
        assert_eq!(skinning.file_vertex, whole.file_vertex, "{name}");
        let (a, b) = (skinning.gltf.unwrap(), whole.gltf.unwrap());
        assert_eq!(a.document, b.document, "{name}");
        assert_eq!(a.buffers, b.buffers, "{name}");
        assert_eq!(a.primitives, b.primitives, "{name}");
        assert_eq!(
            (a.skin, a.inverse_binds_cleaned),
            (b.skin, b.inverse_binds_cleaned)
        );
        assert!(skinning.reference_weights.is_none(), "{name}");
        assert_eq!(skinning.clips, whole.clips, "{name}");
    }
    let whole = gltf::read(std::path::Path::new(robot)).unwrap();
    assert!(whole.reference_weights.is_some() && !whole.clips.is_empty());
    assert!(whole.warnings.iter().any(|w| w.contains("animations[0]")));
}
