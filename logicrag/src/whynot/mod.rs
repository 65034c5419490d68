//! Why-not: what a "no" answer rests on, as claims that can be asked back.
//!
//! For each answer variable of a failed conjunctive query, the window's
//! objects that come closest (satisfy the most of the variable's literals
//! on their own) are listed as [`WhyNot`] candidates, each object at most
//! once per answer (one named for an earlier variable gives its place to
//! the next). Every sentence of a candidate is a *claim* written as query
//! text, with the candidate in place of the variable, and is true by
//! construction:
//!
//! - each `satisfied` claim is one literal that holds on its own (its other
//!   variables existential): asked back as a query it answers *yes*;
//! - each `failed` claim is a set of literals that cannot hold together —
//!   a *minimal* one: asked back it answers *no*, and without any one of
//!   its literals it answers *yes* (or could not be asked alone, see
//!   below).
//!
//! The failed claims are complete: with the candidate in place, the
//! query's literals fall into groups that share no other variable
//! (`On(van_3, y) ∧ Sidewalk(y)` is one group: one `y` for both), the
//! candidate fails the query exactly when it fails some group, and every
//! group it fails is named — each of its literals that fails on its own,
//! and a minimal failing set of the rest when the rest still fails.
//!
//! A literal whose meaning alone would need a variable no positive literal
//! binds (`¬On(car_1, y)`, `car_1 ≠ y`) is never a claim on its own: as a
//! query it is unsafe, so it is stated only inside a failed set that binds
//! its variables, or not at all. Minimality is therefore among the *safe*
//! subsets: a literal is kept in a failed set when dropping it would leave
//! a negation or comparison unbound.
//!
//! These sentences become the C2 context a multimodal model reads as
//! proved, so "nothing it has not checked" is the rule: a failed set that
//! is not a literal decided on its own is found by asking the engine
//! (deletion-based minimal unsatisfiable subset), never by a heuristic. A
//! property test asks every claim back over random KBs and over the
//! built-in question sets.

use crate::ask::WHY_NOT_CANDIDATES;
use crate::kb::WindowKb;
use logicpad::fol::{Arg, Literal};
use logicpad::{LogicPad, QueryAst};
use serde::Serialize;
use std::sync::Arc;

mod claims;
mod scores;
#[cfg(test)]
mod tests;

pub(crate) use claims::literal_text;
use claims::{
    Bounds, Groups, bind_var, blocking_match, candidate, conjunction_text, is_safe,
    minimal_unsatisfiable, satisfiable, vars_in,
};
pub(crate) use scores::HolderCache;
use scores::{Holds, is_identity, mentions_var, scores};
use std::borrow::Cow;

/// One candidate object of a "no" answer and the claims that explain it.
///
/// Invariant: `satisfied_claims` and `failed_claims` are the claims,
/// typed, and `satisfied` and `failed` the same claims in words, one for
/// one (query text over the LogicPad, the candidate in place of
/// `variable`); each `satisfied` claim answers yes and each `failed`
/// claim answers no when asked back on the same window, and a failed
/// claim of several literals answers yes without any one of them (among
/// safe subsets). A [`Claim::Literals`] claim is over the variables of
/// `query`, which is `Some` whenever one is.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct WhyNot {
    /// The query variable (for a universal, its variables, comma-separated).
    pub variable: String,
    /// The candidate constant, or `(none)` when no object of the window is
    /// of the kind the query asks about.
    pub candidate: String,
    /// Literals (with the candidate substituted) that hold, each on its own;
    /// a variable left in one is existential ("for some y").
    pub satisfied: Vec<String>,
    /// Conjunctions (literals joined by ` ∧ `, the candidate substituted)
    /// that cannot hold: each has no binding of the variables left in it.
    pub failed: Vec<String>,
    /// For each `failed` claim, the variables left in it (existential), in
    /// order of first appearance: "holds for no y".
    #[serde(skip)]
    pub failed_vars: Vec<Vec<String>>,
    /// Notes, not claims: the ground facts the claims rest on that the
    /// perception is unsure of — a failed atom in doubt ("may hold all the
    /// same, probability 0.31"), a satisfied atom measured below
    /// `context::PROBABLY_BELOW`. Empty on a certain source.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub uncertain: Vec<String>,
    /// `satisfied`, typed: what [`audit`] asks back and the notes read.
    #[serde(skip)]
    pub satisfied_claims: Vec<Claim>,
    /// `failed`, typed.
    #[serde(skip)]
    pub failed_claims: Vec<Claim>,
    /// The query whose literals the claims are (their variables' names):
    /// one for all the candidates of an answer.
    #[serde(skip)]
    pub query: Option<Arc<QueryAst>>,
}

