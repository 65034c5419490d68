//! Tabled relations: SLG-style tabling (producers and consumers) in the
//! stream model.
//!
//! A call to a tabled relation is reduced to its *variant key* — the walked
//! arguments with their variables renamed `_0, _1, …` by first occurrence —
//! and answered from that key's table, which lives for the run.
//!
//! - **Producer.** The first call of a key creates the table and a producer:
//!   an `Scheduler` running the body on the key. The producer is not run
//!   there and then; it is a stream of its own that `next_answer` steps one
//!   turn at a time, round robin with the other producers and alternating
//!   with the caller's search (see `drive`). Each answer the body finds is
//!   added to the table unless the table already holds it.
//! - **Consumers.** Every call of the key — the first, later ones, and the
//!   recursive calls inside producers — is a consumer (`TableAnswers`): it
//!   hands out the table's answers in the order they were added, each
//!   unified with the caller's arguments, as soon as they are there. Having
//!   read them all, it *suspends* (the engine parks it) until the table has
//!   more or is complete; then it is woken, or it ends. A consumer reads each
//!   answer once, by position, so it never returns one twice.
//! - **Completion.** A table is complete when its producer has no task left;
//!   or when its producer is *stuck* — every task it has left is a consumer
//!   (or a `conda`/`condu`/`onceo` sub-search whose tasks all are) waiting on
//!   tables — and it belongs to a strongly connected component of stuck
//!   producers none of whose waits leave the component: nothing can ever add
//!   an answer to those tables again, so they all complete together, their
//!   producers are dropped and their waiting consumers end. The components
//!   are computed (Tarjan) whenever no producer can run; a producer stuck on
//!   its own table alone (left recursion) completes at once. A search whose
//!   tasks are all parked therefore drives the producers until one of its
//!   tasks wakes or the tables complete, and then ends; it never spins.
//! - **Answers.** An answer is the key walked in the answer's state, its
//!   variables renamed by first occurrence, together with the constraints
//!   of that state restricted to those variables: the type (`symbolo` …)
//!   and `absento` constraints on them, and each disequality whose two sides,
//!   walked, mention only them. A disequality that also mentions a variable
//!   the answer does not show is dropped: that variable is existential and
//!   unconstrained outside the body, so the disequality can always be
//!   satisfied (faster-miniKanren drops such constraints when reifying, for
//!   the same reason). A consumer re-posts the kept constraints on the
//!   caller's state after unifying, so a later binding that violates one
//!   fails. Tuple and constraints together identify an answer for the
//!   table's deduplication. When proofs are on, an answer keeps the
//!   derivation it was first found with, and a consumer appends it to the
//!   caller's.
//!
//! Limits: tables live for one run, and a producer runs on (interleaved)
//! until its table completes even when its consumers are gone, e.g. after
//! `onceo`. Recursion through negation that is not stratified — a `naf`, or
//! a `conda`/`condu` whose `else` is still open, that needs a table's complete
//! answers inside that table's own evaluation — is reported as
//! [`RunError::TabledNegationCycle`]; a `naf` inside a producer that waits on
//! such a table while unrelated producers can still run keeps running them
//! until they finish (or a budget stops the run) before it reports that.
//! A relation with infinitely many answers has an ever-growing table
//! (`run(n)` still returns the first `n`).

use crate::ctx::{Ctx, Drive, GenStep, Producers, Wait};
use crate::engine::{Generator, Out, Scheduler, Turn};
use crate::error::RunError;
use crate::goal::{Goal, goal_fn};
use crate::proof::{self, ProofNode};
use crate::state::{State, TypeTag};
use crate::subst::Subst;
use crate::term::{Sym, Term, Var};
use std::cell::RefCell;
use std::collections::{BTreeSet, HashMap, HashSet, VecDeque};
use std::convert::Infallible;
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

type Body = dyn Fn(&Tabled, &[Term]) -> Goal + Send + Sync;

struct TabledInner {
    id: usize,
    name: Sym,
    arity: usize,
    body: Box<Body>,
}

/// A tabled relation. Build it once with [`Tabled::new`] (the body receives
/// the relation itself, for recursive calls) and call it with [`Tabled::call`].
#[derive(Clone)]
pub struct Tabled(Arc<TabledInner>);

impl std::fmt::Debug for Tabled {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Tabled({}/{})", self.0.name, self.0.arity)
    }
}

