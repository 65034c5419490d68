//! Queries: the same FOL grammar as rule bodies, compiled to a kanren
//! program and answered by kanren's lazy search over a [`Model`]'s
//! relations, so derived predicates are queried exactly like base facts.

use crate::diag::{DiagKind, Diagnostic, Severity, SourceFile, Span};
use crate::eval::{
    DerivationTree, GroundAtom, Model, ProofLimits, bind_from, term_name, term_text,
};
use crate::fol::{self, Arg, Formula, Literal, Quant, Resolver};
use crate::program::{CArg, CAtom, Rule, RuleSource};
use crate::schema::Schema;
use kanren::{FactId, Goal, RunConfig, RunError, StopReason, Sym, Term};
use std::collections::{BTreeMap, BTreeSet};
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
    slot: std::sync::OnceLock<Arc<Plan>>,
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

/// A query compiled against one program: what [`Model::compile`] needs
/// besides the window's relations.
///
/// Invariant: `rules`, `labels` have one entry per alternative of the
/// query; `program` is the program it was compiled against. A weak
/// reference, not an address: a query may outlive its program (a REPL
/// reloads its LogicPad), and a new program could be allocated at the
/// old one's address, where a stale plan would read the wrong relations;
/// the weak reference keeps the allocation, so no other program gets it.
pub(crate) struct Plan {
    program: std::sync::Weak<crate::program::Inner>,
    rules: Vec<Option<Arc<Rule>>>,
    labels: Vec<Sym>,
    answer_vars: Vec<usize>,
    names: Vec<String>,
    /// The `¬∃` literals of each alternative, compiled; empty (no
    /// allocation) when the query has none, as nearly every query.
    not_exists: Vec<Arc<[NotExistsPlan]>>,
}

/// A `¬∃vars: body` literal compiled: the body as a rule (its positive
/// atoms joined, negated atoms and comparisons tested inside the join),
/// its own nested `¬∃`, and the slots of its own variables, which get
/// fresh kanren variables each time it runs (so that `naf` sees them as
/// local).
///
/// Invariant: `rule` is `None` when a positive atom of the body can never
/// hold (an unknown predicate, a wrong arity): the literal then always
/// holds. `literal` is the literal as resolved, for proofs.
pub(crate) struct NotExistsPlan {
    locals: Vec<usize>,
    rule: Option<Arc<Rule>>,
    nested: Arc<[NotExistsPlan]>,
    literal: Literal,
}

/// `naf` of each `¬∃` of `nes`, after `g` (which binds every variable
/// they read from outside).
fn with_not_exists(
    rels: &Arc<[Arc<kanren::Relation>]>,
    g: Goal,
    nes: &[NotExistsPlan],
    terms: &Arc<[Term]>,
) -> Goal {
    if nes.is_empty() {
        return g;
    }
    kanren::conj(
        std::iter::once(g).chain(
            nes.iter()
                .map(|ne| kanren::naf(not_exists_goal(rels, ne, terms))),
        ),
    )
}

/// The goal whose failure a `¬∃` asks for: fresh variables for its own
/// slots, then the join of its body (with its nested `¬∃`).
fn not_exists_goal(
    rels: &Arc<[Arc<kanren::Relation>]>,
    ne: &NotExistsPlan,
    terms: &Arc<[Term]>,
) -> Goal {
    let Some(rule) = ne.rule.clone() else {
        return kanren::fail();
    };
    let (rels, terms) = (Arc::clone(rels), Arc::clone(terms));
    let locals = ne.locals.clone();
    let nested = Arc::clone(&ne.nested);
    let body = Arc::new(move |fresh: &[Term]| {
        let mut t: Vec<Term> = terms.to_vec();
        for (&slot, v) in locals.iter().zip(fresh) {
            if let Some(x) = t.get_mut(slot) {
                *x = v.clone();
            }
        }
        let t: Arc<[Term]> = t.into();
        with_not_exists(&rels, join_goal(&rels, &rule, &t), &nested, &t)
    });
    with_fresh(ne.locals.len(), Vec::new(), body)
}

/// A goal made from the terms of fresh variables (see [`with_fresh`]).
type FreshBody = Arc<dyn Fn(&[Term]) -> Goal + Send + Sync>;

/// The goal `k(v₁…vₙ)` over `n` fresh kanren variables, made when the
/// search reaches it (after the `naf` that encloses it has taken its mark).
fn with_fresh(n: usize, acc: Vec<Term>, k: FreshBody) -> Goal {
    if n == 0 {
        return k(&acc);
    }
    kanren::fresh(move |[v]| {
        let mut next = acc.clone();
        next.push(v);
        with_fresh(n - 1, next, Arc::clone(&k))
    })
}

