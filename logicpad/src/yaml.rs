//! A YAML document as a tree of nodes that remember where they were written.
//!
//! serde-saphyr parses; [`Node`] keeps every key, sequence item and scalar
//! with its byte span, so the checker can point into the file.

use crate::diag::Span;
use serde::de::{self, Deserialize, Deserializer, MapAccess, SeqAccess, Visitor};
use serde_saphyr::Spanned;
use std::fmt;

/// A YAML node with the span of its text.
#[derive(Debug, Clone, PartialEq)]
pub(crate) struct Node {
    pub value: Value,
    pub span: Span,
}

/// The node's content. Scalars are kept as text (numbers and booleans are
/// rendered back to text: LogicPad has no typed scalars). Only `true` and
/// `false` are booleans: YAML 1.1's `on`, `off`, `yes`, `no` stay words,
/// as a phrase list such as `[on, on top of]` means them.
#[derive(Debug, Clone, PartialEq)]
pub(crate) enum Value {
    Null,
    Scalar(String),
    Seq(Vec<Node>),
    Map(Vec<(Node, Node)>),
}

impl Node {
    pub(crate) fn as_str(&self) -> Option<&str> {
        match &self.value {
            Value::Scalar(s) => Some(s),
            _ => None,
        }
    }
    pub(crate) fn kind(&self) -> &'static str {
        match self.value {
            Value::Null => "an empty value",
            Value::Scalar(_) => "a text value",
            Value::Seq(_) => "a list",
            Value::Map(_) => "a mapping",
        }
    }
    pub(crate) fn get(&self, key: &str) -> Option<&Node> {
        match &self.value {
            Value::Map(m) => m
                .iter()
                .find(|(k, _)| k.as_str() == Some(key))
                .map(|(_, v)| v),
            _ => None,
        }
    }
}

/// Raw content as deserialized (spans are attached by [`RawNode`]).
struct RawValue(Value);

struct RawNode(Spanned<RawValue>);

impl<'de> Deserialize<'de> for RawNode {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        Spanned::<RawValue>::deserialize(d).map(RawNode)
    }
}

fn to_node(n: RawNode) -> Node {
    let loc = n.0.referenced;
    let sp = loc.span();
    let start = sp.byte_offset().unwrap_or(0) as usize;
    let len = sp.byte_len().unwrap_or(0) as usize;
    Node {
        value: n.0.value.0,
        span: Span::new(start, start + len),
    }
}

impl<'de> Deserialize<'de> for RawValue {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ValueVisitor)
    }
}

struct ValueVisitor;

impl<'de> Visitor<'de> for ValueVisitor {
    type Value = RawValue;
    fn expecting(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str("a YAML value")
    }
    fn visit_bool<E: de::Error>(self, v: bool) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v.to_string())))
    }
    fn visit_i64<E: de::Error>(self, v: i64) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v.to_string())))
    }
    fn visit_u64<E: de::Error>(self, v: u64) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v.to_string())))
    }
    fn visit_f64<E: de::Error>(self, v: f64) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v.to_string())))
    }
    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v.to_string())))
    }
    fn visit_string<E: de::Error>(self, v: String) -> Result<RawValue, E> {
        Ok(RawValue(Value::Scalar(v)))
    }
    fn visit_unit<E: de::Error>(self) -> Result<RawValue, E> {
        Ok(RawValue(Value::Null))
    }
    fn visit_none<E: de::Error>(self) -> Result<RawValue, E> {
        Ok(RawValue(Value::Null))
    }
    fn visit_some<D: Deserializer<'de>>(self, d: D) -> Result<RawValue, D::Error> {
        RawValue::deserialize(d)
    }
    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<RawValue, A::Error> {
        let mut out = Vec::new();
        while let Some(n) = seq.next_element::<RawNode>()? {
            out.push(to_node(n));
        }
        Ok(RawValue(Value::Seq(out)))
    }
    fn visit_map<A: MapAccess<'de>>(self, mut map: A) -> Result<RawValue, A::Error> {
        let mut out = Vec::new();
        while let Some(k) = map.next_key::<RawNode>()? {
            let v = map.next_value::<RawNode>()?;
            out.push((to_node(k), to_node(v)));
        }
        Ok(RawValue(Value::Map(out)))
    }
}

/// A YAML syntax error with its position.
pub(crate) struct YamlError {
    pub message: String,
    pub span: Span,
}

/// Parses a YAML document into a [`Node`] tree.
pub(crate) fn parse(text: &str) -> Result<Node, YamlError> {
    let options = serde_saphyr::options! { strict_booleans: true };
    match serde_saphyr::from_str_with_options::<RawNode>(text, options) {
        Ok(n) => Ok(to_node(n)),
        Err(e) => {
            let (start, len) = e.location().map_or((0, 0), |l| {
                let s = l.span();
                match s.byte_offset() {
                    Some(b) if b > 0 || (l.line() <= 1 && l.column() <= 1) => {
                        (b as usize, s.byte_len().unwrap_or(0) as usize)
                    }
                    _ => (offset_of(text, l.line() as usize, l.column() as usize), 1),
                }
            });
            let full = e.to_string();
            let first = full.lines().next().unwrap_or("invalid YAML");
            // The position is shown by the caret; keep only the reason.
            let message = first
                .find("column")
                .and_then(|i| first.get(i..))
                .and_then(|r| r.split_once(": "))
                .map_or(first, |(_, reason)| reason)
                .to_string();
            Err(YamlError {
                message,
                span: Span::new(start, start + len.max(1)),
            })
        }
    }
}

/// Where the characters of a scalar's value start in the file, when the
/// scalar is written plainly or quoted without escapes (so offsets inside the
/// value map 1:1 to the file). `None` when they do not map.
pub(crate) fn scalar_content_offset(source: &str, node: &Node, value: &str) -> Option<usize> {
    let start = node.span.start;
    let rest = source.get(start..)?;
    if rest.starts_with(value) {
        return Some(start);
    }
    let first = rest.chars().next()?;
    if (first == '"' || first == '\'') && rest.get(1..).is_some_and(|r| r.starts_with(value)) {
        return Some(start + 1);
    }
    None
}

/// Byte offset of a 1-based line and 1-based character column (clamped).
fn offset_of(text: &str, line: usize, column: usize) -> usize {
    let mut off = 0;
    for (i, l) in text.split_inclusive('\n').enumerate() {
        if i + 1 == line {
            let col: usize = l
                .chars()
                .take(column.saturating_sub(1))
                .map(char::len_utf8)
                .sum();
            return off + col;
        }
        off += l.len();
    }
    text.len()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn items(text: &str) -> Vec<String> {
        let Ok(root) = parse(text) else {
            panic!("parses: {text}")
        };
        match root.get("phrases").map(|n| &n.value) {
            Some(Value::Seq(items)) => items
                .iter()
                .filter_map(|n| n.as_str().map(str::to_string))
                .collect(),
            other => panic!("a list: {other:?}"),
        }
    }

    #[test]
    fn yaml_1_1_booleans_stay_words() {
        // Regression: `[on, on top of]` was read as `["true", "on top of"]`,
        // so the relation `On` lost its preposition.
        assert_eq!(
            items("phrases: [on, off, yes, no, on top of]\n"),
            ["on", "off", "yes", "no", "on top of"]
        );
        assert_eq!(items("phrases: [true, 3]\n"), ["true", "3"]);
    }
}
