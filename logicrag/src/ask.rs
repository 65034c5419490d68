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
    /// The metric view of this outcome.
    pub fn said(self) -> crate::metrics::Said {
        use crate::metrics::Said;
        match self {
            Outcome::Yes => Said::Yes,
            Outcome::No => Said::No,
            Outcome::Unknown => Said::Unknown,
            Outcome::Invalid => Said::Invalid,
        }
    }
}

/// One candidate object of a "no" answer and the conjuncts it fails.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct WhyNot {
    /// The query variable.
    pub variable: String,
    /// The candidate constant.
    pub candidate: String,
    /// Conjuncts (with the candidate substituted) that hold.
    pub satisfied: Vec<String>,
    /// Conjuncts that fail.
    pub failed: Vec<String>,
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
}

impl Default for AskOptions {
    fn default() -> Self {
        AskOptions {
            proofs: true,
            why_not: true,
            count_only: false,
            max_answers: logicpad::DEFAULT_MAX_ANSWERS,
            proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
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
    };
    /// Counts only (the KB benchmark's answers).
    pub const COUNT: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: true,
        max_answers: logicpad::DEFAULT_MAX_ANSWERS,
        proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
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
            let names = u.vars.join(", ");
            for b in counter.iter().take(WHY_NOT_CANDIDATES) {
                let subst: Vec<String> = b.iter().map(|(_, c)| c.clone()).collect();
                result.why_not.push(WhyNot {
                    variable: names.clone(),
                    candidate: subst.join(", "),
                    satisfied: vec![left.clone()],
                    failed: vec![right.clone()],
                });
            }
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
const WHY_NOT_CANDIDATES: usize = 3;

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
                result.why_not = why_not(pad, kb, ast);
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

/// Why-not for a failed conjunctive query: for each answer variable, the
/// window's objects that satisfy the most conjuncts mentioning only that
/// variable (with the others existential), and the conjuncts they fail.
fn why_not(pad: &LogicPad, kb: &WindowKb, ast: &QueryAst) -> Vec<WhyNot> {
    let Some(conj) = ast.disjuncts.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for &v in &ast.answer_vars {
        let name = ast.vars.get(v).cloned().unwrap_or_default();
        let mentions: Vec<&Literal> = conj.iter().filter(|l| mentions_var(l, v)).collect();
        if mentions.is_empty() {
            continue;
        }
        // Candidates must be what the query asks about: for "the van",
        // vans (when there are any), never poles and buildings.
        let identity: Vec<bool> = mentions.iter().map(|l| is_identity(pad, l, v)).collect();
        let (any_of_kind, mut scored) = scores(kb, ast, v, &mentions, &identity);
        if !any_of_kind && identity.contains(&true) {
            let what: Vec<String> = mentions
                .iter()
                .zip(&identity)
                .filter(|(_, id)| **id)
                .map(|(l, _)| literal_text(l, ast, None))
                .collect();
            out.push(WhyNot {
                variable: name.clone(),
                candidate: "(none)".into(),
                satisfied: Vec::new(),
                failed: vec![format!(
                    "no object of the window satisfies {}",
                    what.join(" ∧ ")
                )],
            });
            continue;
        }
        // Score every candidate by the literals it satisfies, then put
        // into words only the few that are shown: a window of a thousand
        // objects asked a thousand questions must not format a million
        // sentences to print thirty.
        scored.sort_unstable_by(|a, b| b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1)));
        scored.truncate(WHY_NOT_CANDIDATES);
        for (_, obj, holds) in scored {
            let mut satisfied = Vec::new();
            let mut failed = Vec::new();
            for (lit, h) in mentions.iter().zip(holds) {
                let text = literal_text(lit, ast, Some((v, obj)));
                if h {
                    satisfied.push(text);
                } else {
                    failed.push(text);
                }
            }
            if failed.is_empty() && !satisfied.is_empty() {
                // Every part holds on its own; what fails is the join
                // through the other variables.
                failed.push(format!(
                    "{} together (no common binding of the other variables)",
                    satisfied.join(" ∧ ")
                ));
            }
            out.push(WhyNot {
                variable: name.clone(),
                candidate: obj.to_string(),
                satisfied,
                failed,
            });
        }
    }
    out
}