static NEXT_TABLED_ID: AtomicUsize = AtomicUsize::new(0);

impl Tabled {
    /// A tabled relation `name/arity` whose calls run `body(self, args)`.
    ///
    /// The body is built once per call variant, when the variant is first
    /// called, with `args` the variant's key (its variables numbered from 0).
    pub fn new(
        name: impl Into<Sym>,
        arity: usize,
        body: impl Fn(&Tabled, &[Term]) -> Goal + Send + Sync + 'static,
    ) -> Tabled {
        Tabled(Arc::new(TabledInner {
            id: NEXT_TABLED_ID.fetch_add(1, Ordering::Relaxed),
            name: name.into(),
            arity,
            body: Box::new(body),
        }))
    }

    /// The relation's name.
    pub fn name(&self) -> Sym {
        self.0.name
    }

    /// The goal calling the relation on `args`.
    pub fn call(&self, args: Vec<Term>) -> Goal {
        let rel = self.clone();
        let args: Arc<[Term]> = args.into();
        goal_fn(move |ctx, st| call(&rel, &args, ctx, st))
    }
}

/// Shorthand for [`Tabled::new`].
pub fn tabled(
    name: impl Into<Sym>,
    arity: usize,
    body: impl Fn(&Tabled, &[Term]) -> Goal + Send + Sync + 'static,
) -> Tabled {
    Tabled::new(name, arity, body)
}

/// A constraint of a tabled answer, over the answer's own variables.
#[derive(Clone, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
enum Constraint {
    /// The two sides must never become equal. Several pairs "not all of
    /// `l_i = r_i`" are the lists of the `l_i` and of the `r_i`.
    Neq(Term, Term),
    /// The variable must take this type.
    Type(Var, TypeTag),
    /// The ground term must occur nowhere in the variable's value.
    Absent(Term, Var),
}

/// What identifies an answer within its table: its tuple and constraints.
type AnswerKey = (Arc<[Term]>, Arc<[Constraint]>);

/// One answer of a table, in its own variables.
///
/// Invariants: `tuple` has one term per argument of the relation; its
/// variables are exactly `Var(0)..Var(nvars)`, numbered by first occurrence
/// left to right, so two answers are variants exactly when their tuples are
/// equal; `constraints` mention no other variable and are sorted without
/// duplicates, so equal constraint sets are equal slices; `proof` is the
/// derivation the answer was first found with (`None` when proofs are off).
struct TabledAnswer {
    tuple: Arc<[Term]>,
    nvars: u32,
    constraints: Arc<[Constraint]>,
    proof: Option<Arc<ProofNode>>,
}

/// How far a table's evaluation has got.
enum Status {
    /// The producer may go on; the table is queued in `Tables::runnable`,
    /// once.
    Runnable(Box<Scheduler>),
    /// The producer is taking a turn: its engine is on the Rust stack of a
    /// [`drive`] call, and the table is in `Tables::busy`.
    Busy,
    /// Every task the producer has left is parked on the tables in `waits`
    /// (sorted, no duplicates); the table is in `Tables::stuck` and in the
    /// `dependents` of each of those tables.
    Stuck {
        engine: Box<Scheduler>,
        waits: Vec<usize>,
    },
    /// No answer will be added; the producer is gone.
    Complete,
}

/// One call variant's table.
///
/// Invariants: `answers` are appended only, and only while `status` is not
/// `Complete`; `seen` holds exactly the (tuple, constraints) of `answers`,
/// so each answer is there once; every table in `dependents` was `Stuck`
/// waiting on this one when it was added (it may have been woken since, so
/// entries are checked, not trusted).
struct Table {
    relation: Sym,
    /// The variant key: the body's arguments, variables `Var(0)..`.
    key: Arc<[Term]>,
    answers: Vec<Arc<TabledAnswer>>,
    seen: HashSet<AnswerKey>,
    status: Status,
    dependents: BTreeSet<usize>,
}

