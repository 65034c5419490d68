//! The [`Model`]'s query entry points: [`Model::ask`] and its variants
//! (answers with proofs, sorted), [`Model::answers`] (lazy), and
//! [`Model::bindings`], [`Model::count`], [`Model::satisfiable`] (no
//! proofs), with the answer budgets they run under.

use super::answers::Answers;
use super::ast::{AskError, QueryAnswer, QueryAst};
use super::compile::{Compiled, NotExistsPlan};
use crate::eval::{
    DerivationTree, GroundAtom, Model, ProofLimits, bind_from, term_name, term_text,
};
use crate::fol;
use crate::program::{CArg, Rule};
use kanren::{FactId, RunConfig, Term};

use super::limits::{COUNT_FACTOR, Found, Limits, Stopped};

/// The answer tuples a run has returned, to return each distinct one once.
pub(super) type AnswerSet = rustc_hash::FxHashSet<Vec<Term>>;

impl Model {
    /// Answers a query through its kanren program ([`Model::goal`] for one
    /// alternative) and, with `config.proofs`, a proof per answer built
    /// from the answer's kanren proof: each positive literal's fact,
    /// expanded through the derivations recorded in the fixpoint, and each
    /// negated literal as an absent fact. Answers are deduplicated over
    /// the answer variables and sorted; each carries the proof of its first
    /// derivation, within the default [`ProofLimits`] for the whole result
    /// (see [`Model::ask_with`]). Running out of `config.budget` or of the
    /// default answer limit is [`AskError::Stopped`]; [`Model::ask_limited`]
    /// keeps what was found instead.
    pub fn ask(&self, q: &QueryAst, config: RunConfig) -> Result<Vec<QueryAnswer>, AskError> {
        self.ask_with(q, config, ProofLimits::default())
    }

    /// [`Model::ask`] with explicit proof limits. `limits.max_nodes` is one
    /// budget for the proofs of *all* answers together, spent in the order
    /// of the sorted answers: per tree it would let a query with many
    /// answers print millions of lines into a retrieval context. Once it is
    /// spent, each further proof step is a single node (a base fact, or a
    /// [`DerivationTree::Truncated`] derived one), so every answer still
    /// names the facts it rests on.
    pub fn ask_with(
        &self,
        q: &QueryAst,
        config: RunConfig,
        limits: ProofLimits,
    ) -> Result<Vec<QueryAnswer>, AskError> {
        let limits = Limits {
            steps: config.budget.max_steps,
            time: config.budget.max_time,
            proof_nodes: limits.max_nodes,
            proof_depth: limits.max_depth,
            ..Limits::default()
        };
        complete(self.ask_limited(q, config.proofs, &limits)?)
    }

    /// Answers a query within `limits` (the one run policy): every answer,
    /// sorted, each with its proof when `proofs` is set (the proofs of all
    /// answers sharing `limits.proof_nodes`); or, when the run stops at a
    /// limit, the distinct answers found before it in the order the search
    /// found them, with the reason ([`Found`]).
    pub fn ask_limited(
        &self,
        q: &QueryAst,
        proofs: bool,
        limits: &Limits,
    ) -> Result<Found<QueryAnswer>, AskError> {
        let program = self.compile(q, true)?;
        // The first derivation of each distinct answer (its alternative
        // and the premise of each positive literal), in the order found.
        let mut order: Vec<(Vec<Term>, Premises)> = Vec::new();
        // FxHash: a key is a few interned symbols, and SipHash over them
        // (one small write per term) cost more than the rest of the
        // bookkeeping of an answer.
        let mut seen: AnswerSet = AnswerSet::default();
        let mut run = program.run(proofs, limits.budget());
        let mut stopped = None;
        for answer in run.by_ref() {
            let answer = answer?;
            let key = program.key(&answer);
            if seen.contains(&key) {
                continue;
            }
            if order.len() >= limits.answers {
                stopped = Some(Stopped::Answers);
                break;
            }
            seen.insert(key.clone());
            order.push((key, program.premises(&answer)));
        }
        let stopped = stopped.or_else(|| Stopped::of(run.stop_reason()));
        let mut found: Vec<_> = order
            .into_iter()
            .map(|(vals, prem)| (sorted_bindings(&program.plan.names, &vals), prem))
            .collect();
        // Sorted before any proof is built: the node budget is spent in the
        // order of the sorted answers. (The terms' own order is by symbol
        // number, which depends on the order names were interned, so
        // spending the budget in it made which answers got full proofs
        // differ from run to run.) A stopped run keeps the search's order.
        if stopped.is_none() {
            found.sort_by(|a, b| a.0.cmp(&b.0));
        }
        let proof_limits = limits.proofs();
        let mut budget = limits.proof_nodes;
        let items = found
            .into_iter()
            .map(|(bindings, prem)| {
                let proof = match prem
                    .as_ref()
                    .and_then(|(alt, prem)| Some((program.rule(*alt)?, *alt, prem)))
                {
                    Some((rule, alt, prem)) if proofs => self.proof_from_premises(
                        rule,
                        program.not_exists(alt),
                        prem,
                        proof_limits,
                        &mut budget,
                    ),
                    _ => Vec::new(),
                };
                QueryAnswer { bindings, proof }
            })
            .collect();
        Ok(Found { items, stopped })
    }

