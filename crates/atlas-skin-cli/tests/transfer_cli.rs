//! `atlas-skin transfer` on real characters: KayKit's Knight gives its weights to its own
//! cape written as an OBJ (the cape added to the output as a skinned mesh, validator-clean,
//! close to the artist's weights), re-weights its helmet in place (`--meshes`), and refuses
//! bad input with a message naming the file and no output: a target far away, a target
//! ten times too large, an empty target, a source without weights, an unknown mesh name.

mod support;

use atlas_skin_corpus::{data_file, node_check};
use atlas_skin_io::{load_character, LoadOptions};
use serde_json::Value;
use std::path::{Path, PathBuf};
use support::{atlas_skin, atlas_skin_ok, out_dir};

fn knight() -> PathBuf {
    data_file("bench/kaykit/Knight.glb")
}

/// The stored vertices and triangles of the Knight's mesh named `name`, as an OBJ (each
/// position moved by `offset`, scaled by `scale`).
fn write_mesh_obj(name: &str, offset: [f32; 3], scale: f32, path: &Path) -> usize {
    let character = load_character(&knight(), &LoadOptions::default()).unwrap();
    let gltf = character.gltf.as_ref().unwrap();
    let primitive = gltf
        .primitives
        .iter()
        .find(|p| gltf.document["meshes"][p.mesh]["name"] == name)
        .unwrap();
    let mut text = String::new();
    for p in &character.mesh.positions[primitive.vertices.clone()] {
        text.push_str(&format!(
            "v {} {} {}\n",
            p.x * scale + offset[0],
            p.y * scale + offset[1],
            p.z * scale + offset[2]
        ));
    }
    let first = primitive.vertices.start as u32;
    for t in &character.mesh.triangles[primitive.triangles.clone()] {
        text.push_str(&format!(
            "f {} {} {}\n",
            t[0] - first + 1,
            t[1] - first + 1,
            t[2] - first + 1
        ));
    }
    std::fs::write(path, text).unwrap();
    primitive.vertices.len()
}

/// The cape, taken from the Knight and handed back as a separate OBJ: one more skinned
/// mesh in the output, every row summing to 1, the glTF validator finds no error, the
/// report tells how each of its vertices got its weights.
#[test]
fn a_cape_given_as_obj_is_added_skinned() {
    let dir = out_dir("transfer_cape");
    let cape = dir.join("cape.obj");
    let vertices = write_mesh_obj("Knight_Cape", [0.0; 3], 1.0, &cape);
    let glb = dir.join("knight_cape.glb");
    let report = dir.join("knight_cape.json");
    let html = dir.join("knight_cape.html");
    atlas_skin_ok(&[
        "transfer".as_ref(),
        knight().as_os_str(),
        cape.as_os_str(),
        "-o".as_ref(),
        glb.as_os_str(),
        "--report".as_ref(),
        report.as_os_str(),
        "--html".as_ref(),
        html.as_os_str(),
    ]);
    let source = load_character(&knight(), &LoadOptions::default()).unwrap();
    let out = load_character(&glb, &LoadOptions::default()).unwrap();
    assert_eq!(
        out.mesh.positions.len(),
        source.mesh.positions.len() + vertices
    );
    let weights = out.reference_weights.as_ref().unwrap();
    for v in 0..weights.vertex_count() {
        let total: f32 = weights.row(v).map(|(_, w)| w).sum();
        assert!((total - 1.0).abs() < 1e-5, "vertex {v}: {total}");
    }
    let report: Value = serde_json::from_slice(&std::fs::read(&report).unwrap()).unwrap();
    let target = &report["targets"][0];
    assert_eq!(target["name"], "cape");
    assert_eq!(target["counts"]["stored_vertices"], vertices);
    assert!(target["counts"]["matched"].as_u64().unwrap() > 0);
    assert_eq!(target["vertex_sources"].as_array().unwrap().len(), vertices);
    assert!(std::fs::metadata(&html).unwrap().len() > 10_000);
    let validation = node_check("validate.mjs", &[&glb]);
    assert_eq!(validation[0]["errors"], 0, "{}", validation[0]);
}