/// A compiled rule's join over `terms`: `join_where` of its positive
/// atoms with `naf` of each negated atom and `=`/`=/=` of each comparison
/// tested inside it.
fn join_goal(rels: &Arc<[Arc<kanren::Relation>]>, rule: &Rule, terms: &Arc<[Term]>) -> Goal {
    // Most queries have no negation and no comparison: share one empty
    // list rather than allocate two per query.
    type Empty = (Arc<[CAtom]>, Arc<[kanren::join::Cmp]>);
    static NONE: std::sync::OnceLock<Empty> = std::sync::OnceLock::new();
    let none = NONE.get_or_init(|| (Arc::from([]), Arc::from([])));
    let negated = if rule.negated.is_empty() {
        none.0.clone()
    } else {
        rule.negated.clone().into()
    };
    let cmps = if rule.cmps.is_empty() {
        none.1.clone()
    } else {
        rule.cmps.clone().into()
    };
    kanren::join::join_where(
        rels.clone(),
        rule.body.clone(),
        negated,
        cmps,
        terms.clone(),
    )
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
    /// every span points into it; the result equals what [`parse_query`]
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
    /// Occurs when a query has more answers than its budget: it would take
    /// memory without bound (`Vehicles(v0) ∧ … ∧ Vehicles(v11)` over four
    /// vehicles has 16 million).
    #[error("query too large: more than {limit} bindings; narrow it or raise --max-answers")]
    TooLarge {
        /// The budget that was exceeded.
        limit: usize,
    },
    /// Occurs when the step or time budget ran out; `partial` holds the
    /// answers found before that.
    #[error("query stopped early ({reason}) after {} answer(s)", partial.len())]
    Budget {
        /// Which budget.
        reason: StopReason,
        /// Answers found so far (sorted).
        partial: Vec<QueryAnswer>,
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
    Exists(QueryAst),
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
/// ([`check_any_query`]) reports a counted variable that `Q` does not
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

fn query_syntax_error(source: &Arc<SourceFile>, e: fol::SyntaxError, help: &str) -> Diagnostic {
    Diagnostic::new(
        DiagKind::FolSyntax,
        Severity::Error,
        source,
        e.span,
        e.message,
    )
    .with_label(e.label)
    .with_help(help)
}

const QUERY_HELP: &str = "a query looks like `TypeOf(x, Car) ∧ ColorOf(x) = White ∧ ¬Moving(x)`";

/// Parses an existential query (conjunctions, `∨`, `¬`, `∃`, comparisons).
/// Names are variables or constants by their spelling alone
/// ([`is_variable_name`]). A leading `∀` is refused here, never dropped:
/// [`parse_any_query`] answers universals.
// The error is a full diagnostic (source, spans, help), returned by value
// because it is the shape every caller renders.
#[allow(clippy::result_large_err)]
pub fn parse_query(text: &str) -> Result<QueryAst, Diagnostic> {
    match parse_any_query(text)? {
        ParsedQuery::Exists(q) => Ok(q),
        ParsedQuery::Forall(u) => Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &u.source,
            Span::new(0, u.source.text.len()),
            "a universal query is not an existential one",
        )
        .with_label("`∀` asks whether every object qualifies")
        .with_help("answer it with `parse_any_query`, or drop the `∀` to list the objects")),
        ParsedQuery::Count(c) => Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &c.source,
            Span::new(0, c.source.text.len()),
            "a counting query is not an existential one",
        )
        .with_label("`#{…}` asks how many objects qualify")
        .with_help(
            "answer it with `parse_any_query`, or drop the `#{x: …} op N` to list the objects",
        )),
    }
}

/// The default answer budget of a query: more bindings than this is
/// [`AskError::TooLarge`], never an allocation without bound.
pub const DEFAULT_MAX_ANSWERS: usize = 100_000;

/// How many times the answer budget a count may reach when it needs no
/// memory per answer (see [`Model::count_within`]): the budget then bounds
/// time, not memory.
pub const COUNT_FACTOR: usize = 1_000;

/// Parses a query of either form. A leading `∀x: A → B` is a universal
/// query; a `∀` whose body is not an implication (`∀x: Moving(x)`) ranges
/// over everything and is refused with a diagnostic, as are `→` and `∀`
/// anywhere else: a query is never read as something weaker than written.
#[allow(clippy::result_large_err)]
pub fn parse_any_query(text: &str) -> Result<ParsedQuery, Diagnostic> {
    let source = SourceFile::new("<query>", text);
    if text.trim_start().starts_with('#') {
        return parse_count(&source).map(|c| ParsedQuery::Count(Box::new(c)));
    }
    let f = fol::parse_formula(text).map_err(|e| query_syntax_error(&source, e, QUERY_HELP))?;
    let mut forall: Vec<String> = Vec::new();
    let mut body = &f;
    let mut forall_span = None;
    while let Formula::Quantified {
        quant: Quant::Forall,
        vars,
        body: b,
        span,
    } = body
    {
        forall.extend(vars.iter().map(|(n, _)| n.clone()));
        forall_span.get_or_insert(*span);
        body = b;
    }
    let Some(forall_span) = forall_span else {
        return existential(&source, &f, None).map(ParsedQuery::Exists);
    };
    let Formula::Implies(antecedent, consequent, _) = body else {
        let v = forall.first().cloned().unwrap_or_else(|| "x".into());
        return Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            &source,
            forall_span,
            format!("`∀{v}` without `→` ranges over everything, which no window can list"),
        )
        .with_label("say which objects this is about")
        .with_help(format!(
            "write `∀{v}: Vehicles({v}) → Moving({v})` to ask whether every vehicle moves, or drop the `∀` to ask which objects do"
        )));
    };
    let written = |f: &Formula| {
        let sp = f.span();
        text.get(sp.start..sp.end)
            .unwrap_or_default()
            .trim()
            .to_string()
    };
    let (antecedent_text, consequent_text) = (written(antecedent), written(consequent));
    let (a, b) = (antecedent.as_ref().clone(), consequent.as_ref().clone());
    let span = f.span();
    let and = |parts: Vec<Formula>| Formula::And(parts);
    let counter = and(vec![a.clone(), Formula::Not(Box::new(b.clone()), span)]);
    let witness = and(vec![a.clone(), b]);
    let answer = Some(forall.as_slice());
    Ok(ParsedQuery::Forall(Box::new(UniversalQuery {
        counterexamples: existential(&source, &counter, answer)?,
        domain: existential(&source, &a, answer)?,
        witnesses: existential(&source, &witness, answer)?,
        vars: forall,
        antecedent: antecedent_text,
        consequent: consequent_text,
        source,
    })))
}

const COUNT_HELP: &str = "a counting query looks like `#{x: TypeOf(x, Car)} >= 3` (ops >= > <= < =; `#{x, y: …}` counts pairs)";

