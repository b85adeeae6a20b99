//! One benchmark run: every character skinned by `atlas-skin skin --report` and judged by
//! `atlas-skin eval --json` against the weights its file came with (under the main draw of
//! random poses and under the other draws of [`OTHER_SEEDS`]), in parallel; a
//! character that fails gives a result saying why. The whole run serialises to JSON, the
//! input of `--compare`.

use crate::bench_baselines::{BaselineTable, Figures};
use crate::bench_characters::{Character, Set};
use crate::computed_baselines::{compute_baselines, Baselines};
use crate::gltf_skins::skinned_meshes;
use crate::run::{run_eval, run_skin, SkinRun};
use crate::scoring::Pair;
use crate::single_joint::single_joint_share;
use anyhow::{Context, Result};
use atlas_skin_eval::{DeformError, EvalOptions, Evaluation};
use rayon::prelude::*;
use serde::{Deserialize, Serialize};
use std::path::Path;
use std::time::Instant;

/// How many of each character's worst vertices (`eval --worst`, with both weight rows) the
/// JSON keeps: where to look first when a character gets worse.
pub const WORST_VERTICES: usize = 3;

/// The first seeds of the other pose sets every character is judged under besides the
/// main one: issue 13's per-character goals count single vertices in single poses, and
/// these sets show how much of a count is the draw of the poses.
pub const OTHER_SEEDS: [u64; 4] = [10, 20, 30, 40];

/// The settings `atlas-skin eval` ran with (its defaults).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Settings {
    pub poses: usize,
    pub first_seed: u64,
    pub max_angle_degrees: f64,
    pub anim_frames: usize,
    pub bleeding_radius: f64,
    /// The first seeds of the other sets of `poses` random poses under which the deform
    /// figures are measured again (none in runs written before they were).
    #[serde(default)]
    pub other_seeds: Vec<u64>,
}

impl Settings {
    /// Whether both judge the main figures under the same poses (the other pose sets aside).
    pub fn same_main_poses(&self, other: &Settings) -> bool {
        let main = |s: &Settings| Settings {
            other_seeds: Vec::new(),
            ..s.clone()
        };
        main(self) == main(other)
    }

    /// `eval`'s defaults, which the benchmark does not override but for the first seed,
    /// and the other pose sets of [`OTHER_SEEDS`].
    pub fn of_eval() -> Self {
        Self::of_eval_from(EvalOptions::default().seed, &OTHER_SEEDS)
    }

    /// `eval`'s defaults with the poses' seeds from `first_seed` on, and other pose sets
    /// from each of `other_seeds` (`first_seed` and repeats left out).
    pub fn of_eval_from(first_seed: u64, other_seeds: &[u64]) -> Self {
        let o = EvalOptions::default();
        let mut others = Vec::new();
        for &seed in other_seeds {
            if seed != first_seed && !others.contains(&seed) {
                others.push(seed);
            }
        }
        Self {
            poses: o.poses,
            first_seed,
            max_angle_degrees: f64::from(o.max_angle.to_degrees()).round(),
            anim_frames: o.anim_frames,
            bleeding_radius: o.bleeding_radius,
            other_seeds: others,
        }
    }
}

/// A whole run, as written to benchmark.json.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BenchmarkRun {
    /// `git describe`-like: the commit measured, `+changes` when the tree was not clean.
    pub commit: String,
    pub settings: Settings,
    pub jobs: usize,
    /// Wall time of all characters (skin and eval), seconds.
    pub wall_seconds: f64,
    /// The machine's 1-minute load average when the run started and ended (Linux's
    /// /proc/loadavg), for reading the times: other work on the cores slows them.
    pub load_average: Option<(f64, f64)>,
    pub characters: Vec<CharacterResult>,
}

impl BenchmarkRun {
    /// The result of `name` in `set`.
    pub fn find(&self, set: Set, name: &str) -> Option<&CharacterResult> {
        self.characters
            .iter()
            .find(|c| c.set == set && c.name == name)
    }

    /// The results of `set`, in run order.
    pub fn of(&self, set: Set) -> Vec<&CharacterResult> {
        self.characters.iter().filter(|c| c.set == set).collect()
    }

