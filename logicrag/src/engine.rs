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

use crate::ask::{AskOptions, AskResult, Blindness, Outcome, ask_parsed, invalid};
use crate::kb::{KbError, Observability, Observed, WindowInput, WindowKb};
use crate::translate::{TranslateError, Translator, Vocabulary, VocabularyError, looks_like_query};
use logicpad::{LogicPad, ParsedQuery};
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// Errors that keep an engine from being built.
#[derive(Debug, thiserror::Error)]
pub enum EngineError {
    /// Occurs when the LogicPad's vocabulary cannot drive the translator
    /// (e.g. two predicates claim one phrase in an incompatible way).
    #[error("the LogicPad's vocabulary cannot drive the translator: {0}")]
    Vocabulary(#[from] VocabularyError),
}

/// How a question becomes a query (`--translator`, the REPL's
/// `:translator`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum TranslatorMode {
    /// The built-in grammar (no network).
    #[default]
    Grammar,
    /// An LLM, its reply checked by the LogicPad and repaired.
    Llm,
    /// The grammar, and the LLM when the grammar refuses.
    Auto,
}

impl TranslatorMode {
    /// The mode's name as the flag takes it.
    pub fn as_str(self) -> &'static str {
        match self {
            TranslatorMode::Grammar => "grammar",
            TranslatorMode::Llm => "llm",
            TranslatorMode::Auto => "auto",
        }
    }
}

impl std::str::FromStr for TranslatorMode {
    type Err = String;
    fn from_str(s: &str) -> Result<TranslatorMode, String> {
        match s.trim() {
            "grammar" => Ok(TranslatorMode::Grammar),
            "llm" => Ok(TranslatorMode::Llm),
            "auto" => Ok(TranslatorMode::Auto),
            other => Err(format!(
                "unknown translator `{other}`: expected grammar, llm or auto"
            )),
        }
    }
}

/// The LLM half of a translator: a server, its prompts and the repair
/// rounds for a query the LogicPad rejects.
#[derive(Debug, Clone)]
pub struct LlmSetup {
    /// The server and its cache.
    pub chat: crate::llm::Chat,
    /// The prompts.
    pub templates: crate::llm::Templates,
    /// Repair rounds after the first answer.
    pub repairs: u32,
}

/// How an English question becomes a query: the grammar ([`Grammar`]), an
/// LLM ([`ByLlm`]), or the grammar and then the LLM when the grammar
/// refuses ([`GrammarThenLlm`]). Every front end's
/// [`crate::pipeline::Pipeline`] holds one (built by [`translator`] from
/// `--translator` and `--llm`) and prepares questions through it
/// ([`Engine::prepare_with`], which takes queries as written).
pub trait Translate: Send + Sync + std::fmt::Debug {
    /// The mode, as `--translator` names it.
    fn mode(&self) -> TranslatorMode;
    /// Translates an English question for `engine`'s LogicPad.
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError>;
    /// True when translating may ask a server (a front end may bound or
    /// time such calls).
    fn asks_server(&self) -> bool {
        false
    }
    /// The translation when it needs no server: the grammar's answer or
    /// refusal, or a question the grammar reads before an LLM would be
    /// asked; `None` when only a server can tell.
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>>;
}

/// The built-in grammar: no network, every question the same way.
#[derive(Debug, Clone, Copy, Default)]
pub struct Grammar;

impl Translate for Grammar {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Grammar
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        Ok(engine.prepare(question)?)
    }
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>> {
        Some(self.translate(engine, question))
    }
}

/// An LLM: its reply is checked by the LogicPad and repaired.
#[derive(Debug, Clone)]
pub struct ByLlm(pub LlmSetup);

impl ByLlm {
    fn run(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Result<Prepared, crate::llm::translate::LlmTranslateError> {
        let t = crate::llm::translate::LlmTranslator {
            chat: &self.0.chat,
            templates: &self.0.templates,
            pad: &engine.pad,
            repairs: self.0.repairs,
        };
        engine.prepare_llm(question, &t)
    }
}

impl Translate for ByLlm {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Llm
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        Ok(self.run(engine, question)?)
    }
    fn asks_server(&self) -> bool {
        true
    }
    fn translate_offline(&self, _: &Engine, _: &str) -> Option<Result<Prepared, PrepareError>> {
        None
    }
}

/// The grammar, then the LLM for the questions the grammar refuses.
#[derive(Debug, Clone)]
pub struct GrammarThenLlm(pub ByLlm);

impl Translate for GrammarThenLlm {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Auto
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        match engine.prepare(question) {
            Ok(p) => Ok(p),
            Err(grammar) => self
                .0
                .run(engine, question)
                .map_err(|llm| PrepareError::Neither { grammar, llm }),
        }
    }
    fn asks_server(&self) -> bool {
        true
    }
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>> {
        engine.prepare(question).ok().map(Ok)
    }
}

/// The translator of a mode: `Llm` needs `llm` ([`PrepareError::NoLlm`]
/// without it); `Auto` without `llm` is the grammar alone.
pub fn translator(
    mode: TranslatorMode,
    llm: Option<LlmSetup>,
) -> Result<std::sync::Arc<dyn Translate>, PrepareError> {
    Ok(match (mode, llm) {
        (TranslatorMode::Grammar, _) | (TranslatorMode::Auto, None) => std::sync::Arc::new(Grammar),
        (TranslatorMode::Llm, None) => return Err(PrepareError::NoLlm),
        (TranslatorMode::Llm, Some(setup)) => std::sync::Arc::new(ByLlm(setup)),
        (TranslatorMode::Auto, Some(setup)) => std::sync::Arc::new(GrammarThenLlm(ByLlm(setup))),
    })
}

