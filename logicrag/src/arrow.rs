//! Facts and answers as Arrow record batches and Parquet files: one schema
//! for both, so that a table written by `logicrag facts --parquet`, by
//! `logicrag ask --queries … --parquet` or returned by the Python package
//! reads the same in DuckDB, pandas or Spark (docs/formats.md documents
//! every column).
//!
//! - [`facts_schema`] / [`FactsBuilder`]: one row per fact of a window,
//!   windows in source order, facts in the order the source gave them
//!   (as `facts --json`); the provenance is a struct column, so SQL reads
//!   `provenance.threshold.name` without parsing JSON.
//! - [`answers_schema`] / [`AnswersBuilder`]: one row per (window, query),
//!   bindings as a typed list of `(variable, value)` lists, proofs (only
//!   when asked for) as typed proof nodes ([`proofs`]: each tree flattened
//!   into a list with parent indices; [`read_proofs`] reads them back).
//! - [`ParquetWriter`] writes batches to a file as they come (a batch
//!   with millions of answers is never held whole); [`read_parquet`]
//!   reads one back.
//!
//! - [`tracks`]: the other direction, a *tracks table* any dataset can
//!   fill (one row per object and frame) read into a sequence
//!   ([`tracks_from_batches`], Python's `Engine.open_tracks`).
//!
//! Every integer column is signed (`Int64`): Spark refuses unsigned
//! Parquet integers, and every count and frame number fits.

use crate::ask::AskResult;
use crate::json::WindowPlace;
use crate::kb::FactRef;
use arrow_array::builder::{Float64Builder, Int64Builder, OffsetBufferBuilder, StringBuilder};
use arrow_array::{ArrayRef, ListArray, StructArray};
use arrow_schema::{ArrowError, DataType, Field, FieldRef, Fields, Schema};
use columns::{ProvenanceColumns, StrLists, provenance_fields};
use std::path::{Path, PathBuf};
use std::sync::Arc;

mod columns;
pub mod proofs;
pub mod tracks;

pub use proofs::read_proofs;

pub use arrow_array::RecordBatch;
pub use arrow_schema::SchemaRef;
pub use tracks::{TracksError, read_map, tracks_from_batches};
/// The Arrow and Parquet crates these tables are made with, for callers
/// that read the columns (one version for all).
pub use {arrow_array, arrow_schema, parquet};

/// Errors of building, writing or reading a table.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    /// Occurs when the columns of a batch do not fit its schema (a bug in
    /// this module, reported rather than panicking).
    #[error("building an Arrow table: {0}")]
    Arrow(#[from] ArrowError),
    /// Occurs when a batch holds more list items or text than Arrow's
    /// 32-bit offsets address (the builders flush long before; one
    /// gigantic answer can still reach it).
    #[error("building an Arrow table: {0}")]
    TooLarge(String),
    /// Occurs when a table read back does not hold what this module
    /// writes (a column of another type, a proof node whose parent is not
    /// before it).
    #[error("reading an Arrow table: {0}")]
    Malformed(String),
    /// Occurs when a Parquet file cannot be created or opened.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: String,
        /// The OS error.
        #[source]
        source: std::io::Error,
    },
    /// Occurs when the Parquet writer or reader fails (a full disk, a
    /// file that is not Parquet or was written with another schema).
    #[error("{path}: {source}")]
    Parquet {
        /// The file.
        path: String,
        /// What went wrong.
        #[source]
        source: parquet::errors::ParquetError,
    },
    /// Occurs when the pipeline a table is built from cannot answer (an
    /// unknown window, a question the translator cannot read).
    #[error(transparent)]
    Session(Box<crate::session::SessionError>),
}

impl From<crate::session::SessionError> for TableError {
    fn from(e: crate::session::SessionError) -> TableError {
        TableError::Session(Box::new(e))
    }
}

/// A batch is closed when it holds this many rows, so that a whole
/// source's answers never need one buffer…
pub(crate) const BATCH_ROWS: usize = 64 * 1024;

/// …or this much text: Arrow's string and list columns address their
/// contents with 32-bit offsets (2 GiB), and a batch with proofs can hold
/// hundreds of kilobytes per row.
pub(crate) const BATCH_BYTES: usize = 64 << 20;

