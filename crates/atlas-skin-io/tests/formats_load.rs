//! `load_character`: dispatch, skeleton and weights attachment, and its own errors.

use atlas_skin_io::{load_character, LoadOptions};
use atlas_skin_runtime::NO_PARENT;
use std::path::PathBuf;

/// Writes `files` into a fresh folder named `case` and returns the folder.
fn folder(case: &str, files: &[(&str, &[u8])]) -> PathBuf {
    let dir = std::env::temp_dir()
        .join(format!("atlas-skin-load-{}", std::process::id()))
        .join(case);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for (name, bytes) in files {
        std::fs::write(dir.join(name), bytes).unwrap();
    }
    dir
}

/// A square of two triangles (vertices 1–4) plus an unused vertex 5 between them in the
/// file, in two groups.
const SQUARE: &[u8] = b"v 0 0 0\nv 1 0 0\nv 9 9 9\nv 1 1 0\nv 0 1 0\n\
    g left\nf 1 2 4\ng right\nf 1 4 5\n";
const TGF: &[u8] = b"1 0 0 0\n2 1 0 0\n3 1 1 0\n#\n1 2\n2 3\n#\n";
/// One column per TGF bone, one row per file vertex (5), column-major.
const DMAT: &[u8] = b"2 5\n1 1 0 0.5 1\n0 0 1 0.5 0\n";

fn options(dir: &std::path::Path, skeleton: Option<&str>, weights: Option<&str>) -> LoadOptions {
    LoadOptions {
        skeleton: skeleton.map(|s| dir.join(s)),
        group: None,
        weights: weights.map(|w| dir.join(w)),
    }
}

#[test]
fn obj_with_tgf_and_per_bone_dmat() {
    let dir = folder(
        "full",
        &[("m.obj", SQUARE), ("s.tgf", TGF), ("w.dmat", DMAT)],
    );
    let character = load_character(
        &dir.join("m.obj"),
        &options(&dir, Some("s.tgf"), Some("w.dmat")),
    )
    .unwrap();
    assert_eq!(character.mesh.positions.len(), 4);
    assert_eq!(character.file_vertex, [0, 1, 3, 4]);
    assert_eq!(character.mesh.triangles, [[0, 1, 2], [0, 2, 3]]);
    let skeleton = character.skeleton.as_ref().unwrap();
    assert_eq!(skeleton.parents, [NO_PARENT, 0, 1]);
    assert_eq!(character.rig.as_ref().unwrap().names, skeleton.names);
    // Bone 1→2 goes to joint 0, bone 2→3 to joint 1; file vertex 3 (kept vertex 2) is 50/50.
    let weights = character.reference_weights.as_ref().unwrap();
    assert_eq!(weights.vertex_count(), 4);
    assert_eq!(weights.row(2).collect::<Vec<_>>(), [(0, 0.5), (1, 0.5)]);
    assert_eq!(weights.row(3).collect::<Vec<_>>(), [(0, 1.0)]);
    assert!(character
        .warnings
        .iter()
        .any(|w| w.contains("1 of the file's 5 vertices")));
}

#[test]
fn a_group_and_a_mesh_without_skeleton() {
    let dir = folder("group", &[("m.obj", SQUARE)]);
    let options = LoadOptions {
        group: Some("right".into()),
        ..LoadOptions::default()
    };
    let character = load_character(&dir.join("m.obj"), &options).unwrap();
    assert_eq!(character.file_vertex, [0, 3, 4]);
    assert!(character.skeleton.is_none());
    assert!(character.warnings.iter().any(|w| w.contains("no skeleton")));
}

#[test]
fn load_errors_name_the_file_and_problem() {
    let dir = folder(
        "errors",
        &[
            ("m.obj", SQUARE),
            ("s.tgf", TGF),
            ("empty.stl", b""),
            ("m.xyz", b"1 2 3"),
            ("points.off", b"OFF\n1 0 0\n0 0 0\n"),
            ("w.dmat", DMAT),
            ("short.dmat", b"2 4\n1 1 1 1\n0 0 0 0\n"),
            (
                "wide.dmat",
                b"4 5\n1 1 1 1 1\n0 0 0 0 0\n0 0 0 0 0\n0 0 0 0 0\n",
            ),
            ("joints.dmat", b"3 5\n0 0 0 0 0\n0 0 0 0 0\n1 1 1 1 1\n"),
            ("s.txt", b"x"),
            ("s.xyz", b"x"),
            ("empty.json", br#"{"joints": []}"#),
        ],
    );
    let load = |mesh: &str, options: LoadOptions| {
        load_character(&dir.join(mesh), &options)
            .unwrap_err()
            .to_string()
    };
    let group = |name: &str| LoadOptions {
        group: Some(name.into()),
        ..LoadOptions::default()
    };
    let cases = [
        (
            load("absent.obj", LoadOptions::default()),
            "absent.obj: cannot read",
        ),
        (
            load("empty.stl", LoadOptions::default()),
            "empty.stl: the file is empty",
        ),
        (load("", LoadOptions::default()), "is a directory"),
        (
            load("m.xyz", LoadOptions::default()),
            "m.xyz: unsupported file type \"xyz\"",
        ),
        (
            load("points.off", LoadOptions::default()),
            "points.off: the mesh has no triangles",
        ),
        (
            load("points.off", group("body")),
            "--group applies to OBJ files only",
        ),
        (
            load("m.obj", group("body")),
            "no group named \"body\" (groups in the file: left, right)",
        ),
        (
            load("m.obj", options(&dir, Some("s.xyz"), None)),
            "s.xyz: unsupported file type \"xyz\"",
        ),
        (
            load("m.obj", options(&dir, Some("s.txt"), None)),
            "s.txt:1: unknown record \"x\" (expected joints, root, hier or skin)",
        ),
        (
            load("m.obj", options(&dir, Some("empty.json"), None)),
            "empty.json: the skeleton has no joint",
        ),
        (
            load("m.obj", options(&dir, None, Some("w.dmat"))),
            "w.dmat: weights need a skeleton",
        ),
        (
            load("m.obj", options(&dir, Some("s.tgf"), Some("short.dmat"))),
            "short.dmat: 4 rows, but the mesh file has 5 vertices",
        ),
        (
            load("m.obj", options(&dir, Some("s.tgf"), Some("wide.dmat"))),
            "wide.dmat: 4 columns, expected 3 (one per joint) or 2 (one per TGF bone)",
        ),
    ];
    for (error, expected) in cases {
        assert!(error.contains(expected), "{error} lacks {expected}");
    }
    // One column per joint is accepted too.
    let character = load_character(
        &dir.join("m.obj"),
        &options(&dir, Some("s.tgf"), Some("joints.dmat")),
    )
    .unwrap();
    let weights = character.reference_weights.unwrap();
    assert!((0..4).all(|v| weights.row(v).collect::<Vec<_>>() == [(2, 1.0)]));
}
