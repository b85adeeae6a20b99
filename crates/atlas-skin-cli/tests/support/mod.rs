//! Shared helpers of the CLI's integration tests (`mod support;`): running the
//! `atlas-skin` binary, a fresh output folder per test, reading back an OBJ it wrote. The corpus and the node
//! checkers of tests/js are in the `atlas-skin-corpus` crate.

#![allow(dead_code)] // each test binary uses a subset

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// Runs `atlas-skin ARGS...` and returns what it did, success or not.
pub fn atlas_skin<A: AsRef<OsStr>>(args: &[A]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_atlas-skin"))
        .args(args)
        .output()
        .expect("cannot run atlas-skin")
}

/// Runs `atlas-skin ARGS...` and fails, with its arguments and stderr, unless it exits 0.
pub fn atlas_skin_ok<A: AsRef<OsStr>>(args: &[A]) -> Output {
    let output = atlas_skin(args);
    assert!(
        output.status.success(),
        "atlas-skin {:?} failed: {}",
        args.iter().map(AsRef::as_ref).collect::<Vec<_>>(),
        String::from_utf8_lossy(&output.stderr)
    );
    output
}

/// `atlas-skin eval REFERENCE CANDIDATE --json`, parsed; fails unless it exits 0.
pub fn eval_json(reference: &Path, candidate: &Path) -> serde_json::Value {
    let output = atlas_skin_ok(&[Path::new("eval"), reference, candidate, Path::new("--json")]);
    serde_json::from_slice(&output.stdout).expect("eval's JSON")
}

/// Runs `atlas-skin skin INPUT -o DIR/STEM.glb --report DIR/STEM.json` and returns the
/// written glb's path and the report.
pub fn skin_with_report(input: &Path, dir: &Path, stem: &str) -> (PathBuf, serde_json::Value) {
    let glb = dir.join(format!("{stem}.glb"));
    let json = dir.join(format!("{stem}.json"));
    let args: [&OsStr; 6] = [
        "skin".as_ref(),
        input.as_ref(),
        "-o".as_ref(),
        glb.as_ref(),
        "--report".as_ref(),
        json.as_ref(),
    ];
    atlas_skin_ok(&args);
    let report =
        std::fs::read(&json).unwrap_or_else(|e| panic!("cannot read {}: {e}", json.display()));
    let report = serde_json::from_slice(&report).expect("the report is JSON");
    (glb, report)
}

/// `atlas-skin eval REFERENCE CANDIDATE --anim-frames 0 --json`: the candidate's
/// deformation against the reference's weights over `eval`'s random poses
/// (`deform_random`: mean and max over the bounding-box diagonal).
pub fn deform_random(reference: &Path, candidate: &Path) -> serde_json::Value {
    let args: [&OsStr; 6] = [
        "eval".as_ref(),
        reference.as_ref(),
        candidate.as_ref(),
        "--anim-frames".as_ref(),
        "0".as_ref(),
        "--json".as_ref(),
    ];
    let eval = atlas_skin_ok(&args);
    let figures: serde_json::Value =
        serde_json::from_slice(&eval.stdout).expect("eval --json prints JSON");
    figures["deform_random"].clone()
}

/// A skinned character of the bench: its input file, the written glb and the report.
pub struct BenchSkin {
    pub input: PathBuf,
    pub glb: PathBuf,
    pub report: serde_json::Value,
}

impl BenchSkin {
    /// Skins `bench/NAME.glb` of `../shared/data` (NAME such as `rignet-val/1442`) into the
    /// output folder of `test`.
    pub fn new(name: &str, test: &str) -> Self {
        let input = atlas_skin_corpus::data_dir().join(format!("bench/{name}.glb"));
        let dir = out_dir(test);
        let stem = input.file_stem().unwrap().to_str().unwrap().to_string();
        let (glb, report) = skin_with_report(&input, &dir, &stem);
        BenchSkin { input, glb, report }
    }

    /// The decision of the report's decomposition for the joint named `name`.
    pub fn joint(&self, name: &str) -> &serde_json::Value {
        self.report["decomposition"]["joints"]
            .as_array()
            .unwrap()
            .iter()
            .find(|j| j["name"] == name)
            .unwrap_or_else(|| panic!("no joint {name} in the report"))
    }

    /// The pieces and gaps the report lists as weighted as wholes (`pieces.not_decomposed`).
    pub fn whole_pieces(&self) -> &[serde_json::Value] {
        self.report["pieces"]["not_decomposed"].as_array().unwrap()
    }

    /// The pieces and gaps of `vertices` vertices among [`Self::whole_pieces`].
    pub fn whole_pieces_of(&self, vertices: u64) -> Vec<&serde_json::Value> {
        self.whole_pieces()
            .iter()
            .filter(|p| p["vertices"] == vertices)
            .collect()
    }

    /// Asserts that every piece of `vertices` vertices ([`Self::whole_pieces_of`], at least
    /// one) is rigid to the joint named `joint`; returns how many there are.
    pub fn assert_rigid(&self, vertices: u64, joint: &str) -> usize {
        let pieces = self.whole_pieces_of(vertices);
        assert!(
            !pieces.is_empty(),
            "no piece of {vertices} vertices weighted as a whole"
        );
        for piece in &pieces {
            assert_eq!(piece["treatment"], "rigid", "{piece}");
            assert_eq!(piece["joint"], joint, "{piece}");
        }
        pieces.len()
    }

    /// Asserts that the deform figures ([`Self::deform`]) are below `mean` and `max`.
    pub fn assert_deform_below(&self, mean: f64, max: f64) {
        let deform = self.deform();
        assert!(deform["mean"].as_f64().unwrap() < mean, "{deform}");
        assert!(deform["max"].as_f64().unwrap() < max, "{deform}");
    }

    /// The deform figures against the artist's weights ([`deform_random`]).
    pub fn deform(&self) -> serde_json::Value {
        deform_random(&self.input, &self.glb)
    }
}

/// Skins `input` (a path under `../shared/data`) into the output folder of `test` and returns
/// its report's `counts.COUNT` with the deform figures against the input's own weights
/// ([`deform_random`]).
pub fn count_and_deform(
    input: &str,
    test: &str,
    stem: &str,
    count: &str,
) -> (u64, serde_json::Value) {
    let input = atlas_skin_corpus::data_dir().join(input);
    let dir = out_dir(test);
    let (glb, report) = skin_with_report(&input, &dir, stem);
    let counted = report["counts"][count]
        .as_u64()
        .unwrap_or_else(|| panic!("the report counts no {count}"));
    (counted, deform_random(&input, &glb))
}

/// A fresh, empty output folder for one test under the target's test temp dir. It is
/// emptied first, so no two tests of one binary (they run in parallel) may share `test`.
pub fn out_dir(test: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_tests")
        .join(test);
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir
}

/// A path for file `name` in test `test`'s output folder, created if missing but never
/// emptied (several tests of one binary may share it while running in parallel).
pub fn test_file(test: &str, name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR"))
        .join("cli_tests")
        .join(test);
    std::fs::create_dir_all(&dir)
        .unwrap_or_else(|e| panic!("cannot create {}: {e}", dir.display()));
    dir.join(name)
}

/// Vertex positions (`v x y z` lines) of an OBJ file the binary wrote.
pub fn obj_positions(path: &Path) -> Vec<[f32; 3]> {
    let text = std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f32> = l
                .split_whitespace()
                .map(|x| x.parse().expect("a number"))
                .collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}