/// A claim of a why-not, typed: what one string of
/// [`WhyNot::satisfied`] or [`WhyNot::failed`] says.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Claim {
    /// Literals of the query (over [`WhyNot::query`]'s variables, the
    /// candidate in place of its variable) that hold, or cannot hold,
    /// together; a variable left in them is existential.
    Literals(Vec<Literal>),
    /// One literal of the query, by its position in the query's first
    /// alternative, with the candidate in place of [`WhyNot::variable`]:
    /// most claims are one literal on the candidate, and keeping its place
    /// instead of a bound copy spares a copy per claim of every "no" of a
    /// batch ([`WhyNot::claim_literals`] binds it when it is read).
    OnCandidate(usize),
    /// A universal's antecedent or consequent as written, the
    /// counterexample in place of its variables: a formula, which
    /// logicpad keeps as text, asked back as text.
    Formula(String),
}

impl WhyNot {
    /// A claim's literals, the candidate in place (`None` for a formula,
    /// or a claim whose query is not set).
    pub fn claim_literals<'a>(&'a self, claim: &'a Claim) -> Option<Cow<'a, [Literal]>> {
        match claim {
            Claim::Literals(lits) => Some(Cow::Borrowed(lits)),
            Claim::OnCandidate(i) => {
                let q = self.query.as_deref()?;
                let lit = q.disjuncts.first()?.get(*i)?;
                let v = q.vars.iter().position(|n| *n == self.variable)?;
                Some(Cow::Owned(vec![bind_var(lit, v, &self.candidate)]))
            }
            Claim::Formula(_) => None,
        }
    }

    /// Whether a claim is one `¬∃` literal.
    fn claim_is_not_exists(&self, claim: &Claim) -> bool {
        match claim {
            Claim::Formula(text) => text.starts_with("¬∃"),
            _ => self
                .claim_literals(claim)
                .is_some_and(|lits| matches!(&lits[..], [l] if l.is_not_exists())),
        }
    }

    /// The names of the variables a claim's words mention (a `¬∃`'s own
    /// among them), in order of first appearance.
    pub(crate) fn mentioned_vars(&self, claim: &Claim) -> Vec<String> {
        let query = self.query.as_deref();
        let lits = match claim {
            Claim::Formula(text) => return free_vars_of_text(text),
            _ => match self.claim_literals(claim) {
                Some(lits) => lits,
                None => return Vec::new(),
            },
        };
        fn walk(l: &Literal, out: &mut Vec<usize>) {
            let mut arg = |a: &Arg| {
                if let Arg::Var(v) = a
                    && !out.contains(v)
                {
                    out.push(*v);
                }
            };
            match l {
                Literal::Pos(a) | Literal::Neg(a) => a.args.iter().for_each(arg),
                Literal::Cmp { left, right, .. } => {
                    arg(left);
                    arg(right);
                }
                Literal::NotExists { vars, body, .. } => {
                    for v in vars {
                        arg(&Arg::Var(*v));
                    }
                    for b in body {
                        walk(b, out);
                    }
                }
            }
        }
        let mut seen = Vec::new();
        for l in lits.iter() {
            walk(l, &mut seen);
        }
        seen.iter()
            .filter_map(|&v| query.and_then(|q| q.vars.get(v)).cloned())
            .collect()
    }
}

