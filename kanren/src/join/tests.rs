use super::*;
use crate::{Query, RunConfig, conj, fact};

fn rel(name: &str, rows: &[&[&str]]) -> Arc<Relation> {
    let arity = rows.first().map_or(2, |r| r.len());
    let mut r = Relation::new(name, arity);
    for row in rows {
        let t: Vec<Term> = row.iter().map(|s| Term::Sym(crate::Sym::new(s))).collect();
        r.insert(&t).ok();
    }
    Arc::new(r)
}

/// Relation `pred` applied to the slots `slots`.
fn atom(pred: usize, slots: &[usize]) -> Atom {
    Atom {
        pred,
        args: slots.iter().map(|&v| Arg::Var(v)).collect(),
    }
}

fn answers(goal: Goal, q: &Query) -> Vec<String> {
    let mut v: Vec<String> = q
        .run(goal, RunConfig::default())
        .map(|a| a.map(|a| a.to_string()).unwrap_or_else(|e| e.to_string()))
        .collect();
    v.sort();
    v
}

/// The join goal answers exactly what the conjunction of `fact` goals
/// answers, with bound and unbound query variables and constants.
#[test]
fn join_equals_the_conjunction_of_fact_goals() {
    let edge = rel(
        "edge",
        &[&["a", "b"], &["b", "c"], &["c", "a"], &["b", "d"]],
    );
    let red = rel("red", &[&["b"], &["c"]]);
    let rels: Arc<[Arc<Relation>]> = vec![edge.clone(), red.clone()].into();
    let mut q = Query::new();
    let (x, y, z) = (q.var("x"), q.var("y"), q.var("z"));
    let atoms: Arc<[Atom]> = vec![atom(0, &[0, 1]), atom(0, &[1, 2]), atom(1, &[1])].into();
    let terms: Arc<[Term]> = vec![x.clone(), y.clone(), z.clone()].into();
    let by_join = answers(join(rels.clone(), atoms.clone(), terms), &q);
    let by_facts = answers(
        conj([
            fact(&edge, vec![x.clone(), y.clone()]),
            fact(&edge, vec![y.clone(), z.clone()]),
            fact(&red, vec![y.clone()]),
        ]),
        &q,
    );
    assert_eq!(by_join, by_facts);
    assert_eq!(by_join, ["a, b, c", "a, b, d", "b, c, a"]);
    // A query variable bound before the join runs is a preset slot.
    let bound = conj([
        crate::eq(x.clone(), Term::Sym(crate::Sym::new("b"))),
        join(rels, atoms, vec![x, y, z].into()),
    ]);
    assert_eq!(answers(bound, &q), ["b, c, a"]);
}

/// A join is lazy: taking the first answer of a cross product of two
/// thousand-fact relations tries a handful of candidates, not a million.
#[test]
fn the_first_answer_costs_a_few_steps() {
    let mut a = Relation::new("a", 1);
    let mut b = Relation::new("b", 1);
    for i in 0..1000i64 {
        a.insert(&[Term::Int(i)]).ok();
        b.insert(&[Term::Int(i)]).ok();
    }
    let rels: Arc<[Arc<Relation>]> = vec![Arc::new(a), Arc::new(b)].into();
    let atoms: Arc<[Atom]> = vec![atom(0, &[0]), atom(1, &[1])].into();
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let mut run = q.run(join(rels, atoms, vec![x, y].into()), RunConfig::default());
    let first: Vec<_> = run.by_ref().take(10).collect();
    assert_eq!(first.len(), 10);
    assert!(run.steps() < 100, "{} steps for 10 answers", run.steps());
}

/// With proofs on, each answer names the fact of every atom, in the
/// atoms' order (not the join's).
#[test]
fn proofs_name_each_atoms_fact_in_body_order() {
    let big = rel("big", &[&["a", "1"], &["b", "2"], &["c", "3"]]);
    let one = rel("one", &[&["b"]]);
    let rels: Arc<[Arc<Relation>]> = vec![big, one].into();
    let atoms: Arc<[Atom]> = vec![atom(0, &[0, 1]), atom(1, &[0])].into();
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let cfg = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    let got: Vec<_> = q
        .run(join(rels, atoms, vec![x, y].into()), cfg)
        .collect::<Result<_, _>>()
        .unwrap_or_default();
    assert_eq!(got.len(), 1);
    let steps = got[0].proof.clone().unwrap_or_default().steps;
    assert_eq!(
        steps,
        [
            ProofStep::Fact {
                relation: crate::Sym::new("big"),
                id: 1
            },
            ProofStep::Fact {
                relation: crate::Sym::new("one"),
                id: 0
            }
        ]
    );
}

/// A counting run counts a join's matches without building states, and
/// gets the number the answers would give — with a variable shared by
/// two slots (a match must unify to count) and with a cap.
#[test]
fn counting_equals_the_answers() {
    let edge = rel(
        "edge",
        &[
            &["a", "a"],
            &["a", "b"],
            &["b", "b"],
            &["b", "c"],
            &["c", "a"],
        ],
    );
    let rels: Arc<[Arc<Relation>]> = vec![edge].into();
    let atoms: Arc<[Atom]> = vec![atom(0, &[0, 1])].into();
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let cfg = RunConfig::default;
    let all = q.run(
        join(
            rels.clone(),
            atoms.clone(),
            vec![x.clone(), y.clone()].into(),
        ),
        cfg(),
    );
    assert_eq!(all.count(), 5);
    let mut run = q.run(
        join(
            rels.clone(),
            atoms.clone(),
            vec![x.clone(), y.clone()].into(),
        ),
        cfg(),
    );
    assert_eq!(run.count_up_to(100).ok(), Some(5));
    assert_eq!(run.stop_reason(), Some(crate::StopReason::Exhausted));
    // x in both slots: only the loops a-a and b-b.
    let mut run = q.run(
        join(
            rels.clone(),
            atoms.clone(),
            vec![x.clone(), x.clone()].into(),
        ),
        cfg(),
    );
    assert_eq!(run.count_up_to(100).ok(), Some(2));
    // Past the cap the count stops at cap + 1.
    let mut run = q.run(join(rels, atoms, vec![x, y].into()), cfg());
    assert_eq!(run.count_up_to(2).ok(), Some(3));
}
