//! `atlas-skin eval` on the real characters of ../shared/data: candidates written from
//! the reference weights themselves (unchanged, reordered, with joints swapped) give the
//! figures worked out from the data, and the JSON keys are the documented contract.

mod support;

use atlas_skin_corpus::{Model, ARM, MAKEHUMAN, MODELS, RIGGEDSIMPLE};
use atlas_skin_io::gltf::{write_skinned_glb, WriteOptions};
use atlas_skin_io::{load_character, Character, TriangleMesh};
use atlas_skin_runtime::VertexWeights;
use serde_json::Value;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use support::{atlas_skin_ok, out_dir};

/// The model's input with its reference weights.
fn load(model: &Model) -> Character {
    load_character(&model.input_path(), &model.load_options(true)).unwrap()
}

fn eval_json(reference: &Model, candidate: &Path, extra: &[&str]) -> Value {
    let mut args: Vec<OsString> = vec!["eval".into()];
    args.extend(reference.input_args(true));
    args.extend([candidate.into(), "--json".into()]);
    args.extend(extra.iter().map(OsString::from));
    let output = atlas_skin_ok(&args);
    serde_json::from_slice(&output.stdout).unwrap()
}

/// Writes `weights` on `character` as the skinned glb `path`.
fn write_candidate(character: &Character, weights: &VertexWeights, path: PathBuf) -> PathBuf {
    let options = WriteOptions {
        max_influences: weights.max_influences().max(1),
        ..WriteOptions::default()
    };
    write_skinned_glb(character, weights, &options, &path).unwrap();
    path
}

fn reference_weights(character: &Character) -> &VertexWeights {
    character.reference_weights.as_ref().unwrap()
}

/// Every figure of a candidate equal to the reference is zero up to float32 rounding.
fn assert_zero(e: &Value, model: &str) {
    let figure = |group: &str, key: &str| e[group][key].as_f64().unwrap();
    for key in ["mean", "p95", "max"] {
        assert!(
            figure("weights_l1", key) < 1e-5,
            "{model}: weights_l1.{key}"
        );
    }
    assert_eq!(figure("weights_l1", "dominant_agreement"), 1.0, "{model}");
    for group in ["deform_random", "deform_random_dqs"] {
        assert!(figure(group, "max") < 1e-5, "{model}: {group} {}", e[group]);
    }
    if !e["deform_anim"].is_null() {
        assert!(
            figure("deform_anim", "max") < 1e-5,
            "{model}: {}",
            e["deform_anim"]
        );
    }
    assert_eq!(figure("bleeding", "fraction"), 0.0, "{model}");
    assert_eq!(e["matched"], e["vertices"], "{model}");
}

fn keys(value: &Value) -> Vec<&str> {
    let mut keys: Vec<&str> = value
        .as_object()
        .unwrap()
        .keys()
        .map(String::as_str)
        .collect();
    keys.sort_unstable();
    keys
}

#[test]
fn reference_weights_as_candidate_give_zeros_and_the_json_contract_holds() {
    let dir = out_dir("eval_same");
    for model in MODELS.iter().filter(|m| m.is_gltf()) {
        let character = load(model);
        let candidate = write_candidate(
            &character,
            reference_weights(&character),
            dir.join(format!("{}.glb", model.name)),
        );
        let e = eval_json(model, &candidate, &[]);
        assert_zero(&e, model.name);
        assert_eq!(
            keys(&e),
            [
                "bleeding",
                "candidate_joints",
                "candidate_vertices",
                "deform_anim",
                "deform_random",
                "deform_random_dqs",
                "joint_matches",
                "joints",
                "matched",
                "rignet",
                "validity",
                "vertices",
                "weights_l1"
            ]
        );
        assert_eq!(
            keys(&e["weights_l1"]),
            ["dominant_agreement", "max", "mean", "p95"]
        );
        for group in ["deform_random", "deform_random_dqs"] {
            assert_eq!(keys(&e[group]), ["max", "mean"]);
        }
        assert_eq!(keys(&e["bleeding"]), ["fraction"]);
        assert_eq!(
            keys(&e["validity"]),
            [
                "max_influences",
                "mean_influences",
                "negative_weights",
                "sums_off_one",
                "unweighted_vertices"
            ]
        );
        // Every glTF model of the corpus has one animation.
        assert_eq!(keys(&e["deform_anim"]), ["max", "mean"], "{}", model.name);
    }
}

#[test]
fn makehuman_pruned_reference_as_candidate_gives_zeros() {
    let character = load(&MAKEHUMAN);
    let pruned = reference_weights(&character).pruned(4);
    let candidate = write_candidate(
        &character,
        &pruned,
        out_dir("eval_same_makehuman").join("makehuman.glb"),
    );
    let e = eval_json(
        &MAKEHUMAN,
        &candidate,
        &["--prune-reference", "4", "--poses", "2"],
    );
    assert_zero(&e, "makehuman");
    assert_eq!(
        (e["vertices"].as_u64(), e["joints"].as_u64()),
        (Some(13380), Some(163))
    );
    assert!(e["deform_anim"].is_null());
}

