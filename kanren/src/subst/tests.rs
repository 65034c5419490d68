use super::*;
use proptest::prelude::*;
use std::collections::BTreeMap;

/// What one step of the model does to the substitution in hand.
#[derive(Clone, Debug)]
enum Op {
    /// Commit these bindings (variables not yet bound are kept).
    Commit(Vec<(u32, i64)>),
    /// Fork: the copy goes on, the original is kept for the checks.
    Fork,
    /// A plain clone goes on, the original is kept.
    Clone,
}

fn op() -> impl Strategy<Value = Op> {
    prop_oneof![
        4 => prop::collection::vec((0u32..300, any::<i64>()), 0..24).prop_map(Op::Commit),
        1 => Just(Op::Fork),
        1 => Just(Op::Clone),
    ]
}

fn check(s: &Subst, model: &BTreeMap<u32, i64>) -> Result<(), TestCaseError> {
    prop_assert_eq!(s.len(), model.len());
    for v in 0..300 {
        let want = model.get(&v).map(|i| Term::Int(*i));
        prop_assert_eq!(s.get(Var(v)).cloned(), want);
    }
    let seen: Vec<(u32, Term)> = s.iter().map(|(v, t)| (v.0, t.clone())).collect();
    let want: Vec<(u32, Term)> = model.iter().map(|(v, i)| (*v, Term::Int(*i))).collect();
    prop_assert_eq!(seen, want);
    Ok(())
}

proptest! {
    /// Commits (into the overlay, through a full one, or more than it
    /// holds at once), forks and clones in any order: every
    /// substitution kept along the way still holds exactly its own
    /// bindings, wherever they live.
    #[test]
    fn overlay_and_trie_behave_like_one_map(ops in prop::collection::vec(op(), 0..40)) {
        let mut s = Subst::new();
        let mut model = BTreeMap::new();
        let mut kept = Vec::new();
        for op in ops {
            match op {
                Op::Commit(bs) => {
                    let mut pending: Vec<(Var, Term)> = Vec::new();
                    for (v, i) in bs {
                        if let std::collections::btree_map::Entry::Vacant(e) = model.entry(v) {
                            e.insert(i);
                            pending.push((Var(v), Term::Int(i)));
                        }
                    }
                    s.commit(&pending);
                }
                Op::Fork => {
                    let copy = s.fork();
                    kept.push((std::mem::replace(&mut s, copy), model.clone()));
                }
                Op::Clone => {
                    let copy = s.clone();
                    kept.push((std::mem::replace(&mut s, copy), model.clone()));
                }
            }
            check(&s, &model)?;
        }
        for (k, m) in &kept {
            check(k, m)?;
        }
    }
}
