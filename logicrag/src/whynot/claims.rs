//! The claims of one candidate, each checked: the query's literals in groups
//! that hold together, each group's failed claims (a deletion-based minimal
//! unsatisfiable set), satisfiability asked of the engine, and claims as
//! query text.

use super::scores::{atom_consts, mentions_var};
use super::{Claim, WhyNot};
use crate::kb::WindowKb;
use logicpad::QueryAst;
use logicpad::fol::{Arg, Literal};

/// A blocking match of a `¬∃`: its own variables' values, and its body
/// with them in place, in words and typed.
pub(super) type Blocking = (Vec<(String, String)>, String, Vec<Literal>);

/// A failed claim: literals (the candidate in place) that cannot hold
/// together, in words and typed, and the variables left in them.
type Failed = (String, Vec<String>, Vec<Literal>);

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
pub(super) struct Groups<'a> {
    conj: &'a [Literal],
    pub(super) members: Vec<Vec<usize>>,
    fixed: Vec<Option<Vec<Failed>>>,
    memo: Memo,
    /// The limits of every engine check the explanation makes.
    pub(super) bounds: Bounds,
}

impl<'a> Groups<'a> {
    pub(super) fn of(
        kb: &WindowKb,
        ast: &QueryAst,
        conj: &'a [Literal],
        v: usize,
        bounds: Bounds,
    ) -> Groups<'a> {
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
                    .then(|| group_failures(kb, ast, lits, &memo, &bounds))
            })
            .collect();
        Groups {
            conj,
            members,
            fixed,
            memo,
            bounds,
        }
    }
}

/// The claim of one literal of `conj` on the candidate: its place, when
/// it is one of `conj`'s (bound when read), else a bound copy.
fn on_candidate(conj: &[Literal], lit: &Literal, v: usize, obj: &str) -> Claim {
    match conj.iter().position(|l| std::ptr::eq(l, lit)) {
        Some(i) => Claim::OnCandidate(i),
        None => Claim::Literals(vec![bind_var(lit, v, obj)]),
    }
}

