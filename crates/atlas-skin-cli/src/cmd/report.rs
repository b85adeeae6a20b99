//! `atlas-skin report`: the self-contained HTML report of a skinned glTF binary (see
//! [`atlas_skin_job::html`]).

use anyhow::Context;
use atlas_skin_io::OutputPlan;
use std::path::{Path, PathBuf};

use atlas_skin_job::html::write_html;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    /// A skinned character: a glTF binary (.glb), for example the output of `atlas-skin
    /// skin`, or any input with weights (e.g. .fbx).
    pub input: PathBuf,
    /// Skinning report JSON (`atlas-skin skin --report R.json`) shown in the side panel.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// A BVH motion to play in the viewer, retargeted onto the character by joint names (as
    /// `atlas-skin animate`) and embedded as a glTF animation.
    #[arg(long, value_name = "FILE")]
    pub bvh: Option<PathBuf>,
    /// JSON object pairing character joints (keys) with BVH joints (values) whose names
    /// differ, with --bvh.
    #[arg(long, value_name = "MAP.json", requires = "bvh")]
    pub joint_map: Option<PathBuf>,
    /// The HTML file to write.
    #[arg(short, long, value_name = "REPORT.html")]
    pub output: PathBuf,
}

pub fn run(args: Args) -> anyhow::Result<()> {
    let inputs = [Some(&args.input), args.report.as_ref(), args.bvh.as_ref()]
        .into_iter()
        .chain([args.joint_map.as_ref()])
        .flatten()
        .map(PathBuf::as_path);
    let plan = OutputPlan::new(inputs, [args.output.as_path()])?;
    let glb = match &args.bvh {
        Some(bvh) => {
            crate::cmd::animate::animate_glb_bytes(&args.input, bvh, args.joint_map.as_deref())
                .with_context(|| format!("putting the motion {} on the character", bvh.display()))?
        }
        None => crate::cmd::animate::skinned_glb_bytes(&args.input)?,
    };
    let report = args.report.as_deref().map(read_report).transpose()?;
    write_html(&glb, report.as_ref(), &args.output, &plan)
        .with_context(|| format!("writing the report of {}", args.input.display()))
}

fn read_report(path: &Path) -> anyhow::Result<serde_json::Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not valid JSON", path.display()))
}
