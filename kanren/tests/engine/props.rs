//! Property tests: unification laws, and the engine against brute force.

use kanren::*;
use proptest::prelude::*;
use std::collections::BTreeSet;

// ---------------------------------------------------------------- terms

/// Terms over variables 0..3, atoms a/b/1 and functors f/1, g/2, lists.
fn term() -> impl Strategy<Value = Term> {
    let leaf = prop_oneof![
        (0u32..3).prop_map(|i| Term::Var(Var::from_index(i))),
        Just(sym("a")),
        Just(sym("b")),
        Just(Term::Int(1)),
        Just(Term::Nil),
    ];
    leaf.prop_recursive(3, 12, 2, |inner| {
        prop_oneof![
            inner.clone().prop_map(|t| Term::app("f", [t])),
            (inner.clone(), inner.clone()).prop_map(|(a, b)| Term::app("g", [a, b])),
            (inner.clone(), inner).prop_map(|(a, b)| Term::cons(a, b)),
        ]
    })
}

/// A small universe of ground values for the three variables.
fn universe() -> Vec<Term> {
    let atoms = [sym("a"), sym("b"), Term::Int(1), Term::Nil];
    let mut u: Vec<Term> = atoms.to_vec();
    for x in &atoms {
        u.push(Term::app("f", [x.clone()]));
        u.push(Term::cons(x.clone(), Term::Nil));
    }
    u
}

fn subst_apply(t: &Term, sigma: &[Term]) -> Term {
    match t {
        Term::Var(v) => sigma
            .get(v.index() as usize)
            .cloned()
            .unwrap_or_else(|| t.clone()),
        Term::Cons(..) => match t.uncons() {
            Some((h, tl)) => Term::cons(subst_apply(h, sigma), subst_apply(&tl, sigma)),
            None => t.clone(),
        },
        Term::App(f, args) => Term::app(*f, args.iter().map(|a| subst_apply(a, sigma))),
        other => other.clone(),
    }
}

fn vars3() -> [Term; 3] {
    [0, 1, 2].map(|i| Term::Var(Var::from_index(i)))
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    #[test]
    fn unification_is_symmetric(a in term(), b in term()) {
        let s = Subst::new();
        let ab = unify(&s, &a, &b, true);
        let ba = unify(&s, &b, &a, true);
        prop_assert_eq!(ab.is_some(), ba.is_some());
        if let (Some(ab), Some(ba)) = (ab, ba) {
            // Same unifier up to variable renaming direction: both make a = b,
            // and each is an instance of the other (checked through the terms).
            prop_assert_eq!(ab.walk_star(&a), ab.walk_star(&b));
            prop_assert_eq!(ba.walk_star(&a), ba.walk_star(&b));
            for v in vars3() {
                let x = ab.walk_star(&v);
                let y = ba.walk_star(&v);
                prop_assert!(unify(&ab, &y, &x, true).map(|s| s.len()) == Some(ab.len()),
                    "{} vs {}", x, y);
            }
        }
    }

    #[test]
    fn unification_is_idempotent(a in term(), b in term()) {
        if let Some(s) = unify(&Subst::new(), &a, &b, true) {
            let again = unify(&s, &a, &b, true);
            prop_assert_eq!(again.as_ref().map(Subst::len), Some(s.len()));
            prop_assert_eq!(s.walk_star(&a), s.walk_star(&b));
            // Walking is idempotent too: the result has no bound variable left.
            let w = s.walk_star(&a);
            prop_assert_eq!(s.walk_star(&w), w);
        }
    }

    #[test]
    fn unification_gives_a_most_general_unifier(a in term(), b in term()) {
        let mgu = unify(&Subst::new(), &a, &b, true);
        let u = universe();
        for x in &u { for y in &u { for z in &u {
            let sigma = [x.clone(), y.clone(), z.clone()];
            if subst_apply(&a, &sigma) == subst_apply(&b, &sigma) {
                // Every unifier is an instance of the mgu: sigma ∘ mgu = sigma.
                let Some(m) = &mgu else {
                    return Err(TestCaseError::fail(format!("{a} and {b} unify under {sigma:?}, but unify failed")));
                };
                for v in vars3() {
                    prop_assert_eq!(subst_apply(&m.walk_star(&v), &sigma), subst_apply(&v, &sigma));
                }
            }
        }}}
    }
}

// ------------------------------------------------ engine vs brute force

/// A primitive constraint over variables x0..x2 and the domain below.
#[derive(Clone, Debug)]
enum Prim {
    Eq(usize, Dom),
    EqVar(usize, usize),
    Neq(usize, Dom),
    NeqVar(usize, usize),
    NeqPair(usize, usize, Dom, Dom),
    Sym(usize),
    Num(usize),
    Absent(usize),
}

