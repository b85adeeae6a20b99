//! `atlas-skin skin` on every character of ../shared/data: it exits 0, every stored vertex
//! of the output gets non-negative weights summing to 1 on at most N joints, the report has
//! its documented keys, the Khronos glTF-Validator finds no error and three.js loads the
//! result with its skin bound.

mod support;

use atlas_skin_corpus::{node_check, Model, MAKEHUMAN, MODELS, RIGGEDFIGURE};
use atlas_skin_io::{load_character, LoadOptions};
use serde_json::Value;
use std::ffi::OsString;
use std::path::Path;
use support::{atlas_skin, out_dir};

/// The vertex count of `model`'s input as stored.
fn stored_vertex_count(model: &Model) -> usize {
    load_character(&model.input_path(), &model.load_options(false))
        .expect("input loads")
        .mesh
        .positions
        .len()
}

/// `atlas-skin skin MODEL ARGS...`.
fn run_skin(model: &Model, args: &[OsString]) -> std::process::Output {
    let mut all: Vec<OsString> = vec!["skin".into()];
    all.extend(model.input_args(false));
    all.extend_from_slice(args);
    atlas_skin(&all)
}

/// Checks the weights of the written glb against the invariants.
fn check_weights(model: &Model, glb: &Path, max_influences: usize) {
    let character = load_character(glb, &LoadOptions::default()).expect("output loads");
    let weights = character.reference_weights.expect("output has weights");
    let joints = character.skeleton.expect("output has a skeleton").len();
    assert_eq!(
        weights.vertex_count(),
        stored_vertex_count(model),
        "{}",
        model.name
    );
    weights
        .validate(joints)
        .expect("weights in range and non-negative");
    for v in 0..weights.vertex_count() {
        let row: Vec<(u32, f32)> = weights.row(v).filter(|&(_, w)| w > 0.0).collect();
        assert!(!row.is_empty(), "{}: vertex {v} unweighted", model.name);
        assert!(
            row.len() <= max_influences,
            "{}: vertex {v} {row:?}",
            model.name
        );
        let sum: f64 = row.iter().map(|&(_, w)| w as f64).sum();
        assert!(
            (sum - 1.0).abs() < 1e-6,
            "{}: vertex {v} sums to {sum}",
            model.name
        );
    }
}

#[test]
fn skin_runs_on_every_corpus_model_and_writes_valid_bound_skins() {
    let dir = out_dir("skin-corpus");
    let mut outputs = Vec::new();
    for model in &MODELS {
        let glb = dir.join(format!("{}.glb", model.name));
        let report = dir.join(format!("{}.json", model.name));
        let output = run_skin(
            model,
            &[
                "-o".into(),
                glb.clone().into(),
                "--report".into(),
                report.clone().into(),
            ],
        );
        assert!(
            output.status.success(),
            "{}: {}",
            model.name,
            String::from_utf8_lossy(&output.stderr)
        );
        check_weights(model, &glb, 4);

        let report: Value =
            serde_json::from_str(&std::fs::read_to_string(&report).expect("report written"))
                .expect("report is JSON");
        for stage in [
            "weld",
            "topology",
            "decompose",
            "overlap",
            "weights",
            "write",
        ] {
            assert!(
                report["timings_ms"][stage].is_f64(),
                "{}: timing {stage}",
                model.name
            );
        }
        for count in [
            "vertices",
            "welded_vertices",
            "joints",
            "unreachable_vertices",
            "fallback_weighted_vertices",
            "duplicate_faces",
        ] {
            assert!(
                report["counts"][count].is_u64(),
                "{}: count {count}",
                model.name
            );
        }
        let body = &report["pieces"]["by_treatment"]["body"];
        assert!(
            body["pieces"].as_u64().unwrap_or(0) >= 1 && body["vertices"].is_u64(),
            "{}: pieces {}",
            model.name,
            report["pieces"]
        );
        let joints = report["decomposition"]["joints"]
            .as_array()
            .expect("joints");
        assert_eq!(
            joints.len() as u64,
            report["counts"]["joints"].as_u64().unwrap_or(0)
        );
        for joint in joints.iter().filter(|j| j["status"] != "skipped") {
            assert!(joint["overlap_width"].is_f64(), "{}: {joint}", model.name);
        }
        assert!(report["decomposition"]["regions"].is_array());
        assert!(report["warnings"].is_array());
        outputs.push(glb);
    }

    for result in node_check("validate.mjs", &outputs) {
        assert_eq!(result["errors"], 0, "{result}");
    }
    for result in node_check("three_load.mjs", &outputs) {
        assert_eq!(result["ok"], true, "{result}");
    }
}

