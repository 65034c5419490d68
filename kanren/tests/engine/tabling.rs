//! Tabled relations: left recursion over cyclic data terminates complete.

use super::{all_answers, sorted};
use kanren::*;
use std::collections::BTreeSet;
use std::sync::Arc;

fn graph(edges: &[(&str, &str)]) -> Arc<Relation> {
    let mut r = Relation::new("edge", 2);
    for (a, b) in edges {
        r.insert(&[sym(a), sym(b)])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    Arc::new(r)
}

/// path(X, Y) :- path(X, Z), edge(Z, Y).   (left recursive)
/// path(X, Y) :- edge(X, Y).
fn left_path(edge: Arc<Relation>) -> Tabled {
    Tabled::new("path", 2, move |path, args| {
        let (x, y) = (args[0].clone(), args[1].clone());
        let (edge1, edge2, path) = (edge.clone(), edge.clone(), path.clone());
        let (x1, y1) = (x.clone(), y.clone());
        disj([
            fresh(move |[z]| {
                conj([
                    path.call(vec![x1.clone(), z.clone()]),
                    fact(&edge1, vec![z, y1.clone()]),
                ])
            }),
            fact(&edge2, vec![x, y]),
        ])
    })
}

/// The transitive closure, computed directly.
fn closure(edges: &[(&str, &str)]) -> BTreeSet<(String, String)> {
    let mut set: BTreeSet<(String, String)> = edges
        .iter()
        .map(|(a, b)| (a.to_string(), b.to_string()))
        .collect();
    loop {
        let mut next = set.clone();
        for (a, b) in &set {
            for (c, d) in &set {
                if b == c {
                    next.insert((a.clone(), d.clone()));
                }
            }
        }
        if next == set {
            return set;
        }
        set = next;
    }
}

const CYCLIC: &[(&str, &str)] = &[("a", "b"), ("b", "c"), ("c", "a"), ("c", "d"), ("e", "e")];

#[test]
fn left_recursive_path_over_a_cycle_from_a_node() {
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let y = q.var("y");
    let got = sorted(all_answers(&q, path.call(vec![sym("a"), y])));
    assert_eq!(got, ["a", "b", "c", "d"]);
}

#[test]
fn left_recursive_path_all_pairs_equals_transitive_closure() {
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let got: BTreeSet<(String, String)> = all_answers(&q, path.call(vec![x, y]))
        .into_iter()
        .filter_map(|s| {
            s.split_once(", ")
                .map(|(a, b)| (a.to_owned(), b.to_owned()))
        })
        .collect();
    assert_eq!(got, closure(CYCLIC));
    // Answers come once each: tables hold sets.
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    assert_eq!(
        all_answers(&q, path.call(vec![x, y])).len(),
        closure(CYCLIC).len()
    );
}

#[test]
fn right_recursive_and_mutual_recursion() {
    // reach(X, Y) :- edge(X, Y).  reach(X, Y) :- edge(X, Z), reach2(Z, Y).
    // reach2(X, Y) :- reach(X, Y).            (two tables depending on each other)
    let edge = graph(CYCLIC);
    let reach2_cell: Arc<std::sync::OnceLock<Tabled>> = Arc::new(std::sync::OnceLock::new());
    let reach = {
        let cell = reach2_cell.clone();
        let edge = edge.clone();
        Tabled::new("reach", 2, move |_reach, args| {
            let (x, y) = (args[0].clone(), args[1].clone());
            let (e1, e2, cell) = (edge.clone(), edge.clone(), cell.clone());
            let (x1, y1) = (x.clone(), y.clone());
            disj([
                fact(&e1, vec![x, y]),
                fresh(move |[z]| {
                    let r2 = cell
                        .get()
                        .map(|t| t.call(vec![z.clone(), y1.clone()]))
                        .unwrap_or_else(fail);
                    conj([fact(&e2, vec![x1.clone(), z]), r2])
                }),
            ])
        })
    };
    let reach2 = {
        let reach = reach.clone();
        Tabled::new("reach2", 2, move |_, args| reach.call(args.to_vec()))
    };
    assert!(reach2_cell.set(reach2).is_ok());
    let mut q = Query::new();
    let y = q.var("y");
    let got = sorted(all_answers(&q, reach.call(vec![sym("b"), y])));
    assert_eq!(got, ["a", "b", "c", "d"]);
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    assert_eq!(
        all_answers(&q, reach.call(vec![x, y])).len(),
        closure(CYCLIC).len()
    );
}

#[test]
fn tabled_answers_keep_their_proofs() {
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let y = q.var("y");
    let cfg = RunConfig {
        proofs: true,
        ..RunConfig::default()
    };
    let answers: Vec<Answer> = q
        .run(path.call(vec![sym("a"), y]), cfg)
        .collect::<Result<_, _>>()
        .unwrap_or_else(|e| panic!("{e}"));
    let d = answers
        .iter()
        .find(|a| a.values[0] == sym("d"))
        .unwrap_or_else(|| panic!("no answer d"));
    let facts: Vec<FactId> = d
        .proof
        .as_ref()
        .map(|p| {
            p.steps
                .iter()
                .filter_map(|s| match s {
                    ProofStep::Fact { id, .. } => Some(*id),
                    ProofStep::Rule(_) => None,
                })
                .collect()
        })
        .unwrap_or_default();
    // a -> b -> c -> d: edges 0, 1, 3.
    assert_eq!(facts, [0, 1, 3]);
}

#[test]
fn tabled_arity_error() {
    let path = left_path(graph(CYCLIC));
    let q = Query::new();
    let got: Vec<_> = q
        .run(path.call(vec![sym("a")]), RunConfig::default())
        .collect();
    assert!(matches!(
        got.as_slice(),
        [Err(RunError::TabledArity { got: 1, .. })]
    ));
}
