//! glTF animation sampling (`Clip::sample`) agrees with three.js's AnimationMixer
//! (tests/js/three_anim.mjs) on the corpus glTF models: every node's local translation,
//! rotation and scale at several times.

use atlas_skin_corpus::{node_json, CESIUMMAN, RIGGEDFIGURE, RIGGEDSIMPLE};
use atlas_skin_runtime::Trs;
use glam::{Quat, Vec3};
use std::ffi::OsString;
use std::path::Path;

/// Times as fractions of the clip: first key, between keys, near the end.
const FRACTIONS: [f32; 5] = [0.0, 0.13, 0.5, 0.71, 0.98];

/// Every node's local transform at `times` of animation 0 of `input`, sampled by three.js.
fn three_frames(input: &Path, times: &[f32]) -> serde_json::Value {
    let mut args: Vec<OsString> = vec![input.into(), "0".into()];
    args.extend(times.iter().map(|t| t.to_string().into()));
    node_json("three_anim.mjs", &args)
}

fn floats<const N: usize>(value: &serde_json::Value) -> [f32; N] {
    let items = value.as_array().expect("array");
    std::array::from_fn(|i| items[i].as_f64().expect("number") as f32)
}

#[test]
fn sampling_matches_three_js_animation_mixer() {
    for model in [CESIUMMAN, RIGGEDFIGURE, RIGGEDSIMPLE] {
        let (folder, input) = (model.name, model.input_path());
        let character = atlas_skin_io::load_character(&input, &Default::default()).expect("load");
        let rig = character.rig.as_ref().expect("rig");
        let clip = character.clips.first().expect("an animation");
        clip.validate(rig.len()).expect("valid clip");
        let times: Vec<f32> = FRACTIONS.iter().map(|f| f * clip.duration).collect();
        let three = three_frames(&input, &times);
        let mut local = vec![Trs::IDENTITY; rig.len()];
        for (frame, &time) in three["frames"]
            .as_array()
            .expect("frames")
            .iter()
            .zip(&times)
        {
            clip.sample(time, &rig.rest, &mut local);
            let nodes = frame["nodes"].as_array().expect("nodes");
            assert_eq!(nodes.len(), rig.len(), "{folder}: node count");
            for (n, (node, ours)) in nodes.iter().zip(&local).enumerate() {
                let what = format!("{folder}, node {n}, t = {time}");
                let translation = Vec3::from(floats::<3>(&node["translation"]));
                let scale = Vec3::from(floats::<3>(&node["scale"]));
                let rotation = Quat::from_array(floats::<4>(&node["rotation"]));
                let size = ours.translation.length().max(1.0);
                assert!(
                    ours.translation.abs_diff_eq(translation, 1e-5 * size),
                    "{what}: translation {} vs {translation}",
                    ours.translation
                );
                assert!(ours.scale.abs_diff_eq(scale, 1e-5), "{what}: scale");
                // q and −q are the same rotation.
                let distance = (ours.rotation - rotation)
                    .length()
                    .min((ours.rotation + rotation).length());
                assert!(
                    distance < 1e-5,
                    "{what}: rotation {} vs {rotation}",
                    ours.rotation
                );
            }
        }
    }
}
