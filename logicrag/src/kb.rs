//! The knowledge base of one window: perception facts (each with its
//! provenance) plus the LogicPad's rules, reasoned to a fixpoint.

use crate::facts_text::ParsedFacts;
use kanren::{FactId, Relation, Sym, Term};
use logicpad::{FactBase, LogicPad, Model, PredKind, Program};
use perception::{Fact, Provenance};
use std::collections::{BTreeMap, BTreeSet, HashMap};
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
    pub facts: WindowFacts,
}

/// A window's base facts before reasoning, in the form their source makes.
#[derive(Debug, Clone)]
pub enum WindowFacts {
    /// Owned facts, each with its provenance: perception's sources (every
    /// fact has its own measurement) and tests.
    Listed(Vec<Fact>),
    /// A text KB parsed straight into interned symbols, every fact from one
    /// place: no `String` per name and one provenance for all. Why: the
    /// `facts:` source read two million lines into `Fact`s first, which
    /// cost more time and memory than reasoning over them.
    Parsed {
        /// The facts in file order, duplicates kept.
        facts: ParsedFacts,
        /// Where every one of them came from.
        provenance: Arc<Provenance>,
    },
}

impl From<Vec<Fact>> for WindowFacts {
    fn from(facts: Vec<Fact>) -> WindowFacts {
        WindowFacts::Listed(facts)
    }
}

impl WindowFacts {
    /// Number of facts, duplicates counted.
    pub fn len(&self) -> usize {
        match self {
            WindowFacts::Listed(v) => v.len(),
            WindowFacts::Parsed { facts, .. } => facts.len(),
        }
    }

    /// True when there is no fact.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The facts in source order, duplicates kept, borrowed.
    pub fn iter(&self) -> impl Iterator<Item = FactRef<'_>> {
        let (listed, parsed) = match self {
            WindowFacts::Listed(v) => (Some(v), None),
            WindowFacts::Parsed { facts, provenance } => (None, Some((facts, provenance))),
        };
        let listed = listed.into_iter().flatten().map(|f| FactRef {
            predicate: &f.predicate,
            args: Args::Strings(&f.args),
            provenance: &f.provenance,
        });
        let parsed = parsed.into_iter().flat_map(|(facts, provenance)| {
            facts.iter().map(move |(pred, args)| FactRef {
                predicate: pred.as_str(),
                args: Args::Syms(args),
                provenance,
            })
        });
        listed.chain(parsed)
    }

    /// The facts as owned [`Fact`]s, for callers that keep or hand them on.
    pub fn to_vec(&self) -> Vec<Fact> {
        match self {
            WindowFacts::Listed(v) => v.clone(),
            WindowFacts::Parsed { .. } => self.iter().map(|f| f.to_fact()).collect(),
        }
    }
}

/// A base fact borrowed from a window's KB or input: its predicate,
/// arguments and provenance, without copying a name.
#[derive(Debug, Clone, Copy)]
pub struct FactRef<'a> {
    predicate: &'a str,
    args: Args<'a>,
    provenance: &'a Arc<Provenance>,
}

/// Where a [`FactRef`]'s arguments are stored.
#[derive(Debug, Clone, Copy)]
enum Args<'a> {
    /// A tuple of a model relation (every term a symbol: base facts are
    /// stored from text).
    Terms(kanren::Tuple<'a>),
    /// A parsed text KB's symbols.
    Syms(&'a [Sym]),
    /// A listed fact's strings.
    Strings(&'a [String]),
}

impl<'a> Args<'a> {
    fn len(&self) -> usize {
        match self {
            Args::Terms(t) => t.len(),
            Args::Syms(s) => s.len(),
            Args::Strings(s) => s.len(),
        }
    }

    fn get(&self, i: usize) -> Option<&'a str> {
        match *self {
            Args::Terms(t) => t.get(i).map(|t| match t {
                Term::Sym(s) => s.as_str(),
                Term::Str(s) => &**s,
                // Never stored as a base fact: the KB interns every
                // argument as a symbol.
                _ => "",
            }),
            Args::Syms(s) => s.get(i).map(Sym::as_str),
            Args::Strings(s) => s.get(i).map(String::as_str),
        }
    }
}

/// The arguments of a [`FactRef`], in order.
#[derive(Debug, Clone)]
pub struct FactArgs<'a> {
    args: Args<'a>,
    next: usize,
}

