use super::*;
use crate::kb::{Observability, test_window};
use logicpad::{Diagnostic, LogicPad};

fn engine() -> Engine {
    Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine")
}

/// A window `id` over `first..=last` with these facts.
fn window(e: &Engine, id: &str, first: u32, last: u32, facts: &[(&str, &[&str])]) -> WindowKb {
    let mut kb = test_window(e.pad().program(), facts);
    kb.id = id.to_string();
    kb.first_frame = first;
    kb.last_frame = last;
    kb
}

const SLOWING: &[(&str, &[&str])] = &[
    ("Vehicles", &["car_1"]),
    ("Moving", &["car_1"]),
    ("SpeedDown", &["car_1"]),
];
const STANDING: &[(&str, &[&str])] = &[("Vehicles", &["car_1"])];
const CRUISING: &[(&str, &[&str])] = &[("Vehicles", &["car_1"]), ("Moving", &["car_1"])];

/// car_1 cruising (frames 0–9), slowing down (10–19), then standing
/// (20–29).
fn story(e: &Engine) -> Vec<WindowKb> {
    vec![
        window(e, "w0", 0, 9, CRUISING),
        window(e, "w1", 10, 19, SLOWING),
        window(e, "w2", 20, 29, STANDING),
    ]
}

fn ask(e: &Engine, text: &str, kbs: &[WindowKb]) -> TemporalAnswer {
    let p = e.prepare_query(text);
    let t = p
        .temporal
        .clone()
        .unwrap_or_else(|| panic!("{text} is temporal: {:?}", p.parsed.err()));
    let refs: Vec<&WindowKb> = kbs.iter().collect();
    answer(e, "video", &t, text, &refs, AskOptions::default())
}

#[test]
fn then_holds_in_order_only() {
    let e = engine();
    let kbs = story(&e);
    let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    assert_eq!(
        a.result.bindings,
        vec![vec![("x".to_string(), "car_1".to_string())]]
    );
    assert_eq!(
        a.headline,
        "yes — x = car_1: `Decelerate(x)` in frames 10–19, then `Stopped(x)` in frames 20–29"
    );
    assert_eq!(a.result.window, "video");
    assert_eq!((a.result.first_frame, a.result.last_frame), (0, 29));
    assert_eq!(a.result.probability, Some(1.0));
    // The proof is both parts' proofs, in their windows.
    let facts: Vec<&str> = a.result.proofs[0].iter().map(|n| n.fact.as_str()).collect();
    assert_eq!(facts, ["Decelerate(car_1)", "Stopped(car_1)"]);
    // BEFORE is THEN; AFTER swaps the parts.
    let b = ask(&e, "(Decelerate(x)) before (Stopped(x))", &kbs);
    assert_eq!(b.result.answer, Outcome::Yes);
    let c = ask(&e, "(Stopped(x)) AFTER (Decelerate(x))", &kbs);
    assert_eq!(c.result.answer, Outcome::Yes);
    assert_eq!(c.parts, ["Decelerate(x)", "Stopped(x)"]);
    // The reverse order is no, saying what was seen.
    let r = ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs);
    assert_eq!(r.result.answer, Outcome::No, "{r:?}");
    assert!(r.headline.contains("never in that order"), "{}", r.headline);
    assert!(r.result.why_not.is_empty());
    assert!(r.result.notes[0].starts_with("x = car_1: `Stopped(x)` in frames 20–29"));
    let r = ask(&e, "(Decelerate(x)) AFTER (Stopped(x))", &kbs);
    assert_eq!(r.result.answer, Outcome::No);
}

#[test]
fn then_needs_the_same_object_on_both_sides() {
    let e = engine();
    let kbs = [
        window(&e, "w0", 0, 9, SLOWING),
        window(
            &e,
            "w1",
            10,
            19,
            &[
                ("Vehicles", &["car_1"]),
                ("Moving", &["car_1"]),
                ("Vehicles", &["car_2"]),
            ],
        ),
    ];
    // car_1 slows, car_2 stands: not the same car.
    let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::No, "{a:?}");
    // Different variables are different objects, each existential.
    let a = ask(&e, "(Decelerate(x)) THEN (Stopped(y))", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    assert!(a.result.variables.is_empty());
    assert_eq!(a.result.bindings, vec![Vec::<(String, String)>::new()]);
}

