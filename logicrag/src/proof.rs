//! Proofs as structure: each answer's derivation is a tree of
//! [`ProofNode`]s — an observed fact with its provenance, a rule step with
//! its premises, an atom absent under the closed world, or a proof cut by
//! its limits. Rendering happens at the edges, from the structure: the
//! terminal ([`lines`]), JSON (serde), the C2 sentences of the RAG context.

use crate::kb::WindowKb;
use logicpad::{DerivationTree, GroundAtom, QueryAnswer};
use perception::Provenance;
use serde::Serialize;
use smallvec::SmallVec;
use std::cmp::Ordering;

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
    pub fact: ProofFact,
    /// How it holds.
    pub step: Step,
    /// The premises of a rule step.
    pub premises: Vec<ProofNode>,
}

/// The fact of a proof node: its text as the outputs write it, and, for
/// an atom (`Moving(car_1)`, `¬Moving(car_1)`), the atom itself
/// ([`ProofFact::atom`]) — its predicate and arguments recorded as the
/// text was written from the typed atom, never read back from the text.
///
/// The text is kept because every output writes it (JSON, Arrow, the
/// terminal); the atom is where the text's pieces lie in it, so a node is
/// still one allocation (a batch with proofs builds millions). A fact
/// made from text alone (`From<String>`: a `¬∃` formula, a proof read
/// back from a table) has no atom. Equality is the text's.
///
/// JSON: the text, as a string.
#[derive(Debug, Clone)]
pub struct ProofFact {
    text: String,
    shape: Option<Shape>,
}

/// Where an atom's pieces lie in a [`ProofFact`]'s text: the predicate
/// from `start` (after any `¬`) to `pred_end`, each argument up to its
/// end, the next one two bytes (`, `) later.
#[derive(Debug, Clone)]
struct Shape {
    negated: bool,
    pred_end: u32,
    arg_ends: SmallVec<[u32; 4]>,
}

impl ProofFact {
    /// The fact of a ground atom, `¬` in front when `negated`, written in
    /// one allocation of the right size (a proof has a node per fact,
    /// and the formatting machinery cost more than the rest of building
    /// a node).
    pub(crate) fn of_atom(a: &GroundAtom, negated: bool) -> ProofFact {
        let neg = if negated { "¬" } else { "" };
        let len = neg.len() + a.pred.len() + 2 + a.args.iter().map(|x| x.len() + 2).sum::<usize>();
        let mut text = String::with_capacity(len);
        text.push_str(neg);
        text.push_str(&a.pred);
        let pred_end = text.len();
        text.push('(');
        let mut arg_ends = SmallVec::new();
        for (i, x) in a.args.iter().enumerate() {
            if i > 0 {
                text.push_str(", ");
            }
            text.push_str(x);
            arg_ends.push(u32::try_from(text.len()).unwrap_or(u32::MAX));
        }
        text.push(')');
        // A fact past 4 GiB of text keeps its text and loses its atom.
        let shape = u32::try_from(text.len()).ok().map(|_| Shape {
            negated,
            pred_end: u32::try_from(pred_end).unwrap_or(u32::MAX),
            arg_ends,
        });
        ProofFact { text, shape }
    }

    /// The fact as the outputs write it.
    pub fn as_str(&self) -> &str {
        &self.text
    }

    /// The atom, without its negation: `Moving(car_1)` of both
    /// `Moving(car_1)` and `¬Moving(car_1)`. `None` for a fact made from
    /// text (a `¬∃` formula).
    pub fn atom(&self) -> Option<Atom<'_>> {
        let s = self.shape.as_ref()?;
        let start = if s.negated { '¬'.len_utf8() } else { 0 };
        let pred = self.text.get(start..s.pred_end as usize)?;
        let mut args = SmallVec::new();
        let mut from = s.pred_end as usize + 1;
        for &end in &s.arg_ends {
            args.push(self.text.get(from..end as usize)?);
            from = end as usize + 2;
        }
        Some(Atom { pred, args })
    }
}

impl ProofFact {
    /// Whether the fact is a negated atom (`¬Moving(car_1)`).
    pub(crate) fn is_negated(&self) -> bool {
        self.shape.as_ref().is_some_and(|s| s.negated)
    }
}

