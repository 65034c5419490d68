use super::claims::{atom_satisfiable, bind_var};
use super::scores::{cmp_holds, not_exists_holds};
use super::*;
use crate::ask::{AskOptions, AskResult, Outcome, ask, prepare};
use crate::kb::{Observed, test_window};
use logicpad::ParsedQuery;
use logicpad::fol::Arg;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// Every predicate of the LogicPad fully observed: claims answer yes or no.
fn all_observed(pad: &LogicPad) -> BTreeMap<String, Observed> {
    pad.schema()
        .predicates()
        .map(|p| (p.name.clone(), Observed::Fully))
        .collect()
}

/// `q` asked of `kb`, every predicate observed, with the default options.
fn ask_all(pad: &LogicPad, kb: &WindowKb, q: &str) -> AskResult {
    ask(pad, kb, &all_observed(pad), q, AskOptions::default())
}

/// The claims of `r`'s why-not that the engine contradicts (empty when
/// all agree), every predicate observed.
fn contradicted(pad: &LogicPad, kb: &WindowKb, r: &AskResult) -> Vec<String> {
    audit(pad, kb, &all_observed(pad), r)
}

/// The why-not candidate named for variable `v`.
fn candidate_for<'r>(r: &'r AskResult, v: &str) -> &'r WhyNot {
    r.why_not
        .iter()
        .find(|w| w.variable == v)
        .unwrap_or_else(|| panic!("a candidate for {v}"))
}

/// The two-roads case: "is the pedestrian not on a road?" is no for
/// ped_1, and why-not names the blocking match; "are there no
/// trucks?" is no, named with the truck. Every claim is asked back.
#[test]
fn a_failed_negated_exists_is_named_with_its_blocking_match() {
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Pedestrian", &["ped_1"]),
            ("Road", &["road_1"]),
            ("Road", &["road_2"]),
            ("On", &["ped_1", "road_1"]),
            ("Vehicles", &["truck_1"]),
            ("TypeOf", &["truck_1", "Truck"]),
        ],
    );
    let q = "Pedestrian(x) ∧ ¬∃y: (Road(y) ∧ On(x, y))";
    let r = ask_all(&pad, &kb, q);
    assert_eq!(r.answer, Outcome::No);
    let w = &r.why_not[0];
    assert_eq!(w.candidate, "ped_1");
    assert_eq!(w.failed, vec!["¬∃y: (Road(y) ∧ On(ped_1, y))"]);
    assert!(
        w.satisfied
            .contains(&"Road(road_1) ∧ On(ped_1, road_1)".to_string()),
        "{w:?}"
    );
    assert!(
        contradicted(&pad, &kb, &r).is_empty(),
        "{:?}",
        contradicted(&pad, &kb, &r)
    );
    assert!(r.why_not.iter().all(claims_say_their_words), "{r:?}");
    // The loose reading answers yes: some road ped_1 is not on.
    let loose = ask_all(&pad, &kb, "Pedestrian(x) ∧ Road(y) ∧ ¬On(x, y)");
    assert_eq!(loose.answer, Outcome::Yes);
    let r = ask_all(&pad, &kb, "¬∃x: (TypeOf(x, Truck))");
    assert_eq!(r.answer, Outcome::No);
    assert_eq!(
        r.why_not[0].sentence().as_deref(),
        Some("¬∃x: (TypeOf(x, Truck)) does not hold: TypeOf(truck_1, Truck) holds (x = truck_1).")
    );
    assert!(contradicted(&pad, &kb, &r).is_empty());
    let r = ask_all(&pad, &kb, "¬∃x: (TypeOf(x, Car))");
    assert_eq!(r.answer, Outcome::Yes);
    assert_eq!(
        crate::proof::lines(&r.proofs[0]),
        vec!["¬∃x: (TypeOf(x, Car))  [no match: closed world]"]
    );
}

#[test]
fn a_join_that_fails_is_named_with_the_literal_outside_the_candidate() {
    // Regression (issue 22): "Is the pedestrian on the road?" said
    // "Pedestrian(ped_5) ∧ On(ped_5, y) together does not hold" — it
    // holds with y = walk_9; what fails is Road(y) for every such y.
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Pedestrian", &["ped_5"]),
            ("Sidewalk", &["walk_9"]),
            ("Road", &["road_1"]),
            ("On", &["ped_5", "walk_9"]),
        ],
    );
    let r = ask_all(&pad, &kb, "Pedestrian(x) ∧ On(x, y) ∧ Road(y)");
    assert_eq!(r.answer, Outcome::No);
    let w = candidate_for(&r, "x");
    assert_eq!(w.candidate, "ped_5");
    assert_eq!(w.satisfied, ["Pedestrian(ped_5)", "On(ped_5, y)"]);
    assert_eq!(w.failed, ["On(ped_5, y) ∧ Road(y)"]);
    assert_eq!(
        w.sentence().as_deref(),
        Some(
            "ped_5 comes closest: Pedestrian(ped_5) holds and On(ped_5, y) holds for some y, \
             but On(ped_5, y) ∧ Road(y) holds for no y."
        )
    );
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
}

