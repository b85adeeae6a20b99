//! Writing an output file safely: never over the input, never half-written.

use crate::IoError;
use std::path::Path;

/// Writes `bytes` to `out` through a temporary file in the same folder that is then renamed
/// into place, so `out` is either complete or untouched; the temporary file is removed on
/// error. A missing output folder is created.
///
/// # Errors
/// [`IoError::WouldOverwriteInput`] when `out` is one of the files `inputs` (same path after
/// resolving links), [`IoError::IsDirectory`] when `out` is a folder, [`IoError::Write`]
/// when the file cannot be written.
pub fn write_atomically<'a>(
    out: &Path,
    inputs: impl IntoIterator<Item = &'a Path>,
    bytes: &[u8],
) -> Result<(), IoError> {
    check_not_input(out, inputs)?;
    if out.is_dir() {
        return Err(IoError::IsDirectory {
            path: out.to_path_buf(),
        });
    }
    let write_error = |cause| IoError::Write {
        path: out.to_path_buf(),
        cause,
    };
    let name = out
        .file_name()
        .ok_or_else(|| write_error(std::io::Error::other("the path has no file name")))?;
    if let Some(folder) = out.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder).map_err(write_error)?;
    }
    let temporary = out.with_file_name(format!(
        ".{}.{}.tmp",
        name.to_string_lossy(),
        std::process::id()
    ));
    let result = std::fs::write(&temporary, bytes).and_then(|()| std::fs::rename(&temporary, out));
    if let Err(source) = result {
        // Best effort: the temporary file may not exist if its creation failed.
        let _ = std::fs::remove_file(&temporary);
        return Err(write_error(source));
    }
    Ok(())
}

/// [`IoError::WouldOverwriteInput`] when `out` is one of the files `inputs`: lets a
/// command refuse an output before it writes any other.
pub fn check_not_input<'a>(
    out: &Path,
    inputs: impl IntoIterator<Item = &'a Path>,
) -> Result<(), IoError> {
    if inputs.into_iter().any(|input| is_same_file(out, input)) {
        return Err(IoError::WouldOverwriteInput {
            path: out.to_path_buf(),
        });
    }
    Ok(())
}

/// True when `a` and `b` name the same file (equal paths, or equal once resolved).
fn is_same_file(a: &Path, b: &Path) -> bool {
    if a == b {
        return true;
    }
    match (a.canonicalize(), b.canonicalize()) {
        (Ok(a), Ok(b)) => a == b,
        _ => false,
    }
}
