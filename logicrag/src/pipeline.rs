//! [`Pipeline`]: the one way from a question to answers, shared by every
//! front end — the CLI's `ask`, `context`, `demo` and `eval`, batches, the
//! LMM evaluation, the REPL, `serve` (API, retriever, proxy) and the Python
//! package.
//!
//! ```text
//! text ──prepare (its translator)──▶ Prepared
//! windows ──reason (once, lazily or up front)──▶ WindowKb per window
//! (Prepared, window id or all) ──ask / context / retrieve──▶ answers
//! ```
//!
//! Why one type: each front end used to wire engine, translator, windows
//! and KBs by hand, and they drifted (a translator one of them ignored, an
//! unknown window said in another's words). A pipeline owns all four, so a
//! front end only renders what it returns; a window id it does not have is
//! always [`SessionError::UnknownWindow`], worded by [`NoWindow`].
//!
//! A temporal query (`(Q1) THEN (Q2)`, `EVER: Q`, …) is answered once per
//! video, not per window ([`Pipeline::ask_temporal`]): asked of every
//! window it looks at all of them, asked of window W at the windows up to
//! and including W (the past seen from W), and every asking method gives
//! that one answer, spanning those windows' frames.

use crate::ask::{AskOptions, AskResult};
use crate::context::RagContext;
use crate::engine::{Engine, Page, PrepareError, Prepared, Summary, Translate, Truncation};
use crate::kb::{KbError, NoWindow, WindowInput, WindowKb};
use crate::session::{SessionError, SourceOptions, camera_note};
use crate::source::{Progress, SourceSpec};
use crate::temporal::TemporalAnswer;
use serde_json::Value;
use std::sync::{Arc, Mutex, OnceLock};

/// A source's windows with the engine for its observability and a
/// translator, ready to be asked.
///
/// Invariant: `engine` has this source's observability; `kbs`, once set,
/// holds one reasoned KB per window, in source order — reasoned from
/// `inputs` (then `inputs` are kept, for facts and for reasoning again
/// under another LogicPad), or [`Pipeline::into_reasoned`] (then `inputs`
/// is empty).
#[derive(Debug)]
pub struct Pipeline {
    label: String,
    engine: Engine,
    translator: Arc<dyn Translate>,
    inputs: Vec<WindowInput>,
    notes: Vec<String>,
    /// Reasoned on the first question: a caller who only reads facts never
    /// pays for reasoning.
    kbs: OnceLock<Vec<WindowKb>>,
    /// Held while reasoning, so that two first questions at once reason
    /// the windows once.
    building: Mutex<()>,
}

/// One window's answer to a prepared question.
#[derive(Debug, Clone)]
pub struct Answer<'a> {
    /// The window asked.
    pub window: &'a WindowKb,
    /// Its answer.
    pub result: AskResult,
    /// What a paged answer left out (`None`: nothing).
    pub truncated: Option<Truncation>,
}

impl Pipeline {
    /// A pipeline over `windows` of the source labelled `label`, reasoned
    /// when first asked; `engine` must have the source's observability.
    /// Questions go through the grammar until [`Pipeline::with_translator`].
    pub fn new(label: impl Into<String>, engine: Engine, windows: Vec<WindowInput>) -> Pipeline {
        Pipeline {
            label: label.into(),
            engine,
            translator: Arc::new(crate::engine::Grammar),
            inputs: windows,
            notes: Vec::new(),
            kbs: OnceLock::new(),
            building: Mutex::new(()),
        }
    }

