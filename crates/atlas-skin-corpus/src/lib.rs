//! Test support shared by the workspace's integration tests and the `quality` tool: the
//! characters of `../shared/data` (one table: input, skeleton, group, weights, kind of
//! reference) and the node checkers of `tests/js`.
//!
//! Everything that reads the corpus or runs node panics with a message naming what is
//! missing and how to get it: tests never skip.

mod damage;
mod js;
mod model;

pub use damage::damaged_copies;
pub use js::{node_check, node_json};
pub use model::{
    find, Model, Reference, ARM, CESIUMMAN, ELEPHANT, HAND, MAKEHUMAN, MODELS, RIGGEDFIGURE,
    RIGGEDSIMPLE, SIMPLESKIN,
};

use std::path::{Path, PathBuf};

/// `shared/data`, the corpus beside the repository.
const DATA: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/../../../shared/data");

/// The corpus folder `../shared/data` (`models/`, `motion/`, BASELINES.md); panics when
/// it is missing.
pub fn data_dir() -> PathBuf {
    let dir = Path::new(DATA);
    assert!(
        dir.join("models").is_dir(),
        "the corpus is missing: {} (tests never skip)",
        dir.display()
    );
    dir.to_path_buf()
}

/// `../shared/data/models`, one folder per model; panics when it is missing.
pub fn models_dir() -> PathBuf {
    data_dir().join("models")
}

/// The file `relative` of `../shared/data` (e.g. `fbx/KayKit_Knight.fbx`); panics when it
/// is missing.
pub fn data_file(relative: &str) -> PathBuf {
    let path = data_dir().join(relative);
    assert!(
        path.is_file(),
        "corpus file {} is missing (tests never skip)",
        path.display()
    );
    path
}

/// The motion clip `file` of `../shared/data/motion` (e.g. `walk.bvh`); panics when it is
/// missing.
pub fn motion_path(file: &str) -> PathBuf {
    let path = data_dir().join("motion").join(file);
    assert!(path.is_file(), "motion file {} is missing", path.display());
    path
}