#[test]
fn a_reordered_candidate_still_matches() {
    let dir = out_dir("eval_reversed");
    let character = load(&ARM);
    let weights = reference_weights(&character);
    // Reverse the vertex order (and the triangles' indices with it).
    let n = character.mesh.positions.len() as u32;
    let reordered_mesh = TriangleMesh {
        positions: character.mesh.positions.iter().rev().copied().collect(),
        triangles: character
            .mesh
            .triangles
            .iter()
            .map(|t| t.map(|v| n - 1 - v))
            .collect(),
    };
    let mut reordered = Character::new(dir.join("arm_reversed.obj"), reordered_mesh);
    reordered.skeleton = character.skeleton.clone();
    let reversed_weights = VertexWeights::from_rows((0..n as usize).rev().map(|v| weights.row(v)));
    let candidate = write_candidate(&reordered, &reversed_weights, dir.join("arm.glb"));
    let e = eval_json(&ARM, &candidate, &[]);
    assert_zero(&e, "arm reversed");
    assert_eq!(e["matched"].as_u64(), Some(u64::from(n)));
}

#[test]
fn swapped_joints_give_the_weight_difference_worked_out_from_the_data() {
    let model = &RIGGEDSIMPLE; // two joints
    let character = load(model);
    let weights = reference_weights(&character);
    assert_eq!(character.skeleton.as_ref().unwrap().len(), 2);
    let swapped = VertexWeights::from_rows(
        (0..weights.vertex_count()).map(|v| weights.row(v).map(|(j, w)| (1 - j, w))),
    );
    let candidate = write_candidate(
        &character,
        &swapped,
        out_dir("eval_swapped").join("riggedsimple.glb"),
    );
    let e = eval_json(model, &candidate, &[]);
    // Row (a, b) normalised against (b, a): d = 2 |a − b| / (a + b).
    let d: Vec<f64> = (0..weights.vertex_count())
        .map(|v| {
            let dense = [0u32, 1].map(|j| {
                weights
                    .row(v)
                    .filter(|&(k, _)| k == j)
                    .map(|(_, w)| f64::from(w))
                    .sum::<f64>()
            });
            2.0 * (dense[0] - dense[1]).abs() / (dense[0] + dense[1])
        })
        .collect();
    let mean = d.iter().sum::<f64>() / d.len() as f64;
    let max = d.iter().copied().fold(0.0, f64::max);
    let got = |key: &str| e["weights_l1"][key].as_f64().unwrap();
    assert!(
        (got("mean") - mean).abs() < 1e-5,
        "{} vs {mean}",
        got("mean")
    );
    assert!((got("max") - max).abs() < 1e-5, "{} vs {max}", got("max"));
    assert!(e["deform_random"]["mean"].as_f64().unwrap() > 1e-3);
    assert!(e.get("worst_vertices").is_none());

    // --worst lists the vertices of the largest error, worst first, with both rows.
    let e = eval_json(model, &candidate, &["--worst", "3"]);
    let worst = e["worst_vertices"].as_array().unwrap();
    assert_eq!(worst.len(), 3);
    let error = |w: &Value| w["error"].as_f64().unwrap();
    assert_eq!(
        error(&worst[0]),
        e["deform_random"]["max"].as_f64().unwrap()
    );
    assert!(error(&worst[0]) >= error(&worst[1]) && error(&worst[1]) >= error(&worst[2]));
    for w in worst {
        let v = w["vertex"].as_u64().unwrap() as usize;
        let position = character.mesh.positions[v].to_array();
        let listed: Vec<f32> = w["position"]
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap() as f32)
            .collect();
        assert_eq!(listed, position);
        assert!(w["pose"].as_u64().unwrap() < 10);
        // The candidate's row is the reference's with the two joints swapped.
        let names = &character.skeleton.as_ref().unwrap().names;
        let row = |key: &str| -> Vec<(String, f64)> {
            w[key]
                .as_array()
                .unwrap()
                .iter()
                .map(|r| {
                    (
                        r["joint"].as_str().unwrap().to_string(),
                        r["weight"].as_f64().unwrap(),
                    )
                })
                .collect()
        };
        let candidate = row("candidate");
        for (joint, weight) in row("reference") {
            let other = names.iter().find(|n| **n != joint).unwrap();
            let swapped = candidate.iter().find(|(j, _)| j == other).unwrap();
            assert!((swapped.1 - weight).abs() < 1e-5, "{w}");
        }
        // Every joint's bones are at least as far as the nearest bone, and the nearest
        // bone's joint has ratio 1.
        let ratios: Vec<f64> = ["reference", "candidate"]
            .iter()
            .flat_map(|key| w[*key].as_array().unwrap().iter())
            .map(|r| {
                assert!(r["bone_distance"].as_f64().unwrap() >= 0.0, "{r}");
                // null: unbounded, the vertex lies on another joint's bone.
                r["bone_distance_ratio"].as_f64().unwrap_or(f64::INFINITY)
            })
            .collect();
        assert!(ratios.iter().all(|&x| x >= 1.0 - 1e-12), "{w}");
    }
}
