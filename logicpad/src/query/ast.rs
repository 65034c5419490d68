//! The query types: a parsed query of each form (existential, universal,
//! counting), its answers, and why asking it can fail.

use super::compile::Plan;
use crate::diag::{Diagnostic, SourceFile, Span};
use crate::eval::DerivationTree;
use crate::fol::{self, Arg, Literal};
use kanren::RunError;
use std::sync::Arc;

/// A parsed query: a disjunction of conjunctions of literals.
///
/// Invariant: `answer_vars` ⊆ `0..vars.len()`, in order of first appearance;
/// the other variables are existential (bound by `∃`) and projected away.
/// `plans` holds the query as compiled against a program; it is filled on
/// first use and describes the other fields, so a query is not edited in
/// place after it has been asked (build a new one: a clone starts with an
/// empty cache).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct QueryAst {
    /// The query text.
    pub source: Arc<SourceFile>,
    /// Every variable's name.
    pub vars: Vec<String>,
    /// Variables reported in answers.
    pub answer_vars: Vec<usize>,
    /// Alternatives (one for a conjunctive query).
    pub disjuncts: Vec<Vec<Literal>>,
    /// The query checked and compiled against a program for counting, once
    /// for every window of that program (`Model::compile`).
    pub plans: PlanCache,
}

/// A query's checked, compiled form for counting ([`QueryAst::plans`]): a
/// batch counts each query on hundreds of windows of one LogicPad, and
/// checking and compiling it each time was a tenth of a count's work.
/// A clone is empty, and every cache equals every other.
#[derive(Default)]
pub struct PlanCache {
    pub(super) slot: std::sync::OnceLock<Arc<Plan>>,
}

impl Clone for PlanCache {
    fn clone(&self) -> Self {
        PlanCache::default()
    }
}

impl PartialEq for PlanCache {
    fn eq(&self, _: &Self) -> bool {
        true
    }
}

impl Eq for PlanCache {}

impl std::fmt::Debug for PlanCache {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("PlanCache")
    }
}

/// One literal of a conjunction built without text ([`QueryAst::conjunction`]).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct LiteralSpec {
    /// Predicate name.
    pub pred: String,
    /// Argument names: variables and constants by their spelling
    /// ([`is_variable_name`]), as in query text.
    pub args: Vec<String>,
    /// True for `¬P(..)`.
    pub negated: bool,
}

impl QueryAst {
    /// The conjunctive query of `literals`, built directly — for a
    /// translator that already holds the query's structure and should not
    /// render it to text only to have it parsed back. The text
    /// (`P(x, c)^¬Q(x)`, for display and diagnostics) is rendered here and
    /// every span points into it; the result equals what [`parse_query`](super::parse_query)
    /// gives for that text (variables numbered by first appearance, every
    /// variable an answer variable), which a test holds.
    pub fn conjunction(literals: &[LiteralSpec]) -> QueryAst {
        let mut text = String::new();
        let mut vars: Vec<String> = Vec::new();
        let mut conj = Vec::with_capacity(literals.len());
        for (i, l) in literals.iter().enumerate() {
            if i > 0 {
                text.push('^');
            }
            let start = text.len();
            if l.negated {
                text.push('¬');
            }
            let pred_start = text.len();
            text.push_str(&l.pred);
            let pred_span = Span::new(pred_start, text.len());
            text.push('(');
            let mut args = Vec::with_capacity(l.args.len());
            let mut arg_spans = Vec::with_capacity(l.args.len());
            for (k, a) in l.args.iter().enumerate() {
                if k > 0 {
                    text.push_str(", ");
                }
                let a_start = text.len();
                text.push_str(a);
                arg_spans.push(Span::new(a_start, text.len()));
                args.push(if is_variable_name(a) {
                    let v = vars.iter().position(|n| n == a).unwrap_or_else(|| {
                        vars.push(a.clone());
                        vars.len() - 1
                    });
                    Arg::Var(v)
                } else {
                    Arg::Const(a.clone())
                });
            }
            text.push(')');
            let atom = fol::Atom {
                pred: l.pred.clone(),
                args,
                span: Span::new(start, text.len()),
                pred_span,
                arg_spans,
            };
            conj.push(if l.negated {
                Literal::Neg(atom)
            } else {
                Literal::Pos(atom)
            });
        }
        QueryAst {
            source: SourceFile::new("<query>", text),
            answer_vars: (0..vars.len()).collect(),
            vars,
            disjuncts: vec![conj],
            plans: PlanCache::default(),
        }
    }