/// `#{x, y: Q} op N`, the text around `Q` read here and `Q` by the FOL
/// parser, over the whole text with everything but `Q` blanked out, so
/// that every span of `Q` points into the text as written.
#[allow(clippy::result_large_err)]
fn parse_count(source: &Arc<SourceFile>) -> Result<CountQuery, Diagnostic> {
    let text = source.text.as_str();
    let err = |span: Span, message: String, label: &str| {
        Diagnostic::new(DiagKind::FolSyntax, Severity::Error, source, span, message)
            .with_label(label)
            .with_help(COUNT_HELP)
    };
    let hash = text.find('#').unwrap_or(0);
    let after = |i: usize| text.get(i..).unwrap_or("");
    let skip_ws = |i: usize| i + (after(i).len() - after(i).trim_start().len());
    let open = skip_ws(hash + 1);
    if !after(open).starts_with('{') {
        return Err(err(
            Span::new(hash, open + 1),
            "expected `{` after `#`".into(),
            "a count is written `#{x: …}`",
        ));
    }
    let Some(close) = after(open).find('}').map(|i| open + i) else {
        return Err(err(
            Span::new(open, text.len()),
            "this `{` is never closed".into(),
            "expected `}` after the counted query",
        ));
    };
    let Some(colon) = text
        .get(open + 1..close)
        .and_then(|h| h.find(':'))
        .map(|i| open + 1 + i)
    else {
        return Err(err(
            Span::new(open, close + 1),
            "expected `:` after the counted variables".into(),
            "write `#{x: Query}`",
        ));
    };
    // The counted variables: names (or `?names`) separated by commas.
    let mut vars: Vec<String> = Vec::new();
    let mut var_spans = Vec::new();
    let mut at = open + 1;
    for part in text.get(open + 1..colon).unwrap_or("").split(',') {
        let lead = part.len() - part.trim_start().len();
        let name = part.trim();
        let start = at + lead;
        let span = Span::new(start, start + name.len());
        at += part.len() + 1;
        let bare = name.strip_prefix('?').unwrap_or(name);
        let ok = !bare.is_empty()
            && bare
                .chars()
                .next()
                .is_some_and(|c| c.is_alphabetic() || c == '_')
            && bare.chars().all(|c| c.is_alphanumeric() || c == '_');
        if !ok {
            return Err(err(
                span,
                format!("expected a variable name to count, found `{name}`"),
                "expected a variable here",
            ));
        }
        if vars.iter().any(|v| v == bare) {
            return Err(err(
                span,
                format!("`{bare}` is counted twice"),
                "already counted",
            ));
        }
        vars.push(bare.to_string());
        var_spans.push(span);
    }
    // The test after `}`.
    let op_at = skip_ws(close + 1);
    let rest = after(op_at);
    let ops: [(&str, CountOp); 8] = [
        (">=", CountOp::AtLeast),
        ("≥", CountOp::AtLeast),
        ("<=", CountOp::AtMost),
        ("≤", CountOp::AtMost),
        ("==", CountOp::Exactly),
        ("=", CountOp::Exactly),
        (">", CountOp::MoreThan),
        ("<", CountOp::FewerThan),
    ];
    let Some((sym, op)) = ops.iter().find(|(sym, _)| rest.starts_with(sym)) else {
        return Err(err(
            Span::new(op_at, op_at + rest.chars().next().map_or(0, char::len_utf8)),
            "expected a comparison (`>=`, `>`, `<=`, `<` or `=`) after the count".into(),
            "expected `>=`, `>`, `<=`, `<` or `=` here",
        ));
    };
    let num_at = skip_ws(op_at + sym.len());
    let digits: &str = {
        let r = after(num_at);
        let end = r.find(|c: char| !c.is_ascii_digit()).unwrap_or(r.len());
        r.get(..end).unwrap_or("")
    };
    let end = num_at + digits.len();
    let n = match digits.parse::<usize>() {
        Ok(n) => n,
        Err(_) => {
            return Err(err(
                Span::new(num_at, (num_at + 1).min(text.len())),
                "expected a whole number after the comparison".into(),
                "expected a number here",
            ));
        }
    };
    if !after(end).trim().is_empty() {
        return Err(err(
            Span::new(skip_ws(end), text.len()),
            "unexpected text after the count's number".into(),
            "expected the query to end here",
        ));
    }
    // `Q`, parsed in place: every byte outside it becomes a space.
    let (q_start, q_end) = (colon + 1, close);
    let mut blanked = String::with_capacity(text.len());
    for (i, c) in text.char_indices() {
        if i >= q_start && i < q_end {
            blanked.push(c);
        } else {
            blanked.extend(std::iter::repeat_n(' ', c.len_utf8()));
        }
    }
    if text.get(q_start..q_end).is_none_or(|q| q.trim().is_empty()) {
        return Err(err(
            Span::new(open, close + 1),
            "the counted query is empty".into(),
            "write the query after `:`",
        ));
    }
    let f = fol::parse_formula(&blanked).map_err(|e| query_syntax_error(source, e, COUNT_HELP))?;
    if let Formula::Quantified {
        quant: Quant::Forall,
        span,
        ..
    } = &f
    {
        return Err(Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            source,
            *span,
            "a counted query is existential: `∀` cannot be counted",
        )
        .with_label("not countable")
        .with_help(COUNT_HELP));
    }
    let query = existential(source, &f, Some(&vars))?;
    Ok(CountQuery {
        source: Arc::clone(source),
        inner: text.get(q_start..q_end).unwrap_or("").trim().to_string(),
        vars,
        var_spans,
        query,
        op: *op,
        n,
    })
}

/// An existential query from a formula. `answer` names the answer
/// variables (a universal's `∀` variables); `None` takes every variable not
/// bound by `∃`.
#[allow(clippy::result_large_err)]
fn existential(
    source: &Arc<SourceFile>,
    f: &Formula,
    answer: Option<&[String]>,
) -> Result<QueryAst, Diagnostic> {
    let mut exist = Vec::new();
    collect_exists(f, &mut exist);
    let mut bound = Vec::new();
    fol::bound_names(f, &mut bound);
    bound.extend(answer.into_iter().flatten().cloned());
    let is_constant = |n: &str| !is_variable_name(n);
    let mut r = Resolver::new(bound, &is_constant, true);
    let disjuncts = fol::to_dnf(f, &mut r).map_err(|e| {
        Diagnostic::new(
            DiagKind::Unsupported,
            Severity::Error,
            source,
            e.span,
            e.message,
        )
        .with_label(e.label)
    })?;
    // A `¬∃`'s own variables are never answers (they have a slot of
    // their own, which no name outside it finds).
    let answer_vars = match answer {
        None => (0..r.vars.len())
            .filter(|&v| !exist.contains(&r.vars[v]) && !r.locals.contains(&v))
            .collect(),
        Some(names) => names
            .iter()
            .filter_map(|n| (0..r.vars.len()).find(|&v| r.vars[v] == *n && !r.locals.contains(&v)))
            .collect(),
    };
    Ok(QueryAst {
        source: Arc::clone(source),
        vars: r.vars,
        answer_vars,
        disjuncts,
        plans: PlanCache::default(),
    })
}

/// The names a positive `∃` binds (projected away from the answers); a
/// negated `∃` binds variables of its own, which are never answers anyway.
fn collect_exists(f: &Formula, out: &mut Vec<String>) {
    match f {
        Formula::Quantified {
            quant, vars, body, ..
        } => {
            if *quant == Quant::Exists {
                out.extend(vars.iter().map(|(n, _)| n.clone()));
            }
            collect_exists(body, out);
        }
        Formula::Not(g, _) if matches!(**g, Formula::Quantified { .. }) => {}
        Formula::Not(g, _) => collect_exists(g, out),
        Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|g| collect_exists(g, out)),
        Formula::Implies(a, b, _) => {
            collect_exists(a, out);
            collect_exists(b, out);
        }
        Formula::Atom(_) | Formula::Equal { .. } => {}
    }
}

