//! The one way from a question to an answer: [`Engine`] holds the LogicPad,
//! the translator built from *its* vocabulary, and the source's
//! observability, so none of the three can drift from the others. Front
//! ends do not call it directly: they ask through a
//! [`crate::pipeline::Pipeline`], which holds an engine, a [`Translate`] and
//! a source's windows.
//!
//! ```text
//! text ──prepare──▶ Prepared { question?, ParsedQuery | diagnostics }   (once)
//! WindowInput ──build──▶ WindowKb                                       (once per window)
//! (WindowKb, Prepared) ──ask──▶ AskResult                               (per window)
//! [AskResult] ──summarize──▶ Summary ("yes — in 3 of 7 windows: …")
//! ```

use crate::ask::{AskOptions, AskResult, Blindness, ask_parsed, invalid};
use crate::kb::{KbError, Observability, Observed, WindowInput, WindowKb};
use crate::translate::{TranslateError, Translator, Vocabulary, VocabularyError, looks_like_query};
use logicpad::{LogicPad, ParsedQuery};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

mod summary;
#[cfg(test)]
mod tests;
mod translators;
pub use summary::{Summary, WindowOutcome};
pub use translators::*;

/// Errors that keep an engine from being built.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// Occurs when the LogicPad's vocabulary cannot drive the translator
    /// (e.g. two predicates claim one phrase in an incompatible way).
    #[error("the LogicPad's vocabulary cannot drive the translator: {0}")]
    Vocabulary(#[from] VocabularyError),
}

/// Which bindings of a window an answer lists: `limit` of them after the
/// first `offset`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Page {
    /// Bindings skipped first.
    pub offset: usize,
    /// Bindings listed at most (at least 1).
    pub limit: usize,
}

/// What a paged answer left out ([`Engine::ask_page`]).
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct Truncation {
    /// Why, in words.
    pub reason: String,
    /// The page's offset.
    pub offset: usize,
    /// The page's limit.
    pub limit: usize,
    /// Bindings listed.
    pub shown: usize,
    /// Every binding's count, when it is known (`None`: more than the
    /// answer limit exist, and they were not all derived).
    pub total: Option<usize>,
    /// Whether bindings after this page exist.
    pub more: bool,
}

/// Proof nodes per answer at least, when a page of a query past the
/// answer limit shares the proof budget.
const MIN_PROOF_NODES: usize = 64;

/// A LogicPad, its translator and a source's observability, kept in step.
///
/// Invariant: `translator` was built from `pad`'s schema and `observed`
/// classifies every predicate of `pad` under `observability`.
#[derive(Debug, Clone)]
pub struct Engine {
    pad: LogicPad,
    /// Shared: [`Engine::for_source`] is called per command and the
    /// lexicon is large (copying and freeing it was 15% of a batch).
    translator: std::sync::Arc<Translator>,
    words: crate::context::Sentences,
    observability: Observability,
    observed: BTreeMap<String, Observed>,
    /// `observed` says every predicate of the LogicPad is fully observed
    /// (`crate::ask::all_fully`).
    all_observed: bool,
    /// The bounds of the work behind an answer's probability.
    belief: crate::belief::BeliefLimits,
}

/// A question or query, translated and checked once, ready for any window.
#[derive(Debug, Clone)]
pub struct Prepared {
    /// The English question, when the text was one.
    pub question: Option<String>,
    /// The query as run (the translation, or the text as given).
    pub query: String,
    /// The translator's notes on liberties it took.
    pub notes: Vec<String>,
    /// What the question asks for (yes/no for a query as written).
    pub intent: crate::translate::Intent,
    /// The parsed, checked query, or the diagnostics that make it invalid.
    /// For a temporal query, its first part (the whole is `temporal`).
    pub parsed: Result<ParsedQuery, Vec<logicpad::Diagnostic>>,
    /// A temporal query (`(Q1) THEN (Q2)`, `EVER: Q`, …): answered once
    /// over a video's windows ([`crate::temporal`]); a window asked alone
    /// answers it invalid. `None` for every other query.
    pub temporal: Option<std::sync::Arc<crate::temporal::TemporalQuery>>,
}

impl Prepared {
    /// True for a universal query (`∀x: A → B`).
    pub(crate) fn is_universal(&self) -> bool {
        matches!(self.parsed, Ok(ParsedQuery::Forall(_)))
    }

