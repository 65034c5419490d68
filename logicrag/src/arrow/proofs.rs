//! The answers table's `proofs` column: each answer's proof trees as a
//! list of typed nodes, so that SQL reads a proof's predicates, rules and
//! provenance without parsing JSON.
//!
//! `proofs` is `list<list<struct>>`: one list per answer (in the order of
//! `bindings`), holding the nodes of that answer's proof trees (one tree
//! per query literal) in pre-order — a node, then its premises' subtrees
//! in order. A node names its `parent` by position in the same list (null
//! for a tree's root) and carries its `depth` (0 at a root): Arrow has no
//! recursive type, and a flat list with parent indices keeps any depth in
//! one fixed schema. [`read_proofs`] turns a row back into the trees.

use super::columns::{ProvenanceColumns, StrLists, provenance_fields};
use super::{TableError, col, int, list_array};
use crate::proof::{ProofNode, Step};
use arrow_array::builder::{
    BooleanBuilder, Float64Builder, Int64Builder, OffsetBufferBuilder, StringBuilder,
};
use arrow_array::cast::AsArray;
use arrow_array::types::{Float64Type, Int64Type};
use arrow_array::{Array, ArrayRef, StructArray};
use arrow_schema::{DataType, Field, FieldRef, Fields};
use perception::Provenance;
use std::sync::Arc;

/// One proof node's fields.
fn node_fields() -> Fields {
    Fields::from(vec![
        Field::new("parent", DataType::Int64, true),
        col("depth", DataType::Int64),
        col("fact", DataType::Utf8),
        Field::new("predicate", DataType::Utf8, true),
        col(
            "args",
            DataType::List(Arc::new(Field::new("item", DataType::Utf8, false))),
        ),
        col("negated", DataType::Boolean),
        col("kind", DataType::Utf8),
        Field::new("rule_line", DataType::Int64, true),
        Field::new("rule_text", DataType::Utf8, true),
        Field::new("doubt", DataType::Float64, true),
        Field::new("reason", DataType::Utf8, true),
        Field::new("provenance", DataType::Struct(provenance_fields()), true),
    ])
}

/// `list<struct<node>>`: one answer's nodes.
fn answer_field() -> FieldRef {
    Arc::new(Field::new("item", DataType::Struct(node_fields()), false))
}

/// `list<list<struct<node>>>`'s item: one row's answers.
fn row_field() -> FieldRef {
    Arc::new(Field::new("item", DataType::List(answer_field()), false))
}

/// The `proofs` column's type: `list<list<struct<node>>>`.
pub(super) fn proofs_type() -> DataType {
    DataType::List(row_field())
}

/// An atom of a proof: `¬Moving(car_1)` is negated `Moving` of
/// `[car_1]`; a `¬∃` formula has no predicate.
#[derive(Debug, PartialEq)]
struct Atom<'a> {
    negated: bool,
    predicate: Option<&'a str>,
    args: Vec<&'a str>,
}

/// The atom of a proof node's `fact` (`Pred(a, b)` as `GroundAtom`'s
/// `Display` writes it, `¬` in front for an absent one). Arguments are
/// split at `, ` outside double quotes, so a quoted constant holding a
/// comma stays whole.
fn atom(fact: &str) -> Atom<'_> {
    let (negated, rest) = match fact.strip_prefix('¬') {
        Some(rest) => (true, rest),
        None => (false, fact),
    };
    let parts = rest
        .strip_suffix(')')
        .and_then(|r| r.split_once('('))
        .filter(|(p, _)| {
            !p.is_empty()
                && p.chars()
                    .all(|c| c.is_alphanumeric() || c == '_' || c == '-')
        });
    let Some((predicate, inside)) = parts else {
        return Atom {
            negated,
            predicate: None,
            args: Vec::new(),
        };
    };
    let mut args = Vec::new();
    if !inside.is_empty() {
        let (mut start, mut quoted, mut escaped) = (0, false, false);
        let bytes = inside.as_bytes();
        for (i, &b) in bytes.iter().enumerate() {
            match b {
                _ if escaped => escaped = false,
                b'\\' if quoted => escaped = true,
                b'"' => quoted = !quoted,
                b',' if !quoted && bytes.get(i + 1) == Some(&b' ') => {
                    args.push(&inside[start..i]);
                    start = i + 2;
                }
                _ => {}
            }
        }
        args.push(&inside[start..]);
    }
    Atom {
        negated,
        predicate: Some(predicate),
        args,
    }
}

