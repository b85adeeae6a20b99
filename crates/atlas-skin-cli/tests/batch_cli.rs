//! `atlas-skin batch` on the 65 characters of `../shared/data/bench`: 65 validator-clean
//! glbs and 65 log records, then `--resume` does nothing and says so; a broken file among
//! good ones fails alone; a killed batch leaves only complete files and `--resume` finishes
//! it; folders, globs, name clashes and the per-file reports.

mod support;

use atlas_skin_corpus::{data_dir, data_file, node_check};
use serde_json::Value;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::{Duration, SystemTime};
use support::{atlas_skin, out_dir};

/// `atlas-skin batch ARGS...`.
fn batch<A: Into<OsString> + Clone>(args: &[A]) -> Output {
    let mut all: Vec<OsString> = vec!["batch".into()];
    all.extend(args.iter().cloned().map(Into::into));
    atlas_skin(&all)
}

/// As [`batch`], failing unless it exits 0; returns its stdout.
fn batch_ok<A: Into<OsString> + Clone>(args: &[A]) -> String {
    let output = batch(args);
    assert!(
        output.status.success(),
        "batch failed: {}",
        String::from_utf8_lossy(&output.stderr)
    );
    String::from_utf8_lossy(&output.stdout).into_owned()
}

/// `atlas-skin batch INPUT -o OUT --resume`, failing unless it exits 0; returns its stdout.
fn resume_ok(input: &Path, out: &Path) -> String {
    batch_ok(&[
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--resume".as_ref(),
    ])
}

/// The records of a batch log.
fn log_records(path: &Path) -> Vec<Value> {
    std::fs::read_to_string(path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()))
        .lines()
        .map(|line| serde_json::from_str(line).expect("one JSON object per line"))
        .collect()
}

/// Files of `dir` whose names end with `suffix`, sorted.
fn files_ending(dir: &Path, suffix: &str) -> Vec<PathBuf> {
    let mut files: Vec<PathBuf> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.to_string_lossy().ends_with(suffix))
        .collect();
    files.sort();
    files
}

fn modified(path: &Path) -> SystemTime {
    std::fs::metadata(path).unwrap().modified().unwrap()
}

/// A complete glTF binary: the header's length is the file's.
fn is_complete_glb(path: &Path) -> bool {
    let bytes = std::fs::read(path).unwrap();
    bytes.len() >= 12
        && &bytes[..4] == b"glTF"
        && u32::from_le_bytes(bytes[8..12].try_into().unwrap()) as usize == bytes.len()
}

/// The Khronos glTF-Validator finds no error in any output (5 bench inputs carry
/// zero-length normals, which the writer repairs) and no warning the input did not have
/// (information messages such as unused objects are not counted).
fn assert_no_new_validator_issues(inputs: &[PathBuf], outputs: &[PathBuf]) {
    let input_reports = node_check("validate.mjs", inputs);
    let output_reports = node_check("validate.mjs", outputs);
    let mut inputs_with_errors = 0;
    for (input, output) in input_reports.iter().zip(&output_reports) {
        assert_eq!(output["errors"], 0, "{output}");
        inputs_with_errors += usize::from(input["errors"] != 0);
        let codes = output["codes"].as_object().expect("codes");
        for (code, count) in codes
            .iter()
            .filter(|(code, _)| code.starts_with("warning:"))
        {
            let allowed = input["codes"]
                .get(code)
                .and_then(Value::as_u64)
                .unwrap_or(0);
            assert!(
                count.as_u64().unwrap() <= allowed,
                "{code}: {count} in the output, {allowed} in the input: {output}"
            );
        }
    }
    assert!(
        inputs_with_errors >= 5,
        "the bench's inputs with invalid normals are repaired: {inputs_with_errors}"
    );
}

#[test]
fn bench_gives_65_valid_glbs_then_resume_does_nothing() {
    let out = out_dir("batch_bench");
    let bench = data_dir().join("bench");
    let stdout = batch_ok(&[bench.as_os_str(), "-o".as_ref(), out.as_os_str()]);
    assert!(
        stdout.contains("65 files: 65 skinned, 0 failed"),
        "{stdout}"
    );

    let glbs = files_ending(&out, ".glb");
    assert_eq!(glbs.len(), 65);
    let log = out.join("atlas-skin-batch.jsonl");
    let records = log_records(&log);
    assert_eq!(records.len(), 65);
    let inputs: Vec<PathBuf> = records
        .iter()
        .map(|r| PathBuf::from(r["input"].as_str().unwrap()))
        .collect();
    let outputs: Vec<PathBuf> = records
        .iter()
        .map(|r| PathBuf::from(r["output"].as_str().unwrap()))
        .collect();
    assert_no_new_validator_issues(&inputs, &outputs);
    for record in &records {
        assert_eq!(record["status"], "ok", "{record}");
        assert!(record["error"].is_null());
        assert!(
            record["counts"]["vertices"].as_u64().unwrap() > 0,
            "{record}"
        );
        assert!(
            record["timings_ms"]["weights"].as_f64().is_some(),
            "{record}"
        );
        assert!(record["seconds"].as_f64().unwrap() > 0.0);
        assert!(record["warnings"].is_array());
        assert!(Path::new(record["output"].as_str().unwrap()).is_file());
    }

    let before: Vec<SystemTime> = glbs.iter().map(|g| modified(g)).collect();
    let stdout = resume_ok(&bench, &out);
    assert!(
        stdout.contains("nothing to do: the outputs of all 65 files are up to date"),
        "{stdout}"
    );
    let after: Vec<SystemTime> = glbs.iter().map(|g| modified(g)).collect();
    assert_eq!(before, after, "--resume rewrote outputs");
    let records = log_records(&log);
    assert_eq!(records.len(), 65);
    assert!(records.iter().all(|r| r["status"] == "skipped"));
}

