//! The table of corpus models: which files make each character and what its reference
//! weights are (shared/data/README.md).

use atlas_skin_io::LoadOptions;
use serde_json::Value;
use std::ffi::OsString;
use std::path::{Path, PathBuf};

/// Where a model's reference weights come from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Reference {
    /// Painted by an artist (stored in the glTF file, or MakeHuman's .mhw).
    Artist,
    /// Computed by an algorithm and shipped with the data (libigl's .dmat).
    Precomputed,
    /// The model has no weights.
    None,
}

/// One model of `shared/data/models`: the files that make the character and its reference.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Model {
    /// Folder name, as in BASELINES.md.
    pub name: &'static str,
    /// Main input file inside the folder.
    pub input: &'static str,
    /// Skeleton file for inputs that do not carry one.
    pub skeleton: Option<&'static str>,
    /// The OBJ group holding the character (the rest is helper geometry).
    pub group: Option<&'static str>,
    /// Weights file for inputs that do not carry their weights.
    pub weights: Option<&'static str>,
    /// Where the reference weights come from.
    pub reference: Reference,
    /// Reference weights pruned to this many per vertex before comparing (BASELINES.md
    /// does so for MakeHuman).
    pub prune_reference: Option<u16>,
}

/// A glTF file: skeleton and artist weights inside.
const fn gltf(name: &'static str, input: &'static str) -> Model {
    Model {
        name,
        input,
        skeleton: None,
        group: None,
        weights: None,
        reference: Reference::Artist,
        prune_reference: None,
    }
}

/// libigl tutorial data: a mesh, a TGF skeleton and precomputed weights if any.
const fn libigl(
    name: &'static str,
    input: &'static str,
    skeleton: &'static str,
    weights: Option<&'static str>,
) -> Model {
    Model {
        name,
        input,
        skeleton: Some(skeleton),
        group: None,
        weights,
        reference: match weights {
            Some(_) => Reference::Precomputed,
            None => Reference::None,
        },
        prune_reference: None,
    }
}

pub const CESIUMMAN: Model = gltf("cesiumman", "CesiumMan.glb");
pub const RIGGEDFIGURE: Model = gltf("riggedfigure", "RiggedFigure.glb");
pub const RIGGEDSIMPLE: Model = gltf("riggedsimple", "RiggedSimple.glb");
pub const SIMPLESKIN: Model = gltf("simpleskin", "SimpleSkin.gltf");
pub const MAKEHUMAN: Model = Model {
    name: "makehuman",
    input: "base.obj",
    skeleton: Some("default.mhskel"),
    group: Some("body"),
    weights: Some("default_weights.mhw"),
    reference: Reference::Artist,
    prune_reference: Some(4),
};
pub const ARM: Model = libigl("arm", "arm.obj", "arm.tgf", Some("arm-weights.dmat"));
pub const ELEPHANT: Model = libigl(
    "elephant",
    "elephant.obj",
    "elephant.tgf",
    Some("elephant-weights.dmat"),
);
pub const HAND: Model = libigl("hand", "hand.mesh", "hand.tgf", None);

/// Every model of the corpus: artist-weighted first, then precomputed, then unweighted.
pub const MODELS: [Model; 8] = [
    CESIUMMAN,
    RIGGEDFIGURE,
    RIGGEDSIMPLE,
    MAKEHUMAN,
    SIMPLESKIN,
    ARM,
    ELEPHANT,
    HAND,
];

/// The model whose folder is `name`.
pub fn find(name: &str) -> Option<&'static Model> {
    MODELS.iter().find(|m| m.name == name)
}

impl Model {
    /// The model's folder under `models` (the corpus's `models/` folder).
    pub fn folder_in(&self, models: &Path) -> PathBuf {
        models.join(self.name)
    }

    /// The model's folder in `../shared/data/models`; panics when it is missing.
    pub fn folder(&self) -> PathBuf {
        let folder = self.folder_in(&crate::models_dir());
        assert!(
            folder.is_dir(),
            "the corpus is missing: {}",
            folder.display()
        );
        folder
    }

    /// The input is a glTF file (`.glb` or `.gltf`), skeleton and weights inside.
    pub fn is_gltf(&self) -> bool {
        self.input.ends_with(".glb") || self.input.ends_with(".gltf")
    }

    /// The main input file in `../shared/data/models`.
    pub fn input_path(&self) -> PathBuf {
        self.folder().join(self.input)
    }

    /// The input in the command-line form of `atlas-skin`, files under `models` (the
    /// corpus's `models/` folder): `INPUT [--skeleton F] [--group G]`, plus `--weights W`
    /// when `with_weights`.
    pub fn input_args_in(&self, models: &Path, with_weights: bool) -> Vec<OsString> {
        self.args_of(&self.folder_in(models), with_weights)
    }

    /// [`Model::input_args_in`] of `../shared/data/models`.
    pub fn input_args(&self, with_weights: bool) -> Vec<OsString> {
        self.args_of(&self.folder(), with_weights)
    }

    /// The options that read the input the way [`Model::input_args_in`] names it.
    pub fn load_options_in(&self, models: &Path, with_weights: bool) -> LoadOptions {
        self.options_of(&self.folder_in(models), with_weights)
    }

    /// [`Model::load_options_in`] of `../shared/data/models`.
    pub fn load_options(&self, with_weights: bool) -> LoadOptions {
        self.options_of(&self.folder(), with_weights)
    }

    /// The model's manifest.json (counts, joints, weights summary; shared/data/README.md).
    pub fn manifest(&self) -> Value {
        let path = self.folder().join("manifest.json");
        let text = std::fs::read_to_string(&path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        serde_json::from_str(&text)
            .unwrap_or_else(|e| panic!("{} is not JSON: {e}", path.display()))
    }

    fn args_of(&self, folder: &Path, with_weights: bool) -> Vec<OsString> {
        let mut args = vec![folder.join(self.input).into_os_string()];
        if let Some(skeleton) = self.skeleton {
            args.extend(["--skeleton".into(), folder.join(skeleton).into_os_string()]);
        }
        if let Some(group) = self.group {
            args.extend(["--group".into(), group.into()]);
        }
        if let (true, Some(weights)) = (with_weights, self.weights) {
            args.extend(["--weights".into(), folder.join(weights).into_os_string()]);
        }
        args
    }

    fn options_of(&self, folder: &Path, with_weights: bool) -> LoadOptions {
        LoadOptions {
            skeleton: self.skeleton.map(|s| folder.join(s)),
            group: self.group.map(String::from),
            weights: self
                .weights
                .filter(|_| with_weights)
                .map(|w| folder.join(w)),
        }
    }
}
