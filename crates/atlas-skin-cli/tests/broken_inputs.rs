//! Broken inputs give a clear error: `atlas-skin inspect` and `atlas-skin skin` exit
//! non-zero, stderr names the file and the problem, nothing panics and `skin` writes no file.
//! Hostile FBX and rig_info files are made from the corpus's (../shared/data). Inputs whose
//! only fault is in the stored weights are refused by `inspect` and `eval`, which read them,
//! and skinned by `skin`, which replaces them without reading them.

mod support;

use atlas_skin_corpus::{data_file, RIGGEDSIMPLE};
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
    let mut cases = vec![
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
    ];
    cases.extend(hostile_fbx_and_rig_info());
    cases
}

/// A case reading the one file `file` (with `before` arguments ahead of it).
fn file_case(
    name: &'static str,
    files: Vec<(&'static str, Vec<u8>)>,
    before: &[&'static str],
    (file, names): (&'static str, &'static str),
    problem: &'static str,
) -> Case {
    let arg: &'static str = Box::leak(format!("{{dir}}/{file}").into_boxed_str());
    let args: Vec<&'static str> = before.iter().copied().chain([arg]).collect();
    Case {
        name,
        files,
        args: Box::leak(args.into_boxed_slice()),
        names,
        problem,
    }
}

/// The corpus's ASCII FBX (Skeleton_heaps_ascii.fbx).
fn heaps() -> String {
    std::fs::read_to_string(data_file("fbx/Skeleton_heaps_ascii.fbx")).unwrap()
}

/// The number (from 1) of the first line of `text` that contains `needle`.
fn line_of(text: &str, needle: &str) -> usize {
    text.lines().position(|l| l.contains(needle)).unwrap() + 1
}

/// A case reading `heaps` with `from` replaced by `to` on line `line`, as `file`.
fn heaps_edit(
    name: &'static str,
    heaps: &str,
    (file, line): (&'static str, usize),
    (from, to): (&str, &str),
    problem: &'static str,
) -> Case {
    let text: String = heaps
        .lines()
        .enumerate()
        .map(|(i, l)| if i + 1 == line { l.replacen(from, to, 1) } else { l.to_string() } + "\n")
        .collect();
    file_case(
        name,
        vec![(file, text.into_bytes())],
        &[],
        (file, file),
        problem,
    )
}

/// Inputs whose only fault is in the stored weights, each with the bytes of the same file
/// without the fault: Heaps's ASCII FBX with a cluster weighting a vertex past the mesh's
/// end, or with a negative weight.
fn bad_stored_weights() -> Vec<(Case, Vec<u8>)> {
    let heaps = heaps();
    let indexes = line_of(&heaps, "Indexes: *50 {");
    let weights = line_of(&heaps, "Weights: *50 {");
    let cases = [
        heaps_edit(
            "FBX weights on a vertex past the end",
            &heaps,
            ("past.fbx", indexes + 1),
            ("a: 0,", "a: 100000,"),
            "weights vertex 100000, but the mesh has 445 vertices",
        ),
        heaps_edit(
            "FBX negative weight",
            &heaps,
            ("negative.fbx", weights + 1),
            ("a: 1,", "a: -1,"),
            "vertex 0 has skin weight -1",
        ),
    ];
    cases
        .into_iter()
        .map(|case| (case, heaps.clone().into_bytes()))
        .collect()
}

/// The hostile files of the FBX and rig_info readers: truncated, wrong header, huge
/// declared counts, a node cycle, weights on vertices past the end, non-numbers.
fn hostile_fbx_and_rig_info() -> Vec<Case> {
    let knight = std::fs::read(data_file("fbx/KayKit_Knight.fbx")).unwrap();
    let heaps = heaps();
    let rig = std::fs::read_to_string(data_file("rignet-format/498_rig.txt")).unwrap();
    let obj = std::fs::read(data_file("rignet-format/498.obj")).unwrap();
    // 498.obj with the rig_info `text` as its --skeleton `file`.
    let rig_case = |name, (file, names): (&'static str, &'static str), text: String, problem| {
        let files = vec![("498.obj", obj.clone()), (file, text.into_bytes())];
        file_case(
            name,
            files,
            &["{dir}/498.obj", "--skeleton"],
            (file, names),
            problem,
        )
    };
    // Binary FBX: the array header after the first "Vertices" name is (type 'd', length,
    // encoding, compressed length); a length of 2^31 - 1 doubles is 16 GiB.
    let mut huge = knight.clone();
    let at = knight.windows(8).position(|w| w == b"Vertices").unwrap() + 9;
    huge[at..at + 4].copy_from_slice(&0x7fff_ffffu32.to_le_bytes());
    let mut header = knight.clone();
    header[..7].copy_from_slice(b"Kaydarb");
    let vertices = line_of(&heaps, "Vertices: *1335 {");
    let root_connection = line_of(&heaps, "C: \"OO\",551080896,0");
    let half = knight[..knight.len() / 2].to_vec();
    vec![
        file_case(
            "truncated FBX",
            vec![("half.fbx", half)],
            &[],
            ("half.fbx", "half.fbx"),
            "not a readable FBX file",
        ),
        file_case(
            "FBX with a wrong header",
            vec![("header.fbx", header)],
            &[],
            ("header.fbx", "header.fbx"),
            "not a readable FBX file: Not an FBX file",
        ),
        file_case(
            "binary FBX declaring a huge array",
            vec![("huge.fbx", huge)],
            &[],
            ("huge.fbx", "huge.fbx"),
            "Memory limit exceeded",
        ),
        heaps_edit(
            "ASCII FBX declaring a huge array",
            &heaps,
            ("count.fbx", vertices),
            ("*1335", "*999999999999"),
            "declares 999999999999 values but holds 1335",
        ),
        heaps_edit(
            "FBX node cycle",
            &heaps,
            ("cycle.fbx", root_connection),
            ("C: \"OO\",551080896,0", "C: \"OO\",551080896,551069616"),
            "Cyclic node hierarchy",
        ),
        heaps_edit(
            "FBX array with a word",
            &heaps,
            ("word.fbx", vertices + 1),
            ("a: -0.559155941009521", "a: abc"),
            "array value \"abc\" is not a number",
        ),
        heaps_edit(
            "FBX with a NaN position",
            &heaps,
            ("nan.fbx", vertices + 1),
            ("a: -0.559155941009521", "a: nan"),
            "is not finite",
        ),
        rig_case(
            "truncated rig_info",
            ("cut_rig.txt", "cut_rig.txt"),
            rig[..rig.find("skin 300 ").unwrap() + "skin 300 kubi".len()].to_string(),
            "missing weight",
        ),
        rig_case(
            "rig_info with a cycle",
            ("cycle_rig.txt", "cycle_rig.txt"),
            rig.replace("root kosi\n", "hier kubi kosi\n"),
            "cycle",
        ),
        rig_case(
            "rig_info weight on a vertex past the end",
            ("past_rig.txt", "past_rig.txt"),
            rig.replace("skin 0 ", "skin 416 "),
            "vertex index 416 is out of range (416 defined)",
        ),
        rig_case(
            "rig_info with a word for a number",
            ("word_rig.txt", "word_rig.txt:1"),
            rig.replacen("joints jyowanL 0.06800120", "joints jyowanL x", 1),
            "x coordinate \"x\" is not a valid number",
        ),
        rig_case(
            "rig_info declaring a huge vertex",
            ("huge_rig.txt", "huge_rig.txt"),
            rig.replace("skin 0 ", "skin 99999999999999999999 "),
            "vertex index \"99999999999999999999\"",
        ),
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
    let bad_weights = bad_stored_weights().into_iter().map(|(case, _)| case);
    let failures: Vec<String> = cases()
        .into_iter()
        .chain(bad_weights)
        .filter_map(|case| {
            let dir = case_dir("inspect", case.name);
            check(&case, &run(&["inspect"], &case, &dir, &[])).err()
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

/// `eval` reads the reference's stored weights (here the candidate's too: the same file), so
/// it refuses bad ones as `inspect` does.
#[test]
fn eval_rejects_bad_stored_weights_clearly() {
    let failures: Vec<String> = bad_stored_weights()
        .iter()
        .filter_map(|(case, _)| {
            let dir = case_dir("eval", case.name);
            check(case, &run(&["eval"], case, &dir, case.args)).err()
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

/// `skin` replaces the stored weights without reading them: it skins a file whose only
/// fault is there, and writes the same glb as for the file without the fault.
#[test]
fn skin_skins_inputs_whose_only_fault_is_the_stored_weights() {
    for (bad, sound_bytes) in bad_stored_weights() {
        let sound = Case {
            files: vec![(bad.files[0].0, sound_bytes)],
            ..bad
        };
        let [bad_glb, sound_glb] = [("bad", &bad), ("sound", &sound)].map(|(kind, case)| {
            let dir = case_dir(&format!("skin-{kind}"), case.name);
            let output = run(&["skin"], case, &dir, &["-o", "{dir}/out.glb"]);
            assert!(
                output.status.success(),
                "{} ({kind}): {}",
                case.name,
                String::from_utf8_lossy(&output.stderr)
            );
            std::fs::read(dir.join("out.glb")).unwrap()
        });
        assert!(bad_glb == sound_glb, "{}: the glbs differ", bad.name);
    }
}
