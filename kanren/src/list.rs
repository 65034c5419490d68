//! The core's list goals: `membero`/`nextto` over the part of a list that
//! is already built, walked cell by cell (one unification per element, a
//! failed one allocating nothing), continuing relationally where the list
//! ends in a variable. A store-layer module: a [`ListGoal`] is a
//! [`Native`] goal whose scan (a [`Scan`] of the list) the engine keeps and
//! lends the goal to at every step; [`crate::classic`] only builds the
//! goals.

use crate::ctx::{Ctx, GenStep, Scan};
use crate::engine::NativeOut;
use crate::goal::{Goal, Native, conj, disj, eq, fresh};
use crate::state::State;
use crate::term::{ListPos, Term};

/// What a list scan looks for.
pub(crate) enum ListKind {
    Member(Pattern),
    NextTo(Pattern, Pattern),
}

/// A term a list scan matches candidates against, with the argument
/// positions that hold atoms (when it is a compound term): the clash
/// filter looks at those positions only, found once when the goal is
/// made instead of by a test of every argument for every candidate.
pub(crate) struct Pattern {
    term: Term,
    /// Bit `i` is set when argument `i` (below 64) is an atom.
    atoms: u64,
}

impl Pattern {
    pub(crate) fn new(term: Term) -> Pattern {
        let atoms = match &term {
            Term::App(_, args) => args
                .iter()
                .take(64)
                .enumerate()
                .filter(|(_, a)| a.is_atomic())
                .fold(0, |m, (i, _)| m | 1u64 << i),
            _ => 0,
        };
        Pattern { term, atoms }
    }
}

/// A [`membero`](crate::classic::membero) or [`nextto`](crate::classic::nextto) goal: what to look for, and in which list.
pub(crate) struct ListGoal {
    pub(crate) kind: ListKind,
    pub(crate) list: Term,
}

impl Native for ListGoal {
    fn name(&self) -> &'static str {
        match self.kind {
            ListKind::Member(_) => "membero",
            ListKind::NextTo(..) => "nextto",
        }
    }

    /// A scan of the list from its start, and its first step (on the
    /// engine's stack: the engine boxes the scan only if it has more).
    fn run(&self, ctx: &Ctx, st: State) -> NativeOut {
        let mut scan = Scan {
            rest: self.list.clone(),
            state: st,
        };
        let first = scan_step(&mut scan, ctx, &self.kind);
        NativeOut::Scan(scan, first)
    }

    fn resume(&self, ctx: &Ctx, scan: &mut Scan) -> GenStep {
        scan_step(scan, ctx, &self.kind)
    }
}

/// Positions one step may pass over without an answer (bounds the work
/// between two budget checks).
const LIST_CHUNK: usize = 64;

/// True when `pattern` and `cand` cannot unify because they are compound
/// terms of different shapes or one argument position holds two different
/// atoms. A filter with no bindings and no buffer, run before the full
/// unification: most candidates of a scan over compound terms fail this
/// way, and then cost a few lookups, not a unification.
#[inline]
fn clashes(st: &State, pattern: &Pattern, cand: &Term) -> bool {
    let Term::App(f, ps) = &pattern.term else {
        return clashes_walked(st, st.subst.walk(&pattern.term), cand);
    };
    let Term::App(g, cs) = st.subst.walk(cand) else {
        return false;
    };
    if f != g || ps.len() != cs.len() {
        return true;
    }
    let mut bits = pattern.atoms;
    while bits != 0 {
        let i = bits.trailing_zeros() as usize;
        bits &= bits - 1;
        if let (Some(p), Some(c)) = (ps.get(i), cs.get(i))
            && atoms_clash(p, st.subst.walk(c))
        {
            return true;
        }
    }
    ps.len() > 64 && args_clash(st, &ps[64..], &cs[64..])
}

/// [`clashes`] for a pattern that is not itself a compound term (a
/// variable, perhaps bound to one): every argument is looked at.
fn clashes_walked(st: &State, pattern: &Term, cand: &Term) -> bool {
    let (Term::App(f, ps), Term::App(g, cs)) = (pattern, st.subst.walk(cand)) else {
        return false;
    };
    if f != g || ps.len() != cs.len() {
        return true;
    }
    args_clash(st, ps, cs)
}

