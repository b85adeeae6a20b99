//! Characters made of several meshes: skins sharing one skeleton (each with its own inverse
//! bind matrices and joint order) and rigid meshes parented to joint nodes.

mod gltf_support;

use atlas_skin_io::gltf::{self, write_skinned_glb, Binding, WriteOptions};
use glam::{Mat4, Quat, Vec3};
use gltf_support::{assert_valid, data_dir, out_dir};
use serde_json::{json, Value};

/// Little-endian bytes of f32 values.
fn floats(values: &[f32]) -> Vec<u8> {
    values.iter().flat_map(|v| v.to_le_bytes()).collect()
}

/// A document with two joints (`root` at the origin; `arm` at (1, 0, 0), bound unrotated
/// but posed turned 90° about z in the document) and five meshes of one triangle:
/// - mesh 0 on skins[0] (joints root, arm), weights on arm (index 1);
/// - mesh 1 on skins[1] (joints arm, root: another order), its bind space 5 along +z from
///   skins[0]'s (IBM₁ = IBM₀ · T(0, 0, 5)), weights on arm (index 0);
/// - mesh 2 without skin on a node under arm, 2 along +y of arm;
/// - mesh 3 without skin under no joint; mesh 4 on skins[2], over root only.
fn several_skins_document() -> Value {
    let triangle = [0., 0., 0., 1., 0., 0., 0., 1., 0.];
    let arm_bind = Mat4::from_translation(Vec3::X).inverse();
    let shift = Mat4::from_translation(Vec3::new(0.0, 0.0, 5.0));
    let ibm0 = [Mat4::IDENTITY, arm_bind];
    let ibm1 = [arm_bind * shift, shift];
    let mut bytes = floats(&triangle); // 0: positions, 36 bytes
    bytes.extend([1u8, 0, 0, 0].repeat(3)); // 36: joints of mesh 0
    bytes.extend([0u8, 0, 0, 0].repeat(3)); // 48: joints of mesh 1
    bytes.extend(floats(&[1., 0., 0., 0.].repeat(3))); // 60: weights, 48 bytes
    for m in ibm0.iter().chain(&ibm1).chain([&Mat4::IDENTITY]) {
        bytes.extend(floats(&m.to_cols_array())); // 108, 172, 236, 300, 364
    }
    use base64::Engine;
    let uri = format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(&bytes)
    );
    let view = |offset: usize, length: usize| json!({"buffer": 0, "byteOffset": offset, "byteLength": length});
    let skinned = |joints: usize| json!({"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": joints, "WEIGHTS_0": 3}}]});
    let plain = json!({"primitives": [{"attributes": {"POSITION": 0}}]});
    let turned = Quat::from_rotation_z(std::f32::consts::FRAC_PI_2);
    json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": uri, "byteLength": bytes.len()}],
        "bufferViews": [view(0, 36), view(36, 12), view(48, 12), view(60, 48), view(108, 128),
            view(236, 128), view(364, 64)],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5121, "count": 3, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5121, "count": 3, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC4"},
            {"bufferView": 4, "componentType": 5126, "count": 2, "type": "MAT4"},
            {"bufferView": 5, "componentType": 5126, "count": 2, "type": "MAT4"},
            {"bufferView": 6, "componentType": 5126, "count": 1, "type": "MAT4"}
        ],
        "meshes": [skinned(1), skinned(2), plain.clone(), plain, skinned(2)],
        "skins": [
            {"joints": [0, 1], "inverseBindMatrices": 4},
            {"joints": [1, 0], "inverseBindMatrices": 5},
            {"joints": [0], "inverseBindMatrices": 6}
        ],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "arm", "translation": [1, 0, 0], "rotation": turned.to_array(),
             "children": [2]},
            {"name": "visor", "translation": [0, 2, 0], "mesh": 2},
            {"name": "body", "mesh": 0, "skin": 0},
            {"name": "hand", "mesh": 1, "skin": 1},
            {"name": "prop", "mesh": 3},
            {"name": "other", "mesh": 4, "skin": 2}
        ],
        "scenes": [{"nodes": [0, 3, 4, 5, 6]}]
    })
}

