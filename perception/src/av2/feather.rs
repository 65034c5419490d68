//! Feather v2 (Arrow IPC file) tables of an Argoverse 2 log: the cuboid
//! annotations and the ego's city pose, read with the Arrow project's IPC
//! crate (LZ4 or zstd compressed, as pyarrow writes them).
//!
//! A Feather file is untrusted input: before the Arrow reader sees it, a
//! preflight walks its footer and message headers and rejects blocks and
//! buffers that point outside the file, negative lengths and compressed
//! buffers that announce an absurd decompressed size — inputs on which the
//! reader would allocate without bound or panic. Every error names the file.

use std::io::Cursor;
use std::path::Path;

use arrow_array::cast::AsArray;
use arrow_array::types::{Float32Type, Float64Type, Int64Type, TimestampNanosecondType};
use arrow_array::{Array, ArrayRef, RecordBatch};
use arrow_schema::{DataType, SchemaRef, TimeUnit};

use crate::error::PerceptionError;
use crate::model::Skipped;

/// Magic bytes at both ends of an Arrow IPC file.
const MAGIC: &[u8; 6] = b"ARROW1";

/// Largest Feather file read (bytes): far above any AV2 log table (the
/// annotations of a 15 s log are under 1 MB).
pub const MAX_FEATHER_BYTES: u64 = 1 << 30;

/// Decompressed bytes a file may announce: this many times its own size, or
/// [`MIN_DECODED_BUDGET`] for small files. LZ4 cannot expand more than about
/// 255 times; zstd can, but not on real tables.
const DECODED_PER_FILE_BYTE: u64 = 256;
/// Decompressed-size budget of small files.
const MIN_DECODED_BUDGET: u64 = 64 << 20;

/// A Feather file's schema and record batches.
#[derive(Debug, Clone)]
pub struct FeatherTable {
    /// The schema.
    pub schema: SchemaRef,
    /// The record batches, in file order.
    pub batches: Vec<RecordBatch>,
}

impl FeatherTable {
    /// Rows over all batches.
    pub fn num_rows(&self) -> usize {
        self.batches.iter().map(RecordBatch::num_rows).sum()
    }
}

/// Reads a Feather v2 (Arrow IPC file) table from disk.
pub fn read_feather(path: &Path) -> Result<FeatherTable, PerceptionError> {
    let meta = std::fs::metadata(path).map_err(|e| PerceptionError::io(path, e))?;
    if meta.len() > MAX_FEATHER_BYTES {
        return Err(file_err(
            path,
            format!(
                "{} bytes is more than the {MAX_FEATHER_BYTES} bytes a Feather table may have",
                meta.len()
            ),
        ));
    }
    let bytes = std::fs::read(path).map_err(|e| PerceptionError::io(path, e))?;
    parse_feather(&bytes, path)
}

/// Parses a Feather v2 (Arrow IPC file) table held in memory; `origin`
/// names it in errors.
pub fn parse_feather(bytes: &[u8], origin: &Path) -> Result<FeatherTable, PerceptionError> {
    preflight(bytes).map_err(|m| {
        file_err(
            origin,
            format!("not a readable Feather v2 (Arrow IPC) file: {m}"),
        )
    })?;
    // The preflight rules out the inputs known to make the reader panic; a
    // panic on some other malformed input is still an error for this file,
    // never a crash of the caller.
    let decoded = std::panic::catch_unwind(|| -> Result<FeatherTable, String> {
        let reader = arrow_ipc::reader::FileReader::try_new(Cursor::new(bytes), None)
            .map_err(|e| e.to_string())?;
        let schema = reader.schema();
        let mut batches = Vec::with_capacity(reader.num_batches());
        for b in reader {
            batches.push(b.map_err(|e| e.to_string())?);
        }
        Ok(FeatherTable { schema, batches })
    });
    match decoded {
        Ok(Ok(t)) => Ok(t),
        Ok(Err(m)) => Err(file_err(
            origin,
            format!("cannot read the Feather (Arrow IPC) table: {m}"),
        )),
        Err(_) => Err(file_err(
            origin,
            "cannot read the Feather (Arrow IPC) table: the Arrow reader failed on malformed data"
                .to_string(),
        )),
    }
}

