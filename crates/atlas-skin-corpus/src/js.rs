//! The node checkers of `tests/js` (glTF-Validator, three.js, the browser viewer): small
//! scripts that take file arguments and print JSON, run from the workspace root.

use serde_json::Value;
use std::ffi::OsStr;
use std::path::Path;
use std::process::{Command, Output};

/// The workspace root, where `tests/js` is.
const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// Runs `node tests/js/SCRIPT ARGS...` from the workspace root; panics when the checkers'
/// node_modules or node itself is missing.
fn run_node<A: AsRef<OsStr>>(script: &str, args: &[A]) -> Output {
    let workspace = Path::new(WORKSPACE);
    assert!(
        workspace.join("tests/js/node_modules").is_dir(),
        "tests/js/node_modules is missing: run scripts/install-test-deps"
    );
    Command::new("node")
        .current_dir(workspace)
        .arg(Path::new("tests/js").join(script))
        .args(args)
        .output()
        .expect("cannot run node (install it with scripts/install-test-deps)")
}

/// Runs a checker that prints one JSON object per file of `files` (validate.mjs,
/// three_load.mjs) and returns them in order; panics unless there is one per file. The
/// exit status is not checked: the objects say what failed.
pub fn node_check<F: AsRef<OsStr>>(script: &str, files: &[F]) -> Vec<Value> {
    let output = run_node(script, files);
    let stdout = String::from_utf8_lossy(&output.stdout);
    let lines: Vec<Value> = stdout
        .lines()
        .map(|line| {
            serde_json::from_str(line)
                .unwrap_or_else(|e| panic!("{script}: not one JSON object per line ({e}): {line}"))
        })
        .collect();
    assert_eq!(
        lines.len(),
        files.len(),
        "{script}: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    lines
}

/// Runs a checker that prints one JSON document (three_pose.mjs, three_anim.mjs,
/// viewer.mjs) and returns it; panics unless the checker exits 0.
pub fn node_json<A: AsRef<OsStr>>(script: &str, args: &[A]) -> Value {
    let output = run_node(script, args);
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        output.status.success(),
        "{script} failed: {stdout}\n{}",
        String::from_utf8_lossy(&output.stderr)
    );
    serde_json::from_str(&stdout)
        .unwrap_or_else(|e| panic!("{script} did not print JSON ({e}): {stdout}"))
}
