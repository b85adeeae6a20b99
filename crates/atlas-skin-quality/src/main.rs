//! `quality`: skins every corpus model that has reference weights with `atlas-skin skin`,
//! judges the result with `atlas-skin eval`, and writes docs/quality.md beside the other
//! tools' rows of `shared/data/BASELINES.md`. Run it through `scripts/quality`.

mod baselines;
mod table;

use anyhow::{bail, Context, Result};
use atlas_skin_corpus::{Model, Reference, MODELS};
use atlas_skin_eval::Evaluation;
use clap::Parser;
use std::ffi::OsString;
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;
use table::Measured;

const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

/// Regenerates docs/quality.md from the corpus.
#[derive(Parser, Debug)]
#[command(name = "quality")]
struct Args {
    /// The corpus folder: models/ and BASELINES.md.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"))]
    data: PathBuf,
    /// The page to write.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../docs/quality.md"))]
    out: PathBuf,
    /// Folder for the skinned models and reports.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/quality"))]
    work: PathBuf,
    /// Judge the reference weights themselves (written out as a skinned glb) instead of
    /// `skin`'s: every figure must come out zero, which proves the machinery.
    #[arg(long)]
    self_check: bool,
    /// Only these models (folder names; the page then lists only them); all by default.
    #[arg(long = "model")]
    models: Vec<String>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let baselines_path = args.data.join("BASELINES.md");
    let baselines = baselines::parse_baselines(
        &std::fs::read_to_string(&baselines_path)
            .with_context(|| format!("cannot read {}", baselines_path.display()))?,
    )?;
    let exe = atlas_skin_exe()?;
    std::fs::create_dir_all(&args.work)
        .with_context(|| format!("cannot create {}", args.work.display()))?;
    let weighted = || MODELS.iter().filter(|m| m.reference != Reference::None);
    for name in &args.models {
        if !weighted().any(|m| m.name == name) {
            bail!("unknown model {name:?}");
        }
    }
    let models_dir = args.data.join("models");
    let mut measured = Vec::new();
    for model in
        weighted().filter(|m| args.models.is_empty() || args.models.iter().any(|n| n == m.name))
    {
        eprintln!("{}…", model.name);
        let candidate = args.work.join(format!("{}.glb", model.name));
        let (weights_seconds, pipeline_seconds) = if args.self_check {
            write_reference_weights(model, &models_dir, &candidate)?;
            (None, None)
        } else {
            let (weights, pipeline) = run_skin(&exe, model, &models_dir, &candidate, &args.work)?;
            (weights, Some(pipeline))
        };
        let start = Instant::now();
        let evaluation = run_eval(&exe, model, &models_dir, &candidate)?;
        measured.push(Measured {
            model: *model,
            evaluation,
            weights_seconds,
            pipeline_seconds,
            eval_seconds: start.elapsed().as_secs_f64(),
        });
    }
    let candidate = if args.self_check {
        "artist weights (self-check)"
    } else {
        "atlas-skin"
    };
    let page = table::render(&measured, &baselines, candidate);
    std::fs::write(&args.out, page)
        .with_context(|| format!("cannot write {}", args.out.display()))?;
    let written = args.out.canonicalize().unwrap_or(args.out);
    eprintln!("wrote {}", written.display());
    Ok(())
}

/// The `atlas-skin` binary built beside this one.
fn atlas_skin_exe() -> Result<PathBuf> {
    let exe = std::env::current_exe()?
        .with_file_name(format!("atlas-skin{}", std::env::consts::EXE_SUFFIX));
    if !exe.is_file() {
        bail!(
            "{} not found: build it first (cargo build --release -p atlas-skin-cli, or run \
             scripts/quality from {WORKSPACE})",
            exe.display()
        );
    }
    Ok(exe)
}

/// Runs `atlas-skin ARGS`, returning its standard output or an error with its stderr.
fn atlas_skin(exe: &Path, args: &[OsString]) -> Result<Vec<u8>> {
    let output = Command::new(exe)
        .args(args)
        .output()
        .with_context(|| format!("cannot run {}", exe.display()))?;
    if !output.status.success() {
        bail!(
            "atlas-skin {} failed: {}",
            args.iter()
                .map(|a| a.to_string_lossy())
                .collect::<Vec<_>>()
                .join(" "),
            String::from_utf8_lossy(&output.stderr).trim()
        );
    }
    Ok(output.stdout)
}

/// `atlas-skin skin MODEL -o CANDIDATE --report R`: returns the weight computation time
/// from the report (its stages but writing, when it has `timings_ms`) and the wall time.
fn run_skin(
    exe: &Path,
    model: &Model,
    models_dir: &Path,
    candidate: &Path,
    work: &Path,
) -> Result<(Option<f64>, f64)> {
    let report_path = work.join(format!("{}.report.json", model.name));
    let mut args: Vec<OsString> = vec!["skin".into()];
    args.extend(model.input_args_in(models_dir, false));
    args.extend([
        "-o".into(),
        candidate.into(),
        "--report".into(),
        report_path.clone().into(),
    ]);
    let start = Instant::now();
    atlas_skin(exe, &args)?;
    let wall = start.elapsed().as_secs_f64();
    let report: serde_json::Value = serde_json::from_slice(
        &std::fs::read(&report_path)
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
    Ok((weights_ms.map(|ms| ms / 1000.0), wall))
}

/// `atlas-skin eval MODEL CANDIDATE --json`.
fn run_eval(exe: &Path, model: &Model, models_dir: &Path, candidate: &Path) -> Result<Evaluation> {
    let mut args: Vec<OsString> = vec!["eval".into()];
    args.extend(model.input_args_in(models_dir, true));
    args.extend([candidate.into(), "--json".into()]);
    if let Some(n) = model.prune_reference {
        args.extend(["--prune-reference".into(), n.to_string().into()]);
    }
    let stdout = atlas_skin(exe, &args)?;
    serde_json::from_slice(&stdout).context("atlas-skin eval --json printed unexpected JSON")
}

/// Writes the model's own reference weights as a skinned glb (the self-check candidate),
/// keeping as many influences as the comparison does.
fn write_reference_weights(model: &Model, models_dir: &Path, out: &Path) -> Result<()> {
    let options = model.load_options_in(models_dir, true);
    let input = model.folder_in(models_dir).join(model.input);
    let character = atlas_skin_io::load_character(&input, &options)
        .with_context(|| format!("cannot load {}", input.display()))?;
    let weights = character
        .reference_weights
        .as_ref()
        .with_context(|| format!("{} has no reference weights", input.display()))?;
    let write_options = atlas_skin_io::gltf::WriteOptions {
        max_influences: model
            .prune_reference
            .map_or_else(|| weights.max_influences(), usize::from)
            .max(1),
        ..Default::default()
    };
    atlas_skin_io::gltf::write_skinned_glb(&character, weights, &write_options, out)
        .with_context(|| format!("cannot write {}", out.display()))
}
