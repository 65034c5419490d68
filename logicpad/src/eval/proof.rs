//! Derivation trees: why a fact holds, rebuilt from the premises the
//! fixpoint recorded for its first derivation, within stated limits.

use super::{Model, arg_value, bind_from, term_name};
use crate::program::{Rule, RuleId};
use kanren::{FactId, Term};
use std::borrow::Cow;
use std::fmt;

/// A fact written out: predicate and constant arguments.
///
/// Names are borrowed from the symbol interner when they are symbols (as
/// every stored name is) and owned otherwise: a proof has a node per fact,
/// and copying each name into a `String` was most of what a proof cost.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GroundAtom {
    /// Predicate name.
    pub pred: Cow<'static, str>,
    /// Constants.
    pub args: Vec<Cow<'static, str>>,
}

impl fmt::Display for GroundAtom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        // Piece by piece: a proof writes one of these per node, and a
        // joined argument string was an allocation each time.
        f.write_str(&self.pred)?;
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

/// Bounds on a proof tree built by [`Model::explain_with`].
///
/// Why bound proofs at all: a justification chain is as long as the
/// recursion that produced it (a `Reach` over a 300 000-edge chain is 300 000
/// rule steps deep), and a fact whose justification reuses a sub-fact level
/// after level has a tree exponential in its depth, because trees do not
/// share subtrees. Proofs end up in a language model's retrieval context,
/// where a proof of more than a few dozen steps or a few thousand lines is
/// useless anyway, so the tree is cut there and the cut is said out loud
/// ([`DerivationTree::Truncated`]).
///
/// The defaults ([`ProofLimits::DEFAULT_MAX_DEPTH`] = 64,
/// [`ProofLimits::DEFAULT_MAX_NODES`] = 10 000) are far beyond any rule chain
/// of a driving LogicPad (the builtin one is a handful of steps deep) and
/// keep one proof under roughly a megabyte of text.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub struct ProofLimits {
    /// The most rule steps between the root and any node: a derived fact
    /// reached at this depth becomes a [`DerivationTree::Truncated`] node
    /// (base facts are always shown). `0` cuts a derived root at once.
    /// Clamped to [`ProofLimits::MAX_DEPTH_CEILING`].
    pub max_depth: usize,
    /// The most nodes (as [`DerivationTree::size`] counts them) in the tree;
    /// at least 1, since the root is always there. Nodes are given out
    /// breadth first (every derived fact at one depth before any deeper,
    /// in body order within a depth), so the top levels of a large proof
    /// are shown in full: a derived fact whose premises and absent atoms no
    /// longer fit becomes a [`DerivationTree::Truncated`] node.
    pub max_nodes: usize,
}

impl ProofLimits {
    /// Default [`ProofLimits::max_depth`].
    pub const DEFAULT_MAX_DEPTH: usize = 64;
    /// Default [`ProofLimits::max_nodes`].
    pub const DEFAULT_MAX_NODES: usize = 10_000;
    /// Hard upper bound on [`ProofLimits::max_depth`]. The tree's derived
    /// `Clone`, `PartialEq`, `Debug` and `Drop` (and logicrag's renderer)
    /// recurse once per level, so a tree as deep as the derivation would
    /// overflow the stack there. `Debug` takes up to about 1 KiB of stack
    /// per level, so 256 levels need about an eighth of a 2 MiB thread stack
    /// (a test runs all four on a 512 KiB one; 1024 levels did not fit).
    pub const MAX_DEPTH_CEILING: usize = 256;
}

impl Default for ProofLimits {
    fn default() -> ProofLimits {
        ProofLimits {
            max_depth: ProofLimits::DEFAULT_MAX_DEPTH,
            max_nodes: ProofLimits::DEFAULT_MAX_NODES,
        }
    }
}

/// Which limit cut a proof (see [`DerivationTree::Truncated`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum CutReason {
    /// The fact lies this many rule steps below the root
    /// ([`ProofLimits::max_depth`]).
    DepthLimit(usize),
    /// Expanding the fact would take the tree past this many nodes
    /// ([`ProofLimits::max_nodes`]).
    NodeLimit(usize),
}

impl fmt::Display for CutReason {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            CutReason::DepthLimit(n) => write!(f, "depth limit {n}"),
            CutReason::NodeLimit(n) => write!(f, "node limit {n}"),
        }
    }
}