fn file_err(path: &Path, message: String) -> PerceptionError {
    PerceptionError::File {
        path: path.to_path_buf(),
        message,
    }
}

fn le_i32(b: &[u8], at: usize) -> Option<i32> {
    b.get(at..at.checked_add(4)?)
        .and_then(|s| s.try_into().ok())
        .map(i32::from_le_bytes)
}

fn le_i64(b: &[u8], at: usize) -> Option<i64> {
    b.get(at..at.checked_add(8)?)
        .and_then(|s| s.try_into().ok())
        .map(i64::from_le_bytes)
}

/// Checks the file's framing before the Arrow reader trusts it: magic
/// bytes, footer, every block inside the file with non-negative lengths,
/// every message a valid flatbuffer whose buffers lie inside its body, and
/// the announced decompressed sizes within budget.
fn preflight(bytes: &[u8]) -> Result<(), String> {
    let n = bytes.len();
    if n < 2 * MAGIC.len() + 6
        || &bytes[..MAGIC.len()] != MAGIC
        || &bytes[n - MAGIC.len()..] != MAGIC
    {
        return Err(
            "expected the Arrow IPC magic bytes `ARROW1` at its start and end (Feather v1 files are not read)"
                .into(),
        );
    }
    let footer_len = le_i32(bytes, n - 10).ok_or("truncated footer")?;
    let footer_len = usize::try_from(footer_len).map_err(|_| "negative footer length")?;
    let footer_start = (n - 10)
        .checked_sub(footer_len)
        .filter(|s| *s >= 8)
        .ok_or("footer length larger than the file")?;
    let footer = arrow_ipc::root_as_footer(&bytes[footer_start..n - 10])
        .map_err(|e| format!("malformed footer: {e}"))?;
    let budget = (n as u64)
        .saturating_mul(DECODED_PER_FILE_BYTE)
        .max(MIN_DECODED_BUDGET);
    let mut decoded = 0u64;
    let blocks = footer
        .recordBatches()
        .into_iter()
        .flatten()
        .chain(footer.dictionaries().into_iter().flatten());
    for (k, block) in blocks.enumerate() {
        let offset =
            usize::try_from(block.offset()).map_err(|_| format!("block {k}: negative offset"))?;
        let meta_len = usize::try_from(block.metaDataLength())
            .map_err(|_| format!("block {k}: negative metadata length"))?;
        let body_len = usize::try_from(block.bodyLength())
            .map_err(|_| format!("block {k}: negative body length"))?;
        let body_start = offset
            .checked_add(meta_len)
            .filter(|e| *e <= footer_start)
            .ok_or_else(|| format!("block {k}: metadata outside the file"))?;
        let body_end = body_start
            .checked_add(body_len)
            .filter(|e| *e <= footer_start)
            .ok_or_else(|| format!("block {k}: body outside the file"))?;
        // Encapsulated message: [0xFFFFFFFF] i32 length, flatbuffer.
        let mut at = offset;
        let mut len = le_i32(bytes, at).ok_or_else(|| format!("block {k}: truncated message"))?;
        at += 4;
        if len == -1 {
            len = le_i32(bytes, at).ok_or_else(|| format!("block {k}: truncated message"))?;
            at += 4;
        }
        let len =
            usize::try_from(len).map_err(|_| format!("block {k}: negative message length"))?;
        let msg_end = at
            .checked_add(len)
            .filter(|e| *e <= body_start)
            .ok_or_else(|| format!("block {k}: message longer than its block"))?;
        let msg = arrow_ipc::root_as_message(&bytes[at..msg_end])
            .map_err(|e| format!("block {k}: malformed message: {e}"))?;
        let batch = msg
            .header_as_record_batch()
            .or_else(|| msg.header_as_dictionary_batch().and_then(|d| d.data()));
        let Some(batch) = batch else { continue };
        let body = &bytes[body_start..body_end];
        let compressed = batch.compression().is_some();
        let mut body_bytes = 0u64;
        for (j, buf) in batch.buffers().into_iter().flatten().enumerate() {
            let (o, l) = (buf.offset(), buf.length());
            let (Ok(o), Ok(l)) = (usize::try_from(o), usize::try_from(l)) else {
                return Err(format!(
                    "block {k}: buffer {j} has a negative offset or length"
                ));
            };
            if o.checked_add(l).is_none_or(|e| e > body.len()) {
                return Err(format!("block {k}: buffer {j} lies outside its body"));
            }
            if compressed && l >= 8 {
                let size = le_i64(body, o).unwrap_or(0);
                if size > 0 {
                    decoded = decoded.saturating_add(size as u64);
                    body_bytes = body_bytes.saturating_add(size as u64);
                } else if size == -1 {
                    // Stored uncompressed after the 8-byte prefix.
                    body_bytes = body_bytes.saturating_add(l as u64 - 8);
                }
            } else {
                body_bytes = body_bytes.saturating_add(l as u64);
            }
            if decoded > budget {
                return Err(format!(
                    "block {k}: compressed buffers announce more than {budget} decompressed bytes"
                ));
            }
        }
        // Rows need bytes: a column of n rows holds at least n bits unless
        // it is all nulls of the Null type, which AV2 tables never have.
        let rows_cap = body_bytes.saturating_mul(8).max(4096);
        if u64::try_from(batch.length()).map_or(true, |r| r > rows_cap) {
            return Err(format!(
                "block {k}: {} rows announced for {body_bytes} bytes of column data",
                batch.length()
            ));
        }
        for node in batch.nodes().into_iter().flatten() {
            if u64::try_from(node.length()).map_or(true, |r| r > rows_cap) || node.null_count() < 0
            {
                return Err(format!(
                    "block {k}: a column announces {} values for {body_bytes} bytes of data",
                    node.length()
                ));
            }
        }
    }
    Ok(())
}