#[test]
fn options_reach_the_method_and_bad_ones_are_refused() {
    let dir = out_dir("skin-options");
    let model = &RIGGEDFIGURE;
    let glb = dir.join("figure.glb");
    let config = dir.join("config.json");
    std::fs::write(&config, r#"{"overlap": {"factor": 0.6}}"#).expect("config");
    let args = [
        "-o",
        glb.to_str().expect("utf-8 path"),
        "--config",
        config.to_str().expect("utf-8 path"),
        "--blend",
        "paper",
        "--overlap-joint",
        "node13=1.0",
        "--max-influences",
        "2",
        "--debug-glb",
        dir.join("debug.glb").to_str().expect("utf-8 path"),
        "--html",
        dir.join("report.html").to_str().expect("utf-8 path"),
        "--report",
        dir.join("report.json").to_str().expect("utf-8 path"),
        "--forbid",
        "node8",
    ]
    .map(OsString::from);
    let output = run_skin(model, &args);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    check_weights(model, &glb, 2);
    assert!(dir.join("debug.glb").is_file() && dir.join("report.html").is_file());
    let report: Value = serde_json::from_str(
        &std::fs::read_to_string(dir.join("report.json")).expect("report written"),
    )
    .expect("report is JSON");
    let joints = report["decomposition"]["joints"]
        .as_array()
        .expect("joints");
    let forbidden = joints.iter().find(|j| j["name"] == "node8").expect("node8");
    assert_eq!(forbidden["status"], "skipped", "{forbidden}");
    for joint in joints {
        let (Some(width), Some(diameter)) =
            (joint["overlap_width"].as_f64(), joint["diameter"].as_f64())
        else {
            continue;
        };
        let factor = if joint["name"] == "node13" { 1.0 } else { 0.6 };
        assert!((width - factor * diameter).abs() < 1e-9, "{joint}");
    }

    for (flag, value, message) in [
        ("--overlap-joint", "no_such_joint=0.5", "unknown joint"),
        ("--overlap", "0", "not a positive number"),
        ("--overlap-joint", "node13", "expected NAME=F"),
        ("--max-influences", "0", "outside 1..=32"),
        ("--max-influences", "4294967296", "outside 1..=32"),
        ("--forbid", "no_such_joint", "is not in the skeleton"),
        ("--force", "no_such_joint", "is not in the skeleton"),
    ] {
        let output = run_skin(
            model,
            &[
                "-o".into(),
                dir.join("bad.glb").into(),
                flag.into(),
                value.into(),
            ],
        );
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{flag} {value} accepted");
        assert!(stderr.contains(message), "{flag} {value}: {stderr}");
    }
}

#[test]
fn makehuman_forbidden_joints_and_joints_outside_move_nothing() {
    // The tongue's leaves lie in the mouth, outside the mesh; a forbidden joint moves
    // nothing, and its part moves with its parent.
    let largest_weights = |forbid: Option<&str>| {
        let dir = out_dir(&format!(
            "skin-makehuman-forbid-{}",
            forbid.unwrap_or("none")
        ));
        let glb = dir.join("makehuman.glb");
        let mut args: Vec<OsString> = vec!["-o".into(), glb.clone().into_os_string()];
        if let Some(joint) = forbid {
            args.extend(["--forbid".into(), joint.into()]);
        }
        let output = run_skin(&MAKEHUMAN, &args);
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let character = load_character(&glb, &LoadOptions::default()).expect("output loads");
        let weights = character.reference_weights.expect("weights");
        let skeleton = character.skeleton.expect("skeleton");
        let mut largest = vec![0.0f32; skeleton.len()];
        for (j, w) in (0..weights.vertex_count()).flat_map(|v| weights.row(v)) {
            largest[j as usize] = largest[j as usize].max(w);
        }
        move |name: &str| largest[skeleton.find(name).expect(name)]
    };
    let default = largest_weights(None);
    let forbidden = largest_weights(Some("jaw"));
    assert!(default("jaw") > 0.4, "{}", default("jaw"));
    assert_eq!(forbidden("jaw"), 0.0);
    for side in ["L", "R"] {
        for tongue in ["tongue05", "tongue06", "tongue07"] {
            assert_eq!(default(&format!("{tongue}.{side}")), 0.0, "{tongue}.{side}");
        }
    }
}
