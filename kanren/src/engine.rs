//! The search engine: fair, lazy, and constant work per step.
//!
//! µKanren represents a search as a tree of streams (`mplus` nodes for
//! disjunctions, `bind` nodes for conjunctions) and every step walks from the
//! root to the leaf it advances; fairness comes from swapping `mplus`
//! branches. This engine keeps the same guarantees with flat data instead:
//!
//! - A **task** is a state plus its *continuation*: the goals still to run on
//!   it, as a persistent linked list shared between the branches that forked
//!   from the same point.
//! - A **turn** takes a task and runs it depth first — unification,
//!   conjunctions, `fresh` all stay inline — until it fails, answers, or
//!   reaches a branch point. At a disjunction the first alternative continues
//!   inline and the rest are pushed as one lazy `Alts` task. A turn also ends
//!   after [`BURST`] goals, so a branch that recurses forever without
//!   branching (left recursion) gives up control.
//! - Tasks live on **threads**, each a stack (depth first, like Prolog's
//!   choice points: good locality, a frontier no bigger than depth ×
//!   branching), and the threads take turns round robin, [`SLICE`] turns
//!   each. At the end of its slice a thread hands its *oldest* pending task
//!   to a new thread at the back of the queue.
//!
//! That hand-off is what makes the search fair: a task has finitely many
//! older tasks in its thread, so after finitely many slices it is split off
//! and gets slices of its own — a finite branch beside an infinite one still
//! yields all its answers (the fairness of interleaving streams), while a
//! turn costs what its goals cost: no tree descent, no re-allocation of the
//! path from the root. Generators (fact scans, table answers, list walks,
//! committed-choice sub-searches) are tasks that hand out one state per turn.
//!
//! A generator may also *suspend*: a consumer of a tabled call that has read
//! every answer its table has so far (see [`crate::tabling`]). The engine
//! then parks the task beside its threads and wakes it when the table has
//! grown or completed; an engine whose tasks are all parked is *stuck* and
//! lets the producers of the tables run (`next_answer` drives them), so a
//! suspended consumer costs nothing until there is something for it.

use crate::error::RunError;
use crate::facts::FactScan;
use crate::goal::{G, Goal};
use crate::run::StopReason;
use crate::state::State;
use crate::tabling::{self, Drive, TableAnswers, Tables};
use std::cell::{Cell, RefCell};
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;
use std::time::Instant;

/// The most goals one turn runs before the task yields its turn.
const BURST: u32 = 256;

/// Turns a thread runs before the next thread gets its slice.
const SLICE: u32 = 64;

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
    /// Bumped whenever a table gains an answer or completes: an engine with
    /// parked tasks looks at its tables again only when this has moved, so
    /// a turn that changed no table costs parked tasks nothing.
    pub table_epoch: Cell<u64>,
    /// True once a tabled relation has been called in this run: until then
    /// there are no producers to drive and `next_answer` skips them.
    pub has_tables: Cell<bool>,
    /// The binding buffer that `eq` and the list scans reuse for every
    /// unification (borrowed only for the length of one).
    pub pending: RefCell<Vec<(crate::term::Var, crate::term::Term)>>,
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
        // Reading the clock costs more than a step: look every 1024 steps.
        if n & 1023 == 0
            && let Some(d) = self.deadline
            && Instant::now() >= d
        {
            self.halted.set(Some(StopReason::TimeBudget));
            return false;
        }
        true
    }
}

/// A continuation node: the goals `goals`, then `next`.
pub(crate) struct KNode {
    goals: Arc<[Goal]>,
    next: K,
}

/// The goals still to run on a state: `node.goals[idx..]`, then the rest of
/// the node's chain (`None`: nothing — the state is an answer).
///
/// Invariant: `idx < node.goals.len()`. The position lives beside the
/// shared node, not in it, so taking the next goal never allocates, even
/// when other tasks share the node (as every fork does).
pub(crate) type K = Option<(Arc<KNode>, usize)>;

/// Prepends `goals[idx..]` to `k` (no-op when that is empty).
#[inline]
pub(crate) fn push_k(goals: &Arc<[Goal]>, idx: usize, k: K) -> K {
    if idx >= goals.len() {
        return k;
    }
    Some((
        Arc::new(KNode {
            goals: goals.clone(),
            next: k,
        }),
        idx,
    ))
}

