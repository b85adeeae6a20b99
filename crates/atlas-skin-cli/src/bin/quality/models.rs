//! The corpus models with reference weights, and the command-line arguments that read them.

use std::ffi::OsString;
use std::path::Path;

/// One model of `shared/data/models` that carries reference weights.
#[derive(Debug, Clone, Copy)]
pub struct Model {
    /// Folder name, as in BASELINES.md.
    pub name: &'static str,
    /// Main input file inside the folder.
    pub input: &'static str,
    pub skeleton: Option<&'static str>,
    pub group: Option<&'static str>,
    /// Weights file for inputs that do not carry them.
    pub weights: Option<&'static str>,
    /// Reference weights pruned to this many per vertex before comparing (BASELINES.md
    /// does so for MakeHuman).
    pub prune_reference: Option<u16>,
    /// The reference weights were computed by an algorithm, not painted by an artist.
    pub precomputed: bool,
}

const fn gltf(name: &'static str, input: &'static str) -> Model {
    Model {
        name,
        input,
        skeleton: None,
        group: None,
        weights: None,
        prune_reference: None,
        precomputed: false,
    }
}

const fn libigl(
    name: &'static str,
    input: &'static str,
    skeleton: &'static str,
    weights: &'static str,
) -> Model {
    Model {
        name,
        input,
        skeleton: Some(skeleton),
        group: None,
        weights: Some(weights),
        prune_reference: None,
        precomputed: true,
    }
}

/// Every model with reference weights, artist-weighted first.
pub const MODELS: [Model; 7] = [
    gltf("cesiumman", "CesiumMan.glb"),
    gltf("riggedfigure", "RiggedFigure.glb"),
    gltf("riggedsimple", "RiggedSimple.glb"),
    Model {
        name: "makehuman",
        input: "base.obj",
        skeleton: Some("default.mhskel"),
        group: Some("body"),
        weights: Some("default_weights.mhw"),
        prune_reference: Some(4),
        precomputed: false,
    },
    gltf("simpleskin", "SimpleSkin.gltf"),
    libigl("arm", "arm.obj", "arm.tgf", "arm-weights.dmat"),
    libigl(
        "elephant",
        "elephant.obj",
        "elephant.tgf",
        "elephant-weights.dmat",
    ),
];

impl Model {
    /// The input file and the options reading it: `INPUT [--skeleton F] [--group G]`,
    /// plus `--weights W` when `with_weights`.
    pub fn input_args(&self, models: &Path, with_weights: bool) -> Vec<OsString> {
        let folder = models.join(self.name);
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
}