    /// The characters of `set` that have a row in `table`, with our figures, in the
    /// table's order.
    pub fn pairs<'a>(&self, set: Set, table: &'a BaselineTable) -> Vec<Pair<'a>> {
        self.pairs_with(set, table, CharacterResult::figures)
    }

    /// [`BenchmarkRun::pairs`] with the deform figures of the other pose set from `seed`
    /// ([`CharacterResult::figures_under`]).
    pub fn pairs_under<'a>(&self, seed: u64, set: Set, table: &'a BaselineTable) -> Vec<Pair<'a>> {
        self.pairs_with(set, table, |c| c.figures_under(seed))
    }

    fn pairs_with<'a>(
        &self,
        set: Set,
        table: &'a BaselineTable,
        figures: impl Fn(&CharacterResult) -> Option<Figures>,
    ) -> Vec<Pair<'a>> {
        table
            .characters
            .iter()
            .filter_map(|baselines| {
                let ours = self.find(set, &baselines.name)?;
                Some(Pair {
                    baselines,
                    ours: figures(ours),
                })
            })
            .collect()
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct CharacterResult {
    pub set: Set,
    pub name: String,
    /// As the manifest says; `None` where none tells.
    pub rigid_by_artist: Option<bool>,
    pub outcome: Outcome,
    /// The baselines computed under the same poses (none in runs written before them).
    #[serde(default)]
    pub baselines: Baselines,
}

impl CharacterResult {
    /// Our figures in the form of the baseline tables; `None` when the character failed.
    pub fn figures(&self) -> Option<Figures> {
        match &self.outcome {
            Outcome::Scored(s) => Some(figures_of(&s.evaluation)),
            Outcome::Failed { .. } => None,
        }
    }

    /// The figures with the deform mean and max of the pose set from `seed` (one of the
    /// settings' `other_seeds`); `None` when the character failed or was not judged under
    /// those poses.
    pub fn figures_under(&self, seed: u64) -> Option<Figures> {
        let scored = self.scored()?;
        let other = scored.other_poses.iter().find(|o| o.first_seed == seed)?;
        Some(Figures {
            deform_mean: other.deform.mean,
            deform_max: other.deform.max,
            ..figures_of(&scored.evaluation)
        })
    }

    pub fn scored(&self) -> Option<&Scored> {
        match &self.outcome {
            Outcome::Scored(s) => Some(s),
            Outcome::Failed { .. } => None,
        }
    }
}

/// The table figures of an evaluation: LBS random-pose deformation, weight L1, bleeding.
pub fn figures_of(e: &Evaluation) -> Figures {
    Figures {
        deform_mean: e.deform_random.mean,
        deform_max: e.deform_random.max,
        l1_mean: e.weights_l1.mean,
        bleed: Some(e.bleeding.fraction),
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "lowercase")]
pub enum Outcome {
    Scored(Box<Scored>),
    /// `stage`: `skin` or `eval`; `reason`: the error.
    Failed {
        stage: String,
        reason: String,
    },
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Scored {
    pub evaluation: Evaluation,
    /// LBS deform error under the other pose sets of the settings, in their order.
    #[serde(default)]
    pub other_poses: Vec<OtherPoses>,
    pub skin: SkinFacts,
    /// Wall time of `eval`, seconds (the main pose set's and the others').
    pub eval_seconds: f64,
}

/// The deform error (random poses, LBS) under the pose set whose first seed is
/// `first_seed`.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct OtherPoses {
    pub first_seed: u64,
    pub deform: DeformError,
}

/// What the `skin` report and the skinned file say.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct SkinFacts {
    /// Stored vertices of the input as read (`counts.vertices`).
    pub vertices: usize,
    /// `counts.fallback_weighted_vertices`: vertices of decomposed pieces no region reached
    /// (weighted from the nearest weighted vertex of their piece), of pieces bound vertex by
    /// vertex to their nearest bone, and stored vertices no triangle uses.
    pub fallback_weighted_vertices: usize,
    /// The report's stages but writing, seconds.
    pub weights_seconds: Option<f64>,
    /// The whole `skin` command, seconds.
    pub wall_seconds: f64,
    /// Share of our skinned file's vertices bound to a single joint.
    pub single_joint_share: Option<f64>,
    /// The same for the reference weights.
    pub reference_single_joint_share: Option<f64>,
    /// Set when the file skins more vertices than the reader gave (several skins: the
    /// reader reads the first).
    pub partly_read: Option<String>,
    pub warnings: Vec<String>,
}

impl SkinFacts {
    /// `fallback_weighted_vertices` over `vertices`, the share issue 12 quotes.
    pub fn fallback_share(&self) -> f64 {
        self.fallback_weighted_vertices as f64 / self.vertices.max(1) as f64
    }
}