/// All tables of one run, and the scheduling state of their producers.
///
/// Invariants: `keys` maps each (relation id, variant key) to its index in
/// `tables`; a table is in `runnable` (once) exactly when its status is
/// `Runnable`, in `stuck` exactly when it is `Stuck`, and in `busy` exactly
/// when it is `Busy` (`busy` is a stack: nested drives step producers
/// inside a producer's turn, through `naf`); `version` grows with every
/// change of any status or answer set, and `futile` is the version at which
/// the last completion check found nothing to complete.
#[derive(Default)]
pub(crate) struct Tables {
    keys: HashMap<(usize, Arc<[Term]>), usize>,
    tables: Vec<Table>,
    runnable: VecDeque<usize>,
    stuck: BTreeSet<usize>,
    busy: Vec<usize>,
    version: u64,
    futile: Option<u64>,
}

impl Tables {
    /// True when `table` has more than `seen` answers or is complete: a
    /// consumer that had read `seen` of them can go on.
    pub(crate) fn changed_since(&self, table: usize, seen: usize) -> bool {
        self.tables
            .get(table)
            .is_none_or(|t| t.answers.len() > seen || matches!(t.status, Status::Complete))
    }
}

/// The run's tables as the engine's [`Producers`]: installed in
/// [`Ctx::producers`] by the first tabled call of a run.
#[derive(Default)]
struct TableSet(RefCell<Tables>);

impl Producers for TableSet {
    fn drive(&self, ctx: &Ctx) -> Result<Drive, RunError> {
        drive(&self.0, ctx)
    }

    fn changed_since(&self, table: usize, seen: usize) -> bool {
        self.0.borrow().changed_since(table, seen)
    }

    fn stalled(&self, _ctx: &Ctx, waits: &[usize]) -> RunError {
        stalled(&self.0, waits)
    }
}

/// The run's tables, installed on first use. `None` only if another kind
/// of producers held the run's slot, which nothing in this crate installs.
fn tables(ctx: &Ctx) -> Option<&RefCell<Tables>> {
    let producers: &dyn Producers = ctx
        .producers
        .get_or_init(|| Box::new(TableSet::default()))
        .as_ref();
    let any: &dyn std::any::Any = producers;
    any.downcast_ref::<TableSet>().map(|set| &set.0)
}

/// Walks `args` fully and renames their variables `_0, _1, …` by first
/// occurrence, recording the renaming in `map` (which starts empty): two
/// calls are variants exactly when their keys are equal.
fn canonical(subst: &Subst, args: &[Term], map: &mut HashMap<Var, Var>) -> Arc<[Term]> {
    args.iter()
        .map(|a| {
            rename(&subst.walk_star(a), &mut |v| {
                let n = u32::try_from(map.len()).unwrap_or(u32::MAX);
                *map.entry(v).or_insert(Var(n))
            })
        })
        .collect()
}

/// `t` with every variable `v` replaced by `f(v)`, visited left to right
/// (`canonical` numbers variables by first occurrence, so the order matters).
/// A thin infallible wrapper over [`Term::try_map_vars`], which keeps ground
/// subterms shared instead of rebuilding them.
fn rename(t: &Term, f: &mut impl FnMut(Var) -> Var) -> Term {
    let mapped: Result<Option<Term>, Infallible> =
        t.try_map_vars(&mut |v| Ok(Some(Term::Var(f(v)))));
    match mapped {
        Ok(changed) => changed.unwrap_or_else(|| t.clone()),
        Err(never) => match never {},
    }
}

/// `t` renamed by `map`; `None` when it has a variable `map` lacks.
fn rename_in(t: &Term, map: &HashMap<Var, Var>) -> Option<Term> {
    match t.try_map_vars(&mut |v| map.get(&v).map(|r| Some(Term::Var(*r))).ok_or(())) {
        Ok(changed) => Some(changed.unwrap_or_else(|| t.clone())),
        Err(()) => None,
    }
}

