//! The baselines the benchmark computes itself, for every character, and judges with the
//! same `atlas-skin eval` under the same draws of poses as atlas-skin's weights, so that
//! every comparison is made under the same poses:
//!
//! - **nearest bone**: each vertex fully to the joint whose bone segment is nearest
//!   (Euclidean distance; joint j owns the segments from j to each child, a leaf the segment
//!   to its stated tail or, without one, its parent's bone continued by half its length:
//!   [`atlas_skin::skeleton::bones::bone_segments`]). Computed here.
//! - **bone heat**: Blender's "With Automatic Weights" (Baran and Popović 2007), computed by
//!   `scripts/bone-heat` with the `bpy` package into `<work>/bone-heat/<input hash>.glb`
//!   and a status file beside it; a character Blender failed on (or left vertices without
//!   weights) counts as failed; one the script has not run on has no heat figures.
//!
//! The figures of each are cached by the SHA-256 of the input file and the evaluation
//! settings under `<work>/cache/`: a run over unchanged characters re-evaluates only
//! atlas-skin's weights.

use crate::bench_characters::Character;
use crate::bench_run::{OtherPoses, Settings};
use crate::run::run_eval;
use anyhow::{Context, Result};
use atlas_skin::skeleton::bones::nearest_bone_weights;
use atlas_skin_eval::{DeformError, Evaluation, RigNetMetrics};
use atlas_skin_io::gltf::{write_skinned_glb, WriteOptions};
use glam::DVec3;
use serde::{Deserialize, Serialize};
use sha2::{Digest, Sha256};
use std::path::{Path, PathBuf};

/// A baseline the benchmark computes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Baseline {
    NearestBone,
    BoneHeat,
}

impl Baseline {
    /// Its name in files and on the page.
    pub fn name(self) -> &'static str {
        match self {
            Baseline::NearestBone => "nearest-bone",
            Baseline::BoneHeat => "bone-heat",
        }
    }
}

/// The baselines' outcomes of one character; `None` where a baseline was not computed.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
pub struct Baselines {
    pub nearest_bone: Option<BaselineOutcome>,
    pub bone_heat: Option<BaselineOutcome>,
}

impl Baselines {
    pub fn get(&self, baseline: Baseline) -> Option<&BaselineOutcome> {
        match baseline {
            Baseline::NearestBone => self.nearest_bone.as_ref(),
            Baseline::BoneHeat => self.bone_heat.as_ref(),
        }
    }

    /// The figures of `baseline`, when it scored.
    pub fn scored(&self, baseline: Baseline) -> Option<&BaselineFigures> {
        match self.get(baseline)? {
            BaselineOutcome::Scored(f) => Some(f),
            BaselineOutcome::Failed { .. } => None,
        }
    }
}

#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(tag = "status", rename_all = "lowercase")]
pub enum BaselineOutcome {
    Scored(BaselineFigures),
    Failed { reason: String },
}

/// What `eval` says of a baseline's weights.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BaselineFigures {
    /// LBS deform error under the main draw of poses.
    pub deform: DeformError,
    /// Under the other draws, in the settings' order.
    pub other_poses: Vec<OtherPoses>,
    /// Mean per-vertex L1 against the renormalised reference.
    pub weights_l1: f64,
    pub rignet: Option<RigNetMetrics>,
}

impl BaselineFigures {
    /// The deform error under the draw from `first_seed`.
    pub fn deform_under(&self, settings: &Settings, first_seed: u64) -> Option<DeformError> {
        if first_seed == settings.first_seed {
            return Some(self.deform);
        }
        self.other_poses
            .iter()
            .find(|o| o.first_seed == first_seed)
            .map(|o| o.deform)
    }
}

/// The hex SHA-256 of a file's bytes.
pub fn file_hash(path: &Path) -> Result<String> {
    let bytes = std::fs::read(path).with_context(|| format!("cannot read {}", path.display()))?;
    Ok(Sha256::digest(&bytes)
        .iter()
        .map(|b| format!("{b:02x}"))
        .collect())
}

/// Both baselines of `character` (see the module documentation); never fails: a failure
/// is the outcome.
pub fn compute_baselines(
    exe: &Path,
    character: &Character,
    work: &Path,
    settings: &Settings,
) -> Baselines {
    let hash = match file_hash(&character.input) {
        Ok(hash) => hash,
        Err(e) => {
            let failed = || {
                Some(BaselineOutcome::Failed {
                    reason: format!("{e:#}"),
                })
            };
            return Baselines {
                nearest_bone: failed(),
                bone_heat: failed(),
            };
        }
    };
    let judged = |baseline: Baseline, candidate: &dyn Fn() -> Result<Option<PathBuf>>| {
        cached(work, baseline, &hash, settings, || {
            Ok(match candidate()? {
                Some(glb) => Some(judge(exe, character, &glb, settings)?),
                None => None,
            })
        })
    };
    Baselines {
        nearest_bone: judged(Baseline::NearestBone, &|| {
            nearest_bone_glb(character, work, &hash).map(Some)
        }),
        bone_heat: judged(Baseline::BoneHeat, &|| bone_heat_glb(work, &hash)),
    }
}

