//! Semi-naive, stratified evaluation to the least fixpoint, then the
//! integrity constraints.

use super::{
    EvalStats, FactBase, FactError, GroundAtom, Just, Model, Violation, bind_from, term_name,
    term_text,
};
use crate::program::{PredId, Program};
use kanren::{FactId, Relation, Term};
use rustc_hash::FxHashMap as HashMap;
use std::sync::Arc;

fn len32(r: &Relation) -> u32 {
    u32::try_from(r.len()).unwrap_or(u32::MAX)
}

/// Whether `now` holds exactly the first `n` tuples of `before`, in order.
fn same_tuples(now: &Relation, n: u32, before: &Relation) -> bool {
    if now.len() != n as usize || before.len() < n as usize {
        return false;
    }
    // The same relation shared: nothing to compare.
    if std::ptr::eq(now, before) {
        return true;
    }
    (0..n).all(|id| now.tuple(id) == before.tuple(id))
}

impl Program {
    /// Reasons over `facts`: evaluates every component to its least fixpoint
    /// in stratification order, then checks the integrity constraints.
    /// Facts of predicates the program does not know are kept (and can be
    /// queried); a fact base relation whose arity differs from the
    /// LogicPad's declaration is an error.
    pub fn evaluate(&self, facts: FactBase) -> Result<Model, FactError> {
        self.evaluate_inner(facts, None)
    }

    /// Reasons over `facts` like [`Program::evaluate`], reusing what the
    /// model of an overlapping window already derived: a component whose
    /// inputs — the base facts of its own predicates and every relation its
    /// rules read — are the same tuples in the same order as in `prev` gets
    /// `prev`'s relations (shared, not copied) and derivations, without
    /// running a join. Any other component is evaluated; if its result comes
    /// out identical to `prev`'s, the components that read it can still be
    /// reused. The result is the model [`Program::evaluate`] builds, fact ids
    /// included ([`EvalStats::reused_components`] tells how much was
    /// skipped). A `prev` from another program is ignored.
    ///
    /// Why order and not just the set: derivations record their premises
    /// by fact id, so reused derivations are only valid where every input
    /// relation numbers its facts exactly as before.
    pub fn evaluate_after(&self, prev: &Model, facts: FactBase) -> Result<Model, FactError> {
        let prev = Arc::ptr_eq(&prev.program.inner, &self.inner).then_some(prev);
        self.evaluate_inner(facts, prev)
    }