#[test]
fn claims_resting_on_uncertain_facts_say_so() {
    // Issue 36 item 2: a failed atom measured and not asserted (a
    // doubt) may hold all the same; a satisfied atom measured below
    // PROBABLY_BELOW is only probable. Notes, not claims.
    let pad = LogicPad::builtin();
    let fact = |p: &str, args: &[&str], prob: Option<f64>| {
        let mut f = crate::kb::test_fact(p, args, "measured");
        std::sync::Arc::make_mut(&mut f.provenance).probability = prob;
        f
    };
    let input = crate::kb::test_input(
        vec![
            fact("Vehicles", &["car_1"], None),
            fact("TypeOf", &["car_1", "Car"], Some(0.8)),
        ],
        vec![fact("Moving", &["car_1"], Some(0.3))],
    );
    let kb = WindowKb::build(input, pad.program()).unwrap();
    let r = ask_all(&pad, &kb, "TypeOf(x, Car) ∧ Moving(x)");
    assert_eq!(r.answer, Outcome::No);
    let w = &r.why_not[0];
    assert_eq!(w.failed, vec!["Moving(car_1)".to_string()]);
    assert_eq!(
        w.uncertain,
        vec![
            "Moving(car_1) may hold all the same (measured, not asserted: probability 0.3)."
                .to_string(),
            "TypeOf(car_1, Car) is only probable (probability 0.8).".to_string(),
        ]
    );
    let said = w.sentence().unwrap();
    assert!(said.ends_with("(probability 0.8)."), "{said}");
    // A certain window has no notes.
    let certain = test_window(
        pad.program(),
        &[("Vehicles", &["car_1"]), ("TypeOf", &["car_1", "Car"])],
    );
    let r = ask_all(&pad, &certain, "TypeOf(x, Car) ∧ Moving(x)");
    assert!(r.why_not.iter().all(|w| w.uncertain.is_empty()));
}

#[test]
fn a_candidate_is_told_every_condition_it_fails() {
    // Regression (issue 36): "Is the white van on the sidewalk?" said
    // "van_3 comes closest: TypeOf(van_3, Van) holds and On(van_3, y)
    // holds for some y, but ColorOf(van_3, White) does not hold" — van_3
    // is on the road, so `Sidewalk(y) ∧ On(van_3, y)` fails too (one y
    // for both, though each holds on its own).
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Vehicles", &["van_3"]),
            ("TypeOf", &["van_3", "Van"]),
            ("ColorOf", &["van_3", "Silver"]),
            ("Road", &["road_1"]),
            ("Sidewalk", &["walk_2"]),
            ("On", &["van_3", "road_1"]),
        ],
    );
    let r = ask_all(
        &pad,
        &kb,
        "TypeOf(x, Van) ∧ ColorOf(x, White) ∧ Sidewalk(y) ∧ On(x, y)",
    );
    assert_eq!(r.answer, Outcome::No);
    let w = candidate_for(&r, "x");
    assert_eq!(w.candidate, "van_3");
    assert_eq!(w.satisfied, ["TypeOf(van_3, Van)", "On(van_3, y)"]);
    assert_eq!(
        w.failed,
        ["ColorOf(van_3, White)", "Sidewalk(y) ∧ On(van_3, y)"]
    );
    assert_eq!(
        w.sentence().as_deref(),
        Some(
            "van_3 comes closest: TypeOf(van_3, Van) holds and On(van_3, y) holds for some y, \
             but ColorOf(van_3, White) does not hold; Sidewalk(y) ∧ On(van_3, y) holds for no y."
        )
    );
    // For y, each condition of its group fails on its own: nothing is
    // white, and nothing is on the sidewalk.
    let w = candidate_for(&r, "y");
    assert_eq!(w.candidate, "walk_2");
    assert_eq!(w.failed, ["ColorOf(x, White)", "On(x, walk_2)"]);
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
}

