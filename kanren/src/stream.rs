//! Lazy, fair answer streams (µKanren's empty | mature | immature, made explicit).
//!
//! A [`Stream`] is a data structure, not a closure: [`step`] advances it by one
//! unit of work and says whether an answer came out. Immature streams
//! (`Pending`, `Disj`) are the delays that make recursion safe, and
//! `Mplus` swaps its two sides whenever the left one pauses or answers — the
//! interleaving that makes `conde` fair. Because stepping is explicit, the run
//! loop counts every step against the budget and never recurses into a
//! branch that has not been asked for.

use crate::facts::FactScan;
use crate::goal::Goal;
use crate::run::StopReason;
use crate::state::State;
use crate::tabling::{TableAnswers, Tables};
use crate::error::RunError;
use std::cell::{Cell, RefCell};
use std::sync::Arc;
use std::time::Instant;

/// Per-run context: settings, the step counter and the answer tables.
///
/// Owned by one [`crate::Run`]; goals see it by reference while they run, so
/// the interior mutability here is never shared across threads.
pub(crate) struct Ctx {
    pub proofs: bool,
    pub occurs_check: bool,
    pub steps: Cell<u64>,
    pub max_steps: Option<u64>,
    pub deadline: Option<Instant>,
    /// Set when a budget ran out (possibly inside a nested evaluation).
    pub halted: Cell<Option<StopReason>>,
    pub tables: RefCell<Tables>,
}

impl Ctx {
    /// Counts one step; false (and `halted` set) when a budget is exhausted.
    #[inline]
    pub fn tick(&self) -> bool {
        if self.halted.get().is_some() {
            return false;
        }
        let n = self.steps.get() + 1;
        self.steps.set(n);
        if let Some(max) = self.max_steps
            && n > max
        {
            self.halted.set(Some(StopReason::StepBudget));
            return false;
        }
        // Reading the clock costs more than a step: look every 256 steps.
        if n & 255 == 0
            && let Some(d) = self.deadline
            && Instant::now() >= d
        {
            self.halted.set(Some(StopReason::TimeBudget));
            return false;
        }
        true
    }
}

/// What to do with each answer of the left side of a `Bind`.
#[derive(Clone)]
pub(crate) enum Cont {
    /// The conjunction `goals[from..]` (saves building a goal for each tail).
    ConjFrom(Arc<[Goal]>, usize),
}

impl Cont {
    #[inline]
    pub fn apply(&self, ctx: &Ctx, st: State) -> Stream {
        match self {
            Cont::ConjFrom(gs, i) => crate::goal::conj_from(gs, *i, ctx, st),
        }
    }
}

pub(crate) enum Stream {
    Empty,
    Unit(State),
    /// A goal not yet applied (an immature stream).
    Pending(Goal, State),
    /// The alternatives `goals[next..]`, each applied to `state` in turn.
    Disj(Arc<[Goal]>, usize, State),
    Mplus(Box<Stream>, Box<Stream>),
    Bind(Box<Stream>, Cont),
    /// conda / condu: commit to the first answer(s) of `cond`, else run `els`.
    Ifte {
        cond: Box<Stream>,
        then: Cont,
        els: Option<Goal>,
        state: State,
        once: bool,
    },
    Once(Box<Stream>),
    Facts(Box<FactScan>),
    Table(Box<TableAnswers>),
    Error(RunError),
}

pub(crate) enum Step {
    Done,
    Answer(State, Stream),
    More(Stream),
    Error(RunError),
}

#[inline]
pub(crate) fn mplus(a: Stream, b: Stream) -> Stream {
    match (a, b) {
        (Stream::Empty, b) => b,
        (a, Stream::Empty) => a,
        (a, b) => Stream::Mplus(Box::new(a), Box::new(b)),
    }
}

#[inline]
pub(crate) fn bind(s: Stream, k: Cont, ctx: &Ctx) -> Stream {
    match s {
        Stream::Empty => Stream::Empty,
        Stream::Unit(st) => k.apply(ctx, st),
        Stream::Error(e) => Stream::Error(e),
        s => Stream::Bind(Box::new(s), k),
    }
}

