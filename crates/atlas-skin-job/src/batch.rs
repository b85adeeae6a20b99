//! Many characters at once (`atlas-skin batch`, `atlas_skin.batch`): the inputs (files,
//! folders searched for character files, glob patterns) each skinned by a [`SkinJob`] to
//! `OUTDIR/<name>.glb` (with `<name>.json` and `<name>.html` when asked), several at a time
//! on a pool of threads. A failing file is recorded and the others go on; `resume` removes
//! the temporary files a killed run left beside the outputs and skips
//! the files whose outputs exist and are newer than the file (and the settings file).
//! Every finished file appends one JSON record to the log (flushed at once, so a killed
//! batch keeps the records of what it finished); the outputs themselves are written as
//! `skin` writes them, complete or not at all. With a quality gate (the settings'
//! `fail_on`), a file the gate refuses is recorded as [`Status::Rejected`] with the
//! reasons, its outputs kept under their rejected names or not written
//! ([`crate::job`]).

use crate::job::{error_chain, Input, Outputs, SkinJob};
use crate::settings::Settings;
use atlas_skin_io::{IoError, OutputPlan};
use serde::Serialize;
use serde_json::Value;
use std::collections::HashMap;
use std::io::Write;
use std::path::{Path, PathBuf};
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::{Instant, SystemTime};
use thiserror::Error;

/// Extensions of the files taken from a folder: the formats that carry a skeleton.
pub const CHARACTER_EXTENSIONS: [&str; 4] = ["glb", "gltf", "vrm", "fbx"];

/// Most files skinned at the same time.
pub const MAX_JOBS: usize = 256;

/// The log's name in the output folder when none is given.
pub const DEFAULT_LOG_NAME: &str = "atlas-skin-batch.jsonl";

/// Why a batch could not start (a file that fails is a [`Record`], not an error).
#[derive(Debug, Error)]
pub enum BatchError {
    #[error("no input given")]
    NoInputs,
    #[error("{pattern}: not a valid glob pattern")]
    Pattern {
        pattern: String,
        #[source]
        source: glob::PatternError,
    },
    #[error("{pattern}: matches no file")]
    NoMatch { pattern: String },
    #[error("{}: cannot list the folder", path.display())]
    Folder {
        path: PathBuf,
        #[source]
        source: std::io::Error,
    },
    #[error("{}: holds no character file (.glb, .gltf, .vrm, .fbx)", path.display())]
    EmptyFolder { path: PathBuf },
    #[error("{} and {} would both be written to {}: rename one", first.display(), second.display(), output.display())]
    NameClash {
        first: PathBuf,
        second: PathBuf,
        output: PathBuf,
    },
    #[error(transparent)]
    Log(#[from] IoError),
    #[error("jobs {jobs} is outside 1..={MAX_JOBS}")]
    Jobs { jobs: usize },
    #[error("cannot start {jobs} threads")]
    Threads {
        jobs: usize,
        #[source]
        source: rayon::ThreadPoolBuildError,
    },
}

/// How to run a batch.
#[derive(Debug, Clone, Default)]
pub struct BatchOptions {
    /// Where `<name>.glb` (and `.json`, `.html`) go; created when missing.
    pub out_dir: PathBuf,
    /// Files skinned at the same time, `1..=`[`MAX_JOBS`].
    pub jobs: usize,
    /// Skip the files whose outputs exist and are newer than the file and the settings.
    pub resume: bool,
    /// Also write each file's JSON report, `<name>.json`.
    pub report: bool,
    /// Also write each file's HTML report, `<name>.html`.
    pub html: bool,
    /// The JSON-lines log; `None`: [`DEFAULT_LOG_NAME`] in `out_dir`.
    pub log: Option<PathBuf>,
    /// Write the outputs of the files the quality gate rejects, under their rejected
    /// names ([`crate::quality::rejected_name`]: `<name>.rejected.glb`).
    pub keep_rejected: bool,
    /// The method's settings, the same for every file.
    pub settings: Settings,
}

impl BatchOptions {
    /// The log's path.
    pub fn log_path(&self) -> PathBuf {
        self.log
            .clone()
            .unwrap_or_else(|| self.out_dir.join(DEFAULT_LOG_NAME))
    }
}

/// What happened to one file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Status {
    /// Skinned and written.
    Ok,
    /// Not written: see the record's error.
    Failed,
    /// Its outputs were up to date (`resume`).
    Skipped,
    /// Not started: the batch was stopped (see [`run_batch`]'s `stop`).
    Cancelled,
    /// Skinned, and refused by the quality gate: see the record's reasons.
    Rejected,
}

