//! Ground fact tables: dictionary-encoded columns, an id index per argument
//! position and a dedup table.

mod cands;
mod goal;
mod index;

pub(crate) use cands::{CandArgs, Cands};
pub use goal::fact;
use index::{
    Adjacency, IdList, PAIR_INDEX_MIN_FACTS, PAIR_INDEX_PROBES_PER_FACT, PairIndex, ProbeCount,
};

use crate::error::KanrenError;
use crate::term::{Sym, Term};
use std::collections::HashMap;
use std::hash::{BuildHasher, BuildHasherDefault, Hasher};
use std::sync::OnceLock;
use std::sync::atomic::Ordering;

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

/// Term equality with the symbol case inlined: facts are almost all
/// symbols, and the general `eq` is an out-of-line call per argument that
/// showed in query profiles.
#[inline]
pub fn same_term(a: &Term, b: &Term) -> bool {
    match (a, b) {
        (Term::Sym(x), Term::Sym(y)) => x == y,
        _ => a == b,
    }
}

/// Code-slice equality, inline for arities 1 and 2: the slice `==` is a
/// `memcmp` call, which cost more than the comparison in profiles.
#[inline]
fn codes_eq(a: &[Code], b: &[Code]) -> bool {
    match (a, b) {
        ([x], [y]) => x == y,
        ([x0, x1], [y0, y1]) => x0 == y0 && x1 == y1,
        _ => a == b,
    }
}

/// The dedup hash of a fact given as its value codes. A fully bound pattern
/// is hashed from its codes too, so the dedup table doubles as the index of
/// the all-positions-bound access pattern.
#[inline]
fn hash_codes(hasher: &FxBuild, codes: impl Iterator<Item = Code>) -> u64 {
    let mut h = hasher.build_hasher();
    for c in codes {
        h.write_u32(c);
    }
    // The multiply leaves its entropy in the high bits; the table picks
    // buckets by the low ones (as rustc-hash's `finish` does).
    h.finish().rotate_left(26)
}

// Defined with the proof steps that name facts, so that the core's proofs
// need nothing from this module.
pub use crate::proof::FactId;

/// The code of a value in a relation's dictionary (see [`Relation`]).
type Code = u32;

/// A fact's codes, built on the stack for the usual small arities.
type Key = smallvec::SmallVec<[Code; 6]>;

/// A table of ground facts `name(a1, …, an)`.
///
/// Storage is dictionary-encoded, column values as 4-byte codes:
///
/// * `values[c]` is the term with code `c`, and `c` is found back from the
///   term through `sym_codes` (symbols, by their index) or `other_codes`
///   (every other atom): each distinct argument value of the relation (in
///   any position) is stored once, whatever the number of facts holding it;
/// * `codes` holds every fact once, flat: fact `i` is
///   `codes[i*arity..(i+1)*arity]`, every code `< values.len()`, every value
///   a ground atom;
/// * `index[p][c]` lists, ascending, the ids of the facts whose position `p`
///   holds code `c` (a missing or empty entry: none); a one-id list is inline;
/// * `dedup` holds every fact id exactly once, stored under
///   `hash_codes(fact's codes)`, so a duplicate insert, a `contains` and a
///   fully bound probe are one hash lookup without a scan;
/// * `zero_arity_len` is the number of facts of a 0-ary relation (0 or 1),
///   which has no codes to count;
/// * `pairs`, when set, is the `PairIndex` of the current facts (arity 2
///   only; every insert clears it), and `pair_probes` counts the fully
///   bound probes since the last insert, which decide when to build it;
/// * `adjacency[p]`, when set, is the `Adjacency` of position `p` of the
///   current facts (arity 2 only; every insert clears it), and
///   `adjacency_work[p]` counts the candidates that partly bound probes on
///   position `p` handed out since the last insert, which decide when to
///   build it.
///
/// Why codes: a large window's model is millions of facts over a thousand
/// objects. A fact of `Term`s cost 24 bytes an argument and a join reads one
/// per candidate, so the tables outgrew the cache and each candidate was a
/// memory stall; codes cost 4, compare as integers, and the values they
/// name (few) stay cached. Why a raw table of ids for `dedup`: it is the one
/// structure with an entry per fact, and a map from hash to ids cost 24
/// bytes a slot; the table costs 4 and rehashes from `codes`.
#[derive(Clone)]
pub struct Relation {
    name: Sym,
    arity: usize,
    codes: Vec<Code>,
    values: Vec<Term>,
    // Two maps so that the common key, a symbol, hashes as one integer
    // (the general `Term` hash is an out-of-line call).
    sym_codes: HashMap<u32, Code, FxBuild>,
    other_codes: HashMap<Term, Code, FxBuild>,
    index: Vec<Vec<IdList>>,
    dedup: hashbrown::HashTable<FactId>,
    zero_arity_len: usize,
    hasher: FxBuild,
    pairs: OnceLock<PairIndex>,
    pair_probes: ProbeCount,
    adjacency: [OnceLock<Adjacency>; 2],
    adjacency_work: [ProbeCount; 2],
}

