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

use crate::program::{CArg, CAtom, PredId, Program, Rule, RuleId};
use kanren::{FactId, Probe, Relation, Sym, Term};
use std::borrow::Borrow;
use std::collections::{BTreeMap, HashMap};
use std::fmt;
use std::sync::Arc;

/// Errors while building a fact base or evaluating.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FactError {
    /// Occurs when a predicate is used with two different arities.
    #[error("`{pred}` has {expected} argument(s), but a fact gives {got}")]
    Arity {
        /// Predicate.
        pred: String,
        /// Arity fixed earlier (by the LogicPad or the first fact).
        expected: usize,
        /// Arity of the offending fact.
        got: usize,
    },
    /// Occurs when a fact line of a `.facts` text does not parse.
    #[error("{file}:{line}:{column}: cannot read fact `{text}`: {message}")]
    Syntax {
        /// File name given to the parser.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column of the offending character.
        column: usize,
        /// What was expected there.
        message: String,
        /// The line's text.
        text: String,
    },
    /// Occurs when kanren refuses a tuple (e.g. a non-ground argument).
    #[error("cannot store a `{pred}` fact: {message}")]
    Store {
        /// Predicate.
        pred: String,
        /// kanren's message.
        message: String,
    },
}

/// Ground base facts by predicate name, before reasoning.
///
/// Invariant: every relation's name is its key, and its arity is fixed by
/// its first fact.
#[derive(Debug, Clone, Default)]
pub struct FactBase {
    rels: BTreeMap<String, Relation>,
    count: usize,
}

impl FactBase {
    /// An empty fact base.
    pub fn new() -> FactBase {
        FactBase::default()
    }

    /// Adds `pred(args…)` with constant arguments; `Ok(false)` for a duplicate.
    pub fn add(&mut self, pred: &str, args: &[&str]) -> Result<bool, FactError> {
        let terms: Vec<Term> = args.iter().map(|a| Term::Sym(Sym::new(a))).collect();
        self.add_terms(pred, &terms)
    }

    /// Adds a fact given as terms (ground atoms).
    pub fn add_terms(&mut self, pred: &str, args: &[Term]) -> Result<bool, FactError> {
        let rel = match self.rels.get_mut(pred) {
            Some(r) => r,
            None => self
                .rels
                .entry(pred.to_string())
                .or_insert_with(|| Relation::new(Sym::new(pred), args.len())),
        };
        if rel.arity() != args.len() {
            return Err(FactError::Arity {
                pred: pred.to_string(),
                expected: rel.arity(),
                got: args.len(),
            });
        }
        let (_, new) = rel.insert(args).map_err(|e| FactError::Store {
            pred: pred.to_string(),
            message: e.to_string(),
        })?;
        if new {
            self.count += 1;
        }
        Ok(new)
    }

    /// Adds every fact of a text with one `Pred(a, b)` (or `Pred()`) per line
    /// (blank lines and `#` or `%` comments skipped; the line syntax is
    /// [`crate::facts_text::parse_fact_line`]'s). Returns the number of new
    /// facts.
    pub fn add_text(&mut self, text: &str, file: &str) -> Result<usize, FactError> {
        let mut added = 0;
        let mut args: Vec<Term> = Vec::with_capacity(4);
        for (i, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with('%') {
                continue;
            }
            let fact = crate::facts_text::parse_fact_line(line).map_err(|(col, message)| {
                FactError::Syntax {
                    file: file.to_string(),
                    line: i + 1,
                    column: col + 1 + (raw.len() - raw.trim_start().len()),
                    message,
                    text: line.to_string(),
                }
            })?;
            args.clear();
            args.extend(fact.args.iter().map(|a| Term::Sym(Sym::new(a))));
            let pred = fact.predicate.as_str();
            if self.add_terms(pred, &args)? {
                added += 1;
            }
        }
        Ok(added)
    }

    /// Parses a whole `.facts` text.
    pub fn from_text(text: &str, file: &str) -> Result<FactBase, FactError> {
        let mut fb = FactBase::new();
        fb.add_text(text, file)?;
        Ok(fb)
    }

    /// The relation of a predicate.
    pub fn relation(&self, pred: &str) -> Option<&Relation> {
        self.rels.get(pred)
    }