/// The settings a cached figure was measured under, as part of its file name.
fn settings_key(settings: &Settings) -> String {
    let text = serde_json::to_string(settings).unwrap_or_default();
    Sha256::digest(text.as_bytes())
        .iter()
        .take(6)
        .map(|b| format!("{b:02x}"))
        .collect()
}

/// The outcome cached for (`baseline`, `hash`, `settings`), or `compute`'s, cached. A
/// `compute` that gives `None` (no heat run for this input) is not cached.
fn cached(
    work: &Path,
    baseline: Baseline,
    hash: &str,
    settings: &Settings,
    compute: impl FnOnce() -> Result<Option<BaselineFigures>>,
) -> Option<BaselineOutcome> {
    let file = work
        .join("cache")
        .join(baseline.name())
        .join(format!("{hash}-{}.json", settings_key(settings)));
    if let Some(outcome) = std::fs::read(&file)
        .ok()
        .and_then(|bytes| serde_json::from_slice::<BaselineOutcome>(&bytes).ok())
    {
        return Some(outcome);
    }
    let outcome = match compute() {
        Ok(None) => return None,
        Ok(Some(figures)) => BaselineOutcome::Scored(figures),
        Err(e) => BaselineOutcome::Failed {
            reason: format!("{e:#}").replace('\n', " "),
        },
    };
    if let Some(folder) = file.parent() {
        let _ = std::fs::create_dir_all(folder);
    }
    if let Ok(text) = serde_json::to_vec(&outcome) {
        // Through a temporary file: a killed run leaves no half cache entry.
        let temporary = file.with_extension(format!("{}.partial", std::process::id()));
        if std::fs::write(&temporary, text).is_ok() {
            let _ = std::fs::rename(&temporary, &file);
        }
    }
    Some(outcome)
}

/// Writes the nearest-bone weights of `character` as a skinned glb under `work`.
fn nearest_bone_glb(character: &Character, work: &Path, hash: &str) -> Result<PathBuf> {
    let loaded = atlas_skin_io::load_character(&character.input, &character.reference_options)
        .with_context(|| format!("cannot read {}", character.input.display()))?;
    let skeleton = loaded
        .skeleton
        .as_ref()
        .with_context(|| format!("{} has no skeleton", character.input.display()))?;
    let positions: Vec<DVec3> = loaded.mesh.positions.iter().map(|p| p.as_dvec3()).collect();
    let weights = nearest_bone_weights(&positions, skeleton);
    let folder = work.join(Baseline::NearestBone.name());
    std::fs::create_dir_all(&folder)
        .with_context(|| format!("cannot create {}", folder.display()))?;
    let glb = folder.join(format!("{hash}.glb"));
    write_skinned_glb(&loaded, &weights, &WriteOptions::default(), &glb)
        .with_context(|| format!("cannot write {}", glb.display()))?;
    Ok(glb)
}

/// What `scripts/bone-heat` wrote beside each heat glb.
#[derive(Debug, Deserialize)]
struct HeatStatus {
    /// `ok`, or `failed` with the reason.
    status: String,
    #[serde(default)]
    reason: String,
}

/// The heat glb of the input with `hash`, when `scripts/bone-heat` has run on it; an error
/// (the baseline's failure) when Blender failed on it.
fn bone_heat_glb(work: &Path, hash: &str) -> Result<Option<PathBuf>> {
    let folder = work.join(Baseline::BoneHeat.name());
    let status_file = folder.join(format!("{hash}.json"));
    let Ok(text) = std::fs::read_to_string(&status_file) else {
        return Ok(None);
    };
    let status: HeatStatus = serde_json::from_str(&text).with_context(|| {
        format!(
            "{} is not a status of scripts/bone-heat",
            status_file.display()
        )
    })?;
    if status.status != "ok" {
        anyhow::bail!("{}", status.reason);
    }
    Ok(Some(folder.join(format!("{hash}.glb"))))
}

/// `eval` of a baseline's glb under every draw of `settings`.
fn judge(
    exe: &Path,
    character: &Character,
    glb: &Path,
    settings: &Settings,
) -> Result<BaselineFigures> {
    let eval = |first_seed| -> Result<Evaluation> {
        run_eval(
            exe,
            &character.reference_args,
            glb,
            character.prune_reference,
            0,
            first_seed,
            false,
        )
    };
    let main = eval(settings.first_seed)?;
    let other_poses = settings
        .other_seeds
        .iter()
        .map(|&first_seed| {
            Ok(OtherPoses {
                first_seed,
                deform: eval(first_seed)?.deform_random,
            })
        })
        .collect::<Result<Vec<_>>>()?;
    Ok(BaselineFigures {
        deform: main.deform_random,
        other_poses,
        weights_l1: main.weights_l1.mean,
        rignet: main.rignet,
    })
}
