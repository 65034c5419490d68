//! From a parsed formula to resolved rules: quantifiers stripped, head and
//! body split, the body put in disjunctive normal form, spans moved to file
//! coordinates (`Draft`); and the safety check of each resulting rule.

use super::Loader;
use super::load::Parsed;
use crate::diag::{DiagKind, Diagnostic, Severity, Span};
use crate::fol::{self, Arg, Atom, Formula, Literal, Resolver};
use std::collections::BTreeSet;

/// A rule after name resolution, before the semantic checks.
pub(super) struct Draft {
    pub(super) entry: String,
    pub(super) text: String,
    pub(super) node_span: Span,
    pub(super) base: Option<usize>,
    pub(super) heads: Vec<(Atom, bool)>,
    pub(super) bodies: Vec<Vec<Literal>>,
    pub(super) vars: Vec<String>,
}

/// Moves every span of a literal from formula coordinates to file coordinates.
fn shift_atom(a: &mut Atom, f: &dyn Fn(Span) -> Span) {
    a.span = f(a.span);
    a.pred_span = f(a.pred_span);
    for s in &mut a.arg_spans {
        *s = f(*s);
    }
}
fn shift_lit(l: &mut Literal, f: &dyn Fn(Span) -> Span) {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => shift_atom(a, f),
        Literal::Cmp { span, .. } => *span = f(*span),
        Literal::NotExists { body, span, .. } => {
            *span = f(*span);
            body.iter_mut().for_each(|l| shift_lit(l, f));
        }
    }
}

impl Loader {
    fn shifter(&self, base: Option<usize>, node_span: Span) -> impl Fn(Span) -> Span + use<> {
        move |s: Span| base.map_or(node_span, |b| s.shifted(b))
    }

    pub(super) fn draft(&mut self, p: Parsed) -> Option<Draft> {
        let shift = self.shifter(p.base, p.node_span);
        let mut bound = Vec::new();
        fol::bound_names(&p.formula, &mut bound);
        let mut f = &p.formula;
        while let Formula::Quantified {
            quant: fol::Quant::Forall,
            body,
            ..
        } = f
        {
            f = body;
        }
        let Formula::Implies(body, head, _) = f else {
            let d = Diagnostic::new(
                DiagKind::FolSyntax,
                Severity::Error,
                &self.source,
                shift(f.span()),
                "a rule needs `==>` between its body and its head",
            )
            .with_label("no `==>` in this rule")
            .with_help("write rules as `∀x : Body(x) ==> Head(x)`");
            self.diags.push(d);
            return None;
        };
        let never = |_: &str| false;
        // A rule body refuses `¬∃` (only queries answer it).
        let mut r = Resolver::new(bound, &never, false);
        // Head: one atom, a negated atom (integrity constraint) or a conjunction of atoms.
        let mut head_f: &Formula = head;
        while let Formula::Quantified {
            quant: fol::Quant::Forall,
            body,
            ..
        } = head_f
        {
            head_f = body;
        }
        let head_parts: Vec<&Formula> = match head_f {
            Formula::And(fs) => fs.iter().collect(),
            other => vec![other],
        };
        let mut heads = Vec::new();
        for h in head_parts {
            match h {
                Formula::Atom(a) => heads.push((r.atom(a), false)),
                Formula::Not(inner, _) if matches!(**inner, Formula::Atom(_)) => {
                    if let Formula::Atom(a) = &**inner {
                        heads.push((r.atom(a), true));
                    }
                }
                other => {
                    let d = Diagnostic::new(
                        DiagKind::Unsupported,
                        Severity::Error,
                        &self.source,
                        shift(other.span()),
                        "a rule head must be an atom, a negated atom, or a conjunction of atoms",
                    )
                    .with_label("unsupported head")
                    .with_help("split a disjunctive head into several rules with the same body");
                    self.diags.push(d);
                    return None;
                }
            }
        }
        let bodies = match fol::to_dnf(body, &mut r) {
            Ok(b) => b,
            Err(e) => {
                let d = Diagnostic::new(
                    DiagKind::Unsupported,
                    Severity::Error,
                    &self.source,
                    shift(e.span),
                    e.message,
                )
                .with_label(e.label);
                self.diags.push(d);
                return None;
            }
        };
        for (a, _) in &mut heads {
            shift_atom(a, &shift);
        }
        let mut bodies = bodies;
        for b in &mut bodies {
            for l in b {
                shift_lit(l, &shift);
            }
        }
        Some(Draft {
            entry: p.entry,
            text: p.text,
            node_span: p.node_span,
            base: p.base,
            heads,
            bodies,
            vars: r.vars,
        })
    }

