//! Disequality, type and absento constraints (cases from the miniKanren
//! literature: The Reasoned Schemer and faster-miniKanren's test suite).

use super::all_answers;
use kanren::*;

#[test]
fn neq_residual_and_later_binding() {
    let mut q = Query::new();
    let x = q.var("q");
    assert_eq!(all_answers(&q, neq(x.clone(), 5)), ["_0 where _0 =/= 5"]);
    assert!(all_answers(&q, conj([neq(x.clone(), 5), eq(x.clone(), 5)])).is_empty());
    assert!(all_answers(&q, conj([eq(x.clone(), 5), neq(x.clone(), 5)])).is_empty());
    assert_eq!(
        all_answers(&q, conj([neq(x.clone(), 5), eq(x.clone(), 6)])),
        ["6"]
    );
}

#[test]
fn neq_between_variables() {
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    assert!(
        all_answers(
            &q,
            conj([neq(x.clone(), y.clone()), eq(x.clone(), y.clone())])
        )
        .is_empty()
    );
    assert!(
        all_answers(
            &q,
            conj([
                neq(x.clone(), y.clone()),
                eq(x.clone(), 1),
                eq(y.clone(), 1)
            ])
        )
        .is_empty()
    );
    assert_eq!(
        all_answers(
            &q,
            conj([
                neq(x.clone(), y.clone()),
                eq(x.clone(), 1),
                eq(y.clone(), 2)
            ])
        ),
        ["1, 2"]
    );
    assert_eq!(
        all_answers(&q, neq(x.clone(), y.clone())),
        ["_0, _1 where _0 =/= _1"]
    );
    // Equality through a third variable, bound in the "wrong" direction.
    let g = fresh({
        let (x, y) = (x.clone(), y.clone());
        move |[z]| {
            conj([
                neq(x.clone(), y.clone()),
                eq(y.clone(), z.clone()),
                eq(z, x.clone()),
            ])
        }
    });
    assert!(all_answers(&q, g).is_empty());
}

#[test]
fn neq_on_compound_terms() {
    // (run* q (fresh (x y) (== q `(,x ,y)) (=/= `(,x ,y) '(5 6))))
    let mut q = Query::new();
    let p = q.var("q");
    let g = fresh({
        let p = p.clone();
        move |[x, y]| {
            conj([
                eq(p.clone(), Term::list([x.clone(), y.clone()])),
                neq(Term::list([x, y]), Term::list([5i64, 6])),
            ])
        }
    });
    assert_eq!(
        all_answers(&q, g.clone()),
        ["[_0, _1] where (_0, _1) =/= (5, 6)"]
    );
    // Binding one half leaves the other half's disequality.
    let first5 = fresh({
        let p = p.clone();
        move |[y]| eq(p.clone(), Term::list([Term::Int(5), y]))
    });
    assert_eq!(
        all_answers(&q, conj([g.clone(), first5.clone()])),
        ["[5, _0] where _0 =/= 6"]
    );
    let both = eq(p.clone(), Term::list([5i64, 6]));
    assert!(all_answers(&q, conj([g.clone(), both])).is_empty());
    let other = eq(p.clone(), Term::list([5i64, 7]));
    assert_eq!(all_answers(&q, conj([g, other])), ["[5, 7]"]);
}

#[test]
fn neq_that_cannot_fail_leaves_no_constraint() {
    let mut q = Query::new();
    let x = q.var("x");
    let g = neq(Term::list([x.clone(), 1i64.into()]), Term::list([2i64, 3]));
    assert_eq!(all_answers(&q, g), ["_0"]);
}

#[test]
fn type_constraints() {
    let mut q = Query::new();
    let x = q.var("x");
    assert_eq!(
        all_answers(&q, symbolo(x.clone())),
        ["_0 where symbolo(_0)"]
    );
    assert_eq!(
        all_answers(&q, numbero(x.clone())),
        ["_0 where numbero(_0)"]
    );
    assert!(all_answers(&q, conj([symbolo(x.clone()), numbero(x.clone())])).is_empty());
    assert_eq!(
        all_answers(&q, conj([symbolo(x.clone()), eq(x.clone(), "a")])),
        ["a"]
    );
    assert!(all_answers(&q, conj([symbolo(x.clone()), eq(x.clone(), 5)])).is_empty());
    assert!(
        all_answers(
            &q,
            conj([numbero(x.clone()), eq(x.clone(), Term::list([1i64]))])
        )
        .is_empty()
    );
    assert_eq!(
        all_answers(
            &q,
            conj([stringo(x.clone()), eq(x.clone(), Term::str("s"))])
        ),
        ["\"s\""]
    );
    // The restriction follows a variable bound to another variable.
    let g = fresh({
        let x = x.clone();
        move |[y]| conj([symbolo(x.clone()), eq(x.clone(), y.clone()), eq(y, 3)])
    });
    assert!(all_answers(&q, g).is_empty());
    let mut q = Query::new();
    let (x, y) = (q.var("x"), q.var("y"));
    let g = conj([numbero(x.clone()), eq(x, y)]);
    assert_eq!(all_answers(&q, g), ["_0, _0 where numbero(_0)"]);
}

#[test]
fn absento_cases() {
    let mut q = Query::new();
    let x = q.var("q");
    // (absento 'closure q) (== q '(closure)) fails.
    let g = conj([
        absento("closure", x.clone()),
        eq(x.clone(), Term::list([sym("closure")])),
    ]);
    assert!(all_answers(&q, g).is_empty());
    assert_eq!(
        all_answers(&q, absento("a", x.clone())),
        ["_0 where absento(a, _0)"]
    );
    // Tags deep inside a later binding are found.
    let g = fresh({
        let x = x.clone();
        move |[y]| {
            conj([
                absento("a", x.clone()),
                eq(x.clone(), Term::app("f", [sym("b"), y.clone()])),
                eq(y, Term::list([sym("c"), sym("a")])),
            ])
        }
    });
    assert!(all_answers(&q, g).is_empty());
    let g = fresh({
        let x = x.clone();
        move |[y]| {
            conj([
                absento("a", x.clone()),
                eq(x.clone(), Term::cons(sym("b"), y)),
            ])
        }
    });
    assert_eq!(all_answers(&q, g), ["[b | _0] where absento(a, _0)"]);
    // A compound tag: the term may not *be* it, nor contain it.
    let tag = Term::app("f", [sym("a")]);
    let g = fresh({
        let (x, tag) = (x.clone(), tag.clone());
        move |[y]| {
            conj([
                absento(tag.clone(), x.clone()),
                eq(x.clone(), Term::app("f", [y.clone()])),
                eq(y, "a"),
            ])
        }
    });
    assert!(all_answers(&q, g).is_empty());
    let g = conj([
        absento(tag, x.clone()),
        eq(x.clone(), Term::app("f", [sym("b")])),
    ]);
    assert_eq!(all_answers(&q, g), ["f(b)"]);
}

#[test]
fn absento_with_unbound_tag_is_an_error() {
    let mut q = Query::new();
    let (x, t) = (q.var("x"), q.var("t"));
    let got: Vec<_> = q.run(absento(t, x), RunConfig::default()).collect();
    assert!(
        matches!(got.as_slice(), [Err(RunError::NonGroundAbsento { .. })]),
        "{got:?}"
    );
}
