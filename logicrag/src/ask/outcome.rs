//! What an ask gives and takes: the four [`Outcome`]s, the window's
//! [`AskResult`] and the [`AskOptions`].

use super::*;

/// The four outcomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// At least one binding satisfies the query; each comes with a proof.
    Yes,
    /// No binding does, and the source observes everything the query needs.
    No,
    /// No binding was found, but the query needs something this source
    /// cannot observe, or its run stopped at a limit before it could
    /// decide ([`AskResult::stopped`]), so "no" would be a guess.
    Unknown,
    /// The query does not fit the LogicPad (syntax, unknown predicate, arity,
    /// undeclared value, unsafe negation).
    Invalid,
}

impl Outcome {
    /// `"yes"`, `"no"`, `"unknown"` or `"invalid"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Yes => "yes",
            Outcome::No => "no",
            Outcome::Unknown => "unknown",
            Outcome::Invalid => "invalid",
        }
    }
    /// All outcomes, in display order.
    pub const ALL: [Outcome; 4] = [
        Outcome::Yes,
        Outcome::No,
        Outcome::Unknown,
        Outcome::Invalid,
    ];
}

/// The answer to one query on one window.
#[derive(Debug, Clone, Serialize)]
pub struct AskResult {
    /// Window id.
    pub window: String,
    /// The window's first frame.
    pub first_frame: u32,
    /// The window's last frame.
    pub last_frame: u32,
    /// The query as run.
    pub query: String,
    /// The outcome.
    pub answer: Outcome,
    /// The query's answer variables, in order (empty for a ground query or
    /// one that did not parse).
    pub variables: Vec<String>,
    /// Number of distinct bindings of the answer variables.
    pub count: usize,
    /// Bindings, sorted (each a list of `(variable, constant)`).
    pub bindings: Vec<Vec<(String, String)>>,
    /// One proof per binding: a tree per query literal, down to observed
    /// facts with their provenance (empty when proofs were not asked for).
    pub proofs: Vec<Vec<crate::proof::ProofNode>>,
    /// For `no`: the best candidates and what they fail.
    pub why_not: Vec<WhyNot>,
    /// For `unknown`: which predicates the source cannot observe, and why;
    /// for `invalid`: each diagnostic as one sentence ("unknown predicate
    /// `Levitates` (did you mean …)").
    pub reasons: Vec<String>,
    /// For `invalid`: the diagnostics, with code, line and column.
    pub diagnostics: Vec<Problem>,
    /// What else the answer rests on, in words: a constant the window does
    /// not contain ("car_3 is not seen in frames 20–29"), how a universal
    /// held (for every one of N objects, or vacuously).
    pub notes: Vec<String>,
    /// The limit the run behind the answer stopped at (`answers`, `steps`,
    /// `time`), when it did: a yes then lists the bindings found before it
    /// (in the order found), `count` is a lower bound, and an answer that
    /// needed the rest is `unknown`. `None`: the answer is complete.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub stopped: Option<logicpad::Stopped>,
    /// For `yes` and `no`: the probability that the answer is right, from
    /// the probabilities of the facts it rests on ([`crate::belief`]); 1
    /// for a certain source. `None` for `unknown`, `invalid`, and a
    /// count-only ask.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub probability: Option<f64>,
    /// The probability of each binding's proof, in the order of
    /// `bindings`; empty when every binding is certain.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub binding_probabilities: Vec<f64>,
    /// For an answer read by its flips (a no, a count, a list): the
    /// uncertain facts whose flip alone would change it, likeliest first.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub hinges: Vec<crate::belief::Hinge>,
}

/// How to ask.
#[derive(Debug, Clone, Copy)]
pub struct AskOptions {
    /// Record and render proofs.
    pub proofs: bool,
    /// Compute why-not explanations for "no".
    pub why_not: bool,
    /// Only count the bindings (batch answers); implies no proofs.
    pub count_only: bool,
    /// The one run policy: answers, search steps, time, proof nodes and
    /// depth (`--max-answers`, `--proof-depth`, serve's `--query-time`).
    /// It reaches every run behind the answer (the query, a universal's
    /// parts, the why-not checks, the re-asks behind its probability);
    /// running out is the answer's [`AskResult::stopped`], with what was
    /// found, never `invalid`.
    pub limits: logicpad::Limits,
}

impl Default for AskOptions {
    fn default() -> Self {
        AskOptions {
            proofs: true,
            why_not: true,
            count_only: false,
            limits: DEFAULT_LIMITS,
        }
    }
}

impl AskOptions {
    /// Bindings without proofs or why-not.
    pub const BINDINGS: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: false,
        limits: DEFAULT_LIMITS,
    };
    /// Counts only (the KB benchmark's answers).
    pub const COUNT: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: true,
        limits: DEFAULT_LIMITS,
    };
}

/// [`logicpad::Limits::default`], as a constant.
const DEFAULT_LIMITS: logicpad::Limits = logicpad::Limits {
    answers: logicpad::DEFAULT_MAX_ANSWERS,
    steps: None,
    time: None,
    proof_nodes: logicpad::ProofLimits::DEFAULT_MAX_NODES,
    proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
};