#[derive(Clone, Copy, Debug, PartialEq)]
enum Dom {
    A,
    B,
    One,
    Two,
    FA,
}

const DOMAIN: [Dom; 5] = [Dom::A, Dom::B, Dom::One, Dom::Two, Dom::FA];

impl Dom {
    fn term(self) -> Term {
        match self {
            Dom::A => sym("a"),
            Dom::B => sym("b"),
            Dom::One => Term::Int(1),
            Dom::Two => Term::Int(2),
            Dom::FA => Term::app("f", [sym("a")]),
        }
    }
}

fn dom() -> impl Strategy<Value = Dom> {
    prop::sample::select(DOMAIN.to_vec())
}

fn prim() -> impl Strategy<Value = Prim> {
    prop_oneof![
        (0usize..3, dom()).prop_map(|(i, d)| Prim::Eq(i, d)),
        (0usize..3, 0usize..3).prop_map(|(i, j)| Prim::EqVar(i, j)),
        (0usize..3, dom()).prop_map(|(i, d)| Prim::Neq(i, d)),
        (0usize..3, 0usize..3).prop_map(|(i, j)| Prim::NeqVar(i, j)),
        (0usize..3, 0usize..3, dom(), dom()).prop_map(|(i, j, d, e)| Prim::NeqPair(i, j, d, e)),
        (0usize..3).prop_map(Prim::Sym),
        (0usize..3).prop_map(Prim::Num),
        (0usize..3).prop_map(Prim::Absent),
    ]
}

impl Prim {
    fn goal(&self, v: &[Term; 3]) -> Goal {
        match *self {
            Prim::Eq(i, d) => eq(v[i].clone(), d.term()),
            Prim::EqVar(i, j) => eq(v[i].clone(), v[j].clone()),
            Prim::Neq(i, d) => neq(v[i].clone(), d.term()),
            Prim::NeqVar(i, j) => neq(v[i].clone(), v[j].clone()),
            Prim::NeqPair(i, j, d, e) => neq(
                Term::list([v[i].clone(), v[j].clone()]),
                Term::list([d.term(), e.term()]),
            ),
            Prim::Sym(i) => symbolo(v[i].clone()),
            Prim::Num(i) => numbero(v[i].clone()),
            Prim::Absent(i) => absento("a", v[i].clone()),
        }
    }

    /// The constraint's truth for ground values.
    fn holds(&self, g: &[Dom; 3]) -> bool {
        match *self {
            Prim::Eq(i, d) => g[i] == d,
            Prim::EqVar(i, j) => g[i] == g[j],
            Prim::Neq(i, d) => g[i] != d,
            Prim::NeqVar(i, j) => g[i] != g[j],
            Prim::NeqPair(i, j, d, e) => !(g[i] == d && g[j] == e),
            Prim::Sym(i) => matches!(g[i], Dom::A | Dom::B),
            Prim::Num(i) => matches!(g[i], Dom::One | Dom::Two),
            Prim::Absent(i) => !matches!(g[i], Dom::A | Dom::FA),
        }
    }
}

fn domain_list() -> Term {
    Term::list(DOMAIN.map(Dom::term))
}

/// Runs the constraints first (so they sit in the store), then grounds the
/// variables by enumerating the domain: every later binding re-checks them.
fn engine_answers(prims: &[Prim], ground_first: bool) -> BTreeSet<String> {
    let mut q = Query::new();
    let v = [q.var("x0"), q.var("x1"), q.var("x2")];
    let cs: Vec<Goal> = prims.iter().map(|p| p.goal(&v)).collect();
    let enumerate: Vec<Goal> = v
        .iter()
        .map(|x| kanren::classic::membero(x.clone(), domain_list()))
        .collect();
    let goals: Vec<Goal> = if ground_first {
        enumerate.into_iter().chain(cs).collect()
    } else {
        cs.into_iter().chain(enumerate).collect()
    };
    q.run(conj(goals), RunConfig::default())
        .map(|a| match a {
            Ok(a) => {
                assert!(
                    a.constraints.is_empty(),
                    "ground answers carry no constraint: {a}"
                );
                a.to_string()
            }
            Err(e) => panic!("run error: {e}"),
        })
        .collect()
}