fn call(rel: &Tabled, args: &Arc<[Term]>, ctx: &Ctx, st: State) -> Out {
    if args.len() != rel.0.arity {
        return Out::Error(RunError::TabledArity {
            relation: rel.0.name,
            arity: rel.0.arity,
            got: args.len(),
        });
    }
    let Some(tables) = tables(ctx) else {
        return Out::Fail;
    };
    let mut map = HashMap::new();
    let key = canonical(&st.subst, args, &mut map);
    let nvars = u32::try_from(map.len()).unwrap_or(u32::MAX);
    let found = tables.borrow().keys.get(&(rel.0.id, key.clone())).copied();
    let table = match found {
        Some(i) => i,
        None => {
            // The body is user code: build it with no table borrowed.
            let body = (rel.0.body)(rel, &key);
            let producer = Scheduler::new(body, State::new(nvars));
            let mut guard = tables.borrow_mut();
            let t = &mut *guard;
            let i = t.tables.len();
            t.tables.push(Table {
                relation: rel.0.name,
                key: key.clone(),
                answers: Vec::new(),
                seen: HashSet::new(),
                status: Status::Runnable(Box::new(producer)),
                dependents: BTreeSet::new(),
            });
            t.keys.insert((rel.0.id, key), i);
            t.runnable.push_back(i);
            t.version += 1;
            i
        }
    };
    Out::Gen(Box::new(TableAnswers {
        table,
        next: 0,
        args: args.clone(),
        state: st,
    }))
}

/// Gives the producer at the front of the queue one turn (and files its
/// answer, its exhaustion or its being stuck), or, when no producer can
/// run, completes what can be completed.
fn drive(tables: &RefCell<Tables>, ctx: &Ctx) -> Result<Drive, RunError> {
    let next = {
        let mut guard = tables.borrow_mut();
        let t = &mut *guard;
        let mut next = None;
        while let Some(idx) = t.runnable.pop_front() {
            let Some(tab) = t.tables.get_mut(idx) else {
                continue;
            };
            match std::mem::replace(&mut tab.status, Status::Busy) {
                Status::Runnable(engine) => {
                    t.busy.push(idx);
                    t.version += 1;
                    next = Some((idx, engine));
                    break;
                }
                // Unreachable by the queue's invariant; put it back as it was.
                other => tab.status = other,
            }
        }
        next
    };
    let Some((idx, mut engine)) = next else {
        return complete_stuck(tables, ctx);
    };
    // No borrow is held here: the producer's goals call tables, and a `naf`
    // among them drives producers itself.
    let turn = engine.turn(ctx);
    let mut guard = tables.borrow_mut();
    let t = &mut *guard;
    t.busy.pop();
    t.version += 1;
    match turn {
        Turn::Answer(st) => {
            record(t, idx, &st, ctx);
            requeue(t, idx, engine);
        }
        Turn::More => requeue(t, idx, engine),
        Turn::Done if ctx.halted.get().is_some() => requeue(t, idx, engine),
        Turn::Done if engine.is_empty() => complete(t, idx, ctx),
        Turn::Done => {
            let mut waits = Vec::new();
            engine.waits_on(&mut waits);
            waits.sort_unstable();
            waits.dedup();
            // Waiting on itself alone, it is a component of its own that
            // nothing outside can feed: complete it now rather than at the
            // next full check (this is what ends a left recursion).
            if waits.iter().all(|&w| w == idx) && !engine.parks_open_choice() {
                complete(t, idx, ctx);
            } else {
                for &w in &waits {
                    if let Some(dep) = t.tables.get_mut(w) {
                        dep.dependents.insert(idx);
                    }
                }
                if let Some(tab) = t.tables.get_mut(idx) {
                    tab.status = Status::Stuck { engine, waits };
                    t.stuck.insert(idx);
                }
            }
        }
        Turn::Error(e) => {
            requeue(t, idx, engine);
            return Err(e);
        }
    }
    Ok(Drive::Progress)
}

fn requeue(t: &mut Tables, idx: usize, engine: Box<Scheduler>) {
    if let Some(tab) = t.tables.get_mut(idx) {
        tab.status = Status::Runnable(engine);
        t.runnable.push_back(idx);
    }
}

/// Adds the answer `st` of table `idx`'s producer, unless the table has it.
fn record(t: &mut Tables, idx: usize, st: &State, ctx: &Ctx) {
    let Some(tab) = t.tables.get_mut(idx) else {
        return;
    };
    let Some(answer) = TabledAnswer::of(&tab.key, st) else {
        return;
    };
    if tab
        .seen
        .insert((answer.tuple.clone(), answer.constraints.clone()))
    {
        tab.answers.push(Arc::new(answer));
        changed(t, idx, ctx);
    }
}

/// Marks table `idx` complete, dropping its producer: nothing the producer
/// waits on can change any more, so its parked consumers would only end.
fn complete(t: &mut Tables, idx: usize, ctx: &Ctx) {
    if let Some(tab) = t.tables.get_mut(idx) {
        tab.status = Status::Complete;
    }
    t.stuck.remove(&idx);
    changed(t, idx, ctx);
}