/// Takes the next goal off `k`.
#[inline]
fn pop_k(k: &mut K) -> Option<Goal> {
    let (node, idx) = k.as_mut()?;
    let g = node.goals.get(*idx).cloned();
    *idx += 1;
    if *idx >= node.goals.len() {
        let next = node.next.clone();
        *k = next;
    }
    g
}

/// What a goal implemented as a closure does to a state.
pub(crate) enum Out {
    Fail,
    Ok(State),
    /// Continue with this goal (then the continuation).
    Then(State, Goal),
    /// A generator: each of its states continues with the continuation.
    Gen(Gen),
    Error(RunError),
}

/// A task that produces states one turn at a time.
pub(crate) enum Gen {
    Facts(Box<FactScan>),
    Table(Box<TableAnswers>),
    Sub(Box<Sub>),
    List(Box<crate::classic::ListScan>),
}

pub(crate) enum GenStep {
    /// A state, to continue with `goal` (if any) and then the continuation.
    Yield(State, Option<Goal>, bool),
    /// No state this turn; call again.
    More,
    /// No state until a table changes: park the generator (see [`Wait`]).
    Suspend(Wait),
    Done,
    Error(RunError),
}

/// What a suspended generator waits for.
#[derive(Clone, Copy, Debug)]
pub(crate) enum Wait {
    /// A table consumer that has read the first `seen` answers of `table`:
    /// it can go on when the table has more, or is complete.
    Table { table: usize, seen: usize },
    /// A sub-search whose own tasks are all parked: it can go on when any
    /// table changes (its own parked tasks then decide).
    Any,
}

impl Gen {
    fn next(&mut self, ctx: &Ctx) -> GenStep {
        match self {
            Gen::Facts(f) => f.next(ctx),
            Gen::Table(t) => t.next(ctx),
            Gen::Sub(s) => s.next(ctx),
            Gen::List(l) => l.next(ctx),
        }
    }
}

enum Task {
    Run(State, Goal, K),
    /// The alternatives `goals[idx..]`, each on `state`, then `k`.
    Alts(Arc<[Goal]>, usize, State, K),
    Gen(Gen, K),
}

/// What a turn of the engine produced.
pub(crate) enum Turn {
    Answer(State),
    More,
    Done,
    Error(RunError),
}

/// One search: a round-robin queue of threads, each a stack of tasks, and
/// the tasks parked on tables.
///
/// Invariants: no thread in `threads` is empty; the front thread is the one
/// running, for at most `turns_left` more turns. A task is either in a
/// thread or parked, never both.
pub(crate) struct Engine {
    threads: VecDeque<VecDeque<Task>>,
    turns_left: u32,
    parked: Parked,
}

/// Tasks that cannot go on until a table changes.
///
/// Invariants: every task in `by_table[t]` is a consumer of table `t`
/// (`Gen::Table`) that had read at least `seen` of its answers when it
/// parked, and the table was not complete then; every task in `any` is a
/// sub-search (`Gen::Sub`) whose head engine has parked tasks and no
/// running ones. No table has changed since `epoch` in a way that would
/// wake one of them, except where `epoch != ctx.table_epoch`.
#[derive(Default)]
struct Parked {
    by_table: BTreeMap<usize, (usize, Vec<Task>)>,
    any: Vec<Task>,
    epoch: u64,
}

impl Parked {
    fn is_empty(&self) -> bool {
        self.by_table.is_empty() && self.any.is_empty()
    }
}

impl Engine {
    pub fn new(goal: Goal, st: State) -> Engine {
        let mut first = VecDeque::with_capacity(16);
        first.push_back(Task::Run(st, goal, None));
        let mut threads = VecDeque::with_capacity(4);
        threads.push_back(first);
        Engine {
            threads,
            turns_left: SLICE,
            parked: Parked::default(),
        }
    }

    /// True when no task is left, running or parked.
    pub fn is_empty(&self) -> bool {
        self.threads.is_empty() && self.parked.is_empty()
    }

    /// True when some task is parked on a table.
    pub fn has_parked(&self) -> bool {
        !self.parked.is_empty()
    }

