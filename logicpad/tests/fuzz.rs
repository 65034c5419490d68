//! Fuzz-style robustness: truncated and garbled YAML, FOL, queries and fact
//! texts give errors (diagnostics), never a panic.

use logicpad::{BUILTIN_SOURCE, FactBase, LogicPad, RunConfig, check_query, parse_query};

mod common;
use common::Rng;

const NASTY: [&str; 18] = [
    "(", ")", "¬", ":", "\"", "\n", "- ", "[", "{", " ", "∀", "==>", ",", "'", "\t", "#", "?", "∃x",
];

fn garble(text: &str, g: &mut Rng, edits: usize) -> String {
    let mut s = text.to_string();
    for _ in 0..edits {
        let mut at = g.below(s.len() + 1);
        while !s.is_char_boundary(at) {
            at -= 1;
        }
        let mut end = (at + g.below(4)).min(s.len());
        while !s.is_char_boundary(end) {
            end -= 1;
        }
        s.replace_range(at..end, NASTY[g.below(NASTY.len())]);
    }
    s
}

fn boundaries(s: &str, step: usize) -> impl Iterator<Item = usize> + '_ {
    (0..s.len())
        .step_by(step)
        .filter(|&i| s.is_char_boundary(i))
}

/// Loading must never panic, and every diagnostic must render.
fn load_any(text: &str) -> Result<LogicPad, Vec<logicpad::Diagnostic>> {
    match LogicPad::parse(text, "fuzz.yaml", false) {
        Ok(p) => {
            for d in p.diagnostics() {
                assert!(d.span.end <= text.len());
                let _ = d.render_plain(80);
            }
            Ok(p)
        }
        Err(e) => {
            let ds = e.diagnostics();
            assert!(!ds.is_empty(), "an error without diagnostics: {e}");
            for d in &ds {
                let _ = d.render_plain(80);
            }
            Err(ds)
        }
    }
}

#[test]
fn truncated_yaml_never_panics() {
    for cut in boundaries(BUILTIN_SOURCE, 61) {
        let _ = load_any(&BUILTIN_SOURCE[..cut]);
    }
}

#[test]
fn garbled_yaml_never_panics() {
    let mut g = Rng(0x5eed_1234_abcd_0001);
    for round in 0..120 {
        let text = garble(BUILTIN_SOURCE, &mut g, 1 + round % 6);
        let _ = load_any(&text);
    }
}

#[test]
fn every_proper_prefix_of_a_rule_is_an_error() {
    let rules = [
        "∀x : (Vehicles(x) ∨ Pedestrian(x)) ∧ ¬Moving(x) ==> Stopped(x)",
        "∀x,y : DistanceDecrease(x, y) ∧ DistanceZeroEnd(x, y) ∧ Vehicles(x) ==> Collide(x, y)",
        "forall x: TypeOf(x) = Car & ColorOf(x) != White -> NotWhiteCar(x)",
    ];
    for rule in rules {
        for cut in boundaries(rule, 1) {
            let prefix = &rule[..cut];
            let src = format!(
                "atomic_predicates:\n  t:\n    - Vehicles(x)\n    - Pedestrian(x)\n    - Moving(x)\n    - DistanceDecrease(x, y)\n    - DistanceZeroEnd(x, y)\nfunctions:\n  TypeOf:\n    predicate: TypeOf(x, t)\n    values: [Car]\n  ColorOf:\n    predicate: ColorOf(x, c)\n    values: [White]\nderived_predicates:\n  - name: R\n    logic: {prefix:?}\n"
            );
            if let Ok(p) = load_any(&src) {
                assert!(p.has_errors(), "prefix {prefix:?} loaded without an error")
            }
        }
        // The whole rule is fine.
        let full = format!(
            "atomic_predicates:\n  t:\n    - Vehicles(x)\n    - Pedestrian(x)\n    - Moving(x)\n    - DistanceDecrease(x, y)\n    - DistanceZeroEnd(x, y)\nfunctions:\n  TypeOf:\n    predicate: TypeOf(x, t)\n    values: [Car]\n  ColorOf:\n    predicate: ColorOf(x, c)\n    values: [White]\nderived_predicates:\n  - name: R\n    logic: {rule:?}\n"
        );
        let pad = load_any(&full).expect("loads");
        assert!(!pad.has_errors(), "{:?}", pad.diagnostics());
    }
}

#[test]
fn garbled_queries_never_panic() {
    let pad = LogicPad::builtin();
    let mut fb = FactBase::new();
    for (p, a) in [
        ("Vehicles", "car_1"),
        ("Moving", "car_1"),
        ("Pedestrian", "pedestrian_2"),
    ] {
        fb.add(p, &[a]).expect("fact");
    }
    fb.add("DistanceDecrease", &["car_1", "pedestrian_2"])
        .expect("fact");
    let model = pad.program().evaluate(fb).expect("evaluates");
    let base = "∃y : TypeOf(x) = Car ∧ GettingCloser(x, y) ∧ ¬Stopped(x) ∨ (Walk(?p) ∧ p ≠ x)";
    let mut g = Rng(77);
    let mut errors = 0;
    for round in 0..300 {
        let q = if round < base.len() {
            let mut c = round;
            while !base.is_char_boundary(c) {
                c -= 1;
            }
            base[..c].to_string()
        } else {
            garble(base, &mut g, 1 + round % 4)
        };
        match parse_query(&q) {
            Ok(ast) => {
                let diags = check_query(pad.schema(), &ast);
                for d in &diags {
                    let _ = d.render_plain(80);
                }
                if diags.iter().all(|d| !d.is_error()) {
                    let _ = model.ask(
                        &ast,
                        RunConfig {
                            proofs: true,
                            ..RunConfig::default()
                        },
                    );
                }
            }
            Err(d) => {
                errors += 1;
                let _ = d.render_plain(80);
            }
        }
    }
    assert!(errors > 50, "garbling should break most queries ({errors})");
}

#[test]
fn garbled_fact_texts_give_errors() {
    let text = "Vehicles(car_1)\nDistanceDecrease(car_1, car_2)\nColorOf(car_1, White)\n";
    let mut g = Rng(99);
    let pad = LogicPad::builtin();
    for round in 0..200 {
        let t = garble(text, &mut g, 1 + round % 3);
        if let Ok(fb) = FactBase::from_text(&t, "f.facts") {
            let _ = pad.program().evaluate(fb);
        }
    }
    assert!(FactBase::from_text("Vehicles(car_1\n", "f.facts").is_err());
    assert!(FactBase::from_text("Vehicles(car_1, )\n", "f.facts").is_err());
    let err =
        FactBase::from_text("Vehicles(car_1)\nVehicles(a, b)\n", "f.facts").expect_err("arity");
    assert!(err.to_string().contains("Vehicles"));
}

#[test]
fn deeply_nested_yaml_is_an_error_not_a_crash() {
    let deep = format!(
        "atomic_predicates:\n  t: {}{}\n",
        "[".repeat(5000),
        "]".repeat(5000)
    );
    let _ = load_any(&deep);
    let deep_map = format!(
        "functions:\n{}",
        (0..300)
            .map(|i| format!("{}g{i}:\n", "  ".repeat(i + 1)))
            .collect::<String>()
    );
    let _ = load_any(&deep_map);
}
