//! Structure-aware generators: proptest strategies for each format's
//! grammar, sampled outside `#[test]` by a seeded `TestRunner`
//! ([`sample`]), so each generated input is a pure function of the seed the
//! caller derives from `(seed, target, iteration)`.
//!
//! A byte mutator rarely gets past a parser's first check; these reach the
//! code behind it — the checker, the evaluator, the simulator — with
//! values that are well-formed but wild: numbers at the edges
//! ([`crate::mutate::EXTREME_NUMBERS`]), formulas nested and quantified in
//! every spelling, documents with keys dropped, duplicated, or replaced.
//! The serde formats (scenarios, configs, model configs, calibrations,
//! tracks) are generated both from scratch and as edits of real documents
//! (the built-in scenarios, the default config): a [`Doc`] tree emitted as
//! YAML or JSON with raw scalars, so that `NaN`, `1e999` and `0x10` reach
//! the reader exactly as written.

use std::sync::OnceLock;

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::strategy::ValueTree;
use proptest::test_runner::TestRunner;

use crate::mutate::EXTREME_NUMBERS;

/// Draws one value of `strategy` from `runner`'s random stream.
///
/// The strategies here use no filters, so a tree can always be built; if
/// one cannot, the harness is broken, and that is reported (as a panic of
/// the input) rather than skipped.
pub fn sample<S: Strategy>(strategy: S, runner: &mut TestRunner) -> S::Value {
    match strategy.new_tree(runner) {
        Ok(tree) => tree.current(),
        Err(e) => panic!("fuzz harness broken: a generator strategy failed: {e}"),
    }
}

// ---------------------------------------------------------------- vocabulary

/// Names of the built-in LogicPad: generated formulas mostly use
/// predicates and values that exist, so the checker and evaluator run.
struct Vocab {
    preds: Vec<(String, usize)>,
    values: Vec<String>,
    phrases: Vec<String>,
}

fn vocab() -> &'static Vocab {
    static V: OnceLock<Vocab> = OnceLock::new();
    V.get_or_init(|| {
        let pad = logicpad::LogicPad::builtin();
        let schema = pad.schema();
        let mut preds = Vec::new();
        let mut values = Vec::new();
        let mut phrases = Vec::new();
        for p in schema.predicates() {
            preds.push((p.name.clone(), p.arity));
            values.extend(p.values.iter().flatten().cloned());
            phrases.extend(p.phrases.iter().cloned());
            phrases.extend(p.value_phrases.values().flatten().cloned());
        }
        values.sort();
        values.dedup();
        phrases.sort();
        phrases.dedup();
        Vocab {
            preds,
            values,
            phrases,
        }
    })
}

// ------------------------------------------------------------------- numbers

/// A number as text: mostly ordinary, sometimes at an edge.
fn wild_num() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (-100.0f64..100.0).prop_map(|v| format!("{v:.3}")),
        2 => (0u32..50).prop_map(|v| v.to_string()),
        2 => select(EXTREME_NUMBERS).prop_map(str::to_string),
    ]
}

/// A count or index as text: mostly small, sometimes at an edge.
fn wild_count() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (0u32..40).prop_map(|v| v.to_string()),
        1 => select(EXTREME_NUMBERS).prop_map(str::to_string),
    ]
}

// ----------------------------------------------------------------------- FOL

const AND: &[&str] = &["∧", "^", "&", "&&", "and", " ∧ "];
const OR: &[&str] = &["∨", "|", "||", "or"];
const NOT: &[&str] = &["¬", "~", "!", "not "];
const IMPLIES: &[&str] = &["==>", "=>", "->", "→", "⇒", "⟹", "⊃", "implies"];
const FORALL: &[&str] = &["∀", "forall "];
const EXISTS: &[&str] = &["∃", "exists "];
const SEP: &[&str] = &[":", " :", ".", " . ", ""];
const VARS: &[&str] = &["x", "y", "z", "u", "v", "w", "x1", "v11", "?p", "?obj"];
const CONSTS: &[&str] = &[
    "car_1",
    "car_3",
    "pedestrian_2",
    "Car",
    "White",
    "Left",
    "\"quoted constant\"",
    "\"a\\\"b\"",
    "c0",
    "n2",
    "42",
    "car_99999999999999999999",
    "é",
];

fn pred_name() -> impl Strategy<Value = (String, usize)> {
    let known: Vec<(String, usize)> = vocab().preds.clone();
    prop_oneof![
        8 => select(known),
        1 => (select(&["Foo", "P", "Q1", "Vehicle", "typeof", "Λ", "X_"][..]), 0usize..4)
            .prop_map(|(n, a)| (n.to_string(), a)),
    ]
}