/// Checks a query against a schema: unknown predicates (with a suggestion),
/// arity, undeclared function values, and safety (every variable under `¬`
/// or in a comparison, and every answer variable, bound by a positive atom
/// in each alternative).
pub fn check_query(schema: &Schema, q: &QueryAst) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for d in &q.disjuncts {
        for l in d {
            match l {
                Literal::Pos(a) | Literal::Neg(a) => {
                    schema.check_atom(a, &q.source, &mut out);
                }
                Literal::NotExists { .. } => {
                    for (a, _) in l.atoms() {
                        schema.check_atom(a, &q.source, &mut out);
                    }
                }
                Literal::Cmp { .. } => {}
            }
        }
    }
    out.extend(safety(q));
    out.sort_by(|a, b| (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message)));
    out.dedup();
    out
}

/// [`check_query`] for either form: a universal is checked through its
/// counterexample query (`A ∧ ¬B`), which holds every atom of both sides
/// and is unsafe exactly when `B` needs a variable that `A` does not bind.
pub fn check_any_query(schema: &Schema, q: &ParsedQuery) -> Vec<Diagnostic> {
    match q {
        ParsedQuery::Exists(q) => check_query(schema, q),
        ParsedQuery::Count(c) => {
            let mut out = check_query(schema, &c.query);
            for (name, span) in c.vars.iter().zip(&c.var_spans) {
                let occurs = c
                    .query
                    .answer_vars
                    .iter()
                    .any(|&v| c.query.vars.get(v) == Some(name));
                if !occurs {
                    out.push(
                        Diagnostic::new(
                            DiagKind::UnsafeRule,
                            Severity::Error,
                            &c.source,
                            *span,
                            format!("`#{{{name}: …}}` counts `{name}`, which the query does not mention"),
                        )
                        .with_label(format!("`{name}` is not in the counted query"))
                        .with_help(format!(
                            "count a variable of the query, e.g. `#{{{name}: TypeOf({name}, Car)}} >= 2`"
                        )),
                    );
                }
            }
            out.sort_by(|a, b| {
                (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message))
            });
            out.dedup();
            out
        }
        ParsedQuery::Forall(u) => {
            let mut out = check_query(schema, &u.counterexamples);
            for name in &u.vars {
                if !u.domain.vars.contains(name) {
                    out.push(
                        Diagnostic::new(
                            DiagKind::UnsafeRule,
                            Severity::Error,
                            &u.source,
                            Span::new(0, u.source.text.len()),
                            format!("`∀{name}`: `{name}` is not bound on the left of `→`"),
                        )
                        .with_label(format!("`{name}` would range over everything"))
                        .with_help(format!(
                            "bind `{name}` on the left, e.g. `∀{name}: Vehicles({name}) → …`"
                        )),
                    );
                }
            }
            out.sort_by(|a, b| {
                (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message))
            });
            out.dedup();
            out
        }
    }
}

/// An "unsafe query" error at `span`.
fn unsafe_query(q: &QueryAst, span: Span, what: String, label: String, help: String) -> Diagnostic {
    Diagnostic::new(
        DiagKind::UnsafeRule,
        Severity::Error,
        &q.source,
        span,
        format!("unsafe query: {what}"),
    )
    .with_label(label)
    .with_help(help)
}

/// Marks the variables of the positive atoms of `lits` in `bound`.
fn bind_positives(lits: &[Literal], bound: &mut [bool]) {
    for a in lits.iter().filter_map(Literal::positive) {
        for x in &a.args {
            if let Arg::Var(v) = x
                && let Some(b) = bound.get_mut(*v)
            {
                *b = true;
            }
        }
    }
}

/// The safety of the negated atoms, comparisons and `¬∃` of one
/// conjunction whose bound variables are `bound`: each variable they read
/// from outside must be bound; a `¬∃`'s own variables must occur in a
/// positive atom of its body, whose conjunction is checked in turn.
fn conj_safety(
    q: &QueryAst,
    lits: &[Literal],
    bound: &[bool],
    reported: &mut BTreeSet<usize>,
    out: &mut Vec<Diagnostic>,
) {
    let is_bound = |v: usize| bound.get(v).copied().unwrap_or(false);
    let name = |v: usize| q.vars.get(v).cloned().unwrap_or_default();
    for l in lits {
        let (args, right, span): (&[Arg], _, _) = match l {
            Literal::Neg(a) => (&a.args, None, a.span),
            Literal::Cmp {
                left, right, span, ..
            } => (std::slice::from_ref(left), Some(right), *span),
            Literal::Pos(_) => continue,
            Literal::NotExists { vars, body, span } => {
                for v in l.free_vars() {
                    if !is_bound(v) && reported.insert(v) {
                        let name = name(v);
                        out.push(unsafe_query(
                            q,
                            *span,
                            format!(
                                "variable `{name}` in a `¬∃` is neither its own nor bound by a positive atom outside it"
                            ),
                            format!("`{name}` would range over everything"),
                            format!(
                                "list `{name}` after `∃` to make it the `¬∃`'s own, or bind it outside with a positive atom, e.g. `Vehicles({name})`"
                            ),
                        ));
                    }
                }
                let mut inner: smallvec::SmallVec<[bool; 16]> = bound.iter().copied().collect();
                bind_positives(body, &mut inner);
                for &v in vars {
                    if !inner.get(v).copied().unwrap_or(false) && reported.insert(v) {
                        let name = name(v);
                        out.push(unsafe_query(
                            q,
                            *span,
                            format!("`∃{name}`: `{name}` occurs in no positive atom of the `¬∃`"),
                            format!("`{name}` would range over everything"),
                            format!("use `{name}` in a positive atom inside the parentheses, e.g. `¬∃{name}: (Road({name}) ∧ …)`"),
                        ));
                    }
                }
                // Every variable is marked bound for the nested check: the
                // ones that are not were reported above.
                for v in l.free_vars() {
                    if let Some(b) = inner.get_mut(v) {
                        *b = true;
                    }
                }
                for &v in vars {
                    if let Some(b) = inner.get_mut(v) {
                        *b = true;
                    }
                }
                conj_safety(q, body, &inner, reported, out);
                continue;
            }
        };
        for x in args.iter().chain(right) {
            let Arg::Var(v) = x else { continue };
            let v = *v;
            if !is_bound(v) && reported.insert(v) {
                let what = match l {
                    Literal::Neg(a) => format!("`¬{}`", a.pred),
                    _ => "a comparison".to_string(),
                };
                let name = name(v);
                out.push(unsafe_query(
                    q,
                    span,
                    format!("variable `{name}` in {what} is bound by no positive atom"),
                    format!("`{name}` would range over everything"),
                    format!("add a positive atom that binds `{name}`, e.g. `Vehicles({name})`"),
                ));
            }
        }
    }
}