    /// True for a closed "no …" query: no answer variables, and every
    /// alternative made of `¬∃` literals (and comparisons) only ("Are
    /// there no trucks?" → `¬∃x: (TypeOf(x, Truck))`). Over a video it
    /// says that nothing of the kind is seen in any window, so a summary
    /// reads it as a universal: one window with a truck makes it no.
    pub(crate) fn is_closed_negation(&self) -> bool {
        use logicpad::fol::Literal;
        let Ok(ParsedQuery::Exists(ast)) = &self.parsed else {
            return false;
        };
        ast.answer_vars.is_empty()
            && !ast.disjuncts.is_empty()
            && ast.disjuncts.iter().all(|d| {
                d.iter().any(|l| matches!(l, Literal::NotExists { .. }))
                    && d.iter()
                        .all(|l| matches!(l, Literal::NotExists { .. } | Literal::Cmp { .. }))
            })
    }
}

impl Engine {
    /// An engine over a LogicPad for a source that observes what `observability` says.
    pub fn new(pad: LogicPad, observability: Observability) -> Result<Engine, EngineError> {
        let vocab = Vocabulary::from_schema(pad.schema())?.with_rules(pad.program());
        let translator = std::sync::Arc::new(Translator::new(vocab));
        let observed = observability.classify(&pad);
        let words =
            crate::context::Sentences::from_schema(pad.schema()).with_taxonomy(pad.program());
        let all_observed = crate::ask::all_fully(&pad, &observed);
        Ok(Engine {
            pad,
            translator,
            words,
            observability,
            all_observed,
            observed,
            belief: crate::belief::BeliefLimits::default(),
        })
    }

    /// The same engine with other bounds on the work behind an answer's
    /// probability.
    pub fn with_belief_limits(mut self, limits: crate::belief::BeliefLimits) -> Engine {
        self.belief = limits;
        self
    }

    /// The same LogicPad and translator for another source.
    pub fn for_source(&self, observability: Observability) -> Engine {
        let observed = observability.classify(&self.pad);
        Engine {
            pad: self.pad.clone(),
            translator: std::sync::Arc::clone(&self.translator),
            words: self.words.clone(),
            observability,
            all_observed: crate::ask::all_fully(&self.pad, &observed),
            observed,
            belief: self.belief,
        }
    }

    /// The LogicPad.
    pub fn pad(&self) -> &LogicPad {
        &self.pad
    }

    /// The translator built from the LogicPad's vocabulary.
    pub fn translator(&self) -> &Translator {
        &self.translator
    }

    /// What the source cannot observe.
    pub fn observability(&self) -> &Observability {
        &self.observability
    }

    /// Every predicate's observability under this source.
    pub fn observed(&self) -> &BTreeMap<String, Observed> {
        &self.observed
    }

    /// Translates a question (or takes a query as written) and checks it
    /// against the LogicPad. An English question the grammar cannot read
    /// is an error; a query that does not fit the LogicPad is prepared as
    /// invalid, so every window answers "invalid" with the diagnostics.
    pub fn prepare(&self, text: &str) -> Result<Prepared, TranslateError> {
        if looks_like_query(text) {
            return Ok(self.prepare_query(text));
        }
        let t = self.translator.translate(text)?;
        if !t.is_conjunction() {
            // Scoped negation, counting, time: the text is the query,
            // parsed and checked like one written by hand.
            let parsed = self.prepare_query(&t.query);
            return Ok(Prepared {
                question: Some(text.to_string()),
                intent: t.intent,
                notes: t.notes,
                ..parsed
            });
        }
        // The translator's atoms are the query's syntax tree, built as it
        // is: its text is for display, never parsed back.
        let ast = logicpad::QueryAst::conjunction(&t.literals());
        Ok(Prepared {
            question: Some(text.to_string()),
            intent: t.intent,
            notes: t.notes,
            parsed: crate::ask::check(&self.pad, ParsedQuery::Exists(std::sync::Arc::new(ast))),
            query: t.query,
            temporal: None,
        })
    }

    /// Prepares a question through an LLM translator (its query is checked
    /// by this engine's LogicPad, and repaired, inside the translator).
    pub(crate) fn prepare_llm(
        &self,
        question: &str,
        translator: &crate::llm::translate::LlmTranslator<'_>,
    ) -> Result<Prepared, crate::llm::translate::LlmTranslateError> {
        let t = translator.translate(question)?;
        let rounds = t.rounds.len();
        // The reply was checked like a query written by hand; prepared the
        // same way, so that a temporal one keeps its parts.
        let prepared = self.prepare_query(&t.query);
        Ok(Prepared {
            question: Some(question.to_string()),
            intent: crate::translate::Intent::of_question(question),
            notes: vec![format!(
                "translated by the LLM ({}) in {rounds} round{}",
                translator.chat.client.config().model,
                if rounds == 1 { "" } else { "s" }
            )],
            ..prepared
        })
    }

