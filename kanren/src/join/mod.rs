//! Conjunctions of relation goals run as one indexed join.
//!
//! `conj([fact(r1, args1), …, fact(rn, argsn)])` is the commonest kanren
//! program over stored facts, and run goal by goal it pays for every
//! partial match: each `fact` goal boxes a scan, and each candidate that
//! fits extends a persistent substitution that the next goal may throw
//! away. [`join`] is the same conjunction compiled: one search task that
//! walks the atoms in a planned order over the relations' indexes, with its
//! variables in a flat array of slots and a trail to undo them, and that
//! extends the state once per complete match. It is lazy (a match per
//! turn, a bounded number of candidates per turn, every candidate a step
//! of the run's budget) and fair like any other generator.
//!
//! The three types: [`Atom`] (a relation index and [`Arg`]s: slots or
//! constants), [`Body`] (atoms, plus the atoms that must be absent and the
//! `=`/`≠` comparisons, for rules evaluated bottom-up), and [`Cursor`] (the
//! join's position). [`plan`] orders the atoms. The bottom-up fixpoint of
//! a rule language (logicpad) drives [`Cursor`] directly; queries run it
//! through [`join`].
//!
//! Datalog: for `head :- b1, …, bn, ¬n1, …, c1, …` each match is one fact
//! per `bi` (in the planned order) agreeing on shared slots, such that no
//! `nj` holds and every comparison `ck` holds.

use crate::ctx::{Ctx, GenStep};
use crate::engine::{Generator, Out};
use crate::facts::{CandArgs, Cands, FactId, Relation, same_term};
use crate::goal::Goal;
use crate::proof::ProofStep;
use crate::state::State;
use crate::term::Term;
use smallvec::SmallVec;
use std::borrow::Borrow;
use std::sync::Arc;

/// An argument of a join atom: a slot of the join, or a constant.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub enum Arg {
    /// Slot `i` of the join's variables.
    Var(usize),
    /// A constant (an atom: a symbol, number or string).
    Const(Term),
}

/// A join atom: relation `pred` (an index into the relations the join runs
/// over) applied to `args`.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub struct Atom {
    /// The relation's index.
    pub pred: usize,
    /// Its arguments.
    pub args: Vec<Arg>,
}

/// A comparison `a = b` (`negated` false) or `a ≠ b` (true).
pub type Cmp = (Arg, Arg, bool);

/// What a join matches: positive atoms, then filters on complete matches.
///
/// Invariant (the caller's, checked by rule languages as safety): every
/// slot of `negated` and `cmps` occurs in `atoms`, so filters only ever see
/// bound slots; a filter with an unbound slot fails.
#[derive(Debug, Clone, Copy)]
pub struct Body<'a> {
    /// The atoms that must hold.
    pub atoms: &'a [Atom],
    /// The atoms that must not hold.
    pub negated: &'a [Atom],
    /// Comparisons.
    pub cmps: &'a [Cmp],
}

impl<'a> Body<'a> {
    /// A body of positive atoms only.
    pub fn atoms(atoms: &'a [Atom]) -> Body<'a> {
        Body {
            atoms,
            negated: &[],
            cmps: &[],
        }
    }
}

/// The value of `a` under `binds`: a constant, or a bound slot.
#[inline]
pub fn arg_value<'t>(a: &'t Arg, binds: &'t [Option<Term>]) -> Option<&'t Term> {
    match a {
        Arg::Const(t) => Some(t),
        Arg::Var(v) => binds.get(*v).and_then(Option::as_ref),
    }
}

/// What [`Cursor::next`] found.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Next {
    /// A match: [`Cursor::binds`] and [`Cursor::chosen`] describe it.
    Found,
    /// No match is left.
    Done,
    /// The step function said stop; calling `next` again resumes.
    Paused,
}

/// The cursor of one atom: its candidates and the next one to try.
#[derive(Debug)]
struct Frame {
    /// The atom's place in the join order (the atom is `order[depth]`).
    depth: usize,
    cands: Cands,
    next: usize,
    /// The trail's length before this atom bound anything.
    mark: usize,
}

/// What [`Cursor::descend`] reached.
enum Descend {
    /// Every atom matched: a complete match (before the filters).
    Match,
    /// A fully bound atom has no fact, or an atom's relation is missing.
    Fail,
    /// A frame was opened for the next atom with unbound arguments.
    Opened,
}

