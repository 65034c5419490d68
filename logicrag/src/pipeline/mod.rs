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
use crate::session::SessionError;
use crate::temporal::TemporalAnswer;
use std::sync::{Arc, Mutex, OnceLock};

mod open;
pub use open::{OpenOptions, PadChoice, SourceExtras};

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
    /// What of the source is kept besides its windows.
    extras: SourceExtras,
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
            extras: SourceExtras::default(),
        }
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
        p.extras.config = self.extras.config.clone();
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
        self.ask_each(p, window, opts, |kb| (self.engine.ask(kb, p, opts), None))
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
        self.ask_each(p, window, opts, |kb| {
            self.engine.ask_page(kb, p, opts, page)
        })
    }

    /// A temporal query's one answer, or `answer` of each window asked.
    fn ask_each(
        &self,
        p: &Prepared,
        window: Option<&str>,
        opts: AskOptions,
        answer: impl Fn(&WindowKb) -> (AskResult, Option<Truncation>),
    ) -> Result<Vec<Answer<'_>>, SessionError> {
        if let Some(a) = self.ask_temporal(p, window, opts)? {
            return self.as_answers(window, a.result);
        }
        Ok(self
            .select(window)?
            .into_iter()
            .map(|kb| {
                let (result, truncated) = answer(kb);
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

    /// The retrieval context of a question on one window, whose JSON
    /// `context --json` prints.
    pub fn context_of(&self, text: &str, window: &str) -> Result<RagContext, SessionError> {
        let p = self.prepare(text)?;
        match self.contexts(&p, Some(window))?.into_iter().next() {
            Some(ctx) => Ok(ctx),
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

    /// Every prepared question answered on every window, windows in
    /// parallel: one list per window, in source order, each in the order
    /// of `prepared`. The KBs are reasoned once and kept (a front end that
    /// holds a pipeline — Python's `Source`, `serve` — asks it again); a
    /// batch read once goes through `Pipeline::answer_each_in_order`,
    /// which drops each KB after its window.
    pub fn ask_every(
        &self,
        prepared: &[Prepared],
        opts: AskOptions,
    ) -> Result<Vec<Vec<AskResult>>, SessionError> {
        use rayon::prelude::*;
        let kbs = self.kbs()?;
        Ok(kbs
            .par_iter()
            .map(|kb| {
                prepared
                    .iter()
                    .map(|p| self.engine.ask(kb, p, opts))
                    .collect()
            })
            .collect())
    }
}

#[cfg(test)]
mod tests;
