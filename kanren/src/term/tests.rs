use super::*;

/// Each thread's copy of the names agrees with the interner: a name
/// interned on one thread has the same symbol on every other, whether
/// that thread has seen it before or not, and `lookup` of a name never
/// interned stays `None` after the copy holds others.
#[test]
fn every_thread_sees_one_symbol_per_name() {
    let here = Sym::new("local_names_test_a");
    assert_eq!(Sym::new("local_names_test_a"), here);
    assert_eq!(Sym::lookup("local_names_test_a"), Some(here));
    let there = std::thread::spawn(|| {
        let seen = Sym::lookup("local_names_test_a");
        let again = Sym::new("local_names_test_a");
        let fresh = Sym::new("local_names_test_b");
        (seen, again, fresh, Sym::lookup("local_names_test_never"))
    })
    .join()
    .expect("thread");
    assert_eq!(there.0, Some(here));
    assert_eq!(there.1, here);
    assert_eq!(Sym::lookup("local_names_test_b"), Some(there.2));
    assert_eq!(there.2.as_str(), "local_names_test_b");
    assert_eq!(there.3, None);
    assert_eq!(Sym::lookup("local_names_test_never"), None);
}

#[test]
fn name_slots_tile_the_ids_without_gaps() {
    let mut expected = (0usize, 0usize);
    for id in 0..NAMES_BASE * 40 {
        let (chunk, slot) = name_slot(id);
        if (chunk, slot) != expected {
            assert_eq!((chunk, slot), (expected.0 + 1, 0), "id {id}");
        }
        assert!(slot < NAMES_BASE << chunk, "id {id}");
        expected = (chunk, slot + 1);
    }
    let (last, _) = name_slot(u32::MAX as usize);
    assert!(last < NAMES_CHUNKS);
}

#[test]
fn symbols_read_back_across_threads() {
    let handles: Vec<_> = (0..4)
        .map(|t| {
            std::thread::spawn(move || {
                (0..3000)
                    .map(|i| {
                        let name = format!("interner-test-{t}-{i}");
                        let s = Sym::new(&name);
                        assert_eq!(s.as_str(), name);
                        s
                    })
                    .collect::<Vec<_>>()
            })
        })
        .collect();
    for (t, h) in handles.into_iter().enumerate() {
        for (i, s) in h.join().expect("thread").into_iter().enumerate() {
            assert_eq!(s.as_str(), format!("interner-test-{t}-{i}"));
            assert_eq!(Sym::new(&format!("interner-test-{t}-{i}")), s);
        }
    }
}

#[test]
fn interning_is_stable_and_shared_across_threads() {
    let a = Sym::new("kanren_test_sym");
    let b = std::thread::spawn(|| Sym::new("kanren_test_sym"))
        .join()
        .map_err(|_| "thread panicked");
    assert_eq!(Ok(a), b);
    assert_eq!(a.as_str(), "kanren_test_sym");
    assert_ne!(Sym::new("x1"), Sym::new("x2"));
}

#[test]
fn display_is_prolog_like() {
    let t = Term::list_with_tail([sym("a"), Term::Int(2)], Term::Var(Var(3)));
    assert_eq!(t.to_string(), "[a, 2 | _3]");
    let h = Term::app("h", [sym("red"), Term::str("x y"), Term::Nil]);
    assert_eq!(h.to_string(), "h(red, \"x y\", [])");
    assert_eq!(sym("Hello World").to_string(), "'Hello World'");
    assert_eq!(Term::app("f", []), sym("f"));
}

/// A `Term` is a tag and a `u32` next to a two-word payload; lists and
/// terms are copied in the engine's tightest loops, so this is measured.
#[cfg(target_pointer_width = "64")]
#[test]
fn term_is_three_words() {
    assert_eq!(std::mem::size_of::<Term>(), 24);
}

#[test]
fn groundness() {
    assert!(Term::list([1i64, 2]).is_ground());
    assert!(!Term::cons(1i64, Var(0)).is_ground());
    assert_eq!(
        Term::list([1i64, 2]).to_vec(),
        Some(vec![Term::Int(1), Term::Int(2)])
    );
}