    /// One page of a window's answer, from one run of the query within
    /// `opts.limits` (the caller bounds the run: `ask --limit` stops it at
    /// the page's end, so a query with millions of bindings costs the
    /// page; a server at its `--max-answers`), never run twice. A run that
    /// ends within its limits has every binding, sorted, and the page is a
    /// slice of them (`total` known); one that stops at a limit
    /// ([`AskResult::stopped`]) lists its bindings in the order the search
    /// found them (stable for a window), with `more` set. The page carries the
    /// answer's probability like any answer. `None`: nothing was left out.
    pub fn ask_page(
        &self,
        kb: &WindowKb,
        p: &Prepared,
        opts: AskOptions,
        page: Page,
    ) -> (AskResult, Option<Truncation>) {
        let end = page.offset.saturating_add(page.limit);
        let capped = AskOptions {
            limits: logicpad::Limits {
                // The proof budget is the page's answers', not shared with
                // the answers the page skips.
                proof_nodes: (opts.limits.proof_nodes / page.limit.max(1))
                    .max(MIN_PROOF_NODES)
                    .saturating_mul(end.max(1)),
                ..opts.limits
            },
            ..opts
        };
        let mut r = self.ask(kb, p, capped);
        let found = r.bindings.len();
        let complete = r.stopped.is_none();
        if complete && page.offset == 0 && found <= page.limit {
            return (r, None);
        }
        let start = page.offset.min(found);
        let stop = end.min(found);
        r.bindings = r
            .bindings
            .get(start..stop)
            .map(<[_]>::to_vec)
            .unwrap_or_default();
        if !r.proofs.is_empty() {
            r.proofs = r
                .proofs
                .get(start..stop)
                .map(<[_]>::to_vec)
                .unwrap_or_default();
        }
        if !r.binding_probabilities.is_empty() {
            r.binding_probabilities = r
                .binding_probabilities
                .get(start..stop)
                .map(<[_]>::to_vec)
                .unwrap_or_default();
        }
        let reason = match r.stopped {
            None => format!("bindings {start} to {stop} of {found}"),
            Some(why) => format!(
                "stopped at {}: bindings listed as the search found them, not sorted; narrow the query or page with offset/limit",
                why.describe(&capped.limits)
            ),
        };
        let cut = Truncation {
            reason,
            offset: page.offset,
            limit: page.limit,
            shown: stop - start,
            total: complete.then_some(found),
            more: stop < found || r.stopped == Some(logicpad::Stopped::Answers),
        };
        (r, Some(cut))
    }

    /// Prepares `text` with `translator`: a query as written, a question
    /// as the translator turns it into one.
    pub fn prepare_with(
        &self,
        translator: &dyn Translate,
        text: &str,
    ) -> Result<Prepared, PrepareError> {
        if looks_like_query(text) {
            return Ok(self.prepare_query(text));
        }
        translator.translate(self, text)
    }

    /// Prepares a query written in the LogicPad's syntax (no translation),
    /// or a temporal query over existential ones ([`crate::temporal`]).
    pub fn prepare_query(&self, query: &str) -> Prepared {
        let (parsed, temporal) = match crate::temporal::parse(&self.pad, query) {
            None => (crate::ask::prepare(&self.pad, query), None),
            Some(Err(diags)) => (Err(diags), None),
            Some(Ok(t)) => match t.first_parsed() {
                Some(first) => (Ok(first), Some(std::sync::Arc::new(t))),
                None => (Err(Vec::new()), None),
            },
        };
        Prepared {
            question: None,
            query: query.to_string(),
            notes: Vec::new(),
            intent: crate::translate::Intent::YesNo,
            parsed,
            temporal,
        }
    }

    /// Reasons one window's facts with the LogicPad's rules.
    pub fn build(&self, input: WindowInput) -> Result<WindowKb, KbError> {
        WindowKb::build(input, self.pad.program())
    }

    /// Reasons every window, in parallel, each reusing what the window
    /// before it derived from unchanged inputs (overlapping windows,
    /// `--stride` < `--window`); `done` is called once per window.
    pub fn build_all(
        &self,
        inputs: Vec<WindowInput>,
        done: &(dyn Fn() + Sync),
    ) -> Result<Vec<WindowKb>, KbError> {
        crate::kb::build_all(self.pad.program(), inputs, done)
    }

    /// The words facts are said in (the LogicPad's `sentence:` templates).
    pub fn words(&self) -> &crate::context::Sentences {
        &self.words
    }