/// Runs every character on a pool of `jobs` threads, each writing its files under `work`
/// and judged under the random poses of `settings`; `progress` is called as each one ends.
/// Results are in the order of `characters`.
pub fn run_all(
    exe: &Path,
    characters: &[Character],
    work: &Path,
    jobs: usize,
    settings: &Settings,
    progress: &(dyn Fn(&CharacterResult) + Sync),
) -> Result<Vec<CharacterResult>> {
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(jobs.max(1))
        .build()
        .context("cannot start the worker threads")?;
    Ok(pool.install(|| {
        characters
            .par_iter()
            .map(|character| {
                let result = run_character(exe, character, work, settings);
                progress(&result);
                result
            })
            .collect()
    }))
}

/// Skins and judges one character; never fails: a failure is the result.
pub fn run_character(
    exe: &Path,
    character: &Character,
    work: &Path,
    settings: &Settings,
) -> CharacterResult {
    let outcome = match score(exe, character, work, settings) {
        Ok(scored) => Outcome::Scored(Box::new(scored)),
        Err((stage, error)) => Outcome::Failed {
            stage: stage.to_string(),
            reason: format!("{error:#}").replace('\n', " "),
        },
    };
    CharacterResult {
        set: character.set,
        name: character.name.clone(),
        rigid_by_artist: character.rigid_by_artist,
        outcome,
        baselines: compute_baselines(exe, character, work, settings),
    }
}

