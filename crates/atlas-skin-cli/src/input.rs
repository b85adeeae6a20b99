//! Input options shared by the subcommands that read a character.

use anyhow::{Context, Result};
use atlas_skin::pipeline::{skin, SkinInput, SkinParams, WeldedSurface};
use atlas_skin::{MeshStats, Topology, Welded};
use atlas_skin_io::{Character, LoadOptions};
use std::path::{Path, PathBuf};

/// How to read a character's files, besides its main file.
#[derive(clap::Args, Debug, Clone, Default)]
pub struct ReadArgs {
    /// Skeleton file for a mesh without one: .tgf, .bvh, .mhskel, .json, or RigNet's
    /// rig_info X_rig.txt (whose skin lines also give reference weights).
    #[arg(long)]
    pub skeleton: Option<PathBuf>,
    /// Use only the faces of this OBJ group (e.g. MakeHuman's `body`).
    #[arg(long)]
    pub group: Option<String>,
    /// Reference weights for a mesh without them: .dmat (libigl) or .mhw (MakeHuman).
    #[arg(long)]
    pub weights: Option<PathBuf>,
}

impl ReadArgs {
    /// The files these options name (skeleton, weights).
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        [&self.skeleton, &self.weights]
            .into_iter()
            .filter_map(|p| p.as_deref())
    }

    pub fn load_options(&self) -> LoadOptions {
        LoadOptions {
            skeleton: self.skeleton.clone(),
            group: self.group.clone(),
            weights: self.weights.clone(),
        }
    }
}

/// Where the character comes from.
#[derive(clap::Args, Debug, Clone)]
pub struct InputArgs {
    /// The character: .glb/.gltf/.vrm or .fbx (mesh and skeleton), or a mesh (.obj, .mesh,
    /// .off, .ply, .stl) with --skeleton. Without it: the built-in demo character.
    pub input: Option<PathBuf>,
    #[command(flatten)]
    pub read: ReadArgs,
}

impl InputArgs {
    /// Every file read: the input and the files of [`ReadArgs`].
    pub fn paths(&self) -> impl Iterator<Item = &Path> {
        self.input.as_deref().into_iter().chain(self.read.paths())
    }

    /// Reads the character, or builds the demo character when no input is given.
    pub fn load(&self) -> Result<Character> {
        // The reader's errors name the file already.
        Ok(self.job_input().load()?)
    }

    /// The input as the skinning job takes it.
    pub fn job_input(&self) -> atlas_skin_job::Input {
        atlas_skin_job::Input {
            path: self.input.clone(),
            load: self.read.load_options(),
        }
    }

    /// As [`InputArgs::load`], with the demo character skinned by the method
    /// ([`skin_character`]): what the commands that deform a character (`pose`, `animate`,
    /// `bench`) read. A given input keeps its own weights (or lack of them).
    pub fn load_skinned(&self) -> Result<Character> {
        let mut character = self.load()?;
        if self.input.is_none() {
            skin_character(&mut character)?;
        }
        Ok(character)
    }
}

/// Sets `character`'s weights to those the method computes with its default settings
/// ([`atlas_skin::pipeline::skin`], as `atlas-skin skin` without options).
pub fn skin_character(character: &mut Character) -> Result<()> {
    let skeleton = character
        .skeleton
        .as_ref()
        .with_context(|| format!("{} has no skeleton", character.path.display()))?;
    let skinned = skin(
        SkinInput {
            positions: &character.mesh.positions,
            triangles: &character.mesh.triangles,
            skeleton,
            end_joints: &character.end_joints,
        },
        &SkinParams::default(),
        &mut |_| {},
    )
    .with_context(|| format!("cannot skin {}", character.path.display()))?;
    character.reference_weights = Some(skinned.weights);
    Ok(())
}

/// A character with its welded surface and topology, ready for the method.
pub struct Prepared {
    pub character: Character,
    pub welded: Welded,
    pub topology: Topology,
    pub stats: MeshStats,
}

impl Prepared {
    pub fn new(character: Character) -> Self {
        let WeldedSurface { welded, topology } =
            WeldedSurface::new(&character.mesh.positions, &character.mesh.triangles);
        let stats = MeshStats::new(&welded.mesh, &topology);
        Self {
            character,
            welded,
            topology,
            stats,
        }
    }
}
