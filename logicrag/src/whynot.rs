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

/// One candidate object of a "no" answer and the claims that explain it.
///
/// Invariant: every string of `satisfied` and `failed` is query text over
/// the LogicPad (the candidate in place of `variable`); each `satisfied`
/// claim answers yes and each `failed` claim answers no when asked back on
/// the same window, and a failed claim of several literals answers yes
/// without any one of them (among safe subsets).
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
            && f.starts_with("¬∃")
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
            .map(|s| {
                let vars = free_vars_of_text(s);
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
            WhyNot {
                variable: names.join(", "),
                candidate: values.join(", "),
                satisfied: vec![substitute_text(antecedent, b)],
                failed_vars: vec![free_vars_of_text(&failed)],
                uncertain: Vec::new(),
                failed: vec![failed],
            }
        })
        .collect()
}

/// Asks every claim of an answer's why-not back on its window and returns
/// each one the engine contradicts, in words (empty when all agree): a
/// `satisfied` claim must answer yes, a `failed` claim no, and a failed
/// claim of several literals yes without any one of them (where what is
/// left is a safe query). `observed` is the source's observability, as
/// for [`crate::ask::ask`]. This is the check behind "never explained by a
/// false sentence", exposed for tests and audits of other KBs.
pub fn audit(
    pad: &LogicPad,
    kb: &WindowKb,
    observed: &std::collections::BTreeMap<String, crate::kb::Observed>,
    r: &crate::ask::AskResult,
) -> Vec<String> {
    use crate::ask::{AskOptions, Outcome, ask};
    let mut wrong = Vec::new();
    let opts = AskOptions::BINDINGS;
    for w in &r.why_not {
        for s in &w.satisfied {
            let got = ask(pad, kb, observed, s, opts).answer;
            if got != Outcome::Yes {
                wrong.push(format!(
                    "{}: claimed `{s}` holds, the engine says {}",
                    w.candidate,
                    got.as_str()
                ));
            }
        }
        for f in &w.failed {
            let got = ask(pad, kb, observed, f, opts).answer;
            if got != Outcome::No {
                wrong.push(format!(
                    "{}: claimed `{f}` cannot hold, the engine says {}",
                    w.candidate,
                    got.as_str()
                ));
                continue;
            }
            let Ok(logicpad::ParsedQuery::Exists(q)) = crate::ask::prepare(pad, f) else {
                wrong.push(format!("{}: claim `{f}` is not a query", w.candidate));
                continue;
            };
            let Some(lits) = q.disjuncts.first() else {
                continue;
            };
            if lits.len() < 2 {
                continue;
            }
            for i in 0..lits.len() {
                let mut rest = lits.clone();
                let dropped = rest.remove(i);
                if is_safe(&rest) && satisfiable(kb, &q, &rest) != Some(true) {
                    wrong.push(format!(
                        "{}: `{f}` is not minimal: it fails without `{}`",
                        w.candidate,
                        literal_text(&dropped, &q, None)
                    ));
                }
            }
        }
    }
    wrong
}

