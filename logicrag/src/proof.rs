//! Proofs as structure: each answer's derivation is a tree of
//! [`ProofNode`]s — an observed fact with its provenance, a rule step with
//! its premises, an atom absent under the closed world, or a proof cut by
//! its limits. Rendering happens at the edges, from the structure: the
//! terminal ([`lines`]), JSON (serde), the C2 sentences of the RAG context.

use crate::kb::WindowKb;
use logicpad::{DerivationTree, QueryAnswer};
use perception::Provenance;
use serde::Serialize;

/// One fact of a proof and how it holds.
///
/// Invariant: `premises` is empty unless `step` is [`Step::Rule`]; for a
/// rule step it holds the proofs of the rule's positive body atoms in body
/// order, then one [`Step::Absent`] node per negated body atom.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct ProofNode {
    /// The fact, e.g. `Moving(car_1)`; for an absent atom `¬Moving(car_1)`.
    pub fact: String,
    /// How it holds.
    pub step: Step,
    /// The premises of a rule step.
    #[serde(skip_serializing_if = "Vec::is_empty")]
    pub premises: Vec<ProofNode>,
}

/// How a fact of a proof holds.
#[derive(Debug, Clone, PartialEq, Serialize)]
#[serde(tag = "kind", rename_all = "snake_case")]
pub enum Step {
    /// A base fact, with where perception observed it (`None` for a fact
    /// given without provenance).
    Observed {
        /// Window, frames, measured value and threshold.
        provenance: Option<std::sync::Arc<Provenance>>,
    },
    /// Derived by a LogicPad rule.
    Rule {
        /// The rule's line in the LogicPad file.
        line: usize,
        /// The rule as written.
        text: String,
    },
    /// An atom that holds negated: no such fact (closed world).
    Absent,
    /// A fact that holds, whose proof the proof limits left out.
    Cut {
        /// The limit that cut it ("depth limit 64").
        reason: String,
    },
}

/// The proof of one answer: one tree per literal of the query.
pub fn of_answer(kb: &WindowKb, answer: &QueryAnswer) -> Vec<ProofNode> {
    answer.proof.iter().map(|t| node(kb, t)).collect()
}

/// One derivation tree as proof nodes. Recursion is bounded by the proof
/// limits logicpad applies (depth 64 by default).
pub fn node(kb: &WindowKb, tree: &DerivationTree) -> ProofNode {
    match tree {
        DerivationTree::Base(a) => ProofNode {
            fact: a.to_string(),
            step: Step::Observed {
                provenance: kb.shared_provenance(&a.pred, &a.args).cloned(),
            },
            premises: Vec::new(),
        },
        DerivationTree::Absent(a) => absent(a),
        DerivationTree::Truncated { fact, reason } => ProofNode {
            fact: fact.to_string(),
            step: Step::Cut {
                reason: reason.to_string(),
            },
            premises: Vec::new(),
        },
        DerivationTree::Derived {
            fact,
            rule_text,
            rule_line,
            premises,
            absent: missing,
            ..
        } => ProofNode {
            fact: fact.to_string(),
            step: Step::Rule {
                line: *rule_line,
                text: rule_text.clone(),
            },
            premises: premises
                .iter()
                .map(|p| node(kb, p))
                .chain(missing.iter().map(absent))
                .collect(),
        },
    }
}

fn absent(a: &logicpad::GroundAtom) -> ProofNode {
    ProofNode {
        fact: format!("¬{a}"),
        step: Step::Absent,
        premises: Vec::new(),
    }
}

/// One line saying where a fact came from.
pub fn describe_provenance(p: &Provenance) -> String {
    let mut s = format!(
        "{} window {}, frames {}–{}",
        p.source, p.window, p.frames.0, p.frames.1
    );
    if !p.note.is_empty() {
        s.push_str(": ");
        s.push_str(&p.note);
    }
    s
}

/// A proof as indented terminal lines, each fact with how it holds:
/// `Moving(car_1)  [fact: sim:… window 2, frames 20–29: …]`.
pub fn lines(nodes: &[ProofNode]) -> Vec<String> {
    let mut out = Vec::new();
    let mut stack: Vec<(usize, &ProofNode)> = nodes.iter().rev().map(|n| (0, n)).collect();
    while let Some((depth, n)) = stack.pop() {
        let pad = "  ".repeat(depth);
        let how = match &n.step {
            Step::Observed {
                provenance: Some(p),
            } => format!("[fact: {}]", describe_provenance(p)),
            Step::Observed { provenance: None } => "[fact]".to_string(),
            Step::Rule { line, text } => format!("[rule, line {line}: {text}]"),
            Step::Absent => "[no such fact: closed world]".to_string(),
            Step::Cut { reason } => format!("[proof cut: {reason}]"),
        };
        out.push(format!("{pad}{}  {how}", n.fact));
        stack.extend(n.premises.iter().rev().map(|p| (depth + 1, p)));
    }
    out
}
