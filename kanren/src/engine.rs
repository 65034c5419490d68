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
//! path from the root. Generators are tasks that hand out one state per
//! turn: the committed-choice sub-searches here ([`Sub`]), and whatever the
//! store layer builds — fact scans, joins, table answers — through the
//! [`Generator`] trait; goals that step a [`Scan`] of their own (the list
//! scans) come in through [`crate::goal::Native`]. The engine names none of
//! them.
//!
//! A generator may also *suspend*: a consumer of a tabled call that has read
//! every answer its table has so far. The engine then parks the task beside
//! its threads and wakes it when the table has grown or completed; an
//! engine whose tasks are all parked is *stuck* and lets the producers of
//! the tables run (`next_answer` drives them, through [`Producers`]), so a
//! suspended consumer costs nothing until there is something for it.

use crate::ctx::{Ctx, Drive, GenStep, Scan, Wait};
use crate::error::RunError;
use crate::goal::{G, Goal, Native};
use crate::state::State;
use std::collections::{BTreeMap, VecDeque};
use std::sync::Arc;

/// The most goals one turn runs before the task yields its turn.
const BURST: u32 = 256;

/// Turns a thread runs before the next thread gets its slice.
const SLICE: u32 = 64;

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

/// Moves `k` past its first goal, in place: within a node an index bump,
/// with no reference count touched.
#[inline]
fn advance(k: &mut K) {
    if let Some((node, idx)) = k {
        *idx += 1;
        if *idx >= node.goals.len() {
            let next = node.next.clone();
            *k = next;
        }
    }
}