/// One line of the log.
#[derive(Debug, Clone, Serialize)]
pub struct Record {
    /// The input's path, as given (not valid UTF-8: lossily converted).
    pub input: String,
    /// The skinned glb (written, or the one that was up to date).
    pub output: String,
    pub status: Status,
    /// The message `skin` would print, for a failed file.
    pub error: Option<String>,
    /// Why the quality gate rejected the file (empty otherwise).
    pub reasons: Vec<String>,
    /// The skinned glb of a rejected file, kept under its rejected name.
    pub kept: Option<String>,
    /// Wall time of the whole job (reading, skinning, writing), in seconds.
    pub seconds: f64,
    /// The report's `timings_ms` (stages and writing), for a skinned file.
    pub timings_ms: Option<Value>,
    /// The report's `counts`, for a skinned file.
    pub counts: Option<Value>,
    /// The report's warnings (the reader's and the method's), for a skinned file.
    pub warnings: Vec<String>,
}

/// The totals of a batch.
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    pub files: usize,
    pub ok: usize,
    pub failed: usize,
    pub skipped: usize,
    pub cancelled: usize,
    pub rejected: usize,
    /// Wall time of the batch, in seconds.
    pub seconds: f64,
    /// Skinned files per second of wall time.
    pub characters_per_second: f64,
    pub log: PathBuf,
}

impl std::fmt::Display for Summary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        if self.ok == 0 && self.failed == 0 && self.cancelled == 0 && self.rejected == 0 {
            return write!(
                f,
                "nothing to do: the outputs of all {} files are up to date",
                self.files
            );
        }
        let cancelled = match self.cancelled {
            0 => String::new(),
            n => format!(", {n} cancelled"),
        };
        let rejected = match self.rejected {
            0 => String::new(),
            n => format!(", {n} rejected"),
        };
        write!(
            f,
            "{} file{}: {} skinned, {} failed, {} up to date{cancelled}{rejected}, in {:.1} s ({:.2} characters/s); log: {}",
            self.files,
            if self.files == 1 { "" } else { "s" },
            self.ok,
            self.failed,
            self.skipped,
            self.seconds,
            self.characters_per_second,
            self.log.display()
        )
    }
}

/// The files named by `args`, in order, each once: a folder gives its character files
/// ([`CHARACTER_EXTENSIONS`], searched recursively, sorted); an argument that does not
/// exist and holds `*`, `?` or `[` is a glob pattern (its matches, sorted); anything else
/// is taken as a file (a missing one fails in its turn).
pub fn collect_inputs(args: &[PathBuf]) -> Result<Vec<PathBuf>, BatchError> {
    if args.is_empty() {
        return Err(BatchError::NoInputs);
    }
    let mut files = Vec::new();
    for arg in args {
        let text = arg.to_string_lossy();
        if arg.is_dir() {
            let before = files.len();
            character_files(arg, &mut files)?;
            if files.len() == before {
                return Err(BatchError::EmptyFolder { path: arg.clone() });
            }
            files[before..].sort();
        } else if !arg.exists() && text.contains(['*', '?', '[']) {
            let pattern = |source| BatchError::Pattern {
                pattern: text.to_string(),
                source,
            };
            let mut matches: Vec<PathBuf> = glob::glob(&text)
                .map_err(pattern)?
                .filter_map(Result::ok)
                .filter(|p| p.is_file())
                .collect();
            if matches.is_empty() {
                return Err(BatchError::NoMatch {
                    pattern: text.to_string(),
                });
            }
            matches.sort();
            files.extend(matches);
        } else {
            files.push(arg.clone());
        }
    }
    let mut seen = std::collections::HashSet::new();
    files.retain(|f| seen.insert(f.canonicalize().unwrap_or_else(|_| f.clone())));
    Ok(files)
}

/// Appends the character files under `folder` (recursively) to `files`.
fn character_files(folder: &Path, files: &mut Vec<PathBuf>) -> Result<(), BatchError> {
    let error = |source| BatchError::Folder {
        path: folder.to_path_buf(),
        source,
    };
    for entry in std::fs::read_dir(folder).map_err(error)? {
        let path = entry.map_err(error)?.path();
        if path.is_dir() {
            character_files(&path, files)?;
        } else if is_character_file(&path) {
            files.push(path);
        }
    }
    Ok(())
}

fn is_character_file(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| CHARACTER_EXTENSIONS.contains(&e.to_ascii_lowercase().as_str()))
}