fn safety(q: &QueryAst) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for d in &q.disjuncts {
        // Asked of every query on every window: no allocation unless a
        // variable is unsafe.
        let mut bound: smallvec::SmallVec<[bool; 16]> = smallvec::smallvec![false; q.vars.len()];
        bind_positives(d, &mut bound);
        let is_bound = |v: usize| bound.get(v).copied().unwrap_or(false);
        let mut reported = BTreeSet::new();
        conj_safety(q, d, &bound, &mut reported, &mut out);
        // An answer variable missing from an alternative would be answered
        // as an unbound kanren variable by `ask` and dropped by `bindings`.
        let span = d
            .iter()
            .map(Literal::span)
            .reduce(|a, b| Span::new(a.start.min(b.start), a.end.max(b.end)));
        for &v in &q.answer_vars {
            if !is_bound(v)
                && reported.insert(v)
                && let Some(span) = span
            {
                let name = q.vars.get(v).cloned().unwrap_or_default();
                out.push(unsafe_query(
                    q,
                    span,
                    format!("answer variable `{name}` is bound by no positive atom of this alternative"),
                    format!("`{name}` has no value here"),
                    format!("bind `{name}` in every alternative, or write `∃{name}` to leave it out of the answers"),
                ));
            }
        }
    }
    out
}

/// A query compiled to a kanren program: one goal over one kanren variable
/// per query variable, `conde` over the alternatives, each alternative
/// labelled (so an answer's proof says which one produced it) and run as
///
/// `join(positive atoms) ∧ (a = b | a =/= b)… ∧ naf(fact(negated atom))…`
///
/// — kanren's indexed join for the positive atoms (planned when it runs),
/// then the comparisons through unification and the disequality store, then
/// negation as failure (a lookup, since safety binds every variable of a
/// negated atom first).
///
/// Invariant: `rules[i]` is alternative `i` compiled for proofs (`None`
/// when a positive atom can never hold, and the alternative is `fail`);
/// `labels[i]` is its label.
struct Compiled {
    query: kanren::Query,
    goal: Goal,
    plan: Arc<Plan>,
}

impl Compiled {
    /// Runs the program lazily.
    fn run(&self, proofs: bool, budget: kanren::Budget) -> kanren::Run {
        self.query.run(
            self.goal.clone(),
            RunConfig {
                limit: None,
                proofs,
                budget,
            },
        )
    }

    /// The answer variables' values of one kanren answer.
    fn key(&self, a: &kanren::Answer) -> Vec<Term> {
        self.plan
            .answer_vars
            .iter()
            .map(|&v| a.values.get(v).cloned().unwrap_or(Term::Nil))
            .collect()
    }

    /// The alternative and the fact of each positive literal, read from an
    /// answer's proof steps (the label comes first, then one fact per atom).
    fn premises(&self, a: &kanren::Answer) -> Option<(usize, Vec<FactId>)> {
        let steps = &a.proof.as_ref()?.steps;
        let mut alt = None;
        let mut prem = Vec::new();
        for s in steps {
            match s {
                kanren::ProofStep::Rule(l) => alt = self.plan.labels.iter().position(|x| x == l),
                kanren::ProofStep::Fact { id, .. } => prem.push(*id),
            }
        }
        alt.map(|i| (i, prem))
    }

    fn rule(&self, alt: usize) -> Option<&Rule> {
        self.plan.rules.get(alt).and_then(Option::as_deref)
    }

    /// The `¬∃` literals of alternative `alt`.
    fn not_exists(&self, alt: usize) -> &[NotExistsPlan] {
        self.plan.not_exists.get(alt).map_or(&[], |n| &n[..])
    }
}

/// The label of alternative `i` of a query. The first few are interned
/// once for the process: interning takes a global lock, and every query
/// has at least one alternative.
fn alternative_label(i: usize) -> Sym {
    static FIRST: std::sync::OnceLock<Vec<Sym>> = std::sync::OnceLock::new();
    let first = FIRST.get_or_init(|| {
        (0..16)
            .map(|i| Sym::new(&format!("alternative {i}")))
            .collect()
    });
    first
        .get(i)
        .copied()
        .unwrap_or_else(|| Sym::new(&format!("alternative {i}")))
}

impl Model {
    /// Compiles a checked query to its kanren program ([`Compiled`]).
    /// `full`: keep what proofs and printed bindings need (each
    /// alternative's label and variable names, the answer variables'
    /// names); a count needs none of it, and a short query spent a third of
    /// its time building it.
    fn compile(&self, q: &QueryAst, full: bool) -> Result<Compiled, AskError> {
        // Counts keep their plan with the query; a full plan (for proofs and
        // bindings) is compiled each time: kept, it measured slower on the
        // KITTI benchmark's proofs.
        let plan = match q.plans.slot.get() {
            Some(p) if !full && self.program.is(&p.program) => Arc::clone(p),
            _ => {
                let (plan, portable) = self.plan(q, full)?;
                let plan = Arc::new(plan);
                // Only a plan that every window of the program compiles
                // alike is kept (and the first program's, should one query
                // be asked of two).
                if portable && !full {
                    let _ = q.plans.slot.set(Arc::clone(&plan));
                }
                plan
            }
        };
        let mut query = kanren::Query::new();
        // Names word kanren's errors only; a count needs none.
        let terms: Arc<[Term]> = q
            .vars
            .iter()
            .map(|v| query.var(if full { v } else { "" }))
            .collect();
        let mut alts: Vec<Goal> = plan
            .rules
            .iter()
            .zip(&plan.labels)
            .enumerate()
            .map(|(i, (rule, label))| match rule {
                Some(rule) => {
                    let mut g = self.rule_goal(rule, &terms);
                    if let Some(nes) = plan.not_exists.get(i) {
                        g = with_not_exists(&self.rels, g, nes, &terms);
                    }
                    if full { kanren::label(*label, g) } else { g }
                }
                None => kanren::fail(),
            })
            .collect();
        // One alternative (nearly every query) is its own goal.
        let goal = if alts.len() == 1 {
            alts.pop().unwrap_or_else(kanren::fail)
        } else {
            kanren::disj(alts)
        };
        Ok(Compiled { query, goal, plan })
    }

