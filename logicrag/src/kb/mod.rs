//! The knowledge base of one window: perception facts (each with its
//! provenance) plus the LogicPad's rules, reasoned to a fixpoint.

use crate::facts_text::ParsedFacts;
use kanren::{FactId, Relation, Sym, Term};
use logicpad::{FactBase, LogicPad, Model, PredKind, Program};
use perception::{Fact, Provenance};
use std::collections::{BTreeMap, BTreeSet};
use std::sync::Arc;

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

mod input;
mod observe;
mod schedule;
mod store;

pub use input::*;
pub use observe::*;
pub use schedule::*;
use store::*;

/// A reasoned window.
///
/// Invariants: `model` was evaluated from exactly the base facts, which are
/// stored once, in the model's relations; the private `base` columns only
/// say in which order they came and where each came from. `objects` are
/// the constants that occur as a first argument of some base fact,
/// `constants` those that occur anywhere.
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
    /// The base facts' order and provenance; their tuples are the model's.
    base: BaseFacts,
    /// Base and derived relations.
    pub model: Model,
    /// Object constants of the window, sorted (interned names).
    pub objects: BTreeSet<&'static str>,
    /// The symbols of `objects`, in the same order (why-not tests every
    /// object against the model; finding a symbol by name hashes it).
    object_syms: Vec<Sym>,
    /// The same symbols sorted by symbol, to tell an object by its symbol
    /// with a binary search of integers (why-not asks it of every holder
    /// of a literal; a name lookup compares strings).
    object_syms_sorted: Vec<Sym>,
    /// The symbols of `constants`, sorted by symbol (every query asks
    /// whether its constants occur in the window).
    constant_syms_sorted: Vec<Sym>,
    /// Every constant that occurs in some base fact, in any position
    /// (interned names).
    pub constants: BTreeSet<&'static str>,
    /// Measured and not asserted (see [`WindowInput::doubts`]).
    doubts: Arc<Vec<Fact>>,
    /// The doubts' probabilities by predicate and arguments, sorted so
    /// (the last of duplicates kept), for the negated leaves of proofs:
    /// looked up by the atom, never by its text.
    doubt_of: Arc<Vec<(String, Vec<String>, f64)>>,
    /// Some base fact is below probability 1, or `doubts` is not empty.
    uncertain: bool,
    /// The window re-reasoned with one uncertain fact flipped, built on
    /// the first question whose answer's probability needs them
    /// ([`crate::belief`]).
    pub(crate) flips: Arc<std::sync::OnceLock<crate::belief::Flips>>,
    /// The holder sets why-not found in this window, shared by its
    /// questions.
    pub(crate) holders: Arc<crate::whynot::HolderCache>,
}

/// A window id a source does not have: the one message every front end
/// (CLI, REPL, batch, eval, serve, Python) gives for it.
///
/// Invariant: `id` is at most `NoWindow::MAX_ID` characters (a longer id
/// is cut, so an error never echoes a megabyte of input), `known` lists at
/// most `NoWindow::SHOWN` of the source's ids.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{label} has no window `{id}` ({known})")]
pub struct NoWindow {
    /// The source's label.
    pub label: String,
    /// The id asked for (cut to `NoWindow::MAX_ID` characters).
    pub id: String,
    /// "it has a, b, c, …", or "it has none".
    pub known: String,
}

impl NoWindow {
    /// Window ids listed.
    pub(crate) const SHOWN: usize = 5;
    /// Characters of the asked id repeated in the message.
    pub(crate) const MAX_ID: usize = 80;