/// The Arrow types a column may have, for error messages.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ColumnKind {
    /// Signed 64-bit integers (or nanosecond timestamps).
    Int64,
    /// Floating point (double or float).
    Float,
    /// Strings (utf8, large utf8, utf8 view or a dictionary of those).
    Utf8,
}

impl ColumnKind {
    fn describe(self) -> &'static str {
        match self {
            ColumnKind::Int64 => "int64",
            ColumnKind::Float => "double",
            ColumnKind::Utf8 => "string (utf8, large_utf8 or dictionary<_, utf8>)",
        }
    }
}

/// One column of one batch, typed, with per-row access.
enum Col<'a> {
    I64(&'a arrow_array::PrimitiveArray<Int64Type>),
    Ts(&'a arrow_array::PrimitiveArray<TimestampNanosecondType>),
    F64(&'a arrow_array::PrimitiveArray<Float64Type>),
    F32(&'a arrow_array::PrimitiveArray<Float32Type>),
    Str(&'a arrow_array::StringArray),
    LargeStr(&'a arrow_array::LargeStringArray),
    StrView(&'a arrow_array::StringViewArray),
    Dict {
        array: &'a ArrayRef,
        keys: Vec<usize>,
        values: Box<Col<'a>>,
    },
}

impl Col<'_> {
    fn i64(&self, row: usize) -> Option<i64> {
        match self {
            Col::I64(a) => a.is_valid(row).then(|| a.value(row)),
            Col::Ts(a) => a.is_valid(row).then(|| a.value(row)),
            _ => None,
        }
    }

    fn f64(&self, row: usize) -> Option<f64> {
        match self {
            Col::F64(a) => a.is_valid(row).then(|| a.value(row)),
            Col::F32(a) => a.is_valid(row).then(|| f64::from(a.value(row))),
            _ => None,
        }
    }

    fn str(&self, row: usize) -> Option<&str> {
        match self {
            Col::Str(a) => a.is_valid(row).then(|| a.value(row)),
            Col::LargeStr(a) => a.is_valid(row).then(|| a.value(row)),
            Col::StrView(a) => a.is_valid(row).then(|| a.value(row)),
            Col::Dict {
                array,
                keys,
                values,
            } => {
                if array.is_null(row) {
                    return None;
                }
                values.str(*keys.get(row)?)
            }
            _ => None,
        }
    }
}

/// Finds `name` in `batch` with one of the types `kind` allows.
fn column<'a>(
    batch: &'a RecordBatch,
    name: &str,
    kind: ColumnKind,
    origin: &Path,
) -> Result<Option<Col<'a>>, PerceptionError> {
    let Some(array) = batch.column_by_name(name) else {
        return Ok(None);
    };
    typed(array, kind).map(Some).ok_or_else(|| {
        file_err(
            origin,
            format!(
                "column `{name}` has type {}, expected {}",
                array.data_type(),
                kind.describe()
            ),
        )
    })
}

fn typed(array: &ArrayRef, kind: ColumnKind) -> Option<Col<'_>> {
    match (kind, array.data_type()) {
        (ColumnKind::Int64, DataType::Int64) => array.as_primitive_opt().map(Col::I64),
        (ColumnKind::Int64, DataType::Timestamp(TimeUnit::Nanosecond, _)) => {
            array.as_primitive_opt().map(Col::Ts)
        }
        (ColumnKind::Float, DataType::Float64) => array.as_primitive_opt().map(Col::F64),
        (ColumnKind::Float, DataType::Float32) => array.as_primitive_opt().map(Col::F32),
        (ColumnKind::Utf8, DataType::Utf8) => array.as_string_opt::<i32>().map(Col::Str),
        (ColumnKind::Utf8, DataType::LargeUtf8) => array.as_string_opt::<i64>().map(Col::LargeStr),
        (ColumnKind::Utf8, DataType::Utf8View) => array.as_string_view_opt().map(Col::StrView),
        (ColumnKind::Utf8, DataType::Dictionary(_, _)) => {
            let dict = array.as_any_dictionary_opt()?;
            let values = dict.values();
            let inner = match values.data_type() {
                DataType::Utf8 | DataType::LargeUtf8 | DataType::Utf8View => typed(values, kind)?,
                _ => return None,
            };
            // `normalized_keys` needs a value; an empty dictionary leaves
            // every row null (`keys` empty: `str` answers None).
            let keys = if values.is_empty() {
                Vec::new()
            } else {
                dict.normalized_keys()
            };
            Some(Col::Dict {
                array,
                keys,
                values: Box::new(inner),
            })
        }
        _ => None,
    }
}

/// Checks the table has every required column, naming the first missing
/// one with its expected type.
fn require(
    table: &FeatherTable,
    cols: &[(&str, ColumnKind)],
    origin: &Path,
) -> Result<(), PerceptionError> {
    for (name, kind) in cols {
        if table.schema.field_with_name(name).is_err() {
            let have: Vec<&str> = table
                .schema
                .fields()
                .iter()
                .map(|f| f.name().as_str())
                .collect();
            return Err(file_err(
                origin,
                format!(
                    "missing column `{name}` ({}); the table has: {}",
                    kind.describe(),
                    have.join(", ")
                ),
            ));
        }
    }
    Ok(())
}

/// The cuboid columns, in the order of [`AnnotationRow::values`].
const CUBOID_COLUMNS: [&str; 10] = [
    "length_m", "width_m", "height_m", "qw", "qx", "qy", "qz", "tx_m", "ty_m", "tz_m",
];

/// One row of an AV2 annotations table: a cuboid in the ego frame at one
/// timestamp (x forward, y left, z up; `t*` the cuboid's centre).
#[derive(Debug, Clone, PartialEq)]
pub struct AnnotationRow {
    /// Row in the file (0-based, over all record batches).
    pub row: usize,
    /// Sweep timestamp, nanoseconds.
    pub timestamp_ns: i64,
    /// The track's uuid.
    pub track_uuid: String,
    /// The AV2 category (`REGULAR_VEHICLE`, …).
    pub category: String,
    /// `[length_m, width_m, height_m, qw, qx, qy, qz, tx_m, ty_m, tz_m]`.
    pub values: [f64; 10],
}

impl AnnotationRow {
    /// Length along the cuboid's heading, metres.
    pub fn length_m(&self) -> f64 {
        self.values[0]
    }
    /// Width, metres.
    pub fn width_m(&self) -> f64 {
        self.values[1]
    }
    /// Height, metres.
    pub fn height_m(&self) -> f64 {
        self.values[2]
    }
    /// Rotation quaternion `[qw, qx, qy, qz]` (ego frame ← cuboid frame).
    pub fn quaternion(&self) -> [f64; 4] {
        [
            self.values[3],
            self.values[4],
            self.values[5],
            self.values[6],
        ]
    }
    /// Centre `[tx, ty, tz]` in the ego frame, metres.
    pub fn centre(&self) -> [f64; 3] {
        [self.values[7], self.values[8], self.values[9]]
    }
}

/// The readable rows of an annotations table and the rows skipped.
#[derive(Debug, Clone, Default)]
pub struct Annotations {
    /// Rows in file order.
    pub rows: Vec<AnnotationRow>,
    /// Rows skipped (nulls, non-finite or non-positive values), counted by
    /// reason with the first example (`file row N`).
    pub skipped: Vec<Skipped>,
}

/// Adds one skipped row under `reason`, keeping the first example.
pub(crate) fn count_skip(
    skipped: &mut Vec<Skipped>,
    reason: String,
    example: impl FnOnce() -> String,
) {
    if let Some(s) = skipped.iter_mut().find(|s| s.reason == reason) {
        s.count += 1;
    } else {
        skipped.push(Skipped {
            reason,
            count: 1,
            example: example(),
        });
    }
}

/// Reads an AV2 annotations table (`annotations.feather`,
/// `annotations_with_ego.feather`).
pub fn read_annotations(path: &Path) -> Result<Annotations, PerceptionError> {
    annotations_of(&read_feather(path)?, path)
}

/// Parses an AV2 annotations table held in memory (the fuzz target's entry).
pub fn parse_annotations(bytes: &[u8], origin: &Path) -> Result<Annotations, PerceptionError> {
    annotations_of(&parse_feather(bytes, origin)?, origin)
}

/// The annotation rows of a table: a row with a null id, or a null,
/// non-finite or non-positive-size number is skipped and counted.
pub fn annotations_of(table: &FeatherTable, origin: &Path) -> Result<Annotations, PerceptionError> {
    let mut required = vec![
        ("timestamp_ns", ColumnKind::Int64),
        ("track_uuid", ColumnKind::Utf8),
        ("category", ColumnKind::Utf8),
    ];
    required.extend(CUBOID_COLUMNS.iter().map(|c| (*c, ColumnKind::Float)));
    require(table, &required, origin)?;
    let file = origin.file_name().map_or_else(
        || origin.display().to_string(),
        |f| f.to_string_lossy().into_owned(),
    );
    let mut out = Annotations {
        rows: Vec::with_capacity(table.num_rows()),
        skipped: Vec::new(),
    };
    let mut base = 0usize;
    for batch in &table.batches {
        let get = |name: &str, kind| {
            column(batch, name, kind, origin)?
                .ok_or_else(|| file_err(origin, format!("a record batch lacks column `{name}`")))
        };
        let ts = get("timestamp_ns", ColumnKind::Int64)?;
        let uuid = get("track_uuid", ColumnKind::Utf8)?;
        let cat = get("category", ColumnKind::Utf8)?;
        let nums = CUBOID_COLUMNS
            .iter()
            .map(|c| get(c, ColumnKind::Float))
            .collect::<Result<Vec<_>, _>>()?;
        for r in 0..batch.num_rows() {
            let row = base + r;
            let example = || format!("{file} row {row}");
            let (Some(t), Some(u), Some(c)) = (ts.i64(r), uuid.str(r), cat.str(r)) else {
                count_skip(
                    &mut out.skipped,
                    "null timestamp_ns, track_uuid or category".into(),
                    example,
                );
                continue;
            };
            let mut values = [0.0; 10];
            let mut bad = None;
            for (k, col) in nums.iter().enumerate() {
                match col.f64(r) {
                    Some(v) if v.is_finite() => values[k] = v,
                    _ => {
                        bad = Some(CUBOID_COLUMNS[k]);
                        break;
                    }
                }
            }
            if let Some(name) = bad {
                count_skip(
                    &mut out.skipped,
                    format!("null or non-finite `{name}`"),
                    example,
                );
                continue;
            }
            if values[..3].iter().any(|v| *v <= 0.0) {
                count_skip(
                    &mut out.skipped,
                    "non-positive cuboid size (length_m, width_m or height_m)".into(),
                    example,
                );
                continue;
            }
            out.rows.push(AnnotationRow {
                row,
                timestamp_ns: t,
                track_uuid: u.to_string(),
                category: c.to_string(),
                values,
            });
        }
        base += batch.num_rows();
    }
    Ok(out)
}

/// One row of `city_SE3_egovehicle.feather`: the ego's pose in the city
/// frame (city ← ego).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct PoseRow {
    /// Timestamp, nanoseconds.
    pub timestamp_ns: i64,
    /// Rotation quaternion `[qw, qx, qy, qz]`.
    pub quaternion: [f64; 4],
    /// Translation `[tx, ty, tz]`, metres.
    pub translation: [f64; 3],
}

/// Reads an AV2 ego pose table (`city_SE3_egovehicle.feather`).
pub fn read_poses(path: &Path) -> Result<Vec<PoseRow>, PerceptionError> {
    poses_of(&read_feather(path)?, path)
}

/// Parses an AV2 ego pose table held in memory.
pub fn parse_poses(bytes: &[u8], origin: &Path) -> Result<Vec<PoseRow>, PerceptionError> {
    poses_of(&parse_feather(bytes, origin)?, origin)
}

/// The pose rows of a table, in file order. A null or non-finite value is
/// an error naming the row: a pose is not an object to skip, and every
/// frame's facts depend on it.
pub fn poses_of(table: &FeatherTable, origin: &Path) -> Result<Vec<PoseRow>, PerceptionError> {
    const NUMS: [&str; 7] = ["qw", "qx", "qy", "qz", "tx_m", "ty_m", "tz_m"];
    let mut required = vec![("timestamp_ns", ColumnKind::Int64)];
    required.extend(NUMS.iter().map(|c| (*c, ColumnKind::Float)));
    require(table, &required, origin)?;
    let mut out = Vec::with_capacity(table.num_rows());
    let mut base = 0usize;
    for batch in &table.batches {
        let get = |name: &str, kind| {
            column(batch, name, kind, origin)?
                .ok_or_else(|| file_err(origin, format!("a record batch lacks column `{name}`")))
        };
        let ts = get("timestamp_ns", ColumnKind::Int64)?;
        let nums = NUMS
            .iter()
            .map(|c| get(c, ColumnKind::Float))
            .collect::<Result<Vec<_>, _>>()?;
        for r in 0..batch.num_rows() {
            let row = base + r;
            let t = ts
                .i64(r)
                .ok_or_else(|| file_err(origin, format!("row {row}: null `timestamp_ns`")))?;
            let mut v = [0.0; 7];
            for (k, col) in nums.iter().enumerate() {
                v[k] = col.f64(r).filter(|x| x.is_finite()).ok_or_else(|| {
                    file_err(
                        origin,
                        format!(
                            "row {row} (timestamp_ns {t}): `{}` is null or not finite; an ego pose needs finite numbers",
                            NUMS[k]
                        ),
                    )
                })?;
            }
            out.push(PoseRow {
                timestamp_ns: t,
                quaternion: [v[0], v[1], v[2], v[3]],
                translation: [v[4], v[5], v[6]],
            });
        }
        base += batch.num_rows();
    }
    Ok(out)
}
