//! Compiling a checked query to kanren goals over a [`Model`]'s relations:
//! its plan (one rule per alternative, its `¬∃` literals), kept with the
//! query for counting, and the goal each alternative runs as.

use super::ast::{AskError, PlanCache, QueryAst};
use super::check::safety;
use crate::diag::SourceFile;
use crate::eval::Model;
use crate::fol::{self, Arg, Literal};
use crate::program::{CArg, CAtom, Rule, RuleSource};
use kanren::{FactId, Goal, RunConfig, Sym, Term};
use std::sync::Arc;

/// A query compiled against one program: what [`Model::compile`] needs
/// besides the window's relations.
///
/// Invariant: `rules`, `labels` have one entry per alternative of the
/// query; `program` is the program it was compiled against. A weak
/// reference, not an address: a query may outlive its program (a REPL
/// reloads its LogicPad), and a new program could be allocated at the
/// old one's address, where a stale plan would read the wrong relations;
/// the weak reference keeps the allocation, so no other program gets it.
pub(crate) struct Plan {
    pub(super) program: std::sync::Weak<crate::program::Inner>,
    pub(super) rules: Vec<Option<Arc<Rule>>>,
    pub(super) labels: Vec<Sym>,
    pub(super) answer_vars: Vec<usize>,
    pub(super) names: Vec<String>,
    /// The `¬∃` literals of each alternative, compiled; empty (no
    /// allocation) when the query has none, as nearly every query.
    pub(super) not_exists: Vec<Arc<[NotExistsPlan]>>,
}

/// A `¬∃vars: body` literal compiled: the body as a rule (its positive
/// atoms joined, negated atoms and comparisons tested inside the join),
/// its own nested `¬∃`, and the slots of its own variables, which get
/// fresh kanren variables each time it runs (so that `naf` sees them as
/// local).
///
/// Invariant: `rule` is `None` when a positive atom of the body can never
/// hold (an unknown predicate, a wrong arity): the literal then always
/// holds. `literal` is the literal as resolved, for proofs.
pub(crate) struct NotExistsPlan {
    locals: Vec<usize>,
    rule: Option<Arc<Rule>>,
    nested: Arc<[NotExistsPlan]>,
    pub(super) literal: Literal,
}

/// `naf` of each `¬∃` of `nes`, after `g` (which binds every variable
/// they read from outside).
fn with_not_exists(
    rels: &Arc<[Arc<kanren::Relation>]>,
    g: Goal,
    nes: &[NotExistsPlan],
    terms: &Arc<[Term]>,
) -> Goal {
    if nes.is_empty() {
        return g;
    }
    kanren::conj(
        std::iter::once(g).chain(
            nes.iter()
                .map(|ne| kanren::naf(not_exists_goal(rels, ne, terms))),
        ),
    )
}

/// The goal whose failure a `¬∃` asks for: fresh variables for its own
/// slots, then the join of its body (with its nested `¬∃`).
fn not_exists_goal(
    rels: &Arc<[Arc<kanren::Relation>]>,
    ne: &NotExistsPlan,
    terms: &Arc<[Term]>,
) -> Goal {
    let Some(rule) = ne.rule.clone() else {
        return kanren::fail();
    };
    let (rels, terms) = (Arc::clone(rels), Arc::clone(terms));
    let locals = ne.locals.clone();
    let nested = Arc::clone(&ne.nested);
    let body = Arc::new(move |fresh: &[Term]| {
        let mut t: Vec<Term> = terms.to_vec();
        for (&slot, v) in locals.iter().zip(fresh) {
            if let Some(x) = t.get_mut(slot) {
                *x = v.clone();
            }
        }
        let t: Arc<[Term]> = t.into();
        with_not_exists(&rels, join_goal(&rels, &rule, &t), &nested, &t)
    });
    with_fresh(ne.locals.len(), Vec::new(), body)
}

/// A goal made from the terms of fresh variables (see [`with_fresh`]).
type FreshBody = Arc<dyn Fn(&[Term]) -> Goal + Send + Sync>;

