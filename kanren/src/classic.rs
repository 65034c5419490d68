//! Classic relations from the miniKanren literature, ready to use (and used
//! by the tests, examples and benchmarks).

use crate::engine::{Ctx, GenStep};
use crate::goal::{G, Goal, conj, disj, eq, fresh};
use crate::state::State;
use crate::term::{ListPos, Term, sym};
use std::sync::Arc;

/// `out` is `l` followed by `s`.
pub fn appendo(l: Term, s: Term, out: Term) -> Goal {
    disj([
        conj([eq(l.clone(), Term::Nil), eq(s.clone(), out.clone())]),
        fresh(move |[a, d, res]| {
            conj([
                eq(l.clone(), Term::cons(a.clone(), d.clone())),
                eq(out.clone(), Term::cons(a, res.clone())),
                appendo(d, s.clone(), res),
            ])
        }),
    ])
}

/// `x` is an element of the list `l` — the textbook relational definition
/// (two fresh variables and a disjunction per element). [`membero`] gives the
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

/// `out` is `l` with one occurrence of `x` removed — or `l` itself (The
/// Reasoned Schemer, 2nd ed., frame 2:… `rembero`).
pub fn rembero(x: Term, l: Term, out: Term) -> Goal {
    disj([
        conj([eq(l.clone(), Term::Nil), eq(out.clone(), Term::Nil)]),
        eq(l.clone(), Term::cons(x.clone(), out.clone())),
        fresh(move |[a, d, res]| {
            conj([
                eq(l.clone(), Term::cons(a.clone(), d.clone())),
                eq(out.clone(), Term::cons(a, res.clone())),
                rembero(x.clone(), d, res),
            ])
        }),
    ])
}

/// The Peano numeral for `n`: `z`, `s(z)`, `s(s(z))`, …
pub fn peano(n: u32) -> Term {
    (0..n).fold(sym("z"), |acc, _| Term::app("s", [acc]))
}

/// Peano addition: `n + m = k`.
pub fn pluso(n: Term, m: Term, k: Term) -> Goal {
    disj([
        conj([eq(n.clone(), sym("z")), eq(m.clone(), k.clone())]),
        fresh(move |[n1, k1]| {
            conj([
                eq(n.clone(), Term::app("s", [n1.clone()])),
                eq(k.clone(), Term::app("s", [k1.clone()])),
                pluso(n1, m.clone(), k1),
            ])
        }),
    ])
}

/// `a` is immediately followed by `b` in `l` (Prolog's `nextto/3`) — the
/// textbook relational definition; [`nextto`] gives the same answers faster.
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

/// `x` is an element of the list `l`.
///
/// Same answers, in the same order, as the relational [`membero_rel`], but
/// over the part of `l` that is already a list it walks the cells directly,
/// trying one unification per element (a failed one allocates nothing);
/// where the list ends in an unbound variable it continues relationally.
pub fn membero(x: Term, l: Term) -> Goal {
    Goal(G::List(Arc::new(ListGoal {
        kind: ListKind::Member(Pattern::new(x)),
        list: l,
    })))
}

/// `a` is immediately followed by `b` in `l`: the answers of [`nextto_rel`],
/// walking the known part of the list directly like [`membero`].
pub fn nextto(a: Term, b: Term, l: Term) -> Goal {
    Goal(G::List(Arc::new(ListGoal {
        kind: ListKind::NextTo(Pattern::new(a), Pattern::new(b)),
        list: l,
    })))
}

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
    fn new(term: Term) -> Pattern {
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

/// A [`membero`] or [`nextto`] goal: what to look for, and in which list.
pub(crate) struct ListGoal {
    pub(crate) kind: ListKind,
    pub(crate) list: Term,
}

impl ListGoal {
    pub(crate) fn name(&self) -> &'static str {
        match self.kind {
            ListKind::Member(_) => "membero",
            ListKind::NextTo(..) => "nextto",
        }
    }
}

/// The generator behind [`membero`] and [`nextto`]: one list position per
/// step. It holds no copy of its goal: every step is lent the goal's
/// [`ListKind`] by the engine, which keeps the goal where it lies.
pub(crate) struct ListScan {
    rest: Term,
    state: State,
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

impl ListScan {
    /// A scan of `list` from its start, on `state`.
    pub(crate) fn new(list: &Term, state: State) -> ListScan {
        ListScan {
            rest: list.clone(),
            state,
        }
    }