/// Why-not for a failed conjunctive query (its first alternative: every
/// alternative failed): for each answer variable, the window's objects
/// that satisfy the most of the literals mentioning it (none already
/// named for another variable), each with its claims (see the module's
/// documentation).
pub(crate) fn why_not(pad: &LogicPad, kb: &WindowKb, ast: &QueryAst) -> Vec<WhyNot> {
    let Some(conj) = ast.disjuncts.first() else {
        return Vec::new();
    };
    let mut out: Vec<WhyNot> = Vec::new();
    // A `¬∃` over no outside variable ("are there no trucks?") fails by a
    // match of its own: named with the facts that make it.
    for l in conj {
        if l.is_not_exists()
            && l.free_vars().is_empty()
            && let Some((bindings, facts)) = blocking_match(kb, ast, l)
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
        let (any_of_kind, mut scored) = scores(kb, ast, v, &mentions, &identity);
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
            if let Some(core) = minimal_unsatisfiable(kb, ast, kind, false, None) {
                out.push(WhyNot {
                    variable: name.clone(),
                    candidate: NO_CANDIDATE.into(),
                    satisfied: Vec::new(),
                    failed: vec![conjunction_text(&core, ast, None)],
                    failed_vars: vec![vars_in(&core, ast, None)],
                    uncertain: Vec::new(),
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
        let groups = Groups::of(kb, ast, conj, v);
        for (_, obj, holds) in scored {
            if let Some(w) = candidate(kb, ast, &groups, v, &name, obj, &mentions, &holds) {
                out.push(w);
            }
        }
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
    let ground =
        |t: &str| !t.contains('∧') && !t.starts_with('¬') && free_vars_of_text(t).is_empty();
    let mut out = Vec::new();
    for f in w.failed.iter().filter(|f| ground(f)) {
        if let Some(q) = kb.doubt(f) {
            out.push(format!(
                "{f} may hold all the same (measured, not asserted: probability {}).",
                crate::belief::rounded(q)
            ));
        }
    }
    for s in w.satisfied.iter().filter(|s| ground(s)) {
        let Some((pred, rest)) = s.split_once('(') else {
            continue;
        };
        let args: Vec<&str> = rest
            .trim_end_matches(')')
            .split(',')
            .map(str::trim)
            .collect();
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

/// A failed claim: literals (the candidate in place) that cannot hold
/// together, and the variables left in them.
type Claim = (String, Vec<String>);

/// The query's literals for one why-not variable `v`, in groups that must
/// hold *together* once `v` is bound: two literals are in one group when
/// they share a variable other than `v` (`On(x, y) ∧ Sidewalk(y)` for `x`),
/// so that "for some y" is one `y` for the whole group. Groups share no
/// variable but `v`: a candidate satisfies the query exactly when it
/// satisfies every group, so every group it fails is a condition that
/// fails for it.
///
/// Invariant: `members` partitions the conjunction's literal positions,
/// each group ascending, groups in order of their first literal;
/// `fixed[i]` is `Some` exactly for the groups without `v`, holding their
/// failed claims (the same for every candidate, found once); `memo`
/// holds what the engine said of this variable's conjunctions so far.
struct Groups<'a> {
    conj: &'a [Literal],
    members: Vec<Vec<usize>>,
    fixed: Vec<Option<Vec<Claim>>>,
    memo: Memo,
}

impl<'a> Groups<'a> {
    fn of(kb: &WindowKb, ast: &QueryAst, conj: &'a [Literal], v: usize) -> Groups<'a> {
        // Union-find over literal positions, joined by shared variables.
        let mut parent: Vec<usize> = (0..conj.len()).collect();
        fn root(parent: &mut [usize], mut i: usize) -> usize {
            while let Some(&p) = parent.get(i) {
                if p == i {
                    break;
                }
                i = p;
            }
            i
        }
        let vars: Vec<Vec<usize>> = conj
            .iter()
            .map(|l| l.free_vars().into_iter().filter(|&x| x != v).collect())
            .collect();
        for i in 0..conj.len() {
            for j in 0..i {
                let share = vars
                    .get(i)
                    .zip(vars.get(j))
                    .is_some_and(|(a, b)| a.iter().any(|x| b.contains(x)));
                if share {
                    let (a, b) = (root(&mut parent, i), root(&mut parent, j));
                    if let Some(p) = parent.get_mut(a.max(b)) {
                        *p = a.min(b);
                    }
                }
            }
        }
        let mut members: Vec<Vec<usize>> = Vec::new();
        let mut roots: Vec<usize> = Vec::new();
        for i in 0..conj.len() {
            let r = root(&mut parent, i);
            match roots.iter().position(|&x| x == r) {
                Some(k) => {
                    if let Some(m) = members.get_mut(k) {
                        m.push(i);
                    }
                }
                None => {
                    roots.push(r);
                    members.push(vec![i]);
                }
            }
        }
        let memo = Memo::default();
        let fixed = members
            .iter()
            .map(|m| {
                let lits: Vec<Literal> = m.iter().filter_map(|&i| conj.get(i).cloned()).collect();
                (!lits.iter().any(|l| mentions_var(l, v)))
                    .then(|| group_failures(kb, ast, lits, &memo))
            })
            .collect();
        Groups {
            conj,
            members,
            fixed,
            memo,
        }
    }
}

/// The failed claims of one group of literals (the candidate in place),
/// every one checked: each literal that has no answer on its own, then,
/// when the rest still has none together, a minimal set of the rest that
/// has none (found by asking the engine). Empty when the group holds, or
/// the engine cannot say.
fn group_failures(kb: &WindowKb, ast: &QueryAst, lits: Vec<Literal>, memo: &Memo) -> Vec<Claim> {
    let mut out = Vec::new();
    let mut rest = Vec::new();
    for l in lits {
        let one = std::slice::from_ref(&l);
        if is_safe(one) && satisfiable(kb, ast, one) == Some(false) {
            out.push((literal_text(&l, ast, None), vars_in(one, ast, None)));
        } else {
            rest.push(l);
        }
    }
    // What is left fails only by how its literals join (or not at all):
    // a literal failing on its own is in no minimal set of the rest. A
    // group already failing by one of its literals is named by it: the
    // joint check of the rest would cost an engine call per group for a
    // second reason (+14 % on the KITTI KB benchmark's `--json`).
    if out.is_empty()
        && rest.len() > 1
        && is_safe(&rest)
        && satisfiable_memo(kb, ast, &rest, Some(memo)) == Some(false)
        && let Some(core) = minimal_unsatisfiable(kb, ast, rest, true, Some(memo))
    {
        out.push((
            conjunction_text(&core, ast, None),
            vars_in(&core, ast, None),
        ));
    }
    out
}

/// One candidate's claims. What holds: each literal on the candidate that
/// holds on its own (from the holder sets, `holds`, in `mentions` order).
/// What fails: every group of [`Groups`] the candidate fails, each in
/// checked claims — a literal on the candidate alone decided by the holder
/// sets, any other group by asking the engine ([`group_failures`]).
#[allow(clippy::too_many_arguments)]
fn candidate(
    kb: &WindowKb,
    ast: &QueryAst,
    groups: &Groups,
    v: usize,
    name: &str,
    obj: &str,
    mentions: &[&Literal],
    holds: &[bool],
) -> Option<WhyNot> {
    let subst = Some((v, obj));
    let mut satisfied = Vec::new();
    let mut failed = Vec::new();
    let mut failed_vars = Vec::new();
    for (lit, &h) in mentions.iter().zip(holds) {
        // A negation or comparison over another variable says nothing
        // checkable on its own.
        if !alone_is_safe(lit, v) {
            continue;
        }
        if h {
            satisfied.push(literal_text(lit, ast, subst));
        } else if lit.is_not_exists()
            && let Some((_, facts)) = blocking_match(kb, ast, &bind_var(lit, v, obj))
        {
            // A failed `¬∃` is named with its blocking match: the facts,
            // true on their own, that make its conjunction hold.
            satisfied.push(facts);
        }
    }
    // The candidate's own literals first (what it is, on its own), then
    // the groups it shares with other variables, each in query order.
    for own in [true, false] {
        for (members, fixed) in groups.members.iter().zip(&groups.fixed) {
            let lits: Vec<&Literal> = members.iter().filter_map(|&i| groups.conj.get(i)).collect();
            let alone = match lits[..] {
                [lit] if fixed.is_none() && is_ground_but(lit, v) => Some(lit),
                _ => None,
            };
            if alone.is_some() != own {
                continue;
            }
            if let Some(lit) = alone {
                // Decided already, by the holder sets.
                let h = mentions
                    .iter()
                    .position(|m| std::ptr::eq(*m, lit))
                    .and_then(|i| holds.get(i));
                if h == Some(&false) {
                    failed.push(literal_text(lit, ast, subst));
                    failed_vars.push(vars_in(std::slice::from_ref(lit), ast, subst));
                }
                continue;
            }
            let claims = match fixed {
                Some(claims) => claims.clone(),
                None => {
                    let bound: Vec<Literal> = lits.iter().map(|l| bind_var(l, v, obj)).collect();
                    group_failures(kb, ast, bound, &groups.memo)
                }
            };
            for (f, vars) in claims {
                failed.push(f);
                failed_vars.push(vars);
            }
        }
    }
    if failed.is_empty() {
        return None;
    }
    Some(WhyNot {
        variable: name.to_string(),
        candidate: obj.to_string(),
        satisfied,
        failed,
        failed_vars,
        uncertain: Vec::new(),
    })
}

/// A deletion-based minimal unsatisfiable subset of `lits`: each literal
/// in turn is dropped when what is left is safe and still has no answer.
/// `None` when `lits` has an answer after all (checked unless
/// `known_unsatisfiable`), or the engine cannot say.
fn minimal_unsatisfiable(
    kb: &WindowKb,
    ast: &QueryAst,
    lits: Vec<Literal>,
    known_unsatisfiable: bool,
    memo: Option<&Memo>,
) -> Option<Vec<Literal>> {
    // A candidate's whole conjunction has no answer (the query's answer is
    // "no"): asking again would cost a join per "no" of a batch.
    if !known_unsatisfiable && satisfiable_memo(kb, ast, &lits, memo)? {
        return None;
    }
    let mut core = lits;
    // Passes until none drops a literal: a literal kept because dropping
    // it left a negation unbound may go once that negation has gone.
    // A literal kept because the rest has an answer without it stays
    // needed as the set shrinks (fewer literals, more answers); only one
    // kept because dropping it left a negation unbound is tried again, in
    // passes until none goes.
    let mut needed = vec![false; core.len()];
    loop {
        let mut dropped = false;
        let mut unsafe_kept = false;
        let mut i = 0;
        while i < core.len() {
            if needed.get(i).copied().unwrap_or(false) {
                i += 1;
                continue;
            }
            let mut without = core.clone();
            without.remove(i);
            if !is_safe(&without) {
                unsafe_kept = true;
                i += 1;
            } else if satisfiable_memo(kb, ast, &without, memo) == Some(false) {
                core = without;
                needed.remove(i);
                dropped = true;
            } else {
                if let Some(n) = needed.get_mut(i) {
                    *n = true;
                }
                i += 1;
            }
        }
        if !(dropped && unsafe_kept) {
            return Some(core);
        }
    }
}

/// Whether `l` has no variable but `v`.
fn is_ground_but(l: &Literal, v: usize) -> bool {
    let other = |a: &Arg| matches!(a, Arg::Var(x) if *x != v);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => !a.args.iter().any(other),
        Literal::Cmp { left, right, .. } => !other(left) && !other(right),
        Literal::NotExists { .. } => l.free_vars().iter().all(|&x| x == v),
    }
}

/// The first match of a `¬∃` literal whose outside variables are all
/// constants: its own variables' values (sorted by name), and its body
/// with them in place, as query text that holds. `None` when it has no
/// match (the literal holds) or the engine cannot say.
fn blocking_match(
    kb: &WindowKb,
    ast: &QueryAst,
    l: &Literal,
) -> Option<(Vec<(String, String)>, String)> {
    let Literal::NotExists { vars, body, .. } = l else {
        return None;
    };
    let q = QueryAst {
        source: ast.source.clone(),
        vars: ast.vars.clone(),
        answer_vars: vars.clone(),
        disjuncts: vec![body.clone()],
        plans: Default::default(),
    };
    let first = kb.model.answers(&q, None).ok()?.next()?;
    let value = |v: usize| {
        let name = ast.vars.get(v).cloned().unwrap_or_default();
        vars.contains(&v)
            .then(|| first.bindings.iter().find(|(n, _)| *n == name))
            .flatten()
            .map_or(name, |(_, c)| c.clone())
    };
    let facts: Vec<String> = body
        .iter()
        .map(|b| logicpad::fol::literal_text(b, &value))
        .collect();
    Some((first.bindings, facts.join(" ∧ ")))
}

/// Whether a conjunction has an answer on the window (`None` when the
/// engine refuses it).
fn satisfiable(kb: &WindowKb, ast: &QueryAst, lits: &[Literal]) -> Option<bool> {
    match lits {
        [] => return Some(true),
        [Literal::Pos(a)] => return Some(atom_satisfiable(kb, a)),
        _ => {}
    }
    let q = QueryAst {
        source: ast.source.clone(),
        vars: ast.vars.clone(),
        answer_vars: Vec::new(),
        disjuncts: vec![lits.to_vec()],
        plans: Default::default(),
    };
    kb.model.satisfiable(&q).ok()
}

/// The answers of [`satisfiable`] to conjunctions of several literals
/// within one why-not, by query text: the deletion searches of a
/// variable's candidates ask the same subsets (`Vehicles(y) ∧ Moving(y)`)
/// again for each candidate.
type Memo = std::cell::RefCell<rustc_hash::FxHashMap<String, Option<bool>>>;

/// [`satisfiable`], remembered in `memo` (when given) for conjunctions of
/// several literals: one literal is one probe, cheaper than its text.
fn satisfiable_memo(
    kb: &WindowKb,
    ast: &QueryAst,
    lits: &[Literal],
    memo: Option<&Memo>,
) -> Option<bool> {
    let Some(memo) = memo.filter(|_| lits.len() > 1) else {
        return satisfiable(kb, ast, lits);
    };
    let key = conjunction_text(lits, ast, None);
    if let Some(&known) = memo.borrow().get(&key) {
        return known;
    }
    let got = satisfiable(kb, ast, lits);
    memo.borrow_mut().insert(key, got);
    got
}

/// Whether some fact matches one positive atom: one probe of its relation
/// where the engine would compile and run a query (the deletion search of
/// [`minimal_unsatisfiable`] asks this of single atoms most of the time:
/// 34,414 of its 52,434 questions on the KITTI benchmark). An unknown
/// predicate or a wrong arity never holds, as in the engine.
fn atom_satisfiable(kb: &WindowKb, a: &logicpad::fol::Atom) -> bool {
    let Some(rel) = kb.model.relation(&a.pred) else {
        return false;
    };
    if rel.arity() != a.args.len() {
        return false;
    }
    let consts = atom_consts(a);
    let pattern: smallvec::SmallVec<[Option<&kanren::Term>; 4]> =
        consts.iter().map(Option::as_ref).collect();
    // `P(x, x)`: the positions of one variable must hold one value.
    let same: smallvec::SmallVec<[(usize, usize); 2]> = a
        .args
        .iter()
        .enumerate()
        .flat_map(|(i, x)| {
            a.args[i + 1..]
                .iter()
                .enumerate()
                .filter(move |(_, y)| matches!((x, y), (Arg::Var(p), Arg::Var(q)) if p == q))
                .map(move |(j, _)| (i, i + 1 + j))
        })
        .collect();
    if same.is_empty() {
        return rel.first_match(&pattern).is_some();
    }
    rel.lookup(&pattern).into_iter().any(|id| {
        rel.tuple(id)
            .is_some_and(|t| same.iter().all(|&(i, j)| t.get(i) == t.get(j)))
    })
}

/// The query's safety rule: every variable of a negation or comparison is
/// bound by a positive literal of the same conjunction.
fn is_safe(lits: &[Literal]) -> bool {
    let bound: Vec<usize> = lits
        .iter()
        .filter_map(Literal::positive)
        .flat_map(|a| a.args.iter())
        .filter_map(|x| if let Arg::Var(v) = x { Some(*v) } else { None })
        .collect();
    lits.iter().all(|l| match l {
        Literal::Pos(_) => true,
        Literal::Neg(a) => a
            .args
            .iter()
            .all(|x| !matches!(x, Arg::Var(v) if !bound.contains(v))),
        Literal::Cmp { left, right, .. } => [left, right]
            .iter()
            .all(|x| !matches!(x, Arg::Var(v) if !bound.contains(v))),
        Literal::NotExists { .. } => l.free_vars().iter().all(|v| bound.contains(v)),
    })
}

/// Whether `l` with `v` bound is a safe query on its own.
fn alone_is_safe(l: &Literal, v: usize) -> bool {
    match l {
        Literal::Pos(_) => true,
        Literal::Neg(a) => a.args.iter().all(|x| !matches!(x, Arg::Var(w) if *w != v)),
        Literal::Cmp { left, right, .. } => [left, right]
            .iter()
            .all(|x| !matches!(x, Arg::Var(w) if *w != v)),
        Literal::NotExists { .. } => l.free_vars().iter().all(|&w| w == v),
    }
}

/// `l` with variable `v` replaced by the constant `obj`.
fn bind_var(l: &Literal, v: usize, obj: &str) -> Literal {
    let bind = |a: &Arg| match a {
        Arg::Var(x) if *x == v => Arg::Const(obj.to_string()),
        other => other.clone(),
    };
    match l {
        Literal::Pos(a) | Literal::Neg(a) => {
            let mut a = a.clone();
            a.args = a.args.iter().map(bind).collect();
            if matches!(l, Literal::Pos(_)) {
                Literal::Pos(a)
            } else {
                Literal::Neg(a)
            }
        }
        Literal::Cmp {
            left,
            right,
            negated,
            span,
        } => Literal::Cmp {
            left: bind(left),
            right: bind(right),
            negated: *negated,
            span: *span,
        },
        // Its own variables are slots of their own, never `v`.
        Literal::NotExists { vars, body, span } => Literal::NotExists {
            vars: vars.clone(),
            body: body.iter().map(|b| bind_var(b, v, obj)).collect(),
            span: *span,
        },
    }
}

/// Literals joined by ` ∧ `, as query text.
fn conjunction_text(lits: &[Literal], ast: &QueryAst, subst: Option<(usize, &str)>) -> String {
    lits.iter()
        .map(|l| literal_text(l, ast, subst))
        .collect::<Vec<_>>()
        .join(" ∧ ")
}

/// The names of the variables left in `lits` (not `subst`'s), in order of
/// first appearance.
fn vars_in(lits: &[Literal], ast: &QueryAst, subst: Option<(usize, &str)>) -> Vec<String> {
    let mut seen: Vec<usize> = Vec::new();
    for l in lits {
        for x in l.free_vars() {
            if subst.is_none_or(|(v, _)| v != x) && !seen.contains(&x) {
                seen.push(x);
            }
        }
    }
    seen.iter()
        .filter_map(|&x| ast.vars.get(x).cloned())
        .collect()
}

/// Why-not's candidates for variable `v`: whether some object of the
/// window satisfies every identity literal (`identity[i]` says which of
/// `mentions` are), and each candidate that satisfies the identity
/// literals and at least one literal, with how many and which (in
/// `mentions` order), in no particular order. Only the candidates that can
/// score are visited; a test holds the result to the definition (every
/// object, every literal decided by a scan of its relation).
fn scores<'k>(
    kb: &'k WindowKb,
    ast: &QueryAst,
    v: usize,
    mentions: &[&Literal],
    identity: &[bool],
) -> (bool, Vec<(usize, &'k str, Holds)>) {
    // Each literal's constants interned once, not once per candidate.
    let consts: Vec<Consts> = mentions.iter().map(|l| literal_consts(l)).collect();
    // Each atom's holders found once, by one probe of its relation,
    // instead of one probe per object: why-not runs for every "no" of
    // a batch, over every object of the window.
    let checks: Vec<Check> = mentions
        .iter()
        .zip(&consts)
        .map(|(l, c)| Check::of(kb, l, c, v))
        .collect();
    // One pass over the objects decides every literal for each: the
    // identity literals pick the candidates, all of them score it.
    // With an identity literal, only its holders can be candidates:
    // the smallest such set is walked instead of every object (a
    // window of a thousand objects has a handful of vans).
    let narrowest = checks
        .iter()
        .zip(identity)
        .filter_map(|(k, &id)| match k {
            Check::Holders(set, false) if id => Some(set),
            _ => None,
        })
        .min_by_key(|set| set.len());
    let candidates: Vec<(&str, kanren::Sym)> = match narrowest {
        // In any order: the ranking below is a total order.
        Some(set) => set
            .iter()
            .filter(|&&s| kb.is_object(s))
            .map(|&s| (s.as_str(), s))
            .collect(),
        // Without one, an object that holds no literal scores nothing
        // and is not shown: when every literal is a positive atom, the
        // union of their holders is every object that can score.
        None if checks.iter().all(|k| matches!(k, Check::Holders(_, false))) => {
            let mut all: Vec<kanren::Sym> = checks
                .iter()
                .flat_map(|k| match k {
                    Check::Holders(set, _) => &set[..],
                    Check::PerObject | Check::NoMatch => &[],
                })
                .copied()
                .collect();
            all.sort_unstable();
            all.dedup();
            all.into_iter()
                .filter(|&s| kb.is_object(s))
                .map(|s| (s.as_str(), s))
                .collect()
        }
        None => kb.objects_with_syms().collect(),
    };
    let mut of_kind = 0usize;
    let mut scored: Vec<(usize, &str, Holds)> = Vec::new();
    for (obj, sym) in candidates {
        let holds: Holds = checks
            .iter()
            .zip(mentions)
            .map(|(k, lit)| k.holds(kb, lit, ast, v, (obj, sym)))
            .collect();
        if holds.iter().zip(identity).any(|(&h, &id)| id && !h) {
            continue;
        }
        of_kind += 1;
        let n = holds.iter().filter(|&&h| h).count();
        if n > 0 {
            scored.push((n, obj, holds));
        }
    }
    (of_kind > 0, scored)
}

/// Whether a literal says what kind of object variable `v` is: its class
/// (a predicate of the `semantic_segmentation` group, or a derived alias
/// of classes such as `IsPerson`) or its `TypeOf`.
fn is_identity(pad: &LogicPad, l: &Literal, v: usize) -> bool {
    let Literal::Pos(a) = l else {
        return false;
    };
    let on_v = matches!(a.args.first(), Some(Arg::Var(x)) if *x == v);
    if !on_v {
        return false;
    }
    if a.pred == "TypeOf" {
        return matches!(a.args.get(1), Some(Arg::Const(_)));
    }
    if a.args.len() != 1 {
        return false;
    }
    let is_class = |name: &str| {
        pad.schema()
            .get(name)
            .is_some_and(|p| p.group.as_deref() == Some("semantic_segmentation"))
    };
    if is_class(&a.pred) {
        return true;
    }
    // A derived alias whose every rule rests on classes alone.
    let program = pad.program();
    let Some(pid) = program.pred_id(&a.pred) else {
        return false;
    };
    let rules: Vec<_> = program
        .rules()
        .iter()
        .filter(|r| r.head.pred == pid)
        .collect();
    !rules.is_empty()
        && rules.iter().all(|r| {
            r.negated.is_empty()
                && r.body.iter().all(|b| {
                    program
                        .pred_name(b.pred)
                        .is_some_and(|n| is_class(n) || n == "TypeOf")
                })
        })
}

/// Whether variable `v` is an argument of `l`.
fn mentions_var(l: &Literal, v: usize) -> bool {
    let is_v = |a: &Arg| matches!(a, Arg::Var(x) if *x == v);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().any(is_v),
        Literal::Cmp { left, right, .. } => is_v(left) || is_v(right),
        Literal::NotExists { .. } => l.free_vars().contains(&v),
    }
}

fn arg_str<'a>(a: &'a Arg, ast: &'a QueryAst, subst: Option<(usize, &'a str)>) -> &'a str {
    match a {
        Arg::Var(v) => match subst {
            Some((sv, c)) if sv == *v => c,
            _ => ast.vars.get(*v).map_or("", String::as_str),
        },
        Arg::Const(c) => c,
    }
}

/// A literal as query text, optionally with one variable replaced.
pub(crate) fn literal_text(l: &Literal, ast: &QueryAst, subst: Option<(usize, &str)>) -> String {
    // Built in one buffer of about the right size: why-not writes a few of
    // these for every "no" of a batch.
    let mut out = String::with_capacity(48);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => {
            if matches!(l, Literal::Neg(_)) {
                out.push('¬');
            }
            out.push_str(&a.pred);
            out.push('(');
            for (i, x) in a.args.iter().enumerate() {
                if i > 0 {
                    out.push_str(", ");
                }
                out.push_str(arg_str(x, ast, subst));
            }
            out.push(')');
        }
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => {
            out.push_str(arg_str(left, ast, subst));
            out.push_str(if *negated { " ≠ " } else { " = " });
            out.push_str(arg_str(right, ast, subst));
        }
        Literal::NotExists { .. } => {
            let name = |v: usize| arg_str(&Arg::Var(v), ast, subst).to_string();
            out.push_str(&logicpad::fol::literal_text(l, &name));
        }
    }
    out
}