/// The goal `k(v₁…vₙ)` over `n` fresh kanren variables, made when the
/// search reaches it (after the `naf` that encloses it has taken its mark).
fn with_fresh(n: usize, acc: Vec<Term>, k: FreshBody) -> Goal {
    if n == 0 {
        return k(&acc);
    }
    kanren::fresh(move |[v]| {
        let mut next = acc.clone();
        next.push(v);
        with_fresh(n - 1, next, Arc::clone(&k))
    })
}

/// A compiled rule's join over `terms`: `join_where` of its positive
/// atoms with `naf` of each negated atom and `=`/`=/=` of each comparison
/// tested inside it.
fn join_goal(rels: &Arc<[Arc<kanren::Relation>]>, rule: &Rule, terms: &Arc<[Term]>) -> Goal {
    // Most queries have no negation and no comparison: share one empty
    // list rather than allocate two per query.
    type Empty = (Arc<[CAtom]>, Arc<[kanren::join::Cmp]>);
    static NONE: std::sync::OnceLock<Empty> = std::sync::OnceLock::new();
    let none = NONE.get_or_init(|| (Arc::from([]), Arc::from([])));
    let negated = if rule.negated.is_empty() {
        none.0.clone()
    } else {
        rule.negated.clone().into()
    };
    let cmps = if rule.cmps.is_empty() {
        none.1.clone()
    } else {
        rule.cmps.clone().into()
    };
    kanren::join::join_where(
        rels.clone(),
        rule.body.clone(),
        negated,
        cmps,
        terms.clone(),
    )
}

/// A query compiled to a kanren program: one goal over one kanren variable
/// per query variable, `conde` over the alternatives, each alternative
/// labelled (so an answer's proof says which one produced it) and run as
///
/// `join(positive atoms) ∧ (a = b | a =/= b)… ∧ naf(fact(negated atom))…`
///
/// — kanren's indexed join for the positive atoms (planned when it runs),
/// then the comparisons through unification and the disequality store, then
/// negation as failure (a lookup, since safety binds every variable of a
/// negated atom first).
///
/// Invariant: `rules[i]` is alternative `i` compiled for proofs (`None`
/// when a positive atom can never hold, and the alternative is `fail`);
/// `labels[i]` is its label.
pub(super) struct Compiled {
    query: kanren::Query,
    goal: Goal,
    pub(super) plan: Arc<Plan>,
}

impl Compiled {
    /// Runs the program lazily.
    pub(super) fn run(&self, proofs: bool, budget: kanren::Budget) -> kanren::Run {
        self.query.run(
            self.goal.clone(),
            RunConfig {
                limit: None,
                proofs,
                budget,
            },
        )
    }

    /// The answer variables' values of one kanren answer.
    pub(super) fn key(&self, a: &kanren::Answer) -> Vec<Term> {
        self.plan
            .answer_vars
            .iter()
            .map(|&v| a.values.get(v).cloned().unwrap_or(Term::Nil))
            .collect()
    }

    /// The alternative and the fact of each positive literal, read from an
    /// answer's proof steps (the label comes first, then one fact per atom).
    pub(super) fn premises(&self, a: &kanren::Answer) -> Option<(usize, Vec<FactId>)> {
        let steps = &a.proof.as_ref()?.steps;
        let mut alt = None;
        let mut prem = Vec::new();
        for s in steps {
            match s {
                kanren::ProofStep::Rule(l) => alt = self.plan.labels.iter().position(|x| x == l),
                kanren::ProofStep::Fact { id, .. } => prem.push(*id),
            }
        }
        alt.map(|i| (i, prem))
    }

    pub(super) fn rule(&self, alt: usize) -> Option<&Rule> {
        self.plan.rules.get(alt).and_then(Option::as_deref)
    }

    /// The `¬∃` literals of alternative `alt`.
    pub(super) fn not_exists(&self, alt: usize) -> &[NotExistsPlan] {
        self.plan.not_exists.get(alt).map_or(&[], |n| &n[..])
    }
}

/// The label of alternative `i` of a query. The first few are interned
/// once for the process: interning takes a global lock, and every query
/// has at least one alternative.
fn alternative_label(i: usize) -> Sym {
    static FIRST: std::sync::OnceLock<Vec<Sym>> = std::sync::OnceLock::new();
    let first = FIRST.get_or_init(|| {
        (0..16)
            .map(|i| Sym::new(&format!("alternative {i}")))
            .collect()
    });
    first
        .get(i)
        .copied()
        .unwrap_or_else(|| Sym::new(&format!("alternative {i}")))
}