/// The `proofs` column being built.
#[derive(Debug)]
pub(super) struct ProofColumns {
    /// One offset per row into the answers; a row without proofs is null.
    rows: OffsetBufferBuilder<i32>,
    row_valid: Vec<bool>,
    /// One offset per answer into the nodes.
    answers: OffsetBufferBuilder<i32>,
    parent: Int64Builder,
    depth: Int64Builder,
    fact: StringBuilder,
    predicate: StringBuilder,
    args: StrLists,
    negated: BooleanBuilder,
    kind: StringBuilder,
    rule_line: Int64Builder,
    rule_text: StringBuilder,
    doubt: Float64Builder,
    reason: StringBuilder,
    provenance: ProvenanceColumns,
}

impl ProofColumns {
    pub(super) fn new() -> ProofColumns {
        ProofColumns {
            rows: OffsetBufferBuilder::new(0),
            row_valid: Vec::new(),
            answers: OffsetBufferBuilder::new(0),
            parent: Int64Builder::new(),
            depth: Int64Builder::new(),
            fact: StringBuilder::new(),
            predicate: StringBuilder::new(),
            args: StrLists::new(),
            negated: BooleanBuilder::new(),
            kind: StringBuilder::new(),
            rule_line: Int64Builder::new(),
            rule_text: StringBuilder::new(),
            doubt: Float64Builder::new(),
            reason: StringBuilder::new(),
            provenance: ProvenanceColumns::new(),
        }
    }

    /// Appends one row: each answer's proof (`None`: a null row); returns
    /// the bytes of text it added.
    pub(super) fn push(&mut self, proofs: Option<&[Vec<ProofNode>]>) -> usize {
        let Some(proofs) = proofs else {
            self.rows.push_length(0);
            self.row_valid.push(false);
            return 0;
        };
        let mut bytes = 0;
        // Pre-order with an explicit stack: a proof's depth is bounded by
        // its limits, not by this thread's stack.
        let mut stack: Vec<(&ProofNode, Option<i64>, i64)> = Vec::new();
        for trees in proofs {
            let mut n: i64 = 0;
            stack.extend(trees.iter().rev().map(|t| (t, None, 0)));
            while let Some((node, parent, depth)) = stack.pop() {
                bytes += self.push_node(node, parent, depth);
                stack.extend(node.premises.iter().rev().map(|p| (p, Some(n), depth + 1)));
                n += 1;
            }
            self.answers.push_length(usize::try_from(n).unwrap_or(0));
        }
        self.rows.push_length(proofs.len());
        self.row_valid.push(true);
        bytes
    }

    fn push_node(&mut self, node: &ProofNode, parent: Option<i64>, depth: i64) -> usize {
        // The typed atom the proof was built from; a fact known only as
        // text (a `¬∃` formula, a proof read back from a table) is read.
        let a = match node.fact.atom() {
            Some(t) => Atom {
                negated: node.fact.is_negated(),
                predicate: Some(t.pred),
                args: t.args.to_vec(),
            },
            None => atom(&node.fact),
        };
        self.parent.append_option(parent);
        self.depth.append_value(depth);
        self.fact.append_value(&node.fact);
        self.predicate.append_option(a.predicate);
        let mut bytes = node.fact.len() * 2 + self.args.push(a.args);
        self.negated.append_value(a.negated);
        let (kind, line, text, doubt, reason, provenance) = match &node.step {
            Step::Observed { provenance } => {
                ("observed", None, None, None, None, provenance.as_deref())
            }
            Step::Rule { line, text } => {
                ("rule", Some(int(*line)), Some(&**text), None, None, None)
            }
            Step::Absent { doubt } => (
                "absent",
                None,
                None,
                doubt.map(crate::belief::rounded),
                None,
                None,
            ),
            Step::Cut { reason } => ("cut", None, None, None, Some(reason.as_str()), None),
        };
        self.kind.append_value(kind);
        self.rule_line.append_option(line);
        self.rule_text.append_option(text);
        self.doubt.append_option(doubt);
        self.reason.append_option(reason);
        bytes += text.map_or(0, str::len) + reason.map_or(0, str::len);
        bytes + self.provenance.push(provenance)
    }

