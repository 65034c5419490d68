use super::index::ADJACENCY_WORK_PER_FACT;
use super::*;
use crate::term::sym;

#[test]
fn insert_dedup_lookup() -> Result<(), KanrenError> {
    let mut r = Relation::new("color", 2);
    assert_eq!(r.insert(&[sym("car1"), sym("white")])?, (0, true));
    assert_eq!(r.insert(&[sym("car2"), sym("red")])?, (1, true));
    assert_eq!(r.insert(&[sym("car3"), sym("white")])?, (2, true));
    assert_eq!(r.insert(&[sym("car1"), sym("white")])?, (0, false));
    assert_eq!(r.len(), 3);
    assert!(r.contains(&[sym("car2"), sym("red")]));
    assert!(!r.contains(&[sym("car2"), sym("white")]));
    assert_eq!(r.lookup(&[None, Some(&sym("white"))]), vec![0, 2]);
    assert_eq!(
        r.lookup(&[Some(&sym("car3")), Some(&sym("white"))]),
        vec![2]
    );
    assert_eq!(r.lookup(&[None, None]), vec![0, 1, 2]);
    assert_eq!(r.lookup(&[Some(&sym("nope")), None]), Vec::<FactId>::new());
    let all: Vec<_> = r.iter().map(|(i, t)| (i, t.to_vec())).collect();
    assert_eq!(all[1], (1, vec![sym("car2"), sym("red")]));
    Ok(())
}

#[test]
fn values_at_is_the_distinct_projection() -> Result<(), KanrenError> {
    let mut r = Relation::new("near", 2);
    for (a, b) in [("a", "b"), ("b", "a"), ("a", "c"), ("c", "c")] {
        r.insert(&[sym(a), sym(b)])?;
    }
    let at = |p: usize| -> Vec<Term> { r.values_at(p).cloned().collect() };
    assert_eq!(at(0), vec![sym("a"), sym("b"), sym("c")]);
    // Code order (first stored anywhere in the relation), each once.
    assert_eq!(at(1), vec![sym("a"), sym("b"), sym("c")]);
    assert!(at(2).is_empty());
    Ok(())
}

#[test]
fn rejects_bad_tuples() {
    let mut r = Relation::new("p", 2);
    assert!(matches!(
        r.insert(&[sym("a")]),
        Err(KanrenError::ArityMismatch { got: 1, .. })
    ));
    assert!(matches!(
        r.insert(&[sym("a"), Term::Var(crate::term::Var(0))]),
        Err(KanrenError::NonGroundFact { position: 1, .. })
    ));
    assert!(matches!(
        r.insert(&[sym("a"), Term::list([1i64])]),
        Err(KanrenError::NonGroundFact { position: 1, .. })
    ));
    assert!(r.is_empty());
}

/// The pair index, once built, answers fully bound probes exactly as
/// the dedup table does (hits, misses, unknown values), and an insert
/// clears it so a new fact is found.
#[test]
fn pair_index_agrees_with_the_dedup_table() -> Result<(), KanrenError> {
    let n = 200i64;
    let mut r = Relation::new("edge", 2);
    for a in 0..n {
        for b in 0..n {
            if (a * 7 + b * 3) % 5 != 0 {
                r.insert(&[Term::Int(a), Term::Int(b)])?;
            }
        }
    }
    assert!(r.len() >= PAIR_INDEX_MIN_FACTS);
    let ask = |r: &Relation, a: i64, b: i64| -> Vec<FactId> {
        let (ta, tb) = (Term::Int(a), Term::Int(b));
        match r.probe(&[Some(&ta), Some(&tb)]) {
            Probe::Ids(ids) => ids.to_vec(),
            Probe::Range(lo, hi) => (lo..hi).collect(),
        }
    };
    let mut before = Vec::new();
    for a in 0..n + 1 {
        for b in 0..n + 1 {
            before.push(ask(&r, a, b));
        }
    }
    assert!(before.len() >= r.len() * PAIR_INDEX_PROBES_PER_FACT);
    // Enough probes were asked to build it.
    assert!(r.pairs.get().is_some());
    let mut after = Vec::new();
    for a in 0..n + 1 {
        for b in 0..n + 1 {
            let ids = ask(&r, a, b);
            let want = (a < n && b < n && (a * 7 + b * 3) % 5 != 0) as usize;
            assert_eq!(ids.len(), want, "({a}, {b})");
            for &id in &ids {
                let t = r.tuple(id).map(|t| t.to_vec());
                assert_eq!(t, Some(vec![Term::Int(a), Term::Int(b)]));
            }
            after.push(ids);
        }
    }
    assert_eq!(before, after);
    let (id, new) = r.insert(&[Term::Int(0), Term::Int(0)])?;
    assert!(new);
    assert!(r.pairs.get().is_none());
    assert_eq!(ask(&r, 0, 0), vec![id]);
    Ok(())
}