    /// The error for `id` on a source labelled `label` whose windows are `ids`.
    pub fn new<'a>(label: &str, id: &str, ids: impl IntoIterator<Item = &'a str>) -> NoWindow {
        let mut ids = ids.into_iter();
        let shown: Vec<&str> = ids.by_ref().take(NoWindow::SHOWN).collect();
        let more = ids.next().is_some();
        let known = if shown.is_empty() {
            "it has none".to_string()
        } else {
            format!(
                "it has {}{}",
                shown.join(", "),
                if more { ", …" } else { "" }
            )
        };
        let id = if id.chars().count() > NoWindow::MAX_ID {
            format!("{}…", id.chars().take(NoWindow::MAX_ID).collect::<String>())
        } else {
            id.to_string()
        };
        NoWindow {
            label: label.to_string(),
            id,
            known,
        }
    }
}

impl WindowKb {
    /// Reasons over a window's facts with a program.
    pub fn build(input: WindowInput, program: &Program) -> Result<WindowKb, KbError> {
        WindowKb::build_after(input, program, None)
    }

    /// Reasons over a window's facts with a program, reusing from `prev`
    /// (the window before it, typically overlapping) every component of
    /// the program whose inputs did not change
    /// ([`Program::evaluate_after`]). The KB is the one [`WindowKb::build`]
    /// makes; only the work differs.
    pub(crate) fn build_after(
        input: WindowInput,
        program: &Program,
        prev: Option<&WindowKb>,
    ) -> Result<WindowKb, KbError> {
        let WindowInput {
            id,
            index,
            first_frame,
            last_frame,
            facts,
            doubts,
        } = input;
        let err = |source| KbError::Fact {
            window: id.clone(),
            source,
        };
        // Listed facts are interned into the parsed form first: one path
        // stores both.
        let (columns, listed, one) = match &facts {
            WindowFacts::Listed(list) => (
                std::borrow::Cow::Owned(ParsedFacts::intern(list).map_err(err)?),
                Some(list),
                None,
            ),
            WindowFacts::Parsed { facts, provenance } => {
                (std::borrow::Cow::Borrowed(facts), None, Some(provenance))
            }
        };
        let Stored {
            base,
            preds,
            pred_of,
            new,
            objects,
            constants,
        } = store(&columns).map_err(err)?;
        drop(columns);
        // The source order and provenance columns: the `k`-th new fact of a
        // predicate has id `k`.
        let mut next_id = vec![0 as FactId; preds.len()];
        // Sized exactly: these columns live as long as the KB.
        let mut kept_of = vec![0usize; preds.len()];
        for (&p, _) in pred_of.iter().zip(&new).filter(|(_, n)| **n) {
            if let Some(k) = kept_of.get_mut(p as usize) {
                *k += 1;
            }
        }
        let mut prov: Vec<Vec<u32>> = kept_of.into_iter().map(Vec::with_capacity).collect();
        let mut order: Vec<(u32, FactId)> = Vec::with_capacity(new.iter().filter(|n| **n).count());
        let mut provenances: Vec<Arc<Provenance>> = one.into_iter().cloned().collect();
        let kept = pred_of
            .iter()
            .zip(&new)
            .enumerate()
            .filter(|(_, (_, n))| **n);
        for (i, (&p, _)) in kept {
            let (Some(id), Some(ids)) = (next_id.get_mut(p as usize), prov.get_mut(p as usize))
            else {
                continue;
            };
            if let Some(f) = listed.and_then(|l| l.get(i)) {
                let shared = provenances
                    .last()
                    .is_some_and(|last| Arc::ptr_eq(last, &f.provenance));
                if !shared {
                    provenances.push(Arc::clone(&f.provenance));
                }
            }
            ids.push(u32::try_from(provenances.len().saturating_sub(1)).unwrap_or(u32::MAX));
            order.push((p, *id));
            *id += 1;
        }
        let uncertain = !doubts.is_empty() || provenances.iter().any(|p| p.belief() < 1.0);
        // The input is no longer needed: freed before reasoning grows the
        // model.
        drop((pred_of, new, facts));
        let model = match prev {
            Some(prev) => program.evaluate_after(&prev.model, base),
            None => program.evaluate(base),
        }
        .map_err(err)?;
        let rels: Vec<Arc<Relation>> = preds
            .iter()
            .map(|p| match model.relation(p.as_str()) {
                Some(r) => Arc::clone(r),
                // Evaluation keeps every base relation; an empty one keeps
                // the columns consistent should that ever change.
                None => Arc::new(Relation::new(*p, 0)),
            })
            .collect();
        let by_name = preds
            .iter()
            .enumerate()
            .map(|(i, p)| (p.as_str(), u32::try_from(i).unwrap_or(u32::MAX)))
            .collect();
        Ok(WindowKb {
            id,
            index,
            first_frame,
            last_frame,
            base: BaseFacts {
                rels,
                by_name,
                order,
                prov,
                provenances,
            },
            model,
            object_syms_sorted: sorted_syms(&objects),
            constant_syms_sorted: sorted_syms(&constants),
            object_syms: syms_by_name(&objects),
            objects: names(objects),
            constants: names(constants),
            doubt_of: Arc::new(doubt_index(&doubts)),
            doubts: Arc::new(doubts),
            uncertain,
            flips: Arc::default(),
            holders: Arc::default(),
        })
    }

