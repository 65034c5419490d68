//! Checks over the predicate dependency graph (head → body edges) of the
//! rules that passed the per-rule checks: negation through recursion (no
//! stratification exists) and dead rules (a body nothing can produce).

use super::Loader;
use crate::diag::{DiagKind, Diagnostic, Severity};
use crate::fol::Literal;
use crate::program::SourceRule;
use crate::schema::PredKind;
use std::collections::{BTreeMap, BTreeSet};

impl Loader {
    /// Drops (and reports) every rule that negates a predicate of its own
    /// recursive component: such programs have no stratification.
    pub(super) fn negation_cycles(&mut self, rules: &mut Vec<SourceRule>) {
        let names: Vec<String> = self.schema.predicates().map(|p| p.name.clone()).collect();
        let index: BTreeMap<&str, usize> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.as_str(), i))
            .collect();
        let mut edges: Vec<Vec<(usize, usize)>> = vec![Vec::new(); names.len()]; // head -> (body pred, rule)
        for (ri, r) in rules.iter().enumerate() {
            if r.constraint {
                continue;
            }
            let Some(&h) = index.get(r.head.pred.as_str()) else {
                continue;
            };
            for l in &r.body {
                if let Literal::Pos(a) | Literal::Neg(a) = l
                    && let Some(&b) = index.get(a.pred.as_str())
                {
                    edges[h].push((b, ri));
                }
            }
        }
        let plain: Vec<Vec<usize>> = edges
            .iter()
            .map(|e| e.iter().map(|(b, _)| *b).collect())
            .collect();
        let comp = crate::program::scc_ids(&plain);
        let mut drop = BTreeSet::new();
        for (ri, r) in rules.iter().enumerate() {
            if r.constraint {
                continue;
            }
            let Some(&h) = index.get(r.head.pred.as_str()) else {
                continue;
            };
            for l in &r.body {
                let Literal::Neg(a) = l else { continue };
                let Some(&b) = index.get(a.pred.as_str()) else {
                    continue;
                };
                if comp.get(b) != comp.get(h) {
                    continue;
                }
                // Show the cycle: head ⇒ ¬b ⇒ … ⇒ head (shortest path b ⇝ head).
                let path = shortest_path(&edges, b, h).unwrap_or_default();
                let mut cycle = format!("{} ⇐ ¬{}", names[h], names[b]);
                let mut related = Vec::new();
                let mut cur = b;
                for (next, rule) in &path {
                    cycle.push_str(&format!(" ⇐ {}", names[*next]));
                    if let Some(rr) = rules.get(*rule) {
                        related.push((
                            rr.source.span,
                            format!("`{}` depends on `{}` here", names[cur], names[*next]),
                        ));
                    }
                    cur = *next;
                }
                let mut diag = Diagnostic::new(
                    DiagKind::NegationCycle,
                    Severity::Error,
                    &self.source,
                    a.span,
                    format!("negation through recursion: `{}` depends on its own negation", names[h]),
                )
                .with_label(format!("cycle: {cycle}"))
                .with_help("no stratification exists; break the cycle or replace the negation by a positive predicate");
                for (sp, t) in related {
                    diag = diag.with_related(sp, t);
                }
                self.diags.push(diag);
                drop.insert(ri);
            }
        }
        let mut i = 0;
        rules.retain(|_| {
            let keep = !drop.contains(&i);
            i += 1;
            keep
        });
    }

    /// Warns about rules whose body needs a predicate nothing can produce
    /// (a derived predicate all of whose rules were left out or are dead).
    pub(super) fn dead_rules(&mut self, rules: &[SourceRule]) {
        let mut producible: BTreeSet<String> = self
            .schema
            .predicates()
            .filter(|p| p.kind != PredKind::Derived)
            .map(|p| p.name.clone())
            .collect();
        loop {
            let mut changed = false;
            for r in rules.iter().filter(|r| !r.constraint) {
                if producible.contains(&r.head.pred) {
                    continue;
                }
                let ok = r.body.iter().all(|l| match l {
                    Literal::Pos(a) => producible.contains(&a.pred),
                    _ => true,
                });
                if ok {
                    producible.insert(r.head.pred.clone());
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        for r in rules {
            for l in &r.body {
                let Literal::Pos(a) = l else { continue };
                if producible.contains(&a.pred) {
                    continue;
                }
                let diag = Diagnostic::new(
                    DiagKind::DeadRule,
                    Severity::Warning,
                    &self.source,
                    a.pred_span,
                    format!("dead rule: nothing can produce `{}`, so this rule never fires", a.pred),
                )
                .with_label(format!("no fact source and no working rule for `{}`", a.pred))
                .with_help(format!("fix the rules for `{}` (see the errors above) or declare it as an atomic predicate", a.pred));
                self.diags.push(diag);
                break;
            }
        }
    }
}

/// Breadth-first path from `from` to `to` along head→body edges, as
/// (next predicate, rule index) steps.
fn shortest_path(
    edges: &[Vec<(usize, usize)>],
    from: usize,
    to: usize,
) -> Option<Vec<(usize, usize)>> {
    let mut prev: Vec<Option<(usize, usize)>> = vec![None; edges.len()];
    let mut seen = vec![false; edges.len()];
    let mut queue = std::collections::VecDeque::from([from]);
    *seen.get_mut(from)? = true;
    while let Some(n) = queue.pop_front() {
        if n == to {
            let mut path = Vec::new();
            let mut cur = to;
            while cur != from {
                let (p, rule) = prev[cur]?;
                path.push((cur, rule));
                cur = p;
            }
            path.reverse();
            return Some(path);
        }
        for &(m, rule) in edges.get(n)? {
            if !seen[m] {
                seen[m] = true;
                prev[m] = Some((n, rule));
                queue.push_back(m);
            }
        }
    }
    None
}
