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