    /// One step: the candidates at the scan's position. `rest` is kept a
    /// list cell itself (not a variable bound to one) while the scan is in
    /// a block, so moving to the next cell of the block is an index bump,
    /// with no reference count touched.
    pub(crate) fn next(&mut self, ctx: &Ctx, kind: &ListKind) -> GenStep {
        let ListScan { rest, state } = self;
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
                            ListKind::NextTo(a, b) => {
                                nextto_rel(a.term.clone(), b.term.clone(), cur)
                            }
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
                                && subst.unify_pending(
                                    &b.term,
                                    next_head,
                                    ctx.occurs_check,
                                    pending,
                                ))
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
                                    || (next.is_none()
                                        && matches!(state.subst.walk(tail), Term::Nil))
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
}

/// `a` and `b` are neighbours in `l`, in either order.
pub fn next_to(a: Term, b: Term, l: Term) -> Goal {
    disj([nextto(a.clone(), b.clone(), l.clone()), nextto(b, a, l)])
}

/// Anonymous variables handed out one by one (Prolog's `_`).
struct Anon(std::vec::IntoIter<Term>);

impl Anon {
    fn next(&mut self) -> Term {
        self.0.next().unwrap_or(Term::Nil)
    }

    /// A house `h(Color, Nationality, Pet, Drink, Smoke)`; `""` is `_`.
    fn house(&mut self, slots: [&str; 5]) -> Term {
        Term::app(
            "h",
            slots.map(|s| if s.is_empty() { self.next() } else { sym(s) }),
        )
    }
}

/// The number of `_` in the puzzle below.
const ZEBRA_ANON: usize = 75;

/// The zebra puzzle (five houses), in the classic member/nextto formulation
/// and constraint order of `shared/bench/zebra.pl`: `hs` is the list of the
/// five houses `h(Color, Nationality, Pet, Drink, Smoke)`.
pub fn zebrao(hs: Term) -> Goal {
    zebra_with(hs, membero, nextto)
}

/// [`zebrao`] with the textbook relational [`membero_rel`] and [`nextto_rel`].
pub fn zebrao_rel(hs: Term) -> Goal {
    zebra_with(hs, membero_rel, nextto_rel)
}

fn zebra_with(
    hs: Term,
    membero: fn(Term, Term) -> Goal,
    nextto: fn(Term, Term, Term) -> Goal,
) -> Goal {
    let next_to = move |a: Term, b: Term, l: Term| {
        disj([nextto(a.clone(), b.clone(), l.clone()), nextto(b, a, l)])
    };
    fresh(move |vars: [Term; ZEBRA_ANON]| {
        let mut a = Anon(Vec::from(vars).into_iter());
        let houses = Term::list([
            a.house(["", "norwegian", "", "", ""]),
            a.next(),
            a.house(["", "", "", "milk", ""]),
            a.next(),
            a.next(),
        ]);
        let hs = hs.clone();
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g1 = member(["red", "english", "", "", ""]);
        let g2 = member(["", "spanish", "dog", "", ""]);
        let g3 = member(["green", "", "", "coffee", ""]);
        let g4 = member(["", "ukrainian", "", "tea", ""]);
        let ivory = a.house(["ivory", "", "", "", ""]);
        let green = a.house(["green", "", "", "", ""]);
        let g5 = nextto(ivory, green, hs.clone());
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g6 = member(["", "", "snails", "", "oldgold"]);
        let g7 = member(["yellow", "", "", "", "kools"]);
        let mut near = |x: [&str; 5], y: [&str; 5]| {
            let (x, y) = (a.house(x), a.house(y));
            next_to(x, y, hs.clone())
        };
        let g8 = near(["", "", "", "", "chesterfield"], ["", "", "fox", "", ""]);
        let g9 = near(["", "", "", "", "kools"], ["", "", "horse", "", ""]);
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g10 = member(["", "", "", "orange_juice", "lucky_strike"]);
        let g11 = member(["", "japanese", "", "", "parliament"]);
        let mut near = |x: [&str; 5], y: [&str; 5]| {
            let (x, y) = (a.house(x), a.house(y));
            next_to(x, y, hs.clone())
        };
        let g12 = near(["", "norwegian", "", "", ""], ["blue", "", "", "", ""]);
        let mut member = |slots: [&str; 5]| membero(a.house(slots), hs.clone());
        let g13 = member(["", "", "zebra", "", ""]);
        let g14 = member(["", "", "", "water", ""]);
        conj([
            eq(hs.clone(), houses),
            g1,
            g2,
            g3,
            g4,
            g5,
            g6,
            g7,
            g8,
            g9,
            g10,
            g11,
            g12,
            g13,
            g14,
        ])
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::run::{Query, RunConfig};

    #[test]
    fn zebra_uses_exactly_its_anonymous_variables() {
        // Every `_` must get its own variable: running out would silently
        // turn one into `[]` and change the puzzle.
        let mut q = Query::new();
        let hs = q.var("hs");
        let answers: Vec<_> = q.run(zebrao(hs), RunConfig::default()).collect();
        assert_eq!(answers.len(), 1);
        let text = answers[0]
            .as_ref()
            .map(|a| a.to_string())
            .unwrap_or_default();
        assert!(!text.contains("[]"), "{text}");
        assert!(
            text.contains("h(green, japanese, zebra, coffee, parliament)"),
            "{text}"
        );
        assert!(
            text.contains("h(yellow, norwegian, fox, water, kools)"),
            "{text}"
        );
    }
}
