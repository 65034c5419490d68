use super::*;
use crate::ask::Outcome;
use crate::kb::test_window;
/// `--translator` and `--llm` choose the translator; the LLM one needs a
/// server, and `auto` without one is the grammar alone. Queries are
/// taken as written whatever the translator.
#[test]
fn translator_modes() {
    assert!(matches!(
        translator(TranslatorMode::Llm, None),
        Err(PrepareError::NoLlm)
    ));
    for mode in [TranslatorMode::Grammar, TranslatorMode::Auto] {
        let t = translator(mode, None).map_err(|e| e.to_string());
        assert_eq!(t.map(|t| t.mode()), Ok(TranslatorMode::Grammar));
    }
    let e = engine();
    let p = e
        .prepare_with(&Grammar, "Vehicles(x)")
        .map_err(|e| e.to_string());
    assert_eq!(p.map(|p| p.question), Ok(None));
    let p = e
        .prepare_with(&Grammar, "Is there a car?")
        .map_err(|e| e.to_string());
    assert!(p.is_ok_and(|p| p.question.is_some()));
}

fn engine() -> Engine {
    Engine::new(LogicPad::builtin(), Observability::everything()).expect("builtin engine")
}

#[test]
fn an_absent_constant_is_a_constant_and_answers_no() {
    // Regression: `TypeOf(car_3, Sedan)` on a window without car_3 made
    // car_3 a variable and answered "yes, car_3 = sedan_6".
    let e = engine();
    let kb = test_window(
        e.pad().program(),
        &[
            ("Vehicles", &["sedan_6"]),
            ("TypeOf", &["sedan_6", "Sedan"]),
            ("Moving", &["sedan_6"]),
            ("Moving", &["car_4"]),
            ("Vehicles", &["car_4"]),
            ("ColorOf", &["car_4", "Red"]),
        ],
    );
    for q in ["TypeOf(car_3, Sedan)", "Moving(foo)", "ColorOf(car_1, x)"] {
        let p = e.prepare(q).expect("prepares");
        let r = e.ask(&kb, &p, AskOptions::default());
        assert_eq!(r.answer, Outcome::No, "{q}: {r:?}");
        assert!(
            r.notes
                .iter()
                .any(|n| n.contains("is not seen in frames 0–9")),
            "{q}: {:?}",
            r.notes
        );
    }
    // `x != car_1` with car_1 absent is a safe comparison with a constant.
    let p = e.prepare("Moving(x) ^ x != car_1").expect("prepares");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Yes, "{r:?}");
    assert_eq!(r.count, 2);
    // A constant only under ¬ proves nothing absent.
    let p = e.prepare("Vehicles(x) ^ ¬On(x, road_9)").expect("prepares");
    assert_eq!(e.ask(&kb, &p, AskOptions::default()).answer, Outcome::Yes);
}

#[test]
fn a_universal_is_answered_under_the_closed_world() {
    let e = engine();
    let kb = test_window(
        e.pad().program(),
        &[
            ("Vehicles", &["car_1"]),
            ("Moving", &["car_1"]),
            ("Vehicles", &["car_2"]),
            ("Pedestrian", &["ped_1"]),
        ],
    );
    // Regression: `forall x: Moving(x)` was read as `Moving(x)`: YES.
    let p = e.prepare("forall x: Moving(x)").expect("prepares");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Invalid);
    assert!(
        r.reasons
            .iter()
            .any(|s| s.contains("ranges over everything")),
        "{:?}",
        r.reasons
    );
    let p = e
        .prepare("forall x: Vehicles(x) -> Moving(x)")
        .expect("prepares");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::No);
    assert_eq!(
        r.why_not.first().map(|w| w.candidate.as_str()),
        Some("car_2")
    );
    let p = e
        .prepare("∀x: Vehicles(x) ∧ Moving(x) → Move(x)")
        .expect("prepares");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Yes);
    assert_eq!(
        r.bindings,
        vec![vec![("x".to_string(), "car_1".to_string())]]
    );
    assert!(!r.proofs.is_empty());
    let p = e.prepare("∀x: Cyclist(x) → Moving(x)").expect("prepares");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Yes);
    assert!(
        r.notes.iter().any(|n| n.starts_with("vacuously")),
        "{:?}",
        r.notes
    );
    // A universal over what the source cannot see is unknown.
    let blind = e.for_source(Observability::everything().without(&["Moving"], "no motion here"));
    let p = blind
        .prepare("∀x: Vehicles(x) → Moving(x)")
        .expect("prepares");
    let r = blind.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Unknown);
    assert!(
        r.reasons.iter().any(|s| s.contains("no motion here")),
        "{:?}",
        r.reasons
    );
}

