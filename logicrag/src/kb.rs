//! The knowledge base of one window: perception facts (each with its
//! provenance) plus the LogicPad's rules, reasoned to a fixpoint.

use logicpad::{FactBase, LogicPad, Model, PredKind, Program};
use perception::{Fact, Provenance};
use std::collections::{BTreeMap, BTreeSet, HashMap, HashSet};

/// Errors while building a window's KB.
#[derive(Debug, thiserror::Error)]
pub enum KbError {
    /// Occurs when a fact cannot be stored (e.g. a predicate used with two arities).
    #[error("window {window}: {source}")]
    Fact {
        /// Window id.
        window: String,
        /// The underlying error.
        #[source]
        source: logicpad::FactError,
    },
}

/// One window's input: its id, frames and base facts with provenance.
#[derive(Debug, Clone)]
pub struct WindowInput {
    /// Stable window id (`0000_000010`, `urban_crossing#2`).
    pub id: String,
    /// Position of the window in its source (0-based).
    pub index: u32,
    /// First frame (inclusive).
    pub first_frame: u32,
    /// Last frame (inclusive).
    pub last_frame: u32,
    /// Base facts (duplicates are dropped when the KB is built, keeping
    /// the first one's provenance).
    pub facts: Vec<Fact>,
}

/// A reasoned window.
///
/// Invariant: `model` was evaluated from exactly `facts`, which hold no
/// duplicate; `fact_index[p][id]` is the position in `facts` of the base
/// fact with id `id` in the model's relation `p` (ids are insertion order,
/// so a fact's provenance is found through the model's own hash index, with
/// no sorting by string); `objects` are the constants that occur as a first
/// argument of some fact, `constants` those that occur anywhere.
#[derive(Debug, Clone)]
pub struct WindowKb {
    /// Window id.
    pub id: String,
    /// Position in the source.
    pub index: u32,
    /// First frame.
    pub first_frame: u32,
    /// Last frame.
    pub last_frame: u32,
    /// Base facts with provenance, in the source's order (sorted for
    /// perception's sources, file order for `facts:`).
    pub facts: Vec<Fact>,
    /// Per predicate, the position in `facts` of each base fact by its id.
    fact_index: HashMap<String, Vec<u32>>,
    /// Base and derived relations.
    pub model: Model,
    /// Object constants of the window, sorted.
    pub objects: BTreeSet<String>,
    /// Every constant that occurs in some base fact, in any position.
    pub constants: BTreeSet<String>,
}

/// Answers items addressed to windows by id, reasoning over each window
/// once and windows in parallel; the answers come back in item order.
///
/// `window_of(i)` names item `i`'s window; an id that names no window is
/// `unknown(i)` for the first such item, before any reasoning. `answer` runs
/// on worker threads, and so does `done(n)`, called when a window's `n`
/// items are answered.
pub fn answer_by_window<T, E>(
    program: &Program,
    windows: Vec<WindowInput>,
    items: usize,
    window_of: impl Fn(usize) -> String,
    unknown: impl FnOnce(usize) -> E,
    answer: impl Fn(&WindowKb, usize) -> T + Sync,
    done: &(dyn Fn(usize) + Sync),
) -> Result<Vec<T>, E>
where
    T: Send,
    E: Send + From<KbError>,
{
    use rayon::prelude::*;
    let by_id: std::collections::HashMap<&str, usize> = windows
        .iter()
        .enumerate()
        .map(|(i, w)| (w.id.as_str(), i))
        .collect();
    // Item positions grouped by window, in the windows' own order.
    let mut groups: Vec<Vec<usize>> = vec![Vec::new(); windows.len()];
    for i in 0..items {
        match by_id.get(window_of(i).as_str()) {
            Some(&w) => groups[w].push(i),
            None => return Err(unknown(i)),
        }
    }
    let work: Vec<(WindowInput, Vec<usize>)> = windows
        .into_iter()
        .zip(groups)
        .filter(|(_, g)| !g.is_empty())
        .collect();
    let answered: Result<Vec<Vec<(usize, T)>>, E> = work
        .into_par_iter()
        .map(|(input, group)| {
            let kb = WindowKb::build(input, program)?;
            let n = group.len();
            let out: Vec<(usize, T)> = group.into_iter().map(|i| (i, answer(&kb, i))).collect();
            done(n);
            Ok(out)
        })
        .collect();
    let mut answered: Vec<(usize, T)> = answered?.into_iter().flatten().collect();
    answered.sort_by_key(|(i, _)| *i);
    Ok(answered.into_iter().map(|(_, t)| t).collect())
}

