//! `logicrag._native`: the Python classes `Engine` and `Source` over the
//! `logicrag` library crate. Thin on purpose: every answer, JSON object,
//! table and error message comes from the library (`logicrag::pipeline`,
//! `logicrag::session`, `logicrag::json`, `logicrag::arrow`), the code the
//! CLI runs, so Python and the command line cannot disagree. What is here: converting
//! arguments, releasing the GIL around the work, and turning results
//! into Python objects (dicts and lists built directly from the values
//! the CLI prints as JSON, tables through pyarrow's C data interface).
//!
//! Errors: an error whose cause is the OS refusing a file is `OSError`,
//! any other `ValueError`, both with the message the CLI prints after
//! `error: `. Nothing here panics on input.
#![forbid(unsafe_code)]

use arrow_pyarrow::{FromPyArrow, IntoPyArrow};
use logicrag::arrow::RecordBatch;
use logicrag::ask::AskOptions;
use logicrag::pipeline::{OpenOptions, PadChoice, Pipeline};
use logicrag::session::{self, SessionError, SourceOptions};
use logicrag::source::SourceSpec;
use pyo3::exceptions::{PyOSError, PyValueError};
use pyo3::prelude::*;
use std::path::PathBuf;
use std::sync::Arc;

/// The Python exception for a library error, with the CLI's message.
fn py_err(e: &SessionError) -> PyErr {
    let message = session::message(e);
    if e.is_io() {
        PyOSError::new_err(message)
    } else {
        PyValueError::new_err(message)
    }
}

/// The Python exception for an Arrow table's error: the pipeline's own
/// errors as [`py_err`] raises them, a file the OS refused as `OSError`,
/// the rest as `ValueError`.
fn table_err(e: &logicrag::arrow::TableError) -> PyErr {
    use logicrag::arrow::TableError;
    match e {
        TableError::Session(e) => py_err(e),
        TableError::Io { .. } => PyOSError::new_err(session::message(e)),
        _ => PyValueError::new_err(session::message(e)),
    }
}

mod topy;

/// A value the CLI prints as JSON, as Python objects built directly from
/// its typed serde form ([`topy`]) — the objects `json.loads` of the CLI's
/// output gives, without building a JSON value or text (that round trip
/// was half of `ask`'s time on a long video).
fn to_python<'py, T: serde::Serialize + ?Sized>(
    py: Python<'py>,
    value: &T,
) -> PyResult<Bound<'py, PyAny>> {
    topy::to_python(py, value)
}

/// Batches of one schema as a `pyarrow.Table`.
fn to_table(
    py: Python<'_>,
    batches: Vec<RecordBatch>,
    schema: logicrag::arrow::SchemaRef,
) -> PyResult<Bound<'_, PyAny>> {
    let table = arrow_pyarrow::Table::try_new(batches, schema)
        .map_err(|e| PyValueError::new_err(e.to_string()))?;
    table.into_pyarrow(py)
}

/// Issues a Python `UserWarning` (what the CLI says on stderr).
fn warn(py: Python<'_>, message: &str) -> PyResult<()> {
    py.import("warnings")?.call_method1("warn", (message,))?;
    Ok(())
}

/// A frame count option (`window`, `stride`) as the library takes it.
/// A negative count is passed on as 0, which the library refuses in the
/// CLI's words ("--window must be at least 1 frame").
fn frame_count(flag: &str, value: Option<i64>) -> PyResult<Option<u32>> {
    match value {
        None => Ok(None),
        Some(v) if v < 0 => Ok(Some(0)),
        Some(v) => u32::try_from(v).map(Some).map_err(|_| {
            PyValueError::new_err(format!("{flag} {v}: more frames than a source can hold"))
        }),
    }
}

/// The answer options of `ask`'s flags (`--no-proofs`, `--max-answers`,
/// `--proof-depth`), checked by the library.
fn ask_options(
    proofs: bool,
    max_answers: Option<usize>,
    proof_depth: Option<usize>,
) -> PyResult<AskOptions> {
    let base = if proofs {
        AskOptions::default()
    } else {
        AskOptions::BINDINGS
    };
    session::ask_options(
        base,
        max_answers.unwrap_or(base.limits.answers),
        proof_depth.unwrap_or(base.limits.proof_depth),
    )
    .map_err(|e| py_err(&e))
}

