//! Checking a query against a schema: predicates, arities, declared values,
//! and the safety of its negations and comparisons.

use super::ast::{ParsedQuery, QueryAst};
use crate::diag::{DiagKind, Diagnostic, Severity, Span};
use crate::fol::{Arg, Literal};
use crate::schema::Schema;
use std::collections::BTreeSet;

/// Checks a query against a schema: unknown predicates (with a suggestion),
/// arity, undeclared function values, and safety (every variable under `¬`
/// or in a comparison, and every answer variable, bound by a positive atom
/// in each alternative).
pub fn check_query(schema: &Schema, q: &QueryAst) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for d in &q.disjuncts {
        for l in d {
            match l {
                Literal::Pos(a) | Literal::Neg(a) => {
                    schema.check_atom(a, &q.source, &mut out);
                }
                Literal::NotExists { .. } => {
                    for (a, _) in l.atoms() {
                        schema.check_atom(a, &q.source, &mut out);
                    }
                }
                Literal::Cmp { .. } => {}
            }
        }
    }
    out.extend(safety(q));
    out.sort_by(|a, b| (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message)));
    out.dedup();
    out
}

/// [`check_query`] for either form: a universal is checked through its
/// counterexample query (`A ∧ ¬B`), which holds every atom of both sides
/// and is unsafe exactly when `B` needs a variable that `A` does not bind.
pub fn check_any_query(schema: &Schema, q: &ParsedQuery) -> Vec<Diagnostic> {
    match q {
        ParsedQuery::Exists(q) => check_query(schema, q),
        ParsedQuery::Count(c) => {
            let mut out = check_query(schema, &c.query);
            for (name, span) in c.vars.iter().zip(&c.var_spans) {
                let occurs = c
                    .query
                    .answer_vars
                    .iter()
                    .any(|&v| c.query.vars.get(v) == Some(name));
                if !occurs {
                    out.push(
                        Diagnostic::new(
                            DiagKind::UnsafeRule,
                            Severity::Error,
                            &c.source,
                            *span,
                            format!("`#{{{name}: …}}` counts `{name}`, which the query does not mention"),
                        )
                        .with_label(format!("`{name}` is not in the counted query"))
                        .with_help(format!(
                            "count a variable of the query, e.g. `#{{{name}: TypeOf({name}, Car)}} >= 2`"
                        )),
                    );
                }
            }
            out.sort_by(|a, b| {
                (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message))
            });
            out.dedup();
            out
        }
        ParsedQuery::Forall(u) => {
            let mut out = check_query(schema, &u.counterexamples);
            for name in &u.vars {
                if !u.domain.vars.contains(name) {
                    out.push(
                        Diagnostic::new(
                            DiagKind::UnsafeRule,
                            Severity::Error,
                            &u.source,
                            Span::new(0, u.source.text.len()),
                            format!("`∀{name}`: `{name}` is not bound on the left of `→`"),
                        )
                        .with_label(format!("`{name}` would range over everything"))
                        .with_help(format!(
                            "bind `{name}` on the left, e.g. `∀{name}: Vehicles({name}) → …`"
                        )),
                    );
                }
            }
            out.sort_by(|a, b| {
                (a.span.start, a.kind, &a.message).cmp(&(b.span.start, b.kind, &b.message))
            });
            out.dedup();
            out
        }
    }
}

/// An "unsafe query" error at `span`.
fn unsafe_query(q: &QueryAst, span: Span, what: String, label: String, help: String) -> Diagnostic {
    Diagnostic::new(
        DiagKind::UnsafeRule,
        Severity::Error,
        &q.source,
        span,
        format!("unsafe query: {what}"),
    )
    .with_label(label)
    .with_help(help)
}

/// Marks the variables of the positive atoms of `lits` in `bound`.
fn bind_positives(lits: &[Literal], bound: &mut [bool]) {
    for a in lits.iter().filter_map(Literal::positive) {
        for x in &a.args {
            if let Arg::Var(v) = x
                && let Some(b) = bound.get_mut(*v)
            {
                *b = true;
            }
        }
    }
}