    /// Facts perception measured and did not assert, with the probability
    /// that each holds all the same.
    pub fn doubts(&self) -> &[Fact] {
        &self.doubts
    }

    /// The probability that the atom `pred(args)` (`Moving(car_1)`),
    /// absent from the window, holds all the same: `Some` only for a
    /// doubt.
    pub fn doubt<S: AsRef<str>>(&self, pred: &str, args: &[S]) -> Option<f64> {
        if self.doubt_of.is_empty() {
            return None;
        }
        let i = self
            .doubt_of
            .binary_search_by(|(p, a, _)| {
                p.as_str().cmp(pred).then_with(|| {
                    a.iter()
                        .map(String::as_str)
                        .cmp(args.iter().map(AsRef::as_ref))
                })
            })
            .ok()?;
        self.doubt_of.get(i).map(|d| d.2)
    }

    /// Whether some base fact has a probability below 1 or some fact is in
    /// doubt: only then is an answer's probability worth computing.
    pub(crate) fn is_uncertain(&self) -> bool {
        self.uncertain
    }

    /// The base facts with their provenance, in the source's order (sorted
    /// for perception's sources, file order for `facts:`), duplicates
    /// dropped.
    pub fn facts(&self) -> impl ExactSizeIterator<Item = FactRef<'_>> + '_ {
        // `fact` finds every listed fact (see `BaseFacts`' invariants); the
        // fallback keeps the iterator's length exact regardless.
        self.base.order.iter().map(|&(p, id)| {
            self.base.fact(p, id).unwrap_or(FactRef {
                predicate: "",
                args: Args::Syms(&[]),
                provenance: no_provenance(),
            })
        })
    }

    /// Number of base facts (duplicates dropped).
    pub fn fact_count(&self) -> usize {
        self.base.order.len()
    }

    /// Where a base fact came from.
    pub fn provenance<S: AsRef<str>>(&self, predicate: &str, args: &[S]) -> Option<&Provenance> {
        self.shared_provenance(predicate, args).map(|p| &**p)
    }

    /// Where a base fact came from, as the shared handle the KB keeps (a
    /// proof node takes it without copying the provenance's strings).
    pub(crate) fn shared_provenance<S: AsRef<str>>(
        &self,
        predicate: &str,
        args: &[S],
    ) -> Option<&Arc<Provenance>> {
        let p = *self.base.by_name.get(predicate)?;
        let rel = self.base.rels.get(p as usize)?;
        // Looked up, not interned: a name no fact holds has no provenance,
        // and asking must not grow the interner.
        let terms: Option<smallvec::SmallVec<[Term; 4]>> = args
            .iter()
            .map(|a| Sym::lookup(a.as_ref()).map(Term::Sym))
            .collect();
        let id = rel.id_of(&terms?)?;
        // Derived facts have ids past the base facts: no entry, no provenance.
        let at = *self.base.prov.get(p as usize)?.get(id as usize)?;
        self.base.provenances.get(at as usize)
    }