/// The LogicPad rules and the question translator built from them.
///
/// `Engine()` uses the built-in LogicPad; `Engine(logicpad="rules.yaml")`
/// reads one (as the CLI's `--logicpad`). A file that cannot be read
/// raises `OSError`, one that is not LogicPad YAML `ValueError`; a file
/// some of whose rules have errors loads without them, with a
/// `UserWarning` (see `logicrag lint FILE`).
///
/// An engine opens sources (`Engine.open`) and may be shared by threads.
#[pyclass(module = "logicrag", name = "Engine", frozen)]
struct Engine {
    /// The LogicPad read and built once ([`OpenOptions::prepared`]); each
    /// `open` adds its source options.
    options: OpenOptions,
    logicpad: Option<PathBuf>,
}

#[pymethods]
impl Engine {
    #[new]
    #[pyo3(signature = (logicpad = None))]
    fn new(py: Python<'_>, logicpad: Option<PathBuf>) -> PyResult<Engine> {
        let options = OpenOptions {
            logicpad: PadChoice::from_flag(logicpad.clone()),
            ..OpenOptions::default()
        };
        let (options, warning) = py.detach(|| options.prepared()).map_err(|e| py_err(&e))?;
        if let Some(w) = warning {
            warn(py, &w)?;
        }
        Ok(Engine { options, logicpad })
    }

    /// Opens a source: any `--source` string of the CLI (`sim:NAME[@SEED]`,
    /// `kitti:DIR`, `json:FILE`, `av2:DIR`, `facts:PATH`, `frames:DIR`) with the
    /// CLI's source options as keywords — `sequence="0000"`, `window=10`,
    /// `stride=5`, `frames="0-9"`, `config=PATH`, `models=PATH`,
    /// `camera=PATH`, `fps=10.0`, `noise="high"` (a simulator source's noise
    /// level: none, low, default, high, mono, or one with its sigmas scaled
    /// as `"high*2"`). Perceives and cuts the windows now (without the
    /// GIL); reasoning waits for the first question.
    ///
    /// Raises `ValueError` for a source or option the CLI refuses (with
    /// its message), `OSError` for a file that cannot be read.
    #[pyo3(signature = (source, *, sequence = None, window = None, stride = None, frames = None, config = None, models = None, camera = None, fps = None, noise = None))]
    #[allow(clippy::too_many_arguments)]
    fn open(
        &self,
        py: Python<'_>,
        source: &str,
        sequence: Option<String>,
        window: Option<i64>,
        stride: Option<i64>,
        frames: Option<String>,
        config: Option<PathBuf>,
        models: Option<PathBuf>,
        camera: Option<PathBuf>,
        fps: Option<f64>,
        noise: Option<String>,
    ) -> PyResult<Source> {
        let noise = noise
            .map(|n| n.parse::<session::NoiseLevel>())
            .transpose()
            .map_err(|e| PyValueError::new_err(format!("noise: {e}")))?;
        let options = OpenOptions {
            source: SourceOptions {
                sequence,
                window: frame_count("--window", window)?,
                stride: frame_count("--stride", stride)?,
                frames,
                config,
                models,
                camera,
                fps,
                noise,
            },
            ..self.options.clone()
        };
        let opened = py
            .detach(|| {
                let spec: SourceSpec = source.parse().map_err(SessionError::Source)?;
                Pipeline::open(spec, &options, &mut |_| {})
            })
            .map_err(|e| py_err(&e))?;
        for note in opened.notes() {
            warn(py, note)?;
        }
        Ok(Source {
            inner: Arc::new(opened),
        })
    }

