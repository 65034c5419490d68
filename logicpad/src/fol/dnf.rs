//! Name resolution ([`Resolver`]) and the conversion of a body formula to
//! disjunctive normal form: conjunctions of [`Literal`]s.

use super::lex::SyntaxError;
use super::literal::{Arg, Atom, Literal};
use super::parse::{AtomAst, Formula, Quant, TermAst};
use crate::diag::Span;

/// How names are resolved: which bare lower-case names are constants.
///
/// `scope` holds the names a `¬∃` binds while its body is resolved, each
/// with its own slot (searched last first, so an inner `∃` hides an
/// outer name); `not_exists` says whether a `¬∃` is allowed at all
/// (queries) or refused (rule bodies).
pub(crate) struct Resolver<'a> {
    pub bound: Vec<String>,
    pub is_constant: &'a dyn Fn(&str) -> bool,
    pub vars: Vec<String>,
    pub var_spans: Vec<Span>,
    pub scope: Vec<(String, usize)>,
    pub locals: Vec<usize>,
    pub not_exists: bool,
}

impl<'a> Resolver<'a> {
    /// A resolver with no variables yet. `bound`: the names quantifiers
    /// bind; `not_exists`: whether `¬∃` is allowed (queries).
    pub(crate) fn new(
        bound: Vec<String>,
        is_constant: &'a dyn Fn(&str) -> bool,
        not_exists: bool,
    ) -> Resolver<'a> {
        Resolver {
            bound,
            is_constant,
            vars: Vec::new(),
            var_spans: Vec::new(),
            scope: Vec::new(),
            locals: Vec::new(),
            not_exists,
        }
    }

    pub(crate) fn arg(&mut self, t: &TermAst) -> Arg {
        match t {
            TermAst::Quoted(v, _) => Arg::Const(v.clone()),
            TermAst::QVar(n, s) => Arg::Var(self.var(n, *s)),
            TermAst::Name(n, s) => {
                let bound = self.bound.iter().any(|b| b == n);
                let upper = n
                    .chars()
                    .next()
                    .is_some_and(|c| c.is_uppercase() || c.is_ascii_digit());
                if bound || (!upper && !(self.is_constant)(n)) {
                    Arg::Var(self.var(n, *s))
                } else {
                    Arg::Const(n.clone())
                }
            }
        }
    }
    fn var(&mut self, n: &str, s: Span) -> usize {
        if let Some(&(_, i)) = self.scope.iter().rev().find(|(m, _)| m == n) {
            return i;
        }
        // A slot of a `¬∃` that has been left is never reused by name.
        let local = |i: usize| self.locals.contains(&i);
        if let Some(i) = self
            .vars
            .iter()
            .enumerate()
            .position(|(i, v)| v == n && !local(i))
        {
            i
        } else {
            self.vars.push(n.to_string());
            self.var_spans.push(s);
            self.vars.len() - 1
        }
    }
    pub(crate) fn atom(&mut self, a: &AtomAst) -> Atom {
        Atom {
            pred: a.pred.clone(),
            args: a.args.iter().map(|t| self.arg(t)).collect(),
            span: a.span,
            pred_span: a.pred_span,
            arg_spans: a.args.iter().map(TermAst::span).collect(),
        }
    }
}

/// Limit on the number of conjunctions a body may expand to.
pub const MAX_DISJUNCTS: usize = 64;

/// Collects every quantifier-bound name in `f` (LogicPad has no shadowing:
/// one name is one variable per rule).
pub(crate) fn bound_names(f: &Formula, out: &mut Vec<String>) {
    match f {
        Formula::Atom(_) | Formula::Equal { .. } => {}
        Formula::Not(g, _) => bound_names(g, out),
        Formula::And(fs) | Formula::Or(fs) => fs.iter().for_each(|g| bound_names(g, out)),
        Formula::Implies(a, b, _) => {
            bound_names(a, out);
            bound_names(b, out);
        }
        Formula::Quantified { vars, body, .. } => {
            out.extend(vars.iter().map(|(n, _)| n.clone()));
            bound_names(body, out);
        }
    }
}

/// Converts a body formula into disjunctive normal form: a list of
/// conjunctions of literals. Errors name the unsupported construct.
pub(crate) fn to_dnf(f: &Formula, r: &mut Resolver<'_>) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    dnf(f, false, r)
}

/// An atom, a comparison, or a negated atom: one literal in DNF.
fn is_literal(f: &Formula) -> bool {
    match f {
        Formula::Atom(_) | Formula::Equal { .. } => true,
        Formula::Not(g, _) => matches!(**g, Formula::Atom(_) | Formula::Equal { .. }),
        _ => false,
    }
}

