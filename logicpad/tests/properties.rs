//! Property tests: on random stratified programs and random facts, the
//! evaluator agrees with a naive bottom-up evaluator written here; permuting
//! rules or body literals changes nothing; every derived fact's proof checks
//! out against the rules and the facts.

use logicpad::{CArg, DerivationTree, FactBase, LogicPad, Model, Program};
use proptest::prelude::*;
use std::borrow::Cow;
use std::collections::{BTreeMap, BTreeSet};

const CONSTS: [&str; 4] = ["Ka", "Kb", "Kc", "Kd"];
const VARS: [&str; 3] = ["x", "y", "z"];
const BASE: [(&str, usize); 3] = [("B0", 1), ("B1", 2), ("B2", 1)];
const NDERIVED: usize = 6;

mod common;
use common::Rng;

#[derive(Clone, Debug, PartialEq)]
enum T {
    V(usize),
    C(usize),
}
#[derive(Clone, Debug)]
struct A {
    pred: String,
    args: Vec<T>,
}
#[derive(Clone, Debug)]
enum L {
    Pos(A),
    Neg(A),
    Neq(usize, usize),
}
#[derive(Clone, Debug)]
struct R {
    head: A,
    body: Vec<L>,
}

fn stratum(d: usize) -> usize {
    d / 2
}

fn gen_program(seed: u64) -> (Vec<usize>, Vec<R>) {
    let mut g = Rng(seed | 1);
    let arity: Vec<usize> = (0..NDERIVED).map(|_| 1 + g.below(2)).collect();
    let mut rules = Vec::new();
    for d in 0..NDERIVED {
        for _ in 0..1 + g.below(3) {
            let mut body = Vec::new();
            let mut bound = BTreeSet::new();
            for _ in 0..1 + g.below(3) {
                // Positive atoms: base, or derived of the same or a lower stratum.
                let (pred, ar) = if g.chance(1, 2) {
                    let (p, a) = BASE[g.below(BASE.len())];
                    (p.to_string(), a)
                } else {
                    let cands: Vec<usize> = (0..NDERIVED)
                        .filter(|&j| stratum(j) <= stratum(d))
                        .collect();
                    let j = cands[g.below(cands.len())];
                    (format!("D{j}"), arity[j])
                };
                let args: Vec<T> = (0..ar)
                    .map(|_| {
                        if g.chance(4, 5) {
                            T::V(g.below(VARS.len()))
                        } else {
                            T::C(g.below(CONSTS.len()))
                        }
                    })
                    .collect();
                for a in &args {
                    if let T::V(v) = a {
                        bound.insert(*v);
                    }
                }
                body.push(L::Pos(A { pred, args }));
            }
            let bound: Vec<usize> = bound.into_iter().collect();
            let pick = |g: &mut Rng| {
                if !bound.is_empty() && g.chance(4, 5) {
                    T::V(bound[g.below(bound.len())])
                } else {
                    T::C(g.below(CONSTS.len()))
                }
            };
            for _ in 0..g.below(2) + usize::from(g.chance(1, 8)) {
                // Negated atoms: base, or derived of a strictly lower stratum.
                let cands: Vec<(String, usize)> = BASE
                    .iter()
                    .map(|(p, a)| (p.to_string(), *a))
                    .chain(
                        (0..NDERIVED)
                            .filter(|&j| stratum(j) < stratum(d))
                            .map(|j| (format!("D{j}"), arity[j])),
                    )
                    .collect();
                let (pred, ar) = cands[g.below(cands.len())].clone();
                let args = (0..ar).map(|_| pick(&mut g)).collect();
                body.push(L::Neg(A { pred, args }));
            }
            if bound.len() >= 2 && g.chance(1, 4) {
                body.push(L::Neq(bound[0], bound[1]));
            }
            let head = A {
                pred: format!("D{d}"),
                args: (0..arity[d]).map(|_| pick(&mut g)).collect(),
            };
            rules.push(R { head, body });
        }
    }
    (arity, rules)
}

fn gen_facts(seed: u64) -> Vec<(String, Vec<String>)> {
    let mut g = Rng(seed.wrapping_mul(0x9E37_79B9_7F4A_7C15) | 1);
    let mut out = Vec::new();
    for (p, ar) in BASE {
        let n = CONSTS.len().pow(ar as u32);
        for i in 0..n {
            if g.chance(3, 5) {
                let args = (0..ar)
                    .map(|k| CONSTS[(i / CONSTS.len().pow(k as u32)) % CONSTS.len()].to_string())
                    .collect();
                out.push((p.to_string(), args));
            }
        }
    }
    out
}

fn term(t: &T) -> String {
    match t {
        T::V(v) => VARS[*v].to_string(),
        T::C(c) => CONSTS[*c].to_string(),
    }
}
fn atom(a: &A) -> String {
    format!(
        "{}({})",
        a.pred,
        a.args.iter().map(term).collect::<Vec<_>>().join(", ")
    )
}

/// LogicPad YAML for the rules, entries and rules in the given order.
fn yaml(rules: &[R]) -> String {
    let mut s = String::from("atomic_predicates:\n  base:\n");
    for (p, a) in BASE {
        s.push_str(&format!("    - {p}({})\n", VARS[..a].join(", ")));
    }
    s.push_str("derived_predicates:\n");
    for r in rules {
        let body: Vec<String> = r
            .body
            .iter()
            .map(|l| match l {
                L::Pos(a) => atom(a),
                L::Neg(a) => format!("¬{}", atom(a)),
                L::Neq(a, b) => format!("{} ≠ {}", VARS[*a], VARS[*b]),
            })
            .collect();
        s.push_str(&format!(
            "  - name: {}\n    logic: \"∀x,y,z : {} ==> {}\"\n",
            r.head.pred,
            body.join(" ∧ "),
            atom(&r.head)
        ));
    }
    s
}

type Db = BTreeMap<String, BTreeSet<Vec<String>>>;