/// Why-not's candidates for variable `v`: whether some object of the
/// window satisfies every identity literal (`identity[i]` says which of
/// `mentions` are), and each candidate that satisfies the identity
/// literals and at least one literal, with how many and which (in
/// `mentions` order), in no particular order. Only the candidates that can
/// score are visited; a test holds the result to the definition (every
/// object, every literal decided by a scan of its relation).
fn scores<'k>(
    kb: &'k WindowKb,
    ast: &QueryAst,
    v: usize,
    mentions: &[&Literal],
    identity: &[bool],
) -> (bool, Vec<(usize, &'k str, Holds)>) {
    // Each literal's constants interned once, not once per candidate.
    let consts: Vec<Consts> = mentions.iter().map(|l| literal_consts(l)).collect();
    // Each atom's holders found once, by one probe of its relation,
    // instead of one probe per object: why-not runs for every "no" of
    // a batch, over every object of the window.
    let checks: Vec<Check> = mentions
        .iter()
        .zip(&consts)
        .map(|(l, c)| Check::of(kb, l, c, v))
        .collect();
    // One pass over the objects decides every literal for each: the
    // identity literals pick the candidates, all of them score it.
    // With an identity literal, only its holders can be candidates:
    // the smallest such set is walked instead of every object (a
    // window of a thousand objects has a handful of vans).
    let narrowest = checks
        .iter()
        .zip(identity)
        .filter_map(|(k, &id)| match k {
            Check::Holders(set, false) if id => Some(set),
            _ => None,
        })
        .min_by_key(|set| set.len());
    let candidates: Vec<(&str, kanren::Sym)> = match narrowest {
        // In any order: the ranking below is a total order.
        Some(set) => set
            .iter()
            .filter(|&&s| kb.is_object(s))
            .map(|&s| (s.as_str(), s))
            .collect(),
        // Without one, an object that holds no literal scores nothing
        // and is not shown: when every literal is a positive atom, the
        // union of their holders is every object that can score.
        None if checks.iter().all(|k| matches!(k, Check::Holders(_, false))) => {
            let mut all: Vec<kanren::Sym> = checks
                .iter()
                .flat_map(|k| match k {
                    Check::Holders(set, _) => set.as_slice(),
                    Check::PerObject => &[],
                })
                .copied()
                .collect();
            all.sort_unstable();
            all.dedup();
            all.into_iter()
                .filter(|&s| kb.is_object(s))
                .map(|s| (s.as_str(), s))
                .collect()
        }
        None => kb.objects_with_syms().collect(),
    };
    let mut of_kind = 0usize;
    let mut scored: Vec<(usize, &str, Holds)> = Vec::new();
    for (obj, sym) in candidates {
        let holds: Holds = checks
            .iter()
            .zip(mentions)
            .map(|(k, lit)| k.holds(lit, ast, v, (obj, sym)))
            .collect();
        if holds.iter().zip(identity).any(|(&h, &id)| id && !h) {
            continue;
        }
        of_kind += 1;
        let n = holds.iter().filter(|&&h| h).count();
        if n > 0 {
            scored.push((n, obj, holds));
        }
    }
    (of_kind > 0, scored)
}

/// Whether a literal says what kind of object variable `v` is: its class
/// (a predicate of the `semantic_segmentation` group, or a derived alias
/// of classes such as `IsPerson`) or its `TypeOf`.
fn is_identity(pad: &LogicPad, l: &Literal, v: usize) -> bool {
    let Literal::Pos(a) = l else {
        return false;
    };
    let on_v = matches!(a.args.first(), Some(Arg::Var(x)) if *x == v);
    if !on_v {
        return false;
    }
    if a.pred == "TypeOf" {
        return matches!(a.args.get(1), Some(Arg::Const(_)));
    }
    if a.args.len() != 1 {
        return false;
    }
    let is_class = |name: &str| {
        pad.schema()
            .get(name)
            .is_some_and(|p| p.group.as_deref() == Some("semantic_segmentation"))
    };
    if is_class(&a.pred) {
        return true;
    }
    // A derived alias whose every rule rests on classes alone.
    let program = pad.program();
    let Some(pid) = program.pred_id(&a.pred) else {
        return false;
    };
    let rules: Vec<_> = program
        .rules()
        .iter()
        .filter(|r| r.head.pred == pid)
        .collect();
    !rules.is_empty()
        && rules.iter().all(|r| {
            r.negated.is_empty()
                && r.body.iter().all(|b| {
                    program
                        .pred_name(b.pred)
                        .is_some_and(|n| is_class(n) || n == "TypeOf")
                })
        })
}

/// Whether variable `v` is an argument of `l`.
fn mentions_var(l: &Literal, v: usize) -> bool {
    let is_v = |a: &Arg| matches!(a, Arg::Var(x) if *x == v);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().any(is_v),
        Literal::Cmp { left, right, .. } => is_v(left) || is_v(right),
    }
}

fn arg_str<'a>(a: &'a Arg, ast: &'a QueryAst, subst: Option<(usize, &'a str)>) -> &'a str {
    match a {
        Arg::Var(v) => match subst {
            Some((sv, c)) if sv == *v => c,
            _ => ast.vars.get(*v).map_or("", String::as_str),
        },
        Arg::Const(c) => c,
    }
}

