//! Ground fact tables with a hash index per argument position.

use crate::engine::{Ctx, Gen, GenStep, Out};
use crate::error::KanrenError;
use crate::goal::Goal;
use crate::proof::ProofStep;
use crate::state::State;
use crate::term::{Sym, Term};
use std::collections::HashMap;
use std::hash::{BuildHasher, BuildHasherDefault, Hasher};
use std::sync::Arc;

/// A multiply-rotate hasher (the FxHash scheme): fact keys are symbols and
/// small integers, for which SipHash's protection against chosen collisions
/// costs more than the whole lookup.
#[derive(Default, Clone, Copy)]
struct FxHasher(u64);

impl Hasher for FxHasher {
    #[inline]
    fn finish(&self) -> u64 {
        self.0
    }
    #[inline]
    fn write(&mut self, bytes: &[u8]) {
        for chunk in bytes.chunks(8) {
            let mut buf = [0u8; 8];
            buf[..chunk.len()].copy_from_slice(chunk);
            self.write_u64(u64::from_le_bytes(buf));
        }
    }
    #[inline]
    fn write_u64(&mut self, i: u64) {
        self.0 = (self.0.rotate_left(5) ^ i).wrapping_mul(0x51_7c_c1_b7_27_22_0a_95);
    }
    #[inline]
    fn write_u32(&mut self, i: u32) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_u8(&mut self, i: u8) {
        self.write_u64(u64::from(i));
    }
    #[inline]
    fn write_usize(&mut self, i: usize) {
        self.write_u64(i as u64);
    }
    #[inline]
    fn write_i64(&mut self, i: i64) {
        self.write_u64(i as u64);
    }
}

type FxBuild = BuildHasherDefault<FxHasher>;

/// A fact's index in its relation (insertion order, from 0).
pub type FactId = u32;

/// A table of ground facts `name(a1, …, an)`.
///
/// Invariants: `tuples` holds every fact once, flat (`arity` terms per fact,
/// fact `i` at `tuples[i*arity..(i+1)*arity]`); every argument is a ground
/// atom; `index[p]` maps each value at position `p` to the ascending ids of
/// the facts holding it there; `dedup` maps a tuple hash to the ids with that
/// hash, so a duplicate insert is found without a scan. Indexes store ids, not
/// copies of tuples (a key term is shared through its `Arc` where it has one);
/// a one-id list is stored inline.
#[derive(Clone)]
pub struct Relation {
    name: Sym,
    arity: usize,
    tuples: Vec<Term>,
    index: Vec<HashMap<Term, IdList, FxBuild>>,
    dedup: HashMap<u64, IdList, FxBuild>,
    hasher: FxBuild,
}

/// A list of fact ids, ascending. Kept inline while it has one id: the ids
/// sharing a tuple hash are almost always one, and so are the ids of a key
/// that identifies its fact, so most facts cost no extra allocation.
#[derive(Clone, Debug)]
enum IdList {
    One(FactId),
    Many(Vec<FactId>),
}

impl IdList {
    fn as_slice(&self) -> &[FactId] {
        match self {
            IdList::One(id) => std::slice::from_ref(id),
            IdList::Many(v) => v,
        }
    }

    fn push(&mut self, id: FactId) {
        match self {
            IdList::One(first) => *self = IdList::Many(vec![*first, id]),
            IdList::Many(v) => v.push(id),
        }
    }
}

impl std::fmt::Debug for Relation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(
            f,
            "Relation({}/{}, {} facts)",
            self.name,
            self.arity,
            self.len()
        )
    }
}

impl Relation {
    /// An empty relation.
    pub fn new(name: impl Into<Sym>, arity: usize) -> Relation {
        Relation {
            name: name.into(),
            arity,
            tuples: Vec::new(),
            index: (0..arity).map(|_| HashMap::default()).collect(),
            dedup: HashMap::default(),
            hasher: FxBuild::default(),
        }
    }

