//! The candidate lists a join reads: a probe cut to an id range, owned
//! (no borrow of the relation), and read one candidate at a time.

use super::index::{ADJACENCY_WORK_PER_FACT, Adjacency, PAIR_INDEX_MIN_FACTS};
use super::{Code, FactId, Probe, Relation, Tuple};
use crate::term::Term;
use std::sync::atomic::Ordering;

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
