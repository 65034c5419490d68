//! Negation as failure.

use super::all_answers;
use kanren::classic::membero;
use kanren::*;
use std::sync::Arc;

fn speeds() -> Arc<Relation> {
    let mut r = Relation::new("speed_up", 1);
    r.insert(&[sym("car1")]).unwrap_or_else(|e| panic!("{e}"));
    Arc::new(r)
}

#[test]
fn naf_on_bound_variables() {
    let up = speeds();
    let mut q = Query::new();
    let x = q.var("x");
    // ∀x: vehicle(x) ∧ ¬speed_up(x)
    let g = conj([
        membero(
            x.clone(),
            Term::list([sym("car1"), sym("car2"), sym("car3")]),
        ),
        naf(fact(&up, vec![x.clone()])),
    ]);
    assert_eq!(all_answers(&q, g), ["car2", "car3"]);
}

#[test]
fn naf_with_local_variables_is_fine() {
    let up = speeds();
    let q = Query::new();
    // ¬∃y speed_up(y): false, since car1 speeds up.
    let g = naf(fresh({
        let up = up.clone();
        move |[y]| fact(&up, vec![y])
    }));
    assert!(all_answers(&q, g).is_empty());
    let empty = Arc::new(Relation::new("slow_down", 1));
    let g = naf(fresh(move |[y]| fact(&empty, vec![y])));
    assert_eq!(all_answers(&q, g), [""]);
}

#[test]
fn naf_on_an_unbound_variable_is_an_error() {
    let up = speeds();
    let mut q = Query::new();
    let x = q.var("x");
    let got: Vec<_> = q
        .run(naf(fact(&up, vec![x.clone()])), RunConfig::default())
        .collect();
    match got.as_slice() {
        [Err(RunError::UnboundNegation { vars })] => assert_eq!(vars, &["x".to_owned()]),
        other => panic!("expected UnboundNegation, got {other:?}"),
    }
    let msg = naf_error_text(&q, naf(fact(&up, vec![x])));
    assert!(msg.contains("unbound") && msg.contains('x'), "{msg}");
}

fn naf_error_text(q: &Query, g: Goal) -> String {
    q.run(g, RunConfig::default())
        .find_map(|r| r.err())
        .map(|e| e.to_string())
        .unwrap_or_default()
}

#[test]
fn run_stops_with_error_reason() {
    let up = speeds();
    let mut q = Query::new();
    let x = q.var("x");
    let mut run = q.run(naf(fact(&up, vec![x])), RunConfig::default());
    assert!(matches!(run.next(), Some(Err(_))));
    assert!(run.next().is_none());
    assert_eq!(run.stop_reason(), Some(StopReason::Error));
}

/// A relation that recurses forever without an answer.
fn loopo() -> Goal {
    delay(loopo)
}

#[test]
fn budgets_reach_inside_negation_and_committed_choice() {
    let q = Query::new();
    let cfg = RunConfig {
        budget: Budget {
            max_steps: Some(2_000),
            max_time: None,
        },
        ..RunConfig::default()
    };
    // naf of a goal that never finishes: the run stops on the budget, it
    // does not conclude "no answer, so the negation holds".
    let mut run = q.run(naf(loopo()), cfg.clone());
    assert!(run.next().is_none());
    assert_eq!(run.stop_reason(), Some(StopReason::StepBudget));
    let mut run = q.run(onceo(loopo()), cfg);
    assert!(run.next().is_none());
    assert_eq!(run.stop_reason(), Some(StopReason::StepBudget));
}

#[test]
fn errors_inside_committed_choice_reach_the_run() {
    let up = speeds();
    let mut q = Query::new();
    let x = q.var("x");
    let got: Vec<_> = q
        .run(onceo(naf(fact(&up, vec![x]))), RunConfig::default())
        .collect();
    assert!(
        matches!(got.as_slice(), [Err(RunError::UnboundNegation { .. })]),
        "{got:?}"
    );
}
