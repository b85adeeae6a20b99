//! `atlas-skin batch`: many characters at once (the batch itself:
//! [`atlas_skin_job::batch`]), with one progress bar, the failures printed as they come and
//! the totals at the end; the exit code is 1 when any file failed, else 3 when the quality
//! gate rejected any.

use crate::cmd::skin::MethodArgs;
use crate::quality_gate::{GateArgs, Rejected};
use anyhow::{bail, Result};
use atlas_skin_job::batch::{collect_inputs, plan_jobs, run_batch, BatchOptions, Record, Status};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::sync::atomic::AtomicBool;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    /// Character files (.glb, .gltf, .vrm, .fbx), folders (searched for such files, with
    /// their subfolders) and glob patterns (quoted: 'chars/*.fbx').
    #[arg(required = true, value_name = "INPUT")]
    pub inputs: Vec<PathBuf>,
    /// The output folder: each INPUT is written to OUTDIR/<name>.glb.
    #[arg(short, long = "out-dir", value_name = "OUTDIR")]
    pub out_dir: PathBuf,
    /// Files skinned at the same time [default: the number of cores].
    #[arg(short, long, value_name = "N",
          value_parser = crate::counts::count_between(1, atlas_skin_job::batch::MAX_JOBS))]
    pub jobs: Option<usize>,
    /// Skip the files whose outputs exist and are newer than the file (and --config).
    #[arg(long)]
    pub resume: bool,
    /// Also write each file's JSON report, OUTDIR/<name>.json.
    #[arg(long)]
    pub report: bool,
    /// Also write each file's HTML report, OUTDIR/<name>.html.
    #[arg(long)]
    pub html: bool,
    /// The JSON-lines log, one record per file [default: OUTDIR/atlas-skin-batch.jsonl].
    #[arg(long, value_name = "FILE.jsonl")]
    pub log: Option<PathBuf>,
    #[command(flatten)]
    pub method: MethodArgs,
    #[command(flatten)]
    pub gate: GateArgs,
}

pub fn run(args: Args) -> Result<()> {
    let options = BatchOptions {
        jobs: args
            .jobs
            .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get())),
        resume: args.resume,
        report: args.report,
        html: args.html,
        log: args.log,
        keep_rejected: args.gate.keep_rejected,
        settings: args.method.settings(&args.gate)?,
        out_dir: args.out_dir,
    };
    let inputs = collect_inputs(&args.inputs)?;
    let jobs = plan_jobs(&inputs, &options)?;
    let bar = progress_bar(jobs.len() as u64);
    let on_record = |record: &Record| {
        if record.status == Status::Failed {
            let message = record.error.as_deref().unwrap_or_default();
            bar.suspend(|| eprintln!("error: {message}"));
        }
        if record.status == Status::Rejected {
            let reasons = record.reasons.join("; ");
            bar.suspend(|| eprintln!("rejected: {}: {reasons}", record.input));
        }
        bar.inc(1);
    };
    let (_, summary) = run_batch(&jobs, &options, &on_record, &AtomicBool::new(false))?;
    bar.finish_and_clear();
    println!("{summary}");
    if summary.failed > 0 {
        bail!(
            "{} of {} files failed (see {})",
            summary.failed,
            summary.files,
            summary.log.display()
        );
    }
    if summary.rejected > 0 {
        return Err(Rejected(format!(
            "the quality gate rejected {} of {} files (see {})",
            summary.rejected,
            summary.files,
            summary.log.display()
        ))
        .into());
    }
    Ok(())
}

/// One bar for the batch on stderr, hidden when stderr is not a terminal.
fn progress_bar(files: u64) -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new(files);
    bar.set_style(
        ProgressStyle::with_template(
            "{elapsed} [{bar:30}] {pos}/{len} files, {per_sec}, eta {eta}",
        )
        .unwrap_or_else(|_| ProgressStyle::default_bar()),
    );
    bar
}