/// A literal as query text, optionally with one variable replaced.
pub fn literal_text(l: &Literal, ast: &QueryAst, subst: Option<(usize, &str)>) -> String {
    // Built in one buffer of about the right size: why-not writes a few of
    // these for every "no" of a batch.
    let mut out = String::with_capacity(48);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => {
            if matches!(l, Literal::Neg(_)) {
                out.push('¬');
            }
            out.push_str(&a.pred);
            out.push('(');
            for (i, x) in a.args.iter().enumerate() {
                if i > 0 {
                    out.push_str(", ");
                }
                out.push_str(arg_str(x, ast, subst));
            }
            out.push(')');
        }
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => {
            out.push_str(arg_str(left, ast, subst));
            out.push_str(if *negated { " ≠ " } else { " = " });
            out.push_str(arg_str(right, ast, subst));
        }
    }
    out
}

/// Whether one literal holds with variable `v` set to `obj` (other
/// variables existential; a negated literal with other free variables is
/// read as "no binding of them makes the atom hold").
/// A literal's constant arguments as terms, by position (`None` for a
/// variable), for [`literal_holds`].
type Consts = smallvec::SmallVec<[Option<kanren::Term>; 4]>;

/// Which of a why-not variable's literals one candidate satisfies, in
/// literal order (inline up to eight: one allocation less per object).
type Holds = smallvec::SmallVec<[bool; 8]>;

fn literal_consts(l: &Literal) -> Consts {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a
            .args
            .iter()
            .map(|x| match x {
                Arg::Const(c) => Some(logicpad::const_term(c)),
                Arg::Var(_) => None,
            })
            .collect(),
        Literal::Cmp { .. } => Consts::new(),
    }
}

/// How why-not decides a literal for one candidate object.
enum Check {
    /// An atom: the values of the why-not variable that some fact gives it
    /// (the literal's other variables existential), and whether the atom is
    /// negated.
    /// (Sorted and without duplicates, searched by binary search: the
    /// sets are small and built once per "no", where hashing cost more.)
    Holders(Vec<kanren::Sym>, bool),
    /// A comparison, decided per object by [`cmp_holds`].
    PerObject,
}

impl Check {
    fn of(kb: &WindowKb, l: &Literal, consts: &Consts, v: usize) -> Check {
        let (atom, neg) = match l {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => return Check::PerObject,
        };
        let mut set = Vec::new();
        let Some(rel) = kb.model.relation(&atom.pred) else {
            return Check::Holders(set, neg);
        };
        let pattern: smallvec::SmallVec<[Option<&kanren::Term>; 4]> = atom
            .args
            .iter()
            .zip(consts)
            .map(|(a, c)| match a {
                Arg::Const(_) => c.as_ref(),
                Arg::Var(_) => None,
            })
            .collect();
        let at: smallvec::SmallVec<[usize; 2]> = atom
            .args
            .iter()
            .enumerate()
            .filter(|(_, a)| matches!(a, Arg::Var(x) if *x == v))
            .map(|(i, _)| i)
            .collect();
        // Nothing but the why-not variable, at one position: its holders
        // are that position's distinct values, read off the index.
        if let [pos] = at[..]
            && pattern.iter().all(Option::is_none)
        {
            set.extend(rel.values_at(pos).filter_map(|t| match t {
                kanren::Term::Sym(s) => Some(*s),
                _ => None,
            }));
            set.sort_unstable();
            return Check::Holders(set, neg);
        }
        for id in rel.lookup(&pattern) {
            let Some(t) = rel.tuple(id) else { continue };
            let mut vals = at.iter().filter_map(|&i| t.get(i));
            // `P(x, x)`: every position of the variable takes one value.
            if let Some(kanren::Term::Sym(first)) = vals.next()
                && vals.all(|o| matches!(o, kanren::Term::Sym(s) if s == first))
            {
                set.push(*first);
            }
        }
        set.sort_unstable();
        set.dedup();
        Check::Holders(set, neg)
    }

    fn holds(
        &self,
        l: &Literal,
        ast: &QueryAst,
        v: usize,
        (obj, obj_sym): (&str, kanren::Sym),
    ) -> bool {
        match self {
            Check::Holders(set, neg) => set.binary_search(&obj_sym).is_ok() != *neg,
            Check::PerObject => cmp_holds(l, ast, v, obj),
        }
    }
}

