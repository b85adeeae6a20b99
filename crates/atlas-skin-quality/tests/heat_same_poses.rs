//! `scripts/heat-same-poses`: Blender's bone heat (the `bpy` package in the venv
//! `scripts/install-test-deps` makes under target/bpy-venv) judged under the draws of a
//! benchmark run, through the released binaries (`benchmark` and, built by the workspace's
//! `cargo test`, `atlas-skin`).

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::Command;

/// The workspace's folder.
fn workspace() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// `scripts/heat-same-poses` on a benchmark run of two characters: Blender's bone heat
/// weighs one (and reproduces BASELINES.md's heat mean there) and fails on the other, as it
/// does in BASELINES.md; the page judges the first under every draw of the run.
#[test]
fn heat_same_poses_judges_bone_heat_under_the_runs_own_draws() {
    let dir = std::env::temp_dir().join(format!("heat-same-poses-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let python = workspace().join("target/bpy-venv/bin/python");
    assert!(
        python.is_file(),
        "{} is missing: run scripts/install-test-deps (tests never skip)",
        python.display()
    );
    let benchmark = Path::new(env!("CARGO_BIN_EXE_benchmark"));
    let run = dir.join("run.json");
    let output = Command::new(benchmark)
        .args(["--character", "rignet-val/8190.glb"])
        .args(["--character", "rignet-val/1168.glb"])
        .arg("--json")
        .arg(&run)
        .arg("--out")
        .arg(dir.join("benchmark.md"))
        .arg("--work")
        .arg(dir.join("benchmark"))
        .output()
        .unwrap();
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let script = workspace().join("scripts/heat-same-poses");
    let page = dir.join("page.md");
    let heat = |extra: &[&str]| {
        Command::new(&script)
            .arg("--benchmark")
            .arg(&run)
            .arg("--out")
            .arg(&page)
            .arg("--work")
            .arg(dir.join("heat"))
            .args(extra)
            .output()
            .unwrap()
    };
    let output = heat(&[]);
    assert!(
        output.status.success(),
        "{}",
        String::from_utf8_lossy(&output.stderr)
    );
    let text = std::fs::read_to_string(&page).unwrap();
    let seeds = [0, 10, 20, 30, 40];
    for seed in seeds {
        assert!(
            text.contains(&format!("| {seed} | 1 of 1 | ")),
            "no row for the draw from seed {seed}:\n{text}"
        );
    }
    assert!(
        text.contains("| rignet-val/1168.glb | failed | failed |"),
        "{text}"
    );
    let figures: Value =
        serde_json::from_str(&std::fs::read_to_string(dir.join("heat/heat.json")).unwrap())
            .unwrap();
    let scored = figures["characters"]
        .as_array()
        .unwrap()
        .iter()
        .find(|c| c["name"] == "rignet-val/8190.glb")
        .unwrap();
    for seed in seeds {
        let deform = &scored["heat"][seed.to_string()];
        let (mean, max) = (
            deform["mean"].as_f64().unwrap(),
            deform["max"].as_f64().unwrap(),
        );
        assert!(mean > 0.0 && max > mean, "seed {seed}: {deform}");
    }
    // BASELINES.md's heat row of 8190: deform mean .0026 under its own draw.
    let mean = scored["heat"]["0"]["mean"].as_f64().unwrap();
    assert!((mean / 0.0026 - 1.0).abs() < 0.25, "{mean}");
    // A character the run did not score is named, and the page is left as it was.
    let before = std::fs::read_to_string(&page).unwrap();
    let output = heat(&["--character", "rignet-val/426.glb"]);
    assert!(!output.status.success());
    let message = String::from_utf8_lossy(&output.stderr);
    assert!(message.contains("rignet-val/426.glb"), "{message}");
    assert_eq!(std::fs::read_to_string(&page).unwrap(), before);
    std::fs::remove_dir_all(&dir).unwrap();
}