    /// The query text.
    pub fn text(&self) -> &str {
        &self.source.text
    }
    /// Names of the answer variables, in order.
    pub fn answer_var_names(&self) -> Vec<&str> {
        self.answer_vars
            .iter()
            .filter_map(|&v| self.vars.get(v).map(String::as_str))
            .collect()
    }
}

/// One answer of a query.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct QueryAnswer {
    /// `(variable, constant)`, sorted by variable name.
    pub bindings: Vec<(String, String)>,
    /// One tree per literal of the alternative that produced the answer:
    /// base facts, derivations and absent atoms.
    pub proof: Vec<DerivationTree>,
}

/// Why a query could not be answered.
#[derive(Debug, Clone, thiserror::Error)]
pub enum AskError {
    /// Occurs when the query fails a check that makes it unanswerable
    /// (an unsafe negation).
    #[error("{}", .0.first().map(Diagnostic::summary).unwrap_or_default())]
    Invalid(Vec<Diagnostic>),
    /// Occurs when the kanren run reports an error.
    #[error("query run failed: {0}")]
    Run(#[from] RunError),
    /// Occurs when a method that must have every answer ([`Model::ask`],
    /// [`Model::bindings`], [`Model::count`], [`Model::satisfiable`]) runs
    /// out of a limit; the `*_limited` methods return what was found with
    /// the reason instead.
    ///
    /// [`Model::ask`]: crate::Model::ask
    /// [`Model::bindings`]: crate::Model::bindings
    /// [`Model::count`]: crate::Model::count
    /// [`Model::satisfiable`]: crate::Model::satisfiable
    #[error("query stopped at its {reason} limit after {found} answer(s)")]
    Stopped {
        /// Which limit.
        reason: super::Stopped,
        /// Answers found before it.
        found: usize,
    },
}

/// Whether a bare lower-case name in a query is a variable, by its
/// spelling alone: `x`, `y`, `z`, `u`, `v` or `w`, optionally followed by
/// digits (`x`, `y2`, `w10`). Every other lower-case name (`car_3`, `foo`,
/// `n2`, `a`) is a constant, and so are capitalised names and quoted text;
/// `?name` is always a variable, and so is a name bound by `∃`/`∀`.
///
/// The rule must not depend on the data: when it followed the window's
/// objects, `TypeOf(car_3, Sedan)` asked of a window without `car_3` made
/// `car_3` a variable and answered "yes, car_3 = sedan_6".
pub fn is_variable_name(name: &str) -> bool {
    let mut chars = name.chars();
    matches!(chars.next(), Some('x' | 'y' | 'z' | 'u' | 'v' | 'w'))
        && chars.all(|c| c.is_ascii_digit())
}

/// A parsed query of either form.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum ParsedQuery {
    /// An existential query (a conjunction, or alternatives joined by `∨`):
    /// "is there an x such that …", answered by its bindings.
    Exists(std::sync::Arc<QueryAst>),
    /// A universal query `∀x: A(x) → B(x)`, answered under the closed world
    /// over the window's objects.
    Forall(Box<UniversalQuery>),
    /// A counting query `#{x: Q} >= N`: whether the number of distinct
    /// bindings of the counted variables passes the test.
    Count(Box<CountQuery>),
}

/// The test of a counting query: `count op n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CountOp {
    /// `>=` / `≥`: at least `n`.
    AtLeast,
    /// `>`: more than `n`.
    MoreThan,
    /// `<=` / `≤`: at most `n`.
    AtMost,
    /// `<`: fewer than `n`.
    FewerThan,
    /// `=` / `==`: exactly `n`.
    Exactly,
}