#[test]
fn an_object_comes_closest_once_per_answer() {
    // Regression (issue 36): car_1 came closest for x and again for y;
    // y's explanation goes to the next candidate, ped_2.
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Vehicles", &["car_1"]),
            ("Pedestrian", &["ped_2"]),
            ("Moving", &["car_1"]),
            ("Moving", &["ped_2"]),
        ],
    );
    let r = ask_all(
        &pad,
        &kb,
        "Vehicles(x) ∧ Moving(y) ∧ DistanceDecrease(x, y)",
    );
    assert_eq!(r.answer, Outcome::No);
    let named: Vec<(&str, &str)> = r
        .why_not
        .iter()
        .map(|w| (w.variable.as_str(), w.candidate.as_str()))
        .collect();
    assert_eq!(named, [("x", "car_1"), ("y", "ped_2")]);
    assert_eq!(r.why_not[0].failed, ["DistanceDecrease(car_1, y)"]);
    assert_eq!(r.why_not[1].failed, ["DistanceDecrease(x, ped_2)"]);
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
}

#[test]
fn a_negation_over_another_variable_is_claimed_only_with_what_binds_it() {
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Pedestrian", &["ped_4"]),
            ("Vehicles", &["car_1"]),
            ("DistanceDecrease", &["car_1", "ped_4"]),
        ],
    );
    let r = ask_all(
        &pad,
        &kb,
        "Vehicles(x) ∧ Pedestrian(y) ∧ ¬DistanceDecrease(x, y)",
    );
    assert_eq!(r.answer, Outcome::No);
    for w in &r.why_not {
        for c in w.satisfied.iter().chain(&w.failed) {
            assert!(prepare(&pad, c).is_ok(), "claim `{c}` must be a safe query");
        }
    }
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
}

#[test]
fn a_universal_names_its_counterexample_by_its_own_variable() {
    // The counterexample's values come sorted by variable name; the
    // names must come from the same bindings, not from the written order.
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[("Pedestrian", &["ped_4"]), ("Vehicles", &["car_1"])],
    );
    let r = ask_all(&pad, &kb, "∀x: Pedestrian(x) → Moving(x)");
    assert_eq!(r.answer, Outcome::No, "{r:?}");
    assert_eq!(r.why_not[0].satisfied, ["Pedestrian(ped_4)"]);
    assert_eq!(r.why_not[0].failed, ["Moving(ped_4)"]);
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
    // Written `y, x`, answered sorted `x, y`: each name goes with its
    // own value (they were paired in written order before).
    let r = ask_all(
        &pad,
        &kb,
        "∀y, x: Vehicles(y) ∧ Pedestrian(x) → DistanceDecrease(y, x)",
    );
    assert_eq!(r.answer, Outcome::No, "{r:?}");
    assert_eq!(r.why_not[0].variable, "x, y");
    assert_eq!(r.why_not[0].candidate, "ped_4, car_1");
    assert_eq!(r.why_not[0].failed, ["DistanceDecrease(car_1, ped_4)"]);
    assert_eq!(contradicted(&pad, &kb, &r), Vec::<String>::new());
}

const OBJECTS: [&str; 6] = ["car_1", "car_2", "van_3", "ped_4", "road_5", "walk_6"];
const MOVERS: [&str; 4] = ["car_1", "car_2", "van_3", "ped_4"];

/// A random window over six objects: classes, motion, colours, places
/// and pairwise distance trends, each present or not.
fn random_facts() -> impl Strategy<Value = Vec<(String, Vec<String>)>> {
    let mut choices: Vec<(String, Vec<String>)> = Vec::new();
    let one = |p: &str, a: &[&str]| (p.to_string(), a.iter().map(|s| s.to_string()).collect());
    for o in MOVERS {
        for p in ["Vehicles", "Pedestrian", "Moving", "SpeedUp", "SpeedDown"] {
            choices.push(one(p, &[o]));
        }
        for c in ["Red", "White"] {
            choices.push(one("ColorOf", &[o, c]));
        }
        for t in ["Car", "Van"] {
            choices.push(one("TypeOf", &[o, t]));
        }
        for place in ["road_5", "walk_6"] {
            choices.push(one("On", &[o, place]));
        }
        for o2 in MOVERS {
            choices.push(one("DistanceDecrease", &[o, o2]));
        }
    }
    for o in ["road_5", "walk_6"] {
        choices.push(one("Road", &[o]));
        choices.push(one("Sidewalk", &[o]));
    }
    let n = choices.len();
    prop::collection::vec(any::<bool>(), n).prop_map(move |keep| {
        choices
            .iter()
            .zip(keep)
            .filter(|(_, k)| *k)
            .map(|(f, _)| f.clone())
            .collect()
    })
}