    /// Safety: every head variable, every variable under `¬` and every
    /// variable of a comparison must occur in a positive body atom.
    pub(super) fn check_safety(
        &mut self,
        d: &Draft,
        head: &Atom,
        negated_head: bool,
        body: &[Literal],
    ) -> bool {
        let mut positives: Vec<&Atom> = body.iter().filter_map(Literal::positive).collect();
        if negated_head {
            positives.push(head);
        }
        let bound: BTreeSet<usize> = positives
            .iter()
            .flat_map(|a| a.args.iter())
            .filter_map(|x| if let Arg::Var(v) = x { Some(*v) } else { None })
            .collect();
        let mut offenders: Vec<(usize, Span, String)> = Vec::new();
        let check =
            |v: usize, span: Span, place: String, offenders: &mut Vec<(usize, Span, String)>| {
                if !bound.contains(&v) && !offenders.iter().any(|(o, _, _)| *o == v) {
                    offenders.push((v, span, place));
                }
            };
        if !negated_head {
            for (i, a) in head.args.iter().enumerate() {
                if let Arg::Var(v) = a {
                    check(
                        *v,
                        head.arg_spans.get(i).copied().unwrap_or(head.span),
                        "the head".into(),
                        &mut offenders,
                    );
                }
            }
        }
        let mut negs = Vec::new();
        for l in body {
            match l {
                Literal::Neg(a) => {
                    negs.push(a);
                    for (i, x) in a.args.iter().enumerate() {
                        if let Arg::Var(v) = x {
                            let sp = a.arg_spans.get(i).copied().unwrap_or(a.span);
                            check(*v, sp, format!("`¬{}`", a.pred), &mut offenders);
                        }
                    }
                }
                Literal::Cmp {
                    left, right, span, ..
                } => {
                    for x in [left, right] {
                        if let Arg::Var(v) = x {
                            check(*v, *span, "a comparison".into(), &mut offenders);
                        }
                    }
                }
                // Never in a rule: the resolver refuses `¬∃` in rule bodies.
                Literal::Pos(_) | Literal::NotExists { .. } => {}
            }
        }
        let Some((v, span, place)) = offenders.first().cloned() else {
            return true;
        };
        let name = d.vars.get(v).cloned().unwrap_or_default();
        let mut diag = Diagnostic::new(
            DiagKind::UnsafeRule,
            Severity::Error,
            &self.source,
            span,
            format!("unsafe rule: variable `{name}` in {place} is bound by no positive atom"),
        )
        .with_label(format!("`{name}` ranges over everything here"));
        for (v2, sp2, place2) in offenders.iter().skip(1) {
            let n2 = d.vars.get(*v2).cloned().unwrap_or_default();
            diag = diag.with_related(*sp2, format!("`{n2}` in {place2} is unbound too"));
        }
        // How the reference's `¬P` → `NotP` rewriting treated this rule.
        let help = match negs.first() {
            Some(a) if positives.is_empty() => {
                let not_name = format!("Not{}", a.pred);
                let how = if self.schema.get(&not_name).is_some() {
                    format!(
                        "the reference rewrote `¬{}` into the base predicate `{not_name}`, which hid this; ",
                        a.pred
                    )
                } else {
                    format!(
                        "under the reference's `¬{0}` → `{not_name}` rewriting this rule is dead: nothing produces `{not_name}`; ",
                        a.pred
                    )
                };
                let written = self
                    .source
                    .text
                    .get(a.span.start..a.span.end)
                    .unwrap_or(&a.pred)
                    .to_string();
                format!(
                    "{how}add a positive atom that binds `{name}`, e.g. `Vehicles({name}) ∧ ¬{written}`"
                )
            }
            _ => format!("add a positive atom that binds `{name}` to the body"),
        };
        diag = diag.with_help(help);
        self.diags.push(diag);
        false
    }
}