    /// Parks `task` until what it waits for happens.
    fn park(&mut self, ctx: &Ctx, wait: Wait, task: Task) {
        // With nothing parked there is nothing older to re-check: start
        // from now. Otherwise keep the older epoch, so that changes the
        // already parked tasks have not seen still wake them.
        if self.parked.is_empty() {
            self.parked.epoch = ctx.table_epoch.get();
        }
        match wait {
            Wait::Table { table, seen } => {
                let group = self
                    .parked
                    .by_table
                    .entry(table)
                    .or_insert_with(|| (seen, Vec::new()));
                group.0 = group.0.min(seen);
                group.1.push(task);
            }
            Wait::Any => self.parked.any.push(task),
        }
    }

    /// Moves the parked tasks whose table has changed since they parked
    /// (and every parked sub-search) to a new thread at the back of the
    /// queue, when some table has changed since the last look.
    fn wake(&mut self, ctx: &Ctx) {
        let now = ctx.table_epoch.get();
        if self.parked.is_empty() || self.parked.epoch == now {
            return;
        }
        self.parked.epoch = now;
        let mut woken: VecDeque<Task> = self.parked.any.drain(..).collect();
        {
            let tables = ctx.tables.borrow();
            self.parked.by_table.retain(|&table, (seen, tasks)| {
                if tables.changed_since(table, *seen) {
                    woken.extend(tasks.drain(..));
                    false
                } else {
                    true
                }
            });
        }
        if !woken.is_empty() {
            self.threads.push_back(woken);
        }
    }

    /// The tables the parked tasks wait on, sub-searches' included.
    pub(crate) fn waits_on(&self, out: &mut Vec<usize>) {
        out.extend(self.parked.by_table.keys().copied());
        for task in &self.parked.any {
            if let Task::Gen(Gen::Sub(sub), _) = task {
                sub.head.waits_on(out);
            }
        }
    }

    /// True when a parked committed choice has not committed yet and has an
    /// `else` branch: when the tables it waits on complete it would go on
    /// with that branch, so they cannot be completed from here.
    pub(crate) fn parks_open_choice(&self) -> bool {
        self.parked.any.iter().any(|task| match task {
            Task::Gen(Gen::Sub(sub), _) => {
                (!sub.committed && sub.els.is_some()) || sub.head.parks_open_choice()
            }
            _ => false,
        })
    }

    /// Pushes a task on the running thread's stack (depth first).
    #[inline]
    fn push(&mut self, task: Task) {
        match self.threads.front_mut() {
            Some(t) => t.push_back(task),
            None => self.threads.push_back(VecDeque::from([task])),
        }
    }

    /// The next task to run: the top of the running thread's stack. Every
    /// `SLICE` turns the running thread gives the oldest task on its stack
    /// a thread of its own, at the back of the queue, and goes to the back
    /// itself. A task is therefore never starved: the tasks older than it
    /// in its thread are finitely many, so it becomes the oldest and is
    /// split off after finitely many slices, and every thread gets slices
    /// in turn.
    fn next_task(&mut self, ctx: &Ctx) -> Option<Task> {
        if !self.parked.is_empty() {
            self.wake(ctx);
        }
        if self.turns_left == 0 {
            self.turns_left = SLICE;
            if let Some(mut running) = self.threads.pop_front() {
                if running.len() >= 2
                    && let Some(oldest) = running.pop_front()
                {
                    self.threads.push_back(VecDeque::from([oldest]));
                }
                if !running.is_empty() {
                    self.threads.push_back(running);
                }
            }
        }
        loop {
            let front = self.threads.front_mut()?;
            match front.pop_back() {
                Some(task) => {
                    self.turns_left -= 1;
                    return Some(task);
                }
                None => {
                    self.threads.pop_front();
                    self.turns_left = SLICE;
                }
            }
        }
    }

