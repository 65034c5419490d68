//! # logicrag-fuzz — every parser of the workspace, fuzzed on stable Rust
//!
//! cargo-fuzz needs a nightly compiler; this harness needs none. It has
//! two engines, both deterministic from a seed, and a supervisor that
//! catches what `catch_unwind` cannot:
//!
//! - [`targets`]: one [`targets::Target`] per parser — FOL, queries,
//!   LogicPad YAML, text facts, query TSV files, KITTI labels and calib,
//!   JSON tracks, scenarios (YAML, JSON), fact configs (YAML, JSON), model
//!   configs, camera calibrations, the English question translator, CSV
//!   question files, language-model replies, source arguments — each a
//!   `fn(&[u8])` calling the real entry point and, when the parsed value is
//!   small, the code that consumes it.
//! - [`corpus`]: the seeds — small valid files under `fuzz/corpus/<target>/`,
//!   the project's built-in inputs, and the hostile inputs of issue 13
//!   (12-atom queries, `frames: 1000000`, 2,000 objects in a frame, 10,000
//!   chained `==>`, …) generated rather than committed.
//! - [`mutate`]: byte and token mutations of seeds.
//! - [`generate`]: proptest strategies for each grammar, sampled by a
//!   seeded `TestRunner` outside `#[test]`.
//! - [`worker`]: runs a target's inputs in a child process, each written to
//!   a file first; [`worker::input_for`] makes input `i` a pure function of
//!   `(seed, target, i)`.
//! - [`supervisor`]: spawns workers under `prlimit --as`, kills one that
//!   exceeds the per-input time limit, classifies every death (panic,
//!   abort, stack overflow, memory, timeout), saves the culprit under
//!   `fuzz/artifacts/<target>/` and restarts after it; its
//!   [`supervisor::Report`] is the run's summary.
//!
//! `docs/fuzzing.md` describes the commands and the last one-hour run.
#![forbid(unsafe_code)]

pub mod corpus;
pub mod generate;
pub mod mutate;
pub mod rng;
pub mod supervisor;
pub mod targets;
pub mod worker;

use std::path::PathBuf;

/// Errors of the harness itself (never of a target: those are failures in
/// the report).
#[derive(Debug, thiserror::Error)]
pub enum FuzzError {
    /// Occurs when a corpus, work or artifact file cannot be read or written.
    #[error("{}: {source}", path.display())]
    Io {
        /// The file or folder.
        path: PathBuf,
        /// The I/O error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when a target's corpus folder holds no seed.
    #[error("no seed for target `{target}` in {}", dir.display())]
    EmptyCorpus {
        /// The target.
        target: String,
        /// Its corpus folder.
        dir: PathBuf,
    },
    /// Occurs when `--targets` names a target that does not exist.
    #[error("unknown target `{name}` (targets: {known})")]
    UnknownTarget {
        /// The name given.
        name: String,
        /// The targets, comma-separated.
        known: String,
    },
    /// Occurs when the worker process cannot be started or waited for.
    #[error("cannot run the worker {}: {source}", exe.display())]
    Spawn {
        /// The executable.
        exe: PathBuf,
        /// The error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when a worker fails before it runs any input (a broken
    /// harness, not a parser bug).
    #[error("worker for `{target}` failed: {message}")]
    Worker {
        /// The target.
        target: String,
        /// What went wrong.
        message: String,
    },
}

/// The targets named in a comma-separated list (`fol,query`); all of them
/// for an empty list.
pub fn select_targets(list: &str) -> Result<Vec<&'static targets::Target>, FuzzError> {
    if list.trim().is_empty() {
        return Ok(targets::ALL.iter().collect());
    }
    list.split(',')
        .map(str::trim)
        .filter(|n| !n.is_empty())
        .map(|n| {
            targets::find(n).ok_or_else(|| FuzzError::UnknownTarget {
                name: n.to_string(),
                known: targets::ALL
                    .iter()
                    .map(|t| t.name)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
        })
        .collect()
}
