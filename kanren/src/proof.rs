//! Derivation records (opt-in with [`crate::RunConfig::proofs`]).

use crate::facts::FactId;
use crate::term::Sym;
use std::sync::Arc;

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
#[derive(Debug)]
pub(crate) struct ProofNode {
    pub step: ProofStep,
    pub prev: Option<Arc<ProofNode>>,
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
