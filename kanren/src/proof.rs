//! Derivation records (opt-in with [`crate::RunConfig::proofs`]).

use crate::term::Sym;
use std::sync::Arc;

/// A fact's index in its relation (insertion order, from 0). Defined here,
/// with the proof steps that name facts, so that proofs need nothing from
/// the fact store (`crate::facts` re-exports it).
pub type FactId = u32;

/// One step of a derivation.
#[derive(Clone, Debug, PartialEq, Eq, Hash)]
pub enum ProofStep {
    /// The fact with id `id` of relation `relation` was used.
    Fact {
        /// The relation's name.
        relation: Sym,
        /// The fact's id in its relation.
        id: FactId,
    },
    /// The rule (or relation) named here was entered (see [`crate::label`]).
    Rule(Sym),
}

/// The steps that produced an answer, in the order the search took them along
/// the answer's path (a rule's step comes before the steps of its body).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct Proof {
    /// The steps, in order.
    pub steps: Vec<ProofStep>,
}

/// A persistent (shared-tail) list of steps, newest first, so that branching
/// states share their common prefix instead of copying it.
pub(crate) struct ProofNode {
    pub step: ProofStep,
    pub prev: Option<Arc<ProofNode>>,
}

// Printed as a flat list, newest first: a derived Debug would nest (and
// recurse) once per step.
impl std::fmt::Debug for ProofNode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut steps = f.debug_list();
        steps.entry(&self.step);
        let mut cur = self.prev.as_deref();
        while let Some(node) = cur {
            steps.entry(&node.step);
            cur = node.prev.as_deref();
        }
        steps.finish()
    }
}

// The derived drop would free a list recursively, one stack frame per step,
// so the proof of a derivation a few hundred thousand steps long overflowed
// the stack when its state was dropped. Unlink it iteratively instead; stop
// at the first node another list still shares (its owner frees the rest).
impl Drop for ProofNode {
    fn drop(&mut self) {
        let mut next = self.prev.take();
        while let Some(node) = next {
            next = match Arc::into_inner(node) {
                Some(mut owned) => owned.prev.take(),
                None => None,
            };
        }
    }
}

pub(crate) fn push(prev: &Option<Arc<ProofNode>>, step: ProofStep) -> Option<Arc<ProofNode>> {
    Some(Arc::new(ProofNode {
        step,
        prev: prev.clone(),
    }))
}

pub(crate) fn to_vec(list: &Option<Arc<ProofNode>>) -> Vec<ProofStep> {
    let mut out = Vec::new();
    let mut cur = list.as_ref();
    while let Some(node) = cur {
        out.push(node.step.clone());
        cur = node.prev.as_ref();
    }
    out.reverse();
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(i: u32) -> ProofStep {
        ProofStep::Fact {
            relation: Sym::new("edge"),
            id: i,
        }
    }

    /// Regression: dropping (or Debug-printing) a long list recursed once
    /// per step and overflowed the stack.
    #[test]
    fn a_million_step_list_drops_and_prints_without_recursion() {
        let mut list = None;
        for i in 0..1_000_000 {
            list = push(&list, step(i));
        }
        assert_eq!(to_vec(&list).len(), 1_000_000);
        let node = list
            .as_deref()
            .map(|n| format!("{n:?}"))
            .unwrap_or_default();
        assert!(node.starts_with("[Fact { relation: edge, id: 999999 }, Fact"));
        drop(list);
    }

    /// Dropping one branch must not free the prefix another branch shares.
    #[test]
    fn dropping_a_branch_keeps_the_shared_prefix() {
        let mut prefix = None;
        for i in 0..1000 {
            prefix = push(&prefix, step(i));
        }
        let a = push(&prefix, step(5000));
        let b = push(&prefix, step(6000));
        drop(prefix);
        drop(a);
        let steps = to_vec(&b);
        assert_eq!(steps.len(), 1001);
        assert_eq!(steps.first(), Some(&step(0)));
        assert_eq!(steps.last(), Some(&step(6000)));
    }
}