    /// Number of distinct facts.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when there is no fact.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}

/// A fact written out: predicate and constant arguments.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct GroundAtom {
    /// Predicate name.
    pub pred: String,
    /// Constants.
    pub args: Vec<String>,
}

impl fmt::Display for GroundAtom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}({})", self.pred, self.args.join(", "))
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
    Base(GroundAtom),
    /// A fact derived by a rule.
    Derived {
        /// The derived fact.
        fact: GroundAtom,
        /// The rule's id in [`Program::rules`].
        rule: RuleId,
        /// The rule text as written.
        rule_text: String,
        /// Its line in the LogicPad file.
        rule_line: usize,
        /// Proofs of the positive body atoms, in body order.
        premises: Vec<DerivationTree>,
        /// Negated body atoms checked absent (closed world).
        absent: Vec<GroundAtom>,
    },
    /// A negated query literal that holds because the atom is absent.
    Absent(GroundAtom),
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
    /// The fact this tree proves (for `Absent`: the atom that is absent).
    pub fn fact(&self) -> &GroundAtom {
        match self {
            DerivationTree::Base(f) | DerivationTree::Absent(f) => f,
            DerivationTree::Derived { fact, .. } | DerivationTree::Truncated { fact, .. } => fact,
        }
    }

    /// Number of nodes: one per fact node, plus one per absent atom of a
    /// `Derived` node (a `Truncated` node counts one).
    pub fn size(&self) -> usize {
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
                Line::Node(DerivationTree::Base(a)) => writeln!(f, "{pad}{a}  [fact]")?,
                Line::Node(DerivationTree::Absent(a)) => writeln!(f, "{pad}¬{a}  [absent]")?,
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
}

/// The result of reasoning over one fact base: base plus derived relations.
///
/// Invariants: relation `p` holds its base facts at ids `0..base_len[p]` and
/// derived facts after them; `just[p][i]` justifies fact `base_len[p] + i`.
#[derive(Debug, Clone)]
pub struct Model {
    pub(crate) program: Program,
    pub(crate) rels: Vec<Arc<Relation>>,
    pub(crate) names: HashMap<String, usize>,
    base_len: Vec<u32>,
    just: Vec<Vec<Just>>,
    premises: Vec<FactId>,
    violations: Vec<Violation>,
    stats: EvalStats,
}

/// One join of a rule's body over relations: the planner's order, then
/// for each atom in turn the candidates of an index probe (cut to the
/// atom's semi-naive range), bound against the tuple. The same join derives
/// facts in the fixpoint, counts and lists a query's answers, records the
/// premises that proofs are built from, and — pulled one derivation at a
/// time through [`Join::next_derivation`] — enumerates answers lazily.
///
/// Datalog: for `head :- b1, …, bn, ¬n1, …, c1, …` each derivation is one
/// fact per `bi` (in `order`) agreeing on shared variables, such that no
/// `nj` holds and every comparison `ck` holds.
///
/// Invariants: `frames[d]` is the cursor of atom `order[d]`; `trail` holds
/// the variables bound so far, innermost last, and `frames[d].mark` is its
/// length before atom `order[d]` bound anything; `chosen[i]` is the fact of
/// body atom `i` in the current derivation.
pub(crate) struct Join<'a, R: Borrow<Relation>> {
    pub(crate) rels: &'a [R],
    pub(crate) rule: RuleRef<'a>,
    pub(crate) order: Vec<usize>,
    pub(crate) ranges: Vec<(u32, u32)>,
    pub(crate) binds: Vec<Option<Term>>,
    pub(crate) chosen: Vec<FactId>,
    pub(crate) neg: Vec<Term>,
    pub(crate) trail: Vec<usize>,
    /// Output: head tuples, flat.
    pub(crate) out_terms: Vec<Term>,
    /// Output: premise ids in body order, flat.
    pub(crate) out_prem: Vec<FactId>,
    /// Number of successful derivations (also counts 0-ary heads).
    pub(crate) emitted: usize,
    /// The join stops once this many derivations are emitted (a query's
    /// answer budget; `usize::MAX` for rules, which the fixpoint bounds).
    pub(crate) limit: usize,
    /// False when only the number of derivations is wanted: nothing is
    /// stored, so counting takes no memory per answer.
    pub(crate) store: bool,
    /// A query's step and time budget (none for rules).
    pub(crate) budget: JoinBudget,
    /// The cursors of the atoms bound so far.
    frames: Vec<Frame<'a>>,
    /// Whether the first derivation was asked for.
    started: bool,
}

