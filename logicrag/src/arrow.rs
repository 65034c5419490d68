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
//!   bindings as a typed list of `(variable, value)` lists, proofs as the
//!   JSON `ask --json` prints (only when asked for).
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
use std::path::{Path, PathBuf};
use std::sync::Arc;

pub mod tracks;

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
    /// Occurs when a proof cannot be rendered as JSON.
    #[error("rendering proofs as JSON: {0}")]
    Json(#[from] serde_json::Error),
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

/// The provenance struct's fields (a fact's `provenance` in JSON).
fn provenance_fields() -> Fields {
    Fields::from(vec![
        col("window", DataType::Int64),
        col("first_frame", DataType::Int64),
        col("last_frame", DataType::Int64),
        col("source", DataType::Utf8),
        Field::new("measured", DataType::Float64, true),
        Field::new("threshold", DataType::Struct(threshold_fields()), true),
        Field::new("note", DataType::Utf8, true),
        Field::new("probability", DataType::Float64, true),
    ])
}

/// A threshold: the `FactConfig` field and its value.
fn threshold_fields() -> Fields {
    Fields::from(vec![
        col("name", DataType::Utf8),
        col("value", DataType::Float64),
    ])
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
/// | `proofs` | string, null | one proof per binding, as the JSON of `ask --json`'s `"proofs"`; null when proofs were not asked for |
/// | `probability` | float64, null | the probability that the answer is right (`ask --json`'s); null for unknown, invalid, or a count-only ask |
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
        Field::new("proofs", DataType::Utf8, true),
        Field::new("probability", DataType::Float64, true),
    ]))
}

/// A `usize` or `u32` as an `Int64` value; never out of range in practice
/// (a count above 2^63 cannot be held in memory), and saturating if it were.
fn int(n: impl TryInto<i64>) -> i64 {
    n.try_into().unwrap_or(i64::MAX)
}

/// A `list<string>` column being built.
#[derive(Debug)]
struct StrLists {
    offsets: OffsetBufferBuilder<i32>,
    values: StringBuilder,
}

impl StrLists {
    fn new() -> StrLists {
        StrLists {
            offsets: OffsetBufferBuilder::new(0),
            values: StringBuilder::new(),
        }
    }

    /// Appends one list; returns the bytes of text it added.
    fn push<'a>(&mut self, items: impl IntoIterator<Item = &'a str>) -> usize {
        let (mut n, mut bytes) = (0, 0);
        for s in items {
            self.values.append_value(s);
            n += 1;
            bytes += s.len();
        }
        self.offsets.push_length(n);
        bytes
    }

    fn finish(&mut self) -> Result<ArrayRef, TableError> {
        let offsets = std::mem::replace(&mut self.offsets, OffsetBufferBuilder::new(0))
            .try_finish()
            .map_err(|e| TableError::TooLarge(e.to_string()))?;
        let values: ArrayRef = Arc::new(self.values.finish());
        let item = Arc::new(Field::new("item", DataType::Utf8, false));
        Ok(Arc::new(ListArray::try_new(item, offsets, values, None)?))
    }
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
    p_window: Int64Builder,
    p_first: Int64Builder,
    p_last: Int64Builder,
    p_source: StringBuilder,
    p_measured: Float64Builder,
    p_threshold_name: StringBuilder,
    p_threshold_value: Float64Builder,
    /// Which rows have a threshold.
    p_threshold_valid: Vec<bool>,
    p_note: StringBuilder,
    p_probability: Float64Builder,
    rows: usize,
    bytes: usize,
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
            p_window: Int64Builder::new(),
            p_first: Int64Builder::new(),
            p_last: Int64Builder::new(),
            p_source: StringBuilder::new(),
            p_measured: Float64Builder::new(),
            p_threshold_name: StringBuilder::new(),
            p_threshold_value: Float64Builder::new(),
            p_threshold_valid: Vec::new(),
            p_note: StringBuilder::new(),
            p_probability: Float64Builder::new(),
            rows: 0,
            bytes: 0,
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
        self.p_window.append_value(int(p.window));
        self.p_first.append_value(int(p.frames.0));
        self.p_last.append_value(int(p.frames.1));
        self.p_source.append_value(&*p.source);
        self.p_measured.append_option(p.measured);
        match &p.threshold {
            Some((name, value)) => {
                self.p_threshold_name.append_value(name);
                self.p_threshold_value.append_value(*value);
                self.p_threshold_valid.push(true);
            }
            // A null struct's children still need a slot each.
            None => {
                self.p_threshold_name.append_value("");
                self.p_threshold_value.append_value(0.0);
                self.p_threshold_valid.push(false);
            }
        }
        if p.note.is_empty() {
            self.p_note.append_null();
        } else {
            self.p_note.append_value(&p.note);
        }
        self.p_probability.append_option(p.probability);
        self.rows += 1;
        self.bytes += video.len()
            + place.id.len()
            + f.predicate().len()
            + arg_bytes
            + p.source.len()
            + p.note.len()
            + p.threshold.as_ref().map_or(0, |t| t.0.len());
    }

    /// Rows appended since the last [`FactsBuilder::finish`].
    pub fn len(&self) -> usize {
        self.rows
    }

    /// True when no row was appended since the last finish.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// True when the batch should be closed (`BATCH_ROWS`, `BATCH_BYTES`).
    pub fn is_full(&self) -> bool {
        self.rows >= BATCH_ROWS || self.bytes >= BATCH_BYTES
    }

    /// The rows appended so far as one batch; the builder starts afresh.
    pub fn finish(&mut self) -> Result<RecordBatch, TableError> {
        let threshold = StructArray::try_new(
            threshold_fields(),
            vec![
                Arc::new(self.p_threshold_name.finish()) as ArrayRef,
                Arc::new(self.p_threshold_value.finish()),
            ],
            Some(std::mem::take(&mut self.p_threshold_valid).into()),
        )?;
        let provenance = StructArray::try_new(
            provenance_fields(),
            vec![
                Arc::new(self.p_window.finish()) as ArrayRef,
                Arc::new(self.p_first.finish()),
                Arc::new(self.p_last.finish()),
                Arc::new(self.p_source.finish()),
                Arc::new(self.p_measured.finish()),
                Arc::new(threshold),
                Arc::new(self.p_note.finish()),
                Arc::new(self.p_probability.finish()),
            ],
            None,
        )?;
        let columns: Vec<ArrayRef> = vec![
            Arc::new(self.video.finish()),
            Arc::new(self.window.finish()),
            Arc::new(self.window_index.finish()),
            Arc::new(self.first_frame.finish()),
            Arc::new(self.last_frame.finish()),
            Arc::new(self.predicate.finish()),
            self.args.finish()?,
            Arc::new(provenance),
        ];
        self.rows = 0;
        self.bytes = 0;
        Ok(RecordBatch::try_new(facts_schema(), columns)?)
    }
}

