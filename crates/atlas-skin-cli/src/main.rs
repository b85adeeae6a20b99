//! `atlas-skin`: automatic character skinning from the command line.

mod cmd;
mod counts;
mod input;
mod quality_gate;
mod skinning_data;

use clap::{Parser, Subcommand};
use std::process::ExitCode;

/// Skins a character automatically: cuts the mesh into regions at the joints, overlaps them
/// along the surface, turns the overlaps into smooth weights and writes a skinned glTF.
#[derive(Parser)]
#[command(name = "atlas-skin", version, about, long_about = None)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Print what was read from a character: mesh facts, the joint tree, warnings.
    Inspect(cmd::inspect::Args),
    /// Compute skinning weights and write a skinned glTF binary (the main job).
    Skin(cmd::skin::Args),
    /// Skin many characters at once: files, folders, globs, to OUTDIR/<name>.glb.
    Batch(cmd::batch::Args),
    /// Write the project's own demo character (a closed humanoid with its skeleton).
    Demo(cmd::demo::Args),
    /// Pose a skinned character and write the deformed mesh.
    Pose(cmd::pose::Args),
    /// Put a BVH motion on a skinned character as a glTF animation.
    Animate(cmd::animate::Args),
    /// Time linear blend and dual quaternion skinning on this machine.
    Bench(cmd::bench::Args),
    /// Compare candidate weights with reference (artist) weights.
    Eval(cmd::eval::Args),
    /// Write a self-contained HTML report with an interactive 3D view.
    Report(cmd::report::Args),
    /// Carry a skinned character's weights onto clothes, hair and props (or re-weight
    /// some of its meshes from the others).
    Transfer(cmd::transfer::Args),
}

/// Makes the main thread one of the global thread pool's workers (the pool starts one
/// thread fewer). Without it every parallel loop of the method was handed from the main
/// thread to a worker and the main thread slept until it ended: on cesiumman (3.3k
/// vertices) about 300 context switches per run, 25 with it, and with one thread
/// (`RAYON_NUM_THREADS=1`) no thread is started at all. A pool that already exists (never
/// the case here) is kept.
fn join_the_thread_pool() {
    let _ = rayon::ThreadPoolBuilder::new()
        .use_current_thread()
        .build_global();
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    join_the_thread_pool();
    let result = match cli.command {
        Command::Inspect(args) => cmd::inspect::run(args),
        Command::Skin(args) => cmd::skin::run(args),
        Command::Batch(args) => cmd::batch::run(args),
        Command::Demo(args) => cmd::demo::run(args),
        Command::Pose(args) => cmd::pose::run(args),
        Command::Animate(args) => cmd::animate::run(args),
        Command::Bench(args) => cmd::bench::run(args),
        Command::Eval(args) => cmd::eval::run(args),
        Command::Report(args) => cmd::report::run(args),
        Command::Transfer(args) => cmd::transfer::run(args),
    };
    match result {
        Ok(()) => ExitCode::SUCCESS,
        Err(error) => {
            eprintln!("error: {error:#}");
            match error.downcast_ref::<quality_gate::Rejected>() {
                Some(_) => ExitCode::from(quality_gate::EXIT_REJECTED),
                None => ExitCode::FAILURE,
            }
        }
    }
}