/// The rule a join runs: the program's own, or a query compiled for a lazy
/// answer stream, which owns it.
#[derive(Clone)]
pub(crate) enum RuleRef<'a> {
    Borrowed(&'a Rule),
    Shared(Arc<Rule>),
}

impl RuleRef<'_> {
    pub(crate) fn get(&self) -> &Rule {
        match self {
            RuleRef::Borrowed(r) => r,
            RuleRef::Shared(r) => r,
        }
    }
}

/// The cursor of one atom of a join: its candidates and the next one.
struct Frame<'a> {
    probe: Probe<'a>,
    next: usize,
    mark: usize,
}

impl Frame<'_> {
    fn next_id(&mut self) -> Option<FactId> {
        let id = match self.probe {
            Probe::Range(lo, hi) => {
                let id = lo.checked_add(u32::try_from(self.next).ok()?)?;
                (id < hi).then_some(id)
            }
            Probe::Ids(ids) => ids.get(self.next).copied(),
        };
        self.next += 1;
        id
    }
}

/// The step and time budget of a query's join: a step is one candidate
/// fact tried. When it runs out the join stops with what it has found.
#[derive(Debug, Clone, Default)]
pub(crate) struct JoinBudget {
    pub(crate) max_steps: Option<u64>,
    pub(crate) deadline: Option<std::time::Instant>,
    pub(crate) steps: u64,
    /// Why the join stopped early, once it has.
    pub(crate) stopped: Option<kanren::StopReason>,
}

impl JoinBudget {
    /// How often the clock is read, in steps.
    const CLOCK_EVERY: u64 = 4096;

    /// Counts one step; false once the budget is spent.
    #[inline]
    fn step(&mut self) -> bool {
        if self.stopped.is_some() {
            return false;
        }
        self.steps += 1;
        if self.max_steps.is_some_and(|m| self.steps > m) {
            self.stopped = Some(kanren::StopReason::StepBudget);
            return false;
        }
        if self.steps % Self::CLOCK_EVERY == 0
            && self
                .deadline
                .is_some_and(|d| std::time::Instant::now() >= d)
        {
            self.stopped = Some(kanren::StopReason::TimeBudget);
            return false;
        }
        true
    }
}

pub(crate) fn arg_value<'t>(a: &'t CArg, binds: &'t [Option<Term>]) -> Option<&'t Term> {
    match a {
        CArg::Const(t) => Some(t),
        CArg::Var(v) => binds.get(*v).and_then(Option::as_ref),
    }
}