    /// The provenance of base fact `id` of `predicate`'s relation (the id a
    /// proof's [`DerivationTree::Base`](logicpad::DerivationTree) node
    /// carries): no names to look up, so a proof of a thousand facts costs
    /// a thousand array reads. `None` for an id past the base facts.
    pub(crate) fn provenance_of_id(&self, predicate: &str, id: FactId) -> Option<&Arc<Provenance>> {
        let p = *self.base.by_name.get(predicate)?;
        let at = *self.base.prov.get(p as usize)?.get(id as usize)?;
        self.base.provenances.get(at as usize)
    }

    /// Whether `sym` occurs in some base fact of the window.
    pub(crate) fn is_constant(&self, sym: Sym) -> bool {
        self.constant_syms_sorted.binary_search(&sym).is_ok()
    }

    /// Whether `sym` is one of the window's objects.
    pub(crate) fn is_object(&self, sym: Sym) -> bool {
        self.object_syms_sorted.binary_search(&sym).is_ok()
    }

    /// The window's objects with their symbols, sorted by name.
    pub(crate) fn objects_with_syms(&self) -> impl Iterator<Item = (&'static str, Sym)> + '_ {
        self.objects
            .iter()
            .copied()
            .zip(self.object_syms.iter().copied())
    }

    /// Base facts grouped by their first argument (the object they describe).
    pub(crate) fn facts_by_object(&self) -> BTreeMap<&str, Vec<FactRef<'_>>> {
        let mut m: BTreeMap<&str, Vec<FactRef<'_>>> = BTreeMap::new();
        for f in self.facts() {
            if let Some(a) = f.arg(0) {
                m.entry(a).or_default().push(f);
            }
        }
        m
    }
}

/// The doubts' probabilities sorted by predicate and arguments, for
/// [`WindowKb::doubt`]; of two doubts of one atom the later is kept.
fn doubt_index(doubts: &[Fact]) -> Vec<(String, Vec<String>, f64)> {
    let mut all: Vec<(String, Vec<String>, f64)> = doubts
        .iter()
        .map(|d| (d.predicate.clone(), d.args.clone(), d.provenance.belief()))
        .collect();
    // Stable: duplicates stay in input order, and the last one wins.
    all.sort_by(|a, b| (&a.0, &a.1).cmp(&(&b.0, &b.1)));
    let mut out: Vec<(String, Vec<String>, f64)> = Vec::with_capacity(all.len());
    for d in all {
        match out.last_mut() {
            Some(last) if last.0 == d.0 && last.1 == d.1 => *last = d,
            _ => out.push(d),
        }
    }
    out
}

/// A fact of window 0, frames 0–9, with `note` as its provenance.
#[cfg(test)]
pub(crate) fn test_fact(predicate: &str, args: &[&str], note: &str) -> Fact {
    Fact {
        predicate: predicate.to_string(),
        args: args.iter().map(|a| (*a).to_string()).collect(),
        provenance: std::sync::Arc::new(Provenance {
            window: 0,
            frames: (0, 9),
            source: "test".into(),
            measured: None,
            threshold: None,
            note: note.to_string(),
            probability: None,
        }),
    }
}

/// Window `w`, frames 0–9, of `facts` and `doubts` (tests).
#[cfg(test)]
pub(crate) fn test_input(facts: Vec<Fact>, doubts: Vec<Fact>) -> WindowInput {
    WindowInput {
        id: "w".into(),
        index: 0,
        first_frame: 0,
        last_frame: 9,
        facts: WindowFacts::Listed(facts),
        doubts,
    }
}

