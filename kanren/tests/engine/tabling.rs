//! Tabled relations: left recursion over cyclic data terminates complete.

use super::{all_answers, first_answers, sorted};
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

// ------------------------------------------------ laziness and fairness

use proptest::prelude::*;
use std::sync::OnceLock;
use std::sync::atomic::{AtomicUsize, Ordering};

/// `edge(a, b)`, counting every edge it hands out in `touched`.
fn counted_edge(edge: &Arc<Relation>, touched: &Arc<AtomicUsize>, a: Term, b: Term) -> Goal {
    let touched = touched.clone();
    conj([
        fact(edge, vec![a, b]),
        project(vec![], move |_| {
            touched.fetch_add(1, Ordering::Relaxed);
            succeed()
        }),
    ])
}

/// The left-recursive `path` over `edge`, counting edges touched and body
/// builds (one per call variant).
fn counted_left_path(
    edge: Arc<Relation>,
    touched: Arc<AtomicUsize>,
    bodies: Arc<AtomicUsize>,
) -> Tabled {
    Tabled::new("path", 2, move |path, args| {
        bodies.fetch_add(1, Ordering::Relaxed);
        let (x, y) = (args[0].clone(), args[1].clone());
        let (edge1, touched1, path) = (edge.clone(), touched.clone(), path.clone());
        let (x1, y1) = (x.clone(), y.clone());
        disj([
            fresh(move |[z]| {
                conj([
                    path.call(vec![x1.clone(), z.clone()]),
                    counted_edge(&edge1, &touched1, z, y1.clone()),
                ])
            }),
            counted_edge(&edge, &touched, x, y),
        ])
    })
}