/// The adjacency of a position, once built, hands out the candidates
/// the index list would, in the same order, with each fact's
/// arguments; an insert clears it, so a new fact is found.
#[test]
fn adjacency_agrees_with_the_index() -> Result<(), KanrenError> {
    let n = 200i64;
    let mut r = Relation::new("edge", 2);
    // `(a, b)` beside `(b, a)`, as a text KB lists them: the facts of
    // one value lie far apart.
    for a in 0..n {
        for b in a..n {
            if (a * 7 + b * 3) % 5 != 0 {
                r.insert(&[Term::Int(a), Term::Int(b)])?;
                if a != b {
                    r.insert(&[Term::Int(b), Term::Int(a)])?;
                }
            }
        }
    }
    assert!(r.len() >= PAIR_INDEX_MIN_FACTS);
    let scan = |r: &Relation, pos: usize, v: i64| -> Vec<(FactId, Vec<Term>)> {
        let t = Term::Int(v);
        let pat = if pos == 0 {
            [Some(&t), None]
        } else {
            [None, Some(&t)]
        };
        let c = r.cands(&pat, 0, FactId::MAX);
        let mut out = Vec::new();
        while let Some((id, args)) = r.candidate_args(&c, out.len()) {
            let args: Vec<Term> = match args {
                CandArgs::Stored(t) => t.to_vec(),
                CandArgs::Pair(p) => p.iter().map(|t| (*t).clone()).collect(),
            };
            out.push((id, args));
        }
        out
    };
    for pos in 0..2 {
        let before: Vec<_> = (0..n).map(|v| scan(&r, pos, v)).collect();
        for (v, facts) in (0..n).zip(&before) {
            assert!(facts.len() > 4, "{v}: no index scan");
            assert!(facts.windows(2).all(|w| w[0].0 < w[1].0));
            for (id, args) in facts {
                assert_eq!(args.get(pos), Some(&Term::Int(v)));
                assert_eq!(r.tuple(*id).map(|t| t.to_vec()).as_ref(), Some(args));
            }
        }
        // Enough scans to build it.
        for _ in 0..ADJACENCY_WORK_PER_FACT {
            for v in 0..n {
                scan(&r, pos, v);
            }
        }
        assert!(r.adjacency[pos].get().is_some(), "position {pos}");
        let three = Term::Int(3);
        let pat = if pos == 0 {
            [Some(&three), None]
        } else {
            [None, Some(&three)]
        };
        let c = r.cands(&pat, 0, FactId::MAX);
        assert!(
            matches!(c, Cands::Adjacent { pos: p, .. } if p == pos),
            "{c:?}"
        );
        let after: Vec<_> = (0..n).map(|v| scan(&r, pos, v)).collect();
        assert_eq!(before, after, "position {pos}");
    }
    let (id, new) = r.insert(&[Term::Int(0), Term::Int(n)])?;
    assert!(new);
    assert!(r.adjacency.iter().all(|a| a.get().is_none()));
    let zeros = scan(&r, 0, 0);
    assert_eq!(zeros.last(), Some(&(id, vec![Term::Int(0), Term::Int(n)])));
    Ok(())
}

/// A tuple reads through the dictionary: equal to its terms, printed
/// like a slice, and values shared between positions are stored once.
#[test]
fn tuples_read_through_the_dictionary() -> Result<(), KanrenError> {
    let mut r = Relation::new("p", 3);
    r.insert(&[sym("a"), Term::Int(1), Term::str("s")])?;
    r.insert(&[Term::Int(1), sym("a"), Term::Int(1)])?;
    assert_eq!(r.values.len(), 3);
    let t = r.tuple(1).ok_or(KanrenError::ArityMismatch {
        relation: r.name(),
        arity: 3,
        got: 0,
    })?;
    assert_eq!(t.len(), 3);
    assert!(t == *[Term::Int(1), sym("a"), Term::Int(1)].as_slice());
    assert_eq!(format!("{t:?}"), format!("{:?}", t.to_vec()));
    assert_eq!(t.get(1), Some(&sym("a")));
    assert_eq!(t.get(3), None);
    assert_ne!(r.tuple(0), r.tuple(1));
    assert_eq!(r.tuple(1), r.clone().tuple(1));
    assert_eq!(r.tuple(2), None);
    assert_eq!(r.lookup(&[None, Some(&sym("a")), None]), vec![1]);
    assert_eq!(
        r.lookup(&[Some(&sym("zz")), None, None]),
        Vec::<FactId>::new()
    );
    Ok(())
}

#[test]
fn zero_arity_relation() -> Result<(), KanrenError> {
    let mut r = Relation::new("raining", 0);
    assert!(r.is_empty());
    assert_eq!(r.insert(&[])?, (0, true));
    assert_eq!(r.insert(&[])?, (0, false));
    assert_eq!(r.len(), 1);
    assert_eq!(r.iter().count(), 1);
    Ok(())
}