/// A non-nullable column.
fn col(name: &str, t: DataType) -> Field {
    Field::new(name, t, false)
}

/// A list of non-null strings (`list<string>`).
fn str_list() -> DataType {
    DataType::List(Arc::new(Field::new("item", DataType::Utf8, false)))
}

/// One binding's pair.
fn binding_fields() -> Fields {
    Fields::from(vec![
        col("variable", DataType::Utf8),
        col("value", DataType::Utf8),
    ])
}

/// `list<struct<variable, value>>`: one binding.
fn binding_field() -> FieldRef {
    Arc::new(Field::new(
        "item",
        DataType::Struct(binding_fields()),
        false,
    ))
}

/// `list<list<struct<variable, value>>>`: every binding.
fn bindings_field() -> FieldRef {
    Arc::new(Field::new("item", DataType::List(binding_field()), false))
}

/// The facts table: one row per fact.
///
/// | column | type | |
/// |---|---|---|
/// | `video` | string | the source's label (`sim:urban_crossing`, `kitti:0000`) |
/// | `window` | string | window id |
/// | `window_index` | int64 | position of the window in its source |
/// | `first_frame`, `last_frame` | int64 | the window's frames (inclusive) |
/// | `predicate` | string | e.g. `TypeOf` |
/// | `args` | `list<string>` | e.g. `["car_3", "Car"]` |
/// | `provenance` | struct | `window`, `first_frame`, `last_frame`, `source`, `measured` (null when read, not measured), `threshold` (struct `name`, `value`; null when none), `note` (null when empty), `probability` (null when certain) |
pub fn facts_schema() -> SchemaRef {
    Arc::new(Schema::new(vec![
        col("video", DataType::Utf8),
        col("window", DataType::Utf8),
        col("window_index", DataType::Int64),
        col("first_frame", DataType::Int64),
        col("last_frame", DataType::Int64),
        col("predicate", DataType::Utf8),
        col("args", str_list()),
        col("provenance", DataType::Struct(provenance_fields())),
    ]))
}

/// The answers table: one row per (window, query).
///
/// | column | type | |
/// |---|---|---|
/// | `video` | string | the source's label |
/// | `window` | string | window id |
/// | `first_frame`, `last_frame` | int64 | the window's frames |
/// | `question` | string, null | the English question (null for a query) |
/// | `query` | string | the query as run |
/// | `query_index` | int64 | the query's position among its window's queries |
/// | `answer` | string | `yes`, `no`, `unknown` or `invalid` |
/// | `count` | int64 | distinct bindings |
/// | `variables` | `list<string>` | the answer variables, in order |
/// | `bindings` | list<list<struct<variable, value>>> | each binding, sorted |
/// | `reasons` | `list<string>` | why unknown or invalid |
/// | `proofs` | list<list<struct<…>>>, null | one list per binding, holding its proof trees' nodes in pre-order ([`proofs`]); null when proofs were not asked for |
/// | `probability` | float64, null | the probability that the answer is right (`ask --json`'s); null for unknown, invalid, or a count-only ask |
/// | `stopped` | string, null | the limit the answer's run stopped at (`answers`, `steps`, `time`: the bindings are those found before it, `count` a lower bound); null for a complete answer |
pub fn answers_schema() -> SchemaRef {
    Arc::new(Schema::new(vec![
        col("video", DataType::Utf8),
        col("window", DataType::Utf8),
        col("first_frame", DataType::Int64),
        col("last_frame", DataType::Int64),
        Field::new("question", DataType::Utf8, true),
        col("query", DataType::Utf8),
        col("query_index", DataType::Int64),
        col("answer", DataType::Utf8),
        col("count", DataType::Int64),
        col("variables", str_list()),
        col("bindings", DataType::List(bindings_field())),
        col("reasons", str_list()),
        Field::new("proofs", proofs::proofs_type(), true),
        Field::new("probability", DataType::Float64, true),
        Field::new("stopped", DataType::Utf8, true),
    ]))
}

/// An offset overflow (more than 2^31 list items or bytes of text in one
/// batch) as the error that says so.
fn too_large(e: impl std::fmt::Display) -> TableError {
    TableError::TooLarge(e.to_string())
}

