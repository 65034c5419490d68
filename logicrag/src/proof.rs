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
///
/// JSON: `{"fact": …, "step": {"kind": …, …}, "premises": […]}`, the
/// premises left out when there are none.
#[derive(Debug, Clone, PartialEq)]
pub struct ProofNode {
    /// The fact, e.g. `Moving(car_1)`; for an absent atom `¬Moving(car_1)`.
    pub fact: String,
    /// How it holds.
    pub step: Step,
    /// The premises of a rule step.
    pub premises: Vec<ProofNode>,
}

/// How a fact of a proof holds.
///
/// JSON: an object whose `kind` names the variant in snake case
/// (`observed`, `rule`, `absent`, `cut`), followed by its fields.
#[derive(Debug, Clone, PartialEq)]
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
        /// The rule as written (shared with the LogicPad's rule).
        text: std::sync::Arc<str>,
    },
    /// An atom that holds negated: no such fact (closed world); or a
    /// `¬∃` literal that holds because its conjunction has no match
    /// (`¬∃y: (Road(y) ∧ On(ped_1, y))`, never with a doubt).
    Absent {
        /// When perception measured the fact and did not assert it: the
        /// probability that it holds all the same (a doubt,
        /// docs/probability.md). `None` for a fact nothing suggested.
        doubt: Option<f64>,
    },
    /// A fact that holds, whose proof the proof limits left out.
    Cut {
        /// The limit that cut it ("depth limit 64").
        reason: String,
    },
}

// Written by hand rather than derived: a batch with proofs serialises
// millions of nodes, and serde's internally tagged enum goes through a
// buffering flat-map serialiser for every step. The bytes are those the
// derive wrote (a test pins them).
impl Serialize for ProofNode {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let n = if self.premises.is_empty() { 2 } else { 3 };
        let mut m = s.serialize_map(Some(n))?;
        m.serialize_entry("fact", &self.fact)?;
        m.serialize_entry("step", &self.step)?;
        if !self.premises.is_empty() {
            m.serialize_entry("premises", &self.premises)?;
        }
        m.end()
    }
}

impl Serialize for Step {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeMap;
        let mut m;
        match self {
            Step::Observed { provenance } => {
                m = s.serialize_map(Some(2))?;
                m.serialize_entry("kind", "observed")?;
                m.serialize_entry("provenance", provenance)?;
            }
            Step::Rule { line, text } => {
                m = s.serialize_map(Some(3))?;
                m.serialize_entry("kind", "rule")?;
                m.serialize_entry("line", line)?;
                m.serialize_entry("text", &**text)?;
            }
            Step::Absent { doubt } => {
                m = s.serialize_map(Some(1 + usize::from(doubt.is_some())))?;
                m.serialize_entry("kind", "absent")?;
                if let Some(q) = doubt {
                    m.serialize_entry("doubt", &crate::belief::rounded(*q))?;
                }
            }
            Step::Cut { reason } => {
                m = s.serialize_map(Some(2))?;
                m.serialize_entry("kind", "cut")?;
                m.serialize_entry("reason", reason)?;
            }
        }
        m.end()
    }
}

/// The proof of one answer: one tree per literal of the query.
pub(crate) fn of_answer(kb: &WindowKb, answer: &QueryAnswer) -> Vec<ProofNode> {
    answer.proof.iter().map(|t| node(kb, t)).collect()
}

/// One derivation tree as proof nodes. Recursion is bounded by the proof
/// limits logicpad applies (depth 64 by default).
pub fn node(kb: &WindowKb, tree: &DerivationTree) -> ProofNode {
    match tree {
        DerivationTree::Base { fact, id } => ProofNode {
            fact: atom_text(fact),
            step: Step::Observed {
                provenance: kb.provenance_of_id(&fact.pred, *id).cloned(),
            },
            premises: Vec::new(),
        },
        DerivationTree::Absent(a) => absent(kb, a),
        // A `¬∃` literal: its conjunction, instantiated with the answer's
        // bindings, has no match. Shown as an absence (it is one: of
        // every match), so every renderer reads it as closed-world.
        DerivationTree::NoMatch { formula } => ProofNode {
            fact: formula.clone(),
            step: Step::Absent { doubt: None },
            premises: Vec::new(),
        },
        DerivationTree::Truncated { fact, reason } => ProofNode {
            fact: atom_text(fact),
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
            fact: atom_text(fact),
            step: Step::Rule {
                line: *rule_line,
                text: rule_text.clone(),
            },
            premises: premises
                .iter()
                .map(|p| node(kb, p))
                .chain(missing.iter().map(|a| absent(kb, a)))
                .collect(),
        },
    }
}

/// `Pred(a, b)`, as `GroundAtom`'s `Display` writes it, built in one
/// allocation of the right size: a proof has a node per fact, and the
/// formatting machinery cost more than the rest of building a node.
fn atom_text(a: &logicpad::GroundAtom) -> String {
    let mut s = String::new();
    write_atom(&mut s, a);
    s
}

fn write_atom(s: &mut String, a: &logicpad::GroundAtom) {
    let len = a.pred.len() + 2 + a.args.iter().map(|x| x.len() + 2).sum::<usize>();
    s.reserve(len);
    s.push_str(&a.pred);
    s.push('(');
    for (i, x) in a.args.iter().enumerate() {
        if i > 0 {
            s.push_str(", ");
        }
        s.push_str(x);
    }
    s.push(')');
}