impl<'a, R: Borrow<Relation>> Join<'a, R> {
    /// A join of `rule` over `rels` in `order`, each body atom within its
    /// id range.
    pub(crate) fn new(
        rels: &'a [R],
        rule: RuleRef<'a>,
        order: Vec<usize>,
        ranges: Vec<(u32, u32)>,
    ) -> Join<'a, R> {
        let (nvars, nbody) = (rule.get().vars.len(), rule.get().body.len());
        Join {
            rels,
            rule,
            order,
            ranges,
            binds: vec![None; nvars],
            chosen: vec![0; nbody],
            neg: Vec::new(),
            trail: Vec::new(),
            out_terms: Vec::new(),
            out_prem: Vec::new(),
            emitted: 0,
            limit: usize::MAX,
            store: true,
            budget: JoinBudget::default(),
            frames: Vec::new(),
            started: false,
        }
    }

    /// Runs the join to the end (or to `limit` derivations), storing each
    /// derivation's head tuple and premises unless `store` is off.
    pub(crate) fn run(&mut self) {
        while self.emitted < self.limit && self.next_derivation() {
            self.emit();
        }
    }

    /// Advances to the next derivation: afterwards `binds` and `chosen`
    /// describe it. False when there is none left (or the budget ran out).
    pub(crate) fn next_derivation(&mut self) -> bool {
        let rule = self.rule.get();
        if !self.started {
            self.started = true;
            if self.order.is_empty() {
                return filters_hold(rule, self.rels, &self.binds, &mut self.neg);
            }
            match open_frame(self.rels, rule, &self.order, &self.ranges, &self.binds, 0, &self.trail) {
                Some(f) => self.frames.push(f),
                None => return false,
            }
        }
        loop {
            let depth = self.frames.len();
            let Some(frame) = self.frames.last_mut() else {
                return false;
            };
            // Undo what the previous candidate of this atom bound.
            for v in self.trail.drain(frame.mark..) {
                if let Some(slot) = self.binds.get_mut(v) {
                    *slot = None;
                }
            }
            let Some(id) = frame.next_id() else {
                self.frames.pop();
                continue;
            };
            if !self.budget.step() {
                self.frames.clear();
                return false;
            }
            let Some(&ai) = self.order.get(depth - 1) else {
                return false;
            };
            let (Some(atom), Some(rel)) = (
                rule.body.get(ai),
                rule.body.get(ai).and_then(|a| self.rels.get(a.pred)).map(Borrow::borrow),
            ) else {
                return false;
            };
            if !bind_tuple(atom, rel, id, &mut self.binds, &mut self.trail) {
                continue;
            }
            if let Some(c) = self.chosen.get_mut(ai) {
                *c = id;
            }
            if depth == self.order.len() {
                if filters_hold(rule, self.rels, &self.binds, &mut self.neg) {
                    return true;
                }
                continue;
            }
            if let Some(f) = open_frame(
                self.rels,
                rule,
                &self.order,
                &self.ranges,
                &self.binds,
                depth,
                &self.trail,
            ) {
                self.frames.push(f);
            }
        }
    }

    /// Records the current derivation (its head tuple and premises).
    fn emit(&mut self) {
        if !self.store {
            self.emitted += 1;
            return;
        }
        let start = self.out_terms.len();
        for a in &self.rule.get().head.args {
            match arg_value(a, &self.binds) {
                Some(t) => self.out_terms.push(t.clone()),
                None => {
                    self.out_terms.truncate(start);
                    return;
                }
            }
        }
        self.out_prem.extend_from_slice(&self.chosen);
        self.emitted += 1;
    }
}

/// The cursor of atom `order[depth]` under the current bindings: an index
/// probe for its bound arguments, cut to the atom's id range. `None` when
/// the atom or its relation is missing (the join then has no derivation
/// through it).
fn open_frame<'a, R: Borrow<Relation>>(
    rels: &'a [R],
    rule: &Rule,
    order: &[usize],
    ranges: &[(u32, u32)],
    binds: &[Option<Term>],
    depth: usize,
    trail: &[usize],
) -> Option<Frame<'a>> {
    let ai = *order.get(depth)?;
    let atom = rule.body.get(ai)?;
    let rel: &'a Relation = rels.get(atom.pred)?.borrow();
    let (lo, hi) = ranges.get(ai).copied().unwrap_or((0, 0));
    // The lookup pattern borrows the bound values; small arities use a
    // stack array so the inner loop does not allocate.
    let mut small: [Option<&Term>; 4] = [None; 4];
    let big: Vec<Option<&Term>>;
    let pat: &[Option<&Term>] = if atom.args.len() <= small.len() {
        for (slot, a) in small.iter_mut().zip(&atom.args) {
            *slot = arg_value(a, binds);
        }
        &small[..atom.args.len()]
    } else {
        big = atom.args.iter().map(|a| arg_value(a, binds)).collect();
        &big
    };
    Some(Frame {
        probe: rel.probe(pat).within(lo, hi),
        next: 0,
        mark: trail.len(),
    })
}

/// Binds the atom's variables to fact `id`, checking constants and
/// variables bound earlier (or earlier in the same atom). On failure the
/// bindings it made stay on the trail, for the caller's undo.
fn bind_tuple(
    atom: &CAtom,
    rel: &Relation,
    id: FactId,
    binds: &mut [Option<Term>],
    trail: &mut Vec<usize>,
) -> bool {
    let Some(tuple) = rel.tuple(id) else {
        return false;
    };
    for (a, t) in atom.args.iter().zip(tuple) {
        match a {
            CArg::Const(c) => {
                if c != t {
                    return false;
                }
            }
            CArg::Var(v) => match binds.get_mut(*v) {
                Some(Some(b)) => {
                    if b != t {
                        return false;
                    }
                }
                Some(slot @ None) => {
                    *slot = Some(t.clone());
                    trail.push(*v);
                }
                None => return false,
            },
        }
    }
    true
}