/// The position of a join: one frame per atom entered, the slots bound so
/// far and the facts chosen.
///
/// Invariants: frames are opened only for atoms with an unbound argument
/// when their turn comes (`exact[d]` false); an atom whose arguments are
/// all bound by then (`exact[d]`) is one probe with one fact or none, made
/// inline, with no frame. `frames` is ordered by `depth`; `trail` holds the
/// slots bound by atoms (preset slots are never on it), innermost last, and
/// a frame's `mark` is its length before that frame's atom bound anything;
/// `chosen[i]` is the fact of atom `i` in the current match.
///
/// A cursor owns no relation and no body: each call of [`Cursor::next`]
/// lends them, so a cursor can live in a search task that shares its
/// relations with others (what [`join`] does), or borrow a model's.
#[derive(Debug)]
pub struct Cursor {
    // Inline up to eight atoms and slots: a query's join is small, and a
    // cursor is built per query (the heap allocations were a quarter of a
    // short query's time).
    order: SmallVec<[usize; 8]>,
    ranges: SmallVec<[(FactId, FactId); 8]>,
    binds: SmallVec<[Option<Term>; 8]>,
    chosen: SmallVec<[FactId; 8]>,
    trail: SmallVec<[usize; 8]>,
    frames: SmallVec<[Frame; 4]>,
    neg: SmallVec<[Term; 4]>,
    /// `exact[d]`: every argument of atom `order[d]` is bound when its turn
    /// comes (set when the join starts, once presets are known).
    exact: SmallVec<[bool; 8]>,
    started: bool,
}

impl Cursor {
    /// A cursor over `slots` slots, visiting the atoms in `order`, atom `i`
    /// within the fact ids `ranges[i]` (a semi-naive delta; `0..len` for
    /// every fact).
    pub fn new(slots: usize, order: &[usize], ranges: &[(FactId, FactId)]) -> Cursor {
        Cursor {
            order: order.into(),
            ranges: ranges.into(),
            binds: smallvec::smallvec![None; slots],
            chosen: smallvec::smallvec![0; ranges.len()],
            trail: SmallVec::new(),
            frames: SmallVec::new(),
            neg: SmallVec::new(),
            exact: SmallVec::new(),
            started: false,
        }
    }

    /// Binds slot `v` before the join starts (an argument known from the
    /// outside); the join never unbinds it.
    pub fn preset(&mut self, v: usize, value: Term) {
        if let Some(slot) = self.binds.get_mut(v) {
            *slot = Some(value);
        }
    }

    /// The slots' values in the current match.
    pub fn binds(&self) -> &[Option<Term>] {
        &self.binds
    }

    /// The fact id of each atom (in body order) in the current match.
    pub fn chosen(&self) -> &[FactId] {
        &self.chosen
    }

    /// Advances to the next match of `body` over `rels` (the same for every
    /// call). `step` is asked before each candidate fact is tried; when it
    /// says false the cursor returns [`Next::Paused`] and resumes there.
    pub fn next<R: Borrow<Relation>>(
        &mut self,
        rels: &[R],
        body: Body<'_>,
        step: &mut impl FnMut() -> bool,
    ) -> Next {
        if !self.started {
            self.started = true;
            self.exact = self.exact_turns(body);
            if self.order.is_empty() {
                return if self.filters_hold(rels, body) {
                    Next::Found
                } else {
                    Next::Done
                };
            }
            match self.descend(rels, body, 0) {
                Descend::Match if self.filters_hold(rels, body) => return Next::Found,
                Descend::Match | Descend::Fail => return Next::Done,
                Descend::Opened => {}
            }
        }
        loop {
            let Some(frame) = self.frames.last_mut() else {
                return Next::Done;
            };
            // Undo what the previous candidate of this atom bound.
            for v in self.trail.drain(frame.mark..) {
                if let Some(slot) = self.binds.get_mut(v) {
                    *slot = None;
                }
            }
            if !step() {
                return Next::Paused;
            }
            let depth = frame.depth;
            let Some(&ai) = self.order.get(depth) else {
                return Next::Done;
            };
            let (Some(atom), Some(rel)) = (
                body.atoms.get(ai),
                body.atoms
                    .get(ai)
                    .and_then(|a| rels.get(a.pred))
                    .map(Borrow::borrow),
            ) else {
                return Next::Done;
            };
            let Some((id, args)) = rel.candidate_args(&frame.cands, frame.next) else {
                self.frames.pop();
                continue;
            };
            frame.next += 1;
            let bound = match args {
                CandArgs::Stored(t) => bind_args(atom, t, &mut self.binds, &mut self.trail),
                CandArgs::Pair(p) => bind_args(atom, p, &mut self.binds, &mut self.trail),
            };
            if !bound {
                continue;
            }
            if let Some(c) = self.chosen.get_mut(ai) {
                *c = id;
            }
            match self.descend(rels, body, depth + 1) {
                Descend::Match if self.filters_hold(rels, body) => return Next::Found,
                Descend::Match | Descend::Fail | Descend::Opened => {}
            }
        }
    }

