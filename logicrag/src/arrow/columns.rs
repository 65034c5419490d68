//! Column builders shared by the tables: a `list<string>` column
//! ([`StrLists`]) and the provenance struct ([`ProvenanceColumns`]), which
//! the facts table and the proof nodes of the answers table both carry.

use super::{TableError, col, int, list_array};
use arrow_array::builder::{Float64Builder, Int64Builder, OffsetBufferBuilder, StringBuilder};
use arrow_array::{ArrayRef, StructArray};
use arrow_schema::{DataType, Field, Fields};
use perception::Provenance;
use std::sync::Arc;

/// The provenance struct's fields (a fact's `provenance` in JSON).
pub(super) fn provenance_fields() -> Fields {
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

/// A `list<string>` column being built.
#[derive(Debug)]
pub(super) struct StrLists {
    offsets: OffsetBufferBuilder<i32>,
    values: StringBuilder,
}

impl StrLists {
    pub(super) fn new() -> StrLists {
        StrLists {
            offsets: OffsetBufferBuilder::new(0),
            values: StringBuilder::new(),
        }
    }

    /// Appends one list; returns the bytes of text it added.
    pub(super) fn push<'a>(&mut self, items: impl IntoIterator<Item = &'a str>) -> usize {
        let (mut n, mut bytes) = (0, 0);
        for s in items {
            self.values.append_value(s);
            n += 1;
            bytes += s.len();
        }
        self.offsets.push_length(n);
        bytes
    }

    pub(super) fn finish(&mut self) -> Result<ArrayRef, TableError> {
        let values: ArrayRef = Arc::new(self.values.finish());
        let item = Arc::new(Field::new("item", DataType::Utf8, false));
        Ok(Arc::new(list_array(item, &mut self.offsets, values, None)?))
    }
}

/// A provenance struct column being built ([`provenance_fields`]); a row
/// without provenance is a null struct (its children hold placeholders,
/// as Arrow wants a slot in each).
#[derive(Debug)]
pub(super) struct ProvenanceColumns {
    window: Int64Builder,
    first: Int64Builder,
    last: Int64Builder,
    source: StringBuilder,
    measured: Float64Builder,
    threshold_name: StringBuilder,
    threshold_value: Float64Builder,
    /// Which rows have a threshold.
    threshold_valid: Vec<bool>,
    note: StringBuilder,
    probability: Float64Builder,
    /// Which rows have a provenance.
    valid: Vec<bool>,
}

impl ProvenanceColumns {
    pub(super) fn new() -> ProvenanceColumns {
        ProvenanceColumns {
            window: Int64Builder::new(),
            first: Int64Builder::new(),
            last: Int64Builder::new(),
            source: StringBuilder::new(),
            measured: Float64Builder::new(),
            threshold_name: StringBuilder::new(),
            threshold_value: Float64Builder::new(),
            threshold_valid: Vec::new(),
            note: StringBuilder::new(),
            probability: Float64Builder::new(),
            valid: Vec::new(),
        }
    }

    /// Appends one row (`None`: a null struct); returns the bytes of text
    /// it added.
    pub(super) fn push(&mut self, p: Option<&Provenance>) -> usize {
        self.valid.push(p.is_some());
        let Some(p) = p else {
            self.window.append_value(0);
            self.first.append_value(0);
            self.last.append_value(0);
            self.source.append_value("");
            self.measured.append_null();
            self.push_threshold(None);
            self.note.append_null();
            self.probability.append_null();
            return 0;
        };
        self.window.append_value(int(p.window));
        self.first.append_value(int(p.frames.0));
        self.last.append_value(int(p.frames.1));
        self.source.append_value(&*p.source);
        self.measured.append_option(p.measured);
        self.push_threshold(p.threshold.as_ref());
        if p.note.is_empty() {
            self.note.append_null();
        } else {
            self.note.append_value(&p.note);
        }
        self.probability.append_option(p.probability);
        p.source.len() + p.note.len() + p.threshold.as_ref().map_or(0, |t| t.0.len())
    }

    fn push_threshold(&mut self, t: Option<&(String, f64)>) {
        match t {
            Some((name, value)) => {
                self.threshold_name.append_value(name);
                self.threshold_value.append_value(*value);
                self.threshold_valid.push(true);
            }
            // A null struct's children still need a slot each.
            None => {
                self.threshold_name.append_value("");
                self.threshold_value.append_value(0.0);
                self.threshold_valid.push(false);
            }
        }
    }

    /// The rows appended so far; the builder starts afresh. Without a
    /// null row the struct has no null buffer.
    pub(super) fn finish(&mut self) -> Result<StructArray, TableError> {
        let threshold = StructArray::try_new(
            threshold_fields(),
            vec![
                Arc::new(self.threshold_name.finish()) as ArrayRef,
                Arc::new(self.threshold_value.finish()),
            ],
            Some(std::mem::take(&mut self.threshold_valid).into()),
        )?;
        let valid = std::mem::take(&mut self.valid);
        let nulls = valid.contains(&false).then(|| valid.into());
        Ok(StructArray::try_new(
            provenance_fields(),
            vec![
                Arc::new(self.window.finish()) as ArrayRef,
                Arc::new(self.first.finish()),
                Arc::new(self.last.finish()),
                Arc::new(self.source.finish()),
                Arc::new(self.measured.finish()),
                Arc::new(threshold),
                Arc::new(self.note.finish()),
                Arc::new(self.probability.finish()),
            ],
            nulls,
        )?)
    }
}
