//! Goals and their combinators.
//!
//! A [`Goal`] is built once (a tree of `Arc`-shared nodes) and applied to many
//! states. The common goals — `eq`, `conj`, `disj` — are enum variants the
//! stepper matches on directly; everything else is a closure. Recursive
//! relations are ordinary Rust functions returning goals: `fresh` and `disj`
//! are *delayed* (their bodies are built or applied only when the search
//! steps into them), so a relation that calls itself inside either never
//! loops at construction and never recurses without yielding control. Use
//! [`delay`] for recursion that is guarded by neither.

use crate::ctx::{Ctx, GenStep, Scan};
use crate::engine::{NativeOut, Out, Scheduler, Sub, first_answer};
use crate::error::RunError;
use crate::proof::ProofStep;
use crate::state::{State, TypeTag};
use crate::term::{Sym, Term, Var};
use std::sync::Arc;

type GoalFn = dyn Fn(&Ctx, State) -> Out + Send + Sync;

/// A goal kept as data that the engine runs through this trait: the store
/// layer's fact goals and list scans. Data rather than a closure so that
/// `naf` can ask it for a one-lookup answer ([`Native::ground_holds`]), and
/// so that a scan it starts can be lent the goal where it lies at each
/// later step ([`Native::resume`]) instead of holding a copy.
pub(crate) trait Native: Send + Sync {
    /// The goal's name, for `Debug`.
    fn name(&self) -> &'static str;
    /// Runs the goal on `st`. It may return [`NativeOut::Scan`]: a scan
    /// whose later steps are [`Native::resume`] of this goal.
    fn run(&self, ctx: &Ctx, st: State) -> NativeOut;
    /// One later step of a scan that [`Native::run`] of this goal started.
    fn resume(&self, _ctx: &Ctx, _scan: &mut Scan) -> GenStep {
        GenStep::Done
    }
    /// Whether the goal holds on `st` when that is one lookup (a fact whose
    /// arguments are all bound); `None` when a search is needed.
    fn ground_holds(&self, _st: &State) -> Option<bool> {
        None
    }
}

/// The goal's representation: the goals the engine runs itself are variants
/// it matches on; everything else is one shared closure. Each variant costs
/// one allocation to build (none for `Succeed`/`Fail`).
#[derive(Clone)]
pub(crate) enum G {
    Succeed,
    Fail,
    Eq(Arc<(Term, Term)>),
    Conj(Arc<[Goal]>),
    Disj(Arc<[Goal]>),
    /// A goal kept as data ([`Native`]: a fact goal, a `membero`/`nextto`
    /// scan): the engine lends it to the scans it starts at every step, so
    /// a scan copies nothing out of it, and `naf` can look a fact up.
    Native(Arc<dyn Native>),
    Fn(Arc<GoalFn>),
}

/// A goal: a relation applied to terms, run on search states by the engine.
///
/// Invariant: running one goal on a state does a bounded amount of work
/// before the engine regains control (recursion goes through `fresh`,
/// `disj` or `delay`, each of which yields back to the engine's turn
/// loop), which is what lets the search interleave branches fairly and count
/// steps against a budget. Cloning a goal is one reference-count increment.
#[derive(Clone)]
pub struct Goal(pub(crate) G);

impl std::fmt::Debug for Goal {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            G::Succeed => f.write_str("succeed"),
            G::Fail => f.write_str("fail"),
            G::Eq(ab) => write!(f, "eq({}, {})", ab.0, ab.1),
            G::Conj(gs) => f.debug_tuple("conj").field(&gs.len()).finish(),
            G::Disj(gs) => f.debug_tuple("disj").field(&gs.len()).finish(),
            G::Native(g) => f.write_str(g.name()),
            G::Fn(_) => f.write_str("goal"),
        }
    }
}

/// Wraps a closure as a goal (crate-internal building block).
pub(crate) fn goal_fn(f: impl Fn(&Ctx, State) -> Out + Send + Sync + 'static) -> Goal {
    Goal::from_fn(f)
}

impl Goal {
    /// Wraps a [`Native`] goal (crate-internal building block).
    pub(crate) fn native(g: impl Native + 'static) -> Goal {
        Goal(G::Native(Arc::new(g)))
    }

    fn from_fn(f: impl Fn(&Ctx, State) -> Out + Send + Sync + 'static) -> Goal {
        Goal(G::Fn(Arc::new(f)))
    }
}

/// The goal that always succeeds once.
pub fn succeed() -> Goal {
    Goal(G::Succeed)
}

/// The goal that never succeeds.
pub fn fail() -> Goal {
    Goal(G::Fail)
}

