//! One module per subcommand, each with its `Args` and `run`.

pub mod animate;
pub mod batch;
pub mod bench;
pub mod demo;
pub mod eval;
pub mod inspect;
pub mod pose;
pub mod report;
pub mod skin;
pub mod transfer;
