//! `atlas-skin eval` on small glb files written by hand: the validity counts and weight
//! differences of a candidate with every defect, worked out by hand.

mod support;

use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::process::Output;
use support::{atlas_skin, atlas_skin_ok};

/// A unit square of 4 vertices (2 triangles) skinned to two joints, "root" and "tip".
fn square_glb(joints: [[u8; 4]; 4], weights: [[f32; 4]; 4]) -> Vec<u8> {
    rectangle_glb(0.0, 1.0, joints, weights)
}

/// [`square_glb`] `width` wide along X, moved by `dx` along X.
fn rectangle_glb(dx: f32, width: f32, joints: [[u8; 4]; 4], weights: [[f32; 4]; 4]) -> Vec<u8> {
    let positions: [[f32; 3]; 4] = [
        [dx, 0.0, 0.0],
        [width + dx, 0.0, 0.0],
        [width + dx, 1.0, 0.0],
        [dx, 1.0, 0.0],
    ];
    let indices: [u16; 6] = [0, 1, 2, 0, 2, 3];
    let mut bin = Vec::new();
    let mut views = Vec::new();
    let mut push = |bytes: Vec<u8>| {
        views.push(json!({"buffer": 0, "byteOffset": bin.len(), "byteLength": bytes.len()}));
        bin.extend(bytes);
        while !bin.len().is_multiple_of(4) {
            bin.push(0);
        }
    };
    push(
        positions
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect(),
    );
    push(joints.iter().flatten().copied().collect());
    push(
        weights
            .iter()
            .flatten()
            .flat_map(|x| x.to_le_bytes())
            .collect(),
    );
    push(indices.iter().flat_map(|x| x.to_le_bytes()).collect());
    let document = json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 2]}],
        "nodes": [
            {"name": "root", "children": [1]},
            {"name": "tip", "translation": [1.0, 0.0, 0.0]},
            {"name": "square", "mesh": 0, "skin": 0}
        ],
        "meshes": [{"primitives": [{
            "attributes": {"POSITION": 0, "JOINTS_0": 1, "WEIGHTS_0": 2},
            "indices": 3
        }]}],
        "skins": [{"joints": [0, 1]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3",
             "min": [dx, 0.0, 0.0], "max": [1.0 + dx, 1.0, 0.0]},
            {"bufferView": 1, "componentType": 5121, "count": 4, "type": "VEC4"},
            {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC4"},
            {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ],
        "bufferViews": views,
        "buffers": [{"byteLength": bin.len()}]
    });
    let mut text = serde_json::to_vec(&document).unwrap();
    while !text.len().is_multiple_of(4) {
        text.push(b' ');
    }
    let mut glb = Vec::new();
    let total = 12 + 8 + text.len() + 8 + bin.len();
    for word in [0x4654_6C67u32, 2, total as u32] {
        glb.extend(word.to_le_bytes());
    }
    glb.extend((text.len() as u32).to_le_bytes());
    glb.extend(0x4E4F_534Au32.to_le_bytes());
    glb.extend(text);
    glb.extend((bin.len() as u32).to_le_bytes());
    glb.extend(0x004E_4942u32.to_le_bytes());
    glb.extend(bin);
    glb
}

fn write(name: &str, bytes: &[u8]) -> PathBuf {
    let path = Path::new(env!("CARGO_TARGET_TMPDIR")).join(name);
    std::fs::write(&path, bytes).unwrap();
    path
}

/// The arguments of `atlas-skin eval REFERENCE CANDIDATE --json`.
fn eval_args<'a>(reference: &'a Path, candidate: &'a Path) -> [&'a Path; 4] {
    [Path::new("eval"), reference, candidate, Path::new("--json")]
}

fn eval(reference: &Path, candidate: &Path) -> Output {
    atlas_skin(&eval_args(reference, candidate))
}

fn eval_json(reference: &Path, candidate: &Path) -> Value {
    let output = atlas_skin_ok(&eval_args(reference, candidate));
    serde_json::from_slice(&output.stdout).unwrap()
}