/// The naive evaluator: stratum by stratum, try every assignment of every
/// rule's variables over the constants until nothing changes.
fn naive(rules: &[R], facts: &[(String, Vec<String>)]) -> Db {
    let mut db: Db = BTreeMap::new();
    for (p, a) in facts {
        db.entry(p.clone()).or_default().insert(a.clone());
    }
    let inst = |a: &A, asg: &[usize]| -> Vec<String> {
        a.args
            .iter()
            .map(|t| match t {
                T::V(v) => CONSTS[asg[*v]].to_string(),
                T::C(c) => CONSTS[*c].to_string(),
            })
            .collect()
    };
    for s in 0..=stratum(NDERIVED - 1) {
        loop {
            let mut changed = false;
            for r in rules
                .iter()
                .filter(|r| stratum(r.head.pred[1..].parse().unwrap_or(0)) == s)
            {
                for code in 0..CONSTS.len().pow(VARS.len() as u32) {
                    let asg: Vec<usize> = (0..VARS.len())
                        .map(|k| (code / CONSTS.len().pow(k as u32)) % CONSTS.len())
                        .collect();
                    let holds = |a: &A| {
                        db.get(&a.pred)
                            .is_some_and(|set| set.contains(&inst(a, &asg)))
                    };
                    let ok = r.body.iter().all(|l| match l {
                        L::Pos(a) => holds(a),
                        L::Neg(a) => !holds(a),
                        L::Neq(a, b) => asg[*a] != asg[*b],
                    });
                    if ok {
                        let h = inst(&r.head, &asg);
                        changed |= db.entry(r.head.pred.clone()).or_default().insert(h);
                    }
                }
            }
            if !changed {
                break;
            }
        }
    }
    db
}

fn load(rules: &[R]) -> LogicPad {
    let pad = LogicPad::parse(&yaml(rules), "gen.yaml", false).expect("generated YAML loads");
    let errors: Vec<String> = pad
        .diagnostics()
        .iter()
        .filter(|d| d.is_error())
        .map(|d| d.render_plain(100))
        .collect();
    assert!(errors.is_empty(), "{}\n{}", yaml(rules), errors.join("\n"));
    pad
}

fn evaluate(pad: &LogicPad, facts: &[(String, Vec<String>)]) -> Model {
    let mut fb = FactBase::new();
    for (p, a) in facts {
        let args: Vec<&str> = a.iter().map(String::as_str).collect();
        fb.add(p, &args).expect("fact");
    }
    pad.program().evaluate(fb).expect("evaluates")
}

fn derived(m: &Model) -> Db {
    (0..NDERIVED)
        .map(|d| {
            let p = format!("D{d}");
            let set: BTreeSet<Vec<String>> = m.facts(&p).into_iter().collect();
            (p, set)
        })
        .collect()
}

/// A written-out fact as owned names, to look up among the base facts.
fn key(f: &logicpad::GroundAtom) -> (String, Vec<String>) {
    (
        f.pred.to_string(),
        f.args.iter().map(|a| a.to_string()).collect(),
    )
}

/// Checks a proof tree against the program, the base facts and the model.
fn check_tree(
    t: &DerivationTree,
    prog: &Program,
    base: &BTreeSet<(String, Vec<String>)>,
    m: &Model,
) -> Result<(), String> {
    match t {
        DerivationTree::Base { fact: f, .. } => {
            if base.contains(&key(f)) {
                Ok(())
            } else {
                Err(format!("{f} is not a base fact"))
            }
        }
        DerivationTree::Absent(f) => Err(format!("unexpected absent node {f} in a fact's proof")),
        DerivationTree::NoMatch { formula } => {
            Err(format!("unexpected ¬∃ node {formula} in a fact's proof"))
        }
        // A cut proof must still stand for a derived fact that holds.
        DerivationTree::Truncated { fact, .. } => {
            let args: Vec<&str> = fact.args.iter().map(|a| a.as_ref()).collect();
            if !m.holds(&fact.pred, &args) {
                Err(format!("{fact} is cut but does not hold"))
            } else if base.contains(&key(fact)) {
                Err(format!("base fact {fact} is cut instead of shown"))
            } else {
                Ok(())
            }
        }
        DerivationTree::Derived {
            fact,
            rule,
            premises,
            absent,
            ..
        } => {
            let r = prog.rules().get(*rule).ok_or("no such rule")?;
            let mut sub: BTreeMap<usize, String> = BTreeMap::new();
            let mut unify = |args: &[CArg], vals: &[Cow<'static, str>]| -> Result<(), String> {
                if args.len() != vals.len() {
                    return Err("arity".into());
                }
                for (a, v) in args.iter().zip(vals) {
                    match a {
                        CArg::Const(c) => {
                            if c.as_sym().map(|s| s.as_str()) != Some(v.as_ref()) {
                                return Err(format!("constant {c} vs {v}"));
                            }
                        }
                        CArg::Var(x) => {
                            if let Some(prev) = sub.insert(*x, v.to_string())
                                && prev != *v
                            {
                                return Err(format!("variable bound to {prev} and {v}"));
                            }
                        }
                    }
                }
                Ok(())
            };
            if premises.len() != r.body.len() || absent.len() != r.negated.len() {
                return Err(format!(
                    "{fact}: premise count does not match rule {}",
                    r.source.text
                ));
            }
            for (atom, p) in r.body.iter().zip(premises) {
                let Some(pf) = p.fact() else {
                    return Err(format!("{fact}: a premise proves no fact"));
                };
                if prog.pred_name(atom.pred) != Some(pf.pred.as_ref()) {
                    return Err(format!("{fact}: premise {pf} does not match the rule"));
                }
                unify(&atom.args, &pf.args)?;
                check_tree(p, prog, base, m)?;
            }
            unify(&r.head.args, &fact.args)?;
            for (atom, a) in r.negated.iter().zip(absent) {
                unify(&atom.args, &a.args)?;
                let args: Vec<&str> = a.args.iter().map(|x| x.as_ref()).collect();
                if m.holds(&a.pred, &args) {
                    return Err(format!("{fact}: {a} was assumed absent but holds"));
                }
            }
            for (l, rr, neg) in &r.cmps {
                let val = |c: &CArg| match c {
                    CArg::Var(x) => sub.get(x).cloned().unwrap_or_default(),
                    CArg::Const(t) => t.to_string(),
                };
                if (val(l) == val(rr)) == *neg {
                    return Err(format!("{fact}: comparison fails"));
                }
            }
            Ok(())
        }
    }
}

