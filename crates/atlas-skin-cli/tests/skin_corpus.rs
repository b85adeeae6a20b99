//! `atlas-skin skin` on every character of ../shared/data: it exits 0, every stored vertex
//! of the output gets non-negative weights summing to 1 on at most N joints, the report has
//! its documented keys, the Khronos glTF-Validator finds no error and three.js loads the
//! result with its skin bound.

use atlas_skin_io::{load_character, LoadOptions};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/models");
const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// A corpus model: folder, input file, and the reading options.
struct Model {
    name: &'static str,
    input: &'static str,
    skeleton: Option<&'static str>,
    group: Option<&'static str>,
}

const fn model(name: &'static str, input: &'static str, skeleton: Option<&'static str>) -> Model {
    Model {
        name,
        input,
        skeleton,
        group: None,
    }
}

const MODELS: [Model; 8] = [
    model("cesiumman", "CesiumMan.glb", None),
    model("riggedfigure", "RiggedFigure.glb", None),
    model("riggedsimple", "RiggedSimple.glb", None),
    model("simpleskin", "SimpleSkin.gltf", None),
    model("arm", "arm.obj", Some("arm.tgf")),
    model("elephant", "elephant.obj", Some("elephant.tgf")),
    model("hand", "hand.mesh", Some("hand.tgf")),
    Model {
        name: "makehuman",
        input: "base.obj",
        skeleton: Some("default.mhskel"),
        group: Some("body"),
    },
];

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

    /// The input arguments of `skin` (and the reading options for the same input).
    fn input_args(&self) -> Vec<String> {
        let folder = self.folder();
        let mut args = vec![folder.join(self.input).display().to_string()];
        if let Some(skeleton) = self.skeleton {
            args.extend([
                "--skeleton".into(),
                folder.join(skeleton).display().to_string(),
            ]);
        }
        if let Some(group) = self.group {
            args.extend(["--group".into(), group.into()]);
        }
        args
    }

    fn stored_vertex_count(&self) -> usize {
        let folder = self.folder();
        let options = LoadOptions {
            skeleton: self.skeleton.map(|s| folder.join(s)),
            group: self.group.map(String::from),
            weights: None,
        };
        load_character(&folder.join(self.input), &options)
            .expect("input loads")
            .mesh
            .positions
            .len()
    }
}

fn out_dir(test: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("atlas-skin-{test}-{}", std::process::id()));
    std::fs::create_dir_all(&dir).expect("temporary directory");
    dir
}

fn run_skin(args: &[String]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_atlas-skin"))
        .arg("skin")
        .args(args)
        .output()
        .expect("atlas-skin runs")
}

/// Runs a node checker of tests/js on `files`; returns its JSON lines.
fn node_check(script: &str, files: &[PathBuf]) -> Vec<Value> {
    let workspace = Path::new(WORKSPACE);
    assert!(
        workspace.join("tests/js/node_modules").is_dir(),
        "tests/js/node_modules is missing: run scripts/install-test-deps"
    );
    let output = Command::new("node")
        .current_dir(workspace)
        .arg(format!("tests/js/{script}"))
        .args(files)
        .output()
        .expect("node runs");
    let stdout = String::from_utf8_lossy(&output.stdout);
    let lines: Vec<Value> = stdout
        .lines()
        .map(|l| serde_json::from_str(l).expect("one JSON object per line"))
        .collect();
    assert_eq!(
        lines.len(),
        files.len(),
        "{script}: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    lines
}

/// Checks the weights of the written glb against the invariants.
fn check_weights(model: &Model, glb: &Path, max_influences: usize) {
    let character = load_character(glb, &LoadOptions::default()).expect("output loads");
    let weights = character.reference_weights.expect("output has weights");
    let joints = character.skeleton.expect("output has a skeleton").len();
    assert_eq!(
        weights.vertex_count(),
        model.stored_vertex_count(),
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
        let mut args = model.input_args();
        args.extend([
            "-o".into(),
            glb.display().to_string(),
            "--report".into(),
            report.display().to_string(),
        ]);
        let output = run_skin(&args);
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
            "distances",
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
        ] {
            assert!(
                report["counts"][count].is_u64(),
                "{}: count {count}",
                model.name
            );
        }
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
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn options_reach_the_method_and_bad_ones_are_refused() {
    let dir = out_dir("skin-options");
    let model = &MODELS[1];
    let glb = dir.join("figure.glb");
    let config = dir.join("config.json");
    std::fs::write(&config, r#"{"weights": {"overlap": {"factor": 0.6}}}"#).expect("config");
    let mut args = model.input_args();
    args.extend(
        [
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
        ]
        .map(String::from),
    );
    let output = run_skin(&args);
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
    for joint in report["decomposition"]["joints"]
        .as_array()
        .expect("joints")
    {
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
        ("--max-influences", "0", "at least 1"),
    ] {
        let mut args = model.input_args();
        args.extend(["-o".into(), dir.join("bad.glb").display().to_string()]);
        args.extend([flag.into(), value.into()]);
        let output = run_skin(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{flag} {value} accepted");
        assert!(stderr.contains(message), "{flag} {value}: {stderr}");
    }
    std::fs::remove_dir_all(&dir).ok();
}
