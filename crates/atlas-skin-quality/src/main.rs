//! `quality`: skins every corpus model that has reference weights with `atlas-skin skin`,
//! judges the result with `atlas-skin eval`, and writes docs/quality.md beside the other
//! tools' rows of `shared/data/BASELINES.md`. Run it through `scripts/quality`.

mod table;

use anyhow::{bail, Context, Result};
use atlas_skin_corpus::{Model, Reference, MODELS};
use atlas_skin_eval::Evaluation;
use atlas_skin_quality::{baselines, run};
use clap::Parser;
use std::path::{Path, PathBuf};
use std::time::Instant;
use table::Measured;

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
    let exe = run::atlas_skin_exe()?;
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

/// `atlas-skin skin MODEL -o CANDIDATE --report R`: returns the weight computation time
/// from the report and the wall time.
fn run_skin(
    exe: &Path,
    model: &Model,
    models_dir: &Path,
    candidate: &Path,
    work: &Path,
) -> Result<(Option<f64>, f64)> {
    let report = work.join(format!("{}.report.json", model.name));
    let run = run::run_skin(
        exe,
        &model.input_args_in(models_dir, false),
        candidate,
        &report,
    )?;
    Ok((run.weights_seconds, run.wall_seconds))
}

/// `atlas-skin eval MODEL CANDIDATE --json`.
fn run_eval(exe: &Path, model: &Model, models_dir: &Path, candidate: &Path) -> Result<Evaluation> {
    run::run_eval(
        exe,
        &model.input_args_in(models_dir, true),
        candidate,
        model.prune_reference,
        0,
        atlas_skin_eval::EvalOptions::default().seed,
        true,
    )
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