fn shuffled(rules: &[R], seed: u64) -> Vec<R> {
    let mut g = Rng(seed.rotate_left(17) | 1);
    let mut out = rules.to_vec();
    for i in (1..out.len()).rev() {
        out.swap(i, g.below(i + 1));
    }
    for r in &mut out {
        for i in (1..r.body.len()).rev() {
            r.body.swap(i, g.below(i + 1));
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    #[test]
    fn agrees_with_naive_evaluation_and_order_and_proofs(seed in any::<u64>(), fact_seed in any::<u64>(), perm in any::<u64>()) {
        let (_, rules) = gen_program(seed);
        let facts = gen_facts(fact_seed);
        let pad = load(&rules);
        let model = evaluate(&pad, &facts);
        let expected = naive(&rules, &facts);
        let got = derived(&model);
        for (p, set) in &got {
            let want = expected.get(p).cloned().unwrap_or_default();
            prop_assert_eq!(set, &want, "predicate {} differs\n{}", p, yaml(&rules));
        }
        // Permuting rules and body literals changes nothing.
        let pad2 = load(&shuffled(&rules, perm));
        let model2 = evaluate(&pad2, &facts);
        prop_assert_eq!(derived(&model2), got.clone());
        // Every derived fact's proof checks out.
        let base: BTreeSet<(String, Vec<String>)> = facts.iter().cloned().collect();
        for (p, set) in &got {
            for args in set {
                let a: Vec<&str> = args.iter().map(String::as_str).collect();
                let tree = model.explain(p, &a);
                prop_assert!(tree.is_some(), "no proof for {}({:?})", p, args);
                if let Some(t) = tree {
                    let r = check_tree(&t, pad.program(), &base, &model);
                    prop_assert!(r.is_ok(), "bad proof for {}({:?}): {:?}\n{}", p, args, r, t);
                }
                // Small limits (from the permutation seed) cut proofs: what
                // is left must still check out, and stay within them.
                let limits = logicpad::ProofLimits {
                    max_depth: (perm % 4) as usize,
                    max_nodes: ((perm >> 8) % 6) as usize,
                };
                if let Some(t) = model.explain_with(p, &a, limits) {
                    prop_assert!(t.size() <= limits.max_nodes.max(1), "{} nodes under {:?}", t.size(), limits);
                    let r = check_tree(&t, pad.program(), &base, &model);
                    prop_assert!(r.is_ok(), "bad cut proof for {}({:?}) under {:?}: {:?}\n{}", p, args, limits, r, t);
                } else {
                    prop_assert!(false, "no cut proof for {}({:?})", p, args);
                }
            }
        }
    }
}

/// The generator must exercise what the property claims: derived facts,
/// negation, recursion.
#[test]
fn generated_programs_are_not_trivial() {
    let (mut derived_total, mut negations, mut recursive) = (0, 0, 0);
    for seed in 1..40u64 {
        let (_, rules) = gen_program(seed);
        negations += rules
            .iter()
            .flat_map(|r| &r.body)
            .filter(|l| matches!(l, L::Neg(_)))
            .count();
        let pad = load(&rules);
        recursive += pad
            .program()
            .components()
            .iter()
            .filter(|c| c.recursive)
            .count();
        let m = evaluate(&pad, &gen_facts(seed));
        derived_total += m.stats().derived_facts;
    }
    eprintln!("derived {derived_total}, negations {negations}, recursive components {recursive}");
    assert!(derived_total > 200, "{derived_total}");
    assert!(negations > 20, "{negations}");
    assert!(recursive > 10, "{recursive}");
}

/// A random safe conjunctive query over the generated vocabulary.
fn gen_query(seed: u64, arity: &[usize]) -> (String, Vec<L>) {
    let mut g = Rng(seed | 1);
    let preds: Vec<(String, usize)> = BASE
        .iter()
        .map(|(p, a)| (p.to_string(), *a))
        .chain((0..NDERIVED).map(|j| (format!("D{j}"), arity[j])))
        .collect();
    let mut lits = Vec::new();
    let mut bound = BTreeSet::new();
    for _ in 0..1 + g.below(3) {
        let (pred, ar) = preds[g.below(preds.len())].clone();
        let args: Vec<T> = (0..ar)
            .map(|_| {
                if g.chance(3, 4) {
                    T::V(g.below(2))
                } else {
                    T::C(g.below(CONSTS.len()))
                }
            })
            .collect();
        bound.extend(
            args.iter()
                .filter_map(|t| if let T::V(v) = t { Some(*v) } else { None }),
        );
        lits.push(L::Pos(A { pred, args }));
    }
    let bound: Vec<usize> = bound.into_iter().collect();
    if g.chance(1, 2) {
        let (pred, ar) = preds[g.below(preds.len())].clone();
        let args = (0..ar)
            .map(|_| {
                if !bound.is_empty() && g.chance(3, 4) {
                    T::V(bound[g.below(bound.len())])
                } else {
                    T::C(g.below(CONSTS.len()))
                }
            })
            .collect();
        lits.push(L::Neg(A { pred, args }));
    }
    if bound.len() == 2 && g.chance(1, 4) {
        lits.push(L::Neq(0, 1));
    }
    let text = lits
        .iter()
        .map(|l| match l {
            L::Pos(a) => atom(a),
            L::Neg(a) => format!("¬{}", atom(a)),
            L::Neq(a, b) => format!("{} ≠ {}", VARS[*a], VARS[*b]),
        })
        .collect::<Vec<_>>()
        .join(" ∧ ");
    (text, lits)
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// The query's kanren program (`ask` with proofs, `bindings`, `count`,
    /// the lazy `answers`) gives the answers of a naive enumeration over the
    /// naive evaluator's model, and the same answers as the textbook kanren
    /// program of the query — `fact` goals one by one, `=/=`, `naf` — which
    /// shares no code with the compiled join; every proof has one tree per
    /// literal.
    #[test]
    fn kanren_answers_equal_naive_and_textbook_kanren(seed in any::<u64>(), qseed in any::<u64>()) {
        let (arity, rules) = gen_program(seed);
        let facts = gen_facts(seed ^ 0xabcdef);
        let pad = load(&rules);
        let model = evaluate(&pad, &facts);
        let db = naive(&rules, &facts);
        for k in 0..4u64 {
            let (text, lits) = gen_query(qseed.wrapping_add(k), &arity);
            let ast = logicpad::parse_query(&text).expect("query parses");
            let asked = model
                .ask(&ast, logicpad::RunConfig { proofs: true, ..Default::default() })
                .expect("ask");
            for a in &asked {
                prop_assert_eq!(a.proof.len(), lits.iter().filter(|l| !matches!(l, L::Neq(..))).count(), "query {}", text);
            }
            let via_ask: Vec<Vec<(String, String)>> = asked.into_iter().map(|a| a.bindings).collect();
            let via_join = model.bindings(&ast).expect("bindings");
            prop_assert_eq!(&via_ask, &via_join, "query {}", text);
            prop_assert_eq!(&textbook_kanren(&model, &ast), &via_join, "query {}", text);
            prop_assert_eq!(&goal_answers(&model, &ast), &via_join, "query {}", text);
            prop_assert_eq!(model.count(&ast).expect("count"), via_join.len(), "query {}", text);
            let mut lazy: Vec<Vec<(String, String)>> = model
                .answers(&ast, Some(Default::default()))
                .expect("lazy answers")
                .map(|a| a.bindings)
                .collect();
            lazy.sort();
            prop_assert_eq!(&lazy, &via_join, "query {}", text);
            // Naive: every assignment of x, y over the constants.
            let names = ast.answer_var_names();
            let mut want: BTreeSet<Vec<(String, String)>> = BTreeSet::new();
            for code in 0..CONSTS.len() * CONSTS.len() {
                let asg = [code % CONSTS.len(), code / CONSTS.len()];
                let inst = |a: &A| -> Vec<String> {
                    a.args.iter().map(|t| match t { T::V(v) => CONSTS[asg[*v]].to_string(), T::C(c) => CONSTS[*c].to_string() }).collect()
                };
                let holds = |a: &A| db.get(&a.pred).is_some_and(|s| s.contains(&inst(a)));
                let ok = lits.iter().all(|l| match l {
                    L::Pos(a) => holds(a),
                    L::Neg(a) => !holds(a),
                    L::Neq(a, b) => asg[*a] != asg[*b],
                });
                if ok {
                    let mut b: Vec<(String, String)> = names
                        .iter()
                        .map(|n| (n.to_string(), CONSTS[asg[VARS.iter().position(|v| v == n).unwrap_or(0)]].to_string()))
                        .collect();
                    b.sort();
                    want.insert(b);
                }
            }
            prop_assert_eq!(via_join, want.into_iter().collect::<Vec<_>>(), "query {}", text);
        }
    }
}

/// The answers of a query as the textbook kanren program over the model's
/// relations: a `fact` goal per positive literal, then `=/=` and `=`, then
/// `naf(fact)` per negated literal, run goal by goal.
fn textbook_kanren(model: &Model, ast: &logicpad::QueryAst) -> Vec<Vec<(String, String)>> {
    use logicpad::fol::Literal;
    kanren_answers(ast, |d, to_term| {
        let fact = |a: &logicpad::fol::Atom| {
            model
                .relation(&a.pred)
                .map(|r| kanren::fact(r, a.args.iter().map(to_term).collect()))
        };
        let mut goals = Vec::new();
        for l in d {
            if let Literal::Pos(a) = l {
                goals.push(fact(a)?);
            }
        }
        for l in d {
            if let Literal::Cmp {
                left,
                right,
                negated,
                ..
            } = l
            {
                goals.push(if *negated {
                    kanren::neq(to_term(left), to_term(right))
                } else {
                    kanren::eq(to_term(left), to_term(right))
                });
            }
        }
        for l in d {
            if let Literal::Neg(a) = l
                && let Some(g) = fact(a)
            {
                goals.push(kanren::naf(g));
            }
        }
        Some(kanren::conj(goals))
    })
}

/// The answers of a query through [`Model::goal`], one alternative at a
/// time, in a kanren program of the test's own.
fn goal_answers(model: &Model, ast: &logicpad::QueryAst) -> Vec<Vec<(String, String)>> {
    kanren_answers(ast, |d, to_term| Some(model.goal(d, to_term)))
}

/// The distinct answers of the kanren goals `goal` builds, one per
/// alternative (`None`: the alternative has none), over one kanren
/// variable per query variable.
fn kanren_answers(
    ast: &logicpad::QueryAst,
    goal: impl Fn(
        &[logicpad::fol::Literal],
        &dyn Fn(&logicpad::fol::Arg) -> kanren::Term,
    ) -> Option<kanren::Goal>,
) -> Vec<Vec<(String, String)>> {
    use logicpad::fol::Arg;
    let mut out: BTreeSet<Vec<(String, String)>> = BTreeSet::new();
    for d in &ast.disjuncts {
        let mut kq = kanren::Query::new();
        let terms: Vec<kanren::Term> = ast.vars.iter().map(|v| kq.var(v)).collect();
        let to_term = |a: &Arg| match a {
            Arg::Var(v) => terms[*v].clone(),
            Arg::Const(c) => kanren::Term::Sym(kanren::Sym::new(c)),
        };
        let Some(g) = goal(d, &to_term) else { continue };
        for ans in kq.run(g, logicpad::RunConfig::default()) {
            let ans = ans.expect("a kanren answer");
            let mut b: Vec<(String, String)> = ast
                .answer_vars
                .iter()
                .map(|&v| (ast.vars[v].clone(), value_text(&ans.values[v])))
                .collect();
            b.sort();
            out.insert(b);
        }
    }
    out.into_iter().collect()
}

/// Renders literals as a conjunction.
fn conj_text(lits: &[L]) -> String {
    lits.iter()
        .map(|l| match l {
            L::Pos(a) => atom(a),
            L::Neg(a) => format!("¬{}", atom(a)),
            L::Neq(a, b) => format!("{} ≠ {}", VARS[*a], VARS[*b]),
        })
        .collect::<Vec<_>>()
        .join(" ∧ ")
}

fn lit_vars(l: &L) -> Vec<usize> {
    match l {
        L::Pos(a) | L::Neg(a) => a
            .args
            .iter()
            .filter_map(|t| if let T::V(v) = t { Some(*v) } else { None })
            .collect(),
        L::Neq(a, b) => vec![*a, *b],
    }
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    /// A universal query `∀x,y: A → B` is answered through its
    /// counterexamples `A ∧ ¬B`: they are exactly the assignments a naive
    /// enumeration finds where A holds and B does not, so the universal
    /// holds iff the naive "for every assignment, A implies B" does.
    #[test]
    fn universal_queries_equal_naive_for_all(seed in any::<u64>(), qseed in any::<u64>()) {
        let (arity, rules) = gen_program(seed);
        let facts = gen_facts(seed ^ 0x5eed);
        let pad = load(&rules);
        let model = evaluate(&pad, &facts);
        let db = naive(&rules, &facts);
        for k in 0..4u64 {
            let (_, guard) = gen_query(qseed.wrapping_add(k), &arity);
            let (_, cons) = gen_query(qseed.wrapping_add(k) ^ 0x77, &arity);
            let bound: BTreeSet<usize> = guard
                .iter()
                .filter(|l| matches!(l, L::Pos(_)))
                .flat_map(lit_vars)
                .collect();
            // The consequent may only speak of what the guard binds.
            let cons: Vec<L> = cons.into_iter().filter(|l| lit_vars(l).iter().all(|v| bound.contains(v))).collect();
            if bound.is_empty() || cons.is_empty() {
                continue;
            }
            let vars: Vec<usize> = bound.iter().copied().collect();
            let names: Vec<&str> = vars.iter().map(|&v| VARS[v]).collect();
            let text = format!("∀{}: {} → {}", names.join(", "), conj_text(&guard), conj_text(&cons));
            let parsed = logicpad::parse_any_query(&text).expect("universal parses");
            let logicpad::ParsedQuery::Forall(u) = parsed else {
                panic!("{text} parsed as an existential query");
            };
            prop_assert!(logicpad::check_any_query(pad.schema(), &logicpad::ParsedQuery::Forall(u.clone())).iter().all(|d| !d.is_error()), "{}", text);
            let counter = model.bindings(&u.counterexamples).expect("counterexamples");
            let via_kanren: Vec<Vec<(String, String)>> = model
                .ask(&u.counterexamples, logicpad::RunConfig::default())
                .expect("ask")
                .into_iter()
                .map(|a| a.bindings)
                .collect();
            prop_assert_eq!(&counter, &via_kanren, "query {}", text);
            let mut want: BTreeSet<Vec<(String, String)>> = BTreeSet::new();
            for code in 0..CONSTS.len() * CONSTS.len() {
                let asg = [code % CONSTS.len(), code / CONSTS.len()];
                let inst = |a: &A| -> Vec<String> {
                    a.args.iter().map(|t| match t { T::V(v) => CONSTS[asg[*v]].to_string(), T::C(c) => CONSTS[*c].to_string() }).collect()
                };
                let holds = |l: &L| match l {
                    L::Pos(a) => db.get(&a.pred).is_some_and(|s| s.contains(&inst(a))),
                    L::Neg(a) => !db.get(&a.pred).is_some_and(|s| s.contains(&inst(a))),
                    L::Neq(a, b) => asg[*a] != asg[*b],
                };
                if guard.iter().all(holds) && !cons.iter().all(holds) {
                    let mut b: Vec<(String, String)> = vars
                        .iter()
                        .map(|&v| (VARS[v].to_string(), CONSTS[asg[v]].to_string()))
                        .collect();
                    b.sort();
                    want.insert(b);
                }
            }
            prop_assert_eq!(counter, want.into_iter().collect::<Vec<_>>(), "query {}", text);
        }
    }
}

#[test]
fn a_universal_without_a_guard_is_refused_not_dropped() {
    // Regression: `forall x: Moving(x)` was read as `Moving(x)` and answered
    // "yes (2 answers)" while not every object moved.
    let e = logicpad::parse_any_query("forall x: Moving(x)").expect_err("refused");
    assert!(
        e.message.contains("ranges over everything"),
        "{}",
        e.message
    );
    let e = logicpad::parse_query("∀x: Vehicles(x) → Moving(x)").expect_err("not existential");
    assert!(e.message.contains("universal"), "{}", e.message);
    // `→` inside a conjunction, and a nested ∀, are refused too.
    assert!(logicpad::parse_any_query("Vehicles(x) ∧ (Moving(x) → SpeedUp(x))").is_err());
    assert!(logicpad::parse_any_query("∃y: Road(y) ∧ ∀x: On(x, y)").is_err());
}

#[test]
fn names_are_variables_by_spelling_alone() {
    for v in ["x", "y", "z", "u", "v", "w", "x1", "y22"] {
        assert!(logicpad::is_variable_name(v), "{v}");
    }
    for c in ["car_3", "foo", "a", "n2", "xy", "x_1", "Car", "vehicle"] {
        assert!(!logicpad::is_variable_name(c), "{c}");
    }
    let q = logicpad::parse_query("TypeOf(car_3, Sedan) ∧ Moving(?who) ∧ x ≠ car_1 ∧ Moving(x)")
        .expect("parses");
    assert_eq!(q.vars, ["who", "x"]);
}

#[test]
fn hostile_queries_end_in_an_error_not_an_abort() {
    // Regression: 10,000 chained `==>` overflowed the stack (abort).
    let chain = format!("∀x : {}", vec!["Vehicles(x)"; 10_000].join(" ==> "));
    let e = logicpad::parse_any_query(&chain).expect_err("too deep");
    assert!(e.message.contains("nested more than"), "{}", e.message);
    let yaml = format!(
        "atomic_predicates:\n  g:\n    - Vehicles(x)\nderived_predicates:\n  - name: Deep\n    logic: \"{chain}\"\n"
    );
    let pad = LogicPad::parse(&yaml, "deep.yaml", false).expect("loads, with the rule left out");
    assert!(
        pad.diagnostics()
            .iter()
            .any(|d| d.message.contains("nested more than"))
    );
    // Regression: a 12-atom cross product over four facts took 2.8 GB and
    // aborted; it is refused at the answer budget.
    let mut facts = FactBase::new();
    for c in ["c1", "c2", "c3", "c4"] {
        facts.add("Vehicles", &[c]).expect("fact");
    }
    let model = LogicPad::builtin()
        .program()
        .evaluate(facts)
        .expect("model");
    let q = (0..12)
        .map(|i| format!("Vehicles(v{i})"))
        .collect::<Vec<_>>()
        .join(" ∧ ");
    let ast = logicpad::parse_query(&q).expect("parses");
    // A count keeps no answer, so its budget is COUNT_FACTOR times larger
    // and bounds time only: 4^12 derivations are counted under the default
    // budget, and refused under a small one.
    let limits = |answers: usize| logicpad::Limits {
        answers,
        ..logicpad::Limits::default()
    };
    assert_eq!(
        model
            .count_limited(&ast, &limits(logicpad::DEFAULT_MAX_ANSWERS))
            .expect("counted without memory"),
        (4usize.pow(12), None)
    );
    assert_eq!(
        model.count_limited(&ast, &limits(1000)).expect("counts"),
        (
            1000 * logicpad::COUNT_FACTOR,
            Some(logicpad::Stopped::Answers)
        )
    );
    // Past the answer limit, the answers found first are kept, in the
    // order found, with the reason: never an allocation without bound.
    let bound = model.bindings_limited(&ast, &limits(1000)).expect("runs");
    assert_eq!(bound.stopped, Some(logicpad::Stopped::Answers));
    assert_eq!(bound.items.len(), 1000);
    let asked = model.ask_limited(&ast, true, &limits(1000)).expect("runs");
    assert_eq!(asked.stopped, Some(logicpad::Stopped::Answers));
    assert_eq!(asked.items.len(), 1000);
    assert!(asked.items.iter().all(|a| a.proof.len() == 12));
    // The same first answers, in the same order, as the lazy run gives.
    let lazy: Vec<_> = model
        .answers(&ast, None)
        .expect("lazy answers")
        .take(1000)
        .map(|a| a.bindings)
        .collect();
    assert_eq!(bound.items, lazy);
    // Lazily, the first answers of the 16.7 million come at once, each
    // with its proof.
    let first: Vec<_> = model
        .answers(&ast, Some(Default::default()))
        .expect("lazy answers")
        .take(5)
        .collect();
    assert_eq!(first.len(), 5);
    assert!(
        first
            .iter()
            .all(|a| a.bindings.len() == 12 && a.proof.len() == 12)
    );
    let two = logicpad::parse_query("Vehicles(x) ∧ Vehicles(y)").expect("parses");
    assert_eq!(
        model.count_limited(&two, &limits(16)).expect("16 fit"),
        (16, None)
    );
    let all = model.bindings_limited(&two, &limits(16)).expect("16 fit");
    assert_eq!((all.items.len(), all.stopped), (16, None));
    let cut = model.bindings_limited(&two, &limits(15)).expect("15 found");
    assert_eq!(
        (cut.items.len(), cut.stopped),
        (15, Some(logicpad::Stopped::Answers))
    );
}

/// The next window of `facts`: base predicates picked by `seed` lose or gain
/// a few facts; the others keep theirs, in order.
fn next_window(facts: &[(String, Vec<String>)], seed: u64) -> Vec<(String, Vec<String>)> {
    let mut g = Rng(seed.rotate_left(29) | 1);
    let changed: Vec<&str> = BASE
        .iter()
        .filter(|_| g.chance(1, 3))
        .map(|(p, _)| *p)
        .collect();
    let mut out: Vec<(String, Vec<String>)> = facts
        .iter()
        .filter(|(p, _)| !changed.contains(&p.as_str()) || !g.chance(1, 3))
        .cloned()
        .collect();
    for (p, ar) in BASE {
        if changed.contains(&p) && g.chance(1, 2) {
            let args = (0..ar)
                .map(|_| CONSTS[g.below(CONSTS.len())].to_string())
                .collect();
            out.push((p.to_string(), args));
        }
    }
    out
}

fn proofs(m: &Model) -> Vec<String> {
    let mut out = Vec::new();
    for (p, set) in derived(m) {
        for args in set {
            let a: Vec<&str> = args.iter().map(String::as_str).collect();
            out.push(format!("{p}{args:?}: {:?}", m.explain(&p, &a)));
        }
    }
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 96, ..ProptestConfig::default() })]

    /// Sliding windows: reasoning over the next window from the previous
    /// window's model gives the model a fresh evaluation gives — the same
    /// facts, the same derivation count and the same proofs.
    #[test]
    fn evaluate_after_equals_a_fresh_evaluation(seed in any::<u64>(), fact_seed in any::<u64>(), change in any::<u64>()) {
        let (_, rules) = gen_program(seed);
        let pad = load(&rules);
        let first = gen_facts(fact_seed);
        let prev = evaluate(&pad, &first);
        let mut windows = vec![first.clone(), next_window(&first, change)];
        windows.push(next_window(&windows[1], change.wrapping_add(1)));
        let mut before = prev;
        for facts in windows {
            let mut fb = FactBase::new();
            for (p, a) in &facts {
                let args: Vec<&str> = a.iter().map(String::as_str).collect();
                fb.add(p, &args).expect("fact");
            }
            let inc = pad.program().evaluate_after(&before, fb).expect("evaluates");
            let fresh = evaluate(&pad, &facts);
            prop_assert_eq!(derived(&inc), derived(&fresh), "\n{}", yaml(&rules));
            prop_assert_eq!(inc.stats().derived_facts, fresh.stats().derived_facts);
            prop_assert_eq!(proofs(&inc), proofs(&fresh));
            prop_assert_eq!(inc.violations(), fresh.violations());
            before = inc;
        }
    }
}

