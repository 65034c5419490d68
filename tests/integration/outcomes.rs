//! The four outcomes are never confused; every query part is used or rejected.
use logicpad::LogicPad;
use logicrag::ask::{AskOptions, Outcome, ask};
use logicrag::context::{RagContext, Sentences};
use logicrag::kb::WindowKb;
use logicrag::source::{LoadOptions, load};

fn window(
    spec: &str,
    id: &str,
) -> (
    LogicPad,
    WindowKb,
    std::collections::BTreeMap<String, logicrag::kb::Observed>,
) {
    let pad = LogicPad::builtin();
    let loaded = load(&spec.parse().unwrap(), &LoadOptions::default(), &mut |_| {}).unwrap();
    let observed = loaded.observability.classify(&pad);
    let input = loaded.windows.into_iter().find(|w| w.id == id).unwrap();
    let kb = WindowKb::build(input, pad.program()).unwrap();
    (pad, kb, observed)
}

#[test]
fn unknown_predicate_is_invalid_never_a_weaker_query() {
    let (pad, kb, obs) = window("sim:urban_crossing", "urban_crossing_000030");
    // Pedestrian(x) alone is yes; adding an unknown atom must not drop it.
    assert_eq!(
        ask(&pad, &kb, &obs, "Pedestrian(x)", AskOptions::default()).answer,
        Outcome::Yes
    );
    let r = ask(
        &pad,
        &kb,
        &obs,
        "Pedestrian(x) ^ Levitates(x)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::Invalid);
    assert!(
        r.reasons.iter().any(|m| m.contains("Levitates")),
        "{:?}",
        r.reasons
    );
    let r = ask(&pad, &kb, &obs, "Pedestrian(x, y)", AskOptions::default());
    assert_eq!(r.answer, Outcome::Invalid, "arity");
    let r = ask(&pad, &kb, &obs, "ColorOf(x, Plaid)", AskOptions::default());
    assert_eq!(r.answer, Outcome::Invalid, "undeclared value");
    let r = ask(
        &pad,
        &kb,
        &obs,
        "Pedestrian(x) ^ ¬Moving(y)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::Invalid, "unsafe negation");
}

#[test]
fn a_variable_in_its_own_atoms_is_still_constrained() {
    let (pad, kb, obs) = window("sim:urban_crossing", "urban_crossing_000030");
    // y appears only in Bus(y)-like atoms: no bus exists, so the whole query fails.
    let alone = ask(&pad, &kb, &obs, "Pedestrian(x)", AskOptions::default());
    assert_eq!(alone.answer, Outcome::Yes);
    let r = ask(
        &pad,
        &kb,
        &obs,
        "Pedestrian(x) ^ TypeOf(y, Bus)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::No, "{r:?}");
    assert!(!r.why_not.is_empty());
}

#[test]
fn yes_answers_carry_sorted_bindings_and_proofs_with_provenance() {
    let (pad, kb, obs) = window("sim:urban_crossing", "urban_crossing_000030");
    let r = ask(
        &pad,
        &kb,
        &obs,
        "Vehicles(x) ^ Stopped(x)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::Yes);
    assert_eq!(r.count, r.bindings.len());
    let mut sorted = r.bindings.clone();
    sorted.sort();
    assert_eq!(sorted, r.bindings);
    assert_eq!(r.proofs.len(), r.bindings.len());
    let proof = logicrag::proof::lines(&r.proofs[0]).join("\n");
    assert!(proof.contains("[rule, line"), "{proof}");
    assert!(proof.contains("sim:urban_crossing window 3"), "{proof}");
    let ctx = RagContext::new(
        &kb,
        Some("Are there stopped vehicles?"),
        &r,
        Sentences::builtin(),
    );
    assert!(ctx.c2[0].starts_with("The answer is yes"));
    assert!(
        ctx.c3
            .iter()
            .any(|s| s.starts_with("pedestrian_5 is a pedestrian")),
        "{:?}",
        ctx.c3
    );
    let text = ctx.to_text();
    assert!(text.contains("[C2]") && text.contains("[C3]"));
}

#[test]
fn constant_distance_fires_for_measured_pairs_without_a_trend() {
    // Regression: ConstantDistance needs SharesFrames(x, y) from perception
    // to bind both objects; without it the rule could never fire.
    let (pad, kb, obs) = window("sim:urban_crossing", "urban_crossing_000000");
    let r = ask(
        &pad,
        &kb,
        &obs,
        "ConstantDistance(x, y)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::Yes, "{r:?}");
    for b in &r.bindings {
        let (x, y) = (&b[0].1, &b[1].1);
        for trend in ["DistanceIncrease", "DistanceDecrease"] {
            let q = format!("{trend}({x}, {y})");
            assert_eq!(
                ask(&pad, &kb, &obs, &q, AskOptions::default()).answer,
                Outcome::No,
                "{q}"
            );
        }
    }
}

#[test]
fn why_not_never_reads_another_variable_as_a_constant() {
    // `x = y` with `y` free says nothing against a candidate for `x`; it
    // used to compare the candidate with the text "y" and list it as failed.
    let (pad, kb, obs) = window("sim:urban_crossing", "urban_crossing_000030");
    let r = ask(
        &pad,
        &kb,
        &obs,
        "Pedestrian(x) ^ Pedestrian(y) ^ x = y ^ SpeedUp(x)",
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::No);
    let for_x: Vec<_> = r.why_not.iter().filter(|w| w.variable == "x").collect();
    assert!(!for_x.is_empty(), "{:?}", r.why_not);
    for w in for_x {
        assert!(
            w.failed.iter().all(|f| !f.contains("= y")),
            "{}: {:?}",
            w.candidate,
            w.failed
        );
        // `pedestrian_1 = y` alone is no query (y unbound): it is never a
        // claim of its own, only inside a failed set that binds y.
        assert!(w.satisfied.iter().all(|s| !s.ends_with("= y")), "{w:?}");
    }
    assert_eq!(
        logicrag::whynot::audit(&pad, &kb, &obs, &r),
        Vec::<String>::new()
    );
}

/// A proof deeper than logicpad's default depth limit reaches the answer's
/// proof lines (the JSON `proofs`) and the C2 context as a stated cut, not
/// as an overflow or a silently missing premise.
#[test]
fn a_proof_cut_by_the_depth_limit_is_said_in_proofs_and_context() {
    use logicrag::kb::{Observability, WindowInput};
    use perception::{Fact, Provenance};
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
    let pad = LogicPad::parse(src, "chain.yaml", false).unwrap();
    assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
    let fact = |p: &str, args: &[String]| Fact {
        predicate: p.to_string(),
        args: args.to_vec(),
        provenance: std::sync::Arc::new(Provenance {
            window: 0,
            frames: (0, 9),
            source: "test".into(),
            measured: None,
            threshold: None,
            note: String::new(),
            probability: None,
        }),
    };
    let len = 200;
    let mut facts = vec![fact("Start", &["n0".into()])];
    facts.extend((0..len).map(|i| fact("Edge", &[format!("n{i}"), format!("n{}", i + 1)])));
    let input = WindowInput {
        id: "chain".into(),
        index: 0,
        first_frame: 0,
        last_frame: 9,
        facts: facts.into(),
        doubts: Vec::new(),
    };
    let kb = WindowKb::build(input, pad.program()).unwrap();
    let obs = Observability::everything().classify(&pad);
    // n199, not n200: a constant must be some fact's first argument.
    let target = len - 1;
    let r = ask(
        &pad,
        &kb,
        &obs,
        &format!("Reach(n0, n{target})"),
        AskOptions::default(),
    );
    assert_eq!(r.answer, Outcome::Yes, "{r:?}");
    let depth = logicpad::ProofLimits::DEFAULT_MAX_DEPTH;
    let cut = format!(
        "{}Reach(n0, n{})  [proof cut: depth limit {depth}]",
        "  ".repeat(depth),
        target - depth
    );
    let lines = logicrag::proof::lines(&r.proofs[0]);
    assert!(lines.contains(&cut), "{lines:?}");
    let ctx = RagContext::new(&kb, None, &r, Sentences::builtin());
    let sentence = format!(
        "Reach(n0, n{}) holds; its proof is left out here (depth limit {depth}).",
        target - depth
    );
    assert!(
        ctx.c2
            .iter()
            .any(|s| s.trim_start().ends_with(&format!("because {sentence}"))),
        "{:?}",
        ctx.c2
    );
}

/// Every why-not and C2 claim over the built-in question sets of every
/// scenario at every noise level, and over templated two-variable
/// questions on every window, asked back as a query, agrees with the
/// engine (issue 22: one claim in seven of the two-variable kind used to
/// be false).
#[test]
fn every_why_not_claim_on_the_built_in_question_sets_is_true() {
    use perception::sim::NoisePreset;
    for noise in [
        NoisePreset::None,
        NoisePreset::Low,
        NoisePreset::Default,
        NoisePreset::High,
        NoisePreset::Mono,
    ] {
        why_not_claims_are_true(LoadOptions {
            noise: Some(noise.into()),
            ..LoadOptions::default()
        });
    }
}

/// The claims of [`every_why_not_claim_on_the_built_in_question_sets_is_true`]
/// for sources loaded with `opts`.
fn why_not_claims_are_true(opts: LoadOptions) {
    let pad = LogicPad::builtin();
    let engine =
        logicrag::engine::Engine::new(pad.clone(), logicrag::kb::Observability::everything())
            .unwrap();
    // Each a place, a relation or a trend through a second variable.
    let templates = [
        "Is the pedestrian on the road?",
        "Is there a pedestrian on the sidewalk?",
        "Pedestrian(x) ∧ On(x, y) ∧ Road(y)",
        "Vehicles(x) ∧ On(x, y) ∧ Sidewalk(y)",
        "Vehicles(x) ∧ Pedestrian(y) ∧ DistanceDecrease(x, y) ∧ SpeedUp(x)",
        "Vehicles(x) ∧ Vehicles(y) ∧ x ≠ y ∧ GettingCloser(x, y) ∧ Stopped(x)",
        "Pedestrian(x) ∧ Vehicles(y) ∧ ¬DistanceDecrease(y, x) ∧ Moving(y) ∧ Cross(x)",
        "TypeOf(x, Truck) ∧ Moving(x)",
        "∀x: Pedestrian(x) → NotCross(x)",
    ];
    let (mut claims, mut noes, mut hinges_checked) = (0usize, 0usize, 0usize);
    for name in perception::sim::BUILTIN_NAMES {
        let loaded = load(&format!("sim:{name}").parse().unwrap(), &opts, &mut |_| {}).unwrap();
        let run = loaded.sim.as_ref().unwrap();
        let windows = perception::window_facts(&run.sequence, opts.windows, &opts.config).unwrap();
        let questions = logicrag::questions::generate(run, &windows, &opts.config);
        let inputs = loaded.windows.clone();
        let kbs: Vec<WindowKb> = loaded
            .windows
            .into_iter()
            .map(|w| engine.build(w).unwrap())
            .collect();
        for (kb, input) in kbs.iter().zip(&inputs) {
            let asked = questions
                .iter()
                .filter(|q| q.window == kb.id)
                .map(|q| q.question.as_str())
                .chain(templates);
            for text in asked {
                let Ok(p) = engine.prepare(text) else {
                    continue;
                };
                let r = engine.ask(kb, &p, AskOptions::default());
                if r.answer != Outcome::No {
                    continue;
                }
                noes += 1;
                claims += r
                    .why_not
                    .iter()
                    .map(|w| w.satisfied.len() + w.failed.len())
                    .sum::<usize>();
                let wrong = logicrag::whynot::audit(&pad, kb, engine.observed(), &r);
                assert!(
                    wrong.is_empty(),
                    "{:?} {} `{text}`: {wrong:#?}",
                    opts.noise,
                    kb.id
                );
                let c2 = engine.context(kb, &p, &r).c2;
                let said: Vec<String> = r
                    .why_not
                    .iter()
                    .filter_map(logicrag::whynot::WhyNot::sentence)
                    .collect();
                // Then the hinges of a noisy window's answer, each true:
                // the window rebuilt with that one fact flipped answers
                // otherwise.
                let hinges: Vec<String> = r
                    .hinges
                    .iter()
                    .map(logicrag::belief::Hinge::sentence)
                    .collect();
                let mut expected = said.clone();
                expected.extend(hinges);
                assert_eq!(
                    c2[1 + r.notes.len()..],
                    expected[..],
                    "{:?} {} `{text}`",
                    opts.noise,
                    kb.id
                );
                for h in &r.hinges {
                    let flipped = engine.build(flip(input, &h.fact, h.holds)).unwrap();
                    let again = engine.ask(&flipped, &p, AskOptions::default());
                    assert!(
                        (again.answer, again.count, &again.bindings)
                            != (r.answer, r.count, &r.bindings),
                        "{:?} {} `{text}`: flipping {} changes nothing",
                        opts.noise,
                        kb.id,
                        h.fact
                    );
                    hinges_checked += 1;
                }
            }
        }
    }
    assert!(
        noes > 100 && claims > 200,
        "{:?}: {noes} no answers, {claims} claims",
        opts.noise
    );
    // A noisy source has hinges to check; a certain one has none.
    let certain = opts.noise == Some(perception::sim::NoisePreset::None.into());
    assert_eq!(
        certain,
        hinges_checked == 0,
        "{:?}: {hinges_checked} hinges",
        opts.noise
    );
}

/// `input` with the base fact written `fact` dropped (`holds`) or its
/// doubt asserted (not `holds`).
fn flip(input: &logicrag::kb::WindowInput, fact: &str, holds: bool) -> logicrag::kb::WindowInput {
    let text = |f: &perception::Fact| format!("{}({})", f.predicate, f.args.join(", "));
    let mut out = input.clone();
    let logicrag::kb::WindowFacts::Listed(facts) = &mut out.facts else {
        panic!("a simulator window lists its facts");
    };
    if holds {
        let before = facts.len();
        facts.retain(|f| text(f) != fact);
        assert!(facts.len() < before, "{fact} is not a fact of {}", input.id);
    } else {
        let doubt = input
            .doubts
            .iter()
            .find(|f| text(f) == fact)
            .unwrap_or_else(|| panic!("{fact} is not a doubt of {}", input.id));
        facts.push(doubt.clone());
    }
    out
}

/// The translator's syntax tree is the query's: built directly from its
/// atoms, it equals what the parser reads from the rendered text (the
/// same variables, answer variables and literals, spans and all), over
/// every built-in scenario's question set.
#[test]
fn a_translated_querys_tree_is_the_tree_of_its_text() {
    let engine = logicrag::engine::Engine::new(
        LogicPad::builtin(),
        logicrag::kb::Observability::everything(),
    )
    .expect("engine");
    let mut checked = 0;
    for scenario in perception::sim::BUILTIN_NAMES {
        let options = logicrag::pipeline::OpenOptions {
            keep_scene: true,
            ..Default::default()
        };
        let pipeline = logicrag::pipeline::Pipeline::open(
            format!("sim:{scenario}").parse().expect("spec"),
            &options,
            &mut |_| {},
        )
        .expect("opens");
        let questions = logicrag::eval::scenario_questions(&pipeline).expect("questions");
        for q in questions {
            let Ok(t) = engine.translator().translate(&q.question) else {
                continue;
            };
            let built = logicpad::QueryAst::conjunction(&t.literals());
            let parsed = logicpad::parse_query(&t.query).expect("the rendered query parses");
            assert_eq!(built.text(), t.query, "{}", q.question);
            assert_eq!(built.vars, parsed.vars, "{}", q.question);
            assert_eq!(built.answer_vars, parsed.answer_vars, "{}", q.question);
            assert_eq!(built.disjuncts, parsed.disjuncts, "{}", q.question);
            checked += 1;
        }
    }
    assert!(checked > 500, "only {checked} questions translated");
}
