//! The [`Doc`] tree (a YAML/JSON document with raw scalars) and its
//! structural edits.

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;

use super::wild_num;

// ---------------------------------------------------------- documents (serde)

/// A YAML/JSON document with raw scalars.
#[derive(Debug, Clone, PartialEq)]
pub enum Doc {
    /// A mapping, keys in order (duplicates allowed: they are a test).
    Map(Vec<(String, Doc)>),
    /// A sequence.
    Seq(Vec<Doc>),
    /// A scalar written exactly as given (`12`, `NaN`, `true`, `~`).
    Raw(String),
    /// A string, written quoted.
    Str(String),
}

impl Doc {
    /// From a JSON value (numbers and booleans become raw scalars).
    pub fn from_json(v: &serde_json::Value) -> Doc {
        use serde_json::Value;
        match v {
            Value::Null => Doc::Raw("null".into()),
            Value::Bool(b) => Doc::Raw(b.to_string()),
            Value::Number(n) => Doc::Raw(n.to_string()),
            Value::String(s) => Doc::Str(s.clone()),
            Value::Array(a) => Doc::Seq(a.iter().map(Doc::from_json).collect()),
            Value::Object(m) => Doc::Map(
                m.iter()
                    .map(|(k, v)| (k.clone(), Doc::from_json(v)))
                    .collect(),
            ),
        }
    }

    /// As JSON text (raw scalars unquoted, so `NaN` makes it invalid JSON,
    /// which is one of the things tried).
    pub fn to_json(&self) -> String {
        let mut out = String::new();
        self.write_json(&mut out);
        out
    }

    fn write_json(&self, out: &mut String) {
        match self {
            Doc::Raw(s) => out.push_str(s),
            Doc::Str(s) => out.push_str(&quote(s)),
            Doc::Seq(items) => {
                out.push('[');
                for (i, d) in items.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    d.write_json(out);
                }
                out.push(']');
            }
            Doc::Map(entries) => {
                out.push('{');
                for (i, (k, d)) in entries.iter().enumerate() {
                    if i > 0 {
                        out.push(',');
                    }
                    out.push_str(&quote(k));
                    out.push(':');
                    d.write_json(out);
                }
                out.push('}');
            }
        }
    }

    /// As block-style YAML (flow style for sequences of scalars).
    pub fn to_yaml(&self) -> String {
        let mut out = String::new();
        self.write_yaml(&mut out, 0);
        out
    }

    fn is_scalar(&self) -> bool {
        matches!(self, Doc::Raw(_) | Doc::Str(_))
    }

    fn write_yaml(&self, out: &mut String, indent: usize) {
        let pad = " ".repeat(indent);
        match self {
            Doc::Raw(s) => {
                out.push_str(s);
                out.push('\n');
            }
            Doc::Str(s) => {
                out.push_str(&quote(s));
                out.push('\n');
            }
            Doc::Seq(items) if items.iter().all(Doc::is_scalar) => {
                let inner: Vec<String> = items
                    .iter()
                    .map(|d| match d {
                        Doc::Raw(s) => s.clone(),
                        Doc::Str(s) => quote(s),
                        _ => String::new(),
                    })
                    .collect();
                out.push_str(&format!("[{}]\n", inner.join(", ")));
            }
            Doc::Seq(items) => {
                out.push('\n');
                for d in items {
                    out.push_str(&pad);
                    out.push_str("- ");
                    if d.is_scalar() {
                        d.write_yaml(out, indent + 2);
                    } else {
                        // A mapping inside a list item: first key on the dash line.
                        let mut inner = String::new();
                        d.write_yaml(&mut inner, indent + 2);
                        out.push_str(inner.trim_start());
                        if !inner.ends_with('\n') {
                            out.push('\n');
                        }
                    }
                }
            }
            Doc::Map(entries) if entries.is_empty() => out.push_str("{}\n"),
            Doc::Map(entries) => {
                if indent > 0 {
                    out.push('\n');
                }
                for (k, d) in entries {
                    out.push_str(&pad);
                    out.push_str(&yaml_key(k));
                    out.push(':');
                    if d.is_scalar()
                        || matches!(d, Doc::Seq(items) if items.iter().all(Doc::is_scalar))
                    {
                        out.push(' ');
                    }
                    d.write_yaml(out, indent + 2);
                }
            }
        }
    }

    /// Nodes in pre-order.
    pub(super) fn count(&self) -> usize {
        1 + match self {
            Doc::Map(e) => e.iter().map(|(_, d)| d.count()).sum(),
            Doc::Seq(s) => s.iter().map(Doc::count).sum(),
            _ => 0,
        }
    }

    /// The `n`th node in pre-order.
    fn nth_mut(&mut self, n: usize) -> Option<&mut Doc> {
        if n == 0 {
            return Some(self);
        }
        let mut n = n - 1;
        let children: Vec<&mut Doc> = match self {
            Doc::Map(e) => e.iter_mut().map(|(_, d)| d).collect(),
            Doc::Seq(s) => s.iter_mut().collect(),
            _ => return None,
        };
        for c in children {
            let size = c.count();
            if n < size {
                return c.nth_mut(n);
            }
            n -= size;
        }
        None
    }
}

