//! Asking a window: a query (or a question, through the translator) becomes
//! one of four outcomes that are never confused — **yes** with every binding
//! and its proof, **no** with why-not, **unknown** when the source cannot
//! observe what the query needs, **invalid** when the query does not fit the
//! LogicPad.

use crate::kb::{Observed, WindowKb};
use kanren::RunConfig;
use logicpad::fol::{Arg, Literal};
use logicpad::{LogicPad, ParsedQuery, QueryAnswer, QueryAst, check_any_query, parse_any_query};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

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

pub use crate::whynot::WhyNot;

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
    pub fn proof_limits(&self) -> logicpad::ProofLimits {
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

/// Parses a query and checks it against the LogicPad, once for every
/// window: whether a name is a variable depends on its spelling alone
/// ([`logicpad::is_variable_name`]), never on the window's contents.
pub fn prepare(pad: &LogicPad, query: &str) -> Result<ParsedQuery, Vec<logicpad::Diagnostic>> {
    let parsed = parse_any_query(query).map_err(|d| vec![d])?;
    let errors: Vec<logicpad::Diagnostic> = check_any_query(pad.schema(), &parsed)
        .into_iter()
        .filter(|d| d.is_error())
        .collect();
    if errors.is_empty() {
        Ok(parsed)
    } else {
        Err(errors)
    }
}

/// Runs a query written as text on a window. `observed` is the source's
/// observability of every predicate (from
/// [`crate::kb::Observability::classify`]). For many windows, prepare the
/// query once and use [`ask_parsed`] (the [`crate::engine::Engine`] does).
pub fn ask(
    pad: &LogicPad,
    kb: &WindowKb,
    observed: &BTreeMap<String, Observed>,
    query: &str,
    opts: AskOptions,
) -> AskResult {
    let blind = Blindness {
        observed,
        observability: None,
    };
    match prepare(pad, query) {
        Ok(parsed) => ask_parsed(pad, kb, &blind, &parsed, opts),
        Err(diags) => invalid(kb, query, &diags),
    }
}

/// The "invalid" answer of a query that does not fit the LogicPad.
pub fn invalid(kb: &WindowKb, query: &str, diagnostics: &[logicpad::Diagnostic]) -> AskResult {
    let mut r = AskResult::empty(kb, query);
    r.diagnostics = diagnostics.iter().map(Problem::new).collect();
    r.reasons = r.diagnostics.iter().map(Problem::sentence).collect();
    r
}

/// What a source cannot see: the per-predicate classification, and the
/// source's reasons when they are at hand (for answers in words).
#[derive(Debug, Clone, Copy)]
pub struct Blindness<'a> {
    /// Observability of every predicate.
    pub observed: &'a BTreeMap<String, Observed>,
    /// The source's unobservable base predicates with their reasons.
    pub observability: Option<&'a crate::kb::Observability>,
}

impl AskResult {
    /// An answer with nothing in it yet (outcome `invalid`).
    fn empty(kb: &WindowKb, query: &str) -> AskResult {
        AskResult {
            window: kb.id.clone(),
            first_frame: kb.first_frame,
            last_frame: kb.last_frame,
            query: query.to_string(),
            answer: Outcome::Invalid,
            variables: Vec::new(),
            count: 0,
            bindings: Vec::new(),
            proofs: Vec::new(),
            why_not: Vec::new(),
            reasons: Vec::new(),
            diagnostics: Vec::new(),
            notes: Vec::new(),
            too_large: None,
        }
    }
}

impl AskResult {
    /// The answer with one more reason (an invalid answer's cause in words).
    pub fn with_reason(mut self, reason: String) -> AskResult {
        self.reasons.push(reason);
        self
    }
}

/// An engine error makes the answer invalid: its diagnostics when it has
/// them (an unsafe query), else its message.
fn set_error(result: &mut AskResult, e: &logicpad::AskError) {
    result.answer = Outcome::Invalid;
    match e {
        logicpad::AskError::Invalid(diags) => {
            result.diagnostics = diags.iter().map(Problem::new).collect();
            result.reasons = result.diagnostics.iter().map(Problem::sentence).collect();
        }
        other => {
            if let logicpad::AskError::TooLarge { limit } = other {
                result.too_large = Some(*limit);
            }
            result.reasons = vec![other.to_string()];
        }
    }
}

