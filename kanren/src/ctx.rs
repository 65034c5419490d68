//! The per-run context every goal sees ([`Ctx`]: settings, the step
//! counter, the budgets, the run's [`Producers`]), what a generator yields
//! ([`GenStep`], [`Wait`], the [`Scan`] a goal steps itself) and why a run
//! stops ([`StopReason`]). Kept apart from the engine's scheduler and from
//! `run`'s public iterator so that the goals and the scheduler depend on
//! this module, not on each other; the store layer (facts, joins, tables,
//! list scans) plugs in through [`Producers`], [`crate::engine::Generator`]
//! and [`crate::goal::Native`], which this layer never names.

use crate::error::RunError;
use crate::goal::Goal;
use crate::state::State;
use crate::term::Term;
use std::any::Any;
use std::cell::{Cell, OnceCell, RefCell};
use std::time::Instant;

/// Why a run stopped producing answers.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum StopReason {
    /// The search space was exhausted: every answer was produced.
    Exhausted,
    /// `RunConfig::limit` answers were produced.
    Limit,
    /// `Budget::max_steps` ran out.
    StepBudget,
    /// `Budget::max_time` ran out.
    TimeBudget,
    /// The run reported a [`RunError`] and stopped.
    Error,
}

impl std::fmt::Display for StopReason {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            StopReason::Exhausted => "every answer was found",
            StopReason::Limit => "the answer limit was reached",
            StopReason::StepBudget => "the step budget ran out",
            StopReason::TimeBudget => "the time budget ran out",
            StopReason::Error => "an error stopped the run",
        })
    }
}

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
    /// The run's answer tables and their producers, installed by the first
    /// tabled call (`crate::tabling`): until then there are no producers to
    /// drive and `next_answer` skips them.
    pub producers: OnceCell<Box<dyn Producers>>,
    /// Bumped whenever a table gains an answer or completes: an engine with
    /// parked tasks looks at its tables again only when this has moved, so
    /// a turn that changed no table costs parked tasks nothing.
    pub table_epoch: Cell<u64>,
    /// The binding buffer that `eq` and the list scans reuse for every
    /// unification (borrowed only for the length of one).
    pub pending: RefCell<Vec<(crate::term::Var, crate::term::Term)>>,
    /// Set by a counting engine ([`crate::Run::count_up_to`]) just before it
    /// steps a generator that nothing follows: every state the generator
    /// would yield is an answer that is only counted, so it may count its
    /// answers ([`GenStep::Counted`]) instead of building them. Nested
    /// engines (`naf`, `conda`) clear it before their own generators.
    pub count_tail: Cell<bool>,
    /// Answers counted that way and not yet taken by the run.
    pub counted: Cell<u64>,
}

impl Ctx {
    /// A context with these settings, no step taken, no table.
    pub fn new(
        proofs: bool,
        occurs_check: bool,
        max_steps: Option<u64>,
        deadline: Option<Instant>,
    ) -> Ctx {
        Ctx {
            proofs,
            occurs_check,
            steps: Cell::new(0),
            max_steps,
            deadline,
            halted: Cell::new(None),
            producers: OnceCell::new(),
            table_epoch: Cell::new(0),
            pending: RefCell::new(Vec::new()),
            count_tail: Cell::new(false),
            counted: Cell::new(0),
        }
    }

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

impl Ctx {
    /// Counts `n` steps at once (a generator that tried `n` candidates in
    /// one turn); false (and `halted` set) when a budget is exhausted. The
    /// clock is read once.
    pub fn tick_n(&self, n: u64) -> bool {
        if self.halted.get().is_some() {
            return false;
        }
        let total = self.steps.get().saturating_add(n);
        self.steps.set(total);
        if let Some(max) = self.max_steps
            && total > max
        {
            self.halted.set(Some(StopReason::StepBudget));
            return false;
        }
        if let Some(d) = self.deadline
            && Instant::now() >= d
        {
            self.halted.set(Some(StopReason::TimeBudget));
            return false;
        }
        true
    }
}

/// One step of a generator (a fact scan, a list scan, a table consumer):
/// what it hands the scheduler.
pub(crate) enum GenStep {
    /// A state, to continue with `goal` (if any) and then the continuation.
    Yield(State, Option<Goal>, bool),
    /// No state this turn; call again.
    More,
    /// No state until a table changes: park the generator (see [`Wait`]).
    Suspend(Wait),
    /// This many answers, counted without states (only when
    /// `Ctx::count_tail` was set); `true` when it has more to give.
    Counted(u64, bool),
    Done,
    Error(RunError),
}

/// Where a scan stands that its own goal steps ([`crate::goal::Native`]):
/// the rest of the term it walks, and the state it started on. The engine
/// keeps it (boxed only when it has more to give) and lends it the goal,
/// which lies where it was, at every step, so a step copies nothing out of
/// the goal.
pub(crate) struct Scan {
    pub rest: Term,
    pub state: State,
}

/// The answer tables of one run and their producers, as the scheduler sees
/// them: the store layer (`crate::tabling`) implements it and installs it
/// in [`Ctx::producers`] at the first tabled call. The scheduler gives the
/// producers turns between its own and asks whether a table a parked task
/// waits on ([`Wait::Table`]) has changed.
pub(crate) trait Producers: Any + Send {
    /// Gives one producer a turn or, when none can run, completes what can
    /// be completed.
    fn drive(&self, ctx: &Ctx) -> Result<Drive, RunError>;
    /// True when `table` has more than `seen` answers or is complete: a
    /// consumer that had read `seen` of them can go on.
    fn changed_since(&self, table: usize, seen: usize) -> bool;
    /// The error for a search whose tasks all wait on the tables `waits`
    /// and nothing can complete them.
    fn stalled(&self, ctx: &Ctx, waits: &[usize]) -> RunError;
}

/// What one call of [`Producers::drive`] achieved.
pub(crate) enum Drive {
    /// A producer took a turn, or tables completed.
    Progress,
    /// No producer can run and no table can complete.
    Stalled,
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