    /// The relation's name.
    pub fn name(&self) -> Sym {
        self.name
    }

    /// The number of arguments of each fact.
    pub fn arity(&self) -> usize {
        self.arity
    }

    /// The number of facts.
    pub fn len(&self) -> usize {
        match self.tuples.len().checked_div(self.arity) {
            Some(n) => n,
            None => self.dedup.values().map(|l| l.as_slice().len()).sum(),
        }
    }

    /// True when there are no facts.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    fn hash_tuple(&self, tuple: &[Term]) -> u64 {
        self.hash_values(tuple.iter())
    }

    /// The dedup key of a tuple given as its values: a fully bound pattern
    /// hashes like the stored tuple, so the dedup map doubles as the index
    /// of the all-positions-bound access pattern.
    fn hash_values<'t>(&self, values: impl Iterator<Item = &'t Term>) -> u64 {
        use std::hash::Hash;
        let mut h = self.hasher.build_hasher();
        for t in values {
            t.hash(&mut h);
        }
        h.finish()
    }

    /// Adds a fact: `Ok((id, true))` when new, `Ok((existing_id, false))` for
    /// a duplicate; an error for a wrong arity or an argument that is not a
    /// ground atom (nothing is added then).
    pub fn insert(&mut self, tuple: &[Term]) -> Result<(FactId, bool), KanrenError> {
        if tuple.len() != self.arity {
            return Err(KanrenError::ArityMismatch {
                relation: self.name,
                arity: self.arity,
                got: tuple.len(),
            });
        }
        if let Some((position, t)) = tuple.iter().enumerate().find(|(_, t)| !t.is_atomic()) {
            return Err(KanrenError::NonGroundFact {
                relation: self.name,
                position,
                term: t.to_string(),
            });
        }
        if let Some(id) = self.id_of(tuple) {
            return Ok((id, false));
        }
        let id = FactId::try_from(self.len()).map_err(|_| KanrenError::TooManyFacts {
            relation: self.name,
            limit: u64::from(u32::MAX),
        })?;
        let h = self.hash_tuple(tuple);
        match self.dedup.get_mut(&h) {
            Some(list) => list.push(id),
            None => {
                self.dedup.insert(h, IdList::One(id));
            }
        }
        for (p, t) in tuple.iter().enumerate() {
            if let Some(ix) = self.index.get_mut(p) {
                match ix.get_mut(t) {
                    Some(list) => list.push(id),
                    None => {
                        ix.insert(t.clone(), IdList::One(id));
                    }
                }
            }
        }
        self.tuples.extend(tuple.iter().cloned());
        Ok((id, true))
    }

    /// Releases the spare capacity left by growth (call after a bulk load).
    pub fn shrink_to_fit(&mut self) {
        self.tuples.shrink_to_fit();
        self.dedup.shrink_to_fit();
        for ix in &mut self.index {
            ix.shrink_to_fit();
        }
    }

    /// True when the fact is in the table.
    pub fn contains(&self, tuple: &[Term]) -> bool {
        self.id_of(tuple).is_some()
    }

    /// The id of the fact, when present.
    pub fn id_of(&self, tuple: &[Term]) -> Option<FactId> {
        if tuple.len() != self.arity {
            return None;
        }
        let ids = self.dedup.get(&self.hash_tuple(tuple))?;
        ids.as_slice()
            .iter()
            .copied()
            .find(|&id| self.tuple(id) == Some(tuple))
    }

    /// The fact with id `id`.
    pub fn tuple(&self, id: FactId) -> Option<&[Term]> {
        if self.arity == 0 {
            return (id == 0 && !self.dedup.is_empty()).then_some(&[][..]);
        }
        let start = (id as usize).checked_mul(self.arity)?;
        self.tuples.get(start..start.checked_add(self.arity)?)
    }

    /// All facts in id (insertion) order.
    pub fn iter(&self) -> impl Iterator<Item = (FactId, &[Term])> + '_ {
        (0..self.len()).filter_map(move |i| {
            let id = FactId::try_from(i).ok()?;
            Some((id, self.tuple(id)?))
        })
    }

    /// The most selective bound position of `pattern`: (position, its ids).
    /// `None` when no position is bound.
    fn best_index<'a>(&'a self, pattern: &[Option<&Term>]) -> Option<(usize, &'a [FactId])> {
        let mut best: Option<(usize, &[FactId])> = None;
        for (p, t) in pattern.iter().enumerate() {
            let Some(t) = t else { continue };
            let ids: &[FactId] = self
                .index
                .get(p)
                .and_then(|ix| ix.get(*t))
                .map(IdList::as_slice)
                .unwrap_or(&[]);
            if best.is_none_or(|(_, b)| ids.len() < b.len()) {
                best = Some((p, ids));
                if ids.len() <= 1 {
                    break; // nothing can be more selective
                }
            }
        }
        best
    }

    fn matches(&self, id: FactId, pattern: &[Option<&Term>]) -> bool {
        match self.tuple(id) {
            Some(tuple) => pattern
                .iter()
                .zip(tuple)
                .all(|(p, t)| p.is_none_or(|p| p == t)),
            None => false,
        }
    }

    /// The candidate ids for `pattern` (`None` = any value), without
    /// allocating: a superset of the matching facts that the caller checks
    /// as it binds them. A fully bound pattern probes the dedup map (its
    /// candidates are the facts with the same tuple hash, almost always the
    /// one fact or none); a partly bound one takes the index of its most
    /// selective bound position; an unbound one is every fact. A pattern of
    /// the wrong length has no candidates.
    pub fn probe(&self, pattern: &[Option<&Term>]) -> Probe<'_> {
        if pattern.len() != self.arity {
            return Probe::Ids(&[]);
        }
        if self.arity > 0 && pattern.iter().all(Option::is_some) {
            let h = self.hash_values(pattern.iter().flatten().copied());
            return Probe::Ids(self.dedup.get(&h).map_or(&[], IdList::as_slice));
        }
        match self.best_index(pattern) {
            Some((_, ids)) => Probe::Ids(ids),
            None => Probe::Range(0, FactId::try_from(self.len()).unwrap_or(FactId::MAX)),
        }
    }

    /// The first fact matching `pattern` (`None` = any value), without
    /// allocating.
    pub fn first_match(&self, pattern: &[Option<&Term>]) -> Option<FactId> {
        match self.probe(pattern) {
            Probe::Ids(ids) => ids.iter().copied().find(|&id| self.matches(id, pattern)),
            Probe::Range(lo, hi) => (lo < hi).then_some(lo),
        }
    }

    /// The ids of the facts matching `pattern` (`None` = any value), ascending.
    /// Filters the candidates of [`Relation::probe`] by every bound position.
    /// A pattern of the wrong length matches nothing.
    pub fn lookup(&self, pattern: &[Option<&Term>]) -> Vec<FactId> {
        match self.probe(pattern) {
            Probe::Ids(ids) => ids
                .iter()
                .copied()
                .filter(|&id| self.matches(id, pattern))
                .collect(),
            Probe::Range(lo, hi) => (lo..hi).collect(),
        }
    }
}