/// A random safe conjunctive query over x, y, z: two to five literals
/// from positive atoms, negations and comparisons over bound variables.
fn random_query() -> impl Strategy<Value = String> {
    let vars = prop::sample::select(vec!["x", "y", "z"]);
    let konst = prop::sample::select(OBJECTS.to_vec());
    let term = prop_oneof![4 => vars.clone().prop_map(str::to_string), 1 => konst.prop_map(str::to_string)];
    let unary = prop::sample::select(vec![
        "Vehicles",
        "Pedestrian",
        "Moving",
        "SpeedUp",
        "Road",
        "Sidewalk",
        "Stopped",
        "Walk",
        "Cross",
        "ConstantSpeed",
    ]);
    let binary = prop::sample::select(vec!["On", "DistanceDecrease"]);
    let value = prop::sample::select(vec![
        ("ColorOf", "Red"),
        ("ColorOf", "White"),
        ("TypeOf", "Car"),
        ("TypeOf", "Van"),
    ]);
    let atom = prop_oneof![
        (unary, term.clone()).prop_map(|(p, a)| format!("{p}({a})")),
        (binary, term.clone(), term.clone()).prop_map(|(p, a, b)| format!("{p}({a}, {b})")),
        (value, term.clone()).prop_map(|((p, v), a)| format!("{p}({a}, {v})")),
    ];
    let lit = prop_oneof![
        5 => atom.clone().prop_map(|a| (false, a)),
        2 => atom.prop_map(|a| (true, format!("¬{a}"))),
        1 => (vars.clone(), vars, any::<bool>()).prop_map(|(a, b, ne)| (true, format!("{a} {} {b}", if ne { "≠" } else { "=" }))),
    ];
    prop::collection::vec(lit, 2..6).prop_filter_map("needs a positive literal", |lits| {
        let text: Vec<String> = lits.iter().map(|(_, t)| t.clone()).collect();
        lits.iter().any(|(neg, _)| !neg).then(|| text.join(" ∧ "))
    })
}

/// A window of the built-in LogicPad holding `facts`.
fn random_window(pad: &LogicPad, facts: &[(String, Vec<String>)]) -> WindowKb {
    let lines: Vec<(&str, Vec<&str>)> = facts
        .iter()
        .map(|(p, a)| (p.as_str(), a.iter().map(String::as_str).collect()))
        .collect();
    let refs: Vec<(&str, &[&str])> = lines.iter().map(|(p, a)| (*p, a.as_slice())).collect();
    test_window(pad.program(), &refs)
}

/// The groups of the query's literals (the candidate in place) that
/// have no answer for a why-not candidate, yet no failed claim of it
/// names: each should be named by a claim of its own literals.
fn unnamed_failures(pad: &LogicPad, kb: &WindowKb, q: &str, why: &[WhyNot]) -> Vec<String> {
    let Ok(ParsedQuery::Exists(ast)) = prepare(pad, q) else {
        return Vec::new();
    };
    let Some(conj) = ast.disjuncts.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for w in why.iter().filter(|w| w.candidate != NO_CANDIDATE) {
        let Some(v) = ast.vars.iter().position(|n| *n == w.variable) else {
            continue;
        };
        let groups = Groups::of(kb, &ast, conj, v, unbounded());
        for m in &groups.members {
            let bound: Vec<Literal> = m
                .iter()
                .filter_map(|&i| conj.get(i))
                .map(|l| bind_var(l, v, &w.candidate))
                .collect();
            if !is_safe(&bound) || satisfiable(kb, &ast, &bound, &unbounded()) != Some(false) {
                continue;
            }
            let texts: Vec<String> = bound.iter().map(|l| literal_text(l, &ast, None)).collect();
            let named = w
                .failed
                .iter()
                .any(|f| f.split(" ∧ ").all(|part| texts.iter().any(|t| t == part)));
            if !named {
                out.push(format!("{}: {}", w.candidate, texts.join(" ∧ ")));
            }
        }
    }
    out
}