/// Whether one literal holds with variable `v` set to `obj` (other
/// variables existential; a negated literal with other free variables is
/// read as "no binding of them makes the atom hold").
/// A literal's constant arguments as terms, by position (`None` for a
/// variable), for [`literal_holds`].
type Consts = smallvec::SmallVec<[Option<kanren::Term>; 4]>;

/// Which of a why-not variable's literals one candidate satisfies, in
/// literal order (inline up to eight: one allocation less per object).
type Holds = smallvec::SmallVec<[bool; 8]>;

fn literal_consts(l: &Literal) -> Consts {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => atom_consts(a),
        Literal::Cmp { .. } | Literal::NotExists { .. } => Consts::new(),
    }
}

/// An atom's constants as terms, `None` at its variables.
fn atom_consts(a: &logicpad::fol::Atom) -> Consts {
    a.args
        .iter()
        .map(|x| match x {
            Arg::Const(c) => Some(logicpad::const_term(c)),
            Arg::Var(_) => None,
        })
        .collect()
}

/// How why-not decides a literal for one candidate object.
enum Check {
    /// An atom: the values of the why-not variable that some fact gives it
    /// (the literal's other variables existential), and whether the atom is
    /// negated.
    /// (Sorted and without duplicates, searched by binary search: the
    /// sets are small, and hashing cost more.)
    Holders(Arc<[kanren::Sym]>, bool),
    /// A comparison, decided per object by [`cmp_holds`].
    PerObject,
    /// A `¬∃`, decided per object by asking whether its conjunction has
    /// a match with the object in place.
    NoMatch,
}