/// The candidates of a [`Relation::probe`], ascending.
#[derive(Clone, Copy, Debug)]
pub enum Probe<'a> {
    /// The ids `lo..hi` (every fact, or a range of them).
    Range(FactId, FactId),
    /// These ids (a superset of the matches: check each candidate).
    Ids(&'a [FactId]),
}

impl<'a> Probe<'a> {
    /// The candidates with ids in `lo..hi` (a semi-naive delta, or the facts
    /// known before a round), cut by binary search.
    pub fn within(self, lo: FactId, hi: FactId) -> Probe<'a> {
        match self {
            Probe::Range(a, b) => Probe::Range(a.max(lo), b.min(hi).max(a.max(lo))),
            Probe::Ids(ids) => {
                let start = ids.partition_point(|&id| id < lo);
                let end = ids.partition_point(|&id| id < hi).max(start);
                Probe::Ids(ids.get(start..end).unwrap_or(&[]))
            }
        }
    }

    /// The number of candidates.
    pub fn len(&self) -> usize {
        match self {
            Probe::Range(a, b) => b.saturating_sub(*a) as usize,
            Probe::Ids(ids) => ids.len(),
        }
    }

    /// True when there is no candidate.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
}

/// Where a fact scan takes its candidate ids from.
enum Candidates {
    /// Every fact, `0..len`.
    All,
    /// The index of position `pos` for value `key` (looked up again on each
    /// turn: the scan cannot borrow from the relation it shares).
    Index { pos: usize, key: Term },
    /// A short candidate list, copied once: the common case of a key that
    /// (nearly) identifies its fact, where a second hash lookup per turn
    /// would cost more than the copy.
    Few(smallvec::SmallVec<[FactId; 4]>),
}