    /// Which atoms are fully bound when their turn comes: by the presets
    /// or by the atoms before them in the order.
    fn exact_turns(&self, body: Body<'_>) -> SmallVec<[bool; 8]> {
        let mut bound: SmallVec<[bool; 16]> = self.binds.iter().map(Option::is_some).collect();
        let mut exact = SmallVec::with_capacity(self.order.len());
        for &ai in &self.order {
            let args = body.atoms.get(ai).map_or(&[][..], |a| &a.args[..]);
            exact.push(args.iter().all(|a| match a {
                Arg::Var(v) => bound.get(*v).copied().unwrap_or(false),
                Arg::Const(_) => true,
            }));
            for a in args {
                if let Arg::Var(v) = a
                    && let Some(b) = bound.get_mut(*v)
                {
                    *b = true;
                }
            }
        }
        exact
    }

    /// Goes on from the atom at `depth` of the order: each fully bound
    /// atom is probed inline (its one fact chosen), until the order ends
    /// ([`Descend::Match`]) or an atom with an unbound argument gets a
    /// frame ([`Descend::Opened`]).
    ///
    /// Why inline: a fully bound atom is a membership test, and a frame per
    /// test (candidates built, pushed, popped) was most of the cost of the
    /// joins that end in one (`…^NotDistanceDecrease(x, y)`).
    fn descend<R: Borrow<Relation>>(
        &mut self,
        rels: &[R],
        body: Body<'_>,
        mut depth: usize,
    ) -> Descend {
        while self.exact.get(depth).copied().unwrap_or(false) {
            let Some(&ai) = self.order.get(depth) else {
                return Descend::Fail;
            };
            let Some(atom) = body.atoms.get(ai) else {
                return Descend::Fail;
            };
            let Some(rel) = rels.get(atom.pred).map(Borrow::borrow) else {
                return Descend::Fail;
            };
            let (lo, hi) = self.ranges.get(ai).copied().unwrap_or((0, 0));
            let found = with_pattern(atom, &self.binds, |pat| rel.exact_id(pat, lo, hi));
            match (found, self.chosen.get_mut(ai)) {
                (Some(id), Some(c)) => *c = id,
                _ => return Descend::Fail,
            }
            depth += 1;
        }
        if depth >= self.order.len() {
            return Descend::Match;
        }
        match self.open_frame(rels, body, depth) {
            Some(f) => {
                self.frames.push(f);
                Descend::Opened
            }
            None => Descend::Fail,
        }
    }

    /// The frame of atom `order[depth]` under the current bindings: an
    /// index probe for its bound arguments, cut to the atom's id range.
    /// `None` when the atom or its relation is missing.
    fn open_frame<R: Borrow<Relation>>(
        &self,
        rels: &[R],
        body: Body<'_>,
        depth: usize,
    ) -> Option<Frame> {
        let ai = *self.order.get(depth)?;
        let atom = body.atoms.get(ai)?;
        let rel: &Relation = rels.get(atom.pred)?.borrow();
        let (lo, hi) = self.ranges.get(ai).copied().unwrap_or((0, 0));
        Some(Frame {
            depth,
            cands: with_pattern(atom, &self.binds, |pat| rel.cands(pat, lo, hi)),
            next: 0,
            mark: self.trail.len(),
        })
    }