/// Whether the rule's comparisons hold and none of its negated atoms does,
/// under complete bindings.
fn filters_hold<R: Borrow<Relation>>(
    rule: &Rule,
    rels: &[R],
    binds: &[Option<Term>],
    neg: &mut Vec<Term>,
) -> bool {
    for (l, r, negated) in &rule.cmps {
        let (Some(a), Some(b)) = (arg_value(l, binds), arg_value(r, binds)) else {
            return false;
        };
        if (a == b) == *negated {
            return false;
        }
    }
    for n in &rule.negated {
        neg.clear();
        for a in &n.args {
            match arg_value(a, binds) {
                Some(t) => neg.push(t.clone()),
                None => return false,
            }
        }
        if rels.get(n.pred).is_some_and(|r| r.borrow().contains(neg)) {
            return false;
        }
    }
    true
}

/// Join order: the atom at `first` (if any), then repeatedly the atom with
/// the most bound arguments, ties broken by the smaller relation.
pub(crate) fn plan<R: Borrow<Relation>>(
    rule: &Rule,
    rels: &[R],
    first: Option<usize>,
) -> Vec<usize> {
    let n = rule.body.len();
    let mut bound = vec![false; rule.vars.len()];
    let mut order = Vec::with_capacity(n);
    let mut used = vec![false; n];
    let take = |i: usize, bound: &mut Vec<bool>, order: &mut Vec<usize>, used: &mut Vec<bool>| {
        used[i] = true;
        order.push(i);
        for a in &rule.body[i].args {
            if let CArg::Var(v) = a
                && let Some(b) = bound.get_mut(*v)
            {
                *b = true;
            }
        }
    };
    if let Some(f) = first.filter(|&f| f < n) {
        take(f, &mut bound, &mut order, &mut used);
    }
    while order.len() < n {
        // (no bound argument though it has some, unbound args, size, index):
        // prefer atoms connected to what is bound (an index lookup) over a
        // cross product, then the most bound, then the smallest relation.
        let mut best: Option<(bool, usize, usize, usize)> = None;
        for i in (0..n).filter(|&i| !used[i]) {
            let atom = &rule.body[i];
            let unbound = atom
                .args
                .iter()
                .filter(|a| matches!(a, CArg::Var(v) if !bound.get(*v).copied().unwrap_or(false)))
                .count();
            let disconnected = !order.is_empty() && unbound == atom.args.len() && unbound > 0;
            let size = rels.get(atom.pred).map_or(0, |r| r.borrow().len());
            let key = (disconnected, unbound, size, i);
            if best.is_none_or(|b| key < b) {
                best = Some(key);
            }
        }
        let Some((_, _, _, i)) = best else { break };
        take(i, &mut bound, &mut order, &mut used);
    }
    order
}

fn len32(r: &Relation) -> u32 {
    u32::try_from(r.len()).unwrap_or(u32::MAX)
}

