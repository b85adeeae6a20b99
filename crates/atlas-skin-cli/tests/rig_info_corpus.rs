//! RigNet's OBJ + rig_info characters of ../shared/data/rignet-format: they load, their
//! weights equal the glb copies of the same ids in bench/rignet-val, and `skin --rig-info`
//! writes a file the reader reads back to the weights of the glb written beside it.

mod support;

use atlas_skin_corpus::data_file;
use atlas_skin_io::{load_character, LoadOptions};
use serde_json::Value;
use std::path::PathBuf;
use support::{atlas_skin_ok, out_dir};

const IDS: [&str; 5] = ["1134", "1168", "426", "485", "498"];

fn obj_and_rig(id: &str) -> (PathBuf, PathBuf) {
    (
        data_file(&format!("rignet-format/{id}.obj")),
        data_file(&format!("rignet-format/{id}_rig.txt")),
    )
}

fn text(path: &std::path::Path) -> &str {
    path.to_str().expect("utf-8 path")
}

#[test]
fn the_five_characters_load_and_match_their_glb_copies() {
    for id in IDS {
        let (obj, rig) = obj_and_rig(id);
        let rig_text = std::fs::read_to_string(&rig).unwrap();
        let joint_lines = rig_text
            .lines()
            .filter(|l| l.starts_with("joints "))
            .count();
        let output = atlas_skin_ok(&["inspect", "--json", text(&obj), "--skeleton", text(&rig)]);
        let report: Value = serde_json::from_slice(&output.stdout).unwrap();
        assert_eq!(
            report["joints"].as_array().unwrap().len(),
            joint_lines,
            "{id}"
        );
        assert_eq!(report["reference_weights"], true, "{id}");

        let glb = data_file(&format!("bench/rignet-val/{id}.glb"));
        let output = atlas_skin_ok(&[
            "eval",
            text(&obj),
            "--skeleton",
            text(&rig),
            text(&glb),
            "--prune-reference",
            "4",
            "--json",
        ]);
        let evaluation: Value = serde_json::from_slice(&output.stdout).unwrap();
        assert_eq!(evaluation["matched"], evaluation["vertices"], "{id}");
        let l1 = evaluation["weights_l1"]["max"].as_f64().unwrap();
        assert!(l1 < 1e-3, "{id}: L1 max {l1}");
    }
}

#[test]
fn skin_rig_info_round_trips_through_the_reader() {
    let dir = out_dir("rig-info-round-trip");
    let (obj, rig) = obj_and_rig("498");
    let glb = dir.join("498.glb");
    let written = dir.join("498_rig.txt");
    atlas_skin_ok(&[
        "skin",
        text(&obj),
        "--skeleton",
        text(&rig),
        "-o",
        text(&glb),
        "--rig-info",
        text(&written),
    ]);
    let options = LoadOptions {
        skeleton: Some(written.clone()),
        ..LoadOptions::default()
    };
    let read_back = load_character(&obj, &options).unwrap();
    let skinned = load_character(&glb, &LoadOptions::default()).unwrap();
    let (a, b) = (read_back.skeleton.unwrap(), skinned.skeleton.unwrap());
    assert_eq!(a.names, b.names);
    assert_eq!(a.parents, b.parents);
    for (p, q) in a.bind_positions().iter().zip(b.bind_positions()) {
        assert!(p.distance(q) < 1e-6, "{p} {q}");
    }
    // The glb's vertices are the OBJ's used ones in order: rows line up one to one.
    let (a, b) = (
        read_back.reference_weights.unwrap(),
        skinned.reference_weights.unwrap(),
    );
    assert_eq!(a.vertex_count(), b.vertex_count());
    for v in 0..a.vertex_count() {
        let dense = |w: &atlas_skin_runtime::VertexWeights| {
            let mut row = vec![0f32; 13];
            for (j, x) in w.row(v) {
                row[j as usize] += x;
            }
            row
        };
        let l1: f32 = dense(&a)
            .iter()
            .zip(dense(&b))
            .map(|(x, y)| (x - y).abs())
            .sum();
        assert!(l1 < 1e-6, "vertex {v}: L1 {l1}");
    }
    // The writer refuses to write over its input.
    let output = support::atlas_skin(&[
        "skin",
        text(&obj),
        "--skeleton",
        text(&written),
        "-o",
        text(&dir.join("again.glb")),
        "--rig-info",
        text(&written),
    ]);
    assert!(!output.status.success());
    assert!(String::from_utf8_lossy(&output.stderr).contains("refusing to write over the input"));
    assert!(!dir.join("again.glb").exists(), "nothing is written");
}

#[test]
fn a_rig_info_without_every_skin_line_gives_its_skeleton_and_no_weights() {
    let dir = out_dir("rig-info-cut");
    let (obj, rig) = obj_and_rig("498");
    let text = std::fs::read_to_string(&rig).unwrap();
    let cut = dir.join("cut_rig.txt");
    std::fs::write(&cut, &text[..text.find("skin 300 ").unwrap()]).unwrap();
    let options = LoadOptions {
        skeleton: Some(cut),
        ..LoadOptions::default()
    };
    let character = load_character(&obj, &options).unwrap();
    assert_eq!(character.skeleton.unwrap().len(), 13);
    assert!(character.reference_weights.is_none());
    let warnings = character.warnings.join("\n");
    assert!(
        warnings.contains("116 vertices of the mesh have no skin line (the first: vertex 300)"),
        "{warnings}"
    );
}