/// The list column of `values` cut by `offsets` (which start afresh),
/// with `nulls` (`None`: no null list).
fn list_array(
    item: FieldRef,
    offsets: &mut OffsetBufferBuilder<i32>,
    values: ArrayRef,
    nulls: Option<Vec<bool>>,
) -> Result<ListArray, TableError> {
    let offsets = std::mem::replace(offsets, OffsetBufferBuilder::new(0))
        .try_finish()
        .map_err(too_large)?;
    ListArray::try_new(item, offsets, values, nulls.map(Into::into)).map_err(too_large)
}

/// How full a batch being built is: rows and bytes of text since it was
/// last finished.
#[derive(Debug, Default)]
struct Fill {
    rows: usize,
    bytes: usize,
}

/// The fill methods of a table builder with a `fill: Fill` field.
macro_rules! fill_methods {
    ($builder:ident) => {
        impl $builder {
            /// Rows appended since the last finish.
            pub fn len(&self) -> usize {
                self.fill.rows
            }

            /// True when no row was appended since the last finish.
            pub fn is_empty(&self) -> bool {
                self.fill.rows == 0
            }

            /// True when the batch should be closed (`BATCH_ROWS`,
            /// `BATCH_BYTES`).
            pub fn is_full(&self) -> bool {
                self.fill.rows >= BATCH_ROWS || self.fill.bytes >= BATCH_BYTES
            }

            /// Counts one row of `bytes` of text.
            fn count_row(&mut self, bytes: usize) {
                self.fill.rows += 1;
                self.fill.bytes += bytes;
            }
        }
    };
}

fill_methods!(FactsBuilder);
fill_methods!(AnswersBuilder);

/// A `usize` or `u32` as an `Int64` value; never out of range in practice
/// (a count above 2^63 cannot be held in memory), and saturating if it were.
fn int(n: impl TryInto<i64>) -> i64 {
    n.try_into().unwrap_or(i64::MAX)
}

/// Builds facts-table batches ([`facts_schema`]).
#[derive(Debug)]
pub struct FactsBuilder {
    video: StringBuilder,
    window: StringBuilder,
    window_index: Int64Builder,
    first_frame: Int64Builder,
    last_frame: Int64Builder,
    predicate: StringBuilder,
    args: StrLists,
    provenance: ProvenanceColumns,
    fill: Fill,
}

impl Default for FactsBuilder {
    fn default() -> Self {
        FactsBuilder::new()
    }
}

impl FactsBuilder {
    /// An empty builder.
    pub fn new() -> FactsBuilder {
        FactsBuilder {
            video: StringBuilder::new(),
            window: StringBuilder::new(),
            window_index: Int64Builder::new(),
            first_frame: Int64Builder::new(),
            last_frame: Int64Builder::new(),
            predicate: StringBuilder::new(),
            args: StrLists::new(),
            provenance: ProvenanceColumns::new(),
            fill: Fill::default(),
        }
    }

    /// Appends a window's facts, in the order given.
    pub(crate) fn push_window<'a>(
        &mut self,
        video: &str,
        place: WindowPlace<'_>,
        facts: impl IntoIterator<Item = FactRef<'a>>,
    ) {
        for f in facts {
            self.push(video, place, f);
        }
    }

    /// Appends one fact.
    pub fn push(&mut self, video: &str, place: WindowPlace<'_>, f: FactRef<'_>) {
        let p = f.provenance();
        self.video.append_value(video);
        self.window.append_value(place.id);
        self.window_index.append_value(int(place.index));
        self.first_frame.append_value(int(place.first_frame));
        self.last_frame.append_value(int(place.last_frame));
        self.predicate.append_value(f.predicate());
        let arg_bytes = self.args.push(f.args());
        let provenance_bytes = self.provenance.push(Some(p));
        self.count_row(
            video.len() + place.id.len() + f.predicate().len() + arg_bytes + provenance_bytes,
        );
    }

    /// The rows appended so far as one batch; the builder starts afresh.
    pub fn finish(&mut self) -> Result<RecordBatch, TableError> {
        let columns: Vec<ArrayRef> = vec![
            Arc::new(self.video.finish()),
            Arc::new(self.window.finish()),
            Arc::new(self.window_index.finish()),
            Arc::new(self.first_frame.finish()),
            Arc::new(self.last_frame.finish()),
            Arc::new(self.predicate.finish()),
            self.args.finish()?,
            Arc::new(self.provenance.finish()?),
        ];
        self.fill = Fill::default();
        Ok(RecordBatch::try_new(facts_schema(), columns)?)
    }
}

