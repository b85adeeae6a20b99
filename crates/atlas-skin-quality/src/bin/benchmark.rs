//! `benchmark`: skins every character of `shared/data/bench` and of the clean corpus with
//! `atlas-skin skin --report`, judges each with `atlas-skin eval --json` against the artist
//! weights in its file, in parallel, and writes docs/benchmark.md (the aggregate table of
//! bench/BASELINES.md with atlas-skin's row, the goal lines of issues 12 and 13 under each
//! draw of poses, the worst vertices on far bones, every character) and the whole result
//! as JSON. `--compare OLD.json` prints what changed
//! against an earlier run. Run it through `scripts/benchmark`.

use anyhow::{bail, Context, Result};
use atlas_skin_quality::bench_characters::{
    bench_characters, large_characters, model_characters, Group, Set,
};
use atlas_skin_quality::bench_run::{run_all, BenchmarkRun, Outcome, Settings, OTHER_SEEDS};
use atlas_skin_quality::{
    baselines, bench_baselines, bench_compare, bench_page, group_scores, run,
};
use clap::{Parser, ValueEnum};
use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

const WORKSPACE: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SetArg {
    /// ../shared/data/bench: 65 game characters, against bench/BASELINES.md (tune).
    Bench,
    /// ../shared/data/bench-large/rignet-train: 400 characters to tune on.
    Train,
    /// ../shared/data/bench-large/rignet-check: 210 characters to confirm on.
    Check,
    /// ../shared/data/models: the clean corpus, against BASELINES.md.
    Models,
}

/// Skins and judges the benchmark characters and the corpus; writes docs/benchmark.md.
#[derive(Parser, Debug)]
#[command(name = "benchmark")]
struct Args {
    /// The data folder: bench/ (with its BASELINES.md), models/ and BASELINES.md.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"))]
    data: PathBuf,
    /// Characters run at once (each runs `skin` then `eval`); default: the number of cores.
    #[arg(long)]
    jobs: Option<usize>,
    /// Only these sets (repeatable); both by default.
    #[arg(long = "set", value_enum)]
    sets: Vec<SetArg>,
    /// Only these characters (repeatable): a bench name such as `rignet-val/426.glb` or a
    /// corpus model such as `cesiumman`.
    #[arg(long = "character")]
    characters: Vec<String>,
    /// The page to write; default docs/benchmark.md for a full run, target/benchmark/
    /// benchmark.md when --set or --character restrict it (the committed page stays whole).
    #[arg(long)]
    out: Option<PathBuf>,
    /// The whole result as JSON (the input of a later --compare).
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/benchmark/benchmark.json"))]
    json: PathBuf,
    /// Folder for the skinned characters and their reports.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/benchmark"))]
    work: PathBuf,
    /// An earlier run's JSON: print which characters got better or worse on mean and max,
    /// and the change of the aggregates.
    #[arg(long)]
    compare: Option<PathBuf>,
    /// Settings for every `skin` run (`atlas-skin skin --config FILE.json`), to measure
    /// other settings than the defaults on the whole benchmark. A run with it writes its
    /// page under target/benchmark/ unless --out says otherwise.
    #[arg(long, value_name = "FILE.json")]
    skin_config: Option<PathBuf>,
    /// The seed of `eval`'s first random pose (pose i uses SEED + i); default BASELINES.md's
    /// 0. The maxima of 10 poses move with the seed: another seed measures how much. A run
    /// with another writes its page under target/benchmark/ unless --out says otherwise.
    #[arg(long, default_value_t = Settings::of_eval().first_seed)]
    seed: u64,
    /// The first seeds of other pose sets, comma-separated: each character's deform error is measured again
    /// under each, and the page counts issue 13's goals for each (how much of a count is
    /// the draw of the poses). A run with others than the default writes its page under
    /// target/benchmark/ unless --out says otherwise.
    #[arg(long, value_delimiter = ',', default_values_t = OTHER_SEEDS)]
    other_seeds: Vec<u64>,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let old = args.compare.as_deref().map(read_run).transpose()?;
    let bench_table =
        bench_baselines::parse_bench_baselines(&read(&args.data.join("bench/BASELINES.md"))?)?;
    let models_table = baselines::table(&baselines::parse_baselines(&read(
        &args.data.join("BASELINES.md"),
    )?)?)?;

    let wanted = |set: SetArg| args.sets.is_empty() || args.sets.contains(&set);
    let mut characters = Vec::new();
    if wanted(SetArg::Bench) {
        characters.extend(bench_characters(&args.data.join("bench"))?);
    }
    for (arg, set) in [(SetArg::Train, Set::Train), (SetArg::Check, Set::Check)] {
        if wanted(arg) {
            characters.extend(large_characters(&args.data, set)?);
        }
    }
    if wanted(SetArg::Models) {
        characters.extend(model_characters(&args.data.join("models")));
    }
    for name in &args.characters {
        if !characters.iter().any(|c| &c.name == name) {
            bail!("unknown character {name:?} (names as in docs/benchmark.md)");
        }
    }
    if !args.characters.is_empty() {
        characters.retain(|c| args.characters.contains(&c.name));
    }

