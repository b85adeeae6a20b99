//! Writing output files safely: one policy for every command (docs/security.md).
//!
//! - No output may be an input of the same command, nor another of its outputs (paths
//!   compared after resolving links, `..` and `.`).
//! - An existing file at an output path must be a regular file: a folder, device node,
//!   FIFO or socket is refused, never replaced.
//! - Bytes go to a temporary file created exclusively (`O_EXCL`) under a random name in the
//!   output's folder, then renamed over the output: the output is complete or untouched,
//!   and a link planted at the temporary name cannot redirect the write.

use crate::IoError;
use std::collections::hash_map::RandomState;
use std::hash::{BuildHasher, Hasher};
use std::io::Write;
use std::path::{Component, Path, PathBuf};

/// The inputs and outputs of one command, checked together before anything is computed;
/// the only way this project writes a file.
#[derive(Debug)]
pub struct OutputPlan {
    inputs: Vec<(PathBuf, PathBuf)>,
    outputs: Vec<(PathBuf, PathBuf)>,
}

impl OutputPlan {
    /// Checks the `outputs` a command will write against its `inputs` and each other.
    ///
    /// # Errors
    /// [`IoError::WouldOverwriteInput`] when an output is an input,
    /// [`IoError::DuplicateOutput`] when two outputs are one file, [`IoError::IsDirectory`]
    /// or [`IoError::NotARegularFile`] when an output path holds a folder, device, FIFO
    /// or socket.
    pub fn new<'a>(
        inputs: impl IntoIterator<Item = &'a Path>,
        outputs: impl IntoIterator<Item = &'a Path>,
    ) -> Result<Self, IoError> {
        let inputs: Vec<(PathBuf, PathBuf)> = inputs
            .into_iter()
            .map(|p| (p.to_path_buf(), resolve(p)))
            .collect();
        let mut planned: Vec<(PathBuf, PathBuf)> = Vec::new();
        for out in outputs {
            let resolved = resolve(out);
            if let Some((input, _)) = inputs.iter().find(|(_, r)| *r == resolved) {
                return Err(IoError::WouldOverwriteInput {
                    path: out.to_path_buf(),
                    input: input.clone(),
                });
            }
            if let Some((other, _)) = planned.iter().find(|(_, r)| *r == resolved) {
                return Err(IoError::DuplicateOutput {
                    path: out.to_path_buf(),
                    other: other.clone(),
                });
            }
            check_target(out)?;
            planned.push((out.to_path_buf(), resolved));
        }
        Ok(Self {
            inputs,
            outputs: planned,
        })
    }

    /// Writes `bytes` to the planned output `out` (see the module documentation). A missing
    /// output folder is created. On error no file is left at `out` nor beside it.
    ///
    /// # Errors
    /// Those of [`OutputPlan::new`], checked again; [`IoError::Write`] when `out` was not
    /// planned or the file cannot be written.
    pub fn write(&self, out: &Path, bytes: &[u8]) -> Result<(), IoError> {
        let write_error = |cause| IoError::Write {
            path: out.to_path_buf(),
            cause,
        };
        let resolved = resolve(out);
        if !self.outputs.iter().any(|(_, r)| *r == resolved) {
            return Err(write_error(std::io::Error::other(
                "not one of the command's planned outputs",
            )));
        }
        if let Some((input, _)) = self.inputs.iter().find(|(_, r)| *r == resolved) {
            return Err(IoError::WouldOverwriteInput {
                path: out.to_path_buf(),
                input: input.clone(),
            });
        }
        check_target(out)?;
        write_atomically(out, bytes).map_err(write_error)
    }
}

/// Refuses an existing folder, device, FIFO or socket at `out` (links followed).
fn check_target(out: &Path) -> Result<(), IoError> {
    match std::fs::metadata(out) {
        Ok(metadata) if metadata.is_dir() => Err(IoError::IsDirectory {
            path: out.to_path_buf(),
        }),
        Ok(metadata) if !metadata.is_file() => Err(IoError::NotARegularFile {
            path: out.to_path_buf(),
        }),
        _ => Ok(()),
    }
}

/// `path` with links, `.` and `..` resolved as far as it exists: the longest existing
/// ancestor canonicalized, the rest appended with `.` and `..` applied by name.
fn resolve(path: &Path) -> PathBuf {
    let absolute = if path.is_absolute() {
        path.to_path_buf()
    } else {
        std::env::current_dir().unwrap_or_default().join(path)
    };
    let mut existing = absolute.as_path();
    let mut rest: Vec<Component> = Vec::new();
    loop {
        if let Ok(resolved) = existing.canonicalize() {
            let mut out = resolved;
            for component in rest.iter().rev() {
                match component {
                    Component::ParentDir => {
                        out.pop();
                    }
                    Component::CurDir => {}
                    other => out.push(other),
                }
            }
            return out;
        }
        match (existing.parent(), existing.components().next_back()) {
            (Some(parent), Some(last)) => {
                rest.push(last);
                existing = parent;
            }
            _ => return absolute,
        }
    }
}

/// How many random names are tried before giving up (another file at each).
const TEMPORARY_NAME_ATTEMPTS: usize = 16;

