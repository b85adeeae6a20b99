//! The quality gate's flags, shared by `skin` and `batch` (`--fail-on LIST`,
//! `--keep-rejected`; the gate itself: [`atlas_skin_job::quality`]), and the exit code of
//! a rejected character.

use atlas_skin_job::quality::Condition;
use clap::builder::{PossibleValue, PossibleValuesParser, TypedValueParser};
use std::fmt;

/// The exit code when the quality gate rejects the character (`skin`) or a file of a
/// batch of which none failed (`batch`): apart from 1 (an error) and 2 (a usage error).
pub const EXIT_REJECTED: u8 = 3;

/// The flags of the quality gate.
#[derive(clap::Args)]
pub struct GateArgs {
    /// Refuse a character on these conditions (comma-separated or repeated): the exit code
    /// is 3 (`batch`: when no file failed; a batch record says `rejected` with the
    /// reasons), the reasons go to stderr and to the JSON report's `quality`, the outputs
    /// are not written but the JSON report, as NAME.rejected.json; an earlier run's
    /// outputs under either name are removed. Overrides the settings file's `fail_on`.
    #[arg(long, value_name = "LIST", value_delimiter = ',', value_parser = conditions())]
    pub fail_on: Vec<Condition>,
    /// Write a rejected character's outputs anyway, each with `.rejected` before its
    /// extension (OUT.rejected.glb), never under the name of an accepted one.
    #[arg(long)]
    pub keep_rejected: bool,
}

/// `--fail-on` values: the gate's conditions, each with what it refuses in `--help`.
fn conditions() -> impl TypedValueParser<Value = Condition> {
    PossibleValuesParser::new(
        Condition::ALL.map(|c| PossibleValue::new(c.name()).help(c.description())),
    )
    .try_map(|name| name.parse::<Condition>())
}

/// A command whose character (or one of whose files) the gate rejected: `main` exits
/// with [`EXIT_REJECTED`].
#[derive(Debug)]
pub struct Rejected(pub String);

impl fmt::Display for Rejected {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.0)
    }
}

impl std::error::Error for Rejected {}