/// The holder sets a window's why-not answers have found, by atom shape:
/// the questions of a batch on one window share their literals
/// (`TypeOf(x, Car)`, `Moving(x)`), and each set was found again for every
/// "no" (a probe of the relation, a sort).
///
/// Invariant: the set under a key is what [`Check::of`] finds for an atom
/// of that shape in the window the cache belongs to (the window's model
/// never changes).
#[derive(Debug, Default)]
pub(crate) struct HolderCache(
    std::sync::Mutex<rustc_hash::FxHashMap<HolderKey, Arc<[kanren::Sym]>>>,
);

/// An atom's shape for [`HolderCache`]: its relation, and per argument its
/// constant, the why-not variable, or another (existential) variable.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) struct HolderKey {
    pred: kanren::Sym,
    args: smallvec::SmallVec<[KeyArg; 4]>,
}

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum KeyArg {
    Const(Option<kanren::Term>),
    Target,
    Other,
}

impl HolderCache {
    fn get(&self, key: &HolderKey) -> Option<Arc<[kanren::Sym]>> {
        self.0.lock().ok()?.get(key).cloned()
    }

    fn put(&self, key: HolderKey, set: Arc<[kanren::Sym]>) {
        if let Ok(mut m) = self.0.lock() {
            m.insert(key, set);
        }
    }
}

