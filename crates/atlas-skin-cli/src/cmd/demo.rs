//! `atlas-skin demo`: write the project's own demo character.

use anyhow::{Context, Result};
use atlas_skin::skeleton::bones::nearest_bone_weights;
use atlas_skin_io::gltf::{skinned_glb, WriteOptions};
use atlas_skin_io::OutputPlan;
use atlas_skin_job::demo_character;
use std::path::PathBuf;

/// Writes DIR/demo.glb: the built-in demo character (a closed, genus-0 humanoid with hands,
/// fingers and feet, 35 joints, metres, Y up), the same one `skin`, `inspect` and the other
/// subcommands use when no INPUT is given. Its skin binds every vertex to the nearest bone, a
/// placeholder that `atlas-skin skin DIR/demo.glb` replaces.
#[derive(clap::Args)]
pub struct Args {
    /// Output folder (created if missing).
    #[arg(short, long, default_value = ".")]
    pub out: PathBuf,
}

pub fn run(args: Args) -> Result<()> {
    let character = demo_character();
    let skeleton = character
        .skeleton
        .as_ref()
        .context("the demo character has a skeleton")?;
    let positions: Vec<_> = character
        .mesh
        .positions
        .iter()
        .map(|p| p.as_dvec3())
        .collect();
    let weights = nearest_bone_weights(&positions, skeleton);
    let path = args.out.join("demo.glb");
    let plan = OutputPlan::new([], [path.as_path()])?;
    let glb = skinned_glb(&character, &weights, &WriteOptions::default(), &path)?;
    plan.write(&path, &glb)?;
    println!(
        "wrote {} ({} vertices, {} triangles, {} joints)",
        path.display(),
        character.mesh.positions.len(),
        character.mesh.triangles.len(),
        skeleton.len()
    );
    Ok(())
}