/// A diagnostic of an invalid query, as data: rendering (a caret under the
/// query, one sentence for a language model) happens at the edges.
#[derive(Debug, Clone, Serialize)]
pub struct Problem {
    /// The diagnostic's code, e.g. `logicpad::unknown_predicate`.
    pub code: &'static str,
    /// What is wrong.
    pub message: String,
    /// How to fix it, when known.
    pub help: Option<String>,
    /// 1-based line in the query.
    pub line: usize,
    /// 1-based column in the query.
    pub column: usize,
    /// The full diagnostic, for renderers that show the query with a caret.
    #[serde(skip)]
    pub diagnostic: logicpad::Diagnostic,
}

impl Problem {
    /// The diagnostic as data.
    pub fn new(d: &logicpad::Diagnostic) -> Problem {
        Problem {
            code: d.kind.code(),
            message: d.message.clone(),
            help: d.help.clone(),
            line: d.line(),
            column: d.column(),
            diagnostic: d.clone(),
        }
    }

    /// One sentence: the message, and the help in parentheses.
    pub fn sentence(&self) -> String {
        match &self.help {
            Some(h) => format!("{} ({h})", self.message),
            None => self.message.clone(),
        }
    }
}

/// Runs a prepared query on a window: an existential query by its
/// bindings, a universal one through its counterexamples.
pub fn ask_parsed(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    query: &ParsedQuery,
    opts: AskOptions,
) -> AskResult {
    let mut result = AskResult::empty(kb, query.text());
    match query {
        ParsedQuery::Exists(ast) => {
            result.variables = ast
                .answer_var_names()
                .into_iter()
                .map(str::to_string)
                .collect();
            ask_prepared(pad, kb, blind, ast, opts, result)
        }
        ParsedQuery::Forall(u) => ask_universal(pad, kb, blind, u, opts, result),
    }
}

/// Constants of the query that the window never mentions and that every
/// alternative needs in a positive atom: the query cannot hold, whatever
/// the source observes. (A constant only under `¬` proves nothing absent.)
fn absent_constants(pad: &LogicPad, kb: &WindowKb, ast: &QueryAst) -> Vec<String> {
    // A rule's constants are interned: a name the interner does not know
    // is in no rule, and one it knows is compared as a symbol, not a string.
    let in_rules = |c: &str| {
        let Some(sym) = kanren::Sym::lookup(c) else {
            return false;
        };
        pad.program().rules().iter().any(|r| {
            r.head
                .args
                .iter()
                .chain(r.body.iter().flat_map(|a| a.args.iter()))
                .any(|a| matches!(a, logicpad::CArg::Const(kanren::Term::Sym(s)) if *s == sym))
        })
    };
    // A declared value (`White`) names no object: its absence is a matter
    // of what the source observes, which the outcome logic decides.
    let declared = |c: &str| {
        pad.schema()
            .predicates()
            .any(|p| p.values.as_ref().is_some_and(|v| v.iter().any(|x| x == c)))
    };
    let mut all: BTreeSet<String> = BTreeSet::new();
    for d in &ast.disjuncts {
        let missing: BTreeSet<String> = d
            .iter()
            .filter_map(Literal::positive)
            .flat_map(|a| a.args.iter())
            .filter_map(|x| if let Arg::Const(c) = x { Some(c) } else { None })
            // A name the interner does not know occurs in no fact.
            .filter(|c| {
                !kanren::Sym::lookup(c).is_some_and(|s| kb.is_constant(s))
                    && !in_rules(c)
                    && !declared(c)
            })
            .cloned()
            .collect();
        if missing.is_empty() {
            return Vec::new();
        }
        all.extend(missing);
    }
    all.into_iter().collect()
}