/// Why a fact holds.
///
/// Invariants: a `Derived` node's `premises` instantiate the positive body of
/// rule `rule` and its `fact` the head, under one substitution; `absent`
/// lists the negated body atoms under that substitution, none of which holds.
/// A `Truncated` node stands for a *derived* fact that holds in the model and
/// whose proof was left out because of `reason` (explaining that fact on its
/// own gives it). A tree from [`Model::explain`] / [`Model::explain_with`] is
/// at most [`ProofLimits::max_depth`] rule steps deep and has at most
/// [`ProofLimits::max_nodes`] nodes.
#[derive(Debug, Clone, PartialEq, Eq)]
pub enum DerivationTree {
    /// A base fact (given, not derived).
    Base {
        /// The fact.
        fact: GroundAtom,
        /// Its id in its relation of the model, so that a caller can find
        /// what it keeps per base fact (a KB's provenance) without looking
        /// the fact up by name.
        id: FactId,
    },
    /// A fact derived by a rule.
    Derived {
        /// The derived fact.
        fact: GroundAtom,
        /// The rule's id in [`Program::rules`](crate::Program::rules).
        rule: RuleId,
        /// The rule text as written.
        rule_text: std::sync::Arc<str>,
        /// Its line in the LogicPad file.
        rule_line: usize,
        /// Proofs of the positive body atoms, in body order.
        premises: Vec<DerivationTree>,
        /// Negated body atoms checked absent (closed world).
        absent: Vec<GroundAtom>,
    },
    /// A negated query literal that holds because the atom is absent.
    Absent(GroundAtom),
    /// A `¬∃` query literal that holds because its conjunction,
    /// instantiated with the answer's bindings, has no match (closed
    /// world): `¬∃y: (Road(y) ∧ On(ped_1, y))`.
    NoMatch {
        /// The literal as written, its outer variables replaced by the
        /// answer's values and its own variables kept by name.
        formula: String,
    },
    /// A derived fact that holds, whose proof is cut here by a
    /// [`ProofLimits`] bound.
    Truncated {
        /// The fact (it holds).
        fact: GroundAtom,
        /// The limit that cut its proof.
        reason: CutReason,
    },
}

impl DerivationTree {
    /// The fact this tree proves (for `Absent`: the atom that is absent;
    /// `None` for a `NoMatch`, which proves no single fact).
    pub fn fact(&self) -> Option<&GroundAtom> {
        match self {
            DerivationTree::Absent(f) => Some(f),
            DerivationTree::Base { fact, .. }
            | DerivationTree::Derived { fact, .. }
            | DerivationTree::Truncated { fact, .. } => Some(fact),
            DerivationTree::NoMatch { .. } => None,
        }
    }

    /// Number of nodes: one per fact node, plus one per absent atom of a
    /// `Derived` node (a `Truncated` node counts one).
    pub fn size(&self) -> usize {
        // A leaf, or a rule step over leaves (nearly every node of a
        // query's proof), without a stack: the size of each tree a query
        // builds is asked, and the allocation showed in profiles.
        let DerivationTree::Derived {
            premises, absent, ..
        } = self
        else {
            return 1;
        };
        if !premises
            .iter()
            .any(|p| matches!(p, DerivationTree::Derived { .. }))
        {
            return 1 + premises.len() + absent.len();
        }
        // An explicit stack rather than recursion, so that the count does
        // not depend on the tree being shallow.
        let mut n = 0;
        let mut todo = vec![self];
        while let Some(t) = todo.pop() {
            n += 1;
            if let DerivationTree::Derived {
                premises, absent, ..
            } = t
            {
                n += absent.len();
                todo.extend(premises);
            }
        }
        n
    }

    /// True when some node of the tree is `Truncated`.
    pub fn is_truncated(&self) -> bool {
        let mut todo = vec![self];
        while let Some(t) = todo.pop() {
            match t {
                DerivationTree::Truncated { .. } => return true,
                DerivationTree::Derived { premises, .. } => todo.extend(premises),
                _ => {}
            }
        }
        false
    }
}

