//! The quality gate (`--fail-on LIST`, `--keep-rejected`, a settings file's `fail_on`) of
//! `skin` and `batch`: each condition on real characters that trigger it and on clean
//! ones, exit code 3, the reasons in the report and the batch log, rejected outputs kept
//! under their rejected names or not written, an earlier run's outputs under the other
//! name removed.

mod support;

use atlas_skin_corpus::data_file;
use serde_json::Value;
use std::collections::BTreeSet;
use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::Output;
use support::{atlas_skin, out_dir};

/// Every condition of the gate, as `--fail-on` names them.
const CONDITIONS: [&str; 9] = [
    "warnings",
    "input",
    "mesh",
    "placement",
    "skeleton",
    "weights",
    "fallback",
    "soft-joints",
    "unweighted-joints",
];

/// The exit code of a rejected character.
const REJECTED: i32 = 3;

fn text(path: &Path) -> &str {
    path.to_str().expect("utf-8 path")
}

/// `atlas-skin skin INPUT -o DIR/STEM.glb --report DIR/STEM.json ARGS...`.
fn skin(input: &Path, dir: &Path, stem: &str, args: &[&str]) -> Output {
    let glb = dir.join(format!("{stem}.glb"));
    let report = dir.join(format!("{stem}.json"));
    let mut all: Vec<&OsStr> = vec![
        "skin".as_ref(),
        input.as_ref(),
        "-o".as_ref(),
        glb.as_ref(),
        "--report".as_ref(),
        report.as_ref(),
    ];
    all.extend(args.iter().map(OsStr::new));
    atlas_skin(&all)
}