/// A window of bare facts (frames 0–9) reasoned under `program`, for
/// unit tests.
#[cfg(test)]
pub(crate) fn test_window(program: &Program, lines: &[(&str, &[&str])]) -> WindowKb {
    let facts = lines
        .iter()
        .map(|(p, args)| test_fact(p, args, ""))
        .collect();
    let input = test_input(facts, Vec::new());
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
        let fact = test_fact;
        let input = crate::kb::test_input(
            vec![
                fact("Edge", &["c", "d"], "first c-d"),
                fact("Seen", &["a"], "seen a"),
                fact("Edge", &["a", "b"], "a-b"),
                fact("Edge", &["c", "d"], "second c-d"),
            ],
            Vec::new(),
        );
        let kb = WindowKb::build(input, pad.program()).expect("builds");
        assert_eq!(kb.fact_count(), 3, "the duplicate is dropped");
        let listed: Vec<(String, &str)> = kb
            .facts()
            .map(|f| (f.to_kb_line(), f.provenance().note.as_str()))
            .collect();
        assert_eq!(
            listed,
            [
                ("Edge(c, d)".to_string(), "first c-d"),
                ("Seen(a)".to_string(), "seen a"),
                ("Edge(a, b)".to_string(), "a-b"),
            ],
            "source order, first provenance"
        );
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

    fn note(n: &str) -> Arc<Provenance> {
        Arc::new(Provenance {
            window: 0,
            frames: (0, 9),
            source: "test".into(),
            measured: Some(1.5),
            threshold: Some(("t".into(), 1.0)),
            note: n.to_string(),
            probability: None,
        })
    }

    fn window(facts: WindowFacts) -> WindowInput {
        WindowInput {
            id: "w".into(),
            index: 0,
            first_frame: 0,
            last_frame: 9,
            facts,
            doubts: Vec::new(),
        }
    }

    /// Everything a reader of the KB sees of its base facts.
    fn seen(kb: &WindowKb) -> Vec<(String, String)> {
        kb.facts()
            .map(|f| (f.to_kb_line(), f.provenance().note.clone()))
            .collect()
    }

    #[test]
    fn a_parsed_window_builds_as_the_same_facts_listed() {
        let pad = LogicPad::parse(REACH, "reach.yaml", true).expect("loads");
        let text = "Edge(c, d)\nSeen(a)\nEdge(a, b)\nEdge(c, d)\nOther(x, y, z)\n";
        let shared = note("file");
        let parsed = crate::facts_text::parse_facts_interned(text, "w.facts").expect("parses");
        let listed: Vec<Fact> = crate::facts_text::parse_facts(text, "w.facts")
            .expect("parses")
            .into_iter()
            .map(|t| Fact {
                predicate: t.predicate,
                args: t.args,
                provenance: Arc::clone(&shared),
            })
            .collect();
        let a = WindowKb::build(
            window(WindowFacts::Parsed {
                facts: parsed,
                provenance: Arc::clone(&shared),
            }),
            pad.program(),
        )
        .expect("builds");
        let b =
            WindowKb::build(window(WindowFacts::Listed(listed)), pad.program()).expect("builds");
        assert_eq!(a.fact_count(), 4);
        assert_eq!(seen(&a), seen(&b));
        assert_eq!(a.objects, b.objects);
        assert_eq!(a.constants, b.constants);
        assert_eq!(a.base.provenances.len(), 1, "one provenance for the file");
        let objects: Vec<&str> = a.objects.iter().copied().collect();
        assert_eq!(objects, ["a", "c", "x"]);
        assert!(a.constants.contains("z"));
        assert_eq!(
            a.provenance("Other", &["x", "y", "z"])
                .map(|p| p.note.as_str()),
            Some("file")
        );
        let by_object: Vec<(&str, usize)> = a
            .facts_by_object()
            .into_iter()
            .map(|(o, fs)| (o, fs.len()))
            .collect();
        assert_eq!(by_object, [("a", 2), ("c", 1), ("x", 1)]);
    }

    #[test]
    fn a_fact_ref_is_serialised_and_owned_as_its_fact() {
        let pad = LogicPad::parse(REACH, "reach.yaml", true).expect("loads");
        let fact = Fact {
            predicate: "Edge".into(),
            args: vec!["a".into(), "b".into()],
            provenance: note("measured"),
        };
        let kb = WindowKb::build(
            window(WindowFacts::Listed(vec![fact.clone()])),
            pad.program(),
        )
        .expect("builds");
        let r = kb.facts().next().expect("one fact");
        assert_eq!(
            serde_json::to_string(&r).expect("serialises"),
            serde_json::to_string(&fact).expect("serialises")
        );
        assert_eq!(r.to_fact(), fact);
        assert_eq!(r.to_kb_line(), fact.to_kb_line());
        assert_eq!(r.args().len(), 2);
        assert!(Arc::ptr_eq(r.shared_provenance(), &fact.provenance));
    }

    #[test]
    fn a_large_window_stored_in_parallel_keeps_order_ids_and_first_provenance() {
        // Past the size stored on several threads: source order, the first
        // copy's provenance, ids that find each fact in the model, and
        // consecutive facts sharing one provenance stored once.
        let pad = LogicPad::parse(REACH, "reach.yaml", true).expect("loads");
        let n = PARALLEL_FACTS + 5000;
        let mut facts = Vec::with_capacity(n);
        let mut expected: Vec<(String, String)> = Vec::new();
        let mut seen_lines = std::collections::HashSet::new();
        let mut run = note("0");
        for i in 0..n {
            // Every 7th fact repeats an earlier one; every 3rd starts a new
            // provenance, the others share the previous fact's.
            let (p, args): (&str, Vec<String>) = match i % 7 {
                0 if i > 0 => ("Edge", vec![format!("n{}", i / 2), format!("m{}", i / 2)]),
                1 | 4 => ("Seen", vec![format!("n{i}")]),
                2 => (
                    "Mark",
                    vec![format!("n{i}"), "v".into(), format!("w{}", i % 11)],
                ),
                _ => ("Edge", vec![format!("n{i}"), format!("m{i}")]),
            };
            if i % 3 == 0 {
                run = note(&i.to_string());
            }
            let f = Fact {
                predicate: p.into(),
                args,
                provenance: Arc::clone(&run),
            };
            if seen_lines.insert(f.to_kb_line()) {
                expected.push((f.to_kb_line(), run.note.clone()));
            }
            facts.push(f);
        }
        let kb =
            WindowKb::build(window(WindowFacts::Listed(facts)), pad.program()).expect("builds");
        assert!(expected.len() < n, "the test repeats some facts");
        assert_eq!(kb.fact_count(), expected.len());
        assert_eq!(seen(&kb), expected);
        assert_eq!(kb.base.provenances.len(), n.div_ceil(3));
        for f in kb.facts().step_by(997) {
            let args: Vec<&str> = f.args().collect();
            assert!(kb.model.holds(f.predicate(), &args));
            assert_eq!(
                kb.provenance(f.predicate(), &args).map(|p| &p.note),
                Some(&f.provenance().note)
            );
        }
    }

    #[test]
    fn a_large_window_reports_the_first_bad_fact_in_source_order() {
        // Predicates are stored by several threads; the error is still the
        // one a fact-by-fact insert meets first.
        let pad = LogicPad::parse(REACH, "reach.yaml", true).expect("loads");
        let p = note("p");
        let fact = |pred: &str, args: &[&str]| Fact {
            predicate: pred.into(),
            args: args.iter().map(|a| a.to_string()).collect(),
            provenance: Arc::clone(&p),
        };
        let mut facts: Vec<Fact> = (0..PARALLEL_FACTS)
            .map(|i| {
                let a = format!("n{i}");
                if i % 2 == 0 {
                    fact("Edge", &[&a, "b"])
                } else {
                    fact("Mark", &[&a])
                }
            })
            .collect();
        facts.push(fact("Mark", &["x", "y"]));
        facts.push(fact("Edge", &["x"]));
        let mut sequential = FactBase::new();
        let first = facts
            .iter()
            .find_map(|f| {
                let args: Vec<&str> = f.args.iter().map(String::as_str).collect();
                sequential.add(&f.predicate, &args).err()
            })
            .expect("an arity error");
        let e = WindowKb::build(window(WindowFacts::Listed(facts)), pad.program())
            .expect_err("refused");
        assert_eq!(e.to_string(), format!("window w: {first}"));
        assert!(e.to_string().contains("`Mark`"), "{e}");
    }
}