impl fmt::Display for DerivationTree {
    /// One line per node, indented two spaces per rule step; premises come
    /// before their rule's absent atoms.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        enum Line<'t> {
            Node(&'t DerivationTree),
            Absent(&'t GroundAtom),
        }
        // Depth-first with an explicit stack (children pushed in reverse),
        // so printing does not recurse once per level.
        let mut todo = vec![(Line::Node(self), 0usize)];
        while let Some((line, indent)) = todo.pop() {
            let pad = "  ".repeat(indent);
            match line {
                Line::Absent(a) => writeln!(f, "{pad}¬{a}  [absent]")?,
                Line::Node(DerivationTree::Base { fact: a, .. }) => {
                    writeln!(f, "{pad}{a}  [fact]")?
                }
                Line::Node(DerivationTree::Absent(a)) => writeln!(f, "{pad}¬{a}  [absent]")?,
                Line::Node(DerivationTree::NoMatch { formula }) => {
                    writeln!(f, "{pad}{formula}  [no match]")?
                }
                Line::Node(DerivationTree::Truncated { fact, reason }) => {
                    writeln!(f, "{pad}{fact}  [proof cut: {reason}]")?
                }
                Line::Node(DerivationTree::Derived {
                    fact,
                    rule_text,
                    rule_line,
                    premises,
                    absent,
                    ..
                }) => {
                    writeln!(f, "{pad}{fact}  [rule, line {rule_line}: {rule_text}]")?;
                    todo.extend(absent.iter().rev().map(|a| (Line::Absent(a), indent + 1)));
                    todo.extend(premises.iter().rev().map(|p| (Line::Node(p), indent + 1)));
                }
            }
        }
        Ok(())
    }
}

impl Model {
    /// Why a fact holds, down to base facts, within the default
    /// [`ProofLimits`]; `None` when it does not hold.
    pub fn explain(&self, pred: &str, args: &[&str]) -> Option<DerivationTree> {
        self.explain_with(pred, args, ProofLimits::default())
    }

    /// Why a fact holds, with the proof cut ([`DerivationTree::Truncated`])
    /// where it would exceed `limits`; `None` when the fact does not hold.
    pub fn explain_with(
        &self,
        pred: &str,
        args: &[&str],
        limits: ProofLimits,
    ) -> Option<DerivationTree> {
        let i = self.index_of(pred)?;
        let terms: Vec<Term> = args.iter().map(|a| super::const_term(a)).collect();
        let id = self.rels.get(i)?.id_of(&terms)?;
        self.explain_id(i, id, limits, limits.max_nodes)
    }

    /// Fact `id` of relation `index`, written out.
    fn ground_atom(&self, index: usize, id: FactId) -> Option<GroundAtom> {
        let tuple = self.rels.get(index)?.tuple(id)?;
        Some(GroundAtom {
            pred: self.name_of(index),
            args: tuple.iter().map(term_name).collect(),
        })
    }

    /// The recorded first derivation of fact `id` of relation `index`:
    /// `Some(None)` for a base fact, `None` when the id is unknown.
    fn justification(&self, index: usize, id: FactId) -> Option<Option<(&Rule, &[FactId])>> {
        let base = self.base_len.get(index).copied().unwrap_or(0);
        if id < base {
            return Some(None);
        }
        let j = self.just.get(index)?.get((id - base) as usize)?;
        let rule = self.program.rules().get(j.rule as usize)?;
        let prem = self
            .premises
            .get(j.start as usize..(j.start + j.len) as usize)?;
        Some(Some((rule, prem)))
    }

