//! One file-skinning job (`atlas-skin skin`): read a character, compute its weights
//! ([`atlas_skin::pipeline::skin`]: cuts at the joints, regions, overlaps along the surface,
//! blended weights), write the skinned glTF binary and, when asked, the JSON report, the
//! HTML report, a debug view and RigNet's rig_info text. Every output goes through one
//! [`OutputPlan`], checked before any work: complete or untouched, never over an input.
//!
//! With a quality gate ([`crate::quality`], `Settings::fail_on`), a rejected character's
//! outputs are written only when asked ([`SkinJob::keep_rejected`]), under their rejected
//! names ([`rejected_name`]); its JSON report always, under its rejected name. Of the
//! outputs' names and their rejected names, a gated run leaves only the files it wrote:
//! an earlier run's file under the other name is removed, so that a folder's `*.glb`
//! hold accepted characters only.

use crate::html::{write_html, HtmlError};
use crate::quality::{rejected_name, Findings, Verdict};
use crate::report::{stage_timings, SkinReport};
use crate::settings::{Settings, SettingsError};
use atlas_skin::pipeline::{skin, SkinError, SkinInput, Skinned};
use atlas_skin::report::{debug_colors, debug_lines};
use atlas_skin::Warning;
use atlas_skin_io::gltf::{debug_glb, skinned_glb_taking_document, WriteOptions};
use atlas_skin_io::{Character, Contents, IoError, LoadOptions, OutputPlan, TriangleMesh};
use glam::Vec3;
use serde_json::{json, Value};
use std::path::{Path, PathBuf};
use std::time::Instant;
use thiserror::Error;