#[test]
fn a_count_over_a_video_counts_distinct_objects_of_every_window() {
    // Two windows of two cars each, one car in both: three distinct
    // cars, though no window alone has more than two.
    let e = engine();
    let k1 = test_window(
        e.pad().program(),
        &[
            ("Vehicles", &["car_1"]),
            ("TypeOf", &["car_1", "Car"]),
            ("Vehicles", &["car_2"]),
            ("TypeOf", &["car_2", "Car"]),
        ],
    );
    let k2 = test_window(
        e.pad().program(),
        &[
            ("Vehicles", &["car_2"]),
            ("TypeOf", &["car_2", "Car"]),
            ("Vehicles", &["car_3"]),
            ("TypeOf", &["car_3", "Car"]),
        ],
    );
    let p = e.prepare_query("#{x: TypeOf(x, Car)} > 2");
    let rs = [
        e.ask(&k1, &p, AskOptions::default()),
        e.ask(&k2, &p, AskOptions::default()),
    ];
    assert!(rs.iter().all(|r| r.answer == Outcome::No && r.count == 2));
    assert_eq!(
        rs[0].notes,
        vec!["found 2 cars (car_1, car_2); the question asks for more than 2"]
    );
    let s = Summary::new(e.words(), &p, &rs);
    assert_eq!(s.answer, Outcome::Yes);
    assert_eq!((s.how_many, s.unit.as_deref()), (Some(3), Some("cars")));
    assert_eq!(
        s.headline(),
        "yes (3 cars over 2 windows; the question asks for more than 2)"
    );
    // Each window keeps its own answer; "exactly 2" holds in each and
    // fails over the video.
    let p = e.prepare_query("#{x: TypeOf(x, Car)} = 2");
    let rs = [
        e.ask(&k1, &p, AskOptions::default()),
        e.ask(&k2, &p, AskOptions::default()),
    ];
    assert!(rs.iter().all(|r| r.answer == Outcome::Yes));
    assert_eq!(Summary::new(e.words(), &p, &rs).answer, Outcome::No);
}

#[test]
fn how_many_counts_distinct_objects_and_symmetric_pairs_once() {
    let e = engine();
    let kb = test_window(
        e.pad().program(),
        &[
            ("Pedestrian", &["ped_1"]),
            ("Pedestrian", &["ped_2"]),
            ("Moving", &["ped_1"]),
            ("Moving", &["ped_2"]),
            ("Vehicles", &["car_1"]),
            ("Vehicles", &["car_2"]),
            ("TooClose", &["car_1", "car_2"]),
            ("TooClose", &["car_2", "car_1"]),
        ],
    );
    let mut p = e.prepare_query("Pedestrian(x) ^ Walk(x)");
    p.intent = crate::translate::Intent::HowMany;
    let r = e.ask(&kb, &p, AskOptions::default());
    let s = Summary::new(e.words(), &p, &[r.clone(), r]);
    assert_eq!(
        (s.how_many, s.unit.as_deref()),
        (Some(2), Some("pedestrians"))
    );
    assert!(
        s.headline()
            .starts_with("2 pedestrians — in 2 of 2 windows: frames 0–9"),
        "{}",
        s.headline()
    );
    let mut p = e.prepare_query("Vehicles(x) ^ Vehicles(y) ^ TooClose(x, y)");
    p.intent = crate::translate::Intent::HowMany;
    let s = Summary::new(e.words(), &p, &[e.ask(&kb, &p, AskOptions::default())]);
    assert_eq!((s.how_many, s.unit.as_deref()), (Some(1), Some("pairs")));
    assert_eq!(s.headline(), "1 pair — in frames 0–9");
}

