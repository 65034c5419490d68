//! How sure an answer is: the probability that it is right, from the
//! probabilities perception gives its facts (docs/probability.md).
//!
//! The semantics, and why:
//! - **Base facts are independent events** (a tuple-independent
//!   probabilistic database, as ProbLog's probabilistic facts): an
//!   asserted fact holds with its provenance's probability, a *doubt* —
//!   measured and not asserted — holds with its own, and every other fact
//!   is certainly absent. Perception's facts come from separate
//!   measurements (a track's speed, a pair's gap slope, frame votes), which
//!   is what makes independence a fair first model.
//! - **A binding's probability is its proof's**: the product over the
//!   proof's observed leaves of their probability, times, over its negated
//!   leaves (`¬SpeedUp(car_1)`), the probability that the doubt, if any,
//!   does not hold. A fact that occurs twice in a proof counts once.
//! - **A yes/no "yes" is the disjunction of its top-k proofs**, computed
//!   exactly (inclusion–exclusion over the proofs' shared leaves), as
//!   Scallop's top-k-proofs provenance does: proofs that share a fact are
//!   not counted as independent (noisy-or would overcount them). Proofs
//!   past the k most probable are left out, which can only lower the
//!   figure. Each derived fact contributes the one derivation the fixpoint
//!   recorded.
//! - **Every other answer** (a "no", a count, a list of objects) is right
//!   when the set of answers does not change. Its probability is, over the
//!   uncertain facts whose flip alone would change the answer (an asserted
//!   fact dropped, a doubt added, the window re-reasoned each time), the
//!   probability that none flips. Only facts of predicates the question
//!   can feel (its own, and what their rules rest on) are flipped. This is
//!   a first-order estimate: two flips that change the answer only
//!   together are not seen.
//! - A source without uncertainty (labels, a noise-free simulation, a
//!   text KB) gives 1 without any of this work.
//!
//! The main types: [`BeliefLimits`] (the named bounds of the work), and,
//! inside the crate, `Flips` (a window's uncertain facts, each with the
//! window re-reasoned with it flipped, built on first need and shared by
//! every question on the window).

use crate::ask::{AskOptions, AskResult, Outcome};
use crate::kb::{WindowFacts, WindowInput, WindowKb};
use crate::proof::{Atom, ProofNode, Step};
use crate::translate::Intent;
use logicpad::Program;
use perception::Fact;
use std::collections::{BTreeMap, BTreeSet};

/// The bounds of the work behind an answer's probability.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BeliefLimits {
    /// The most proofs whose disjunction is computed exactly (2^k terms of
    /// inclusion–exclusion); the most probable are kept. At most
    /// `MAX_EXACT_PROOFS` (16) are used whatever this says.
    pub max_proofs: usize,
    /// The most flips one answer looks at, of those its question can feel
    /// (each re-reasons the window once, for every later question too);
    /// the likeliest are kept.
    pub max_flips: usize,
    /// A fact whose flip is less likely than this is taken as certain.
    pub min_flip: f64,
}

/// The most proofs ever combined exactly: 2^16 subsets is already a
/// millisecond per answer, and a larger `max_proofs` must not overflow the
/// subset mask or run for ever.
pub(crate) const MAX_EXACT_PROOFS: usize = 16;

impl Default for BeliefLimits {
    fn default() -> Self {
        BeliefLimits {
            max_proofs: 8,
            max_flips: 32,
            min_flip: 0.01,
        }
    }
}

/// One uncertain fact of a window that could be flipped, and the window
/// with it flipped, reasoned on first need.
#[derive(Debug)]
pub(crate) struct Flip {
    /// The fact dropped (asserted, probability below 1) or added (a doubt).
    fact: Fact,
    /// Whether the fact is added (a doubt) rather than dropped.
    added: bool,
    /// The probability of the flip: 1 − p for a drop, q for an addition.
    chance: f64,
    /// The window with the flip, reasoned (`None`: it did not build, which
    /// the window's own facts cannot cause).
    kb: std::sync::OnceLock<Option<WindowKb>>,
}