/// Why a job failed. Each message names the file and the problem; causes are error sources
/// (a chain printer such as anyhow's `{:#}` joins them with `: `, see [`error_chain`]).
#[derive(Debug, Error)]
pub enum JobError {
    /// Reading the character, planning or writing an output.
    #[error(transparent)]
    Io(#[from] IoError),
    #[error(transparent)]
    Settings(#[from] SettingsError),
    #[error("{} has no skeleton: give one with --skeleton", path.display())]
    NoSkeleton { path: PathBuf },
    #[error("cannot skin {}", path.display())]
    Skin {
        path: PathBuf,
        #[source]
        source: SkinError,
    },
    #[error("cannot write {}", path.display())]
    DebugView {
        path: PathBuf,
        #[source]
        source: IoError,
    },
    #[error("cannot serialise the report")]
    Report(#[source] serde_json::Error),
    #[error(transparent)]
    Html(#[from] HtmlError),
}

/// `error` and its sources joined by `: `, as the command line prints them.
pub fn error_chain(error: &dyn std::error::Error) -> String {
    let mut text = error.to_string();
    let mut source = error.source();
    while let Some(cause) = source {
        text.push_str(": ");
        text.push_str(&cause.to_string());
        source = cause.source();
    }
    text
}

/// Where the character comes from.
#[derive(Debug, Clone, Default)]
pub struct Input {
    /// The character's file; `None`: the built-in demo character ([`demo_character`]).
    pub path: Option<PathBuf>,
    /// Companion files (skeleton, reference weights) and the OBJ group.
    pub load: LoadOptions,
}

impl Input {
    /// A character file with no companion file.
    pub fn file(path: impl Into<PathBuf>) -> Self {
        Self {
            path: Some(path.into()),
            load: LoadOptions::default(),
        }
    }

    /// Every file read: the character's and its companions.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.path
            .as_deref()
            .into_iter()
            .chain(self.load.skeleton.as_deref())
            .chain(self.load.weights.as_deref())
    }

    /// Reads the character, or builds the demo character.
    pub fn load(&self) -> Result<Character, IoError> {
        match &self.path {
            Some(path) => atlas_skin_io::load_character(path, &self.load),
            None => Ok(demo_character()),
        }
    }

    /// [`Input::load`] without what skinning does not use: a glTF or FBX input's stored
    /// weights are not decoded ([`Contents::ForSkinning`]).
    fn load_for_skinning(&self) -> Result<Character, IoError> {
        match &self.path {
            Some(path) => {
                atlas_skin_io::load_character_with(path, &self.load, Contents::ForSkinning)
            }
            None => Ok(demo_character()),
        }
    }
}

/// The built-in demo character ([`atlas_skin::fixtures::demo`]) as if read from a file named
/// `demo`: mesh and skeleton, no weights.
pub fn demo_character() -> Character {
    let demo = atlas_skin::fixtures::demo::demo_character(atlas_skin::fixtures::demo::DEFAULT_STEP);
    let mut character = Character::new(
        "demo",
        TriangleMesh {
            positions: demo.positions,
            triangles: demo.triangles,
        },
    );
    character.skeleton = Some(demo.skeleton);
    character
}

/// The files a job writes: the skinned glb always, the others when given.
#[derive(Debug, Clone, Default)]
pub struct Outputs {
    /// The skinned glTF binary.
    pub glb: PathBuf,
    /// The JSON report ([`crate::report::skin_report`]).
    pub report: Option<PathBuf>,
    /// The self-contained HTML report ([`crate::html`]).
    pub html: Option<PathBuf>,
    /// An unskinned glb with the regions as vertex colours and the cut curves as lines.
    pub debug_glb: Option<PathBuf>,
    /// The weights (pruned as in the glb) and the skeleton in RigNet's rig_info text.
    pub rig_info: Option<PathBuf>,
}

impl Outputs {
    /// Only the skinned glb.
    pub fn glb(path: impl Into<PathBuf>) -> Self {
        Self {
            glb: path.into(),
            ..Self::default()
        }
    }

    /// The same outputs under their rejected names ([`rejected_name`]).
    pub fn rejected_names(&self) -> Self {
        let rename = |path: &PathBuf| rejected_name(path);
        Self {
            glb: rename(&self.glb),
            report: self.report.as_ref().map(rename),
            html: self.html.as_ref().map(rename),
            debug_glb: self.debug_glb.as_ref().map(rename),
            rig_info: self.rig_info.as_ref().map(rename),
        }
    }

    /// Every file written.
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        [
            Some(&self.glb),
            self.report.as_ref(),
            self.debug_glb.as_ref(),
            self.html.as_ref(),
            self.rig_info.as_ref(),
        ]
        .into_iter()
        .flatten()
        .map(PathBuf::as_path)
    }
}

/// One character to skin: what to read, with which settings, and what to write.
#[derive(Debug, Clone, Default)]
pub struct SkinJob {
    pub input: Input,
    pub settings: Settings,
    pub outputs: Outputs,
    /// Return the JSON report in the [`JobOutcome`] (a batch's log, the Python binding);
    /// without it the report is built only for [`Outputs::report`] (serialised straight
    /// to its file) and [`Outputs::html`] (as values).
    pub keep_report: bool,
    /// When the quality gate rejects the character, write all its outputs anyway, under
    /// their rejected names ([`rejected_name`]); otherwise only its JSON report is.
    pub keep_rejected: bool,
}

/// What a finished job tells its caller.
#[derive(Debug, Clone)]
pub struct JobOutcome {
    /// The JSON report as values, when [`SkinJob::keep_report`] asked for it or the HTML
    /// report needed it. (The file of [`Outputs::report`] is serialised without them.)
    pub report: Option<Value>,
    /// What the method noticed and handled (the report's warnings also hold the reader's).
    pub method_warnings: Vec<Warning>,
    /// One line: input, vertices, joints (cut, soft, skipped), regions, output.
    pub summary: String,
    /// The quality gate's verdict (without a gate: accepted).
    pub verdict: Verdict,
    /// The skinned glb of a rejected character, written under its rejected name when
    /// [`SkinJob::keep_rejected`] asked for it.
    pub kept: Option<PathBuf>,
}

impl SkinJob {
    /// Runs the job (see the module documentation). `progress` is told each step as it
    /// starts: the method's stages by name, then `writing`.
    pub fn run(&self, progress: &mut dyn FnMut(&'static str)) -> Result<JobOutcome, JobError> {
        let fail_on = self.settings.fail_on()?;
        let rejected_outputs = (!fail_on.is_empty()).then(|| self.outputs.rejected_names());
        let plan = OutputPlan::new(
            self.input.paths().chain(self.settings.paths()),
            self.outputs
                .paths()
                .chain(rejected_outputs.iter().flat_map(Outputs::paths)),
        )?;
        let params = self.settings.params()?;
        let mut character = self.input.load_for_skinning()?;
        let Some(skeleton) = character.skeleton.clone() else {
            return Err(JobError::NoSkeleton {
                path: character.path.clone(),
            });
        };
        let skinned = skin(
            SkinInput {
                positions: &character.mesh.positions,
                triangles: &character.mesh.triangles,
                skeleton: &skeleton,
                end_joints: &character.end_joints,
            },
            &params,
            &mut |stage| progress(stage.name()),
        )
        .map_err(|source| JobError::Skin {
            path: character.path.clone(),
            source,
        })?;
        let mut timings = stage_timings(&skinned);
        let findings = Findings::new(&character.warnings, &skinned);
        let verdict = Verdict::new(&findings, &fail_on);
        let rejected = verdict.rejected();
        // A rejected character's outputs go under their rejected names, all of them when
        // kept, else its report only.
        let outputs = match &rejected_outputs {
            Some(renamed) if rejected => renamed.clone(),
            _ => self.outputs.clone(),
        };
        let write_all = !rejected || self.keep_rejected;
        if let Some(renamed) = &rejected_outputs {
            let written: Vec<&Path> = if write_all {
                outputs.paths().collect()
            } else {
                outputs.report.iter().map(PathBuf::as_path).collect()
            };
            for path in self.outputs.paths().chain(renamed.paths()) {
                if !written.contains(&path) {
                    plan.remove(path)?;
                }
            }
        }

        progress("writing");
        let glb = if write_all {
            let start = Instant::now();
            let options = WriteOptions {
                max_influences: params.max_influences,
                ..WriteOptions::default()
            };
            // Nothing below reads the input's JSON document: it goes into the output uncopied.
            let glb = skinned_glb_taking_document(
                &mut character,
                &skinned.weights,
                &options,
                &outputs.glb,
            )?;
            plan.write(&outputs.glb, &glb)?;
            timings.insert("write".into(), json!(start.elapsed().as_secs_f64() * 1e3));
            Some(glb)
        } else {
            None
        };

        let input_name = character.path.display().to_string();
        let written = outputs.report.is_some();
        let kept = self.keep_report || outputs.html.is_some();
        let report = (written || kept).then(|| {
            SkinReport::new(
                &input_name,
                &findings,
                &verdict,
                &skinned,
                &timings,
                character.gltf.as_ref(),
            )
        });
        if let (Some(path), Some(report)) = (&outputs.report, &report) {
            // Serialised straight from the report, not through its JSON values.
            let text = report.to_text().map_err(JobError::Report)?;
            plan.write(path, &text)?;
        }
        let report = report.filter(|_| kept).map(|report| report.to_value());
        if let Some(path) = outputs.rig_info.as_ref().filter(|_| write_all) {
            let pruned = skinned.weights.pruned(params.max_influences);
            let text = atlas_skin_io::rig_info::to_text(&skeleton, &pruned, &character.file_vertex);
            plan.write(path, text.as_bytes())?;
        }
        if let Some(path) = outputs.debug_glb.as_ref().filter(|_| write_all) {
            let bytes = debug_view(&skinned, path).map_err(|source| JobError::DebugView {
                path: path.clone(),
                source,
            })?;
            plan.write(path, &bytes)?;
        }
        if let (Some(path), Some(glb)) = (&outputs.html, &glb) {
            write_html(glb, report.as_ref(), path, &plan)?;
        }
        let d = skinned.decomposition.report();
        let destination = match (&glb, rejected) {
            (Some(_), false) => outputs.glb.display().to_string(),
            (Some(_), true) => format!("rejected, kept as {}", outputs.glb.display()),
            (None, _) => "rejected, not written".to_string(),
        };
        let summary = format!(
            "{}: {} vertices, {} joints ({} cut, {} soft, {} skipped), {} regions -> {destination}",
            input_name,
            skinned.counts.stored_vertices,
            skinned.counts.joints,
            d.cuts,
            d.soft,
            d.skipped,
            skinned.decomposition.regions.len(),
        );
        Ok(JobOutcome {
            report,
            method_warnings: skinned.warnings,
            summary,
            kept: glb.filter(|_| rejected).map(|_| outputs.glb.clone()),
            verdict,
        })
    }
}

/// The debug view (a glb): the split surface coloured by region, the cut curves as lines.
fn debug_view(skinned: &Skinned, path: &Path) -> Result<Vec<u8>, IoError> {
    let d = &skinned.decomposition;
    let positions: Vec<Vec3> = d.surface.positions.iter().map(|p| p.as_vec3()).collect();
    let lines: Vec<[Vec3; 2]> = debug_lines(d)
        .iter()
        .map(|[a, b]| [Vec3::from_array(*a), Vec3::from_array(*b)])
        .collect();
    debug_glb(
        &positions,
        &d.surface.triangles,
        &debug_colors(d),
        &lines,
        [0.0, 0.0, 0.0, 1.0],
        path,
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The report is in the outcome only when asked (`keep_report`); written to its file
    /// it is the same report; the glb is the same either way.
    #[test]
    fn the_report_is_built_when_asked_or_written() {
        let input = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../../shared/data/models/riggedsimple/RiggedSimple.glb"
        );
        let dir =
            std::env::temp_dir().join(format!("atlas-skin-job-report-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let run = |name: &str, keep_report: bool, report: bool| {
            let glb = dir.join(format!("{name}.glb"));
            let job = SkinJob {
                input: Input::file(input),
                outputs: Outputs {
                    report: report.then(|| dir.join(format!("{name}.json"))),
                    ..Outputs::glb(&glb)
                },
                keep_report,
                ..SkinJob::default()
            };
            let outcome = job.run(&mut |_| {}).unwrap();
            let written = report.then(|| std::fs::read(dir.join(format!("{name}.json"))).unwrap());
            (outcome.report, std::fs::read(glb).unwrap(), written)
        };
        let (none, glb, _) = run("plain", false, false);
        let (kept, kept_glb, _) = run("kept", true, false);
        let (not_kept, _, written) = run("written", false, true);
        std::fs::remove_dir_all(&dir).unwrap();
        assert!(none.is_none() && not_kept.is_none());
        assert_eq!(glb, kept_glb);
        let kept = kept.expect("kept");
        assert!(kept["counts"]["vertices"].as_u64().is_some_and(|n| n > 0));
        let written: Value = serde_json::from_slice(&written.expect("written")).unwrap();
        assert_eq!(written["counts"], kept["counts"]);
    }
}