/// True when some position holds an atom in `ps` and a different atom in
/// `cs` (walked).
fn args_clash(st: &State, ps: &[Term], cs: &[Term]) -> bool {
    ps.iter()
        .zip(cs.iter())
        .any(|(p, c)| p.is_atomic() && atoms_clash(p, st.subst.walk(c)))
}

/// True when the atom `p` and the walked `c` are two different atoms.
#[inline]
fn atoms_clash(p: &Term, c: &Term) -> bool {
    match (p, c) {
        (Term::Sym(s), Term::Sym(t)) => s != t,
        _ => c.is_atomic() && c != p,
    }
}

/// What follows a list cell, for `nextto`.
enum After<'a> {
    /// The next cell's head, and whether that cell is the list's last.
    Cell(&'a Term, bool),
    /// An unbound tail.
    Open,
    /// No next cell.
    End,
}

/// The generator behind [`membero`](crate::classic::membero) and
/// [`nextto`](crate::classic::nextto): one list position per step. The scan
/// holds no copy of its goal: every step is lent the goal's [`ListKind`] by
/// the engine, which keeps the goal where it lies.
///
/// One step: the candidates at the scan's position. `rest` is kept a
/// list cell itself (not a variable bound to one) while the scan is in
/// a block, so moving to the next cell of the block is an index bump,
/// with no reference count touched.
#[inline]
fn scan_step(scan: &mut Scan, ctx: &Ctx, kind: &ListKind) -> GenStep {
    let Scan { rest, state } = scan;
    let pending = &mut *ctx.pending.borrow_mut();
    for _ in 0..LIST_CHUNK {
        if !matches!(rest, Term::Cons(..)) {
            let walked = state.subst.walk(rest);
            match walked {
                Term::Cons(..) => *rest = walked.clone(),
                Term::Var(_) => {
                    let cur = walked.clone();
                    // An open tail: the relational definition enumerates
                    // the lists it could be, lazily.
                    let g = match kind {
                        ListKind::Member(x) => membero_rel(x.term.clone(), cur),
                        ListKind::NextTo(a, b) => nextto_rel(a.term.clone(), b.term.clone(), cur),
                    };
                    return GenStep::Yield(state.clone(), Some(g), false);
                }
                _ => return GenStep::Done,
            }
        }
        let Term::Cons(block, pos) = &*rest else {
            return GenStep::Done;
        };
        let (o, e) = (pos.index(block), block.tail_index());
        let block = block.slots();
        let (Some(head), Some(tail)) = (block.get(o), block.get(e)) else {
            return GenStep::Done;
        };
        let found = match kind {
            ListKind::Member(x) => {
                if clashes(state, x, head) {
                    None
                } else {
                    // The next candidate of this block that does not
                    // clash: the ones between would fail, so the scan
                    // skips them — and when there is none and the list
                    // ends here, this candidate is the scan's last.
                    let next = (o + 1..e).find(|&k| !clashes(state, x, &block[k]));
                    if next.is_none() && matches!(state.subst.walk(tail), Term::Nil) {
                        // The last candidate: its state moves instead of
                        // being copied (trie nodes it alone holds are
                        // then updated in place).
                        let st = std::mem::replace(state, State::new(0));
                        let out = st.unify_buf(&x.term, head, ctx.occurs_check, pending);
                        *rest = Term::Nil;
                        return match out {
                            Some(st) => GenStep::Yield(st, None, false),
                            None => GenStep::Done,
                        };
                    }
                    let found = state.unified_buf(&x.term, head, ctx.occurs_check, pending);
                    match next {
                        Some(k) => {
                            if let Term::Cons(_, pos) = rest {
                                *pos = ListPos::at(k);
                            }
                        }
                        None => *rest = tail.clone(),
                    }
                    if let Some(st) = found {
                        return GenStep::Yield(st, None, true);
                    }
                    continue;
                }
            }
            ListKind::NextTo(a, b) => {
                let after = if o + 1 < e {
                    let last = o + 2 >= e && matches!(state.subst.walk(tail), Term::Nil);
                    After::Cell(&block[o + 1], last)
                } else {
                    let next = state.subst.walk(tail);
                    match next.cells() {
                        Some((items, t)) => match items.first() {
                            Some(h) => After::Cell(
                                h,
                                items.len() == 1 && matches!(state.subst.walk(t), Term::Nil),
                            ),
                            None => After::End,
                        },
                        None if matches!(next, Term::Var(_)) => After::Open,
                        None => After::End,
                    }
                };
                match after {
                    // Both unifications into one pending buffer: when the
                    // second fails, no state has been copied.
                    After::Cell(next_head, _)
                        if clashes(state, a, head) || clashes(state, b, next_head) =>
                    {
                        None
                    }
                    After::Cell(next_head, last) => {
                        if !pending.is_empty() {
                            pending.clear();
                        }
                        let subst = &state.subst;
                        if !(subst.unify_pending(&a.term, head, ctx.occurs_check, pending)
                            && subst.unify_pending(&b.term, next_head, ctx.occurs_check, pending))
                        {
                            None
                        } else {
                            // The next pair of this block that does not
                            // clash (see Member); none, and the list
                            // ending with this block, makes this pair the
                            // scan's last.
                            let next = if last {
                                None
                            } else {
                                (o + 1..e.saturating_sub(1)).find(|&k| {
                                    !clashes(state, a, &block[k])
                                        && !clashes(state, b, &block[k + 1])
                                })
                            };
                            if last
                                || (next.is_none() && matches!(state.subst.walk(tail), Term::Nil))
                            {
                                // The last pair: move the state.
                                let st = std::mem::replace(state, State::new(0));
                                *rest = Term::Nil;
                                return match st.extended(pending, ctx.occurs_check) {
                                    Some(st) => GenStep::Yield(st, None, false),
                                    None => GenStep::Done,
                                };
                            }
                            let found = state.fork().extended(pending, ctx.occurs_check);
                            // Skip the clashing pairs; a pair that may
                            // cross into the next block starts at e - 1.
                            let target = next.unwrap_or(e - 1).max(o + 1);
                            if target < e {
                                if let Term::Cons(_, pos) = rest {
                                    *pos = ListPos::at(target);
                                }
                            } else {
                                *rest = tail.clone();
                            }
                            if let Some(st) = found {
                                return GenStep::Yield(st, None, true);
                            }
                            continue;
                        }
                    }
                    After::Open => {
                        let g = nextto_rel(a.term.clone(), b.term.clone(), rest.clone());
                        return GenStep::Yield(state.clone(), Some(g), false);
                    }
                    After::End => return GenStep::Done,
                }
            }
        };
        // Move to the next cell: within the block, a position bump.
        if o + 1 < e {
            if let Term::Cons(_, pos) = rest {
                pos.step();
            }
        } else {
            *rest = tail.clone();
        }
        if let Some(st) = found {
            return GenStep::Yield(st, None, true);
        }
    }
    GenStep::More
}