fn term() -> impl Strategy<Value = String> {
    let values: Vec<String> = vocab().values.clone();
    prop_oneof![
        4 => select(VARS).prop_map(str::to_string),
        2 => select(CONSTS).prop_map(str::to_string),
        2 => select(values),
    ]
}

fn atom() -> impl Strategy<Value = String> {
    prop_oneof![
        // An atom with (usually) its declared arity.
        6 => (pred_name(), vec(term(), 0..4), 0u8..10).prop_map(|((p, arity), args, keep)| {
            let args = if keep < 8 {
                args.iter().cycle().take(arity).cloned().collect::<Vec<_>>()
            } else {
                args
            };
            format!("{p}({})", args.join(", "))
        }),
        // The function form `TypeOf(x) = Car`.
        2 => (select(&["TypeOf", "ColorOf", "InitialLocation", "LastLocation"][..]), term(),
              select(&["=", "!=", "≠", "/="][..]), term())
            .prop_map(|(f, a, op, v)| format!("{f}({a}) {op} {v}")),
        // A comparison.
        1 => (term(), select(&["=", "!=", "≠"][..]), term())
            .prop_map(|(a, op, b)| format!("{a} {op} {b}")),
    ]
}

fn vars_list() -> impl Strategy<Value = String> {
    (vec(select(VARS), 1..4), select(&[",", ", ", " "][..])).prop_map(|(vs, sep)| vs.join(sep))
}

/// A formula: atoms under ∧, ∨, ¬, parentheses and quantifiers.
fn formula() -> impl Strategy<Value = String> {
    atom().prop_recursive(6, 48, 4, |inner| {
        prop_oneof![
            3 => (inner.clone(), select(AND), inner.clone())
                .prop_map(|(a, op, b)| format!("{a} {op} {b}")),
            1 => (inner.clone(), select(OR), inner.clone())
                .prop_map(|(a, op, b)| format!("{a} {op} {b}")),
            1 => (select(NOT), inner.clone()).prop_map(|(n, a)| format!("{n}{a}")),
            1 => inner.clone().prop_map(|a| format!("({a})")),
            1 => (select(EXISTS), vars_list(), select(SEP), inner.clone())
                .prop_map(|(q, v, s, a)| format!("{q}{v}{s} {a}")),
        ]
    })
}

/// A rule `∀x,y : body ==> Head(x, y)`, or one of its wrong shapes.
fn rule() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => (select(FORALL), vars_list(), select(SEP), formula(), select(IMPLIES), atom())
            .prop_map(|(q, v, s, b, i, h)| format!("{q}{v}{s} {b} {i} {h}")),
        1 => (formula(), select(IMPLIES), formula()).prop_map(|(b, i, h)| format!("{b} {i} {h}")),
        1 => (formula(), select(IMPLIES), select(NOT), atom())
            .prop_map(|(b, i, n, h)| format!("{b} {i} {n}{h}")),
    ]
}

/// A query: existential, or universal `∀x: A → B`.
fn query_text() -> impl Strategy<Value = String> {
    prop_oneof![
        5 => formula(),
        1 => (select(FORALL), vars_list(), select(SEP), formula(), select(IMPLIES), formula())
            .prop_map(|(q, v, s, a, i, b)| format!("{q}{v}{s} {a} {i} {b}")),
    ]
}

/// FOL formulas and rules.
pub fn fol(runner: &mut TestRunner) -> Vec<u8> {
    sample(prop_oneof![formula(), rule(), query_text()], runner).into_bytes()
}

/// Queries.
pub fn query(runner: &mut TestRunner) -> Vec<u8> {
    sample(query_text(), runner).into_bytes()
}

// ------------------------------------------------------------------ LogicPad

const ROLES: &[&str] = &[
    "class",
    "property",
    "relation",
    "type",
    "attribute",
    "location",
    "silent",
    "Class",
    "bogus",
];

fn phrase_list() -> impl Strategy<Value = String> {
    let phrases: Vec<String> = vocab().phrases.clone();
    vec(
        prop_oneof![
            6 => select(phrases),
            1 => select(&["on", "yes", "no", "~", "", "a b c", "\"q\"", "[x]"][..]).prop_map(str::to_string),
        ],
        0..4,
    )
    .prop_map(|ps| format!("[{}]", ps.join(", ")))
}