    fn evaluate_inner(&self, facts: FactBase, prev: Option<&Model>) -> Result<Model, FactError> {
        let inner = &self.inner;
        let n = inner.names.len();
        let mut rels: Vec<Arc<Relation>> = (0..n)
            .map(|p| Arc::new(Relation::new(inner.syms[p], inner.arity[p])))
            .collect();
        let mut names: HashMap<String, usize> = HashMap::default();
        for (name, rel) in facts.rels {
            match inner.by_name.get(&name) {
                Some(&p) => {
                    if rel.arity() != inner.arity[p] {
                        return Err(FactError::Arity {
                            pred: name,
                            expected: inner.arity[p],
                            got: rel.arity(),
                        });
                    }
                    rels[p] = Arc::new(rel);
                }
                None => {
                    names.insert(name, rels.len());
                    rels.push(Arc::new(rel));
                }
            }
        }
        let base_len: Vec<u32> = rels.iter().map(|r| len32(r)).collect();
        let mut just: Vec<Vec<Just>> = vec![Vec::new(); rels.len()];
        let mut premises: Vec<FactId> = Vec::new();
        let mut stats = EvalStats {
            base_facts: facts.count,
            ..EvalStats::default()
        };

        // `same[p]`: relation `p` as it stands holds exactly `prev`'s tuples
        // of `p`, in the same order (base facts now; derived ones once `p`'s
        // component is done).
        let mut same: Vec<bool> = (0..n)
            .map(|p| prev.is_some_and(|m| same_tuples(&rels[p], m.base_len[p], &m.rels[p])))
            .collect();

        for (ci, comp) in inner.components.iter().enumerate() {
            let in_comp = |p: PredId| inner.comp_of.get(p) == Some(&ci);
            if let Some(m) = prev
                && comp.preds.iter().all(|&p| same[p])
                && comp.rules.iter().all(|&rid| {
                    let r = &inner.rules[rid];
                    r.body.iter().chain(&r.negated).all(|a| same[a.pred])
                })
            {
                // Unchanged inputs: the fixpoint would rebuild `prev`'s
                // relations fact for fact, so take them and their
                // derivations (premise ids stay valid: every input relation
                // numbers its facts as before).
                for &p in &comp.preds {
                    rels[p] = Arc::clone(&m.rels[p]);
                    for j in &m.just[p] {
                        let start = u32::try_from(premises.len()).unwrap_or(u32::MAX);
                        let (a, b) = (j.start as usize, j.start as usize + j.len as usize);
                        premises.extend_from_slice(m.premises.get(a..b).unwrap_or(&[]));
                        just[p].push(Just { start, ..*j });
                    }
                    stats.derived_facts += m.just[p].len();
                }
                stats.reused_components += 1;
                continue;
            }
            // Semi-naive state per predicate of the component: delta = lo..hi.
            let mut lo: HashMap<PredId, u32> = comp.preds.iter().map(|&p| (p, 0)).collect();
            let mut hi: HashMap<PredId, u32> =
                comp.preds.iter().map(|&p| (p, len32(&rels[p]))).collect();
            let mut first_round = true;
            loop {
                let mut produced = false;
                for &rid in &comp.rules {
                    let rule = &inner.rules[rid];
                    // Sparse windows: most rules have an empty body relation.
                    // (An empty relation of this component that fills later
                    // in the round is caught as next round's delta.)
                    if rule.body.iter().any(|a| rels[a.pred].is_empty()) {
                        continue;
                    }
                    if first_round
                        && let Some(b) = copy_of(rule)
                        && !in_comp(b)
                        && rels[rule.head.pred].is_empty()
                    {
                        // Datalog: `h(x1, …, xn) :- b(x1, …, xn)` into an
                        // empty `h` derives `b`'s facts in `b`'s id order, each
                        // from itself: the relation is copied whole, not
                        // re-inserted fact by fact.
                        let head = rule.head.pred;
                        let copied = rels[b].renamed(rels[head].name());
                        let count = len32(&copied);
                        rels[head] = Arc::new(copied);
                        premises.reserve(count as usize);
                        just[head].reserve(count as usize);
                        for id in 0..count {
                            let start = u32::try_from(premises.len()).unwrap_or(u32::MAX);
                            premises.push(id);
                            just[head].push(Just {
                                rule: rid as u32,
                                start,
                                len: 1,
                            });
                        }
                        stats.derived_facts += count as usize;
                        produced |= count > 0;
                        continue;
                    }
                    let rec: Vec<usize> = (0..rule.body.len())
                        .filter(|&i| in_comp(rule.body[i].pred))
                        .collect();
                    // Variants: one per recursive body atom taking the delta;
                    // a non-recursive rule runs once, in the first round.
                    let variants: Vec<Option<usize>> = if rec.is_empty() {
                        if first_round { vec![None] } else { Vec::new() }
                    } else {
                        rec.iter().map(|&k| Some(k)).collect()
                    };
                    let mut out_terms = Vec::new();
                    let mut out_prem = Vec::new();
                    let mut emitted = 0;
                    for variant in variants {
                        let ranges: Vec<(u32, u32)> = rule
                            .body
                            .iter()
                            .enumerate()
                            .map(|(j, a)| {
                                let full = (0, len32(&rels[a.pred]));
                                match variant {
                                    None => full,
                                    Some(k) if in_comp(a.pred) => {
                                        let (l, h) = (lo[&a.pred], hi[&a.pred]);
                                        if j < k && rec.contains(&j) {
                                            (0, l)
                                        } else if j == k {
                                            (l, h)
                                        } else {
                                            (0, h)
                                        }
                                    }
                                    Some(_) => full,
                                }
                            })
                            .collect();
                        if ranges.iter().any(|(l, h)| l >= h) {
                            continue;
                        }
                        emitted +=
                            derive(&rels, rule, variant, ranges, &mut out_terms, &mut out_prem);
                    }
                    let arity = rule.head.args.len();
                    let nb = rule.body.len();
                    let head = rule.head.pred;
                    // A propositional head (`Danger()`) has no terms: one
                    // empty tuple per derivation.
                    let tuples: Vec<&[Term]> = if arity == 0 {
                        vec![&[]; emitted]
                    } else {
                        out_terms.chunks(arity).collect()
                    };
                    for (k, tuple) in tuples.into_iter().enumerate() {
                        let (id, new) =
                            Arc::make_mut(&mut rels[head]).insert(tuple).map_err(|e| {
                                FactError::Store {
                                    pred: inner.names[head].clone(),
                                    message: e.to_string(),
                                }
                            })?;
                        if new {
                            produced = true;
                            stats.derived_facts += 1;
                            debug_assert_eq!(
                                id as usize,
                                base_len[head] as usize + just[head].len()
                            );
                            let start = u32::try_from(premises.len()).unwrap_or(u32::MAX);
                            premises.extend_from_slice(
                                out_prem.get(k * nb..(k + 1) * nb).unwrap_or(&[]),
                            );
                            just[head].push(Just {
                                rule: rid as u32,
                                start,
                                len: nb as u32,
                            });
                        }
                    }
                }
                first_round = false;
                if !comp.recursive || !produced {
                    break;
                }
                stats.rounds += 1;
                for &p in &comp.preds {
                    let h = hi[&p];
                    lo.insert(p, h);
                    hi.insert(p, len32(&rels[p]));
                }
            }
            if let Some(m) = prev {
                for &p in &comp.preds {
                    same[p] = same_tuples(&rels[p], len32(&m.rels[p]), &m.rels[p]);
                }
            }
        }

        // Integrity constraints: every solution of `body ∧ head` is a violation.
        let mut violations = Vec::new();
        for c in &inner.constraints {
            let ranges: Vec<(u32, u32)> =
                c.body.iter().map(|a| (0, len32(&rels[a.pred]))).collect();
            let (mut out_terms, mut out_prem) = (Vec::new(), Vec::new());
            let emitted = derive(&rels, c, None, ranges, &mut out_terms, &mut out_prem);
            // One violation per derivation; a propositional head (`¬Danger()`)
            // has no terms, so count derivations rather than head tuples.
            let arity = c.head.args.len();
            let nb = c.body.len();
            for k in 0..emitted {
                let tuple = out_terms.get(k * arity..(k + 1) * arity).unwrap_or(&[]);
                let prem = out_prem.get(k * nb..(k + 1) * nb).unwrap_or(&[]);
                let binds = bind_from(c, |p| rels.get(p).map(|r| &**r), prem);
                let mut bindings: Vec<(String, String)> = c
                    .vars
                    .iter()
                    .zip(&binds)
                    .filter_map(|(n, b)| b.as_ref().map(|t| (n.clone(), term_text(t))))
                    .collect();
                bindings.sort();
                let facts = c
                    .body
                    .iter()
                    .zip(prem)
                    .filter_map(|(a, &id)| {
                        let t = rels.get(a.pred)?.tuple(id)?;
                        Some(GroundAtom {
                            pred: inner.names.get(a.pred)?.clone().into(),
                            args: t.iter().map(term_name).collect(),
                        })
                    })
                    .collect();
                violations.push(Violation {
                    facts,
                    constraint: c.id,
                    rule_text: c.source.text.to_string(),
                    rule_line: c.source.line,
                    atom: GroundAtom {
                        pred: inner.names[c.head.pred].clone().into(),
                        args: tuple.iter().map(term_name).collect(),
                    },
                    bindings,
                });
            }
        }
        violations.sort_by(|a, b| (a.constraint, &a.atom).cmp(&(b.constraint, &b.atom)));
        violations.dedup();

        Ok(Model {
            program: self.clone(),
            rels: rels.into(),
            names,
            base_len,
            just,
            premises,
            violations,
            stats,
        })
    }
}

