//! `atlas-skin eval` on another tool's output of the same character: joints renamed
//! (case and punctuation as Blender does, or wholly) and vertices split differently give
//! the figures of the plain pair, and the report says how each joint was matched; two
//! different characters are a clear error. Crafted from RigNet character 498.

mod support;

use atlas_skin_corpus::data_file;
use serde_json::Value;
use std::path::{Path, PathBuf};
use support::{atlas_skin, atlas_skin_ok, out_dir};

fn text(path: &Path) -> &str {
    path.to_str().expect("utf-8 path")
}

/// `skin MESH --skeleton RIG -o OUT`.
fn skin(mesh: &Path, rig: &Path, out: &Path) {
    atlas_skin_ok(&["skin", text(mesh), "--skeleton", text(rig), "-o", text(out)]);
}

/// `eval` of 498 with its own rig against `candidate`, as JSON.
fn eval(candidate: &Path) -> Value {
    let (obj, rig) = originals();
    let output = atlas_skin_ok(&[
        "eval",
        text(&obj),
        "--skeleton",
        text(&rig),
        text(candidate),
        "--json",
    ]);
    serde_json::from_slice(&output.stdout).expect("eval prints JSON")
}

fn originals() -> (PathBuf, PathBuf) {
    (
        data_file("rignet-format/498.obj"),
        data_file("rignet-format/498_rig.txt"),
    )
}

/// The figures that must not depend on names or on the vertex split.
fn figures(e: &Value) -> Vec<f64> {
    ["weights_l1", "deform_random", "deform_random_dqs"]
        .iter()
        .flat_map(|k| ["mean", "max"].map(|m| e[k][m].as_f64().unwrap()))
        .chain([e["bleeding"]["fraction"].as_f64().unwrap()])
        .collect()
}

#[test]
fn renamed_joints_and_resplit_vertices_give_the_plain_pair_figures() {
    let dir = out_dir("eval-across-tools");
    let (obj, rig) = originals();
    let plain = dir.join("plain.glb");
    skin(&obj, &rig, &plain);
    let reference = eval(&plain);
    assert!(reference["joint_matches"]
        .as_array()
        .unwrap()
        .iter()
        .all(|m| m["how"] == "name"));

    // Blender-like renames (case and punctuation) and two names nothing like the originals
    // (`targetR` is named as a helper that moves no skin, `skeleton::helpers`: its new name
    // is one too, so that the skin is the same).
    let renames = [
        ("kosi", "Kosi"),
        ("momoL", "MOMO_L"),
        ("suneR", "sune.r"),
        ("kubi", "bone_7"),
        ("targetR", "ik_helper"),
    ];
    let mut renamed_text = std::fs::read_to_string(&rig).unwrap();
    for (from, to) in renames {
        renamed_text = renamed_text
            .split_inclusive('\n')
            .map(|line| {
                line.split(' ')
                    .map(|t| {
                        if t.trim_end() == from {
                            t.replacen(from, to, 1)
                        } else {
                            t.to_string()
                        }
                    })
                    .collect::<Vec<_>>()
                    .join(" ")
            })
            .collect();
    }
    let renamed_rig = dir.join("renamed_rig.txt");
    std::fs::write(&renamed_rig, renamed_text).unwrap();
    let renamed = dir.join("renamed.glb");
    skin(&obj, &renamed_rig, &renamed);
    let evaluation = eval(&renamed);
    assert_eq!(figures(&evaluation), figures(&reference));
    let how = |candidate: &str| {
        let matches = evaluation["joint_matches"].as_array().unwrap();
        let m = matches
            .iter()
            .find(|m| m["candidate"] == candidate)
            .unwrap();
        (
            m["reference"].as_str().unwrap().to_string(),
            m["how"].as_str().unwrap().to_string(),
        )
    };
    assert_eq!(how("Kosi"), ("kosi".into(), "name_ignoring_case".into()));
    assert_eq!(how("sune.r"), ("suneR".into(), "name_ignoring_case".into()));
    assert_eq!(how("bone_7"), ("kubi".into(), "position".into()));
    assert_eq!(how("ik_helper"), ("targetR".into(), "position".into()));
    assert_eq!(how("jyowanL"), ("jyowanL".into(), "name".into()));
    let output = atlas_skin_ok(&["eval", text(&obj), "--skeleton", text(&rig), text(&renamed)]);
    let summary = String::from_utf8_lossy(&output.stdout);
    assert!(
        summary.contains(
            "joints matched         8 by name, 3 ignoring case and punctuation, 2 by bind position"
        ),
        "{summary}"
    );

    // Every vertex of the first 200 faces duplicated, as a tool splitting seams would.
    let source = std::fs::read_to_string(&obj).unwrap();
    let vertex_lines: Vec<&str> = source.lines().filter(|l| l.starts_with("v ")).collect();
    let mut extra = Vec::new();
    let mut faces = Vec::new();
    for (f, line) in source.lines().filter(|l| l.starts_with("f ")).enumerate() {
        if f >= 200 {
            faces.push(line.to_string());
            continue;
        }
        let corners: Vec<String> = line[2..]
            .split_whitespace()
            .map(|c| {
                let v: usize = c.parse().unwrap();
                extra.push(vertex_lines[v - 1]);
                (vertex_lines.len() + extra.len()).to_string()
            })
            .collect();
        faces.push(format!("f {}", corners.join(" ")));
    }
    let resplit_obj = dir.join("resplit.obj");
    let body: Vec<&str> = vertex_lines.iter().chain(&extra).copied().collect();
    std::fs::write(
        &resplit_obj,
        format!("{}\n{}\n", body.join("\n"), faces.join("\n")),
    )
    .unwrap();
    let resplit = dir.join("resplit.glb");
    skin(&resplit_obj, &rig, &resplit);
    let evaluation = eval(&resplit);
    assert!(
        evaluation["candidate_vertices"].as_u64().unwrap() > 416 + 100,
        "{evaluation}"
    );
    assert_eq!(evaluation["matched"], evaluation["vertices"]);
    let (a, b) = (figures(&evaluation), figures(&reference));
    for (x, y) in a.iter().zip(&b) {
        assert!((x - y).abs() < 1e-6, "{a:?} vs {b:?}");
    }
}

#[test]
fn two_different_characters_are_a_clear_error() {
    let dir = out_dir("eval-not-same");
    let other = dir.join("426.glb");
    skin(
        &data_file("rignet-format/426.obj"),
        &data_file("rignet-format/426_rig.txt"),
        &other,
    );
    let (obj, rig) = originals();
    let output = atlas_skin(&["eval", text(&obj), "--skeleton", text(&rig), text(&other)]);
    assert!(!output.status.success());
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stderr.contains("not the same"), "{stderr}");
    assert!(output.stdout.is_empty());
}