    if let Some(config) = &args.skin_config {
        let config = std::fs::canonicalize(config)
            .with_context(|| format!("cannot read the settings file {}", config.display()))?;
        for character in &mut characters {
            character.skin_args.push("--config".into());
            character.skin_args.push(config.clone().into_os_string());
        }
    }
    let exe = run::atlas_skin_exe()?;
    let jobs = args
        .jobs
        .unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    if jobs == 0 {
        bail!("--jobs must be at least 1");
    }
    eprintln!("{} characters on {jobs} jobs…", characters.len());
    let start = Instant::now();
    let load_at_start = load_average();
    let settings = Settings::of_eval_from(args.seed, &args.other_seeds);
    let results = run_all(
        &exe,
        &characters,
        &args.work,
        jobs,
        &settings,
        &|r| match &r.outcome {
            Outcome::Scored(s) => eprintln!(
                "  {:<40} mean {:.4}  max {:.3}",
                r.name, s.evaluation.deform_random.mean, s.evaluation.deform_random.max
            ),
            Outcome::Failed { stage, reason } => {
                eprintln!("  {:<40} FAILED ({stage}): {reason}", r.name)
            }
        },
    )?;
    let run = BenchmarkRun {
        commit: commit(),
        settings,
        jobs,
        wall_seconds: start.elapsed().as_secs_f64(),
        load_average: load_at_start.zip(load_average()),
        characters: results,
    };

    write(&args.json, &serde_json::to_string_pretty(&run)?)?;
    let page = bench_page::render(&run, &bench_table, &models_table, true);
    let whole = args.sets.is_empty()
        && args.characters.is_empty()
        && args.skin_config.is_none()
        && run.settings == Settings::of_eval();
    let out = args.out.clone().unwrap_or_else(|| {
        if whole {
            Path::new(WORKSPACE).join("docs/benchmark.md")
        } else {
            args.work.join("benchmark.md")
        }
    });
    write(&out, &page)?;
    // The page without its per-character tables, on the terminal.
    println!(
        "{}",
        bench_page::render(&run, &bench_table, &models_table, false)
    );
    let groups_now: Vec<_> = Group::ALL
        .iter()
        .filter_map(|&g| group_scores::group_scores(&run, g))
        .collect();
    for g in &groups_now {
        println!("{}", group_scores::summary_line(g));
    }
    if let Some(old) = &old {
        println!("before ({}):", old.commit);
        for g in Group::ALL
            .iter()
            .filter_map(|&g| group_scores::group_scores(old, g))
        {
            println!("{}", group_scores::summary_line(&g));
        }
    }
    if let (Some(old), Some(path)) = (&old, &args.compare) {
        println!(
            "{}",
            bench_compare::render(
                old,
                &run,
                &[(Set::Bench, &bench_table), (Set::Models, &models_table)],
                &path.display().to_string()
            )
        );
    }
    eprintln!(
        "wrote {} and {} ({:.1} s)",
        out.display(),
        args.json.display(),
        run.wall_seconds
    );
    Ok(())
}

fn read(path: &Path) -> Result<String> {
    std::fs::read_to_string(path).with_context(|| format!("cannot read {}", path.display()))
}

fn read_run(path: &Path) -> Result<BenchmarkRun> {
    serde_json::from_str(&read(path)?)
        .with_context(|| format!("{} is not a benchmark.json of this tool", path.display()))
}

/// Writes through a temporary file renamed into place: never a partial page or JSON.
fn write(path: &Path, text: &str) -> Result<()> {
    if let Some(folder) = path.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder)
            .with_context(|| format!("cannot create {}", folder.display()))?;
    }
    let temporary = path.with_extension("partial");
    std::fs::write(&temporary, text)
        .with_context(|| format!("cannot write {}", temporary.display()))?;
    std::fs::rename(&temporary, path).with_context(|| format!("cannot write {}", path.display()))
}

/// The commit measured, with `+changes` when files other than the generated page differ
/// from it; `unknown` outside a git checkout.
fn commit() -> String {
    let git = |args: &[&str]| {
        Command::new("git")
            .current_dir(WORKSPACE)
            .args(args)
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short", "HEAD"]) {
        None => "unknown".into(),
        Some(head) => match git(&["status", "--porcelain", "--", ".", ":!docs/benchmark.md"]) {
            Some(changes) if changes.is_empty() => head,
            _ => format!("{head}+changes"),
        },
    }
}

/// The 1-minute load average of /proc/loadavg; `None` where there is none.
fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg")
        .ok()?
        .split_whitespace()
        .next()?
        .parse()
        .ok()
}