fn read_json(path: &Path) -> Value {
    let bytes = std::fs::read(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    serde_json::from_slice(&bytes).expect("JSON")
}

fn stderr(output: &Output) -> String {
    String::from_utf8_lossy(&output.stderr).into_owned()
}

/// SimpleSkin (a strip of 10 vertices) without its last two triangles: 2 stored vertices
/// that no triangle uses, weighted by the nearest-bone fallback.
fn simpleskin_with_unused_vertices(dir: &Path) -> PathBuf {
    let mut json = read_json(&data_file("models/simpleskin/SimpleSkin.gltf"));
    assert_eq!(json["accessors"][0]["count"], 24, "the strip's indices");
    json["accessors"][0]["count"] = 18.into();
    let path = dir.join("simpleskin-unused.gltf");
    std::fs::write(&path, json.to_string()).unwrap();
    path
}

/// On each character, `--fail-on` every condition rejects it for exactly the conditions
/// it triggers (each reason starts with its condition), and `--fail-on` the others
/// accepts it and writes it: two clean characters (a glb and an FBX), one per topic of
/// warnings, soft joints and joints with a boundary that carry no weight, and vertices
/// weighted by a fallback (a crafted file: no corpus character has any).
#[test]
fn each_condition_rejects_the_characters_that_trigger_it_and_only_those() {
    let dir = out_dir("quality_gate_conditions");
    let cases: Vec<(PathBuf, &[&str])> = vec![
        (data_file("models/riggedsimple/RiggedSimple.glb"), &[]),
        (data_file("fbx/assimp_huesitos.fbx"), &[]),
        (
            data_file("fbx/Skeleton_heaps_ascii.fbx"),
            &["warnings", "input"],
        ),
        (
            data_file("bench/rignet-val/6808.glb"),
            &["warnings", "mesh"],
        ),
        (
            data_file("bench/rignet-val/498.glb"),
            &["warnings", "skeleton"],
        ),
        (
            data_file("models/simpleskin/SimpleSkin.gltf"),
            &["warnings", "placement"],
        ),
        (
            data_file("bench/rignet-val/1168.glb"),
            &["warnings", "weights", "soft-joints", "unweighted-joints"],
        ),
        (
            data_file("bench/rignet-val/10089.glb"),
            &["unweighted-joints"],
        ),
        (
            simpleskin_with_unused_vertices(&dir),
            &["warnings", "mesh", "placement", "fallback"],
        ),
    ];
    let all = CONDITIONS.join(",");
    for (k, (input, expected)) in cases.iter().enumerate() {
        let stem = format!("case{k}");
        let output = skin(input, &dir, &stem, &["--fail-on", &all]);
        let name = input.display();
        let report = if expected.is_empty() {
            assert_eq!(output.status.code(), Some(0), "{name}: {}", stderr(&output));
            assert!(dir.join(format!("{stem}.glb")).is_file());
            read_json(&dir.join(format!("{stem}.json")))
        } else {
            assert_eq!(output.status.code(), Some(REJECTED), "{name}");
            assert!(stderr(&output).contains("the quality gate rejected the character"));
            assert!(!dir.join(format!("{stem}.glb")).exists(), "{name}");
            assert!(!dir.join(format!("{stem}.json")).exists(), "{name}");
            read_json(&dir.join(format!("{stem}.rejected.json")))
        };
        let quality = &report["quality"];
        assert_eq!(quality["fail_on"], serde_json::json!(CONDITIONS));
        assert_eq!(quality["rejected"], !expected.is_empty());
        let reasons: Vec<&str> = quality["reasons"]
            .as_array()
            .unwrap()
            .iter()
            .map(|r| r.as_str().unwrap())
            .collect();
        let found: BTreeSet<&str> = reasons
            .iter()
            .map(|r| r.split_once(": ").expect("CONDITION: cause").0)
            .collect();
        assert_eq!(
            found,
            expected.iter().copied().collect(),
            "{name}: {reasons:?}"
        );
        assert_eq!(
            report["warning_topics"].as_array().unwrap().len(),
            report["warnings"].as_array().unwrap().len()
        );

        let others: Vec<&str> = CONDITIONS
            .into_iter()
            .filter(|c| !expected.contains(c))
            .collect();
        let output = skin(
            input,
            &dir,
            &format!("{stem}-others"),
            &["--fail-on", &others.join(",")],
        );
        assert_eq!(output.status.code(), Some(0), "{name}: {}", stderr(&output));
        assert!(dir.join(format!("{stem}-others.glb")).is_file());
    }
}

/// A rejected character: without `--keep-rejected` only its report is written (under its
/// rejected name) and an earlier run's glb is removed; with it every output is written
/// under its rejected name, a valid glb; accepted again, the rejected files go. A
/// settings file's `fail_on` works as the flag, which overrides it; an unknown condition
/// is a usage error naming the conditions.
#[test]
fn rejected_outputs_are_kept_apart_or_not_written() {
    let dir = out_dir("quality_gate_outputs");
    let input = data_file("bench/rignet-val/1168.glb");
    let (glb, report, html) = (
        dir.join("out.glb"),
        dir.join("out.json"),
        dir.join("out.html"),
    );
    let rejected_glb = dir.join("out.rejected.glb");
    let (rejected_report, rejected_html) =
        (dir.join("out.rejected.json"), dir.join("out.rejected.html"));

    let plain = skin(&input, &dir, "out", &["--html", text(&html)]);
    assert!(plain.status.success() && glb.is_file() && html.is_file());
    let refused = skin(
        &input,
        &dir,
        "out",
        &["--fail-on", "soft-joints", "--html", text(&html)],
    );
    assert_eq!(refused.status.code(), Some(REJECTED));
    assert!(String::from_utf8_lossy(&refused.stdout).contains("rejected, not written"));
    assert!(
        !glb.exists() && !html.exists() && !report.exists(),
        "earlier outputs removed"
    );
    assert!(rejected_report.is_file() && !rejected_glb.exists() && !rejected_html.exists());

    let kept = skin(
        &input,
        &dir,
        "out",
        &[
            "--fail-on",
            "soft-joints",
            "--keep-rejected",
            "--html",
            text(&html),
        ],
    );
    assert_eq!(kept.status.code(), Some(REJECTED));
    let summary = String::from_utf8_lossy(&kept.stdout).into_owned();
    assert!(
        summary.contains(&format!("rejected, kept as {}", rejected_glb.display())),
        "{summary}"
    );
    assert!(rejected_glb.is_file() && rejected_html.is_file() && rejected_report.is_file());
    assert!(!glb.exists());
    let eval = atlas_skin(&["eval", text(&input), text(&rejected_glb), "--json"]);
    assert!(
        eval.status.success(),
        "the kept glb is a skinned glb: {}",
        stderr(&eval)
    );

    let accepted = skin(
        &input,
        &dir,
        "out",
        &["--fail-on", "placement", "--html", text(&html)],
    );
    assert!(accepted.status.success(), "{}", stderr(&accepted));
    assert!(glb.is_file() && html.is_file() && report.is_file());
    for path in [&rejected_glb, &rejected_html, &rejected_report] {
        assert!(!path.exists(), "{} stayed", path.display());
    }

    let config = dir.join("gate.json");
    std::fs::write(
        &config,
        r#"{"fail_on": ["unweighted-joints"], "overlap": {"factor": 0.5}}"#,
    )
    .unwrap();
    let from_file = skin(&input, &dir, "file", &["--config", text(&config)]);
    assert_eq!(from_file.status.code(), Some(REJECTED));
    let reasons = &read_json(&dir.join("file.rejected.json"))["quality"]["reasons"];
    assert!(
        reasons[0]
            .as_str()
            .unwrap()
            .starts_with("unweighted-joints: "),
        "{reasons}"
    );
    let overridden = skin(
        &input,
        &dir,
        "file",
        &["--config", text(&config), "--fail-on", "mesh"],
    );
    assert!(overridden.status.success(), "{}", stderr(&overridden));

    let typo = skin(&input, &dir, "typo", &["--fail-on", "soft-joint"]);
    assert_eq!(typo.status.code(), Some(2));
    assert!(stderr(&typo).contains("soft-joints"), "{}", stderr(&typo));
    let help = String::from_utf8_lossy(&atlas_skin(&["skin", "--help"]).stdout).into_owned();
    assert!(help.contains("the exit code is 3"));
    assert!(
        CONDITIONS.iter().all(|c| help.contains(&format!("- {c}:"))),
        "{help}"
    );
}

/// A batch with the gate: the rejected file is logged `rejected` with its reasons, the
/// others `ok`, the exit code is 3 (1 when a file also failed); with `--keep-rejected`
/// its glb is written under its rejected name, named in the record; `--resume` skips the
/// accepted files and judges the rejected one again.
#[test]
fn a_batch_logs_rejected_files_and_exits_3() {
    let dir = out_dir("quality_gate_batch");
    let inputs = [
        data_file("models/riggedsimple/RiggedSimple.glb"),
        data_file("bench/rignet-val/1168.glb"),
        data_file("bench/rignet-val/498.glb"),
    ];
    let run = |out: &Path, extra: &[&OsStr]| {
        let mut args: Vec<&OsStr> = vec!["batch".as_ref()];
        args.extend(inputs.iter().map(|p| p.as_os_str()));
        args.extend([
            "-o".as_ref(),
            out.as_os_str(),
            "--fail-on".as_ref(),
            "soft-joints".as_ref(),
        ]);
        args.extend(extra);
        atlas_skin(&args)
    };
    // The log's records in the order of the inputs (it holds them as they finish).
    let records = |out: &Path| -> Vec<Value> {
        let text = std::fs::read_to_string(out.join("atlas-skin-batch.jsonl")).unwrap();
        let mut log: Vec<Value> = text
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        log.sort_by_key(|r| {
            let input = Path::new(r["input"].as_str().unwrap());
            inputs.iter().position(|p| p == input)
        });
        log
    };
    let out = dir.join("plain");
    let output = run(&out, &[]);
    assert_eq!(output.status.code(), Some(REJECTED), "{}", stderr(&output));
    let stdout = String::from_utf8_lossy(&output.stdout).into_owned();
    assert!(
        stdout.contains("2 skinned, 0 failed, 0 up to date, 1 rejected"),
        "{stdout}"
    );
    assert!(
        stderr(&output).contains("rejected: ")
            && stderr(&output).contains("1168.glb: soft-joints: ")
    );
    let log = records(&out);
    let statuses: Vec<&str> = log.iter().map(|r| r["status"].as_str().unwrap()).collect();
    assert_eq!(statuses, ["ok", "rejected", "ok"]);
    assert!(log[1]["reasons"][0]
        .as_str()
        .unwrap()
        .starts_with("soft-joints: "));
    assert_eq!(log[1]["kept"], Value::Null);
    assert!(log[0]["reasons"].as_array().unwrap().is_empty());
    assert!(out.join("RiggedSimple.glb").is_file() && out.join("498.glb").is_file());
    assert!(!out.join("1168.glb").exists() && !out.join("1168.rejected.glb").exists());

    let again = run(&out, &["--resume".as_ref()]);
    assert_eq!(again.status.code(), Some(REJECTED));
    let statuses: Vec<String> = records(&out)
        .iter()
        .map(|r| r["status"].to_string())
        .collect();
    assert_eq!(statuses, ["\"skipped\"", "\"rejected\"", "\"skipped\""]);

    let kept = dir.join("kept");
    assert_eq!(
        run(&kept, &["--keep-rejected".as_ref()]).status.code(),
        Some(REJECTED)
    );
    let log = records(&kept);
    let kept_glb = kept.join("1168.rejected.glb");
    assert_eq!(log[1]["kept"], text(&kept_glb));
    assert!(kept_glb.is_file());

    let broken = dir.join("broken.glb");
    std::fs::write(&broken, b"not a glb").unwrap();
    let failed = atlas_skin(&[
        "batch".as_ref(),
        inputs[1].as_os_str(),
        broken.as_os_str(),
        "-o".as_ref(),
        dir.join("failed").as_os_str(),
        "--fail-on".as_ref(),
        "soft-joints".as_ref(),
    ]);
    assert_eq!(
        failed.status.code(),
        Some(1),
        "a failure outranks a rejection"
    );
}