    /// The answers of a query one at a time, pulled from its kanren run
    /// (not sorted; [`Model::ask`] sorts), each distinct binding once, with
    /// its proof when `proofs` is set (each proof within `limits` on its
    /// own). Nothing beyond the answers taken is computed, so the first
    /// answers of a query with millions come at once:
    /// `answers(&q, None).take(10)`. A query that is not safe is
    /// [`AskError::Invalid`]. A run error ends the iteration
    /// ([`Answers::error`] says which).
    pub fn answers(
        &self,
        q: &QueryAst,
        proofs: Option<ProofLimits>,
    ) -> Result<Answers<'_>, AskError> {
        self.answers_limited(q, proofs, kanren::Budget::default())
    }

    /// [`Model::answers`] within a step and time budget
    /// ([`Limits::budget`]); [`Answers::stopped`] says whether the run
    /// stopped at it.
    pub fn answers_limited(
        &self,
        q: &QueryAst,
        proofs: Option<ProofLimits>,
        budget: kanren::Budget,
    ) -> Result<Answers<'_>, AskError> {
        let program = self.compile(q, true)?;
        let run = program.run(proofs.is_some(), budget);
        Ok(Answers {
            model: self,
            program,
            run,
            seen: AnswerSet::default(),
            proofs,
            error: None,
        })
    }

    /// The proof of one derivation of a compiled query: a tree per positive
    /// literal (in the query's order) from its premise fact, then each
    /// negated literal as an absent fact; `budget` is what is left of the
    /// result's node budget and shrinks by each tree's size.
    pub(super) fn proof_from_premises(
        &self,
        rule: &Rule,
        not_exists: &[NotExistsPlan],
        prem: &[FactId],
        limits: ProofLimits,
        budget: &mut usize,
    ) -> Vec<DerivationTree> {
        let mut trees = Vec::with_capacity(rule.body.len() + rule.negated.len() + not_exists.len());
        for (atom, &id) in rule.body.iter().zip(prem) {
            if let Some(t) = self.explain_id(atom.pred, id, limits, *budget) {
                *budget = budget.saturating_sub(t.size());
                trees.push(t);
            }
        }
        // The bindings are read only to write negated literals: a query
        // of positive atoms alone (most of a batch) needs none.
        if rule.negated.is_empty() && not_exists.is_empty() {
            return trees;
        }
        let binds = bind_from(rule, |p| self.rels.get(p).map(|r| &**r), prem);
        for n in &rule.negated {
            let args = n
                .args
                .iter()
                .map(|a| match a {
                    CArg::Const(c) => term_name(c),
                    CArg::Var(v) => binds
                        .get(*v)
                        .and_then(Option::as_ref)
                        .map(term_name)
                        .unwrap_or_else(|| rule.vars.get(*v).cloned().unwrap_or_default().into()),
                })
                .collect();
            trees.push(DerivationTree::Absent(GroundAtom {
                pred: self.name_of(n.pred),
                args,
            }));
        }
        for ne in not_exists {
            let value = |v: usize| binds.get(v).and_then(Option::as_ref).map(term_text);
            let name = |v: usize| rule.vars.get(v).cloned().unwrap_or_else(|| format!("_{v}"));
            trees.push(DerivationTree::NoMatch {
                formula: fol::literal_text(&ne.literal, &|v| value(v).unwrap_or_else(|| name(v))),
            });
        }
        trees
    }
}

/// An answer's `(variable, value)` pairs, sorted by variable name.
pub(super) fn sorted_bindings<N: AsRef<str>>(
    names: &[N],
    values: &[Term],
) -> Vec<(String, String)> {
    let mut b: Vec<(String, String)> = names
        .iter()
        .map(|n| n.as_ref().to_string())
        .zip(values.iter().map(term_text))
        .collect();
    b.sort();
    b
}

/// The first derivation of an answer: its alternative and the premise
/// fact of each positive literal (`None` without proofs).
type Premises = Option<(usize, Vec<FactId>)>;

/// The answers of a run that must have them all: a stopped one is
/// [`AskError::Stopped`], with what it found.
fn complete<T>(found: Found<T>) -> Result<Vec<T>, AskError> {
    match found.stopped {
        None => Ok(found.items),
        Some(reason) => Err(AskError::Stopped {
            reason,
            found: found.items.len(),
        }),
    }
}

impl Model {
    /// Answers a query without proofs: the distinct bindings of
    /// [`Model::ask`], sorted, under the default [`Limits`] (running out is
    /// [`AskError::Stopped`]). For bulk question answering and benchmarks.
    pub fn bindings(&self, q: &QueryAst) -> Result<Vec<Vec<(String, String)>>, AskError> {
        complete(self.bindings_limited(q, &Limits::default())?)
    }

