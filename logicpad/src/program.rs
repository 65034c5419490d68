//! Compiled rules: predicates numbered, constants interned, rules grouped
//! into recursive components in evaluation (stratification) order.

use crate::diag::Span;
use crate::fol::{Arg, Atom, Literal};
use crate::schema::{PredKind, Schema};
use kanren::{Sym, Term};
use rustc_hash::FxHashMap as HashMap;
use std::fmt;
use std::sync::Arc;

/// Index of a predicate in a [`Program`] (its position in the sorted schema).
pub type PredId = usize;
/// Index of a rule in [`Program::rules`].
pub type RuleId = usize;

/// Where a rule was written.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct RuleSource {
    /// The `name:` of the derived-predicate entry it belongs to.
    pub entry: String,
    /// The rule text as written; shared, since every proof step through
    /// the rule names it.
    pub text: std::sync::Arc<str>,
    /// 1-based line in the LogicPad file.
    pub line: usize,
    /// Span of the rule text in the file.
    pub span: Span,
}

/// A checked rule before compilation (one head, one conjunctive body).
#[derive(Debug, Clone)]
pub struct SourceRule {
    /// Where it came from.
    pub source: RuleSource,
    /// The head (for a constraint: the atom that must not hold).
    pub head: Atom,
    /// Body literals.
    pub body: Vec<Literal>,
    /// Variable names, indexed by `Arg::Var`.
    pub vars: Vec<String>,
    /// True for `body ==> ¬head` (an integrity constraint).
    pub constraint: bool,
}

/// A compiled argument: a variable slot or a constant (always a
/// `Term::Sym`) — kanren's join argument, so that rules run as kanren joins.
pub type CArg = kanren::join::Arg;

/// A compiled atom: predicate (`pred`, a [`PredId`]) and arguments.
pub type CAtom = kanren::join::Atom;

/// A compiled rule `head :- body, ¬negated, cmps`.
///
/// Invariants (established by the checker): every variable of `head`,
/// `negated` and `cmps` occurs in `body`; every predicate in `negated` lies in
/// an earlier component than the head (stratification).
#[derive(Debug, Clone)]
pub struct Rule {
    /// Position in [`Program::rules`] (or [`Program::constraints`]).
    pub id: RuleId,
    /// The derived atom (for a constraint: the atom that must not hold).
    pub head: CAtom,
    /// Positive body atoms (for a constraint this includes the head atom last).
    /// Shared, so that a query's kanren goal takes it without a copy.
    pub body: std::sync::Arc<[CAtom]>,
    /// Atoms that must be absent.
    pub negated: Vec<CAtom>,
    /// `(a, b, negated)`: `a = b` or `a ≠ b`.
    pub cmps: Vec<(CArg, CArg, bool)>,
    /// Variable names.
    pub vars: Vec<String>,
    /// Where it was written.
    pub source: RuleSource,
}

impl Rule {
    /// The body as kanren's join sees it.
    pub fn join_body(&self) -> kanren::join::Body<'_> {
        kanren::join::Body {
            atoms: &self.body,
            negated: &self.negated,
            cmps: &self.cmps,
        }
    }
}

impl fmt::Display for Rule {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.source.text)
    }
}

/// A set of mutually recursive derived predicates and the rules for them,
/// evaluated together to a fixpoint.
#[derive(Debug, Clone)]
pub struct Component {
    /// The predicates defined here.
    pub preds: Vec<PredId>,
    /// The rules whose head is one of `preds`.
    pub rules: Vec<RuleId>,
    /// True when some rule's body uses a predicate of this component.
    pub recursive: bool,
}

#[derive(Debug)]
pub(crate) struct Inner {
    pub schema: Arc<Schema>,
    pub names: Vec<String>,
    pub syms: Vec<Sym>,
    pub arity: Vec<usize>,
    pub by_name: HashMap<String, PredId>,
    pub rules: Vec<Rule>,
    pub constraints: Vec<Rule>,
    pub components: Vec<Component>,
    pub comp_of: Vec<usize>,
}

