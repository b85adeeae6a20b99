//! The runtime's error type: every variant names the offending index and value.

use thiserror::Error;

/// What can be wrong with data handed to the runtime. Validation happens once, at the
/// boundary (constructors and `validate` methods); hot loops trust validated data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum RuntimeError {
    #[error("joint {joint} has parent index {parent}, but the skeleton has {count} joints")]
    ParentOutOfRange {
        joint: usize,
        parent: u32,
        count: usize,
    },
    #[error("the joint hierarchy has a cycle through joint {joint} ({name:?})")]
    Cycle { joint: usize, name: String },
    #[error("skeleton arrays disagree in length: {what}")]
    LengthMismatch { what: String },
    #[error("joint {joint} ({name:?}) has a non-finite or singular bind matrix")]
    BadBindMatrix { joint: usize, name: String },
    #[error("joint {joint} ({name:?}) has a non-finite bone tail")]
    BadTail { joint: usize, name: String },
    #[error("vertex {vertex} refers to joint {joint}, but the skeleton has {count} joints")]
    JointOutOfRange {
        vertex: usize,
        joint: u32,
        count: usize,
    },
    #[error("vertex {vertex} has weight {weight} (weights must be finite and >= 0)")]
    BadWeight { vertex: usize, weight: f32 },
    #[error("buffer sizes disagree: {what}")]
    BufferSize { what: String },
    #[error("palette matrix {joint} has scale {scale} (or shear); dual quaternion skinning needs rigid transforms")]
    NonRigid { joint: usize, scale: f32 },
    #[error("palette matrix {joint} is not finite")]
    NonFinitePalette { joint: usize },
    #[error(
        "palette matrix {joint} has bottom row {row:?}, not (0, 0, 0, 1): not an affine transform"
    )]
    ProjectivePalette { joint: usize, row: [f32; 4] },
    #[error("rig node {node} ({name:?}): {what}")]
    BadRig {
        node: usize,
        name: String,
        what: String,
    },
    #[error("animation {clip:?}, track {track} (node {node}): {what}")]
    BadTrack {
        clip: String,
        track: usize,
        node: u32,
        what: String,
    },
    #[error("vertex {vertex} has no influence with a positive weight")]
    UnweightedVertex { vertex: usize },
    #[error(
        "the skin has {influences} influences per vertex; quantised weights hold at most {max}"
    )]
    TooManyQuantisedInfluences { influences: usize, max: usize },
    #[error("the skeleton has {count} joints; compact skins index at most 65536")]
    TooManyJoints { count: usize },
    #[error("no joint name in common between the motion (joints like {source_joint:?}) and the character (joints like {target_joint:?})")]
    NoCommonJoints {
        source_joint: String,
        target_joint: String,
    },
    #[error(
        "instruction set {name:?} is unknown or not supported by this CPU (portable, avx2, avx512)"
    )]
    UnsupportedInstructionSet { name: String },
    #[error("the joint map names {name:?}, which is not a joint of the {rig}")]
    UnknownMappedJoint { name: String, rig: &'static str },
}