impl<'a> Iterator for FactArgs<'a> {
    type Item = &'a str;

    fn next(&mut self) -> Option<&'a str> {
        let a = self.args.get(self.next)?;
        self.next += 1;
        Some(a)
    }

    fn size_hint(&self) -> (usize, Option<usize>) {
        let n = self.args.len().saturating_sub(self.next);
        (n, Some(n))
    }
}

impl ExactSizeIterator for FactArgs<'_> {}

impl<'a> FactRef<'a> {
    /// Predicate name, e.g. `Moving`.
    pub fn predicate(&self) -> &'a str {
        self.predicate
    }

    /// Constant arguments in order.
    pub fn args(&self) -> FactArgs<'a> {
        FactArgs {
            args: self.args,
            next: 0,
        }
    }

    /// Argument `i` (from 0).
    pub fn arg(&self, i: usize) -> Option<&'a str> {
        self.args.get(i)
    }

    /// Number of arguments.
    pub fn arity(&self) -> usize {
        self.args.len()
    }

    /// Where the fact came from.
    pub fn provenance(&self) -> &'a Provenance {
        self.provenance
    }

    /// The provenance as the shared handle the facts of a window keep.
    pub fn shared_provenance(&self) -> &'a Arc<Provenance> {
        self.provenance
    }

    /// The fact in the reference KB syntax, e.g. `TypeOf(car_3, Car)`
    /// (as [`Fact::to_kb_line`]).
    pub fn to_kb_line(&self) -> String {
        self.to_string()
    }

    /// An owned copy, for callers that keep or hand on a [`Fact`].
    pub fn to_fact(&self) -> Fact {
        Fact {
            predicate: self.predicate.to_string(),
            args: self.args().map(str::to_string).collect(),
            provenance: Arc::clone(self.provenance),
        }
    }
}

impl std::fmt::Display for FactRef<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}(", self.predicate)?;
        for (i, a) in self.args().enumerate() {
            if i > 0 {
                f.write_str(", ")?;
            }
            f.write_str(a)?;
        }
        f.write_str(")")
    }
}

/// Serialised exactly as [`Fact`] is (`predicate`, `args`, `provenance`),
/// so JSON output does not depend on where a fact is stored.
impl serde::Serialize for FactRef<'_> {
    fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
        use serde::ser::SerializeStruct;
        struct ArgList<'a>(FactArgs<'a>);
        impl serde::Serialize for ArgList<'_> {
            fn serialize<S: serde::Serializer>(&self, s: S) -> Result<S::Ok, S::Error> {
                s.collect_seq(self.0.clone())
            }
        }
        let mut st = s.serialize_struct("Fact", 3)?;
        st.serialize_field("predicate", self.predicate)?;
        st.serialize_field("args", &ArgList(self.args()))?;
        st.serialize_field("provenance", &**self.provenance)?;
        st.end()
    }
}

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
}

/// Answers items addressed to windows by id, reasoning over each window
/// once and windows in parallel; the answers come back in item order.
///
/// `window_of(i)` names item `i`'s window; an id that names no window is
/// `unknown(i)` for the first such item, before any reasoning. `answer` runs
/// on worker threads, and so does `done(n)`, called when a window's `n`
/// items are answered.
/// A window id a source does not have: the one message every front end
/// (CLI, REPL, batch, eval, serve, Python) gives for it.
///
/// Invariant: `id` is at most [`NoWindow::MAX_ID`] characters (a longer id
/// is cut, so an error never echoes a megabyte of input), `known` lists at
/// most [`NoWindow::SHOWN`] of the source's ids.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[error("{label} has no window `{id}` ({known})")]
pub struct NoWindow {
    /// The source's label.
    pub label: String,
    /// The id asked for (cut to [`NoWindow::MAX_ID`] characters).
    pub id: String,
    /// "it has a, b, c, …", or "it has none".
    pub known: String,
}

