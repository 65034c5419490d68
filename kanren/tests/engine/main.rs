//! Integration tests of the kanren engine, one module per area.

mod classic;
mod constraints;
mod facts;
mod naf;
mod props;
mod tabling;
mod terms;

use kanren::{Answer, Goal, Query, RunConfig, RunError};

/// Every answer of `goal` over `q`'s variables, printed; panics on a run error.
pub fn all_answers(q: &Query, goal: Goal) -> Vec<String> {
    answers(q, goal).iter().map(Answer::to_string).collect()
}

/// Every answer, failing the test on a run error.
pub fn answers(q: &Query, goal: Goal) -> Vec<Answer> {
    q.run(goal, RunConfig::default())
        .collect::<Result<Vec<_>, RunError>>()
        .unwrap_or_else(|e| panic!("unexpected run error: {e}"))
}

/// The first `n` answers, printed.
pub fn first_answers(q: &Query, n: usize, goal: Goal) -> Vec<String> {
    let cfg = RunConfig {
        limit: Some(n),
        ..RunConfig::default()
    };
    q.run(goal, cfg)
        .map(|a| a.map(|a| a.to_string()))
        .collect::<Result<Vec<_>, RunError>>()
        .unwrap_or_else(|e| panic!("unexpected run error: {e}"))
}

/// Sorted copy, for answer-set comparisons.
pub fn sorted(mut v: Vec<String>) -> Vec<String> {
    v.sort();
    v
}
