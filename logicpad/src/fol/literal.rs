//! Resolved formulas: variables numbered, constants named ([`Arg`],
//! [`Atom`]), and the body [`Literal`]s rules and queries are made of.

use crate::diag::Span;
use std::fmt;

/// A resolved term: a variable (index into the owner's variable list) or a constant.
#[derive(Debug, Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Arg {
    /// Variable number `i` (see the owner's `vars`).
    Var(usize),
    /// A constant.
    Const(String),
}

/// A resolved atom.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Atom {
    /// Predicate name.
    pub pred: String,
    /// Arguments.
    pub args: Vec<Arg>,
    /// Span of the whole atom.
    pub span: Span,
    /// Span of the predicate name.
    pub pred_span: Span,
    /// Span of each argument.
    pub arg_spans: Vec<Span>,
}

/// A body literal.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum Literal {
    /// `P(..)`
    Pos(Atom),
    /// `¬P(..)`
    Neg(Atom),
    /// `a = b` / `a ≠ b` (`negated`).
    Cmp {
        /// The left argument.
        left: Arg,
        /// The right argument.
        right: Arg,
        /// True for `≠`.
        negated: bool,
        /// Where it is written.
        span: Span,
    },
    /// `¬∃vars: (body)`: no binding of the local variables `vars` makes
    /// the conjunction `body` hold (queries only; a rule body refuses it).
    ///
    /// Invariant: the local variables are slots of their own (a name
    /// bound by this `∃` never shares a slot with the same name outside
    /// it), so they occur only in `body`; every other variable of `body`
    /// is bound outside, by a positive atom of the enclosing conjunction
    /// (the query's safety check).
    NotExists {
        /// The local variables (`∃`'s), as slots of the owner's `vars`.
        vars: Vec<usize>,
        /// The conjunction that must have no match: atoms, negated atoms,
        /// comparisons and nested `¬∃`.
        body: Vec<Literal>,
        /// Where it is written (from `¬` or `∃` to the end of the body).
        span: Span,
    },
}

impl Literal {
    /// The atom of a positive literal.
    pub fn positive(&self) -> Option<&Atom> {
        match self {
            Literal::Pos(a) => Some(a),
            _ => None,
        }
    }

    /// Where the literal was written.
    pub fn span(&self) -> Span {
        match self {
            Literal::Pos(a) | Literal::Neg(a) => a.span,
            Literal::Cmp { span, .. } | Literal::NotExists { span, .. } => *span,
        }
    }

    /// Every atom of the literal with whether it is negated, including
    /// the atoms inside a `¬∃` body (read as negated: the literal holds
    /// when they are absent), depth first in written order. For scans
    /// that must see each predicate a query uses (checks, observability).
    pub fn atoms(&self) -> Vec<(&Atom, bool)> {
        let mut out = Vec::new();
        let mut todo = vec![(self, false)];
        while let Some((l, under)) = todo.pop() {
            match l {
                Literal::Pos(a) => out.push((a, under)),
                Literal::Neg(a) => out.push((a, true)),
                Literal::Cmp { .. } => {}
                Literal::NotExists { body, .. } => {
                    todo.extend(body.iter().rev().map(|b| (b, true)));
                }
            }
        }
        out
    }

    /// The variables the literal reads from outside: its arguments, and
    /// for a `¬∃` the variables of its body that are not its own (nor a
    /// nested `¬∃`'s), in written order, possibly repeated.
    pub fn free_vars(&self) -> Vec<usize> {
        fn walk(l: &Literal, local: &mut Vec<usize>, out: &mut Vec<usize>) {
            let mut arg = |a: &Arg, local: &Vec<usize>| {
                if let Arg::Var(v) = a
                    && !local.contains(v)
                {
                    out.push(*v);
                }
            };
            match l {
                Literal::Pos(a) | Literal::Neg(a) => a.args.iter().for_each(|x| arg(x, local)),
                Literal::Cmp { left, right, .. } => {
                    arg(left, local);
                    arg(right, local);
                }
                Literal::NotExists { vars, body, .. } => {
                    let mark = local.len();
                    local.extend(vars.iter().copied());
                    for b in body {
                        walk(b, local, out);
                    }
                    local.truncate(mark);
                }
            }
        }
        let mut out = Vec::new();
        walk(self, &mut Vec::new(), &mut out);
        out
    }

    /// True for a `¬∃` literal.
    pub fn is_not_exists(&self) -> bool {
        matches!(self, Literal::NotExists { .. })
    }
}

/// The variables a literal binds for itself: a `¬∃`'s own variables and
/// those of the `¬∃`s nested in its body (none for other literals).
pub fn local_vars(l: &Literal) -> Vec<usize> {
    let mut out = Vec::new();
    let mut todo = vec![l];
    while let Some(l) = todo.pop() {
        if let Literal::NotExists { vars, body, .. } = l {
            out.extend(vars.iter().copied());
            todo.extend(body.iter());
        }
    }
    out
}

/// A literal written out in the query syntax, each variable as `name`
/// says (its name, or the value an answer gives it): `On(ped_1, y)`,
/// `¬Moving(x)`, `x ≠ y`, `¬∃y: (Road(y) ∧ On(ped_1, y))`.
pub fn literal_text(l: &Literal, name: &dyn Fn(usize) -> String) -> String {
    let arg = |a: &Arg| match a {
        Arg::Var(v) => name(*v),
        Arg::Const(c) => c.clone(),
    };
    let atom = |a: &Atom| {
        let args: Vec<String> = a.args.iter().map(arg).collect();
        format!("{}({})", a.pred, args.join(", "))
    };
    match l {
        Literal::Pos(a) => atom(a),
        Literal::Neg(a) => format!("¬{}", atom(a)),
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => format!(
            "{} {} {}",
            arg(left),
            if *negated { "≠" } else { "=" },
            arg(right)
        ),
        Literal::NotExists { vars, body, .. } => {
            let names: Vec<String> = vars.iter().map(|v| name(*v)).collect();
            let parts: Vec<String> = body.iter().map(|b| literal_text(b, name)).collect();
            format!("¬∃{}: ({})", names.join(", "), parts.join(" ∧ "))
        }
    }
}

impl fmt::Display for Arg {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Arg::Var(i) => write!(f, "_{i}"),
            Arg::Const(c) => write!(f, "{c}"),
        }
    }
}
