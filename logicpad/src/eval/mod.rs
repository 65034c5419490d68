//! Bottom-up, semi-naive, stratified evaluation over `kanren::Relation`s.
//!
//! Why bottom-up: the least fixpoint does not depend on rule or atom order,
//! a window holds about a thousand facts so materialising every derived fact
//! is cheap, and each derived fact gets exactly one recorded justification
//! (its first derivation), from which [`Model::explain`] builds a proof tree.
//!
//! Semi-naive bookkeeping uses fact ids: a relation hands out ids in
//! insertion order, so "the facts new in the last round" of a relation are
//! the id range `lo..hi`, "the old facts" are `0..lo`, and no delta relation
//! is ever copied.
//!
//! The module's parts: [`facts`] (the fact base read before reasoning),
//! [`fixpoint`]'s rules run as kanren joins (`kanren::join`: the one
//! planner and join, which queries use through kanren goals too),
//! [`fixpoint`] (semi-naive strata and integrity constraints) and
//! [`proof`] (derivation trees from the recorded premises).

mod facts;
mod fixpoint;
mod proof;

pub use facts::{FactBase, FactError};
pub(crate) use kanren::join::arg_value;
pub use proof::{CutReason, DerivationTree, GroundAtom, ProofLimits};

use crate::program::{CArg, Program, Rule, RuleId};
use kanren::{FactId, Relation, Sym, Term};
use rustc_hash::FxHashMap as HashMap;
use std::fmt;
use std::sync::Arc;

/// An integrity constraint (`body ==> ¬P(..)`) that the model breaks.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Violation {
    /// Index in [`Program::constraints`].
    pub constraint: RuleId,
    /// The constraint as written.
    pub rule_text: String,
    /// Its line.
    pub rule_line: usize,
    /// The atom that holds although the constraint forbids it.
    pub atom: GroundAtom,
    /// Variable bindings, sorted by name.
    pub bindings: Vec<(String, String)>,
    /// The facts matching the constraint's positive body (the forbidden atom
    /// last); each can be explained with [`Model::explain`].
    pub facts: Vec<GroundAtom>,
}

impl fmt::Display for Violation {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "{} holds, but line {} forbids it: {}",
            self.atom, self.rule_line, self.rule_text
        )
    }
}

/// First derivation of a derived fact: its rule and where its premises lie
/// in [`Model`]'s premise arena.
#[derive(Debug, Clone, Copy)]
struct Just {
    rule: u32,
    start: u32,
    len: u32,
}

/// Figures of one evaluation.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub struct EvalStats {
    /// Base facts.
    pub base_facts: usize,
    /// Facts added by rules.
    pub derived_facts: usize,
    /// Semi-naive rounds over all recursive components.
    pub rounds: usize,
    /// Components taken unchanged from the previous window's model
    /// ([`Program::evaluate_after`](crate::Program::evaluate_after)).
    pub reused_components: usize,
}

/// The result of reasoning over one fact base: base plus derived relations.
///
/// Invariants: relation `p` holds its base facts at ids `0..base_len[p]` and
/// derived facts after them; `just[p][i]` justifies fact `base_len[p] + i`.
#[derive(Debug, Clone)]
pub struct Model {
    pub(crate) program: Program,
    pub(crate) rels: Arc<[Arc<Relation>]>,
    pub(crate) names: HashMap<String, usize>,
    base_len: Vec<u32>,
    just: Vec<Vec<Just>>,
    premises: Vec<FactId>,
    violations: Vec<Violation>,
    stats: EvalStats,
}

/// The text of a constant term.
/// A term's text, borrowed from the interner for a symbol.
pub(crate) fn term_name(t: &Term) -> std::borrow::Cow<'static, str> {
    match t {
        Term::Sym(s) => std::borrow::Cow::Borrowed(s.as_str()),
        other => std::borrow::Cow::Owned(term_text(other)),
    }
}

pub(crate) fn term_text(t: &Term) -> String {
    match t {
        Term::Sym(s) => s.as_str().to_string(),
        Term::Str(s) => s.to_string(),
        other => other.to_string(),
    }
}

/// The term of a constant written in a query or a lookup: its symbol when
/// some fact or rule interned it, else a string term, which equals no
/// stored symbol (so it matches nothing, as an unknown constant should)
/// and is freed with the query instead of growing the global interner.
pub fn const_term(c: &str) -> Term {
    Sym::lookup(c).map_or_else(|| Term::str(c), Term::Sym)
}

/// Rebuilds a rule's substitution from the ids of its positive premises.
pub(crate) fn bind_from<'r>(
    rule: &Rule,
    rel: impl Fn(usize) -> Option<&'r Relation>,
    prem: &[FactId],
) -> Vec<Option<Term>> {
    let mut binds = vec![None; rule.vars.len()];
    for (atom, &id) in rule.body.iter().zip(prem) {
        let Some(tuple) = rel(atom.pred).and_then(|r| r.tuple(id)) else {
            continue;
        };
        for (a, t) in atom.args.iter().zip(tuple) {
            if let CArg::Var(v) = a
                && let Some(slot) = binds.get_mut(*v)
            {
                *slot = Some(t.clone());
            }
        }
    }
    binds
}

