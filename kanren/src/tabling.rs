//! Tabled relations: answer tables per call variant, computed to a fixpoint.
//!
//! A call to a tabled relation is reduced to its *variant key* — the walked
//! arguments with their variables renamed `_0, _1, …` by first occurrence —
//! and answered from that key's table. The first call of a key evaluates the
//! body repeatedly (semi-naively: each pass reads the answers found so far)
//! until a pass adds no answer anywhere; a recursive call of a key that is
//! still being evaluated reads its table instead of re-entering the body.
//! Left-recursive relations over cyclic data therefore terminate, with every
//! answer, provided the set of answers is finite.
//!
//! Keys that depend on each other are completed together (a lowlink, as in
//! Tarjan's SCC algorithm, marks which evaluation is their leader): a table
//! that read an ancestor's still-growing table stays incomplete and is
//! re-evaluated by the leader's next pass; when the leader's pass adds
//! nothing, all of them are complete.
//!
//! Limits: answers are the arguments' bindings (constraints the body puts on
//! non-ground answers are not kept in the table); tables live for one run.

use crate::engine::{Ctx, Gen, GenStep, Out, for_each_answer};
use crate::error::RunError;
use crate::goal::{Goal, goal_fn};
use crate::proof::{self, ProofNode};
use crate::state::State;
use crate::subst::Subst;
use crate::term::{Sym, Term, Var};
use std::collections::{HashMap, HashSet};
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

type Answer = (Arc<[Term]>, Option<Arc<ProofNode>>);

struct Table {
    answers: Vec<Answer>,
    seen: HashSet<Arc<[Term]>>,
    complete: bool,
    /// The evaluation-stack depth while its body is being evaluated.
    evaluating: Option<usize>,
}

struct Frame {
    lowlink: usize,
}

/// All tables of one run.
#[derive(Default)]
pub(crate) struct Tables {
    keys: HashMap<(usize, Arc<[Term]>), usize>,
    tables: Vec<Table>,
    /// Answers added so far, over all tables: a pass that leaves it unchanged
    /// has reached the fixpoint.
    added: u64,
    stack: Vec<Frame>,
    /// Incomplete tables waiting for their leader to finish.
    pending: Vec<usize>,
}