fn absent(kb: &WindowKb, a: &logicpad::GroundAtom) -> ProofNode {
    let mut fact = String::from("¬");
    write_atom(&mut fact, a);
    let doubt = kb.doubt(&fact['¬'.len_utf8()..]);
    ProofNode {
        fact,
        step: Step::Absent { doubt },
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
    if let Some(prob) = p.probability {
        s.push_str(&format!("; probability {}", crate::belief::rounded(prob)));
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
            Step::Absent { doubt: None } if n.fact.starts_with("¬∃") => {
                "[no match: closed world]".to_string()
            }
            Step::Absent { doubt: None } => "[no such fact: closed world]".to_string(),
            Step::Absent { doubt: Some(q) } => format!(
                "[no such fact: closed world; measured, and holds with probability {}]",
                crate::belief::rounded(*q)
            ),
            Step::Cut { reason } => format!("[proof cut: {reason}]"),
        };
        out.push(format!("{pad}{}  {how}", n.fact));
        stack.extend(n.premises.iter().rev().map(|p| (depth + 1, p)));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::Arc;

    #[test]
    fn the_fast_writer_writes_what_serde_writes() {
        let shared = Arc::new(Provenance {
            window: 0,
            frames: (0, 9),
            source: "kitti:\"0000\"\\x".into(),
            measured: Some(0.1 + 0.2),
            threshold: None,
            note: "tab\there, ctl \u{1} \u{7f} é ✓".into(),
            probability: None,
        });
        let other = Arc::new(Provenance {
            window: 1,
            frames: (10, 19),
            source: "sim:s".into(),
            measured: None,
            threshold: Some(("t".into(), -1e-9)),
            note: String::new(),
            probability: None,
        });
        let leaf = |fact: &str, p: &Arc<Provenance>| ProofNode {
            fact: fact.into(),
            step: Step::Observed {
                provenance: Some(Arc::clone(p)),
            },
            premises: Vec::new(),
        };
        let proofs = vec![
            vec![
                ProofNode {
                    fact: "Moving(\"q\")".into(),
                    step: Step::Rule {
                        line: 12,
                        text: "∀x: A(x) ==> B(x)\n".into(),
                    },
                    premises: vec![
                        leaf("A(a)", &shared),
                        leaf("A(b)", &shared),
                        leaf("A(c)", &other),
                        leaf("A(d)", &shared),
                        ProofNode {
                            fact: "¬C(a)".into(),
                            step: Step::Absent { doubt: None },
                            premises: Vec::new(),
                        },
                    ],
                },
                ProofNode {
                    fact: "D(a)".into(),
                    step: Step::Cut {
                        reason: "node limit 10000".into(),
                    },
                    premises: Vec::new(),
                },
            ],
            Vec::new(),
            vec![ProofNode {
                fact: "E()".into(),
                step: Step::Observed { provenance: None },
                premises: Vec::new(),
            }],
        ];
        let mut fast = Vec::new();
        crate::json::write_proofs_json(&mut fast, &proofs).expect("writes");
        let serde = serde_json::to_vec(&proofs).expect("serialises");
        assert_eq!(
            String::from_utf8_lossy(&fast),
            String::from_utf8_lossy(&serde)
        );
        let mut none = Vec::new();
        crate::json::write_proofs_json(&mut none, &[]).expect("writes");
        assert_eq!(none, b"[]");
    }

    #[test]
    fn proof_json_is_the_documented_shape() {
        // The hand-written `Serialize` must keep the bytes the derived one
        // wrote: `kind` first, the variant's fields, no empty premises.
        let prov = Provenance {
            window: 2,
            frames: (20, 29),
            source: "sim:x".into(),
            measured: Some(1.5),
            threshold: Some(("moving".into(), 0.7)),
            note: "n".into(),
            probability: None,
        };
        let node = ProofNode {
            fact: "Moving(car_1)".into(),
            step: Step::Rule {
                line: 7,
                text: "∀x: A(x) ==> B(x)".into(),
            },
            premises: vec![
                ProofNode {
                    fact: "A(car_1)".into(),
                    step: Step::Observed {
                        provenance: Some(Arc::new(prov)),
                    },
                    premises: Vec::new(),
                },
                ProofNode {
                    fact: "A(car_2)".into(),
                    step: Step::Observed { provenance: None },
                    premises: Vec::new(),
                },
                ProofNode {
                    fact: "¬C(car_1)".into(),
                    step: Step::Absent { doubt: None },
                    premises: Vec::new(),
                },
                ProofNode {
                    fact: "D(car_1)".into(),
                    step: Step::Cut {
                        reason: "depth limit 64".into(),
                    },
                    premises: Vec::new(),
                },
            ],
        };
        assert_eq!(
            serde_json::to_string(&node).expect("serialises"),
            concat!(
                r#"{"fact":"Moving(car_1)","step":{"kind":"rule","line":7,"text":"∀x: A(x) ==> B(x)"},"#,
                r#""premises":[{"fact":"A(car_1)","step":{"kind":"observed","provenance":{"window":2,"#,
                r#""frames":[20,29],"source":"sim:x","measured":1.5,"threshold":["moving",0.7],"note":"n"}}},"#,
                r#"{"fact":"A(car_2)","step":{"kind":"observed","provenance":null}},"#,
                r#"{"fact":"¬C(car_1)","step":{"kind":"absent"}},"#,
                r#"{"fact":"D(car_1)","step":{"kind":"cut","reason":"depth limit 64"}}]}"#
            )
        );
    }
}