/// What a goal the engine runs itself asks for next. Built while the goal
/// is borrowed from its continuation node, acted on once that borrow ends.
enum Step {
    /// It succeeded: go on with the continuation.
    Next(State),
    /// Run this goal next, then the continuation.
    Then(State, Goal),
    /// A conjunction: its goals, then the continuation.
    Conj(State, Arc<[Goal]>),
    /// A disjunction: each alternative, then the continuation.
    Disj(State, Arc<[Goal]>),
    /// A disjunction of this many alternatives that is the first goal of
    /// the continuation: its alternatives are run where they lie.
    DisjInK(State, usize),
    /// A generator: each of its states, then the continuation.
    Gen(Gen),
    /// A scan its goal steps (a list scan), and its first step.
    Scan(Scan, GenStep),
    /// A state (from a scan that goes on as a task), to continue with the
    /// goal, if any, then the continuation.
    Yielded(State, Option<Goal>),
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

/// What a [`Native`] goal does to a state: what a closure goal does, or a
/// scan that the goal steps itself, with the scan's first step (the engine
/// lends the goal to the scan's later steps). Apart from [`Out`] so that
/// the closures' result stays small: every `fresh` returns one.
pub(crate) enum NativeOut {
    Out(Out),
    Scan(Scan, GenStep),
}

/// A task that produces states one turn at a time: a fact scan, a join, a
/// table's answers (the store layer), or a committed-choice sub-search.
pub(crate) trait Generator: Send {
    /// One step: a state, nothing yet, a suspension, or the end.
    fn next(&mut self, ctx: &Ctx) -> GenStep;
    /// Adds the tables this generator's parked tasks wait on (a sub-search
    /// with its own parked tasks); nothing for the others.
    fn waits_on(&self, _out: &mut Vec<usize>) {}
    /// True when this generator is a committed choice that has not
    /// committed and has an `else` branch, or holds one parked.
    fn parks_open_choice(&self) -> bool {
        false
    }
}

/// A generator, as the engine holds it.
pub(crate) type Gen = Box<dyn Generator>;

enum Task {
    /// The goal, then the continuation.
    Run(State, Cur, K),
    /// The alternatives `goals[idx..]`, each on `state`, then `k`.
    Alts(Arc<[Goal]>, usize, State, K),
    /// The alternatives from `idx` on of the disjunction that is the first
    /// goal of `k`, each on `state`, then the rest of `k`.
    AltsInK(usize, State, K),
    Gen(Gen, K),
    /// A scan its goal steps, then `k`; see [`ScanTask`].
    Scan(Box<ScanTask>, K),
}

/// The goal being run, or to run: held, or lying in the continuation.
///
/// A goal is run where it lies whenever it can be: cloning it out of its
/// node (and dropping the clone) was two atomic reference-count operations
/// per goal run; for a disjunction's alternatives, four more.
enum Cur {
    /// Held here: made by a goal, or taken from a disjunction that does
    /// not lie in the continuation.
    Own(Goal),
    /// In the continuation, which still begins with it (or, for
    /// [`Place::Alt`], with the disjunction it belongs to).
    InK(Place),
}

/// Where in a continuation a goal lies.
#[derive(Clone, Copy)]
enum Place {
    /// The first goal.
    Head,
    /// Alternative `i` of the disjunction that is the first goal.
    Alt(usize),
}

/// The goal at `place` in `k`, if there is one.
#[inline]
fn goal_in(k: &K, place: Place) -> Option<&Goal> {
    let (node, idx) = k.as_ref()?;
    let g = node.goals.get(*idx)?;
    match place {
        Place::Head => Some(g),
        Place::Alt(i) => match &g.0 {
            G::Disj(gs) => gs.get(i),
            _ => None,
        },
    }
}

/// A scan that goes on as a task (a list scan). Its goal is held, or lies
/// at a place in the task's continuation, which is then kept positioned on
/// it: the scan's pattern is read where it lies, never copied (each copy
/// was an atomic count up and one down).
struct ScanTask {
    goal: ScanGoal,
    scan: Scan,
}

/// Where a [`ScanTask`]'s goal is: held, or in the task's continuation.
enum ScanGoal {
    Own(Arc<dyn Native>),
    InK(Place),
}

/// The goal of a scan that goes on as a task, given where the scan's goal
/// lay (`None`: held in `cur`).
fn scan_goal(place: Option<Place>, cur: Cur) -> Option<ScanGoal> {
    match (place, cur) {
        (Some(p), _) => Some(ScanGoal::InK(p)),
        (None, Cur::Own(Goal(G::Native(g)))) => Some(ScanGoal::Own(g)),
        // Never: the scan came from `cur`, a native goal.
        (None, _) => None,
    }
}

/// `k` without its first goal, as a new continuation (one count up).
#[inline]
fn after_head(k: &K) -> K {
    let (node, idx) = k.as_ref()?;
    if idx + 1 < node.goals.len() {
        Some((node.clone(), idx + 1))
    } else {
        node.next.clone()
    }
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
pub(crate) struct Scheduler {
    threads: VecDeque<VecDeque<Task>>,
    turns_left: u32,
    parked: Parked,
    /// Only counts its answers: a generator that nothing follows may count
    /// them instead of yielding states (see `Ctx::count_tail`).
    pub(crate) counts: bool,
}

/// Tasks that cannot go on until a table changes.
///
/// Invariants: every task in `by_table[t]` is a consumer of table `t`
/// (a table-answers generator) that had read at least `seen` of its answers when it
/// parked, and the table was not complete then; every task in `any` is a
/// sub-search ([`Sub`]) whose head engine has parked tasks and no
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

impl Scheduler {
    pub fn new(goal: Goal, st: State) -> Scheduler {
        let mut first = VecDeque::with_capacity(16);
        first.push_back(Task::Run(st, Cur::Own(goal), None));
        let mut threads = VecDeque::with_capacity(4);
        threads.push_back(first);
        Scheduler {
            threads,
            turns_left: SLICE,
            parked: Parked::default(),
            counts: false,
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
        let producers = ctx.producers.get();
        self.parked.by_table.retain(|&table, (seen, tasks)| {
            if producers.is_none_or(|p| p.changed_since(table, *seen)) {
                woken.extend(tasks.drain(..));
                false
            } else {
                true
            }
        });
        if !woken.is_empty() {
            self.threads.push_back(woken);
        }
    }

    /// The tables the parked tasks wait on, sub-searches' included.
    pub(crate) fn waits_on(&self, out: &mut Vec<usize>) {
        out.extend(self.parked.by_table.keys().copied());
        for task in &self.parked.any {
            if let Task::Gen(generator, _) = task {
                generator.waits_on(out);
            }
        }
    }

    /// True when a parked committed choice has not committed yet and has an
    /// `else` branch: when the tables it waits on complete it would go on
    /// with that branch, so they cannot be completed from here.
    pub(crate) fn parks_open_choice(&self) -> bool {
        self.parked.any.iter().any(|task| match task {
            Task::Gen(generator, _) => generator.parks_open_choice(),
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
            Task::Alts(gs, idx, mut st, k) => {
                let Some(g) = gs.get(idx).cloned() else {
                    return Turn::More;
                };
                if idx + 1 < gs.len() {
                    self.push(Task::Alts(gs, idx + 1, st.fork(), k.clone()));
                }
                (st, Cur::Own(g), k)
            }
            Task::AltsInK(idx, mut st, k) => {
                if goal_in(&k, Place::Alt(idx)).is_none() {
                    return Turn::More;
                }
                if goal_in(&k, Place::Alt(idx + 1)).is_some() {
                    self.push(Task::AltsInK(idx + 1, st.fork(), k.clone()));
                }
                (st, Cur::InK(Place::Alt(idx)), k)
            }
            Task::Gen(mut generator, k) => match self.step_gen(ctx, &mut generator, &k) {
                GenStep::Yield(st, g, more) => {
                    // The generator keeps the continuation only when it has
                    // more to give: a last state takes it, uncloned.
                    let k = if more {
                        let k2 = k.clone();
                        self.push(Task::Gen(generator, k));
                        k2
                    } else {
                        k
                    };
                    match g {
                        Some(g) => (st, Cur::Own(g), k),
                        None if k.is_none() => return Turn::Answer(st),
                        None => (st, Cur::InK(Place::Head), k),
                    }
                }
                GenStep::More | GenStep::Counted(_, true) => {
                    self.push(Task::Gen(generator, k));
                    return Turn::More;
                }
                GenStep::Suspend(wait) => {
                    self.park(ctx, wait, Task::Gen(generator, k));
                    return Turn::More;
                }
                GenStep::Done | GenStep::Counted(_, false) => return Turn::More,
                GenStep::Error(e) => return Turn::Error(e),
            },
            Task::Scan(mut task, k) => {
                let in_k = matches!(task.goal, ScanGoal::InK(_));
                let ScanTask { goal, scan } = &mut *task;
                let step = match goal {
                    ScanGoal::Own(g) => g.resume(ctx, scan),
                    ScanGoal::InK(place) => match goal_in(&k, *place) {
                        Some(Goal(G::Native(g))) => g.resume(ctx, scan),
                        // Never: the task is made with `k` on its goal.
                        _ => GenStep::Done,
                    },
                };
                match step {
                    GenStep::Yield(st, g, more) => {
                        let k = if more {
                            let k2 = if in_k { after_head(&k) } else { k.clone() };
                            self.push(Task::Scan(task, k));
                            k2
                        } else {
                            let mut k = k;
                            if in_k {
                                advance(&mut k);
                            }
                            k
                        };
                        match g {
                            Some(g) => (st, Cur::Own(g), k),
                            None if k.is_none() => return Turn::Answer(st),
                            None => (st, Cur::InK(Place::Head), k),
                        }
                    }
                    // A scan never suspends; it would just be retried.
                    GenStep::More | GenStep::Suspend(_) => {
                        self.push(Task::Scan(task, k));
                        return Turn::More;
                    }
                    // A scan never counts.
                    GenStep::Done | GenStep::Counted(..) => return Turn::More,
                    GenStep::Error(e) => return Turn::Error(e),
                }
            }
        };
        self.run(ctx, st, goal, k)
    }

    /// Runs `cur`, then `k`, depth first.
    fn run(&mut self, ctx: &Ctx, mut st: State, mut cur: Cur, mut k: K) -> Turn {
        let mut burst = BURST;
        loop {
            if !ctx.tick() {
                return Turn::Done;
            }
            let place = match &cur {
                Cur::Own(_) => None,
                Cur::InK(p) => Some(*p),
            };
            let goal = match &cur {
                Cur::Own(g) => g,
                Cur::InK(_) if k.is_none() => return Turn::Answer(st),
                Cur::InK(p) => match goal_in(&k, *p) {
                    Some(g) => g,
                    None => return Turn::More,
                },
            };
            let step = match &goal.0 {
                G::Succeed => Step::Next(st),
                G::Fail => return Turn::More,
                G::Eq(ab) => match st.unify_buf(
                    &ab.0,
                    &ab.1,
                    ctx.occurs_check,
                    &mut ctx.pending.borrow_mut(),
                ) {
                    Some(s) => Step::Next(s),
                    None => return Turn::More,
                },
                G::Conj(gs) => Step::Conj(st, gs.clone()),
                G::Disj(gs) if matches!(place, Some(Place::Head)) => Step::DisjInK(st, gs.len()),
                G::Disj(gs) => Step::Disj(st, gs.clone()),
                // A scan's first step runs on the stack; the scan is boxed
                // only if it has more to give.
                G::Native(g) => match g.run(ctx, st) {
                    NativeOut::Scan(scan, first) => Step::Scan(scan, first),
                    NativeOut::Out(Out::Fail) => return Turn::More,
                    NativeOut::Out(Out::Ok(s)) => Step::Next(s),
                    NativeOut::Out(Out::Then(s, g)) => Step::Then(s, g),
                    NativeOut::Out(Out::Gen(generator)) => Step::Gen(generator),
                    NativeOut::Out(Out::Error(e)) => return Turn::Error(e),
                },
                G::Fn(f) => match f(ctx, st) {
                    Out::Fail => return Turn::More,
                    Out::Ok(s) => Step::Next(s),
                    Out::Then(s, g) => Step::Then(s, g),
                    Out::Gen(generator) => Step::Gen(generator),
                    Out::Error(e) => return Turn::Error(e),
                },
            };
            // Before `k` moves past the goal: a disjunction that lies in `k`
            // keeps `k` on it while its alternatives run, and so does a scan
            // that goes on as a task, when its goal lies in `k`.
            let step = match step {
                Step::DisjInK(mut s, n) => {
                    if n == 0 {
                        return Turn::More;
                    }
                    if n > 1 {
                        self.push(Task::AltsInK(1, s.fork(), k.clone()));
                    }
                    st = s;
                    cur = Cur::InK(Place::Alt(0));
                    continue;
                }
                Step::Scan(scan, GenStep::Yield(s, g, true)) => {
                    let Some(goal) = scan_goal(place, cur) else {
                        return Turn::More;
                    };
                    self.push(Task::Scan(Box::new(ScanTask { goal, scan }), k.clone()));
                    Step::Yielded(s, g)
                }
                Step::Scan(scan, GenStep::More | GenStep::Suspend(_)) => {
                    let Some(goal) = scan_goal(place, cur) else {
                        return Turn::More;
                    };
                    self.push(Task::Scan(Box::new(ScanTask { goal, scan }), k));
                    return Turn::More;
                }
                other => other,
            };
            // From here `k` is what follows the goal just run.
            if place.is_some() {
                advance(&mut k);
            }
            cur = Cur::InK(Place::Head);
            match step {
                Step::Next(s) => st = s,
                Step::Then(s, g) => {
                    st = s;
                    cur = Cur::Own(g);
                    burst -= 1;
                    if burst == 0 {
                        self.push(Task::Run(st, cur, k));
                        return Turn::More;
                    }
                    continue;
                }
                Step::Conj(s, gs) => {
                    st = s;
                    // An empty conjunction (`conj` never builds one) is
                    // `succeed`: it falls through to the continuation.
                    if !gs.is_empty() {
                        k = Some((Arc::new(KNode { goals: gs, next: k }), 0));
                        continue;
                    }
                }
                Step::Disj(s, gs) => {
                    st = s;
                    let Some(first) = gs.first().cloned() else {
                        return Turn::More;
                    };
                    if gs.len() > 1 {
                        self.push(Task::Alts(gs, 1, st.fork(), k.clone()));
                    }
                    cur = Cur::Own(first);
                    continue;
                }
                Step::Gen(mut generator) => match self.step_gen(ctx, &mut generator, &k) {
                    // The first state continues inline (depth first);
                    // the generator waits its turn for the others.
                    GenStep::Yield(s, g, more) => {
                        if more {
                            self.push(Task::Gen(generator, k.clone()));
                        }
                        st = s;
                        if let Some(g) = g {
                            cur = Cur::Own(g);
                            continue;
                        }
                    }
                    GenStep::More | GenStep::Counted(_, true) => {
                        self.push(Task::Gen(generator, k));
                        return Turn::More;
                    }
                    GenStep::Suspend(wait) => {
                        self.park(ctx, wait, Task::Gen(generator, k));
                        return Turn::More;
                    }
                    GenStep::Done | GenStep::Counted(_, false) => return Turn::More,
                    GenStep::Error(e) => return Turn::Error(e),
                },
                Step::Yielded(s, g) | Step::Scan(_, GenStep::Yield(s, g, _)) => {
                    st = s;
                    if let Some(g) = g {
                        cur = Cur::Own(g);
                        continue;
                    }
                }
                Step::Scan(_, GenStep::Error(e)) => return Turn::Error(e),
                Step::Scan(..) | Step::DisjInK(..) => return Turn::More,
            }
            if k.is_none() {
                return Turn::Answer(st);
            }
            burst -= 1;
            if burst == 0 {
                self.push(Task::Run(st, Cur::InK(Place::Head), k));
                return Turn::More;
            }
        }
    }

    /// Steps `generator`, whose continuation is `k`, telling it whether it
    /// may count its answers (see `Ctx::count_tail`); counted answers go
    /// to `Ctx::counted`.
    fn step_gen(&mut self, ctx: &Ctx, generator: &mut Gen, k: &K) -> GenStep {
        ctx.count_tail.set(self.counts && k.is_none());
        let step = generator.next(ctx);
        ctx.count_tail.set(false);
        if let GenStep::Counted(n, _) = step {
            ctx.counted.set(ctx.counted.get().saturating_add(n));
        }
        step
    }

    /// [`Scheduler::next_answer`] for a counting run: also returns (`None`)
    /// once `room` answers have been counted without states, so a count
    /// that passes its cap stops there.
    pub fn next_answer_counting(
        &mut self,
        ctx: &Ctx,
        room: u64,
    ) -> Result<Option<State>, RunError> {
        loop {
            if ctx.halted.get().is_some() || ctx.counted.get() >= room {
                return Ok(None);
            }
            if let Some(producers) = ctx.producers.get() {
                producers.drive(ctx)?;
            }
            match self.turn(ctx) {
                Turn::Answer(st) => return Ok(Some(st)),
                Turn::More => {}
                Turn::Done => {
                    if self.is_empty() || ctx.halted.get().is_some() {
                        return Ok(None);
                    }
                    // Tasks are parked, so some table exists (only table
                    // consumers and the sub-searches holding them park).
                    let Some(producers) = ctx.producers.get() else {
                        return Ok(None);
                    };
                    if let Drive::Stalled = producers.drive(ctx)? {
                        let mut waits = Vec::new();
                        self.waits_on(&mut waits);
                        return Err(producers.stalled(ctx, &waits));
                    }
                }
                Turn::Error(e) => return Err(e),
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
        self.next_answer_counting(ctx, u64::MAX)
    }
}

/// Steps a fresh search of `goal` on `st` to its first answer.
pub(crate) fn first_answer(ctx: &Ctx, goal: Goal, st: State) -> Result<Option<State>, RunError> {
    Scheduler::new(goal, st).next_answer(ctx)
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
    let mut e = Scheduler::new(goal, st);
    while let Some(st) = e.next_answer(ctx)? {
        f(st);
    }
    Ok(())
}

/// A committed-choice sub-search (`conda`, `condu`, `onceo`): the head runs in
/// its own engine, so its branches can be cut without touching the others.
pub(crate) struct Sub {
    pub head: Scheduler,
    /// Goal to run on each committed head answer.
    pub then: Option<Goal>,
    /// Goal to run on `state` when the head has no answer.
    pub els: Option<Goal>,
    pub state: State,
    /// Keep only the head's first answer (`condu`, `onceo`).
    pub once: bool,
    pub committed: bool,
}

impl Generator for Sub {
    fn waits_on(&self, out: &mut Vec<usize>) {
        self.head.waits_on(out);
    }

    fn parks_open_choice(&self) -> bool {
        (!self.committed && self.els.is_some()) || self.head.parks_open_choice()
    }

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
        Ctx::new(false, false, Some(10_000), None)
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