impl Flip {
    /// The flip as an answer's hinge: the fact, whether it holds in the
    /// window, and the (rounded) chance that it is the other way.
    fn hinge(&self) -> Hinge {
        Hinge {
            fact: self.fact.to_kb_line(),
            holds: !self.added,
            chance: rounded(self.chance),
        }
    }
}

/// A window's possible flips, likeliest first (ties by fact, so the order
/// is stable). Only the flips a question can feel are ever reasoned, once
/// each: "Is there a truck moving?" re-reasons no window for a doubtful
/// `LeftOf`.
pub(crate) type Flips = Vec<Flip>;

/// A proof's uncertain leaves: atom → (holds, probability of that). A
/// fact and its negation are one key.
type Term<'a> = BTreeMap<Atom<'a>, (bool, f64)>;

/// The uncertain leaves of a proof. Every observed or absent node that
/// [`crate::proof::node`] writes has its atom; one without (a proof read
/// back from text) counts as certain.
fn leaves(proof: &[ProofNode]) -> Term<'_> {
    fn walk<'a>(n: &'a ProofNode, out: &mut Term<'a>) {
        match &n.step {
            Step::Observed { provenance } => {
                let p = provenance.as_ref().map_or(1.0, |p| p.belief());
                if p < 1.0
                    && let Some(atom) = n.fact.atom()
                {
                    out.insert(atom, (true, p));
                }
            }
            Step::Absent { doubt: Some(q) } => {
                if let Some(atom) = n.fact.atom() {
                    out.insert(atom, (false, 1.0 - q));
                }
            }
            Step::Absent { doubt: None } => {}
            Step::Rule { .. } => {
                for p in &n.premises {
                    walk(p, out);
                }
            }
            // A proof cut by its limits: its hidden leaves are taken as
            // certain (the figure can only be too high by what is hidden).
            Step::Cut { .. } => {}
        }
    }
    let mut out = Term::new();
    for n in proof {
        walk(n, &mut out);
    }
    out
}

fn term_probability(t: &Term<'_>) -> f64 {
    t.values().map(|(_, p)| p).product()
}

/// The exact probability that at least one of `terms` holds, by
/// inclusion–exclusion: each subset's leaves must hold together (a leaf
/// needed both true and false makes the subset impossible).
fn disjunction(terms: &[Term<'_>]) -> f64 {
    let n = terms.len();
    let mut total = 0.0;
    for mask in 1u32..(1u32 << n) {
        let mut joint: Term<'_> = Term::new();
        let mut possible = true;
        for (i, t) in terms.iter().enumerate() {
            if mask & (1 << i) == 0 {
                continue;
            }
            for (fact, &(holds, p)) in t {
                match joint.get(fact) {
                    Some(&(h, _)) if h != holds => possible = false,
                    Some(_) => {}
                    None => {
                        joint.insert(fact.clone(), (holds, p));
                    }
                }
            }
        }
        if !possible {
            continue;
        }
        let sign = if mask.count_ones() % 2 == 1 {
            1.0
        } else {
            -1.0
        };
        total += sign * term_probability(&joint);
    }
    total.clamp(0.0, 1.0)
}

/// Rounds a probability for output (four decimals), never to 1 unless it
/// is 1, so that "certain" is said only of what is.
pub(crate) fn rounded(p: f64) -> f64 {
    let r = (p * 1e4).round() / 1e4;
    if r >= 1.0 && p < 1.0 { 0.9999 } else { r }
}

/// An uncertain fact whose flip alone would change an answer: checked, by
/// re-reasoning the window with it flipped.
///
/// JSON: `{"fact": "Moving(car_1)", "holds": false, "chance": 0.29}`.
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Hinge {
    /// The fact, e.g. `Moving(car_1)`.
    pub fact: String,
    /// Whether the window holds it (an asserted fact below probability 1)
    /// or not (a doubt).
    pub holds: bool,
    /// The probability that the measurement is wrong about it: that it
    /// does not hold (when it does) or holds (when it does not).
    pub chance: f64,
}

impl Hinge {
    /// The hinge as a sentence for C2 and the terminal.
    pub fn sentence(&self) -> String {
        let (cond, verb) = if self.holds {
            ("did not hold", "it holds")
        } else {
            ("held", "it does not hold")
        };
        format!(
            "The answer would change if {} {cond}: the window says {verb}, with probability {} of being wrong.",
            self.fact, self.chance
        )
    }
}

/// What [`believe`] needs to know of the question behind an answer.
pub(crate) struct Asked<'a> {
    /// What the question asks for.
    pub(crate) intent: Intent,
    /// Whether the query is a universal (`∀x: A → B`).
    pub(crate) universal: bool,
    /// The query, when it parsed: a count and a `¬∃` are read their own
    /// way.
    pub(crate) parsed: Option<&'a logicpad::ParsedQuery>,
    /// Whether the question can feel a predicate ([`reach`]).
    pub(crate) relevant: &'a dyn Fn(&str) -> bool,
    /// The question answered on another window, without probabilities.
    pub(crate) ask: &'a dyn Fn(&WindowKb) -> AskResult,
}

