//! Asking a window: a query (or a question, through the translator) becomes
//! one of four outcomes that are never confused — **yes** with every binding
//! and its proof, **no** with why-not, **unknown** when the source cannot
//! observe what the query needs, **invalid** when the query does not fit the
//! LogicPad.

use crate::kb::{Observed, WindowKb};
use kanren::RunConfig;
use logicpad::fol::{Arg, Literal};
use logicpad::{LogicPad, QueryAnswer, QueryAst, check_query, parse_query};
use serde::Serialize;
use std::collections::BTreeMap;

/// The four outcomes.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Outcome {
    /// At least one binding satisfies the query; each comes with a proof.
    Yes,
    /// No binding does, and the source observes everything the query needs.
    No,
    /// No binding was found, but the query needs something this source
    /// cannot observe, so "no" would be a guess.
    Unknown,
    /// The query does not fit the LogicPad (syntax, unknown predicate, arity,
    /// undeclared value, unsafe negation).
    Invalid,
}

impl Outcome {
    /// `"yes"`, `"no"`, `"unknown"` or `"invalid"`.
    pub fn as_str(self) -> &'static str {
        match self {
            Outcome::Yes => "yes",
            Outcome::No => "no",
            Outcome::Unknown => "unknown",
            Outcome::Invalid => "invalid",
        }
    }
    /// The metric view of this outcome.
    pub fn said(self) -> crate::metrics::Said {
        use crate::metrics::Said;
        match self {
            Outcome::Yes => Said::Yes,
            Outcome::No => Said::No,
            Outcome::Unknown => Said::Unknown,
            Outcome::Invalid => Said::Invalid,
        }
    }
}

/// One candidate object of a "no" answer and the conjuncts it fails.
#[derive(Debug, Clone, PartialEq, Eq, Serialize)]
pub struct WhyNot {
    /// The query variable.
    pub variable: String,
    /// The candidate constant.
    pub candidate: String,
    /// Conjuncts (with the candidate substituted) that hold.
    pub satisfied: Vec<String>,
    /// Conjuncts that fail.
    pub failed: Vec<String>,
}

/// The answer to one query on one window.
#[derive(Debug, Clone, Serialize)]
pub struct AskResult {
    /// Window id.
    pub window: String,
    /// The query as run.
    pub query: String,
    /// The outcome.
    pub answer: Outcome,
    /// The query's answer variables, in order (empty for a ground query or
    /// one that did not parse).
    pub variables: Vec<String>,
    /// Number of distinct bindings of the answer variables.
    pub count: usize,
    /// Bindings, sorted (each a list of `(variable, constant)`).
    pub bindings: Vec<Vec<(String, String)>>,
    /// One proof per binding, rendered as indented lines with provenance
    /// (empty when proofs were not asked for).
    pub proofs: Vec<Vec<String>>,
    /// For `no`: the best candidates and what they fail.
    pub why_not: Vec<WhyNot>,
    /// For `unknown`: which predicates the source cannot observe; for
    /// `invalid`: the diagnostics.
    pub reasons: Vec<String>,
}

/// How to ask.
#[derive(Debug, Clone, Copy)]
pub struct AskOptions {
    /// Record and render proofs.
    pub proofs: bool,
    /// Compute why-not explanations for "no".
    pub why_not: bool,
    /// Only count the bindings (batch answers); implies no proofs.
    pub count_only: bool,
}

impl Default for AskOptions {
    fn default() -> Self {
        AskOptions {
            proofs: true,
            why_not: true,
            count_only: false,
        }
    }
}

impl AskOptions {
    /// Bindings without proofs or why-not.
    pub const BINDINGS: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: false,
    };
    /// Counts only (the KB benchmark's answers).
    pub const COUNT: AskOptions = AskOptions {
        proofs: false,
        why_not: false,
        count_only: true,
    };
}

