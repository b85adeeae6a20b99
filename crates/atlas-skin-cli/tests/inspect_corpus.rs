//! `atlas-skin inspect --json` on every model of ../shared/data/models agrees with its
//! manifest.json: stored and welded vertices, triangles, components, closedness, Euler
//! characteristic, genus, joint count and every joint's inside flag.

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/models");

fn model_file(model: &str, file: &str) -> PathBuf {
    let path = Path::new(MODELS).join(model).join(file);
    assert!(path.exists(), "corpus file {} is missing", path.display());
    path
}

/// Runs `inspect --json` on `model`'s `mesh` with extra arguments (`--skeleton FILE` and
/// `--group NAME`, file names relative to the model folder) and checks it against the
/// manifest.
fn check(model: &str, mesh: &str, skeleton: Option<&str>, group: Option<&str>) {
    let mut command = Command::new(env!("CARGO_BIN_EXE_atlas-skin"));
    command
        .arg("inspect")
        .arg("--json")
        .arg(model_file(model, mesh));
    if let Some(skeleton) = skeleton {
        command.arg("--skeleton").arg(model_file(model, skeleton));
    }
    if let Some(group) = group {
        command.args(["--group", group]);
    }
    let output = command.output().expect("run atlas-skin");
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(output.status.success(), "{model}: inspect failed: {stderr}");
    let report: Value = serde_json::from_slice(&output.stdout).expect("inspect prints JSON");
    let text = std::fs::read_to_string(model_file(model, "manifest.json")).unwrap();
    let manifest: Value = serde_json::from_str(&text).unwrap();

    for (key, manifest_key) in [
        ("vertices", "stored_vertex_count"),
        ("welded_vertices", "welded_vertex_count"),
        ("triangles", "triangle_count"),
        ("components", "connected_components"),
        ("closed", "closed"),
        ("euler_characteristic", "euler_characteristic"),
        ("genus", "genus"),
    ] {
        assert_eq!(report[key], manifest[manifest_key], "{model}: {key}");
    }
    let joints = report["joints"].as_array().expect("joints");
    let expected = manifest["joints"].as_array().unwrap();
    assert_eq!(joints.len(), expected.len(), "{model}: joint count");
    assert_eq!(
        joints.len() as u64,
        manifest["joint_count"].as_u64().unwrap()
    );
    for joint in expected {
        let name = &joint["name"];
        let found = joints
            .iter()
            .find(|j| &j["name"] == name)
            .unwrap_or_else(|| panic!("{model}: no joint {name}"));
        assert_eq!(
            found["inside"], joint["inside_mesh"],
            "{model}: {name} inside"
        );
        assert_eq!(found["parent"], joint["parent"], "{model}: {name} parent");
    }
}

#[test]
fn arm() {
    check("arm", "arm.obj", Some("arm.tgf"), None);
}

#[test]
fn elephant() {
    check("elephant", "elephant.obj", Some("elephant.tgf"), None);
}

#[test]
fn hand() {
    check("hand", "hand.mesh", Some("hand.tgf"), None);
}

#[test]
fn makehuman() {
    check(
        "makehuman",
        "base.obj",
        Some("default.mhskel"),
        Some("body"),
    );
}

#[test]
fn cesiumman() {
    check("cesiumman", "CesiumMan.glb", None, None);
}

#[test]
fn riggedfigure() {
    check("riggedfigure", "RiggedFigure.glb", None, None);
}

#[test]
fn riggedsimple() {
    check("riggedsimple", "RiggedSimple.glb", None, None);
}

#[test]
fn simpleskin() {
    check("simpleskin", "SimpleSkin.gltf", None, None);
}