fn atomic_entry() -> impl Strategy<Value = String> {
    prop_oneof![
        2 => atom().prop_map(|a| format!("    - {a}\n")),
        2 => (atom(), proptest::option::of(select(ROLES)), proptest::option::of(phrase_list()),
              proptest::option::of(select(&["initial", "last", "first"][..])),
              proptest::option::of(select(&["\"{x} moves\"", "\"\"", "\"{y} {z}\"", "7"][..])))
            .prop_map(|(a, role, phrases, frames, sentence)| {
                let mut s = format!("    - predicate: {a}\n");
                if let Some(r) = role { s += &format!("      role: {r}\n"); }
                if let Some(p) = phrases { s += &format!("      phrases: {p}\n"); }
                if let Some(f) = frames { s += &format!("      frames: {f}\n"); }
                if let Some(t) = sentence { s += &format!("      sentence: {t}\n"); }
                s
            }),
    ]
}

fn function_entry() -> impl Strategy<Value = String> {
    let values: Vec<String> = vocab().values.clone();
    (
        select(&["TypeOf", "ColorOf", "SizeOf", "InitialLocation", "F"][..]),
        select(&["(x, t)", "(x, color)", "(x)", "(x, y, z)", "", "(x, x)"][..]),
        vec(select(values), 0..5),
        proptest::option::of(select(ROLES)),
        0u8..3,
    )
        .prop_map(|(name, params, values, role, style)| {
            let mut s = format!("    {name}:\n      predicate: {name}{params}\n");
            if let Some(r) = role {
                s += &format!("      role: {r}\n");
            }
            match style {
                0 => s += &format!("      values: [{}]\n", values.join(", ")),
                1 => {
                    s += "      values:\n";
                    for v in &values {
                        s += &format!("        - {v}: [{}]\n", v.to_lowercase());
                    }
                }
                _ => {}
            }
            s
        })
}

fn derived_entry() -> impl Strategy<Value = String> {
    (
        select(&["R", "Stopped", "Move", "NewPred", "Vehicles", ""][..]),
        rule(),
        proptest::option::of(select(ROLES)),
        proptest::option::of(phrase_list()),
    )
        .prop_map(|(name, logic, role, phrases)| {
            let mut s = format!("  - name: {name}\n");
            if let Some(r) = role {
                s += &format!("    role: {r}\n");
            }
            if let Some(p) = phrases {
                s += &format!("    phrases: {p}\n");
            }
            // JSON quoting makes a valid YAML double-quoted scalar of any rule.
            s += &format!("    logic: {}\n", quote(&logic));
            s
        })
}

/// LogicPad documents: groups of atomic predicates, functions with values,
/// derived predicates with generated rules.
pub fn logicpad(runner: &mut TestRunner) -> Vec<u8> {
    let doc = (
        vec(
            (select(&["tracker", "semantic_segmentation", "g"][..]), vec(atomic_entry(), 0..6)),
            0..3,
        ),
        vec(function_entry(), 0..3),
        vec(derived_entry(), 0..6),
        any::<bool>(),
    )
        .prop_map(|(groups, functions, derived, anchors)| {
            let mut s = String::from("atomic_predicates:\n");
            for (g, entries) in groups {
                s += &format!("  {g}:\n");
                for e in entries {
                    s += &e;
                }
            }
            s += "functions:\n  f:\n";
            for f in functions {
                s += &f;
            }
            if anchors {
                s += "  g2:\n    Loc:\n      predicate: Loc(x, l)\n      values: &v [A, B]\n    Loc2:\n      predicate: Loc2(x, l)\n      values: *v\n";
            }
            s += "derived_predicates:\n";
            for d in derived {
                s += &d;
            }
            s
        });
    sample(doc, runner).into_bytes()
}

// --------------------------------------------------------------------- facts

fn ident() -> impl Strategy<Value = String> {
    prop_oneof![
        4 => select(CONSTS).prop_map(str::to_string),
        2 => "[a-zA-Z_][a-zA-Z0-9_.'-]{0,12}",
        1 => "\\PC{0,6}",
    ]
}

fn fact_line() -> impl Strategy<Value = String> {
    prop_oneof![
        6 => (pred_name(), vec(ident(), 0..4), select(&[", ", ",", " , ", ",,"][..]),
              select(&["", ".", " ", "\r"][..]))
            .prop_map(|((p, _), args, sep, end)| format!("{p}({}){end}", args.join(sep))),
        1 => select(&["# comment", "% comment", "", "   ", "Vehicles(", ")(", "()", "P()",
                      "Vehicles(car_1", "TypeOf(car_1, \"Car\")", "TypeOf(car_1, \"Ca,r\")"][..])
            .prop_map(str::to_string),
    ]
}

/// Text KBs.
pub fn facts(runner: &mut TestRunner) -> Vec<u8> {
    sample(vec(fact_line(), 0..30).prop_map(|ls| ls.join("\n")), runner).into_bytes()
}

