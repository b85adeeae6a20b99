//! Which characters the benchmark runs and how each is given to `atlas-skin`: every glTF
//! binary under `shared/data/bench/*/` and `shared/data/bench-large/*/` (the artist weights
//! are in the file), and every corpus model of `shared/data/models` with reference weights
//! (the corpus table of `atlas-skin-corpus`).
//!
//! The sets form the three groups a change to the method is judged on: **tune** (`bench/`
//! and `bench-large/rignet-train/`: rules and widths may be chosen looking at them),
//! **check** (`bench-large/rignet-check/`: a change is confirmed there, never chosen there)
//! and the clean **corpus**.

use anyhow::{Context, Result};
use atlas_skin_corpus::{Reference, MODELS};
use atlas_skin_io::LoadOptions;
use serde::{Deserialize, Serialize};
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// The sets of characters, each a folder of `shared/data`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Set {
    /// `shared/data/bench`: 65 game characters as they come, with bench/BASELINES.md's rows.
    Bench,
    /// `shared/data/bench-large/rignet-train`: 400 more of the same dataset, to tune on.
    Train,
    /// `shared/data/bench-large/rignet-check`: 210 more, to confirm on, never to tune on.
    Check,
    /// `shared/data/models`: the clean corpus, with BASELINES.md's rows.
    Models,
}

/// What a set is for: the groups a change is judged on.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Group {
    /// `bench` and `rignet-train`.
    Tune,
    /// `rignet-check`.
    Check,
    /// The clean corpus.
    Corpus,
}

impl Group {
    pub const ALL: [Group; 3] = [Group::Tune, Group::Check, Group::Corpus];

    pub fn name(self) -> &'static str {
        match self {
            Group::Tune => "tune",
            Group::Check => "check",
            Group::Corpus => "corpus",
        }
    }
}

impl Set {
    /// The group the set belongs to.
    pub fn group(self) -> Group {
        match self {
            Set::Bench | Set::Train => Group::Tune,
            Set::Check => Group::Check,
            Set::Models => Group::Corpus,
        }
    }

    /// The set's folder under `shared/data`.
    pub fn folder(self) -> &'static str {
        match self {
            Set::Bench => "bench",
            Set::Train => "bench-large/rignet-train",
            Set::Check => "bench-large/rignet-check",
            Set::Models => "models",
        }
    }
}

/// One character to skin and judge.
#[derive(Debug, Clone)]
pub struct Character {
    pub set: Set,
    /// `rignet-val/426.glb` (a path under `bench/`, as bench/BASELINES.md names it), or the
    /// corpus folder name (`cesiumman`).
    pub name: String,
    /// The main input file.
    pub input: PathBuf,
    /// `atlas-skin skin` arguments naming the input (the file, plus `--skeleton`/`--group`).
    pub skin_args: Vec<OsString>,
    /// `atlas-skin eval` arguments naming the reference (plus `--weights` where needed).
    pub reference_args: Vec<OsString>,
    /// How the reference with its weights is read (for the single-joint share).
    pub reference_options: LoadOptions,
    pub prune_reference: Option<u16>,
    /// The artist bound every vertex to a single joint, as the folder's manifest.json says
    /// (`rigid_binding`); `None` where no manifest tells.
    pub rigid_by_artist: Option<bool>,
}

/// Every `*.glb` in the subfolders of `bench` (sorted by folder, then by name, numbers in
/// numeric order), with the rigid flags of each folder's manifest.json where it has one.
pub fn bench_characters(bench: &Path) -> Result<Vec<Character>> {
    let mut folders: Vec<PathBuf> = read_dir(bench)?
        .into_iter()
        .filter(|p| p.is_dir())
        .collect();
    folders.sort();
    let characters = folders
        .iter()
        .map(|folder| folder_characters(folder, Set::Bench))
        .collect::<Result<Vec<_>>>()?
        .concat();
    if characters.is_empty() {
        anyhow::bail!("no .glb file in the subfolders of {}", bench.display());
    }
    Ok(characters)
}

/// Every `*.glb` of `data/bench-large/rignet-train` (`set` [`Set::Train`]) or
/// `rignet-check` ([`Set::Check`]), named `rignet-train/53.glb`, with the manifest's rigid
/// flags.
pub fn large_characters(data: &Path, set: Set) -> Result<Vec<Character>> {
    debug_assert!(matches!(set, Set::Train | Set::Check));
    let folder = data.join(set.folder());
    let characters = folder_characters(&folder, set)?;
    if characters.is_empty() {
        anyhow::bail!("no .glb file in {}", folder.display());
    }
    Ok(characters)
}

