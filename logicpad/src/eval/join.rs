//! The one join of the evaluator, and its planner.

use crate::program::{CArg, CAtom, Rule};
use kanren::{FactId, Probe, Relation, Term};
use std::borrow::Borrow;
use std::sync::Arc;

/// One join of a rule's body over relations: the planner's order, then
/// for each atom in turn the candidates of an index probe (cut to the
/// atom's semi-naive range), bound against the tuple. The same join derives
/// facts in the fixpoint, counts and lists a query's answers, records the
/// premises that proofs are built from, and — pulled one derivation at a
/// time through [`Join::next_derivation`] — enumerates answers lazily.
///
/// Datalog: for `head :- b1, …, bn, ¬n1, …, c1, …` each derivation is one
/// fact per `bi` (in `order`) agreeing on shared variables, such that no
/// `nj` holds and every comparison `ck` holds.
///
/// Invariants: `frames[d]` is the cursor of atom `order[d]`; `trail` holds
/// the variables bound so far, innermost last, and `frames[d].mark` is its
/// length before atom `order[d]` bound anything; `chosen[i]` is the fact of
/// body atom `i` in the current derivation.
pub(crate) struct Join<'a, R: Borrow<Relation>> {
    pub(crate) rels: &'a [R],
    pub(crate) rule: RuleRef<'a>,
    pub(crate) order: Vec<usize>,
    pub(crate) ranges: Vec<(u32, u32)>,
    pub(crate) binds: Vec<Option<Term>>,
    pub(crate) chosen: Vec<FactId>,
    pub(crate) neg: Vec<Term>,
    pub(crate) trail: Vec<usize>,
    /// Output: head tuples, flat.
    pub(crate) out_terms: Vec<Term>,
    /// Output: premise ids in body order, flat.
    pub(crate) out_prem: Vec<FactId>,
    /// Number of successful derivations (also counts 0-ary heads).
    pub(crate) emitted: usize,
    /// The join stops once this many derivations are emitted (a query's
    /// answer budget; `usize::MAX` for rules, which the fixpoint bounds).
    pub(crate) limit: usize,
    /// False when only the number of derivations is wanted: nothing is
    /// stored, so counting takes no memory per answer.
    pub(crate) store: bool,
    /// A query's step and time budget (none for rules).
    pub(crate) budget: JoinBudget,
    /// The cursors of the atoms bound so far.
    frames: Vec<Frame<'a>>,
    /// Whether the first derivation was asked for.
    started: bool,
}

/// The rule a join runs: the program's own, or a query compiled for a lazy
/// answer stream, which owns it.
#[derive(Clone)]
pub(crate) enum RuleRef<'a> {
    Borrowed(&'a Rule),
    Shared(Arc<Rule>),
}

impl RuleRef<'_> {
    pub(crate) fn get(&self) -> &Rule {
        match self {
            RuleRef::Borrowed(r) => r,
            RuleRef::Shared(r) => r,
        }
    }
}

/// The cursor of one atom of a join: its candidates and the next one.
struct Frame<'a> {
    probe: Probe<'a>,
    next: usize,
    mark: usize,
}

impl Frame<'_> {
    fn next_id(&mut self) -> Option<FactId> {
        let id = match self.probe {
            Probe::Range(lo, hi) => {
                let id = lo.checked_add(u32::try_from(self.next).ok()?)?;
                (id < hi).then_some(id)
            }
            Probe::Ids(ids) => ids.get(self.next).copied(),
        };
        self.next += 1;
        id
    }
}

/// The step and time budget of a query's join: a step is one candidate
/// fact tried. When it runs out the join stops with what it has found.
#[derive(Debug, Clone, Default)]
pub(crate) struct JoinBudget {
    pub(crate) max_steps: Option<u64>,
    pub(crate) deadline: Option<std::time::Instant>,
    pub(crate) steps: u64,
    /// Why the join stopped early, once it has.
    pub(crate) stopped: Option<kanren::StopReason>,
}

impl JoinBudget {
    /// How often the clock is read, in steps.
    const CLOCK_EVERY: u64 = 4096;

    /// Counts one step; false once the budget is spent.
    #[inline]
    fn step(&mut self) -> bool {
        if self.stopped.is_some() {
            return false;
        }
        self.steps += 1;
        if self.max_steps.is_some_and(|m| self.steps > m) {
            self.stopped = Some(kanren::StopReason::StepBudget);
            return false;
        }
        if self.steps.is_multiple_of(Self::CLOCK_EVERY)
            && self
                .deadline
                .is_some_and(|d| std::time::Instant::now() >= d)
        {
            self.stopped = Some(kanren::StopReason::TimeBudget);
            return false;
        }
        true
    }
}