fn brute_force(prims: &[Prim]) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    for a in DOMAIN {
        for b in DOMAIN {
            for c in DOMAIN {
                let g = [a, b, c];
                if prims.iter().all(|p| p.holds(&g)) {
                    out.insert(format!("{}, {}, {}", a.term(), b.term(), c.term()));
                }
            }
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 120, ..ProptestConfig::default() })]

    #[test]
    fn run_all_equals_brute_force(prims in prop::collection::vec(prim(), 0..5)) {
        let want = brute_force(&prims);
        prop_assert_eq!(engine_answers(&prims, false), want.clone());
        prop_assert_eq!(engine_answers(&prims, true), want);
    }

    #[test]
    fn answers_do_not_depend_on_conjunct_order(
        prims in prop::collection::vec(prim(), 1..5),
        seed in any::<u64>(),
    ) {
        let mut shuffled = prims.clone();
        // Deterministic Fisher–Yates from the seed.
        let mut s = seed | 1;
        for i in (1..shuffled.len()).rev() {
            s ^= s << 13; s ^= s >> 7; s ^= s << 17;
            shuffled.swap(i, (s % (i as u64 + 1)) as usize);
        }
        prop_assert_eq!(engine_answers(&prims, false), engine_answers(&shuffled, false));
    }

    #[test]
    fn every_answer_satisfies_its_constraints_when_substituted_back(
        prims in prop::collection::vec(prim(), 0..5),
    ) {
        // Partial answers (no enumeration): ground every remaining variable
        // in every way allowed by the residual constraints' own goal; each
        // resulting grounding must satisfy the original constraints.
        let mut q = Query::new();
        let v = [q.var("x0"), q.var("x1"), q.var("x2")];
        let goal = conj(prims.iter().map(|p| p.goal(&v)));
        for answer in q.run(goal.clone(), RunConfig::default()) {
            let answer = answer.map_err(|e| TestCaseError::fail(e.to_string()))?;
            // Substitute the answer back: the goal must accept it.
            let mut q2 = Query::new();
            let w = [q2.var("y0"), q2.var("y1"), q2.var("y2")];
            let back = conj(
                w.iter()
                    .zip(&answer.values)
                    .map(|(y, val)| eq(y.clone(), shift(val)))
                    .chain(prims.iter().map(|p| p.goal(&w))),
            );
            let n = q2.run(back, RunConfig::default()).filter(|r| r.is_ok()).count();
            prop_assert!(n >= 1, "answer {} does not satisfy {:?}", answer, prims);
        }
    }

    #[test]
    fn conde_is_fair(k in 1usize..6, depth in 0usize..3) {
        // A finite branch of k answers beside a branch that never answers:
        // run k must give all k answers.
        fn never(d: usize) -> Goal {
            if d == 0 { delay(|| never(0)) } else { disj([never(d - 1), never(d - 1)]) }
        }
        let mut q = Query::new();
        let x = q.var("x");
        let finite = kanren::classic::membero(x, Term::list((0..k as i64).map(Term::Int)));
        let cfg = RunConfig { limit: Some(k), budget: Budget { max_steps: Some(200_000), max_time: None }, ..RunConfig::default() };
        let got: BTreeSet<String> = q.run(disj([never(depth), finite]), cfg)
            .filter_map(Result::ok).map(|a| a.to_string()).collect();
        prop_assert_eq!(got.len(), k);
    }
}

/// Reified variables `_i` of an answer are renamed far away from the new
/// query's own variables, so substituting back cannot capture them.
fn shift(t: &Term) -> Term {
    match t {
        Term::Var(v) => Term::Var(Var::from_index(v.index() + 1000)),
        Term::Cons(..) => match t.uncons() {
            Some((h, tl)) => Term::cons(shift(h), shift(&tl)),
            None => t.clone(),
        },
        Term::App(f, args) => Term::app(*f, args.iter().map(shift)),
        other => other.clone(),
    }
}

// ------------------------------------------- fact joins vs nested loops