#[test]
fn a_closed_no_query_over_a_video_fails_in_one_window() {
    let e = engine();
    let empty = test_window(e.pad().program(), &[("Vehicles", &["car_1"])]);
    let with = test_window(e.pad().program(), &[("Pedestrian", &["ped_1"])]);
    let p = e.prepare_query("¬∃x: (Pedestrian(x))");
    assert!(p.is_closed_negation());
    let (a, b) = (
        e.ask(&empty, &p, AskOptions::default()),
        e.ask(&with, &p, AskOptions::default()),
    );
    assert_eq!((a.answer, b.answer), (Outcome::Yes, Outcome::No));
    // "Are there no pedestrians?" over a video with one: no, though
    // a window without one says yes.
    let s = Summary::new(e.words(), &p, &[a.clone(), b]);
    assert_eq!(s.answer, Outcome::No);
    assert_eq!(
        Summary::new(e.words(), &p, &[a.clone(), a]).answer,
        Outcome::Yes
    );
    // An open query with a negation stays existential over windows.
    let open = e.prepare_query("Vehicles(x) ^ ¬∃y: (Pedestrian(y))");
    assert!(!open.is_closed_negation());
}

#[test]
fn value_questions_are_answered_by_their_values() {
    let e = engine();
    let kb = test_window(
        e.pad().program(),
        &[
            ("Vehicles", &["van_3"]),
            ("TypeOf", &["van_3", "Van"]),
            ("ColorOf", &["van_3", "White"]),
        ],
    );
    let p = e.prepare("What colour is the van?").expect("translates");
    let r = e.ask(&kb, &p, AskOptions::default());
    let s = Summary::new(e.words(), &p, &[r]);
    assert_eq!(s.values, ["White"]);
    assert_eq!(s.headline(), "White — in frames 0–9");
}

#[test]
fn unknown_says_what_the_source_lacks_in_words() {
    let e = Engine::new(
        LogicPad::builtin(),
        Observability::everything().without(
            &["Road", "Sidewalk", "On"],
            "KITTI labels carry no road or sidewalk",
        ),
    )
    .expect("engine");
    let kb = test_window(e.pad().program(), &[("Pedestrian", &["ped_1"])]);
    let p = e.prepare_query("Pedestrian(x) ^ Cross(x)");
    let r = e.ask(&kb, &p, AskOptions::default());
    assert_eq!(r.answer, Outcome::Unknown);
    let text = r.reasons.join("\n");
    assert!(
        text.contains("KITTI labels carry no road or sidewalk"),
        "{text}"
    );
    assert!(text.contains("`Cross`"), "{text}");
}

mod props {
    use super::*;
    use crate::kb::test_window;
    use proptest::prelude::*;

    const PRESENT: [&str; 3] = ["car_1", "car_2", "ped_1"];
    const ABSENT: [&str; 3] = ["car_3", "foo", "ped_9"];

    /// A fact: predicate and arguments.
    type FactRow = (String, Vec<String>);
    /// A query atom: negated, predicate, arguments.
    type AtomRow = (bool, String, Vec<String>);