impl CountOp {
    /// Whether `count` passes the test against `n`.
    pub fn holds(self, count: usize, n: usize) -> bool {
        match self {
            CountOp::AtLeast => count >= n,
            CountOp::MoreThan => count > n,
            CountOp::AtMost => count <= n,
            CountOp::FewerThan => count < n,
            CountOp::Exactly => count == n,
        }
    }

    /// True when more objects can only make the test true (`>=`, `>`):
    /// a count that passes it stays passed whatever else exists.
    pub fn monotone(self) -> bool {
        matches!(self, CountOp::AtLeast | CountOp::MoreThan)
    }

    /// The operator as the query syntax writes it (ASCII).
    pub fn symbol(self) -> &'static str {
        match self {
            CountOp::AtLeast => ">=",
            CountOp::MoreThan => ">",
            CountOp::AtMost => "<=",
            CountOp::FewerThan => "<",
            CountOp::Exactly => "=",
        }
    }

    /// The test in words: "at least", "more than", "at most", "fewer
    /// than", "exactly".
    pub fn words(self) -> &'static str {
        match self {
            CountOp::AtLeast => "at least",
            CountOp::MoreThan => "more than",
            CountOp::AtMost => "at most",
            CountOp::FewerThan => "fewer than",
            CountOp::Exactly => "exactly",
        }
    }
}

/// `#{x₁…xₙ : Q} op N`: how many distinct tuples of the counted variables
/// satisfy the existential query `Q`, tested against `N`.
///
/// Invariant: `query` is `Q` with the counted variables as its answer
/// variables (every other variable of `Q` is existential), in the order
/// written; its spans point into `source` (the whole text). The checker
/// ([`check_any_query`](super::check_any_query)) reports a counted variable that `Q` does not
/// mention or does not bind.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct CountQuery {
    /// The query text.
    pub source: Arc<SourceFile>,
    /// The counted variables, as written.
    pub vars: Vec<String>,
    /// Where each counted variable is written.
    pub var_spans: Vec<Span>,
    /// `Q`, whose distinct answers are counted.
    pub query: QueryAst,
    /// The test.
    pub op: CountOp,
    /// The number it compares with.
    pub n: usize,
    /// `Q` as written.
    pub inner: String,
}

impl CountQuery {
    /// Whether `count` distinct bindings pass the test.
    pub fn holds(&self, count: usize) -> bool {
        self.op.holds(count, self.n)
    }

    /// The query text.
    pub fn text(&self) -> &str {
        &self.source.text
    }
}

/// `∀x₁…xₙ : A → B` over a window, in the three existential queries that
/// answer it. Every one shares the variable names of the text; the answer
/// variables of each are the `∀` variables.
///
/// Invariant: `counterexamples` is `A ∧ ¬B`, `domain` is `A` and `witnesses`
/// is `A ∧ B`; the universal holds iff `counterexamples` has no answer
/// (vacuously when `domain` has none).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UniversalQuery {
    /// The query text.
    pub source: Arc<SourceFile>,
    /// The universally quantified variables, in the order written.
    pub vars: Vec<String>,
    /// `A ∧ ¬B`: the objects for which the universal fails.
    pub counterexamples: QueryAst,
    /// `A`: the objects the universal speaks about.
    pub domain: QueryAst,
    /// `A ∧ B`: the objects for which it holds, with their proofs.
    pub witnesses: QueryAst,
    /// `A` as written.
    pub antecedent: String,
    /// `B` as written.
    pub consequent: String,
}

impl ParsedQuery {
    /// The query text.
    pub fn text(&self) -> &str {
        match self {
            ParsedQuery::Exists(q) => q.text(),
            ParsedQuery::Forall(u) => &u.source.text,
            ParsedQuery::Count(c) => c.text(),
        }
    }
    /// The existential queries that answer this one, for checks and scans
    /// that must see every atom.
    pub fn parts(&self) -> Vec<&QueryAst> {
        match self {
            ParsedQuery::Exists(q) => vec![q],
            ParsedQuery::Forall(u) => vec![&u.domain, &u.counterexamples, &u.witnesses],
            ParsedQuery::Count(c) => vec![&c.query],
        }
    }
}