/// One job per input, writing `OUTDIR/<file stem>.glb` (and `.json`, `.html`); two inputs
/// with the same stem are refused before any work.
pub fn plan_jobs(inputs: &[PathBuf], options: &BatchOptions) -> Result<Vec<SkinJob>, BatchError> {
    let mut by_output: HashMap<PathBuf, &PathBuf> = HashMap::new();
    let mut jobs = Vec::new();
    for input in inputs {
        let stem = input.file_stem().unwrap_or(input.as_os_str());
        let output = |extension: &str| {
            let mut name = stem.to_os_string();
            name.push(".");
            name.push(extension);
            options.out_dir.join(name)
        };
        let glb = output("glb");
        if let Some(first) = by_output.insert(glb.clone(), input) {
            return Err(BatchError::NameClash {
                first: first.clone(),
                second: input.clone(),
                output: glb,
            });
        }
        jobs.push(SkinJob {
            input: Input::file(input),
            settings: options.settings.clone(),
            outputs: Outputs {
                report: options.report.then(|| output("json")),
                html: options.html.then(|| output("html")),
                ..Outputs::glb(glb)
            },
            // The log's timings, counts and warnings come from the report.
            keep_report: true,
            keep_rejected: options.keep_rejected,
        });
    }
    Ok(jobs)
}

/// True when every output of `job` exists and is at least as new as every file it reads.
fn up_to_date(job: &SkinJob) -> bool {
    let modified = |path: &Path| std::fs::metadata(path).and_then(|m| m.modified()).ok();
    let newest_input = job
        .input
        .paths()
        .chain(job.settings.paths())
        .map(modified)
        .try_fold(SystemTime::UNIX_EPOCH, |newest, time| {
            time.map(|t| newest.max(t))
        });
    let oldest_output = job
        .outputs
        .paths()
        .map(modified)
        .try_fold(None::<SystemTime>, |oldest, time| {
            time.map(|t| Some(oldest.map_or(t, |o| o.min(t))))
        });
    matches!((newest_input, oldest_output), (Some(i), Some(Some(o))) if o >= i)
}

/// Runs `job` (unless `stop` is set) and describes what happened.
fn run_one(job: &SkinJob, resume: bool, stop: &AtomicBool) -> Record {
    let start = Instant::now();
    let mut record = Record {
        input: job
            .input
            .path
            .as_deref()
            .unwrap_or(Path::new(""))
            .to_string_lossy()
            .into_owned(),
        output: job.outputs.glb.to_string_lossy().into_owned(),
        status: Status::Skipped,
        error: None,
        reasons: Vec::new(),
        kept: None,
        seconds: 0.0,
        timings_ms: None,
        counts: None,
        warnings: Vec::new(),
    };
    if stop.load(Ordering::Relaxed) {
        record.status = Status::Cancelled;
        return record;
    }
    if resume {
        // Files a killed run was writing when it stopped (under either name).
        let outputs = &job.outputs;
        outputs
            .paths()
            .chain(outputs.rejected_names().paths())
            .for_each(|out| {
                atlas_skin_io::remove_leftover_temporaries(out);
            });
        if up_to_date(job) {
            return record;
        }
    }
    match job.run(&mut |_| {}) {
        Ok(outcome) => {
            let mut report = outcome.report.unwrap_or_default();
            record.status = if outcome.verdict.rejected() {
                Status::Rejected
            } else {
                Status::Ok
            };
            record.reasons = outcome.verdict.reasons;
            record.kept = outcome.kept.map(|p| p.to_string_lossy().into_owned());
            record.timings_ms = Some(report["timings_ms"].take());
            record.counts = Some(report["counts"].take());
            record.warnings = serde_json::from_value(report["warnings"].take()).unwrap_or_default();
        }
        Err(error) => {
            record.status = Status::Failed;
            record.error = Some(error_chain(&error));
        }
    }
    record.seconds = start.elapsed().as_secs_f64();
    record
}