#[cfg(test)]
mod sliding_tests {
    use super::*;
    use crate::source::{LoadOptions, SourceSpec, load};
    use perception::WindowSpec;

    fn everything(kb: &WindowKb) -> Vec<String> {
        let mut out: Vec<String> = kb.facts().map(|f| f.to_kb_line()).collect();
        let prog = kb.model.program();
        for p in (0..prog.num_preds()).filter_map(|i| prog.pred_name(i)) {
            for args in kb.model.facts(p) {
                out.push(format!("{p}{args:?}"));
                let a: Vec<&str> = args.iter().map(String::as_str).collect();
                out.push(format!("{:?}", kb.model.explain(p, &a)));
            }
        }
        out
    }

    /// The built-in scenario `urban_crossing` in windows of 10 frames.
    fn sim_windows(stride: u32) -> Vec<WindowInput> {
        let spec: SourceSpec = "sim:urban_crossing".parse().expect("spec");
        let opts = LoadOptions {
            windows: WindowSpec { size: 10, stride },
            ..LoadOptions::default()
        };
        load(&spec, &opts, &mut |_| {}).expect("loads").windows
    }

    /// Overlapping windows reasoned in chains give exactly the KBs built one
    /// by one (facts, derived facts, proofs), and the chains do reuse.
    #[test]
    fn chained_windows_equal_windows_built_alone() {
        let windows = sim_windows(1);
        assert!(windows.len() > 20);
        let pad = LogicPad::builtin();
        let chained = build_all(pad.program(), windows.clone(), &|| {}).expect("builds");
        assert_eq!(chained.len(), windows.len());
        let mut reused = 0;
        for (kb, input) in chained.iter().zip(windows) {
            let alone = WindowKb::build(input, pad.program()).expect("builds");
            assert_eq!(kb.id, alone.id);
            assert_eq!(everything(kb), everything(&alone), "window {}", kb.id);
            reused += kb.model.stats().reused_components;
        }
        assert!(reused > 0, "no component was reused over stride-1 windows");
    }