/// A folder of good characters and one broken file.
fn folder_with_a_broken_file(test: &str) -> (PathBuf, PathBuf) {
    let dir = out_dir(test);
    let inputs = dir.join("in");
    std::fs::create_dir_all(&inputs).unwrap();
    for relative in [
        "bench/kaykit/Knight.glb",
        "bench/rignet-val/1168.glb",
        "models/cesiumman/CesiumMan.glb",
    ] {
        let source = data_file(relative);
        std::fs::copy(&source, inputs.join(source.file_name().unwrap())).unwrap();
    }
    std::fs::write(inputs.join("broken.glb"), b"glTF\x02\x00\x00\x00not a glb").unwrap();
    (inputs, dir.join("out"))
}

#[test]
fn a_broken_file_fails_alone() {
    let (inputs, out) = folder_with_a_broken_file("batch_broken");
    let output = batch(&[
        inputs.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "-j".as_ref(),
        "2".as_ref(),
    ]);
    assert!(
        !output.status.success(),
        "a failed file must make the exit code non-zero"
    );
    let stdout = String::from_utf8_lossy(&output.stdout);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(stdout.contains("4 files: 3 skinned, 1 failed"), "{stdout}");
    assert!(stderr.contains("1 of 4 files failed"), "{stderr}");

    // The failure reads as `skin` prints it.
    let broken = inputs.join("broken.glb");
    let skin = atlas_skin(&[
        "skin".as_ref(),
        broken.as_os_str(),
        "-o".as_ref(),
        out.join("skin.glb").as_os_str(),
    ]);
    let skin_error = String::from_utf8_lossy(&skin.stderr).trim().to_string();
    assert!(stderr.contains(&skin_error), "{stderr}\nskin: {skin_error}");

    let records = log_records(&out.join("atlas-skin-batch.jsonl"));
    assert_eq!(records.len(), 4);
    let failed: Vec<&Value> = records.iter().filter(|r| r["status"] == "failed").collect();
    assert_eq!(failed.len(), 1);
    assert!(failed[0]["input"].as_str().unwrap().ends_with("broken.glb"));
    assert_eq!(
        format!("error: {}", failed[0]["error"].as_str().unwrap()),
        skin_error
    );
    let glbs = files_ending(&out, ".glb");
    let names: Vec<String> = glbs
        .iter()
        .map(|g| g.file_name().unwrap().to_string_lossy().into_owned())
        .collect();
    assert_eq!(names, ["1168.glb", "CesiumMan.glb", "Knight.glb"]);
    assert!(files_ending(&out, ".tmp").is_empty());
}