/// Identical windows reuse every component; a change reaches only the
/// components that read it.
#[test]
fn evaluate_after_reuses_only_unchanged_components() {
    let pad = LogicPad::parse(
        "atomic_predicates:\n  base:\n    - A(x)\n    - B(x)\nderived_predicates:\n  \
         - name: PA\n    logic: \"∀x : A(x) ==> PA(x)\"\n  \
         - name: PB\n    logic: \"∀x : B(x) ==> PB(x)\"\n  \
         - name: PC\n    logic: \"∀x : PA(x) ∧ ¬PB(x) ==> PC(x)\"\n",
        "w.yaml",
        false,
    )
    .expect("loads");
    assert!(!pad.diagnostics().iter().any(|d| d.is_error()));
    assert_eq!(pad.program().components().len(), 3);
    let fb = |facts: &[(&str, &str)]| {
        let mut fb = FactBase::new();
        for (p, a) in facts {
            fb.add(p, &[a]).expect("fact");
        }
        fb
    };
    let prog = pad.program();
    let w1 = prog
        .evaluate(fb(&[("A", "a"), ("B", "b")]))
        .expect("evaluates");
    assert_eq!(w1.stats().reused_components, 0);
    let same = prog
        .evaluate_after(&w1, fb(&[("A", "a"), ("B", "b")]))
        .expect("evaluates");
    assert_eq!(same.stats().reused_components, prog.components().len());
    // B changes: PA is reused, PB and PC (which reads ¬PB) are not.
    let w2 = prog
        .evaluate_after(&w1, fb(&[("A", "a"), ("B", "a")]))
        .expect("evaluates");
    assert_eq!(w2.stats().reused_components, 1);
    assert!(w1.holds("PC", &["a"]));
    assert!(!w2.holds("PC", &["a"]));
}

