//! Semantics on the default LogicPad: the reference's never-firing rules
//! fire, negation is real, answers carry proofs, constraints are checked.

use logicpad::{
    CutReason, DerivationTree, FactBase, LogicPad, Model, ProofLimits, RunConfig, parse_query,
};
use std::sync::OnceLock;

fn model(facts: &[(&str, &[&str])]) -> Model {
    let pad = LogicPad::builtin();
    assert!(
        pad.diagnostics().is_empty(),
        "builtin LogicPad is lint clean: {:?}",
        pad.diagnostics()
    );
    let mut fb = FactBase::new();
    for (p, args) in facts {
        fb.add(p, args).expect("fact");
    }
    pad.program().evaluate(fb).expect("evaluates")
}

fn ask(m: &Model, q: &str) -> Vec<Vec<(String, String)>> {
    let ast = parse_query(q).expect("query parses");
    m.ask(&ast, RunConfig::default())
        .expect("answers")
        .into_iter()
        .map(|a| a.bindings)
        .collect()
}

fn b(pairs: &[(&str, &str)]) -> Vec<(String, String)> {
    pairs
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect()
}

#[test]
fn the_eight_never_firing_reference_rules_fire() {
    let m = model(&[
        // Cross / NotCross: a pedestrian on a road / a sidewalk (y existential).
        ("Pedestrian", &["pedestrian_1"]),
        ("On", &["pedestrian_1", "road_0"]),
        ("Road", &["road_0"]),
        ("Pedestrian", &["pedestrian_2"]),
        ("On", &["pedestrian_2", "sidewalk_0"]),
        ("Sidewalk", &["sidewalk_0"]),
        // Collide: two vehicles closing to zero distance.
        ("Vehicles", &["car_1"]),
        ("Vehicles", &["car_2"]),
        ("DistanceDecrease", &["car_1", "car_2"]),
        ("DistanceDecreasesToZero", &["car_1", "car_2"]),
        // Crash: a vehicle into a construction object.
        ("Vehicles", &["car_3"]),
        ("ConstructionObj", &["cone_0"]),
        ("DistanceDecrease", &["car_3", "cone_0"]),
        ("DistanceZeroEnd", &["car_3", "cone_0"]),
        // Merge: car_4 disappears into car_5.
        ("Vehicles", &["car_4"]),
        ("Vehicles", &["car_5"]),
        ("Disappear", &["car_4"]),
        ("DistanceDecrease", &["car_4", "car_5"]),
        ("DistanceZeroEnd", &["car_4", "car_5"]),
        // Enter: pedestrian_3 gets into car_6.
        ("Pedestrian", &["pedestrian_3"]),
        ("Vehicles", &["car_6"]),
        ("Disappear", &["pedestrian_3"]),
        ("DistanceDecrease", &["pedestrian_3", "car_6"]),
        ("DistanceZeroEnd", &["pedestrian_3", "car_6"]),
        // Diverge: car_7 appears out of car_8.
        ("Vehicles", &["car_7"]),
        ("Vehicles", &["car_8"]),
        ("Appear", &["car_7"]),
        ("DistanceIncrease", &["car_7", "car_8"]),
        ("DistanceZeroStart", &["car_7", "car_8"]),
        // Exit: pedestrian_4 steps out of car_9.
        ("Pedestrian", &["pedestrian_4"]),
        ("Vehicles", &["car_9"]),
        ("Appear", &["pedestrian_4"]),
        ("DistanceIncrease", &["pedestrian_4", "car_9"]),
        ("DistanceZeroStart", &["pedestrian_4", "car_9"]),
        // Ride: pedestrian_5 on a motorcycle.
        ("Pedestrian", &["pedestrian_5"]),
        ("Vehicles", &["motorcycle_0"]),
        ("TypeOf", &["motorcycle_0", "Motorcycle"]),
        ("On", &["pedestrian_5", "motorcycle_0"]),
    ]);
    assert!(m.holds("Cross", &["pedestrian_1"]));
    assert!(!m.holds("Cross", &["pedestrian_2"]));
    assert!(m.holds("NotCross", &["pedestrian_2"]));
    assert!(m.holds("Collide", &["car_1", "car_2"]));
    assert!(m.holds("Crash", &["car_3", "cone_0"]));
    assert!(m.holds("Merge", &["car_4", "car_5"]));
    assert!(m.holds("Enter", &["pedestrian_3", "car_6"]));
    assert!(m.holds("Diverge", &["car_7", "car_8"]));
    assert!(m.holds("Exit", &["pedestrian_4", "car_9"]));
    assert!(m.holds("Ride", &["pedestrian_5", "motorcycle_0"]));
    // A head adds exactly the fact it names: no mirrored copies.
    assert!(!m.holds("Collide", &["car_2", "car_1"]));
    // Every derived fact explains itself down to base facts.
    let tree = m
        .explain("Ride", &["pedestrian_5", "motorcycle_0"])
        .expect("explained");
    let DerivationTree::Derived {
        premises,
        rule_text,
        ..
    } = &tree
    else {
        panic!("{tree}")
    };
    assert!(rule_text.contains("Motorcycle"));
    assert_eq!(premises.len(), 4);
    assert!(
        premises
            .iter()
            .all(|p| matches!(p, DerivationTree::Base { .. }))
    );
}

#[test]
fn negation_is_real_and_order_free() {
    let m = model(&[
        ("Vehicles", &["car_1"]),
        ("Vehicles", &["car_2"]),
        ("SpeedUp", &["car_2"]),
        ("Moving", &["car_2"]),
        ("Pedestrian", &["pedestrian_1"]),
    ]);
    // Every mover keeps a constant speed unless it speeds up or slows down
    // (the standing pedestrian too: "steady pace" and "constant speed" agree).
    assert_eq!(
        m.facts("ConstantSpeed"),
        vec![vec!["car_1".to_string()], vec!["pedestrian_1".to_string()]]
    );
    assert_eq!(
        m.facts("Stopped"),
        vec![vec!["car_1".to_string()], vec!["pedestrian_1".to_string()]]
    );
    assert_eq!(m.facts("Stand"), vec![vec!["pedestrian_1".to_string()]]);
    let tree = m.explain("Stopped", &["car_1"]).expect("explained");
    let DerivationTree::Derived { absent, .. } = &tree else {
        panic!("{tree}")
    };
    assert_eq!(
        absent.iter().map(ToString::to_string).collect::<Vec<_>>(),
        vec!["Moving(car_1)"]
    );
    let text = tree.to_string();
    assert!(
        text.contains("Vehicles(car_1)  [fact]") && text.contains("¬Moving(car_1)  [absent]"),
        "{text}"
    );
}