    /// The retrieval context of an answer: C2 from the answer, C3 from the
    /// window's facts in this LogicPad's `sentence:` words.
    pub fn context(
        &self,
        kb: &WindowKb,
        p: &Prepared,
        r: &AskResult,
    ) -> crate::context::RagContext {
        crate::context::RagContext::new(kb, p.question.as_deref(), r, &self.words)
    }

    /// Answers a prepared query on one window, with how sure the answer
    /// is ([`crate::belief`]) unless `opts` asks for a count only.
    pub fn ask(&self, kb: &WindowKb, p: &Prepared, opts: AskOptions) -> AskResult {
        if let Some(t) = &p.temporal {
            return t.one_window(kb, &p.query);
        }
        let mut r = self.answer(kb, p, opts);
        if opts.count_only {
            return r;
        }
        // The bindings' proofs give their probabilities: asked for here
        // when the caller did not ask for them and the window is uncertain.
        let proofs = if opts.proofs || !kb.is_uncertain() || r.bindings.is_empty() {
            std::mem::take(&mut r.proofs)
        } else {
            let with = AskOptions {
                proofs: true,
                why_not: false,
                ..opts
            };
            self.answer(kb, p, with).proofs
        };
        let again = |k: &WindowKb| self.answer(k, p, crate::belief::flip_options(opts));
        // Computed only when a flip is looked at (an uncertain window).
        let reach = std::sync::OnceLock::new();
        let relevant = |pred: &str| {
            reach
                .get_or_init(|| match &p.parsed {
                    Ok(q) => crate::belief::reach(self.pad.program(), q),
                    Err(_) => Default::default(),
                })
                .contains(pred)
        };
        let asked = crate::belief::Asked {
            intent: p.intent,
            universal: p.is_universal(),
            parsed: p.parsed.as_ref().ok(),
            relevant: &relevant,
            ask: &again,
        };
        crate::belief::believe(
            kb,
            self.pad.program(),
            &self.belief,
            &asked,
            &mut r,
            &proofs,
        );
        if opts.proofs {
            r.proofs = proofs;
        }
        r
    }

    /// Answers a prepared query on one window, without its probability.
    fn answer(&self, kb: &WindowKb, p: &Prepared, opts: AskOptions) -> AskResult {
        if let Some(t) = &p.temporal {
            return t.one_window(kb, &p.query);
        }
        let mut r = match &p.parsed {
            Ok(q) => {
                let blind = Blindness {
                    observed: &self.observed,
                    observability: Some(&self.observability),
                    all_observed: self.all_observed,
                };
                ask_parsed(&self.pad, kb, &blind, q, opts)
            }
            Err(diags) => invalid(kb, &p.query, diags),
        };
        r.query.clone_from(&p.query);
        r
    }
}

/// Each value of function `pred` with its strict supertypes under
/// `program`'s taxonomy rules: a rule whose one positive body atom is
/// `pred(x, Sub)`, with no negation or comparison, and whose head is
/// `pred(x, Super)` (same variable) makes `Super` a supertype of `Sub`;
/// transitively closed.
pub(crate) fn taxonomy_edges(
    program: &logicpad::Program,
    pred: &str,
) -> BTreeMap<String, BTreeSet<String>> {
    use logicpad::CArg;
    let Some(pid) = program.pred_id(pred) else {
        return BTreeMap::new();
    };
    let constant = |a: Option<&CArg>| match a {
        Some(CArg::Const(t)) => t.as_sym().map(|s| s.as_str().to_string()),
        _ => None,
    };
    let var = |a: Option<&CArg>| match a {
        Some(CArg::Var(v)) => Some(*v),
        _ => None,
    };
    let mut up: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
    for r in program.rules() {
        let [b] = &r.body[..] else { continue };
        if r.head.pred != pid || b.pred != pid || !r.negated.is_empty() || !r.cmps.is_empty() {
            continue;
        }
        let same_object =
            var(r.head.args.first()).is_some() && var(r.head.args.first()) == var(b.args.first());
        if let (true, Some(sub), Some(sup)) = (
            same_object,
            constant(b.args.get(1)),
            constant(r.head.args.get(1)),
        ) && sub != sup
        {
            up.entry(sub).or_default().insert(sup);
        }
    }
    // Transitive closure (the taxonomy is small: a few dozen values).
    loop {
        let mut grew = false;
        let snapshot = up.clone();
        for sups in up.values_mut() {
            let more: Vec<String> = sups
                .iter()
                .filter_map(|s| snapshot.get(s))
                .flatten()
                .filter(|s| !sups.contains(*s))
                .cloned()
                .collect();
            grew |= !more.is_empty();
            sups.extend(more);
        }
        if !grew {
            break;
        }
    }
    up
}