impl WindowKb {
    /// Reasons over a window's facts with a program.
    pub fn build(mut input: WindowInput, program: &Program) -> Result<WindowKb, KbError> {
        let mut base = FactBase::new();
        let mut fact_index: HashMap<String, Vec<u32>> = HashMap::new();
        let mut keep: Vec<bool> = Vec::with_capacity(input.facts.len());
        // Hash sets while scanning (a window may hold millions of facts over
        // a few thousand names), sorted once at the end.
        let mut objects: HashSet<&str> = HashSet::new();
        let mut constants: HashSet<&str> = HashSet::new();
        let mut args: Vec<&str> = Vec::with_capacity(4);
        let mut kept = 0u32;
        for f in &input.facts {
            args.clear();
            args.extend(f.args.iter().map(String::as_str));
            let new = base
                .add(&f.predicate, &args)
                .map_err(|source| KbError::Fact {
                    window: input.id.clone(),
                    source,
                })?;
            keep.push(new);
            if !new {
                continue;
            }
            // The relation hands out ids in insertion order: the n-th new
            // fact of a predicate has id n.
            match fact_index.get_mut(f.predicate.as_str()) {
                Some(ids) => ids.push(kept),
                None => {
                    fact_index.insert(f.predicate.clone(), vec![kept]);
                }
            }
            kept += 1;
            if let Some(first) = f.args.first() {
                objects.insert(first);
            }
            constants.extend(args.iter().copied());
        }
        let objects: BTreeSet<String> = objects.into_iter().map(str::to_string).collect();
        let constants: BTreeSet<String> = constants.into_iter().map(str::to_string).collect();
        if keep.iter().any(|k| !k) {
            let mut k = keep.iter();
            input.facts.retain(|_| k.next().copied().unwrap_or(false));
        }
        let model = program.evaluate(base).map_err(|source| KbError::Fact {
            window: input.id.clone(),
            source,
        })?;
        Ok(WindowKb {
            id: input.id,
            index: input.index,
            first_frame: input.first_frame,
            last_frame: input.last_frame,
            facts: input.facts,
            fact_index,
            model,
            objects,
            constants,
        })
    }

    /// Where a base fact came from.
    pub fn provenance(&self, predicate: &str, args: &[String]) -> Option<&Provenance> {
        let rel = self.model.relation(predicate)?;
        let terms: smallvec::SmallVec<[kanren::Term; 4]> =
            args.iter().map(|a| kanren::sym(a.as_str())).collect();
        let id = rel.id_of(&terms)?;
        // Derived facts have ids past the base facts: no entry, no provenance.
        let at = *self.fact_index.get(predicate)?.get(id as usize)?;
        self.facts.get(at as usize).map(|f| &*f.provenance)
    }

    /// Base facts grouped by their first argument (the object they describe).
    pub fn facts_by_object(&self) -> BTreeMap<&str, Vec<&Fact>> {
        let mut m: BTreeMap<&str, Vec<&Fact>> = BTreeMap::new();
        for f in &self.facts {
            if let Some(a) = f.args.first() {
                m.entry(a.as_str()).or_default().push(f);
            }
        }
        m
    }
}

/// How completely a source can observe a predicate.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord)]
pub enum Observed {
    /// The source never produces it: an absent fact says nothing.
    Never,
    /// Some of its rules rest on unobservable predicates: a present fact is
    /// proved, an absent one says nothing.
    Partly,
    /// Fully observed: the closed-world assumption holds.
    Fully,
}

/// What a source can observe, as the set of base predicates it cannot produce.
/// Derived predicates inherit from their rules.
#[derive(Debug, Clone, Default)]
pub struct Observability {
    /// Base predicates this source never produces, with the reason.
    pub unobservable: BTreeMap<String, String>,
}

impl Observability {
    /// A source that observes everything its LogicPad declares.
    pub fn everything() -> Observability {
        Observability::default()
    }

    /// Marks predicates as unobservable for a reason.
    pub fn without(mut self, preds: &[&str], why: &str) -> Observability {
        for p in preds {
            self.unobservable.insert((*p).to_string(), why.to_string());
        }
        self
    }

    /// The base predicates under `pred` (itself, or those its rules rest on,
    /// through derived ones) that this source cannot observe, each with the
    /// source's reason: what an "unknown" answer tells the user.
    pub fn blind_spots(&self, pad: &LogicPad, pred: &str) -> Vec<(String, String)> {
        let program = pad.program();
        let mut seen = BTreeSet::new();
        let mut stack = vec![pred.to_string()];
        let mut out = Vec::new();
        while let Some(p) = stack.pop() {
            if !seen.insert(p.clone()) {
                continue;
            }
            if let Some(why) = self.unobservable.get(&p) {
                out.push((p, why.clone()));
                continue;
            }
            let Some(pid) = program.pred_id(&p) else {
                continue;
            };
            for r in program.rules().iter().filter(|r| r.head.pred == pid) {
                for a in r.body.iter().chain(r.negated.iter()) {
                    if let Some(name) = program.pred_name(a.pred) {
                        stack.push(name.to_string());
                    }
                }
            }
        }
        out.sort();
        out
    }

