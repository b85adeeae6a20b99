//! Any reader fed with raw bytes through a scratch file: what the fuzz targets (`fuzz/`,
//! `scripts/fuzz`) run, and what the regression test replaying their corpora and crash
//! inputs under the stable toolchain runs (`tests/fuzz_corpus.rs`).

use crate::IoError;
use atlas_skin_runtime::Skeleton;
use glam::Vec3;
use std::path::{Path, PathBuf};

/// One reader of this crate: the fuzz target of the same name.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    Gltf,
    Obj,
    Ply,
    Stl,
    Off,
    Medit,
    Bvh,
    Tgf,
    Mhskel,
    SkeletonJson,
    Dmat,
    Mhw,
    Fbx,
    RigInfo,
}

impl Format {
    /// Every reader.
    pub const ALL: [Format; 14] = [
        Self::Gltf,
        Self::Obj,
        Self::Ply,
        Self::Stl,
        Self::Off,
        Self::Medit,
        Self::Bvh,
        Self::Tgf,
        Self::Mhskel,
        Self::SkeletonJson,
        Self::Dmat,
        Self::Mhw,
        Self::Fbx,
        Self::RigInfo,
    ];

    /// The fuzz target's name (and its corpus folder's).
    pub fn name(self) -> &'static str {
        self.names().0
    }

    /// The target's name and the scratch file's extension (a `.gltf` may hold a binary
    /// glTF: the content decides).
    fn names(self) -> (&'static str, &'static str) {
        match self {
            Self::Gltf => ("gltf", "gltf"),
            Self::Obj => ("obj", "obj"),
            Self::Ply => ("ply", "ply"),
            Self::Stl => ("stl", "stl"),
            Self::Off => ("off", "off"),
            Self::Medit => ("medit", "mesh"),
            Self::Bvh => ("bvh", "bvh"),
            Self::Tgf => ("tgf", "tgf"),
            Self::Mhskel => ("mhskel", "mhskel"),
            Self::SkeletonJson => ("skeleton_json", "json"),
            Self::Dmat => ("dmat", "dmat"),
            Self::Mhw => ("mhw", "mhw"),
            Self::Fbx => ("fbx", "fbx"),
            Self::RigInfo => ("rig_info", "txt"),
        }
    }
}

/// Mesh vertices the readers that index a mesh are given (`mhskel` heads and tails, `mhw`
/// rows, `rig_info` skin lines).
const MAKEHUMAN_VERTICES: usize = 64;

/// The folder of `format`'s scratch file for this process: empty but for that file, so a
/// glTF `uri` finds nothing else to read.
pub fn scratch_folder(format: Format) -> PathBuf {
    std::env::temp_dir().join(format!(
        "atlas-skin-fuzz-{}-{}",
        std::process::id(),
        format.name()
    ))
}

/// Writes `bytes` to the scratch file of `format` and reads it with that reader. The
/// result is what the reader said; a panic is the bug a fuzzer looks for.
///
/// # Errors
/// The reader's error, or an [`IoError::Write`] when the scratch file cannot be written.
pub fn read_bytes(format: Format, bytes: &[u8]) -> Result<(), IoError> {
    let folder = scratch_folder(format);
    let path = folder.join(format!("input.{}", format.names().1));
    std::fs::create_dir_all(&folder)
        .and_then(|()| std::fs::write(&path, bytes))
        .map_err(|cause| IoError::Write {
            path: path.clone(),
            cause,
        })?;
    read_file(format, &path)
}

/// Reads the file at `path` with the reader of `format`.
fn read_file(format: Format, path: &Path) -> Result<(), IoError> {
    let positions: Vec<Vec3> = (0..MAKEHUMAN_VERTICES)
        .map(|i| Vec3::new(i as f32, (i % 7) as f32, (i % 3) as f32))
        .collect();
    match format {
        Format::Gltf => crate::gltf::read(path).map(drop),
        Format::Obj => crate::obj::read(path, None).map(drop),
        Format::Ply => crate::ply::read(path).map(drop),
        Format::Stl => crate::stl::read(path).map(drop),
        Format::Off => crate::off::read(path).map(drop),
        Format::Medit => crate::medit::read(path).map(drop),
        Format::Bvh => crate::bvh::read_motion(path).map(drop),
        Format::Tgf => crate::tgf::read(path).map(drop),
        Format::Mhskel => crate::mhskel::read(path, &positions).map(drop),
        Format::SkeletonJson => crate::skeleton_json::read(path).map(drop),
        Format::Dmat => crate::dmat::read(path).map(drop),
        Format::Mhw => {
            let names = ["root", "spine", "head"].map(String::from).to_vec();
            let skeleton = Skeleton::new(
                names,
                vec![atlas_skin_runtime::NO_PARENT, 0, 1],
                vec![glam::Mat4::IDENTITY; 3],
            )
            .map_err(|cause| IoError::Skeleton {
                path: path.to_path_buf(),
                cause,
            })?;
            crate::mhw::read(path, &skeleton, MAKEHUMAN_VERTICES).map(drop)
        }
        Format::Fbx => crate::fbx::read(path).map(drop),
        Format::RigInfo => crate::rig_info::read(path, MAKEHUMAN_VERTICES).map(drop),
    }
}