/// Advances `s` by one unit of work.
pub(crate) fn step(ctx: &Ctx, s: Stream) -> Step {
    match s {
        Stream::Empty => Step::Done,
        Stream::Unit(st) => Step::Answer(st, Stream::Empty),
        Stream::Pending(g, st) => Step::More(g.apply(ctx, st)),
        Stream::Disj(gs, i, st) => {
            if i + 1 >= gs.len() {
                match gs.get(i) {
                    Some(g) => Step::More(g.apply(ctx, st)),
                    None => Step::Done,
                }
            } else {
                let first = gs[i].apply(ctx, st.clone());
                Step::More(mplus(first, Stream::Disj(gs, i + 1, st)))
            }
        }
        Stream::Mplus(a, b) => match step(ctx, *a) {
            Step::Done => Step::More(*b),
            // Swapping on every answer and every pause interleaves the two.
            Step::Answer(st, rest) => Step::Answer(st, mplus(*b, rest)),
            Step::More(a2) => Step::More(mplus(*b, a2)),
            Step::Error(e) => Step::Error(e),
        },
        Stream::Bind(s, k) => match step(ctx, *s) {
            Step::Done => Step::Done,
            Step::Answer(st, rest) => {
                let head = k.apply(ctx, st);
                let tail = bind(rest, k, ctx);
                match head {
                    Stream::Unit(st2) => Step::Answer(st2, tail),
                    Stream::Error(e) => Step::Error(e),
                    head => Step::More(mplus(head, tail)),
                }
            }
            Step::More(s2) => Step::More(bind(s2, k, ctx)),
            Step::Error(e) => Step::Error(e),
        },
        Stream::Ifte {
            cond,
            then,
            els,
            state,
            once,
        } => match step(ctx, *cond) {
            Step::Done => Step::More(match els {
                Some(g) => g.apply(ctx, state),
                None => Stream::Empty,
            }),
            Step::Answer(st, rest) => {
                if once {
                    Step::More(then.apply(ctx, st))
                } else {
                    let head = then.apply(ctx, st);
                    Step::More(mplus(head, bind(rest, then, ctx)))
                }
            }
            Step::More(c2) => Step::More(Stream::Ifte {
                cond: Box::new(c2),
                then,
                els,
                state,
                once,
            }),
            Step::Error(e) => Step::Error(e),
        },
        Stream::Once(s) => match step(ctx, *s) {
            Step::Done => Step::Done,
            Step::Answer(st, _) => Step::Answer(st, Stream::Empty),
            Step::More(s2) => Step::More(Stream::Once(Box::new(s2))),
            Step::Error(e) => Step::Error(e),
        },
        Stream::Facts(scan) => scan.step(ctx),
        Stream::Table(t) => t.step(ctx),
        Stream::Error(e) => Step::Error(e),
    }
}

/// Steps `s` until its first answer. `Ok(None)` when it has none or a budget
/// ran out (then `ctx.halted` says which).
pub(crate) fn first_answer(ctx: &Ctx, mut s: Stream) -> Result<Option<State>, RunError> {
    loop {
        if !ctx.tick() {
            return Ok(None);
        }
        match step(ctx, s) {
            Step::Done => return Ok(None),
            Step::Answer(st, _) => return Ok(Some(st)),
            Step::More(s2) => s = s2,
            Step::Error(e) => return Err(e),
        }
    }
}

/// Steps `s` to exhaustion, calling `f` on every answer. Stops early (without
/// error) when a budget runs out; `ctx.halted` then says so.
pub(crate) fn for_each_answer(
    ctx: &Ctx,
    mut s: Stream,
    mut f: impl FnMut(State),
) -> Result<(), RunError> {
    loop {
        if !ctx.tick() {
            return Ok(());
        }
        match step(ctx, s) {
            Step::Done => return Ok(()),
            Step::Answer(st, rest) => {
                f(st);
                s = rest;
            }
            Step::More(s2) => s = s2,
            Step::Error(e) => return Err(e),
        }
    }
}
