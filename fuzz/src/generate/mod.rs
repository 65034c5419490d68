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

mod doc;
mod documents;
mod lines;
mod logic;
mod questions;

pub use doc::{Doc, MAX_DOC_NODES};
pub use documents::{
    camera, config_json, config_yaml, model_config, scenario_json, scenario_yaml, tracks_json,
};
pub use lines::{facts, kitti_calib, kitti_labels, queries_tsv};
pub use logic::{fol, logicpad, query};
pub use questions::{llm_reply, question, question_csv, source_spec};

#[cfg(test)]
mod tests;