#[test]
fn validity_and_weight_differences_of_a_crafted_candidate() {
    // Reference: vertices 0, 1 on the root, 2, 3 on the tip.
    let reference = write(
        "eval_crafted_reference.glb",
        &square_glb(
            [[0, 0, 0, 0], [0, 0, 0, 0], [1, 0, 0, 0], [1, 0, 0, 0]],
            [[1.0, 0.0, 0.0, 0.0]; 4],
        ),
    );
    // Candidate: a tie, rows summing to 1.3 and 0.5, an empty row. (Negative weights are
    // refused by the glTF reader; `validity`'s own tests count them.)
    let candidate = write(
        "eval_crafted_candidate.glb",
        &square_glb(
            [[0, 1, 0, 0], [0, 1, 0, 0], [0, 0, 0, 0], [0, 0, 0, 0]],
            [
                [0.5, 0.5, 0.0, 0.0],
                [0.7, 0.6, 0.0, 0.0],
                [0.5, 0.0, 0.0, 0.0],
                [0.0, 0.0, 0.0, 0.0],
            ],
        ),
    );
    let e = eval_json(&reference, &candidate);
    assert_eq!(
        e["validity"],
        json!({
            "negative_weights": 0,
            "sums_off_one": 2,
            "unweighted_vertices": 1,
            "max_influences": 2,
            "mean_influences": 1.25
        })
    );
    // Per vertex Σ|w_ref − w_cand|: 0.5 + 0.5, 0.3 + 0.6, 1 + 0.5, 1: mean 4.4 / 4. The
    // heaviest joint agrees on vertices 0 (the tie resolves to the root) and 1.
    let close = |key: &str, expected: f64| {
        let got = e["weights_l1"][key].as_f64().unwrap();
        assert!(
            (got - expected).abs() < 1e-6,
            "{key}: {got}, expected {expected}"
        );
    };
    close("mean", 1.1);
    close("p95", 1.5);
    close("max", 1.5);
    close("dominant_agreement", 0.5);
    assert_eq!(
        (e["vertices"].as_u64(), e["matched"].as_u64()),
        (Some(4), Some(4))
    );
    assert!(e["deform_anim"].is_null());
}

#[test]
fn identical_crafted_files_give_zeros() {
    let weights = [[0.25, 0.75, 0.0, 0.0]; 4];
    let reference = write(
        "eval_crafted_same.glb",
        &square_glb([[0, 1, 0, 0]; 4], weights),
    );
    let e = eval_json(&reference, &reference);
    for key in ["mean", "p95", "max"] {
        assert_eq!(e["weights_l1"][key].as_f64(), Some(0.0), "{key}");
    }
    for group in ["deform_random", "deform_random_dqs"] {
        assert_eq!(e[group]["max"].as_f64(), Some(0.0), "{group}");
    }
    assert_eq!(e["bleeding"]["fraction"].as_f64(), Some(0.0));
}

/// The same square moved is fitted back (a translation, said in the output); a
/// rectangle is another mesh, which no fit pairs: refused.
#[test]
fn a_candidate_of_another_mesh_is_refused() {
    let weights = [[1.0, 0.0, 0.0, 0.0]; 4];
    let reference = write("eval_crafted_here.glb", &square_glb([[0; 4]; 4], weights));
    let elsewhere = write(
        "eval_crafted_elsewhere.glb",
        &rectangle_glb(5.0, 1.0, [[0; 4]; 4], weights),
    );
    let moved = eval_json(&reference, &elsewhere);
    let fit = &moved["fit"];
    assert_eq!(
        (&fit["turn"], &fit["scale"]),
        (&json!("none"), &json!(1.0)),
        "{fit}"
    );
    assert_eq!(fit["translation"], json!([-5.0, 0.0, 0.0]), "{fit}");
    assert_eq!(moved["weights_l1"]["max"], 0.0);
    let other = write(
        "eval_crafted_other.glb",
        &rectangle_glb(5.0, 3.0, [[0; 4]; 4], weights),
    );
    let output = eval(&reference, &other);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success());
    assert!(stderr.contains("not the same mesh?"), "{stderr}");
    assert!(!stderr.contains("panicked"), "{stderr}");
}