/// Builds answers-table batches ([`answers_schema`]).
#[derive(Debug)]
pub struct AnswersBuilder {
    with_proofs: bool,
    video: StringBuilder,
    window: StringBuilder,
    first_frame: Int64Builder,
    last_frame: Int64Builder,
    question: StringBuilder,
    query: StringBuilder,
    query_index: Int64Builder,
    answer: StringBuilder,
    count: Int64Builder,
    variables: StrLists,
    /// One offset per row into the bindings.
    bindings: OffsetBufferBuilder<i32>,
    /// One offset per binding into the pairs.
    binding: OffsetBufferBuilder<i32>,
    pair_variable: StringBuilder,
    pair_value: StringBuilder,
    reasons: StrLists,
    proofs: proofs::ProofColumns,
    probability: Float64Builder,
    stopped: StringBuilder,
    fill: Fill,
}

impl AnswersBuilder {
    /// An empty builder; `with_proofs` says whether rows carry proofs
    /// (the `proofs` column is null for every row otherwise).
    pub fn new(with_proofs: bool) -> AnswersBuilder {
        AnswersBuilder {
            with_proofs,
            video: StringBuilder::new(),
            window: StringBuilder::new(),
            first_frame: Int64Builder::new(),
            last_frame: Int64Builder::new(),
            question: StringBuilder::new(),
            query: StringBuilder::new(),
            query_index: Int64Builder::new(),
            answer: StringBuilder::new(),
            count: Int64Builder::new(),
            variables: StrLists::new(),
            bindings: OffsetBufferBuilder::new(0),
            binding: OffsetBufferBuilder::new(0),
            pair_variable: StringBuilder::new(),
            pair_value: StringBuilder::new(),
            reasons: StrLists::new(),
            proofs: proofs::ProofColumns::new(),
            probability: Float64Builder::new(),
            stopped: StringBuilder::new(),
            fill: Fill::default(),
        }
    }

    /// Appends one answer: `question` is the English question the query
    /// was translated from (`None` for a query as written), `query_index`
    /// its position among its window's queries; its proofs fill the
    /// `proofs` column when the builder was made with proofs.
    pub fn push(&mut self, video: &str, question: Option<&str>, query_index: usize, r: &AskResult) {
        self.video.append_value(video);
        self.window.append_value(&r.window);
        self.first_frame.append_value(int(r.first_frame));
        self.last_frame.append_value(int(r.last_frame));
        self.question.append_option(question);
        self.query.append_value(&r.query);
        self.query_index.append_value(int(query_index));
        self.answer.append_value(r.answer.as_str());
        self.count.append_value(int(r.count));
        let mut bytes = video.len()
            + r.window.len()
            + question.map_or(0, str::len)
            + r.query.len()
            + self.variables.push(r.variables.iter().map(String::as_str))
            + self.reasons.push(r.reasons.iter().map(String::as_str));
        for b in &r.bindings {
            for (var, value) in b {
                self.pair_variable.append_value(var);
                self.pair_value.append_value(value);
                bytes += var.len() + value.len();
            }
            self.binding.push_length(b.len());
        }
        self.bindings.push_length(r.bindings.len());
        bytes += self
            .proofs
            .push(self.with_proofs.then_some(r.proofs.as_slice()));
        self.probability.append_option(r.probability);
        self.stopped
            .append_option(r.stopped.map(logicpad::Stopped::as_str));
        self.count_row(bytes);
    }

