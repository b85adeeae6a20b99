//! `atlas-skin eval` on the real characters of ../shared/data: candidates written from
//! the reference weights themselves (unchanged, reordered, with joints swapped) give the
//! figures worked out from the data, and the JSON keys are the documented contract.

use atlas_skin_io::gltf::{write_skinned_glb, WriteOptions};
use atlas_skin_io::{load_character, Character, LoadOptions, TriangleMesh};
use atlas_skin_runtime::VertexWeights;
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/models");

/// A corpus model with reference weights: folder, input, and the reading options as
/// (flag, file) pairs; files are relative to the folder except the group name.
struct Model {
    name: &'static str,
    input: &'static str,
    skeleton: Option<&'static str>,
    group: Option<&'static str>,
    weights: Option<&'static str>,
}

const fn gltf(name: &'static str, input: &'static str) -> Model {
    Model {
        name,
        input,
        skeleton: None,
        group: None,
        weights: None,
    }
}

const GLTF_MODELS: [Model; 4] = [
    gltf("cesiumman", "CesiumMan.glb"),
    gltf("riggedfigure", "RiggedFigure.glb"),
    gltf("riggedsimple", "RiggedSimple.glb"),
    gltf("simpleskin", "SimpleSkin.gltf"),
];

const ARM: Model = Model {
    name: "arm",
    input: "arm.obj",
    skeleton: Some("arm.tgf"),
    group: None,
    weights: Some("arm-weights.dmat"),
};

const MAKEHUMAN: Model = Model {
    name: "makehuman",
    input: "base.obj",
    skeleton: Some("default.mhskel"),
    group: Some("body"),
    weights: Some("default_weights.mhw"),
};

impl Model {
    fn folder(&self) -> PathBuf {
        let folder = Path::new(DATA).join(self.name);
        assert!(
            folder.is_dir(),
            "the corpus is missing: {}",
            folder.display()
        );
        folder
    }

    fn load(&self) -> Character {
        let folder = self.folder();
        let options = LoadOptions {
            skeleton: self.skeleton.map(|s| folder.join(s)),
            group: self.group.map(String::from),
            weights: self.weights.map(|w| folder.join(w)),
        };
        load_character(&folder.join(self.input), &options).unwrap()
    }

    /// `eval` arguments naming this model as the reference.
    fn reference_args(&self) -> Vec<String> {
        let folder = self.folder();
        let path = |f: &str| folder.join(f).display().to_string();
        let mut args = vec![path(self.input)];
        for (flag, value) in [
            ("--skeleton", self.skeleton.map(path)),
            ("--group", self.group.map(String::from)),
            ("--weights", self.weights.map(path)),
        ] {
            if let Some(value) = value {
                args.extend([flag.to_string(), value]);
            }
        }
        args
    }
}

fn out_path(name: &str) -> PathBuf {
    Path::new(env!("CARGO_TARGET_TMPDIR")).join(name)
}

fn eval_json(reference: &Model, candidate: &Path, extra: &[&str]) -> Value {
    let output = Command::new(env!("CARGO_BIN_EXE_atlas-skin"))
        .arg("eval")
        .args(reference.reference_args())
        .arg(candidate)
        .arg("--json")
        .args(extra)
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "eval on {} failed: {}",
        reference.name,
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_slice(&output.stdout).unwrap()
}

fn write_candidate(character: &Character, weights: &VertexWeights, name: &str) -> PathBuf {
    let path = out_path(name);
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
    for model in &GLTF_MODELS {
        let character = model.load();
        let candidate = write_candidate(
            &character,
            reference_weights(&character),
            &format!("eval_same_{}.glb", model.name),
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
                "joints",
                "matched",
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
    let character = MAKEHUMAN.load();
    let pruned = reference_weights(&character).pruned(4);
    let candidate = write_candidate(&character, &pruned, "eval_same_makehuman.glb");
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
    let character = ARM.load();
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
    let mut reordered = Character::new(out_path("arm_reversed.obj"), reordered_mesh);
    reordered.skeleton = character.skeleton.clone();
    let reversed_weights = VertexWeights::from_rows((0..n as usize).rev().map(|v| weights.row(v)));
    let candidate = write_candidate(&reordered, &reversed_weights, "eval_reversed_arm.glb");
    let e = eval_json(&ARM, &candidate, &[]);
    assert_zero(&e, "arm reversed");
    assert_eq!(e["matched"].as_u64(), Some(u64::from(n)));
}

#[test]
fn swapped_joints_give_the_weight_difference_worked_out_from_the_data() {
    let model = &GLTF_MODELS[2]; // riggedsimple: two joints
    let character = model.load();
    let weights = reference_weights(&character);
    assert_eq!(character.skeleton.as_ref().unwrap().len(), 2);
    let swapped = VertexWeights::from_rows(
        (0..weights.vertex_count()).map(|v| weights.row(v).map(|(j, w)| (1 - j, w))),
    );
    let candidate = write_candidate(&character, &swapped, "eval_swapped_riggedsimple.glb");
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
}