/// The generator of a `fact` goal: tries candidates one by one, so the
/// search can interleave it with other branches and stop it early.
pub(crate) struct FactScan {
    rel: Arc<Relation>,
    cand: Candidates,
    next: usize,
    args: Arc<[Term]>,
    state: State,
}

/// How many failing candidates one step may skip: bounds the work between
/// two budget checks.
const SCAN_CHUNK: usize = 64;

impl FactScan {
    pub(crate) fn next(&mut self, ctx: &Ctx) -> GenStep {
        let ids: &[FactId] = match &self.cand {
            Candidates::All => &[],
            Candidates::Few(ids) => ids,
            Candidates::Index { pos, key } => self
                .rel
                .index
                .get(*pos)
                .and_then(|ix| ix.get(key))
                .map(IdList::as_slice)
                .unwrap_or(&[]),
        };
        let total = match self.cand {
            Candidates::All => self.rel.len(),
            Candidates::Index { .. } | Candidates::Few(_) => ids.len(),
        };
        let mut tried = 0;
        while self.next < total && tried < SCAN_CHUNK {
            let id = match self.cand {
                Candidates::All => FactId::try_from(self.next).unwrap_or(FactId::MAX),
                Candidates::Index { .. } | Candidates::Few(_) => {
                    ids.get(self.next).copied().unwrap_or(FactId::MAX)
                }
            };
            self.next += 1;
            tried += 1;
            let Some(tuple) = self.rel.tuple(id) else {
                continue;
            };
            // All arguments in one pending unification: a candidate that
            // fails costs lookups only, no state copy.
            let mut pending = crate::subst::Pending::new();
            let ok = self
                .args
                .iter()
                .zip(tuple)
                .all(|(a, t)| self.state.subst.unify_pending(a, t, false, &mut pending));
            let st = if ok {
                self.state.clone().extended(&pending, false)
            } else {
                None
            };
            if let Some(mut st) = st {
                if ctx.proofs {
                    st.record(ProofStep::Fact {
                        relation: self.rel.name,
                        id,
                    });
                }
                return GenStep::Yield(st, None, self.next < total);
            }
        }
        if self.next < total {
            GenStep::More
        } else {
            GenStep::Done
        }
    }
}