    /// The rows appended so far as one batch; the builder starts afresh.
    pub fn finish(&mut self) -> Result<RecordBatch, TableError> {
        let pairs = StructArray::try_new(
            binding_fields(),
            vec![
                Arc::new(self.pair_variable.finish()) as ArrayRef,
                Arc::new(self.pair_value.finish()),
            ],
            None,
        )?;
        let one = list_array(binding_field(), &mut self.binding, Arc::new(pairs), None)?;
        let bindings = list_array(bindings_field(), &mut self.bindings, Arc::new(one), None)?;
        let columns: Vec<ArrayRef> = vec![
            Arc::new(self.video.finish()),
            Arc::new(self.window.finish()),
            Arc::new(self.first_frame.finish()),
            Arc::new(self.last_frame.finish()),
            Arc::new(self.question.finish()),
            Arc::new(self.query.finish()),
            Arc::new(self.query_index.finish()),
            Arc::new(self.answer.finish()),
            Arc::new(self.count.finish()),
            self.variables.finish()?,
            Arc::new(bindings),
            self.reasons.finish()?,
            self.proofs.finish()?,
            Arc::new(self.probability.finish()),
            Arc::new(self.stopped.finish()),
        ];
        self.fill = Fill::default();
        Ok(RecordBatch::try_new(answers_schema(), columns)?)
    }
}

/// A Parquet file being written, batch by batch (Snappy-compressed).
pub struct ParquetWriter {
    path: PathBuf,
    inner: parquet::arrow::ArrowWriter<std::fs::File>,
    rows: usize,
}

impl std::fmt::Debug for ParquetWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ParquetWriter")
            .field("path", &self.path)
            .field("rows", &self.rows)
            .finish_non_exhaustive()
    }
}

impl ParquetWriter {
    /// Creates (or truncates) `path` for batches of `schema`.
    pub fn create(path: &Path, schema: SchemaRef) -> Result<ParquetWriter, TableError> {
        let shown = path.display().to_string();
        let file = std::fs::File::create(path).map_err(|source| TableError::Io {
            path: shown.clone(),
            source,
        })?;
        let props = parquet::file::properties::WriterProperties::builder()
            .set_compression(parquet::basic::Compression::SNAPPY)
            .build();
        let inner =
            parquet::arrow::ArrowWriter::try_new(file, schema, Some(props)).map_err(|source| {
                TableError::Parquet {
                    path: shown,
                    source,
                }
            })?;
        Ok(ParquetWriter {
            path: path.to_path_buf(),
            inner,
            rows: 0,
        })
    }

    /// Appends a batch.
    pub fn write(&mut self, batch: &RecordBatch) -> Result<(), TableError> {
        self.rows += batch.num_rows();
        self.inner
            .write(batch)
            .map_err(|source| TableError::Parquet {
                path: self.path.display().to_string(),
                source,
            })
    }

    /// Writes the footer and closes the file; returns the rows written.
    pub fn finish(self) -> Result<usize, TableError> {
        let path = self.path.display().to_string();
        self.inner
            .close()
            .map_err(|source| TableError::Parquet { path, source })?;
        Ok(self.rows)
    }
}

/// Writes `batches` (of `schema`) to one Parquet file; returns the rows
/// written.
pub fn write_parquet(
    path: &Path,
    schema: SchemaRef,
    batches: &[RecordBatch],
) -> Result<usize, TableError> {
    let mut w = ParquetWriter::create(path, schema)?;
    for b in batches {
        w.write(b)?;
    }
    w.finish()
}

/// Reads every batch of a Parquet file (batches of up to `BATCH_ROWS`
/// rows).
pub fn read_parquet(path: &Path) -> Result<Vec<RecordBatch>, TableError> {
    let shown = path.display().to_string();
    let file = std::fs::File::open(path).map_err(|source| TableError::Io {
        path: shown.clone(),
        source,
    })?;
    let parquet_err = |source| TableError::Parquet {
        path: shown.clone(),
        source,
    };
    let reader = parquet::arrow::arrow_reader::ParquetRecordBatchReaderBuilder::try_new(file)
        .and_then(|b| b.with_batch_size(BATCH_ROWS).build())
        .map_err(parquet_err)?;
    reader
        .map(|b| {
            b.map_err(|e| TableError::Parquet {
                path: shown.clone(),
                source: e.into(),
            })
        })
        .collect()
}