/// `window<TAB>query` files.
pub fn queries_tsv(runner: &mut TestRunner) -> Vec<u8> {
    let line = prop_oneof![
        6 => (select(&["w0", "w1", "w2", "", " w0", "w0\t"][..]), query_text())
            .prop_map(|(w, q)| format!("{w}\t{q}")),
        1 => select(&["# comment", "", "w0", "\t", "w0\t ", "w1\tVehicles(x)\tMoving(x)"][..])
            .prop_map(str::to_string),
    ];
    sample(vec(line, 0..20).prop_map(|ls| ls.join("\n")), runner).into_bytes()
}

// --------------------------------------------------------------------- KITTI

const KITTI_TYPES: &[&str] = &[
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Pedestrian",
    "Person",
    "Person_sitting",
    "Cyclist",
    "Misc",
    "DontCare",
    "car",
    "Bus",
];

fn kitti_line() -> impl Strategy<Value = String> {
    let frame = prop_oneof![6 => (0u32..6).prop_map(|v| v.to_string()), 1 => wild_count()];
    let track = prop_oneof![
        6 => (0u32..8).prop_map(|v| v.to_string()),
        1 => Just("-1".to_string()),
        1 => wild_count()
    ];
    let occluded = prop_oneof![6 => (0u8..4).prop_map(|v| v.to_string()), 1 => wild_count()];
    // A plausible box, sometimes wild.
    let bbox = prop_oneof![
        6 => (0.0f64..1200.0, 0.0f64..350.0, 1.0f64..200.0, 1.0f64..100.0)
            .prop_map(|(l, t, w, h)| format!("{l:.2} {t:.2} {:.2} {:.2}", l + w, t + h)),
        1 => vec(wild_num(), 4).prop_map(|v| v.join(" ")),
    ];
    let dims = prop_oneof![
        6 => (0.5f64..4.0, 0.5f64..3.0, 0.5f64..12.0)
            .prop_map(|(h, w, l)| format!("{h:.2} {w:.2} {l:.2}")),
        1 => Just("-1 -1 -1".to_string()),
        1 => vec(wild_num(), 3).prop_map(|v| v.join(" ")),
    ];
    let loc = prop_oneof![
        6 => (-20.0f64..20.0, 0.5f64..2.5, 1.0f64..80.0)
            .prop_map(|(x, y, z)| format!("{x:.2} {y:.2} {z:.2}")),
        1 => Just("-1000 -1000 -1000".to_string()),
        1 => vec(wild_num(), 3).prop_map(|v| v.join(" ")),
    ];
    let score = prop_oneof![
        6 => Just(String::new()),
        1 => wild_num().prop_map(|s| format!(" {s}")),
    ];
    (
        frame,
        track,
        select(KITTI_TYPES),
        prop_oneof![3 => Just("0".to_string()), 1 => wild_num()],
        occluded,
        wild_num(),
        bbox,
        dims,
        loc,
        wild_num(),
        score,
    )
        .prop_map(|(f, t, ty, tr, oc, alpha, bbox, dims, loc, rot, score)| {
            format!("{f} {t} {ty} {tr} {oc} {alpha} {bbox} {dims} {loc} {rot}{score}")
        })
}

/// KITTI tracking label files.
pub fn kitti_labels(runner: &mut TestRunner) -> Vec<u8> {
    sample(
        prop_oneof![
            8 => vec(kitti_line(), 0..40),
            // One frame crowded with objects.
            1 => (200usize..400).prop_map(|n| (0..n)
                .map(|i| format!("0 {i} Car 0 0 0 10 10 20 20 1.5 1.6 4 0 1.7 {}", 5 + i % 60))
                .collect()),
        ]
        .prop_map(|ls| ls.join("\n")),
        runner,
    )
    .into_bytes()
}

