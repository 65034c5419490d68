//! Fact relations, joins, proofs, budgets and `Send`.

use super::{all_answers, sorted};
use kanren::*;
use std::sync::Arc;
use std::time::Duration;

/// type(car_i, car|truck) and color(car_i, white|red) for `n` vehicles, plus
/// `noise` unrelated vehicles (other types and colors).
fn kb(n: usize, noise: usize) -> (Arc<Relation>, Arc<Relation>) {
    let mut ty = Relation::new("type_of", 2);
    let mut color = Relation::new("color_of", 2);
    for i in 0..n {
        let v = sym(&format!("v{i}"));
        let t = if i % 2 == 0 { "car" } else { "truck" };
        let c = if i % 3 == 0 { "white" } else { "red" };
        ty.insert(&[v.clone(), sym(t)])
            .unwrap_or_else(|e| panic!("{e}"));
        color.insert(&[v, sym(c)]).unwrap_or_else(|e| panic!("{e}"));
    }
    for i in 0..noise {
        let v = sym(&format!("noise{i}"));
        ty.insert(&[v.clone(), sym("bus")])
            .unwrap_or_else(|e| panic!("{e}"));
        color
            .insert(&[v, sym("blue")])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    (Arc::new(ty), Arc::new(color))
}

/// TypeOf(x, car) ^ ColorOf(x, white)
fn white_cars(ty: &Arc<Relation>, color: &Arc<Relation>, x: &Term) -> Goal {
    conj([
        fact(ty, vec![x.clone(), sym("car")]),
        fact(color, vec![x.clone(), sym("white")]),
    ])
}

#[test]
fn conjunctive_query_over_facts() {
    let (ty, color) = kb(12, 5);
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(
        sorted(all_answers(&q, white_cars(&ty, &color, &x))),
        ["v0", "v6"]
    );
    // Both orders of the conjunction give the same set.
    let swapped = conj([
        fact(&color, vec![x.clone(), sym("white")]),
        fact(&ty, vec![x.clone(), sym("car")]),
    ]);
    assert_eq!(sorted(all_answers(&q, swapped)), ["v0", "v6"]);
}

#[test]
fn indexed_join_cost_is_flat_in_unrelated_facts() {
    // The step count of a run is deterministic: doubling (and more) the
    // unrelated facts must not change it, because every lookup goes through
    // the index of a bound argument instead of scanning.
    let steps = |noise: usize| {
        let (ty, color) = kb(40, noise);
        let mut q = Query::new();
        let x = q.var("x");
        let mut run = q.run(white_cars(&ty, &color, &x), RunConfig::default());
        let n = run.by_ref().count();
        (n, run.steps())
    };
    let base = steps(1_000);
    assert_eq!(base.0, 7);
    assert_eq!(steps(2_000), base);
    assert_eq!(steps(8_000), base);
}

#[test]
fn proofs_name_facts_and_rules() {
    let (ty, color) = kb(12, 0);
    let mut q = Query::new();
    let x = q.var("x");
    let rule = label("white_car", white_cars(&ty, &color, &x));
    let cfg = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    let answers: Vec<Answer> = q
        .run(rule.clone(), cfg)
        .collect::<Result<_, _>>()
        .unwrap_or_else(|e| panic!("{e}"));
    let first = answers
        .iter()
        .find(|a| a.values[0] == sym("v6"))
        .unwrap_or_else(|| panic!("no v6"));
    assert_eq!(
        first.proof.as_ref().map(|p| p.steps.clone()),
        Some(vec![
            ProofStep::Rule(Sym::new("white_car")),
            ProofStep::Fact {
                relation: Sym::new("type_of"),
                id: 6
            },
            ProofStep::Fact {
                relation: Sym::new("color_of"),
                id: 6
            },
        ])
    );
    // Off by default: no proof recorded.
    let plain = q.run(rule, RunConfig::default()).next();
    assert!(matches!(plain, Some(Ok(Answer { proof: None, .. }))));
}

#[test]
fn fact_with_wrong_arity_or_compound_argument_matches_nothing() {
    let (ty, _) = kb(4, 0);
    let mut q = Query::new();
    let x = q.var("x");
    assert!(all_answers(&q, fact(&ty, vec![x.clone()])).is_empty());
    assert!(all_answers(&q, fact(&ty, vec![x, Term::list([1i64])])).is_empty());
}

fn nato(n: Term) -> Goal {
    disj([
        eq(n.clone(), 0),
        fresh(move |[m]| conj([eq(n.clone(), Term::app("s", [m.clone()])), nato(m)])),
    ])
}

#[test]
fn budgets_stop_infinite_runs_with_a_reason() {
    let mut q = Query::new();
    let n = q.var("n");
    let cfg = RunConfig {
        budget: Budget {
            max_steps: Some(500),
            max_time: None,
        },
        ..RunConfig::default()
    };
    let mut run = q.run(nato(n.clone()), cfg);
    let got = run.by_ref().count();
    assert!(got > 10, "{got}");
    assert_eq!(run.stop_reason(), Some(StopReason::StepBudget));
    assert!(run.steps() <= 501);

    let cfg = RunConfig {
        budget: Budget {
            max_steps: None,
            max_time: Some(Duration::from_millis(30)),
        },
        ..RunConfig::default()
    };
    let mut run = q.run(fresh(|[x]| nato(x)), cfg);
    let _ = run.by_ref().count();
    assert_eq!(run.stop_reason(), Some(StopReason::TimeBudget));

    let cfg = RunConfig {
        limit: Some(4),
        ..RunConfig::default()
    };
    let mut run = q.run(nato(n.clone()), cfg);
    assert_eq!(run.by_ref().count(), 4);
    assert_eq!(run.stop_reason(), Some(StopReason::Limit));

    let mut run = q.run(eq(n, 1), RunConfig::default());
    assert!(run.stop_reason().is_none());
    assert_eq!(run.by_ref().count(), 1);
    assert_eq!(run.stop_reason(), Some(StopReason::Exhausted));
}

#[test]
fn runs_and_answers_are_send_and_run_on_other_threads() {
    fn assert_send<T: Send>() {}
    fn assert_send_sync<T: Send + Sync>() {}
    assert_send::<Run>();
    assert_send::<Answer>();
    assert_send_sync::<Goal>();
    assert_send_sync::<Relation>();
    assert_send_sync::<Term>();
    assert_send_sync::<Sym>();

    let (ty, color) = kb(30, 10);
    let handles: Vec<_> = (0..3)
        .map(|_| {
            let (ty, color) = (ty.clone(), color.clone());
            let mut q = Query::new();
            let x = q.var("x");
            let run = q.run(white_cars(&ty, &color, &x), RunConfig::default());
            std::thread::spawn(move || run.filter_map(Result::ok).count())
        })
        .collect();
    for h in handles {
        assert_eq!(h.join().ok(), Some(5));
    }
}

/// reach(x, z) over a chain of `edge` facts, with every step labelled.
fn reach(edge: Arc<Relation>, x: Term, z: Term) -> Goal {
    label(
        "reach",
        conde([
            vec![fact(&edge, vec![x.clone(), z.clone()])],
            vec![fresh(move |[y]| {
                let e = edge.clone();
                let z = z.clone();
                conj([
                    fact(&edge, vec![x.clone(), y.clone()]),
                    delay(move || reach(e.clone(), y.clone(), z.clone())),
                ])
            })],
        ]),
    )
}

/// Regression: an answer's proof is a shared-tail list of steps, and dropping
/// it recursed once per step, so the proof of a 300 000-step derivation
/// overflowed the stack when the run's states were dropped.
#[test]
fn a_proof_of_300k_steps_is_dropped_without_overflowing_the_stack() {
    let n = 300_000;
    let mut edge = Relation::new("edge", 2);
    for i in 0..n {
        edge.insert(&[sym(&format!("n{i}")), sym(&format!("n{}", i + 1))])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    let edge = Arc::new(edge);
    let q = Query::new();
    let goal = reach(edge, sym("n0"), sym(&format!("n{n}")));
    let cfg = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    let answers: Vec<Answer> = q
        .run(goal, cfg)
        .collect::<Result<_, _>>()
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(answers.len(), 1);
    let steps = answers[0].proof.as_ref().map_or(0, |p| p.steps.len());
    // One `reach` label and one `edge` fact per step.
    assert_eq!(steps, 2 * n);
}
