//! What a source can observe ([`Observed`], [`Observability`]): the line
//! between "no" and "unknown".

use super::*;

/// How completely a source can observe a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Observed {
    /// The source never produces it: an absent fact says nothing.
    Never,
    /// Some of its rules rest on unobservable predicates: a present fact is
    /// proved, an absent one says nothing.
    Partly,
    /// Fully observed: the closed-world assumption holds.
    Fully,
}

/// What a source can observe, as the set of base predicates it cannot produce.
/// Derived predicates inherit from their rules.
#[derive(Debug, Clone, Default)]
pub struct Observability {
    /// Base predicates this source never produces, with the reason.
    pub unobservable: BTreeMap<String, String>,
}

impl Observability {
    /// A source that observes everything its LogicPad declares.
    pub fn everything() -> Observability {
        Observability::default()
    }

    /// Marks predicates as unobservable for a reason.
    pub fn without(mut self, preds: &[&str], why: &str) -> Observability {
        for p in preds {
            self.unobservable.insert((*p).to_string(), why.to_string());
        }
        self
    }

    /// The base predicates under `pred` (itself, or those its rules rest on,
    /// through derived ones) that this source cannot observe, each with the
    /// source's reason: what an "unknown" answer tells the user.
    pub(crate) fn blind_spots(&self, pad: &LogicPad, pred: &str) -> Vec<(String, String)> {
        let mut out = Vec::new();
        rests_on(pad.program(), vec![pred.to_string()], |p| {
            match self.unobservable.get(p) {
                Some(why) => {
                    out.push((p.to_string(), why.clone()));
                    false
                }
                None => true,
            }
        });
        out.sort();
        out
    }

    /// Observability of every predicate of a program (fixpoint over the rules:
    /// a derived predicate is fully observed when every rule for it rests on
    /// fully observed predicates only; partly when at least one rule does, or
    /// when it has any rule at all that can fire on observed facts).
    ///
    /// The fixpoint is the greatest one: a recursive rule over fully observed
    /// facts (`Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)`) computes its
    /// predicate exactly, so it must not hold its own predicate down.
    pub fn classify(&self, pad: &LogicPad) -> BTreeMap<String, Observed> {
        let program = pad.program();
        let schema = pad.schema();
        let mut status: BTreeMap<String, Observed> = BTreeMap::new();
        for p in schema.predicates() {
            // Derived predicates start fully observed and fall in the fixpoint below.
            let s = if self.unobservable.contains_key(&p.name) {
                Observed::Never
            } else {
                Observed::Fully
            };
            status.insert(p.name.clone(), s);
        }
        // Derived predicates: iterate to a fixpoint (recursion converges
        // because a rule's status is monotone in its body's, so statuses only fall).
        loop {
            let mut changed = false;
            for p in schema.predicates().filter(|p| p.kind == PredKind::Derived) {
                if self.unobservable.contains_key(&p.name) {
                    continue;
                }
                let Some(pid) = program.pred_id(&p.name) else {
                    continue;
                };
                let rules: Vec<_> = program
                    .rules()
                    .iter()
                    .filter(|r| r.head.pred == pid)
                    .collect();
                let rule_status = |r: &&logicpad::Rule| -> Observed {
                    let mut worst = Observed::Fully;
                    for a in r.body.iter().chain(r.negated.iter()) {
                        let name = program.pred_name(a.pred).unwrap_or_default();
                        let s = status.get(name).copied().unwrap_or(Observed::Never);
                        let s = if r.negated.contains(a) && s != Observed::Fully {
                            // ¬P on a partly observed P can be wrongly true.
                            Observed::Never
                        } else {
                            s
                        };
                        worst = worst.min(s);
                    }
                    worst
                };
                let statuses: Vec<Observed> = rules.iter().map(rule_status).collect();
                let new = if statuses.is_empty() {
                    Observed::Never
                } else if statuses.iter().all(|s| *s == Observed::Fully) {
                    Observed::Fully
                } else if statuses.iter().any(|s| *s != Observed::Never) {
                    Observed::Partly
                } else {
                    Observed::Never
                };
                let old = status.get(&p.name).copied().unwrap_or(Observed::Never);
                if new < old {
                    status.insert(p.name.clone(), new);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        status
    }
}

/// The predicates `roots` rest on: themselves, and through the rules for
/// each (positive and negated bodies) everything under them, visiting each
/// once; `descend(p)` says whether to go under `p`.
pub(crate) fn rests_on(
    program: &logicpad::Program,
    roots: Vec<String>,
    mut descend: impl FnMut(&str) -> bool,
) -> BTreeSet<String> {
    let mut seen = BTreeSet::new();
    let mut stack = roots;
    while let Some(p) = stack.pop() {
        if !seen.insert(p.clone()) || !descend(&p) {
            continue;
        }
        let Some(pid) = program.pred_id(&p) else {
            continue;
        };
        for r in program.rules().iter().filter(|r| r.head.pred == pid) {
            for a in r.body.iter().chain(r.negated.iter()) {
                if let Some(name) = program.pred_name(a.pred) {
                    stack.push(name.to_string());
                }
            }
        }
    }
    seen
}
