//! The non-glTF readers on the real corpus (../shared/data): counts, joint names, joint
//! positions and reference weights against each model's manifest.json.

use atlas_skin_corpus::{motion_path, Model, ARM, ELEPHANT, HAND, MAKEHUMAN};
use atlas_skin_io::{bvh, load_character, Character};
use serde_json::Value;

/// The model's input with its skeleton and reference weights.
fn load(model: &Model) -> Character {
    load_character(&model.input_path(), &model.load_options(true)).unwrap_or_else(|e| panic!("{e}"))
}

/// Stored vertex and triangle counts, joint names, parents and bind positions (to 1e-5 of
/// the manifest's 6 decimals, relative to the model's size).
fn check_against_manifest(model: &Model, character: &Character) {
    let m = model.manifest();
    let model = model.name;
    assert_eq!(
        character.mesh.positions.len() as u64,
        m["stored_vertex_count"].as_u64().unwrap()
    );
    assert_eq!(
        character.mesh.triangles.len() as u64,
        m["triangle_count"].as_u64().unwrap()
    );
    let skeleton = character.skeleton.as_ref().expect("skeleton");
    let joints = m["joints"].as_array().unwrap();
    assert_eq!(skeleton.len(), joints.len());
    let positions = skeleton.bind_positions();
    let size = (character
        .mesh
        .positions
        .iter()
        .fold(glam::Vec3::NEG_INFINITY, |a, &p| a.max(p))
        - character
            .mesh
            .positions
            .iter()
            .fold(glam::Vec3::INFINITY, |a, &p| a.min(p)))
    .length();
    for joint in joints {
        let name = joint["name"].as_str().unwrap();
        let j = skeleton
            .find(name)
            .unwrap_or_else(|| panic!("{model}: no joint {name}"));
        let parent = skeleton.parent(j).map(|p| skeleton.names[p].as_str());
        assert_eq!(
            parent,
            joint["parent"].as_str(),
            "{model}: parent of {name}"
        );
        let expected: Vec<f32> = joint["bind_position"]
            .as_array()
            .unwrap()
            .iter()
            .map(|v| v.as_f64().unwrap() as f32)
            .collect();
        let distance = positions[j].distance(glam::Vec3::from_slice(&expected));
        assert!(
            distance <= 1e-5 * size.max(1.0),
            "{model}: {name} is {distance} off"
        );
    }
}

/// Every row of the reference weights sums to within `tolerance` of 1.
fn check_row_sums(character: &Character, tolerance: f32) {
    let weights = character.reference_weights.as_ref().expect("weights");
    assert_eq!(weights.vertex_count(), character.mesh.positions.len());
    for v in 0..weights.vertex_count() {
        let sum: f32 = weights.row(v).map(|(_, w)| w).sum();
        assert!((sum - 1.0).abs() <= tolerance, "vertex {v} sums to {sum}");
    }
}

#[test]
fn arm_obj_tgf_and_per_bone_dmat() {
    let arm = load(&ARM);
    check_against_manifest(&ARM, &arm);
    check_row_sums(&arm, 1e-5);
    // 4 bone columns land on joints tgf_1..tgf_4; the tip joint tgf_5 has no bone of its own.
    let weights = arm.reference_weights.as_ref().unwrap();
    assert!(weights.joints.iter().all(|&j| j < 4));
    // ...so it is an end joint, which the skin command gives no boundary.
    assert_eq!(arm.end_joints, vec![4]);
}

#[test]
fn elephant_obj_tgf_and_binary_dmat() {
    let elephant = load(&ELEPHANT);
    check_against_manifest(&ELEPHANT, &elephant);
    check_row_sums(&elephant, 1e-5);
}

#[test]
fn hand_tetrahedral_mesh_keeps_the_surface() {
    let hand = load(&HAND);
    check_against_manifest(&HAND, &hand);
    assert_eq!(hand.file_vertex.len(), 4780);
    assert!(
        hand.warnings
            .iter()
            .any(|w| w.contains("2454 of the file's 7234 vertices")),
        "{:?}",
        hand.warnings
    );
}

#[test]
fn makehuman_body_group_mhskel_and_mhw() {
    let human = load(&MAKEHUMAN);
    check_against_manifest(&MAKEHUMAN, &human);
    // MakeHuman rounds weights to 3 decimals: sums range 0.954–1.063 (manifest).
    check_row_sums(&human, 0.07);
    assert_eq!(*human.file_vertex.last().unwrap(), 13379);
}

#[test]
fn bvh_clips_match_the_motion_manifest() {
    let text = std::fs::read_to_string(motion_path("manifest.json")).unwrap();
    let manifest: Value = serde_json::from_str(&text).unwrap();
    for clip in manifest["clips"].as_array().unwrap() {
        let file = clip["file"].as_str().unwrap();
        let (skeleton, rig, motion) = bvh::read_motion(&motion_path(file)).unwrap();
        let names: Vec<&str> = clip["joint_names"]
            .as_array()
            .unwrap()
            .iter()
            .map(|n| n.as_str().unwrap())
            .collect();
        assert_eq!(skeleton.names, names, "{file}");
        assert_eq!(rig.names, names, "{file}");
        let frames = clip["frames"].as_u64().unwrap() as usize;
        let step = clip["frame_time_s"].as_f64().unwrap() as f32;
        assert!(
            motion.tracks.iter().all(|t| t.times.len() == frames),
            "{file}"
        );
        assert!(
            (motion.duration - (frames - 1) as f32 * step).abs() < 1e-3,
            "{file}: {}",
            motion.duration
        );
        // Hips: rotation and translation; the 30 other joints: rotation only.
        assert_eq!(motion.tracks.len(), 32, "{file}");
        for track in &motion.tracks {
            let width = if track.property == atlas_skin_runtime::Property::Rotation {
                4
            } else {
                3
            };
            assert_eq!(track.values.len(), frames * width);
        }
    }
}