    /// Opens `source` (any `--source` string) with `options`, for
    /// `engine`'s LogicPad; `progress` sees every frame of a `frames:` run.
    pub fn open(
        engine: &Engine,
        source: &str,
        options: &SourceOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Pipeline, SessionError> {
        let spec: SourceSpec = source.parse()?;
        let mut notes: Vec<String> = camera_note(&spec).into_iter().collect();
        let loaded = options.load(spec, progress)?;
        // What the source skipped (an AV2 log's ego rows), for every front
        // end to show.
        notes.extend(loaded.skipped_notes());
        let mut p = Pipeline::new(
            loaded.label,
            engine.for_source(loaded.observability),
            loaded.windows,
        );
        p.notes = notes;
        Ok(p)
    }

    /// A pipeline over a loaded source's windows, with `engine`'s
    /// LogicPad for the source's observability (its pictures, tracks and
    /// run are the caller's to take first).
    pub fn from_loaded(engine: &Engine, loaded: crate::source::Loaded) -> Pipeline {
        let notes = loaded.skipped_notes();
        let mut p = Pipeline::new(
            loaded.label,
            engine.for_source(loaded.observability),
            loaded.windows,
        );
        p.notes = notes;
        p
    }

    /// The pipeline narrowed to the window named `id` (all of them for
    /// `None`), before any reasoning: a front end that asks one window
    /// reasons that window only.
    pub fn only(mut self, id: Option<&str>) -> Result<Pipeline, SessionError> {
        let Some(id) = id else {
            return Ok(self);
        };
        self.check_window(Some(id))?;
        self.inputs.retain(|w| w.id == id);
        if let Some(kbs) = self.kbs.take() {
            let _ = self
                .kbs
                .set(kbs.into_iter().filter(|k| k.id == id).collect());
        }
        Ok(self)
    }

    /// A pipeline over the windows `keep` picks, with the same engine and
    /// translator, not yet reasoned: for a front end that asks some
    /// windows again after handing this pipeline on (the demo's worked
    /// examples, the LMM evaluation after the logic's).
    pub fn subset(&self, keep: impl Fn(&WindowInput) -> bool) -> Pipeline {
        let windows = self.inputs.iter().filter(|w| keep(w)).cloned().collect();
        let mut p = Pipeline::new(self.label.clone(), self.engine.clone(), windows);
        p.translator = Arc::clone(&self.translator);
        p.notes = self.notes.clone();
        p
    }

    /// The same pipeline translating with `translator`.
    pub fn with_translator(mut self, translator: Arc<dyn Translate>) -> Pipeline {
        self.translator = translator;
        self
    }

    /// Translates with `translator` from now on (the REPL's `:translator`).
    pub fn set_translator(&mut self, translator: Arc<dyn Translate>) {
        self.translator = translator;
    }

    /// The same windows and translator under `engine` (another LogicPad),
    /// reasoned again now. Only a pipeline that kept its inputs (not one
    /// made [`Pipeline::into_reasoned`]) has windows to reason.
    pub fn rebuilt(&self, engine: Engine) -> Result<Pipeline, SessionError> {
        let mut p = self.subset(|_| true);
        p.engine = engine;
        p.build(&|| {})?;
        Ok(p)
    }

    /// The source's label (`sim:urban_crossing`, `kitti:0000`).
    pub fn label(&self) -> &str {
        &self.label
    }

    /// What the user should know about the source (the CLI's `note:`
    /// lines on stderr).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The engine, for this source's observability.
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// The translator questions go through.
    pub fn translator(&self) -> &Arc<dyn Translate> {
        &self.translator
    }

    /// The windows' inputs, in order (empty after
    /// [`Pipeline::into_reasoned`]).
    pub fn windows(&self) -> &[WindowInput] {
        &self.inputs
    }

    /// The window ids, in order.
    pub fn ids(&self) -> Box<dyn Iterator<Item = &str> + '_> {
        match self.kbs.get() {
            Some(kbs) => Box::new(kbs.iter().map(|k| k.id.as_str())),
            None => Box::new(self.inputs.iter().map(|w| w.id.as_str())),
        }
    }

    /// How many windows the source has.
    pub fn window_count(&self) -> usize {
        self.kbs.get().map_or(self.inputs.len(), Vec::len)
    }

    /// The sentence for a window id this source does not have.
    pub fn no_window(&self, id: &str) -> NoWindow {
        NoWindow::new(&self.label, id, self.ids())
    }

    /// Every window reasoned now (once: later calls share the result),
    /// `done` called once per window.
    pub fn build(&self, done: &(dyn Fn() + Sync)) -> Result<&[WindowKb], SessionError> {
        if let Some(kbs) = self.kbs.get() {
            return Ok(kbs);
        }
        // A poisoned lock only means another thread panicked while
        // reasoning; `kbs` is then still unset or complete.
        let _guard = self
            .building
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(kbs) = self.kbs.get() {
            return Ok(kbs);
        }
        let kbs = self.engine.build_all(self.inputs.clone(), done)?;
        Ok(self.kbs.get_or_init(|| kbs))
    }