/// Writes `bytes` to a new temporary file beside `out` (created exclusively, random name)
/// and renames it to `out`; the temporary file is removed on error.
fn write_atomically(out: &Path, bytes: &[u8]) -> std::io::Result<()> {
    let name = out
        .file_name()
        .ok_or_else(|| std::io::Error::other("the path has no file name"))?;
    if let Some(folder) = out.parent().filter(|f| !f.as_os_str().is_empty()) {
        std::fs::create_dir_all(folder)?;
    }
    let mut attempt = 0;
    let (temporary, mut file) = loop {
        let temporary = out.with_file_name(temporary_name(name, random_u64()));
        match std::fs::OpenOptions::new()
            .write(true)
            .create_new(true)
            .open(&temporary)
        {
            Ok(file) => break (temporary, file),
            Err(e)
                if e.kind() == std::io::ErrorKind::AlreadyExists
                    && attempt + 1 < TEMPORARY_NAME_ATTEMPTS =>
            {
                attempt += 1;
            }
            Err(e) => return Err(e),
        }
    };
    let result = file
        .write_all(bytes)
        .and_then(|()| file.sync_all())
        .and_then(|()| std::fs::rename(&temporary, out));
    if result.is_err() {
        // Best effort: the error being reported matters more than a failed cleanup.
        let _ = std::fs::remove_file(&temporary);
    }
    result
}

/// The name of a temporary file for an output named `name`: `.NAME.<16 hex digits>.tmp`.
fn temporary_name(name: &std::ffi::OsStr, random: u64) -> String {
    format!(".{}.{random:016x}.tmp", name.to_string_lossy())
}

/// Removes the temporary files beside `out` that writes of `out` killed before their
/// rename left behind (named `.NAME.<16 hex digits>.tmp`); returns how many. For a
/// run that resumes killed work; a write of `out` running at the same time would lose its
/// file.
pub fn remove_leftover_temporaries(out: &Path) -> usize {
    let (Some(name), Some(folder)) = (out.file_name(), out.parent()) else {
        return 0;
    };
    let folder = if folder.as_os_str().is_empty() {
        Path::new(".")
    } else {
        folder
    };
    let prefix = format!(".{}.", name.to_string_lossy());
    let Ok(entries) = std::fs::read_dir(folder) else {
        return 0;
    };
    entries
        .flatten()
        .filter(|entry| {
            let file = entry.file_name();
            let file = file.to_string_lossy();
            file.strip_prefix(&prefix)
                .and_then(|rest| rest.strip_suffix(".tmp"))
                .is_some_and(|hex| hex.len() == 16 && hex.bytes().all(|b| b.is_ascii_hexdigit()))
                && entry.file_type().is_ok_and(|t| t.is_file())
        })
        .filter(|entry| std::fs::remove_file(entry.path()).is_ok())
        .count()
}

/// A random number from the standard library's randomly seeded hasher (no dependency).
fn random_u64() -> u64 {
    let mut hasher = RandomState::new().build_hasher();
    hasher.write_u128(
        std::time::SystemTime::now()
            .duration_since(std::time::UNIX_EPOCH)
            .map_or(0, |d| d.as_nanos()),
    );
    hasher.write_u32(std::process::id());
    hasher.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn scratch(test: &str) -> PathBuf {
        let dir = std::env::temp_dir()
            .join(format!("atlas-skin-output-{}", std::process::id()))
            .join(test);
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).unwrap();
        dir
    }

    #[test]
    fn outputs_that_are_inputs_or_each_other_are_refused() {
        let dir = scratch("plan");
        let input = dir.join("in.glb");
        std::fs::write(&input, b"input").unwrap();
        std::os::unix::fs::symlink(&input, dir.join("link.glb")).unwrap();
        let dotted = dir.join("sub/../in.glb");
        for out in [input.clone(), dir.join("link.glb"), dotted] {
            let error = OutputPlan::new([input.as_path()], [out.as_path()]).unwrap_err();
            assert!(
                matches!(error, IoError::WouldOverwriteInput { .. }),
                "{error}"
            );
        }
        let a = dir.join("a.glb");
        let also_a = dir.join("new/../a.glb");
        let error = OutputPlan::new([], [a.as_path(), also_a.as_path()]).unwrap_err();
        assert!(matches!(error, IoError::DuplicateOutput { .. }), "{error}");
        let error = OutputPlan::new([], [dir.as_path()]).unwrap_err();
        assert!(matches!(error, IoError::IsDirectory { .. }), "{error}");
        let error = OutputPlan::new([], [Path::new("/dev/null")]).unwrap_err();
        assert!(matches!(error, IoError::NotARegularFile { .. }), "{error}");
        assert_eq!(std::fs::read(&input).unwrap(), b"input");
    }

    #[test]
    fn writes_replace_the_output_and_leave_nothing_else() {
        let dir = scratch("write");
        let out = dir.join("deeper/out.bin");
        let plan = OutputPlan::new([], [out.as_path()]).unwrap();
        plan.write(&out, b"first").unwrap();
        plan.write(&out, b"second").unwrap();
        assert_eq!(std::fs::read(&out).unwrap(), b"second");
        let names: Vec<_> = std::fs::read_dir(dir.join("deeper"))
            .unwrap()
            .map(|e| e.unwrap().file_name())
            .collect();
        assert_eq!(names, ["out.bin"]);
        let other = dir.join("other.bin");
        assert!(plan.write(&other, b"x").is_err(), "an unplanned output");
        assert!(!other.exists());
    }
}
