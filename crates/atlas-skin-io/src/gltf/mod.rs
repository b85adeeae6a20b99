//! glTF 2.0 (`.gltf` with embedded or external buffers, `.glb`) and VRM (a `.glb`):
//! reading a [`Character`](crate::Character) and writing skinned or debug binaries.
//!
//! The document is kept as raw JSON ([`serde_json::Value`]) with its buffers, so that the
//! writer can replace the skin weights in a copy that preserves everything else
//! (materials, textures, animations, names, extras, extensions).

mod accessor;
mod added_meshes;
mod animation;
mod bindings;
mod budget;
mod builder;
mod container;
mod debug;
mod document;
mod file_access;
mod new_document;
mod nodes;
mod prune;
mod read;
mod rewrite;
mod view_span;
mod write;

pub use added_meshes::{with_added_meshes, AddedMesh};
pub use bindings::Binding;
pub use budget::{DECODED_FLOOR_BYTES, DECODED_PER_INPUT_BYTE, MAX_DECODED_BYTES};
pub use container::{ImageBytes, MAX_LOADED_BYTES};
pub use debug::debug_glb;
pub use read::{read, read_contents};
pub use write::{
    skinned_glb, skinned_glb_taking_document, write_skinned_glb, WriteOptions, MAX_INFLUENCES,
};

use serde_json::Value;
use std::ops::Range;

/// What a character read from glTF keeps of its source, for the writer.
///
/// - `document`: the whole JSON document, untouched.
/// - `buffers`: the bytes of every buffer, in `document.buffers` order.
/// - `images`: the bytes of every image given by `uri`, in `document.images` order; `None`
///   for images in a bufferView and for those the reader left out (with a warning).
/// - `skin`: the skin whose joints are the character's skeleton, if any.
/// - `inverse_binds_cleaned`: the skin's inverse bind matrices were projective and the
///   skeleton holds affine ones (the writer then writes the skeleton's).
/// - `primitives`: every primitive read into `Character::mesh`, in mesh order.
#[derive(Clone)]
pub struct GltfSource {
    pub document: Value,
    pub buffers: Vec<Vec<u8>>,
    pub images: Vec<Option<ImageBytes>>,
    pub skin: Option<usize>,
    pub inverse_binds_cleaned: bool,
    pub primitives: Vec<PrimitiveSource>,
}

impl std::fmt::Debug for GltfSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GltfSource")
            .field(
                "buffer_bytes",
                &self.buffers.iter().map(Vec::len).collect::<Vec<_>>(),
            )
            .field("skin", &self.skin)
            .field("primitives", &self.primitives)
            .finish_non_exhaustive()
    }
}

/// Where a primitive of the document went in `Character::mesh`.
///
/// - `mesh`, `primitive`: its index in `meshes` and in that mesh's `primitives`.
/// - `node`: the node instantiating the mesh (the first one, for a skinned mesh).
/// - `binding`: how its vertices follow the skeleton (the writer replaces the weights of
///   skinned primitives only; rigid ones stay children of their joint node).
/// - `position_accessor`: its POSITION accessor; primitives sharing it share `vertices`.
/// - `vertices`: its vertices' range in `Character::mesh.positions` (all the accessor's
///   vertices, in accessor order).
/// - `triangles`: its triangles' range in `Character::mesh.triangles`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PrimitiveSource {
    pub mesh: usize,
    pub primitive: usize,
    pub node: usize,
    pub binding: Binding,
    pub position_accessor: usize,
    pub vertices: Range<usize>,
    pub triangles: Range<usize>,
}
