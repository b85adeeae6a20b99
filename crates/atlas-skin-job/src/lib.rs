//! The file-skinning job of atlas-skin, shared by the command line (`atlas-skin skin`,
//! `atlas-skin batch`) and the Python package: read a character, skin it, write the skinned
//! glTF binary and its reports ([`job`]); the settings of a job ([`settings`]); the JSON
//! report ([`report`]) and the self-contained HTML report ([`html`]); the quality gate
//! that may reject a result ([`quality`]); many files at once ([`batch`]); weights carried
//! from a skinned character onto other meshes ([`transfer`]).

pub mod batch;
pub mod html;
pub mod job;
pub mod quality;
pub mod report;
pub mod settings;
pub mod transfer;

pub use job::{demo_character, error_chain, Input, JobError, JobOutcome, Outputs, SkinJob};
pub use settings::{Settings, SettingsError};