/// Sets `r.probability`, `r.binding_probabilities` and `r.hinges` for an
/// answer whose outcome is yes or no; `proofs` are the bindings' proofs,
/// in order.
pub(crate) fn believe<'a>(
    kb: &'a WindowKb,
    program: &Program,
    limits: &BeliefLimits,
    q: &Asked<'_>,
    r: &mut AskResult,
    proofs: &'a [Vec<ProofNode>],
) {
    let (intent, universal, relevant, ask) = (q.intent, q.universal, q.relevant, q.ask);
    if !matches!(r.answer, Outcome::Yes | Outcome::No) {
        return;
    }
    if !kb.is_uncertain() {
        r.probability = Some(1.0);
        return;
    }
    let terms: Vec<Term<'_>> = proofs.iter().map(|p| leaves(p)).collect();
    let each: Vec<f64> = terms.iter().map(term_probability).collect();
    if let Some(logicpad::ParsedQuery::Count(c)) = q.parsed {
        let p = count_probability(kb, program, limits, q, c, r, &terms);
        r.probability = Some(rounded(p));
        if each.len() == r.bindings.len() && each.iter().any(|p| *p < 1.0) {
            r.binding_probabilities = each.into_iter().map(rounded).collect();
        }
        return;
    }
    // A `¬∃` holds when no match exists: its proof shows none of the
    // facts whose arrival would break it, so its "yes" is read by its
    // flips, as a set is.
    let scoped = q.parsed.is_some_and(|p| {
        p.parts()
            .iter()
            .any(|a| a.disjuncts.iter().flatten().any(|l| l.is_not_exists()))
    });
    // A universal's "yes" needs every instance, not one: it is read by
    // its flips like the answers that are sets.
    let p = if r.answer == Outcome::Yes && intent == Intent::YesNo && !universal && !scoped {
        let mut order: Vec<usize> = (0..terms.len()).collect();
        order.sort_by(|&a, &b| each[b].total_cmp(&each[a]).then(a.cmp(&b)));
        let top: Vec<Term<'_>> = order
            .iter()
            .take(limits.max_proofs.min(MAX_EXACT_PROOFS))
            .map(|&i| terms[i].clone())
            .collect();
        disjunction(&top)
    } else {
        let flips = kb.flips.get_or_init(|| candidates(kb, limits));
        let hinges: Vec<&Flip> = flips
            .iter()
            .filter(|f| relevant(&f.fact.predicate))
            .take(limits.max_flips)
            .filter(|f| {
                let flipped = f.kb.get_or_init(|| flip(kb, program, f));
                flipped
                    .as_ref()
                    .is_some_and(|k| changes(intent, r, &ask(k)))
            })
            .collect();
        // From the unrounded chances: rounding is for output only.
        let p = hinges.iter().map(|f| 1.0 - f.chance).product();
        r.hinges = hinges.iter().map(|f| f.hinge()).collect();
        p
    };
    r.probability = Some(rounded(p));
    // One probability per binding or none: proofs cut short by a budget
    // would leave them out of step.
    if each.len() == r.bindings.len() && each.iter().any(|p| *p < 1.0) {
        r.binding_probabilities = each.into_iter().map(rounded).collect();
    }
}