    /// Runs one turn: the front task, depth first, until it answers, fails,
    /// branches off its last alternative, or uses up its burst.
    pub fn turn(&mut self, ctx: &Ctx) -> Turn {
        let Some(task) = self.next_task(ctx) else {
            return Turn::Done;
        };
        let (st, goal, k) = match task {
            Task::Run(st, g, k) => (st, g, k),
            Task::Alts(gs, idx, st, k) => {
                let Some(g) = gs.get(idx).cloned() else {
                    return Turn::More;
                };
                if idx + 1 < gs.len() {
                    self.push(Task::Alts(gs, idx + 1, st.clone(), k.clone()));
                }
                (st, g, k)
            }
            Task::Gen(mut generator, k) => match generator.next(ctx) {
                GenStep::Yield(st, g, more) => {
                    let k2 = k.clone();
                    if more {
                        self.push(Task::Gen(generator, k));
                    }
                    match g {
                        Some(g) => (st, g, k2),
                        None => match self.resume(ctx, st, k2) {
                            Some(x) => return x,
                            None => return Turn::More,
                        },
                    }
                }
                GenStep::More => {
                    self.push(Task::Gen(generator, k));
                    return Turn::More;
                }
                GenStep::Suspend(wait) => {
                    self.park(ctx, wait, Task::Gen(generator, k));
                    return Turn::More;
                }
                GenStep::Done => return Turn::More,
                GenStep::Error(e) => return Turn::Error(e),
            },
        };
        self.run(ctx, st, goal, k)
    }

    /// Continues a state with its continuation: an answer when it is empty.
    fn resume(&mut self, ctx: &Ctx, st: State, mut k: K) -> Option<Turn> {
        match pop_k(&mut k) {
            None => Some(Turn::Answer(st)),
            Some(g) => Some(self.run(ctx, st, g, k)),
        }
    }

    fn run(&mut self, ctx: &Ctx, mut st: State, mut goal: Goal, mut k: K) -> Turn {
        let mut burst = BURST;
        loop {
            if !ctx.tick() {
                return Turn::Done;
            }
            match &goal.0 {
                G::Succeed => {}
                G::Fail => return Turn::More,
                G::Eq(ab) => match st.unify_buf(
                    &ab.0,
                    &ab.1,
                    ctx.occurs_check,
                    &mut ctx.pending.borrow_mut(),
                ) {
                    Some(s) => st = s,
                    None => return Turn::More,
                },
                G::Conj(gs) => {
                    // An empty conjunction (`conj` never builds one) is
                    // `succeed`: it falls through to the continuation.
                    if let Some(first) = gs.first().cloned() {
                        k = push_k(gs, 1, k);
                        goal = first;
                        continue;
                    }
                }
                G::Disj(gs) => {
                    let Some(first) = gs.first().cloned() else {
                        return Turn::More;
                    };
                    if gs.len() > 1 {
                        self.push(Task::Alts(gs.clone(), 1, st.clone(), k.clone()));
                    }
                    goal = first;
                    continue;
                }
                G::Fn(f) => match f(ctx, st) {
                    Out::Fail => return Turn::More,
                    Out::Ok(s) => st = s,
                    Out::Then(s, g) => {
                        st = s;
                        goal = g;
                        burst -= 1;
                        if burst == 0 {
                            self.push(Task::Run(st, goal, k));
                            return Turn::More;
                        }
                        continue;
                    }
                    Out::Gen(mut generator) => match generator.next(ctx) {
                        // The first state continues inline (depth first);
                        // the generator waits its turn for the others.
                        GenStep::Yield(s, g, more) => {
                            if more {
                                self.push(Task::Gen(generator, k.clone()));
                            }
                            st = s;
                            if let Some(g) = g {
                                goal = g;
                                continue;
                            }
                        }
                        GenStep::More => {
                            self.push(Task::Gen(generator, k));
                            return Turn::More;
                        }
                        GenStep::Suspend(wait) => {
                            self.park(ctx, wait, Task::Gen(generator, k));
                            return Turn::More;
                        }
                        GenStep::Done => return Turn::More,
                        GenStep::Error(e) => return Turn::Error(e),
                    },
                    Out::Error(e) => return Turn::Error(e),
                },
            }
            match pop_k(&mut k) {
                None => return Turn::Answer(st),
                Some(g) => goal = g,
            }
            burst -= 1;
            if burst == 0 {
                self.push(Task::Run(st, goal, k));
                return Turn::More;
            }
        }
    }