    /// Checks a query and compiles its alternatives against this model's
    /// program; also says whether the plan holds for every window of the
    /// program (every atom's predicate is the program's, not one only this
    /// window's facts have).
    fn plan(&self, q: &QueryAst, full: bool) -> Result<(Plan, bool), AskError> {
        let unsafe_diags = safety(q);
        if !unsafe_diags.is_empty() {
            return Err(AskError::Invalid(unsafe_diags));
        }
        let portable = q.disjuncts.iter().flatten().all(|l| match l {
            Literal::Pos(a) | Literal::Neg(a) => self.program.pred_id(&a.pred).is_some(),
            Literal::Cmp { .. } => true,
            Literal::NotExists { .. } => l
                .atoms()
                .iter()
                .all(|(a, _)| self.program.pred_id(&a.pred).is_some()),
        });
        let mut rules = Vec::with_capacity(q.disjuncts.len());
        let mut labels = Vec::with_capacity(q.disjuncts.len());
        for (i, d) in q.disjuncts.iter().enumerate() {
            labels.push(alternative_label(i));
            rules.push(self.compile_query(q, d, full).map(Arc::new));
        }
        let not_exists = if q.disjuncts.iter().flatten().any(Literal::is_not_exists) {
            q.disjuncts
                .iter()
                .map(|d| self.compile_not_exists(q, d))
                .collect()
        } else {
            Vec::new()
        };
        let plan = Plan {
            program: self.program.downgrade(),
            rules,
            labels,
            answer_vars: q.answer_vars.clone(),
            names: if full {
                q.answer_var_names()
                    .into_iter()
                    .map(str::to_string)
                    .collect()
            } else {
                Vec::new()
            },
            not_exists,
        };
        Ok((plan, portable))
    }

    /// The `¬∃` literals of a conjunction, compiled (nested ones within).
    fn compile_not_exists(&self, q: &QueryAst, lits: &[Literal]) -> Arc<[NotExistsPlan]> {
        lits.iter()
            .filter_map(|l| match l {
                Literal::NotExists { vars, body, .. } => Some(NotExistsPlan {
                    locals: vars.clone(),
                    rule: self.compile_query(q, body, false).map(Arc::new),
                    nested: self.compile_not_exists(q, body),
                    literal: l.clone(),
                }),
                _ => None,
            })
            .collect()
    }

    /// A compiled alternative as a kanren goal over `terms` (one per
    /// variable slot): `join_where`, kanren's join of the positive atoms
    /// with `naf` of each negated atom and `=`/`=/=` of each comparison
    /// tested inside it — safety binds every variable they read, so each is
    /// a test of bound values, and a failing match costs no kanren state.
    fn rule_goal(&self, rule: &Rule, terms: &Arc<[Term]>) -> Goal {
        join_goal(&self.rels, rule, terms)
    }

    /// Answers a query through its kanren program ([`Model::goal`] for one
    /// alternative) and, with `config.proofs`, a proof per answer built
    /// from the answer's kanren proof: each positive literal's fact,
    /// expanded through the derivations recorded in the fixpoint, and each
    /// negated literal as an absent fact. Answers are deduplicated over
    /// the answer variables and sorted; each carries the proof of its first
    /// derivation, within the default [`ProofLimits`] for the whole result
    /// (see [`Model::ask_with`]).
    pub fn ask(&self, q: &QueryAst, config: RunConfig) -> Result<Vec<QueryAnswer>, AskError> {
        self.ask_with(q, config, ProofLimits::default())
    }

    /// [`Model::ask`] with explicit proof limits. `limits.max_nodes` is one
    /// budget for the proofs of *all* answers together, spent in the order
    /// of the sorted answers: per tree it would let a query with many
    /// answers print millions of lines into a retrieval context. Once it is
    /// spent, each further proof step is a single node (a base fact, or a
    /// [`DerivationTree::Truncated`] derived one), so every answer still
    /// names the facts it rests on.
    pub fn ask_with(
        &self,
        q: &QueryAst,
        config: RunConfig,
        limits: ProofLimits,
    ) -> Result<Vec<QueryAnswer>, AskError> {
        self.ask_within(q, config, limits, DEFAULT_MAX_ANSWERS)
    }

    /// [`Model::ask_with`] with an answer budget: more than `max` answers
    /// found (before duplicates are removed) is [`AskError::TooLarge`].
    /// `config.limit` is ignored: every answer is needed to sort them (take
    /// the first answers with [`Model::answers`]).
    pub fn ask_within(
        &self,
        q: &QueryAst,
        config: RunConfig,
        limits: ProofLimits,
        max: usize,
    ) -> Result<Vec<QueryAnswer>, AskError> {
        let program = self.compile(q, true)?;
        // The first derivation of each answer: its alternative and the
        // premise of each positive literal.
        let mut found: BTreeMap<Vec<Term>, Option<(usize, Vec<FactId>)>> = BTreeMap::new();
        let mut run = program.run(config.proofs, config.budget.clone());
        let mut raw = 0usize;
        for answer in run.by_ref() {
            let answer = answer?;
            raw += 1;
            if raw > max {
                return Err(AskError::TooLarge { limit: max });
            }
            found
                .entry(program.key(&answer))
                .or_insert_with(|| program.premises(&answer));
        }
        // Sorted before any proof is built: the node budget is spent in the
        // order of the sorted answers. (`found`'s own order is the terms'
        // order, by symbol number, which depends on the order names were
        // interned, so spending the budget in it made which answers got
        // full proofs differ from run to run.)
        let mut sorted: Vec<_> = found
            .into_iter()
            .map(|(vals, prem)| (sorted_bindings(&program.plan.names, &vals), prem))
            .collect();
        sorted.sort_by(|a, b| a.0.cmp(&b.0));
        let mut budget = limits.max_nodes;
        let out: Vec<QueryAnswer> = sorted
            .into_iter()
            .map(|(bindings, prem)| {
                let proof = match prem
                    .as_ref()
                    .and_then(|(alt, prem)| Some((program.rule(*alt)?, *alt, prem)))
                {
                    Some((rule, alt, prem)) if config.proofs => self.proof_from_premises(
                        rule,
                        program.not_exists(alt),
                        prem,
                        limits,
                        &mut budget,
                    ),
                    _ => Vec::new(),
                };
                QueryAnswer { bindings, proof }
            })
            .collect();
        match run.stop_reason() {
            Some(reason @ (StopReason::StepBudget | StopReason::TimeBudget)) => {
                Err(AskError::Budget {
                    reason,
                    partial: out,
                })
            }
            _ => Ok(out),
        }
    }