/// The probability that a counting query's answer is right: the chance
/// that the number of distinct witnesses passes (for a yes; fails, for a
/// no) the test, with the count a sum of independent events
/// (Poisson-binomial, computed exactly by dynamic programming):
///
/// - each witness found is there with its proof's probability, lowered by
///   each doubt whose arrival alone would remove it (a match of a `¬∃`
///   body, a negated atom) and that its proof does not already count;
/// - each object that one flip alone would add as a witness (a doubt
///   arriving, an uncertain fact of a `¬∃` body or negated atom going) is
///   there with that flip's chance (several such flips: any of them).
///
/// Unlike reading the answer by single flips, a count with slack is not
/// certain: five cars each seen with probability 0.6 pass "at least 3"
/// with probability 0.68, though no one flip changes the answer. Objects
/// are taken as independent, and a witness's own derivations beyond its
/// first proof are left out (which can only lower its probability);
/// combinations of flips that add a witness only together are not seen.
/// The hinges are, as for every answer read by flips, the single flips
/// that change the outcome.
fn count_probability<'a>(
    kb: &'a WindowKb,
    program: &Program,
    limits: &BeliefLimits,
    q: &Asked<'_>,
    c: &logicpad::CountQuery,
    r: &mut AskResult,
    terms: &[Term<'a>],
) -> f64 {
    let key = |b: &Vec<(String, String)>| -> Vec<(String, String)> {
        b.iter()
            .filter(|(v, _)| c.vars.contains(v))
            .cloned()
            .collect()
    };
    let found: Vec<Vec<(String, String)>> = r.bindings.iter().map(key).collect();
    let mut present: Vec<f64> = (0..found.len())
        .map(|i| terms.get(i).map_or(1.0, term_probability))
        .collect();
    // Witnesses a flip would add: key → probability that none of those
    // flips happens.
    let mut joining: BTreeMap<Vec<(String, String)>, f64> = BTreeMap::new();
    let flips = kb.flips.get_or_init(|| candidates(kb, limits));
    let mut hinges = Vec::new();
    for f in flips
        .iter()
        .filter(|f| (q.relevant)(&f.fact.predicate))
        .take(limits.max_flips)
    {
        let Some(flipped) = f.kb.get_or_init(|| flip(kb, program, f)).as_ref() else {
            continue;
        };
        let other = (q.ask)(flipped);
        if other.answer != r.answer {
            hinges.push(f);
        }
        let theirs: BTreeSet<Vec<(String, String)>> = other.bindings.iter().map(key).collect();
        let fact = Atom::of_fact(&f.fact);
        for (i, w) in found.iter().enumerate() {
            // A drop the proof already counts is not counted twice.
            let counted = terms.get(i).is_some_and(|t| t.contains_key(&fact));
            if !theirs.contains(w) && !counted {
                present[i] *= 1.0 - f.chance;
            }
        }
        for w in theirs {
            if !found.contains(&w) {
                *joining.entry(w).or_insert(1.0) *= 1.0 - f.chance;
            }
        }
    }
    let events: Vec<f64> = present
        .into_iter()
        .chain(joining.values().map(|none| 1.0 - none))
        .collect();
    // dist[k] = P(exactly k of the events happen).
    let mut dist = vec![1.0f64];
    for p in events {
        let mut next = vec![0.0f64; dist.len() + 1];
        for (k, d) in dist.iter().enumerate() {
            next[k] += d * (1.0 - p);
            next[k + 1] += d * p;
        }
        dist = next;
    }
    let passes: f64 = dist
        .iter()
        .enumerate()
        .filter(|(k, _)| c.holds(*k))
        .map(|(_, d)| d)
        .sum();
    r.hinges = hinges.iter().map(|f| f.hinge()).collect();
    let p = if r.answer == Outcome::Yes {
        passes
    } else {
        1.0 - passes
    };
    p.clamp(0.0, 1.0)
}