/// Parses and validates a query for a window (its objects are constants).
pub fn prepare(pad: &LogicPad, kb: &WindowKb, query: &str) -> Result<QueryAst, Vec<String>> {
    let is_const = |s: &str| kb.is_constant(s);
    let ast = parse_query(query, &is_const).map_err(|d| vec![d.render_plain(REASON_WIDTH)])?;
    let diags = check_query(pad.schema(), &ast);
    let errors: Vec<String> = diags
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.render_plain(REASON_WIDTH))
        .collect();
    if errors.is_empty() {
        Ok(ast)
    } else {
        Err(errors)
    }
}

/// Runs a query on a window. `observed` is the source's observability of
/// every predicate (from [`crate::kb::Observability::classify`]).
pub fn ask(
    pad: &LogicPad,
    kb: &WindowKb,
    observed: &BTreeMap<String, Observed>,
    query: &str,
    opts: AskOptions,
) -> AskResult {
    let mut result = AskResult {
        window: kb.id.clone(),
        query: query.to_string(),
        answer: Outcome::Invalid,
        variables: Vec::new(),
        count: 0,
        bindings: Vec::new(),
        proofs: Vec::new(),
        why_not: Vec::new(),
        reasons: Vec::new(),
    };
    let ast = match prepare(pad, kb, query) {
        Ok(a) => a,
        Err(reasons) => {
            result.reasons = reasons;
            return result;
        }
    };
    result.variables = ast
        .answer_var_names()
        .into_iter()
        .map(str::to_string)
        .collect();
    ask_prepared(pad, kb, observed, &ast, opts, result)
}

fn ask_prepared(
    pad: &LogicPad,
    kb: &WindowKb,
    observed: &BTreeMap<String, Observed>,
    ast: &QueryAst,
    opts: AskOptions,
    mut result: AskResult,
) -> AskResult {
    // With proofs the query runs as kanren goals and each answer carries
    // its derivation; without, logicpad's index joins give the same answer
    // set (a property test holds them equal) at a fraction of the cost.
    let answers: Result<(usize, Vec<QueryAnswer>), logicpad::AskError> = if opts.count_only {
        kb.model.count(ast).map(|n| (n, Vec::new()))
    } else if !opts.proofs {
        kb.model.bindings(ast).map(|b| {
            (
                b.len(),
                b.into_iter()
                    .map(|bindings| QueryAnswer {
                        bindings,
                        proof: Vec::new(),
                    })
                    .collect(),
            )
        })
    } else {
        kb.model
            .ask(
                ast,
                RunConfig {
                    proofs: true,
                    ..RunConfig::default()
                },
            )
            .map(|a| (a.len(), a))
    };
    let (count, answers) = match answers {
        Ok(a) => a,
        Err(e) => {
            result.answer = Outcome::Invalid;
            result.reasons = vec![e.to_string()];
            return result;
        }
    };
    // Negated atoms over predicates the source does not fully observe make
    // even a found binding a guess.
    let mut blind_neg = Vec::new();
    let mut blind_pos = Vec::new();
    for lit in ast.disjuncts.iter().flatten() {
        let (atom, neg) = match lit {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => continue,
        };
        let s = observed.get(&atom.pred).copied().unwrap_or(Observed::Never);
        if s != Observed::Fully {
            let why = match s {
                Observed::Never if has_no_rule(pad, &atom.pred) => format!(
                    "`{}` is derived but none of its rules loaded (the LogicPad has errors; \
                     `logicrag lint` shows them)",
                    atom.pred
                ),
                Observed::Never => format!("this source cannot observe `{}`", atom.pred),
                _ => format!("this source observes `{}` only in part", atom.pred),
            };
            if neg {
                blind_neg.push(why)
            } else {
                blind_pos.push(why)
            }
        }
    }
    if !blind_neg.is_empty() {
        result.answer = Outcome::Unknown;
        blind_neg.sort();
        blind_neg.dedup();
        result.reasons = blind_neg;
        return result;
    }
    if count == 0 {
        if blind_pos.is_empty() {
            result.answer = Outcome::No;
            if opts.why_not {
                result.why_not = why_not(kb, ast);
            }
        } else {
            result.answer = Outcome::Unknown;
            blind_pos.sort();
            blind_pos.dedup();
            result.reasons = blind_pos;
        }
        return result;
    }
    result.answer = Outcome::Yes;
    result.count = count;
    for a in &answers {
        result.bindings.push(a.bindings.clone());
        if opts.proofs {
            result.proofs.push(render_proof(kb, a));
        }
    }
    result
}