    /// The rows appended so far as the column; the builder starts afresh.
    pub(super) fn finish(&mut self) -> Result<ArrayRef, TableError> {
        let nodes = StructArray::try_new(
            node_fields(),
            vec![
                Arc::new(self.parent.finish()) as ArrayRef,
                Arc::new(self.depth.finish()),
                Arc::new(self.fact.finish()),
                Arc::new(self.predicate.finish()),
                self.args.finish()?,
                Arc::new(self.negated.finish()),
                Arc::new(self.kind.finish()),
                Arc::new(self.rule_line.finish()),
                Arc::new(self.rule_text.finish()),
                Arc::new(self.doubt.finish()),
                Arc::new(self.reason.finish()),
                Arc::new(self.provenance.finish()?),
            ],
            None,
        )?;
        let answers = list_array(answer_field(), &mut self.answers, Arc::new(nodes), None)?;
        let valid = std::mem::take(&mut self.row_valid);
        let nulls = valid.contains(&false).then_some(valid);
        Ok(Arc::new(list_array(
            row_field(),
            &mut self.rows,
            Arc::new(answers),
            nulls,
        )?))
    }
}

/// The proofs of row `row` of a `proofs` column (as [`super::answers_schema`]
/// has it): each answer's proof trees, as `ask --json` has them in its
/// `"proofs"` (an absent atom's doubt rounded as JSON writes it); `None`
/// for a null row (proofs not asked for).
pub fn read_proofs(
    column: &dyn Array,
    row: usize,
) -> Result<Option<Vec<Vec<ProofNode>>>, TableError> {
    let bad = |what: &str| TableError::Malformed(format!("proofs column: {what}"));
    let rows = column
        .as_list_opt::<i32>()
        .ok_or_else(|| bad("not a list"))?;
    if row >= rows.len() {
        return Err(bad(&format!("no row {row}")));
    }
    if rows.is_null(row) {
        return Ok(None);
    }
    let answers = rows.value(row);
    let answers = answers
        .as_list_opt::<i32>()
        .ok_or_else(|| bad("answers are not lists"))?;
    (0..answers.len())
        .map(|a| {
            let nodes = answers.value(a);
            let nodes = nodes
                .as_struct_opt()
                .ok_or_else(|| bad("nodes are not structs"))?;
            trees(nodes).map_err(|e| bad(&e))
        })
        .collect::<Result<Vec<_>, _>>()
        .map(Some)
}