/// Whether the answer on a flipped window differs from `r` in what the
/// question asks: the outcome of a yes/no, the number of a how-many, the
/// objects of a which.
fn changes(intent: Intent, r: &AskResult, flipped: &AskResult) -> bool {
    match intent {
        Intent::YesNo => flipped.answer != r.answer,
        Intent::HowMany => flipped.count != r.count,
        Intent::Which => flipped.count != r.count || flipped.bindings != r.bindings,
    }
}

/// The window's possible flips: each asserted fact below probability 1
/// (dropped), each doubt (added), at least `min_flip` likely.
fn candidates(kb: &WindowKb, limits: &BeliefLimits) -> Flips {
    let dropped = kb.facts().filter_map(|f| {
        let chance = 1.0 - f.provenance().belief();
        (chance >= limits.min_flip).then(|| (f.to_fact(), false, chance))
    });
    let added = kb.doubts().iter().filter_map(|d| {
        let chance = d.provenance.belief();
        (chance >= limits.min_flip).then(|| (d.clone(), true, chance))
    });
    let mut all: Vec<(Fact, bool, f64)> = dropped.chain(added).collect();
    all.sort_by(|a, b| b.2.total_cmp(&a.2).then_with(|| a.0.key().cmp(&b.0.key())));
    all.into_iter()
        .map(|(fact, added, chance)| Flip {
            fact,
            added,
            chance,
            kb: std::sync::OnceLock::new(),
        })
        .collect()
}

/// The window reasoned again with `f` flipped.
fn flip(kb: &WindowKb, program: &Program, f: &Flip) -> Option<WindowKb> {
    let is_flipped = |x: &crate::kb::FactRef<'_>| {
        x.predicate() == f.fact.predicate && x.args().eq(f.fact.args.iter().map(String::as_str))
    };
    let mut facts: Vec<Fact> = kb
        .facts()
        .filter(|x| f.added || !is_flipped(x))
        .map(|x| x.to_fact())
        .collect();
    if f.added {
        facts.push(f.fact.clone());
    }
    let input = WindowInput {
        id: kb.id.clone(),
        index: kb.index,
        first_frame: kb.first_frame,
        last_frame: kb.last_frame,
        facts: WindowFacts::Listed(facts),
        doubts: Vec::new(),
    };
    WindowKb::build(input, program).ok()
}

/// The predicates a query can feel: its own, and through the rules every
/// predicate their derivations rest on.
pub(crate) fn reach(program: &Program, query: &logicpad::ParsedQuery) -> BTreeSet<String> {
    let roots: Vec<String> = query
        .parts()
        .iter()
        .flat_map(|q| q.disjuncts.iter().flatten())
        .flat_map(|l| l.atoms())
        .map(|(a, _)| a.pred.clone())
        .collect();
    crate::kb::rests_on(program, roots, |_| true)
}

