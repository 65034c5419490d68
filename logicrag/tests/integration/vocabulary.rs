//! One vocabulary. The built-in LogicPad (`logicpad/LogicPad.yaml`) declares
//! the predicates, the values of `TypeOf`/`ColorOf`, the roles and the
//! everyday phrases; perception, the sources and the translator must say
//! the same, and a user's new predicate gets words from its entry alone.

use std::collections::BTreeSet;

use logicpad::{BUILTIN_SOURCE, LogicPad, PredKind, Role};
use logicrag::translate::{Translator, Vocabulary};

fn set<'a>(names: impl IntoIterator<Item = &'a str>) -> BTreeSet<String> {
    names.into_iter().map(str::to_string).collect()
}

fn declared_values(pad: &LogicPad, function: &str) -> BTreeSet<String> {
    match pad.schema().values(function) {
        Some(vs) => set(vs.iter().map(String::as_str)),
        None => panic!("the built-in LogicPad declares no function {function}"),
    }
}

#[test]
fn perception_emits_exactly_the_declared_type_and_colour_values() {
    let pad = LogicPad::builtin();
    assert_eq!(
        set(perception::facts::TYPE_VALUES),
        declared_values(&pad, "TypeOf"),
        "perception's TYPE_VALUES and the LogicPad's TypeOf values differ"
    );
    let colours = declared_values(&pad, "ColorOf");
    assert_eq!(
        set(perception::facts::COLOR_VALUES),
        colours,
        "perception's COLOR_VALUES (facts) and the LogicPad's ColorOf values differ"
    );
    assert_eq!(
        set(perception::raw::color::COLOR_VALUES),
        colours,
        "the colour namer's COLOR_VALUES and the LogicPad's ColorOf values differ"
    );
}

#[test]
fn perception_classes_are_the_declared_class_predicates() {
    let pad = LogicPad::builtin();
    let declared = set(pad
        .schema()
        .predicates()
        .filter(|p| p.kind == PredKind::Atomic && p.role == Some(Role::Class))
        .map(|p| p.name.as_str()));
    assert_eq!(
        set(perception::raw::config::CLASS_PREDICATES.iter().copied()),
        declared,
        "perception's CLASS_PREDICATES and the LogicPad's atomic class predicates differ"
    );
}

#[test]
fn every_predicate_a_source_cannot_observe_is_declared() {
    let pad = LogicPad::builtin();
    let unknown: Vec<&str> = logicrag::source::KITTI_UNOBSERVABLE
        .iter()
        .copied()
        .filter(|p| pad.schema().get(p).is_none())
        .collect();
    assert!(
        unknown.is_empty(),
        "KITTI_UNOBSERVABLE names predicates the LogicPad does not declare: {unknown:?}"
    );
}

#[test]
fn the_builtin_vocabulary_is_the_logicpads() {
    let pad = LogicPad::builtin();
    // With the LogicPad's rules (the classes each property is defined
    // for), as the engine builds it.
    let from_pad = Vocabulary::from_schema(pad.schema())
        .expect("a vocabulary")
        .with_rules(pad.program());
    assert_eq!(Vocabulary::builtin(), from_pad);
    // Every class with words is askable by its first phrase.
    let t = Translator::builtin();
    for p in pad.schema().predicates() {
        let (Some(Role::Class), Some(phrase)) = (p.role, p.phrases.first()) else {
            continue;
        };
        let q = format!("Is there a {phrase}?");
        assert_eq!(
            t.translate(&q).map(|t| t.query),
            Ok(format!("{}(x)", p.name)),
            "{q}"
        );
    }
}

#[test]
fn a_new_predicate_gets_its_words_from_its_entry() {
    // The built-in LogicPad ends with its derived predicates: an entry
    // appended there is one more of them.
    let src = format!(
        "{BUILTIN_SOURCE}
  - name: Tailgating
    role: property
    phrases: [tailgating]
    logic: \"∀x,y : Vehicles(x) ∧ Behind(x, y) ∧ TooClose(x, y) ==> Tailgating(x)\"
"
    );
    let pad = match LogicPad::parse(&src, "tailgating.yaml", true) {
        Ok(p) => p,
        Err(e) => panic!("{e}"),
    };
    let t = Translator::new(Vocabulary::from_schema(pad.schema()).expect("a vocabulary"));
    assert_eq!(
        t.translate("Is the truck tailgating?").map(|t| t.query),
        Ok("TypeOf(x, Truck)^Tailgating(x)".to_string())
    );
    // The built-in vocabulary has no such word.
    assert!(
        Translator::builtin()
            .translate("Is the truck tailgating?")
            .is_err()
    );
}
