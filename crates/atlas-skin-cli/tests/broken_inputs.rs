//! Broken inputs give a clear error: `atlas-skin inspect` and `atlas-skin skin` exit
//! non-zero, stderr names the file and the problem, nothing panics and `skin` writes no file.

mod support;

use atlas_skin_corpus::RIGGEDSIMPLE;
use std::path::{Path, PathBuf};
use std::process::Output;
use support::{atlas_skin, out_dir};

/// One broken input: the files to write (name, bytes) into a fresh folder, the
/// `inspect` arguments after the subcommand (`{dir}` is replaced by that folder), the file
/// the error must name and a fragment of the problem it must state.
struct Case {
    name: &'static str,
    files: Vec<(&'static str, Vec<u8>)>,
    args: &'static [&'static str],
    names: &'static str,
    problem: &'static str,
}

fn corpus_glb() -> Vec<u8> {
    let path = RIGGEDSIMPLE.input_path();
    std::fs::read(&path).unwrap_or_else(|e| panic!("corpus file {}: {e}", path.display()))
}

/// A one-triangle glTF with an external buffer: `positions` (f32 x, y, z, as many as
/// `position_count` says) then u16 `indices`.
fn triangle_gltf(
    positions: &[f32],
    position_count: usize,
    indices: &[u16],
) -> Vec<(&'static str, Vec<u8>)> {
    let mut buffer: Vec<u8> = positions.iter().flat_map(|v| v.to_le_bytes()).collect();
    let index_offset = buffer.len();
    buffer.extend(indices.iter().flat_map(|i| i.to_le_bytes()));
    buffer.resize(buffer.len().next_multiple_of(4), 0);
    let document = serde_json::json!({
        "asset": {"version": "2.0"},
        "buffers": [{"uri": "triangle.bin", "byteLength": buffer.len()}],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": index_offset},
            {"buffer": 0, "byteOffset": index_offset, "byteLength": indices.len() * 2}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": position_count, "type": "VEC3",
             "min": [0, 0, 0], "max": [1, 1, 0]},
            {"bufferView": 1, "componentType": 5123, "count": indices.len(), "type": "SCALAR"}
        ],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0
    });
    vec![
        ("triangle.gltf", serde_json::to_vec(&document).unwrap()),
        ("triangle.bin", buffer),
    ]
}

const TRIANGLE: [f32; 9] = [0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 0.0];
const OBJ: &[u8] = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";
const BVH: &str =
    "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 3 Zrotation Yrotation Xrotation\n  \
    JOINT Leg\n  {\n    OFFSET 0 -1 0\n    CHANNELS 3 Zrotation Yrotation Xrotation\n  }\n}\n\
    MOTION\nFrames: 1\nFrame Time: 0.1\n0 0 0 0 0 0\n";

