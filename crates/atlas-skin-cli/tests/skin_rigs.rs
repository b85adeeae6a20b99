//! `atlas-skin skin` on a rig as some files store it: RiggedFigure with the parent links
//! between its joints removed. The method infers a hierarchy and says so; the written file
//! keeps the input's nodes exactly as they were.

mod support;

use atlas_skin_corpus::RIGGEDFIGURE;
use serde_json::Value;
use std::ffi::OsString;
use support::{atlas_skin_ok, out_dir};

/// The JSON and BIN chunks of a `.glb`.
fn glb_chunks(bytes: &[u8]) -> (Value, Vec<u8>) {
    let word = |at: usize| u32::from_le_bytes(bytes[at..at + 4].try_into().unwrap()) as usize;
    let json_length = word(12);
    let json = serde_json::from_slice(&bytes[20..20 + json_length]).unwrap();
    let bin_length = word(20 + json_length);
    let bin = bytes[28 + json_length..28 + json_length + bin_length].to_vec();
    (json, bin)
}

/// The skin report of `input` and the written document.
fn skin(input: &std::path::Path, dir: &std::path::Path, name: &str) -> (Value, Value) {
    let glb = dir.join(format!("{name}.glb"));
    let report = dir.join(format!("{name}.json"));
    atlas_skin_ok(&[
        OsString::from("skin"),
        input.into(),
        "-o".into(),
        glb.clone().into(),
        "--report".into(),
        report.clone().into(),
    ]);
    let report = serde_json::from_slice(&std::fs::read(report).unwrap()).unwrap();
    (report, glb_chunks(&std::fs::read(glb).unwrap()).0)
}

#[test]
fn joints_without_parent_links_get_an_inferred_tree_and_the_nodes_stay() {
    let dir = out_dir("skin-rigs");
    let (mut json, bin) = glb_chunks(&std::fs::read(RIGGEDFIGURE.input_path()).unwrap());
    let joints: Vec<u64> = json["skins"][0]["joints"]
        .as_array()
        .unwrap()
        .iter()
        .map(|j| j.as_u64().unwrap())
        .collect();
    for node in json["nodes"].as_array_mut().unwrap() {
        if let Some(Value::Array(children)) = node.get_mut("children") {
            children.retain(|c| !joints.contains(&c.as_u64().unwrap()));
        }
    }
    std::fs::write(dir.join("figure.bin"), &bin).unwrap();
    json["buffers"][0]["uri"] = "figure.bin".into();
    let input = dir.join("unlinked.gltf");
    std::fs::write(&input, json.to_string()).unwrap();

    let (linked, _) = skin(&RIGGEDFIGURE.input_path(), &dir, "linked");
    let (report, written) = skin(&input, &dir, "unlinked");
    let warnings = report["warnings"].to_string();
    assert!(
        warnings.contains(&format!(
            "the skeleton's {} joints have no parent links among themselves",
            joints.len()
        )),
        "{warnings}"
    );
    assert_eq!(
        written["nodes"], json["nodes"],
        "the file's nodes are unchanged"
    );
    let cuts = |r: &Value| r["decomposition"]["cuts"].as_u64().unwrap();
    // Measured: 13 cuts from the inferred tree, 15 from the file's links. In the inferred
    // tree every section of one ankle (node9) crosses the cut of its foot, and the other
    // ankle, its mirror twin, gives up its cut with it (`cuts::conflicts`); before that
    // rule, 14.
    assert!(
        cuts(&report) + 2 >= cuts(&linked),
        "{} vs {}",
        cuts(&report),
        cuts(&linked)
    );
}