/// One answer's nodes as its trees.
fn trees(nodes: &StructArray) -> Result<Vec<ProofNode>, String> {
    let column = |name: &str| {
        nodes
            .column_by_name(name)
            .ok_or_else(|| format!("no field `{name}`"))
    };
    let parent = column("parent")?
        .as_primitive_opt::<Int64Type>()
        .ok_or("`parent` is not int64")?;
    let fact = column("fact")?
        .as_string_opt::<i32>()
        .ok_or("`fact` is not a string")?;
    let kind = column("kind")?
        .as_string_opt::<i32>()
        .ok_or("`kind` is not a string")?;
    let rule_line = column("rule_line")?
        .as_primitive_opt::<Int64Type>()
        .ok_or("`rule_line` is not int64")?;
    let rule_text = column("rule_text")?
        .as_string_opt::<i32>()
        .ok_or("`rule_text` is not a string")?;
    let doubt = column("doubt")?
        .as_primitive_opt::<Float64Type>()
        .ok_or("`doubt` is not float64")?;
    let reason = column("reason")?
        .as_string_opt::<i32>()
        .ok_or("`reason` is not a string")?;
    let provenance = column("provenance")?
        .as_struct_opt()
        .ok_or("`provenance` is not a struct")?;
    let n = nodes.len();
    // Children are gathered last to first, so each list is reversed once.
    let mut kids: Vec<Vec<ProofNode>> = (0..n).map(|_| Vec::new()).collect();
    let mut roots = Vec::new();
    for i in (0..n).rev() {
        let step = match kind.value(i) {
            "observed" => Step::Observed {
                provenance: if provenance.is_null(i) {
                    None
                } else {
                    Some(Arc::new(read_provenance(provenance, i)?))
                },
            },
            "rule" => Step::Rule {
                line: usize::try_from(rule_line.value(i))
                    .map_err(|_| format!("node {i}: rule line {}", rule_line.value(i)))?,
                text: Arc::from(rule_text.value(i)),
            },
            "absent" => Step::Absent {
                doubt: doubt.is_valid(i).then(|| doubt.value(i)),
            },
            "cut" => Step::Cut {
                reason: reason.value(i).to_string(),
            },
            other => return Err(format!("node {i}: unknown kind `{other}`")),
        };
        let mut premises = std::mem::take(&mut kids[i]);
        premises.reverse();
        let node = ProofNode {
            fact: fact.value(i).to_string().into(),
            step,
            premises,
        };
        if parent.is_null(i) {
            roots.push(node);
        } else {
            let p = usize::try_from(parent.value(i))
                .ok()
                .filter(|&p| p < i)
                .ok_or_else(|| format!("node {i}: parent {}", parent.value(i)))?;
            kids[p].push(node);
        }
    }
    roots.reverse();
    Ok(roots)
}

/// Row `i` of a provenance struct column.
fn read_provenance(s: &StructArray, i: usize) -> Result<Provenance, String> {
    let int_at = |c: usize| -> Result<u32, String> {
        let v = s.column(c).as_primitive::<Int64Type>().value(i);
        u32::try_from(v).map_err(|_| format!("provenance value {v} out of range"))
    };
    let float_at = |c: usize| {
        let a = s.column(c).as_primitive::<Float64Type>();
        a.is_valid(i).then(|| a.value(i))
    };
    let threshold = s.column(5).as_struct();
    let note = s.column(6).as_string::<i32>();
    Ok(Provenance {
        window: int_at(0)?,
        frames: (int_at(1)?, int_at(2)?),
        source: Arc::from(s.column(3).as_string::<i32>().value(i)),
        measured: float_at(4),
        threshold: threshold.is_valid(i).then(|| {
            (
                threshold.column(0).as_string::<i32>().value(i).to_string(),
                threshold.column(1).as_primitive::<Float64Type>().value(i),
            )
        }),
        note: if note.is_valid(i) {
            note.value(i).to_string()
        } else {
            String::new()
        },
        probability: float_at(7),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn atoms_are_read_from_the_fact_text() {
        let a = |negated, predicate, args: &[&'static str]| Atom {
            negated,
            predicate,
            args: args.to_vec(),
        };
        assert_eq!(
            atom("TypeOf(car_1, Car)"),
            a(false, Some("TypeOf"), &["car_1", "Car"])
        );
        assert_eq!(atom("¬Moving(car_1)"), a(true, Some("Moving"), &["car_1"]));
        assert_eq!(atom("Road()"), a(false, Some("Road"), &[]));
        assert_eq!(
            atom(r#"Named("a, b", c)"#),
            a(false, Some("Named"), &[r#""a, b""#, "c"])
        );
        assert_eq!(
            atom(r#"Named("a\", b", c)"#),
            a(false, Some("Named"), &[r#""a\", b""#, "c"])
        );
        // A `¬∃` formula is no atom.
        assert_eq!(atom("¬∃y: (Road(y) ∧ On(ped_1, y))"), a(true, None, &[]));
    }
}