/// The `*.glb` files of one folder, in natural order, named `<folder>/<file>`.
fn folder_characters(folder: &Path, set: Set) -> Result<Vec<Character>> {
    let rigid = rigid_bindings(&folder.join("manifest.json"))?;
    let mut files: Vec<PathBuf> = read_dir(folder)?
        .into_iter()
        .filter(|p| p.extension().is_some_and(|e| e == "glb"))
        .collect();
    files.sort_by_key(|p| natural_key(p));
    let folder_name = folder.file_name().unwrap_or_default().to_string_lossy();
    Ok(files
        .into_iter()
        .map(|input| {
            let file = input
                .file_name()
                .unwrap_or_default()
                .to_string_lossy()
                .to_string();
            Character {
                set,
                name: format!("{folder_name}/{file}"),
                skin_args: vec![input.clone().into_os_string()],
                reference_args: vec![input.clone().into_os_string()],
                reference_options: LoadOptions::default(),
                prune_reference: None,
                rigid_by_artist: rigid.iter().find(|(f, _)| f == &file).map(|r| r.1),
                input,
            }
        })
        .collect())
}

/// The corpus models of `models` that have reference weights, in the corpus table's order.
pub fn model_characters(models: &Path) -> Vec<Character> {
    MODELS
        .iter()
        .filter(|m| m.reference != Reference::None)
        .map(|m| Character {
            set: Set::Models,
            name: m.name.to_string(),
            input: m.folder_in(models).join(m.input),
            skin_args: m.input_args_in(models, false),
            reference_args: m.input_args_in(models, true),
            reference_options: m.load_options_in(models, true),
            prune_reference: m.prune_reference,
            rigid_by_artist: None,
        })
        .collect()
}

fn read_dir(dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::read_dir(dir)
        .with_context(|| format!("cannot read {}", dir.display()))?
        .map(|entry| Ok(entry?.path()))
        .collect()
}

/// `(file, rigid_binding)` of each manifest entry (`models: [{file, rigid_binding}]`); none
/// without a manifest.
fn rigid_bindings(manifest: &Path) -> Result<Vec<(String, bool)>> {
    if !manifest.exists() {
        return Ok(Vec::new());
    }
    let text = std::fs::read_to_string(manifest)
        .with_context(|| format!("cannot read {}", manifest.display()))?;
    let json: serde_json::Value = serde_json::from_str(&text)
        .with_context(|| format!("{} is not JSON", manifest.display()))?;
    Ok(json["models"]
        .as_array()
        .into_iter()
        .flatten()
        .filter_map(|m| {
            Some((
                m["file"].as_str()?.to_string(),
                m["rigid_binding"].as_bool()?,
            ))
        })
        .collect())
}

/// Sorts `426.glb` before `1134.glb`: a numeric stem by its number, others after by name.
fn natural_key(path: &Path) -> (u64, String) {
    let stem = path.file_stem().unwrap_or_default().to_string_lossy();
    (stem.parse().unwrap_or(u64::MAX), stem.to_string())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_real_bench_folder_has_65_characters_12_rigid() {
        let bench = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data/bench");
        let characters = bench_characters(Path::new(bench))
            .expect("the benchmark characters are missing: ../shared/data/bench");
        assert_eq!(characters.len(), 65);
        let rigid = |flag| {
            characters
                .iter()
                .filter(|c| c.rigid_by_artist == flag)
                .count()
        };
        assert_eq!(
            (rigid(Some(true)), rigid(Some(false)), rigid(None)),
            (12, 48, 5)
        );
        let names: Vec<&str> = characters.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(names[0], "kaykit/Barbarian.glb");
        assert!(names.contains(&"robotexpressive/RobotExpressive.glb"));
        let rignet: Vec<&&str> = names.iter().filter(|n| n.starts_with("rignet")).collect();
        assert_eq!(
            (*rignet[0], *rignet[1]),
            ("rignet-val/426.glb", "rignet-val/485.glb")
        );
        assert!(characters
            .iter()
            .any(|c| c.name == "rignet-val/1168.glb" && c.rigid_by_artist == Some(true)));
    }

    #[test]
    fn the_corpus_models_with_weights_are_listed() {
        let models = model_characters(Path::new("/corpus"));
        let names: Vec<&str> = models.iter().map(|c| c.name.as_str()).collect();
        assert_eq!(
            names,
            [
                "cesiumman",
                "riggedfigure",
                "riggedsimple",
                "makehuman",
                "simpleskin",
                "arm",
                "elephant"
            ]
        );
        let makehuman = &models[3];
        assert_eq!(makehuman.prune_reference, Some(4));
        assert!(makehuman.reference_args.len() > makehuman.skin_args.len());
    }

    #[test]
    fn a_missing_folder_is_an_error_naming_it() {
        let error = format!(
            "{:#}",
            bench_characters(Path::new("/no/such/bench")).unwrap_err()
        );
        assert!(error.contains("/no/such/bench"), "{error}");
    }
}