    /// Opens a tracks table: any dataset's object tracks (nuScenes,
    /// Waymo, Argoverse 2, a tracker's output) as a `pyarrow.Table` (or a
    /// pandas or polars frame, anything with `__arrow_c_stream__`) in the
    /// tracks schema of docs/formats.md — one row per object and frame:
    /// `frame` or `timestamp_ns`, `track_id` (integer or string),
    /// `category`, the box centre `x`, `y`, `z` in the ego frame (x
    /// forward, y left, z up), `length`, `width`, `height`, `yaw`, and
    /// optionally `color` and `score`. `poses` is a table of the ego's
    /// world pose (`frame` or `timestamp_ns`, `x`, `y`, optional `z`,
    /// `yaw`); `map` the path of a map file (an Argoverse 2
    /// `log_map_archive_*.json` or a logicrag map JSON), which needs the
    /// poses. `name` names the source (`tracks:NAME`, the window ids);
    /// `window`, `stride`, `frames` and `config` are `open`'s.
    ///
    /// Returns the same kind of source as `open`. Raises `ValueError`
    /// naming the column and row of a bad value, `OSError` for a map file
    /// that cannot be read.
    #[pyo3(signature = (table, *, map = None, poses = None, name = "tracks", window = None, stride = None, frames = None, config = None))]
    #[allow(clippy::too_many_arguments)]
    fn open_tracks(
        &self,
        py: Python<'_>,
        table: &Bound<'_, PyAny>,
        map: Option<PathBuf>,
        poses: Option<&Bound<'_, PyAny>>,
        name: &str,
        window: Option<i64>,
        stride: Option<i64>,
        frames: Option<String>,
        config: Option<PathBuf>,
    ) -> PyResult<Source> {
        let batches = |t: &Bound<'_, PyAny>, what: &str| -> PyResult<Vec<RecordBatch>> {
            arrow_pyarrow::Table::from_pyarrow_bound(t)
                .map(|t| t.into_inner().0)
                .map_err(|e| {
                    PyValueError::new_err(format!(
                        "{what}: expected a pyarrow.Table (or anything with __arrow_c_stream__): {e}"
                    ))
                })
        };
        let tracks = batches(table, "table")?;
        let poses = poses.map(|p| batches(p, "poses")).transpose()?;
        let options = OpenOptions {
            source: SourceOptions {
                window: frame_count("--window", window)?,
                stride: frame_count("--stride", stride)?,
                frames,
                config,
                ..SourceOptions::default()
            },
            ..self.options.clone()
        };
        let opened = py
            .detach(|| -> Result<Pipeline, SessionError> {
                let map = map.as_deref().map(logicrag::arrow::read_map).transpose()?;
                let seq =
                    logicrag::arrow::tracks_from_batches(name, &tracks, poses.as_deref(), map)
                        .map_err(|e| match e {
                            logicrag::arrow::TracksError::Perception(p) => {
                                SessionError::Perception(p)
                            }
                            other => SessionError::Option(other.to_string()),
                        })?;
                Pipeline::open_sequence(seq, &options)
            })
            .map_err(|e| py_err(&e))?;
        for note in opened.notes() {
            warn(py, note)?;
        }
        Ok(Source {
            inner: Arc::new(opened),
        })
    }

    fn __repr__(&self) -> String {
        match &self.logicpad {
            Some(p) => format!("logicrag.Engine(logicpad={:?})", p.display().to_string()),
            None => "logicrag.Engine()".to_string(),
        }
    }
}

/// A source opened by `Engine.open`: its windows, ready to be asked.
///
/// Answers are those of the CLI on the same source and options:
/// `ask` returns what `logicrag ask --json` prints, `facts` the facts
/// `logicrag facts --json` prints (as an Arrow table), `answer` the
/// answers of `logicrag ask --queries` (as an Arrow table). The windows
/// are reasoned once, on the first question, and shared by every later
/// one; methods release the GIL while they work, so threads may ask one
/// source at once.
#[pyclass(module = "logicrag", name = "Source", frozen)]
struct Source {
    inner: Arc<Pipeline>,
}

#[pymethods]
impl Source {
    /// The source's label, e.g. `sim:urban_crossing` or `kitti:0000`: the
    /// `video` column of its tables.
    #[getter]
    fn video(&self) -> String {
        self.inner.label().to_string()
    }

    /// The window ids, in order (e.g. `urban_crossing_000000`,
    /// `urban_crossing_000010`, …).
    #[getter]
    fn windows(&self) -> Vec<String> {
        self.inner.windows().iter().map(|w| w.id.clone()).collect()
    }