#[test]
fn a_killed_batch_leaves_complete_files_and_resume_finishes_it() {
    let out = out_dir("batch_killed");
    let bench = data_dir().join("bench");
    let mut child = Command::new(env!("CARGO_BIN_EXE_atlas-skin"))
        .args([
            "batch".as_ref(),
            bench.as_os_str(),
            "-o".as_ref(),
            out.as_os_str(),
            "-j".as_ref(),
            "1".as_ref(),
        ])
        .spawn()
        .unwrap();
    let log = out.join("atlas-skin-batch.jsonl");
    // Kill it once it has finished a few files, well before the 65.
    let started = std::time::Instant::now();
    let finished = || std::fs::read(&log).map_or(0, |b| b.iter().filter(|&&c| c == b'\n').count());
    while finished() < 3 {
        assert!(started.elapsed() < Duration::from_secs(60), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
    child.kill().unwrap();
    child.wait().unwrap();
    let done = log_records(&log).len();
    assert!(done < 65, "the batch finished before it was killed");
    let glbs = files_ending(&out, ".glb");
    assert!(glbs.len() >= done);
    for glb in &glbs {
        assert!(is_complete_glb(glb), "{} is incomplete", glb.display());
    }

    // What a write killed before its rename leaves, and a file that only looks alike.
    let leftover = out.join(".Knight.glb.0123456789abcdef.tmp");
    let kept = out.join(".Knight.glb.notes.tmp");
    std::fs::write(&leftover, b"half a glb").unwrap();
    std::fs::write(&kept, b"mine").unwrap();
    let stdout = resume_ok(&bench, &out);
    assert!(
        !leftover.exists(),
        "--resume removes the killed run's temporary files"
    );
    assert!(kept.exists());
    let records = log_records(&log);
    let skipped = records.iter().filter(|r| r["status"] == "skipped").count();
    assert_eq!(records.len(), 65);
    assert_eq!(skipped, glbs.len(), "{stdout}");
    assert!(records.iter().all(|r| r["status"] != "failed"));
    assert_eq!(files_ending(&out, ".glb").len(), 65);
}

#[test]
fn resume_redoes_a_file_newer_than_its_output() {
    let dir = out_dir("batch_resume_newer");
    let input = dir.join("Knight.glb");
    std::fs::copy(data_file("bench/kaykit/Knight.glb"), &input).unwrap();
    let out = dir.join("out");
    batch_ok(&[input.as_os_str(), "-o".as_ref(), out.as_os_str()]);
    std::thread::sleep(Duration::from_millis(20));
    let bytes = std::fs::read(&input).unwrap();
    std::fs::write(&input, bytes).unwrap();
    let stdout = resume_ok(&input, &out);
    assert!(
        stdout.contains("1 file: 1 skinned, 0 failed, 0 up to date"),
        "{stdout}"
    );
    // Asking for a report the first run did not write also redoes the file.
    let stdout = batch_ok(&[
        input.as_os_str(),
        "-o".as_ref(),
        out.as_os_str(),
        "--resume".as_ref(),
        "--report".as_ref(),
    ]);
    assert!(stdout.contains("1 skinned"), "{stdout}");
    assert!(out.join("Knight.json").is_file());
}

#[test]
fn globs_reports_and_per_file_html() {
    let dir = out_dir("batch_globs");
    let pattern = data_dir().join("bench/kaykit/[KM]*.glb");
    let log = dir.join("logs/run.jsonl");
    let stdout = batch_ok(&[
        pattern.as_os_str(),
        "-o".as_ref(),
        dir.join("out").as_os_str(),
        "--report".as_ref(),
        "--html".as_ref(),
        "--log".as_ref(),
        log.as_os_str(),
        "--max-influences".as_ref(),
        "2".as_ref(),
    ]);
    assert!(stdout.contains("2 files: 2 skinned"), "{stdout}");
    for name in ["Knight", "Mage"] {
        let report: Value = serde_json::from_str(
            &std::fs::read_to_string(dir.join(format!("out/{name}.json"))).unwrap(),
        )
        .unwrap();
        assert_eq!(report["counts"]["max_influences"], 2);
        let html = std::fs::read_to_string(dir.join(format!("out/{name}.html"))).unwrap();
        assert!(html.starts_with("<!DOCTYPE html>"), "{name}");
    }
    assert_eq!(log_records(&log).len(), 2);
}

#[test]
fn inputs_that_cannot_start_a_batch() {
    let dir = out_dir("batch_refused");
    let out = dir.join("out");
    let cases: [(Vec<OsString>, &str); 4] = [
        (
            vec![data_dir().join("bench/kaykit/*.nothing").into()],
            "matches no file",
        ),
        (
            vec![data_dir().join("motion").into()],
            "holds no character file (.glb, .gltf, .vrm, .fbx)",
        ),
        (
            vec![
                data_file("bench/kaykit/Knight.glb").into(),
                data_file("fbx/KayKit_Knight.fbx").into(),
                dir.join("Knight.fbx").into(),
            ],
            "would both be written to",
        ),
        (
            vec![
                data_file("bench/kaykit/Knight.glb").into(),
                "--jobs".into(),
                "0".into(),
            ],
            "0 is outside 1..=256",
        ),
    ];
    std::fs::write(dir.join("Knight.fbx"), b"").unwrap();
    for (mut args, message) in cases {
        args.extend(["-o".into(), out.clone().into()]);
        let output = batch(&args);
        let stderr = String::from_utf8_lossy(&output.stderr);
        assert!(!output.status.success(), "{args:?}");
        assert!(stderr.contains(message), "{args:?}: {stderr}");
        assert!(!out.exists(), "{args:?} wrote {}", out.display());
    }
    // An output folder that is an input's folder: refused before any work.
    let input = dir.join("in.glb");
    std::fs::copy(data_file("bench/kaykit/Knight.glb"), &input).unwrap();
    let output = batch(&[input.as_os_str(), "-o".as_ref(), dir.as_os_str()]);
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(
        stderr.contains("refusing to write over the input file"),
        "{stderr}"
    );
}