impl Program {
    /// Reasons over `facts`: evaluates every component to its least fixpoint
    /// in stratification order, then checks the integrity constraints.
    /// Facts of predicates the program does not know are kept (and can be
    /// queried); a fact base relation whose arity differs from the
    /// LogicPad's declaration is an error.
    pub fn evaluate(&self, facts: FactBase) -> Result<Model, FactError> {
        let inner = &self.inner;
        let n = inner.names.len();
        let mut rels: Vec<Relation> = (0..n)
            .map(|p| Relation::new(inner.syms[p], inner.arity[p]))
            .collect();
        let mut names: HashMap<String, usize> = HashMap::new();
        for (name, rel) in facts.rels {
            match inner.by_name.get(&name) {
                Some(&p) => {
                    if rel.arity() != inner.arity[p] {
                        return Err(FactError::Arity {
                            pred: name,
                            expected: inner.arity[p],
                            got: rel.arity(),
                        });
                    }
                    rels[p] = rel;
                }
                None => {
                    names.insert(name, rels.len());
                    rels.push(rel);
                }
            }
        }
        let base_len: Vec<u32> = rels.iter().map(len32).collect();
        let mut just: Vec<Vec<Just>> = vec![Vec::new(); rels.len()];
        let mut premises: Vec<FactId> = Vec::new();
        let mut stats = EvalStats {
            base_facts: facts.count,
            ..EvalStats::default()
        };

        for (ci, comp) in inner.components.iter().enumerate() {
            let in_comp = |p: PredId| inner.comp_of.get(p) == Some(&ci);
            // Semi-naive state per predicate of the component: delta = lo..hi.
            let mut lo: HashMap<PredId, u32> = comp.preds.iter().map(|&p| (p, 0)).collect();
            let mut hi: HashMap<PredId, u32> =
                comp.preds.iter().map(|&p| (p, len32(&rels[p]))).collect();
            let mut first_round = true;
            loop {
                let mut produced = false;
                for &rid in &comp.rules {
                    let rule = &inner.rules[rid];
                    // Sparse windows: most rules have an empty body relation.
                    // (An empty relation of this component that fills later
                    // in the round is caught as next round's delta.)
                    if rule.body.iter().any(|a| rels[a.pred].is_empty()) {
                        continue;
                    }
                    let rec: Vec<usize> = (0..rule.body.len())
                        .filter(|&i| in_comp(rule.body[i].pred))
                        .collect();
                    // Variants: one per recursive body atom taking the delta;
                    // a non-recursive rule runs once, in the first round.
                    let variants: Vec<Option<usize>> = if rec.is_empty() {
                        if first_round { vec![None] } else { Vec::new() }
                    } else {
                        rec.iter().map(|&k| Some(k)).collect()
                    };
                    let mut out_terms = Vec::new();
                    let mut out_prem = Vec::new();
                    let mut emitted = 0;
                    for variant in variants {
                        let ranges: Vec<(u32, u32)> = rule
                            .body
                            .iter()
                            .enumerate()
                            .map(|(j, a)| {
                                let full = (0, len32(&rels[a.pred]));
                                match variant {
                                    None => full,
                                    Some(k) if in_comp(a.pred) => {
                                        let (l, h) = (lo[&a.pred], hi[&a.pred]);
                                        if j < k && rec.contains(&j) {
                                            (0, l)
                                        } else if j == k {
                                            (l, h)
                                        } else {
                                            (0, h)
                                        }
                                    }
                                    Some(_) => full,
                                }
                            })
                            .collect();
                        if ranges.iter().any(|(l, h)| l >= h) {
                            continue;
                        }
                        let mut join = Join::new(
                            &rels,
                            RuleRef::Borrowed(rule),
                            plan(rule, &rels, variant),
                            ranges,
                        );
                        join.out_terms = out_terms;
                        join.out_prem = out_prem;
                        join.run();
                        out_terms = join.out_terms;
                        out_prem = join.out_prem;
                        emitted += join.emitted;
                    }
                    let arity = rule.head.args.len();
                    let nb = rule.body.len();
                    let head = rule.head.pred;
                    // A propositional head (`Danger()`) has no terms: one
                    // empty tuple per derivation.
                    let tuples: Vec<&[Term]> = if arity == 0 {
                        vec![&[]; emitted]
                    } else {
                        out_terms.chunks(arity).collect()
                    };
                    for (k, tuple) in tuples.into_iter().enumerate() {
                        let (id, new) = rels[head].insert(tuple).map_err(|e| FactError::Store {
                            pred: inner.names[head].clone(),
                            message: e.to_string(),
                        })?;
                        if new {
                            produced = true;
                            stats.derived_facts += 1;
                            debug_assert_eq!(
                                id as usize,
                                base_len[head] as usize + just[head].len()
                            );
                            let start = u32::try_from(premises.len()).unwrap_or(u32::MAX);
                            premises.extend_from_slice(
                                out_prem.get(k * nb..(k + 1) * nb).unwrap_or(&[]),
                            );
                            just[head].push(Just {
                                rule: rid as u32,
                                start,
                                len: nb as u32,
                            });
                        }
                    }
                }
                first_round = false;
                if !comp.recursive || !produced {
                    break;
                }
                stats.rounds += 1;
                for &p in &comp.preds {
                    let h = hi[&p];
                    lo.insert(p, h);
                    hi.insert(p, len32(&rels[p]));
                }
            }
        }

        // Integrity constraints: every solution of `body ∧ head` is a violation.
        let mut violations = Vec::new();
        for c in &inner.constraints {
            let ranges: Vec<(u32, u32)> =
                c.body.iter().map(|a| (0, len32(&rels[a.pred]))).collect();
            let mut join = Join::new(&rels, RuleRef::Borrowed(c), plan(c, &rels, None), ranges);
            join.run();
            // One violation per derivation; a propositional head (`¬Danger()`)
            // has no terms, so count derivations rather than head tuples.
            let arity = c.head.args.len();
            let nb = c.body.len();
            for k in 0..join.emitted {
                let tuple = join
                    .out_terms
                    .get(k * arity..(k + 1) * arity)
                    .unwrap_or(&[]);
                let prem = join.out_prem.get(k * nb..(k + 1) * nb).unwrap_or(&[]);
                let binds = bind_from(c, |p| rels.get(p), prem);
                let mut bindings: Vec<(String, String)> = c
                    .vars
                    .iter()
                    .zip(&binds)
                    .filter_map(|(n, b)| b.as_ref().map(|t| (n.clone(), term_text(t))))
                    .collect();
                bindings.sort();
                let facts = c
                    .body
                    .iter()
                    .zip(prem)
                    .filter_map(|(a, &id)| {
                        let t = rels.get(a.pred)?.tuple(id)?;
                        Some(GroundAtom {
                            pred: inner.names.get(a.pred)?.clone(),
                            args: t.iter().map(term_text).collect(),
                        })
                    })
                    .collect();
                violations.push(Violation {
                    facts,
                    constraint: c.id,
                    rule_text: c.source.text.clone(),
                    rule_line: c.source.line,
                    atom: GroundAtom {
                        pred: inner.names[c.head.pred].clone(),
                        args: tuple.iter().map(term_text).collect(),
                    },
                    bindings,
                });
            }
        }
        violations.sort_by(|a, b| (a.constraint, &a.atom).cmp(&(b.constraint, &b.atom)));
        violations.dedup();

        Ok(Model {
            program: self.clone(),
            rels: rels.into_iter().map(Arc::new).collect(),
            names,
            base_len,
            just,
            premises,
            violations,
            stats,
        })
    }
}