impl NoWindow {
    /// Window ids listed.
    pub const SHOWN: usize = 5;
    /// Characters of the asked id repeated in the message.
    pub const MAX_ID: usize = 80;

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
    let mut out: Vec<T> = Vec::with_capacity(items);
    answer_by_window_in_order(
        program,
        windows,
        items,
        window_of,
        unknown,
        answer,
        done,
        &mut |_, t| out.push(t),
    )?;
    Ok(out)
}

/// [`answer_by_window`], handing each answer to `emit` in item order as
/// soon as every earlier item is answered, instead of keeping them all: a
/// batch writes its output while it runs and holds only the answers that
/// wait for an earlier one. Runs of consecutive windows are taken in
/// order by the worker threads, so for items listed window by window (a
/// benchmark's queries file) few answers wait. `emit` runs under a lock on
/// whichever worker completes the run of items.
///
/// On an error (a window's facts cannot be stored) the items before it have
/// been emitted and the others are not.
#[allow(clippy::too_many_arguments)]
pub fn answer_by_window_in_order<T, E>(
    program: &Program,
    windows: Vec<WindowInput>,
    items: usize,
    window_of: impl Fn(usize) -> String,
    unknown: impl FnOnce(usize) -> E,
    answer: impl Fn(&WindowKb, usize) -> T + Sync,
    done: &(dyn Fn(usize) + Sync),
    emit: &mut (dyn FnMut(usize, T) + Send),
) -> Result<(), E>
where
    T: Send,
    E: Send + From<KbError>,
{
    use std::sync::Mutex;
    use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};
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
    // Contiguous runs of windows, each reasoned in order so that a window
    // reuses its predecessor's unchanged components; a KB is dropped as soon
    // as the next one is built. Workers take runs by a shared counter, in
    // order, so answers come out roughly in item order.
    type Run = Vec<(WindowInput, Vec<usize>)>;
    let runs: Vec<Mutex<Option<Run>>> = chained_runs(work)
        .into_iter()
        .map(|r| Mutex::new(Some(r)))
        .collect();
    let next_run = AtomicUsize::new(0);
    let failed = AtomicBool::new(false);
    struct Reorder<'e, T> {
        next: usize,
        waiting: BTreeMap<usize, T>,
        emit: &'e mut (dyn FnMut(usize, T) + Send),
        error: Option<KbError>,
    }
    let state = Mutex::new(Reorder {
        next: 0,
        waiting: BTreeMap::new(),
        emit,
        error: None,
    });
    let worker = || {
        loop {
            if failed.load(Ordering::Relaxed) {
                return;
            }
            let r = next_run.fetch_add(1, Ordering::Relaxed);
            let Some(slot) = runs.get(r) else { return };
            let Some(run) = slot.lock().ok().and_then(|mut g| g.take()) else {
                continue;
            };
            let mut prev: Option<WindowKb> = None;
            for (input, group) in run {
                let kb = match WindowKb::build_after(input, program, prev.as_ref()) {
                    Ok(kb) => kb,
                    Err(e) => {
                        failed.store(true, Ordering::Relaxed);
                        if let Ok(mut st) = state.lock() {
                            st.error.get_or_insert(e);
                        }
                        return;
                    }
                };
                let n = group.len();
                let answered: Vec<(usize, T)> =
                    group.into_iter().map(|i| (i, answer(&kb, i))).collect();
                done(n);
                // A poisoned lock means `emit` panicked on another worker;
                // that panic is re-raised by the scope.
                let Ok(mut st) = state.lock() else { return };
                st.waiting.extend(answered);
                loop {
                    let next = st.next;
                    let Some(t) = st.waiting.remove(&next) else {
                        break;
                    };
                    (st.emit)(next, t);
                    st.next += 1;
                }
                drop(st);
                prev = Some(kb);
            }
        }
    };
    let threads = rayon::current_num_threads().clamp(1, runs.len().max(1));
    rayon::scope(|s| {
        for _ in 0..threads {
            s.spawn(|_| worker());
        }
    });
    let st = state.into_inner().unwrap_or_else(|e| e.into_inner());
    match st.error {
        Some(e) => Err(E::from(e)),
        None => Ok(()),
    }
}