#[test]
fn one_window_cannot_order_what_it_sees() {
    let e = engine();
    let both: &[(&str, &[&str])] = &[("Vehicles", &["car_1"]), ("SpeedDown", &["car_1"])];
    let kbs = [
        window(&e, "w0", 0, 9, CRUISING),
        window(&e, "w1", 10, 19, both),
    ];
    // Decelerate and Stopped both hold in frames 10–19 only.
    for q in [
        "(Decelerate(x)) THEN (Stopped(x))",
        "(Stopped(x)) THEN (Decelerate(x))",
    ] {
        let a = ask(&e, q, &kbs);
        assert_eq!(a.result.answer, Outcome::Unknown, "{q}: {a:?}");
        assert!(
            a.headline
                .contains("one window cannot tell which came first"),
            "{}",
            a.headline
        );
    }
    // Seen in order elsewhere, the overlap does not make the opposite
    // order unknown.
    let kbs = [
        window(&e, "w0", 0, 9, SLOWING),
        window(&e, "w1", 10, 19, both),
        window(&e, "w2", 20, 29, STANDING),
    ];
    let a = ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::No, "{a:?}");
    assert!(a.headline.contains("opposite order"), "{}", a.headline);
    assert_eq!(
        ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs)
            .result
            .answer,
        Outcome::Yes
    );
}

#[test]
fn overlapping_windows_order_only_what_they_separate() {
    let e = engine();
    // Stride 5 over windows of 10: slowing seen in 0–9 and 5–14,
    // standing in 10–19 and 15–24.
    let kbs = [
        window(&e, "w0", 0, 9, SLOWING),
        window(&e, "w1", 5, 14, SLOWING),
        window(&e, "w2", 10, 19, STANDING),
        window(&e, "w3", 15, 24, STANDING),
    ];
    let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    assert_eq!(
        a.headline,
        "yes — x = car_1: `Decelerate(x)` in frames 0–9, then `Stopped(x)` in frames 10–19"
    );
    assert_eq!(
        a.holds[0].parts[0].frames,
        [Frames { first: 0, last: 14 }],
        "overlapping windows merge"
    );
    assert_eq!(
        ask(&e, "(Stopped(x)) THEN (Decelerate(x))", &kbs)
            .result
            .answer,
        Outcome::No
    );
    // Only overlapping windows between them: not proven.
    let kbs = [
        window(&e, "w0", 0, 9, SLOWING),
        window(&e, "w1", 5, 14, STANDING),
    ];
    assert_eq!(
        ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs)
            .result
            .answer,
        Outcome::Unknown
    );
}