/// Unification: `a` and `b` are made equal.
pub fn eq(a: impl Into<Term>, b: impl Into<Term>) -> Goal {
    Goal(G::Eq(Arc::new((a.into(), b.into()))))
}

/// Disequality: `a` and `b` must never become equal. Stored as a constraint
/// and re-checked whenever one of its variables is bound.
pub fn neq(a: impl Into<Term>, b: impl Into<Term>) -> Goal {
    let (a, b) = (a.into(), b.into());
    Goal::from_fn(move |ctx, st| match st.neq(&a, &b, ctx.occurs_check) {
        Some(s) => Out::Ok(s),
        None => Out::Fail,
    })
}

/// All of `goals` (left to right). The empty conjunction succeeds.
pub fn conj(goals: impl IntoIterator<Item = Goal>) -> Goal {
    // Collecting straight into the `Arc` is one allocation for arrays and
    // other exact-size sources.
    let gs: Arc<[Goal]> = goals.into_iter().collect();
    match gs.len() {
        0 => succeed(),
        1 => gs.first().cloned().unwrap_or_else(succeed),
        _ => Goal(G::Conj(gs)),
    }
}

/// Alias of [`conj`] (miniKanren's `all`).
pub fn all(goals: impl IntoIterator<Item = Goal>) -> Goal {
    conj(goals)
}

/// Any of `goals`, interleaved fairly. The empty disjunction fails.
pub fn disj(goals: impl IntoIterator<Item = Goal>) -> Goal {
    let gs: Arc<[Goal]> = goals.into_iter().collect();
    match gs.len() {
        0 => fail(),
        1 => gs.first().cloned().unwrap_or_else(fail),
        _ => Goal(G::Disj(gs)),
    }
}

/// `conde`: a disjunction of conjunctions (one `Vec` per clause).
pub fn conde(clauses: impl IntoIterator<Item = Vec<Goal>>) -> Goal {
    disj(clauses.into_iter().map(conj))
}

/// Introduces `N` fresh variables: `fresh(|[a, d]| conj([...]))`. The body is
/// built when the search reaches it, one step later (the delay that keeps
/// recursive relations from looping).
pub fn fresh<const N: usize>(f: impl Fn([Term; N]) -> Goal + Send + Sync + 'static) -> Goal {
    Goal::from_fn(move |_ctx, mut st| {
        let vars: [Term; N] = std::array::from_fn(|_| st.fresh_var());
        Out::Then(st, f(vars))
    })
}

/// Builds the goal from `f` when the search reaches it (one step later): the
/// delay for recursion that is not already under a `fresh` or a `disj`.
pub fn delay(f: impl Fn() -> Goal + Send + Sync + 'static) -> Goal {
    Goal::from_fn(move |_ctx, st| Out::Then(st, f()))
}

fn ifte_chain(clauses: &[Vec<Goal>], once: bool) -> Option<Goal> {
    let (clause, rest) = clauses.split_first()?;
    let els = ifte_chain(rest, once);
    let Some((head, then)) = clause.split_first() else {
        // An empty clause is a head that succeeds: it commits here.
        return Some(succeed());
    };
    let head = head.clone();
    let then = (!then.is_empty()).then(|| conj(then.iter().cloned()));
    Some(Goal::from_fn(move |_ctx, st| {
        Out::Gen(Box::new(Sub {
            head: Scheduler::new(head.clone(), st.clone()),
            then: then.clone(),
            els: els.clone(),
            state: st,
            once,
            committed: false,
        }))
    }))
}

/// `conda` (soft cut): the first clause whose head goal succeeds is committed
/// to, with all of that head's answers; later clauses are not tried.
pub fn conda(clauses: impl IntoIterator<Item = Vec<Goal>>) -> Goal {
    let cs: Vec<Vec<Goal>> = clauses.into_iter().collect();
    ifte_chain(&cs, false).unwrap_or_else(fail)
}

/// `condu` (committed choice): like `conda`, but keeps only the head's first answer.
pub fn condu(clauses: impl IntoIterator<Item = Vec<Goal>>) -> Goal {
    let cs: Vec<Vec<Goal>> = clauses.into_iter().collect();
    ifte_chain(&cs, true).unwrap_or_else(fail)
}

/// The first answer of `g` only.
pub fn onceo(g: Goal) -> Goal {
    Goal::from_fn(move |_ctx, st| {
        Out::Gen(Box::new(Sub {
            head: Scheduler::new(g.clone(), st.clone()),
            then: None,
            els: None,
            state: st,
            once: true,
            committed: false,
        }))
    })
}