/// The sliding-window property must see both reuse and re-evaluation.
#[test]
fn next_windows_exercise_reuse_and_change() {
    let (mut reused, mut evaluated) = (0, 0);
    for seed in 1..40u64 {
        let (_, rules) = gen_program(seed);
        let pad = load(&rules);
        let first = gen_facts(seed);
        let prev = evaluate(&pad, &first);
        let mut fb = FactBase::new();
        for (p, a) in next_window(&first, seed) {
            let args: Vec<&str> = a.iter().map(String::as_str).collect();
            fb.add(&p, &args).expect("fact");
        }
        let m = pad.program().evaluate_after(&prev, fb).expect("evaluates");
        reused += m.stats().reused_components;
        evaluated += pad.program().components().len() - m.stats().reused_components;
    }
    assert!(
        reused > 20 && evaluated > 20,
        "reused {reused}, evaluated {evaluated}"
    );
}

/// A value as the answers print it (a symbol's name).
fn value_text(t: &kanren::Term) -> String {
    match t {
        kanren::Term::Sym(s) => s.as_str().to_string(),
        other => other.to_string(),
    }
}

/// A query keeps its compiled count plan (`QueryAst::plans`) from the
/// first window it is counted on: every later window of that program, and
/// a window of another program alive at the same time, must count as a
/// freshly parsed query does, in any order.
#[test]
fn one_query_counted_on_many_windows_and_programs_counts_each_as_fresh() {
    let facts = |list: &[(&str, &[&str])]| -> Vec<(String, Vec<String>)> {
        list.iter()
            .map(|(p, a)| (p.to_string(), a.iter().map(|s| s.to_string()).collect()))
            .collect()
    };
    let pad = LogicPad::builtin();
    // Another program, with other predicates (so other predicate ids): a
    // plan of the first would read the wrong relations here.
    let other = LogicPad::parse(
        "atomic_predicates:\n  g:\n    - Moving(x)\n    - SpeedUp(x)\n    - Pole(x)\n    - Vehicles(x)\n",
        "other.yaml",
        false,
    )
    .expect("loads");
    assert!(other.diagnostics().iter().all(|d| !d.is_error()));
    let w1 = evaluate(
        &pad,
        &facts(&[
            ("Vehicles", &["a"]),
            ("Vehicles", &["b"]),
            ("Moving", &["a"]),
        ]),
    );
    let w2 = evaluate(&pad, &facts(&[("Vehicles", &["c"])]));
    let w3 = evaluate(
        &other,
        &facts(&[
            ("Vehicles", &["a"]),
            ("Vehicles", &["b"]),
            ("Moving", &["a"]),
            ("Moving", &["b"]),
        ]),
    );
    let text = "Vehicles(x) ∧ Moving(x) ∧ ¬SpeedUp(x)";
    let kept = logicpad::parse_query(text).expect("parses");
    for (m, n) in [(&w1, 1), (&w2, 0), (&w3, 2), (&w1, 1), (&w3, 2), (&w2, 0)] {
        let fresh = logicpad::parse_query(text).expect("parses");
        assert_eq!(m.count(&fresh).expect("counts"), n);
        assert_eq!(m.count(&kept).expect("counts"), n);
        // Bindings and proofs are compiled afresh, and agree.
        assert_eq!(m.bindings(&kept).expect("binds").len(), n);
    }
    // An unsafe query is refused every time, not cached.
    let bad = logicpad::parse_query("¬Moving(x)").expect("parses");
    assert!(w1.count(&bad).is_err() && w2.count(&bad).is_err());
}