    /// The answers of a query one at a time, pulled from its kanren run
    /// (not sorted; [`Model::ask`] sorts), each distinct binding once, with
    /// its proof when `proofs` is set (each proof within `limits` on its
    /// own). Nothing beyond the answers taken is computed, so the first
    /// answers of a query with millions come at once:
    /// `answers(&q, None).take(10)`. A query that is not safe is
    /// [`AskError::Invalid`]. A run error ends the iteration
    /// ([`Answers::error`] says which).
    pub fn answers(
        &self,
        q: &QueryAst,
        proofs: Option<ProofLimits>,
    ) -> Result<Answers<'_>, AskError> {
        let program = self.compile(q, true)?;
        let run = program.run(proofs.is_some(), kanren::Budget::default());
        Ok(Answers {
            model: self,
            program,
            run,
            seen: std::collections::HashSet::new(),
            proofs,
            error: None,
        })
    }

    /// The proof of one derivation of a compiled query: a tree per positive
    /// literal (in the query's order) from its premise fact, then each
    /// negated literal as an absent fact; `budget` is what is left of the
    /// result's node budget and shrinks by each tree's size.
    fn proof_from_premises(
        &self,
        rule: &Rule,
        not_exists: &[NotExistsPlan],
        prem: &[FactId],
        limits: ProofLimits,
        budget: &mut usize,
    ) -> Vec<DerivationTree> {
        let mut trees = Vec::new();
        for (atom, &id) in rule.body.iter().zip(prem) {
            if let Some(t) = self.explain_id(atom.pred, id, limits, *budget) {
                *budget = budget.saturating_sub(t.size());
                trees.push(t);
            }
        }
        let binds = bind_from(rule, |p| self.rels.get(p).map(|r| &**r), prem);
        for n in &rule.negated {
            let args = n
                .args
                .iter()
                .map(|a| match a {
                    CArg::Const(c) => term_name(c),
                    CArg::Var(v) => binds
                        .get(*v)
                        .and_then(Option::as_ref)
                        .map(term_name)
                        .unwrap_or_else(|| rule.vars.get(*v).cloned().unwrap_or_default().into()),
                })
                .collect();
            trees.push(DerivationTree::Absent(GroundAtom {
                pred: self.name_of(n.pred),
                args,
            }));
        }
        for ne in not_exists {
            let value = |v: usize| binds.get(v).and_then(Option::as_ref).map(term_text);
            let name = |v: usize| rule.vars.get(v).cloned().unwrap_or_else(|| format!("_{v}"));
            trees.push(DerivationTree::NoMatch {
                formula: fol::literal_text(&ne.literal, &|v| value(v).unwrap_or_else(|| name(v))),
            });
        }
        trees
    }

    /// One alternative of a query as the kanren goal the answers come from:
    /// `kanren::join::join_where` of the positive atoms, with `naf` of each
    /// negated atom and `=`/`=/=` of each comparison tested inside it, over
    /// the model's relations. `to_term` gives
    /// the term of each query variable. A positive atom over an unknown
    /// predicate (or of the wrong arity) makes it `fail`.
    pub fn goal(&self, d: &[Literal], to_term: &dyn Fn(&Arg) -> Term) -> Goal {
        let mut vars: Vec<usize> = Vec::new();
        for l in d {
            vars.extend(l.free_vars());
            if let Literal::NotExists { .. } = l {
                vars.extend(fol::local_vars(l));
            }
        }
        let n = vars.iter().max().map_or(0, |m| m + 1);
        let names: Vec<String> = (0..n).map(|i| format!("v{i}")).collect();
        let q = QueryAst {
            source: SourceFile::new("<goal>", String::new()),
            vars: names,
            answer_vars: Vec::new(),
            disjuncts: vec![d.to_vec()],
            plans: PlanCache::default(),
        };
        let terms: Arc<[Term]> = (0..n).map(|v| to_term(&Arg::Var(v))).collect();
        match self.compile_query(&q, d, false) {
            Some(rule) => {
                let nes = self.compile_not_exists(&q, d);
                with_not_exists(&self.rels, self.rule_goal(&rule, &terms), &nes, &terms)
            }
            None => kanren::fail(),
        }
    }
}

/// An answer's `(variable, value)` pairs, sorted by variable name.
fn sorted_bindings<N: AsRef<str>>(names: &[N], values: &[Term]) -> Vec<(String, String)> {
    let mut b: Vec<(String, String)> = names
        .iter()
        .map(|n| n.as_ref().to_string())
        .zip(values.iter().map(term_text))
        .collect();
    b.sort();
    b
}

/// The lazy answers of a query ([`Model::answers`]): its kanren run, pulled
/// one answer at a time.
///
/// Invariant: `seen` holds the answer tuples already returned, so each
/// distinct binding comes once.
pub struct Answers<'m> {
    model: &'m Model,
    program: Compiled,
    run: kanren::Run,
    seen: std::collections::HashSet<Vec<Term>>,
    proofs: Option<ProofLimits>,
    error: Option<RunError>,
}

impl Answers<'_> {
    /// The error that ended the run early, if one did.
    pub fn error(&self) -> Option<&RunError> {
        self.error.as_ref()
    }

    /// Search steps taken so far (candidate facts tried, goals run).
    pub fn steps(&self) -> u64 {
        self.run.steps()
    }
}