impl Check {
    fn of(kb: &WindowKb, l: &Literal, consts: &Consts, v: usize) -> Check {
        let (atom, neg) = match l {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => return Check::PerObject,
            Literal::NotExists { .. } => return Check::NoMatch,
        };
        let Some(rel) = kb.model.relation(&atom.pred) else {
            return Check::Holders(Arc::from([]), neg);
        };
        let key = HolderKey {
            pred: rel.name(),
            args: atom
                .args
                .iter()
                .zip(consts)
                .map(|(a, c)| match a {
                    Arg::Const(_) => KeyArg::Const(c.clone()),
                    Arg::Var(x) if *x == v => KeyArg::Target,
                    Arg::Var(_) => KeyArg::Other,
                })
                .collect(),
        };
        if let Some(set) = kb.holders.get(&key) {
            return Check::Holders(set, neg);
        }
        let set: Arc<[kanren::Sym]> = holders_of(rel, atom, consts, v).into();
        kb.holders.put(key, Arc::clone(&set));
        Check::Holders(set, neg)
    }

    fn holds(
        &self,
        kb: &WindowKb,
        l: &Literal,
        ast: &QueryAst,
        v: usize,
        (obj, obj_sym): (&str, kanren::Sym),
    ) -> bool {
        match self {
            Check::Holders(set, neg) => set.binary_search(&obj_sym).is_ok() != *neg,
            Check::PerObject => cmp_holds(l, ast, v, obj),
            Check::NoMatch => not_exists_holds(kb, ast, l, v, obj),
        }
    }
}

/// The values of variable `v` that some fact of `rel` gives atom `atom`
/// (its constants `consts`, its other variables existential): sorted,
/// without duplicates.
fn holders_of(
    rel: &kanren::Relation,
    atom: &logicpad::fol::Atom,
    consts: &Consts,
    v: usize,
) -> Vec<kanren::Sym> {
    let mut set = Vec::new();
    let pattern: smallvec::SmallVec<[Option<&kanren::Term>; 4]> = atom
        .args
        .iter()
        .zip(consts)
        .map(|(a, c)| match a {
            Arg::Const(_) => c.as_ref(),
            Arg::Var(_) => None,
        })
        .collect();
    let at: smallvec::SmallVec<[usize; 2]> = atom
        .args
        .iter()
        .enumerate()
        .filter(|(_, a)| matches!(a, Arg::Var(x) if *x == v))
        .map(|(i, _)| i)
        .collect();
    // Nothing but the why-not variable, at one position: its holders are
    // that position's distinct values, read off the index.
    if let [pos] = at[..]
        && pattern.iter().all(Option::is_none)
    {
        set.extend(rel.values_at(pos).filter_map(|t| match t {
            kanren::Term::Sym(s) => Some(*s),
            _ => None,
        }));
        set.sort_unstable();
        return set;
    }
    for id in rel.lookup(&pattern) {
        let Some(t) = rel.tuple(id) else { continue };
        let mut vals = at.iter().filter_map(|&i| t.get(i));
        // `P(x, x)`: every position of the variable takes one value.
        if let Some(kanren::Term::Sym(first)) = vals.next()
            && vals.all(|o| matches!(o, kanren::Term::Sym(s) if s == first))
        {
            set.push(*first);
        }
    }
    set.sort_unstable();
    set.dedup();
    set
}

/// Whether a `¬∃` holds with `v` bound to `obj`: its conjunction has no
/// match. Another free variable is existential, so the literal alone
/// cannot rule `obj` out (as for a comparison).
fn not_exists_holds(kb: &WindowKb, ast: &QueryAst, l: &Literal, v: usize, obj: &str) -> bool {
    if l.free_vars().iter().any(|&w| w != v) {
        return true;
    }
    satisfiable(kb, ast, &[bind_var(l, v, obj)]).unwrap_or(true)
}