/// A claim's one positive ground atom (`Moving(car_1)`), if it is one: its
/// predicate and arguments.
fn ground_atom(lits: &[Literal]) -> Option<(&str, Vec<&str>)> {
    {
        let [Literal::Pos(a)] = lits else {
            return None;
        };
        let args: Option<Vec<&str>> = a
            .args
            .iter()
            .map(|x| match x {
                Arg::Const(c) => Some(c.as_str()),
                Arg::Var(_) => None,
            })
            .collect();
        Some((a.pred.as_str(), args?))
    }
}

impl WhyNot {
    /// The candidate in words, for C2 and the terminal: what holds, and
    /// what cannot. `None` for a candidate with nothing to say.
    pub fn sentence(&self) -> Option<String> {
        let said = self.claims_sentence()?;
        if self.uncertain.is_empty() {
            return Some(said);
        }
        Some(format!("{said} {}", self.uncertain.join(" ")))
    }

    /// [`WhyNot::sentence`] without the notes on uncertain facts.
    fn claims_sentence(&self) -> Option<String> {
        if self.failed.is_empty() {
            return None;
        }
        let failed: Vec<String> = self
            .failed
            .iter()
            .enumerate()
            .map(|(i, f)| {
                let vars = self.failed_vars.get(i).map_or(&[][..], Vec::as_slice);
                if vars.is_empty() {
                    format!("{f} does not hold")
                } else {
                    format!("{f} holds for no {}", vars.join(", "))
                }
            })
            .collect();
        // A `¬∃` that fails by a match of its own variables: the claim,
        // and the match that blocks it.
        if let ([f], [blocking]) = (self.failed.as_slice(), self.satisfied.as_slice())
            && self
                .failed_claims
                .first()
                .is_some_and(|c| self.claim_is_not_exists(c))
            && self.candidate != NO_CANDIDATE
        {
            return Some(format!(
                "{f} does not hold: {blocking} holds ({} = {}).",
                self.variable, self.candidate
            ));
        }
        if self.candidate == NO_CANDIDATE {
            let what: Vec<String> = self.failed.to_vec();
            return Some(format!(
                "No object of the window satisfies {}.",
                what.join(", nor ")
            ));
        }
        if self.satisfied.is_empty() {
            return Some(format!("{}: {}.", self.candidate, failed.join("; ")));
        }
        let satisfied: Vec<String> = self
            .satisfied
            .iter()
            .enumerate()
            .map(|(i, s)| {
                let vars = self
                    .satisfied_claims
                    .get(i)
                    .map(|c| self.mentioned_vars(c))
                    .unwrap_or_default();
                if vars.is_empty() {
                    format!("{s} holds")
                } else {
                    format!("{s} holds for some {}", vars.join(", "))
                }
            })
            .collect();
        Some(format!(
            "{} comes closest: {}, but {}.",
            self.candidate,
            satisfied.join(" and "),
            failed.join("; ")
        ))
    }
}

/// The candidate of a why-not that says no object is of the asked kind.
pub(crate) const NO_CANDIDATE: &str = "(none)";

/// The lower-case identifiers of a claim that are variables (by spelling,
/// [`logicpad::is_variable_name`]), in order of first appearance.
fn free_vars_of_text(text: &str) -> Vec<String> {
    let mut out: Vec<String> = Vec::new();
    for tok in text.split(|c: char| !(c.is_alphanumeric() || c == '_' || c == '?')) {
        if !tok.is_empty() && logicpad::is_variable_name(tok) && !out.iter().any(|o| o == tok) {
            out.push(tok.to_string());
        }
    }
    out
}

/// Replaces whole identifier tokens of `text` that name a variable of
/// `subst` by its value: a universal's antecedent and consequent, as
/// written, for one counterexample.
pub(crate) fn substitute_text(text: &str, subst: &[(String, String)]) -> String {
    let mut out = String::with_capacity(text.len() + 16);
    let mut tok = String::new();
    let flush = |tok: &mut String, out: &mut String| {
        match subst.iter().find(|(v, _)| v == tok) {
            Some((_, c)) => out.push_str(c),
            None => out.push_str(tok),
        }
        tok.clear();
    };
    for ch in text.chars() {
        if ch.is_alphanumeric() || ch == '_' || ch == '?' {
            tok.push(ch);
        } else {
            flush(&mut tok, &mut out);
            out.push(ch);
        }
    }
    flush(&mut tok, &mut out);
    out
}

