//! `atlas-skin skin`: the main job. Reads a character, computes its weights (cuts at the
//! joints, regions, geodesic overlaps, blended weights: [`atlas_skin::pipeline::skin`]) and
//! writes a skinned glTF binary, with an optional JSON report, debug view and HTML report
//! (the job itself: [`atlas_skin_job::SkinJob`], shared with `batch` and the Python package).

use crate::input::InputArgs;
use crate::quality_gate::{GateArgs, Rejected};
use anyhow::{bail, Context, Result};
use atlas_skin::weights::blend::Blend;
use atlas_skin::weights::rigid::Binding;
use atlas_skin_job::{Outputs, Settings, SkinJob};
use indicatif::{ProgressBar, ProgressStyle};
use std::io::IsTerminal;
use std::path::PathBuf;
use std::time::Duration;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    #[command(flatten)]
    pub input: InputArgs,
    /// The skinned glTF binary to write.
    #[arg(short, long, value_name = "OUT.glb")]
    pub output: PathBuf,
    /// Write a JSON report: decomposition, overlap widths, timings, counts, warnings.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    #[command(flatten)]
    pub method: MethodArgs,
    #[command(flatten)]
    pub gate: GateArgs,
    /// Write an unskinned glb with the regions as vertex colours and the cut curves.
    #[arg(long, value_name = "D.glb")]
    pub debug_glb: Option<PathBuf>,
    /// Write a self-contained HTML report with an interactive view of the result.
    #[arg(long, value_name = "R.html")]
    pub html: Option<PathBuf>,
    /// Also write the weights (as in the glb: the largest --max-influences, renormalised)
    /// and the skeleton in RigNet's rig_info text format; `skin` lines number the vertices
    /// as the mesh file does (OBJ order).
    #[arg(long, value_name = "OUT.txt")]
    pub rig_info: Option<PathBuf>,
}

/// The method's settings, shared by `skin` and `batch`.
#[derive(clap::Args)]
pub struct MethodArgs {
    /// Settings as JSON (any subset of `decompose`, `overlap` {`factor`, `per_joint`},
    /// `blend`, `binding`, `max_influences`, and the quality gate's `fail_on`); the options
    /// below override it.
    #[arg(long, value_name = "FILE.json")]
    pub config: Option<PathBuf>,
    /// Overlap half-width as a multiple of each boundary's diameter (the paper: 0.5).
    #[arg(long, value_name = "F")]
    pub overlap: Option<f64>,
    /// Overlap factor for one joint, repeatable: from quasi-rigid (small) to soft (large).
    #[arg(long = "overlap-joint", value_name = "NAME=F")]
    pub overlap_joint: Vec<String>,
    /// How overlapping regions are blended: the normalised partition of unity (default)
    /// or the paper's Eq. 1.
    #[arg(long, value_enum)]
    pub blend: Option<BlendArg>,
    /// Blended weights (default), or one joint per vertex for a character its artist would
    /// bind rigidly: the same cuts, each vertex moving with the deepest joint whose branch
    /// holds more than half of its blended weights.
    #[arg(long, value_enum)]
    pub binding: Option<BindingArg>,
    /// Give this joint a boundary even where the rules would not, also one named as a
    /// helper that otherwise moves no skin (repeatable).
    #[arg(long, value_name = "JOINT")]
    pub force: Vec<String>,
    /// Give this joint no boundary: its part moves with its parent's (repeatable).
    #[arg(long, value_name = "JOINT")]
    pub forbid: Vec<String>,
    /// Influences kept per vertex (the largest, renormalised).
    #[arg(long, value_name = "N",
          value_parser = crate::counts::count_between(1, crate::counts::MAX_INFLUENCES))]
    pub max_influences: Option<usize>,
}

/// `--blend` values.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum BlendArg {
    /// Normalised partition of unity: continuous everywhere.
    Pou,
    /// The paper's Eq. 1.
    Paper,
}

impl From<BlendArg> for Blend {
    fn from(arg: BlendArg) -> Self {
        match arg {
            BlendArg::Pou => Blend::PartitionOfUnity,
            BlendArg::Paper => Blend::Paper,
        }
    }
}

/// `--binding` values.
#[derive(Debug, Clone, Copy, clap::ValueEnum)]
pub enum BindingArg {
    /// Blended weights: a vertex may follow several joints.
    Smooth,
    /// One joint per vertex, with weight 1.
    Rigid,
}

impl From<BindingArg> for Binding {
    fn from(arg: BindingArg) -> Self {
        match arg {
            BindingArg::Smooth => Binding::Smooth,
            BindingArg::Rigid => Binding::Rigid,
        }
    }
}

impl MethodArgs {
    /// The job's settings, with the gate's conditions; `--overlap-joint` entries parsed.
    pub fn settings(&self, gate: &GateArgs) -> Result<Settings> {
        let mut overlap_joints = Vec::new();
        for entry in &self.overlap_joint {
            let Some((name, value)) = entry.rsplit_once('=') else {
                bail!("--overlap-joint {entry:?}: expected NAME=F");
            };
            let factor: f64 = value
                .parse()
                .with_context(|| format!("--overlap-joint {entry:?}: {value:?} is not a number"))?;
            overlap_joints.push((name.to_string(), factor));
        }
        Ok(Settings {
            config: self.config.clone(),
            overlap: self.overlap,
            overlap_joints,
            blend: self.blend.map(Blend::from),
            binding: self.binding.map(Binding::from),
            force: self.force.clone(),
            forbid: self.forbid.clone(),
            max_influences: self.max_influences,
            fail_on: gate.fail_on.clone(),
        })
    }
}

pub fn run(args: Args) -> Result<()> {
    let job = SkinJob {
        input: args.input.job_input(),
        settings: args.method.settings(&args.gate)?,
        outputs: Outputs {
            glb: args.output,
            report: args.report,
            html: args.html,
            debug_glb: args.debug_glb,
            rig_info: args.rig_info,
        },
        keep_report: false,
        keep_rejected: args.gate.keep_rejected,
    };
    let progress = progress_bar();
    let outcome = job.run(&mut |step| progress.set_message(step));
    progress.finish_and_clear();
    let outcome = outcome?;
    for warning in &outcome.method_warnings {
        eprintln!("warning: {warning}");
    }
    println!("{}", outcome.summary);
    if outcome.verdict.rejected() {
        return Err(Rejected(format!(
            "the quality gate rejected the character: {}",
            outcome.verdict.reasons.join("; ")
        ))
        .into());
    }
    Ok(())
}

/// A spinner with the current stage on stderr, hidden when stderr is not a terminal.
pub(crate) fn progress_bar() -> ProgressBar {
    if !std::io::stderr().is_terminal() {
        return ProgressBar::hidden();
    }
    let bar = ProgressBar::new_spinner();
    bar.set_style(
        ProgressStyle::with_template("{spinner} {elapsed} {msg}")
            .unwrap_or_else(|_| ProgressStyle::default_spinner()),
    );
    bar.enable_steady_tick(Duration::from_millis(100));
    bar
}