/// Whether `w`'s typed claims are its claims in words, one for one: each
/// rendered as query text is the word, and the variables the words
/// mention are those of the typed claims.
fn claims_say_their_words(w: &WhyNot) -> bool {
    let say = |words: &[String], claims: &[Claim]| {
        words.len() == claims.len()
            && words.iter().zip(claims).all(|(text, c)| {
                let rendered = match (c, w.claim_literals(c), &w.query) {
                    (Claim::Formula(f), _, _) => f.clone(),
                    (_, Some(lits), Some(q)) => super::claims::conjunction_text(&lits, q, None),
                    _ => return false,
                };
                rendered == *text && w.mentioned_vars(c) == free_vars_of_text(text)
            })
    };
    say(&w.satisfied, &w.satisfied_claims) && say(&w.failed, &w.failed_claims)
}

proptest! {
        #![proptest_config(ProptestConfig::with_cases(300))]
        /// Every claim of every "no" answer, asked back as a query over a
        /// random window, agrees with the engine (and each failed set is
        /// minimal among safe subsets).
        #[test]
        fn every_why_not_claim_agrees_with_the_engine(facts in random_facts(), queries in prop::collection::vec(random_query(), 4)) {
            let pad = LogicPad::builtin();
            let kb = random_window(&pad, &facts);
            let obs = all_observed(&pad);
            for q in &queries {
                // Unsafe or ill-typed random queries are invalid: nothing to explain.
                let r = ask(&pad, &kb, &obs, q, AskOptions::default());
                if r.answer != Outcome::No {
                    continue;
                }
                let wrong = audit(&pad, &kb, &obs, &r);
                prop_assert!(wrong.is_empty(), "{q}: {wrong:?}\n{:?}", r.why_not);
                for w in &r.why_not {
                    prop_assert!(claims_say_their_words(w), "{q}: {w:?}");
                }
                let missing = unnamed_failures(&pad, &kb, q, &r.why_not);
                prop_assert!(missing.is_empty(), "{q}: unnamed {missing:?}\n{:?}", r.why_not);
                let mut names: Vec<&str> = r.why_not.iter().map(|w| w.candidate.as_str())
.filter(|c| *c != NO_CANDIDATE).collect();
                names.sort_unstable();
                prop_assert!(names.windows(2).all(|p| p[0] != p[1]), "{q}: {names:?}");
                // The window's holder sets, filled by the questions before,
                // change nothing: a window of its own says the same.
                let fresh = random_window(&pad, &facts);
                let alone = ask(&pad, &fresh, &obs, q, AskOptions::default());
                prop_assert_eq!(format!("{:?}", r.why_not), format!("{:?}", alone.why_not), "{}", q);
                // The C2 context says nothing but these claims.
                let ctx = crate::context::RagContext::new(&kb, None, &r, crate::context::Sentences::builtin());
                let expected: Vec<String> = r.why_not.iter().filter_map(WhyNot::sentence).collect();
                prop_assert_eq!(&ctx.c2[1 + r.notes.len()..], expected.as_slice());
            }
        }
    }

proptest! {
    #![proptest_config(ProptestConfig::with_cases(200))]
    /// The one-atom shortcut of `satisfiable` answers as the engine
    /// does, for every positive atom of random queries over random
    /// windows (constants, repeated variables, unknown objects).
    #[test]
    fn one_atom_satisfiability_is_the_engines(facts in random_facts(), queries in prop::collection::vec(random_query(), 4)) {
        let pad = LogicPad::builtin();
        let kb = random_window(&pad, &facts);
        for q in &queries {
            let Ok(ParsedQuery::Exists(ast)) = prepare(&pad, q) else {
                continue;
            };
            for l in ast.disjuncts.iter().flatten() {
                let Literal::Pos(a) = l else { continue };
                let one = QueryAst {
                    source: ast.source.clone(),
                    vars: ast.vars.clone(),
                    answer_vars: Vec::new(),
                    disjuncts: vec![vec![l.clone()]],
                    plans: Default::default(),
                };
                let engine = kb.model.satisfiable(&one).ok();
                prop_assert_eq!(Some(atom_satisfiable(&kb, a)), engine, "{:?} in {}", a, q);
            }
        }
    }
}

/// Whether literal `l` holds with `v` bound to `obj`, by definition: a
/// scan of every fact of its relation (other variables existential).
fn holds_by_scan(kb: &WindowKb, ast: &QueryAst, l: &Literal, v: usize, obj: &str) -> bool {
    let (atom, neg) = match l {
        Literal::Pos(a) => (a, false),
        Literal::Neg(a) => (a, true),
        Literal::Cmp { .. } => return cmp_holds(l, ast, v, obj),
        Literal::NotExists { .. } => return not_exists_holds(kb, ast, l, v, obj, &unbounded()),
    };
    let some = kb.model.relation(&atom.pred).is_some_and(|rel| {
        rel.iter().any(|(_, t)| {
            t.len() == atom.args.len()
                && atom.args.iter().zip(t.iter()).all(|(a, x)| match a {
                    Arg::Const(c) => x.as_sym().is_some_and(|s| s.as_str() == c),
                    Arg::Var(w) if *w == v => x.as_sym().is_some_and(|s| s.as_str() == obj),
                    Arg::Var(_) => true,
                })
        })
    });
    some != neg
}