/// The why-not of a failed universal `∀x: A → B`: each counterexample
/// (`bindings`, sorted by variable name as answers are) satisfies `A` and
/// fails `B`, both written with the counterexample substituted.
pub(crate) fn universal(
    antecedent: &str,
    consequent: &str,
    counterexamples: &[Vec<(String, String)>],
) -> Vec<WhyNot> {
    counterexamples
        .iter()
        .take(WHY_NOT_CANDIDATES)
        .map(|b| {
            let names: Vec<&str> = b.iter().map(|(v, _)| v.as_str()).collect();
            let values: Vec<&str> = b.iter().map(|(_, c)| c.as_str()).collect();
            let failed = substitute_text(consequent, b);
            let satisfied = substitute_text(antecedent, b);
            WhyNot {
                variable: names.join(", "),
                candidate: values.join(", "),
                satisfied_claims: vec![Claim::Formula(satisfied.clone())],
                satisfied: vec![satisfied],
                failed_vars: vec![free_vars_of_text(&failed)],
                uncertain: Vec::new(),
                failed_claims: vec![Claim::Formula(failed.clone())],
                failed: vec![failed],
                query: None,
            }
        })
        .collect()
}

/// Asks every claim of an answer's why-not back on its window and returns
/// each one the engine contradicts, in words (empty when all agree): a
/// `satisfied` claim must answer yes, a `failed` claim no, and a failed
/// claim of several literals yes without any one of them (where what is
/// left is a safe query). Each claim is asked as the query its typed form
/// makes (a universal's formulas as written). `observed` is the source's
/// observability, as for [`crate::ask::ask`]. This is the check behind
/// "never explained by a false sentence", exposed for tests and audits of
/// other KBs.
pub fn audit(
    pad: &LogicPad,
    kb: &WindowKb,
    observed: &std::collections::BTreeMap<String, crate::kb::Observed>,
    r: &crate::ask::AskResult,
) -> Vec<String> {
    use crate::ask::{AskOptions, Outcome, ask, ask_parsed};
    let mut wrong = Vec::new();
    let opts = AskOptions::BINDINGS;
    let blind = crate::ask::Blindness {
        observed,
        observability: None,
        all_observed: crate::ask::all_fully(pad, observed),
    };
    // A claim asked back: the disagreement in words, or `None` when the
    // engine answers `expected`.
    let disagrees = |w: &WhyNot, text: &str, claim: &Claim, expected: Outcome, said: &str| {
        let got = match (claim, w.claim_literals(claim), &w.query) {
            (Claim::Formula(text), _, _) => ask(pad, kb, observed, text, opts).answer,
            (_, Some(lits), Some(q)) => {
                let asked =
                    logicpad::ParsedQuery::Exists(Arc::new(claim_query(q, lits.into_owned())));
                ask_parsed(pad, kb, &blind, &asked, opts).answer
            }
            _ => Outcome::Invalid,
        };
        (got != expected).then(|| {
            format!(
                "{}: claimed `{text}` {said}, the engine says {}",
                w.candidate,
                got.as_str()
            )
        })
    };
    for w in &r.why_not {
        for (s, claim) in w.satisfied.iter().zip(&w.satisfied_claims) {
            wrong.extend(disagrees(w, s, claim, Outcome::Yes, "holds"));
        }
        for (f, claim) in w.failed.iter().zip(&w.failed_claims) {
            if let Some(e) = disagrees(w, f, claim, Outcome::No, "cannot hold") {
                wrong.push(e);
                continue;
            }
            let (q, lits) = match (claim, w.claim_literals(claim), &w.query) {
                (Claim::Formula(text), _, _) => {
                    let Ok(logicpad::ParsedQuery::Exists(q)) = crate::ask::prepare(pad, text)
                    else {
                        wrong.push(format!("{}: claim `{f}` is not a query", w.candidate));
                        continue;
                    };
                    let Some(lits) = q.disjuncts.first().cloned() else {
                        continue;
                    };
                    (Arc::unwrap_or_clone(q), lits)
                }
                (_, Some(lits), Some(q)) => (claim_query(q, lits.to_vec()), lits.into_owned()),
                _ => continue,
            };
            if lits.len() < 2 {
                continue;
            }
            for i in 0..lits.len() {
                let mut rest = lits.clone();
                let dropped = rest.remove(i);
                if is_safe(&rest)
                    && satisfiable(kb, &q, &rest, &Bounds::new(&logicpad::Limits::default()))
                        != Some(true)
                {
                    wrong.push(format!(
                        "{}: `{f}` is not minimal: it fails without `{}`",
                        w.candidate,
                        literal_text(&dropped, &q, None)
                    ));
                }
            }
        }
        if w.satisfied_claims.len() != w.satisfied.len() || w.failed_claims.len() != w.failed.len()
        {
            wrong.push(format!(
                "{}: the claims in words and the typed claims differ in number",
                w.candidate
            ));
        }
    }
    wrong
}

