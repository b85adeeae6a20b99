//! Input options shared by the subcommands that read a character.

use anyhow::{Context, Result};
use atlas_skin::{weld, MeshStats, Topology, Welded};
use atlas_skin_io::{Character, LoadOptions};
use std::path::PathBuf;

/// Where the character comes from.
#[derive(clap::Args, Debug, Clone)]
pub struct InputArgs {
    /// The character: .glb/.gltf/.vrm (mesh and skeleton), or a mesh (.obj, .mesh, .off,
    /// .ply, .stl) with --skeleton.
    pub input: PathBuf,
    /// Skeleton file for a mesh without one: .tgf, .bvh, .mhskel or .json.
    #[arg(long)]
    pub skeleton: Option<PathBuf>,
    /// Use only the faces of this OBJ group (e.g. MakeHuman's `body`).
    #[arg(long)]
    pub group: Option<String>,
    /// Reference weights for a mesh without them: .dmat (libigl) or .mhw (MakeHuman).
    #[arg(long)]
    pub weights: Option<PathBuf>,
}

impl InputArgs {
    pub fn load_options(&self) -> LoadOptions {
        LoadOptions {
            skeleton: self.skeleton.clone(),
            group: self.group.clone(),
            weights: self.weights.clone(),
        }
    }

    /// Reads the character.
    pub fn load(&self) -> Result<Character> {
        atlas_skin_io::load_character(&self.input, &self.load_options())
            .with_context(|| format!("cannot load {}", self.input.display()))
    }
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
        let welded = weld(
            &character.mesh.positions,
            &character.mesh.triangles,
            atlas_skin::weld::DEFAULT_WELD_TOLERANCE,
        );
        let topology = Topology::new(&welded.mesh);
        let stats = MeshStats::new(&welded.mesh, &topology);
        Self {
            character,
            welded,
            topology,
            stats,
        }
    }
}