/// Why a question could not be prepared under a [`TranslatorMode`].
#[derive(Debug, thiserror::Error)]
pub enum PrepareError {
    /// Occurs when the grammar cannot read the question (grammar mode, or
    /// auto mode without an LLM).
    #[error("cannot translate the question: {0}")]
    Grammar(#[from] TranslateError),
    /// Occurs when the LLM cannot translate it (llm mode).
    #[error("cannot translate the question: {0}")]
    Llm(#[from] crate::llm::translate::LlmTranslateError),
    /// Occurs when neither can (auto mode).
    #[error("cannot translate the question: the grammar: {grammar}; the LLM: {llm}")]
    Neither {
        /// The grammar's reason.
        grammar: TranslateError,
        /// The LLM's reason.
        llm: crate::llm::translate::LlmTranslateError,
    },
    /// Occurs when the llm mode has no server to ask.
    #[error("the llm translator needs a server: give --llm URL (or set LOGICRAG_LLM_URL)")]
    NoLlm,
}

impl PrepareError {
    /// Why, without the leading "cannot translate the question: " (for a
    /// line that says what failed itself, as an evaluation record does).
    pub fn reason(&self) -> String {
        match self {
            PrepareError::Grammar(e) => e.to_string(),
            PrepareError::Llm(e) => e.to_string(),
            PrepareError::Neither { grammar, llm } => {
                format!("the grammar: {grammar}; the LLM: {llm}")
            }
            PrepareError::NoLlm => self.to_string(),
        }
    }
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
            parsed: crate::ask::check(&self.pad, ParsedQuery::Exists(ast)),
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

    /// One page of a window's answer. Within `opts.max_answers` the answer
    /// is complete and sorted, and the page a slice of it (`total` known).
    /// Past it the engine stops at one binding more, so a query with
    /// millions of bindings costs no more than one at the limit, and the
    /// page comes from the query's kanren run as it finds the bindings, lazily (stable
    /// for a window, not sorted: sorting needs them all), with `more` set
    /// when one lies beyond the page. A negated literal the source does
    /// not fully observe makes any binding a guess: then the engine's own
    /// answer (too large) stands. `None`: nothing was left out.
    pub fn ask_page(
        &self,
        kb: &WindowKb,
        p: &Prepared,
        opts: AskOptions,
        page: Page,
    ) -> (AskResult, Option<Truncation>) {
        let mut r = self.ask(kb, p, opts);
        if let (Some(limit), Ok(ParsedQuery::Exists(q))) = (r.too_large, &p.parsed) {
            // A negated atom, or any atom of a `¬∃` body, over what the
            // source may miss makes a binding a guess.
            let blind_negation = q.disjuncts.iter().flatten().any(|l| match l {
                logicpad::fol::Literal::Neg(a) => {
                    self.observed.get(&a.pred) != Some(&Observed::Fully)
                }
                logicpad::fol::Literal::NotExists { .. } => l
                    .atoms()
                    .iter()
                    .any(|(a, _)| self.observed.get(&a.pred) != Some(&Observed::Fully)),
                _ => false,
            });
            if blind_negation {
                return (r, None);
            }
            let limits = logicpad::ProofLimits {
                max_nodes: (opts.proof_limits().max_nodes / page.limit.max(1)).max(MIN_PROOF_NODES),
                ..opts.proof_limits()
            };
            let Ok(mut answers) = kb.model.answers(q, opts.proofs.then_some(limits)) else {
                return (r, None);
            };
            let found: Vec<logicpad::QueryAnswer> = answers
                .by_ref()
                .skip(page.offset)
                .take(page.limit.saturating_add(1))
                .collect();
            // A run that failed part way would show a short page as if it
            // were all: the engine's own answer (too large) stands instead.
            if answers.error().is_some() {
                return (r, None);
            }
            let more = found.len() > page.limit;
            let shown = &found[..found.len().min(page.limit)];
            r.answer = Outcome::Yes;
            r.reasons.clear();
            r.too_large = None;
            r.bindings = shown.iter().map(|a| a.bindings.clone()).collect();
            r.proofs = if opts.proofs {
                shown
                    .iter()
                    .map(|a| crate::proof::of_answer(kb, a))
                    .collect()
            } else {
                Vec::new()
            };
            r.count = r.bindings.len();
            let cut = Truncation {
                reason: format!(
                    "more than {limit} bindings: listed as the engine finds them, not sorted; narrow the query or page with offset/limit"
                ),
                offset: page.offset,
                limit: page.limit,
                shown: r.bindings.len(),
                total: None,
                more,
            };
            return (r, Some(cut));
        }
        let total = r.bindings.len();
        if page.offset == 0 && total <= page.limit {
            return (r, None);
        }
        let start = page.offset.min(total);
        let end = start.saturating_add(page.limit).min(total);
        r.bindings = r
            .bindings
            .get(start..end)
            .map(<[_]>::to_vec)
            .unwrap_or_default();
        if !r.proofs.is_empty() {
            r.proofs = r
                .proofs
                .get(start..end)
                .map(<[_]>::to_vec)
                .unwrap_or_default();
        }
        let cut = Truncation {
            reason: format!("bindings {start} to {end} of {total}"),
            offset: page.offset,
            limit: page.limit,
            shown: end - start,
            total: Some(total),
            more: end < total,
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

/// One window's answer in a summary.
#[derive(Debug, Clone, Serialize)]
pub struct WindowOutcome {
    /// Window id.
    pub window: String,
    /// First frame.
    pub first_frame: u32,
    /// Last frame.
    pub last_frame: u32,
    /// The window's outcome.
    pub answer: Outcome,
}

/// The answer over every window asked, read as one answer.
///
/// Invariant: `answer` is yes when some window says yes (for a universal
/// or a closed "no …" query, `Prepared::is_closed_negation`: when every
/// window that can tell says yes and none says no), unknown
/// when none says yes but some cannot tell, invalid when every window
/// finds the query invalid, and no otherwise — except for a counting
/// query (`#{x: Q} op N`), whose answer is its test on `how_many`, the
/// distinct counted objects over every window (unknown where what the
/// source cannot see could change it).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The overall outcome.
    pub answer: Outcome,
    /// Windows asked.
    pub windows: usize,
    /// The windows whose answer is yes.
    pub yes: Vec<WindowOutcome>,
    /// Windows that cannot tell (unknown).
    pub unknown: usize,
    /// For "how many" questions: distinct objects (or unordered pairs)
    /// over all windows.
    pub how_many: Option<usize>,
    /// What `how_many` counts: "pedestrians", "pairs", "objects".
    pub unit: Option<String>,
    /// For "what …/which …" questions: the values asked for, over every
    /// window that says yes ("What colour is the van?" → `["White"]`).
    pub values: Vec<String>,
    /// For a counting query (`#{x: Q} > 2`): its test in words ("more
    /// than 2"), which `how_many` (the distinct counted objects over every
    /// window) is held to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count_test: Option<String>,
}

impl Summary {
    /// Summarizes the answers of one prepared query over several windows;
    /// nouns and asked-for values come from `words` (the LogicPad's roles
    /// and phrases, [`Engine::words`]).
    pub fn new(words: &crate::context::Sentences, p: &Prepared, results: &[AskResult]) -> Summary {
        let yes: Vec<WindowOutcome> = results
            .iter()
            .filter(|r| r.answer == Outcome::Yes)
            .map(|r| WindowOutcome {
                window: r.window.clone(),
                first_frame: r.first_frame,
                last_frame: r.last_frame,
                answer: r.answer,
            })
            .collect();
        let count = |o: Outcome| results.iter().filter(|r| r.answer == o).count();
        let (no, unknown, invalid) = (
            count(Outcome::No),
            count(Outcome::Unknown),
            count(Outcome::Invalid),
        );
        let answer = if !results.is_empty() && invalid == results.len() {
            Outcome::Invalid
        } else if p.is_universal() || p.is_closed_negation() {
            if no > 0 {
                Outcome::No
            } else if unknown > 0 {
                Outcome::Unknown
            } else {
                Outcome::Yes
            }
        } else if !yes.is_empty() {
            Outcome::Yes
        } else if unknown > 0 {
            Outcome::Unknown
        } else {
            Outcome::No
        };
        let (how_many, unit) = if p.intent.counts() && matches!(answer, Outcome::Yes | Outcome::No)
        {
            let (n, unit) = count_objects(words, p, results);
            (Some(n), Some(unit))
        } else {
            (None, None)
        };
        let values = if answer == Outcome::Yes {
            asked_values(words, p, results)
        } else {
            Vec::new()
        };
        let mut summary = Summary {
            answer,
            windows: results.len(),
            yes,
            unknown,
            how_many,
            unit,
            values,
            count_test: None,
        };
        if let Ok(ParsedQuery::Count(c)) = &p.parsed
            && summary.answer != Outcome::Invalid
        {
            summary.count_over_video(words, c, results);
        }
        summary
    }

    /// A counting query over a video: the distinct counted objects (or
    /// tuples) of every window that is not invalid, held to the test. Each
    /// window's count is exact, a lower or an upper bound
    /// (`crate::ask::Bound`, read back from its answer); the union is then
    /// one too, and the test is decided only where what no window could
    /// see cannot change it. Per-window outcomes stay as they were.
    fn count_over_video(
        &mut self,
        words: &crate::context::Sentences,
        c: &logicpad::CountQuery,
        results: &[AskResult],
    ) {
        use crate::ask::{Bound, bound_of_note, decide};
        let counted: Vec<&AskResult> = results
            .iter()
            .filter(|r| r.answer != Outcome::Invalid)
            .collect();
        let distinct: BTreeSet<Vec<(String, String)>> = counted
            .iter()
            .flat_map(|r| r.bindings.iter())
            .map(|b| {
                b.iter()
                    .filter(|(v, _)| c.vars.contains(v))
                    .cloned()
                    .collect()
            })
            .collect();
        let n = distinct.len();
        // One source, so one kind of bound for every window; any window
        // whose count is not exact makes the video's not exact.
        let bound = counted
            .iter()
            .map(|r| bound_of_note(r))
            .find(|b| *b != Bound::Exact)
            .unwrap_or(Bound::Exact);
        self.answer = match decide(c.op, c.n, n, bound) {
            Some(true) => Outcome::Yes,
            Some(false) => Outcome::No,
            None => Outcome::Unknown,
        };
        self.how_many = Some(n);
        self.unit = Some(match c.vars.as_slice() {
            [v] => noun_in(words, &c.query, v),
            [_, _] => "pairs".into(),
            _ => "tuples".into(),
        });
        self.count_test = Some(format!("{} {}", c.op.words(), c.n));
        self.values = Vec::new();
    }

    /// The one line that answers the question: "yes — in 3 of 7 windows:
    /// frames 10–19, 20–29, 60–69", "2 pedestrians — in 1 of 7 windows: …".
    pub fn headline(&self) -> String {
        let head = match (self.how_many, &self.unit) {
            // A counting query answers yes or no; the count says why.
            (Some(n), Some(unit)) if self.count_test.is_some() => format!(
                "{} ({n} {}{}; the question asks for {})",
                self.answer.as_str(),
                if n == 1 { singular(unit) } else { unit.clone() },
                if self.windows > 1 {
                    format!(" over {} windows", self.windows)
                } else {
                    String::new()
                },
                self.count_test.as_deref().unwrap_or_default()
            ),
            (Some(n), Some(unit)) => {
                format!("{n} {}", if n == 1 { singular(unit) } else { unit.clone() })
            }
            _ if !self.values.is_empty() => {
                let shown: Vec<&str> = self
                    .values
                    .iter()
                    .take(SUMMARY_VALUES)
                    .map(String::as_str)
                    .collect();
                let more = self.values.len().saturating_sub(SUMMARY_VALUES);
                if more > 0 {
                    format!("{} and {more} more", shown.join(", "))
                } else {
                    shown.join(", ")
                }
            }
            _ => self.answer.as_str().to_string(),
        };
        let of = |k: usize| {
            if self.windows == 1 {
                String::new()
            } else {
                format!(" in {k} of {} windows", self.windows)
            }
        };
        match self.answer {
            Outcome::Yes | Outcome::No if !self.yes.is_empty() => {
                let frames: Vec<String> = self
                    .yes
                    .iter()
                    .take(SUMMARY_WINDOWS)
                    .map(|w| format!("{}–{}", w.first_frame, w.last_frame))
                    .collect();
                let more = if self.yes.len() > SUMMARY_WINDOWS {
                    format!(" and {} more", self.yes.len() - SUMMARY_WINDOWS)
                } else {
                    String::new()
                };
                let sep = if self.windows == 1 { " in" } else { ":" };
                // A universal that fails somewhere still names where it held.
                let held = if self.answer == Outcome::No {
                    " it holds only"
                } else {
                    ""
                };
                format!(
                    "{head} —{held}{}{sep} frames {}{more}",
                    of(self.yes.len()),
                    frames.join(", ")
                )
            }
            Outcome::No => {
                if self.windows == 1 {
                    head
                } else {
                    format!("{head} — in none of {} windows", self.windows)
                }
            }
            Outcome::Unknown => format!(
                "{head} — no window proves it, and {} cannot tell",
                if self.windows == 1 {
                    "this window".to_string()
                } else {
                    format!("{} of {} windows", self.unknown, self.windows)
                }
            ),
            Outcome::Invalid | Outcome::Yes => head,
        }
    }
}

/// Windows named in a summary line before "and N more".
const SUMMARY_WINDOWS: usize = 8;
/// Values named in a summary line before "and N more".
const SUMMARY_VALUES: usize = 10;

/// The values a "what …/which …" question asks for: those of the variable
/// in a function's value position (`ColorOf(x, y)` → `y`), else of the
/// first answer variable ("Which vehicles …" → the vehicles), distinct and
/// sorted, over every window that says yes. Of the values bound to one
/// object, a value is dropped when another is its subtype by the LogicPad's
/// taxonomy rules (`TypeOf(x, Sedan) ==> TypeOf(x, Car)`): "What type is
/// the blue sedan?" answers `Sedan`, not `Car, Sedan`.
fn asked_values(
    words: &crate::context::Sentences,
    p: &Prepared,
    results: &[AskResult],
) -> Vec<String> {
    if p.intent != crate::translate::Intent::Which {
        return Vec::new();
    }
    let Ok(ParsedQuery::Exists(ast)) = &p.parsed else {
        return Vec::new();
    };
    use logicpad::fol::{Arg, Literal};
    // The valued literal: its predicate, the object variable (first
    // argument, when a variable) and the value variable.
    let valued = ast
        .disjuncts
        .first()
        .into_iter()
        .flatten()
        .find_map(|l| match l {
            Literal::Pos(a) if words.is_valued(&a.pred) => match a.args.get(1) {
                Some(Arg::Var(v)) => {
                    let object = match a.args.first() {
                        Some(Arg::Var(o)) => ast.vars.get(*o).cloned(),
                        _ => None,
                    };
                    Some((a.pred.clone(), object, ast.vars.get(*v).cloned()?))
                }
                _ => None,
            },
            _ => None,
        });
    let (var, taxonomy) = match valued {
        Some((pred, object, var)) => (var, object.map(|o| (pred, o))),
        None => match ast.answer_var_names().first() {
            Some(v) => (v.to_string(), None),
            None => return Vec::new(),
        },
    };
    let value_of =
        |b: &Vec<(String, String)>, v: &str| b.iter().find(|(n, _)| n == v).map(|(_, c)| c.clone());
    let bindings = results
        .iter()
        .filter(|r| r.answer == Outcome::Yes)
        .flat_map(|r| r.bindings.iter());
    let Some((pred, object)) = taxonomy else {
        let values: BTreeSet<String> = bindings.filter_map(|b| value_of(b, &var)).collect();
        return values.into_iter().collect();
    };
    // Values per object, then each object's most specific ones.
    let mut per_object: BTreeMap<Option<String>, BTreeSet<String>> = BTreeMap::new();
    for b in bindings {
        if let Some(v) = value_of(b, &var) {
            per_object
                .entry(value_of(b, &object))
                .or_default()
                .insert(v);
        }
    }
    let empty = BTreeMap::new();
    let supers = words.supertypes(&pred).unwrap_or(&empty);
    let values: BTreeSet<String> = per_object
        .values()
        .flat_map(|vs| {
            vs.iter()
                .filter(|v| {
                    !vs.iter()
                        .any(|w| supers.get(w.as_str()).is_some_and(|up| up.contains(*v)))
                })
                .cloned()
                .collect::<Vec<_>>()
        })
        .collect();
    values.into_iter().collect()
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

#[cfg(test)]
mod taxonomy_tests {
    use super::*;

    #[test]
    fn the_builtin_taxonomy_makes_every_car_body_style_a_car_and_vans_not() {
        let words = crate::context::Sentences::builtin();
        let up = words.supertypes("TypeOf").cloned().unwrap_or_default();
        for sub in [
            "Sedan",
            "SUV",
            "Coupe",
            "Hatchback",
            "Wagon",
            "Minivan",
            "Cab",
            "Convertible",
            "PoliceCar",
        ] {
            assert!(
                up.get(sub).is_some_and(|s| s.contains("Car")),
                "{sub}: {up:?}"
            );
        }
        for not_car in ["Car", "Van", "Truck", "Bus", "Tram", "Pedestrian"] {
            assert!(
                !up.get(not_car).is_some_and(|s| s.contains("Car")),
                "{not_car}"
            );
        }
        assert!(words.supertypes("ColorOf").is_none());
    }

    #[test]
    fn taxonomy_edges_are_closed_transitively_and_ignore_other_rules() {
        let pad = LogicPad::parse(
            r#"
atomic_predicates:
  a:
    - predicate: Vehicles(x)
functions:
  f:
    TypeOf:
      predicate: TypeOf(x, type)
      values: [Car, Sedan, Limousine, Van]
derived_predicates:
  - name: TypeOf
    logic:
      - "∀x : TypeOf(x, Sedan) ==> TypeOf(x, Car)"
      - "∀x : TypeOf(x, Limousine) ==> TypeOf(x, Sedan)"
      - "∀x : TypeOf(x, Van) ∧ Vehicles(x) ==> TypeOf(x, Car)"
"#,
            "t.yaml",
            false,
        )
        .unwrap();
        let up = taxonomy_edges(pad.program(), "TypeOf");
        let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
        assert_eq!(up.get("Limousine"), Some(&set(&["Car", "Sedan"])));
        assert_eq!(up.get("Sedan"), Some(&set(&["Car"])));
        // Two body atoms: not a plain is-a edge.
        assert_eq!(up.get("Van"), None);
    }

    /// urban_crossing's agents: car_1 and car_4 (Car), suv_2 (SUV), van_3
    /// (Van), the blue sedan_6 driving, pedestrian_5.
    #[test]
    fn a_sedan_is_counted_as_a_car_and_a_type_question_names_the_sedan() {
        let loaded = crate::source::load(
            &"sim:urban_crossing".parse().unwrap(),
            &crate::source::LoadOptions::default(),
            &mut |_| {},
        )
        .unwrap();
        let e = Engine::new(LogicPad::builtin(), loaded.observability).unwrap();
        let kbs: Vec<WindowKb> = loaded
            .windows
            .into_iter()
            .map(|w| WindowKb::build(w, e.pad().program()).unwrap())
            .collect();
        let run = |query: &str, intent: crate::translate::Intent| {
            let mut p = e.prepare(query).unwrap();
            p.intent = intent;
            let results: Vec<AskResult> = kbs
                .iter()
                .map(|kb| e.ask(kb, &p, AskOptions::default()))
                .collect();
            Summary::new(e.words(), &p, &results)
        };
        use crate::translate::Intent;
        let cars = run("TypeOf(x, Car)", Intent::Which);
        assert_eq!(cars.values, ["car_1", "car_4", "sedan_6", "suv_2"]);
        let how_many = run("TypeOf(x, Car)", Intent::HowMany);
        assert_eq!(how_many.how_many, Some(4));
        let moving = run("TypeOf(x, Car) ^ Move(x)", Intent::Which);
        assert_eq!(moving.values, ["sedan_6"]);
        let what = run(
            "TypeOf(x, Sedan) ^ ColorOf(x, Blue) ^ TypeOf(x, y)",
            Intent::Which,
        );
        assert_eq!(what.values, ["Sedan"]);
        // Whatever car: each object's most specific type.
        let types = run("TypeOf(x, Car) ^ TypeOf(x, y)", Intent::Which);
        assert_eq!(types.values, ["Car", "SUV", "Sedan"]);
    }
}

fn singular(unit: &str) -> String {
    match unit {
        "people" => "person".into(),
        "pairs" => "pair".into(),
        u if u.ends_with("ies") => format!("{}y", &u[..u.len() - 3]),
        u if u.ends_with("ses") || u.ends_with("shes") || u.ends_with("ches") => {
            u[..u.len() - 2].to_string()
        }
        u => u.strip_suffix('s').unwrap_or(u).to_string(),
    }
}

/// Distinct objects over all windows bound to the query's first answer
/// variable, or unordered pairs when the bindings of two variables are
/// symmetric (`TooClose(x, y)` lists each pair both ways).
fn count_objects(
    words: &crate::context::Sentences,
    p: &Prepared,
    results: &[AskResult],
) -> (usize, String) {
    let bindings: Vec<&Vec<(String, String)>> = results
        .iter()
        .filter(|r| r.answer == Outcome::Yes)
        .flat_map(|r| r.bindings.iter())
        .collect();
    let vars: Vec<String> = results
        .iter()
        .find(|r| !r.variables.is_empty())
        .map(|r| r.variables.clone())
        .unwrap_or_default();
    let Some(first) = vars.first() else {
        return (bindings.len(), "answers".into());
    };
    let value =
        |b: &Vec<(String, String)>, v: &str| b.iter().find(|(n, _)| n == v).map(|(_, c)| c.clone());
    if let [x, y] = vars.as_slice() {
        let pairs: BTreeSet<(String, String)> = bindings
            .iter()
            .filter_map(|b| Some((value(b, x)?, value(b, y)?)))
            .collect();
        let symmetric = !pairs.is_empty()
            && pairs
                .iter()
                .all(|(a, b)| pairs.contains(&(b.clone(), a.clone())));
        if symmetric {
            let unordered: BTreeSet<(String, String)> = pairs
                .into_iter()
                .map(|(a, b)| if a <= b { (a, b) } else { (b, a) })
                .collect();
            return (unordered.len(), "pairs".into());
        }
    }
    let objects: BTreeSet<String> = bindings.iter().filter_map(|b| value(b, first)).collect();
    (objects.len(), noun_of(words, p, first))
}

/// The plural noun for what variable `var` stands for: its type or class
/// in the query, in the LogicPad's words (`Pedestrian(x)` → "pedestrians",
/// `TypeOf(x, Car)` → "cars"), else "objects".
fn noun_of(words: &crate::context::Sentences, p: &Prepared, var: &str) -> String {
    match &p.parsed {
        Ok(ParsedQuery::Exists(ast)) => noun_in(words, ast, var),
        Ok(ParsedQuery::Count(c)) => noun_in(words, &c.query, var),
        _ => "objects".into(),
    }
}

/// [`noun_of`] for the variable `var` of one existential query.
fn noun_in(words: &crate::context::Sentences, ast: &logicpad::QueryAst, var: &str) -> String {
    let Some(v) = ast.vars.iter().position(|n| n == var) else {
        return "objects".into();
    };
    use logicpad::fol::{Arg, Literal};
    let atoms = ast
        .disjuncts
        .first()
        .into_iter()
        .flatten()
        .filter_map(Literal::positive);
    let mut class = None;
    for a in atoms {
        match a.args.as_slice() {
            [Arg::Var(x), Arg::Const(t)] if *x == v && words.is_type(&a.pred) => {
                if let Some(n) = words.noun(t) {
                    return plural(n);
                }
            }
            [Arg::Var(x)] if *x == v && class.is_none() => {
                class = words.noun(&a.pred).filter(|_| words.is_class(&a.pred));
            }
            _ => {}
        }
    }
    class.map_or_else(|| "objects".into(), plural)
}

fn plural(noun: &str) -> String {
    if let Some(head) = noun.strip_suffix("person") {
        return format!("{head}people");
    }
    match noun {
        "vehicles" => "vehicles".into(),
        n if n.ends_with('s') || n.ends_with("sh") || n.ends_with("ch") => format!("{n}es"),
        n => format!("{n}s"),
    }
}

#[cfg(test)]
mod tests {

    /// `--translator` and `--llm` choose the translator; the LLM one needs a
    /// server, and `auto` without one is the grammar alone. Queries are
    /// taken as written whatever the translator.
    #[test]
    fn translator_modes() {
        assert!(matches!(
            translator(TranslatorMode::Llm, None),
            Err(PrepareError::NoLlm)
        ));
        for mode in [TranslatorMode::Grammar, TranslatorMode::Auto] {
            let t = translator(mode, None).map_err(|e| e.to_string());
            assert_eq!(t.map(|t| t.mode()), Ok(TranslatorMode::Grammar));
        }
        let e = engine();
        let p = e
            .prepare_with(&Grammar, "Vehicles(x)")
            .map_err(|e| e.to_string());
        assert_eq!(p.map(|p| p.question), Ok(None));
        let p = e
            .prepare_with(&Grammar, "Is there a car?")
            .map_err(|e| e.to_string());
        assert!(p.is_ok_and(|p| p.question.is_some()));
    }

    use super::*;
    use crate::kb::test_window;

    fn engine() -> Engine {
        Engine::new(LogicPad::builtin(), Observability::everything()).expect("builtin engine")
    }

    #[test]
    fn an_absent_constant_is_a_constant_and_answers_no() {
        // Regression: `TypeOf(car_3, Sedan)` on a window without car_3 made
        // car_3 a variable and answered "yes, car_3 = sedan_6".
        let e = engine();
        let kb = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["sedan_6"]),
                ("TypeOf", &["sedan_6", "Sedan"]),
                ("Moving", &["sedan_6"]),
                ("Moving", &["car_4"]),
                ("Vehicles", &["car_4"]),
                ("ColorOf", &["car_4", "Red"]),
            ],
        );
        for q in ["TypeOf(car_3, Sedan)", "Moving(foo)", "ColorOf(car_1, x)"] {
            let p = e.prepare(q).expect("prepares");
            let r = e.ask(&kb, &p, AskOptions::default());
            assert_eq!(r.answer, Outcome::No, "{q}: {r:?}");
            assert!(
                r.notes
                    .iter()
                    .any(|n| n.contains("is not seen in frames 0–9")),
                "{q}: {:?}",
                r.notes
            );
        }
        // `x != car_1` with car_1 absent is a safe comparison with a constant.
        let p = e.prepare("Moving(x) ^ x != car_1").expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Yes, "{r:?}");
        assert_eq!(r.count, 2);
        // A constant only under ¬ proves nothing absent.
        let p = e.prepare("Vehicles(x) ^ ¬On(x, road_9)").expect("prepares");
        assert_eq!(e.ask(&kb, &p, AskOptions::default()).answer, Outcome::Yes);
    }

    #[test]
    fn a_universal_is_answered_under_the_closed_world() {
        let e = engine();
        let kb = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["car_1"]),
                ("Moving", &["car_1"]),
                ("Vehicles", &["car_2"]),
                ("Pedestrian", &["ped_1"]),
            ],
        );
        // Regression: `forall x: Moving(x)` was read as `Moving(x)`: YES.
        let p = e.prepare("forall x: Moving(x)").expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Invalid);
        assert!(
            r.reasons
                .iter()
                .any(|s| s.contains("ranges over everything")),
            "{:?}",
            r.reasons
        );
        let p = e
            .prepare("forall x: Vehicles(x) -> Moving(x)")
            .expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::No);
        assert_eq!(
            r.why_not.first().map(|w| w.candidate.as_str()),
            Some("car_2")
        );
        let p = e
            .prepare("∀x: Vehicles(x) ∧ Moving(x) → Move(x)")
            .expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Yes);
        assert_eq!(
            r.bindings,
            vec![vec![("x".to_string(), "car_1".to_string())]]
        );
        assert!(!r.proofs.is_empty());
        let p = e.prepare("∀x: Cyclist(x) → Moving(x)").expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Yes);
        assert!(
            r.notes.iter().any(|n| n.starts_with("vacuously")),
            "{:?}",
            r.notes
        );
        // A universal over what the source cannot see is unknown.
        let blind =
            e.for_source(Observability::everything().without(&["Moving"], "no motion here"));
        let p = blind
            .prepare("∀x: Vehicles(x) → Moving(x)")
            .expect("prepares");
        let r = blind.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Unknown);
        assert!(
            r.reasons.iter().any(|s| s.contains("no motion here")),
            "{:?}",
            r.reasons
        );
    }

    #[test]
    fn a_count_over_a_video_counts_distinct_objects_of_every_window() {
        // Two windows of two cars each, one car in both: three distinct
        // cars, though no window alone has more than two.
        let e = engine();
        let k1 = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["car_1"]),
                ("TypeOf", &["car_1", "Car"]),
                ("Vehicles", &["car_2"]),
                ("TypeOf", &["car_2", "Car"]),
            ],
        );
        let k2 = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["car_2"]),
                ("TypeOf", &["car_2", "Car"]),
                ("Vehicles", &["car_3"]),
                ("TypeOf", &["car_3", "Car"]),
            ],
        );
        let p = e.prepare_query("#{x: TypeOf(x, Car)} > 2");
        let rs = [
            e.ask(&k1, &p, AskOptions::default()),
            e.ask(&k2, &p, AskOptions::default()),
        ];
        assert!(rs.iter().all(|r| r.answer == Outcome::No && r.count == 2));
        assert_eq!(
            rs[0].notes,
            vec!["found 2 cars (car_1, car_2); the question asks for more than 2"]
        );
        let s = Summary::new(e.words(), &p, &rs);
        assert_eq!(s.answer, Outcome::Yes);
        assert_eq!((s.how_many, s.unit.as_deref()), (Some(3), Some("cars")));
        assert_eq!(
            s.headline(),
            "yes (3 cars over 2 windows; the question asks for more than 2)"
        );
        // Each window keeps its own answer; "exactly 2" holds in each and
        // fails over the video.
        let p = e.prepare_query("#{x: TypeOf(x, Car)} = 2");
        let rs = [
            e.ask(&k1, &p, AskOptions::default()),
            e.ask(&k2, &p, AskOptions::default()),
        ];
        assert!(rs.iter().all(|r| r.answer == Outcome::Yes));
        assert_eq!(Summary::new(e.words(), &p, &rs).answer, Outcome::No);
    }

    #[test]
    fn how_many_counts_distinct_objects_and_symmetric_pairs_once() {
        let e = engine();
        let kb = test_window(
            e.pad().program(),
            &[
                ("Pedestrian", &["ped_1"]),
                ("Pedestrian", &["ped_2"]),
                ("Moving", &["ped_1"]),
                ("Moving", &["ped_2"]),
                ("Vehicles", &["car_1"]),
                ("Vehicles", &["car_2"]),
                ("TooClose", &["car_1", "car_2"]),
                ("TooClose", &["car_2", "car_1"]),
            ],
        );
        let mut p = e.prepare_query("Pedestrian(x) ^ Walk(x)");
        p.intent = crate::translate::Intent::HowMany;
        let r = e.ask(&kb, &p, AskOptions::default());
        let s = Summary::new(e.words(), &p, &[r.clone(), r]);
        assert_eq!(
            (s.how_many, s.unit.as_deref()),
            (Some(2), Some("pedestrians"))
        );
        assert!(
            s.headline()
                .starts_with("2 pedestrians — in 2 of 2 windows: frames 0–9"),
            "{}",
            s.headline()
        );
        let mut p = e.prepare_query("Vehicles(x) ^ Vehicles(y) ^ TooClose(x, y)");
        p.intent = crate::translate::Intent::HowMany;
        let s = Summary::new(e.words(), &p, &[e.ask(&kb, &p, AskOptions::default())]);
        assert_eq!((s.how_many, s.unit.as_deref()), (Some(1), Some("pairs")));
        assert_eq!(s.headline(), "1 pair — in frames 0–9");
    }

    #[test]
    fn a_closed_no_query_over_a_video_fails_in_one_window() {
        let e = engine();
        let empty = test_window(e.pad().program(), &[("Vehicles", &["car_1"])]);
        let with = test_window(e.pad().program(), &[("Pedestrian", &["ped_1"])]);
        let p = e.prepare_query("¬∃x: (Pedestrian(x))");
        assert!(p.is_closed_negation());
        let (a, b) = (
            e.ask(&empty, &p, AskOptions::default()),
            e.ask(&with, &p, AskOptions::default()),
        );
        assert_eq!((a.answer, b.answer), (Outcome::Yes, Outcome::No));
        // "Are there no pedestrians?" over a video with one: no, though
        // a window without one says yes.
        let s = Summary::new(e.words(), &p, &[a.clone(), b]);
        assert_eq!(s.answer, Outcome::No);
        assert_eq!(
            Summary::new(e.words(), &p, &[a.clone(), a]).answer,
            Outcome::Yes
        );
        // An open query with a negation stays existential over windows.
        let open = e.prepare_query("Vehicles(x) ^ ¬∃y: (Pedestrian(y))");
        assert!(!open.is_closed_negation());
    }

    #[test]
    fn value_questions_are_answered_by_their_values() {
        let e = engine();
        let kb = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["van_3"]),
                ("TypeOf", &["van_3", "Van"]),
                ("ColorOf", &["van_3", "White"]),
            ],
        );
        let p = e.prepare("What colour is the van?").expect("translates");
        let r = e.ask(&kb, &p, AskOptions::default());
        let s = Summary::new(e.words(), &p, &[r]);
        assert_eq!(s.values, ["White"]);
        assert_eq!(s.headline(), "White — in frames 0–9");
    }

    #[test]
    fn unknown_says_what_the_source_lacks_in_words() {
        let e = Engine::new(
            LogicPad::builtin(),
            Observability::everything().without(
                &["Road", "Sidewalk", "On"],
                "KITTI labels carry no road or sidewalk",
            ),
        )
        .expect("engine");
        let kb = test_window(e.pad().program(), &[("Pedestrian", &["ped_1"])]);
        let p = e.prepare_query("Pedestrian(x) ^ Cross(x)");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::Unknown);
        let text = r.reasons.join("\n");
        assert!(
            text.contains("KITTI labels carry no road or sidewalk"),
            "{text}"
        );
        assert!(text.contains("`Cross`"), "{text}");
    }
}

