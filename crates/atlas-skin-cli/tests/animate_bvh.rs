//! `atlas-skin animate`: a BVH motion put on a character whose skeleton is the motion's
//! own comes back as a glTF animation that reproduces every joint's motion, passes the
//! Khronos validator, and as an OBJ sequence with one posed mesh per frame; a joint map puts
//! the same motion on a character whose joints have other names.

mod support;

use atlas_skin_corpus::{motion_path, node_check, CESIUMMAN};
use atlas_skin_io::gltf::{write_skinned_glb, WriteOptions};
use atlas_skin_io::{Character, TriangleMesh};
use atlas_skin_runtime::{Rig, Trs, VertexWeights};
use glam::{Mat4, Vec3};
use std::path::Path;
use support::{atlas_skin, atlas_skin_ok, obj_positions, out_dir};

/// A character made of one small tetrahedron at every joint of the BVH skeleton, each
/// bound rigidly to its joint, written as a skinned glb.
fn bvh_character(out: &Path) {
    let skeleton = atlas_skin_io::bvh::read(&motion_path("walk.bvh")).expect("read BVH skeleton");
    let corners = [Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z];
    let mut mesh = TriangleMesh::default();
    let mut rows = Vec::new();
    for (joint, position) in skeleton.bind_positions().iter().enumerate() {
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend(corners.iter().map(|c| *position + *c));
        mesh.triangles
            .extend([[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]].map(|t| t.map(|i| base + i)));
        rows.extend(std::iter::repeat_n(vec![(joint as u32, 1.0)], 4));
    }
    let mut character = Character::new("bvh-character", mesh);
    character.skeleton = Some(skeleton);
    write_skinned_glb(
        &character,
        &VertexWeights::from_rows(rows),
        &WriteOptions::default(),
        out,
    )
    .expect("write glb");
}

/// `atlas-skin animate INPUT --bvh walk.bvh -o OUT`.
fn animate(input: &Path, out: &Path) {
    let motion = motion_path("walk.bvh");
    atlas_skin_ok(&[
        Path::new("animate"),
        input,
        Path::new("--bvh"),
        &motion,
        Path::new("-o"),
        out,
    ]);
}

/// World position of every joint of `rig` in a pose.
fn joint_positions(rig: &Rig, local: &[Trs]) -> Vec<Vec3> {
    let mut world = vec![Mat4::IDENTITY; rig.len()];
    rig.world(local, &mut world);
    rig.joint_nodes
        .iter()
        .map(|&n| world[n as usize].w_axis.truncate())
        .collect()
}

#[test]
fn animation_reproduces_the_motion_on_its_own_skeleton() {
    let dir = out_dir("animate_gltf");
    let input = dir.join("character.glb");
    let out = dir.join("animated.glb");
    bvh_character(&input);
    animate(&input, &out);

    let (_, source_rig, source_clip) =
        atlas_skin_io::bvh::read_motion(&motion_path("walk.bvh")).unwrap();
    let animated = atlas_skin_io::load_character(&out, &Default::default()).expect("read output");
    let rig = animated.rig.as_ref().expect("rig");
    let clip = animated.clips.last().expect("an animation");
    clip.validate(rig.len()).expect("valid animation");
    let frame_times = &source_clip.tracks[0].times;
    let mut source_local = source_rig.rest.clone();
    let mut local = rig.rest.clone();
    for &time in frame_times.iter().step_by(37) {
        source_clip.sample(time, &source_rig.rest, &mut source_local);
        clip.sample(time, &rig.rest, &mut local);
        let expected = joint_positions(&source_rig, &source_local);
        let got = joint_positions(rig, &local);
        for (j, (e, g)) in expected.iter().zip(&got).enumerate() {
            assert!(
                e.abs_diff_eq(*g, 1e-3),
                "t = {time}, joint {j}: {g} instead of {e}"
            );
        }
    }

    for report in node_check("validate.mjs", &[&out]) {
        assert_eq!(report["errors"], 0, "validator: {report}");
    }
}

#[test]
fn obj_sequence_has_one_posed_mesh_per_frame() {
    let dir = out_dir("animate_obj");
    let input = dir.join("sequence-character.glb");
    bvh_character(&input);
    let out = dir.join("sequence/walk.obj");
    std::fs::create_dir_all(out.parent().unwrap()).unwrap();
    animate(&input, &out);
    let (_, _, clip) = atlas_skin_io::bvh::read_motion(&motion_path("walk.bvh")).unwrap();
    let frames = clip.tracks[0].times.len();
    let count = std::fs::read_dir(out.parent().unwrap()).unwrap().count();
    assert_eq!(count, frames);
    let first = std::fs::read_to_string(dir.join("sequence/walk_0001.obj")).expect("first frame");
    let last = std::fs::read_to_string(dir.join(format!("sequence/walk_{frames:04}.obj")))
        .expect("last frame");
    assert_ne!(first, last, "the mesh moves");
}