/// The proofs of an answer as the JSON `ask --json` prints in its
/// `"proofs"` field: the `proofs` column of the answers table.
pub fn proofs_json(r: &AskResult) -> Result<String, TableError> {
    let mut out = Vec::new();
    crate::json::write_proofs_json(&mut out, &r.proofs)?;
    // serde_json writes UTF-8; nothing is replaced.
    Ok(String::from_utf8_lossy(&out).into_owned())
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
    proofs: StringBuilder,
    probability: Float64Builder,
    rows: usize,
    bytes: usize,
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
            proofs: StringBuilder::new(),
            probability: Float64Builder::new(),
            rows: 0,
            bytes: 0,
        }
    }

    /// Appends one answer: `question` is the English question the query
    /// was translated from (`None` for a query as written), `query_index`
    /// its position among its window's queries, `proofs` its
    /// [`proofs_json`] (ignored unless the builder was made with proofs).
    pub fn push(
        &mut self,
        video: &str,
        question: Option<&str>,
        query_index: usize,
        r: &AskResult,
        proofs: Option<&str>,
    ) {
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
        match proofs.filter(|_| self.with_proofs) {
            Some(p) => {
                self.proofs.append_value(p);
                bytes += p.len();
            }
            None => self.proofs.append_null(),
        }
        self.probability.append_option(r.probability);
        self.rows += 1;
        self.bytes += bytes;
    }

    /// Rows appended since the last [`AnswersBuilder::finish`].
    pub fn len(&self) -> usize {
        self.rows
    }

    /// True when no row was appended since the last finish.
    pub fn is_empty(&self) -> bool {
        self.rows == 0
    }

    /// True when the batch should be closed (`BATCH_ROWS`, `BATCH_BYTES`).
    pub fn is_full(&self) -> bool {
        self.rows >= BATCH_ROWS || self.bytes >= BATCH_BYTES
    }

    /// The rows appended so far as one batch; the builder starts afresh.
    pub fn finish(&mut self) -> Result<RecordBatch, TableError> {
        let too_large = |e: arrow_schema::ArrowError| TableError::TooLarge(e.to_string());
        let pairs = StructArray::try_new(
            binding_fields(),
            vec![
                Arc::new(self.pair_variable.finish()) as ArrayRef,
                Arc::new(self.pair_value.finish()),
            ],
            None,
        )?;
        let binding_offsets = std::mem::replace(&mut self.binding, OffsetBufferBuilder::new(0))
            .try_finish()
            .map_err(|e| TableError::TooLarge(e.to_string()))?;
        let one = ListArray::try_new(binding_field(), binding_offsets, Arc::new(pairs), None)
            .map_err(too_large)?;
        let row_offsets = std::mem::replace(&mut self.bindings, OffsetBufferBuilder::new(0))
            .try_finish()
            .map_err(|e| TableError::TooLarge(e.to_string()))?;
        let bindings = ListArray::try_new(bindings_field(), row_offsets, Arc::new(one), None)
            .map_err(too_large)?;
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
            Arc::new(self.proofs.finish()),
            Arc::new(self.probability.finish()),
        ];
        self.rows = 0;
        self.bytes = 0;
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
mod tests {
    use super::*;
    use crate::ask::{AskOptions, Outcome};
    use crate::engine::Engine;
    use crate::kb::{Observability, test_window};
    use arrow_array::cast::AsArray;
    use arrow_array::types::{Float64Type, Int64Type};
    use arrow_array::{Array, StringArray};
    use logicpad::LogicPad;
    use perception::{Fact, Provenance};

