//! Terms as code outside the crate sees them.

use kanren::*;

/// The parts of a list cell: its block and position.
fn parts(t: &Term) -> (kanren::term::ListBlock, kanren::term::ListPos) {
    match t {
        Term::Cons(block, pos) => (block.clone(), *pos),
        other => panic!("not a list cell: {other}"),
    }
}

/// Regression: `Term::Cons` used to take a bare `Arc<[Term]>` and a
/// position, so outside code could pair a position with an empty or short
/// block, and `unify` then panicked ("attempt to subtract with overflow").
/// Blocks now come only from the crate, and a position beyond its block
/// names the block's last cell: every pairing is a well-formed list.
#[test]
fn a_position_moved_to_another_block_still_names_a_cell() {
    let long = Term::list([1i64, 2, 3, 4, 5]);
    let mut suffix = long.clone();
    for _ in 0..4 {
        suffix = suffix.uncons().map(|(_, t)| t).unwrap_or(Term::Nil);
    }
    assert_eq!(suffix, Term::list([5i64]));
    let (_, far) = parts(&suffix); // position 4 of a five-cell block

    let short = Term::list([7i64, 8]);
    let one = Term::cons(9i64, Term::Nil);
    for (block_of, expected) in [
        (&short, Term::list([8i64])),
        (&one, Term::list([9i64])),
        (&long, Term::list([5i64])),
    ] {
        let (block, _) = parts(block_of);
        let moved = Term::Cons(block, far);
        assert_eq!(moved, expected);
        assert_eq!(moved.to_string(), expected.to_string());
        assert_eq!(moved.to_vec(), expected.to_vec());
        assert_eq!(moved.cmp(&expected), std::cmp::Ordering::Equal);
        let (head, tail) = moved.uncons().unwrap_or((&Term::Nil, Term::Int(0)));
        assert_eq!(
            (head, tail),
            expected.uncons().unwrap_or((&Term::Nil, Term::Nil))
        );
        assert!(unify(&Subst::new(), &moved, &expected, true).is_some());
        let open = Term::list_with_tail([Term::Var(Var::from_index(0))], Term::Nil);
        assert!(unify(&Subst::new(), &open, &moved, true).is_some());
        assert!(unify(&Subst::new(), &moved, &Term::list([0i64]), true).is_none());
        // The engine's list scan (membero) walks it like any other list.
        let mut q = Query::new();
        let x = q.var("x");
        let got = super::all_answers(&q, kanren::classic::membero(x, moved.clone()));
        assert_eq!(
            got,
            [expected
                .uncons()
                .map(|(h, _)| h.to_string())
                .unwrap_or_default()]
        );
    }
}
