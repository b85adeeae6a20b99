//! `atlas-skin pose`: every pose source on a corpus model, the rest pose giving the rest
//! mesh, and a table of invalid invocations that must fail with a message.

use glam::Vec3;
use std::path::{Path, PathBuf};
use std::process::Output;

mod support;

use support::{atlas_skin, obj_positions, test_file};

/// Runs `atlas-skin pose ARGS...`.
fn pose(args: &[&str]) -> Output {
    let mut all = vec!["pose"];
    all.extend_from_slice(args);
    atlas_skin(&all)
}

const MODELS: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/models");
const MOTION: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../../shared/data/motion/walk.bvh"
);

fn model(folder: &str, file: &str) -> PathBuf {
    let path = Path::new(MODELS).join(folder).join(file);
    assert!(path.exists(), "corpus file {} is missing", path.display());
    path
}

/// An empty pose file is the rest pose: on the arm (skeleton in its bind pose, weights
/// summing to 1) the output is the input mesh, with both methods, up to the round-off of
/// composing the joint hierarchy (world · inverse bind is the identity only to ~1 ulp).
#[test]
fn rest_pose_gives_the_rest_mesh() {
    let dir = Path::new(MODELS).join("arm");
    let empty = test_file("pose_cli", "empty.json");
    std::fs::write(&empty, "{}").unwrap();
    let input = atlas_skin_io::obj::read(&dir.join("arm.obj"), None).expect("read arm");
    for dqs in [false, true] {
        let out = test_file("pose_cli", &format!("arm-rest-{dqs}.obj"));
        let mut args = vec![
            dir.join("arm.obj").to_str().unwrap().to_string(),
            "--skeleton".into(),
            dir.join("arm.tgf").to_str().unwrap().to_string(),
            "--weights".into(),
            dir.join("arm-weights.dmat").to_str().unwrap().to_string(),
            "--pose".into(),
            empty.to_str().unwrap().to_string(),
            "-o".into(),
            out.to_str().unwrap().to_string(),
        ];
        if dqs {
            args.push("--dqs".into());
        }
        let output = pose(&args.iter().map(String::as_str).collect::<Vec<_>>());
        assert!(
            output.status.success(),
            "{}",
            String::from_utf8_lossy(&output.stderr)
        );
        let posed = obj_positions(&out);
        assert_eq!(posed.len(), input.positions.len());
        let worst = posed
            .iter()
            .zip(&input.positions)
            .map(|(p, q)| Vec3::from(*p).distance(*q))
            .fold(0.0, f32::max);
        // The arm is 1.8 long: 1e-6 of it is a few ulps.
        assert!(worst < 2e-6, "dqs: {dqs}: moved by {worst}");
    }
}

#[test]
fn every_pose_source_writes_obj_and_glb() {
    let input = model("cesiumman", "CesiumMan.glb");
    let input = input.to_str().unwrap();
    for (i, source) in [
        vec!["--anim", "0", "--time", "1.2"],
        vec!["--random", "7"],
        vec!["--random", "7", "--dqs"],
    ]
    .iter()
    .enumerate()
    {
        for extension in ["obj", "glb"] {
            let out = test_file("pose_cli", &format!("cesium-{i}.{extension}"));
            let mut args = vec![input];
            args.extend(source.iter().copied());
            args.extend(["-o", out.to_str().unwrap()]);
            let output = pose(&args);
            assert!(
                output.status.success(),
                "{source:?}: {}",
                String::from_utf8_lossy(&output.stderr)
            );
            assert!(std::fs::metadata(&out).unwrap().len() > 0);
        }
    }
    // Same seed, same pose; another seed, another pose.
    let out = |seed: &str, name: &str| {
        let path = test_file("pose_cli", name);
        assert!(
            pose(&[input, "--random", seed, "-o", path.to_str().unwrap()])
                .status
                .success()
        );
        obj_positions(&path)
    };
    assert_eq!(out("7", "a.obj"), out("7", "b.obj"));
    assert_ne!(out("7", "a.obj"), out("8", "c.obj"));
}

#[test]
fn invalid_invocations_fail_with_a_message() {
    let cesium = model("cesiumman", "CesiumMan.glb");
    let cesium = cesium.to_str().unwrap();
    let unknown_joint = test_file("pose_cli", "unknown-joint.json");
    std::fs::write(&unknown_joint, r#"{"no such joint": [0, 0, 0, 1]}"#).unwrap();
    let not_json = test_file("pose_cli", "not.json");
    std::fs::write(&not_json, "{").unwrap();
    let arm = model("arm", "arm.obj");
    let out = test_file("pose_cli", "never.obj");
    let out = out.to_str().unwrap();
    let cases: Vec<(Vec<&str>, &str)> = vec![
        (vec![cesium, "-o", out], "required"),
        (
            vec![cesium, "--random", "1", "--anim", "0", "-o", out],
            "cannot be used with",
        ),
        (vec![cesium, "--anim", "walk", "-o", out], "no animation"),
        (
            vec![cesium, "--bvh", MOTION, "-o", out],
            "no joint name in common",
        ),
        (
            vec![cesium, "--pose", unknown_joint.to_str().unwrap(), "-o", out],
            "no joint named",
        ),
        (
            vec![cesium, "--pose", not_json.to_str().unwrap(), "-o", out],
            "not valid JSON",
        ),
        (
            vec![cesium, "--random", "1", "-o", "posed.stl"],
            ".obj or .glb",
        ),
        (
            vec![arm.to_str().unwrap(), "--random", "1", "-o", out],
            "no skeleton",
        ),
    ];
    for (args, message) in cases {
        let output = pose(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?} succeeded");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
    }
    assert!(!Path::new(out).exists());
}