/// Runs the batch: `jobs` ([`plan_jobs`]) on `options.jobs` threads; `on_record` is called
/// with each record as its file finishes (from the worker threads), after the record is in
/// the log. Once `stop` is set (by `on_record` or another thread), the files not yet
/// started are not run: each is logged as [`Status::Cancelled`]; those running finish.
/// Returns every record, in the order of `jobs`, and the totals.
pub fn run_batch(
    jobs: &[SkinJob],
    options: &BatchOptions,
    on_record: &(dyn Fn(&Record) + Sync),
    stop: &AtomicBool,
) -> Result<(Vec<Record>, Summary), BatchError> {
    let start = Instant::now();
    if !(1..=MAX_JOBS).contains(&options.jobs) {
        return Err(BatchError::Jobs { jobs: options.jobs });
    }
    let log_path = options.log_path();
    let inputs: Vec<&Path> = jobs
        .iter()
        .flat_map(|job| job.input.paths().chain(job.settings.paths()))
        .collect();
    let outputs: Vec<&Path> = jobs.iter().flat_map(|job| job.outputs.paths()).collect();
    // The log is neither an input nor another output, nor a folder or device.
    OutputPlan::new(inputs, outputs.into_iter().chain([log_path.as_path()]))?;
    let log_error = |cause| IoError::Write {
        path: log_path.clone(),
        cause,
    };
    if let Some(folder) = log_path.parent().filter(|p| !p.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(log_error)?;
    }
    let log = Mutex::new(std::fs::File::create(&log_path).map_err(log_error)?);
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(options.jobs)
        .build()
        .map_err(|source| BatchError::Threads {
            jobs: options.jobs,
            source,
        })?;
    let records: Vec<Result<Record, IoError>> = pool.install(|| {
        use rayon::prelude::*;
        jobs.par_iter()
            .with_max_len(1)
            .map(|job| {
                let record = run_one(job, options.resume, stop);
                let mut line = serde_json::to_vec(&record).map_err(|e| log_error(e.into()))?;
                line.push(b'\n');
                let mut file = log.lock().unwrap_or_else(|e| e.into_inner());
                file.write_all(&line)
                    .and_then(|()| file.flush())
                    .map_err(log_error)?;
                drop(file);
                on_record(&record);
                Ok(record)
            })
            .collect()
    });
    let records = records.into_iter().collect::<Result<Vec<_>, _>>()?;
    let count = |status| records.iter().filter(|r| r.status == status).count();
    let seconds = start.elapsed().as_secs_f64();
    let summary = Summary {
        files: records.len(),
        ok: count(Status::Ok),
        failed: count(Status::Failed),
        skipped: count(Status::Skipped),
        cancelled: count(Status::Cancelled),
        rejected: count(Status::Rejected),
        seconds,
        characters_per_second: count(Status::Ok) as f64 / seconds.max(1e-9),
        log: log_path,
    };
    Ok((records, summary))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A fresh folder under the system's temporary folder.
    fn scratch(name: &str) -> PathBuf {
        let dir =
            std::env::temp_dir().join(format!("atlas-skin-job-{name}-{}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(dir.join("sub")).unwrap();
        dir
    }

    #[test]
    fn folders_give_their_character_files_sorted_and_each_file_once() {
        let dir = scratch("collect");
        for name in ["b.glb", "a.FBX", "sub/c.vrm", "notes.txt", "mesh.obj"] {
            std::fs::write(dir.join(name), b"").unwrap();
        }
        let files = collect_inputs(&[dir.clone(), dir.join("b.glb")]).unwrap();
        let names: Vec<PathBuf> = files
            .iter()
            .map(|f| f.strip_prefix(&dir).unwrap().to_path_buf())
            .collect();
        assert_eq!(names, ["a.FBX", "b.glb", "sub/c.vrm"].map(PathBuf::from));
        let pattern = dir.join("*.glb");
        assert_eq!(collect_inputs(&[pattern]).unwrap(), [dir.join("b.glb")]);
        let missing = dir.join("missing.glb");
        assert_eq!(
            collect_inputs(std::slice::from_ref(&missing)).unwrap(),
            [missing]
        );
        assert!(matches!(
            collect_inputs(&[dir.join("*.fbx")]),
            Err(BatchError::NoMatch { .. })
        ));
        assert!(matches!(collect_inputs(&[]), Err(BatchError::NoInputs)));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn outputs_are_named_after_the_inputs_and_clashes_refused() {
        let options = BatchOptions {
            out_dir: PathBuf::from("out"),
            jobs: 1,
            report: true,
            ..BatchOptions::default()
        };
        let jobs = plan_jobs(&[PathBuf::from("a/knight.fbx")], &options).unwrap();
        assert_eq!(jobs[0].outputs.glb, Path::new("out/knight.glb"));
        assert_eq!(
            jobs[0].outputs.report.as_deref(),
            Some(Path::new("out/knight.json"))
        );
        assert_eq!(jobs[0].outputs.html, None);
        let clash = plan_jobs(
            &[PathBuf::from("a/knight.fbx"), PathBuf::from("b/knight.glb")],
            &options,
        );
        assert!(matches!(clash, Err(BatchError::NameClash { .. })));
    }
}
