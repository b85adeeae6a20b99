//! Checks against Blender (the `bpy` package of PyPI, in the venv `scripts/install-test-deps`
//! makes under target/bpy-venv): FBX characters posed by `atlas-skin pose` land where
//! Blender's FBX import posed the same way puts them, and `eval` takes Blender's bone-heat
//! export of a glb (joints renamed, mesh baked into the scene's space).
//!
//! "The same way" does not depend on how each tool orients its bones: every joint turns by
//! a rotation Q_j about its own head, in world axes, after its parent's. atlas-skin's pose
//! file takes local rotations, so joint j gets `q_j = L_j⁻¹ · Q_j · L_j` with L_j the
//! linear part of its bind frame; Blender's bones get the world matrix `S_j · B_j` (see
//! tests/blender/pose_fbx.py).

mod support;

use atlas_skin_corpus::data_file;
use atlas_skin_io::{load_character, Character, LoadOptions};
use glam::{Mat3, Quat, Vec3};
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Command;
use support::{atlas_skin_ok, eval_json, obj_positions, out_dir};

/// The workspace's folder.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// Runs a script of tests/blender with the bpy venv's Python; panics with its stderr.
fn run_blender(script: &str, args: &[&Path]) {
    let python = workspace().join("target/bpy-venv/bin/python");
    assert!(
        python.is_file(),
        "{} is missing: run scripts/install-test-deps (tests never skip)",
        python.display()
    );
    let output = Command::new(&python)
        .arg(workspace().join("tests/blender").join(script))
        .args(args)
        .output()
        .expect("cannot run Python");
    assert!(
        output.status.success(),
        "{script} failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
}

/// A world-axis turn for joint j: 20–40° about an axis that varies with j.
fn turn(j: usize) -> Quat {
    let f = j as f32;
    let axis = Vec3::new(f.sin(), (2.0 * f).cos(), 0.5).normalize();
    Quat::from_axis_angle(axis, (20.0 + 10.0 * (j % 3) as f32).to_radians())
}

/// The largest distance between atlas-skin's and Blender's posed vertices, over the
/// bounding-box diagonal, for one FBX file.
fn pose_difference(file: &str) -> f32 {
    let dir = out_dir(&format!("blender-fbx-{file}"));
    let input = data_file(&format!("fbx/{file}"));
    let character: Character = load_character(&input, &LoadOptions::default()).unwrap();
    let skeleton = character.skeleton.as_ref().unwrap();
    let mut local = serde_json::Map::new();
    let mut world = serde_json::Map::new();
    for (j, name) in skeleton.names.iter().enumerate() {
        // The bind frame's linear part L (a rotation times a uniform scale, possibly
        // mirrored): the local turn is L⁻¹ · Q · L, a rotation again.
        let frame = Mat3::from_mat4(skeleton.inverse_bind[j].inverse());
        let q = turn(j);
        let turn_local = Quat::from_mat3(&(frame.inverse() * Mat3::from_quat(q) * frame));
        local.insert(name.clone(), json!(turn_local.normalize().to_array()));
        world.insert(name.clone(), json!(q.to_array()));
    }
    let (local_path, world_path) = (dir.join("local.json"), dir.join("world.json"));
    std::fs::write(&local_path, Value::Object(local).to_string()).unwrap();
    std::fs::write(&world_path, Value::Object(world).to_string()).unwrap();

    let obj = dir.join("posed.obj");
    let args = [
        Path::new("pose"),
        input.as_path(),
        Path::new("--pose"),
        &local_path,
        Path::new("-o"),
        &obj,
    ];
    atlas_skin_ok(&args.map(Path::as_os_str));
    let ours = obj_positions(&obj);
    let blender = dir.join("blender.json");
    run_blender("pose_fbx.py", &[&input, &world_path, &blender]);
    let theirs: Value = serde_json::from_str(&std::fs::read_to_string(&blender).unwrap()).unwrap();

    let (min, max) = character
        .mesh
        .positions
        .iter()
        .fold((Vec3::MAX, Vec3::MIN), |(lo, hi), p| {
            (lo.min(*p), hi.max(*p))
        });
    let diagonal = (max - min).length();
    let mut worst = 0f32;
    for part in &character.parts {
        let mesh = theirs["meshes"]
            .as_array()
            .unwrap()
            .iter()
            .find(|m| m["name"] == part.name.as_str())
            .unwrap_or_else(|| panic!("{file}: Blender has no mesh {:?}", part.name));
        let positions = mesh["positions"].as_array().unwrap();
        assert_eq!(
            positions.len(),
            part.vertices.len(),
            "{file}: {}",
            part.name
        );
        for (v, p) in part.vertices.clone().zip(positions) {
            let p = Vec3::new(
                p[0].as_f64().unwrap() as f32,
                p[1].as_f64().unwrap() as f32,
                p[2].as_f64().unwrap() as f32,
            );
            let moved = Vec3::from_array(ours[v]).distance(p);
            worst = worst.max(moved / diagonal);
        }
    }
    // The pose does move the character: the check is not between two rest poses.
    let displacement = ours
        .iter()
        .zip(&character.mesh.positions)
        .map(|(a, b)| Vec3::from_array(*a).distance(*b))
        .fold(0f32, f32::max);
    assert!(displacement > 0.05 * diagonal, "{file}: {displacement}");
    worst
}

#[test]
fn posed_fbx_characters_agree_with_blender() {
    for file in [
        "KayKit_Knight.fbx",
        "assimp_huesitos.fbx",
        "assimp_animation_with_skeleton.fbx",
    ] {
        let difference = pose_difference(file);
        eprintln!("{file}: largest difference {difference:.2e} of the diagonal");
        assert!(difference < 1e-4, "{file}: {difference}");
    }
}

#[test]
fn eval_takes_a_blender_bone_heat_export_as_it_takes_one_with_matching_names() {
    let dir = out_dir("blender-bone-heat");
    let reference = atlas_skin_corpus::RIGGEDFIGURE.input_path();
    let (renamed, plain) = (dir.join("blender_names.glb"), dir.join("plain_names.glb"));
    run_blender("bone_heat.py", &[&reference, &renamed, &plain]);
    let eval = |candidate: &Path| -> Value {
        let args = [
            Path::new("eval"),
            &reference,
            candidate,
            Path::new("--json"),
        ];
        let output = atlas_skin_ok(&args.map(Path::as_os_str));
        serde_json::from_slice(&output.stdout).unwrap()
    };
    let (with_blender_names, with_plain_names) = (eval(&renamed), eval(&plain));
    let hows = |e: &Value| -> Vec<String> {
        let matches = e["joint_matches"].as_array().unwrap();
        matches
            .iter()
            .map(|m| m["how"].as_str().unwrap().to_string())
            .collect()
    };
    assert!(hows(&with_blender_names)
        .iter()
        .all(|h| h == "name_ignoring_case"));
    assert!(hows(&with_plain_names).iter().all(|h| h == "name"));
    assert_eq!(
        with_blender_names["matched"],
        with_blender_names["vertices"]
    );
    for key in [
        "weights_l1",
        "deform_random",
        "deform_random_dqs",
        "deform_anim",
        "bleeding",
    ] {
        assert_eq!(with_blender_names[key], with_plain_names[key], "{key}");
    }
    // Bone heat is not the artist's weighting: real, finite differences.
    let max = with_blender_names["deform_random"]["max"].as_f64().unwrap();
    assert!(max > 1e-3 && max < 0.5, "{max}");
}

/// The KayKit knight's FBX (metres, +Y up) exported by Blender's glTF exporter as a glb in
/// metres, +Y up and +Z up (the exporter's "+Y Up" off): `eval` matches the first as
/// stored and fits the second (a quarter turn, scale 1), both with 0 error (below 1e-6).
#[test]
fn eval_fits_a_blender_export_in_other_axes() {
    let dir = out_dir("blender-eval-axes");
    let input = data_file("fbx/KayKit_Knight.fbx");
    for (flag, turn) in [(None, None), (Some("--z-up"), Some("z_up_to_y_up"))] {
        let glb = dir.join(format!("knight{}.glb", flag.unwrap_or("")));
        let mut args = vec![input.as_path(), glb.as_path()];
        args.extend(flag.map(Path::new));
        run_blender("export_glb.py", &args);
        let e = eval_json(&input, &glb);
        assert_eq!(e["matched"], e["vertices"], "{flag:?}");
        assert_eq!(e["fit"]["turn"].as_str(), turn, "{flag:?}: {}", e["fit"]);
        if turn.is_some() {
            assert!((e["fit"]["scale"].as_f64().unwrap() - 1.0).abs() < 1e-6);
        }
        // Equal weights: Blender stores them in float32, the FBX in float64.
        for figure in [&e["weights_l1"]["max"], &e["deform_random"]["max"]] {
            assert!(figure.as_f64().unwrap() < 1e-6, "{flag:?}: {figure}");
        }
    }
}