    /// Turns until the next answer. `Ok(None)`: no more answers, or a budget
    /// ran out (`ctx.halted` says which).
    ///
    /// Once tables exist, every turn of this engine comes after one turn of
    /// a table producer, so producers advance even while this search has
    /// work of its own (a consumer here may be waiting on them — fairness),
    /// and when every task left here is parked the producers run until one
    /// wakes, or the tables complete.
    pub fn next_answer(&mut self, ctx: &Ctx) -> Result<Option<State>, RunError> {
        loop {
            if ctx.halted.get().is_some() {
                return Ok(None);
            }
            // Before our turn, not after: a turn that answers returns, and a
            // search answering every turn would starve the producers.
            if ctx.has_tables.get() {
                tabling::drive(ctx)?;
            }
            match self.turn(ctx) {
                Turn::Answer(st) => return Ok(Some(st)),
                Turn::More => {}
                Turn::Done => {
                    if self.is_empty() || ctx.halted.get().is_some() {
                        return Ok(None);
                    }
                    // Stuck: everything left waits on tables.
                    if let Drive::Stalled = tabling::drive(ctx)? {
                        let mut waits = Vec::new();
                        self.waits_on(&mut waits);
                        return Err(tabling::stalled(ctx, &waits));
                    }
                }
                Turn::Error(e) => return Err(e),
            }
        }
    }
}

/// Steps a fresh search of `goal` on `st` to its first answer.
pub(crate) fn first_answer(ctx: &Ctx, goal: Goal, st: State) -> Result<Option<State>, RunError> {
    Engine::new(goal, st).next_answer(ctx)
}

/// Runs a fresh search of `goal` on `st` to exhaustion, calling `f` on every
/// answer. Stops early (without error) when a budget runs out.
#[cfg(test)]
pub(crate) fn for_each_answer(
    ctx: &Ctx,
    goal: Goal,
    st: State,
    mut f: impl FnMut(State),
) -> Result<(), RunError> {
    let mut e = Engine::new(goal, st);
    while let Some(st) = e.next_answer(ctx)? {
        f(st);
    }
    Ok(())
}

/// A committed-choice sub-search (`conda`, `condu`, `onceo`): the head runs in
/// its own engine, so its branches can be cut without touching the others.
pub(crate) struct Sub {
    pub head: Engine,
    /// Goal to run on each committed head answer.
    pub then: Option<Goal>,
    /// Goal to run on `state` when the head has no answer.
    pub els: Option<Goal>,
    pub state: State,
    /// Keep only the head's first answer (`condu`, `onceo`).
    pub once: bool,
    pub committed: bool,
}

impl Sub {
    fn next(&mut self, ctx: &Ctx) -> GenStep {
        match self.head.turn(ctx) {
            Turn::Answer(st) => {
                self.committed = true;
                let more = !self.once;
                GenStep::Yield(st, self.then.clone(), more)
            }
            Turn::More => GenStep::More,
            Turn::Done => {
                // The head has no running task but some parked on tables:
                // it can only go on when one of them changes.
                if self.head.has_parked() && ctx.halted.get().is_none() {
                    return GenStep::Suspend(Wait::Any);
                }
                if self.committed || ctx.halted.get().is_some() {
                    GenStep::Done
                } else {
                    match self.els.take() {
                        Some(g) => GenStep::Yield(self.state.clone(), Some(g), false),
                        None => GenStep::Done,
                    }
                }
            }
            Turn::Error(e) => GenStep::Error(e),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::goal::{eq, succeed};
    use crate::term::{Term, Var};

    fn ctx() -> Ctx {
        Ctx {
            proofs: false,
            occurs_check: false,
            steps: Cell::new(0),
            max_steps: Some(10_000),
            deadline: None,
            halted: Cell::new(None),
            tables: RefCell::new(Default::default()),
            table_epoch: Cell::new(0),
            has_tables: Cell::new(false),
            pending: RefCell::new(Vec::new()),
        }
    }

    /// Regression: an empty `G::Conj` used to `continue` on itself, spinning
    /// until the step budget ran out instead of succeeding.
    #[test]
    fn empty_conj_node_succeeds() {
        let ctx = ctx();
        let empty = Goal(G::Conj(Arc::from(Vec::<Goal>::new())));
        let goal = Goal(G::Conj(Arc::from(vec![
            empty,
            eq(Term::Var(Var(0)), Term::Int(1)),
            succeed(),
        ])));
        let mut answers = Vec::new();
        let r = for_each_answer(&ctx, goal, State::new(1), |st| {
            answers.push(st.subst.walk_star(&Term::Var(Var(0))));
        });
        assert!(r.is_ok());
        assert_eq!(ctx.halted.get(), None);
        assert_eq!(answers, vec![Term::Int(1)]);
    }
}