/// Every mesh of the skins over the skeleton's joints is read into the first skin's bind
/// space, the rigid mesh where it sits relative to its joint (weight 1 on it), and the
/// meshes left out are named in warnings; the written file keeps every mesh, gives each
/// skinned mesh weights in its own skin's joint order and passes the Khronos validator.
#[test]
fn skins_sharing_a_skeleton_and_rigid_meshes_are_read_and_written() {
    let dir = out_dir("several_skins");
    let input = dir.join("several.gltf");
    std::fs::write(&input, several_skins_document().to_string()).unwrap();
    let character = gltf::read(&input).unwrap();

    let p = &character.mesh.positions;
    assert_eq!(p.len(), 9);
    let triangle = [Vec3::ZERO, Vec3::X, Vec3::Y];
    for k in 0..3 {
        assert!(p[k].abs_diff_eq(triangle[k], 1e-6), "{p:?}");
        let shifted = triangle[k] + Vec3::new(0.0, 0.0, 5.0);
        assert!(p[3 + k].abs_diff_eq(shifted, 1e-5), "{p:?}");
        // Posed arm: 2 along its y; unposed (bind): arm at (1, 0, 0), so (1, 2, 0) + v.
        let rigid = triangle[k] + Vec3::new(1.0, 2.0, 0.0);
        assert!(p[6 + k].abs_diff_eq(rigid, 1e-5), "{p:?}");
    }
    let source = character.gltf.as_ref().unwrap();
    let bindings: Vec<Binding> = source.primitives.iter().map(|p| p.binding).collect();
    assert_eq!(
        bindings,
        [Binding::Skin(0), Binding::Skin(1), Binding::Rigid(1)]
    );
    let reference = character.reference_weights.as_ref().unwrap();
    for v in 0..9 {
        assert_eq!(
            reference.row(v).collect::<Vec<_>>(),
            [(1, 1.0)],
            "vertex {v}"
        );
    }
    let warnings = character.warnings.join("\n");
    assert!(
        warnings.contains("meshes of skins[2] are not read"),
        "{warnings}"
    );
    assert!(warnings.contains("nodes[5] (prop)"), "{warnings}");

    let out = dir.join("several.glb");
    write_skinned_glb(&character, reference, &WriteOptions::default(), &out).unwrap();
    assert_valid(std::slice::from_ref(&out));
    let written = gltf::read(&out).unwrap();
    assert_eq!(written.mesh, character.mesh);
    assert_eq!(written.reference_weights, character.reference_weights);
    let document = &written.gltf.as_ref().unwrap().document;
    assert_eq!(document["meshes"].as_array().unwrap().len(), 5);
    assert_eq!(
        document["nodes"][2]["mesh"], 2,
        "the rigid mesh stays on its node"
    );
}

/// RobotExpressive (three.js): 4 skinned meshes on 4 skins over the same 43 joints and 15
/// rigid meshes under joint nodes. All are read (1,108 skinned vertices, as the file's
/// accessors count them), each hand lies at a palm joint, and every rigid part has weight
/// 1 on the joint above it.
#[test]
fn robotexpressive_reads_every_mesh() {
    let path = data_dir().join("bench/robotexpressive/RobotExpressive.glb");
    let character = gltf::read(&path).unwrap();
    let source = character.gltf.as_ref().unwrap();
    let skinned: usize = source
        .primitives
        .iter()
        .filter(|p| matches!(p.binding, Binding::Skin(_)))
        .map(|p| p.vertices.len())
        .sum();
    assert_eq!(skinned, 1108);
    let rigid = source
        .primitives
        .iter()
        .filter(|p| matches!(p.binding, Binding::Rigid(_)))
        .count();
    assert_eq!(rigid, 15);
    let skeleton = character.skeleton.as_ref().unwrap();
    let bind = skeleton.bind_positions();
    let hand = |name: &str| bind[skeleton.names.iter().position(|n| n == name).unwrap()];
    let diagonal = {
        let (lo, hi) = character.mesh.positions.iter().fold(
            (Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)),
            |(lo, hi), &p| (lo.min(p), hi.max(p)),
        );
        lo.distance(hi)
    };
    for primitive in &source.primitives {
        let vertices = &character.mesh.positions[primitive.vertices.clone()];
        let centroid = vertices.iter().copied().sum::<Vec3>() / vertices.len() as f32;
        if let Binding::Skin(_) = primitive.binding {
            let nearest = hand("Palm2L")
                .distance(centroid)
                .min(hand("Palm2R").distance(centroid));
            assert!(
                nearest < 0.1 * diagonal,
                "{primitive:?}: {nearest} of {diagonal}"
            );
        }
    }
    let reference = character.reference_weights.as_ref().unwrap();
    assert!((0..reference.vertex_count()).all(|v| reference.row(v).count() > 0));
}