impl From<String> for ProofFact {
    fn from(text: String) -> ProofFact {
        ProofFact { text, shape: None }
    }
}

impl From<&str> for ProofFact {
    fn from(text: &str) -> ProofFact {
        ProofFact::from(text.to_string())
    }
}

impl std::ops::Deref for ProofFact {
    type Target = str;
    fn deref(&self) -> &str {
        &self.text
    }
}

impl AsRef<str> for ProofFact {
    fn as_ref(&self) -> &str {
        &self.text
    }
}

impl std::fmt::Display for ProofFact {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.text)
    }
}

impl PartialEq for ProofFact {
    fn eq(&self, other: &ProofFact) -> bool {
        self.text == other.text
    }
}

impl Eq for ProofFact {}

impl PartialEq<str> for ProofFact {
    fn eq(&self, other: &str) -> bool {
        self.text == other
    }
}

impl PartialEq<&str> for ProofFact {
    fn eq(&self, other: &&str) -> bool {
        self.text == *other
    }
}

impl Serialize for ProofFact {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        s.serialize_str(&self.text)
    }
}

/// A ground atom by its predicate and arguments, borrowed: the key under
/// which belief counts a proof's leaves and matches them with the facts it
/// flips, and why-not looks up its notes.
///
/// Ordered (and equal) as its text `Pred(a, b)` would be, byte by byte,
/// so that whatever is ordered by atoms keeps the order it had when it was
/// ordered by text (a product of probabilities is taken in that order).
#[derive(Debug, Clone)]
pub struct Atom<'a> {
    /// The predicate, e.g. `Moving`.
    pub pred: &'a str,
    /// The constant arguments, e.g. `[car_1]`.
    pub args: SmallVec<[&'a str; 4]>,
}

impl<'a> Atom<'a> {
    /// The atom of a perception fact.
    pub(crate) fn of_fact(f: &'a perception::Fact) -> Atom<'a> {
        Atom {
            pred: &f.predicate,
            args: f.args.iter().map(String::as_str).collect(),
        }
    }

    /// The bytes of the atom's text, `Pred(a, b)`, without writing it.
    fn bytes(&self) -> impl Iterator<Item = u8> + '_ {
        let args = self.args.iter().enumerate().flat_map(|(i, a)| {
            let sep: &[u8] = if i > 0 { b", " } else { b"" };
            sep.iter().copied().chain(a.bytes())
        });
        self.pred
            .bytes()
            .chain(std::iter::once(b'('))
            .chain(args)
            .chain(std::iter::once(b')'))
    }
}

impl Ord for Atom<'_> {
    fn cmp(&self, other: &Self) -> Ordering {
        // Piece by piece while the pieces line up (nearly always: names
        // hold none of `(`, `,`, `)`); the whole text's bytes otherwise.
        let piece = |a: &str, b: &str, next_a: u8, next_b: u8| -> Option<Ordering> {
            let n = a.len().min(b.len());
            match a.as_bytes()[..n].cmp(&b.as_bytes()[..n]) {
                Ordering::Equal => {}
                o => return Some(o),
            }
            let (x, y) = (
                a.as_bytes().get(n).copied().unwrap_or(next_a),
                b.as_bytes().get(n).copied().unwrap_or(next_b),
            );
            match x.cmp(&y) {
                Ordering::Equal if a.len() == b.len() => Some(Ordering::Equal),
                Ordering::Equal => None,
                o => Some(o),
            }
        };
        let lined_up = (|| {
            match piece(self.pred, other.pred, b'(', b'(')? {
                Ordering::Equal => {}
                o => return Some(o),
            }
            let after = |args: &[&str], i: usize| if i + 1 < args.len() { b',' } else { b')' };
            for i in 0..self.args.len().min(other.args.len()) {
                let o = piece(
                    self.args[i],
                    other.args[i],
                    after(&self.args, i),
                    after(&other.args, i),
                )?;
                if o != Ordering::Equal {
                    return Some(o);
                }
                // Equal pieces and equal next bytes: both go on, or both end.
            }
            // `P()` against `P(a…)`: `)` against the argument's first
            // byte, unless that is `)` too.
            let first = |args: &[&str]| args.first()?.as_bytes().first().copied();
            match (self.args.len(), other.args.len()) {
                (a, b) if a == b => Some(Ordering::Equal),
                (0, _) => first(&other.args)
                    .filter(|&y| y != b')')
                    .map(|y| b')'.cmp(&y)),
                (_, 0) => first(&self.args)
                    .filter(|&x| x != b')')
                    .map(|x| x.cmp(&b')')),
                // Unreachable: the last common argument was followed by
                // `,` in one and `)` in the other, and those differ.
                _ => None,
            }
        })();
        lined_up.unwrap_or_else(|| self.bytes().cmp(other.bytes()))
    }
}