impl Model {
    /// The relation of a predicate (base and derived facts), if it exists.
    pub fn relation(&self, name: &str) -> Option<&Arc<Relation>> {
        self.index_of(name).and_then(|i| self.rels.get(i))
    }

    pub(crate) fn index_of(&self, name: &str) -> Option<usize> {
        self.program
            .pred_id(name)
            .or_else(|| self.names.get(name).copied())
    }

    /// Relation `index`'s name, borrowed from the interner.
    pub(crate) fn name_of(&self, index: usize) -> std::borrow::Cow<'static, str> {
        self.rels
            .get(index)
            .map_or(std::borrow::Cow::Borrowed(""), |r| {
                std::borrow::Cow::Borrowed(r.name().as_str())
            })
    }

    /// The program that produced this model.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// True when the fact holds (given or derived).
    pub fn holds(&self, pred: &str, args: &[&str]) -> bool {
        let terms: Vec<Term> = args.iter().map(|a| const_term(a)).collect();
        self.relation(pred).is_some_and(|r| r.contains(&terms))
    }

    /// Every fact of a predicate, as text tuples, sorted.
    pub fn facts(&self, pred: &str) -> Vec<Vec<String>> {
        let mut out: Vec<Vec<String>> = self
            .relation(pred)
            .map(|r| {
                r.iter()
                    .map(|(_, t)| t.iter().map(term_text).collect())
                    .collect()
            })
            .unwrap_or_default();
        out.sort();
        out
    }

    /// Derived (not given) facts of a predicate, sorted.
    pub fn derived_facts(&self, pred: &str) -> Vec<Vec<String>> {
        let Some(i) = self.index_of(pred) else {
            return Vec::new();
        };
        let base = self.base_len.get(i).copied().unwrap_or(0);
        let mut out: Vec<Vec<String>> = self
            .rels
            .get(i)
            .map(|r| {
                r.iter()
                    .filter(|(id, _)| *id >= base)
                    .map(|(_, t)| t.iter().map(term_text).collect())
                    .collect()
            })
            .unwrap_or_default();
        out.sort();
        out
    }

    /// Integrity constraints that the facts break, sorted.
    pub fn violations(&self) -> &[Violation] {
        &self.violations
    }

    /// Evaluation figures.
    pub fn stats(&self) -> EvalStats {
        self.stats
    }

    /// Total number of facts (base and derived).
    pub fn len(&self) -> usize {
        self.rels.iter().map(|r| r.len()).sum()
    }

    /// True when the model holds no fact.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn atom(pred: &str, args: &[&str]) -> GroundAtom {
        GroundAtom {
            pred: pred.to_string().into(),
            args: args.iter().map(|a| a.to_string().into()).collect(),
        }
    }

    /// A cut proof says which fact holds and which limit cut it, indented
    /// like any other premise, and counts as one node.
    #[test]
    fn a_truncated_node_prints_the_fact_and_the_limit() {
        let cut = DerivationTree::Truncated {
            fact: atom("Reach", &["a", "y"]),
            reason: CutReason::DepthLimit(64),
        };
        assert_eq!(
            cut.to_string(),
            "Reach(a, y)  [proof cut: depth limit 64]\n"
        );
        assert_eq!(cut.fact(), Some(&atom("Reach", &["a", "y"])));
        assert_eq!(cut.size(), 1);
        assert!(cut.is_truncated());
        let tree = DerivationTree::Derived {
            fact: atom("Reach", &["a", "z"]),
            rule: 1,
            rule_text: "Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)".into(),
            rule_line: 7,
            premises: vec![
                cut,
                DerivationTree::Base {
                    fact: atom("Edge", &["y", "z"]),
                    id: 0,
                },
                DerivationTree::Truncated {
                    fact: atom("Near", &["a", "z"]),
                    reason: CutReason::NodeLimit(10_000),
                },
            ],
            absent: vec![atom("Blocked", &["z"])],
        };
        assert_eq!(
            tree.to_string(),
            "Reach(a, z)  [rule, line 7: Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)]\n\
             \x20 Reach(a, y)  [proof cut: depth limit 64]\n\
             \x20 Edge(y, z)  [fact]\n\
             \x20 Near(a, z)  [proof cut: node limit 10000]\n\
             \x20 ¬Blocked(z)  [absent]\n"
        );
        assert_eq!(tree.size(), 5);
        assert!(tree.is_truncated());
        assert!(
            !DerivationTree::Base {
                fact: atom("Edge", &["y", "z"]),
                id: 0
            }
            .is_truncated()
        );
        assert_eq!(ProofLimits::default().max_depth, 64);
        assert_eq!(ProofLimits::default().max_nodes, 10_000);
    }
}