/// Table `idx` gained an answer or completed: engines with parked tasks look
/// again (the epoch), and the producers stuck on it may run.
fn changed(t: &mut Tables, idx: usize, ctx: &Ctx) {
    ctx.table_epoch.set(ctx.table_epoch.get().wrapping_add(1));
    t.version += 1;
    let dependents = t
        .tables
        .get_mut(idx)
        .map(|tab| std::mem::take(&mut tab.dependents))
        .unwrap_or_default();
    for p in dependents {
        let Some(tab) = t.tables.get_mut(p) else {
            continue;
        };
        if let Status::Stuck { .. } = tab.status
            && let Status::Stuck { engine, .. } =
                std::mem::replace(&mut tab.status, Status::Complete)
        {
            tab.status = Status::Runnable(engine);
            t.stuck.remove(&p);
            t.runnable.push_back(p);
        }
    }
}

/// With no producer able to run: completes every strongly connected
/// component of stuck producers whose waits all stay inside it (a *leaf*:
/// its tables can only be fed by producers that are all waiting on them).
/// A component with waits on a running, busy or other stuck table is left:
/// those may still add answers, and completing it would be premature.
fn complete_stuck(tables: &RefCell<Tables>, ctx: &Ctx) -> Result<Drive, RunError> {
    let mut guard = tables.borrow_mut();
    let t = &mut *guard;
    if t.stuck.is_empty() || t.futile == Some(t.version) {
        return Ok(Drive::Stalled);
    }
    let nodes: Vec<usize> = t.stuck.iter().copied().collect();
    let pos: HashMap<usize, usize> = nodes.iter().enumerate().map(|(i, &n)| (n, i)).collect();
    let mut succ: Vec<Vec<usize>> = vec![Vec::new(); nodes.len()];
    let mut open = vec![false; nodes.len()];
    for (i, &n) in nodes.iter().enumerate() {
        let Some(Status::Stuck { waits, .. }) = t.tables.get(n).map(|tab| &tab.status) else {
            continue;
        };
        for w in waits {
            match pos.get(w) {
                Some(&j) => succ[i].push(j),
                None => {
                    let done = t
                        .tables
                        .get(*w)
                        .is_none_or(|tab| matches!(tab.status, Status::Complete));
                    if !done {
                        open[i] = true;
                    }
                }
            }
        }
    }
    let comp = components(&succ);
    let ncomp = comp.iter().max().map_or(0, |m| m + 1);
    let mut leaf = vec![true; ncomp];
    for (i, next) in succ.iter().enumerate() {
        if open[i] || next.iter().any(|&j| comp[j] != comp[i]) {
            leaf[comp[i]] = false;
        }
    }
    let done: Vec<usize> = (0..nodes.len())
        .filter(|&i| leaf[comp[i]])
        .map(|i| nodes[i])
        .collect();
    if done.is_empty() {
        t.futile = Some(t.version);
        return Ok(Drive::Stalled);
    }
    // A committed choice with an `else` still open in the component would
    // take that branch once the component's tables are complete, adding
    // answers to them: its answers depend on their own completion.
    for &n in &done {
        if let Some(tab) = t.tables.get(n)
            && let Status::Stuck { engine, .. } = &tab.status
            && engine.parks_open_choice()
        {
            return Err(RunError::TabledNegationCycle {
                relation: tab.relation,
            });
        }
    }
    for n in done {
        complete(t, n, ctx);
    }
    Ok(Drive::Progress)
}