#[test]
fn a_joint_map_puts_the_motion_on_joints_named_otherwise() {
    // CesiumMan's joints are named node*; it faces +x with +z up, so +y is its left.
    let dir = out_dir("animate_joint_map");
    let map = dir.join("cesiumman-cmu.json");
    let pairs = [
        ("node2", "Hips"),
        ("node11", "Spine"),
        ("node12", "Spine1"),
        ("node19", "Neck"),
        ("node20", "Head"),
        ("node16", "LeftArm"),
        ("node17", "LeftForeArm"),
        ("node18", "LeftHand"),
        ("node13", "RightArm"),
        ("node14", "RightForeArm"),
        ("node15", "RightHand"),
        ("node7", "LeftUpLeg"),
        ("node8", "LeftLeg"),
        ("node9", "LeftFoot"),
        ("node3", "RightUpLeg"),
        ("node4", "RightLeg"),
        ("node5", "RightFoot"),
    ];
    let json: serde_json::Map<String, serde_json::Value> = pairs
        .iter()
        .map(|&(character, motion)| (character.to_string(), motion.into()))
        .collect();
    std::fs::write(&map, serde_json::to_string_pretty(&json).unwrap()).unwrap();
    let input = CESIUMMAN.input_path();
    let motion = motion_path("walk.bvh");
    let out = dir.join("walking.glb");
    // `animate CESIUMMAN --bvh walk.bvh [--joint-map MAP] -o OUT`.
    let run = |map: Option<&Path>, out: &Path| {
        let mut args = vec![
            Path::new("animate"),
            &input,
            Path::new("--bvh"),
            &motion,
            Path::new("-o"),
            out,
        ];
        if let Some(map) = map {
            args.extend([Path::new("--joint-map"), map]);
        }
        atlas_skin(&args)
    };

    let unmapped = run(None, &out);
    assert!(!unmapped.status.success());
    assert!(String::from_utf8_lossy(&unmapped.stderr).contains("no joint name in common"));
    assert!(!out.exists());

    let mapped = run(Some(&map), &out);
    assert!(
        mapped.status.success(),
        "{}",
        String::from_utf8_lossy(&mapped.stderr)
    );
    let animated = atlas_skin_io::load_character(&out, &Default::default()).expect("read output");
    let rig = animated.rig.as_ref().expect("rig");
    let clip = animated.clips.last().expect("the walk");
    clip.validate(rig.len()).expect("valid animation");
    // Every mapped joint turns during the walk.
    let skeleton = animated.skeleton.as_ref().expect("skeleton");
    for (character_joint, _) in pairs {
        let node = rig.joint_nodes[skeleton.find(character_joint).unwrap()];
        assert!(
            clip.tracks.iter().any(|t| t.node == node),
            "{character_joint} does not move"
        );
    }
    for report in node_check("validate.mjs", &[&out]) {
        assert_eq!(report["errors"], 0, "validator: {report}");
    }

    // The same map serves `pose --bvh` (one frame) and `report --bvh` (the HTML page).
    let pose = |frame: &str, obj: &Path| {
        atlas_skin_ok(&[
            Path::new("pose"),
            &input,
            Path::new("--bvh"),
            &motion,
            Path::new("--frame"),
            Path::new(frame),
            Path::new("--joint-map"),
            &map,
            Path::new("-o"),
            obj,
        ]);
        obj_positions(obj)
    };
    let (early, late) = (dir.join("frame0.obj"), dir.join("frame60.obj"));
    assert_ne!(
        pose("0", &early),
        pose("60", &late),
        "the walk moves the mesh"
    );
    let html = dir.join("walking.html");
    atlas_skin_ok(&[
        Path::new("report"),
        &input,
        Path::new("--bvh"),
        &motion,
        Path::new("--joint-map"),
        &map,
        Path::new("-o"),
        &html,
    ]);
    assert!(std::fs::metadata(&html).expect("report written").len() > 100_000);

    // A map naming a joint the character does not have names it and the map.
    let bad = dir.join("bad-map.json");
    std::fs::write(&bad, r#"{"nodeX": "Hips"}"#).unwrap();
    let bad_out = dir.join("never.glb");
    let output = run(Some(&bad), &bad_out);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("\"nodeX\"") && stderr.contains("bad-map.json"),
        "{stderr}"
    );
    assert!(!bad_out.exists());
    std::fs::write(&bad, "[1, 2]").unwrap();
    let output = run(Some(&bad), &bad_out);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("bad-map.json") && stderr.contains("JSON object"),
        "{stderr}"
    );
}