/// The facts of `pipeline`'s window named `window`, or of every window,
/// as record batches of the facts schema: windows in order, facts in
/// source order.
pub fn facts_table(
    pipeline: &crate::pipeline::Pipeline,
    window: Option<&str>,
) -> Result<Vec<RecordBatch>, TableError> {
    pipeline.check_window(window)?;
    let mut b = FactsBuilder::new();
    let mut out = Vec::new();
    for w in pipeline
        .windows()
        .iter()
        .filter(|w| window.is_none_or(|id| w.id == id))
    {
        b.push_window(pipeline.label(), w.into(), w.facts.iter());
        flush(&mut b, &mut out, false)?;
    }
    flush(&mut b, &mut out, true)?;
    Ok(out)
}

/// Every question (or query) of `texts` answered on every window of
/// `pipeline`, as record batches of the answers schema: window by
/// window, each window's answers in the order of `texts` — the order of
/// an `ask --queries` file that lists each window's queries in turn, an
/// answer's `query_index` its text's position. Proofs fill the `proofs`
/// column when `opts` asks for them. Every text is prepared first, so a
/// question that cannot be translated fails before any reasoning.
pub fn answer_table(
    pipeline: &crate::pipeline::Pipeline,
    texts: &[&str],
    opts: crate::ask::AskOptions,
) -> Result<Vec<RecordBatch>, TableError> {
    let prepared = texts
        .iter()
        .map(|t| pipeline.prepare(t))
        .collect::<Result<Vec<_>, _>>()
        .map_err(crate::session::SessionError::from)?;
    let by_window = pipeline.ask_every(&prepared, opts)?;
    let mut b = AnswersBuilder::new(opts.proofs && !opts.count_only);
    let mut out = Vec::new();
    for results in &by_window {
        for (i, (r, p)) in results.iter().zip(&prepared).enumerate() {
            b.push(pipeline.label(), p.question.as_deref(), i, r);
            flush(&mut b, &mut out, false)?;
        }
    }
    flush(&mut b, &mut out, true)?;
    Ok(out)
}

/// What the table builders share: closing a batch.
trait Builder {
    fn is_full(&self) -> bool;
    fn is_empty(&self) -> bool;
    fn finish(&mut self) -> Result<RecordBatch, TableError>;
}

impl Builder for FactsBuilder {
    fn is_full(&self) -> bool {
        FactsBuilder::is_full(self)
    }
    fn is_empty(&self) -> bool {
        FactsBuilder::is_empty(self)
    }
    fn finish(&mut self) -> Result<RecordBatch, TableError> {
        FactsBuilder::finish(self)
    }
}

impl Builder for AnswersBuilder {
    fn is_full(&self) -> bool {
        AnswersBuilder::is_full(self)
    }
    fn is_empty(&self) -> bool {
        AnswersBuilder::is_empty(self)
    }
    fn finish(&mut self) -> Result<RecordBatch, TableError> {
        AnswersBuilder::finish(self)
    }
}

/// Closes `b`'s batch into `out` when it is full, or (`last`) when it
/// holds rows or `out` has none yet.
fn flush(b: &mut impl Builder, out: &mut Vec<RecordBatch>, last: bool) -> Result<(), TableError> {
    let close = if last {
        out.is_empty() || !b.is_empty()
    } else {
        b.is_full()
    };
    if close {
        out.push(b.finish()?);
    }
    Ok(())
}

/// The file `facts --parquet DIR` writes a window's facts to:
/// `DIR/<window id>.parquet` (ids are zero-padded, so the files sort in
/// window order). An id that cannot be a file name (a `facts:DIR` file
/// stem can be almost anything) is refused rather than mangled, since a
/// mangled name could collide with another window's.
pub fn window_file(dir: &Path, window: &str) -> Result<PathBuf, String> {
    let ok = !window.is_empty()
        && !window.starts_with('.')
        && window
            .chars()
            .all(|c| c.is_alphanumeric() || matches!(c, '_' | '-' | '.' | '+' | '@'));
    if ok {
        Ok(dir.join(format!("{window}.parquet")))
    } else {
        Err(format!(
            "window id `{window}` cannot be a file name (letters, digits, `_-.+@`, not starting with `.`)"
        ))
    }
}

#[cfg(test)]
mod tests;
