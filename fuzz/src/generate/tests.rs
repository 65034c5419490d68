//! The generators' tests: determinism, documents the readers accept,
//! bounded edits.

use super::doc::{Edit, apply, edited};
use super::documents::default_config;
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
