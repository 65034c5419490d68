//! Formulas, rules, queries and LogicPad documents, from the built-in
//! LogicPad's vocabulary.

use proptest::collection::vec;
use proptest::prelude::*;
use proptest::sample::select;
use proptest::test_runner::TestRunner;

use super::doc::quote;
use super::{sample, vocab};

// ----------------------------------------------------------------------- FOL

const AND: &[&str] = &["∧", "^", "&", "&&", "and", " ∧ "];
const OR: &[&str] = &["∨", "|", "||", "or"];
const NOT: &[&str] = &["¬", "~", "!", "not "];
const IMPLIES: &[&str] = &["==>", "=>", "->", "→", "⇒", "⟹", "⊃", "implies"];
const FORALL: &[&str] = &["∀", "forall "];
const EXISTS: &[&str] = &["∃", "exists "];
const SEP: &[&str] = &[":", " :", ".", " . ", ""];
const VARS: &[&str] = &["x", "y", "z", "u", "v", "w", "x1", "v11", "?p", "?obj"];
pub(super) const CONSTS: &[&str] = &[
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

pub(super) fn pred_name() -> impl Strategy<Value = (String, usize)> {
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
pub(super) fn query_text() -> impl Strategy<Value = String> {
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
