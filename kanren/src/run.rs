//! Queries, runs, budgets and reified answers.

use crate::ctx::Ctx;
use crate::engine::Scheduler;
use crate::error::RunError;
use crate::goal::Goal;
use crate::proof::{self, Proof};
use crate::state::State;
use crate::term::{Term, Var};
use std::collections::{HashMap, HashSet};
use std::time::{Duration, Instant};

/// Limits on the work a run may do. `Default` is unlimited.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Budget {
    /// The most search steps (goals run, generator turns) the run may take.
    pub max_steps: Option<u64>,
    /// The most wall-clock time the run may take, from [`Query::run`].
    pub max_time: Option<Duration>,
}

/// How to run a query. `Default`: all answers, no proofs, no budget.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct RunConfig {
    /// The most answers to produce (`run n`); `None` is `run*`.
    pub limit: Option<usize>,
    /// Record a [`Proof`] with every answer.
    pub proofs: bool,
    /// Step and time limits.
    pub budget: Budget,
}

pub use crate::ctx::StopReason;

/// One answer: the query variables' values, fully walked, with unbound
/// variables renamed `_0, _1, …` in order of first appearance (as
/// `Term::Var(Var(i))`, which displays as `_i`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Answer {
    /// One value per query variable, in creation order.
    pub values: Vec<Term>,
    /// Residual constraints on the answer's unbound variables, printed, sorted.
    pub constraints: Vec<String>,
    /// The derivation, when `RunConfig::proofs` was on.
    pub proof: Option<Proof>,
}

impl std::fmt::Display for Answer {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (i, v) in self.values.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            write!(f, "{v}")?;
        }
        if !self.constraints.is_empty() {
            write!(f, " where {}", self.constraints.join(", "))?;
        }
        Ok(())
    }
}

/// A query: named variables plus settings, run against goals over them.
///
/// Invariant: the query's variables are `Var(0)..Var(n)` in creation order,
/// and every run starts its fresh variables after them.
#[derive(Clone, Debug)]
pub struct Query {
    // Shared with every run of the query: a run needs the names only to
    // word an error, and copying them cost an allocation per variable.
    names: std::sync::Arc<Vec<String>>,
    occurs_check: bool,
}

impl Default for Query {
    fn default() -> Query {
        Query::new()
    }
}

impl Query {
    /// A query with no variables yet, occurs check on.
    pub fn new() -> Query {
        Query {
            names: Default::default(),
            occurs_check: true,
        }
    }

    /// A fresh query variable; answers list values in creation order.
    pub fn var(&mut self, name: &str) -> Term {
        let v = Var(u32::try_from(self.names.len()).unwrap_or(u32::MAX));
        std::sync::Arc::make_mut(&mut self.names).push(name.to_owned());
        Term::Var(v)
    }

    /// `n` fresh query variables named `{prefix}0…`.
    pub fn vars<const N: usize>(&mut self, prefix: &str) -> [Term; N] {
        std::array::from_fn(|i| self.var(&format!("{prefix}{i}")))
    }

    /// The variables' names, in creation order.
    pub fn names(&self) -> &[String] {
        &self.names
    }

    /// Turns the occurs check on (the default: `x = f(x)` fails) or off
    /// (faster; cyclic bindings then make walking loop — only for programs
    /// known not to create them, like appendo on proper lists).
    pub fn set_occurs_check(&mut self, on: bool) -> &mut Query {
        self.occurs_check = on;
        self
    }

    /// Runs `goal` lazily: the returned iterator does the search as it is consumed.
    pub fn run(&self, goal: Goal, config: RunConfig) -> Run {
        let nvars = u32::try_from(self.names.len()).unwrap_or(u32::MAX);
        let ctx = Ctx::new(
            config.proofs,
            self.occurs_check,
            config.budget.max_steps,
            config.budget.max_time.map(|d| Instant::now() + d),
        );
        Run {
            engine: Some(Scheduler::new(goal, State::new(nvars))),
            ctx,
            names: self.names.clone(),
            limit: config.limit,
            produced: 0,
            stop: None,
            scratch: Vec::new(),
        }
    }

    /// Every answer (no limit, no budget), errors included.
    pub fn run_all(&self, goal: Goal) -> Vec<Result<Answer, RunError>> {
        self.run(goal, RunConfig::default()).collect()
    }