/// A query outlives the program it was first counted on (a REPL reloads
/// its LogicPad): a program made after the first one is dropped, with
/// other predicates, may take the first one's memory, and the query's kept
/// plan must not be taken for one of the new program (the plan keeps the
/// allocation through a weak reference; the allocator's reuse itself
/// cannot be forced here, so this holds the identity check to account).
#[test]
fn a_query_kept_past_its_program_counts_afresh_on_the_next_one() {
    let text = "Vehicles(x) ∧ Moving(x)";
    let kept = logicpad::parse_query(text).expect("parses");
    let yaml = |order: &[&str]| {
        let preds: String = order.iter().map(|p| format!("    - {p}(x)\n")).collect();
        format!("atomic_predicates:\n  g:\n{preds}")
    };
    let facts: Vec<(String, Vec<String>)> = vec![
        ("Vehicles".into(), vec!["a".into()]),
        ("Moving".into(), vec!["a".into()]),
        ("Pole".into(), vec!["p".into()]),
    ];
    for round in 0..20 {
        // Alternate the predicates, so that the ids differ and a stale
        // plan reads the wrong relations.
        let order: &[&str] = if round % 2 == 0 {
            &["Vehicles", "Moving", "Pole"]
        } else {
            &["Aisle", "Bay", "Moving", "Vehicles"]
        };
        let pad = LogicPad::parse(&yaml(order), "g.yaml", false).expect("loads");
        let model = evaluate(&pad, &facts);
        assert_eq!(model.count(&kept).expect("counts"), 1, "round {round}");
    }
}

