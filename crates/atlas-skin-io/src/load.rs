//! Reading a character from any supported input (dispatch on the file extension).

use crate::{Character, IoError, LoadOptions};
use std::path::Path;

/// Reads the character at `path` with `options`.
pub fn load_character(path: &Path, _options: &LoadOptions) -> Result<Character, IoError> {
    Err(IoError::invalid(path, "no reader yet"))
}
