//! Ground fact tables: dictionary-encoded columns, an id index per argument
//! position and a dedup table.

use crate::ctx::{Ctx, GenStep};
use crate::engine::{Gen, Out};
use crate::error::KanrenError;
use crate::goal::Goal;
use crate::proof::ProofStep;
use crate::state::State;
use crate::term::{Sym, Term};
use std::collections::HashMap;
use std::hash::{BuildHasher, BuildHasherDefault, Hasher};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::{Arc, OnceLock};

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

/// A fact's index in its relation (insertion order, from 0).
pub type FactId = u32;

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

/// The facts of a binary relation grouped by first value and sorted by
/// second value within each group, for fully bound probes.
///
/// Why: a join binds `x` in an outer loop and then asks `R(x, y)` for many
/// `y`; through the dedup table each ask is a random access into a table
/// of every fact, which stalls on memory once the relation outgrows the
/// cache, while `x`'s group is a few kilobytes that stay cached for the
/// whole loop and is searched by bisection.
///
/// Invariants: `start.len() == values.len() + 1` of the relation it was
/// built from; the facts with first code `c` are
/// `by_first[start[c]..start[c+1]]`, as `(second code, id)`, strictly
/// ascending by second code (facts are distinct, so no two share it).
#[derive(Clone, Debug)]
struct PairIndex {
    start: Vec<u32>,
    by_first: Vec<(Code, FactId)>,
}

impl PairIndex {
    /// The adjacency of the first position, each group then sorted by
    /// second code.
    fn build(codes: &[Code], values: usize) -> Option<PairIndex> {
        let Adjacency {
            start,
            rows: mut by_first,
        } = Adjacency::build(codes, values, 0)?;
        for w in start.windows(2) {
            if let [lo, hi] = *w {
                by_first
                    .get_mut(lo as usize..hi as usize)?
                    .sort_unstable_by_key(|p| p.0);
            }
        }
        Some(PairIndex { start, by_first })
    }

    fn find(&self, first: Code, second: Code) -> Option<&FactId> {
        let lo = *self.start.get(first as usize)? as usize;
        let hi = *self.start.get(first as usize + 1)? as usize;
        let group = self.by_first.get(lo..hi)?;
        let at = group.binary_search_by_key(&second, |p| p.0).ok()?;
        group.get(at).map(|p| &p.1)
    }
}

/// The facts of a binary relation grouped by their value at one position,
/// each group in id order with the other position's code beside each id.
///
/// Why: a join that binds `x` and then scans `R(x, y)` reads each
/// candidate's `y` through the fact table, and the facts of one `x` lie
/// far apart in it (a text KB lists `R(a, b)` beside `R(b, a)`): a cache
/// miss per candidate once the relation outgrows the cache. Here a group
/// is one contiguous run.
///
/// Invariants (for the position `pos`, 0 or 1, it was built for):
/// `start.len() == values.len() + 1` of the
/// relation it was built from; the facts whose position `pos` holds code
/// `c` are `rows[start[c]..start[c+1]]`, as `(code at the other position,
/// id)`, ids strictly ascending: the ids of `index[pos][c]`, in the same
/// order, so a scan through it visits the facts in the order the index
/// would.
#[derive(Clone, Debug)]
struct Adjacency {
    start: Vec<u32>,
    rows: Vec<(Code, FactId)>,
}

impl Adjacency {
    /// A counting sort of the facts by their code at `pos`: one pass over
    /// the fact table in id order, so each group comes out ascending.
    fn build(codes: &[Code], values: usize, pos: usize) -> Option<Adjacency> {
        let other = 1 - pos.min(1);
        let mut start = vec![0u32; values.checked_add(1)?];
        for pair in codes.chunks_exact(2) {
            let slot = start.get_mut(*pair.get(pos)? as usize + 1)?;
            *slot = slot.checked_add(1)?;
        }
        for i in 1..start.len() {
            let prev = *start.get(i - 1)?;
            let slot = start.get_mut(i)?;
            *slot = slot.checked_add(prev)?;
        }
        let mut fill: Vec<u32> = start.clone();
        let mut rows = vec![(0, 0); codes.len() / 2];
        for (id, pair) in codes.chunks_exact(2).enumerate() {
            let at = fill.get_mut(*pair.get(pos)? as usize)?;
            *rows.get_mut(*at as usize)? = (*pair.get(other)?, FactId::try_from(id).ok()?);
            *at += 1;
        }
        Some(Adjacency { start, rows })
    }