    /// The first `n` answers (no budget), errors included.
    pub fn run_n(&self, n: usize, goal: Goal) -> Vec<Result<Answer, RunError>> {
        let cfg = RunConfig {
            limit: Some(n),
            ..RunConfig::default()
        };
        self.run(goal, cfg).collect()
    }
}

/// A running query: an iterator of answers (or errors), then a [`StopReason`].
///
/// `Run` is `Send` (move it to another thread) but not shared between threads.
pub struct Run {
    engine: Option<Scheduler>,
    ctx: Ctx,
    names: std::sync::Arc<Vec<String>>,
    limit: Option<usize>,
    produced: usize,
    stop: Option<StopReason>,
    /// Scratch space for reification, reused across answers.
    scratch: Vec<Term>,
}

impl Run {
    /// Why the run stopped; `None` while answers may still come.
    pub fn stop_reason(&self) -> Option<StopReason> {
        self.stop
    }

    /// Search steps taken so far (nested evaluations — naf, tables — included).
    /// Deterministic for a given query and data: usable as a cost measure in tests.
    pub fn steps(&self) -> u64 {
        self.ctx.steps.get()
    }

    fn finish(&mut self, why: StopReason) {
        self.engine = None;
        self.stop = Some(why);
    }

    fn name_vars(&self, e: RunError) -> RunError {
        match e {
            RunError::UnboundNegation { vars } => RunError::UnboundNegation {
                vars: vars
                    .into_iter()
                    .map(|v| {
                        v.strip_prefix('_')
                            .and_then(|n| n.parse::<usize>().ok())
                            .and_then(|n| self.names.get(n))
                            .cloned()
                            .unwrap_or(v)
                    })
                    .collect(),
            },
            other => other,
        }
    }
}

impl Run {
    /// Counts the answers still to come without building them (no walk of
    /// the substitution, no allocation per answer), stopping once the count
    /// passes `max` (it then returns `max + 1`). What the iterator would
    /// have yielded is consumed either way.
    pub fn count_up_to(&mut self, max: usize) -> Result<usize, RunError> {
        if let Some(engine) = self.engine.as_mut() {
            engine.counts = true;
        }
        let mut n = 0usize;
        let take_counted = |ctx: &Ctx, n: &mut usize, produced: &mut usize| {
            let c = usize::try_from(ctx.counted.replace(0)).unwrap_or(usize::MAX);
            *n = n.saturating_add(c);
            *produced = produced.saturating_add(c);
        };
        while n <= max {
            if self.limit.is_some_and(|l| self.produced >= l) {
                if self.stop.is_none() {
                    self.finish(StopReason::Limit);
                }
                break;
            }
            let Some(engine) = self.engine.as_mut() else {
                break;
            };
            let room = u64::try_from(max - n).unwrap_or(u64::MAX).saturating_add(1);
            match engine.next_answer_counting(&self.ctx, room) {
                Ok(Some(_)) => {
                    self.produced += 1;
                    n += 1;
                    take_counted(&self.ctx, &mut n, &mut self.produced);
                }
                Ok(None) => {
                    take_counted(&self.ctx, &mut n, &mut self.produced);
                    if n > max {
                        break;
                    }
                    let why = self.ctx.halted.get().unwrap_or(StopReason::Exhausted);
                    self.finish(why);
                    break;
                }
                Err(e) => {
                    let why = self.ctx.halted.get().unwrap_or(StopReason::Error);
                    self.finish(why);
                    return Err(self.name_vars(e));
                }
            }
        }
        if let Some(engine) = self.engine.as_mut() {
            engine.counts = false;
        }
        // A generator counts a whole turn at once, so it may pass the cap.
        Ok(n.min(max.saturating_add(1)))
    }
}

impl Iterator for Run {
    type Item = Result<Answer, RunError>;

    fn next(&mut self) -> Option<Self::Item> {
        if self.limit.is_some_and(|l| self.produced >= l) {
            if self.stop.is_none() {
                self.finish(StopReason::Limit);
            }
            return None;
        }
        let engine = self.engine.as_mut()?;
        match engine.next_answer(&self.ctx) {
            Ok(Some(st)) => {
                self.produced += 1;
                if self.limit.is_some_and(|l| self.produced >= l) {
                    self.finish(StopReason::Limit);
                }
                Some(Ok(reify(
                    &st,
                    self.names.len(),
                    self.ctx.proofs,
                    &mut self.scratch,
                )))
            }
            Ok(None) => {
                let why = self.ctx.halted.get().unwrap_or(StopReason::Exhausted);
                self.finish(why);
                None
            }
            Err(e) => {
                let why = self.ctx.halted.get().unwrap_or(StopReason::Error);
                self.finish(why);
                Some(Err(self.name_vars(e)))
            }
        }
    }
}