#[cfg(test)]
mod props {
    use super::*;
    use crate::kb::test_window;
    use proptest::prelude::*;

    const PRESENT: [&str; 3] = ["car_1", "car_2", "ped_1"];
    const ABSENT: [&str; 3] = ["car_3", "foo", "ped_9"];

    /// A fact: predicate and arguments.
    type FactRow = (String, Vec<String>);
    /// A query atom: negated, predicate, arguments.
    type AtomRow = (bool, String, Vec<String>);

    /// A random window over the present objects, and a random conjunctive
    /// query over x, y and constants (present or absent).
    fn window_and_query() -> impl Strategy<Value = (Vec<FactRow>, Vec<AtomRow>)> {
        let obj = prop::sample::select(PRESENT.to_vec()).prop_map(str::to_string);
        let unary = (
            prop::sample::select(vec!["Vehicles", "Pedestrian", "Moving", "SpeedUp"]),
            obj.clone(),
        )
            .prop_map(|(p, o)| (p.to_string(), vec![o]));
        let binary = (
            prop::sample::select(vec!["TooClose", "DistanceDecrease"]),
            obj.clone(),
            obj,
        )
            .prop_map(|(p, a, b)| (p.to_string(), vec![a, b]));
        let facts = prop::collection::vec(prop_oneof![unary, binary], 0..12);
        let term = prop::sample::select(vec!["x", "y", "car_1", "ped_1", "car_3", "foo", "ped_9"])
            .prop_map(str::to_string);
        let atom = (
            any::<bool>(),
            prop::sample::select(vec![
                "Vehicles",
                "Pedestrian",
                "Moving",
                "TooClose",
                "DistanceDecrease",
            ]),
            term.clone(),
            term,
        )
            .prop_map(|(neg, p, a, b)| {
                let args = if matches!(p, "TooClose" | "DistanceDecrease") {
                    vec![a, b]
                } else {
                    vec![a]
                };
                (neg, p.to_string(), args)
            });
        (facts, prop::collection::vec(atom, 1..4))
    }