/// The failed claims of one group of literals (the candidate in place),
/// every one checked: each literal that has no answer on its own, then,
/// when the rest still has none together, a minimal set of the rest that
/// has none (found by asking the engine). Empty when the group holds, or
/// the engine cannot say.
fn group_failures(
    kb: &WindowKb,
    ast: &QueryAst,
    lits: Vec<Literal>,
    memo: &Memo,
    bounds: &Bounds,
) -> Vec<Failed> {
    let mut out = Vec::new();
    let mut rest = Vec::new();
    for l in lits {
        let one = std::slice::from_ref(&l);
        if is_safe(one) && satisfiable(kb, ast, one, bounds) == Some(false) {
            let vars = vars_in(one, ast, None);
            out.push((literal_text(&l, ast, None), vars, vec![l]));
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
        && satisfiable_memo(kb, ast, &rest, Some(memo), bounds) == Some(false)
        && let Some(core) = minimal_unsatisfiable(kb, ast, rest, true, Some(memo), bounds)
    {
        out.push((
            conjunction_text(&core, ast, None),
            vars_in(&core, ast, None),
            core,
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
pub(super) fn candidate(
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
    let mut satisfied_claims = Vec::new();
    let mut failed = Vec::new();
    let mut failed_claims = Vec::new();
    let mut failed_vars = Vec::new();
    for (lit, &h) in mentions.iter().zip(holds) {
        // A negation or comparison over another variable says nothing
        // checkable on its own.
        if !alone_is_safe(lit, v) {
            continue;
        }
        if h {
            satisfied.push(literal_text(lit, ast, subst));
            satisfied_claims.push(on_candidate(groups.conj, lit, v, obj));
        } else if lit.is_not_exists()
            && let Some((_, facts, lits)) =
                blocking_match(kb, ast, &bind_var(lit, v, obj), &groups.bounds)
        {
            // A failed `¬∃` is named with its blocking match: the facts,
            // true on their own, that make its conjunction hold.
            satisfied.push(facts);
            satisfied_claims.push(Claim::Literals(lits));
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
                    failed_claims.push(on_candidate(groups.conj, lit, v, obj));
                    failed_vars.push(vars_in(std::slice::from_ref(lit), ast, subst));
                }
                continue;
            }
            let claims = match fixed {
                Some(claims) => claims.clone(),
                None => {
                    let bound: Vec<Literal> = lits.iter().map(|l| bind_var(l, v, obj)).collect();
                    group_failures(kb, ast, bound, &groups.memo, &groups.bounds)
                }
            };
            for (f, vars, lits) in claims {
                failed.push(f);
                failed_claims.push(Claim::Literals(lits));
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
        satisfied_claims,
        failed_claims,
        // Set by `why_not`, once for all its candidates.
        query: None,
    })
}

/// A deletion-based minimal unsatisfiable subset of `lits`: each literal
/// in turn is dropped when what is left is safe and still has no answer.
/// `None` when `lits` has an answer after all (checked unless
/// `known_unsatisfiable`), or the engine cannot say.
pub(super) fn minimal_unsatisfiable(
    kb: &WindowKb,
    ast: &QueryAst,
    lits: Vec<Literal>,
    known_unsatisfiable: bool,
    memo: Option<&Memo>,
    bounds: &Bounds,
) -> Option<Vec<Literal>> {
    // A candidate's whole conjunction has no answer (the query's answer is
    // "no"): asking again would cost a join per "no" of a batch.
    if !known_unsatisfiable && satisfiable_memo(kb, ast, &lits, memo, bounds)? {
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
            } else if satisfiable_memo(kb, ast, &without, memo, bounds) == Some(false) {
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
/// with them in place, as query text and as literals, that holds. `None`
/// when it has no match (the literal holds) or the engine cannot say.
pub(super) fn blocking_match(
    kb: &WindowKb,
    ast: &QueryAst,
    l: &Literal,
    bounds: &Bounds,
) -> Option<Blocking> {
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
    let first = kb
        .model
        .answers_limited(&q, None, bounds.now()?.budget())
        .ok()?
        .next()?;
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
    // The same literals, typed: each own variable the match bound, bound.
    let lits: Vec<Literal> = body
        .iter()
        .map(|b| {
            vars.iter().fold(b.clone(), |lit, &v| {
                let name = ast.vars.get(v).map_or("", String::as_str);
                match first.bindings.iter().find(|(n, _)| n == name) {
                    Some((_, c)) => bind_var(&lit, v, c),
                    None => lit,
                }
            })
        })
        .collect();
    Some((first.bindings, facts.join(" ∧ "), lits))
}

/// Whether a conjunction has an answer on the window (`None` when the
/// engine refuses it).
pub(super) fn satisfiable(
    kb: &WindowKb,
    ast: &QueryAst,
    lits: &[Literal],
    bounds: &Bounds,
) -> Option<bool> {
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
    match kb.model.satisfiable_limited(&q, &bounds.now()?).ok()? {
        (found, None) => Some(found),
        // Stopped at a limit: the engine cannot say.
        (_, Some(_)) => None,
    }
}

/// The limits a why-not's engine checks run under: the answer's, its time
/// limit one deadline for all of them (a why-not asks many), so that a
/// server's `--query-time` bounds the explanation too.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Bounds {
    limits: logicpad::Limits,
    deadline: Option<std::time::Instant>,
}

impl Bounds {
    /// Checks under `limits`, the time limit counted from now.
    pub(crate) fn new(limits: &logicpad::Limits) -> Bounds {
        Bounds {
            limits: *limits,
            deadline: limits.time.map(|t| std::time::Instant::now() + t),
        }
    }

    /// The limits of one check now: the time left before the deadline;
    /// `None` once it has passed (the check cannot say).
    fn now(&self) -> Option<logicpad::Limits> {
        match self.deadline {
            None => Some(self.limits),
            Some(d) => Some(logicpad::Limits {
                time: Some(d.checked_duration_since(std::time::Instant::now())?),
                ..self.limits
            }),
        }
    }
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
    bounds: &Bounds,
) -> Option<bool> {
    let Some(memo) = memo.filter(|_| lits.len() > 1) else {
        return satisfiable(kb, ast, lits, bounds);
    };
    let key = conjunction_text(lits, ast, None);
    if let Some(&known) = memo.borrow().get(&key) {
        return known;
    }
    let got = satisfiable(kb, ast, lits, bounds);
    memo.borrow_mut().insert(key, got);
    got
}

/// Whether some fact matches one positive atom: one probe of its relation
/// where the engine would compile and run a query (the deletion search of
/// [`minimal_unsatisfiable`] asks this of single atoms most of the time:
/// 34,414 of its 52,434 questions on the KITTI benchmark). An unknown
/// predicate or a wrong arity never holds, as in the engine.
pub(super) fn atom_satisfiable(kb: &WindowKb, a: &logicpad::fol::Atom) -> bool {
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
pub(super) fn is_safe(lits: &[Literal]) -> bool {
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
pub(super) fn bind_var(l: &Literal, v: usize, obj: &str) -> Literal {
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
pub(super) fn conjunction_text(
    lits: &[Literal],
    ast: &QueryAst,
    subst: Option<(usize, &str)>,
) -> String {
    lits.iter()
        .map(|l| literal_text(l, ast, subst))
        .collect::<Vec<_>>()
        .join(" ∧ ")
}

/// The names of the variables left in `lits` (not `subst`'s), in order of
/// first appearance.
pub(super) fn vars_in(
    lits: &[Literal],
    ast: &QueryAst,
    subst: Option<(usize, &str)>,
) -> Vec<String> {
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

pub(super) fn arg_str<'a>(
    a: &'a Arg,
    ast: &'a QueryAst,
    subst: Option<(usize, &'a str)>,
) -> &'a str {
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