// Moved here verbatim from its own `mod packed_tests` beside `mod tests`.
mod packed_tests {
    use super::*;
    use proptest::prelude::*;
    use std::collections::hash_map::DefaultHasher;
    use std::hash::{Hash, Hasher};

    /// The same cells, split into blocks at the given points.
    fn split(items: &[Term], tail: Term, cuts: &[usize]) -> Term {
        let mut bounds: Vec<usize> = cuts.iter().map(|c| c % (items.len() + 1)).collect();
        bounds.push(items.len());
        bounds.sort_unstable();
        bounds.dedup();
        let mut acc = tail;
        let mut end = items.len();
        for &b in bounds.iter().rev().chain(std::iter::once(&0)) {
            if b < end {
                acc = Term::list_with_tail(items[b..end].iter().cloned(), acc);
                end = b;
            }
        }
        acc
    }

    /// The textbook order: cell by cell, as derived on `Cons(head, tail)`.
    fn reference_cmp(a: &[Term], at: &Term, b: &[Term], bt: &Term) -> std::cmp::Ordering {
        match (a.split_first(), b.split_first()) {
            (Some((x, xs)), Some((y, ys))) => x.cmp(y).then_with(|| reference_cmp(xs, at, ys, bt)),
            (None, None) => at.cmp(bt),
            (None, Some(_)) => at.rank().cmp(&CONS_RANK),
            (Some(_), None) => CONS_RANK.cmp(&bt.rank()),
        }
    }

    fn hash(t: &Term) -> u64 {
        let mut h = DefaultHasher::new();
        t.hash(&mut h);
        h.finish()
    }

    fn atom() -> impl Strategy<Value = Term> {
        prop_oneof![
            (0i64..3).prop_map(Term::Int),
            (0u32..2).prop_map(|i| Term::Var(Var(i))),
            Just(Term::Nil),
            Just(Term::app("f", [Term::Int(1)])),
        ]
    }

    proptest! {
        #[test]
        fn block_splits_are_invisible(
            a in prop::collection::vec(atom(), 0..5),
            b in prop::collection::vec(atom(), 0..5),
            at in atom(),
            bt in atom(),
            cuts1 in prop::collection::vec(0usize..6, 0..3),
            cuts2 in prop::collection::vec(0usize..6, 0..3),
        ) {
            let x1 = split(&a, at.clone(), &cuts1);
            let x2 = split(&a, at.clone(), &cuts2);
            prop_assert_eq!(&x1, &x2);
            prop_assert_eq!(hash(&x1), hash(&x2));
            prop_assert_eq!(x1.to_string(), x2.to_string());
            let y = split(&b, bt.clone(), &cuts2);
            prop_assert_eq!(x1.cmp(&y), reference_cmp(&a, &at, &b, &bt));
            prop_assert_eq!(x1 == y, reference_cmp(&a, &at, &b, &bt).is_eq());
            let mut cells = Vec::new();
            let mut cur = x1.clone();
            while let Some((h, t)) = cur.uncons() {
                cells.push(h.clone());
                cur = t;
            }
            prop_assert_eq!(cells, a);
            prop_assert_eq!(cur, at);
        }
    }

    #[test]
    fn packed_list_shapes() {
        let l = Term::list([1i64, 2, 3]);
        assert_eq!(
            l,
            Term::cons(1i64, Term::cons(2i64, Term::cons(3i64, Term::Nil)))
        );
        let (_, t) = l.uncons().unwrap_or((&Term::Nil, Term::Nil));
        assert_eq!(t, Term::list([2i64, 3]));
        assert_eq!(
            Term::list_with_tail(Vec::<Term>::new(), Term::Int(7)),
            Term::Int(7)
        );
        // A list ending in an App sorts after one that continues (App > Cons).
        let a = Term::list_with_tail([Term::Int(1)], Term::app("f", [Term::Int(0)]));
        let b = Term::list([1i64, 2]);
        assert!(a > b);
    }
}
