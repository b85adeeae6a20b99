//! The non-glTF readers on the real corpus (../shared/data): counts, joint names, joint
//! positions and reference weights against each model's manifest.json.

use atlas_skin_io::{bvh, load_character, Character, LoadOptions};
use serde_json::Value;
use std::path::{Path, PathBuf};

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");

fn data(relative: &str) -> PathBuf {
    let path = Path::new(DATA).join(relative);
    assert!(path.exists(), "corpus file {} is missing", path.display());
    path
}

fn manifest(model: &str) -> Value {
    let text = std::fs::read_to_string(data(&format!("models/{model}/manifest.json"))).unwrap();
    serde_json::from_str(&text).unwrap()
}

fn load(
    model: &str,
    mesh: &str,
    skeleton: &str,
    weights: Option<&str>,
    group: Option<&str>,
) -> Character {
    let dir = format!("models/{model}/");
    let options = LoadOptions {
        skeleton: Some(data(&(dir.clone() + skeleton))),
        group: group.map(str::to_string),
        weights: weights.map(|w| data(&(dir.clone() + w))),
    };
    load_character(&data(&(dir + mesh)), &options).unwrap_or_else(|e| panic!("{e}"))
}

/// Stored vertex and triangle counts, joint names, parents and bind positions (to 1e-5 of
/// the manifest's 6 decimals, relative to the model's size).
fn check_against_manifest(model: &str, character: &Character) {
    let m = manifest(model);
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
    let arm = load("arm", "arm.obj", "arm.tgf", Some("arm-weights.dmat"), None);
    check_against_manifest("arm", &arm);
    check_row_sums(&arm, 1e-5);
    // 4 bone columns land on joints tgf_1..tgf_4; the tip joint tgf_5 has no bone of its own.
    let weights = arm.reference_weights.as_ref().unwrap();
    assert!(weights.joints.iter().all(|&j| j < 4));
}

#[test]
fn elephant_obj_tgf_and_binary_dmat() {
    let elephant = load(
        "elephant",
        "elephant.obj",
        "elephant.tgf",
        Some("elephant-weights.dmat"),
        None,
    );
    check_against_manifest("elephant", &elephant);
    check_row_sums(&elephant, 1e-5);
}

#[test]
fn hand_tetrahedral_mesh_keeps_the_surface() {
    let hand = load("hand", "hand.mesh", "hand.tgf", None, None);
    check_against_manifest("hand", &hand);
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
    let human = load(
        "makehuman",
        "base.obj",
        "default.mhskel",
        Some("default_weights.mhw"),
        Some("body"),
    );
    check_against_manifest("makehuman", &human);
    // MakeHuman rounds weights to 3 decimals: sums range 0.954–1.063 (manifest).
    check_row_sums(&human, 0.07);
    assert_eq!(*human.file_vertex.last().unwrap(), 13379);
}

#[test]
fn bvh_clips_match_the_motion_manifest() {
    let text = std::fs::read_to_string(data("motion/manifest.json")).unwrap();
    let manifest: Value = serde_json::from_str(&text).unwrap();
    for clip in manifest["clips"].as_array().unwrap() {
        let file = clip["file"].as_str().unwrap();
        let (skeleton, rig, motion) = bvh::read_motion(&data(&format!("motion/{file}"))).unwrap();
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