/// The stratified program of a LogicPad. Cheap to clone.
#[derive(Debug, Clone)]
pub struct Program {
    pub(crate) inner: Arc<Inner>,
}

fn carg(a: &Arg) -> CArg {
    match a {
        Arg::Var(v) => CArg::Var(*v),
        Arg::Const(c) => CArg::Const(Term::Sym(Sym::new(c))),
    }
}

impl Program {
    /// Compiles checked rules. Predicates are numbered in the schema's
    /// (sorted) order; rules that mention a predicate missing from the schema
    /// are skipped (the loader never produces such rules).
    pub fn build(schema: Arc<Schema>, rules: Vec<SourceRule>) -> Program {
        let names: Vec<String> = schema.predicates().map(|p| p.name.clone()).collect();
        let arity: Vec<usize> = schema.predicates().map(|p| p.arity).collect();
        let syms: Vec<Sym> = names.iter().map(|n| Sym::new(n)).collect();
        let by_name: HashMap<String, PredId> = names
            .iter()
            .enumerate()
            .map(|(i, n)| (n.clone(), i))
            .collect();
        let catom = |a: &Atom| {
            by_name.get(&a.pred).map(|&p| CAtom {
                pred: p,
                args: a.args.iter().map(carg).collect(),
            })
        };
        let mut compiled = Vec::new();
        let mut constraints = Vec::new();
        'rules: for r in rules {
            let Some(head) = catom(&r.head) else { continue };
            let mut body = Vec::new();
            let mut negated = Vec::new();
            let mut cmps = Vec::new();
            for l in &r.body {
                match l {
                    Literal::Pos(a) => match catom(a) {
                        Some(c) => body.push(c),
                        None => continue 'rules,
                    },
                    Literal::Neg(a) => match catom(a) {
                        Some(c) => negated.push(c),
                        None => continue 'rules,
                    },
                    Literal::Cmp {
                        left,
                        right,
                        negated: n,
                        ..
                    } => cmps.push((carg(left), carg(right), *n)),
                    // Rules never hold one (the loader refuses `¬∃` in a
                    // rule body); a rule built by hand with one is skipped
                    // rather than read as something weaker.
                    Literal::NotExists { .. } => continue 'rules,
                }
            }
            // A constraint `body ==> ¬head` is checked as a rule whose body
            // also holds the forbidden head.
            let target = if r.constraint {
                body.push(head.clone());
                &mut constraints
            } else {
                &mut compiled
            };
            target.push(Rule {
                id: target.len(),
                head,
                body: body.into(),
                negated,
                cmps,
                vars: r.vars,
                source: r.source,
            });
        }
        // Dependency graph head -> body predicates; components in dependency order.
        let mut edges = vec![Vec::new(); names.len()];
        for r in &compiled {
            for a in r.body.iter().chain(&r.negated) {
                edges[r.head.pred].push(a.pred);
            }
        }
        let comps = scc_list(&edges);
        let mut comp_of = vec![0; names.len()];
        for (ci, c) in comps.iter().enumerate() {
            for &p in c {
                comp_of[p] = ci;
            }
        }
        let mut components: Vec<Component> = comps
            .into_iter()
            .map(|preds| Component {
                preds,
                rules: Vec::new(),
                recursive: false,
            })
            .collect();
        for r in &compiled {
            let c = comp_of[r.head.pred];
            components[c].rules.push(r.id);
            if r.body.iter().any(|a| comp_of[a.pred] == c) {
                components[c].recursive = true;
            }
        }
        components.retain(|c| !c.rules.is_empty());
        let comp_of = {
            let mut v = vec![usize::MAX; names.len()];
            for (ci, c) in components.iter().enumerate() {
                for &p in &c.preds {
                    v[p] = ci;
                }
            }
            v
        };
        Program {
            inner: Arc::new(Inner {
                schema,
                names,
                syms,
                arity,
                by_name,
                rules: compiled,
                constraints,
                components,
                comp_of,
            }),
        }
    }

    /// The schema the program was compiled against.
    pub fn schema(&self) -> &Schema {
        &self.inner.schema
    }
    /// The rules (not constraints), in file order.
    pub fn rules(&self) -> &[Rule] {
        &self.inner.rules
    }
    /// The integrity constraints (rules with a negated head).
    pub fn constraints(&self) -> &[Rule] {
        &self.inner.constraints
    }
    /// Components in evaluation order (each only depends on earlier ones).
    pub fn components(&self) -> &[Component] {
        &self.inner.components
    }
    /// Number of predicates.
    pub fn num_preds(&self) -> usize {
        self.inner.names.len()
    }
    /// A weak reference to the program's shared state, for [`Program::is`].
    pub(crate) fn downgrade(&self) -> std::sync::Weak<Inner> {
        Arc::downgrade(&self.inner)
    }
    /// Whether `w` refers to this program (or a clone of it).
    pub(crate) fn is(&self, w: &std::sync::Weak<Inner>) -> bool {
        std::ptr::eq(w.as_ptr(), Arc::as_ptr(&self.inner))
    }
    /// Predicate id of a name.
    pub fn pred_id(&self, name: &str) -> Option<PredId> {
        self.inner.by_name.get(name).copied()
    }
    /// Name of a predicate id.
    pub fn pred_name(&self, id: PredId) -> Option<&str> {
        self.inner.names.get(id).map(String::as_str)
    }
    /// Arity of a predicate id.
    pub fn arity(&self, id: PredId) -> Option<usize> {
        self.inner.arity.get(id).copied()
    }
    /// Stratum (component index) of a derived predicate; `None` for a
    /// predicate no rule defines.
    pub fn stratum(&self, id: PredId) -> Option<usize> {
        self.inner
            .comp_of
            .get(id)
            .copied()
            .filter(|&c| c != usize::MAX)
    }
    /// True when the predicate is a rule head.
    pub fn is_derived(&self, id: PredId) -> bool {
        self.stratum(id).is_some()
    }
    /// Kind in the schema.
    pub fn kind(&self, id: PredId) -> Option<PredKind> {
        self.pred_name(id).and_then(|n| self.inner.schema.kind(n))
    }
}