    /// A scratch directory, removed when dropped.
    struct TempDir(PathBuf);

    impl TempDir {
        fn new(test: &str) -> TempDir {
            let dir =
                std::env::temp_dir().join(format!("logicrag-arrow-{}-{test}", std::process::id()));
            std::fs::create_dir_all(&dir).expect("temp dir");
            TempDir(dir)
        }
    }

    impl Drop for TempDir {
        fn drop(&mut self) {
            let _ = std::fs::remove_dir_all(&self.0);
        }
    }

    /// Every type in `t`, nested ones included.
    fn types(t: &DataType, out: &mut Vec<DataType>) {
        out.push(t.clone());
        match t {
            DataType::List(f) | DataType::LargeList(f) => types(f.data_type(), out),
            DataType::Struct(fields) => {
                for f in fields {
                    types(f.data_type(), out);
                }
            }
            _ => {}
        }
    }

    #[test]
    fn no_column_is_unsigned() {
        for schema in [facts_schema(), answers_schema()] {
            let mut all = Vec::new();
            for f in schema.fields() {
                types(f.data_type(), &mut all);
            }
            assert!(all.contains(&DataType::Int64), "{schema:?}");
            for t in &all {
                assert!(!t.is_unsigned_integer(), "{t} in {schema:?}");
            }
        }
    }

    fn fact(pred: &str, args: &[&str], provenance: Provenance) -> Fact {
        Fact {
            predicate: pred.into(),
            args: args.iter().map(|a| (*a).to_string()).collect(),
            provenance: Arc::new(provenance),
        }
    }

    fn provenance(measured: Option<f64>, threshold: Option<(&str, f64)>, note: &str) -> Provenance {
        Provenance {
            window: 3,
            frames: (30, 39),
            source: "sim:test".into(),
            measured,
            threshold: threshold.map(|(n, v)| (n.to_string(), v)),
            note: note.into(),
            probability: None,
        }
    }

    #[test]
    fn facts_keep_their_order_and_provenance_through_parquet() {
        let facts = [
            fact(
                "Moving",
                &["car_1"],
                provenance(
                    Some(3.25),
                    Some(("moving_speed_vehicle_mps", 0.7)),
                    "mean speed 3.25 m/s",
                ),
            ),
            fact("TypeOf", &["car_1", "Car"], provenance(None, None, "")),
            fact("Road", &[], provenance(None, None, "")),
        ];
        let place = WindowPlace {
            id: "test_000030",
            index: 3,
            first_frame: 30,
            last_frame: 39,
        };
        let input = crate::kb::WindowFacts::from(facts.to_vec());
        let mut b = FactsBuilder::new();
        b.push_window("sim:test", place, input.iter());
        assert_eq!(b.len(), 3);
        let batch = b.finish().expect("builds");
        assert!(b.is_empty());
        assert_eq!(batch.num_rows(), 3);

        let tmp = TempDir::new("facts");
        let path = tmp.0.join("facts.parquet");
        let rows =
            write_parquet(&path, facts_schema(), std::slice::from_ref(&batch)).expect("writes");
        assert_eq!(rows, 3);
        let back = read_parquet(&path).expect("reads");
        assert_eq!(back.len(), 1);
        let read = &back[0];
        assert_eq!(read.schema().fields(), facts_schema().fields());
        assert_eq!(read.columns(), batch.columns());

        // What the columns say, against the facts.
        let pred: &StringArray = read.column(5).as_string();
        assert_eq!(
            pred.iter().flatten().collect::<Vec<_>>(),
            ["Moving", "TypeOf", "Road"]
        );
        let args = read.column(6).as_list::<i32>();
        let arg1 = args.value(1);
        let arg1: &StringArray = arg1.as_string();
        assert_eq!(arg1.iter().flatten().collect::<Vec<_>>(), ["car_1", "Car"]);
        assert_eq!(args.value(2).len(), 0);
        let prov = read.column(7).as_struct();
        let measured = prov.column(4).as_primitive::<Float64Type>();
        assert_eq!(measured.value(0), 3.25);
        assert!(measured.is_null(1));
        let threshold = prov.column(5).as_struct();
        assert!(threshold.is_valid(0) && threshold.is_null(1));
        assert_eq!(
            threshold.column(0).as_string::<i32>().value(0),
            "moving_speed_vehicle_mps"
        );
        let note: &StringArray = prov.column(6).as_string();
        assert_eq!(note.value(0), "mean speed 3.25 m/s");
        assert!(note.is_null(1));
        let first = prov.column(1).as_primitive::<Int64Type>();
        assert_eq!(first.value(2), 30);
    }

