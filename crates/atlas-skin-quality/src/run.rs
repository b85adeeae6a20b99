//! Running the released command-line path as a user does: `atlas-skin skin … --report` and
//! `atlas-skin eval REFERENCE CANDIDATE --json`, each as a process of the `atlas-skin`
//! binary built beside these tools.

use anyhow::{bail, Context, Result};
use atlas_skin_eval::Evaluation;
use std::ffi::OsString;
use std::io::Read;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::thread;
use std::time::{Duration, Instant};

/// Longest a single `atlas-skin` process may run before it is killed and reported as
/// failed (the slowest character of the corpus takes about a second).
pub const PROCESS_TIMEOUT: Duration = Duration::from_secs(600);

/// The `atlas-skin` binary built beside the running tool.
pub fn atlas_skin_exe() -> Result<PathBuf> {
    let exe = std::env::current_exe()?
        .with_file_name(format!("atlas-skin{}", std::env::consts::EXE_SUFFIX));
    if !exe.is_file() {
        bail!(
            "{} not found: build it first (cargo build --release -p atlas-skin-cli, or run \
             scripts/quality or scripts/benchmark)",
            exe.display()
        );
    }
    Ok(exe)
}

/// Runs `program ARGS`, returning its standard output; an error carries its standard error
/// when it exits unsuccessfully, and says so when it runs longer than `timeout` (it is
/// killed then).
pub fn run_process(program: &Path, args: &[OsString], timeout: Duration) -> Result<Vec<u8>> {
    let command_line = || {
        let name = program
            .file_name()
            .map_or_else(|| program.to_string_lossy(), |n| n.to_string_lossy());
        std::iter::once(name)
            .chain(args.iter().map(|a| a.to_string_lossy()))
            .collect::<Vec<_>>()
            .join(" ")
    };
    let mut child = Command::new(program)
        .args(args)
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .with_context(|| format!("cannot run {}", program.display()))?;
    // Both pipes are drained by threads while this one waits, so a chatty child never
    // blocks on a full pipe.
    let drain = |pipe: Option<Box<dyn Read + Send>>| {
        thread::spawn(move || {
            let mut bytes = Vec::new();
            if let Some(mut pipe) = pipe {
                let _ = pipe.read_to_end(&mut bytes);
            }
            bytes
        })
    };
    let stdout = drain(
        child
            .stdout
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let stderr = drain(
        child
            .stderr
            .take()
            .map(|p| Box::new(p) as Box<dyn Read + Send>),
    );
    let start = Instant::now();
    let status = loop {
        if let Some(status) = child.try_wait()? {
            break status;
        }
        if start.elapsed() > timeout {
            let _ = child.kill();
            let _ = child.wait();
            bail!(
                "{} did not finish within {} s (killed)",
                command_line(),
                timeout.as_secs_f64()
            );
        }
        thread::sleep(Duration::from_millis(5));
    };
    let stdout = stdout.join().unwrap_or_default();
    let stderr = stderr.join().unwrap_or_default();
    if !status.success() {
        bail!(
            "{} failed ({status}): {}",
            command_line(),
            String::from_utf8_lossy(&stderr).trim()
        );
    }
    Ok(stdout)
}

/// What `atlas-skin skin … --report R` gave.
#[derive(Debug, Clone)]
pub struct SkinRun {
    /// The JSON report.
    pub report: serde_json::Value,
    /// Weight computation in seconds: the report's stages but writing (`timings_ms`).
    pub weights_seconds: Option<f64>,
    /// Wall time of the whole command (reading, weights, writing).
    pub wall_seconds: f64,
}

/// `atlas-skin skin INPUT_ARGS -o CANDIDATE --report REPORT`.
pub fn run_skin(
    exe: &Path,
    input_args: &[OsString],
    candidate: &Path,
    report_path: &Path,
) -> Result<SkinRun> {
    let mut args: Vec<OsString> = vec!["skin".into()];
    args.extend_from_slice(input_args);
    args.extend([
        "-o".into(),
        candidate.into(),
        "--report".into(),
        report_path.into(),
    ]);
    let start = Instant::now();
    run_process(exe, &args, PROCESS_TIMEOUT)?;
    let wall_seconds = start.elapsed().as_secs_f64();
    let report: serde_json::Value = serde_json::from_slice(
        &std::fs::read(report_path)
            .with_context(|| format!("cannot read {}", report_path.display()))?,
    )
    .with_context(|| format!("{} is not JSON", report_path.display()))?;
    let weights_ms = report["timings_ms"].as_object().map(|stages| {
        stages
            .iter()
            .filter(|(stage, _)| stage.as_str() != "write")
            .filter_map(|(_, ms)| ms.as_f64())
            .sum::<f64>()
    });
    Ok(SkinRun {
        report,
        weights_seconds: weights_ms.map(|ms| ms / 1000.0),
        wall_seconds,
    })
}

/// `atlas-skin eval REFERENCE_ARGS CANDIDATE --json --worst WORST --seed FIRST_SEED
/// [--prune-reference N] [--anim-frames 0]`, with `eval`'s other default settings (those of
/// BASELINES.md: 10 random poses, from seed 0 there, up to 60° per joint, LBS and DQS, 8
/// animation frames unless `animation` is false: the animation's figures do not depend on
/// the seed).
pub fn run_eval(
    exe: &Path,
    reference_args: &[OsString],
    candidate: &Path,
    prune_reference: Option<u16>,
    worst: usize,
    first_seed: u64,
    animation: bool,
) -> Result<Evaluation> {
    let mut args: Vec<OsString> = vec!["eval".into()];
    args.extend_from_slice(reference_args);
    args.extend([
        candidate.into(),
        "--json".into(),
        "--worst".into(),
        worst.to_string().into(),
        "--seed".into(),
        first_seed.to_string().into(),
    ]);
    if let Some(n) = prune_reference {
        args.extend(["--prune-reference".into(), n.to_string().into()]);
    }
    if !animation {
        args.extend(["--anim-frames".into(), "0".into()]);
    }
    let stdout = run_process(exe, &args, PROCESS_TIMEOUT)?;
    serde_json::from_slice(&stdout).context("atlas-skin eval --json printed unexpected JSON")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sh(script: &str, timeout: Duration) -> Result<Vec<u8>> {
        run_process(Path::new("/bin/sh"), &["-c".into(), script.into()], timeout)
    }

    #[test]
    fn output_and_failures_are_reported() {
        let long = Duration::from_secs(30);
        assert_eq!(sh("echo hello", long).unwrap(), b"hello\n");
        let error = sh("echo broken >&2; exit 3", long).unwrap_err().to_string();
        assert!(
            error.contains("failed") && error.contains("broken"),
            "{error}"
        );
        // More than a pipe's buffer on both streams must not block.
        let big = sh(
            "head -c 300000 /dev/zero; head -c 300000 /dev/zero >&2",
            long,
        )
        .unwrap();
        assert_eq!(big.len(), 300_000);
    }

    #[test]
    fn a_process_that_runs_too_long_is_killed() {
        let start = Instant::now();
        let error = sh("sleep 20", Duration::from_millis(200))
            .unwrap_err()
            .to_string();
        assert!(error.contains("did not finish"), "{error}");
        assert!(start.elapsed() < Duration::from_secs(10));
    }
}