/// `--meshes`: the helmet re-weighted from the rest of the Knight, written in place of its
/// own weights; its deformation stays near the artist's (eval on the whole character).
#[test]
fn a_mesh_of_the_source_is_reweighted_in_place() {
    let dir = out_dir("transfer_meshes");
    let glb = dir.join("knight_helmet.glb");
    atlas_skin_ok(&[
        "transfer".as_ref(),
        knight().as_os_str(),
        "--meshes".as_ref(),
        "Knight_Helmet".as_ref(),
        "-o".as_ref(),
        glb.as_os_str(),
    ]);
    let out = load_character(&glb, &LoadOptions::default()).unwrap();
    let source = load_character(&knight(), &LoadOptions::default()).unwrap();
    assert_eq!(out.mesh.positions.len(), source.mesh.positions.len());
    let deform = support::deform_random(&knight(), &glb);
    let mean = deform["mean"].as_f64().unwrap();
    assert!(mean < 0.01, "{deform}");
    let validation = node_check("validate.mjs", &[&glb]);
    assert_eq!(validation[0]["errors"], 0, "{}", validation[0]);
}

/// Runs a transfer that must fail: exit status 1, the message names `file` and says
/// `what`, and no output is left.
fn assert_refused(args: &[&std::ffi::OsStr], out: &Path, file: &Path, what: &str) {
    let mut all: Vec<&std::ffi::OsStr> = vec!["transfer".as_ref()];
    all.extend_from_slice(args);
    all.extend(["-o".as_ref(), out.as_os_str()]);
    let output = atlas_skin(&all);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "{stderr}");
    assert!(stderr.contains(&file.display().to_string()), "{stderr}");
    assert!(stderr.contains(what), "{stderr}");
    assert!(!out.exists());
    let dir = out.parent().unwrap();
    assert!(
        std::fs::read_dir(dir).unwrap().all(|e| !e
            .unwrap()
            .file_name()
            .to_string_lossy()
            .ends_with(".tmp")),
        "a temporary file was left"
    );
}

#[test]
fn bad_input_is_refused_with_the_file_named() {
    let dir = out_dir("transfer_refused");
    let out = dir.join("out.glb");
    let far = dir.join("far.obj");
    write_mesh_obj("Knight_Cape", [0.0, 0.0, 30.0], 1.0, &far);
    assert_refused(
        &[knight().as_os_str(), far.as_os_str()],
        &out,
        &far,
        "rest space",
    );
    let large = dir.join("centimetres.obj");
    write_mesh_obj("Knight_Cape", [0.0; 3], 100.0, &large);
    assert_refused(
        &[knight().as_os_str(), large.as_os_str()],
        &out,
        &large,
        "times the size",
    );
    let empty = dir.join("empty.obj");
    std::fs::write(&empty, "v 0 0 0\nv 1 0 0\nv 0 1 0\n").unwrap();
    let output = atlas_skin(&[
        "transfer".as_ref(),
        knight().as_os_str(),
        empty.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
    ]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        !output.status.success() && stderr.contains("empty.obj"),
        "{stderr}"
    );
    assert!(!out.exists());
    // A source without weights: a bare mesh with a skeleton file.
    let cape = dir.join("cape.obj");
    write_mesh_obj("Knight_Cape", [0.0; 3], 1.0, &cape);
    let bare = dir.join("bare.obj");
    write_mesh_obj("Knight_Body", [0.0; 3], 1.0, &bare);
    let skeleton = dir.join("skeleton.tgf");
    std::fs::write(&skeleton, "1 0 0 0\n2 0 1 0\n#\n1 2\n").unwrap();
    assert_refused(
        &[
            bare.as_os_str(),
            cape.as_os_str(),
            "--skeleton".as_ref(),
            skeleton.as_os_str(),
        ],
        &out,
        &bare,
        "no skin weights",
    );
    assert_refused(
        &[
            knight().as_os_str(),
            "--meshes".as_ref(),
            "Knight_Hat".as_ref(),
        ],
        &out,
        &knight(),
        "no mesh named \"Knight_Hat\"",
    );
}