    /// The pipeline with every window reasoned now, `done` called once per
    /// window, keeping the KBs only: a front end that answers from the
    /// same windows for its whole life (`serve`) does not hold every fact
    /// twice. [`Pipeline::windows`] is then empty.
    pub fn into_reasoned(mut self, done: &(dyn Fn() + Sync)) -> Result<Pipeline, SessionError> {
        if self.kbs.get().is_none() {
            let inputs = std::mem::take(&mut self.inputs);
            let kbs = self.engine.build_all(inputs, done)?;
            let _ = self.kbs.set(kbs);
        } else {
            self.inputs.clear();
        }
        Ok(self)
    }

    /// Every window reasoned (on the first call).
    pub fn kbs(&self) -> Result<&[WindowKb], SessionError> {
        self.build(&|| {})
    }

    /// The reasoned windows, if they have been reasoned.
    pub fn reasoned_windows(&self) -> Option<&[WindowKb]> {
        self.kbs.get().map(Vec::as_slice)
    }

    /// Checks that `id` (when given) names a window, without reasoning.
    pub fn check_window(&self, id: Option<&str>) -> Result<(), SessionError> {
        match id {
            Some(id) if !self.ids().any(|w| w == id) => {
                Err(SessionError::UnknownWindow(self.no_window(id)))
            }
            _ => Ok(()),
        }
    }

    /// The windows named `id`, or all of them, reasoned; a wrong id costs
    /// no reasoning.
    pub fn select(&self, id: Option<&str>) -> Result<Vec<&WindowKb>, SessionError> {
        self.check_window(id)?;
        Ok(self
            .kbs()?
            .iter()
            .filter(|kb| id.is_none_or(|id| kb.id == id))
            .collect())
    }

    /// The window named `id`, reasoned.
    pub fn window(&self, id: &str) -> Result<&WindowKb, SessionError> {
        self.select(Some(id))?
            .into_iter()
            .next()
            .ok_or_else(|| SessionError::UnknownWindow(self.no_window(id)))
    }

    /// The position of the window named `id`.
    pub fn position(&self, id: &str) -> Result<usize, SessionError> {
        self.ids()
            .position(|w| w == id)
            .ok_or_else(|| SessionError::UnknownWindow(self.no_window(id)))
    }

    /// Prepares `text` with the pipeline's translator: a query as written,
    /// a question as the translator turns it into one.
    pub fn prepare(&self, text: &str) -> Result<Prepared, PrepareError> {
        self.engine.prepare_with(&*self.translator, text)
    }

    /// [`Pipeline::prepare`] when it needs no server (a query, the grammar,
    /// or a question the grammar reads under the grammar-then-LLM
    /// translator); `None` when only the translator's server can tell, so
    /// that a front end can bound its calls before making one.
    pub fn prepare_offline(&self, text: &str) -> Option<Result<Prepared, PrepareError>> {
        if crate::translate::looks_like_query(text) {
            return Some(Ok(self.engine.prepare_query(text)));
        }
        self.translator.translate_offline(&self.engine, text)
    }

    /// Answers a prepared question on one window.
    pub fn ask_window(&self, kb: &WindowKb, p: &Prepared, opts: AskOptions) -> AskResult {
        self.engine.ask(kb, p, opts)
    }