    /// Whether the comparisons hold and no negated atom does, under
    /// complete bindings.
    fn filters_hold<R: Borrow<Relation>>(&mut self, rels: &[R], body: Body<'_>) -> bool {
        for (l, r, negated) in body.cmps {
            let (Some(a), Some(b)) = (arg_value(l, &self.binds), arg_value(r, &self.binds)) else {
                return false;
            };
            if (a == b) == *negated {
                return false;
            }
        }
        for n in body.negated {
            self.neg.clear();
            for a in &n.args {
                match arg_value(a, &self.binds) {
                    Some(t) => self.neg.push(t.clone()),
                    None => return false,
                }
            }
            if rels
                .get(n.pred)
                .is_some_and(|r| r.borrow().contains(&self.neg))
            {
                return false;
            }
        }
        true
    }
}

/// Calls `f` with the lookup pattern of `atom` under `binds` (each
/// argument's value, `None` for an unbound slot); small arities keep the
/// pattern on the stack.
#[inline]
fn with_pattern<T>(
    atom: &Atom,
    binds: &[Option<Term>],
    f: impl FnOnce(&[Option<&Term>]) -> T,
) -> T {
    let mut small: [Option<&Term>; 4] = [None; 4];
    if atom.args.len() <= small.len() {
        for (slot, a) in small.iter_mut().zip(&atom.args) {
            *slot = arg_value(a, binds);
        }
        f(small.get(..atom.args.len()).unwrap_or(&[]))
    } else {
        let big: Vec<Option<&Term>> = atom.args.iter().map(|a| arg_value(a, binds)).collect();
        f(&big)
    }
}