    /// Why fact `id` of relation `index` holds, within `limits`.
    ///
    /// Nodes of the `max_nodes` budget are handed out breadth first (every
    /// derived fact at depth `d` is offered room before any at depth `d + 1`,
    /// in body order within a level): proofs feed a retrieval context where
    /// the top levels matter most, and depth first let a large first premise
    /// spend the whole budget while a sibling at depth 1 was cut.
    ///
    /// Two phases, neither recursive (a justification chain can be hundreds
    /// of thousands of steps long and the depth limit may be the ceiling):
    /// a breadth-first walk decides which facts are expanded, then the tree
    /// is assembled from the last node back to the root.
    ///
    /// `allowance` is how many of the `max_nodes` are still free (the whole
    /// limit for one fact; what is left of a query's shared budget for
    /// [`Model::ask_with`]); a cut names the configured limit, not the
    /// remainder, which would read "node limit 1".
    pub(crate) fn explain_id(
        &self,
        index: usize,
        id: FactId,
        limits: ProofLimits,
        allowance: usize,
    ) -> Option<DerivationTree> {
        /// What the walk decided for one node.
        enum Plan<'m> {
            Base,
            Cut(CutReason),
            /// Expanded by `rule`; its premises are the nodes
            /// `first..first + n` (`n` = premises proved), in body order.
            Expand {
                rule: &'m Rule,
                prem: &'m [FactId],
                first: usize,
                n: usize,
            },
        }
        /// A node of the tree in breadth-first order: `(relation, fact id,
        /// depth)`, then its plan once the walk has reached it.
        struct Node<'m> {
            rel: usize,
            id: FactId,
            depth: usize,
            plan: Plan<'m>,
        }
        // A base fact is its own proof: most premises of a query are, and
        // the walk below allocates its queues for every fact.
        if self.justification(index, id)?.is_none() {
            return Some(DerivationTree::Base {
                fact: self.ground_atom(index, id)?,
                id,
            });
        }
        let max_depth = limits.max_depth.min(ProofLimits::MAX_DEPTH_CEILING);
        let max_nodes = limits.max_nodes.max(1);
        let allowance = allowance.clamp(1, max_nodes);
        // Nodes given out so far: an expansion reserves one per premise and
        // absent atom, so `used` never passes `allowance` however its
        // premises turn out.
        let mut used = 1usize;
        let mut nodes = vec![Node {
            rel: index,
            id,
            depth: 0,
            plan: Plan::Base,
        }];
        // Phase 1. `nodes` is its own FIFO queue: children are appended
        // after every node already queued, so a level is decided in full, in
        // body order, before the next one starts.
        let mut i = 0;
        while i < nodes.len() {
            let (rel, fid, depth) = (nodes[i].rel, nodes[i].id, nodes[i].depth);
            let plan = match self.justification(rel, fid)? {
                None => Plan::Base,
                Some((rule, prem)) => {
                    let n = rule.body.len().min(prem.len());
                    let extra = n + rule.negated.len();
                    if depth >= max_depth {
                        Plan::Cut(CutReason::DepthLimit(max_depth))
                    } else if used.saturating_add(extra) > allowance {
                        // Later facts of this level may still fit: a cut
                        // here does not stop the walk.
                        Plan::Cut(CutReason::NodeLimit(max_nodes))
                    } else {
                        used += extra;
                        let first = nodes.len();
                        nodes.extend(rule.body.iter().zip(prem).take(n).map(|(atom, &pid)| Node {
                            rel: atom.pred,
                            id: pid,
                            depth: depth + 1,
                            plan: Plan::Base,
                        }));
                        Plan::Expand {
                            rule,
                            prem,
                            first,
                            n,
                        }
                    }
                }
            };
            nodes[i].plan = plan;
            i += 1;
        }
        // Phase 2. A node's premises come after it in `nodes`, so walking
        // backwards finds them built; each is taken exactly once.
        let mut built: Vec<Option<DerivationTree>> = Vec::with_capacity(nodes.len());
        built.resize_with(nodes.len(), || None);
        for (k, node) in nodes.iter().enumerate().rev() {
            let fact = self.ground_atom(node.rel, node.id)?;
            let tree = match node.plan {
                Plan::Base => DerivationTree::Base { fact, id: node.id },
                Plan::Cut(reason) => DerivationTree::Truncated { fact, reason },
                Plan::Expand {
                    rule,
                    prem,
                    first,
                    n,
                } => DerivationTree::Derived {
                    fact,
                    rule: rule.id,
                    rule_text: rule.source.text.clone(),
                    rule_line: rule.source.line,
                    premises: built
                        .get_mut(first..first + n)?
                        .iter_mut()
                        .map(Option::take)
                        .collect::<Option<Vec<_>>>()?,
                    absent: self.absent_atoms(rule, prem),
                },
            };
            built[k] = Some(tree);
        }
        built.first_mut()?.take()
    }

    /// A rule's negated body atoms under the substitution its premises give.
    fn absent_atoms(&self, rule: &Rule, prem: &[FactId]) -> Vec<GroundAtom> {
        if rule.negated.is_empty() {
            return Vec::new();
        }
        let binds = bind_from(rule, |p| self.rels.get(p).map(|r| &**r), prem);
        rule.negated
            .iter()
            .map(|n| GroundAtom {
                pred: self.name_of(n.pred),
                args: n
                    .args
                    .iter()
                    .map(|a| arg_value(a, &binds).map_or(Cow::Borrowed("?"), term_name))
                    .collect(),
            })
            .collect()
    }
}
