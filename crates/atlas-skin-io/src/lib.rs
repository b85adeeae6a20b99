//! File formats for atlas-skin.
//!
//! Readers turn a file (or a mesh plus a skeleton file) into a [`Character`]: the mesh as
//! stored (vertices are never welded or reordered here), the skeleton in bind space, and the
//! artist weights when the file has them. The glTF writer puts new weights into a copy of
//! the input document, or builds a new document for other inputs.
//!
//! Units and axes stay as in the file, except FBX's, which are converted to glTF's.

pub mod bvh;
pub mod character;
pub mod dmat;
pub mod error;
pub mod fbx;
pub mod fuzz_input;
pub mod gltf;
pub mod load;
pub mod medit;
pub mod mhskel;
pub mod mhw;
mod names;
pub mod obj;
pub mod off;
pub mod output;
pub mod ply;
pub mod rig_info;
pub mod skeleton_json;
pub mod stl;
mod text;
pub mod tgf;

pub use character::{
    Character, Contents, LoadOptions, Material, MeshPart, PartBinding, TriangleMesh,
};
pub use error::IoError;
pub use load::{load_character, load_character_with};
pub use output::{remove_leftover_temporaries, OutputPlan};