    fn text(atoms: &[AtomRow], rename: Option<(&str, &str)>) -> String {
        let mut atoms: Vec<_> = atoms.to_vec();
        // Positive atoms first so negations are bound where possible.
        atoms.sort_by_key(|(neg, _, _)| *neg);
        atoms
            .iter()
            .map(|(neg, p, args)| {
                let args: Vec<&str> = args
                    .iter()
                    .map(|a| match rename {
                        Some((from, to)) if a == from => to,
                        _ => a.as_str(),
                    })
                    .collect();
                format!("{}{p}({})", if *neg { "¬" } else { "" }, args.join(", "))
            })
            .collect::<Vec<_>>()
            .join(" ∧ ")
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        /// Whether a name is a constant never depends on the window: renaming
        /// an absent object to another absent name changes no outcome, and a
        /// query that needs an absent object in a positive atom is never yes.
        #[test]
        fn renaming_an_absent_object_never_turns_no_into_yes((facts, atoms) in window_and_query(), to in prop::sample::select(ABSENT.to_vec())) {
            let e = Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine");
            let lines: Vec<(&str, Vec<&str>)> = facts.iter().map(|(p, a)| (p.as_str(), a.iter().map(String::as_str).collect())).collect();
            let refs: Vec<(&str, &[&str])> = lines.iter().map(|(p, a)| (*p, a.as_slice())).collect();
            let kb = test_window(e.pad().program(), &refs);
            let q = text(&atoms, None);
            let base = e.ask(&kb, &e.prepare_query(&q), AskOptions::BINDINGS);
            for from in ABSENT {
                if kb.constants.contains(from) { continue; }
                let renamed = text(&atoms, Some((from, to)));
                let r = e.ask(&kb, &e.prepare_query(&renamed), AskOptions::BINDINGS);
                prop_assert_eq!(base.answer, r.answer, "{} vs {}", q, renamed);
                prop_assert_eq!(base.count, r.count, "{} vs {}", q, renamed);
            }
            let needs_absent = atoms.iter().any(|(neg, _, args)| !neg && args.iter().any(|a| ABSENT.contains(&a.as_str())));
            if needs_absent {
                prop_assert_ne!(base.answer, Outcome::Yes, "{}", q);
            }
        }
    }
}
