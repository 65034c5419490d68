//! The column store of a window's base facts: facts as codes in the
//! model's relations, provenance runs shared, and the objects and symbols
//! a window names.

use super::*;

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
pub(super) struct BaseFacts {
    pub(super) rels: Vec<Arc<Relation>>,
    pub(super) by_name: rustc_hash::FxHashMap<&'static str, u32>,
    pub(super) order: Vec<(u32, FactId)>,
    pub(super) prov: Vec<Vec<u32>>,
    pub(super) provenances: Vec<Arc<Provenance>>,
}

impl BaseFacts {
    pub(super) fn fact(&self, p: u32, id: FactId) -> Option<FactRef<'_>> {
        let tuple = self.rels.get(p as usize)?.tuple(id)?;
        let at = *self.prov.get(p as usize)?.get(id as usize)?;
        Some(FactRef {
            predicate: self.rels.get(p as usize)?.name().as_str(),
            args: Args::Terms(tuple),
            provenance: self.provenances.get(at as usize)?,
        })
    }
}

pub(super) type SymSet = rustc_hash::FxHashSet<Sym>;

/// Windows of at least this many facts store their predicates on several
/// threads; smaller ones are not worth the hand-off (and the loader already
/// builds many windows at once).
pub(super) const PARALLEL_FACTS: usize = 1 << 16;

/// A window's facts stored in a [`FactBase`], before reasoning.
///
/// Invariants: `pred_of[i]` numbers fact `i`'s predicate (`preds`, by first
/// appearance); `new[i]` is false for a duplicate of an earlier fact, so
/// the `k`-th new fact of predicate `p` has id `k` in `base`'s relation.
pub(super) struct Stored {
    pub(super) base: FactBase,
    pub(super) preds: Vec<Sym>,
    pub(super) pred_of: Vec<u32>,
    pub(super) new: Vec<bool>,
    pub(super) objects: SymSet,
    pub(super) constants: SymSet,
}

/// The facts of one group of predicates, stored by one thread.
pub(super) struct Part {
    pub(super) base: FactBase,
    /// For each fact of the group, in source order: new (not a duplicate).
    pub(super) new: Vec<bool>,
    pub(super) objects: SymSet,
    pub(super) constants: SymSet,
}

/// Stores `facts` in a fact base, predicates split into groups stored in
/// parallel (a relation's ids depend only on its own facts' order). An
/// error is the one the first offending fact in source order raises, as a
/// sequential insert would report it: every error is about one
/// predicate's own facts.
pub(super) fn store(facts: &ParsedFacts) -> Result<Stored, logicpad::FactError> {
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
            // The group's relations by local predicate number, sized from
            // the counts: a lookup by name per fact cost more than the
            // insert.
            let mut rels: Vec<Option<Relation>> = preds.iter().map(|_| None).collect();
            let mut terms: Vec<Term> = Vec::with_capacity(4);
            for (i, ((pred, args), &p)) in facts.iter().zip(&pred_of).enumerate() {
                if in_group(i) != g {
                    continue;
                }
                // `pred_of` numbers every fact's predicate below
                // `preds.len()`; a fact past that is an error, never
                // dropped.
                let Some(slot) = rels.get_mut(p as usize) else {
                    return Err((
                        i,
                        logicpad::FactError::Store {
                            pred: pred.as_str().to_string(),
                            message: format!("predicate number {p} has no relation"),
                        },
                    ));
                };
                let rel = slot.get_or_insert_with(|| {
                    let count = counts.get(p as usize).copied().unwrap_or(0);
                    Relation::with_capacity(pred, args.len(), count)
                });
                if rel.arity() != args.len() {
                    return Err((
                        i,
                        logicpad::FactError::Arity {
                            pred: pred.as_str().to_string(),
                            expected: rel.arity(),
                            got: args.len(),
                        },
                    ));
                }
                terms.clear();
                terms.extend(args.iter().map(|&a| Term::Sym(a)));
                let (_, new) = rel.insert(&terms).map_err(|e| {
                    (
                        i,
                        logicpad::FactError::Store {
                            pred: pred.as_str().to_string(),
                            message: e.to_string(),
                        },
                    )
                })?;
                part.new.push(new);
                if new {
                    if let Some(&first) = args.first() {
                        part.objects.insert(first);
                    }
                    part.constants.extend(args.iter().copied());
                }
            }
            for rel in rels.into_iter().flatten() {
                part.base.add_relation(rel).map_err(|e| (0, e))?;
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
pub(super) fn no_provenance() -> &'static Arc<Provenance> {
    static NONE: std::sync::OnceLock<Arc<Provenance>> = std::sync::OnceLock::new();
    NONE.get_or_init(|| {
        Arc::new(Provenance {
            window: 0,
            frames: (0, 0),
            source: "".into(),
            measured: None,
            threshold: None,
            note: String::new(),
            probability: None,
        })
    })
}

/// Symbols as a sorted set of their names (interned: no copy).
pub(super) fn names(set: SymSet) -> BTreeSet<&'static str> {
    set.into_iter().map(|s| s.as_str()).collect()
}

/// Symbols sorted by name (the order of [`names`]).
pub(super) fn sorted_syms(set: &SymSet) -> Vec<Sym> {
    let mut v: Vec<Sym> = set.iter().copied().collect();
    v.sort_unstable();
    v
}

pub(super) fn syms_by_name(set: &SymSet) -> Vec<Sym> {
    let mut v: Vec<Sym> = set.iter().copied().collect();
    v.sort_by_key(|s| s.as_str());
    v
}