pub(crate) fn arg_value<'t>(a: &'t CArg, binds: &'t [Option<Term>]) -> Option<&'t Term> {
    match a {
        CArg::Const(t) => Some(t),
        CArg::Var(v) => binds.get(*v).and_then(Option::as_ref),
    }
}

impl<'a, R: Borrow<Relation>> Join<'a, R> {
    /// A join of `rule` over `rels` in `order`, each body atom within its
    /// id range.
    pub(crate) fn new(
        rels: &'a [R],
        rule: RuleRef<'a>,
        order: Vec<usize>,
        ranges: Vec<(u32, u32)>,
    ) -> Join<'a, R> {
        let (nvars, nbody) = (rule.get().vars.len(), rule.get().body.len());
        Join {
            rels,
            rule,
            order,
            ranges,
            binds: vec![None; nvars],
            chosen: vec![0; nbody],
            neg: Vec::new(),
            trail: Vec::new(),
            out_terms: Vec::new(),
            out_prem: Vec::new(),
            emitted: 0,
            limit: usize::MAX,
            store: true,
            budget: JoinBudget::default(),
            frames: Vec::new(),
            started: false,
        }
    }

    /// Runs the join to the end (or to `limit` derivations), storing each
    /// derivation's head tuple and premises unless `store` is off.
    pub(crate) fn run(&mut self) {
        while self.emitted < self.limit && self.next_derivation() {
            self.emit();
        }
    }

    /// Advances to the next derivation: afterwards `binds` and `chosen`
    /// describe it. False when there is none left (or the budget ran out).
    pub(crate) fn next_derivation(&mut self) -> bool {
        let rule = self.rule.get();
        if !self.started {
            self.started = true;
            if self.order.is_empty() {
                return filters_hold(rule, self.rels, &self.binds, &mut self.neg);
            }
            match open_frame(
                self.rels,
                rule,
                &self.order,
                &self.ranges,
                &self.binds,
                0,
                &self.trail,
            ) {
                Some(f) => self.frames.push(f),
                None => return false,
            }
        }
        loop {
            let depth = self.frames.len();
            let Some(frame) = self.frames.last_mut() else {
                return false;
            };
            // Undo what the previous candidate of this atom bound.
            for v in self.trail.drain(frame.mark..) {
                if let Some(slot) = self.binds.get_mut(v) {
                    *slot = None;
                }
            }
            let Some(id) = frame.next_id() else {
                self.frames.pop();
                continue;
            };
            if !self.budget.step() {
                self.frames.clear();
                return false;
            }
            let Some(&ai) = self.order.get(depth - 1) else {
                return false;
            };
            let (Some(atom), Some(rel)) = (
                rule.body.get(ai),
                rule.body
                    .get(ai)
                    .and_then(|a| self.rels.get(a.pred))
                    .map(Borrow::borrow),
            ) else {
                return false;
            };
            if !bind_tuple(atom, rel, id, &mut self.binds, &mut self.trail) {
                continue;
            }
            if let Some(c) = self.chosen.get_mut(ai) {
                *c = id;
            }
            if depth == self.order.len() {
                if filters_hold(rule, self.rels, &self.binds, &mut self.neg) {
                    return true;
                }
                continue;
            }
            if let Some(f) = open_frame(
                self.rels,
                rule,
                &self.order,
                &self.ranges,
                &self.binds,
                depth,
                &self.trail,
            ) {
                self.frames.push(f);
            }
        }
    }

    /// Records the current derivation (its head tuple and premises).
    fn emit(&mut self) {
        if !self.store {
            self.emitted += 1;
            return;
        }
        let start = self.out_terms.len();
        for a in &self.rule.get().head.args {
            match arg_value(a, &self.binds) {
                Some(t) => self.out_terms.push(t.clone()),
                None => {
                    self.out_terms.truncate(start);
                    return;
                }
            }
        }
        self.out_prem.extend_from_slice(&self.chosen);
        self.emitted += 1;
    }
}