/// The safety of the negated atoms, comparisons and `¬∃` of one
/// conjunction whose bound variables are `bound`: each variable they read
/// from outside must be bound; a `¬∃`'s own variables must occur in a
/// positive atom of its body, whose conjunction is checked in turn.
fn conj_safety(
    q: &QueryAst,
    lits: &[Literal],
    bound: &[bool],
    reported: &mut BTreeSet<usize>,
    out: &mut Vec<Diagnostic>,
) {
    let is_bound = |v: usize| bound.get(v).copied().unwrap_or(false);
    let name = |v: usize| q.vars.get(v).cloned().unwrap_or_default();
    for l in lits {
        let (args, right, span): (&[Arg], _, _) = match l {
            Literal::Neg(a) => (&a.args, None, a.span),
            Literal::Cmp {
                left, right, span, ..
            } => (std::slice::from_ref(left), Some(right), *span),
            Literal::Pos(_) => continue,
            Literal::NotExists { vars, body, span } => {
                for v in l.free_vars() {
                    if !is_bound(v) && reported.insert(v) {
                        let name = name(v);
                        out.push(unsafe_query(
                            q,
                            *span,
                            format!(
                                "variable `{name}` in a `¬∃` is neither its own nor bound by a positive atom outside it"
                            ),
                            format!("`{name}` would range over everything"),
                            format!(
                                "list `{name}` after `∃` to make it the `¬∃`'s own, or bind it outside with a positive atom, e.g. `Vehicles({name})`"
                            ),
                        ));
                    }
                }
                let mut inner: smallvec::SmallVec<[bool; 16]> = bound.iter().copied().collect();
                bind_positives(body, &mut inner);
                for &v in vars {
                    if !inner.get(v).copied().unwrap_or(false) && reported.insert(v) {
                        let name = name(v);
                        out.push(unsafe_query(
                            q,
                            *span,
                            format!("`∃{name}`: `{name}` occurs in no positive atom of the `¬∃`"),
                            format!("`{name}` would range over everything"),
                            format!("use `{name}` in a positive atom inside the parentheses, e.g. `¬∃{name}: (Road({name}) ∧ …)`"),
                        ));
                    }
                }
                // Every variable is marked bound for the nested check: the
                // ones that are not were reported above.
                for v in l.free_vars() {
                    if let Some(b) = inner.get_mut(v) {
                        *b = true;
                    }
                }
                for &v in vars {
                    if let Some(b) = inner.get_mut(v) {
                        *b = true;
                    }
                }
                conj_safety(q, body, &inner, reported, out);
                continue;
            }
        };
        for x in args.iter().chain(right) {
            let Arg::Var(v) = x else { continue };
            let v = *v;
            if !is_bound(v) && reported.insert(v) {
                let what = match l {
                    Literal::Neg(a) => format!("`¬{}`", a.pred),
                    _ => "a comparison".to_string(),
                };
                let name = name(v);
                out.push(unsafe_query(
                    q,
                    span,
                    format!("variable `{name}` in {what} is bound by no positive atom"),
                    format!("`{name}` would range over everything"),
                    format!("add a positive atom that binds `{name}`, e.g. `Vehicles({name})`"),
                ));
            }
        }
    }
}

pub(super) fn safety(q: &QueryAst) -> Vec<Diagnostic> {
    let mut out = Vec::new();
    for d in &q.disjuncts {
        // Asked of every query on every window: no allocation unless a
        // variable is unsafe.
        let mut bound: smallvec::SmallVec<[bool; 16]> = smallvec::smallvec![false; q.vars.len()];
        bind_positives(d, &mut bound);
        let is_bound = |v: usize| bound.get(v).copied().unwrap_or(false);
        let mut reported = BTreeSet::new();
        conj_safety(q, d, &bound, &mut reported, &mut out);
        // An answer variable missing from an alternative would be answered
        // as an unbound kanren variable by `ask` and dropped by `bindings`.
        let span = d
            .iter()
            .map(Literal::span)
            .reduce(|a, b| Span::new(a.start.min(b.start), a.end.max(b.end)));
        for &v in &q.answer_vars {
            if !is_bound(v)
                && reported.insert(v)
                && let Some(span) = span
            {
                let name = q.vars.get(v).cloned().unwrap_or_default();
                out.push(unsafe_query(
                    q,
                    span,
                    format!("answer variable `{name}` is bound by no positive atom of this alternative"),
                    format!("`{name}` has no value here"),
                    format!("bind `{name}` in every alternative, or write `∃{name}` to leave it out of the answers"),
                ));
            }
        }
    }
    out
}
