//! The runtime's error type: every variant names the offending index and value.

use thiserror::Error;

/// What can be wrong with data handed to the runtime. Validation happens once, at the
/// boundary (constructors and `validate` methods); hot loops trust validated data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RuntimeError {
    #[error("joint {joint} has parent index {parent}, but the skeleton has {count} joints")]
    ParentOutOfRange { joint: usize, parent: u32, count: usize },
    #[error("the joint hierarchy has a cycle through joint {joint} ({name:?})")]
    Cycle { joint: usize, name: String },
    #[error("skeleton arrays disagree in length: {what}")]
    LengthMismatch { what: String },
    #[error("joint {joint} ({name:?}) has a non-finite or singular bind matrix")]
    BadBindMatrix { joint: usize, name: String },
    #[error("vertex {vertex} refers to joint {joint}, but the skeleton has {count} joints")]
    JointOutOfRange { vertex: usize, joint: u32, count: usize },
    #[error("vertex {vertex} has weight {weight} (weights must be finite and >= 0)")]
    BadWeight { vertex: usize, weight: f32 },
    #[error("buffer sizes disagree: {what}")]
    BufferSize { what: String },
    #[error("joint {joint} ({name:?}) has scale {scale} in its skinning matrix; dual quaternion skinning needs rigid transforms")]
    NonRigid { joint: usize, name: String, scale: f32 },
}