/// A window's base facts as columns over the model's relations.
///
/// Invariants: `rels[p]` is the model's relation of base predicate `p`
/// (predicates numbered by first appearance in the source), whose base
/// facts have ids `0..prov[p].len()` in the order they came (kanren hands
/// out ids in insertion order and evaluation keeps them; derived facts come
/// after). `order` lists every base fact once, as `(p, id)`, in source
/// order; a duplicate in the source was dropped at build, so the first
/// copy's place and provenance win. `prov[p][id]` indexes `provenances`,
/// which holds each run of consecutive facts sharing one `Arc` once (a text
/// KB window: one entry in all). Why columns: a `Fact` per base fact (a
/// `String` per name) was most of the time and memory of a large window.
#[derive(Debug, Clone, Default)]
struct BaseFacts {
    rels: Vec<Arc<Relation>>,
    by_name: HashMap<&'static str, u32>,
    order: Vec<(u32, FactId)>,
    prov: Vec<Vec<u32>>,
    provenances: Vec<Arc<Provenance>>,
}

impl BaseFacts {
    fn fact(&self, p: u32, id: FactId) -> Option<FactRef<'_>> {
        let tuple = self.rels.get(p as usize)?.tuple(id)?;
        let at = *self.prov.get(p as usize)?.get(id as usize)?;
        Some(FactRef {
            predicate: self.rels.get(p as usize)?.name().as_str(),
            args: Args::Terms(tuple),
            provenance: self.provenances.get(at as usize)?,
        })
    }
}

type SymSet = rustc_hash::FxHashSet<Sym>;

/// Windows of at least this many facts store their predicates on several
/// threads; smaller ones are not worth the hand-off (and the loader already
/// builds many windows at once).
const PARALLEL_FACTS: usize = 1 << 16;

/// A window's facts stored in a [`FactBase`], before reasoning.
///
/// Invariants: `pred_of[i]` numbers fact `i`'s predicate (`preds`, by first
/// appearance); `new[i]` is false for a duplicate of an earlier fact, so
/// the `k`-th new fact of predicate `p` has id `k` in `base`'s relation.
struct Stored {
    base: FactBase,
    preds: Vec<Sym>,
    pred_of: Vec<u32>,
    new: Vec<bool>,
    objects: SymSet,
    constants: SymSet,
}

/// The facts of one group of predicates, stored by one thread.
struct Part {
    base: FactBase,
    /// For each fact of the group, in source order: new (not a duplicate).
    new: Vec<bool>,
    objects: SymSet,
    constants: SymSet,
}