/// A random query with one `¬∃z: (…)` literal (`z` its own variable):
/// outer positive atoms over `x`, `y` (none for a closed query), then
/// the `¬∃` whose body has one or two positive atoms using `z` and the
/// outer variables, maybe a negated atom and `z ≠ x`. Returns the text,
/// the outer literals and the body.
fn gen_not_exists_query(seed: u64, arity: &[usize]) -> (String, Vec<L>, Vec<L>) {
    let mut g = Rng(seed | 1);
    let preds: Vec<(String, usize)> = BASE
        .iter()
        .map(|(p, a)| (p.to_string(), *a))
        .chain((0..NDERIVED).map(|j| (format!("D{j}"), arity[j])))
        .collect();
    let closed = g.chance(1, 5);
    let mut outer = Vec::new();
    let mut bound = BTreeSet::new();
    if !closed {
        for _ in 0..1 + g.below(2) {
            let (pred, ar) = preds[g.below(preds.len())].clone();
            let args: Vec<T> = (0..ar)
                .map(|_| {
                    if g.chance(4, 5) {
                        T::V(g.below(2))
                    } else {
                        T::C(g.below(CONSTS.len()))
                    }
                })
                .collect();
            bound.extend(args.iter().filter_map(|t| match t {
                T::V(v) => Some(*v),
                T::C(_) => None,
            }));
            outer.push(L::Pos(A { pred, args }));
        }
    }
    let bound: Vec<usize> = bound.into_iter().collect();
    // Body variables: `z` (2) and the outer bound ones.
    let mut body_vars = vec![2];
    body_vars.extend(&bound);
    let pick = |g: &mut Rng, vars: &[usize]| {
        if g.chance(4, 5) {
            T::V(vars[g.below(vars.len())])
        } else {
            T::C(g.below(CONSTS.len()))
        }
    };
    let mut body = Vec::new();
    for i in 0..1 + g.below(2) {
        let (pred, ar) = preds[g.below(preds.len())].clone();
        let mut args: Vec<T> = (0..ar).map(|_| pick(&mut g, &body_vars)).collect();
        // The first atom holds `z`, so `z` is bound inside.
        if i == 0 {
            let k = g.below(ar);
            args[k] = T::V(2);
        }
        body.push(L::Pos(A { pred, args }));
    }
    if g.chance(1, 3) {
        let (pred, ar) = preds[g.below(preds.len())].clone();
        let args = (0..ar).map(|_| pick(&mut g, &body_vars)).collect();
        body.push(L::Neg(A { pred, args }));
    }
    if bound.contains(&0) && g.chance(1, 4) {
        body.push(L::Neq(2, 0));
    }
    let mut text = conj_text(&outer);
    if !text.is_empty() {
        text.push_str(" ∧ ");
    }
    text.push_str(&format!("¬∃z: ({})", conj_text(&body)));
    (text, outer, body)
}