fn type_goal(t: Term, ty: TypeTag) -> Goal {
    Goal::from_fn(move |_ctx, st| match st.post_type(&t, ty) {
        Some(s) => Out::Ok(s),
        None => Out::Fail,
    })
}

/// `t` is (or will be) a symbol.
pub fn symbolo(t: impl Into<Term>) -> Goal {
    type_goal(t.into(), TypeTag::Sym)
}

/// `t` is (or will be) an integer.
pub fn numbero(t: impl Into<Term>) -> Goal {
    type_goal(t.into(), TypeTag::Num)
}

/// `t` is (or will be) a string.
pub fn stringo(t: impl Into<Term>) -> Goal {
    type_goal(t.into(), TypeTag::Str)
}

/// The ground term `tag` occurs nowhere in `t` (now or after any later
/// binding). Running it with a non-ground `tag` is a [`RunError::NonGroundAbsento`].
pub fn absento(tag: impl Into<Term>, t: impl Into<Term>) -> Goal {
    let (tag, t) = (tag.into(), t.into());
    Goal::from_fn(
        move |ctx, st| match st.absento(&tag, &t, ctx.occurs_check) {
            Ok(Some(s)) => Out::Ok(s),
            Ok(None) => Out::Fail,
            Err(e) => Out::Error(e),
        },
    )
}

/// Calls a host computation on the current values of `terms` (fully walked;
/// unbound parts stay variables) and runs the goal it returns.
pub fn project(terms: Vec<Term>, f: impl Fn(&[Term]) -> Goal + Send + Sync + 'static) -> Goal {
    Goal::from_fn(move |_ctx, st| {
        let vals: Vec<Term> = terms.iter().map(|t| st.subst.walk_star(t)).collect();
        Out::Then(st, f(&vals))
    })
}

/// Like [`project`], for host computations that can fail: an `Err` becomes a
/// [`RunError::Host`] reported by the run.
pub fn project_result(
    terms: Vec<Term>,
    f: impl Fn(&[Term]) -> Result<Goal, String> + Send + Sync + 'static,
) -> Goal {
    Goal::from_fn(move |_ctx, st| {
        let vals: Vec<Term> = terms.iter().map(|t| st.subst.walk_star(t)).collect();
        match f(&vals) {
            Ok(g) => Out::Then(st, g),
            Err(msg) => Out::Error(RunError::Host(msg)),
        }
    })
}

/// Negation as failure: succeeds (once, binding nothing) when `g` has no
/// answer. When `g` does have an answer that binds or constrains a variable
/// that existed before the negation — `g` was run with unbound variables, so
/// its failure is undecided — the run reports [`RunError::UnboundNegation`]
/// instead of guessing. Local variables of `g` (its own `fresh`) are fine.
pub fn naf(g: Goal) -> Goal {
    Goal::from_fn(move |ctx, st| {
        // A fact whose arguments are all bound is one lookup, not a search.
        if let G::Native(f) = &g.0
            && let Some(holds) = f.ground_holds(&st)
        {
            return if !ctx.tick() || holds {
                Out::Fail
            } else {
                Out::Ok(st)
            };
        }
        let mark = st.next_var;
        match first_answer(ctx, g.clone(), st.clone()) {
            Err(e) => Out::Error(e),
            Ok(None) => {
                if ctx.halted.get().is_some() {
                    Out::Fail
                } else {
                    Out::Ok(st)
                }
            }
            Ok(Some(ans)) => {
                let mut bound: Vec<Var> = ans
                    .subst
                    .iter()
                    .filter(|(v, _)| v.0 < mark && st.subst.get(*v).is_none())
                    .map(|(v, _)| v)
                    .collect();
                for (k, _) in ans.store.iter() {
                    if *k < mark && st.subst.get(Var(*k)).is_none() && !st.store.contains_key(k) {
                        bound.push(Var(*k));
                    }
                }
                if bound.is_empty() {
                    Out::Fail
                } else {
                    bound.sort();
                    bound.dedup();
                    Out::Error(RunError::UnboundNegation {
                        vars: bound.iter().map(|v| v.to_string()).collect(),
                    })
                }
            }
        }
    })
}

/// Names a rule: when proofs are on, records [`ProofStep::Rule`] before the
/// steps of `g`; otherwise it is `g`.
pub fn label(name: impl Into<Sym>, g: Goal) -> Goal {
    let name = name.into();
    Goal::from_fn(move |ctx, mut st| {
        if ctx.proofs {
            st.record(ProofStep::Rule(name));
        }
        Out::Then(st, g.clone())
    })
}