/// Width the diagnostics in `reasons` are rendered at: wide enough that no
/// message or help line wraps, since the RAG context reads them back line
/// by line (at 100 columns a long predicate name fell off its line).
const REASON_WIDTH: usize = 10_000;

/// Whether `pred` is a derived predicate without a single loaded rule: its
/// rules were rejected, so "unknown" is the LogicPad's fault, not the
/// source's.
fn has_no_rule(pad: &LogicPad, pred: &str) -> bool {
    let derived = pad
        .schema()
        .predicates()
        .any(|p| p.name == pred && p.kind == logicpad::PredKind::Derived);
    let program = pad.program();
    derived
        && program
            .pred_id(pred)
            .is_none_or(|id| program.rules().iter().all(|r| r.head.pred != id))
}

/// Renders an answer's proof as indented lines, base facts with provenance.
pub fn render_proof(kb: &WindowKb, answer: &QueryAnswer) -> Vec<String> {
    let mut lines = Vec::new();
    for tree in &answer.proof {
        render_tree(kb, tree, 0, &mut lines);
    }
    lines
}

fn render_tree(
    kb: &WindowKb,
    tree: &logicpad::DerivationTree,
    depth: usize,
    out: &mut Vec<String>,
) {
    use logicpad::DerivationTree as T;
    let pad = "  ".repeat(depth);
    match tree {
        T::Base(a) => {
            let prov = kb
                .provenance(&a.pred, &a.args)
                .map(|p| format!("  [fact: {}]", describe_provenance(p)))
                .unwrap_or_else(|| "  [fact]".to_string());
            out.push(format!("{pad}{a}{prov}"));
        }
        T::Absent(a) => out.push(format!("{pad}¬{a}  [no such fact: closed world]")),
        // The fact holds; its proof was cut by logicpad's ProofLimits.
        T::Truncated { fact, reason } => out.push(format!("{pad}{fact}  [proof cut: {reason}]")),
        T::Derived {
            fact,
            rule_text,
            rule_line,
            premises,
            absent,
            ..
        } => {
            out.push(format!(
                "{pad}{fact}  [rule, line {rule_line}: {rule_text}]"
            ));
            for p in premises {
                render_tree(kb, p, depth + 1, out);
            }
            for a in absent {
                out.push(format!("{pad}  ¬{a}  [no such fact: closed world]"));
            }
        }
    }
}