pub(super) fn quote(s: &str) -> String {
    serde_json::to_string(s).unwrap_or_else(|_| "\"\"".to_string())
}

fn yaml_key(k: &str) -> String {
    if !k.is_empty() && k.chars().all(|c| c.is_ascii_alphanumeric() || c == '_') {
        k.to_string()
    } else {
        quote(k)
    }
}

/// One structural edit of a document.
#[derive(Debug, Clone)]
pub(super) enum Edit {
    /// The node becomes this raw scalar.
    Raw(String),
    /// The node becomes this string.
    Str(String),
    /// A child of a mapping or sequence is removed.
    Delete,
    /// A mapping gains a key (maybe unknown, maybe a duplicate).
    AddKey(String, String),
    /// A child is repeated this many times (lists past their limits).
    Repeat(usize),
    /// The node is wrapped in this many one-element lists.
    Nest(usize),
}

fn edit() -> impl Strategy<Value = Edit> {
    prop_oneof![
        6 => wild_num().prop_map(Edit::Raw),
        1 => select(&["true", "null", "~", "[]", "{}", "\"\"", "-", "*x", "&x 1", "!!float 1", "0x1F"][..])
            .prop_map(|s| Edit::Raw(s.to_string())),
        2 => select(&["", "../../x", "x", "Car", "Vehicles", "tiles", "detector", "depth", "flow",
                      "nanodet_gfl", "inverse_depth", "segmentation", "name with spaces",
                      "a/b", "\u{0}", "ＣＡＲ"][..])
            .prop_map(|s| Edit::Str(s.to_string())),
        2 => Just(Edit::Delete),
        1 => (select(&["name", "frames", "unknown_key", "fps", "id", "model", "kind", "x"][..]), wild_num())
            .prop_map(|(k, v)| Edit::AddKey(k.to_string(), v)),
        1 => select(&[2usize, 10, 300, 3000][..]).prop_map(Edit::Repeat),
        1 => select(&[1usize, 5, 200][..]).prop_map(Edit::Nest),
    ]
}

/// Most nodes an edited document may have. Edits that repeat a list 3,000
/// times, then the list holding it, multiplied a document past memory
/// (a camera document stalled its worker before it was written).
pub const MAX_DOC_NODES: usize = 20_000;

pub(super) fn apply(doc: &mut Doc, at: u64, child: u64, e: &Edit) {
    let total = doc.count();
    let n = (at % total as u64) as usize;
    let Some(node) = doc.nth_mut(n) else {
        return;
    };
    match e {
        Edit::Raw(s) => *node = Doc::Raw(s.clone()),
        Edit::Str(s) => *node = Doc::Str(s.clone()),
        Edit::Delete => match node {
            Doc::Map(entries) if !entries.is_empty() => {
                let i = (child % entries.len() as u64) as usize;
                entries.remove(i);
            }
            Doc::Seq(items) if !items.is_empty() => {
                let i = (child % items.len() as u64) as usize;
                items.remove(i);
            }
            _ => {}
        },
        Edit::AddKey(k, v) => {
            if let Doc::Map(entries) = node {
                entries.push((k.clone(), Doc::Raw(v.clone())));
            }
        }
        Edit::Repeat(times) => match node {
            Doc::Seq(items) if !items.is_empty() => {
                let i = (child % items.len() as u64) as usize;
                let item = items[i].clone();
                let room = MAX_DOC_NODES.saturating_sub(total) / item.count().max(1);
                items.extend(std::iter::repeat_n(item, (*times).min(room)));
            }
            Doc::Map(entries) if !entries.is_empty() => {
                let i = (child % entries.len() as u64) as usize;
                let entry = entries[i].clone();
                entries.push(entry);
            }
            _ => {}
        },
        Edit::Nest(depth) => {
            if total + depth > MAX_DOC_NODES {
                return;
            }
            let mut d = node.clone();
            for _ in 0..*depth {
                d = Doc::Seq(vec![d]);
            }
            *node = d;
        }
    }
}

/// Documents made by 0 to 6 edits of one of `bases`.
pub(super) fn edited(bases: Vec<Doc>) -> impl Strategy<Value = Doc> {
    let n = bases.len().max(1);
    (0..n, vec((any::<u64>(), any::<u64>(), edit()), 0..6)).prop_map(move |(i, edits)| {
        let mut d = bases.get(i).cloned().unwrap_or(Doc::Map(Vec::new()));
        for (at, child, e) in &edits {
            apply(&mut d, *at, *child, e);
        }
        d
    })
}

pub(super) fn doc_of_yaml(text: &str) -> Option<Doc> {
    serde_saphyr::from_str::<serde_json::Value>(text)
        .ok()
        .map(|v| Doc::from_json(&v))
}
