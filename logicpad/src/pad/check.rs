//! The end of a load: drafts become rules; derived predicates are declared
//! from rule heads, entry metadata attached, and each rule checked (head
//! names, schema and arity, safety, duplicates, `NotP` predicates) before
//! the [`Program`] is built.

use super::Loader;
use super::rules::Draft;
use crate::diag::{DiagKind, Diagnostic, Severity, Span};
use crate::fol::{Arg, Atom, Literal};
use crate::program::{Program, RuleSource, SourceRule};
use crate::schema::{PredInfo, PredKind, Schema};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

impl Loader {
    pub(super) fn finish(mut self) -> (Arc<Schema>, Program, Vec<Diagnostic>) {
        let parsed = std::mem::take(&mut self.rules);
        let drafts: Vec<Draft> = parsed.into_iter().filter_map(|p| self.draft(p)).collect();
        let declared: BTreeSet<String> = self.schema.predicates().map(|p| p.name.clone()).collect();
        let entry_names: BTreeSet<String> = drafts.iter().map(|d| d.entry.clone()).collect();
        // Rule heads define derived predicates (first head fixes the arity).
        for d in &drafts {
            for (h, neg) in &d.heads {
                if !*neg && self.schema.get(&h.pred).is_none() {
                    self.schema.insert(PredInfo {
                        name: h.pred.clone(),
                        arity: h.args.len(),
                        kind: PredKind::Derived,
                        group: Some(d.entry.clone()),
                        params: Vec::new(),
                        values: None,
                        phrases: Vec::new(),
                        value_phrases: BTreeMap::new(),
                        role: None,
                        frames: None,
                        sentence: None,
                        description: None,
                        span: Some(h.pred_span),
                    });
                }
            }
        }
        for meta in std::mem::take(&mut self.entry_meta) {
            let Some((kind, arity)) = self.schema.get(&meta.name).map(|p| (p.kind, p.arity)) else {
                continue;
            };
            let worded = !meta.phrases.is_empty();
            let sentence = self.fit_sentence(&meta.role, &meta.name, arity);
            let (role, frames) = self.fit_role(meta.role, &meta.name, (kind, arity), worded);
            if let Some(p) = self.schema.get_mut(&meta.name) {
                p.phrases.extend(meta.phrases);
                if p.description.is_none() {
                    p.description = meta.description;
                }
                // A declaration's own role comes first; the entry that
                // derives the predicate only fills in what it left open.
                p.role = p.role.or(role);
                p.frames = p.frames.or(frames);
                if p.sentence.is_none() {
                    p.sentence = sentence;
                }
            }
        }
        // Head names that match neither their entry nor a declaration: likely typos.
        for d in &drafts {
            for (h, neg) in &d.heads {
                if *neg
                    || h.pred == d.entry
                    || declared.contains(&h.pred)
                    || entry_names.contains(&h.pred)
                {
                    continue;
                }
                let close = crate::diag::did_you_mean(&h.pred, declared.iter().map(String::as_str));
                let mut diag = Diagnostic::new(
                    DiagKind::HeadMismatch,
                    Severity::Warning,
                    &self.source,
                    h.pred_span,
                    format!(
                        "rule head `{}` is neither its entry's name `{}` nor a declared predicate",
                        h.pred, d.entry
                    ),
                )
                .with_label("defines a new predicate");
                diag = match close {
                    Some(c) => diag.with_help(format!(
                        "`{}` and the declared `{c}` are different predicates; did you mean `{c}`?",
                        h.pred
                    )),
                    None => diag.with_help(format!(
                        "rename the head to `{}` or add an entry for `{}`",
                        d.entry, h.pred
                    )),
                };
                self.diags.push(diag);
            }
        }
        // Per-rule checks: schema, safety; each (head, disjunct) becomes one rule.
        let mut rules: Vec<SourceRule> = Vec::new();
        let mut seen: BTreeMap<String, Span> = BTreeMap::new();
        let schema_snapshot = self.schema.clone();
        for d in &drafts {
            let line = self.source.line_col(d.base.unwrap_or(d.node_span.start)).0;
            for (head, negated_head) in &d.heads {
                if *negated_head {
                    let diag = Diagnostic::new(
                        DiagKind::NegatedHead,
                        Severity::Warning,
                        &self.source,
                        head.span,
                        format!("`¬{}` in a rule head is not a Horn rule", head.pred),
                    )
                    .with_label("negated head")
                    .with_help(format!(
                        "kept as an integrity constraint: after reasoning, every `{}` fact that satisfies the body is reported as a violation; nothing is derived",
                        head.pred
                    ));
                    self.diags.push(diag);
                }
                for body in &d.bodies {
                    let mut ok = true;
                    let mut local = Vec::new();
                    ok &= schema_snapshot.check_atom(head, &self.source, &mut local);
                    for l in body {
                        if let Literal::Pos(a) | Literal::Neg(a) = l {
                            ok &= schema_snapshot.check_atom(a, &self.source, &mut local);
                        }
                    }
                    self.diags.append(&mut local);
                    if !ok || !self.check_safety(d, head, *negated_head, body) {
                        continue;
                    }
                    let key = canonical(head, *negated_head, body, &d.vars);
                    if let Some(first) = seen.get(&key) {
                        let diag = Diagnostic::new(
                            DiagKind::DuplicateRule,
                            Severity::Warning,
                            &self.source,
                            d.base
                                .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                            format!("duplicate rule for `{}`; the copy is ignored", head.pred),
                        )
                        .with_label("same rule again")
                        .with_related(*first, "first written here");
                        self.diags.push(diag);
                        continue;
                    }
                    seen.insert(
                        key,
                        d.base
                            .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                    );
                    rules.push(SourceRule {
                        source: RuleSource {
                            entry: d.entry.clone(),
                            text: d.text.as_str().into(),
                            line,
                            span: d
                                .base
                                .map_or(d.node_span, |b| Span::new(b, b + d.text.len())),
                        },
                        head: head.clone(),
                        body: body.clone(),
                        vars: d.vars.clone(),
                        constraint: *negated_head,
                    });
                }
            }
        }
        self.negation_cycles(&mut rules);
        self.dead_rules(&rules);
        // Base predicates named `NotP` encode negation as facts (the reference's quirk).
        let names: Vec<(String, Option<Span>)> = self
            .schema
            .predicates()
            .filter(|p| p.kind == PredKind::Atomic)
            .map(|p| (p.name.clone(), p.span))
            .collect();
        for (n, span) in names {
            if let Some(rest) = n.strip_prefix("Not")
                && rest.chars().next().is_some_and(char::is_uppercase)
                && self.schema.get(rest).is_some()
            {
                let diag = Diagnostic::new(
                        DiagKind::NegationAsPredicate,
                        Severity::Warning,
                        &self.source,
                        span.unwrap_or_default(),
                        format!("`{n}` encodes negation as a base predicate"),
                    )
                    .with_label(format!("a separate fact, unrelated to `{rest}` for the reasoner"))
                    .with_help(format!(
                        "the world is closed: write `¬{rest}(..)` in rules and queries; `{n}` facts can contradict `{rest}` facts"
                    ));
                self.diags.push(diag);
            }
        }
        let schema = Arc::new(self.schema);
        let program = Program::build(Arc::clone(&schema), rules);
        (schema, program, self.diags)
    }
}