/// `x` is an element of the list `l` — the textbook relational definition
/// (two fresh variables and a disjunction per element). [`membero`](crate::classic::membero) gives the
/// same answers in the same order, faster.
pub fn membero_rel(x: Term, l: Term) -> Goal {
    disj([
        fresh({
            let (x, l) = (x.clone(), l.clone());
            move |[d]| eq(l.clone(), Term::cons(x.clone(), d))
        }),
        fresh(move |[a, d]| {
            conj([
                eq(l.clone(), Term::cons(a, d.clone())),
                membero_rel(x.clone(), d),
            ])
        }),
    ])
}

/// `a` is immediately followed by `b` in `l` (Prolog's `nextto/3`) — the
/// textbook relational definition; [`nextto`](crate::classic::nextto) gives the same answers faster.
pub fn nextto_rel(a: Term, b: Term, l: Term) -> Goal {
    disj([
        fresh({
            let (a, b, l) = (a.clone(), b.clone(), l.clone());
            move |[rest]| {
                eq(
                    l.clone(),
                    Term::cons(a.clone(), Term::cons(b.clone(), rest)),
                )
            }
        }),
        fresh(move |[h, t]| {
            conj([
                eq(l.clone(), Term::cons(h, t.clone())),
                nextto_rel(a.clone(), b.clone(), t),
            ])
        }),
    ])
}
