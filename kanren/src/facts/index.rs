//! The extra indexes of binary relations (pair index, adjacency), built
//! on demand, and the id lists of the per-position index.

use super::{Code, FactId};
use std::sync::atomic::{AtomicUsize, Ordering};

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
pub(super) struct PairIndex {
    pub(super) start: Vec<u32>,
    pub(super) by_first: Vec<(Code, FactId)>,
}

impl PairIndex {
    /// The adjacency of the first position, each group then sorted by
    /// second code.
    pub(super) fn build(codes: &[Code], values: usize) -> Option<PairIndex> {
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

    pub(super) fn find(&self, first: Code, second: Code) -> Option<&FactId> {
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
pub(super) struct Adjacency {
    pub(super) start: Vec<u32>,
    pub(super) rows: Vec<(Code, FactId)>,
}

impl Adjacency {
    /// A counting sort of the facts by their code at `pos`: one pass over
    /// the fact table in id order, so each group comes out ascending.
    pub(super) fn build(codes: &[Code], values: usize, pos: usize) -> Option<Adjacency> {
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
    pub(super) fn group(&self, code: Code) -> Option<(usize, usize)> {
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
pub(super) const ADJACENCY_WORK_PER_FACT: usize = 2;

/// How many fully bound probes a relation has answered since its last
/// insert (a counter that clones by value).
#[derive(Debug, Default)]
pub(super) struct ProbeCount(pub(super) AtomicUsize);

impl Clone for ProbeCount {
    fn clone(&self) -> ProbeCount {
        ProbeCount(AtomicUsize::new(self.0.load(Ordering::Relaxed)))
    }
}

/// A relation builds its [`PairIndex`] once this many fully bound probes
/// came since its last insert, per fact: the build costs about a sort of the
/// facts, so it pays only when the relation has stopped growing and is
/// asked often (a model's queries), not between the inserts of a fixpoint.
pub(super) const PAIR_INDEX_PROBES_PER_FACT: usize = 1;

/// Relations smaller than this stay cached anyway: no pair index.
pub(super) const PAIR_INDEX_MIN_FACTS: usize = 1 << 14;

/// A list of fact ids, ascending. Kept inline while it has one id: the ids
/// of a key that identifies its fact are one, so such keys cost no extra
/// allocation.
#[derive(Clone, Debug)]
pub(super) enum IdList {
    One(FactId),
    Many(Vec<FactId>),
}

impl IdList {
    pub(super) const EMPTY: IdList = IdList::Many(Vec::new());

    pub(super) fn as_slice(&self) -> &[FactId] {
        match self {
            IdList::One(id) => std::slice::from_ref(id),
            IdList::Many(v) => v,
        }
    }

    pub(super) fn push(&mut self, id: FactId) {
        match self {
            IdList::One(first) => *self = IdList::Many(vec![*first, id]),
            IdList::Many(v) if v.is_empty() => *self = IdList::One(id),
            IdList::Many(v) => v.push(id),
        }
    }
}