    /// Observability of every predicate of a program (fixpoint over the rules:
    /// a derived predicate is fully observed when every rule for it rests on
    /// fully observed predicates only; partly when at least one rule does, or
    /// when it has any rule at all that can fire on observed facts).
    ///
    /// The fixpoint is the greatest one: a recursive rule over fully observed
    /// facts (`Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)`) computes its
    /// predicate exactly, so it must not hold its own predicate down.
    pub fn classify(&self, pad: &LogicPad) -> BTreeMap<String, Observed> {
        let program = pad.program();
        let schema = pad.schema();
        let mut status: BTreeMap<String, Observed> = BTreeMap::new();
        for p in schema.predicates() {
            // Derived predicates start fully observed and fall in the fixpoint below.
            let s = if self.unobservable.contains_key(&p.name) {
                Observed::Never
            } else {
                Observed::Fully
            };
            status.insert(p.name.clone(), s);
        }
        // Derived predicates: iterate to a fixpoint (recursion converges
        // because a rule's status is monotone in its body's, so statuses only fall).
        loop {
            let mut changed = false;
            for p in schema.predicates().filter(|p| p.kind == PredKind::Derived) {
                if self.unobservable.contains_key(&p.name) {
                    continue;
                }
                let Some(pid) = program.pred_id(&p.name) else {
                    continue;
                };
                let rules: Vec<_> = program
                    .rules()
                    .iter()
                    .filter(|r| r.head.pred == pid)
                    .collect();
                let rule_status = |r: &&logicpad::Rule| -> Observed {
                    let mut worst = Observed::Fully;
                    for a in r.body.iter().chain(r.negated.iter()) {
                        let name = program.pred_name(a.pred).unwrap_or_default();
                        let s = status.get(name).copied().unwrap_or(Observed::Never);
                        let s = if r.negated.contains(a) && s != Observed::Fully {
                            // ¬P on a partly observed P can be wrongly true.
                            Observed::Never
                        } else {
                            s
                        };
                        worst = worst.min(s);
                    }
                    worst
                };
                let statuses: Vec<Observed> = rules.iter().map(rule_status).collect();
                let new = if statuses.is_empty() {
                    Observed::Never
                } else if statuses.iter().all(|s| *s == Observed::Fully) {
                    Observed::Fully
                } else if statuses.iter().any(|s| *s != Observed::Never) {
                    Observed::Partly
                } else {
                    Observed::Never
                };
                let old = status.get(&p.name).copied().unwrap_or(Observed::Never);
                if new < old {
                    status.insert(p.name.clone(), new);
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
        status
    }
}

/// A window of bare facts (frames 0–9, provenance "test") for unit tests.
#[cfg(test)]
pub(crate) fn test_window(program: &Program, lines: &[(&str, &[&str])]) -> WindowKb {
    let facts = lines
        .iter()
        .map(|(p, args)| Fact {
            predicate: (*p).to_string(),
            args: args.iter().map(|a| (*a).to_string()).collect(),
            provenance: std::sync::Arc::new(Provenance {
                window: 0,
                frames: (0, 9),
                source: "test".into(),
                measured: None,
                threshold: None,
                note: String::new(),
            }),
        })
        .collect();
    let input = WindowInput {
        id: "w".into(),
        index: 0,
        first_frame: 0,
        last_frame: 9,
        facts,
    };
    match WindowKb::build(input, program) {
        Ok(kb) => kb,
        Err(e) => panic!("test window does not build: {e}"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const REACH: &str = "atomic_predicates:
  tracker:
    - Edge(x, y)
    - Seen(x)
derived_predicates:
  - name: Reach
    logic:
      - \"∀x,y : Edge(x, y) ==> Reach(x, y)\"
      - \"∀x,y,z : Reach(x, y) ∧ Edge(y, z) ==> Reach(x, z)\"
  - name: Cut
    logic: \"∀x,y : Edge(x, y) ∧ ¬Reach(y, x) ==> Cut(x, y)\"
";

    #[test]
    fn provenance_is_found_through_fact_ids_in_any_order() {
        // Regression for the unsorted fact path: facts arrive in file
        // order, a duplicate keeps the first one's provenance, and a
        // derived fact has none.
        let pad = LogicPad::parse(REACH, "reach.yaml", true).expect("loads");
        let fact = |p: &str, args: &[&str], note: &str| Fact {
            predicate: p.to_string(),
            args: args.iter().map(|a| a.to_string()).collect(),
            provenance: std::sync::Arc::new(Provenance {
                window: 0,
                frames: (0, 9),
                source: "test".into(),
                measured: None,
                threshold: None,
                note: note.to_string(),
            }),
        };
        let input = WindowInput {
            id: "w".into(),
            index: 0,
            first_frame: 0,
            last_frame: 9,
            facts: vec![
                fact("Edge", &["c", "d"], "first c-d"),
                fact("Seen", &["a"], "seen a"),
                fact("Edge", &["a", "b"], "a-b"),
                fact("Edge", &["c", "d"], "second c-d"),
            ],
        };
        let kb = WindowKb::build(input, pad.program()).expect("builds");
        assert_eq!(kb.facts.len(), 3, "the duplicate is dropped");
        let note = |p: &str, args: &[&str]| {
            let args: Vec<String> = args.iter().map(|a| a.to_string()).collect();
            kb.provenance(p, &args).map(|pr| pr.note.clone())
        };
        assert_eq!(note("Edge", &["c", "d"]).as_deref(), Some("first c-d"));
        assert_eq!(note("Edge", &["a", "b"]).as_deref(), Some("a-b"));
        assert_eq!(note("Seen", &["a"]).as_deref(), Some("seen a"));
        assert!(kb.model.holds("Reach", &["a", "b"]));
        assert_eq!(note("Reach", &["a", "b"]), None, "derived");
        assert_eq!(note("Edge", &["b", "a"]), None, "absent");
        assert_eq!(note("Nope", &["a"]), None, "unknown predicate");
    }

    #[test]
    fn recursion_over_observed_facts_is_fully_observed() {
        // Regression: the fixpoint rose from "never", so a recursive rule
        // kept its predicate at "partly" and a true "no" became "unknown".
        let pad = LogicPad::parse(REACH, "r.yaml", false).expect("loads");
        assert!(pad.diagnostics().is_empty(), "{:?}", pad.diagnostics());
        let s = Observability::everything().classify(&pad);
        assert_eq!(s.get("Reach"), Some(&Observed::Fully));
        assert_eq!(s.get("Cut"), Some(&Observed::Fully));
    }

    #[test]
    fn a_constant_seen_only_in_a_later_argument_is_still_a_constant() {
        // Regression: only first arguments counted as constants, so in
        // `Reach(n0, n2)` the chain's end `n2` was read as a variable and the
        // query answered "yes" with `n2 = n1` among its bindings.
        let pad = LogicPad::parse(REACH, "r.yaml", false).expect("loads");
        let kb = test_window(
            pad.program(),
            &[("Edge", &["n0", "n1"]), ("Edge", &["n1", "n2"])],
        );
        assert!(!logicpad::is_variable_name("n2"));
        assert!(!kb.objects.contains("n2"));
        let observed = Observability::everything().classify(&pad);
        let r = crate::ask::ask(&pad, &kb, &observed, "Reach(n0, n2)", Default::default());
        assert_eq!(r.answer, crate::ask::Outcome::Yes);
        assert_eq!(r.bindings, vec![Vec::<(String, String)>::new()]);
        let r = crate::ask::ask(&pad, &kb, &observed, "Reach(n2, n0)", Default::default());
        assert_eq!(r.answer, crate::ask::Outcome::No);
    }

    #[test]
    fn a_value_shaped_like_a_variable_does_not_capture_the_translators_x() {
        // Regression: with every argument a constant, `Label(car_1, x)` made
        // `x` a constant, and "How many vehicles are moving?"
        // (`Vehicles(x)^Move(x)`) answered no.
        let pad = LogicPad::builtin();
        let kb = test_window(
            pad.program(),
            &[
                ("Moving", &["car_1"]),
                ("SharesFrames", &["car_1", "y"]),
                ("Vehicles", &["car_1"]),
            ],
        );
        let observed = Observability::everything().classify(&pad);
        let r = crate::ask::ask(
            &pad,
            &kb,
            &observed,
            "Vehicles(y)^Moving(y)",
            Default::default(),
        );
        assert_eq!(r.answer, crate::ask::Outcome::Yes);
        assert_eq!(r.count, 1);
    }

    #[test]
    fn recursion_over_an_unobservable_base_is_never_observed() {
        let pad = LogicPad::parse(REACH, "r.yaml", false).expect("loads");
        let s = Observability::everything()
            .without(&["Edge"], "no edges")
            .classify(&pad);
        assert_eq!(s.get("Edge"), Some(&Observed::Never));
        assert_eq!(s.get("Reach"), Some(&Observed::Never));
        assert_eq!(s.get("Cut"), Some(&Observed::Never));
        assert_eq!(s.get("Seen"), Some(&Observed::Fully));
    }
}