/// Stores `facts` in a fact base, predicates split into groups stored in
/// parallel (a relation's ids depend only on its own facts' order). An
/// error is the one the first offending fact in source order raises, as a
/// sequential insert would report it: every error is about one
/// predicate's own facts.
fn store(facts: &ParsedFacts) -> Result<Stored, logicpad::FactError> {
    use rayon::prelude::*;
    let mut local: rustc_hash::FxHashMap<Sym, u32> = Default::default();
    let mut preds: Vec<Sym> = Vec::new();
    let mut counts: Vec<usize> = Vec::new();
    let mut pred_of: Vec<u32> = Vec::with_capacity(facts.len());
    for (pred, _) in facts.iter() {
        let p = *local.entry(pred).or_insert_with(|| {
            preds.push(pred);
            counts.push(0);
            u32::try_from(preds.len() - 1).unwrap_or(u32::MAX)
        });
        if let Some(c) = counts.get_mut(p as usize) {
            *c += 1;
        }
        pred_of.push(p);
    }
    let groups = if facts.len() >= PARALLEL_FACTS {
        rayon::current_num_threads().clamp(1, preds.len().max(1))
    } else {
        1
    };
    // Largest predicates first, each to the least loaded group.
    let mut group_of = vec![0usize; preds.len()];
    let mut load = vec![0usize; groups];
    let mut by_size: Vec<usize> = (0..preds.len()).collect();
    by_size.sort_by_key(|&p| std::cmp::Reverse(counts.get(p).copied().unwrap_or(0)));
    for p in by_size {
        if let Some((g, l)) = load.iter_mut().enumerate().min_by_key(|(_, l)| **l) {
            *l += counts.get(p).copied().unwrap_or(0);
            if let Some(slot) = group_of.get_mut(p) {
                *slot = g;
            }
        }
    }
    let in_group = |i: usize| {
        pred_of
            .get(i)
            .and_then(|&p| group_of.get(p as usize))
            .copied()
            .unwrap_or(0)
    };
    let parts: Vec<Result<Part, (usize, logicpad::FactError)>> = (0..groups)
        .into_par_iter()
        .map(|g| {
            let mut part = Part {
                base: FactBase::new(),
                new: Vec::new(),
                objects: SymSet::default(),
                constants: SymSet::default(),
            };
            let mut terms: Vec<Term> = Vec::with_capacity(4);
            for (i, (pred, args)) in facts.iter().enumerate() {
                if in_group(i) != g {
                    continue;
                }
                terms.clear();
                terms.extend(args.iter().map(|&a| Term::Sym(a)));
                let (_, new) = part
                    .base
                    .insert(pred.as_str(), &terms)
                    .map_err(|e| (i, e))?;
                part.new.push(new);
                if new {
                    if let Some(&first) = args.first() {
                        part.objects.insert(first);
                    }
                    part.constants.extend(args.iter().copied());
                }
            }
            Ok(part)
        })
        .collect();
    let mut first_error: Option<(usize, logicpad::FactError)> = None;
    let mut ok = Vec::with_capacity(parts.len());
    for part in parts {
        match part {
            Ok(p) => ok.push(p),
            Err((i, e)) => {
                if first_error.as_ref().is_none_or(|(j, _)| i < *j) {
                    first_error = Some((i, e));
                }
            }
        }
    }
    if let Some((_, e)) = first_error {
        return Err(e);
    }
    // Each fact's flag, taken from its group's list in source order.
    let mut cursors = vec![0usize; ok.len()];
    let mut new = Vec::with_capacity(facts.len());
    for i in 0..facts.len() {
        let g = in_group(i);
        let flag = match (ok.get(g), cursors.get_mut(g)) {
            (Some(part), Some(at)) => {
                *at += 1;
                part.new.get(*at - 1).copied().unwrap_or(false)
            }
            _ => false,
        };
        new.push(flag);
    }
    let mut base = FactBase::new();
    let mut objects = SymSet::default();
    let mut constants = SymSet::default();
    for part in ok {
        // Groups hold disjoint predicates: each relation moves whole.
        base.append(part.base)?;
        objects.extend(part.objects);
        constants.extend(part.constants);
    }
    Ok(Stored {
        base,
        preds,
        pred_of,
        new,
        objects,
        constants,
    })
}

/// The provenance of a fact that cannot be found (never, by
/// [`BaseFacts`]' invariants): an empty one rather than a panic.
fn no_provenance() -> &'static Arc<Provenance> {
    static NONE: std::sync::OnceLock<Arc<Provenance>> = std::sync::OnceLock::new();
    NONE.get_or_init(|| {
        Arc::new(Provenance {
            window: 0,
            frames: (0, 0),
            source: "".into(),
            measured: None,
            threshold: None,
            note: String::new(),
        })
    })
}

/// Symbols as a sorted set of their names (interned: no copy).
fn names(set: SymSet) -> BTreeSet<&'static str> {
    set.into_iter().map(|s| s.as_str()).collect()
}

/// Symbols sorted by name (the order of [`names`]).
fn sorted_syms(set: &SymSet) -> Vec<Sym> {
    let mut v: Vec<Sym> = set.iter().copied().collect();
    v.sort_unstable();
    v
}