/// KITTI calibration files.
pub fn kitti_calib(runner: &mut TestRunner) -> Vec<u8> {
    let p_line = (
        select(
            &[
                "P0:",
                "P1:",
                "P2:",
                "P3:",
                "R0_rect:",
                "Tr_velo_cam:",
                " P2:",
                "P2 :",
            ][..],
        ),
        prop_oneof![6 => Just(12usize), 1 => 0usize..16],
        vec(wild_num(), 16),
    )
        .prop_map(|(key, n, nums)| {
            format!(
                "{key} {}",
                nums.into_iter().take(n).collect::<Vec<_>>().join(" ")
            )
        });
    let p2_real = (500.0f64..1500.0, 100.0f64..1300.0, 50.0f64..400.0).prop_map(|(f, cx, cy)| {
        format!("P2: {f:.3} 0 {cx:.3} 44.8 0 {f:.3} {cy:.3} 0.2 0 0 1 0.003")
    });
    sample(
        (vec(p_line, 0..6), proptest::option::of(p2_real)).prop_map(|(mut ls, p2)| {
            ls.extend(p2);
            ls.join("\n")
        }),
        runner,
    )
    .into_bytes()
}

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
    fn count(&self) -> usize {
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

fn quote(s: &str) -> String {
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
enum Edit {
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

fn apply(doc: &mut Doc, at: u64, child: u64, e: &Edit) {
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
fn edited(bases: Vec<Doc>) -> impl Strategy<Value = Doc> {
    let n = bases.len().max(1);
    (0..n, vec((any::<u64>(), any::<u64>(), edit()), 0..6)).prop_map(move |(i, edits)| {
        let mut d = bases.get(i).cloned().unwrap_or(Doc::Map(Vec::new()));
        for (at, child, e) in &edits {
            apply(&mut d, *at, *child, e);
        }
        d
    })
}

fn doc_of_yaml(text: &str) -> Option<Doc> {
    serde_saphyr::from_str::<serde_json::Value>(text)
        .ok()
        .map(|v| Doc::from_json(&v))
}

fn builtin_scenarios() -> &'static [Doc] {
    static D: OnceLock<Vec<Doc>> = OnceLock::new();
    D.get_or_init(|| {
        perception::sim::BUILTIN_NAMES
            .iter()
            .filter_map(|n| perception::sim::builtin_text(n))
            .filter_map(doc_of_yaml)
            .collect()
    })
}

fn motion() -> impl Strategy<Value = Doc> {
    let phase = (
        wild_count(),
        wild_count(),
        0u8..4,
        wild_num(),
        proptest::option::of(0u32..8),
    )
        .prop_map(|(from, to, kind, v, other)| {
            let mut e = vec![
                ("from".to_string(), Doc::Raw(from)),
                ("to".to_string(), Doc::Raw(to)),
            ];
            match kind {
                0 => e.push(("accel".into(), Doc::Raw(v))),
                1 => e.push(("speed_to".into(), Doc::Raw(v))),
                2 => e.push(("turn_deg".into(), Doc::Raw(v))),
                _ => {}
            }
            if let Some(o) = other {
                e.push((
                    if kind % 2 == 0 { "enter" } else { "merge_into" }.into(),
                    Doc::Raw(o.to_string()),
                ));
            }
            Doc::Map(e)
        });
    (
        wild_num(),
        wild_num(),
        wild_num(),
        wild_num(),
        vec(phase, 0..3),
    )
        .prop_map(|(x, z, h, s, phases)| {
            Doc::Map(vec![
                ("start".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
                ("heading_deg".into(), Doc::Raw(h)),
                ("speed".into(), Doc::Raw(s)),
                ("phases".into(), Doc::Seq(phases)),
            ])
        })
}

fn scenario_doc() -> impl Strategy<Value = Doc> {
    let agent = (
        0u32..8,
        select(
            &[
                "Vehicles",
                "Pedestrian",
                "Person",
                "Cyclist",
                "Misc",
                "Pole",
                "Car",
            ][..],
        ),
        proptest::option::of(select(
            &["Car", "Van", "Truck", "Bus", "SUV", "Bicycle", "Zeppelin"][..],
        )),
        proptest::option::of(select(&["White", "Red", "Black", "Plaid"][..])),
        proptest::option::of(vec(wild_num(), 3)),
        any::<bool>(),
        motion(),
    )
        .prop_map(|(id, class, ty, color, size, parked, m)| {
            let mut e = vec![
                ("id".to_string(), Doc::Raw(id.to_string())),
                ("class".to_string(), Doc::Str(class.to_string())),
            ];
            if let Some(t) = ty {
                e.push(("type".into(), Doc::Str(t.into())));
            }
            if let Some(c) = color {
                e.push(("color".into(), Doc::Str(c.into())));
            }
            if let Some(s) = size {
                e.push((
                    "size".into(),
                    Doc::Seq(s.into_iter().map(Doc::Raw).collect()),
                ));
            }
            if parked {
                e.push(("parked".into(), Doc::Raw("true".into())));
            }
            if let Doc::Map(m) = m {
                e.extend(m);
            }
            Doc::Map(e)
        });
    let road =
        (wild_num(), wild_num(), wild_num(), wild_num(), wild_num()).prop_map(|(x, z, l, w, s)| {
            Doc::Map(vec![
                ("center".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
                ("length".into(), Doc::Raw(l)),
                ("width".into(), Doc::Raw(w)),
                ("sidewalk_width".into(), Doc::Raw(s)),
            ])
        });
    let prop = (
        select(&["Pole", "TrafficSign", "Building", "Vegetation", "Vehicles"][..]),
        wild_num(),
        wild_num(),
    )
        .prop_map(|(c, x, z)| {
            Doc::Map(vec![
                ("class".into(), Doc::Str(c.into())),
                ("at".into(), Doc::Seq(vec![Doc::Raw(x), Doc::Raw(z)])),
            ])
        });
    let camera =
        (vec(wild_num(), 4), wild_count(), wild_count(), wild_num()).prop_map(|(k, w, h, hm)| {
            let mut it = k.into_iter().map(Doc::Raw);
            let mut intr = Vec::new();
            for key in ["fx", "fy", "cx", "cy"] {
                intr.push((key.to_string(), it.next().unwrap_or(Doc::Raw("1".into()))));
            }
            intr.push(("image_width".into(), Doc::Raw(w)));
            intr.push(("image_height".into(), Doc::Raw(h)));
            Doc::Map(vec![
                ("intrinsics".into(), Doc::Map(intr)),
                ("height_m".into(), Doc::Raw(hm)),
            ])
        });
    let noise = vec(wild_num(), 5).prop_map(|v| {
        let keys = [
            "position_sigma_m",
            "depth_sigma_fraction",
            "box_jitter_px",
            "miss_probability",
            "id_switch_probability",
        ];
        Doc::Map(
            keys.iter()
                .zip(v)
                .map(|(k, v)| (k.to_string(), Doc::Raw(v)))
                .collect(),
        )
    });
    (
        select(
            &[
                "fuzz",
                "a",
                "",
                "../../x",
                "x y",
                "ünï",
                "aaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaaa",
            ][..],
        ),
        wild_count(),
        proptest::option::of(wild_num()),
        proptest::option::of(camera),
        motion(),
        vec(road, 0..2),
        vec(prop, 0..3),
        vec(agent, 0..5),
        proptest::option::of(noise),
    )
        .prop_map(
            |(name, frames, fps, camera, ego, roads, props, agents, noise)| {
                let mut e = vec![
                    ("name".to_string(), Doc::Str(name.to_string())),
                    ("frames".to_string(), Doc::Raw(frames)),
                ];
                if let Some(f) = fps {
                    e.push(("fps".into(), Doc::Raw(f)));
                }
                if let Some(c) = camera {
                    e.push(("camera".into(), c));
                }
                e.push(("ego".into(), ego));
                e.push((
                    "world".into(),
                    Doc::Map(vec![
                        ("roads".into(), Doc::Seq(roads)),
                        ("props".into(), Doc::Seq(props)),
                    ]),
                ));
                e.push(("agents".into(), Doc::Seq(agents)));
                if let Some(n) = noise {
                    e.push(("noise".into(), n));
                }
                Doc::Map(e)
            },
        )
}

fn scenario(runner: &mut TestRunner) -> Doc {
    let bases = builtin_scenarios().to_vec();
    sample(prop_oneof![scenario_doc(), edited(bases)], runner)
}

/// Scenarios as YAML: generated from the format, or edits of the built-ins.
pub fn scenario_yaml(runner: &mut TestRunner) -> Vec<u8> {
    scenario(runner).to_yaml().into_bytes()
}

/// Scenarios as JSON.
pub fn scenario_json(runner: &mut TestRunner) -> Vec<u8> {
    scenario(runner).to_json().into_bytes()
}

fn default_config() -> Doc {
    static D: OnceLock<Doc> = OnceLock::new();
    D.get_or_init(|| {
        serde_json::to_value(perception::FactConfig::default())
            .map(|v| Doc::from_json(&v))
            .unwrap_or(Doc::Map(Vec::new()))
    })
    .clone()
}

/// Fact configs: edits of the default, keys dropped, added or made wild.
pub fn config_yaml(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(vec![default_config(), Doc::Map(Vec::new())]), runner)
        .to_yaml()
        .into_bytes()
}

/// Fact configs as JSON.
pub fn config_json(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(vec![default_config(), Doc::Map(Vec::new())]), runner)
        .to_json()
        .into_bytes()
}

fn model_bases() -> Vec<Doc> {
    [
        crate::targets::MODEL_DETECTOR,
        crate::targets::MODEL_DEPTH,
        crate::targets::MODEL_FLOW,
        "detector: det.yaml\ndepth: depth.yaml\nflow: flow.yaml\n",
        "name: seg\nmodel: seg.onnx\ninput: { width: 8, height: 8, layout: nchw, colour: rgb, mean: [0, 0, 0], std: [255, 255, 255], resize: { mode: tiles, columns: 3, overlap: 0.1 } }\noutput: { kind: segmentation, num_classes: 3 }\nlabels:\n  - { id: 1, name: red, class: Vehicles, type: Car }\n",
    ]
    .iter()
    .filter_map(|t| doc_of_yaml(t))
    .collect()
}

/// Model configs and model sets: edits of working ones.
pub fn model_config(runner: &mut TestRunner) -> Vec<u8> {
    let d = sample(edited(model_bases()), runner);
    let mut text = d.to_yaml();
    // A set is recognised by a line starting `detector:`; keep it first.
    if text.contains("\ndetector:") && !text.starts_with("detector:") {
        text = format!("detector: det.yaml\n{text}");
    }
    text.into_bytes()
}

/// Camera calibrations: YAML intrinsics (edited) or a KITTI P2 file.
pub fn camera(runner: &mut TestRunner) -> Vec<u8> {
    let base = Doc::Map(
        [
            ("fx", "721.5"),
            ("fy", "721.5"),
            ("cx", "609.6"),
            ("cy", "172.9"),
            ("height_m", "1.65"),
            ("image_width", "1242"),
            ("image_height", "375"),
        ]
        .iter()
        .map(|(k, v)| (k.to_string(), Doc::Raw(v.to_string())))
        .collect(),
    );
    if sample(0u8..3, runner) == 0 {
        kitti_calib(runner)
    } else {
        sample(edited(vec![base]), runner).to_yaml().into_bytes()
    }
}

fn track_bases() -> &'static [Doc] {
    static D: OnceLock<Vec<Doc>> = OnceLock::new();
    D.get_or_init(|| {
        crate::corpus::tracks_seed_text()
            .and_then(|t| serde_json::from_str::<serde_json::Value>(&t).ok())
            .map(|v| vec![Doc::from_json(&v)])
            .unwrap_or_default()
    })
}

/// JSON tracks: edits of a simulated sequence's tracks.
pub fn tracks_json(runner: &mut TestRunner) -> Vec<u8> {
    sample(edited(track_bases().to_vec()), runner)
        .to_json()
        .into_bytes()
}

// ----------------------------------------------------------------- questions

const GRAMMAR_WORDS: &[&str] = &[
    "is", "are", "there", "a", "an", "the", "any", "does", "do", "how", "many", "which", "what",
    "who", "that", "and", "or", "not", "no", "every", "all", "each", "of", "to", "from", "on",
    "in", "at", "with", "than", "it", "its", "than", "more", "other", "another", "one", "two", "?",
    ",", "'s", "first", "then", "while", "between", "both", "neither", "nor", "only",
];

/// English questions from the LogicPad's phrases and the grammar's words.
pub fn question(runner: &mut TestRunner) -> Vec<u8> {
    let phrases: Vec<String> = vocab().phrases.clone();
    let word = prop_oneof![
        3 => select(phrases),
        3 => select(GRAMMAR_WORDS).prop_map(str::to_string),
        1 => wild_num(),
        1 => "[a-z]{1,10}",
    ];
    let q = (
        select(
            &[
                "Is there", "Does", "How many", "Are all", "Is the", "Which", "Do", "",
            ][..],
        ),
        vec(word, 0..16),
        select(&["?", "", "??", " ?", "."][..]),
    )
        .prop_map(|(start, words, end)| format!("{start} {}{end}", words.join(" ")));
    sample(q, runner).into_bytes()
}

/// CSV files of questions, with quoting and odd columns.
pub fn question_csv(runner: &mut TestRunner) -> Vec<u8> {
    let header = select(
        &[
            "Question",
            "Id,Question",
            "Question,Query",
            "question",
            "\"Question\"",
            "Q",
        ][..],
    );
    let cell = prop_oneof![
        3 => select(&["Is there a white car?", "How many pedestrians are there?", "Does the van move?"][..])
            .prop_map(str::to_string),
        1 => "[a-z ,\"]{0,20}",
        1 => Just("\"a \"\"quoted\"\" one, with comma\"".to_string()),
        1 => Just("\"unterminated".to_string()),
    ];
    let rows = vec(vec(cell, 1..3).prop_map(|c| c.join(",")), 0..8);
    let csv = (header, rows, select(&["\n", "\r\n"][..]))
        .prop_map(|(h, rows, nl)| format!("{h}{nl}{}", rows.join(nl)));
    sample(csv, runner).into_bytes()
}

/// A language model's replies: a query wrapped in fences, labels, quotes.
pub fn llm_reply(runner: &mut TestRunner) -> Vec<u8> {
    let reply = (
        select(
            &[
                "",
                "Yes",
                "No",
                "The answer is yes.",
                "```\n",
                "Query: ",
                "`",
                "\"",
                "\n\n",
            ][..],
        ),
        query_text(),
        select(&["", "\n```", "`", "\"", " — because it moves", "\nCANNOT: x"][..]),
    )
        .prop_map(|(a, q, b)| format!("{a}{q}{b}"));
    sample(reply, runner).into_bytes()
}

/// Source arguments.
pub fn source_spec(runner: &mut TestRunner) -> Vec<u8> {
    let spec = (
        select(
            &[
                "sim", "kitti", "json", "facts", "frames", "", "SIM", "sim:sim",
            ][..],
        ),
        select(&[":", "", "::"][..]),
        select(
            &[
                "urban_crossing",
                "../x",
                "",
                "/dev/zero",
                "a@b",
                "x y",
                "0-9",
                "ünï",
            ][..],
        ),
        proptest::option::of(wild_count()),
    )
        .prop_map(|(k, c, r, seed)| match seed {
            Some(s) => format!("{k}{c}{r}@{s}"),
            None => format!("{k}{c}{r}"),
        });
    let range = (
        wild_count(),
        select(&["-", "--", " - ", ""][..]),
        wild_count(),
    )
        .prop_map(|(a, d, b)| format!("{a}{d}{b}"));
    sample(prop_oneof![spec, range], runner).into_bytes()
}

#[cfg(test)]
mod tests {
    use super::*;
    use proptest::test_runner::{Config, RngAlgorithm, TestRng};

    fn runner(seed: u8) -> TestRunner {
        TestRunner::new_with_rng(
            Config::default(),
            TestRng::from_seed(RngAlgorithm::ChaCha, &[seed; 32]),
        )
    }

    #[test]
    fn generators_are_deterministic() {
        for t in crate::targets::ALL {
            let Some(g) = t.generate else { continue };
            for seed in 0..8 {
                assert_eq!(g(&mut runner(seed)), g(&mut runner(seed)), "{}", t.name);
            }
        }
    }

    #[test]
    fn generated_documents_are_mostly_accepted_by_the_readers() {
        // Generators that never produce a valid document would only test
        // the first check of each reader.
        let mut ok = 0;
        for seed in 0..64 {
            let text = String::from_utf8(scenario_yaml(&mut runner(seed))).unwrap_or_default();
            ok += usize::from(perception::sim::Scenario::from_yaml(&text, "t").is_ok());
        }
        assert!(ok > 0, "no generated scenario parsed");
        let mut ok = 0;
        for seed in 0..64 {
            let text = String::from_utf8(query(&mut runner(seed))).unwrap_or_default();
            ok += usize::from(logicpad::parse_any_query(&text).is_ok());
        }
        assert!(ok > 16, "only {ok} of 64 generated queries parsed");
    }

    /// Regression: however the edits combine, a document stays within
    /// [`MAX_DOC_NODES`] (repeats of repeats once grew without bound).
    #[test]
    fn edited_documents_stay_bounded() {
        let base = Doc::Map(vec![(
            "a".into(),
            Doc::Seq(vec![Doc::Seq(vec![Doc::Raw("1".into())])]),
        )]);
        let mut d = base.clone();
        for k in 0..12u64 {
            apply(&mut d, 1 + k % 3, 0, &Edit::Repeat(3000));
            apply(&mut d, 2, 0, &Edit::Nest(200));
        }
        assert!(d.count() <= MAX_DOC_NODES, "{}", d.count());
        for seed in 0..64 {
            let mut r = runner(seed);
            let doc = sample(edited(vec![base.clone(), default_config()]), &mut r);
            assert!(doc.count() <= MAX_DOC_NODES);
        }
    }

    #[test]
    fn doc_yaml_and_json_read_back() {
        let d = Doc::Map(vec![
            ("a".into(), Doc::Raw("1".into())),
            (
                "b".into(),
                Doc::Seq(vec![Doc::Raw("2".into()), Doc::Str("x".into())]),
            ),
            (
                "c".into(),
                Doc::Seq(vec![Doc::Map(vec![
                    ("d".into(), Doc::Raw("3".into())),
                    (
                        "e".into(),
                        Doc::Map(vec![("f".into(), Doc::Raw("4".into()))]),
                    ),
                ])]),
            ),
        ]);
        let from_yaml: serde_json::Value = serde_saphyr::from_str(&d.to_yaml()).expect("yaml");
        let from_json: serde_json::Value = serde_json::from_str(&d.to_json()).expect("json");
        assert_eq!(from_yaml, from_json, "{}", d.to_yaml());
    }
}
