//! A source opened for asking, the same way from every front end: what the
//! command line's source flags mean ([`SourceOptions`]), reading a LogicPad
//! ([`load_pad`]), picking windows ([`select_windows`]), preparing a
//! question ([`prepare`]) — and [`Opened`], a loaded source with its
//! engine that answers in the objects `ask --json`, `facts --json` and
//! `context --json` print, and (with the `arrow` feature) in Arrow tables.
//!
//! Why here and not in the binary: the Python package (`logicrag-py`)
//! must give the same answers, the same JSON and the same error messages
//! as the CLI; with one implementation in the library neither can drift.

use crate::ask::{AskOptions, AskResult};
use crate::engine::{Engine, EngineError, Prepared};
use crate::kb::{KbError, WindowInput, WindowKb};
use crate::source::{LoadOptions, Loaded, Progress, SourceError, SourceSpec};
use crate::translate::TranslateError;
use logicpad::LogicPad;
/// The simulator's noise levels (`--noise`), for front ends that read one.
pub use perception::sim::NoisePreset;
use perception::{FactConfig, PerceptionError, WindowSpec};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// Errors of opening a source and asking it, each worded as the command
/// line reports it (the CLI prints `error: ` and this message).
#[derive(Debug, thiserror::Error)]
pub enum SessionError {
    /// Occurs when the source string is not understood, or the source
    /// cannot be loaded (a missing file, a malformed label file).
    #[error(transparent)]
    Source(#[from] SourceError),
    /// Occurs when the `--config` file or the `--frames` range is not valid.
    #[error(transparent)]
    Perception(#[from] PerceptionError),
    /// Occurs when a source option is out of range or does not apply to
    /// the source's kind (`--window 0`, `--frames` on a `facts:` source).
    #[error("{0}")]
    Option(String),
    /// Occurs when the LogicPad file cannot be read or is not YAML.
    #[error(transparent)]
    LogicPad(#[from] logicpad::LoadError),
    /// Occurs when the LogicPad's vocabulary cannot drive the translator.
    #[error(transparent)]
    Engine(#[from] EngineError),
    /// Occurs when a window id is not one of the source's.
    #[error(transparent)]
    UnknownWindow(#[from] crate::kb::NoWindow),
    /// Occurs when the grammar cannot read an English question.
    #[error("cannot translate the question: {0}")]
    Translate(#[source] TranslateError),
    /// Occurs when a window's facts cannot be stored in its KB.
    #[error(transparent)]
    Kb(#[from] KbError),
    /// Occurs when an answer cannot be rendered as JSON.
    #[error("rendering JSON: {0}")]
    Json(#[from] serde_json::Error),
    /// Occurs when an Arrow table cannot be built.
    #[cfg(feature = "arrow")]
    #[error(transparent)]
    Table(#[from] crate::arrow::TableError),
}

impl SessionError {
    /// True when the error comes from reading a file (the OS said no):
    /// the Python package raises `OSError` for these, `ValueError` for
    /// the rest.
    pub fn is_io(&self) -> bool {
        io_cause(self)
    }
}

/// True when `e` or one of its causes is an I/O error.
pub(crate) fn io_cause(e: &(dyn std::error::Error + 'static)) -> bool {
    let mut next = Some(e);
    while let Some(err) = next {
        if err.is::<std::io::Error>() {
            return true;
        }
        next = err.source();
    }
    false
}

/// An error and its causes on one line, each cause once: our errors
/// already end their message with their cause (`{path}: {source}`), so
/// printing every cause again would say "No such file … : No such file …".
/// The CLI prints this after `error: `; the Python package raises it.
pub fn message(e: &(dyn std::error::Error + 'static)) -> String {
    let mut text = e.to_string();
    let mut next = e.source();
    while let Some(cause) = next {
        let c = cause.to_string();
        // Only a whole trailing cause (`…: cause`) counts as already said.
        if text != c && !text.ends_with(&format!(": {c}")) {
            text.push_str(": ");
            text.push_str(&c);
        }
        next = cause.source();
    }
    text
}

/// A source's options, as the command line's flags give them (`--sequence`,
/// `--window`, …); `None` is a flag not given.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct SourceOptions {
    /// KITTI (or multi-sequence JSON) sequence, e.g. `0000`.
    pub sequence: Option<String>,
    /// Frames per window (default: 10, the paper's).
    pub window: Option<u32>,
    /// Frames between window starts (default: the window size).
    pub stride: Option<u32>,
    /// One inclusive frame range instead of sliding windows, e.g. `0-9`.
    pub frames: Option<String>,
    /// Perception thresholds (YAML or JSON `FactConfig`).
    pub config: Option<PathBuf>,
    /// Model set YAML for `frames:DIR` sources.
    pub models: Option<PathBuf>,
    /// Camera calibration for `frames:DIR` sources.
    pub camera: Option<PathBuf>,
    /// Frame rate of `frames:DIR` frames, per second.
    pub fps: Option<f64>,
    /// Simulator noise level replacing a `sim:` scenario's own (`--noise`).
    pub noise: Option<NoisePreset>,
}

impl SourceOptions {
    /// The source with the options of its kind; an option its kind would
    /// ignore is an error naming the flag, never silently dropped.
    pub fn spec(&self, source: SourceSpec) -> Result<SourceSpec, SessionError> {
        if let Some(level) = self.noise
            && !matches!(source, SourceSpec::Sim { .. })
        {
            return Err(SessionError::Option(format!(
                "--noise {level} applies to simulator sources (sim:SCENARIO[@SEED]), not {source}"
            )));
        }
        let spec = source
            .with_sequence(self.sequence.clone())?
            .with_frames_options(self.models.clone(), self.camera.clone(), self.fps)?;
        // A facts source's windows are its files: frame ranges and window
        // sizes have nothing to cut.
        if matches!(spec, SourceSpec::Facts { .. }) {
            for (flag, given) in [
                ("--frames", self.frames.is_some()),
                ("--window", self.window.is_some()),
                ("--stride", self.stride.is_some()),
                ("--config", self.config.is_some()),
            ] {
                if given {
                    return Err(SessionError::Option(format!(
                        "{flag} does not apply to facts:PATH sources (each file is one window)"
                    )));
                }
            }
        }
        Ok(spec)
    }

    /// How the source's frames are cut into windows, and the thresholds.
    pub fn load_options(&self) -> Result<LoadOptions, SessionError> {
        // The CLI's parser refuses the pair before this; other callers
        // (Python keywords) reach it.
        if self.frames.is_some() && (self.window.is_some() || self.stride.is_some()) {
            return Err(SessionError::Option(
                "--frames (one range) does not combine with --window or --stride (sliding windows)"
                    .into(),
            ));
        }
        let config = match &self.config {
            None => FactConfig::default(),
            Some(p) => FactConfig::load(p)?,
        };
        let frames = match &self.frames {
            Some(f) => Some(perception::source::parse_frame_range(f)?),
            None => None,
        };
        let size = self.window.unwrap_or(WindowSpec::PAPER.size);
        if size == 0 {
            return Err(SessionError::Option(
                "--window must be at least 1 frame".into(),
            ));
        }
        let stride = self.stride.unwrap_or(size);
        if stride == 0 {
            return Err(SessionError::Option(
                "--stride must be at least 1 frame".into(),
            ));
        }
        Ok(LoadOptions {
            windows: WindowSpec { size, stride },
            frames,
            config,
            noise: self.noise,
        })
    }

    /// Loads the source these options qualify: `progress` sees every frame
    /// of a `frames:` run.
    pub fn load(
        &self,
        source: SourceSpec,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Loaded, SessionError> {
        let spec = self.spec(source)?;
        let opts = self.load_options()?;
        Ok(crate::source::load(&spec, &opts, progress)?)
    }
}

/// What to tell the user about a loaded source's accuracy: a `frames:`
/// source without `--camera` has only roughly metric 3D positions.
pub fn camera_note(spec: &SourceSpec) -> Option<String> {
    matches!(spec, SourceSpec::Frames { camera: None, .. }).then(|| {
        format!(
            "no --camera calibration; assumed fx = fy = image width, principal point \
             at the centre and a camera {} m above the road, so 3D positions are only roughly metric",
            perception::raw::frames::DEFAULT_CAMERA_HEIGHT_M
        )
    })
}

/// Reads a LogicPad (the built-in one without a path). Rules with errors
/// are left out of a pad that loads; [`pad_warning`] says so.
pub fn load_pad(path: Option<&Path>) -> Result<LogicPad, SessionError> {
    match path {
        None => Ok(LogicPad::builtin()),
        Some(p) => Ok(LogicPad::load(p)?),
    }
}

/// The warning for a LogicPad read from `path` some of whose rules had to
/// be left out, or `None` when every rule loaded.
pub fn pad_warning(pad: &LogicPad, path: &Path) -> Option<String> {
    let errors = pad.diagnostics().iter().filter(|d| d.is_error()).count();
    (errors > 0).then(|| {
        format!(
            "{} has {errors} error(s); the rules concerned are left out (see `logicrag lint {}`)",
            path.display(),
            path.display()
        )
    })
}

fn unknown_window<'a>(label: &str, id: &str, ids: impl Iterator<Item = &'a str>) -> SessionError {
    SessionError::UnknownWindow(crate::kb::NoWindow::new(label, id, ids))
}

/// The windows to ask about: all of them, or the one named `id` (an id
/// the source does not have is an error, not silence).
pub fn select_windows(
    label: &str,
    windows: Vec<WindowInput>,
    id: Option<&str>,
) -> Result<Vec<WindowInput>, SessionError> {
    let Some(id) = id else {
        return Ok(windows);
    };
    if !windows.iter().any(|w| w.id == id) {
        return Err(unknown_window(
            label,
            id,
            windows.iter().map(|w| w.id.as_str()),
        ));
    }
    Ok(windows.into_iter().filter(|w| w.id == id).collect())
}

/// Prepares a question with the built-in grammar (a query is taken as
/// written); a question the grammar cannot read is an error.
pub fn prepare(engine: &Engine, text: &str) -> Result<Prepared, SessionError> {
    engine.prepare(text).map_err(SessionError::Translate)
}

/// The answer options of `ask`'s flags: `base` (all, bindings only, or
/// counts) with `--max-answers` (at least 1) and `--proof-depth` (capped
/// at [`logicpad::ProofLimits::MAX_DEPTH_CEILING`]).
pub fn ask_options(
    base: AskOptions,
    max_answers: usize,
    proof_depth: usize,
) -> Result<AskOptions, SessionError> {
    if max_answers == 0 {
        return Err(SessionError::Option(
            "--max-answers must be at least 1".into(),
        ));
    }
    Ok(AskOptions {
        max_answers,
        proof_depth: proof_depth.min(logicpad::ProofLimits::MAX_DEPTH_CEILING),
        ..base
    })
}

/// A loaded source with its engine, ready to be asked: what the Python
/// package's `Source` wraps.
///
/// Invariant: `engine` has the LogicPad and translator of the engine that
/// opened the source, with this source's observability; `kbs`, once
/// built, holds one reasoned KB per window of `windows`, in the same order.
#[derive(Debug)]
pub struct Opened {
    label: String,
    engine: Engine,
    windows: Vec<WindowInput>,
    notes: Vec<String>,
    /// Built on the first question: a caller who only reads facts never
    /// pays for reasoning.
    kbs: Mutex<Option<Arc<Vec<WindowKb>>>>,
}

impl Opened {
    /// Opens `source` (any `--source` string) with `options`, for
    /// `engine`'s LogicPad.
    pub fn open(
        engine: &Engine,
        source: &str,
        options: &SourceOptions,
        progress: &mut dyn FnMut(Progress),
    ) -> Result<Opened, SessionError> {
        let spec: SourceSpec = source.parse()?;
        let notes = camera_note(&spec).into_iter().collect();
        let loaded = options.load(spec, progress)?;
        Ok(Opened {
            label: loaded.label,
            engine: engine.for_source(loaded.observability),
            windows: loaded.windows,
            notes,
            kbs: Mutex::new(None),
        })
    }

    /// The source's label (`sim:urban_crossing`, `kitti:0000`): the
    /// `video` column of its tables.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// What the user should know about the source (as the CLI's `note:`
    /// lines on stderr).
    pub fn notes(&self) -> &[String] {
        &self.notes
    }

    /// The engine, for this source's observability.
    pub fn engine(&self) -> &Engine {
        &self.engine
    }

    /// The windows' inputs, in order.
    pub fn windows(&self) -> &[WindowInput] {
        &self.windows
    }

    /// The windows named `id`, or all of them.
    fn window_inputs(&self, id: Option<&str>) -> Result<Vec<&WindowInput>, SessionError> {
        let found: Vec<&WindowInput> = self
            .windows
            .iter()
            .filter(|w| id.is_none_or(|id| w.id == id))
            .collect();
        match id {
            Some(id) if found.is_empty() => Err(unknown_window(
                &self.label,
                id,
                self.windows.iter().map(|w| w.id.as_str()),
            )),
            _ => Ok(found),
        }
    }

    /// Every window reasoned (once; later calls share the result).
    pub fn kbs(&self) -> Result<Arc<Vec<WindowKb>>, SessionError> {
        // A poisoned lock only means another thread panicked while
        // building; its state is still `None` or a finished build.
        let mut slot = self
            .kbs
            .lock()
            .unwrap_or_else(std::sync::PoisonError::into_inner);
        if let Some(kbs) = slot.as_ref() {
            return Ok(Arc::clone(kbs));
        }
        let kbs = Arc::new(self.engine.build_all(self.windows.clone(), &|| {})?);
        *slot = Some(Arc::clone(&kbs));
        Ok(kbs)
    }

    /// Every window reasoned, after checking that `id` (when given) names
    /// one of them, so that a wrong id costs no reasoning.
    fn kbs_for(&self, id: Option<&str>) -> Result<Arc<Vec<WindowKb>>, SessionError> {
        self.window_inputs(id)?;
        self.kbs()
    }

    /// Answers a question (or query) on one window or all:
    /// `{"results": [...], "summary": {...}}`, the objects `ask --json`
    /// prints (as `serve`'s `/api/ask` answers).
    pub fn ask(
        &self,
        text: &str,
        window: Option<&str>,
        opts: AskOptions,
    ) -> Result<Value, SessionError> {
        let p = prepare(&self.engine, text)?;
        let results: Vec<AskResult> = self
            .kbs_for(window)?
            .iter()
            .filter(|kb| window.is_none_or(|id| kb.id == id))
            .map(|kb| self.engine.ask(kb, &p, opts))
            .collect();
        Ok(crate::json::ask_object(self.engine.words(), &p, &results)?)
    }

    /// The retrieval context of a question on one window, as
    /// `context --json` prints it.
    pub fn context(&self, text: &str, window: &str) -> Result<Value, SessionError> {
        let p = prepare(&self.engine, text)?;
        let kbs = self.kbs_for(Some(window))?;
        let mut contexts = kbs.iter().filter(|kb| kb.id == window).map(|kb| {
            let r = self.engine.ask(kb, &p, AskOptions::default());
            serde_json::to_value(self.engine.context(kb, &p, &r))
        });
        match contexts.next() {
            Some(ctx) => Ok(ctx?),
            None => Err(unknown_window(
                &self.label,
                window,
                self.windows.iter().map(|w| w.id.as_str()),
            )),
        }
    }

    /// The facts of one window or all as Arrow record batches (the facts
    /// schema of [`crate::arrow`]), windows in order, facts in source order.
    #[cfg(feature = "arrow")]
    pub fn facts_table(
        &self,
        window: Option<&str>,
    ) -> Result<Vec<crate::arrow::RecordBatch>, SessionError> {
        let mut out = Vec::new();
        let mut b = crate::arrow::FactsBuilder::new();
        for w in self.window_inputs(window)? {
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
    /// first, so a question the grammar cannot read fails before any
    /// reasoning.
    #[cfg(feature = "arrow")]
    pub fn answer_table(
        &self,
        texts: &[&str],
        opts: AskOptions,
    ) -> Result<Vec<crate::arrow::RecordBatch>, SessionError> {
        let prepared = texts
            .iter()
            .map(|t| prepare(&self.engine, t))
            .collect::<Result<Vec<Prepared>, _>>()?;
        let kbs = self.kbs()?;
        let with_proofs = opts.proofs && !opts.count_only;
        let by_window = crate::batch::answer_every_window(&self.engine, &kbs, &prepared, opts);
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
    use crate::kb::Observability;

    fn engine() -> Engine {
        Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine")
    }

    #[test]
    fn options_another_kind_would_ignore_are_refused_with_the_flag() {
        let facts: SourceSpec = "facts:/nowhere".parse().expect("spec");
        let framed = SourceOptions {
            frames: Some("0-9".into()),
            ..SourceOptions::default()
        };
        let err = framed.spec(facts).expect_err("refused");
        assert_eq!(
            err.to_string(),
            "--frames does not apply to facts:PATH sources (each file is one window)"
        );
        let sim: SourceSpec = "sim:braking".parse().expect("spec");
        let seq = SourceOptions {
            sequence: Some("0000".into()),
            ..SourceOptions::default()
        };
        assert!(
            seq.spec(sim)
                .expect_err("refused")
                .to_string()
                .contains("--sequence")
        );
        for (opts, says) in [
            (
                SourceOptions {
                    window: Some(0),
                    ..SourceOptions::default()
                },
                "--window must be at least 1 frame",
            ),
            (
                SourceOptions {
                    stride: Some(0),
                    ..SourceOptions::default()
                },
                "--stride must be at least 1 frame",
            ),
            (
                SourceOptions {
                    frames: Some("0-9".into()),
                    window: Some(5),
                    ..SourceOptions::default()
                },
                "--frames (one range) does not combine",
            ),
        ] {
            let err = opts.load_options().expect_err("refused");
            assert!(err.to_string().starts_with(says), "{err}");
        }
        assert!(ask_options(AskOptions::default(), 0, 3).is_err());
        let capped = ask_options(AskOptions::BINDINGS, 7, usize::MAX).expect("fine");
        assert_eq!(capped.max_answers, 7);
        assert!(!capped.proofs);
        assert_eq!(capped.proof_depth, logicpad::ProofLimits::MAX_DEPTH_CEILING);
    }

    #[test]
    fn a_missing_file_is_an_io_error_said_once() {
        let err = load_pad(Some(Path::new("/nonexistent/pad.yaml"))).expect_err("missing");
        assert!(err.is_io());
        let text = message(&err);
        assert!(
            text.starts_with("cannot read LogicPad file `/nonexistent/pad.yaml`: "),
            "{text}"
        );
        assert_eq!(text.matches("No such file").count(), 1, "{text}");
        let bad: Result<SourceSpec, _> = "nope:x".parse();
        let err = SessionError::from(bad.expect_err("unknown kind"));
        assert!(!err.is_io());
        assert!(message(&err).contains("unknown source kind `nope`"));
    }

    #[test]
    fn an_opened_source_answers_window_by_window() {
        let e = engine();
        let src =
            Opened::open(&e, "sim:braking", &SourceOptions::default(), &mut |_| {}).expect("opens");
        assert_eq!(src.label(), "sim:braking");
        let n = src.windows().len();
        assert!(n > 1);

        // A wrong window id fails before anything is reasoned.
        let err = src
            .ask("Moving(x)", Some("nope"), AskOptions::default())
            .expect_err("unknown window");
        assert!(matches!(err, SessionError::UnknownWindow(_)), "{err}");
        assert!(
            err.to_string()
                .starts_with("sim:braking has no window `nope` (it has braking_000000, ")
        );
        assert!(src.kbs.lock().expect("lock").is_none());

        let all = src
            .ask("Is a car slowing down?", None, AskOptions::default())
            .expect("asks");
        assert_eq!(all["results"].as_array().map(Vec::len), Some(n));
        assert_eq!(all["summary"]["question"], "Is a car slowing down?");
        let first = src.windows()[0].id.clone();
        let one = src
            .ask("Moving(x)", Some(&first), AskOptions::default())
            .expect("asks");
        assert_eq!(one["results"][0]["window"], first.as_str());
        let ctx = src.context("Moving(x)", &first).expect("context");
        assert!(ctx.is_object());

        let err = src
            .ask("Is the zorblax frobnicating?", None, AskOptions::default())
            .expect_err("untranslatable");
        assert!(
            err.to_string()
                .starts_with("cannot translate the question: "),
            "{err}"
        );
    }

    #[cfg(feature = "arrow")]
    #[test]
    fn answer_tables_go_window_by_window_in_question_order() {
        use crate::arrow::arrow_array::Array;
        use crate::arrow::arrow_array::cast::AsArray;
        use crate::arrow::arrow_array::types::Int64Type;
        let e = engine();
        let src =
            Opened::open(&e, "sim:braking", &SourceOptions::default(), &mut |_| {}).expect("opens");
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
        assert!(matches!(err, SessionError::Translate(_)));
        let facts = src.facts_table(None).expect("facts");
        let total: usize = src.windows().iter().map(|w| w.facts.len()).sum();
        assert_eq!(facts.iter().map(|b| b.num_rows()).sum::<usize>(), total);
        assert!(src.facts_table(Some("nope")).is_err());
    }
}