impl Model {
    /// Compiles a checked query to its kanren program ([`Compiled`]).
    /// `full`: keep what proofs and printed bindings need (each
    /// alternative's label and variable names, the answer variables'
    /// names); a count needs none of it, and a short query spent a third of
    /// its time building it.
    pub(super) fn compile(&self, q: &QueryAst, full: bool) -> Result<Compiled, AskError> {
        // Counts keep their plan with the query; a full plan (for proofs and
        // bindings) is compiled each time: kept, it measured slower on the
        // KITTI benchmark's proofs.
        let plan = match q.plans.slot.get() {
            Some(p) if !full && self.program.is(&p.program) => Arc::clone(p),
            _ => {
                let (plan, portable) = self.plan(q, full)?;
                let plan = Arc::new(plan);
                // Only a plan that every window of the program compiles
                // alike is kept (and the first program's, should one query
                // be asked of two).
                if portable && !full {
                    let _ = q.plans.slot.set(Arc::clone(&plan));
                }
                plan
            }
        };
        let mut query = kanren::Query::new();
        // Names word kanren's errors only; a count needs none.
        let terms: Arc<[Term]> = q
            .vars
            .iter()
            .map(|v| query.var(if full { v } else { "" }))
            .collect();
        let mut alts: Vec<Goal> = plan
            .rules
            .iter()
            .zip(&plan.labels)
            .enumerate()
            .map(|(i, (rule, label))| match rule {
                Some(rule) => {
                    let mut g = self.rule_goal(rule, &terms);
                    if let Some(nes) = plan.not_exists.get(i) {
                        g = with_not_exists(&self.rels, g, nes, &terms);
                    }
                    if full { kanren::label(*label, g) } else { g }
                }
                None => kanren::fail(),
            })
            .collect();
        // One alternative (nearly every query) is its own goal.
        let goal = if alts.len() == 1 {
            alts.pop().unwrap_or_else(kanren::fail)
        } else {
            kanren::disj(alts)
        };
        Ok(Compiled { query, goal, plan })
    }

    /// Checks a query and compiles its alternatives against this model's
    /// program; also says whether the plan holds for every window of the
    /// program (every atom's predicate is the program's, not one only this
    /// window's facts have).
    fn plan(&self, q: &QueryAst, full: bool) -> Result<(Plan, bool), AskError> {
        let unsafe_diags = safety(q);
        if !unsafe_diags.is_empty() {
            return Err(AskError::Invalid(unsafe_diags));
        }
        let portable = q.disjuncts.iter().flatten().all(|l| match l {
            Literal::Pos(a) | Literal::Neg(a) => self.program.pred_id(&a.pred).is_some(),
            Literal::Cmp { .. } => true,
            Literal::NotExists { .. } => l
                .atoms()
                .iter()
                .all(|(a, _)| self.program.pred_id(&a.pred).is_some()),
        });
        let mut rules = Vec::with_capacity(q.disjuncts.len());
        let mut labels = Vec::with_capacity(q.disjuncts.len());
        for (i, d) in q.disjuncts.iter().enumerate() {
            labels.push(alternative_label(i));
            rules.push(self.compile_query(q, d, full).map(Arc::new));
        }
        let not_exists = if q.disjuncts.iter().flatten().any(Literal::is_not_exists) {
            q.disjuncts
                .iter()
                .map(|d| self.compile_not_exists(q, d))
                .collect()
        } else {
            Vec::new()
        };
        let plan = Plan {
            program: self.program.downgrade(),
            rules,
            labels,
            answer_vars: q.answer_vars.clone(),
            names: if full {
                q.answer_var_names()
                    .into_iter()
                    .map(str::to_string)
                    .collect()
            } else {
                Vec::new()
            },
            not_exists,
        };
        Ok((plan, portable))
    }

    /// The `¬∃` literals of a conjunction, compiled (nested ones within).
    fn compile_not_exists(&self, q: &QueryAst, lits: &[Literal]) -> Arc<[NotExistsPlan]> {
        lits.iter()
            .filter_map(|l| match l {
                Literal::NotExists { vars, body, .. } => Some(NotExistsPlan {
                    locals: vars.clone(),
                    rule: self.compile_query(q, body, false).map(Arc::new),
                    nested: self.compile_not_exists(q, body),
                    literal: l.clone(),
                }),
                _ => None,
            })
            .collect()
    }