    /// Answers a prepared question on the window named `window`, or on
    /// every window, in source order. A temporal query is answered once,
    /// over every window up to `window` (all of them for `None`): one
    /// answer, its `window` the last window looked at
    /// ([`Pipeline::ask_temporal`]).
    pub fn ask(
        &self,
        p: &Prepared,
        window: Option<&str>,
        opts: AskOptions,
    ) -> Result<Vec<Answer<'_>>, SessionError> {
        if let Some(a) = self.ask_temporal(p, window, opts)? {
            return self.as_answers(window, a.result);
        }
        Ok(self
            .select(window)?
            .into_iter()
            .map(|kb| Answer {
                window: kb,
                result: self.engine.ask(kb, p, opts),
                truncated: None,
            })
            .collect())
    }

    /// [`Pipeline::ask`], each window's bindings cut to `page` (see
    /// [`Engine::ask_page`]); a temporal query's one answer is not paged.
    pub fn ask_page(
        &self,
        p: &Prepared,
        window: Option<&str>,
        opts: AskOptions,
        page: Page,
    ) -> Result<Vec<Answer<'_>>, SessionError> {
        if let Some(a) = self.ask_temporal(p, window, opts)? {
            return self.as_answers(window, a.result);
        }
        Ok(self
            .select(window)?
            .into_iter()
            .map(|kb| {
                let (result, truncated) = self.engine.ask_page(kb, p, opts, page);
                Answer {
                    window: kb,
                    result,
                    truncated,
                }
            })
            .collect())
    }

    /// Answers a temporal query (`None` for any other) over the windows up
    /// to and including the one named `at`, or over all of them: each
    /// part asked of each window, the claim read from their answers
    /// ([`crate::temporal::evaluate`]). An unknown `at` costs no reasoning.
    pub fn ask_temporal(
        &self,
        p: &Prepared,
        at: Option<&str>,
        opts: AskOptions,
    ) -> Result<Option<TemporalAnswer>, SessionError> {
        let Some(t) = &p.temporal else {
            return Ok(None);
        };
        self.check_window(at)?;
        let kbs = crate::temporal::up_to(self.kbs()?, at)
            .ok_or_else(|| SessionError::UnknownWindow(self.no_window(at.unwrap_or_default())))?;
        Ok(Some(crate::temporal::answer(
            &self.engine,
            &self.label,
            t,
            &p.query,
            &kbs,
            opts,
        )))
    }

    /// The window a temporal query asked at `at` is answered on: that
    /// window, or the last one for `None` (`None` when the source has no
    /// window).
    pub fn answered_at(&self, at: Option<&str>) -> Result<Option<&WindowKb>, SessionError> {
        match at {
            Some(id) => self.window(id).map(Some),
            None => Ok(self.kbs()?.last()),
        }
    }

    /// A temporal answer as the one answer of [`Pipeline::ask`], on the
    /// window [`Pipeline::answered_at`] names.
    fn as_answers(
        &self,
        at: Option<&str>,
        result: AskResult,
    ) -> Result<Vec<Answer<'_>>, SessionError> {
        Ok(self
            .answered_at(at)?
            .map(|window| Answer {
                window,
                result,
                truncated: None,
            })
            .into_iter()
            .collect())
    }

    /// The answers' overall outcome and headline.
    pub fn summary(&self, p: &Prepared, results: &[AskResult]) -> Summary {
        Summary::new(self.engine.words(), p, results)
    }

    /// The retrieval context of one window's answer.
    pub fn context(&self, kb: &WindowKb, p: &Prepared, r: &AskResult) -> RagContext {
        self.engine.context(kb, p, r)
    }

    /// The retrieval context of a prepared question on the window named
    /// `window`, or on every window (answered with the default options).
    pub fn contexts(
        &self,
        p: &Prepared,
        window: Option<&str>,
    ) -> Result<Vec<RagContext>, SessionError> {
        Ok(self
            .ask(p, window, AskOptions::default())?
            .iter()
            .map(|a| self.context(a.window, p, &a.result))
            .collect())
    }

    /// The retriever's documents (`POST /v1/retrieve`) for a prepared
    /// question on the window named `window`, or on every window, each
    /// window's bindings cut to `page`.
    #[cfg(feature = "serve")]
    pub fn retrieve(
        &self,
        p: &Prepared,
        window: Option<&str>,
        opts: AskOptions,
        page: Page,
        limits: crate::serve::retrieve::Limits,
    ) -> Result<Vec<crate::serve::retrieve::Document>, SessionError> {
        let answers = self.ask_page(p, window, opts, page)?;
        let windows: Vec<&WindowKb> = answers.iter().map(|a| a.window).collect();
        let results: Vec<AskResult> = answers.into_iter().map(|a| a.result).collect();
        Ok(crate::serve::retrieve::documents_from(
            &self.engine,
            &self.label,
            &windows,
            p,
            &results,
            limits,
        ))
    }

    /// Answers a question (or query) on one window or all:
    /// `{"results": [...], "summary": {...}}`, the objects `ask --json`
    /// prints (as `serve`'s `/api/ask` answers). A temporal query has one
    /// result, spanning the windows up to `window` (all for `None`), with
    /// its `"temporal"` timelines ([`crate::temporal::ask_object`]).
    pub fn ask_json(
        &self,
        text: &str,
        window: Option<&str>,
        opts: AskOptions,
    ) -> Result<Value, SessionError> {
        let p = self.prepare(text)?;
        if let Some(a) = self.ask_temporal(&p, window, opts)? {
            return Ok(crate::temporal::ask_object(self.engine.words(), &p, &a)?);
        }
        let results: Vec<AskResult> = self
            .ask(&p, window, opts)?
            .into_iter()
            .map(|a| a.result)
            .collect();
        Ok(crate::json::ask_object(self.engine.words(), &p, &results)?)
    }

    /// The retrieval context of a question on one window, as
    /// `context --json` prints it.
    pub fn context_json(&self, text: &str, window: &str) -> Result<Value, SessionError> {
        let p = self.prepare(text)?;
        match self.contexts(&p, Some(window))?.into_iter().next() {
            Some(ctx) => Ok(serde_json::to_value(ctx)?),
            None => Err(SessionError::UnknownWindow(self.no_window(window))),
        }
    }

    /// Answers `items` addressed to windows by id (`window_of(i)`),
    /// reasoning each window once, windows in parallel, without keeping
    /// the KBs (a batch or an evaluation far larger than memory would hold
    /// reasoned): `answer(engine, kb, i)` runs on the workers, and each
    /// answer goes to `emit` in item order as soon as every earlier one is
    /// answered; `done(n)` hears each window's `n` items. An id the source
    /// does not have is `unknown(i, why)` for the first such item, before
    /// any reasoning. Consumes the pipeline: its windows are reasoned and
    /// dropped one by one.
    #[allow(clippy::too_many_arguments)]
    pub(crate) fn answer_each_in_order<T, E>(
        self,
        items: usize,
        window_of: impl Fn(usize) -> String,
        unknown: impl FnOnce(usize, NoWindow) -> E,
        answer: impl Fn(&Engine, &WindowKb, usize) -> T + Sync,
        done: &(dyn Fn(usize) + Sync),
        emit: &mut (dyn FnMut(usize, T) + Send),
    ) -> Result<(), E>
    where
        T: Send,
        E: Send + From<KbError>,
    {
        let label = self.label;
        let engine = self.engine;
        let ids: Vec<String> = self.inputs.iter().map(|w| w.id.clone()).collect();
        let window_of = &window_of;
        crate::kb::answer_by_window_in_order(
            engine.pad().program(),
            self.inputs,
            items,
            window_of,
            |i| {
                unknown(
                    i,
                    NoWindow::new(&label, &window_of(i), ids.iter().map(String::as_str)),
                )
            },
            |kb, i| answer(&engine, kb, i),
            done,
            emit,
        )
    }

    /// [`Pipeline::answer_each_in_order`], the answers collected.
    pub(crate) fn answer_each<T, E>(
        self,
        items: usize,
        window_of: impl Fn(usize) -> String,
        unknown: impl FnOnce(usize, NoWindow) -> E,
        answer: impl Fn(&Engine, &WindowKb, usize) -> T + Sync,
        done: &(dyn Fn(usize) + Sync),
    ) -> Result<Vec<T>, E>
    where
        T: Send,
        E: Send + From<KbError>,
    {
        let mut out: Vec<T> = Vec::with_capacity(items);
        self.answer_each_in_order(items, window_of, unknown, answer, done, &mut |_, t| {
            out.push(t)
        })?;
        Ok(out)
    }

    /// The facts of one window or all as Arrow record batches (the facts
    /// schema of [`crate::arrow`]), windows in order, facts in source order.
    #[cfg(feature = "arrow")]
    pub fn facts_table(
        &self,
        window: Option<&str>,
    ) -> Result<Vec<crate::arrow::RecordBatch>, SessionError> {
        self.check_window(window)?;
        let mut out = Vec::new();
        let mut b = crate::arrow::FactsBuilder::new();
        for w in self
            .inputs
            .iter()
            .filter(|w| window.is_none_or(|id| w.id == id))
        {
            b.push_window(&self.label, place(w), w.facts.iter());
            if b.is_full() {
                out.push(b.finish()?);
            }
        }
        if out.is_empty() || !b.is_empty() {
            out.push(b.finish()?);
        }
        Ok(out)
    }

    /// Answers every question (or query) on every window, as Arrow record
    /// batches (the answers schema of [`crate::arrow`]): window by window,
    /// each window's answers in the order of `texts` — the order of an
    /// `ask --queries` file that lists each window's queries in turn, an
    /// answer's `query_index` being its text's position. Proofs fill the
    /// `proofs` column when `opts` asks for them. Every text is prepared
    /// first, so a question that cannot be translated fails before any
    /// reasoning.
    #[cfg(feature = "arrow")]
    pub fn answer_table(
        &self,
        texts: &[&str],
        opts: AskOptions,
    ) -> Result<Vec<crate::arrow::RecordBatch>, SessionError> {
        let prepared = texts
            .iter()
            .map(|t| self.prepare(t))
            .collect::<Result<Vec<Prepared>, _>>()?;
        let kbs = self.kbs()?;
        let with_proofs = opts.proofs && !opts.count_only;
        let by_window = crate::batch::answer_every_window(&self.engine, kbs, &prepared, opts);
        let mut out = Vec::new();
        let mut b = crate::arrow::AnswersBuilder::new(with_proofs);
        for results in &by_window {
            for (i, (r, p)) in results.iter().zip(&prepared).enumerate() {
                let proofs = if with_proofs {
                    Some(crate::arrow::proofs_json(r)?)
                } else {
                    None
                };
                b.push(&self.label, p.question.as_deref(), i, r, proofs.as_deref());
                if b.is_full() {
                    out.push(b.finish()?);
                }
            }
        }
        if out.is_empty() || !b.is_empty() {
            out.push(b.finish()?);
        }
        Ok(out)
    }
}