/// One line saying where a fact came from.
pub fn describe_provenance(p: &perception::Provenance) -> String {
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

/// Why-not for a failed conjunctive query: for each answer variable, the
/// window's objects that satisfy the most conjuncts mentioning only that
/// variable (with the others existential), and the conjuncts they fail.
fn why_not(kb: &WindowKb, ast: &QueryAst) -> Vec<WhyNot> {
    let Some(conj) = ast.disjuncts.first() else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for &v in &ast.answer_vars {
        let name = ast.vars.get(v).cloned().unwrap_or_default();
        let mentions: Vec<&Literal> = conj
            .iter()
            .filter(|l| literal_vars(l).contains(&v))
            .collect();
        if mentions.is_empty() {
            continue;
        }
        let mut scored: Vec<(usize, WhyNot)> = Vec::new();
        for obj in &kb.objects {
            let mut satisfied = Vec::new();
            let mut failed = Vec::new();
            for lit in &mentions {
                let text = literal_text(lit, ast, Some((v, obj)));
                if literal_holds(kb, lit, ast, v, obj) {
                    satisfied.push(text);
                } else {
                    failed.push(text);
                }
            }
            if failed.is_empty() && !satisfied.is_empty() {
                // Every part holds on its own; what fails is the join
                // through the other variables.
                failed.push(format!(
                    "{} together (no common binding of the other variables)",
                    satisfied.join(" ∧ ")
                ));
            }
            if !satisfied.is_empty() {
                scored.push((
                    satisfied.len(),
                    WhyNot {
                        variable: name.clone(),
                        candidate: obj.clone(),
                        satisfied,
                        failed,
                    },
                ));
            }
        }
        scored.sort_by(|a, b| {
            b.0.cmp(&a.0)
                .then_with(|| a.1.candidate.cmp(&b.1.candidate))
        });
        out.extend(scored.into_iter().take(3).map(|(_, w)| w));
    }
    out
}

fn literal_vars(l: &Literal) -> Vec<usize> {
    let args: Vec<&Arg> = match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().collect(),
        Literal::Cmp { left, right, .. } => vec![left, right],
    };
    args.into_iter()
        .filter_map(|a| if let Arg::Var(v) = a { Some(*v) } else { None })
        .collect()
}

fn arg_text(a: &Arg, ast: &QueryAst, subst: Option<(usize, &str)>) -> String {
    match a {
        Arg::Var(v) => match subst {
            Some((sv, c)) if sv == *v => c.to_string(),
            _ => ast.vars.get(*v).cloned().unwrap_or_default(),
        },
        Arg::Const(c) => c.clone(),
    }
}

/// A literal as query text, optionally with one variable replaced.
pub fn literal_text(l: &Literal, ast: &QueryAst, subst: Option<(usize, &str)>) -> String {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => {
            let args: Vec<String> = a.args.iter().map(|x| arg_text(x, ast, subst)).collect();
            let neg = if matches!(l, Literal::Neg(_)) {
                "¬"
            } else {
                ""
            };
            format!("{neg}{}({})", a.pred, args.join(", "))
        }
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => {
            let op = if *negated { "≠" } else { "=" };
            format!(
                "{} {op} {}",
                arg_text(left, ast, subst),
                arg_text(right, ast, subst)
            )
        }
    }
}

/// Whether one literal holds with variable `v` set to `obj` (other
/// variables existential; a negated literal with other free variables is
/// read as "no binding of them makes the atom hold").
fn literal_holds(kb: &WindowKb, l: &Literal, ast: &QueryAst, v: usize, obj: &str) -> bool {
    let (atom, neg) = match l {
        Literal::Pos(a) => (a, false),
        Literal::Neg(a) => (a, true),
        Literal::Cmp {
            left,
            right,
            negated,
            ..
        } => {
            // Another free variable on either side is existential: the
            // comparison alone cannot rule `obj` out (its name is not a
            // constant to compare with).
            let free = |a: &Arg| matches!(a, Arg::Var(x) if *x != v);
            if free(left) || free(right) {
                return true;
            }
            let eq = arg_text(left, ast, Some((v, obj))) == arg_text(right, ast, Some((v, obj)));
            return eq != *negated;
        }
    };
    let Some(rel) = kb.model.relation(&atom.pred) else {
        return neg;
    };
    let terms: Vec<Option<kanren::Term>> = atom
        .args
        .iter()
        .map(|a| match a {
            Arg::Var(x) if *x == v => Some(kanren::sym(obj)),
            Arg::Var(_) => None,
            Arg::Const(c) => Some(kanren::sym(c)),
        })
        .collect();
    let pattern: Vec<Option<&kanren::Term>> = terms.iter().map(Option::as_ref).collect();
    let found = rel.lookup(&pattern).into_iter().next().is_some();
    found != neg
}
