//! File formats for atlas-skin.
//!
//! Readers turn a file (or a mesh plus a skeleton file) into a [`Character`]: the mesh as
//! stored (vertices are never welded or reordered here), the skeleton in bind space, and the
//! artist weights when the file has them. The glTF writer puts new weights into a copy of
//! the input document, or builds a new document for other inputs.
//!
//! Units and axes stay as in the file.

pub mod character;
pub mod error;
pub mod load;

pub use character::{Character, LoadOptions, TriangleMesh};
pub use error::IoError;
pub use load::load_character;