    #[test]
    fn answers_keep_bindings_and_proofs_through_parquet() {
        let e = Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine");
        let kb = test_window(
            e.pad().program(),
            &[
                ("Vehicles", &["car_4"]),
                ("Vehicles", &["car_5"]),
                ("TypeOf", &["car_4", "Car"]),
                ("TypeOf", &["car_5", "Car"]),
                ("Moving", &["car_4"]),
            ],
        );
        let queries = [
            "TypeOf(x, y)",
            "Moving(x)",
            "Flying(x)",
            "TypeOf(car_4, Car)",
        ];
        let results: Vec<AskResult> = queries
            .iter()
            .map(|q| e.ask(&kb, &e.prepare_query(q), AskOptions::default()))
            .collect();
        assert_eq!(results[0].answer, Outcome::Yes);
        assert_eq!(results[2].answer, Outcome::Invalid);
        let mut b = AnswersBuilder::new(true);
        for (i, r) in results.iter().enumerate() {
            let proofs = proofs_json(r).expect("renders");
            let question = (i == 1).then_some("Is a car moving?");
            b.push("sim:test", question, i, r, Some(&proofs));
        }
        let batch = b.finish().expect("builds");
        let tmp = TempDir::new("answers");
        let path = tmp.0.join("answers.parquet");
        write_parquet(&path, answers_schema(), std::slice::from_ref(&batch)).expect("writes");
        let back = read_parquet(&path).expect("reads");
        let read = &back[0];
        assert_eq!(read.schema().fields(), answers_schema().fields());
        assert_eq!(read.columns(), batch.columns());

        let question: &StringArray = read.column(4).as_string();
        assert!(question.is_null(0));
        assert_eq!(question.value(1), "Is a car moving?");
        let answer: &StringArray = read.column(7).as_string();
        assert_eq!(
            answer.iter().flatten().collect::<Vec<_>>(),
            ["yes", "yes", "invalid", "yes"]
        );
        let count = read.column(8).as_primitive::<Int64Type>();
        assert_eq!(count.value(0), 2);
        // Bindings: row 0 has two, each `[(x, car_…), (y, Car)]`, sorted as
        // the answer lists them.
        let bindings = read.column(10).as_list::<i32>();
        let row0 = bindings.value(0);
        let row0 = row0.as_list::<i32>();
        assert_eq!(row0.len(), 2);
        for (i, binding) in results[0].bindings.iter().enumerate() {
            let pairs = row0.value(i);
            let pairs = pairs.as_struct();
            let vars: &StringArray = pairs.column(0).as_string();
            let values: &StringArray = pairs.column(1).as_string();
            let got: Vec<(String, String)> = vars
                .iter()
                .zip(values.iter())
                .map(|(a, b)| (a.unwrap_or("").into(), b.unwrap_or("").into()))
                .collect();
            assert_eq!(&got, binding);
        }
        // A ground query: one binding with no pairs.
        assert_eq!(bindings.value(3).len(), results[3].bindings.len());
        let reasons = read.column(11).as_list::<i32>();
        assert!(!reasons.value(2).is_empty(), "invalid says why");
        let proofs: &StringArray = read.column(12).as_string();
        let parsed: serde_json::Value = serde_json::from_str(proofs.value(0)).expect("json");
        assert_eq!(
            parsed,
            serde_json::to_value(&results[0].proofs).expect("json")
        );

        // Without proofs, the column is null.
        let mut b = AnswersBuilder::new(false);
        b.push("sim:test", None, 0, &results[0], Some("[]"));
        let batch = b.finish().expect("builds");
        assert!(batch.column(12).is_null(0));
    }

    #[test]
    fn window_ids_that_cannot_be_file_names_are_refused() {
        let dir = Path::new("/tmp/x");
        assert_eq!(
            window_file(dir, "0000_000010").expect("fine"),
            dir.join("0000_000010.parquet")
        );
        for bad in ["", "..", ".hidden", "a/b", "a\\b", "a b"] {
            assert!(window_file(dir, bad).is_err(), "{bad}");
        }
    }
}