/// The options of the asks on flipped windows: the answers alone.
pub(crate) fn flip_options(opts: AskOptions) -> AskOptions {
    AskOptions {
        proofs: false,
        why_not: false,
        count_only: false,
        ..opts
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ask::AskOptions;

    fn atom(pred: &str) -> Atom<'_> {
        Atom {
            pred,
            args: Default::default(),
        }
    }

    fn term<'a>(leaves: &[(&'a str, bool, f64)]) -> Term<'a> {
        leaves.iter().map(|(f, h, p)| (atom(f), (*h, *p))).collect()
    }

    #[test]
    fn disjoint_proofs_combine_as_noisy_or() {
        let t = [term(&[("A", true, 0.9)]), term(&[("B", true, 0.8)])];
        assert!((disjunction(&t) - (1.0 - 0.1 * 0.2)).abs() < 1e-12);
    }

    #[test]
    fn a_shared_fact_is_counted_once() {
        // (A ∧ B) ∨ (A ∧ C) = A ∧ (B ∨ C): noisy-or over the proofs would
        // say 1 − (1 − .45)(1 − .36) = .648; the truth is .9 × .7 = .63.
        let t = [
            term(&[("A", true, 0.9), ("B", true, 0.5)]),
            term(&[("A", true, 0.9), ("C", true, 0.4)]),
        ];
        assert!((disjunction(&t) - 0.9 * (1.0 - 0.5 * 0.6)).abs() < 1e-12);
    }

    #[test]
    fn contradicting_proofs_exclude_each_other() {
        // A ∨ ¬A with P(A) = .3 is certain.
        let t = [term(&[("A", true, 0.3)]), term(&[("A", false, 0.7)])];
        assert!((disjunction(&t) - 1.0).abs() < 1e-12);
    }

    fn fact(pred: &str, args: &[&str], probability: Option<f64>) -> Fact {
        let mut f = crate::kb::test_fact(pred, args, "measured");
        std::sync::Arc::make_mut(&mut f.provenance).probability = probability;
        f
    }

    fn engine() -> crate::engine::Engine {
        crate::engine::Engine::new(
            logicpad::LogicPad::builtin(),
            crate::kb::Observability::everything(),
        )
        .expect("built-in engine")
    }

    /// car_1 is surely a vehicle, though it may be moving (a doubt, 0.3);
    /// car_2 is a vehicle with probability 0.8 and surely not moving.
    fn uncertain_window(e: &crate::engine::Engine) -> WindowKb {
        let input = crate::kb::test_input(
            vec![
                fact("Vehicles", &["car_1"], None),
                fact("Vehicles", &["car_2"], Some(0.8)),
            ],
            vec![fact("Moving", &["car_1"], Some(0.3))],
        );
        e.build(input).expect("window builds")
    }

    #[test]
    fn a_yes_is_the_disjunction_of_its_proofs_and_negation_reads_the_doubts() {
        let e = engine();
        let kb = uncertain_window(&e);
        assert!(kb.is_uncertain());
        let r = e.ask(&kb, &e.prepare_query("Stopped(x)"), AskOptions::BINDINGS);
        assert_eq!(r.answer, Outcome::Yes);
        // car_1: Vehicles certain, ¬Moving 1 − 0.3; car_2: Vehicles 0.8.
        assert_eq!(r.binding_probabilities, vec![0.7, 0.8]);
        // Either proof: 1 − 0.3 × 0.2.
        assert_eq!(r.probability, Some(0.94));
        // Proofs asked for by the caller are kept, and change nothing.
        let with = AskOptions {
            proofs: true,
            ..AskOptions::BINDINGS
        };
        let r2 = e.ask(&kb, &e.prepare_query("Stopped(x)"), with);
        assert_eq!(r2.probability, Some(0.94));
        assert_eq!(r2.proofs.len(), 2);
    }

    #[test]
    fn a_no_is_as_sure_as_no_flip_that_would_change_it() {
        let e = engine();
        let kb = uncertain_window(&e);
        let r = e.ask(&kb, &e.prepare_query("Moving(x)"), AskOptions::BINDINGS);
        assert_eq!(r.answer, Outcome::No);
        // Adding the doubt Moving(car_1) (0.3) makes it yes; dropping
        // Vehicles(car_2) (0.2) changes nothing.
        assert_eq!(r.probability, Some(0.7));
        assert!(r.binding_probabilities.is_empty());
        // And it says on what: the one flip that changes it, checked.
        assert_eq!(
            r.hinges,
            vec![Hinge {
                fact: "Moving(car_1)".into(),
                holds: false,
                chance: 0.3,
            }]
        );
        assert_eq!(
            r.hinges[0].sentence(),
            "The answer would change if Moving(car_1) held: the window says it does not hold, with probability 0.3 of being wrong."
        );
        // A yes to a yes/no question is read by its proofs, not its flips.
        let yes = e.ask(&kb, &e.prepare_query("Stopped(x)"), AskOptions::BINDINGS);
        assert!(yes.hinges.is_empty());
    }

    /// Regression: `max_proofs` is public configuration; past 31 the
    /// subset mask overflowed (a panic in a library on user input).
    #[test]
    fn a_huge_proof_limit_is_capped_not_a_panic() {
        let e = engine().with_belief_limits(BeliefLimits {
            max_proofs: 64,
            ..BeliefLimits::default()
        });
        let cars: Vec<String> = (0..40).map(|i| format!("car_{i}")).collect();
        let input = crate::kb::test_input(
            cars.iter()
                .map(|c| fact("Vehicles", &[c.as_str()], Some(0.5)))
                .collect(),
            Vec::new(),
        );
        let kb = e.build(input).expect("window builds");
        let r = e.ask(&kb, &e.prepare_query("Vehicles(x)"), AskOptions::BINDINGS);
        // The 16 most probable of 40 independent proofs at one half each.
        let want = rounded(1.0 - 0.5f64.powi(MAX_EXACT_PROOFS as i32));
        assert_eq!(r.probability, Some(want));
        assert_eq!(r.binding_probabilities.len(), 40);
    }

    #[test]
    fn a_certain_window_is_certain_and_a_count_states_nothing() {
        let e = engine();
        let input = crate::kb::test_input(vec![fact("Vehicles", &["car_1"], None)], Vec::new());
        let kb = e.build(input).expect("window builds");
        assert!(!kb.is_uncertain());
        let p = e.prepare_query("Stopped(x)");
        let r = e.ask(&kb, &p, AskOptions::BINDINGS);
        assert_eq!(r.probability, Some(1.0));
        assert!(r.binding_probabilities.is_empty());
        let count = AskOptions {
            count_only: true,
            ..AskOptions::BINDINGS
        };
        assert_eq!(e.ask(&uncertain_window(&e), &p, count).probability, None);
    }

    /// The probability that some term holds, by enumerating every world
    /// of the facts the terms mention: the naive evaluator the
    /// inclusion–exclusion is held to.
    fn by_worlds(terms: &[Term<'_>], probs: &[f64]) -> f64 {
        let n = probs.len();
        let mut total = 0.0;
        for world in 0u32..(1 << n) {
            let holds = |i: usize| world & (1 << i) != 0;
            let weight: f64 = (0..n)
                .map(|i| if holds(i) { probs[i] } else { 1.0 - probs[i] })
                .product();
            let some = terms.iter().any(|t| {
                t.iter().all(|(f, (h, _))| {
                    let i: usize = f.pred[1..].parse().expect("fact index");
                    holds(i) == *h
                })
            });
            if some {
                total += weight;
            }
        }
        total
    }

    proptest::proptest! {
        #[test]
        fn the_disjunction_agrees_with_every_world(
            probs in proptest::collection::vec(0.0f64..=1.0, 1..6),
            shape in proptest::collection::vec(
                proptest::collection::vec((0usize..6, proptest::bool::ANY), 0..4),
                1..5,
            ),
        ) {
            // A term's leaf (F<i>, holds): probability p_i, or 1 − p_i for
            // a negated leaf; a term needing a fact both ways is dropped
            // (a proof never does).
            let names: Vec<String> = (0..6).map(|i| format!("F{i}")).collect();
            let terms: Vec<Term> = shape
                .iter()
                .filter_map(|t| {
                    let mut term = Term::new();
                    for &(i, h) in t {
                        let i = i % probs.len();
                        let p = if h { probs[i] } else { 1.0 - probs[i] };
                        if let Some(&(old, _)) = term.get(&atom(&names[i]))
                            && old != h
                        {
                            return None;
                        }
                        term.insert(atom(&names[i]), (h, p));
                    }
                    Some(term)
                })
                .collect();
            proptest::prop_assume!(!terms.is_empty());
            let want = by_worlds(&terms, &probs);
            proptest::prop_assert!((disjunction(&terms) - want).abs() < 1e-9,
                "{} vs {want}", disjunction(&terms));
        }
    }

    /// Five cars each seen with probability 0.6: "at least 3" holds with
    /// P(Bin(5, 0.6) ≥ 3) = 0.68256, though no single flip changes it —
    /// never "certain".
    #[test]
    fn a_count_with_slack_is_as_sure_as_its_count_distribution() {
        let e = engine();
        let cars: Vec<String> = (0..5).map(|i| format!("car_{i}")).collect();
        let input = crate::kb::test_input(
            cars.iter()
                .map(|c| fact("Vehicles", &[c.as_str()], Some(0.6)))
                .collect(),
            vec![fact("Vehicles", &["car_9"], Some(0.5))],
        );
        let kb = e.build(input).expect("window builds");
        let r = e.ask(
            &kb,
            &e.prepare_query("#{x: Vehicles(x)} >= 3"),
            AskOptions::BINDINGS,
        );
        assert_eq!(r.answer, Outcome::Yes);
        assert_eq!(r.count, 5);
        // With the doubtful sixth car (0.5) as a possible witness:
        // P(Bin(5, .6) + Bern(.5) ≥ 3).
        let bin = |k: i32| {
            let c = [1.0, 5.0, 10.0, 10.0, 5.0, 1.0][k as usize];
            c * 0.6f64.powi(k) * 0.4f64.powi(5 - k)
        };
        let ge = |n: i32| (n.max(0)..=5).map(bin).sum::<f64>();
        let want = 0.5 * ge(3) + 0.5 * ge(2);
        assert_eq!(r.probability, Some(rounded(want)));
        assert!(r.probability.is_some_and(|p| p < 0.99));
        assert_eq!(r.binding_probabilities, vec![0.6; 5]);
        // The mirror question answers no, as surely.
        let r = e.ask(
            &kb,
            &e.prepare_query("#{x: Vehicles(x)} < 3"),
            AskOptions::BINDINGS,
        );
        assert_eq!(r.answer, Outcome::No);
        assert_eq!(r.probability, Some(rounded(want)));
    }

    /// A `¬∃` "yes" rests on the absence of every match: a doubt that
    /// would be one lowers it, and is its hinge.
    #[test]
    fn a_negated_exists_is_read_by_its_flips() {
        let e = engine();
        let kb = uncertain_window(&e);
        let r = e.ask(
            &kb,
            &e.prepare_query("¬∃x: (Moving(x))"),
            AskOptions::BINDINGS,
        );
        assert_eq!(r.answer, Outcome::Yes);
        assert_eq!(r.probability, Some(0.7));
        assert_eq!(r.hinges.len(), 1);
        assert_eq!(r.hinges[0].fact, "Moving(car_1)");
    }

    #[test]
    fn a_certain_proof_is_certain() {
        assert_eq!(disjunction(&[term(&[])]), 1.0);
        assert_eq!(rounded(0.99999), 0.9999);
        assert_eq!(rounded(1.0), 1.0);
    }
}