/// Walks `args` fully and renames their variables `_0, _1, …` by first
/// occurrence: two calls are variants exactly when their keys are equal.
fn canonical(subst: &Subst, args: &[Term]) -> (Arc<[Term]>, u32) {
    let mut map: HashMap<Var, Var> = HashMap::new();
    let out: Vec<Term> = args
        .iter()
        .map(|a| {
            rename(&subst.walk_star(a), &mut |v| {
                let n = u32::try_from(map.len()).unwrap_or(u32::MAX);
                *map.entry(v).or_insert(Var(n))
            })
        })
        .collect();
    (out.into(), u32::try_from(map.len()).unwrap_or(u32::MAX))
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

fn call(rel: &Tabled, args: &Arc<[Term]>, ctx: &Ctx, st: State) -> Out {
    if args.len() != rel.0.arity {
        return Out::Error(RunError::TabledArity {
            relation: rel.0.name,
            arity: rel.0.arity,
            got: args.len(),
        });
    }
    let (key, nvars) = canonical(&st.subst, args);
    let idx = {
        let mut tables = ctx.tables.borrow_mut();
        let t = &mut *tables;
        match t.keys.get(&(rel.0.id, key.clone())) {
            Some(&i) => i,
            None => {
                let i = t.tables.len();
                t.tables.push(Table {
                    answers: Vec::new(),
                    seen: HashSet::new(),
                    complete: false,
                    evaluating: None,
                });
                t.keys.insert((rel.0.id, key.clone()), i);
                i
            }
        }
    };
    let must_evaluate = {
        let mut tables = ctx.tables.borrow_mut();
        let (complete, evaluating) = match tables.tables.get(idx) {
            Some(t) => (t.complete, t.evaluating),
            None => (true, None),
        };
        if let Some(d) = evaluating
            && let Some(top) = tables.stack.last_mut()
        {
            top.lowlink = top.lowlink.min(d);
        }
        !complete && evaluating.is_none()
    };
    if must_evaluate && let Err(e) = evaluate(rel, idx, &key, nvars, ctx) {
        return Out::Error(e);
    }
    Out::Gen(Gen::Table(Box::new(TableAnswers {
        table: idx,
        next: 0,
        args: args.clone(),
        state: st,
    })))
}

fn evaluate(
    rel: &Tabled,
    idx: usize,
    key: &Arc<[Term]>,
    nvars: u32,
    ctx: &Ctx,
) -> Result<(), RunError> {
    let (depth, pending_mark) = {
        let mut t = ctx.tables.borrow_mut();
        let depth = t.stack.len();
        t.stack.push(Frame { lowlink: depth });
        if let Some(tab) = t.tables.get_mut(idx) {
            tab.evaluating = Some(depth);
        }
        (depth, t.pending.len())
    };
    let result = loop {
        let added0 = ctx.tables.borrow().added;
        let goal = (rel.0.body)(rel, key);
        let mut pass_err = None;
        let r = for_each_answer(ctx, goal, State::new(nvars), |ans| {
            let (tuple, _) = canonical(&ans.subst, key);
            let mut t = ctx.tables.borrow_mut();
            let t = &mut *t;
            if let Some(tab) = t.tables.get_mut(idx)
                && tab.seen.insert(tuple.clone())
            {
                tab.answers.push((tuple, ans.proof));
                t.added += 1;
            }
        });
        if let Err(e) = r {
            pass_err = Some(e);
        }
        if let Some(e) = pass_err {
            break Err(e);
        }
        if ctx.halted.get().is_some() || ctx.tables.borrow().added == added0 {
            break Ok(());
        }
    };
    let mut t = ctx.tables.borrow_mut();
    let frame = t.stack.pop();
    if let Some(tab) = t.tables.get_mut(idx) {
        tab.evaluating = None;
    }
    if result.is_err() || ctx.halted.get().is_some() {
        return result;
    }
    let lowlink = frame.map_or(depth, |f| f.lowlink);
    if lowlink < depth {
        if let Some(parent) = t.stack.last_mut() {
            parent.lowlink = parent.lowlink.min(lowlink);
        }
        t.pending.push(idx);
    } else {
        let done: Vec<usize> = t.pending.drain(pending_mark..).collect();
        for i in done.into_iter().chain([idx]) {
            if let Some(tab) = t.tables.get_mut(i) {
                tab.complete = true;
            }
        }
    }
    result
}

/// The generator of a tabled call: the table's answers in the order found,
/// unified with the call's arguments.
pub(crate) struct TableAnswers {
    table: usize,
    next: usize,
    args: Arc<[Term]>,
    state: State,
}

impl TableAnswers {
    pub(crate) fn next(&mut self, ctx: &Ctx) -> GenStep {
        loop {
            let answer = {
                let t = ctx.tables.borrow();
                t.tables
                    .get(self.table)
                    .and_then(|tab| tab.answers.get(self.next).cloned())
            };
            let Some((tuple, proof_steps)) = answer else {
                return GenStep::Done;
            };
            self.next += 1;
            let mut st = self.state.clone();
            let base = st.next_var;
            let mut max = 0u32;
            let inst: Vec<Term> = tuple
                .iter()
                .map(|t| {
                    rename(t, &mut |v| {
                        max = max.max(v.0 + 1);
                        Var(base + v.0)
                    })
                })
                .collect();
            st.next_var = base + max;
            let mut ok = Some(st);
            for (a, t) in self.args.iter().zip(&inst) {
                ok = ok.and_then(|s| s.unify(a, t, ctx.occurs_check));
            }
            if let Some(mut st) = ok {
                if ctx.proofs {
                    for step in proof::to_vec(&proof_steps) {
                        st.record(step);
                    }
                }
                return GenStep::Yield(st, None, true);
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
        let (key, n) = canonical(&Subst::default(), &args);
        assert_eq!(n, 4);
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
}