    /// The rows of the facts whose position `pos` holds `code`, as a range
    /// of `rows`.
    fn group(&self, code: Code) -> Option<(usize, usize)> {
        let lo = *self.start.get(code as usize)? as usize;
        let hi = *self.start.get(code as usize + 1)? as usize;
        Some((lo, hi))
    }
}

/// A binary relation builds the [`Adjacency`] of a position once partly
/// bound probes on it handed out this many candidates per fact since its
/// last insert: the build is one pass over the facts, about what one scan
/// of every fact through the index costs, so it pays back at once and is
/// never built for a relation that is only read a little.
const ADJACENCY_WORK_PER_FACT: usize = 2;

/// How many fully bound probes a relation has answered since its last
/// insert (a counter that clones by value).
#[derive(Debug, Default)]
struct ProbeCount(AtomicUsize);

impl Clone for ProbeCount {
    fn clone(&self) -> ProbeCount {
        ProbeCount(AtomicUsize::new(self.0.load(Ordering::Relaxed)))
    }
}

/// A relation builds its [`PairIndex`] once this many fully bound probes
/// came since its last insert, per fact: the build costs about a sort of the
/// facts, so it pays only when the relation has stopped growing and is
/// asked often (a model's queries), not between the inserts of a fixpoint.
const PAIR_INDEX_PROBES_PER_FACT: usize = 1;

/// Relations smaller than this stay cached anyway: no pair index.
const PAIR_INDEX_MIN_FACTS: usize = 1 << 14;

/// A list of fact ids, ascending. Kept inline while it has one id: the ids
/// of a key that identifies its fact are one, so such keys cost no extra
/// allocation.
#[derive(Clone, Debug)]
enum IdList {
    One(FactId),
    Many(Vec<FactId>),
}

impl IdList {
    const EMPTY: IdList = IdList::Many(Vec::new());

    fn as_slice(&self) -> &[FactId] {
        match self {
            IdList::One(id) => std::slice::from_ref(id),
            IdList::Many(v) => v,
        }
    }