    /// The facts of one window (or of every window, in order) as a
    /// `pyarrow.Table` with the facts schema of docs/formats.md: `video`,
    /// `window`, `window_index`, `first_frame`, `last_frame`, `predicate`,
    /// `args` (list of strings) and `provenance` (a struct: `window`,
    /// `first_frame`, `last_frame`, `source`, `measured`, `threshold`
    /// {`name`, `value`}, `note`). Rows in the order of `facts --json`.
    ///
    /// Raises `ValueError` for a window id the source does not have.
    #[pyo3(signature = (window = None))]
    fn facts<'py>(&self, py: Python<'py>, window: Option<&str>) -> PyResult<Bound<'py, PyAny>> {
        let batches = py
            .detach(|| logicrag::arrow::facts_table(&self.inner, window))
            .map_err(|e| table_err(&e))?;
        to_table(py, batches, logicrag::arrow::facts_schema())
    }

    /// Answers a question in English or a query (`TypeOf(x, Car) ^
    /// Moving(x)`) on every window, or on the window named `window`.
    ///
    /// Returns `{"results": [...], "summary": {...}}`: one object per
    /// window (answer `yes`/`no`/`unknown`/`invalid`, bindings, proofs,
    /// why-not, reasons) and the summary — the objects `logicrag ask
    /// --json` prints, as `serve`'s `/api/ask` returns them. `proofs=False`
    /// is the CLI's `--no-proofs`; `max_answers` and `proof_depth` its
    /// `--max-answers` and `--proof-depth`.
    ///
    /// Raises `ValueError` when the grammar cannot read the question, or
    /// for an unknown window id. A query that does not fit the LogicPad
    /// is not an error: every window answers `invalid`, saying why.
    #[pyo3(signature = (question, window = None, *, proofs = true, max_answers = None, proof_depth = None))]
    fn ask<'py>(
        &self,
        py: Python<'py>,
        question: &str,
        window: Option<&str>,
        proofs: bool,
        max_answers: Option<usize>,
        proof_depth: Option<usize>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let opts = ask_options(proofs, max_answers, proof_depth)?;
        let value = py
            .detach(|| logicrag::json::ask(&self.inner, question, window, opts))
            .map_err(|e| py_err(&e))?;
        to_python(py, &value)
    }

    /// The retrieval context of a question on one window, as `logicrag
    /// context --json` prints it: the question, the C2 inference sentences
    /// (the proved answer in words) and the C3 fact sentences.
    ///
    /// Raises `ValueError` when the grammar cannot read the question, or
    /// for an unknown window id.
    fn context<'py>(
        &self,
        py: Python<'py>,
        question: &str,
        window: &str,
    ) -> PyResult<Bound<'py, PyAny>> {
        let value = py
            .detach(|| self.inner.context_of(question, window))
            .map_err(|e| py_err(&e))?;
        to_python(py, &value)
    }

    /// Answers every question (or query) of `questions` on every window,
    /// as a `pyarrow.Table` with the answers schema of docs/formats.md:
    /// one row per (window, question), window by window, each window's
    /// rows in the order of `questions` (`query_index` is the question's
    /// position) — the rows of `logicrag ask --queries FILE` for a file
    /// that lists each window's questions in turn. `question` holds the
    /// English text (null for a query), `query` the query as run.
    /// `proofs=True` fills the `proofs` column with each answer's proofs
    /// as typed proof nodes (null otherwise); proofs make a large table.
    ///
    /// Every question is translated before any window is reasoned: one
    /// the grammar cannot read raises `ValueError` and nothing is answered.
    #[pyo3(signature = (questions, *, proofs = false, max_answers = None, proof_depth = None))]
    fn answer<'py>(
        &self,
        py: Python<'py>,
        questions: Vec<String>,
        proofs: bool,
        max_answers: Option<usize>,
        proof_depth: Option<usize>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let opts = ask_options(proofs, max_answers, proof_depth)?;
        let texts: Vec<&str> = questions.iter().map(String::as_str).collect();
        let batches = py
            .detach(|| logicrag::arrow::answer_table(&self.inner, &texts, opts))
            .map_err(|e| table_err(&e))?;
        to_table(py, batches, logicrag::arrow::answers_schema())
    }

    fn __len__(&self) -> usize {
        self.inner.windows().len()
    }

    fn __repr__(&self) -> String {
        format!(
            "<logicrag.Source {} ({} windows)>",
            self.inner.label(),
            self.inner.windows().len()
        )
    }
}

/// The answers schema of docs/formats.md as a `pyarrow.Schema`: what
/// `Source.answer` returns, for a consumer that must declare its output
/// schema before any answer exists (Spark's `applyInArrow`).
#[pyfunction]
fn answers_schema(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    logicrag::arrow::answers_schema()
        .as_ref()
        .clone()
        .into_pyarrow(py)
}

/// The facts schema of docs/formats.md as a `pyarrow.Schema`: what
/// `Source.facts` returns.
#[pyfunction]
fn facts_schema(py: Python<'_>) -> PyResult<Bound<'_, PyAny>> {
    logicrag::arrow::facts_schema()
        .as_ref()
        .clone()
        .into_pyarrow(py)
}

/// JSON text read by serde_json and converted as answers are: for the
/// tests, which compare it with `json.loads` on values the answers do not
/// always hold (bools, negative and large integers). Not public API.
#[pyfunction]
fn _json_to_python<'py>(py: Python<'py>, text: &str) -> PyResult<Bound<'py, PyAny>> {
    let value: serde_json::Value =
        serde_json::from_str(text).map_err(|e| PyValueError::new_err(e.to_string()))?;
    to_python(py, &value)
}

/// The native half of the `logicrag` package (import `logicrag`, not this).
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<Engine>()?;
    m.add_class::<Source>()?;
    m.add_function(wrap_pyfunction!(answers_schema, m)?)?;
    m.add_function(wrap_pyfunction!(facts_schema, m)?)?;
    m.add_function(wrap_pyfunction!(_json_to_python, m)?)?;
    m.add("__version__", env!("CARGO_PKG_VERSION"))?;
    Ok(())
}