fn cases() -> Vec<Case> {
    let glb = corpus_glb();
    let mut wrong_magic = glb.clone();
    wrong_magic[..4].copy_from_slice(b"glTX");
    let mut nan = TRIANGLE;
    nan[4] = f32::NAN;
    vec![
        Case {
            name: "truncated glb",
            files: vec![("truncated.glb", glb[..glb.len() / 2].to_vec())],
            args: &["{dir}/truncated.glb"],
            names: "truncated.glb",
            problem: "truncated glb",
        },
        Case {
            name: "wrong magic",
            files: vec![("magic.glb", wrong_magic)],
            args: &["{dir}/magic.glb"],
            names: "magic.glb",
            problem: "not a binary glTF",
        },
        Case {
            name: "JSON that is not glTF",
            files: vec![("other.gltf", br#"{"hello": [1, 2, 3]}"#.to_vec())],
            args: &["{dir}/other.gltf"],
            names: "other.gltf",
            problem: "not a glTF document",
        },
        Case {
            name: "accessor out of range",
            files: triangle_gltf(&TRIANGLE, 30, &[0, 1, 2]),
            args: &["{dir}/triangle.gltf"],
            names: "triangle.gltf",
            problem: "out of range of bufferViews[0]",
        },
        Case {
            name: "NaN position",
            files: triangle_gltf(&nan, 3, &[0, 1, 2]),
            args: &["{dir}/triangle.gltf"],
            names: "triangle.gltf",
            problem: "is not finite",
        },
        Case {
            name: "index out of range",
            files: triangle_gltf(&TRIANGLE, 3, &[0, 1, 7]),
            args: &["{dir}/triangle.gltf"],
            names: "triangle.gltf",
            problem: "index 7 is out of range",
        },
        Case {
            name: "OBJ face with 2 vertices",
            files: vec![("two.obj", b"v 0 0 0\nv 1 0 0\nf 1 2\n".to_vec())],
            args: &["{dir}/two.obj"],
            names: "two.obj:3",
            problem: "face has 2 vertices",
        },
        Case {
            name: "BVH with a missing brace",
            files: vec![
                ("mesh.obj", OBJ.to_vec()),
                (
                    "brace.bvh",
                    BVH.replacen("  }\n}\n", "  }\n", 1).into_bytes(),
                ),
            ],
            args: &["{dir}/mesh.obj", "--skeleton", "{dir}/brace.bvh"],
            names: "brace.bvh:11",
            problem: "missing } for joint \"Hips\"",
        },
        Case {
            name: "JSON skeleton with a cycle",
            files: vec![
                ("mesh.obj", OBJ.to_vec()),
                (
                    "cycle.json",
                    br#"{"joints": [{"name": "a", "parent": "b", "position": [0, 0, 0]},
                                   {"name": "b", "parent": "a", "position": [0, 1, 0]}]}"#
                        .to_vec(),
                ),
            ],
            args: &["{dir}/mesh.obj", "--skeleton", "{dir}/cycle.json"],
            names: "cycle.json",
            problem: "cycle",
        },
        Case {
            name: "TGF skeleton with a cycle",
            files: vec![
                ("mesh.obj", OBJ.to_vec()),
                (
                    "cycle.tgf",
                    b"1 0 0 0\n2 0 1 0\n3 0 2 0\n#\n1 2\n2 3\n3 1\n".to_vec(),
                ),
            ],
            args: &["{dir}/mesh.obj", "--skeleton", "{dir}/cycle.tgf"],
            names: "cycle.tgf",
            problem: "cycle",
        },
        Case {
            name: "empty file",
            files: vec![("empty.obj", Vec::new())],
            args: &["{dir}/empty.obj"],
            names: "empty.obj",
            problem: "empty",
        },
        Case {
            name: "directory",
            files: vec![],
            args: &["{dir}"],
            names: "broken-directory",
            problem: "is a directory",
        },
        Case {
            name: "missing file",
            files: vec![],
            args: &["{dir}/absent.glb"],
            names: "absent.glb",
            problem: "cannot read",
        },
    ]
}

/// A fresh folder for one case of one subcommand's test (the tests run in parallel).
fn case_dir(subcommand: &str, case: &str) -> PathBuf {
    let slug: String = case
        .chars()
        .map(|c| if c.is_ascii_alphanumeric() { c } else { '-' })
        .collect();
    out_dir(&format!("broken-{subcommand}/broken-{slug}"))
}

fn run(subcommand: &[&str], case: &Case, dir: &Path, trailing: &[&str]) -> Output {
    for (name, bytes) in &case.files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    let dir_text = dir.to_str().unwrap();
    let args: Vec<String> = subcommand
        .iter()
        .map(|a| a.to_string())
        .chain(
            case.args
                .iter()
                .chain(trailing)
                .map(|a| a.replace("{dir}", dir_text)),
        )
        .collect();
    atlas_skin(&args)
}

/// Checks one output: failure, the file and problem in stderr, no panic.
fn check(case: &Case, output: &Output) -> Result<(), String> {
    let stderr = String::from_utf8_lossy(&output.stderr);
    if output.status.success() {
        return Err(format!("{}: succeeded", case.name));
    }
    if stderr.contains("panicked") {
        return Err(format!("{}: panicked: {stderr}", case.name));
    }
    if !stderr.contains(case.names) || !stderr.contains(case.problem) {
        return Err(format!(
            "{}: stderr {stderr:?} lacks {:?} or {:?}",
            case.name, case.names, case.problem
        ));
    }
    Ok(())
}

#[test]
fn inspect_rejects_broken_inputs_clearly() {
    let failures: Vec<String> = cases()
        .iter()
        .filter_map(|case| {
            let dir = case_dir("inspect", case.name);
            check(case, &run(&["inspect"], case, &dir, &[])).err()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn skin_rejects_broken_inputs_without_writing_output() {
    let failures: Vec<String> = cases()
        .iter()
        .filter_map(|case| {
            let dir = case_dir("skin", case.name);
            let output = run(&["skin"], case, &dir, &["-o", "{dir}/out.glb"]);
            // Neither OUT.glb nor a temporary file next to it may be left behind.
            let written: Vec<String> = std::fs::read_dir(&dir)
                .unwrap()
                .map(|entry| entry.unwrap().file_name().to_string_lossy().into_owned())
                .filter(|name| !case.files.iter().any(|(input, _)| input == name))
                .collect();
            match check(case, &output) {
                Err(failure) => Some(failure),
                Ok(()) if !written.is_empty() => Some(format!("{}: wrote {written:?}", case.name)),
                Ok(()) => None,
            }
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
