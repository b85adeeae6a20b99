//! `atlas-skin transfer`: carries the weights of a skinned character (SOURCE) onto meshes
//! placed in its rest space (clothes, hair, props) by closest point matching and weight
//! inpainting (Abdrashitov et al. 2023: [`atlas_skin::transfer`]), and writes one skinned
//! glTF binary with the source's skeleton and meshes plus the targets; or, with
//! `--meshes`, re-weights named meshes of the source from its other meshes. The job
//! itself: [`atlas_skin_job::transfer::TransferJob`], shared with the Python package.

use crate::input::ReadArgs;
use anyhow::Result;
use atlas_skin::transfer::TransferParams;
use atlas_skin_job::transfer::TransferJob;
use atlas_skin_job::{Input, Outputs};
use std::path::PathBuf;

/// Arguments.
#[derive(clap::Args)]
pub struct Args {
    /// The skinned character weights are taken from (.glb/.gltf/.vrm, .fbx, or a mesh with
    /// --skeleton and --weights).
    pub source: PathBuf,
    /// Meshes in the source's rest space to weight (.glb/.gltf/.vrm, .fbx, .obj, .ply,
    /// .stl, .off, .mesh): each is added to the output as one skinned mesh.
    pub targets: Vec<PathBuf>,
    #[command(flatten)]
    pub read: ReadArgs,
    /// Instead of targets: re-weight these meshes of the source (glTF mesh or node names,
    /// FBX mesh names) from its other meshes.
    #[arg(long, num_args = 1.., value_name = "NAME")]
    pub meshes: Vec<String>,
    /// The skinned glTF binary to write.
    #[arg(short, long, value_name = "OUT.glb")]
    pub output: PathBuf,
    /// Write a JSON report: per target, vertices matched, inpainted and bound to the
    /// nearest point, its pieces, how every vertex got its weights; timings; warnings.
    #[arg(long, value_name = "R.json")]
    pub report: Option<PathBuf>,
    /// Write a self-contained HTML report with an interactive view of the result.
    #[arg(long, value_name = "R.html")]
    pub html: Option<PathBuf>,
    /// Influences kept per vertex (the largest, renormalised).
    #[arg(long, value_name = "N", default_value_t = 4,
          value_parser = crate::counts::count_between(1, crate::counts::MAX_INFLUENCES))]
    pub max_influences: usize,
    /// Matching distance, as a fraction of the source's bounding-box diagonal.
    #[arg(long, value_name = "F", default_value_t = TransferParams::default().distance)]
    pub distance: f64,
    /// Matching angle between normals, in degrees.
    #[arg(long, value_name = "DEG", default_value_t = TransferParams::default().angle_degrees)]
    pub angle: f64,
    /// Also match where a target vertex's normal points against the source's (a
    /// single-sided garment wound the other way); by default refused: such a vertex faces
    /// the source across a gap.
    #[arg(long)]
    pub flipped_normals: bool,
    /// Rounds of smoothing near the inpainted vertices (0: none).
    #[arg(long, value_name = "N", default_value_t = TransferParams::default().smooth_iterations,
          value_parser = crate::counts::count_between(0, 10_000))]
    pub smooth: usize,
    /// Smoothing strength per round, 0 to 1.
    #[arg(long, value_name = "A", default_value_t = TransferParams::default().smooth_alpha)]
    pub smooth_alpha: f64,
}

pub fn run(args: Args) -> Result<()> {
    let job = TransferJob {
        source: Input {
            path: Some(args.source),
            load: args.read.load_options(),
        },
        targets: args.targets,
        meshes: args.meshes,
        params: TransferParams {
            distance: args.distance,
            angle_degrees: args.angle,
            flipped_normals: args.flipped_normals,
            smooth_iterations: args.smooth,
            smooth_alpha: args.smooth_alpha,
        },
        max_influences: args.max_influences,
        outputs: Outputs {
            glb: args.output,
            report: args.report,
            html: args.html,
            ..Outputs::default()
        },
        keep_report: false,
    };
    let progress = super::skin::progress_bar();
    let outcome = job.run(&mut |step| progress.set_message(step.to_owned()));
    progress.finish_and_clear();
    let outcome = outcome?;
    for warning in &outcome.warnings {
        eprintln!("warning: {warning}");
    }
    println!("{}", outcome.summary);
    Ok(())
}