/// Binds the atom's slots to a candidate fact's arguments, checking
/// constants and slots bound earlier (or earlier in the same atom). On
/// failure the bindings it made stay on the trail, for the caller's undo.
#[inline(always)]
fn bind_args<'t>(
    atom: &Atom,
    args: impl IntoIterator<Item = &'t Term>,
    binds: &mut [Option<Term>],
    trail: &mut SmallVec<[usize; 8]>,
) -> bool {
    for (a, t) in atom.args.iter().zip(args) {
        match a {
            Arg::Const(c) => {
                if !same_term(c, t) {
                    return false;
                }
            }
            Arg::Var(v) => match binds.get_mut(*v) {
                Some(Some(b)) => {
                    if !same_term(b, t) {
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

/// The join order of `atoms`: the atom at `first` (if any), then
/// repeatedly the atom with the most bound arguments — connected atoms
/// (an index lookup) before cross products, then the fewest unbound
/// arguments, then the smallest relation. `bound[v]` says which slots are
/// bound before the join starts (missing entries: unbound).
pub fn plan<R: Borrow<Relation>>(
    atoms: &[Atom],
    rels: &[R],
    first: Option<usize>,
    bound: &[bool],
) -> SmallVec<[usize; 8]> {
    let n = atoms.len();
    let nslots = atoms
        .iter()
        .flat_map(|a| &a.args)
        .filter_map(|a| match a {
            Arg::Var(v) => Some(v + 1),
            Arg::Const(_) => None,
        })
        .max()
        .unwrap_or(0)
        .max(bound.len());
    let mut is_bound: SmallVec<[bool; 16]> = smallvec::smallvec![false; nslots];
    for (b, &given) in is_bound.iter_mut().zip(bound) {
        *b = given;
    }
    let mut order: SmallVec<[usize; 8]> = SmallVec::with_capacity(n);
    let mut used: SmallVec<[bool; 8]> = smallvec::smallvec![false; n];
    let take = |i: usize,
                is_bound: &mut SmallVec<[bool; 16]>,
                order: &mut SmallVec<[usize; 8]>,
                used: &mut SmallVec<[bool; 8]>| {
        if let Some(u) = used.get_mut(i) {
            *u = true;
        }
        order.push(i);
        for a in atoms.get(i).map_or(&[][..], |a| &a.args) {
            if let Arg::Var(v) = a
                && let Some(b) = is_bound.get_mut(*v)
            {
                *b = true;
            }
        }
    };
    if let Some(f) = first.filter(|&f| f < n) {
        take(f, &mut is_bound, &mut order, &mut used);
    }
    let any_preset = bound.iter().any(|&b| b);
    while order.len() < n {
        let mut best: Option<(bool, usize, usize, usize)> = None;
        for (i, atom) in atoms.iter().enumerate() {
            if used.get(i).copied().unwrap_or(true) {
                continue;
            }
            let unbound = atom
                .args
                .iter()
                .filter(|a| matches!(a, Arg::Var(v) if !is_bound.get(*v).copied().unwrap_or(false)))
                .count();
            let disconnected =
                (!order.is_empty() || any_preset) && unbound == atom.args.len() && unbound > 0;
            let size = rels.get(atom.pred).map_or(0, |r| r.borrow().len());
            let key = (disconnected, unbound, size, i);
            if best.is_none_or(|b| key < b) {
                best = Some(key);
            }
        }
        let Some((_, _, _, i)) = best else { break };
        take(i, &mut is_bound, &mut order, &mut used);
    }
    order
}

/// The generator of a [`join`] goal.
pub(crate) struct JoinScan {
    rels: Arc<[Arc<Relation>]>,
    atoms: Arc<[Atom]>,
    negated: Arc<[Atom]>,
    cmps: Arc<[Cmp]>,
    terms: Arc<[Term]>,
    /// The slots that were unbound when the goal ran: each match unifies
    /// their terms with its values.
    free: smallvec::SmallVec<[usize; 8]>,
    cursor: Cursor,
    state: State,
}

/// How many candidates one turn of a join may try before it yields control
/// (bounds the work between two looks at other branches).
const JOIN_CHUNK: usize = 256;

impl Generator for JoinScan {
    fn next(&mut self, ctx: &Ctx) -> GenStep {
        if ctx.halted.get().is_some() {
            return GenStep::Done;
        }
        if ctx.count_tail.get() {
            return self.count(ctx);
        }
        loop {
            // The candidates are counted against the budget per turn, not
            // one by one: the count is the same, and the check stays out of
            // the join's inner loop.
            let mut tried = 0usize;
            let mut step = || {
                tried += 1;
                tried <= JOIN_CHUNK
            };
            let next = self.advance(&mut step);
            let within = ctx.tick_n(tried.min(JOIN_CHUNK) as u64);
            match next {
                Next::Done => return GenStep::Done,
                Next::Paused => {
                    return if within { GenStep::More } else { GenStep::Done };
                }
                Next::Found if !within => return GenStep::Done,
                Next::Found => {
                    let Some(mut st) = self.match_state() else {
                        continue;
                    };
                    if ctx.proofs {
                        for (atom, &id) in self.atoms.iter().zip(self.cursor.chosen()) {
                            if let Some(rel) = self.rels.get(atom.pred) {
                                st.record(ProofStep::Fact {
                                    relation: rel.name(),
                                    id,
                                });
                            }
                        }
                    }
                    return GenStep::Yield(st, None, true);
                }
            }
        }
    }
}

impl JoinScan {
    /// One turn of a join whose matches are only counted (nothing follows
    /// it and the run counts): matches are counted, no state is built.
    /// A match must still bind its free terms consistently (two slots may
    /// be the same kanren variable), so that check stays.
    fn count(&mut self, ctx: &Ctx) -> GenStep {
        let mut tried = 0usize;
        let mut found = 0u64;
        let aliased = self.aliased();
        loop {
            let mut step = || {
                tried += 1;
                tried <= JOIN_CHUNK
            };
            let next = self.advance(&mut step);
            match next {
                Next::Found => {
                    if !aliased || self.consistent() {
                        found += 1;
                    }
                }
                Next::Paused | Next::Done => {
                    let within = ctx.tick_n(tried.min(JOIN_CHUNK) as u64);
                    let more = next == Next::Paused && within;
                    return GenStep::Counted(found, more);
                }
            }
        }
    }

    /// Whether two free slots share a kanren variable, or a free slot's
    /// term carries constraints: then a match must be unified to count.
    fn aliased(&self) -> bool {
        !self.state.store.is_empty()
            || self.free.iter().enumerate().any(|(i, &a)| {
                self.free.iter().skip(i + 1).any(|&b| {
                    match (self.terms.get(a), self.terms.get(b)) {
                        (Some(x), Some(y)) => self.state.subst.walk(x) == self.state.subst.walk(y),
                        _ => false,
                    }
                })
            })
    }

    /// Whether the current match unifies with the free slots' terms.
    fn consistent(&self) -> bool {
        self.match_state().is_some()
    }

    /// The next match of the join's atoms, negations and comparisons.
    fn advance(&mut self, step: &mut impl FnMut() -> bool) -> Next {
        self.cursor.next(
            &self.rels,
            Body {
                atoms: &self.atoms,
                negated: &self.negated,
                cmps: &self.cmps,
            },
            step,
        )
    }

    /// The goal's state extended with the current match: each free slot's
    /// term unified with its value (`None` when they do not unify, or a
    /// constraint on them fails).
    fn match_state(&self) -> Option<State> {
        let mut pending = crate::subst::Pending::new();
        let binds = self.cursor.binds();
        let ok = self.free.iter().all(|&v| {
            match (self.terms.get(v), binds.get(v).and_then(Option::as_ref)) {
                (Some(t), Some(value)) => {
                    self.state
                        .subst
                        .unify_pending(t, value, false, &mut pending)
                }
                // A slot that no atom mentions stays unbound.
                _ => true,
            }
        });
        if !ok {
            return None;
        }
        self.state.clone().extended(&pending, false)
    }
}

/// The conjunction of `fact(rels[a.pred], a.args)` over `atoms`, run as one
/// indexed join: slot `v` of the atoms is the term `terms[v]`. Answers are
/// the conjunction's (each match once, in the join's order), and with
/// proofs on each records one [`ProofStep::Fact`] per atom, in the atoms'
/// order. The join is planned when the goal runs, from the slots whose
/// terms are bound then; a slot whose term is a list or compound fails (facts hold
/// atoms only), as does an atom whose relation index or arity is wrong.
pub fn join(rels: Arc<[Arc<Relation>]>, atoms: Arc<[Atom]>, terms: Arc<[Term]>) -> Goal {
    join_where(rels, atoms, Arc::from([]), Arc::from([]), terms)
}

/// [`join`] of `atoms`, then `naf(fact(rels[n.pred], n.args))` for each
/// atom `n` of `negated` and `a = b` / `a =/= b` for each comparison of
/// `cmps`, all inside the join: every slot of `negated` and `cmps` must
/// occur in `atoms` (so these are tests of bound values, as the rules of a
/// safe Datalog program are), and a match that fails one is not yielded.
/// Answers and proofs are those of the conjunction written out with
/// [`crate::naf`], [`crate::eq`] and [`crate::neq`]; it costs one lookup per
/// negated atom and no kanren state per failed match.
pub fn join_where(
    rels: Arc<[Arc<Relation>]>,
    atoms: Arc<[Atom]>,
    negated: Arc<[Atom]>,
    cmps: Arc<[Cmp]>,
    terms: Arc<[Term]>,
) -> Goal {
    crate::goal::goal_fn(move |_ctx, st| {
        let valid = atoms.iter().all(|a| {
            rels.get(a.pred).is_some_and(|r| r.arity() == a.args.len())
                && a.args
                    .iter()
                    .all(|x| !matches!(x, Arg::Var(v) if *v >= terms.len()))
        });
        if !valid {
            return Out::Fail;
        }
        let ranges: SmallVec<[(FactId, FactId); 8]> = atoms
            .iter()
            .map(|a| {
                let len = rels.get(a.pred).map_or(0, |r| r.len());
                (0, FactId::try_from(len).unwrap_or(FactId::MAX))
            })
            .collect();
        if ranges.iter().any(|&(lo, hi)| lo >= hi) {
            return Out::Fail; // an empty relation: no match
        }
        let mut presets: smallvec::SmallVec<[(usize, Term); 8]> = smallvec::SmallVec::new();
        let mut free = smallvec::SmallVec::new();
        for (v, t) in terms.iter().enumerate() {
            match st.subst.walk(t) {
                Term::Var(_) => free.push(v),
                Term::Cons(..) | Term::App(..) => return Out::Fail,
                value => presets.push((v, value.clone())),
            }
        }
        let mut bound: SmallVec<[bool; 16]> = smallvec::smallvec![false; terms.len()];
        for (v, _) in &presets {
            if let Some(b) = bound.get_mut(*v) {
                *b = true;
            }
        }
        let order = plan(&atoms, &rels, None, &bound);
        let mut cursor = Cursor::new(terms.len(), &order, &ranges);
        for (v, value) in presets {
            cursor.preset(v, value);
        }
        Out::Gen(Box::new(JoinScan {
            rels: rels.clone(),
            atoms: atoms.clone(),
            negated: negated.clone(),
            cmps: cmps.clone(),
            terms: terms.clone(),
            free,
            cursor,
            state: st,
        }))
    })
}

#[cfg(test)]
mod tests;