/// One fact of a [`Relation`], read through the relation's dictionary:
/// iterates its argument terms, in order.
///
/// Invariant: every code is an index into `values` (the relation's
/// dictionary), so every position has a term.
#[derive(Clone, Copy)]
pub struct Tuple<'a> {
    values: &'a [Term],
    codes: &'a [Code],
}

impl<'a> Tuple<'a> {
    /// The number of arguments.
    pub fn len(&self) -> usize {
        self.codes.len()
    }

    /// True for a fact of a 0-ary relation.
    pub fn is_empty(&self) -> bool {
        self.codes.is_empty()
    }

    /// Argument `i`.
    #[inline]
    pub fn get(&self, i: usize) -> Option<&'a Term> {
        self.values.get(*self.codes.get(i)? as usize)
    }

    /// The arguments, in order.
    #[inline]
    pub fn iter(&self) -> TupleIter<'a> {
        TupleIter {
            values: self.values,
            codes: self.codes.iter(),
        }
    }

    /// The arguments, copied out.
    pub fn to_vec(&self) -> Vec<Term> {
        self.iter().cloned().collect()
    }
}

impl<'a> IntoIterator for Tuple<'a> {
    type Item = &'a Term;
    type IntoIter = TupleIter<'a>;
    fn into_iter(self) -> TupleIter<'a> {
        self.iter()
    }
}

impl PartialEq for Tuple<'_> {
    fn eq(&self, other: &Tuple<'_>) -> bool {
        if std::ptr::eq(self.values, other.values) {
            return self.codes == other.codes; // one dictionary: codes decide
        }
        self.len() == other.len() && self.iter().zip(other.iter()).all(|(a, b)| same_term(a, b))
    }
}

impl Eq for Tuple<'_> {}

impl PartialEq<[Term]> for Tuple<'_> {
    fn eq(&self, other: &[Term]) -> bool {
        self.len() == other.len() && self.iter().zip(other).all(|(a, b)| same_term(a, b))
    }
}

impl std::fmt::Debug for Tuple<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_list().entries(self.iter()).finish()
    }
}

/// The argument terms of a [`Tuple`].
#[derive(Clone)]
pub struct TupleIter<'a> {
    values: &'a [Term],
    codes: std::slice::Iter<'a, Code>,
}