/// Every assignment of `x`, `y` over the constants that satisfies the
/// outer literals and for which no value of `z` satisfies the body,
/// projected on `names` — the naive reading of `¬∃`.
fn naive_not_exists(
    db: &Db,
    outer: &[L],
    body: &[L],
    names: &[&str],
) -> BTreeSet<Vec<(String, String)>> {
    let holds_under = |l: &L, asg: &[usize; 3]| {
        let inst = |a: &A| -> Vec<String> {
            a.args
                .iter()
                .map(|t| match t {
                    T::V(v) => CONSTS[asg[*v]].to_string(),
                    T::C(c) => CONSTS[*c].to_string(),
                })
                .collect()
        };
        let holds = |a: &A| db.get(&a.pred).is_some_and(|s| s.contains(&inst(a)));
        match l {
            L::Pos(a) => holds(a),
            L::Neg(a) => !holds(a),
            L::Neq(a, b) => asg[*a] != asg[*b],
        }
    };
    let mut want = BTreeSet::new();
    for code in 0..CONSTS.len() * CONSTS.len() {
        let mut asg = [code % CONSTS.len(), code / CONSTS.len(), 0];
        if !outer.iter().all(|l| holds_under(l, &asg)) {
            continue;
        }
        let blocked = (0..CONSTS.len()).any(|z| {
            asg[2] = z;
            body.iter().all(|l| holds_under(l, &asg))
        });
        if blocked {
            continue;
        }
        let mut b: Vec<(String, String)> = names
            .iter()
            .map(|n| {
                let v = VARS.iter().position(|w| w == n).unwrap_or(0);
                (n.to_string(), CONSTS[asg[v]].to_string())
            })
            .collect();
        b.sort();
        want.insert(b);
    }
    want
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    /// `¬∃z: (…)` in a query: `ask` (with a `¬∃` node in every proof),
    /// `bindings`, `count`, the lazy `answers`, `satisfiable` and
    /// `Model::goal` all give what a naive enumeration gives — for each
    /// assignment of the outer variables, no value of `z` satisfies the
    /// body.
    #[test]
    fn not_exists_answers_equal_naive(seed in any::<u64>(), qseed in any::<u64>()) {
        let (arity, rules) = gen_program(seed);
        let facts = gen_facts(seed ^ 0x0e15);
        let pad = load(&rules);
        let model = evaluate(&pad, &facts);
        let db = naive(&rules, &facts);
        for k in 0..4u64 {
            let (text, outer, body) = gen_not_exists_query(qseed.wrapping_add(k), &arity);
            let ast = logicpad::parse_query(&text).expect("query parses");
            let diags = logicpad::check_query(pad.schema(), &ast);
            prop_assert!(diags.iter().all(|d| !d.is_error()), "{}: {:?}", text, diags);
            let names = ast.answer_var_names();
            let want: Vec<_> = naive_not_exists(&db, &outer, &body, &names).into_iter().collect();
            let asked = model
                .ask(&ast, logicpad::RunConfig { proofs: true, ..Default::default() })
                .expect("ask");
            for a in &asked {
                let no_match = a.proof.iter().filter(|t| matches!(t, DerivationTree::NoMatch { .. })).count();
                prop_assert_eq!(no_match, 1, "query {}", text);
            }
            let via_ask: Vec<_> = asked.into_iter().map(|a| a.bindings).collect();
            prop_assert_eq!(&via_ask, &want, "query {}", text);
            prop_assert_eq!(&model.bindings(&ast).expect("bindings"), &want, "query {}", text);
            prop_assert_eq!(model.count(&ast).expect("count"), want.len(), "query {}", text);
            prop_assert_eq!(model.satisfiable(&ast).expect("satisfiable"), !want.is_empty(), "query {}", text);
            let mut lazy: Vec<_> = model
                .answers(&ast, Some(Default::default()))
                .expect("lazy answers")
                .map(|a| a.bindings)
                .collect();
            lazy.sort();
            prop_assert_eq!(&lazy, &want, "query {}", text);
            prop_assert_eq!(&goal_answers(&model, &ast), &want, "query {}", text);
        }
    }

    /// `#{vars: Q} op N` counts the distinct bindings of the counted
    /// variables: the number of distinct projections of the naive answers
    /// of `Q` (plain or with a `¬∃`), and the test agrees with it.
    #[test]
    fn counting_equals_enumerated_bindings(seed in any::<u64>(), qseed in any::<u64>(), n in 0usize..5, op in 0usize..5) {
        let (arity, rules) = gen_program(seed);
        let facts = gen_facts(seed ^ 0xc0de);
        let pad = load(&rules);
        let model = evaluate(&pad, &facts);
        let db = naive(&rules, &facts);
        for k in 0..4u64 {
            let (text, outer, body) = if k % 2 == 0 {
                gen_not_exists_query(qseed.wrapping_add(k), &arity)
            } else {
                let (t, lits) = gen_query(qseed.wrapping_add(k), &arity);
                (t, lits, Vec::new())
            };
            let plain = logicpad::parse_query(&text).expect("query parses");
            let all = plain.answer_var_names();
            if all.is_empty() {
                continue;
            }
            // Count the first answer variable, or all of them.
            let counted: Vec<&str> = if k % 4 < 2 { all[..1].to_vec() } else { all.clone() };
            let ops = [">=", ">", "<=", "<", "="];
            let q = format!("#{{{}: {}}} {} {}", counted.join(", "), text, ops[op], n);
            let Ok(logicpad::ParsedQuery::Count(c)) = logicpad::parse_any_query(&q) else {
                return Err(TestCaseError::fail(format!("{q} is not a count")));
            };
            prop_assert!(logicpad::check_any_query(pad.schema(), &logicpad::ParsedQuery::Count(c.clone())).iter().all(|d| !d.is_error()), "{}", q);
            let answers: BTreeSet<Vec<(String, String)>> = if body.is_empty() {
                model.bindings(&plain).expect("bindings").into_iter().collect()
            } else {
                naive_not_exists(&db, &outer, &body, &all)
            };
            let projected: BTreeSet<Vec<(String, String)>> = answers
                .iter()
                .map(|b| b.iter().filter(|(v, _)| counted.contains(&v.as_str())).cloned().collect())
                .collect();
            let count = model.count(&c.query).expect("count");
            prop_assert_eq!(count, projected.len(), "query {}", q);
            prop_assert_eq!(model.bindings(&c.query).expect("bindings").len(), count, "query {}", q);
            let want = match op {
                0 => count >= n,
                1 => count > n,
                2 => count <= n,
                3 => count < n,
                _ => count == n,
            };
            prop_assert_eq!(c.holds(count), want, "query {}", q);
        }
    }
}