/// The body predicate of a rule that copies one relation into another:
/// one positive atom, no negation or comparison, and a head with the same
/// distinct variables in the same order (`ComeClose(x, y) :-
/// DistanceDecrease(x, y)`). `None` for any other rule.
fn copy_of(rule: &crate::program::Rule) -> Option<PredId> {
    let [atom] = &rule.body[..] else {
        return None;
    };
    let distinct_vars = atom.args.iter().enumerate().all(|(i, a)| match a {
        kanren::join::Arg::Var(v) => atom.args[..i]
            .iter()
            .all(|b| !matches!(b, kanren::join::Arg::Var(w) if w == v)),
        kanren::join::Arg::Const(_) => false,
    });
    (rule.negated.is_empty()
        && rule.cmps.is_empty()
        && atom.pred != rule.head.pred
        && atom.args == rule.head.args
        && distinct_vars)
        .then_some(atom.pred)
}

/// Every derivation of `rule` with body atom `i` in `ranges[i]` (the atom
/// `first`, a semi-naive delta, planned first): appends each one's head
/// tuple to `out_terms` and its premises, in body order, to `out_prem`;
/// returns how many there were (a 0-ary head adds no terms).
///
/// Datalog: `head :- body` restricted to the ranges — kanren's join over
/// the rule's [`kanren::join::Body`].
fn derive(
    rels: &[Arc<Relation>],
    rule: &crate::program::Rule,
    first: Option<usize>,
    ranges: Vec<(u32, u32)>,
    out_terms: &mut Vec<Term>,
    out_prem: &mut Vec<kanren::FactId>,
) -> usize {
    let order = kanren::join::plan(&rule.body, rels, first, &[]);
    let mut cursor = kanren::join::Cursor::new(rule.vars.len(), &order, &ranges);
    let body = rule.join_body();
    let mut emitted = 0;
    while cursor.next(rels, body, &mut || true) == kanren::join::Next::Found {
        let start = out_terms.len();
        let complete = rule.head.args.iter().all(|a| {
            kanren::join::arg_value(a, cursor.binds()).is_some_and(|t| {
                out_terms.push(t.clone());
                true
            })
        });
        if !complete {
            out_terms.truncate(start);
            continue;
        }
        out_prem.extend_from_slice(cursor.chosen());
        emitted += 1;
    }
    emitted
}
