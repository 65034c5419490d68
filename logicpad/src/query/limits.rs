//! The one run policy of a query, as egg's `Runner` has one: [`Limits`]
//! bound every entry point's kanren run (answers, search steps, wall time)
//! and its proofs (nodes, depth); running out is a [`Stopped`] reason on
//! what was [`Found`], never an error, and the answers found before it
//! are kept.

use crate::eval::ProofLimits;
use kanren::StopReason;
use std::time::Duration;

/// The default answer limit of a query: past it the run stops with
/// [`Stopped::Answers`], never allocating without bound.
pub const DEFAULT_MAX_ANSWERS: usize = 100_000;

/// How many times the answer limit a count may reach when it needs no
/// memory per answer (see [`crate::Model::count_limited`]): the limit then
/// bounds time, not memory.
pub const COUNT_FACTOR: usize = 1_000;

/// The bounds of one query's run and its proofs.
///
/// Invariant: `answers ≥ 1` is the caller's to keep (0 stops at once).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Limits {
    /// The most distinct answers a run finds; finding one more stops it
    /// with [`Stopped::Answers`] (a count that stores no answers may reach
    /// [`COUNT_FACTOR`] times as many matches).
    pub answers: usize,
    /// The most kanren search steps (`None`: no limit).
    pub steps: Option<u64>,
    /// The most wall-clock time (`None`: no limit).
    pub time: Option<Duration>,
    /// The most proof nodes for all answers together.
    pub proof_nodes: usize,
    /// The most rule steps deep a proof goes before a derived fact is
    /// shown truncated.
    pub proof_depth: usize,
}

impl Default for Limits {
    fn default() -> Limits {
        Limits {
            answers: DEFAULT_MAX_ANSWERS,
            steps: None,
            time: None,
            proof_nodes: ProofLimits::DEFAULT_MAX_NODES,
            proof_depth: ProofLimits::DEFAULT_MAX_DEPTH,
        }
    }
}

impl Limits {
    /// The kanren budget of a run under these limits.
    pub fn budget(&self) -> kanren::Budget {
        kanren::Budget {
            max_steps: self.steps,
            max_time: self.time,
        }
    }

    /// The proof limits.
    pub fn proofs(&self) -> ProofLimits {
        ProofLimits {
            max_depth: self.proof_depth,
            max_nodes: self.proof_nodes,
        }
    }
}

/// Why a run stopped before it had every answer.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, serde::Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Stopped {
    /// It found more answers than [`Limits::answers`].
    Answers,
    /// It took [`Limits::steps`] search steps.
    Steps,
    /// It ran for [`Limits::time`].
    Time,
}

impl Stopped {
    /// The limit a kanren run stopped at, if it was one of [`Limits`]'.
    pub fn of(reason: Option<StopReason>) -> Option<Stopped> {
        match reason? {
            StopReason::StepBudget => Some(Stopped::Steps),
            StopReason::TimeBudget => Some(Stopped::Time),
            _ => None,
        }
    }

    /// `answers`, `steps` or `time`.
    pub fn as_str(self) -> &'static str {
        match self {
            Stopped::Answers => "answers",
            Stopped::Steps => "steps",
            Stopped::Time => "time",
        }
    }

    /// The limit in words: "the answer limit (100000)", "the time limit
    /// (5 s)".
    pub fn describe(self, limits: &Limits) -> String {
        match self {
            Stopped::Answers => format!("the answer limit ({})", limits.answers),
            Stopped::Steps => match limits.steps {
                Some(n) => format!("the step limit ({n} search steps)"),
                None => "the step limit".to_string(),
            },
            Stopped::Time => match limits.time {
                Some(t) => format!("the time limit ({} s)", t.as_secs_f64()),
                None => "the time limit".to_string(),
            },
        }
    }
}

impl std::fmt::Display for Stopped {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// What a query's run found.
///
/// Invariant: with `stopped` `None` the items are every answer, sorted;
/// with a reason they are the answers found before the run stopped, in
/// the order the search found them (deterministic for a model and
/// limits, so a page of them is stable).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Found<T> {
    /// The answers.
    pub items: Vec<T>,
    /// Why the run stopped early (`None`: it has them all).
    pub stopped: Option<Stopped>,
}
