//! Asking a window: a query (or a question, through the translator) becomes
//! one of four outcomes that are never confused — **yes** with every binding
//! and its proof, **no** with why-not, **unknown** when the source cannot
//! observe what the query needs, **invalid** when the query does not fit the
//! LogicPad.

use crate::kb::{Observed, WindowKb};
use logicpad::fol::{Arg, Literal};
use logicpad::{LogicPad, ParsedQuery, QueryAnswer, QueryAst, check_any_query, parse_any_query};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

mod blind;
mod count;
mod outcome;
mod universal;

pub(crate) use blind::Blindness;
pub(crate) use blind::all_fully;
use blind::*;
use count::*;
pub(crate) use count::{Bound, bound_of_note, decide, noun_of_var};
pub use outcome::{AskOptions, AskResult, Outcome};
use universal::*;

pub use crate::whynot::WhyNot;

/// Parses a query and checks it against the LogicPad, once for every
/// window: whether a name is a variable depends on its spelling alone
/// ([`logicpad::is_variable_name`]), never on the window's contents.
pub fn prepare(pad: &LogicPad, query: &str) -> Result<ParsedQuery, Vec<logicpad::Diagnostic>> {
    check(pad, parse_any_query(query).map_err(|d| vec![d])?)
}

/// A query's syntax tree checked against the LogicPad (predicates, arity,
/// declared values, safety): the tree, or the errors.
pub fn check(
    pad: &LogicPad,
    parsed: ParsedQuery,
) -> Result<ParsedQuery, Vec<logicpad::Diagnostic>> {
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
/// query once and use `ask_parsed` (the [`crate::engine::Engine`] does).
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
        all_observed: blind::all_fully(pad, observed),
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

impl AskResult {
    /// An answer about `kb` with nothing in it yet (outcome `invalid`).
    fn empty(kb: &WindowKb, query: &str) -> AskResult {
        AskResult::blank(kb.id.clone(), kb.first_frame, kb.last_frame, query)
    }

    /// An answer about `window` (frames `first_frame..=last_frame`) with
    /// nothing in it yet (outcome `invalid`): the one place an
    /// [`AskResult`] is built field by field.
    pub(crate) fn blank(
        window: String,
        first_frame: u32,
        last_frame: u32,
        query: &str,
    ) -> AskResult {
        AskResult {
            window,
            first_frame,
            last_frame,
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
            stopped: None,
            probability: None,
            binding_probabilities: Vec::new(),
            hinges: Vec::new(),
        }
    }
}

impl AskResult {
    /// The answer with one more reason (an invalid answer's cause in words).
    pub(crate) fn with_reason(mut self, reason: String) -> AskResult {
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
        other => result.reasons = vec![other.to_string()],
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
pub(crate) fn ask_parsed(
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
        ParsedQuery::Count(c) => ask_count(pad, kb, blind, c, opts, result),
    }
}

/// How many counterexamples or candidates a "no" lists.
pub(crate) const WHY_NOT_CANDIDATES: usize = 3;

fn ask_prepared(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    ast: &std::sync::Arc<QueryAst>,
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
    // Every form runs the query's kanren program: a count builds no
    // answers, bindings no proofs, and with proofs each answer carries its
    // derivation.
    let answers = run_query(kb, ast, opts);
    let Ran {
        count,
        answers,
        stopped,
    } = match answers {
        Ok(a) => a,
        Err(e) => {
            result.answer = Outcome::Invalid;
            set_error(&mut result, &e);
            return result;
        }
    };
    result.stopped = stopped;
    // Negated atoms over predicates the source does not fully observe make
    // even a found binding a guess; so do the atoms of a `¬∃` body for a
    // "yes" (an unseen match would break it).
    let guesses = blind_guesses(pad, blind, ast);
    if !guesses.always.is_empty() {
        result.answer = Outcome::Unknown;
        result.reasons = guesses.always;
        return result;
    }
    if count > 0 && !guesses.yes.is_empty() {
        result.answer = Outcome::Unknown;
        result.reasons = guesses.yes;
        return result;
    }
    let blind_pos = guesses.no;
    if count == 0 {
        if let Some(reason) = stopped {
            // Nothing found before the limit: "no" would be a guess.
            result.answer = Outcome::Unknown;
            result.reasons = vec![stopped_reason(reason, &opts.limits, 0)];
            return result;
        }
        if blind_pos.is_empty() {
            result.answer = Outcome::No;
            if opts.why_not {
                result.why_not = crate::whynot::why_not(pad, kb, ast, &opts.limits);
            }
        } else {
            result.answer = Outcome::Unknown;
            result.reasons = blind_pos;
        }
        return result;
    }
    result.answer = Outcome::Yes;
    result.count = count;
    for a in answers {
        if opts.proofs {
            result.proofs.push(crate::proof::of_answer(kb, &a));
        }
        result.bindings.push(a.bindings);
    }
    result
}

/// What a query's run gave: the number of answers (or of matches, for a
/// count), the answers themselves unless only counted, and the limit the
/// run stopped at.
pub(crate) struct Ran {
    /// Answers (or matches) found.
    pub(crate) count: usize,
    /// The answers, in the order of [`logicpad::Found`].
    pub(crate) answers: Vec<QueryAnswer>,
    /// The limit the run stopped at.
    pub(crate) stopped: Option<logicpad::Stopped>,
}

/// A run that stopped at a limit, in words: "the run stopped at the time
/// limit (5 s) after 3 answers".
pub(crate) fn stopped_reason(
    reason: logicpad::Stopped,
    limits: &logicpad::Limits,
    found: usize,
) -> String {
    format!(
        "the run stopped at {} after {found} answer{}",
        reason.describe(limits),
        if found == 1 { "" } else { "s" }
    )
}

/// Runs `q` on a window as `opts` asks, within `opts.limits`: a count
/// builds no answers, bindings no proofs, and with proofs each answer
/// carries its derivation.
pub(crate) fn run_query(
    kb: &WindowKb,
    q: &QueryAst,
    opts: AskOptions,
) -> Result<Ran, logicpad::AskError> {
    let limits = &opts.limits;
    if opts.count_only {
        let (count, stopped) = kb.model.count_limited(q, limits)?;
        return Ok(Ran {
            count,
            answers: Vec::new(),
            stopped,
        });
    }
    let found = answers_limited(kb, q, opts.proofs, limits)?;
    Ok(Ran {
        count: found.items.len(),
        answers: found.items,
        stopped: found.stopped,
    })
}

/// The answers of `q` on a window within `limits`: with their proofs when
/// `proofs` is set, else the bindings alone (each with an empty proof).
pub(super) fn answers_limited(
    kb: &WindowKb,
    q: &QueryAst,
    proofs: bool,
    limits: &logicpad::Limits,
) -> Result<logicpad::Found<QueryAnswer>, logicpad::AskError> {
    if proofs {
        return kb.model.ask_limited(q, true, limits);
    }
    let found = kb.model.bindings_limited(q, limits)?;
    Ok(logicpad::Found {
        items: found
            .items
            .into_iter()
            .map(|bindings| QueryAnswer {
                bindings,
                proof: Vec::new(),
            })
            .collect(),
        stopped: found.stopped,
    })
}