    /// A random window over the present objects, and a random conjunctive
    /// query over x, y and constants (present or absent).
    fn window_and_query() -> impl Strategy<Value = (Vec<FactRow>, Vec<AtomRow>)> {
        let obj = prop::sample::select(PRESENT.to_vec()).prop_map(str::to_string);
        let unary = (
            prop::sample::select(vec!["Vehicles", "Pedestrian", "Moving", "SpeedUp"]),
            obj.clone(),
        )
            .prop_map(|(p, o)| (p.to_string(), vec![o]));
        let binary = (
            prop::sample::select(vec!["TooClose", "DistanceDecrease"]),
            obj.clone(),
            obj,
        )
            .prop_map(|(p, a, b)| (p.to_string(), vec![a, b]));
        let facts = prop::collection::vec(prop_oneof![unary, binary], 0..12);
        let term = prop::sample::select(vec!["x", "y", "car_1", "ped_1", "car_3", "foo", "ped_9"])
            .prop_map(str::to_string);
        let atom = (
            any::<bool>(),
            prop::sample::select(vec![
                "Vehicles",
                "Pedestrian",
                "Moving",
                "TooClose",
                "DistanceDecrease",
            ]),
            term.clone(),
            term,
        )
            .prop_map(|(neg, p, a, b)| {
                let args = if matches!(p, "TooClose" | "DistanceDecrease") {
                    vec![a, b]
                } else {
                    vec![a]
                };
                (neg, p.to_string(), args)
            });
        (facts, prop::collection::vec(atom, 1..4))
    }

    fn text(atoms: &[AtomRow], rename: Option<(&str, &str)>) -> String {
        let mut atoms: Vec<_> = atoms.to_vec();
        // Positive atoms first so negations are bound where possible.
        atoms.sort_by_key(|(neg, _, _)| *neg);
        atoms
            .iter()
            .map(|(neg, p, args)| {
                let args: Vec<&str> = args
                    .iter()
                    .map(|a| match rename {
                        Some((from, to)) if a == from => to,
                        _ => a.as_str(),
                    })
                    .collect();
                format!("{}{p}({})", if *neg { "¬" } else { "" }, args.join(", "))
            })
            .collect::<Vec<_>>()
            .join(" ∧ ")
    }

    proptest! {
        #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

        /// Whether a name is a constant never depends on the window: renaming
        /// an absent object to another absent name changes no outcome, and a
        /// query that needs an absent object in a positive atom is never yes.
        #[test]
        fn renaming_an_absent_object_never_turns_no_into_yes((facts, atoms) in window_and_query(), to in prop::sample::select(ABSENT.to_vec())) {
            let e = Engine::new(LogicPad::builtin(), Observability::everything()).expect("engine");
            let lines: Vec<(&str, Vec<&str>)> = facts.iter().map(|(p, a)| (p.as_str(), a.iter().map(String::as_str).collect())).collect();
            let refs: Vec<(&str, &[&str])> = lines.iter().map(|(p, a)| (*p, a.as_slice())).collect();
            let kb = test_window(e.pad().program(), &refs);
            let q = text(&atoms, None);
            let base = e.ask(&kb, &e.prepare_query(&q), AskOptions::BINDINGS);
            for from in ABSENT {
                if kb.constants.contains(from) { continue; }
                let renamed = text(&atoms, Some((from, to)));
                let r = e.ask(&kb, &e.prepare_query(&renamed), AskOptions::BINDINGS);
                prop_assert_eq!(base.answer, r.answer, "{} vs {}", q, renamed);
                prop_assert_eq!(base.count, r.count, "{} vs {}", q, renamed);
            }
            let needs_absent = atoms.iter().any(|(neg, _, args)| !neg && args.iter().any(|a| ABSENT.contains(&a.as_str())));
            if needs_absent {
                prop_assert_ne!(base.answer, Outcome::Yes, "{}", q);
            }
        }
    }
}

mod taxonomy_tests {
    use super::*;