/// Why an atom's predicate makes an answer a guess, in words: the
/// predicate, and what the source lacks.
fn blind_reason(pad: &LogicPad, blind: &Blindness<'_>, pred: &str, status: Observed) -> String {
    if status == Observed::Never && has_no_rule(pad, pred) {
        return format!(
            "`{pred}` is derived but none of its rules loaded (the LogicPad has errors; \
             `logicrag lint` shows them)"
        );
    }
    let words = crate::translate::default_phrase(pred);
    let spots = blind
        .observability
        .map(|o| o.blind_spots(pad, pred))
        .unwrap_or_default();
    let lacks = if spots.is_empty() {
        String::new()
    } else {
        let mut reasons: Vec<&str> = spots.iter().map(|(_, w)| w.as_str()).collect();
        reasons.sort();
        reasons.dedup();
        let via = if spots.len() == 1 && spots.first().is_some_and(|(p, _)| p == pred) {
            String::new()
        } else {
            let names: Vec<String> = spots.iter().map(|(p, _)| format!("`{p}`")).collect();
            format!(", which rests on {}", names.join(", "))
        };
        format!("{via}: {}", reasons.join("; "))
    };
    match status {
        Observed::Partly => format!("this source observes `{pred}` ({words}) only in part{lacks}"),
        _ => format!("this source cannot observe `{pred}` ({words}){lacks}"),
    }
}

/// Answers `∀x: A → B` under the closed world: "yes" when no object of the
/// window satisfies `A ∧ ¬B` (every binding of `A` then comes with the
/// proof of `B`), "no" with the counterexamples. Every predicate must be
/// fully observed: an object the source cannot see could break the rule,
/// and `¬B` on a partly observed `B` is a guess.
fn ask_universal(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    u: &logicpad::UniversalQuery,
    opts: AskOptions,
    mut result: AskResult,
) -> AskResult {
    let mut reasons: Vec<String> = u
        .counterexamples
        .disjuncts
        .iter()
        .flatten()
        .filter_map(|l| match l {
            Literal::Pos(a) | Literal::Neg(a) => Some(a.pred.as_str()),
            Literal::Cmp { .. } => None,
        })
        .filter_map(|p| {
            let s = blind.observed.get(p).copied().unwrap_or(Observed::Never);
            (s != Observed::Fully).then(|| blind_reason(pad, blind, p, s))
        })
        .collect();
    reasons.sort();
    reasons.dedup();
    if !reasons.is_empty() {
        result.answer = Outcome::Unknown;
        result.reasons = reasons;
        return result;
    }
    let (left, right) = (u.antecedent.clone(), u.consequent.clone());
    let counter = match kb
        .model
        .bindings_within(&u.counterexamples, opts.max_answers)
    {
        Ok(c) => c,
        Err(e) => {
            set_error(&mut result, &e);
            return result;
        }
    };
    let domain = kb
        .model
        .count_within(&u.domain, opts.max_answers)
        .unwrap_or(0);
    let objects = |n: usize| format!("{n} object{}", if n == 1 { "" } else { "s" });
    if !counter.is_empty() {
        result.answer = Outcome::No;
        result.count = counter.len();
        result.notes.push(format!(
            "{} of the {} that satisfy {left} {} not satisfy {right}",
            counter.len(),
            objects(domain),
            if counter.len() == 1 { "does" } else { "do" }
        ));
        if opts.why_not {
            result.why_not = crate::whynot::universal(&left, &right, &counter);
        }
        return result;
    }
    result.answer = Outcome::Yes;
    if domain == 0 {
        result.notes.push(format!(
            "vacuously true: no object satisfies {left} in this window"
        ));
        return result;
    }
    result.notes.push(format!(
        "holds for every one of the {} that satisfy {left}",
        objects(domain)
    ));
    let witnesses = if opts.proofs {
        kb.model.ask_within(
            &u.witnesses,
            RunConfig {
                proofs: true,
                ..RunConfig::default()
            },
            opts.proof_limits(),
            opts.max_answers,
        )
    } else {
        kb.model
            .bindings_within(&u.witnesses, opts.max_answers)
            .map(|b| {
                b.into_iter()
                    .map(|bindings| QueryAnswer {
                        bindings,
                        proof: Vec::new(),
                    })
                    .collect()
            })
    };
    match witnesses {
        Ok(w) => {
            result.count = w.len();
            for a in &w {
                result.bindings.push(a.bindings.clone());
                if opts.proofs {
                    result.proofs.push(crate::proof::of_answer(kb, a));
                }
            }
        }
        Err(e) => {
            result.answer = Outcome::Invalid;
            set_error(&mut result, &e);
        }
    }
    result
}

