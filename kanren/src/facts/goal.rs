//! The `fact` goal: a [`Native`] goal that scans the candidates of its
//! most selective bound argument, one generator step at a time.

use super::{Code, FactId, Relation};
use crate::ctx::{Ctx, GenStep};
use crate::engine::{Generator, NativeOut, Out};
use crate::goal::{Goal, Native};
use crate::proof::ProofStep;
use crate::state::State;
use crate::term::Term;
use std::sync::Arc;

/// Where a fact scan takes its candidate ids from.
enum Candidates {
    /// Every fact, `0..len`.
    All,
    /// The index of position `pos` for the value with code `key` (looked up
    /// again on each turn: the scan cannot borrow from the relation it
    /// shares).
    Index { pos: usize, key: Code },
    /// A short candidate list, copied once: the common case of a key that
    /// (nearly) identifies its fact, where a second hash lookup per turn
    /// would cost more than the copy.
    Few(smallvec::SmallVec<[FactId; 4]>),
}

/// The generator of a `fact` goal: tries candidates one by one, so the
/// search can interleave it with other branches and stop it early.
pub(crate) struct FactScan {
    rel: Arc<Relation>,
    cand: Candidates,
    next: usize,
    args: Arc<[Term]>,
    state: State,
}

/// How many failing candidates one step may skip: bounds the work between
/// two budget checks.
const SCAN_CHUNK: usize = 64;

impl Generator for FactScan {
    fn next(&mut self, ctx: &Ctx) -> GenStep {
        let ids: &[FactId] = match &self.cand {
            Candidates::All => &[],
            Candidates::Few(ids) => ids,
            Candidates::Index { pos, key } => self.rel.ids_at(*pos, *key),
        };
        let total = match self.cand {
            Candidates::All => self.rel.len(),
            Candidates::Index { .. } | Candidates::Few(_) => ids.len(),
        };
        let mut tried = 0;
        while self.next < total && tried < SCAN_CHUNK {
            let id = match self.cand {
                Candidates::All => FactId::try_from(self.next).unwrap_or(FactId::MAX),
                Candidates::Index { .. } | Candidates::Few(_) => {
                    ids.get(self.next).copied().unwrap_or(FactId::MAX)
                }
            };
            self.next += 1;
            tried += 1;
            let Some(tuple) = self.rel.tuple(id) else {
                continue;
            };
            // All arguments in one pending unification: a candidate that
            // fails costs lookups only, no state copy.
            let mut pending = crate::subst::Pending::new();
            let ok = self
                .args
                .iter()
                .zip(tuple)
                .all(|(a, t)| self.state.subst.unify_pending(a, t, false, &mut pending));
            let st = if ok {
                self.state.clone().extended(&pending, false)
            } else {
                None
            };
            if let Some(mut st) = st {
                if ctx.proofs {
                    st.record(ProofStep::Fact {
                        relation: self.rel.name,
                        id,
                    });
                }
                return GenStep::Yield(st, None, self.next < total);
            }
        }
        if self.next < total {
            GenStep::More
        } else {
            GenStep::Done
        }
    }
}

/// A goal that unifies `args` with each matching fact of `rel`, in id order.
/// The candidates come from the index of the most selective argument that is
/// bound *when the goal runs*; with no bound argument it scans. A wrong
/// number of arguments simply matches nothing. With proofs on, each answer
/// records [`ProofStep::Fact`].
pub fn fact(rel: &Arc<Relation>, args: Vec<Term>) -> Goal {
    Goal::native(FactGoal {
        rel: rel.clone(),
        args: args.into(),
    })
}

/// A [`fact`] goal: kept as data, not a closure, so that [`crate::naf`] of
/// a fact whose arguments are all bound is one lookup instead of a search.
pub(crate) struct FactGoal {
    rel: Arc<Relation>,
    args: Arc<[Term]>,
}

impl Native for FactGoal {
    fn name(&self) -> &'static str {
        "fact"
    }

    /// Whether the fact holds, when every argument is bound to an atom in
    /// `st`; `None` when one is not (a search is needed).
    fn ground_holds(&self, st: &State) -> Option<bool> {
        if self.args.len() != self.rel.arity {
            return Some(false);
        }
        let walked: smallvec::SmallVec<[&Term; 6]> =
            self.args.iter().map(|a| st.subst.walk(a)).collect();
        if walked.iter().any(|t| matches!(t, Term::Var(_))) {
            return None;
        }
        if walked
            .iter()
            .any(|t| matches!(t, Term::Cons(..) | Term::App(..)))
        {
            return Some(false); // facts hold atoms only
        }
        let pattern: smallvec::SmallVec<[Option<&Term>; 6]> =
            walked.iter().map(|t| Some(*t)).collect();
        Some(self.rel.first_match(&pattern).is_some())
    }

    fn run(&self, _ctx: &Ctx, st: State) -> NativeOut {
        NativeOut::Out(self.apply(st))
    }
}

impl FactGoal {
    /// Runs the goal on `st`: a scan of the candidates of the most selective
    /// argument bound now.
    fn apply(&self, st: State) -> Out {
        let (rel, args) = (&self.rel, &self.args);
        if args.len() != rel.arity {
            return Out::Fail;
        }
        let cand = {
            // Arities are small: keep the per-call scratch on the stack.
            let walked: smallvec::SmallVec<[&Term; 6]> =
                args.iter().map(|a| st.subst.walk(a)).collect();
            if walked
                .iter()
                .any(|t| matches!(t, Term::Cons(..) | Term::App(..)))
            {
                return Out::Fail; // facts hold atoms only
            }
            let pattern: smallvec::SmallVec<[Option<&Term>; 6]> = walked
                .iter()
                .map(|t| (!matches!(t, Term::Var(_))).then_some(*t))
                .collect();
            match rel.best_index(&pattern) {
                Some((pos, ids)) => {
                    if ids.is_empty() {
                        return Out::Fail;
                    }
                    if ids.len() <= 4 {
                        Candidates::Few(ids.iter().copied().collect())
                    } else {
                        // A non-empty list means the bound value has a code.
                        match pattern
                            .get(pos)
                            .copied()
                            .flatten()
                            .and_then(|t| rel.code(t))
                        {
                            Some(key) => Candidates::Index { pos, key },
                            None => return Out::Fail,
                        }
                    }
                }
                None => {
                    if rel.is_empty() {
                        return Out::Fail;
                    }
                    Candidates::All
                }
            }
        };
        Out::Gen(Box::new(FactScan {
            rel: rel.clone(),
            cand,
            next: 0,
            args: args.clone(),
            state: st,
        }))
    }
}