/// The query that asks a claim's literals back: their conjunction over
/// `query`'s variables, the variables left in it its answers.
fn claim_query(query: &QueryAst, lits: Vec<Literal>) -> QueryAst {
    let answer_vars = {
        let mut seen: Vec<usize> = Vec::new();
        for x in lits.iter().flat_map(Literal::free_vars) {
            if !seen.contains(&x) {
                seen.push(x);
            }
        }
        seen
    };
    QueryAst {
        source: Arc::clone(&query.source),
        vars: query.vars.clone(),
        answer_vars,
        disjuncts: vec![lits],
        plans: Default::default(),
    }
}

/// Why-not for a failed conjunctive query (its first alternative: every
/// alternative failed): for each answer variable, the window's objects
/// that satisfy the most of the literals mentioning it (none already
/// named for another variable), each with its claims (see the module's
/// documentation).
pub(crate) fn why_not(
    pad: &LogicPad,
    kb: &WindowKb,
    ast: &Arc<QueryAst>,
    limits: &logicpad::Limits,
) -> Vec<WhyNot> {
    let Some(conj) = ast.disjuncts.first() else {
        return Vec::new();
    };
    let bounds = Bounds::new(limits);
    let mut out: Vec<WhyNot> = Vec::new();
    // A `¬∃` over no outside variable ("are there no trucks?") fails by a
    // match of its own: named with the facts that make it.
    for l in conj {
        if l.is_not_exists()
            && l.free_vars().is_empty()
            && let Some((bindings, facts, lits)) = blocking_match(kb, ast, l, &bounds)
        {
            let names: Vec<&str> = bindings.iter().map(|(v, _)| v.as_str()).collect();
            let values: Vec<&str> = bindings.iter().map(|(_, c)| c.as_str()).collect();
            out.push(WhyNot {
                variable: names.join(", "),
                candidate: values.join(", "),
                satisfied: vec![facts],
                failed: vec![literal_text(l, ast, None)],
                failed_vars: vec![Vec::new()],
                uncertain: Vec::new(),
                satisfied_claims: vec![Claim::Literals(lits)],
                failed_claims: vec![Claim::Literals(vec![l.clone()])],
                query: None,
            });
        }
    }
    for &v in &ast.answer_vars {
        let name = ast.vars.get(v).cloned().unwrap_or_default();
        let mentions: Vec<&Literal> = conj.iter().filter(|l| mentions_var(l, v)).collect();
        if mentions.is_empty() {
            continue;
        }
        // Candidates must be what the query asks about: for "the van",
        // vans (when there are any), never poles and buildings.
        let identity: Vec<bool> = mentions.iter().map(|l| is_identity(pad, l, v)).collect();
        let (any_of_kind, mut scored) = scores(kb, ast, v, &mentions, &identity, &bounds);
        // Each object is explained once per answer: one already named (for
        // an earlier variable, or as a blocking match) would only say again
        // what fails for it, so the next candidates take its place.
        scored.retain(|(_, obj, _)| !out.iter().any(|w| w.candidate == *obj));
        if !any_of_kind && identity.contains(&true) {
            let kind: Vec<Literal> = mentions
                .iter()
                .zip(&identity)
                .filter(|(_, id)| **id)
                .map(|(l, _)| (*l).clone())
                .collect();
            // Said only when the engine agrees (the candidates were the
            // window's objects, the claim is about every constant), and
            // only the literals that make it so.
            if let Some(core) = minimal_unsatisfiable(kb, ast, kind, false, None, &bounds) {
                out.push(WhyNot {
                    variable: name.clone(),
                    candidate: NO_CANDIDATE.into(),
                    satisfied: Vec::new(),
                    failed: vec![conjunction_text(&core, ast, None)],
                    failed_vars: vec![vars_in(&core, ast, None)],
                    uncertain: Vec::new(),
                    satisfied_claims: Vec::new(),
                    failed_claims: vec![Claim::Literals(core)],
                    query: None,
                });
            }
            continue;
        }
        // Score every candidate by the literals it satisfies, then put
        // into words only the few that are shown: a window of a thousand
        // objects asked a thousand questions must not format a million
        // sentences to print thirty.
        let rank = |a: &(usize, &str, Holds), b: &(usize, &str, Holds)| {
            b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1))
        };
        // The shown few picked in linear time, then only they are sorted.
        if scored.len() > WHY_NOT_CANDIDATES {
            scored.select_nth_unstable_by(WHY_NOT_CANDIDATES, rank);
            scored.truncate(WHY_NOT_CANDIDATES);
        }
        scored.sort_unstable_by(rank);
        if scored.is_empty() {
            continue;
        }
        let groups = Groups::of(kb, ast, conj, v, bounds);
        for (_, obj, holds) in scored {
            if let Some(w) = candidate(kb, ast, &groups, v, &name, obj, &mentions, &holds) {
                out.push(w);
            }
        }
    }
    // The query the claims' literals are over, shared by the candidates
    // (and with the prepared question: never copied).
    for w in &mut out {
        w.query = Some(Arc::clone(ast));
    }
    if kb.is_uncertain() {
        for w in &mut out {
            w.uncertain = uncertain_notes(kb, w);
        }
    }
    out
}