/// Whether a comparison holds with `v` bound to `obj`.
fn cmp_holds(l: &Literal, ast: &QueryAst, v: usize, obj: &str) -> bool {
    let Literal::Cmp {
        left,
        right,
        negated,
        ..
    } = l
    else {
        return true;
    };
    // Another free variable on either side is existential: the comparison
    // alone cannot rule `obj` out (its name is not a constant to compare
    // with).
    let free = |a: &Arg| matches!(a, Arg::Var(x) if *x != v);
    if free(left) || free(right) {
        return true;
    }
    let eq = arg_str(left, ast, Some((v, obj))) == arg_str(right, ast, Some((v, obj)));
    eq != *negated
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ask::{AskOptions, Outcome, ask, prepare};
    use crate::kb::{Observed, test_window};
    use logicpad::ParsedQuery;
    use proptest::prelude::*;
    use std::collections::BTreeMap;

    /// Every predicate of the LogicPad fully observed: claims answer yes or no.
    fn all_observed(pad: &LogicPad) -> BTreeMap<String, Observed> {
        pad.schema()
            .predicates()
            .map(|p| (p.name.clone(), Observed::Fully))
            .collect()
    }

    /// The two-roads case: "is the pedestrian not on a road?" is no for
    /// ped_1, and why-not names the blocking match; "are there no
    /// trucks?" is no, named with the truck. Every claim is asked back.
    #[test]
    fn a_failed_negated_exists_is_named_with_its_blocking_match() {
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Pedestrian", &["ped_1"]),
                ("Road", &["road_1"]),
                ("Road", &["road_2"]),
                ("On", &["ped_1", "road_1"]),
                ("Vehicles", &["truck_1"]),
                ("TypeOf", &["truck_1", "Truck"]),
            ],
        );
        let obs = all_observed(&pad);
        let q = "Pedestrian(x) ∧ ¬∃y: (Road(y) ∧ On(x, y))";
        let r = ask(&pad, &kb, &obs, q, AskOptions::default());
        assert_eq!(r.answer, Outcome::No);
        let w = &r.why_not[0];
        assert_eq!(w.candidate, "ped_1");
        assert_eq!(w.failed, vec!["¬∃y: (Road(y) ∧ On(ped_1, y))"]);
        assert!(
            w.satisfied
                .contains(&"Road(road_1) ∧ On(ped_1, road_1)".to_string()),
            "{w:?}"
        );
        assert!(
            audit(&pad, &kb, &obs, &r).is_empty(),
            "{:?}",
            audit(&pad, &kb, &obs, &r)
        );
        // The loose reading answers yes: some road ped_1 is not on.
        let loose = ask(
            &pad,
            &kb,
            &obs,
            "Pedestrian(x) ∧ Road(y) ∧ ¬On(x, y)",
            AskOptions::default(),
        );
        assert_eq!(loose.answer, Outcome::Yes);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "¬∃x: (TypeOf(x, Truck))",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        assert_eq!(
            r.why_not[0].sentence().as_deref(),
            Some(
                "¬∃x: (TypeOf(x, Truck)) does not hold: TypeOf(truck_1, Truck) holds (x = truck_1)."
            )
        );
        assert!(audit(&pad, &kb, &obs, &r).is_empty());
        let r = ask(
            &pad,
            &kb,
            &obs,
            "¬∃x: (TypeOf(x, Car))",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::Yes);
        assert_eq!(
            crate::proof::lines(&r.proofs[0]),
            vec!["¬∃x: (TypeOf(x, Car))  [no match: closed world]"]
        );
    }

    #[test]
    fn a_join_that_fails_is_named_with_the_literal_outside_the_candidate() {
        // Regression (issue 22): "Is the pedestrian on the road?" said
        // "Pedestrian(ped_5) ∧ On(ped_5, y) together does not hold" — it
        // holds with y = walk_9; what fails is Road(y) for every such y.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Pedestrian", &["ped_5"]),
                ("Sidewalk", &["walk_9"]),
                ("Road", &["road_1"]),
                ("On", &["ped_5", "walk_9"]),
            ],
        );
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "Pedestrian(x) ∧ On(x, y) ∧ Road(y)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        let w = r
            .why_not
            .iter()
            .find(|w| w.variable == "x")
            .expect("a candidate for x");
        assert_eq!(w.candidate, "ped_5");
        assert_eq!(w.satisfied, ["Pedestrian(ped_5)", "On(ped_5, y)"]);
        assert_eq!(w.failed, ["On(ped_5, y) ∧ Road(y)"]);
        assert_eq!(
            w.sentence().as_deref(),
            Some(
                "ped_5 comes closest: Pedestrian(ped_5) holds and On(ped_5, y) holds for some y, \
                 but On(ped_5, y) ∧ Road(y) holds for no y."
            )
        );
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
    }

    #[test]
    fn claims_resting_on_uncertain_facts_say_so() {
        // Issue 36 item 2: a failed atom measured and not asserted (a
        // doubt) may hold all the same; a satisfied atom measured below
        // PROBABLY_BELOW is only probable. Notes, not claims.
        let pad = LogicPad::builtin();
        let fact = |p: &str, args: &[&str], prob: Option<f64>| {
            let mut f = crate::kb::test_fact(p, args, "measured");
            std::sync::Arc::make_mut(&mut f.provenance).probability = prob;
            f
        };
        let input = crate::kb::WindowInput {
            id: "w".into(),
            index: 0,
            first_frame: 0,
            last_frame: 9,
            facts: crate::kb::WindowFacts::Listed(vec![
                fact("Vehicles", &["car_1"], None),
                fact("TypeOf", &["car_1", "Car"], Some(0.8)),
            ]),
            doubts: vec![fact("Moving", &["car_1"], Some(0.3))],
        };
        let kb = WindowKb::build(input, pad.program()).unwrap();
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "TypeOf(x, Car) ∧ Moving(x)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        let w = &r.why_not[0];
        assert_eq!(w.failed, vec!["Moving(car_1)".to_string()]);
        assert_eq!(
            w.uncertain,
            vec![
                "Moving(car_1) may hold all the same (measured, not asserted: probability 0.3)."
                    .to_string(),
                "TypeOf(car_1, Car) is only probable (probability 0.8).".to_string(),
            ]
        );
        let said = w.sentence().unwrap();
        assert!(said.ends_with("(probability 0.8)."), "{said}");
        // A certain window has no notes.
        let certain = test_window(
            pad.program(),
            &[("Vehicles", &["car_1"]), ("TypeOf", &["car_1", "Car"])],
        );
        let r = ask(
            &pad,
            &certain,
            &obs,
            "TypeOf(x, Car) ∧ Moving(x)",
            AskOptions::default(),
        );
        assert!(r.why_not.iter().all(|w| w.uncertain.is_empty()));
    }

    #[test]
    fn a_candidate_is_told_every_condition_it_fails() {
        // Regression (issue 36): "Is the white van on the sidewalk?" said
        // "van_3 comes closest: TypeOf(van_3, Van) holds and On(van_3, y)
        // holds for some y, but ColorOf(van_3, White) does not hold" — van_3
        // is on the road, so `Sidewalk(y) ∧ On(van_3, y)` fails too (one y
        // for both, though each holds on its own).
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Vehicles", &["van_3"]),
                ("TypeOf", &["van_3", "Van"]),
                ("ColorOf", &["van_3", "Silver"]),
                ("Road", &["road_1"]),
                ("Sidewalk", &["walk_2"]),
                ("On", &["van_3", "road_1"]),
            ],
        );
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "TypeOf(x, Van) ∧ ColorOf(x, White) ∧ Sidewalk(y) ∧ On(x, y)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        let w = r
            .why_not
            .iter()
            .find(|w| w.variable == "x")
            .expect("a candidate for x");
        assert_eq!(w.candidate, "van_3");
        assert_eq!(w.satisfied, ["TypeOf(van_3, Van)", "On(van_3, y)"]);
        assert_eq!(
            w.failed,
            ["ColorOf(van_3, White)", "Sidewalk(y) ∧ On(van_3, y)"]
        );
        assert_eq!(
            w.sentence().as_deref(),
            Some(
                "van_3 comes closest: TypeOf(van_3, Van) holds and On(van_3, y) holds for some y, \
                 but ColorOf(van_3, White) does not hold; Sidewalk(y) ∧ On(van_3, y) holds for no y."
            )
        );
        // For y, each condition of its group fails on its own: nothing is
        // white, and nothing is on the sidewalk.
        let w = r
            .why_not
            .iter()
            .find(|w| w.variable == "y")
            .expect("a candidate for y");
        assert_eq!(w.candidate, "walk_2");
        assert_eq!(w.failed, ["ColorOf(x, White)", "On(x, walk_2)"]);
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
    }

    #[test]
    fn an_object_comes_closest_once_per_answer() {
        // Regression (issue 36): car_1 came closest for x and again for y;
        // y's explanation goes to the next candidate, ped_2.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Vehicles", &["car_1"]),
                ("Pedestrian", &["ped_2"]),
                ("Moving", &["car_1"]),
                ("Moving", &["ped_2"]),
            ],
        );
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "Vehicles(x) ∧ Moving(y) ∧ DistanceDecrease(x, y)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        let named: Vec<(&str, &str)> = r
            .why_not
            .iter()
            .map(|w| (w.variable.as_str(), w.candidate.as_str()))
            .collect();
        assert_eq!(named, [("x", "car_1"), ("y", "ped_2")]);
        assert_eq!(r.why_not[0].failed, ["DistanceDecrease(car_1, y)"]);
        assert_eq!(r.why_not[1].failed, ["DistanceDecrease(x, ped_2)"]);
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
    }

    #[test]
    fn a_negation_over_another_variable_is_claimed_only_with_what_binds_it() {
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Pedestrian", &["ped_4"]),
                ("Vehicles", &["car_1"]),
                ("DistanceDecrease", &["car_1", "ped_4"]),
            ],
        );
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "Vehicles(x) ∧ Pedestrian(y) ∧ ¬DistanceDecrease(x, y)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No);
        for w in &r.why_not {
            for c in w.satisfied.iter().chain(&w.failed) {
                assert!(prepare(&pad, c).is_ok(), "claim `{c}` must be a safe query");
            }
        }
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
    }

    #[test]
    fn a_universal_names_its_counterexample_by_its_own_variable() {
        // The counterexample's values come sorted by variable name; the
        // names must come from the same bindings, not from the written order.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[("Pedestrian", &["ped_4"]), ("Vehicles", &["car_1"])],
        );
        let obs = all_observed(&pad);
        let r = ask(
            &pad,
            &kb,
            &obs,
            "∀x: Pedestrian(x) → Moving(x)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No, "{r:?}");
        assert_eq!(r.why_not[0].satisfied, ["Pedestrian(ped_4)"]);
        assert_eq!(r.why_not[0].failed, ["Moving(ped_4)"]);
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
        // Written `y, x`, answered sorted `x, y`: each name goes with its
        // own value (they were paired in written order before).
        let r = ask(
            &pad,
            &kb,
            &obs,
            "∀y, x: Vehicles(y) ∧ Pedestrian(x) → DistanceDecrease(y, x)",
            AskOptions::default(),
        );
        assert_eq!(r.answer, Outcome::No, "{r:?}");
        assert_eq!(r.why_not[0].variable, "x, y");
        assert_eq!(r.why_not[0].candidate, "ped_4, car_1");
        assert_eq!(r.why_not[0].failed, ["DistanceDecrease(car_1, ped_4)"]);
        assert_eq!(audit(&pad, &kb, &obs, &r), Vec::<String>::new());
    }

    const OBJECTS: [&str; 6] = ["car_1", "car_2", "van_3", "ped_4", "road_5", "walk_6"];
    const MOVERS: [&str; 4] = ["car_1", "car_2", "van_3", "ped_4"];

    /// A random window over six objects: classes, motion, colours, places
    /// and pairwise distance trends, each present or not.
    fn random_facts() -> impl Strategy<Value = Vec<(String, Vec<String>)>> {
        let mut choices: Vec<(String, Vec<String>)> = Vec::new();
        let one = |p: &str, a: &[&str]| (p.to_string(), a.iter().map(|s| s.to_string()).collect());
        for o in MOVERS {
            for p in ["Vehicles", "Pedestrian", "Moving", "SpeedUp", "SpeedDown"] {
                choices.push(one(p, &[o]));
            }
            for c in ["Red", "White"] {
                choices.push(one("ColorOf", &[o, c]));
            }
            for t in ["Car", "Van"] {
                choices.push(one("TypeOf", &[o, t]));
            }
            for place in ["road_5", "walk_6"] {
                choices.push(one("On", &[o, place]));
            }
            for o2 in MOVERS {
                choices.push(one("DistanceDecrease", &[o, o2]));
            }
        }
        for o in ["road_5", "walk_6"] {
            choices.push(one("Road", &[o]));
            choices.push(one("Sidewalk", &[o]));
        }
        let n = choices.len();
        prop::collection::vec(any::<bool>(), n).prop_map(move |keep| {
            choices
                .iter()
                .zip(keep)
                .filter(|(_, k)| *k)
                .map(|(f, _)| f.clone())
                .collect()
        })
    }

    /// A random safe conjunctive query over x, y, z: two to five literals
    /// from positive atoms, negations and comparisons over bound variables.
    fn random_query() -> impl Strategy<Value = String> {
        let vars = prop::sample::select(vec!["x", "y", "z"]);
        let konst = prop::sample::select(OBJECTS.to_vec());
        let term = prop_oneof![4 => vars.clone().prop_map(str::to_string), 1 => konst.prop_map(str::to_string)];
        let unary = prop::sample::select(vec![
            "Vehicles",
            "Pedestrian",
            "Moving",
            "SpeedUp",
            "Road",
            "Sidewalk",
            "Stopped",
            "Walk",
            "Cross",
            "ConstantSpeed",
        ]);
        let binary = prop::sample::select(vec!["On", "DistanceDecrease"]);
        let value = prop::sample::select(vec![
            ("ColorOf", "Red"),
            ("ColorOf", "White"),
            ("TypeOf", "Car"),
            ("TypeOf", "Van"),
        ]);
        let atom = prop_oneof![
            (unary, term.clone()).prop_map(|(p, a)| format!("{p}({a})")),
            (binary, term.clone(), term.clone()).prop_map(|(p, a, b)| format!("{p}({a}, {b})")),
            (value, term.clone()).prop_map(|((p, v), a)| format!("{p}({a}, {v})")),
        ];
        let lit = prop_oneof![
            5 => atom.clone().prop_map(|a| (false, a)),
            2 => atom.prop_map(|a| (true, format!("¬{a}"))),
            1 => (vars.clone(), vars, any::<bool>()).prop_map(|(a, b, ne)| (true, format!("{a} {} {b}", if ne { "≠" } else { "=" }))),
        ];
        prop::collection::vec(lit, 2..6).prop_filter_map("needs a positive literal", |lits| {
            let text: Vec<String> = lits.iter().map(|(_, t)| t.clone()).collect();
            lits.iter().any(|(neg, _)| !neg).then(|| text.join(" ∧ "))
        })
    }

    /// A window of the built-in LogicPad holding `facts`.
    fn random_window(pad: &LogicPad, facts: &[(String, Vec<String>)]) -> WindowKb {
        let lines: Vec<(&str, Vec<&str>)> = facts
            .iter()
            .map(|(p, a)| (p.as_str(), a.iter().map(String::as_str).collect()))
            .collect();
        let refs: Vec<(&str, &[&str])> = lines.iter().map(|(p, a)| (*p, a.as_slice())).collect();
        test_window(pad.program(), &refs)
    }

    /// The groups of the query's literals (the candidate in place) that
    /// have no answer for a why-not candidate, yet no failed claim of it
    /// names: each should be named by a claim of its own literals.
    fn unnamed_failures(pad: &LogicPad, kb: &WindowKb, q: &str, why: &[WhyNot]) -> Vec<String> {
        let Ok(ParsedQuery::Exists(ast)) = prepare(pad, q) else {
            return Vec::new();
        };
        let Some(conj) = ast.disjuncts.first() else {
            return Vec::new();
        };
        let mut out = Vec::new();
        for w in why.iter().filter(|w| w.candidate != NO_CANDIDATE) {
            let Some(v) = ast.vars.iter().position(|n| *n == w.variable) else {
                continue;
            };
            let groups = Groups::of(kb, &ast, conj, v);
            for m in &groups.members {
                let bound: Vec<Literal> = m
                    .iter()
                    .filter_map(|&i| conj.get(i))
                    .map(|l| bind_var(l, v, &w.candidate))
                    .collect();
                if !is_safe(&bound) || satisfiable(kb, &ast, &bound) != Some(false) {
                    continue;
                }
                let texts: Vec<String> =
                    bound.iter().map(|l| literal_text(l, &ast, None)).collect();
                let named = w
                    .failed
                    .iter()
                    .any(|f| f.split(" ∧ ").all(|part| texts.iter().any(|t| t == part)));
                if !named {
                    out.push(format!("{}: {}", w.candidate, texts.join(" ∧ ")));
                }
            }
        }
        out
    }

    proptest! {
            #![proptest_config(ProptestConfig::with_cases(300))]
            /// Every claim of every "no" answer, asked back as a query over a
            /// random window, agrees with the engine (and each failed set is
            /// minimal among safe subsets).
            #[test]
            fn every_why_not_claim_agrees_with_the_engine(facts in random_facts(), queries in prop::collection::vec(random_query(), 4)) {
                let pad = LogicPad::builtin();
                let kb = random_window(&pad, &facts);
                let obs = all_observed(&pad);
                for q in &queries {
                    // Unsafe or ill-typed random queries are invalid: nothing to explain.
                    let r = ask(&pad, &kb, &obs, q, AskOptions::default());
                    if r.answer != Outcome::No {
                        continue;
                    }
                    let wrong = audit(&pad, &kb, &obs, &r);
                    prop_assert!(wrong.is_empty(), "{q}: {wrong:?}\n{:?}", r.why_not);
                    let missing = unnamed_failures(&pad, &kb, q, &r.why_not);
                    prop_assert!(missing.is_empty(), "{q}: unnamed {missing:?}\n{:?}", r.why_not);
                    let mut names: Vec<&str> = r.why_not.iter().map(|w| w.candidate.as_str())
    .filter(|c| *c != NO_CANDIDATE).collect();
                    names.sort_unstable();
                    prop_assert!(names.windows(2).all(|p| p[0] != p[1]), "{q}: {names:?}");
                    // The window's holder sets, filled by the questions before,
                    // change nothing: a window of its own says the same.
                    let fresh = random_window(&pad, &facts);
                    let alone = ask(&pad, &fresh, &obs, q, AskOptions::default());
                    prop_assert_eq!(format!("{:?}", r.why_not), format!("{:?}", alone.why_not), "{}", q);
                    // The C2 context says nothing but these claims.
                    let ctx = crate::context::RagContext::new(&kb, None, &r, crate::context::Sentences::builtin());
                    let expected: Vec<String> = r.why_not.iter().filter_map(WhyNot::sentence).collect();
                    prop_assert_eq!(&ctx.c2[1 + r.notes.len()..], expected.as_slice());
                }
            }
        }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(200))]
        /// The one-atom shortcut of `satisfiable` answers as the engine
        /// does, for every positive atom of random queries over random
        /// windows (constants, repeated variables, unknown objects).
        #[test]
        fn one_atom_satisfiability_is_the_engines(facts in random_facts(), queries in prop::collection::vec(random_query(), 4)) {
            let pad = LogicPad::builtin();
            let kb = random_window(&pad, &facts);
            for q in &queries {
                let Ok(ParsedQuery::Exists(ast)) = prepare(&pad, q) else {
                    continue;
                };
                for l in ast.disjuncts.iter().flatten() {
                    let Literal::Pos(a) = l else { continue };
                    let one = QueryAst {
                        source: ast.source.clone(),
                        vars: ast.vars.clone(),
                        answer_vars: Vec::new(),
                        disjuncts: vec![vec![l.clone()]],
                        plans: Default::default(),
                    };
                    let engine = kb.model.satisfiable(&one).ok();
                    prop_assert_eq!(Some(atom_satisfiable(&kb, a)), engine, "{:?} in {}", a, q);
                }
            }
        }
    }

    /// Whether literal `l` holds with `v` bound to `obj`, by definition: a
    /// scan of every fact of its relation (other variables existential).
    fn holds_by_scan(kb: &WindowKb, ast: &QueryAst, l: &Literal, v: usize, obj: &str) -> bool {
        let (atom, neg) = match l {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => return cmp_holds(l, ast, v, obj),
            Literal::NotExists { .. } => return not_exists_holds(kb, ast, l, v, obj),
        };
        let some = kb.model.relation(&atom.pred).is_some_and(|rel| {
            rel.iter().any(|(_, t)| {
                t.len() == atom.args.len()
                    && atom.args.iter().zip(t.iter()).all(|(a, x)| match a {
                        Arg::Const(c) => x.as_sym().is_some_and(|s| s.as_str() == c),
                        Arg::Var(w) if *w == v => x.as_sym().is_some_and(|s| s.as_str() == obj),
                        Arg::Var(_) => true,
                    })
            })
        });
        some != neg
    }

    #[test]
    fn why_not_scores_equal_the_definition() {
        // `scores` visits only the objects that can score and decides
        // literals from holder sets; by definition every object is tried
        // and every literal decided by scanning its relation.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Vehicles", &["car_1"]),
                ("Vehicles", &["car_2"]),
                ("Vehicles", &["van_3"]),
                ("Pedestrian", &["ped_4"]),
                ("Road", &["road_5"]),
                ("TypeOf", &["car_1", "Car"]),
                ("TypeOf", &["car_2", "Car"]),
                ("TypeOf", &["van_3", "Van"]),
                ("ColorOf", &["car_1", "Red"]),
                ("ColorOf", &["car_2", "White"]),
                ("ColorOf", &["van_3", "White"]),
                ("Moving", &["car_1"]),
                ("Moving", &["ped_4"]),
                ("SpeedUp", &["car_2"]),
                ("DistanceDecrease", &["car_1", "ped_4"]),
                ("DistanceDecrease", &["van_3", "van_3"]),
                ("On", &["car_1", "road_5"]),
                ("On", &["ped_4", "road_5"]),
            ],
        );
        let queries = [
            // An identity literal, narrow and empty.
            "TypeOf(x, Car) ^ ColorOf(x, White) ^ Moving(x)",
            "Vehicles(x) ^ TypeOf(x, Bus)",
            // No identity literal, all positive: the union of holders.
            "Moving(x) ^ SpeedUp(x) ^ ColorOf(x, Red)",
            "Moving(x) ^ On(x, road_5) ^ SpeedUp(x)",
            // Negations and comparisons: every object is a candidate.
            "Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, White)",
            "Moving(x) ^ x != car_1 ^ SpeedUp(x)",
            "Vehicles(x) ^ ¬Moving(x) ^ ¬SpeedUp(x) ^ ColorOf(x, Red)",
            // Two variables, a repeated variable, existential others.
            "Vehicles(x) ^ Pedestrian(y) ^ DistanceDecrease(x, y) ^ SpeedUp(x)",
            "DistanceDecrease(x, x) ^ Moving(x)",
            "Pedestrian(y) ^ Vehicles(x) ^ ¬DistanceDecrease(x, y) ^ On(y, z) ^ SpeedUp(y)",
        ];
        for q in queries {
            let Ok(ParsedQuery::Exists(ast)) = prepare(&pad, q) else {
                panic!("{q} must prepare as an existential query");
            };
            let conj = ast.disjuncts.first().expect("one conjunction");
            for &v in &ast.answer_vars {
                let mentions: Vec<&Literal> = conj.iter().filter(|l| mentions_var(l, v)).collect();
                let identity: Vec<bool> =
                    mentions.iter().map(|l| is_identity(&pad, l, v)).collect();
                let (any_of_kind, mut fast) = scores(&kb, &ast, v, &mentions, &identity);
                let mut of_kind = 0;
                let mut slow: Vec<(usize, &str, Holds)> = Vec::new();
                for obj in &kb.objects {
                    let holds: Holds = mentions
                        .iter()
                        .map(|l| holds_by_scan(&kb, &ast, l, v, obj))
                        .collect();
                    if holds.iter().zip(&identity).any(|(&h, &id)| id && !h) {
                        continue;
                    }
                    of_kind += 1;
                    let n = holds.iter().filter(|&&h| h).count();
                    if n > 0 {
                        slow.push((n, obj, holds));
                    }
                }
                let rank = |a: &(usize, &str, Holds), b: &(usize, &str, Holds)| {
                    b.0.cmp(&a.0).then_with(|| a.1.cmp(b.1))
                };
                fast.sort_by(rank);
                slow.sort_by(rank);
                assert_eq!(fast, slow, "{q}, variable {v}");
                if identity.contains(&true) {
                    assert_eq!(any_of_kind, of_kind > 0, "{q}, variable {v}");
                }
            }
        }
    }
}
