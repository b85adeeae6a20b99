//! `atlas-skin pose` agrees with three.js's own skinning (tests/js/three_pose.mjs:
//! GLTFLoader + SkinnedMesh.getVertexPosition) on the corpus glTF models, for animation
//! frames and for a pose file, within 1e-5 of the bounding-box diagonal.

mod support;

use atlas_skin_corpus::{node_json, Model, CESIUMMAN, RIGGEDFIGURE, RIGGEDSIMPLE};
use std::ffi::OsStr;
use std::path::Path;
use support::{atlas_skin_ok, obj_positions, out_dir};

/// (model, joints turned by the pose file)
const CORPUS: [(Model, &[&str]); 3] = [
    (CESIUMMAN, &["node3", "node11", "node16", "node8"]),
    (RIGGEDFIGURE, &["node3", "node11", "node16", "node8"]),
    (RIGGEDSIMPLE, &["node2", "node3"]),
];

/// Vertex positions of `atlas-skin pose INPUT ARGS -o OUT.obj`.
fn atlas_pose(input: &Path, args: &[&str], out: &Path) -> Vec<[f64; 3]> {
    let mut all = vec![OsStr::new("pose"), input.as_os_str()];
    all.extend(args.iter().map(OsStr::new));
    all.extend([OsStr::new("-o"), out.as_os_str()]);
    atlas_skin_ok(&all);
    obj_positions(out)
        .into_iter()
        .map(|p| p.map(f64::from))
        .collect()
}

/// Vertex positions three.js computes for the same input and pose.
fn three_pose(input: &Path, args: &[&str]) -> Vec<[f64; 3]> {
    let mut all = vec![input.as_os_str()];
    all.extend(args.iter().map(OsStr::new));
    let json = node_json("three_pose.mjs", &all);
    let flat: Vec<f64> = json["positions"]
        .as_array()
        .expect("positions")
        .iter()
        .map(|x| x.as_f64().expect("number"))
        .collect();
    flat.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect()
}

fn assert_agree(what: &str, ours: &[[f64; 3]], theirs: &[[f64; 3]]) {
    assert_eq!(ours.len(), theirs.len(), "{what}: vertex count");
    let mut lo = [f64::MAX; 3];
    let mut hi = [f64::MIN; 3];
    for p in theirs {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
    let worst = ours
        .iter()
        .zip(theirs)
        .map(|(a, b)| (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt())
        .fold(0.0, f64::max);
    assert!(
        worst <= 1e-5 * diagonal,
        "{what}: largest distance {worst:e} > 1e-5 × diagonal {diagonal}"
    );
}

#[test]
fn animation_frames_agree_with_three_js() {
    let dir = out_dir("three_pose_anim");
    for (model, _) in CORPUS {
        let (folder, input) = (model.name, model.input_path());
        for time in ["0.3", "0.95"] {
            let out = dir.join(format!("{folder}-anim-{time}.obj"));
            let ours = atlas_pose(&input, &["--anim", "0", "--time", time], &out);
            let theirs = three_pose(&input, &["--anim", "0", "--time", time]);
            assert_agree(&format!("{folder} at {time} s"), &ours, &theirs);
        }
    }
}

#[test]
fn pose_files_agree_with_three_js() {
    let dir = out_dir("three_pose_file");
    for (model, joints) in CORPUS {
        let (folder, input) = (model.name, model.input_path());
        // Unit quaternions of 30° to 50° about assorted axes.
        let rotations = [
            [0.2588, 0.0, 0.0, 0.9659],
            [0.0, 0.3420, 0.0, 0.9397],
            [0.1, 0.2, 0.3, 0.9274],
            [-0.3, 0.1, 0.2, 0.9274],
        ];
        let pose: serde_json::Map<String, serde_json::Value> = joints
            .iter()
            .zip(rotations)
            .map(|(name, q)| (name.to_string(), serde_json::json!(q)))
            .collect();
        let pose_path = dir.join(format!("{folder}-pose.json"));
        std::fs::write(&pose_path, serde_json::Value::Object(pose).to_string()).unwrap();
        let pose_arg = pose_path.to_str().expect("UTF-8 path");
        let out = dir.join(format!("{folder}-pose.obj"));
        let ours = atlas_pose(&input, &["--pose", pose_arg], &out);
        let theirs = three_pose(&input, &["--pose", pose_arg]);
        assert_agree(&format!("{folder} pose file"), &ours, &theirs);
    }
}
