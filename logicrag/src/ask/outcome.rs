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
    /// cannot observe, so "no" would be a guess.
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
    /// For `invalid`: the answer budget the query exceeded, when that is
    /// why (its first answers can still be listed lazily).
    #[serde(skip_serializing_if = "Option::is_none")]
    pub too_large: Option<usize>,
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
    /// The most bindings a query may have before it is refused as too
    /// large (`--max-answers`).
    pub max_answers: usize,
    /// How many rule steps deep proofs go before a derived fact is shown
    /// as truncated (`--proof-depth`): output costs what is rendered.
    pub proof_depth: usize,
    /// The most time the query's join may take (`None`: no limit). Past
    /// it the answer is `invalid`, saying the time budget ran out; a
    /// server sets it so that one request cannot hold a worker for long.
    pub max_time: Option<std::time::Duration>,
}

impl Default for AskOptions {
    fn default() -> Self {
        AskOptions {
            proofs: true,
            why_not: true,
            count_only: false,
            max_answers: logicpad::DEFAULT_MAX_ANSWERS,
            proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
            max_time: None,
        }
    }
}

impl AskOptions {
    /// The proof limits these options ask for.
    pub(crate) fn proof_limits(&self) -> logicpad::ProofLimits {
        logicpad::ProofLimits {
            max_depth: self.proof_depth,
            ..logicpad::ProofLimits::default()
        }
    }

    /// Bindings without proofs or why-not.
    pub const BINDINGS: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: false,
        max_answers: logicpad::DEFAULT_MAX_ANSWERS,
        proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
        max_time: None,
    };
    /// Counts only (the KB benchmark's answers).
    pub const COUNT: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: true,
        max_answers: logicpad::DEFAULT_MAX_ANSWERS,
        proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
        max_time: None,
    };
}