fn syms_by_name(set: &SymSet) -> Vec<Sym> {
    let mut v: Vec<Sym> = set.iter().copied().collect();
    v.sort_by_key(|s| s.as_str());
    v
}

/// Windows are chained (each reasoned from the previous one's model) in
/// runs of this many at most, so that a long sequence still spreads over
/// every thread while each run keeps the reuse of overlapping windows.
const CHAIN: usize = 16;

/// Reasons every window, in parallel over contiguous runs of windows; within
/// a run each window reuses what its predecessor's model derived from
/// unchanged inputs ([`WindowKb::build_after`]). The KBs come back in input
/// order; `done` is called once per window built (on worker threads).
pub fn build_all(
    program: &Program,
    windows: Vec<WindowInput>,
    done: &(dyn Fn() + Sync),
) -> Result<Vec<WindowKb>, KbError> {
    use rayon::prelude::*;
    let runs = chained_runs(windows);
    let built: Result<Vec<Vec<WindowKb>>, KbError> = runs
        .into_par_iter()
        .map(|run| {
            let mut out: Vec<WindowKb> = Vec::with_capacity(run.len());
            for input in run {
                let kb = WindowKb::build_after(input, program, out.last())?;
                done();
                out.push(kb);
            }
            Ok(out)
        })
        .collect();
    Ok(built?.into_iter().flatten().collect())
}

/// Splits `items` into contiguous runs for [`build_all`]: at most
/// [`CHAIN`] long, and enough of them for every thread.
fn chained_runs<T>(items: Vec<T>) -> Vec<Vec<T>> {
    let threads = rayon::current_num_threads().max(1);
    let len = items.len().div_ceil(threads).clamp(1, CHAIN);
    let mut runs: Vec<Vec<T>> = Vec::with_capacity(items.len().div_ceil(len));
    for item in items {
        match runs.last_mut() {
            Some(run) if run.len() < len => run.push(item),
            _ => runs.push(vec![item]),
        }
    }
    runs
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
    pub fn build_after(
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
        })
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
    pub fn shared_provenance<S: AsRef<str>>(
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
    pub fn provenance_of_id(&self, predicate: &str, id: FactId) -> Option<&Arc<Provenance>> {
        let p = *self.base.by_name.get(predicate)?;
        let at = *self.base.prov.get(p as usize)?.get(id as usize)?;
        self.base.provenances.get(at as usize)
    }

    /// Whether `sym` occurs in some base fact of the window.
    pub fn is_constant(&self, sym: Sym) -> bool {
        self.constant_syms_sorted.binary_search(&sym).is_ok()
    }

    /// Whether `sym` is one of the window's objects.
    pub fn is_object(&self, sym: Sym) -> bool {
        self.object_syms_sorted.binary_search(&sym).is_ok()
    }

    /// The window's objects with their symbols, sorted by name.
    pub fn objects_with_syms(&self) -> impl Iterator<Item = (&'static str, Sym)> + '_ {
        self.objects
            .iter()
            .copied()
            .zip(self.object_syms.iter().copied())
    }

    /// Base facts grouped by their first argument (the object they describe).
    pub fn facts_by_object(&self) -> BTreeMap<&str, Vec<FactRef<'_>>> {
        let mut m: BTreeMap<&str, Vec<FactRef<'_>>> = BTreeMap::new();
        for f in self.facts() {
            if let Some(a) = f.arg(0) {
                m.entry(a).or_default().push(f);
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
        facts: WindowFacts::Listed(facts),
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
            facts: WindowFacts::Listed(vec![
                fact("Edge", &["c", "d"], "first c-d"),
                fact("Seen", &["a"], "seen a"),
                fact("Edge", &["a", "b"], "a-b"),
                fact("Edge", &["c", "d"], "second c-d"),
            ]),
        };
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
        })
    }

    fn window(facts: WindowFacts) -> WindowInput {
        WindowInput {
            id: "w".into(),
            index: 0,
            first_frame: 0,
            last_frame: 9,
            facts,
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