/// The text of a constant term.
pub(crate) fn term_text(t: &Term) -> String {
    match t {
        Term::Sym(s) => s.as_str().to_string(),
        other => other.to_string(),
    }
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

    pub(crate) fn name_of(&self, index: usize) -> String {
        self.rels
            .get(index)
            .map_or_else(String::new, |r| r.name().as_str().to_string())
    }

    /// The program that produced this model.
    pub fn program(&self) -> &Program {
        &self.program
    }

    /// True when the fact holds (given or derived).
    pub fn holds(&self, pred: &str, args: &[&str]) -> bool {
        let terms: Vec<Term> = args.iter().map(|a| Term::Sym(Sym::new(a))).collect();
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
        let terms: Vec<Term> = args.iter().map(|a| Term::Sym(Sym::new(a))).collect();
        let id = self.rels.get(i)?.id_of(&terms)?;
        self.explain_id(i, id, limits, limits.max_nodes)
    }

    /// Fact `id` of relation `index`, written out.
    fn ground_atom(&self, index: usize, id: FactId) -> Option<GroundAtom> {
        let tuple = self.rels.get(index)?.tuple(id)?;
        Some(GroundAtom {
            pred: self.name_of(index),
            args: tuple.iter().map(term_text).collect(),
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
                Plan::Base => DerivationTree::Base(fact),
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
                    .map(|a| arg_value(a, &binds).map_or_else(|| "?".into(), term_text))
                    .collect(),
            })
            .collect()
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
            pred: pred.to_string(),
            args: args.iter().map(|a| a.to_string()).collect(),
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
        assert_eq!(cut.fact(), &atom("Reach", &["a", "y"]));
        assert_eq!(cut.size(), 1);
        assert!(cut.is_truncated());
        let tree = DerivationTree::Derived {
            fact: atom("Reach", &["a", "z"]),
            rule: 1,
            rule_text: "Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)".into(),
            rule_line: 7,
            premises: vec![
                cut,
                DerivationTree::Base(atom("Edge", &["y", "z"])),
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
        assert!(!DerivationTree::Base(atom("Edge", &["y", "z"])).is_truncated());
        assert_eq!(ProofLimits::default().max_depth, 64);
        assert_eq!(ProofLimits::default().max_nodes, 10_000);
    }
}