    /// Items scattered over the windows in any order come out in item
    /// order, each once, answered by its own window.
    #[test]
    fn answers_stream_in_item_order() {
        let windows = sim_windows(2);
        let ids: Vec<String> = windows.iter().map(|w| w.id.clone()).collect();
        // Item i asks window (i * 7) mod n: windows out of order, repeated.
        let n = ids.len();
        let items = 3 * n;
        let window_of = |i: usize| ids[(i * 7) % n].clone();
        let pad = LogicPad::builtin();
        let mut seen: Vec<(usize, String)> = Vec::new();
        answer_by_window_in_order::<String, KbError>(
            pad.program(),
            windows,
            items,
            window_of,
            |_| unreachable!("every window exists"),
            |kb, _| kb.id.clone(),
            &|_| {},
            &mut |i, id| seen.push((i, id)),
        )
        .expect("answers");
        assert_eq!(seen.len(), items);
        for (k, (i, id)) in seen.iter().enumerate() {
            assert_eq!(*i, k, "out of order");
            assert_eq!(id, &window_of(k));
        }
    }

    #[test]
    fn runs_are_contiguous_and_cover_everything() {
        for n in [0usize, 1, 5, 17, 100, 1000] {
            let runs = chained_runs((0..n).collect::<Vec<_>>());
            let flat: Vec<usize> = runs.iter().flatten().copied().collect();
            assert_eq!(flat, (0..n).collect::<Vec<_>>());
            assert!(runs.iter().all(|r| !r.is_empty() && r.len() <= CHAIN));
        }
    }
}