impl PartialOrd for Atom<'_> {
    fn partial_cmp(&self, other: &Self) -> Option<Ordering> {
        Some(self.cmp(other))
    }
}

impl PartialEq for Atom<'_> {
    fn eq(&self, other: &Self) -> bool {
        self.cmp(other) == Ordering::Equal
    }
}

impl Eq for Atom<'_> {}

impl std::hash::Hash for Atom<'_> {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        // The text's bytes, as equality is the text's.
        for b in self.bytes() {
            state.write_u8(b);
        }
    }
}

impl std::fmt::Display for Atom<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.pred)?;
        f.write_str("(")?;
        for (i, a) in self.args.iter().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(a)?;
        }
        f.write_str(")")
    }
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
            fact: ProofFact::of_atom(fact, false),
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
            fact: ProofFact::from(formula.clone()),
            step: Step::Absent { doubt: None },
            premises: Vec::new(),
        },
        DerivationTree::Truncated { fact, reason } => ProofNode {
            fact: ProofFact::of_atom(fact, false),
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
            fact: ProofFact::of_atom(fact, false),
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

/// An atom that holds negated, with the probability that it holds all
/// the same when perception measured it (looked up by the atom).
fn absent(kb: &WindowKb, a: &GroundAtom) -> ProofNode {
    ProofNode {
        fact: ProofFact::of_atom(a, true),
        step: Step::Absent {
            doubt: kb.doubt(&a.pred, &a.args),
        },
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

    fn ground(pred: &'static str, args: &[&'static str]) -> GroundAtom {
        GroundAtom {
            pred: pred.into(),
            args: args.iter().map(|a| (*a).into()).collect(),
        }
    }

    #[test]
    fn a_fact_keeps_its_atom_as_written() {
        let f = ProofFact::of_atom(&ground("On", &["car_1", "\"a, b\""]), true);
        assert_eq!(f.as_str(), "¬On(car_1, \"a, b\")");
        assert!(f.is_negated());
        let a = f.atom().expect("an atom");
        assert_eq!(
            (a.pred, a.args.as_slice()),
            ("On", &["car_1", "\"a, b\""][..])
        );
        assert_eq!(a.to_string(), "On(car_1, \"a, b\")");
        let none = ProofFact::of_atom(&ground("Road", &[]), false);
        assert_eq!(none.as_str(), "Road()");
        assert!(none.atom().is_some_and(|a| a.args.is_empty()));
        // A fact from text has no atom, and equals by its text.
        let text = ProofFact::from("¬∃y: (Road(y))");
        assert!(text.atom().is_none() && !text.is_negated());
        assert_eq!(ProofFact::from("Road()"), none);
    }

    proptest::proptest! {
        /// Atoms order (and equal) as their texts do, byte by byte: belief
        /// multiplies its leaves in that order.
        #[test]
        fn atoms_order_as_their_texts(
            a in ("[A-C(),]{0,3}", proptest::collection::vec("[a-c ,()\"_0-9]{0,4}", 0..3)),
            b in ("[A-C(),]{0,3}", proptest::collection::vec("[a-c ,()\"_0-9]{0,4}", 0..3)),
        ) {
            fn atom((p, args): &(String, Vec<String>)) -> Atom<'_> {
                Atom {
                    pred: p.as_str(),
                    args: args.iter().map(String::as_str).collect(),
                }
            }
            let (x, y) = (atom(&a), atom(&b));
            proptest::prop_assert_eq!(x.cmp(&y), x.to_string().cmp(&y.to_string()));
            proptest::prop_assert_eq!(x == y, x.to_string() == y.to_string());
        }
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