#[test]
fn queries_use_derived_predicates_constants_and_existentials() {
    let m = model(&[
        ("Vehicles", &["car_1"]),
        ("TypeOf", &["car_1", "Car"]),
        ("ColorOf", &["car_1", "White"]),
        ("AtCenter", &["car_1"]),
        ("Vehicles", &["car_2"]),
        ("TypeOf", &["car_2", "Car"]),
        ("ColorOf", &["car_2", "Red"]),
        ("SpeedDown", &["car_2"]),
        ("DistanceDecrease", &["car_2", "car_1"]),
    ]);
    // The paper's example question.
    assert_eq!(
        ask(
            &m,
            "(TypeOf(x) = Car) ∧ (ColorOf(x) = White) ∧ AtCenter(x) ∧ ConstantSpeed(x)"
        ),
        vec![b(&[("x", "car_1")])]
    );
    assert_eq!(
        ask(&m, "TypeOf(x, Car) ^ ColorOf(x) ≠ White"),
        vec![b(&[("x", "car_2")])]
    );
    assert_eq!(
        ask(&m, "GettingCloser(x, y)"),
        vec![b(&[("x", "car_2"), ("y", "car_1")])]
    );
    // ∃y is projected away; `?y` and quantified names are variables.
    assert_eq!(
        ask(&m, "∃y : GettingCloser(x, y)"),
        vec![b(&[("x", "car_2")])]
    );
    assert_eq!(
        ask(&m, "Vehicles(?v) and not Decelerate(?v)"),
        vec![b(&[("v", "car_1")])]
    );
    // The constant resolver makes `car_1` a constant; unresolved it is a variable.
    let ast = parse_query("GettingCloser(y, car_1)").expect("parses");
    let answers = m
        .ask(
            &ast,
            RunConfig {
                proofs: true,
                ..RunConfig::default()
            },
        )
        .expect("answers");
    assert_eq!(answers.len(), 1);
    assert_eq!(answers[0].bindings, b(&[("y", "car_2")]));
    let proof = &answers[0].proof;
    assert_eq!(proof.len(), 1);
    let DerivationTree::Derived { premises, .. } = &proof[0] else {
        panic!("{:?}", proof)
    };
    assert_eq!(
        premises[0]
            .fact()
            .map(ToString::to_string)
            .unwrap_or_default(),
        "DistanceDecrease(car_2, car_1)"
    );
    assert_eq!(ask(&m, "Moving(car_1)").len(), 0);
    // Disjunction: union, deduplicated, sorted.
    assert_eq!(
        ask(&m, "ColorOf(x, White) ∨ ColorOf(x, Red) ∨ Vehicles(x)"),
        vec![b(&[("x", "car_1")]), b(&[("x", "car_2")])]
    );
    // A ground yes/no query has one empty answer when true.
    let ast = parse_query("Vehicles(car_1)").expect("parses");
    assert_eq!(m.ask(&ast, RunConfig::default()).expect("answers").len(), 1);
}

#[test]
fn unsafe_queries_are_refused() {
    let m = model(&[("Vehicles", &["car_1"])]);
    let ast = parse_query("¬Moving(x)").expect("parses");
    let err = m.ask(&ast, RunConfig::default()).expect_err("unsafe");
    assert!(err.to_string().contains("unsafe query"), "{err}");
}

#[test]
fn an_answer_variable_missing_from_an_alternative_is_unsafe() {
    // Regression: `ask` answered `y = _0` (an unbound kanren variable) for
    // the first alternative while `bindings` dropped it.
    let m = model(&[("Vehicles", &["car_1"])]);
    let ast = parse_query("Vehicles(x) ∨ Pedestrian(y)").expect("parses");
    let diags = logicpad::check_query(LogicPad::builtin().schema(), &ast);
    assert!(
        diags
            .iter()
            .any(|d| d.is_error() && d.message.contains("answer variable `y`")),
        "{diags:?}"
    );
    let err = m.ask(&ast, RunConfig::default()).expect_err("unsafe");
    assert!(err.to_string().contains("unsafe query"), "{err}");
    assert!(matches!(
        m.bindings(&ast),
        Err(logicpad::AskError::Invalid(_))
    ));
    assert!(matches!(m.count(&ast), Err(logicpad::AskError::Invalid(_))));
    // Left out of the answers with `∃`, it is a safe yes/no query.
    assert_eq!(ask(&m, "∃x,y : Vehicles(x) ∨ Pedestrian(y)"), vec![b(&[])]);
}

#[test]
fn integrity_constraints_report_violations() {
    let src = "atomic_predicates:
  tracker: [Vehicles(x), SpeedUp(x), Accel(x)]
derived_predicates:
  - name: Accelerate
    logic:
      - \"∀x : Vehicles(x) ∧ Accel(x) ==> Accelerate(x)\"
      - \"∀x : ¬SpeedUp(x) ==> ¬Accelerate(x)\"
";
    let pad = LogicPad::parse(src, "c.yaml", false).expect("loads");
    let mut fb = FactBase::new();
    for (p, a) in [
        ("Vehicles", "car_1"),
        ("Accel", "car_1"),
        ("Vehicles", "car_2"),
        ("Accel", "car_2"),
        ("SpeedUp", "car_2"),
    ] {
        fb.add(p, &[a]).expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    let v = m.violations();
    assert_eq!(v.len(), 1, "{v:?}");
    assert_eq!(v[0].atom.to_string(), "Accelerate(car_1)");
    assert_eq!(v[0].rule_line, 7);
    assert_eq!(v[0].bindings, b(&[("x", "car_1")]));
    let facts: Vec<String> = v[0].facts.iter().map(ToString::to_string).collect();
    assert_eq!(facts, vec!["Accelerate(car_1)"]);
    assert!(m.explain("Accelerate", &["car_1"]).is_some());
}

#[test]
fn builtin_schema_exposes_groups_values_and_phrases() {
    let pad = LogicPad::builtin();
    let s = pad.schema();
    assert_eq!(s.arity("DistanceIncrease"), Some(2));
    assert_eq!(
        s.get("Moving").and_then(|p| p.group.as_deref()),
        Some("tracker")
    );
    assert_eq!(
        s.get("InitialLocation").and_then(|p| p.group.as_deref()),
        Some("location")
    );
    assert!(
        s.values("TypeOf")
            .is_some_and(|v| v.iter().any(|x| x == "PoliceCar"))
    );
    // Nine image places and the three bearing places behind the ego (360° sources).
    assert_eq!(s.values("LastLocation").map(<[String]>::len), Some(12));
    assert!(
        s.phrases("ConstantSpeed")
            .iter()
            .any(|p| p == "steady speed")
    );
    assert_eq!(s.value_phrases("ColorOf", "White"), ["white".to_string()]);
    assert_eq!(s.kind("Stopped"), Some(logicpad::PredKind::Derived));
}

#[test]
fn recursion_reaches_the_fixpoint() {
    let src = "atomic_predicates:
  geometry:
    - Edge(x, y)
derived_predicates:
  - name: Reach
    logic:
      - \"∀x,y : Edge(x, y) ==> Reach(x, y)\"
      - \"∀x,y,z : Reach(x, y) ∧ Reach(y, z) ==> Reach(x, z)\"
  - name: Unreachable
    logic: \"∀x,y : Edge(x, x2) ∧ Edge(y, y2) ∧ ¬Reach(x, y) ==> Unreachable(x, y)\"
";
    let pad = LogicPad::parse(src, "r.yaml", false).expect("loads");
    assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
    let mut fb = FactBase::new();
    for i in 0..20 {
        fb.add("Edge", &[&format!("n{i}"), &format!("n{}", i + 1)])
            .expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    assert_eq!(m.facts("Reach").len(), 20 * 21 / 2);
    assert!(m.holds("Reach", &["n0", "n20"]));
    assert!(m.holds("Unreachable", &["n5", "n2"]));
    assert!(!m.holds("Unreachable", &["n2", "n5"]));
    let tree = m.explain("Reach", &["n0", "n20"]).expect("explained");
    assert!(tree.size() >= 20);
}

#[test]
fn core_types_can_be_shared_across_threads() {
    fn shareable<T: Send + Sync>() {}
    shareable::<LogicPad>();
    shareable::<logicpad::Program>();
    shareable::<Model>();
    shareable::<FactBase>();
    shareable::<logicpad::QueryAst>();
    shareable::<logicpad::Diagnostic>();
    // One program, windows evaluated on several threads.
    let pad = LogicPad::builtin();
    let counts: Vec<usize> = std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|i| {
                let program = pad.program().clone();
                s.spawn(move || {
                    let mut fb = FactBase::new();
                    for k in 0..=i {
                        fb.add("Vehicles", &[&format!("car_{k}")]).expect("fact");
                    }
                    program
                        .evaluate(fb)
                        .expect("evaluates")
                        .facts("Stopped")
                        .len()
                })
            })
            .collect();
        handles
            .into_iter()
            .map(|h| h.join().expect("thread"))
            .collect()
    });
    assert_eq!(counts, vec![1, 2, 3, 4]);
}