fn chain(n: i64) -> Arc<Relation> {
    let mut r = Relation::new("edge", 2);
    for i in 0..n {
        r.insert(&[Term::Int(i), Term::Int(i + 1)])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    Arc::new(r)
}

/// The first answer of a left-recursive `path` over a 2 000-edge chain is
/// found without computing the table: a handful of edges are touched, where
/// the whole table touches every edge. (The old fixpoint evaluation computed
/// the whole table inside the first call.)
#[test]
fn run_1_on_a_long_left_recursive_chain_is_lazy() {
    const N: i64 = 2000;
    let edge = chain(N);
    let (touched, bodies) = (Arc::new(AtomicUsize::new(0)), Arc::new(AtomicUsize::new(0)));
    let path = counted_left_path(edge.clone(), touched.clone(), bodies.clone());
    let mut q = Query::new();
    let y = q.var("y");
    let cfg = RunConfig {
        limit: Some(1),
        ..RunConfig::default()
    };
    let mut run = q.run(path.call(vec![Term::Int(0), y.clone()]), cfg);
    let first: Vec<String> = run
        .by_ref()
        .map(|a| a.map(|a| a.to_string()).unwrap_or_else(|e| panic!("{e}")))
        .collect();
    assert_eq!(first, ["1"]);
    let lazy_edges = touched.load(Ordering::Relaxed);
    let lazy_steps = run.steps();
    assert!(lazy_edges <= 4, "run(1) touched {lazy_edges} edges");
    assert_eq!(bodies.load(Ordering::Relaxed), 1);

    touched.store(0, Ordering::Relaxed);
    let mut run = q.run(path.call(vec![Term::Int(0), y]), RunConfig::default());
    let all = run.by_ref().count();
    assert_eq!(all, N as usize);
    assert_eq!(run.stop_reason(), Some(StopReason::Exhausted));
    assert!(touched.load(Ordering::Relaxed) >= N as usize);
    assert!(
        lazy_steps * 100 < run.steps(),
        "{lazy_steps} vs {}",
        run.steps()
    );
}

/// The same for a right-recursive chain, where every node is a variant of
/// its own (2 000 tables when complete).
#[test]
fn run_1_on_a_long_right_recursive_chain_is_lazy() {
    let edge = chain(2000);
    let touched = Arc::new(AtomicUsize::new(0));
    let path = {
        let touched = touched.clone();
        Tabled::new("path", 2, move |path, args| {
            let (x, y) = (args[0].clone(), args[1].clone());
            let (edge1, touched1, path) = (edge.clone(), touched.clone(), path.clone());
            let (x1, y1) = (x.clone(), y.clone());
            disj([
                counted_edge(&edge, &touched, x, y),
                fresh(move |[z]| {
                    conj([
                        counted_edge(&edge1, &touched1, x1.clone(), z.clone()),
                        path.call(vec![z, y1.clone()]),
                    ])
                }),
            ])
        })
    };
    let mut q = Query::new();
    let y = q.var("y");
    assert_eq!(
        first_answers(&q, 3, path.call(vec![Term::Int(0), y])).len(),
        3
    );
    let n = touched.load(Ordering::Relaxed);
    assert!(n <= 40, "run(3) touched {n} edges");
}

/// nat(X) :- nat(Y), X = s(Y).  nat(z).   — infinitely many answers, left
/// recursive: `run(n)` returns the first n (the old evaluation never
/// returned), and a sibling branch beside it is not starved.
fn nat() -> Tabled {
    Tabled::new("nat", 1, |nat, args| {
        let x = args[0].clone();
        let (nat, x1) = (nat.clone(), x.clone());
        disj([
            fresh(move |[y]| {
                conj([
                    nat.call(vec![y.clone()]),
                    eq(x1.clone(), Term::app("s", [y])),
                ])
            }),
            eq(x, sym("z")),
        ])
    })
}

#[test]
fn an_infinite_table_yields_a_prefix_and_is_fair_to_its_siblings() {
    let nat = nat();
    let mut q = Query::new();
    let x = q.var("x");
    let got = first_answers(&q, 5, nat.call(vec![x.clone()]));
    let want = ["z", "s(z)", "s(s(z))", "s(s(s(z)))", "s(s(s(s(z))))"];
    assert_eq!(sorted(got), sorted(want.map(String::from).to_vec()));

    let goal = disj([nat.call(vec![x.clone()]), eq(x, sym("stop"))]);
    let got = first_answers(&q, 20, goal);
    assert!(got.iter().any(|a| a == "stop"), "{got:?}");
}

/// A non-tabled infinite branch beside a tabled call does not starve the
/// table's producer: every answer of the table still comes.
#[test]
fn a_table_beside_an_infinite_branch_still_completes_its_answers() {
    fn forever(x: Term) -> Goal {
        disj([
            eq(x.clone(), sym("loop")),
            delay(move || forever(x.clone())),
        ])
    }
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let y = q.var("y");
    let goal = disj([forever(y.clone()), path.call(vec![sym("a"), y])]);
    let got: BTreeSet<String> = first_answers(&q, 200, goal).into_iter().collect();
    let want: BTreeSet<String> = ["a", "b", "c", "d", "loop"].map(String::from).into();
    assert_eq!(got, want);
}

// ------------------------------------------------ completion

/// p(X) :- p(X).  Every stream ends up suspended on the one table, with no
/// producer able to go on: the table completes empty and the run ends.
#[test]
fn a_call_that_only_calls_itself_completes_empty() {
    let p = Tabled::new("p", 1, |p, args| p.call(args.to_vec()));
    let mut q = Query::new();
    let x = q.var("x");
    let mut run = q.run(p.call(vec![x]), RunConfig::default());
    assert!(run.next().is_none());
    assert_eq!(run.stop_reason(), Some(StopReason::Exhausted));

    // With an exit, the one answer, once.
    let p = Tabled::new("p", 1, |p, args| {
        disj([p.call(args.to_vec()), eq(args[0].clone(), Term::Int(1))])
    });
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(all_answers(&q, p.call(vec![x])), ["1"]);
}

/// A committed choice over a tabled call, at the top and inside a producer
/// (without an `else`, so it is stratified).
#[test]
fn committed_choice_over_tables() {
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let y = q.var("y");
    let goal = conda([
        vec![path.call(vec![sym("a"), y.clone()])],
        vec![eq(y.clone(), sym("none"))],
    ]);
    assert_eq!(sorted(all_answers(&q, goal)), ["a", "b", "c", "d"]);
    let goal = conda([
        vec![path.call(vec![sym("d"), y.clone()])],
        vec![eq(y.clone(), sym("none"))],
    ]);
    assert_eq!(all_answers(&q, goal), ["none"]);
    assert_eq!(
        first_answers(&q, 5, onceo(path.call(vec![sym("a"), y]))).len(),
        1
    );

    // r(X) :- X = 1 ; onceo(r(X)).
    let r = Tabled::new("r", 1, |r, args| {
        disj([
            eq(args[0].clone(), Term::Int(1)),
            onceo(r.call(args.to_vec())),
        ])
    });
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(all_answers(&q, r.call(vec![x])), ["1"]);
}

/// Negation over a table that completes first is fine; a table whose
/// answers depend on its own negation (not stratified) is an error, not a
/// hang or a guess.
#[test]
fn negation_and_tables() {
    let path = left_path(graph(CYCLIC));
    let mut q = Query::new();
    let y = q.var("y");
    let goal = conj([
        disj([eq(y.clone(), sym("d")), eq(y.clone(), sym("e"))]),
        naf(path.call(vec![sym("a"), y])),
    ]);
    assert_eq!(all_answers(&q, goal), ["e"]);

    // p(X) :- X = 1, naf(p(1)).
    let p = Tabled::new("p", 1, |p, args| {
        conj([
            eq(args[0].clone(), Term::Int(1)),
            naf(p.call(vec![Term::Int(1)])),
        ])
    });
    let mut q = Query::new();
    let x = q.var("x");
    let got: Vec<_> = q.run(p.call(vec![x]), RunConfig::default()).collect();
    assert!(
        matches!(got.as_slice(), [Err(RunError::TabledNegationCycle { relation })] if relation.as_str() == "p"),
        "{got:?}"
    );

    // The same cycle through a second table, which is stuck waiting on the
    // table under evaluation: it must not be completed (empty) early.
    // p2(X) :- X = 1, naf(q2(X)).  q2(X) :- p2(X).
    let q2_cell: Arc<OnceLock<Tabled>> = Arc::new(OnceLock::new());
    let p2 = {
        let cell = q2_cell.clone();
        Tabled::new("p2", 1, move |_, args| {
            let q2 = cell
                .get()
                .map(|t| t.call(args.to_vec()))
                .unwrap_or_else(fail);
            conj([eq(args[0].clone(), Term::Int(1)), naf(q2)])
        })
    };
    let q2 = {
        let p2 = p2.clone();
        Tabled::new("q2", 1, move |_, args| p2.call(args.to_vec()))
    };
    let _ = q2_cell.set(q2);
    let mut q = Query::new();
    let x = q.var("x");
    let got: Vec<_> = q.run(p2.call(vec![x]), RunConfig::default()).collect();
    assert!(
        matches!(got.as_slice(), [Err(RunError::TabledNegationCycle { .. })]),
        "{got:?}"
    );

    // q(X) :- conda([[q(X)], [X = 1]]): its else branch depends on q's completion.
    let qrel = Tabled::new("q", 1, |q, args| {
        conda([
            vec![q.call(args.to_vec())],
            vec![eq(args[0].clone(), Term::Int(1))],
        ])
    });
    let mut q = Query::new();
    let x = q.var("x");
    let got: Vec<_> = q.run(qrel.call(vec![x]), RunConfig::default()).collect();
    assert!(
        matches!(got.as_slice(), [Err(RunError::TabledNegationCycle { .. })]),
        "{got:?}"
    );
}

// ------------------------------------------------ constraints

fn one_clause(name: &str, f: impl Fn(&[Term]) -> Goal + Send + Sync + 'static) -> Tabled {
    Tabled::new(name, 1, move |_, args| f(args))
}

#[test]
fn constraints_on_non_ground_answers_are_kept() {
    let not1 = one_clause("not1", |a| neq(a[0].clone(), Term::Int(1)));
    let mut q = Query::new();
    let y = q.var("y");
    assert_eq!(
        all_answers(&q, not1.call(vec![y.clone()])),
        ["_0 where _0 =/= 1"]
    );
    // A later binding that violates the kept constraint fails ...
    let goal = conj([not1.call(vec![y.clone()]), eq(y.clone(), Term::Int(1))]);
    assert!(all_answers(&q, goal).is_empty());
    // ... one that does not, succeeds.
    let goal = conj([not1.call(vec![y.clone()]), eq(y.clone(), Term::Int(2))]);
    assert_eq!(all_answers(&q, goal), ["2"]);

    let sym_only = one_clause("sym_only", |a| symbolo(a[0].clone()));
    assert_eq!(
        all_answers(&q, sym_only.call(vec![y.clone()])),
        ["_0 where symbolo(_0)"]
    );
    let goal = conj([sym_only.call(vec![y.clone()]), eq(y.clone(), Term::Int(5))]);
    assert!(all_answers(&q, goal).is_empty());

    let no_a = one_clause("no_a", |a| absento(sym("a"), a[0].clone()));
    let goal = conj([
        no_a.call(vec![y.clone()]),
        eq(y.clone(), Term::list([sym("b"), sym("a")])),
    ]);
    assert!(all_answers(&q, goal).is_empty());
    let goal = conj([
        no_a.call(vec![y.clone()]),
        eq(y.clone(), Term::list([sym("b")])),
    ]);
    assert_eq!(all_answers(&q, goal), ["[b]"]);
}

#[test]
fn answers_differing_only_in_constraints_are_distinct_and_duplicates_are_not() {
    let two = one_clause("two", |a| {
        disj([
            neq(a[0].clone(), Term::Int(1)),
            neq(a[0].clone(), Term::Int(2)),
        ])
    });
    let same = one_clause("same", |a| {
        disj([
            neq(a[0].clone(), Term::Int(1)),
            neq(Term::Int(1), a[0].clone()),
        ])
    });
    let mut q = Query::new();
    let y = q.var("y");
    assert_eq!(
        sorted(all_answers(&q, two.call(vec![y.clone()]))),
        ["_0 where _0 =/= 1", "_0 where _0 =/= 2"]
    );
    assert_eq!(all_answers(&q, same.call(vec![y])), ["_0 where _0 =/= 1"]);
}

#[test]
fn multi_pair_and_recursive_constraints_are_kept() {
    // t(X, Y) :- (X, Y) =/= (1, 2).
    let t = Tabled::new("t", 2, |_, a| {
        neq(
            Term::app("p", [a[0].clone(), a[1].clone()]),
            Term::app("p", [Term::Int(1), Term::Int(2)]),
        )
    });
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let call = || t.call(vec![x.clone(), y.clone()]);
    assert_eq!(
        all_answers(&q, call()),
        ["_0, _1 where (_0, _1) =/= (1, 2)"]
    );
    let goal = conj([
        call(),
        eq(x.clone(), Term::Int(1)),
        eq(y.clone(), Term::Int(2)),
    ]);
    assert!(all_answers(&q, goal).is_empty());
    let goal = conj([call(), eq(x.clone(), Term::Int(1))]);
    assert_eq!(all_answers(&q, goal), ["1, _0 where _0 =/= 2"]);

    // A constrained answer that comes back through a recursive call is the
    // same answer: nz(X) :- X =/= 0 ; nz(X).
    let nz = Tabled::new("nz", 1, |nz, a| {
        disj([neq(a[0].clone(), Term::Int(0)), nz.call(a.to_vec())])
    });
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(
        all_answers(&q, nz.call(vec![x.clone()])),
        ["_0 where _0 =/= 0"]
    );
    let goal = conj([nz.call(vec![x.clone()]), eq(x, Term::Int(0))]);
    assert!(all_answers(&q, goal).is_empty());
}

/// A disequality on a variable local to the body (one the answer does not
/// show) is dropped: it can always be satisfied by that variable.
#[test]
fn a_disequality_with_a_body_local_variable_is_dropped() {
    let u = one_clause("u", |a| {
        let x = a[0].clone();
        fresh(move |[z]| neq(x.clone(), z))
    });
    let mut q = Query::new();
    let y = q.var("y");
    assert_eq!(all_answers(&q, u.call(vec![y])), ["_0"]);
}

// ------------------------------------------------ against a naive oracle

type Pairs = BTreeSet<(i64, i64)>;

fn int_graph(edges: &[(i64, i64)]) -> Arc<Relation> {
    let mut r = Relation::new("edge", 2);
    for (a, b) in edges {
        r.insert(&[Term::Int(*a), Term::Int(*b)])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    Arc::new(r)
}

/// The transitive closure, and the pairs joined by odd / even (≥ 2) walks.
fn oracle(edges: &[(i64, i64)]) -> (Pairs, Pairs, Pairs) {
    let mut walks: BTreeSet<(i64, i64, bool)> = edges.iter().map(|&(a, b)| (a, b, true)).collect();
    loop {
        let mut next = walks.clone();
        for &(a, b, odd) in &walks {
            for &(c, d) in edges {
                if b == c {
                    next.insert((a, d, !odd));
                }
            }
        }
        if next == walks {
            break;
        }
        walks = next;
    }
    let pick = |want: Option<bool>| {
        walks
            .iter()
            .filter(|w| want.is_none_or(|o| w.2 == o))
            .map(|w| (w.0, w.1))
            .collect::<Pairs>()
    };
    (pick(None), pick(Some(true)), pick(Some(false)))
}

#[derive(Clone, Copy, Debug)]
enum Shape {
    Left,
    Right,
    Double,
}

fn path_of(shape: Shape, edge: Arc<Relation>) -> Tabled {
    Tabled::new("path", 2, move |path, args| {
        let (x, y) = (args[0].clone(), args[1].clone());
        let (e, path) = (edge.clone(), path.clone());
        let (x1, y1) = (x.clone(), y.clone());
        let step = fresh(move |[z]| {
            let (a, b) = match shape {
                Shape::Left => (
                    path.call(vec![x1.clone(), z.clone()]),
                    fact(&e, vec![z, y1.clone()]),
                ),
                Shape::Right => (
                    fact(&e, vec![x1.clone(), z.clone()]),
                    path.call(vec![z, y1.clone()]),
                ),
                Shape::Double => (
                    path.call(vec![x1.clone(), z.clone()]),
                    path.call(vec![z, y1.clone()]),
                ),
            };
            conj([a, b])
        });
        disj([step, fact(&edge, vec![x, y])])
    })
}

/// odd(X, Y) :- edge(X, Y) ; even(X, Z), edge(Z, Y).
/// even(X, Y) :- odd(X, Z), edge(Z, Y).
fn odd_even(edge: Arc<Relation>) -> (Tabled, Tabled) {
    let even_cell: Arc<OnceLock<Tabled>> = Arc::new(OnceLock::new());
    let odd = {
        let (cell, edge) = (even_cell.clone(), edge.clone());
        Tabled::new("odd", 2, move |_, args| {
            let (x, y) = (args[0].clone(), args[1].clone());
            let (e, cell) = (edge.clone(), cell.clone());
            let (x1, y1) = (x.clone(), y.clone());
            disj([
                fact(&edge, vec![x, y]),
                fresh(move |[z]| {
                    let even = cell
                        .get()
                        .map(|t| t.call(vec![x1.clone(), z.clone()]))
                        .unwrap_or_else(fail);
                    conj([even, fact(&e, vec![z, y1.clone()])])
                }),
            ])
        })
    };
    let even = {
        let odd = odd.clone();
        Tabled::new("even", 2, move |_, args| {
            let (x, y) = (args[0].clone(), args[1].clone());
            let (e, odd) = (edge.clone(), odd.clone());
            fresh(move |[z]| {
                conj([
                    odd.call(vec![x.clone(), z.clone()]),
                    fact(&e, vec![z, y.clone()]),
                ])
            })
        })
    };
    let _ = even_cell.set(even.clone());
    (odd, even)
}

/// The answers of `rel(a, b)` as pairs (bound arguments filled in), in order.
fn pairs_of(rel: &Tabled, a: Option<i64>, b: Option<i64>, limit: Option<usize>) -> Vec<(i64, i64)> {
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let arg = |v: Option<i64>, var: &Term| v.map_or_else(|| var.clone(), Term::Int);
    let goal = conj([
        rel.call(vec![arg(a, &x), arg(b, &y)]),
        eq(x.clone(), arg(a, &x)),
        eq(y.clone(), arg(b, &y)),
    ]);
    let cfg = RunConfig {
        limit,
        ..RunConfig::default()
    };
    q.run(goal, cfg)
        .map(|ans| {
            let ans = ans.unwrap_or_else(|e| panic!("{e}"));
            let int = |t: &Term| t.as_int().unwrap_or_else(|| panic!("non-integer {t}"));
            (int(&ans.values[0]), int(&ans.values[1]))
        })
        .collect()
}

/// Every way of calling `rel` against the pairs `want`: all pairs, each
/// first argument bound, each second argument bound, both bound, and
/// `run(n)` prefixes. Answers come once each.
fn check_against(rel: &Tabled, want: &Pairs, nodes: i64) -> Result<(), TestCaseError> {
    let all = pairs_of(rel, None, None, None);
    prop_assert_eq!(all.len(), want.len(), "duplicates or missing: {:?}", all);
    prop_assert_eq!(&all.iter().copied().collect::<Pairs>(), want);
    for n in 0..nodes {
        let from: Vec<(i64, i64)> = pairs_of(rel, Some(n), None, None);
        let want_from: Pairs = want.iter().filter(|p| p.0 == n).copied().collect();
        prop_assert_eq!(from.len(), want_from.len());
        prop_assert_eq!(from.into_iter().collect::<Pairs>(), want_from);
        let to: Vec<(i64, i64)> = pairs_of(rel, None, Some(n), None);
        let want_to: Pairs = want.iter().filter(|p| p.1 == n).copied().collect();
        prop_assert_eq!(to.len(), want_to.len());
        prop_assert_eq!(to.into_iter().collect::<Pairs>(), want_to);
        for m in 0..nodes {
            let both = pairs_of(rel, Some(n), Some(m), None);
            prop_assert_eq!(both.len(), usize::from(want.contains(&(n, m))));
        }
    }
    for k in 1..=4 {
        let first = pairs_of(rel, None, None, Some(k));
        let distinct: Pairs = first.iter().copied().collect();
        prop_assert_eq!(first.len(), k.min(want.len()));
        prop_assert_eq!(distinct.len(), first.len());
        prop_assert!(distinct.is_subset(want));
    }
    Ok(())
}

fn small_graph() -> impl Strategy<Value = (i64, Vec<(i64, i64)>)> {
    (1i64..=6).prop_flat_map(|n| (Just(n), prop::collection::vec((0..n, 0..n), 0..14)))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 128, ..ProptestConfig::default() })]

    /// Left-, right- and doubly-recursive `path` compute the transitive
    /// closure, however called, on graphs with cycles and self-loops.
    #[test]
    fn path_equals_the_transitive_closure((nodes, edges) in small_graph()) {
        let (closure, _, _) = oracle(&edges);
        for shape in [Shape::Left, Shape::Right, Shape::Double] {
            let path = path_of(shape, int_graph(&edges));
            check_against(&path, &closure, nodes)?;
        }
    }

    /// Two tables calling each other (odd / even walks) match the oracle,
    /// called through either one, as does a `path` split across two
    /// relations.
    #[test]
    fn mutual_recursion_matches_the_oracle((nodes, edges) in small_graph()) {
        let (closure, odd_pairs, even_pairs) = oracle(&edges);
        let (odd, even) = odd_even(int_graph(&edges));
        check_against(&odd, &odd_pairs, nodes)?;
        check_against(&even, &even_pairs, nodes)?;

        // reach(X, Y) :- edge(X, Y) ; edge(X, Z), reach2(Z, Y).  reach2 :- reach.
        let edge = int_graph(&edges);
        let cell: Arc<OnceLock<Tabled>> = Arc::new(OnceLock::new());
        let reach = {
            let cell = cell.clone();
            Tabled::new("reach", 2, move |_, args| {
                let (x, y) = (args[0].clone(), args[1].clone());
                let (e, cell) = (edge.clone(), cell.clone());
                let (x1, y1) = (x.clone(), y.clone());
                disj([
                    fact(&edge, vec![x, y]),
                    fresh(move |[z]| {
                        let r2 = cell
                            .get()
                            .map(|t| t.call(vec![z.clone(), y1.clone()]))
                            .unwrap_or_else(fail);
                        conj([fact(&e, vec![x1.clone(), z]), r2])
                    }),
                ])
            })
        };
        let reach2 = {
            let reach = reach.clone();
            Tabled::new("reach2", 2, move |_, args| reach.call(args.to_vec()))
        };
        let _ = cell.set(reach2.clone());
        check_against(&reach, &closure, nodes)?;
        check_against(&reach2, &closure, nodes)?;
    }
}