impl<'a> Iterator for TupleIter<'a> {
    type Item = &'a Term;
    #[inline]
    fn next(&mut self) -> Option<&'a Term> {
        let c = self.codes.next()?;
        self.values.get(*c as usize)
    }
    fn size_hint(&self) -> (usize, Option<usize>) {
        self.codes.size_hint()
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
            codes: Vec::new(),
            values: Vec::new(),
            sym_codes: HashMap::default(),
            other_codes: HashMap::default(),
            index: (0..arity).map(|_| Vec::new()).collect(),
            dedup: hashbrown::HashTable::new(),
            zero_arity_len: 0,
            hasher: FxBuild::default(),
            pairs: OnceLock::new(),
            pair_probes: ProbeCount::default(),
            adjacency: Default::default(),
            adjacency_work: Default::default(),
        }
    }

    /// An empty relation with room for `facts` facts: a bulk load of a known
    /// size grows neither its fact table nor its dedup table.
    pub fn with_capacity(name: impl Into<Sym>, arity: usize, facts: usize) -> Relation {
        let mut r = Relation::new(name, arity);
        r.codes.reserve(facts.saturating_mul(arity));
        r.dedup.reserve(facts, |_| 0);
        r
    }

    /// The same facts under another name: every fact keeps its id, and the
    /// dictionary and indexes are copied, not rebuilt.
    ///
    /// Why: a rule that copies one relation into another
    /// (`DistanceDecrease(x, y) ==> ComeClose(x, y)`) would otherwise insert
    /// every fact again, a hash lookup per value and a dedup probe per fact.
    pub fn renamed(&self, name: impl Into<Sym>) -> Relation {
        Relation {
            name: name.into(),
            ..self.clone()
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
        match self.codes.len().checked_div(self.arity) {
            Some(n) => n,
            None => self.zero_arity_len,
        }
    }

    /// True when there are no facts.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The codes of fact `id` (empty for an id out of range: the dedup table
    /// and the indexes only hold ids in range, so the callers never see it).
    #[inline]
    fn codes_at(codes: &[Code], arity: usize, id: FactId) -> &[Code] {
        let start = (id as usize).saturating_mul(arity);
        codes
            .get(start..start.saturating_add(arity))
            .unwrap_or_default()
    }

    /// The code of a value, when some fact holds it.
    // Called once per bound argument of every probe: a call per lookup
    // showed in query profiles.
    #[inline(always)]
    fn code(&self, t: &Term) -> Option<Code> {
        match t {
            Term::Sym(s) => self.sym_codes.get(&s.index()).copied(),
            other => self.other_codes.get(other).copied(),
        }
    }

    /// The id of the fact with these codes, by one dedup-table lookup.
    fn find_codes(&self, key: &[Code]) -> Option<&FactId> {
        let h = hash_codes(&self.hasher, key.iter().copied());
        let (codes, arity) = (&self.codes, self.arity);
        self.dedup
            .find(h, |&id| codes_eq(Self::codes_at(codes, arity, id), key))
    }

    /// The codes of `values`, or `None` when one of them is in no fact (so
    /// no fact can match). Small arities stay on the stack.
    fn codes_of_all<'t>(&self, values: impl Iterator<Item = &'t Term>) -> Option<Key> {
        let mut key = Key::new();
        for t in values {
            key.push(self.code(t)?);
        }
        Some(key)
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
        let name = self.name;
        let too_many = || KanrenError::TooManyFacts {
            relation: name,
            limit: u64::from(u32::MAX),
        };
        // A value new to the dictionary means a new fact: only a tuple of
        // known values can be a duplicate.
        if let Some(&id) = self.find_tuple(tuple) {
            return Ok((id, false));
        }
        let id = FactId::try_from(self.len()).map_err(|_| too_many())?;
        if self.values.len().saturating_add(tuple.len()) > u32::MAX as usize {
            return Err(too_many());
        }
        if self.pairs.get().is_some() {
            self.pairs = OnceLock::new();
        }
        *self.pair_probes.0.get_mut() = 0;
        for (cell, work) in self.adjacency.iter_mut().zip(&mut self.adjacency_work) {
            if cell.get().is_some() {
                *cell = OnceLock::new();
            }
            *work.0.get_mut() = 0;
        }
        let start = self.codes.len();
        for t in tuple {
            let c = match self.code(t) {
                Some(c) => c,
                None => {
                    let c = Code::try_from(self.values.len()).map_err(|_| too_many())?;
                    self.values.push(t.clone());
                    match t {
                        Term::Sym(s) => self.sym_codes.insert(s.index(), c),
                        other => self.other_codes.insert(other.clone(), c),
                    };
                    c
                }
            };
            self.codes.push(c);
        }
        if self.arity == 0 {
            self.zero_arity_len = 1;
        }
        let key = self.codes.get(start..).unwrap_or_default();
        let h = hash_codes(&self.hasher, key.iter().copied());
        for (p, &c) in key.iter().enumerate() {
            if let Some(ix) = self.index.get_mut(p) {
                if ix.len() <= c as usize {
                    ix.resize(c as usize + 1, IdList::EMPTY);
                }
                if let Some(list) = ix.get_mut(c as usize) {
                    list.push(id);
                }
            }
        }
        // Rehashing re-reads each id's codes: the table stores no hash.
        let (codes, arity, hasher) = (&self.codes, self.arity, &self.hasher);
        self.dedup.insert_unique(h, id, |&i| {
            hash_codes(hasher, Self::codes_at(codes, arity, i).iter().copied())
        });
        Ok((id, true))
    }

    /// Releases the spare capacity left by growth (call after a bulk load).
    pub fn shrink_to_fit(&mut self) {
        self.codes.shrink_to_fit();
        self.values.shrink_to_fit();
        self.sym_codes.shrink_to_fit();
        self.other_codes.shrink_to_fit();
        let (codes, arity, hasher) = (&self.codes, self.arity, &self.hasher);
        self.dedup.shrink_to_fit(|&i| {
            hash_codes(hasher, Self::codes_at(codes, arity, i).iter().copied())
        });
        for ix in &mut self.index {
            ix.shrink_to_fit();
            // Id lists grow by doubling: give back the spare half.
            for list in ix.iter_mut() {
                if let IdList::Many(v) = list {
                    v.shrink_to_fit();
                }
            }
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
        if self.arity == 0 {
            return (self.zero_arity_len > 0).then_some(0);
        }
        self.find_tuple(tuple).copied()
    }

    /// The id of the fact with these values, by one lookup (`None` when a
    /// value is in no fact, so no fact can match).
    #[inline]
    fn find_tuple(&self, tuple: &[Term]) -> Option<&FactId> {
        // Arities 1 and 2 (nearly every fact) keep the key in registers:
        // a key built in a `SmallVec` and returned was a tenth of storing
        // two million facts (profiles put the time on reading it back).
        match tuple {
            // Facts are distinct: a unary value's index entry is its fact.
            [a] => self.ids_at(0, self.code(a)?).first(),
            [a, b] => self.find_codes(&[self.code(a)?, self.code(b)?]),
            _ => self
                .codes_of_all(tuple.iter())
                .and_then(|key| self.find_codes(&key)),
        }
    }

    /// The fact with id `id`.
    #[inline]
    pub fn tuple(&self, id: FactId) -> Option<Tuple<'_>> {
        if self.arity == 0 {
            return (id == 0 && self.zero_arity_len > 0).then_some(Tuple {
                values: &self.values,
                codes: &[],
            });
        }
        let start = (id as usize).checked_mul(self.arity)?;
        let codes = self.codes.get(start..start.checked_add(self.arity)?)?;
        Some(Tuple {
            values: &self.values,
            codes,
        })
    }

    /// All facts in id (insertion) order.
    pub fn iter(&self) -> impl Iterator<Item = (FactId, Tuple<'_>)> + '_ {
        (0..self.len()).filter_map(move |i| {
            let id = FactId::try_from(i).ok()?;
            Some((id, self.tuple(id)?))
        })
    }

    /// The ids holding code `c` at position `p`.
    #[inline]
    fn ids_at(&self, p: usize, c: Code) -> &[FactId] {
        self.index
            .get(p)
            .and_then(|ix| ix.get(c as usize))
            .map_or(&[], IdList::as_slice)
    }

    /// The distinct values at argument position `p`, each once, in code
    /// order (the order values were first stored at any position): the keys of that
    /// position's index, so a projection costs one step per distinct value
    /// instead of one per fact. Empty for a position out of range.
    pub fn values_at(&self, p: usize) -> impl Iterator<Item = &Term> + '_ {
        self.index
            .get(p)
            .into_iter()
            .flat_map(|ix| ix.iter().enumerate())
            .filter(|(_, ids)| !ids.as_slice().is_empty())
            .filter_map(|(c, _)| self.values.get(c))
    }

    /// The most selective bound position of `pattern`: (position, its ids).
    /// `None` when no position is bound; an empty list when a bound value is
    /// in no fact.
    fn best_index<'a>(&'a self, pattern: &[Option<&Term>]) -> Option<(usize, &'a [FactId])> {
        let mut best: Option<(usize, &[FactId])> = None;
        for (p, t) in pattern.iter().enumerate() {
            let Some(t) = t else { continue };
            let ids: &[FactId] = match self.code(t) {
                Some(c) => self.ids_at(p, c),
                None => &[],
            };
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
                .all(|(p, t)| p.is_none_or(|p| same_term(p, t))),
            None => false,
        }
    }

    /// The candidate ids for `pattern` (`None` = any value), without
    /// allocating: a superset of the matching facts that the caller checks
    /// as it binds them. A fully bound pattern probes the dedup table (its
    /// candidates are exactly the matching fact or none); a partly bound one
    /// takes the index of its most selective bound position; an unbound one
    /// is every fact. A pattern of the wrong length, or with a value that no
    /// fact holds, has no candidates.
    pub fn probe(&self, pattern: &[Option<&Term>]) -> Probe<'_> {
        if pattern.len() != self.arity {
            return Probe::Ids(&[]);
        }
        if self.arity > 0 && pattern.iter().all(Option::is_some) {
            // Arities 1 and 2 (nearly every fact) skip the key buffer.
            let found = match *pattern {
                // Facts are distinct: the index entry of a unary relation's
                // value is its one fact, no hashing needed.
                [Some(a)] => self.code(a).and_then(|c| self.ids_at(0, c).first()),
                [Some(a), Some(b)] => match (self.code(a), self.code(b)) {
                    (Some(a), Some(b)) => match self.pair_index() {
                        Some(pairs) => pairs.find(a, b),
                        None => self.find_codes(&[a, b]),
                    },
                    _ => None,
                },
                _ => self
                    .codes_of_all(pattern.iter().flatten().copied())
                    .and_then(|key| self.find_codes(&key)),
            };
            return Probe::Ids(found.map_or(&[], std::slice::from_ref));
        }
        match self.best_index(pattern) {
            Some((_, ids)) => Probe::Ids(ids),
            None => Probe::Range(0, FactId::try_from(self.len()).unwrap_or(FactId::MAX)),
        }
    }

    /// The pair index of a binary relation, built once it has answered
    /// enough fully bound probes since its last insert
    /// ([`PAIR_INDEX_PROBES_PER_FACT`]); `None` before that.
    fn pair_index(&self) -> Option<&PairIndex> {
        if self.arity != 2 || self.len() < PAIR_INDEX_MIN_FACTS {
            return None;
        }
        if let Some(p) = self.pairs.get() {
            return Some(p);
        }
        let asked = self.pair_probes.0.fetch_add(1, Ordering::Relaxed);
        if asked < self.len().saturating_mul(PAIR_INDEX_PROBES_PER_FACT) {
            return None;
        }
        // A build that fails (a code out of range: a broken invariant)
        // leaves the dedup table in charge.
        PairIndex::build(&self.codes, self.values.len()).map(|p| self.pairs.get_or_init(|| p))
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

#[cfg(test)]
mod tests;