/// Strongly connected components (Tarjan, iterative), listed so that every
/// component comes after all components it has edges to.
pub(crate) fn scc_list(edges: &[Vec<usize>]) -> Vec<Vec<usize>> {
    let n = edges.len();
    let mut index = vec![usize::MAX; n];
    let mut low = vec![0; n];
    let mut on_stack = vec![false; n];
    let mut stack = Vec::new();
    let mut out = Vec::new();
    let mut next = 0;
    for root in 0..n {
        if index[root] != usize::MAX {
            continue;
        }
        let mut call: Vec<(usize, usize)> = vec![(root, 0)];
        index[root] = next;
        low[root] = next;
        next += 1;
        stack.push(root);
        on_stack[root] = true;
        while let Some(&mut (v, ref mut ei)) = call.last_mut() {
            if let Some(&w) = edges[v].get(*ei) {
                *ei += 1;
                if index[w] == usize::MAX {
                    index[w] = next;
                    low[w] = next;
                    next += 1;
                    stack.push(w);
                    on_stack[w] = true;
                    call.push((w, 0));
                } else if on_stack[w] {
                    low[v] = low[v].min(index[w]);
                }
            } else {
                call.pop();
                if let Some(&(u, _)) = call.last() {
                    low[u] = low[u].min(low[v]);
                }
                if low[v] == index[v] {
                    let mut comp = Vec::new();
                    while let Some(w) = stack.pop() {
                        on_stack[w] = false;
                        comp.push(w);
                        if w == v {
                            break;
                        }
                    }
                    comp.sort_unstable();
                    out.push(comp);
                }
            }
        }
    }
    out
}

/// Component number of every node (same numbering as [`scc_list`]).
pub(crate) fn scc_ids(edges: &[Vec<usize>]) -> Vec<usize> {
    let mut ids = vec![0; edges.len()];
    for (ci, c) in scc_list(edges).iter().enumerate() {
        for &p in c {
            ids[p] = ci;
        }
    }
    ids
}