    /// [`Model::bindings`] within `limits`: every binding, sorted, or the
    /// distinct ones found before the run stopped, in the order found.
    pub fn bindings_limited(
        &self,
        q: &QueryAst,
        limits: &Limits,
    ) -> Result<Found<Vec<(String, String)>>, AskError> {
        let program = self.compile(q, true)?;
        let found = self.solve(&program, limits)?;
        let mut items: Vec<Vec<(String, String)>> = found
            .items
            .into_iter()
            .map(|t| sorted_bindings(&program.plan.names, &t))
            .collect();
        if found.stopped.is_none() {
            items.sort();
        }
        Ok(Found {
            items,
            stopped: found.stopped,
        })
    }

    /// The number of distinct answers (as [`Model::bindings`] would list
    /// them), under the default [`Limits`].
    pub fn count(&self, q: &QueryAst) -> Result<usize, AskError> {
        let (n, stopped) = self.count_limited(q, &Limits::default())?;
        match stopped {
            None => Ok(n),
            Some(reason) => Err(AskError::Stopped { reason, found: n }),
        }
    }

    /// [`Model::count`] within `limits`: the count, and why the run stopped
    /// early (then the count is of the answers found before it, a lower
    /// bound). A query of one alternative whose answer variables are all
    /// its variables has exactly one answer per derivation (relations are
    /// sets), so it is counted without storing any answer, up to
    /// `limits.answers` × [`COUNT_FACTOR`] derivations; other queries keep
    /// their answers to remove duplicates, up to `limits.answers`.
    pub fn count_limited(
        &self,
        q: &QueryAst,
        limits: &Limits,
    ) -> Result<(usize, Option<Stopped>), AskError> {
        let program = self.compile(q, false)?;
        let all_answered = match program.plan.rules.as_slice() {
            [Some(rule)] => rule.body.iter().flat_map(|a| &a.args).all(|a| match a {
                CArg::Var(v) => q.answer_vars.contains(v),
                CArg::Const(_) => true,
            }),
            _ => false,
        };
        if !all_answered {
            let found = self.solve(&program, limits)?;
            return Ok((found.items.len(), found.stopped));
        }
        let limit = limits.answers.saturating_mul(COUNT_FACTOR);
        let mut run = program.run(false, limits.budget());
        // A ground query (no answer variable) has one answer or none.
        let ground = q.answer_vars.is_empty();
        let n = run.count_up_to(if ground { 0 } else { limit })?;
        if ground {
            let stopped = if n == 0 {
                Stopped::of(run.stop_reason())
            } else {
                None
            };
            return Ok((n.min(1), stopped));
        }
        if n > limit {
            return Ok((limit, Some(Stopped::Answers)));
        }
        Ok((n, Stopped::of(run.stop_reason())))
    }

    /// Whether the query has an answer: its kanren run stops at the first
    /// match, and builds no answer for it.
    pub fn satisfiable(&self, q: &QueryAst) -> Result<bool, AskError> {
        match self.satisfiable_limited(q, &Limits::default())? {
            (found, None) => Ok(found),
            (_, Some(reason)) => Err(AskError::Stopped { reason, found: 0 }),
        }
    }

    /// [`Model::satisfiable`] within `limits`: `(true, None)` at the first
    /// match, `(false, None)` when there is none, `(false, Some(reason))`
    /// when the run stopped before finding one (undecided).
    pub fn satisfiable_limited(
        &self,
        q: &QueryAst,
        limits: &Limits,
    ) -> Result<(bool, Option<Stopped>), AskError> {
        let program = self.compile(q, false)?;
        let mut run = program.run(false, limits.budget());
        let found = run.count_up_to(0)? > 0;
        Ok((
            found,
            (!found).then(|| Stopped::of(run.stop_reason())).flatten(),
        ))
    }

    /// Distinct answer tuples (answer variables in order): all of them in
    /// term order, or those found before the run stopped at `limits`, in
    /// the order found.
    fn solve(&self, program: &Compiled, limits: &Limits) -> Result<Found<Vec<Term>>, AskError> {
        let mut seen: AnswerSet = AnswerSet::default();
        let mut items: Vec<Vec<Term>> = Vec::new();
        let mut run = program.run(false, limits.budget());
        let mut stopped = None;
        for answer in run.by_ref() {
            let key = program.key(&answer?);
            if seen.contains(&key) {
                continue;
            }
            if items.len() >= limits.answers {
                stopped = Some(Stopped::Answers);
                break;
            }
            seen.insert(key.clone());
            items.push(key);
        }
        let stopped = stopped.or_else(|| Stopped::of(run.stop_reason()));
        if stopped.is_none() {
            items.sort();
        }
        Ok(Found { items, stopped })
    }
}
