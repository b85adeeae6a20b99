//! What every reader produces.

use atlas_skin_runtime::{Clip, Rig, Skeleton, VertexWeights};
use glam::Vec3;
use std::ops::Range;
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

impl TriangleMesh {
    /// The mesh without the vertices no triangle uses, in file order, and the file index of
    /// every kept vertex (#kept).
    pub fn without_unused_vertices(&self) -> (TriangleMesh, Vec<u32>) {
        let mut used = vec![false; self.positions.len()];
        for t in &self.triangles {
            for &v in t {
                used[v as usize] = true;
            }
        }
        let file_vertex: Vec<u32> = (0..self.positions.len() as u32)
            .filter(|&v| used[v as usize])
            .collect();
        let mut kept_of_file = vec![u32::MAX; self.positions.len()];
        for (kept, &v) in file_vertex.iter().enumerate() {
            kept_of_file[v as usize] = kept as u32;
        }
        let mesh = TriangleMesh {
            positions: file_vertex
                .iter()
                .map(|&v| self.positions[v as usize])
                .collect(),
            triangles: self
                .triangles
                .iter()
                .map(|t| t.map(|v| kept_of_file[v as usize]))
                .collect(),
        };
        (mesh, file_vertex)
    }
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
    /// #V: index of each mesh vertex in the file's own vertex list. For OBJ, MEDIT, OFF,
    /// PLY and STL the loader drops vertices no kept triangle uses; this maps back, e.g. for
    /// MakeHuman files that index base.obj's full vertex list. Identity for glTF.
    pub file_vertex: Vec<u32>,
    /// Joints that only mark where a bone ends and move nothing: the leaves of a TGF
    /// skeleton (libigl's skinning handles are the bone edges, so a leaf point is never
    /// one). The skin command gives them no boundary.
    pub end_joints: Vec<u32>,
    /// The meshes of an input that holds several (FBX), in `mesh` order; empty for the
    /// other formats.
    pub parts: Vec<MeshPart>,
    /// Surface colours of an input that has materials (FBX), and the material of every
    /// triangle (`None`: no material); both empty when the input has none. The glTF writer
    /// makes one primitive per material.
    pub materials: Vec<Material>,
    pub triangle_materials: Vec<Option<u32>>,
    /// How the reader converted units and axes (FBX: to glTF's metres, +Y up); `None` when
    /// they stay as in the file.
    pub space: Option<String>,
    /// For glTF input: the source document, its buffers and where each primitive went in
    /// `mesh` (what the glTF writer needs to preserve the document).
    pub gltf: Option<crate::gltf::GltfSource>,
}

/// One mesh of a multi-mesh input and where it went in [`Character::mesh`].
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct MeshPart {
    pub name: String,
    pub vertices: Range<usize>,
    pub triangles: Range<usize>,
    pub binding: PartBinding,
}

/// A material's base colour, linear RGBA in [0, 1] (glTF's `baseColorFactor`).
#[derive(Debug, Clone, PartialEq)]
pub struct Material {
    pub name: String,
    pub base_color: [f32; 4],
}

/// How a part moves with the skeleton in the file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum PartBinding {
    /// Deformed by the skin: its reference weights are the file's.
    Skinned,
    /// A rigid mesh under joint `joint` in the node tree (or in the skeleton's tree but
    /// under no joint: on the root joint, with a warning): weight 1 on that joint.
    Rigid { joint: u32 },
    /// A mesh of an input without a skeleton, placed as in the file.
    Unbound,
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

/// What a reader decodes of a glTF or FBX input besides its meshes, skeleton and node rig.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Contents {
    /// Also the stored weights ([`Character::reference_weights`]) and the animations'
    /// keys ([`Character::clips`]), each checked.
    #[default]
    Everything,
    /// What skinning needs: all but the stored weights, which `atlas-skin skin` replaces
    /// (glTF: their accessors are not decoded; FBX: the clusters' vertices and weights are
    /// not turned into rows; so bad values there do not stop it). The animations' keys are
    /// read and checked as for [`Contents::Everything`]: the skinned file copies them, and
    /// a bad key would make it invalid. FBX bind matrices are read and checked either way.
    ForSkinning,
}

impl Character {
    /// A character with a mesh and nothing else; readers fill in the rest.
    pub fn new(path: impl Into<PathBuf>, mesh: TriangleMesh) -> Self {
        let file_vertex = (0..mesh.positions.len() as u32).collect();
        Self {
            path: path.into(),
            mesh,
            skeleton: None,
            reference_weights: None,
            rig: None,
            clips: Vec::new(),
            warnings: Vec::new(),
            file_vertex,
            end_joints: Vec::new(),
            parts: Vec::new(),
            materials: Vec::new(),
            triangle_materials: Vec::new(),
            space: None,
            gltf: None,
        }
    }
}
