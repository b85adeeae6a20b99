//! Rust errors as Python exceptions, with the message the command line prints: a missing
//! input file raises `FileNotFoundError`, any other bad input `ValueError`; a panic (a bug)
//! is caught before it reaches Python and raised as `RuntimeError`. A character the
//! quality gate rejects raises `QualityGateError`.

use atlas_skin_io::IoError;
use atlas_skin_job::quality::Verdict;
use atlas_skin_job::transfer::TransferJobError;
use atlas_skin_job::{error_chain, JobError, SettingsError};
use pyo3::exceptions::{PyException, PyFileNotFoundError, PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

pyo3::create_exception!(
    atlas_skin,
    QualityGateError,
    PyException,
    "The quality gate (``fail_on``) rejected the character: ``reasons`` (list of str, \
     ``CONDITION: cause``), ``report`` (the JSON report as a dict, its ``quality`` \
     holding the verdict), ``output`` (the skinned glb kept under its rejected name, or \
     None)."
);

/// The `QualityGateError` of a character named `what` that `verdict` rejects.
pub fn rejected(
    py: Python<'_>,
    what: &str,
    verdict: &Verdict,
    report: Bound<'_, PyAny>,
    output: Option<&Path>,
) -> PyErr {
    let error = QualityGateError::new_err(format!(
        "the quality gate rejected {what}: {}",
        verdict.reasons.join("; ")
    ));
    let value = error.value(py);
    let output = output.map(|p| p.display().to_string());
    let set = value
        .setattr("reasons", verdict.reasons.clone())
        .and_then(|()| value.setattr("report", report))
        .and_then(|()| value.setattr("output", output));
    match set {
        Ok(()) => error,
        Err(e) => e,
    }
}

/// `error` as a Python exception (see the module documentation).
pub fn to_py_err(error: &JobError) -> PyErr {
    let missing = match error {
        JobError::Io(io) => io_missing(io),
        JobError::Settings(SettingsError::Read { source, .. }) => {
            source.kind() == std::io::ErrorKind::NotFound
        }
        _ => false,
    };
    raise(error, missing)
}

/// A transfer job's `error` as a Python exception (see the module documentation).
pub fn transfer_to_py_err(error: &TransferJobError) -> PyErr {
    let missing = matches!(error, TransferJobError::Io(io) if io_missing(io));
    raise(error, missing)
}

/// Whether `error` is a file that is not there.
fn io_missing(error: &IoError) -> bool {
    matches!(error, IoError::Read { cause, .. } if cause.kind() == std::io::ErrorKind::NotFound)
}

/// `FileNotFoundError` when `missing`, else `ValueError`, with `error`'s chain.
fn raise(error: &dyn std::error::Error, missing: bool) -> PyErr {
    let message = error_chain(error);
    if missing {
        PyFileNotFoundError::new_err(message)
    } else {
        PyValueError::new_err(message)
    }
}

/// Runs `work`, turning a panic into an error: no unwinding crosses into Python.
pub fn no_panic<T>(work: impl FnOnce() -> Result<T, PyErr>) -> Result<T, PyErr> {
    catch_unwind(AssertUnwindSafe(work)).unwrap_or_else(|payload| {
        let what = payload
            .downcast_ref::<String>()
            .map(String::as_str)
            .or_else(|| payload.downcast_ref::<&str>().copied())
            .unwrap_or("unknown panic");
        Err(PyRuntimeError::new_err(format!(
            "atlas-skin internal error (a bug, please report it): {what}"
        )))
    })
}
