//! Classic programs with known answers.

use super::{all_answers, answers, first_answers, sorted};
use kanren::classic::{appendo, membero, nextto, peano, pluso, rembero, zebrao};
use kanren::*;

#[test]
fn appendo_splits_a_list() {
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let got = all_answers(&q, appendo(x, y, Term::list([1i64, 2, 3])));
    assert_eq!(
        got,
        [
            "[], [1, 2, 3]",
            "[1], [2, 3]",
            "[1, 2], [3]",
            "[1, 2, 3], []"
        ]
    );
}

#[test]
fn appendo_forwards_and_unknown_prefix() {
    let mut q = Query::new();
    let z = q.var("z");
    let got = all_answers(&q, appendo(Term::list([1i64, 2]), Term::list([3i64]), z));
    assert_eq!(got, ["[1, 2, 3]"]);

    // run 3 (x y z) (appendo x y z): fresh variables reified _0, _1 …
    let mut q = Query::new();
    let (x, y, z) = (q.var("x"), q.var("y"), q.var("z"));
    let got = first_answers(&q, 3, appendo(x, y, z));
    assert_eq!(
        got,
        [
            "[], _0, _0",
            "[_0], _1, [_0 | _1]",
            "[_0, _1], _2, [_0, _1 | _2]"
        ]
    );
}

#[test]
fn membero_enumerates_and_checks() {
    let mut q = Query::new();
    let x = q.var("x");
    let l = Term::list([sym("a"), sym("b"), sym("c")]);
    assert_eq!(all_answers(&q, membero(x, l.clone())), ["a", "b", "c"]);
    let q = Query::new();
    assert_eq!(all_answers(&q, membero(sym("b"), l.clone())), [""]);
    assert!(all_answers(&q, membero(sym("z"), l)).is_empty());
}

#[test]
fn rembero_from_the_reasoned_schemer() {
    // (run* out (rembero 'pea '(a b pea d peas e) out))
    let mut q = Query::new();
    let out = q.var("out");
    let l = Term::list(["a", "b", "pea", "d", "peas", "e"].map(sym));
    let got = all_answers(&q, rembero(sym("pea"), l, out));
    assert_eq!(got, ["[a, b, d, peas, e]", "[a, b, pea, d, peas, e]"]);
}

#[test]
fn peano_addition_runs_backwards() {
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let got = sorted(all_answers(&q, pluso(x, y, peano(3))));
    let want = sorted(
        (0..=3)
            .map(|i| format!("{}, {}", peano(i), peano(3 - i)))
            .collect(),
    );
    assert_eq!(got, want);
    let mut q = Query::new();
    let k = q.var("k");
    assert_eq!(
        all_answers(&q, pluso(peano(2), peano(2), k)),
        [peano(4).to_string()]
    );
}

#[test]
fn zebra_puzzle_has_one_solution() {
    let mut q = Query::new();
    let hs = q.var("houses");
    let got = answers(&q, zebrao(hs));
    assert_eq!(got.len(), 1);
    let houses = got[0].values[0].to_vec().unwrap_or_default();
    let who = |slot: usize, v: &str| {
        houses.iter().find_map(|h| match h {
            Term::App(_, a) if a[slot] == sym(v) => Some(a[1].clone()),
            _ => None,
        })
    };
    assert_eq!(who(2, "zebra"), Some(sym("japanese")));
    assert_eq!(who(3, "water"), Some(sym("norwegian")));
}

#[test]
fn nextto_finds_neighbours() {
    let mut q = Query::new();
    let (a, b) = (q.var("a"), q.var("b"));
    let got = all_answers(&q, nextto(a, b, Term::list([1i64, 2, 3])));
    assert_eq!(got, ["1, 2", "2, 3"]);
}

/// An infinite relation: the naturals as Peano numerals.
fn nato(n: Term) -> Goal {
    conde([
        vec![eq(n.clone(), sym("z"))],
        vec![fresh(move |[m]| {
            conj([eq(n.clone(), Term::app("s", [m.clone()])), nato(m)])
        })],
    ])
}

/// A relation that recurses forever without an answer.
fn loopo() -> Goal {
    delay(loopo)
}

#[test]
fn infinite_relations_give_their_first_answers() {
    let mut q = Query::new();
    let n = q.var("n");
    let got = first_answers(&q, 3, nato(n));
    assert_eq!(got, ["z", "s(z)", "s(s(z))"]);
}

#[test]
fn conde_is_fair_to_a_finite_branch_beside_an_infinite_one() {
    for infinite_first in [true, false] {
        let mut q = Query::new();
        let x = q.var("x");
        let finite = membero(x.clone(), Term::list([1i64, 2, 3]));
        let branches = if infinite_first {
            vec![loopo(), finite]
        } else {
            vec![finite, loopo()]
        };
        let got = first_answers(&q, 3, disj(branches));
        assert_eq!(sorted(got), ["1", "2", "3"]);
    }
    // Left recursion beside its base case still produces answers.
    fn lefto(x: Term) -> Goal {
        disj([
            conj([delay({
                let x = x.clone();
                move || lefto(x.clone())
            })]),
            eq(x, 7),
        ])
    }
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(first_answers(&q, 2, lefto(x)), ["7", "7"]);
}