    /// A compiled alternative as a kanren goal over `terms` (one per
    /// variable slot): `join_where`, kanren's join of the positive atoms
    /// with `naf` of each negated atom and `=`/`=/=` of each comparison
    /// tested inside it — safety binds every variable they read, so each is
    /// a test of bound values, and a failing match costs no kanren state.
    fn rule_goal(&self, rule: &Rule, terms: &Arc<[Term]>) -> Goal {
        join_goal(&self.rels, rule, terms)
    }

    /// One alternative of a query as the kanren goal the answers come from:
    /// `kanren::join::join_where` of the positive atoms, with `naf` of each
    /// negated atom and `=`/`=/=` of each comparison tested inside it, over
    /// the model's relations. `to_term` gives
    /// the term of each query variable. A positive atom over an unknown
    /// predicate (or of the wrong arity) makes it `fail`.
    pub fn goal(&self, d: &[Literal], to_term: &dyn Fn(&Arg) -> Term) -> Goal {
        let mut vars: Vec<usize> = Vec::new();
        for l in d {
            vars.extend(l.free_vars());
            if let Literal::NotExists { .. } = l {
                vars.extend(fol::local_vars(l));
            }
        }
        let n = vars.iter().max().map_or(0, |m| m + 1);
        let names: Vec<String> = (0..n).map(|i| format!("v{i}")).collect();
        let q = QueryAst {
            source: SourceFile::new("<goal>", String::new()),
            vars: names,
            answer_vars: Vec::new(),
            disjuncts: vec![d.to_vec()],
            plans: PlanCache::default(),
        };
        let terms: Arc<[Term]> = (0..n).map(|v| to_term(&Arg::Var(v))).collect();
        match self.compile_query(&q, d, false) {
            Some(rule) => {
                let nes = self.compile_not_exists(&q, d);
                with_not_exists(&self.rels, self.rule_goal(&rule, &terms), &nes, &terms)
            }
            None => kanren::fail(),
        }
    }

    /// A query alternative as a rule whose head lists the answer variables;
    /// `None` when a positive atom can never hold (unknown predicate or
    /// wrong arity). Negated atoms that can never hold are dropped.
    /// Without `full`, the rule keeps no variable names (only proofs read
    /// them).
    fn compile_query(&self, q: &QueryAst, d: &[Literal], full: bool) -> Option<Rule> {
        let carg = |a: &Arg| match a {
            Arg::Var(v) => CArg::Var(*v),
            Arg::Const(c) => CArg::Const(crate::eval::const_term(c)),
        };
        let resolve = |a: &fol::Atom| -> Option<CAtom> {
            let i = self.index_of(&a.pred)?;
            let rel = self.rels.get(i)?;
            (rel.arity() == a.args.len()).then(|| CAtom {
                pred: i,
                args: a.args.iter().map(carg).collect(),
            })
        };
        let mut body = Vec::new();
        let mut negated = Vec::new();
        let mut cmps = Vec::new();
        for l in d {
            match l {
                Literal::Pos(a) => body.push(resolve(a)?),
                Literal::Neg(a) => negated.extend(resolve(a)),
                Literal::Cmp {
                    left,
                    right,
                    negated: n,
                    ..
                } => cmps.push((carg(left), carg(right), *n)),
                // Compiled on its own (`compile_not_exists`), run after
                // this join as `naf`.
                Literal::NotExists { .. } => {}
            }
        }
        // The answers come from the kanren variables, not a head; a
        // query's rule has no text of its own.
        static NO_TEXT: std::sync::OnceLock<Arc<str>> = std::sync::OnceLock::new();
        Some(Rule {
            id: 0,
            head: CAtom {
                pred: 0,
                args: Vec::new(),
            },
            body: body.into(),
            negated,
            cmps,
            vars: if full { q.vars.clone() } else { Vec::new() },
            source: RuleSource {
                entry: String::new(),
                text: NO_TEXT.get_or_init(|| "".into()).clone(),
                line: 1,
                span: Default::default(),
            },
        })
    }
}