fn small_relation(name: &str, tuples: &[(u8, u8)]) -> std::sync::Arc<Relation> {
    let mut r = Relation::new(name, 2);
    for (a, b) in tuples {
        r.insert(&[Term::Int(i64::from(*a)), Term::Int(i64::from(*b))])
            .unwrap_or_else(|e| panic!("{e}"));
    }
    std::sync::Arc::new(r)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 150, ..ProptestConfig::default() })]

    /// q(x, z) :- p(x, y), r(y, z), x ≠ z, with an optional constant — the
    /// shape of logicrag's conjunctive queries — against nested loops.
    #[test]
    fn fact_joins_equal_nested_loops(
        p in prop::collection::vec((0u8..5, 0u8..5), 0..14),
        r in prop::collection::vec((0u8..5, 0u8..5), 0..14),
        fixed_x in prop::option::of(0u8..5),
        with_proofs in any::<bool>(),
    ) {
        let (pr, rr) = (small_relation("p", &p), small_relation("r", &r));
        let mut q = Query::new();
        let (x, z) = (q.var("x"), q.var("z"));
        let xt = fixed_x.map_or(x.clone(), |v| Term::Int(i64::from(v)));
        let goal = fresh({
            let (pr, rr, x, z, xt) = (pr.clone(), rr.clone(), x.clone(), z.clone(), xt.clone());
            move |[y]| conj([
                eq(x.clone(), xt.clone()),
                fact(&pr, vec![x.clone(), y.clone()]),
                fact(&rr, vec![y, z.clone()]),
                neq(x.clone(), z.clone()),
            ])
        });
        let cfg = RunConfig { proofs: with_proofs, ..RunConfig::default() };
        let mut got: Vec<(i64, i64)> = Vec::new();
        for a in q.run(goal, cfg) {
            let a = a.map_err(|e| TestCaseError::fail(e.to_string()))?;
            let (Some(xv), Some(zv)) = (a.values[0].as_int(), a.values[1].as_int()) else {
                return Err(TestCaseError::fail(format!("non-ground answer {a}")));
            };
            if with_proofs {
                // Each answer's proof names one p fact and one r fact that hold.
                let steps = a.proof.as_ref().map(|p| p.steps.len()).unwrap_or(0);
                prop_assert_eq!(steps, 2);
            }
            got.push((xv, zv));
        }
        got.sort();
        got.dedup();
        let mut want: Vec<(i64, i64)> = Vec::new();
        for (a, b) in pr.iter().map(|(_, t)| (t.get(0).and_then(Term::as_int), t.get(1).and_then(Term::as_int))) {
            for (c, d) in rr.iter().map(|(_, t)| (t.get(0).and_then(Term::as_int), t.get(1).and_then(Term::as_int))) {
                if b == c
                    && a != d
                    && fixed_x.is_none_or(|v| a == Some(i64::from(v)))
                    && let (Some(a), Some(d)) = (a, d)
                {
                    want.push((a, d));
                }
            }
        }
        want.sort();
        want.dedup();
        prop_assert_eq!(got, want);
    }
}

// ---------------------------------------------------------------- list scans

/// House-like items for list scans: mostly `h(_, _)` over two atoms and
/// three variables (so candidates often share a functor and clash, or not,
/// on an atom), sometimes `k(_)` or a bare argument.
fn scan_item() -> impl Strategy<Value = Term> {
    let arg = prop_oneof![
        Just(sym("a")),
        Just(sym("b")),
        (0u32..3).prop_map(|i| Term::Var(Var::from_index(i))),
    ];
    prop_oneof![
        4 => (arg.clone(), arg.clone()).prop_map(|(p, q)| Term::app("h", [p, q])),
        1 => arg.clone().prop_map(|p| Term::app("k", [p])),
        1 => arg,
    ]
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 200, ..ProptestConfig::default() })]

    /// The list-walking `membero` and `nextto` — which skip candidates whose
    /// atoms clash with the pattern's before unifying — give the answers of
    /// the relational definitions, in the same order, for any patterns over
    /// lists of arbitrary terms, closed or ending in an unbound variable.
    #[test]
    fn list_scans_match_the_relational_definitions(
        x in prop_oneof![scan_item(), term()],
        y in prop_oneof![scan_item(), term()],
        items in prop::collection::vec(prop_oneof![3 => scan_item(), 1 => term()], 0..6),
        open in any::<bool>(),
    ) {
        let mut q = Query::new();
        // Variables 0..3 of the terms are query variables; 3 is the tail.
        let [_, _, _, tail] = q.vars::<4>("v");
        let l = Term::list_with_tail(items, if open { tail } else { Term::Nil });
        let run = |g: Goal| -> Vec<String> {
            let cfg = RunConfig {
                limit: Some(12),
                budget: Budget { max_steps: Some(100_000), ..Budget::default() },
                ..RunConfig::default()
            };
            q.run(g, cfg).filter_map(Result::ok).map(|a| a.to_string()).collect()
        };
        let same = |a: Vec<String>, b: Vec<String>| -> Result<(), TestCaseError> {
            if open {
                // Infinitely many answers: compare what both produced.
                let n = a.len().min(b.len());
                prop_assert_eq!(&a[..n], &b[..n]);
            } else {
                prop_assert_eq!(a, b);
            }
            Ok(())
        };
        same(
            run(classic::membero(x.clone(), l.clone())),
            run(classic::membero_rel(x.clone(), l.clone())),
        )?;
        same(
            run(classic::nextto(x.clone(), y.clone(), l.clone())),
            run(classic::nextto_rel(x, y, l)),
        )?;
    }
}