/// Builds the answer for the query variables `Var(0..n)` of `st`.
fn reify(st: &State, n: usize, proofs: bool, scratch: &mut Vec<Term>) -> Answer {
    let mut any_vars = false;
    let walked: Vec<Term> = (0..n)
        .map(|i| {
            let (t, vars) = st.subst.walk_star_vars(
                &Term::Var(Var(u32::try_from(i).unwrap_or(u32::MAX))),
                scratch,
            );
            any_vars |= vars;
            t
        })
        .collect();
    let mut names: HashMap<Var, Var> = HashMap::new();
    let mut order: Vec<Var> = Vec::new();
    // A ground answer (the common case) has no variable to look for.
    for t in walked.iter().filter(|_| any_vars) {
        t.for_each_var(&mut |v| {
            if let std::collections::hash_map::Entry::Vacant(e) = names.entry(v) {
                e.insert(Var(u32::try_from(order.len()).unwrap_or(u32::MAX)));
                order.push(v);
            }
        });
    }
    // A ground answer (the common case) has nothing to rename.
    let values = if names.is_empty() {
        walked
    } else {
        walked.iter().map(|t| rename_with(t, &names)).collect()
    };
    let constraints = if st.store.is_empty() {
        Vec::new()
    } else {
        residual(st, &order, &names)
    };
    Answer {
        values,
        constraints,
        proof: proofs.then(|| Proof {
            steps: proof::to_vec(&st.proof),
        }),
    }
}

/// `t` (already walked) with variables renamed by `names`; `None` when it
/// holds a variable outside `names`.
fn try_rename(t: &Term, names: &HashMap<Var, Var>) -> Option<Term> {
    match t.try_map_vars(&mut |v| {
        names
            .get(&v)
            .map(|r| (*r != v).then_some(Term::Var(*r)))
            .ok_or(())
    }) {
        Ok(changed) => Some(changed.unwrap_or_else(|| t.clone())),
        Err(()) => None,
    }
}

fn rename_with(t: &Term, names: &HashMap<Var, Var>) -> Term {
    try_rename(t, names).unwrap_or_else(|| t.clone())
}

/// The residual constraints that mention only the answer's variables
/// (constraints on variables the answer cannot show are satisfiable and
/// irrelevant to it, so they are left out, as faster-miniKanren does).
fn residual(st: &State, order: &[Var], names: &HashMap<Var, Var>) -> Vec<String> {
    let mut out: HashSet<String> = HashSet::new();
    for v in order {
        let Some(attr) = st.store.get(&v.0) else {
            continue;
        };
        let shown = names
            .get(v)
            .map_or_else(|| v.to_string(), |r| r.to_string());
        if let Some(ty) = attr.ty {
            out.insert(format!("{}({shown})", ty.goal_name()));
        }
        for tag in &attr.absent {
            out.insert(format!("absento({tag}, {shown})"));
        }
        for d in &attr.neqs {
            let pairs: Option<Vec<(Term, Term)>> = d
                .pairs
                .iter()
                .map(|(x, t)| {
                    let l = try_rename(&st.subst.walk_star(&Term::Var(*x)), names)?;
                    let r = try_rename(&st.subst.walk_star(t), names)?;
                    Some(if l <= r { (l, r) } else { (r, l) })
                })
                .collect();
            let Some(mut pairs) = pairs else { continue };
            pairs.sort();
            let text = match pairs.as_slice() {
                [(l, r)] => format!("{l} =/= {r}"),
                many => {
                    let ls: Vec<String> = many.iter().map(|p| p.0.to_string()).collect();
                    let rs: Vec<String> = many.iter().map(|p| p.1.to_string()).collect();
                    format!("({}) =/= ({})", ls.join(", "), rs.join(", "))
                }
            };
            out.insert(text);
        }
    }
    let mut v: Vec<String> = out.into_iter().collect();
    v.sort();
    v
}