#[test]
fn budgets_stop_a_query_with_partial_answers() {
    let mut facts: Vec<(String, Vec<String>)> = Vec::new();
    for i in 0..30 {
        facts.push(("Vehicles".into(), vec![format!("car_{i}")]));
    }
    let pad = LogicPad::builtin();
    let mut fb = FactBase::new();
    for (p, a) in &facts {
        fb.add(p, &[a[0].as_str()]).expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    let ast = parse_query("Vehicles(x) ∧ Vehicles(y) ∧ x ≠ y").expect("parses");
    let all = m.ask(&ast, RunConfig::default()).expect("answers");
    assert_eq!(all.len(), 30 * 29);
    assert_eq!(m.count(&ast).expect("count"), 30 * 29);
    let tight = RunConfig {
        budget: logicpad::Budget {
            max_steps: Some(50),
            max_time: None,
        },
        ..RunConfig::default()
    };
    match m.ask(&ast, tight) {
        Err(logicpad::AskError::Stopped {
            reason: logicpad::Stopped::Steps,
            found,
        }) => assert!(found < all.len()),
        other => panic!("expected a budget stop, got {other:?}"),
    }
    // Within limits, what was found before the stop is kept, with the
    // reason.
    let limits = logicpad::Limits {
        steps: Some(50),
        ..logicpad::Limits::default()
    };
    let found = m.ask_limited(&ast, true, &limits).expect("runs");
    assert_eq!(found.stopped, Some(logicpad::Stopped::Steps));
    assert!(found.items.len() < all.len());
    let found = m.bindings_limited(&ast, &limits).expect("runs");
    assert_eq!(found.stopped, Some(logicpad::Stopped::Steps));
    let (n, stopped) = m.count_limited(&ast, &limits).expect("runs");
    assert_eq!(stopped, Some(logicpad::Stopped::Steps));
    assert!(n < all.len());
}

#[test]
fn propositional_heads_derive_once() {
    let src = "atomic_predicates:
  tracker:
    - Vehicles(x)
    - DistanceDecreasesToZero(x, y)
derived_predicates:
  - name: Danger
    logic: \"∀x,y : Vehicles(x) ∧ DistanceDecreasesToZero(x, y) ==> Danger()\"
";
    let pad = LogicPad::parse(src, "p.yaml", false).expect("loads");
    assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
    let mut fb = FactBase::new();
    fb.add("Vehicles", &["car_1"]).expect("fact");
    fb.add("Vehicles", &["car_2"]).expect("fact");
    let quiet = pad.program().evaluate(fb.clone()).expect("evaluates");
    assert!(!quiet.holds("Danger", &[]));
    fb.add("DistanceDecreasesToZero", &["car_1", "car_2"])
        .expect("fact");
    fb.add("DistanceDecreasesToZero", &["car_2", "car_1"])
        .expect("fact");
    let m = pad.program().evaluate(fb).expect("evaluates");
    assert!(m.holds("Danger", &[]));
    assert_eq!(m.facts("Danger").len(), 1);
    assert!(m.explain("Danger", &[]).is_some());
    let ast = parse_query("Danger()").expect("parses");
    assert_eq!(m.ask(&ast, RunConfig::default()).expect("ask").len(), 1);
    assert_eq!(m.count(&ast).expect("count"), 1);
}

#[test]
fn propositional_constraints_report_violations() {
    // Regression: a constraint whose forbidden atom has no argument
    // (`¬Danger()`) was never reported, since its violations were read from
    // the (empty) head terms.
    let src = "atomic_predicates:
  tracker: [Vehicles(x), Crash(x), Calm(x)]
derived_predicates:
  - name: Danger
    logic:
      - \"∀x : Vehicles(x) ∧ Crash(x) ==> Danger()\"
      - \"∀x : Calm(x) ==> ¬Danger()\"
";
    let pad = LogicPad::parse(src, "c.yaml", false).expect("loads");
    let mut fb = FactBase::new();
    for (p, a) in [("Vehicles", "car_1"), ("Crash", "car_1"), ("Calm", "car_2")] {
        fb.add(p, &[a]).expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    assert!(m.holds("Danger", &[]));
    let v = m.violations();
    assert_eq!(v.len(), 1, "{v:?}");
    assert_eq!(v[0].atom.to_string(), "Danger()");
    assert_eq!(v[0].rule_line, 7);
    assert_eq!(v[0].bindings, b(&[("x", "car_2")]));
    let facts: Vec<String> = v[0].facts.iter().map(ToString::to_string).collect();
    assert_eq!(facts, vec!["Calm(car_2)", "Danger()"]);
}

#[test]
fn joins_over_atoms_of_more_than_64_arguments_keep_earlier_bindings() {
    // Regression: the join remembered which arguments an atom bound in a
    // 64-bit mask, so argument 64 aliased argument 0 and undoing a binding
    // of argument 0 also cleared `y`, bound earlier by `Pick(y, w)`: the
    // next `Link` fact then joined `Wide` with any `y`.
    let xs: Vec<String> = (0..64).map(|i| format!("x{i}")).collect();
    let wide = format!("Wide({}, y)", xs.join(", "));
    let src = format!(
        "atomic_predicates:
  tracker:
    - Pick(y, w)
    - Link(w, z)
    - {wide}
derived_predicates:
  - name: Hit
    logic: \"∀{},y,w,z : Pick(y, w) ∧ Link(w, z) ∧ {wide} ==> Hit(x0, y)\"
",
        xs.join(",")
    );
    let pad = LogicPad::parse(&src, "w.yaml", false).expect("loads");
    assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
    let mut fb = FactBase::new();
    fb.add("Pick", &["b", "w1"]).expect("fact");
    fb.add("Link", &["w1", "z1"]).expect("fact");
    fb.add("Link", &["w1", "z2"]).expect("fact");
    for (first, last) in [("a0", "a"), ("a1", "b"), ("a2", "c")] {
        let mut args = vec![first.to_string()];
        args.extend((1..64).map(|i| format!("v{i}")));
        args.push(last.to_string());
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        fb.add("Wide", &args).expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    assert_eq!(
        m.facts("Hit"),
        vec![vec!["a1".to_string(), "b".to_string()]]
    );
}

#[test]
fn fact_texts_hold_propositional_facts() {
    // Regression: `Danger()` split into one empty argument and was refused,
    // so a propositional fact could not be written in a `.facts` text.
    let fb = FactBase::from_text("Danger()\nVehicles(car_1)\nCalm( )\n", "p.facts").expect("reads");
    assert_eq!(fb.len(), 3);
    assert_eq!(fb.relation("Danger").map(|r| r.arity()), Some(0));
    assert_eq!(fb.relation("Calm").map(|r| r.arity()), Some(0));
    assert!(FactBase::from_text("Vehicles(car_1, )\n", "p.facts").is_err());
    assert!(FactBase::from_text("Vehicles(,)\n", "p.facts").is_err());
}

#[test]
fn fact_texts_are_read_as_strictly_as_logicrag_fact_files() {
    // Regression: `add_text` took `P(a)(b)` as the constant `a)(b`, where
    // logicrag's fact files refused the line; both now share one parser.
    let e = FactBase::from_text("Vehicles(car_1)\nP(a)(b)\n", "k.facts")
        .expect_err("refused")
        .to_string();
    assert!(e.starts_with("k.facts:2:"), "{e}");
    assert!(e.contains("P(a)(b)"), "{e}");
    // What the shared parser accepts beyond the old reader: `%` comments,
    // a Prolog-style final dot, quoted constants.
    let fb =
        FactBase::from_text("% comment\nColorOf(car_1, \"White\").\n", "k.facts").expect("reads");
    assert_eq!(fb.len(), 1);
}

/// Length of the chain in the long-proof tests: long enough that a proof
/// built, printed, counted or dropped by one recursion per step overflowed
/// the stack.
const CHAIN: usize = 300_000;

/// A model whose `Reach` facts form one chain: `Reach(n0, nK)` is derived
/// from `Reach(n0, nK-1)`, so its proof is `K` rule steps deep while the model
/// holds only `K + 1` `Reach` facts (a transitive closure would hold K²/2).
/// Built once and shared by the tests that need it.
fn chain_model() -> &'static Model {
    static MODEL: OnceLock<Model> = OnceLock::new();
    MODEL.get_or_init(|| {
        let src = "atomic_predicates:
  geometry:
    - Edge(x, y)
    - Start(x)
derived_predicates:
  - name: Reach
    logic:
      - \"∀x : Start(x) ==> Reach(x, x)\"
      - \"∀x,y,z : Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)\"
";
        let pad = LogicPad::parse(src, "chain.yaml", false).expect("loads");
        assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
        let mut fb = FactBase::new();
        fb.add("Start", &["n0"]).expect("fact");
        for i in 0..CHAIN {
            fb.add("Edge", &[&format!("n{i}"), &format!("n{}", i + 1)])
                .expect("fact");
        }
        pad.program().evaluate(fb).expect("evaluates")
    })
}

/// The nodes along the first-premise spine of a tree, root first.
fn spine(tree: &DerivationTree) -> Vec<&DerivationTree> {
    let mut out = vec![tree];
    let mut cur = tree;
    while let DerivationTree::Derived { premises, .. } = cur {
        let Some(first) = premises.first() else { break };
        out.push(first);
        cur = first;
    }
    out
}

/// Regression: `explain` recursed once per derivation step, so the last fact
/// of a 300 000-step chain overflowed the stack (and so would have `size`,
/// Display and dropping the tree). Now the proof stops at the default depth
/// limit with a `Truncated` node that says so.
#[test]
fn explaining_a_300k_step_chain_stops_at_the_depth_limit() {
    let m = chain_model();
    let last = format!("n{CHAIN}");
    let tree = m.explain("Reach", &["n0", &last]).expect("explained");
    let depth = ProofLimits::DEFAULT_MAX_DEPTH;
    let path = spine(&tree);
    // 64 rule nodes, then the cut at depth 64.
    assert_eq!(path.len(), depth + 1);
    let cut = format!("n{}", CHAIN - depth);
    assert_eq!(
        path.last().copied(),
        Some(&DerivationTree::Truncated {
            fact: logicpad::GroundAtom {
                pred: "Reach".into(),
                args: vec!["n0".into(), cut.clone().into()],
            },
            reason: CutReason::DepthLimit(depth),
        })
    );
    assert!(tree.is_truncated());
    // Each rule node: itself and its `Edge` premise.
    assert_eq!(tree.size(), 2 * depth + 1);
    let text = tree.to_string();
    assert!(
        text.starts_with(&format!("Reach(n0, {last})  [rule, line")),
        "{text}"
    );
    let cut_line = format!(
        "{}Reach(n0, {cut})  [proof cut: depth limit {depth}]\n",
        "  ".repeat(depth)
    );
    assert!(text.contains(&cut_line), "{text}");
    // A short proof is not cut.
    let short = m.explain("Reach", &["n0", "n10"]).expect("explained");
    assert!(!short.is_truncated());
    // Eleven `Reach` rule nodes, then `Start(n0)`.
    assert_eq!(spine(&short).len(), 12);
}

/// However large the depth limit asked for, the tree stays shallow enough
/// for the derived recursive `Clone`, `PartialEq`, `Debug` and `Drop`.
#[test]
fn an_unlimited_request_is_clamped_to_the_depth_ceiling() {
    let m = chain_model();
    let last = format!("n{CHAIN}");
    let unlimited = ProofLimits {
        max_depth: usize::MAX,
        max_nodes: usize::MAX,
    };
    let tree = m
        .explain_with("Reach", &["n0", &last], unlimited)
        .expect("explained");
    let ceiling = ProofLimits::MAX_DEPTH_CEILING;
    let path = spine(&tree);
    assert_eq!(path.len(), ceiling + 1);
    assert!(matches!(
        path.last(),
        Some(DerivationTree::Truncated {
            reason: CutReason::DepthLimit(d),
            ..
        }) if *d == ceiling
    ));
    // On a thread with a quarter of a test thread's default 2 MiB stack,
    // for margin (at a 1024-level ceiling, `Debug` overflowed it).
    let worker = std::thread::Builder::new()
        .stack_size(STACK)
        .spawn(move || {
            let copy = tree.clone();
            assert_eq!(copy, tree);
            assert!(format!("{copy:?}").contains("DepthLimit"));
            assert_eq!(tree.to_string().lines().count(), tree.size());
            drop(copy);
            drop(tree);
        })
        .expect("spawns");
    assert!(worker.join().is_ok());
}

/// Stack of the thread that clones, compares, prints and drops a tree at
/// the depth ceiling.
const STACK: usize = 512 * 1024;

/// `Ok(aK)` needs `Ok(aK-1)` and `Ok(bK-1)`, and so does `Ok(bK)`: a DAG of
/// 2(K+1) facts whose unshared proof tree doubles with every level.
fn ladder_model(levels: usize) -> Model {
    let src = "atomic_predicates:
  geometry:
    - Left(x, y)
    - Right(x, y)
    - Seed(x)
derived_predicates:
  - name: Ok
    logic:
      - \"∀x : Seed(x) ==> Ok(x)\"
      - \"∀x,y,z : Left(z, x) ∧ Right(z, y) ∧ Ok(x) ∧ Ok(y) ==> Ok(z)\"
";
    let pad = LogicPad::parse(src, "ladder.yaml", false).expect("loads");
    assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
    let mut fb = FactBase::new();
    fb.add("Seed", &["a0"]).expect("fact");
    fb.add("Seed", &["b0"]).expect("fact");
    for k in 0..levels {
        let (a, b) = (format!("a{k}"), format!("b{k}"));
        for z in [format!("a{}", k + 1), format!("b{}", k + 1)] {
            fb.add("Left", &[&z, &a]).expect("fact");
            fb.add("Right", &[&z, &b]).expect("fact");
        }
    }
    pad.program().evaluate(fb).expect("evaluates")
}

/// Nodes of the unshared proof of `Ok` at level `k`: the `Seed` rule node
/// and its premise at level 0, then a rule node, two base premises and two
/// level-`k-1` proofs.
fn ladder_size(k: u32) -> usize {
    if k == 0 {
        2
    } else {
        3 + 2 * ladder_size(k - 1)
    }
}

/// A proof whose sub-facts are reused level after level is exponential in
/// its depth; the node limit keeps it to at most `max_nodes` nodes, with the
/// facts it had no room for cut.
#[test]
fn a_dag_shaped_proof_is_capped_by_the_node_limit() {
    let levels = 60;
    let m = ladder_model(levels);
    let top = format!("a{levels}");
    // Unshared, the full tree would have about 5 * 2^60 nodes (it is within
    // the depth limit): only the node limit keeps this from running forever.
    assert!(levels < ProofLimits::DEFAULT_MAX_DEPTH);
    let tree = m.explain("Ok", &[&top]).expect("explained");
    assert!(
        tree.size() <= ProofLimits::DEFAULT_MAX_NODES,
        "{}",
        tree.size()
    );
    assert!(tree.size() > ProofLimits::DEFAULT_MAX_NODES / 2);
    assert!(tree.to_string().contains("[proof cut: node limit 10000]"));
    // Small levels are exact and exponential when nothing is cut.
    let unlimited = ProofLimits {
        max_depth: ProofLimits::DEFAULT_MAX_DEPTH,
        max_nodes: usize::MAX,
    };
    for k in [1u32, 5, 12] {
        let t = m
            .explain_with("Ok", &[&format!("a{k}")], unlimited)
            .expect("explained");
        assert!(!t.is_truncated());
        assert_eq!(t.size(), ladder_size(k));
    }
    assert_eq!(ladder_size(12), 5 * (1 << 12) - 3);
}

/// The nodes of `tree` level by level, each level in body order.
fn levels_of(tree: &DerivationTree) -> Vec<Vec<&DerivationTree>> {
    let mut levels: Vec<Vec<&DerivationTree>> = vec![vec![tree]];
    loop {
        let next: Vec<&DerivationTree> = levels
            .last()
            .into_iter()
            .flatten()
            .flat_map(|t| match t {
                DerivationTree::Derived { premises, .. } => premises.as_slice(),
                _ => &[],
            })
            .collect();
        if next.is_empty() {
            return levels;
        }
        levels.push(next);
    }
}

/// Regression: nodes were given out depth first, so in the 60-level ladder
/// the root's first premise `Ok(a59)` spent the whole budget down to depth
/// 59 and its second premise `Ok(b59)`, right below the root, was cut. Now
/// every level is expanded in full before the next, as far as the budget
/// goes.
#[test]
fn the_node_budget_is_given_out_breadth_first() {
    let m = ladder_model(60);
    let tree = m.explain("Ok", &["a60"]).expect("explained");
    let DerivationTree::Derived { premises, .. } = &tree else {
        panic!("root not expanded: {tree}");
    };
    assert_eq!(premises.len(), 4);
    assert!(
        matches!(&premises[3], DerivationTree::Derived { fact, .. } if fact.args == ["b59"]),
        "{:?}",
        premises[3].fact()
    );
    // By hand: depth `d` holds 2^d `Ok` facts (the `Seed` level, 60, is far
    // below), and expanding one takes 4 nodes (`Left`, `Right` and two
    // `Ok`). Expanding every `Ok` at depths 0..=L costs
    // 1 + 4 * (2^(L+1) - 1) nodes: 8,189 for L = 10, 16,381 for L = 11. So
    // depths 0..=10 are expanded in full; at depth 11 the 1,811 nodes left
    // pay for the first 452 of 2,048 (1,808 nodes) and the rest are cut;
    // the 904 `Ok` facts at depth 12 find 3 nodes left and are all cut.
    let levels = levels_of(&tree);
    assert_eq!(levels.len(), 13);
    let ok = |level: &[&DerivationTree]| -> (usize, usize) {
        let of = |pred: fn(&DerivationTree) -> bool| {
            level
                .iter()
                .filter(|t| t.fact().is_some_and(|f| f.pred == "Ok") && pred(t))
                .count()
        };
        (
            of(|t| matches!(t, DerivationTree::Derived { .. })),
            of(|t| {
                matches!(
                    t,
                    DerivationTree::Truncated {
                        reason: CutReason::NodeLimit(10_000),
                        ..
                    }
                )
            }),
        )
    };
    for (d, level) in levels.iter().enumerate().take(11) {
        assert_eq!(ok(level), (1 << d, 0), "depth {d}");
    }
    assert_eq!(ok(&levels[11]), (452, 2048 - 452));
    assert_eq!(ok(&levels[12]), (0, 904));
    // Within the level where cutting starts, the expanded facts are the
    // first ones in body order.
    let first_cut = levels[11]
        .iter()
        .position(|t| matches!(t, DerivationTree::Truncated { .. }))
        .expect("a cut at depth 11");
    assert!(
        levels[11][first_cut..]
            .iter()
            .all(|t| !matches!(t, DerivationTree::Derived { .. }))
    );
    assert_eq!(tree.size(), 1 + 4 * (2047 + 452));
}

/// Regression: the node limit applied per tree, so a query with many
/// answers over DAG-shaped proofs printed about 10,000 nodes per answer (a
/// 150 MB "retrieval context" for the 122 answers here). It is one budget
/// for the whole result; spent, each further step is one node.
#[test]
fn the_node_budget_is_shared_by_all_answers_of_a_query() {
    let m = ladder_model(60);
    let ast = parse_query("Ok(x)").expect("parses");
    let proofs = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    let answers = m.ask(&ast, proofs.clone()).expect("answers");
    assert_eq!(answers.len(), 122);
    let total: usize = answers
        .iter()
        .flat_map(|a| &a.proof)
        .map(DerivationTree::size)
        .sum();
    assert!(
        total <= ProofLimits::DEFAULT_MAX_NODES + answers.len(),
        "{total} nodes"
    );
    // Every answer still names the fact it rests on.
    assert!(answers.iter().all(|a| a.proof.len() == 1));
    // A cut names the configured budget, not what was left of it (it read
    // "node limit 1" for most answers).
    let cuts: Vec<String> = answers
        .iter()
        .flat_map(|a| &a.proof)
        .filter(|t| t.is_truncated())
        .map(|t| t.to_string())
        .collect();
    assert!(!cuts.is_empty());
    assert!(
        cuts.iter()
            .all(|c| c.contains("[proof cut: node limit 10000]")),
        "{:?}",
        &cuts[..cuts.len().min(3)]
    );
    // A smaller budget is honoured the same way.
    let small = ProofLimits {
        max_depth: ProofLimits::DEFAULT_MAX_DEPTH,
        max_nodes: 50,
    };
    let answers = m.ask_with(&ast, proofs, small).expect("answers");
    let total: usize = answers
        .iter()
        .flat_map(|a| &a.proof)
        .map(DerivationTree::size)
        .sum();
    assert!(total <= 50 + answers.len(), "{total} nodes");
}

/// `max_nodes` is a hard bound on `size()` for every value, 0 and 1
/// included (the root is always there, cut when it does not fit).
#[test]
fn the_node_limit_bounds_the_tree_size_exactly() {
    let m = ladder_model(8);
    for max_nodes in [0, 1, 2, 3, 4, 5, 6, 7, 17, 100, 333, 1000] {
        let limits = ProofLimits {
            max_depth: ProofLimits::DEFAULT_MAX_DEPTH,
            max_nodes,
        };
        let t = m.explain_with("Ok", &["b8"], limits).expect("explained");
        assert!(t.size() <= max_nodes.max(1), "{max_nodes}: {}", t.size());
        assert!(t.is_truncated());
        assert_eq!(t.fact().map(|f| f.args.clone()), Some(vec!["b8".into()]));
    }
    let root = m
        .explain_with(
            "Ok",
            &["b8"],
            ProofLimits {
                max_depth: 64,
                max_nodes: 1,
            },
        )
        .expect("explained");
    assert_eq!(root.to_string(), "Ok(b8)  [proof cut: node limit 1]\n");
    // A base fact needs no room and no depth.
    let seed = ProofLimits {
        max_depth: 0,
        max_nodes: 0,
    };
    assert!(matches!(
        m.explain_with("Seed", &["a0"], seed),
        Some(DerivationTree::Base { .. })
    ));
    assert!(matches!(
        m.explain_with("Ok", &["a0"], seed),
        Some(DerivationTree::Truncated {
            reason: CutReason::DepthLimit(0),
            ..
        })
    ));
}

/// Regression: every constant of every query was interned, and the
/// interner never frees, so a server fed queries with fresh constants grew
/// without bound. Unknown constants now match nothing and are not kept.
#[test]
fn unknown_query_constants_answer_no_and_are_not_interned() {
    let m = model(&[("Vehicles", &["car_1"]), ("ColorOf", &["car_1", "White"])]);
    let fresh = "NeverSeenColour_7f3a9c";
    assert_eq!(ask(&m, &format!("ColorOf(x, {fresh})")).len(), 0);
    assert_eq!(
        ask(&m, &format!("Vehicles(x) ∧ ¬ColorOf(x, {fresh})")),
        vec![b(&[("x", "car_1")])]
    );
    assert_eq!(
        ask(&m, &format!("Vehicles(x) ∧ x ≠ {fresh}")),
        vec![b(&[("x", "car_1")])]
    );
    assert!(!m.holds("ColorOf", &["car_1", fresh]));
    assert!(m.explain("ColorOf", &["car_1", fresh]).is_none());
    assert!(kanren::Sym::lookup(fresh).is_none(), "{fresh} was interned");
    // Known constants still match.
    assert_eq!(ask(&m, "ColorOf(x, White)"), vec![b(&[("x", "car_1")])]);
}

/// Answers are pulled lazily from the query's kanren run: taking k answers
/// of a query with a million costs work proportional to k (the run's
/// steps), and taking twice as many costs about twice as much.
#[test]
fn taking_k_answers_costs_work_proportional_to_k() {
    let names: Vec<String> = (0..1000).map(|i| format!("car_{i}")).collect();
    let strs: Vec<&str> = names.iter().map(String::as_str).collect();
    let facts: Vec<(&str, &[&str])> = strs
        .iter()
        .map(|n| ("Vehicles", std::slice::from_ref(n)))
        .collect();
    let m = model(&facts);
    let ast = parse_query("Vehicles(x) ∧ Vehicles(y)").expect("parses");
    let steps = |k: usize| {
        let mut answers = m.answers(&ast, None).expect("safe");
        let got = answers.by_ref().take(k).count();
        assert_eq!(got, k);
        answers.steps()
    };
    let (s10, s20, s100) = (steps(10), steps(20), steps(100));
    assert!(s10 < 100, "10 of 10^6 answers took {s10} steps");
    assert!(s20 <= 2 * s10 + 10, "{s10} steps for 10, {s20} for 20");
    assert!(s100 <= 10 * s10 + 50, "{s10} steps for 10, {s100} for 100");
    // And all of them are there when the run goes on.
    assert_eq!(m.count(&ast).expect("counts"), 1_000_000);
}

/// Regression: a query's node budget was spent in the order of the answers'
/// terms — symbol numbers, the order in which names were first interned —
/// and the answers sorted only afterwards, so which answers got full proofs
/// depended on interning order (which parallel parsing makes differ from
/// run to run: `ask --json` on the 2M-fact benchmark window printed
/// different proofs each time). It is spent in the sorted answers' order.
#[test]
fn the_node_budget_is_spent_in_the_order_of_the_sorted_answers() {
    // Interned in the reverse of their sorted order.
    let names: Vec<String> = (0..4).rev().map(|k| format!("budget_order_{k}")).collect();
    for n in &names {
        kanren::Sym::new(n);
    }
    let src = "atomic_predicates:
  geometry:
    - Base(x)
derived_predicates:
  - name: Good
    logic: \"∀x : Base(x) ==> Good(x)\"
";
    let pad = LogicPad::parse(src, "order.yaml", false).expect("loads");
    let mut fb = FactBase::new();
    for n in &names {
        fb.add("Base", &[n]).expect("fact");
    }
    let m = pad.program().evaluate(fb).expect("evaluates");
    let proofs = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    // Each full proof is two nodes (the rule and its base premise): room
    // for the first two answers.
    let limits = ProofLimits {
        max_depth: ProofLimits::DEFAULT_MAX_DEPTH,
        max_nodes: 4,
    };
    let ast = parse_query("Good(x)").expect("parses");
    let answers = m.ask_with(&ast, proofs, limits).expect("answers");
    let shown: Vec<(&str, bool)> = answers
        .iter()
        .map(|a| {
            let cut = a.proof.iter().any(DerivationTree::is_truncated);
            (a.bindings[0].1.as_str(), cut)
        })
        .collect();
    assert_eq!(
        shown,
        [
            ("budget_order_0", false),
            ("budget_order_1", false),
            ("budget_order_2", true),
            ("budget_order_3", true)
        ]
    );
}

/// The tuples of a model's relation in id order, as text.
fn tuples_of(m: &Model, pred: &str) -> Vec<String> {
    m.relation(pred)
        .map(|r| {
            r.iter()
                .map(|(_, t)| {
                    t.iter()
                        .map(|v| v.to_string())
                        .collect::<Vec<_>>()
                        .join(",")
                })
                .collect()
        })
        .unwrap_or_default()
}

/// A rule that copies one relation into another (`Near(x, y) ==>
/// Close(x, y)`) is evaluated by copying the relation whole. The model must
/// be the one fact-by-fact evaluation builds: the same facts with the same
/// ids, the same proofs, and the same count of derived facts; when the head
/// already holds base facts, or the rule is not a plain copy, the ordinary
/// path runs.
#[test]
fn a_copy_rule_builds_the_model_fact_by_fact_evaluation_builds() {
    let pad_with = |rule: &str| {
        let src = format!(
            "atomic_predicates:
  geometry:
    - Near(x, y)
derived_predicates:
  - name: Close
    logic: \"{rule}\"
"
        );
        LogicPad::parse(&src, "copy.yaml", false).expect("loads")
    };
    // The copy, and the same rule in a form that is no copy (a repeated
    // body atom), which runs the join and inserts fact by fact.
    let copy = pad_with("∀x,y : Near(x, y) ==> Close(x, y)");
    let join = pad_with("∀x,y : Near(x, y) ∧ Near(x, y) ==> Close(x, y)");
    let swapped = pad_with("∀x,y : Near(x, y) ==> Close(y, x)");
    let facts = |extra: bool| {
        let mut fb = FactBase::new();
        for (a, b) in [("c", "a"), ("a", "b"), ("b", "c"), ("a", "c"), ("c", "c")] {
            fb.add("Near", &[a, b]).expect("fact");
        }
        if extra {
            fb.add("Close", &["a", "b"]).expect("fact");
            fb.add("Close", &["z", "z"]).expect("fact");
        }
        fb
    };
    for extra in [false, true] {
        let a = copy.program().evaluate(facts(extra)).expect("evaluates");
        let b = join.program().evaluate(facts(extra)).expect("evaluates");
        assert_eq!(tuples_of(&a, "Close"), tuples_of(&b, "Close"), "{extra}");
        assert_eq!(a.stats().derived_facts, b.stats().derived_facts);
        for (x, y) in [("c", "a"), ("a", "b"), ("c", "c"), ("z", "z")] {
            let (pa, pb) = (a.explain("Close", &[x, y]), b.explain("Close", &[x, y]));
            assert_eq!(pa.is_some(), pb.is_some(), "{x} {y}");
            if let (Some(pa), Some(pb)) = (pa, pb) {
                // The proofs differ only in the rule text they cite and in
                // the join's repeated premise.
                let pb = pb.to_string().replace(" ∧ Near(x, y)", "");
                let mut lines: Vec<&str> = pb.lines().collect();
                lines.dedup();
                assert_eq!(pa.to_string(), lines.join("\n") + "\n");
            }
        }
        assert_eq!(
            tuples_of(&a, "Close").len(),
            if extra { 6 } else { 5 },
            "{:?}",
            tuples_of(&a, "Close")
        );
    }
    // Arguments swapped: not a copy.
    let s = swapped.program().evaluate(facts(false)).expect("evaluates");
    assert_eq!(tuples_of(&s, "Close"), ["a,c", "b,a", "c,b", "c,a", "c,c"]);
}

/// The two-roads case: a pedestrian on road_1 and not on road_2. "Is the
/// pedestrian not on the road?" as `¬∃y: (Road(y) ∧ On(x, y))` is no,
/// while "some road the pedestrian is not on" is yes; every form of
/// asking agrees, and a yes carries a `¬∃` node.
#[test]
fn a_negated_exists_negates_the_whole_conjunction() {
    let m = model(&[
        ("Pedestrian", &["ped_1"]),
        ("Pedestrian", &["ped_2"]),
        ("Road", &["road_1"]),
        ("Road", &["road_2"]),
        ("On", &["ped_1", "road_1"]),
    ]);
    let scoped = "Pedestrian(x) ∧ ¬∃y: (Road(y) ∧ On(x, y))";
    assert_eq!(ask(&m, scoped), vec![b(&[("x", "ped_2")])]);
    let loose = "Pedestrian(x) ∧ Road(y) ∧ ¬On(x, y)";
    assert!(ask(&m, loose).contains(&b(&[("x", "ped_1"), ("y", "road_2")])));
    let ast = parse_query(scoped).expect("parses");
    assert_eq!(ast.answer_var_names(), vec!["x"]);
    assert_eq!(m.count(&ast).expect("count"), 1);
    assert!(m.satisfiable(&ast).expect("satisfiable"));
    let a = m
        .ask(
            &ast,
            RunConfig {
                proofs: true,
                ..RunConfig::default()
            },
        )
        .expect("answers");
    assert_eq!(a[0].proof.len(), 2);
    assert_eq!(
        a[0].proof[1].to_string(),
        "¬∃y: (Road(y) ∧ On(ped_2, y))  [no match]\n"
    );
    // The same with a name the ∃ shadows, and the `not exists` spelling.
    assert_eq!(
        ask(
            &m,
            "Pedestrian(x) ∧ Road(y) ∧ not exists y: (Road(y) ∧ On(x, y))"
        ),
        vec![
            b(&[("x", "ped_2"), ("y", "road_1")]),
            b(&[("x", "ped_2"), ("y", "road_2")])
        ]
    );
    // In the middle of a conjunction: the parentheses end its body.
    assert_eq!(
        ask(&m, "Pedestrian(x) ∧ ~∃y:(On(x, y)) ∧ x ≠ ped_1"),
        vec![b(&[("x", "ped_2")])]
    );
}

/// A query of `¬∃` literals only is closed: "Are there no trucks?".
#[test]
fn a_closed_negated_exists_is_a_yes_no_query() {
    let m = model(&[("Vehicles", &["car_1"]), ("TypeOf", &["car_1", "Car"])]);
    assert_eq!(ask(&m, "¬∃x: (TypeOf(x, Truck))"), vec![b(&[])]);
    assert!(ask(&m, "¬∃x: (TypeOf(x, Car))").is_empty());
    assert_eq!(
        ask(&m, "¬∃x, y: (Vehicles(x) ∧ TypeOf(x, y) ∧ y ≠ Car)"),
        vec![b(&[])]
    );
    // Nested: no vehicle without a type.
    assert_eq!(
        ask(&m, "¬∃x: (Vehicles(x) ∧ ¬∃y: (TypeOf(x, y)))"),
        vec![b(&[])]
    );
    // An unknown predicate in the body never holds: the ¬∃ holds.
    let ast = parse_query("Vehicles(x) ∧ ¬∃y: (Zorp(x, y))").expect("parses");
    assert_eq!(m.count(&ast).expect("count"), 1);
}

/// Safety of `¬∃`: a variable of its body that is not its own must be
/// bound outside, and its own variables must occur in a positive atom
/// of its body. Rules refuse `¬∃` with a diagnostic.
#[test]
fn negated_exists_safety_and_rules() {
    let schema = LogicPad::builtin();
    let errors = |q: &str| -> Vec<String> {
        let ast = parse_query(q).expect("parses");
        logicpad::check_query(schema.schema(), &ast)
            .into_iter()
            .filter(|d| d.is_error())
            .map(|d| d.message)
            .collect()
    };
    assert!(errors("Pedestrian(x) ∧ ¬∃y: (Road(y) ∧ On(x, y))").is_empty());
    let e = errors("¬∃y: (Road(y) ∧ On(x, y))");
    assert!(e.iter().any(|m| m.contains("`x`")), "{e:?}");
    let e = errors("Pedestrian(x) ∧ ¬∃y: (¬On(x, y))");
    assert!(e.iter().any(|m| m.contains("∃y")), "{e:?}");
    let e = errors("Pedestrian(x) ∧ ¬∃y: (Rode(y) ∧ On(x, y))");
    assert!(e.iter().any(|m| m.contains("Rode")), "{e:?}");
    let pad = LogicPad::parse(
        "atomic_predicates:\n  base:\n    - A(x)\n    - B(x, y)\nderived_predicates:\n  \
         - name: C\n    logic: \"∀x : A(x) ∧ ¬∃y: (B(x, y)) ==> C(x)\"\n",
        "r.yaml",
        false,
    )
    .expect("loads");
    assert!(
        pad.diagnostics()
            .iter()
            .any(|d| d.is_error() && d.message.contains("negated `∃`")),
        "{:?}",
        pad.diagnostics()
    );
}

/// `#{x: Q} op N`: parsed with its test, counted as Q's distinct
/// answers on the counted variables.
#[test]
fn counting_queries_parse_check_and_count() {
    let m = model(&[
        ("Vehicles", &["car_1"]),
        ("Vehicles", &["car_2"]),
        ("Vehicles", &["car_3"]),
        ("TypeOf", &["car_1", "Car"]),
        ("TypeOf", &["car_2", "Car"]),
        ("TypeOf", &["car_3", "Truck"]),
        ("DistanceDecrease", &["car_1", "car_2"]),
        ("DistanceDecrease", &["car_1", "car_3"]),
    ]);
    let pad = LogicPad::builtin();
    let parse = |q: &str| match logicpad::parse_any_query(q) {
        Ok(logicpad::ParsedQuery::Count(c)) => c,
        other => panic!("{q}: {other:?}"),
    };
    for (q, op, n, holds) in [
        (
            "#{x: TypeOf(x, Car)} >= 2",
            logicpad::CountOp::AtLeast,
            2,
            true,
        ),
        (
            "#{x: TypeOf(x, Car)} > 2",
            logicpad::CountOp::MoreThan,
            2,
            false,
        ),
        (
            "#{x: TypeOf(x, Car)} ≤ 1",
            logicpad::CountOp::AtMost,
            1,
            false,
        ),
        (
            "#{x: TypeOf(x, Car)} < 3",
            logicpad::CountOp::FewerThan,
            3,
            true,
        ),
        (
            "  #{ x : TypeOf(x, Car) } = 2",
            logicpad::CountOp::Exactly,
            2,
            true,
        ),
        (
            "#{x: TypeOf(x, Car)} == 2",
            logicpad::CountOp::Exactly,
            2,
            true,
        ),
        (
            "#{x: TypeOf(x, Car)} ≥ 3",
            logicpad::CountOp::AtLeast,
            3,
            false,
        ),
    ] {
        let c = parse(q);
        assert_eq!((c.op, c.n), (op, n), "{q}");
        assert_eq!(c.inner, "TypeOf(x, Car)");
        assert_eq!(c.query.answer_var_names(), vec!["x"]);
        let n = m.count(&c.query).expect("count");
        assert_eq!(n, 2);
        assert_eq!(c.holds(n), holds, "{q}");
        assert!(
            logicpad::check_any_query(pad.schema(), &logicpad::ParsedQuery::Count(c)).is_empty()
        );
    }
    // Other variables are existential: one car approaches two vehicles.
    let c = parse("#{x: DistanceDecrease(x, y)} = 1");
    assert_eq!(m.count(&c.query).expect("count"), 1);
    let c = parse("#{x, y: DistanceDecrease(x, y)} = 2");
    assert_eq!(m.count(&c.query).expect("count"), 2);
    // With a ¬∃ inside: cars nothing approaches.
    let c = parse("#{x: Vehicles(x) ∧ ¬∃y: (DistanceDecrease(y, x))} = 1");
    assert_eq!(m.count(&c.query).expect("count"), 1);
    // Errors: a counted variable the query does not mention; syntax.
    let c = parse("#{z: TypeOf(x, Car)} > 1");
    let d = logicpad::check_any_query(pad.schema(), &logicpad::ParsedQuery::Count(c));
    assert!(
        d.iter().any(|d| d.is_error() && d.message.contains("`z`")),
        "{d:?}"
    );
    for bad in [
        "#{x: TypeOf(x, Car)}",
        "#{x: TypeOf(x, Car)} >= ",
        "#{x: TypeOf(x, Car)} >= 2 cars",
        "#{x TypeOf(x, Car)} >= 2",
        "#{x: TypeOf(x, Car) >= 2",
        "#{x: } >= 2",
        "#{x, x: TypeOf(x, Car)} >= 2",
        "#x: TypeOf(x, Car) >= 2",
        "#{x: ∀y: TypeOf(y, Car)} >= 2",
        "#{x: TypeOf(x, Car)} ≥ -1",
    ] {
        assert!(logicpad::parse_any_query(bad).is_err(), "{bad}");
    }
    assert!(parse_query("#{x: TypeOf(x, Car)} >= 2").is_err());
    // A syntax error inside Q points into the text as written.
    let e = logicpad::parse_any_query("#{x: TypeOf(x, Car) ∧ $} >= 2").expect_err("bad char");
    assert_eq!(e.span.start, "#{x: TypeOf(x, Car) ∧ ".len());
}