/// How many counterexamples or candidates a "no" lists.
pub(crate) const WHY_NOT_CANDIDATES: usize = 3;

fn ask_prepared(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    ast: &QueryAst,
    opts: AskOptions,
    mut result: AskResult,
) -> AskResult {
    let absent = absent_constants(pad, kb, ast);
    if !absent.is_empty() {
        result.answer = Outcome::No;
        let frames = if kb.first_frame == kb.last_frame {
            format!("frame {}", kb.first_frame)
        } else {
            format!("frames {}–{}", kb.first_frame, kb.last_frame)
        };
        for c in absent {
            result.notes.push(format!("{c} is not seen in {frames}"));
        }
        return result;
    }
    // With proofs the query runs as kanren goals and each answer carries
    // its derivation; without, logicpad's index joins give the same answer
    // set (a property test holds them equal) at a fraction of the cost.
    let answers: Result<(usize, Vec<QueryAnswer>), logicpad::AskError> = if opts.count_only {
        kb.model
            .count_within(ast, opts.max_answers)
            .map(|n| (n, Vec::new()))
    } else if !opts.proofs {
        kb.model.bindings_within(ast, opts.max_answers).map(|b| {
            (
                b.len(),
                b.into_iter()
                    .map(|bindings| QueryAnswer {
                        bindings,
                        proof: Vec::new(),
                    })
                    .collect(),
            )
        })
    } else {
        kb.model
            .ask_within(
                ast,
                RunConfig {
                    proofs: true,
                    budget: kanren::Budget {
                        max_time: opts.max_time,
                        ..kanren::Budget::default()
                    },
                    ..RunConfig::default()
                },
                opts.proof_limits(),
                opts.max_answers,
            )
            .map(|a| (a.len(), a))
    };
    let (count, answers) = match answers {
        Ok(a) => a,
        Err(e) => {
            result.answer = Outcome::Invalid;
            set_error(&mut result, &e);
            return result;
        }
    };
    // Negated atoms over predicates the source does not fully observe make
    // even a found binding a guess.
    let mut blind_neg = Vec::new();
    let mut blind_pos = Vec::new();
    for lit in ast.disjuncts.iter().flatten() {
        let (atom, neg) = match lit {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => continue,
        };
        let s = blind
            .observed
            .get(&atom.pred)
            .copied()
            .unwrap_or(Observed::Never);
        if s != Observed::Fully {
            let why = blind_reason(pad, blind, &atom.pred, s);
            if neg {
                blind_neg.push(why)
            } else {
                blind_pos.push(why)
            }
        }
    }
    if !blind_neg.is_empty() {
        result.answer = Outcome::Unknown;
        blind_neg.sort();
        blind_neg.dedup();
        result.reasons = blind_neg;
        return result;
    }
    if count == 0 {
        if blind_pos.is_empty() {
            result.answer = Outcome::No;
            if opts.why_not {
                result.why_not = crate::whynot::why_not(pad, kb, ast);
            }
        } else {
            result.answer = Outcome::Unknown;
            blind_pos.sort();
            blind_pos.dedup();
            result.reasons = blind_pos;
        }
        return result;
    }
    result.answer = Outcome::Yes;
    result.count = count;
    for a in &answers {
        result.bindings.push(a.bindings.clone());
        if opts.proofs {
            result.proofs.push(crate::proof::of_answer(kb, a));
        }
    }
    result
}

/// Whether `pred` is a derived predicate without a single loaded rule: its
/// rules were rejected, so "unknown" is the LogicPad's fault, not the
/// source's.
fn has_no_rule(pad: &LogicPad, pred: &str) -> bool {
    let derived = pad
        .schema()
        .predicates()
        .any(|p| p.name == pred && p.kind == logicpad::PredKind::Derived);
    let program = pad.program();
    derived
        && program
            .pred_id(pred)
            .is_none_or(|id| program.rules().iter().all(|r| r.head.pred != id))
}