type Staged<T> = std::result::Result<T, (&'static str, anyhow::Error)>;

fn score(exe: &Path, character: &Character, work: &Path, settings: &Settings) -> Staged<Scored> {
    let stem = work
        .join(match character.set {
            Set::Bench => "bench",
            Set::Train | Set::Check => "bench-large",
            Set::Models => "models",
        })
        .join(character.name.trim_end_matches(".glb"));
    let candidate = stem.with_extension("glb");
    let report_path = stem.with_extension("report.json");
    let skin = |e: anyhow::Error| ("skin", e);
    if let Some(folder) = candidate.parent() {
        std::fs::create_dir_all(folder)
            .with_context(|| format!("cannot create {}", folder.display()))
            .map_err(skin)?;
    }
    let run = run_skin(exe, &character.skin_args, &candidate, &report_path).map_err(skin)?;
    let facts = skin_facts(character, &run, &candidate).map_err(skin)?;
    let start = Instant::now();
    let eval = |worst, first_seed, animation| {
        run_eval(
            exe,
            &character.reference_args,
            &candidate,
            character.prune_reference,
            worst,
            first_seed,
            animation,
        )
        .map_err(|e| ("eval", e))
    };
    let evaluation = eval(WORST_VERTICES, settings.first_seed, true)?;
    // Only the random poses' figures differ between draws.
    let other_poses = settings
        .other_seeds
        .iter()
        .map(|&first_seed| {
            Ok(OtherPoses {
                first_seed,
                deform: eval(0, first_seed, false)?.deform_random,
            })
        })
        .collect::<Staged<Vec<_>>>()?;
    Ok(Scored {
        evaluation,
        other_poses,
        skin: facts,
        eval_seconds: start.elapsed().as_secs_f64(),
    })
}

/// The report's counts, timings and warnings, the single-joint shares of our file and of
/// the reference, and whether the reader took every skinned vertex of a glTF input.
fn skin_facts(character: &Character, run: &SkinRun, candidate: &Path) -> Result<SkinFacts> {
    let report = &run.report;
    let count = |key: &str| {
        report["counts"][key]
            .as_u64()
            .map(|n| n as usize)
            .with_context(|| format!("the skin report has no counts.{key}"))
    };
    let vertices = count("vertices")?;
    let ours = atlas_skin_io::load_character(candidate, &Default::default())
        .with_context(|| format!("cannot read our skinned {}", candidate.display()))?;
    let reference = atlas_skin_io::load_character(&character.input, &character.reference_options)
        .with_context(|| format!("cannot read {}", character.input.display()))?;
    let is_gltf = character
        .input
        .extension()
        .is_some_and(|e| e == "glb" || e == "gltf");
    let partly_read = if is_gltf {
        let file = skinned_meshes(&character.input)?;
        (file.vertices > vertices).then(|| {
            format!(
                "the file has {} skinned meshes on {} skins ({} vertices); the reader gave {vertices}",
                file.nodes, file.skins, file.vertices
            )
        })
    } else {
        None
    };
    Ok(SkinFacts {
        vertices,
        fallback_weighted_vertices: count("fallback_weighted_vertices")?,
        weights_seconds: run.weights_seconds,
        wall_seconds: run.wall_seconds,
        single_joint_share: ours.reference_weights.as_ref().and_then(single_joint_share),
        reference_single_joint_share: reference
            .reference_weights
            .as_ref()
            .and_then(single_joint_share),
        partly_read,
        warnings: report["warnings"]
            .as_array()
            .into_iter()
            .flatten()
            .filter_map(|w| w.as_str().map(String::from))
            .collect(),
    })
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use atlas_skin_eval::{Bleeding, Validity, WeightsL1};

    /// A scored bench character with these deformation errors (L1 0.5, bleed 0.1, 100
    /// vertices of which `fallback` fell back, half of them bound to a single joint).
    pub(crate) fn scored(name: &str, mean: f64, max: f64, fallback: usize) -> CharacterResult {
        let deform = DeformError { mean, max };
        CharacterResult {
            set: Set::Bench,
            name: name.to_string(),
            rigid_by_artist: Some(false),
            baselines: Baselines::default(),
            outcome: Outcome::Scored(Box::new(Scored {
                evaluation: Evaluation {
                    vertices: 100,
                    joints: 5,
                    matched: 100,
                    candidate_vertices: 100,
                    candidate_joints: 5,
                    joint_matches: Vec::new(),
                    weights_l1: WeightsL1 {
                        mean: 0.5,
                        p95: 1.0,
                        max: 1.5,
                        dominant_agreement: 0.9,
                    },
                    rignet: None,
                    deform_random: deform,
                    deform_random_dqs: deform,
                    deform_anim: None,
                    bleeding: Bleeding { fraction: 0.1 },
                    validity: Validity {
                        negative_weights: 0,
                        sums_off_one: 0,
                        unweighted_vertices: 0,
                        max_influences: 4,
                        mean_influences: 2.0,
                    },
                    worst_vertices: Vec::new(),
                },
                other_poses: OTHER_SEEDS
                    .iter()
                    .map(|&first_seed| OtherPoses { first_seed, deform })
                    .collect(),
                skin: SkinFacts {
                    vertices: 100,
                    fallback_weighted_vertices: fallback,
                    weights_seconds: Some(0.004),
                    wall_seconds: 0.01,
                    single_joint_share: Some(0.5),
                    reference_single_joint_share: Some(1.0),
                    partly_read: None,
                    warnings: Vec::new(),
                },
                eval_seconds: 0.02,
            })),
        }
    }

    pub(crate) fn failed(name: &str) -> CharacterResult {
        CharacterResult {
            set: Set::Bench,
            name: name.to_string(),
            rigid_by_artist: Some(true),
            baselines: Baselines::default(),
            outcome: Outcome::Failed {
                stage: "skin".into(),
                reason: "the mesh has no triangles".into(),
            },
        }
    }

    pub(crate) fn run(commit: &str, characters: Vec<CharacterResult>) -> BenchmarkRun {
        BenchmarkRun {
            commit: commit.into(),
            settings: Settings::of_eval(),
            jobs: 2,
            wall_seconds: 1.5,
            load_average: Some((0.5, 0.7)),
            characters,
        }
    }

    #[test]
    fn a_run_round_trips_through_json() {
        let run = run("abc", vec![scored("a.glb", 0.01, 0.1, 3), failed("b.glb")]);
        let text = serde_json::to_string(&run).unwrap();
        assert!(text.contains(r#""status":"failed""#));
        assert_eq!(serde_json::from_str::<BenchmarkRun>(&text).unwrap(), run);
        assert_eq!(run.characters[0].figures().unwrap().deform_max, 0.1);
        assert_eq!(run.characters[1].figures(), None);
        assert_eq!(
            run.characters[0].scored().unwrap().skin.fallback_share(),
            0.03
        );
        assert_eq!(
            run.characters[0].figures_under(10),
            run.characters[0].figures()
        );
        assert_eq!(run.characters[0].figures_under(11), None);
        // A run written before the other pose sets reads, with none.
        let mut old: serde_json::Value = serde_json::from_str(&text).unwrap();
        old["settings"]
            .as_object_mut()
            .unwrap()
            .remove("other_seeds");
        old["characters"][0]["outcome"]
            .as_object_mut()
            .unwrap()
            .remove("other_poses");
        let old: BenchmarkRun = serde_json::from_value(old).unwrap();
        assert!(old.settings.other_seeds.is_empty());
        assert!(old.settings.same_main_poses(&run.settings));
        assert_eq!(old.characters[0].figures_under(10), None);
    }

    #[test]
    fn eval_settings_are_baselines_md() {
        let s = Settings::of_eval();
        assert_eq!((s.poses, s.first_seed, s.max_angle_degrees), (10, 0, 60.0));
    }

    /// The real thing on two small characters: a smooth and a rigid one of the benchmark,
    /// through the released binary (built by `cargo test` of the workspace or the scripts).
    #[test]
    fn two_real_characters_are_skinned_and_judged() {
        // The test binary lives in target/release/deps, the CLI one folder up (built by the
        // workspace's `cargo test --all-targets` or by the scripts).
        let test_exe = std::env::current_exe().unwrap();
        let exe = test_exe
            .parent()
            .unwrap()
            .parent()
            .unwrap()
            .join("atlas-skin");
        assert!(
            exe.is_file(),
            "{} is missing: cargo build --release -p atlas-skin-cli",
            exe.display()
        );
        let bench = Path::new(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/bench"
        ));
        let characters: Vec<Character> = crate::bench_characters::bench_characters(bench)
            .expect("the benchmark characters are missing: ../shared/data/bench")
            .into_iter()
            .filter(|c| c.name == "rignet-val/426.glb" || c.name == "rignet-val/9452.glb")
            .collect();
        assert_eq!(characters.len(), 2);
        let work = std::env::temp_dir().join(format!("bench-run-{}", std::process::id()));
        let results = run_all(&exe, &characters, &work, 2, &Settings::of_eval(), &|_| {}).unwrap();
        for result in &results {
            let s = result.scored().unwrap_or_else(|| panic!("{result:?}"));
            assert_eq!(s.evaluation.matched, s.evaluation.vertices);
            assert_eq!(s.evaluation.worst_vertices.len(), WORST_VERTICES);
            assert!(s.evaluation.deform_random.mean > 0.0);
            let seeds: Vec<u64> = s.other_poses.iter().map(|o| o.first_seed).collect();
            assert_eq!(seeds, OTHER_SEEDS);
            // Other poses, other figures (the same weights).
            for other in &s.other_poses {
                assert!(other.deform.mean > 0.0 && other.deform.max >= other.deform.mean);
                assert_ne!(other.deform, s.evaluation.deform_random);
            }
            assert!(s.skin.vertices > 0 && s.skin.weights_seconds.is_some());
            let rignet = s.evaluation.rignet.expect("RigNet's metrics");
            assert!(rignet.vertices > 0 && (0.0..=1.0).contains(&rignet.precision));
            assert!((0.0..=1.0).contains(&rignet.recall) && rignet.l1 >= 0.0);
            // Nearest bone is computed here, under the same poses; bone heat only where
            // scripts/bone-heat has run (not in this fresh folder).
            let nearest = result
                .baselines
                .scored(crate::computed_baselines::Baseline::NearestBone)
                .unwrap_or_else(|| panic!("no nearest-bone figures: {:?}", result.baselines));
            assert!(nearest.deform.mean > 0.0 && nearest.other_poses.len() == OTHER_SEEDS.len());
            assert_eq!(nearest.rignet.map(|r| r.vertices), Some(rignet.vertices));
            assert_eq!(result.baselines.bone_heat, None);
            let artist = s.skin.reference_single_joint_share.unwrap();
            if result.rigid_by_artist == Some(true) {
                assert_eq!(artist, 1.0, "{}", result.name);
            } else {
                assert!(artist < 1.0, "{}", result.name);
            }
        }
        // A character whose file is not a glTF gives a failed result, not an abort.
        let mut broken = characters[0].clone();
        broken.name = "broken.glb".into();
        let text = work.join("broken.glb");
        std::fs::write(&text, "not a glb").unwrap();
        broken.skin_args = vec![text.clone().into_os_string()];
        broken.input = text;
        let result = run_character(&exe, &broken, &work, &Settings::of_eval());
        match &result.outcome {
            Outcome::Failed { stage, reason } => {
                assert_eq!(stage, "skin");
                assert!(reason.contains("broken.glb"), "{reason}");
            }
            Outcome::Scored(_) => panic!("a text file was scored"),
        }
        std::fs::remove_dir_all(&work).unwrap();
    }
}