/// The cursor of atom `order[depth]` under the current bindings: an index
/// probe for its bound arguments, cut to the atom's id range. `None` when
/// the atom or its relation is missing (the join then has no derivation
/// through it).
fn open_frame<'a, R: Borrow<Relation>>(
    rels: &'a [R],
    rule: &Rule,
    order: &[usize],
    ranges: &[(u32, u32)],
    binds: &[Option<Term>],
    depth: usize,
    trail: &[usize],
) -> Option<Frame<'a>> {
    let ai = *order.get(depth)?;
    let atom = rule.body.get(ai)?;
    let rel: &'a Relation = rels.get(atom.pred)?.borrow();
    let (lo, hi) = ranges.get(ai).copied().unwrap_or((0, 0));
    // The lookup pattern borrows the bound values; small arities use a
    // stack array so the inner loop does not allocate.
    let mut small: [Option<&Term>; 4] = [None; 4];
    let big: Vec<Option<&Term>>;
    let pat: &[Option<&Term>] = if atom.args.len() <= small.len() {
        for (slot, a) in small.iter_mut().zip(&atom.args) {
            *slot = arg_value(a, binds);
        }
        &small[..atom.args.len()]
    } else {
        big = atom.args.iter().map(|a| arg_value(a, binds)).collect();
        &big
    };
    Some(Frame {
        probe: rel.probe(pat).within(lo, hi),
        next: 0,
        mark: trail.len(),
    })
}

/// Binds the atom's variables to fact `id`, checking constants and
/// variables bound earlier (or earlier in the same atom). On failure the
/// bindings it made stay on the trail, for the caller's undo.
fn bind_tuple(
    atom: &CAtom,
    rel: &Relation,
    id: FactId,
    binds: &mut [Option<Term>],
    trail: &mut Vec<usize>,
) -> bool {
    let Some(tuple) = rel.tuple(id) else {
        return false;
    };
    for (a, t) in atom.args.iter().zip(tuple) {
        match a {
            CArg::Const(c) => {
                if !kanren::same_term(c, t) {
                    return false;
                }
            }
            CArg::Var(v) => match binds.get_mut(*v) {
                Some(Some(b)) => {
                    if !kanren::same_term(b, t) {
                        return false;
                    }
                }
                Some(slot @ None) => {
                    *slot = Some(t.clone());
                    trail.push(*v);
                }
                None => return false,
            },
        }
    }
    true
}

/// Whether the rule's comparisons hold and none of its negated atoms does,
/// under complete bindings.
fn filters_hold<R: Borrow<Relation>>(
    rule: &Rule,
    rels: &[R],
    binds: &[Option<Term>],
    neg: &mut Vec<Term>,
) -> bool {
    for (l, r, negated) in &rule.cmps {
        let (Some(a), Some(b)) = (arg_value(l, binds), arg_value(r, binds)) else {
            return false;
        };
        if (a == b) == *negated {
            return false;
        }
    }
    for n in &rule.negated {
        neg.clear();
        for a in &n.args {
            match arg_value(a, binds) {
                Some(t) => neg.push(t.clone()),
                None => return false,
            }
        }
        if rels.get(n.pred).is_some_and(|r| r.borrow().contains(neg)) {
            return false;
        }
    }
    true
}

/// Join order: the atom at `first` (if any), then repeatedly the atom with
/// the most bound arguments, ties broken by the smaller relation.
pub(crate) fn plan<R: Borrow<Relation>>(
    rule: &Rule,
    rels: &[R],
    first: Option<usize>,
) -> Vec<usize> {
    let n = rule.body.len();
    let mut bound = vec![false; rule.vars.len()];
    let mut order = Vec::with_capacity(n);
    let mut used = vec![false; n];
    let take = |i: usize, bound: &mut Vec<bool>, order: &mut Vec<usize>, used: &mut Vec<bool>| {
        used[i] = true;
        order.push(i);
        for a in &rule.body[i].args {
            if let CArg::Var(v) = a
                && let Some(b) = bound.get_mut(*v)
            {
                *b = true;
            }
        }
    };
    if let Some(f) = first.filter(|&f| f < n) {
        take(f, &mut bound, &mut order, &mut used);
    }
    while order.len() < n {
        // (no bound argument though it has some, unbound args, size, index):
        // prefer atoms connected to what is bound (an index lookup) over a
        // cross product, then the most bound, then the smallest relation.
        let mut best: Option<(bool, usize, usize, usize)> = None;
        for i in (0..n).filter(|&i| !used[i]) {
            let atom = &rule.body[i];
            let unbound = atom
                .args
                .iter()
                .filter(|a| matches!(a, CArg::Var(v) if !bound.get(*v).copied().unwrap_or(false)))
                .count();
            let disconnected = !order.is_empty() && unbound == atom.args.len() && unbound > 0;
            let size = rels.get(atom.pred).map_or(0, |r| r.borrow().len());
            let key = (disconnected, unbound, size, i);
            if best.is_none_or(|b| key < b) {
                best = Some(key);
            }
        }
        let Some((_, _, _, i)) = best else { break };
        take(i, &mut bound, &mut order, &mut used);
    }
    order
}