/// The strongly connected components of the graph `succ` (Tarjan's
/// algorithm, with an explicit stack: a component can be as long as a
/// table chain): one component number per node.
fn components(succ: &[Vec<usize>]) -> Vec<usize> {
    const NONE: usize = usize::MAX;
    let n = succ.len();
    let mut index = vec![NONE; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut comp = vec![NONE; n];
    let mut next_index = 0;
    let mut ncomp = 0;
    for root in 0..n {
        if index[root] != NONE {
            continue;
        }
        index[root] = next_index;
        low[root] = next_index;
        next_index += 1;
        stack.push(root);
        on_stack[root] = true;
        let mut calls: Vec<(usize, usize)> = vec![(root, 0)];
        while let Some(&mut (v, ref mut edge)) = calls.last_mut() {
            if let Some(&w) = succ[v].get(*edge) {
                *edge += 1;
                if index[w] == NONE {
                    index[w] = next_index;
                    low[w] = next_index;
                    next_index += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    calls.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
                continue;
            }
            calls.pop();
            if let Some(&(u, _)) = calls.last() {
                low[u] = low[u].min(low[v]);
            }
            if low[v] == index[v] {
                while let Some(w) = stack.pop() {
                    on_stack[w] = false;
                    comp[w] = ncomp;
                    if w == v {
                        break;
                    }
                }
                ncomp += 1;
            }
        }
    }
    comp
}

/// The error for a search whose tasks all wait on tables that nothing can
/// complete: only a table whose evaluation is on the stack (a `naf` inside
/// its producer's turn) can hold them up, and its answers depend on that
/// negation.
fn stalled(tables: &RefCell<Tables>, waits: &[usize]) -> RunError {
    let t = tables.borrow();
    let relation = t
        .busy
        .last()
        .or(waits.first())
        .and_then(|&i| t.tables.get(i))
        .map_or_else(|| Sym::new("tabled"), |tab| tab.relation);
    RunError::TabledNegationCycle { relation }
}

impl TabledAnswer {
    /// The answer `st` gives to the table with key `key`; `None` when its
    /// constraints turn out violated (the store never keeps such a state;
    /// this is a guard, not a path).
    fn of(key: &[Term], st: &State) -> Option<TabledAnswer> {
        let mut map = HashMap::new();
        let tuple = canonical(&st.subst, key, &mut map);
        let nvars = u32::try_from(map.len()).ok()?;
        let constraints = if st.store.is_empty() || map.is_empty() {
            Vec::new()
        } else {
            constraints_of(st, &map)?
        };
        Some(TabledAnswer {
            tuple,
            nvars,
            constraints: constraints.into(),
            proof: st.proof.clone(),
        })
    }

    /// The answer for a consumer: its variables made fresh in `state`, its
    /// tuple unified with `args`, its constraints re-posted, its proof
    /// appended. `None` when it does not fit the call.
    fn instantiate(&self, state: &State, args: &[Term], ctx: &Ctx) -> Option<State> {
        let mut st = state.clone();
        let base = st.next_var;
        st.next_var = base.checked_add(self.nvars)?;
        let shift = |t: &Term| {
            if self.nvars == 0 {
                t.clone()
            } else {
                rename(t, &mut |v| Var(base.saturating_add(v.0)))
            }
        };
        for (a, t) in args.iter().zip(self.tuple.iter()) {
            st = st.unify(a, &shift(t), ctx.occurs_check)?;
        }
        for c in self.constraints.iter() {
            st = match c {
                Constraint::Neq(l, r) => st.neq(&shift(l), &shift(r), ctx.occurs_check)?,
                Constraint::Type(v, ty) => {
                    st.post_type(&Term::Var(Var(base.saturating_add(v.0))), *ty)?
                }
                Constraint::Absent(tag, v) => st.post_absent(
                    tag,
                    &Term::Var(Var(base.saturating_add(v.0))),
                    ctx.occurs_check,
                )?,
            };
        }
        if ctx.proofs {
            for step in proof::to_vec(&self.proof) {
                st.record(step);
            }
        }
        Some(st)
    }
}

/// The constraints of `st` on the answer variables (the keys of `map`),
/// renamed by `map`, sorted, without duplicates. `None` when a disequality
/// has every pair already equal (violated).
fn constraints_of(st: &State, map: &HashMap<Var, Var>) -> Option<Vec<Constraint>> {
    let mut out = Vec::new();
    for (orig, canon) in map {
        let Some(attr) = st.store.get(&orig.0) else {
            continue;
        };
        if let Some(ty) = attr.ty {
            out.push(Constraint::Type(*canon, ty));
        }
        for tag in &attr.absent {
            out.push(Constraint::Absent(tag.clone(), *canon));
        }
        'neqs: for d in &attr.neqs {
            // The pairs were solved against an older substitution: walk
            // them again, drop those that now hold, keep the rest.
            let mut pairs = Vec::with_capacity(d.pairs.len());
            for (x, t) in &d.pairs {
                let l = st.subst.walk_star(&Term::Var(*x));
                let r = st.subst.walk_star(t);
                if l == r {
                    continue;
                }
                let (Some(l), Some(r)) = (rename_in(&l, map), rename_in(&r, map)) else {
                    // A variable local to the body: always satisfiable.
                    continue 'neqs;
                };
                pairs.push(if l <= r { (l, r) } else { (r, l) });
            }
            pairs.sort();
            pairs.dedup();
            let (ls, rs): (Vec<Term>, Vec<Term>) = pairs.into_iter().unzip();
            out.push(match (ls.as_slice(), rs.as_slice()) {
                ([], _) | (_, []) => return None,
                ([l], [r]) => Constraint::Neq(l.clone(), r.clone()),
                _ => Constraint::Neq(Term::list(ls), Term::list(rs)),
            });
        }
    }
    out.sort();
    out.dedup();
    Some(out)
}

/// A consumer: the answers of one table in the order they were added, each
/// unified with the call's arguments.
///
/// Invariant: the answers before `next` have been handed out (or did not
/// fit); `state` is the caller's state at the call.
pub(crate) struct TableAnswers {
    table: usize,
    next: usize,
    args: Arc<[Term]>,
    state: State,
}

impl Generator for TableAnswers {
    fn next(&mut self, ctx: &Ctx) -> GenStep {
        let Some(tables) = tables(ctx) else {
            return GenStep::Done;
        };
        loop {
            let (answer, more) = {
                let t = tables.borrow();
                let Some(tab) = t.tables.get(self.table) else {
                    return GenStep::Done;
                };
                let complete = matches!(tab.status, Status::Complete);
                match tab.answers.get(self.next) {
                    Some(a) => (a.clone(), self.next + 1 < tab.answers.len() || !complete),
                    None if complete => return GenStep::Done,
                    None => {
                        return GenStep::Suspend(Wait::Table {
                            table: self.table,
                            seen: self.next,
                        });
                    }
                }
            };
            self.next += 1;
            if let Some(st) = answer.instantiate(&self.state, &self.args, ctx) {
                return GenStep::Yield(st, None, more);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `rename` visits variables left to right through compound terms, list
    /// heads and a list's tail, and leaves constants alone: `canonical`
    /// relies on that order to number variables by first occurrence.
    #[test]
    fn canonical_numbers_variables_by_first_occurrence_everywhere() {
        let v = |i: u32| Term::Var(Var(i));
        let args = [
            Term::app("f", [v(7), Term::from("a"), v(3)]),
            Term::list_with_tail([v(3), Term::from(1i64), v(9)], v(7)),
            Term::cons(Term::from("b"), Term::list([v(5)])),
        ];
        let mut map = HashMap::new();
        let key = canonical(&Subst::default(), &args, &mut map);
        assert_eq!(map.len(), 4);
        let want = [
            Term::app("f", [v(0), Term::from("a"), v(1)]),
            Term::list_with_tail([v(1), Term::from(1i64), v(2)], v(0)),
            Term::cons(Term::from("b"), Term::list([v(3)])),
        ];
        assert_eq!(&key[..], &want[..]);
        // A ground term comes back equal (and shared, not rebuilt).
        let ground = Term::app("g", [Term::list([1i64, 2]), Term::from("c")]);
        let same = rename(&ground, &mut |x| x);
        assert_eq!(same, ground);
        if let (Term::App(_, a), Term::App(_, b)) = (&same, &ground) {
            assert!(Arc::ptr_eq(a, b));
        }
    }

    /// Tarjan on a graph with a cycle, a self-loop, a chain and an isolated
    /// node: nodes share a component exactly when they reach each other.
    #[test]
    fn components_are_the_strongly_connected_ones() {
        // 0 -> 1 -> 2 -> 0 (cycle), 2 -> 3, 3 -> 3 (self-loop), 4 alone, 5 -> 4
        let succ = vec![vec![1], vec![2], vec![0, 3], vec![3], vec![], vec![4]];
        let comp = components(&succ);
        assert_eq!(comp[0], comp[1]);
        assert_eq!(comp[1], comp[2]);
        let distinct: BTreeSet<usize> = [comp[0], comp[3], comp[4], comp[5]].into();
        assert_eq!(distinct.len(), 4);
        // Reverse topological order: a component comes after those it reaches.
        assert!(comp[3] < comp[0]);
        assert!(comp[4] < comp[5]);
    }
}
