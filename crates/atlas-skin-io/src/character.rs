//! What every reader produces.

use atlas_skin_runtime::{Clip, Rig, Skeleton, VertexWeights};
use glam::Vec3;
use std::path::PathBuf;

/// A triangle mesh exactly as stored in the file (after polygon triangulation).
///
/// - `positions`: #V bind-space vertex positions, in the file's units and axes.
/// - `triangles`: #F vertex index triples into `positions`, all in range.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct TriangleMesh {
    pub positions: Vec<Vec3>,
    pub triangles: Vec<[u32; 3]>,
}

/// A character read from disk.
#[derive(Debug, Clone)]
pub struct Character {
    /// The main input file (the mesh, or the glTF document).
    pub path: PathBuf,
    /// The mesh as stored. For glTF, the triangle primitives of the skinned meshes
    /// concatenated in document order.
    pub mesh: TriangleMesh,
    /// The skeleton in the mesh's bind space, if the input has one.
    pub skeleton: Option<Skeleton>,
    /// Weights that came with the input (artist or precomputed), per stored vertex, joint
    /// indices into `skeleton`. Rows are as stored: they may not sum to 1.
    pub reference_weights: Option<VertexWeights>,
    /// The node hierarchy animations drive (glTF nodes, or the joints of a skeleton file).
    pub rig: Option<Rig>,
    /// Animations in the input, tracks on `rig`'s nodes.
    pub clips: Vec<Clip>,
    /// Warnings about quirks of the input that were handled.
    pub warnings: Vec<String>,
}

/// How to read an input.
#[derive(Debug, Clone, Default)]
pub struct LoadOptions {
    /// A skeleton file (TGF, BVH, MakeHuman .mhskel, JSON) for inputs without one.
    pub skeleton: Option<PathBuf>,
    /// Only the faces of this OBJ group (e.g. MakeHuman's `body`).
    pub group: Option<String>,
    /// A weights file (libigl .dmat, MakeHuman .mhw) to use as reference weights.
    pub weights: Option<PathBuf>,
}

impl Character {
    /// A character with a mesh and nothing else; readers fill in the rest.
    pub fn new(path: impl Into<PathBuf>, mesh: TriangleMesh) -> Self {
        Self {
            path: path.into(),
            mesh,
            skeleton: None,
            reference_weights: None,
            rig: None,
            clips: Vec::new(),
            warnings: Vec::new(),
        }
    }
}