impl Iterator for Answers<'_> {
    type Item = QueryAnswer;

    fn next(&mut self) -> Option<QueryAnswer> {
        loop {
            let answer = match self.run.next()? {
                Ok(a) => a,
                Err(e) => {
                    self.error = Some(e);
                    return None;
                }
            };
            let key = self.program.key(&answer);
            if self.seen.contains(&key) {
                continue;
            }
            let bindings = sorted_bindings(&self.program.plan.names, &key);
            let proof = match (self.proofs, self.program.premises(&answer)) {
                (Some(limits), Some((alt, prem))) => match self.program.rule(alt) {
                    Some(rule) => {
                        let mut budget = limits.max_nodes;
                        self.model.proof_from_premises(
                            rule,
                            self.program.not_exists(alt),
                            &prem,
                            limits,
                            &mut budget,
                        )
                    }
                    None => Vec::new(),
                },
                _ => Vec::new(),
            };
            self.seen.insert(key);
            return Some(QueryAnswer { bindings, proof });
        }
    }
}

impl Model {
    /// Answers a query without proofs: the distinct bindings of
    /// [`Model::ask`], sorted. For bulk question answering and benchmarks.
    pub fn bindings(&self, q: &QueryAst) -> Result<Vec<Vec<(String, String)>>, AskError> {
        self.bindings_within(q, DEFAULT_MAX_ANSWERS)
    }

    /// [`Model::bindings`] with an answer budget: more than `max` answers
    /// (counted before duplicates are removed) is [`AskError::TooLarge`].
    pub fn bindings_within(
        &self,
        q: &QueryAst,
        max: usize,
    ) -> Result<Vec<Vec<(String, String)>>, AskError> {
        let program = self.compile(q, true)?;
        let tuples = self.solve(&program, max)?;
        let mut out: Vec<Vec<(String, String)>> = tuples
            .into_iter()
            .map(|t| sorted_bindings(&program.plan.names, &t))
            .collect();
        out.sort();
        out.dedup();
        Ok(out)
    }

    /// The number of distinct answers (as [`Model::bindings`] would list them).
    pub fn count(&self, q: &QueryAst) -> Result<usize, AskError> {
        self.count_within(q, DEFAULT_MAX_ANSWERS)
    }

    /// [`Model::count`] with an answer budget. A query of one alternative
    /// whose answer variables are all its variables has exactly one answer
    /// per derivation (relations are sets), so it is counted without
    /// storing any answer, up to `max` × [`COUNT_FACTOR`] derivations;
    /// other queries keep their answers to remove duplicates, up to `max`.
    pub fn count_within(&self, q: &QueryAst, max: usize) -> Result<usize, AskError> {
        let program = self.compile(q, false)?;
        let all_answered = match program.plan.rules.as_slice() {
            [Some(rule)] => rule.body.iter().flat_map(|a| &a.args).all(|a| match a {
                CArg::Var(v) => q.answer_vars.contains(v),
                CArg::Const(_) => true,
            }),
            _ => false,
        };
        if !all_answered {
            return Ok(self.solve(&program, max)?.len());
        }
        let limit = max.saturating_mul(COUNT_FACTOR);
        let mut run = program.run(false, kanren::Budget::default());
        // A ground query (no answer variable) has one answer or none.
        let n = run.count_up_to(if q.answer_vars.is_empty() { 0 } else { limit })?;
        if n > limit {
            return Err(AskError::TooLarge { limit });
        }
        Ok(if q.answer_vars.is_empty() {
            n.min(1)
        } else {
            n
        })
    }

    /// Whether the query has an answer: its kanren run stops at the first
    /// match, and builds no answer for it.
    pub fn satisfiable(&self, q: &QueryAst) -> Result<bool, AskError> {
        let program = self.compile(q, false)?;
        Ok(program
            .run(false, kanren::Budget::default())
            .count_up_to(0)?
            > 0)
    }

    /// Distinct answer tuples (answer variables in order), in term order;
    /// more than `max` answers before duplicates are removed is too large.
    fn solve(&self, program: &Compiled, max: usize) -> Result<Vec<Vec<Term>>, AskError> {
        let mut all: std::collections::HashSet<Vec<Term>> = std::collections::HashSet::new();
        let mut raw = 0usize;
        for answer in program.run(false, kanren::Budget::default()) {
            let answer = answer?;
            raw += 1;
            if raw > max {
                return Err(AskError::TooLarge { limit: max });
            }
            all.insert(program.key(&answer));
        }
        let mut all: Vec<Vec<Term>> = all.into_iter().collect();
        all.sort();
        Ok(all)
    }

    /// A query alternative as a rule whose head lists the answer variables;
    /// `None` when a positive atom can never hold (unknown predicate or
    /// wrong arity). Negated atoms that can never hold are dropped.
    /// Without `full`, the rule keeps no variable names (only proofs read
    /// them).
    fn compile_query(&self, q: &QueryAst, d: &[Literal], full: bool) -> Option<Rule> {
        let carg = |a: &Arg| match a {
            Arg::Var(v) => CArg::Var(*v),
            Arg::Const(c) => CArg::Const(crate::eval::const_term(c)),
        };
        let resolve = |a: &fol::Atom| -> Option<CAtom> {
            let i = self.index_of(&a.pred)?;
            let rel = self.rels.get(i)?;
            (rel.arity() == a.args.len()).then(|| CAtom {
                pred: i,
                args: a.args.iter().map(carg).collect(),
            })
        };
        let mut body = Vec::new();
        let mut negated = Vec::new();
        let mut cmps = Vec::new();
        for l in d {
            match l {
                Literal::Pos(a) => body.push(resolve(a)?),
                Literal::Neg(a) => negated.extend(resolve(a)),
                Literal::Cmp {
                    left,
                    right,
                    negated: n,
                    ..
                } => cmps.push((carg(left), carg(right), *n)),
                // Compiled on its own (`compile_not_exists`), run after
                // this join as `naf`.
                Literal::NotExists { .. } => {}
            }
        }
        // The answers come from the kanren variables, not a head; a
        // query's rule has no text of its own.
        static NO_TEXT: std::sync::OnceLock<Arc<str>> = std::sync::OnceLock::new();
        Some(Rule {
            id: 0,
            head: CAtom {
                pred: 0,
                args: Vec::new(),
            },
            body: body.into(),
            negated,
            cmps,
            vars: if full { q.vars.clone() } else { Vec::new() },
            source: RuleSource {
                entry: String::new(),
                text: NO_TEXT.get_or_init(|| "".into()).clone(),
                line: 1,
                span: Default::default(),
            },
        })
    }
}