/// The notes of [`WhyNot::uncertain`]: each ground atom among the claims
/// that the window holds with doubt — a failed one whose fact was measured
/// and not asserted (a doubt: it may hold all the same), a satisfied one
/// asserted with a probability below `context::PROBABLY_BELOW`.
fn uncertain_notes(kb: &WindowKb, w: &WhyNot) -> Vec<String> {
    let mut out = Vec::new();
    for (f, claim) in w.failed.iter().zip(&w.failed_claims) {
        let Some(lits) = w.claim_literals(claim) else {
            continue;
        };
        let Some((pred, args)) = ground_atom(&lits) else {
            continue;
        };
        if let Some(q) = kb.doubt(pred, &args) {
            out.push(format!(
                "{f} may hold all the same (measured, not asserted: probability {}).",
                crate::belief::rounded(q)
            ));
        }
    }
    for (s, claim) in w.satisfied.iter().zip(&w.satisfied_claims) {
        let Some(lits) = w.claim_literals(claim) else {
            continue;
        };
        let Some((pred, args)) = ground_atom(&lits) else {
            continue;
        };
        if let Some(p) = kb
            .provenance(pred, &args)
            .and_then(|p| p.probability)
            .filter(|p| *p < crate::context::PROBABLY_BELOW)
        {
            out.push(format!(
                "{s} is only probable (probability {}).",
                crate::belief::rounded(p)
            ));
        }
    }
    out
}