    #[test]
    fn the_builtin_taxonomy_makes_every_car_body_style_a_car_and_vans_not() {
        let words = crate::context::Sentences::builtin();
        let up = words.supertypes("TypeOf").cloned().unwrap_or_default();
        for sub in [
            "Sedan",
            "SUV",
            "Coupe",
            "Hatchback",
            "Wagon",
            "Minivan",
            "Cab",
            "Convertible",
            "PoliceCar",
        ] {
            assert!(
                up.get(sub).is_some_and(|s| s.contains("Car")),
                "{sub}: {up:?}"
            );
        }
        for not_car in ["Car", "Van", "Truck", "Bus", "Tram", "Pedestrian"] {
            assert!(
                !up.get(not_car).is_some_and(|s| s.contains("Car")),
                "{not_car}"
            );
        }
        assert!(words.supertypes("ColorOf").is_none());
    }

    #[test]
    fn taxonomy_edges_are_closed_transitively_and_ignore_other_rules() {
        let pad = LogicPad::parse(
            r#"
atomic_predicates:
  a:
    - predicate: Vehicles(x)
functions:
  f:
    TypeOf:
      predicate: TypeOf(x, type)
      values: [Car, Sedan, Limousine, Van]
derived_predicates:
  - name: TypeOf
    logic:
      - "∀x : TypeOf(x, Sedan) ==> TypeOf(x, Car)"
      - "∀x : TypeOf(x, Limousine) ==> TypeOf(x, Sedan)"
      - "∀x : TypeOf(x, Van) ∧ Vehicles(x) ==> TypeOf(x, Car)"
"#,
            "t.yaml",
            false,
        )
        .unwrap();
        let up = taxonomy_edges(pad.program(), "TypeOf");
        let set = |v: &[&str]| v.iter().map(|s| s.to_string()).collect::<BTreeSet<_>>();
        assert_eq!(up.get("Limousine"), Some(&set(&["Car", "Sedan"])));
        assert_eq!(up.get("Sedan"), Some(&set(&["Car"])));
        // Two body atoms: not a plain is-a edge.
        assert_eq!(up.get("Van"), None);
    }

    /// urban_crossing's agents: car_1 and car_4 (Car), suv_2 (SUV), van_3
    /// (Van), the blue sedan_6 driving, pedestrian_5.
    #[test]
    fn a_sedan_is_counted_as_a_car_and_a_type_question_names_the_sedan() {
        let loaded = crate::source::load(
            &"sim:urban_crossing".parse().unwrap(),
            &crate::source::LoadOptions::default(),
            &mut |_| {},
        )
        .unwrap();
        let e = Engine::new(LogicPad::builtin(), loaded.observability).unwrap();
        let kbs: Vec<WindowKb> = loaded
            .windows
            .into_iter()
            .map(|w| WindowKb::build(w, e.pad().program()).unwrap())
            .collect();
        let run = |query: &str, intent: crate::translate::Intent| {
            let mut p = e.prepare(query).unwrap();
            p.intent = intent;
            let results: Vec<AskResult> = kbs
                .iter()
                .map(|kb| e.ask(kb, &p, AskOptions::default()))
                .collect();
            Summary::new(e.words(), &p, &results)
        };
        use crate::translate::Intent;
        let cars = run("TypeOf(x, Car)", Intent::Which);
        assert_eq!(cars.values, ["car_1", "car_4", "sedan_6", "suv_2"]);
        let how_many = run("TypeOf(x, Car)", Intent::HowMany);
        assert_eq!(how_many.how_many, Some(4));
        let moving = run("TypeOf(x, Car) ^ Move(x)", Intent::Which);
        assert_eq!(moving.values, ["sedan_6"]);
        let what = run(
            "TypeOf(x, Sedan) ^ ColorOf(x, Blue) ^ TypeOf(x, y)",
            Intent::Which,
        );
        assert_eq!(what.values, ["Sedan"]);
        // Whatever car: each object's most specific type.
        let types = run("TypeOf(x, Car) ^ TypeOf(x, y)", Intent::Which);
        assert_eq!(types.values, ["Car", "SUV", "Sedan"]);
    }
}