/// Whether a comparison holds with `v` bound to `obj`.
fn cmp_holds(l: &Literal, ast: &QueryAst, v: usize, obj: &str) -> bool {
    let Literal::Cmp {
        left,
        right,
        negated,
        ..
    } = l
    else {
        return true;
    };
    // Another free variable on either side is existential: the comparison
    // alone cannot rule `obj` out (its name is not a constant to compare
    // with).
    let free = |a: &Arg| matches!(a, Arg::Var(x) if *x != v);
    if free(left) || free(right) {
        return true;
    }
    let eq = arg_str(left, ast, Some((v, obj))) == arg_str(right, ast, Some((v, obj)));
    eq != *negated
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::kb::test_window;

    /// Whether literal `l` holds with `v` bound to `obj`, by definition: a
    /// scan of every fact of its relation (other variables existential).
    fn holds_by_scan(kb: &WindowKb, ast: &QueryAst, l: &Literal, v: usize, obj: &str) -> bool {
        let (atom, neg) = match l {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => return cmp_holds(l, ast, v, obj),
        };
        let some = kb.model.relation(&atom.pred).is_some_and(|rel| {
            rel.iter().any(|(_, t)| {
                t.len() == atom.args.len()
                    && atom.args.iter().zip(t.iter()).all(|(a, x)| match a {
                        Arg::Const(c) => x.as_sym().is_some_and(|s| s.as_str() == c),
                        Arg::Var(w) if *w == v => x.as_sym().is_some_and(|s| s.as_str() == obj),
                        Arg::Var(_) => true,
                    })
            })
        });
        some != neg
    }

    #[test]
    fn why_not_scores_equal_the_definition() {
        // `scores` visits only the objects that can score and decides
        // literals from holder sets; by definition every object is tried
        // and every literal decided by scanning its relation.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Vehicles", &["car_1"]),
                ("Vehicles", &["car_2"]),
                ("Vehicles", &["van_3"]),
                ("Pedestrian", &["ped_4"]),
                ("Road", &["road_5"]),
                ("TypeOf", &["car_1", "Car"]),
                ("TypeOf", &["car_2", "Car"]),
                ("TypeOf", &["van_3", "Van"]),
                ("ColorOf", &["car_1", "Red"]),
                ("ColorOf", &["car_2", "White"]),
                ("ColorOf", &["van_3", "White"]),
                ("Moving", &["car_1"]),
                ("Moving", &["ped_4"]),
                ("SpeedUp", &["car_2"]),
                ("DistanceDecrease", &["car_1", "ped_4"]),
                ("DistanceDecrease", &["van_3", "van_3"]),
                ("On", &["car_1", "road_5"]),
                ("On", &["ped_4", "road_5"]),
            ],
        );
        let queries = [
            // An identity literal, narrow and empty.
            "TypeOf(x, Car) ^ ColorOf(x, White) ^ Moving(x)",
            "Vehicles(x) ^ TypeOf(x, Bus)",
            // No identity literal, all positive: the union of holders.
            "Moving(x) ^ SpeedUp(x) ^ ColorOf(x, Red)",
            "Moving(x) ^ On(x, road_5) ^ SpeedUp(x)",
            // Negations and comparisons: every object is a candidate.
            "Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, White)",
            "Moving(x) ^ x != car_1 ^ SpeedUp(x)",
            "Vehicles(x) ^ ¬Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, Red)",
            // Two variables, a repeated variable, existential others.
            "Vehicles(x) ^ Pedestrian(y) ^ DistanceDecrease(x, y) ^ SpeedUp(x)",
            "DistanceDecrease(x, x) ^ Moving(x)",
            "Pedestrian(y) ^ Vehicles(x) ^ ¬DistanceDecrease(x, y) ^ On(y, z) ^ SpeedUp(y)",
        ];
        for q in queries {
            let Ok(ParsedQuery::Exists(ast)) = prepare(&pad, q) else {
                panic!("{q} must prepare as an existential query");
            };
            let conj = ast.disjuncts.first().expect("one conjunction");
            for &v in &ast.answer_vars {
                let mentions: Vec<&Literal> = conj.iter().filter(|l| mentions_var(l, v)).collect();
                let identity: Vec<bool> =
                    mentions.iter().map(|l| is_identity(&pad, l, v)).collect();
                let (any_of_kind, mut fast) = scores(&kb, &ast, v, &mentions, &identity);
                let mut of_kind = 0;
                let mut slow: Vec<(usize, &str, Holds)> = Vec::new();
                for obj in &kb.objects {
                    let holds: Holds = mentions
                        .iter()
                        .map(|l| holds_by_scan(&kb, &ast, l, v, obj))
                        .collect();
                    if holds.iter().zip(&identity).any(|(&h, &id)| id && !h) {
                        continue;
                    }
                    of_kind += 1;
                    let n = holds.iter().filter(|&&h| h).count();
                    if n > 0 {
                        slow.push((n, obj, holds));
                    }
                }
                let rank = |a: &(usize, &str, Holds), b: &(usize, &str, Holds)| {
                    b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1))
                };
                fast.sort_by(rank);
                slow.sort_by(rank);
                assert_eq!(fast, slow, "{q}, variable {v}");
                if identity.contains(&true) {
                    assert_eq!(any_of_kind, of_kind > 0, "{q}, variable {v}");
                }
            }
        }
    }
}
