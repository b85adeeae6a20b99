//! The development tools of atlas-skin that measure it on real characters as a user would
//! (`atlas-skin skin`, then `atlas-skin eval`, as processes): `quality` writes
//! docs/quality.md from the clean corpus, `benchmark` writes docs/benchmark.md from the
//! benchmark characters (and the corpus). This library holds what both share: the baseline
//! tables, the process runner, the scoring. Errors are `anyhow` reports, as in a command-line
//! tool: every one ends as a message on the terminal or in a failed row.

pub mod baselines;
pub mod bench_baselines;
pub mod bench_characters;
pub mod bench_compare;
pub mod bench_page;
pub mod bench_run;
pub mod computed_baselines;
pub mod gltf_skins;
pub mod group_scores;
pub mod rigid_binding;
pub mod run;
pub mod scoring;
pub mod single_joint;
pub mod stats;
pub mod transfer_peers;
pub mod transfer_split;