/// A goal that unifies `args` with each matching fact of `rel`, in id order.
/// The candidates come from the index of the most selective argument that is
/// bound *when the goal runs*; with no bound argument it scans. A wrong
/// number of arguments simply matches nothing. With proofs on, each answer
/// records [`ProofStep::Fact`].
pub fn fact(rel: &Arc<Relation>, args: Vec<Term>) -> Goal {
    let rel = rel.clone();
    let args: Arc<[Term]> = args.into();
    crate::goal::goal_fn(move |_ctx, st| {
        if args.len() != rel.arity {
            return Out::Fail;
        }
        let cand = {
            // Arities are small: keep the per-call scratch on the stack.
            let walked: smallvec::SmallVec<[&Term; 6]> =
                args.iter().map(|a| st.subst.walk(a)).collect();
            if walked
                .iter()
                .any(|t| matches!(t, Term::Cons(..) | Term::App(..)))
            {
                return Out::Fail; // facts hold atoms only
            }
            let pattern: smallvec::SmallVec<[Option<&Term>; 6]> = walked
                .iter()
                .map(|t| (!matches!(t, Term::Var(_))).then_some(*t))
                .collect();
            match rel.best_index(&pattern) {
                Some((pos, ids)) => {
                    if ids.is_empty() {
                        return Out::Fail;
                    }
                    if ids.len() <= 4 {
                        Candidates::Few(ids.iter().copied().collect())
                    } else {
                        let key = pattern
                            .get(pos)
                            .copied()
                            .flatten()
                            .cloned()
                            .unwrap_or(Term::Nil);
                        Candidates::Index { pos, key }
                    }
                }
                None => {
                    if rel.is_empty() {
                        return Out::Fail;
                    }
                    Candidates::All
                }
            }
        };
        Out::Gen(Gen::Facts(Box::new(FactScan {
            rel: rel.clone(),
            cand,
            next: 0,
            args: args.clone(),
            state: st,
        })))
    })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::term::sym;

    #[test]
    fn insert_dedup_lookup() -> Result<(), KanrenError> {
        let mut r = Relation::new("color", 2);
        assert_eq!(r.insert(&[sym("car1"), sym("white")])?, (0, true));
        assert_eq!(r.insert(&[sym("car2"), sym("red")])?, (1, true));
        assert_eq!(r.insert(&[sym("car3"), sym("white")])?, (2, true));
        assert_eq!(r.insert(&[sym("car1"), sym("white")])?, (0, false));
        assert_eq!(r.len(), 3);
        assert!(r.contains(&[sym("car2"), sym("red")]));
        assert!(!r.contains(&[sym("car2"), sym("white")]));
        assert_eq!(r.lookup(&[None, Some(&sym("white"))]), vec![0, 2]);
        assert_eq!(
            r.lookup(&[Some(&sym("car3")), Some(&sym("white"))]),
            vec![2]
        );
        assert_eq!(r.lookup(&[None, None]), vec![0, 1, 2]);
        assert_eq!(r.lookup(&[Some(&sym("nope")), None]), Vec::<FactId>::new());
        let all: Vec<_> = r.iter().map(|(i, t)| (i, t.to_vec())).collect();
        assert_eq!(all[1], (1, vec![sym("car2"), sym("red")]));
        Ok(())
    }

    #[test]
    fn rejects_bad_tuples() {
        let mut r = Relation::new("p", 2);
        assert!(matches!(
            r.insert(&[sym("a")]),
            Err(KanrenError::ArityMismatch { got: 1, .. })
        ));
        assert!(matches!(
            r.insert(&[sym("a"), Term::Var(crate::term::Var(0))]),
            Err(KanrenError::NonGroundFact { position: 1, .. })
        ));
        assert!(matches!(
            r.insert(&[sym("a"), Term::list([1i64])]),
            Err(KanrenError::NonGroundFact { position: 1, .. })
        ));
        assert!(r.is_empty());
    }

    #[test]
    fn zero_arity_relation() -> Result<(), KanrenError> {
        let mut r = Relation::new("raining", 0);
        assert!(r.is_empty());
        assert_eq!(r.insert(&[])?, (0, true));
        assert_eq!(r.insert(&[])?, (0, false));
        assert_eq!(r.len(), 1);
        assert_eq!(r.iter().count(), 1);
        Ok(())
    }
}
