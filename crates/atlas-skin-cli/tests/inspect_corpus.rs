//! `atlas-skin inspect --json` on every model of ../shared/data/models agrees with its
//! manifest.json: stored and welded vertices, triangles, components, closedness, Euler
//! characteristic, genus, joint count and every joint's inside flag.

mod support;

use atlas_skin_corpus::{
    Model, ARM, CESIUMMAN, ELEPHANT, HAND, MAKEHUMAN, RIGGEDFIGURE, RIGGEDSIMPLE, SIMPLESKIN,
};
use serde_json::Value;
use std::ffi::OsString;
use support::atlas_skin_ok;

/// Runs `inspect --json` on `model` and checks it against the manifest.
fn check(model: &Model) {
    let mut args: Vec<OsString> = vec!["inspect".into(), "--json".into()];
    args.extend(model.input_args(false));
    let output = atlas_skin_ok(&args);
    let report: Value = serde_json::from_slice(&output.stdout).expect("inspect prints JSON");
    let manifest = model.manifest();
    let model = model.name;

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
    check(&ARM);
}

#[test]
fn elephant() {
    check(&ELEPHANT);
}

#[test]
fn hand() {
    check(&HAND);
}

#[test]
fn makehuman() {
    check(&MAKEHUMAN);
}

#[test]
fn cesiumman() {
    check(&CESIUMMAN);
}

#[test]
fn riggedfigure() {
    check(&RIGGEDFIGURE);
}

#[test]
fn riggedsimple() {
    check(&RIGGEDSIMPLE);
}

#[test]
fn simpleskin() {
    check(&SIMPLESKIN);
}

/// RobotExpressive (bench/robotexpressive): `inspect` counts its 4 skinned meshes on 4
/// skins and 15 rigid meshes under joints; `skin` weights every one of its 7,214 vertices
/// and writes a file that keeps all 19 mesh nodes and has no validator issue the input has
/// not (the input's 4 skinned mesh nodes are not roots).
#[test]
fn robotexpressive_every_mesh_is_read_counted_and_kept() {
    let input = atlas_skin_corpus::data_dir().join("bench/robotexpressive/RobotExpressive.glb");
    let output = atlas_skin_ok(&[
        OsString::from("inspect"),
        "--json".into(),
        input.clone().into(),
    ]);
    let report: Value = serde_json::from_slice(&output.stdout).expect("inspect prints JSON");
    assert_eq!(
        report["gltf_meshes"],
        serde_json::json!({"skinned_meshes": 4, "skins": 4, "rigid_meshes": 15})
    );

    let dir = support::out_dir("inspect-robot");
    let (glb, skin_report) = support::skin_with_report(&input, &dir, "robot");
    assert_eq!(skin_report["counts"]["vertices"], 7214);
    let written: Value = {
        let bytes = std::fs::read(&glb).unwrap();
        let length = u32::from_le_bytes(bytes[12..16].try_into().unwrap()) as usize;
        serde_json::from_slice(&bytes[20..20 + length]).unwrap()
    };
    let mesh_nodes = written["nodes"]
        .as_array()
        .unwrap()
        .iter()
        .filter(|n| n.get("mesh").is_some())
        .count();
    assert_eq!(mesh_nodes, 19);
    let reports = atlas_skin_corpus::node_check("validate.mjs", &[input, glb]);
    let codes = |r: &Value| r["codes"].as_object().unwrap().clone();
    assert_eq!(reports[1]["errors"], 0, "{}", reports[1]);
    for (code, count) in codes(&reports[1]) {
        let before = reports[0]["codes"][&code].as_u64().unwrap_or(0);
        assert!(count.as_u64().unwrap() <= before, "{code}: {}", reports[1]);
    }
}