/// Where a window lies in its source, for the tables.
#[cfg(feature = "arrow")]
fn place(w: &WindowInput) -> crate::json::WindowPlace<'_> {
    crate::json::WindowPlace {
        id: &w.id,
        index: w.index,
        first_frame: w.first_frame,
        last_frame: w.last_frame,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::engine::TranslatorMode;
    use crate::kb::Observability;
    use logicpad::LogicPad;
    use std::sync::atomic::{AtomicUsize, Ordering};

    fn engine() -> Engine {
        Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine")
    }

    fn braking() -> Pipeline {
        Pipeline::open(
            &engine(),
            "sim:braking",
            &SourceOptions::default(),
            &mut |_| {},
        )
        .expect("opens")
    }

    /// A translator that turns every question into one query and counts
    /// the questions it was given.
    #[derive(Debug, Default)]
    struct Fixed {
        asked: AtomicUsize,
    }

    impl Translate for Fixed {
        fn mode(&self) -> TranslatorMode {
            TranslatorMode::Llm
        }
        fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
            self.asked.fetch_add(1, Ordering::SeqCst);
            let mut p = engine.prepare_query("Moving(x)");
            p.question = Some(question.to_string());
            Ok(p)
        }
        fn translate_offline(&self, _: &Engine, _: &str) -> Option<Result<Prepared, PrepareError>> {
            None
        }
    }

    #[test]
    fn an_opened_source_answers_window_by_window() {
        let src = braking();
        assert_eq!(src.label(), "sim:braking");
        let n = src.windows().len();
        assert!(n > 1);
        assert_eq!(src.window_count(), n);

        // A wrong window id fails before anything is reasoned.
        let err = src
            .ask_json("Moving(x)", Some("nope"), AskOptions::default())
            .expect_err("unknown window");
        assert!(matches!(err, SessionError::UnknownWindow(_)), "{err}");
        assert!(
            err.to_string()
                .starts_with("sim:braking has no window `nope` (it has braking_000000, ")
        );
        assert!(src.reasoned_windows().is_none());

        let all = src
            .ask_json("Is a car slowing down?", None, AskOptions::default())
            .expect("asks");
        assert_eq!(all["results"].as_array().map(Vec::len), Some(n));
        assert_eq!(all["summary"]["question"], "Is a car slowing down?");
        assert_eq!(src.reasoned_windows().map(<[_]>::len), Some(n));
        let first = src.windows()[0].id.clone();
        let one = src
            .ask_json("Moving(x)", Some(&first), AskOptions::default())
            .expect("asks");
        assert_eq!(one["results"][0]["window"], first.as_str());
        let ctx = src.context_json("Moving(x)", &first).expect("context");
        assert!(ctx.is_object());

        let err = src
            .ask_json("Is the zorblax frobnicating?", None, AskOptions::default())
            .expect_err("untranslatable");
        assert!(
            err.to_string()
                .starts_with("cannot translate the question: "),
            "{err}"
        );
    }

    #[test]
    fn an_unknown_window_is_said_the_same_way_by_every_method() {
        let src = braking();
        let want = src.no_window("nope").to_string();
        assert!(
            want.starts_with("sim:braking has no window `nope`"),
            "{want}"
        );
        let p = src.prepare("Moving(x)").expect("a query");
        let said = |e: SessionError| {
            assert!(matches!(e, SessionError::UnknownWindow(_)), "{e}");
            crate::session::message(&e)
        };
        let opts = AskOptions::default();
        let page = Page {
            offset: 0,
            limit: 1,
        };
        let mut messages = vec![
            said(src.ask(&p, Some("nope"), opts).expect_err("ask")),
            said(
                src.ask_page(&p, Some("nope"), opts, page)
                    .expect_err("page"),
            ),
            said(src.contexts(&p, Some("nope")).expect_err("contexts")),
            said(src.select(Some("nope")).expect_err("select")),
            said(src.window("nope").expect_err("window")),
            said(src.position("nope").expect_err("position")),
            said(
                src.ask_json("Moving(x)", Some("nope"), opts)
                    .expect_err("ask_json"),
            ),
            said(src.context_json("Moving(x)", "nope").expect_err("context")),
        ];
        #[cfg(feature = "serve")]
        messages.push(said(
            src.retrieve(
                &p,
                Some("nope"),
                opts,
                page,
                crate::serve::retrieve::Limits {
                    windows: 1,
                    facts: 1,
                },
            )
            .expect_err("retrieve"),
        ));
        #[cfg(feature = "arrow")]
        messages.push(said(src.facts_table(Some("nope")).expect_err("facts")));
        assert!(
            src.reasoned_windows().is_none(),
            "no reasoning for a wrong id"
        );
        // Reasoned or not, narrowed or not, the same sentence.
        src.kbs().expect("reasons");
        messages.push(said(src.window("nope").expect_err("reasoned")));
        messages.push(said(braking().only(Some("nope")).expect_err("only")));
        for m in &messages {
            assert_eq!(m, &want);
        }
    }

    #[test]
    fn questions_go_through_the_pipelines_translator_and_queries_do_not() {
        let fixed = Arc::new(Fixed::default());
        let src = braking().with_translator(Arc::clone(&fixed) as Arc<dyn Translate>);
        assert_eq!(src.translator().mode(), TranslatorMode::Llm);
        let p = src.prepare("Is anything on the move?").expect("translated");
        assert_eq!(p.query, "Moving(x)");
        assert_eq!(fixed.asked.load(Ordering::SeqCst), 1);
        let answers = src.ask(&p, None, AskOptions::BINDINGS).expect("answers");
        assert_eq!(answers.len(), src.window_count());
        // A query is taken as written, and needs no server.
        let q = src.prepare("Stopped(x)").expect("a query");
        assert_eq!(q.query, "Stopped(x)");
        assert!(src.prepare_offline("Stopped(x)").is_some());
        // A question only the server can translate is not guessed offline.
        assert!(src.prepare_offline("Is anything on the move?").is_none());
        assert_eq!(fixed.asked.load(Ordering::SeqCst), 1);
        let json = src
            .ask_json("Anything moving?", None, AskOptions::BINDINGS)
            .expect("asks");
        assert_eq!(json["summary"]["query"], "Moving(x)");
        assert_eq!(fixed.asked.load(Ordering::SeqCst), 2);
        // The grammar answers offline, its refusal included.
        let grammar = braking();
        assert!(matches!(
            grammar.prepare_offline("Is the zorblax frobnicating?"),
            Some(Err(PrepareError::Grammar(_)))
        ));
    }

    #[test]
    fn a_temporal_query_is_answered_once_over_the_windows_up_to_the_one_asked() {
        let src = braking();
        let q = "(Decelerate(x)) THEN (Stopped(x))";
        let all = src.ask_json(q, None, AskOptions::default()).expect("asks");
        let results = all["results"].as_array().cloned().unwrap_or_default();
        assert_eq!(results.len(), 1, "{all}");
        assert_eq!(results[0]["window"], "sim:braking");
        assert_eq!(results[0]["temporal"]["form"], "then");
        assert_eq!(all["summary"]["summary"]["answer"], "yes");
        let headline = all["summary"]["headline"].as_str().unwrap_or_default();
        assert!(
            headline.contains(", then `Stopped(x)` in frames "),
            "{headline}"
        );
        // Every asking method gives that one answer, on the last window.
        let p = src.prepare(q).expect("a query");
        let last = src.windows().last().map(|w| w.id.clone());
        for answers in [
            src.ask(&p, None, AskOptions::BINDINGS).expect("ask"),
            src.ask_page(
                &p,
                None,
                AskOptions::BINDINGS,
                Page {
                    offset: 0,
                    limit: 1,
                },
            )
            .expect("page"),
        ] {
            assert_eq!(answers.len(), 1);
            assert_eq!(Some(answers[0].window.id.clone()), last);
            assert_eq!(answers[0].result.answer, crate::ask::Outcome::Yes);
        }
        assert_eq!(src.contexts(&p, None).expect("contexts").len(), 1);
        // Asked at the first window, only its frames are looked at: the
        // stop is in its future.
        let first = src.windows()[0].id.clone();
        let early = src
            .ask_temporal(&p, Some(&first), AskOptions::BINDINGS)
            .expect("asks")
            .expect("temporal");
        assert_eq!((early.windows, early.result.last_frame), (1, 9));
        assert_ne!(early.result.answer, crate::ask::Outcome::Yes);
        // A query that is not temporal is not answered here.
        let plain = src.prepare("Moving(x)").expect("a query");
        assert!(
            src.ask_temporal(&plain, None, AskOptions::BINDINGS)
                .expect("asks")
                .is_none()
        );
        let err = src
            .ask_temporal(&p, Some("nope"), AskOptions::BINDINGS)
            .expect_err("unknown window");
        assert!(matches!(err, SessionError::UnknownWindow(_)), "{err}");
    }

    #[test]
    fn a_narrowed_pipeline_reasons_its_window_only() {
        let src = braking();
        let second = src.windows()[1].id.clone();
        let one = src.only(Some(&second)).expect("narrowed");
        assert_eq!(one.window_count(), 1);
        let p = one.prepare("Moving(x)").expect("query");
        let answers = one.ask(&p, None, AskOptions::BINDINGS).expect("answers");
        assert_eq!(answers.len(), 1);
        assert_eq!(answers[0].window.id, second);
        assert_eq!(answers[0].result.window, second);
        // Reasoned up front, a pipeline keeps its KBs only.
        let kept = braking().into_reasoned(&|| {}).expect("reasons");
        assert!(kept.windows().is_empty());
        assert!(kept.window_count() > 1);
        assert!(kept.select(None).expect("all").len() > 1);
    }

    #[cfg(feature = "arrow")]
    #[test]
    fn answer_tables_go_window_by_window_in_question_order() {
        use crate::arrow::arrow_array::Array;
        use crate::arrow::arrow_array::cast::AsArray;
        use crate::arrow::arrow_array::types::Int64Type;
        let src = braking();
        let texts = ["Moving(x)", "Is a car slowing down?", "Levitates(x)"];
        let batches = src
            .answer_table(&texts, AskOptions::BINDINGS)
            .expect("answers");
        assert_eq!(batches.len(), 1);
        let b = &batches[0];
        assert_eq!(b.num_rows(), texts.len() * src.windows().len());
        let window = b.column(1).as_string::<i32>();
        let question = b.column(4).as_string::<i32>();
        let index = b.column(6).as_primitive::<Int64Type>();
        for (row, (w, i)) in src
            .windows()
            .iter()
            .flat_map(|w| (0..texts.len()).map(move |i| (w, i)))
            .enumerate()
        {
            assert_eq!(window.value(row), w.id);
            assert_eq!(index.value(row), i64::try_from(i).expect("small"));
            assert_eq!(question.is_valid(row), i == 1);
        }
        assert!(b.column(12).is_null(0), "no proofs asked for");
        let err = src
            .answer_table(&["Moving(x)", "Is the zorblax here?"], AskOptions::BINDINGS)
            .expect_err("untranslatable");
        assert!(matches!(err, SessionError::Prepare(_)));
        let facts = src.facts_table(None).expect("facts");
        let total: usize = src.windows().iter().map(|w| w.facts.len()).sum();
        assert_eq!(facts.iter().map(|b| b.num_rows()).sum::<usize>(), total);
    }
}
