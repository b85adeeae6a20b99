//! The file formats' error type: every variant names the file and what is wrong with it.

use atlas_skin_runtime::RuntimeError;
use std::path::PathBuf;
use thiserror::Error;

/// Causes are part of the message (fields named `cause`, not error sources), so a chain
/// printer such as anyhow's `{:#}` shows each once.
#[derive(Debug, Error)]
pub enum IoError {
    #[error("{}: cannot read: {cause}", path.display())]
    Read {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("{}: cannot write: {cause}", path.display())]
    Write {
        path: PathBuf,
        cause: std::io::Error,
    },
    #[error("{}: is a directory, not a file", path.display())]
    IsDirectory { path: PathBuf },
    #[error("{}: not a regular file (a device, FIFO or socket)", path.display())]
    NotARegularFile { path: PathBuf },
    #[error("{}: the file is empty", path.display())]
    Empty { path: PathBuf },
    #[error("{}: unsupported file type {extension:?} (expected {expected})", path.display())]
    UnsupportedFormat {
        path: PathBuf,
        extension: String,
        expected: &'static str,
    },
    /// A problem at a known line of a text file (1-based).
    #[error("{}:{line}: {message}", path.display())]
    Syntax {
        path: PathBuf,
        line: usize,
        message: String,
    },
    /// A problem with the content of a file that is not tied to one line.
    #[error("{}: {message}", path.display())]
    Invalid { path: PathBuf, message: String },
    #[error("{}: invalid skeleton: {cause}", path.display())]
    Skeleton { path: PathBuf, cause: RuntimeError },
    #[error("{}: refusing to write over the input file {}", path.display(), input.display())]
    WouldOverwriteInput { path: PathBuf, input: PathBuf },
    #[error("{}: the same file as the output {}: one command cannot write it twice", path.display(), other.display())]
    DuplicateOutput { path: PathBuf, other: PathBuf },
}

impl IoError {
    /// Shorthand for [`IoError::Invalid`].
    pub fn invalid(path: impl Into<PathBuf>, message: impl Into<String>) -> Self {
        Self::Invalid {
            path: path.into(),
            message: message.into(),
        }
    }

    /// Shorthand for [`IoError::Syntax`].
    pub fn syntax(path: impl Into<PathBuf>, line: usize, message: impl Into<String>) -> Self {
        Self::Syntax {
            path: path.into(),
            line,
            message: message.into(),
        }
    }
}