/// A text key equal for rules that differ only in body order.
fn canonical(head: &Atom, negated: bool, body: &[Literal], vars: &[String]) -> String {
    let arg = |a: &Arg| match a {
        Arg::Var(v) => format!("?{}", vars.get(*v).map_or("", String::as_str)),
        Arg::Const(c) => c.clone(),
    };
    let atom = |a: &Atom| {
        format!(
            "{}({})",
            a.pred,
            a.args.iter().map(arg).collect::<Vec<_>>().join(",")
        )
    };
    let mut lits: Vec<String> = body
        .iter()
        .map(|l| match l {
            Literal::Pos(a) => atom(a),
            Literal::Neg(a) => format!("¬{}", atom(a)),
            // Never in a rule (refused when it is resolved); its text
            // keeps two such rules apart all the same.
            Literal::NotExists { span, .. } => format!("¬∃@{}", span.start),
            Literal::Cmp {
                left,
                right,
                negated,
                ..
            } => {
                format!(
                    "{}{}{}",
                    arg(left),
                    if *negated { "≠" } else { "=" },
                    arg(right)
                )
            }
        })
        .collect();
    lits.sort();
    lits.dedup();
    format!(
        "{}{} :- {}",
        if negated { "¬" } else { "" },
        atom(head),
        lits.join(", ")
    )
}
