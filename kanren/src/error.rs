//! Error types.

use crate::term::Sym;

/// Errors building fact tables and other static structures.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum KanrenError {
    /// Occurs when a tuple's length differs from its relation's arity.
    #[error("relation {relation}/{arity}: a tuple has {got} argument(s), expected {arity}")]
    ArityMismatch {
        /// The relation's name.
        relation: Sym,
        /// The relation's arity.
        arity: usize,
        /// The tuple's length.
        got: usize,
    },
    /// Occurs when a fact argument is a variable or a compound term: fact
    /// tables hold ground atoms only (symbols, integers, strings, `[]`), which
    /// is what lets every position be hash-indexed.
    #[error(
        "relation {relation}: argument {position} ({term}) is not a ground atom; facts hold symbols, integers, strings or []"
    )]
    NonGroundFact {
        /// The relation's name.
        relation: Sym,
        /// The 0-based argument position.
        position: usize,
        /// The offending argument, printed.
        term: String,
    },
    /// Occurs when a relation would grow past `u32::MAX` tuples (fact ids are `u32`).
    #[error("relation {relation}: too many facts (the limit is {limit})")]
    TooManyFacts {
        /// The relation's name.
        relation: Sym,
        /// The largest number of facts a relation holds.
        limit: u64,
    },
}

/// Errors a running query reports instead of an answer.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RunError {
    /// Occurs when `naf(g)` runs while `g` has unbound variables that its
    /// success would bind: whether `g` is false then depends on values not yet
    /// known ("floundering"), so no answer would be right.
    #[error(
        "negation as failure on a goal with unbound variable(s) {}: the negated goal only succeeds by binding them, so its truth is undecided here; bind them with a positive goal before the negation",
        vars.join(", ")
    )]
    UnboundNegation {
        /// The variables the negated goal would have bound (query variable
        /// names where known, otherwise `_N`).
        vars: Vec<String>,
    },
    /// Occurs when `absento(tag, t)` runs with a `tag` that is not ground.
    #[error("absento: the absent term {tag} must be ground when the goal runs")]
    NonGroundAbsento {
        /// The tag, printed.
        tag: String,
    },
    /// Occurs when a tabled relation is called with the wrong number of arguments.
    #[error("tabled relation {relation}/{arity} called with {got} argument(s)")]
    TabledArity {
        /// The relation's name.
        relation: Sym,
        /// Its declared arity.
        arity: usize,
        /// The number of arguments given.
        got: usize,
    },
    /// Occurs when a negation or committed choice (`naf`, `conda`, `condu`,
    /// `onceo`) needs the complete answers of a tabled call while that
    /// table's own evaluation depends on the negation's outcome: recursion
    /// through negation that is not stratified, where no answer would be
    /// right. `relation` is the tabled relation whose evaluation is caught in
    /// the cycle.
    #[error(
        "tabled relation {relation}: a negation or committed choice (naf, conda, condu, onceo) needs complete answers that depend on its own outcome (recursion through negation is not stratified)"
    )]
    TabledNegationCycle {
        /// The tabled relation whose evaluation is caught in the cycle.
        relation: Sym,
    },
    /// Occurs when a host computation inside `project_result` reports a failure.
    #[error("host computation failed: {0}")]
    Host(String),
}
