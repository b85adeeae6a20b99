//! `rigid-binding`: the characters their artists bound rigidly (the `rigid_binding` flag
//! of each folder's manifest.json), each skinned by `atlas-skin skin` with the default
//! binding and with `--binding rigid` and judged by `atlas-skin eval --json` against its
//! artist weights ([`atlas_skin_quality::rigid_binding`]); prints one markdown table per
//! set: **tune** (`bench/rignet-val` and `bench-large/rignet-train`) and **check**
//! (`bench-large/rignet-check`, to confirm on, never to choose by). Run it through
//! `scripts/rigid-binding`.

use anyhow::{bail, Context, Result};
use atlas_skin_quality::bench_characters::{bench_characters, Character};
use atlas_skin_quality::rigid_binding::{judge_both_ways, table, BothWays};
use atlas_skin_quality::run;
use clap::{Parser, ValueEnum};
use rayon::prelude::*;
use std::path::{Path, PathBuf};

#[derive(Debug, Clone, Copy, PartialEq, Eq, ValueEnum)]
enum SetArg {
    /// The rigid characters of bench/rignet-val and bench-large/rignet-train.
    Tune,
    /// The rigid characters of bench-large/rignet-check.
    Check,
}

impl SetArg {
    /// The folders of the set, under the data folder.
    fn folders(self) -> &'static [&'static str] {
        match self {
            SetArg::Tune => &["bench/rignet-val", "bench-large/rignet-train"],
            SetArg::Check => &["bench-large/rignet-check"],
        }
    }

    fn name(self) -> &'static str {
        match self {
            SetArg::Tune => "tune",
            SetArg::Check => "check",
        }
    }
}

/// Judges the rigidly bound characters both ways (smooth and `--binding rigid`).
#[derive(Parser, Debug)]
#[command(name = "rigid-binding")]
struct Args {
    /// The data folder, with bench/ and bench-large/.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data"))]
    data: PathBuf,
    /// Only these sets (repeatable); both by default.
    #[arg(long = "set", value_enum)]
    sets: Vec<SetArg>,
    /// Characters run at once; default: the number of cores.
    #[arg(long, value_parser = clap::value_parser!(u16).range(1..))]
    jobs: Option<u16>,
    /// Folder for the skinned characters and their reports.
    #[arg(long, default_value = concat!(env!("CARGO_MANIFEST_DIR"), "/../../target/rigid-binding"))]
    work: PathBuf,
}

fn main() -> Result<()> {
    let args = Args::parse();
    let exe = run::atlas_skin_exe()?;
    let jobs = args.jobs.map_or_else(
        || std::thread::available_parallelism().map_or(1, |n| n.get()),
        usize::from,
    );
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs)
        .build()
        .context("cannot start the worker threads")?;
    let sets = if args.sets.is_empty() {
        vec![SetArg::Tune, SetArg::Check]
    } else {
        args.sets.clone()
    };
    for set in sets {
        let characters = rigid_characters(&args.data, set)?;
        eprintln!(
            "{}: {} rigid characters on {jobs} jobs…",
            set.name(),
            characters.len()
        );
        let results: Vec<BothWays> = pool.install(|| {
            characters
                .par_iter()
                .map(|c| {
                    let judged =
                        judge_both_ways(&exe, c, &args.work).with_context(|| c.name.clone())?;
                    eprintln!(
                        "  {:<32} deform mean {:.4} → {:.4}",
                        c.name, judged.smooth.deform_mean, judged.rigid.deform_mean
                    );
                    Ok(judged)
                })
                .collect::<Result<_>>()
        })?;
        println!("{}", table(set.name(), &results));
    }
    Ok(())
}

/// The characters of `set`'s folders whose manifest says the artist bound them rigidly; an
/// error when a folder is missing or has no manifest saying so.
fn rigid_characters(data: &Path, set: SetArg) -> Result<Vec<Character>> {
    let mut rigid = Vec::new();
    for folder in set.folders() {
        let (parent, name) = folder.split_once('/').unwrap_or(("", folder));
        let prefix = format!("{name}/");
        let found: Vec<Character> = bench_characters(&data.join(parent))?
            .into_iter()
            .filter(|c| c.name.starts_with(&prefix))
            .collect();
        if found.iter().all(|c| c.rigid_by_artist.is_none()) {
            bail!(
                "{} has no manifest.json with rigid_binding flags",
                data.join(folder).display()
            );
        }
        rigid.extend(
            found
                .into_iter()
                .filter(|c| c.rigid_by_artist == Some(true)),
        );
    }
    Ok(rigid)
}