#[test]
fn conda_condu_onceo_commit() {
    let mut q = Query::new();
    let x = q.var("x");
    let l = Term::list([1i64, 2, 3]);
    // conda keeps every answer of the first head that succeeds.
    let g = conda([vec![membero(x.clone(), l.clone())], vec![eq(x.clone(), 9)]]);
    assert_eq!(all_answers(&q, g), ["1", "2", "3"]);
    // … and falls through to the next clause only when the head fails.
    let g = conda([vec![membero(x.clone(), Term::Nil)], vec![eq(x.clone(), 9)]]);
    assert_eq!(all_answers(&q, g), ["9"]);
    // condu keeps only the head's first answer.
    let g = condu([
        vec![membero(x.clone(), l.clone()), succeed()],
        vec![eq(x.clone(), 9)],
    ]);
    assert_eq!(all_answers(&q, g), ["1"]);
    assert_eq!(all_answers(&q, onceo(membero(x.clone(), l))), ["1"]);
    // onceo of an infinite relation still terminates.
    assert_eq!(all_answers(&q, onceo(nato(x.clone()))), ["z"]);
    // The committed clause's body runs on each head answer.
    let g = conda([
        vec![membero(x.clone(), Term::list([1i64, 2])), neq(x.clone(), 1)],
        vec![succeed()],
    ]);
    assert_eq!(all_answers(&q, g), ["2"]);
}

#[test]
fn project_calls_host_code_on_ground_values() {
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let double = project(vec![x.clone()], {
        let y = y.clone();
        move |v| match v[0].as_int() {
            Some(i) => eq(y.clone(), i * 2),
            None => fail(),
        }
    });
    let g = conj([membero(x, Term::list([1i64, 5])), double]);
    assert_eq!(all_answers(&q, g), ["1, 2", "5, 10"]);

    let mut q = Query::new();
    let x = q.var("x");
    let g = project_result(vec![x], |_| Err("no database".to_owned()));
    let got: Vec<_> = q.run(g, RunConfig::default()).collect();
    assert_eq!(got, vec![Err(RunError::Host("no database".to_owned()))]);
}

#[test]
fn occurs_check_is_switchable() {
    // x = [1 | x] has no finite solution: the occurs check rejects it.
    let cyclic = fresh(|[x]| eq(x.clone(), Term::list_with_tail([1i64], x)));
    let mut q = Query::new();
    assert!(all_answers(&q, cyclic.clone()).is_empty());
    // Off (Prolog's default), the binding is made. No query variable is
    // reified, so the cyclic term is never printed.
    q.set_occurs_check(false);
    assert_eq!(all_answers(&q, cyclic), [""]);
}

#[test]
fn list_walking_builtins_match_the_relational_definitions() {
    use kanren::classic::{membero_rel, nextto_rel, zebrao_rel};
    // Closed lists, partially instantiated lists and open tails, in order.
    let lists: Vec<Box<dyn Fn(Term) -> Term>> = vec![
        Box::new(|_| Term::list([1i64, 2, 1])),
        Box::new(|v| Term::list_with_tail([Term::Int(1), v.clone()], Term::list([v]))),
        Box::new(|v| Term::list_with_tail([Term::Int(3)], v)),
        Box::new(|_| Term::Nil),
        Box::new(|_| sym("not_a_list")),
    ];
    for make in &lists {
        let mut q = Query::new();
        let (x, y, v) = (q.var("x"), q.var("y"), q.var("v"));
        let l = make(v);
        assert_eq!(
            first_answers(&q, 6, membero(x.clone(), l.clone())),
            first_answers(&q, 6, membero_rel(x.clone(), l.clone())),
            "membero over {l}"
        );
        assert_eq!(
            first_answers(&q, 6, nextto(x.clone(), y.clone(), l.clone())),
            first_answers(&q, 6, nextto_rel(x, y, l.clone())),
            "nextto over {l}"
        );
    }
    let mut q = Query::new();
    let hs = q.var("hs");
    assert_eq!(
        all_answers(&q, zebrao(hs.clone())),
        all_answers(&q, zebrao_rel(hs))
    );
}

#[test]
fn long_lists_do_not_exhaust_the_stack() {
    // Unification, the occurs check, walk* and reification all loop along
    // list spines instead of recursing.
    const N: i64 = 20_000;
    let mut q = Query::new();
    let (x, tail) = (q.var("x"), q.var("tail"));
    let long = Term::list((0..N).map(Term::Int));
    let open = Term::list_with_tail((0..N - 1).map(Term::Int), tail.clone());
    let got = answers(&q, conj([eq(x.clone(), open), eq(x.clone(), long.clone())]));
    assert_eq!(got.len(), 1);
    assert_eq!(got[0].values[0], long);
    assert_eq!(got[0].values[1], Term::list([N - 1]));
    // Built cell by cell through variables, as a relation would: the prefix
    // `x` of the last answer is a chain of bound variables. (Shorter: with the
    // occurs check on, appendo against a ground list is quadratic.)
    let long = Term::list((0..3000).map(Term::Int));
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let cfg = RunConfig {
        limit: Some(1),
        ..RunConfig::default()
    };
    let g = conj([
        appendo(x.clone(), y.clone(), long.clone()),
        eq(y, Term::Nil),
    ]);
    let last: Vec<Answer> = q.run(g, cfg).filter_map(Result::ok).collect();
    assert_eq!(last.len(), 1);
    assert_eq!(last[0].values[0], long);
}