fn unsupported(span: Span, message: &str, label: &str) -> SyntaxError {
    SyntaxError {
        span,
        message: message.into(),
        label: label.into(),
    }
}

fn dnf(f: &Formula, neg: bool, r: &mut Resolver<'_>) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    match f {
        Formula::Atom(a) => {
            let atom = r.atom(a);
            Ok(vec![vec![if neg {
                Literal::Neg(atom)
            } else {
                Literal::Pos(atom)
            }]])
        }
        Formula::Equal {
            left,
            right,
            negated,
            span,
        } => {
            let (l, rr) = (r.arg(left), r.arg(right));
            Ok(vec![vec![Literal::Cmp {
                left: l,
                right: rr,
                negated: *negated != neg,
                span: *span,
            }]])
        }
        Formula::Not(g, _) => dnf(g, !neg, r),
        Formula::And(fs) | Formula::Or(fs) => {
            let conj = matches!(f, Formula::And(_)) != neg;
            // Fast path for the common query shape, a conjunction of literals.
            if conj && fs.iter().all(is_literal) {
                let mut lits = Vec::with_capacity(fs.len());
                for g in fs {
                    lits.extend(dnf(g, neg, r)?.into_iter().flatten());
                }
                return Ok(vec![lits]);
            }
            let parts = fs
                .iter()
                .map(|g| dnf(g, neg, r))
                .collect::<Result<Vec<_>, _>>()?;
            if conj {
                let mut acc: Vec<Vec<Literal>> = vec![Vec::new()];
                for p in parts {
                    // One alternative: append it to every alternative so far,
                    // in place (moved when there is one). Building a fresh
                    // product here copied every alternative once per part,
                    // quadratic in the parts: the fuzzer's
                    // `∀x: V(x) → (A ∧ B) ∨ C1 ∨ … ∨ C3800` took minutes.
                    if p.len() == 1 {
                        if let Some(b) = p.into_iter().next() {
                            match acc.as_mut_slice() {
                                [a] => a.extend(b),
                                all => all.iter_mut().for_each(|a| a.extend(b.iter().cloned())),
                            }
                        }
                        continue;
                    }
                    let mut next = Vec::new();
                    for a in &acc {
                        for b in &p {
                            let mut c = a.clone();
                            c.extend(b.iter().cloned());
                            next.push(c);
                        }
                    }
                    if next.len() > MAX_DISJUNCTS {
                        return Err(unsupported(
                            f.span(),
                            "formula expands to too many alternatives",
                            "split this rule into several rules",
                        ));
                    }
                    acc = next;
                }
                Ok(acc)
            } else {
                let out: Vec<_> = parts.into_iter().flatten().collect();
                if out.len() > MAX_DISJUNCTS {
                    return Err(unsupported(
                        f.span(),
                        "formula expands to too many alternatives",
                        "split this rule",
                    ));
                }
                Ok(out)
            }
        }
        Formula::Implies(_, _, span) => Err(unsupported(
            *span,
            "`==>` inside a rule body or query is not supported",
            "only one `==>`, at the top, is allowed",
        )),
        Formula::Quantified {
            quant,
            vars,
            body,
            span,
        } => match (quant, neg) {
            (Quant::Exists, false) => dnf(body, neg, r),
            (Quant::Exists, true) if r.not_exists => not_exists(vars, body, *span, r),
            (Quant::Exists, true) => Err(unsupported(
                *span,
                "a negated `∃` inside a rule body cannot be evaluated",
                "define a helper predicate for this part and negate that",
            )),
            _ => Err(unsupported(
                *span,
                "a universal quantifier inside a body cannot be evaluated",
                "define a helper predicate for this part and negate that",
            )),
        },
    }
}

/// `¬∃vars: body` as literals of one conjunction: the body in DNF with the
/// names `vars` bound to slots of their own while it is resolved, one
/// [`Literal::NotExists`] per alternative (`¬∃y: (A ∨ B)` is `¬∃y: A ∧
/// ¬∃y: B`).
fn not_exists(
    vars: &[(String, Span)],
    body: &Formula,
    span: Span,
    r: &mut Resolver<'_>,
) -> Result<Vec<Vec<Literal>>, SyntaxError> {
    let mark = r.scope.len();
    let mut slots = Vec::with_capacity(vars.len());
    for (name, at) in vars {
        let slot = r.vars.len();
        r.vars.push(name.clone());
        r.var_spans.push(*at);
        r.locals.push(slot);
        r.scope.push((name.clone(), slot));
        slots.push(slot);
    }
    let alts = dnf(body, false, r);
    r.scope.truncate(mark);
    let lits = alts?
        .into_iter()
        .map(|alt| Literal::NotExists {
            vars: slots.clone(),
            body: alt,
            span,
        })
        .collect();
    Ok(vec![lits])
}