#[test]
fn a_part_already_going_on_is_not_after() {
    let e = engine();
    // car_2 stands in every window; car_1 slows down in 10–19 only.
    let standing: &[(&str, &[&str])] = &[("Vehicles", &["car_2"])];
    let slowing: &[(&str, &[&str])] = &[
        ("Vehicles", &["car_2"]),
        ("Vehicles", &["car_1"]),
        ("Moving", &["car_1"]),
        ("SpeedDown", &["car_1"]),
    ];
    let kbs = [
        window(&e, "w0", 0, 9, standing),
        window(&e, "w1", 10, 19, slowing),
        window(&e, "w2", 20, 29, standing),
    ];
    // A window of slowing (10–19) ends before a window of standing
    // (20–29) starts, but car_2 had stood since frame 0: "did a car
    // slow down before the other stopped?" is no.
    let a = ask(&e, "(Decelerate(y)) THEN (Stopped(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::No, "{a:?}");
    assert!(a.headline.contains("already going on"), "{}", a.headline);
    // The slowing car's own standing after it began later: yes.
    let kbs = story(&e);
    let a = ask(&e, "(Decelerate(x)) THEN (Stopped(x))", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
}

#[test]
fn chains_order_every_step() {
    let e = engine();
    let kbs = story(&e);
    let q = "(Move(x)) THEN (Decelerate(x)) THEN (Stopped(x))";
    let a = ask(&e, q, &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    assert_eq!(a.holds[0].parts.len(), 3);
    let q = "(Decelerate(x)) THEN (Move(x)) THEN (Stopped(x))";
    // Move holds in 10–19 too (Moving), so the middle step has no
    // window after 10–19 and before 20–29.
    assert_ne!(ask(&e, q, &kbs).result.answer, Outcome::Yes);
}

#[test]
fn ever_throughout_and_still() {
    let e = engine();
    let mut kbs = story(&e);
    kbs.push(window(
        &e,
        "w3",
        30,
        39,
        &[
            ("Vehicles", &["car_1"]),
            ("Vehicles", &["car_2"]),
            ("Moving", &["car_2"]),
        ],
    ));
    let a = ask(&e, "EVER: Stopped(x)", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes);
    assert_eq!(a.headline, "yes — x = car_1: `Stopped(x)` in frames 20–39");
    assert_eq!(
        ask(&e, "ever: Pedestrian(x)", &kbs).result.answer,
        Outcome::No
    );
    // car_1 is a vehicle in every window it is seen; car_2 too.
    let a = ask(&e, "THROUGHOUT: Vehicles(x)", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes);
    assert_eq!(a.result.count, 2);
    // car_1 does not move in 20–39; car_2 moves in the one window it
    // is seen in.
    let a = ask(&e, "THROUGHOUT: Moving(x)", &kbs);
    assert_eq!(
        a.result.bindings,
        vec![vec![("x".to_string(), "car_2".to_string())]]
    );
    assert_eq!(
        ask(&e, "THROUGHOUT: Moving(car_1)", &kbs).result.answer,
        Outcome::No
    );
    // Still: car_1 stands from 20–29 to the end.
    let a = ask(&e, "STILL: Stopped(x)", &kbs);
    assert_eq!(a.result.answer, Outcome::Yes, "{a:?}");
    assert_eq!(
        a.headline,
        "yes — x = car_1: `Stopped(x)` since frames 20–29, through the last window (frames 30–39)"
    );
    // Moving: car_2 still moves; car_1 moved, then stopped.
    let a = ask(&e, "STILL: Moving(car_1)", &kbs);
    assert_eq!(a.result.answer, Outcome::No);
    assert!(
        a.headline.contains("not in the last window"),
        "{}",
        a.headline
    );
}

#[test]
fn a_window_that_cannot_tell_makes_no_unknown() {
    // The source cannot observe motion at all.
    let e = engine().for_source(Observability::everything().without(
        &["SpeedDown", "SpeedUp", "Moving"],
        "no motion in this source",
    ));
    let kbs = [
        window(&e, "w0", 0, 9, STANDING),
        window(&e, "w1", 10, 19, STANDING),
    ];
    for q in [
        "(Decelerate(x)) THEN (Stopped(x))",
        "EVER: Decelerate(x)",
        "THROUGHOUT: Decelerate(x)",
        "STILL: Decelerate(x)",
    ] {
        let a = ask(&e, q, &kbs);
        assert_eq!(a.result.answer, Outcome::Unknown, "{q}: {a:?}");
        assert!(
            a.result
                .reasons
                .iter()
                .any(|r| r.contains("no motion in this source")),
            "{q}: {:?}",
            a.result.reasons
        );
    }
    // A claim that holds is yes whatever cannot be told elsewhere.
    assert_eq!(
        ask(&e, "EVER: Vehicles(x)", &kbs).result.answer,
        Outcome::Yes
    );
}

#[test]
fn parse_errors_are_diagnostics_with_spans() {
    let e = engine();
    let err = |text: &str| -> Vec<Diagnostic> {
        match parse(e.pad(), text) {
            Some(Err(d)) => d,
            other => panic!("{text}: expected diagnostics, got {other:?}"),
        }
    };
    let d = err("(Decelerate(x)) THEN");
    assert_eq!(d[0].message, "expected a query after `THEN`");
    assert_eq!(d[0].snippet(), "THEN");
    let d = err("THEN (Stopped(x))");
    assert_eq!(d[0].message, "expected a query before `THEN`");
    let d = err("EVER:");
    assert_eq!(d[0].message, "expected a query after `EVER:`");
    // An unknown predicate in the second part points into it.
    let d = err("(Decelerate(x)) THEN (Levitates(x))");
    assert_eq!(d[0].snippet(), "Levitates");
    assert_eq!(d[0].column(), 23);
    let d = err("(Decelerate(x)) THEN (Stopped(x)) AFTER (Move(x))");
    assert!(d[0].message.contains("ambiguous"), "{}", d[0].message);
    let d = err("(EVER: Decelerate(x)) THEN (Stopped(x))");
    assert!(
        d[0].message.contains("cannot stand inside"),
        "{}",
        d[0].message
    );
    let d = err("THROUGHOUT: (Decelerate(x)) THEN (Stopped(x))");
    assert!(d[0].message.contains("do not nest"), "{}", d[0].message);
    let d = err("(∀x: Vehicles(x) → Moving(x)) THEN (Stopped(x))");
    assert!(d[0].message.contains("universal"), "{}", d[0].message);
    let d = err("(Decelerate(x) THEN Stopped(x)");
    assert!(
        d[0].message.contains("must stand between"),
        "{}",
        d[0].message
    );
    // Not temporal: left to the query parser.
    for q in [
        "Moving(x)",
        "Then(x)",
        "Moving(then)",
        "Vehicles(x) ^ ¬∃y: (Road(y) ^ On(x, y))",
    ] {
        assert!(parse(e.pad(), q).is_none(), "{q}");
    }
    // Well formed: whole-query parentheses, ∧ inside, any case.
    for q in [
        "((Decelerate(x)) THEN (Stopped(x)))",
        "(Vehicles(x) ∧ Decelerate(x)) then (Stopped(x))",
        "Decelerate(x) THEN Stopped(x)",
        "ever : Stopped(x)",
        "EVER: (Decelerate(x)) THEN (Stopped(x))",
    ] {
        assert!(matches!(parse(e.pad(), q), Some(Ok(_))), "{q}");
    }
}

proptest::proptest! {
    #![proptest_config(proptest::prelude::ProptestConfig { cases: 256, ..Default::default() })]

    /// Any text made of the forms' pieces is prepared without a panic:
    /// a query, or diagnostics whose spans lie in the text.
    #[test]
    fn any_arrangement_of_the_pieces_prepares(pieces in proptest::collection::vec(
        proptest::sample::select(vec![
            "(", ")", " THEN ", " then ", " AFTER ", " BEFORE ", "EVER:", "STILL :",
            "THROUGHOUT:", "Stopped(x)", "Decelerate(x)", " ^ ", "∧", "é", "¬∃y: ", ":", " ",
        ]),
        0..12,
    )) {
        static ENGINE: std::sync::OnceLock<Engine> = std::sync::OnceLock::new();
        let e = ENGINE.get_or_init(engine);
        let text: String = pieces.concat();
        let p = e.prepare_query(&text);
        if let Err(diags) = &p.parsed {
            for d in diags {
                proptest::prop_assert!(d.span.end <= text.len(), "{text}: {d:?}");
            }
        }
        if p.temporal.is_some() {
            proptest::prop_assert!(p.parsed.is_ok());
        }
    }
}

#[test]
fn a_window_alone_answers_a_temporal_query_invalid() {
    let e = engine();
    let kb = window(&e, "w0", 0, 9, SLOWING);
    let p = e.prepare_query("(Decelerate(x)) THEN (Stopped(x))");
    assert!(p.temporal.is_some());
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Invalid);
    assert!(
        r.reasons[0].contains("one window alone cannot answer it"),
        "{:?}",
        r.reasons
    );
    assert_eq!(r.query, "(Decelerate(x)) THEN (Stopped(x))");
    // An invalid part makes the whole query invalid, with its span.
    let p = e.prepare_query("EVER: Levitates(x)");
    assert!(p.temporal.is_none());
    let Err(d) = &p.parsed else { panic!("invalid") };
    assert_eq!(d[0].snippet(), "Levitates");
    assert_eq!(
        e.ask(&kb, &p, AskOptions::default()).answer,
        Outcome::Invalid
    );
}