#[test]
fn why_not_scores_equal_the_definition() {
    // `scores` visits only the objects that can score and decides
    // literals from holder sets; by definition every object is tried
    // and every literal decided by scanning its relation.
    let pad = LogicPad::builtin();
    let kb = test_window(
        pad.program(),
        &[
            ("Vehicles", &["car_1"]),
            ("Vehicles", &["car_2"]),
            ("Vehicles", &["van_3"]),
            ("Pedestrian", &["ped_4"]),
            ("Road", &["road_5"]),
            ("TypeOf", &["car_1", "Car"]),
            ("TypeOf", &["car_2", "Car"]),
            ("TypeOf", &["van_3", "Van"]),
            ("ColorOf", &["car_1", "Red"]),
            ("ColorOf", &["car_2", "White"]),
            ("ColorOf", &["van_3", "White"]),
            ("Moving", &["car_1"]),
            ("Moving", &["ped_4"]),
            ("SpeedUp", &["car_2"]),
            ("DistanceDecrease", &["car_1", "ped_4"]),
            ("DistanceDecrease", &["van_3", "van_3"]),
            ("On", &["car_1", "road_5"]),
            ("On", &["ped_4", "road_5"]),
        ],
    );
    let queries = [
        // An identity literal, narrow and empty.
        "TypeOf(x, Car) ^ ColorOf(x, White) ^ Moving(x)",
        "Vehicles(x) ^ TypeOf(x, Bus)",
        // No identity literal, all positive: the union of holders.
        "Moving(x) ^ SpeedUp(x) ^ ColorOf(x, Red)",
        "Moving(x) ^ On(x, road_5) ^ SpeedUp(x)",
        // Negations and comparisons: every object is a candidate.
        "Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, White)",
        "Moving(x) ^ x != car_1 ^ SpeedUp(x)",
        "Vehicles(x) ^ ¬Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, Red)",
        // Two variables, a repeated variable, existential others.
        "Vehicles(x) ^ Pedestrian(y) ^ DistanceDecrease(x, y) ^ SpeedUp(x)",
        "DistanceDecrease(x, x) ^ Moving(x)",
        "Pedestrian(y) ^ Vehicles(x) ^ ¬DistanceDecrease(x, y) ^ On(y, z) ^ SpeedUp(y)",
    ];
    for q in queries {
        let Ok(ParsedQuery::Exists(ast)) = prepare(&pad, q) else {
            panic!("{q} must prepare as an existential query");
        };
        let conj = ast.disjuncts.first().expect("one conjunction");
        for &v in &ast.answer_vars {
            let mentions: Vec<&Literal> = conj.iter().filter(|l| mentions_var(l, v)).collect();
            let identity: Vec<bool> = mentions.iter().map(|l| is_identity(&pad, l, v)).collect();
            let (any_of_kind, mut fast) = scores(&kb, &ast, v, &mentions, &identity, &unbounded());
            let mut of_kind = 0;
            let mut slow: Vec<(usize, &str, Holds)> = Vec::new();
            for obj in &kb.objects {
                let holds: Holds = mentions
                    .iter()
                    .map(|l| holds_by_scan(&kb, &ast, l, v, obj))
                    .collect();
                if holds.iter().zip(&identity).any(|(&h, &id)| id && !h) {
                    continue;
                }
                of_kind += 1;
                let n = holds.iter().filter(|&&h| h).count();
                if n > 0 {
                    slow.push((n, obj, holds));
                }
            }
            let rank = |a: &(usize, &str, Holds), b: &(usize, &str, Holds)| {
                b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1))
            };
            fast.sort_by(rank);
            slow.sort_by(rank);
            assert_eq!(fast, slow, "{q}, variable {v}");
            if identity.contains(&true) {
                assert_eq!(any_of_kind, of_kind > 0, "{q}, variable {v}");
            }
        }
    }
}

/// Engine checks without limits, as the tests ask them.
fn unbounded() -> Bounds {
    Bounds::new(&logicpad::Limits::default())
}