    fn push(&mut self, id: FactId) {
        match self {
            IdList::One(first) => *self = IdList::Many(vec![*first, id]),
            IdList::Many(v) if v.is_empty() => *self = IdList::One(id),
            IdList::Many(v) => v.push(id),
        }
    }
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

/// The candidates of a probe cut to an id range, owned: a cursor that
/// outlives no borrow of its relation (a join run as a search task) keeps
/// this and asks [`Relation::candidate`] for each one in turn.
#[derive(Clone, Debug)]
pub(crate) enum Cands {
    /// The ids `lo..hi`.
    Range(FactId, FactId),
    /// The index list of position `pos` for code `code`, entries `start..end`.
    Index {
        pos: usize,
        code: Code,
        start: usize,
        end: usize,
    },
    /// A short list, copied once (a fully bound probe has one id or none).
    Few(smallvec::SmallVec<[FactId; 4]>),
    /// The rows `lo..hi` of the relation's adjacency of position `pos`
    /// (the index list of one value at that position, with the other
    /// value beside each id).
    Adjacent {
        pos: usize,
        code: Code,
        lo: usize,
        hi: usize,
    },
}

/// The arguments of a candidate fact: read through the fact table, or
/// taken from an adjacency row (no read of the fact table).
pub(crate) enum CandArgs<'a> {
    /// The fact as stored.
    Stored(Tuple<'a>),
    /// A binary fact's two arguments.
    Pair([&'a Term; 2]),
}

impl Relation {
    /// [`Relation::probe`] cut to `lo..hi`, as an owned [`Cands`].
    pub(crate) fn cands(&self, pattern: &[Option<&Term>], lo: FactId, hi: FactId) -> Cands {
        let bound = pattern.iter().filter(|p| p.is_some()).count();
        if pattern.len() == self.arity && bound > 0 && bound < self.arity {
            // The most selective bound position, as `best_index` picks it,
            // keeping the code it looked up.
            let mut best: Option<(usize, Code, &[FactId])> = None;
            for (p, t) in pattern.iter().enumerate() {
                let Some(t) = t else { continue };
                let Some(code) = self.code(t) else {
                    return Cands::Few(Default::default()); // in no fact
                };
                let ids = self.ids_at(p, code);
                if best.is_none_or(|(_, _, b)| ids.len() < b.len()) {
                    best = Some((p, code, ids));
                    if ids.len() <= 1 {
                        break;
                    }
                }
            }
            let Some((pos, code, ids)) = best else {
                return Cands::Few(Default::default());
            };
            // Queries take every fact: no bisection then.
            let whole = lo == 0 && hi as usize >= self.len();
            let (start, end) = if whole {
                (0, ids.len())
            } else {
                let start = ids.partition_point(|&id| id < lo);
                (start, ids.partition_point(|&id| id < hi).max(start))
            };
            if end - start <= 4 {
                return Cands::Few(ids.get(start..end).unwrap_or(&[]).iter().copied().collect());
            }
            if whole
                && let Some(adj) = self.adjacency(pos, end - start)
                && let Some((lo, hi)) = adj.group(code)
            {
                return Cands::Adjacent { pos, code, lo, hi };
            }
            return Cands::Index {
                pos,
                code,
                start,
                end,
            };
        }
        match self.probe(pattern).within(lo, hi) {
            Probe::Range(a, b) => Cands::Range(a, b),
            Probe::Ids(ids) => Cands::Few(ids.iter().copied().collect()),
        }
    }

    /// The fact matching a fully bound `pattern` with an id in `lo..hi`
    /// (`None`: no such fact, or a pattern of the wrong length). Facts are
    /// distinct, so there is at most one.
    pub(crate) fn exact_id(
        &self,
        pattern: &[Option<&Term>],
        lo: FactId,
        hi: FactId,
    ) -> Option<FactId> {
        match self.probe(pattern).within(lo, hi) {
            Probe::Ids(ids) => ids.first().copied(),
            Probe::Range(a, b) => (a < b).then_some(a),
        }
    }

    /// Candidate `k` of `c` (`None` past the last).
    #[inline]
    pub(crate) fn candidate(&self, c: &Cands, k: usize) -> Option<FactId> {
        match c {
            Cands::Range(lo, hi) => {
                let id = lo.checked_add(FactId::try_from(k).ok()?)?;
                (id < *hi).then_some(id)
            }
            Cands::Index {
                pos,
                code,
                start,
                end,
            } => {
                let i = start.checked_add(k)?;
                if i >= *end {
                    return None;
                }
                self.ids_at(*pos, *code).get(i).copied()
            }
            Cands::Few(ids) => ids.get(k).copied(),
            Cands::Adjacent { pos, lo, hi, .. } => {
                self.adjacent_row(*pos, *lo, *hi, k).map(|r| r.1)
            }
        }
    }

    /// Candidate `k` of `c` with its arguments (`None` past the last).
    #[inline]
    pub(crate) fn candidate_args(&self, c: &Cands, k: usize) -> Option<(FactId, CandArgs<'_>)> {
        if let Cands::Adjacent { pos, code, lo, hi } = c {
            let (other, id) = self.adjacent_row(*pos, *lo, *hi, k)?;
            let (key, other) = (
                self.values.get(*code as usize)?,
                self.values.get(other as usize)?,
            );
            let pair = if *pos == 0 {
                [key, other]
            } else {
                [other, key]
            };
            return Some((id, CandArgs::Pair(pair)));
        }
        let id = self.candidate(c, k)?;
        Some((id, CandArgs::Stored(self.tuple(id)?)))
    }

    /// Row `lo + k` of the adjacency of position `pos` (`None` at or past
    /// `hi`, or when it is not built).
    #[inline]
    fn adjacent_row(&self, pos: usize, lo: usize, hi: usize, k: usize) -> Option<(Code, FactId)> {
        let i = lo.checked_add(k)?;
        if i >= hi {
            return None;
        }
        self.adjacency.get(pos)?.get()?.rows.get(i).copied()
    }

    /// The adjacency of position `pos` of a binary relation, built once
    /// partly bound probes on it have handed out enough candidates since
    /// its last insert ([`ADJACENCY_WORK_PER_FACT`]); `None` before that.
    /// `work` is the candidates of the probe asking.
    fn adjacency(&self, pos: usize, work: usize) -> Option<&Adjacency> {
        if self.arity != 2 || self.len() < PAIR_INDEX_MIN_FACTS {
            return None;
        }
        let cell = self.adjacency.get(pos)?;
        if let Some(a) = cell.get() {
            return Some(a);
        }
        let done = self
            .adjacency_work
            .get(pos)?
            .0
            .fetch_add(work, Ordering::Relaxed);
        if done < self.len().saturating_mul(ADJACENCY_WORK_PER_FACT) {
            return None;
        }
        Adjacency::build(&self.codes, self.values.len(), pos).map(|a| cell.get_or_init(|| a))
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
    /// The index of position `pos` for the value with code `key` (looked up
    /// again on each turn: the scan cannot borrow from the relation it
    /// shares).
    Index { pos: usize, key: Code },
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
            Candidates::Index { pos, key } => self.rel.ids_at(*pos, *key),
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
    Goal(crate::goal::G::Fact(Arc::new(FactGoal {
        rel: rel.clone(),
        args: args.into(),
    })))
}

/// A [`fact`] goal: kept as data, not a closure, so that [`crate::naf`] of
/// a fact whose arguments are all bound is one lookup instead of a search.
pub(crate) struct FactGoal {
    rel: Arc<Relation>,
    args: Arc<[Term]>,
}

impl FactGoal {
    /// Whether the fact holds, when every argument is bound to an atom in
    /// `st`; `None` when one is not (a search is needed).
    pub(crate) fn ground_holds(&self, st: &State) -> Option<bool> {
        if self.args.len() != self.rel.arity {
            return Some(false);
        }
        let walked: smallvec::SmallVec<[&Term; 6]> =
            self.args.iter().map(|a| st.subst.walk(a)).collect();
        if walked.iter().any(|t| matches!(t, Term::Var(_))) {
            return None;
        }
        if walked
            .iter()
            .any(|t| matches!(t, Term::Cons(..) | Term::App(..)))
        {
            return Some(false); // facts hold atoms only
        }
        let pattern: smallvec::SmallVec<[Option<&Term>; 6]> =
            walked.iter().map(|t| Some(*t)).collect();
        Some(self.rel.first_match(&pattern).is_some())
    }

    /// Runs the goal on `st`: a scan of the candidates of the most selective
    /// argument bound now.
    pub(crate) fn apply(&self, st: State) -> Out {
        let (rel, args) = (&self.rel, &self.args);
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
                        // A non-empty list means the bound value has a code.
                        match pattern
                            .get(pos)
                            .copied()
                            .flatten()
                            .and_then(|t| rel.code(t))
                        {
                            Some(key) => Candidates::Index { pos, key },
                            None => return Out::Fail,
                        }
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
    }
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
    fn values_at_is_the_distinct_projection() -> Result<(), KanrenError> {
        let mut r = Relation::new("near", 2);
        for (a, b) in [("a", "b"), ("b", "a"), ("a", "c"), ("c", "c")] {
            r.insert(&[sym(a), sym(b)])?;
        }
        let at = |p: usize| -> Vec<Term> { r.values_at(p).cloned().collect() };
        assert_eq!(at(0), vec![sym("a"), sym("b"), sym("c")]);
        // Code order (first stored anywhere in the relation), each once.
        assert_eq!(at(1), vec![sym("a"), sym("b"), sym("c")]);
        assert!(at(2).is_empty());
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

    /// The pair index, once built, answers fully bound probes exactly as
    /// the dedup table does (hits, misses, unknown values), and an insert
    /// clears it so a new fact is found.
    #[test]
    fn pair_index_agrees_with_the_dedup_table() -> Result<(), KanrenError> {
        let n = 200i64;
        let mut r = Relation::new("edge", 2);
        for a in 0..n {
            for b in 0..n {
                if (a * 7 + b * 3) % 5 != 0 {
                    r.insert(&[Term::Int(a), Term::Int(b)])?;
                }
            }
        }
        assert!(r.len() >= PAIR_INDEX_MIN_FACTS);
        let ask = |r: &Relation, a: i64, b: i64| -> Vec<FactId> {
            let (ta, tb) = (Term::Int(a), Term::Int(b));
            match r.probe(&[Some(&ta), Some(&tb)]) {
                Probe::Ids(ids) => ids.to_vec(),
                Probe::Range(lo, hi) => (lo..hi).collect(),
            }
        };
        let mut before = Vec::new();
        for a in 0..n + 1 {
            for b in 0..n + 1 {
                before.push(ask(&r, a, b));
            }
        }
        assert!(before.len() >= r.len() * PAIR_INDEX_PROBES_PER_FACT);
        // Enough probes were asked to build it.
        assert!(r.pairs.get().is_some());
        let mut after = Vec::new();
        for a in 0..n + 1 {
            for b in 0..n + 1 {
                let ids = ask(&r, a, b);
                let want = (a < n && b < n && (a * 7 + b * 3) % 5 != 0) as usize;
                assert_eq!(ids.len(), want, "({a}, {b})");
                for &id in &ids {
                    let t = r.tuple(id).map(|t| t.to_vec());
                    assert_eq!(t, Some(vec![Term::Int(a), Term::Int(b)]));
                }
                after.push(ids);
            }
        }
        assert_eq!(before, after);
        let (id, new) = r.insert(&[Term::Int(0), Term::Int(0)])?;
        assert!(new);
        assert!(r.pairs.get().is_none());
        assert_eq!(ask(&r, 0, 0), vec![id]);
        Ok(())
    }

    /// The adjacency of a position, once built, hands out the candidates
    /// the index list would, in the same order, with each fact's
    /// arguments; an insert clears it, so a new fact is found.
    #[test]
    fn adjacency_agrees_with_the_index() -> Result<(), KanrenError> {
        let n = 200i64;
        let mut r = Relation::new("edge", 2);
        // `(a, b)` beside `(b, a)`, as a text KB lists them: the facts of
        // one value lie far apart.
        for a in 0..n {
            for b in a..n {
                if (a * 7 + b * 3) % 5 != 0 {
                    r.insert(&[Term::Int(a), Term::Int(b)])?;
                    if a != b {
                        r.insert(&[Term::Int(b), Term::Int(a)])?;
                    }
                }
            }
        }
        assert!(r.len() >= PAIR_INDEX_MIN_FACTS);
        let scan = |r: &Relation, pos: usize, v: i64| -> Vec<(FactId, Vec<Term>)> {
            let t = Term::Int(v);
            let pat = if pos == 0 {
                [Some(&t), None]
            } else {
                [None, Some(&t)]
            };
            let c = r.cands(&pat, 0, FactId::MAX);
            let mut out = Vec::new();
            while let Some((id, args)) = r.candidate_args(&c, out.len()) {
                let args: Vec<Term> = match args {
                    CandArgs::Stored(t) => t.to_vec(),
                    CandArgs::Pair(p) => p.iter().map(|t| (*t).clone()).collect(),
                };
                out.push((id, args));
            }
            out
        };
        for pos in 0..2 {
            let before: Vec<_> = (0..n).map(|v| scan(&r, pos, v)).collect();
            for (v, facts) in (0..n).zip(&before) {
                assert!(facts.len() > 4, "{v}: no index scan");
                assert!(facts.windows(2).all(|w| w[0].0 < w[1].0));
                for (id, args) in facts {
                    assert_eq!(args.get(pos), Some(&Term::Int(v)));
                    assert_eq!(r.tuple(*id).map(|t| t.to_vec()).as_ref(), Some(args));
                }
            }
            // Enough scans to build it.
            for _ in 0..ADJACENCY_WORK_PER_FACT {
                for v in 0..n {
                    scan(&r, pos, v);
                }
            }
            assert!(r.adjacency[pos].get().is_some(), "position {pos}");
            let three = Term::Int(3);
            let pat = if pos == 0 {
                [Some(&three), None]
            } else {
                [None, Some(&three)]
            };
            let c = r.cands(&pat, 0, FactId::MAX);
            assert!(
                matches!(c, Cands::Adjacent { pos: p, .. } if p == pos),
                "{c:?}"
            );
            let after: Vec<_> = (0..n).map(|v| scan(&r, pos, v)).collect();
            assert_eq!(before, after, "position {pos}");
        }
        let (id, new) = r.insert(&[Term::Int(0), Term::Int(n)])?;
        assert!(new);
        assert!(r.adjacency.iter().all(|a| a.get().is_none()));
        let zeros = scan(&r, 0, 0);
        assert_eq!(zeros.last(), Some(&(id, vec![Term::Int(0), Term::Int(n)])));
        Ok(())
    }

    /// A tuple reads through the dictionary: equal to its terms, printed
    /// like a slice, and values shared between positions are stored once.
    #[test]
    fn tuples_read_through_the_dictionary() -> Result<(), KanrenError> {
        let mut r = Relation::new("p", 3);
        r.insert(&[sym("a"), Term::Int(1), Term::str("s")])?;
        r.insert(&[Term::Int(1), sym("a"), Term::Int(1)])?;
        assert_eq!(r.values.len(), 3);
        let t = r.tuple(1).ok_or(KanrenError::ArityMismatch {
            relation: r.name(),
            arity: 3,
            got: 0,
        })?;
        assert_eq!(t.len(), 3);
        assert!(t == *[Term::Int(1), sym("a"), Term::Int(1)].as_slice());
        assert_eq!(format!("{t:?}"), format!("{:?}", t.to_vec()));
        assert_eq!(t.get(1), Some(&sym("a")));
        assert_eq!(t.get(3), None);
        assert_ne!(r.tuple(0), r.tuple(1));
        assert_eq!(r.tuple(1), r.clone().tuple(1));
        assert_eq!(r.tuple(2), None);
        assert_eq!(r.lookup(&[None, Some(&sym("a")), None]), vec![1]);
        assert_eq!(
            r.lookup(&[Some(&sym("zz")), None, None]),
            Vec::<FactId>::new()
        );
        Ok(())
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
