//! The persistent substitution: walking and unification.

use crate::term::{Term, Var};
use crate::vmap::VarMap;
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

/// Bindings found by a unification before they are committed; most
/// unifications bind a handful of variables, so they live on the stack.
/// Twelve: `nextto` collects two house patterns' bindings (up to ten) in one
/// buffer, and a spill to the heap cost zebra 6 % of its instructions.
pub(crate) type Pending = smallvec::SmallVec<[(Var, Term); 12]>;

/// A buffer of pending bindings: a [`Pending`] on the stack for a one-off
/// unification, or a `Vec` that a loop reuses (list scans, the engine's
/// `eq`): cheaper to index and to push to than a `SmallVec`, which checks
/// where its data lives on every access.
pub(crate) trait Bindings: std::ops::Deref<Target = [(Var, Term)]> {
    fn push_binding(&mut self, b: (Var, Term));
}

impl Bindings for Pending {
    #[inline]
    fn push_binding(&mut self, b: (Var, Term)) {
        self.push(b);
    }
}

impl Bindings for Vec<(Var, Term)> {
    #[inline]
    fn push_binding(&mut self, b: (Var, Term)) {
        self.push(b);
    }
}

/// Hashes a variable index by a multiplicative mix: variables are dense small
/// integers, so SipHash would be wasted work, yet the trie wants the low bits
/// of neighbouring indexes to differ.
#[derive(Default, Clone, Copy)]
pub(crate) struct VarHasher(u64);

impl Hasher for VarHasher {
    fn finish(&self) -> u64 {
        self.0
    }
    fn write(&mut self, bytes: &[u8]) {
        for b in bytes {
            self.0 = (self.0 << 8 | u64::from(*b)).wrapping_mul(0x9E37_79B9_7F4A_7C15);
        }
    }
    fn write_u32(&mut self, i: u32) {
        // Identity on the low bits keeps consecutive variables in different
        // slots of the first trie level; the high half feeds deeper levels.
        let x = u64::from(i);
        self.0 = x | (x.wrapping_mul(0x9E37_79B9_7F4A_7C15) & 0xFFFF_FFFF_0000_0000);
    }
}

pub(crate) type Map<V> =
    imbl::GenericHashMap<u32, V, BuildHasherDefault<VarHasher>, imbl::shared_ptr::DefaultSharedPtr>;

/// A triangular substitution: each bound variable maps to a term that may
/// itself contain (bound or unbound) variables.
///
/// Invariants: a variable is bound at most once along a search path (bindings
/// are only ever added); no cycle `x -> … -> x` exists (var–var bindings always
/// point from the higher index to the lower, and the occurs check — when on —
/// rejects `x = f(… x …)`); clones share structure (a persistent radix trie
/// indexed by the variable, `vmap::VarMap`, taken with one count) and copy
/// at most `OVERLAY` recent bindings.
#[derive(Default)]
pub struct Subst {
    map: VarMap<Term>,
    /// The newest bindings, not yet in `map` (see [`Overlay`]). A variable
    /// is bound in one of the two, never both.
    overlay: Option<Box<Overlay>>,
}

/// Bindings the overlay holds before they go into the trie.
const OVERLAY: usize = 16;

/// A state's newest bindings, owned by it alone: a commit appends to it
/// with no atomic operation, where a commit into the shared trie makes each
/// node on a root-to-leaf path unique (an atomic compare-and-swap per node,
/// and a copy — with a count increment per child — where another state
/// shares it). The overlay goes into the trie when it is full, and when
/// the state forks ([`Subst::fork`]), so that the branches share those
/// bindings instead of each copying them in later; most states of a
/// search never fork (a scan's last candidate takes its state) and most
/// die young, so most bindings never reach the trie at all.
///
/// Boxed, count and mask included: a state is moved often, and 460 more
/// bytes in every move would cost more than the allocation (an inline top
/// trie level of 64 bytes already did); and with the count and mask in the
/// state, a move right after a commit — the state returned by the
/// unification — read them with wider loads than the stores that had just
/// written them, and stalled (store forwarding): 5 % of zebra's time.
/// Keys apart from values, so a lookup that the mask lets through scans
/// one cache line.
struct Overlay {
    /// Bit `v % 64` is set for every variable `v` here: a lookup of any
    /// other variable goes to the trie after one test.
    mask: u64,
    /// The used slots: `keys[..len]`, `vals[..len]`.
    len: usize,
    keys: [u32; OVERLAY],
    /// `Term::Nil` past the used slots.
    vals: [Term; OVERLAY],
}

impl Overlay {
    fn new() -> Overlay {
        Overlay {
            mask: 0,
            len: 0,
            keys: [0; OVERLAY],
            vals: std::array::from_fn(|_| Term::Nil),
        }
    }

    /// The used slots' keys (`len` is at most `OVERLAY`).
    #[inline(always)]
    fn keys(&self) -> &[u32] {
        self.keys.get(..self.len).unwrap_or(&self.keys)
    }
}

/// Moves the term out of an overlay slot. Atoms and variables are copied
/// field by field and left where they are (dropping them is free): a fork
/// right after a commit reads the slots the commit has just written, and a
/// whole-term move read them with wider loads than those stores, stalling
/// (store forwarding) — a third of the time spent flushing overlays.
#[inline(always)]
fn take_term(t: &mut Term) -> Term {
    match t {
        Term::Var(v) => Term::Var(*v),
        Term::Sym(s) => Term::Sym(*s),
        Term::Int(i) => Term::Int(*i),
        Term::Nil => Term::Nil,
        _ => std::mem::replace(t, Term::Nil),
    }
}

#[inline]
fn mask_bit(v: u32) -> u64 {
    1u64 << (v & 63)
}

impl Clone for Subst {
    /// An empty overlay is not copied (nor allocated): `Subst::fork`
    /// empties it first, and that is the hot path.
    #[inline]
    fn clone(&self) -> Subst {
        let overlay = match &self.overlay {
            Some(ov) if ov.len > 0 => Some(Box::new(Overlay {
                mask: ov.mask,
                len: ov.len,
                keys: ov.keys,
                vals: std::array::from_fn(|i| {
                    if i < ov.len {
                        ov.vals[i].clone()
                    } else {
                        Term::Nil
                    }
                }),
            })),
            _ => None,
        };
        Subst {
            map: self.map.clone(),
            overlay,
        }
    }
}

impl Subst {
    /// The empty substitution.
    pub fn new() -> Subst {
        Subst::default()
    }

    /// The number of bound variables.
    pub fn len(&self) -> usize {
        self.map.len() + self.recent()
    }

    /// True when nothing is bound.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// The term `v` is bound to, one step (no walking).
    pub fn get(&self, v: Var) -> Option<&Term> {
        self.bound(v.0)
    }

    /// The binding of `v`: the overlay first (only when the mask says it
    /// may be there), then the trie.
    #[inline]
    fn bound(&self, v: u32) -> Option<&Term> {
        if let Some(t) = self.recent_binding(v) {
            return Some(t);
        }
        self.map.get(v)
    }

    /// The number of bindings in the overlay.
    fn recent(&self) -> usize {
        self.overlay.as_ref().map_or(0, |ov| ov.len)
    }

    /// The binding of `v` in the overlay, if there.
    #[inline(always)]
    fn recent_binding(&self, v: u32) -> Option<&Term> {
        let ov = self.overlay.as_deref()?;
        if ov.mask & mask_bit(v) == 0 {
            return None;
        }
        let i = ov.keys().iter().rposition(|&k| k == v)?;
        ov.vals.get(i)
    }

    /// Iterates over the bindings, in variable order.
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Var, &Term)> + '_ {
        let mut out = Vec::with_capacity(self.len());
        self.map.for_each(|k, t| out.push((Var(k), t)));
        if let Some(ov) = &self.overlay {
            let n = ov.len;
            out.extend(
                ov.keys
                    .iter()
                    .zip(ov.vals.iter())
                    .take(n)
                    .map(|(k, t)| (Var(*k), t)),
            );
            out.sort_by_key(|p| p.0);
        }
        out.into_iter()
    }

    /// Moves the overlay's bindings into the trie.
    fn flush(&mut self) {
        let Some(ov) = self.overlay.as_deref_mut() else {
            return;
        };
        let Overlay {
            mask,
            len,
            keys,
            vals,
        } = ov;
        let n = (*len).min(OVERLAY);
        *len = 0;
        *mask = 0;
        match n {
            0 => {}
            1 => self.map.insert(keys[0], take_term(&mut vals[0])),
            _ => {
                let max = keys[..n].iter().copied().max().unwrap_or(0);
                self.map.insert_many(
                    max,
                    keys[..n]
                        .iter()
                        .zip(vals[..n].iter_mut())
                        .map(|(k, t)| (*k, take_term(t))),
                );
            }
        }
    }

    /// A copy for another branch of the search: the overlay goes into the
    /// trie first, once, so both branches share those bindings (each
    /// branch's later bindings then go to its own overlay).
    #[inline]
    pub(crate) fn fork(&mut self) -> Subst {
        if self.recent() > 0 {
            self.flush();
        }
        self.clone()
    }

    /// Follows variable bindings until an unbound variable or a non-variable.
    #[inline]
    pub fn walk<'a>(&'a self, t: &'a Term) -> &'a Term {
        let mut t = t;
        while let Term::Var(v) = t {
            match self.bound(v.0) {
                Some(next) => t = next,
                None => break,
            }
        }
        t
    }

    /// Walks `t` and every subterm: the fully resolved term. Subterms that
    /// contain no bound variable are shared with `t`, not copied.
    pub fn walk_star(&self, t: &Term) -> Term {
        self.star(t, &mut false, &mut Vec::new())
            .unwrap_or_else(|| t.clone())
    }

    /// [`Subst::walk_star`], also telling whether the result holds a
    /// variable (found on the same traversal: reification needs both).
    /// `buf` is scratch space, reused across calls (left empty).
    pub(crate) fn walk_star_vars(&self, t: &Term, buf: &mut Vec<Term>) -> (Term, bool) {
        let mut vars = false;
        let out = self.star(t, &mut vars, buf).unwrap_or_else(|| t.clone());
        (out, vars)
    }

    /// The fully resolved `t`, or `None` when that is `t` itself; sets
    /// `vars` when it meets an unbound variable. `buf` is a stack of list
    /// heads being resolved: each call uses the part past its length on
    /// entry and leaves it as it found it.
    fn star(&self, t: &Term, vars: &mut bool, buf: &mut Vec<Term>) -> Option<Term> {
        match t {
            Term::Var(v) => {
                let Some(b) = self.bound(v.0) else {
                    *vars = true;
                    return None;
                };
                if b.is_atomic() {
                    return Some(b.clone());
                }
                Some(self.star(b, vars, buf).unwrap_or_else(|| b.clone()))
            }
            Term::App(f, args) => {
                let mut out: Option<Vec<Term>> = None;
                for (i, a) in args.iter().enumerate() {
                    match (self.star_head(a, vars, buf), &mut out) {
                        (Some(n), Some(v)) => v.push(n),
                        (Some(n), None) => {
                            let mut v = Vec::with_capacity(args.len());
                            v.extend(args.iter().take(i).cloned());
                            v.push(n);
                            out = Some(v);
                        }
                        (None, Some(v)) => v.push(a.clone()),
                        (None, None) => {}
                    }
                }
                out.map(|v| Term::App(*f, v.into()))
            }
            Term::Cons(..) => {
                if atomic_list(t) {
                    return None; // ground and unchanged: common for data lists
                }
                self.star_list(t, vars, buf)
            }
            _ => None,
        }
    }

    /// `star` of a subterm, with no call for atoms (list elements and
    /// arguments mostly are).
    #[inline]
    fn star_head(&self, t: &Term, vars: &mut bool, buf: &mut Vec<Term>) -> Option<Term> {
        if t.is_atomic() {
            None
        } else {
            self.star(t, vars, buf)
        }
    }

    /// `star` for a list: one pass along the spine (through the bound
    /// variables that link the cells of lists built by relations), pushing
    /// the resolved heads on `buf`, then one packed block for the result —
    /// one allocation however long the list. The part after the last bound
    /// tail variable is shared as it is when nothing in it changed (a data
    /// list that a relation's variable ended on, like appendo's suffixes).
    fn star_list(&self, t: &Term, vars: &mut bool, buf: &mut Vec<Term>) -> Option<Term> {
        let start = buf.len();
        let mut cache = crate::vmap::LeafCache::new();
        // The segment since the last bound tail variable (or the start).
        let mut seg_start = start;
        let mut seg_term = t;
        let mut seg_changed = false;
        let mut cur = t;
        let mut shared_rest = false;
        while let Some((items, tail)) = cur.cells() {
            for h in items {
                // Inline cases first: an atom, and a variable bound to an
                // atom (the elements of lists built by relations).
                let n = match h {
                    Term::Var(v) => match self.cached(&mut cache, v.0) {
                        Some(b) if b.is_atomic() => Some(b.clone()),
                        None => {
                            *vars = true;
                            None
                        }
                        Some(_) => self.star(h, vars, buf),
                    },
                    _ if h.is_atomic() => None,
                    _ => self.star(h, vars, buf),
                };
                match n {
                    Some(n) => {
                        buf.push(n);
                        seg_changed = true;
                    }
                    None => buf.push(h.clone()),
                }
            }
            let mut next = tail;
            let mut via_var = false;
            while let Term::Var(v) = next {
                match self.cached(&mut cache, v.0) {
                    Some(b) => {
                        next = b;
                        via_var = true;
                    }
                    None => break,
                }
            }
            if via_var {
                if matches!(next, Term::Cons(..)) {
                    seg_start = buf.len();
                    seg_term = next;
                    seg_changed = false;
                    // A data list reached through a variable is shared
                    // whole (checked only when its first element is an
                    // atom: a list built by a relation starts with a
                    // variable, and is walked on).
                    if next
                        .cells()
                        .is_some_and(|(items, _)| items.first().is_some_and(Term::is_atomic))
                        && atomic_list(next)
                    {
                        shared_rest = true;
                        break;
                    }
                } else {
                    seg_changed = true;
                }
            }
            cur = next;
        }
        let tail = if shared_rest {
            None
        } else {
            self.star(cur, vars, buf)
        };
        let tail = match tail {
            Some(n) => n,
            None if !seg_changed => {
                if seg_start == start {
                    buf.truncate(start);
                    return None; // nothing bound along the way: `t` itself
                }
                buf.truncate(seg_start);
                seg_term.clone()
            }
            None => cur.clone(),
        };
        if buf.len() == start {
            return Some(tail);
        }
        buf.push(tail);
        let block: Arc<[Term]> = buf.drain(start..).collect();
        Some(Term::packed(block))
    }

    /// `self.bound(v)` through a cache of the last trie leaf reached.
    #[inline]
    fn cached<'a>(
        &'a self,
        cache: &mut crate::vmap::LeafCache<'a, Term>,
        v: u32,
    ) -> Option<&'a Term> {
        if let Some(t) = self.recent_binding(v) {
            return Some(t);
        }
        cache.get(&self.map, v)
    }

    /// Looks `v` up in the bindings not yet committed, then in the map.
    #[inline]
    fn lookup<'a>(&'a self, v: Var, pending: &'a [(Var, Term)]) -> Option<&'a Term> {
        for (w, t) in pending.iter().rev() {
            if *w == v {
                return Some(t);
            }
        }
        self.bound(v.0)
    }

    #[inline]
    fn walk_p<'a>(&'a self, t: &'a Term, pending: &'a [(Var, Term)]) -> &'a Term {
        let mut t = t;
        while let Term::Var(v) = t {
            match self.lookup(*v, pending) {
                Some(next) => t = next,
                None => break,
            }
        }
        t
    }

    fn occurs(&self, v: Var, t: &Term, pending: &[(Var, Term)]) -> bool {
        let mut t = self.walk_p(t, pending);
        if atomic_list(t) {
            return false; // a data list: no variable anywhere in it
        }
        // Loop down list spines (lists can be long), recurse into heads.
        loop {
            match self.walk_p(t, pending) {
                Term::Var(w) => return *w == v,
                c @ Term::Cons(..) => {
                    let Some((items, tail)) = c.cells() else {
                        return false;
                    };
                    if items
                        .iter()
                        .any(|h| !h.is_atomic() && self.occurs(v, h, pending))
                    {
                        return true;
                    }
                    t = tail;
                }
                Term::App(_, args) => {
                    return args
                        .iter()
                        .any(|a| !a.is_atomic() && self.occurs(v, a, pending));
                }
                _ => return false,
            }
        }
    }

    /// Walks `t` through the map and `pending`; the result is borrowed from
    /// the map or `t` when it lives there, else named by its index in
    /// `pending` (a variable is bound in one of the two, never both).
    #[inline(always)]
    fn walk_m<'a>(&'a self, t: &'a Term, pending: &[(Var, Term)]) -> Walked<'a> {
        let mut t = t;
        loop {
            let Term::Var(v) = t else {
                return Walked::Ref(t);
            };
            if let Some(n) = self.bound(v.0) {
                t = n;
                continue;
            }
            let Some(mut i) = pending.iter().rposition(|(w, _)| w == v) else {
                return Walked::Ref(t);
            };
            loop {
                let Term::Var(w) = &pending[i].1 else {
                    return Walked::Pend(i);
                };
                if let Some(n) = self.bound(w.0) {
                    t = n;
                    break;
                }
                match pending.iter().rposition(|(u, _)| u == w) {
                    Some(j) => i = j,
                    None => return Walked::Pend(i),
                }
            }
        }
    }

    /// Unifies `a` and `b` without touching the map: the bindings it needs
    /// are appended to `pending` (and consulted by later lookups). Most
    /// unifications in a search fail, and this way a failure costs only
    /// lookups; [`Subst::commit`] applies the bindings of a success.
    pub(crate) fn unify_pending(
        &self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        pending: &mut impl Bindings,
    ) -> bool {
        self.unify_one(a, b, occurs_check, pending)
    }

    /// Unifies two subterms (arguments, list heads). The cases that need
    /// no recursion — two atoms, an unbound variable against an atom or a
    /// variable — are decided here, inline in the caller's loop, with no
    /// call: in zebra they are nearly all of them. The rest go to
    /// [`Subst::unify_one`].
    #[inline(always)]
    fn unify_arg<B: Bindings>(
        &self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        pending: &mut B,
    ) -> bool {
        let (Walked::Ref(x), Walked::Ref(y)) = (self.walk_m(a, pending), self.walk_m(b, pending))
        else {
            return self.unify_one(a, b, occurs_check, pending);
        };
        match (x, y) {
            (Term::Var(vx), Term::Var(vy)) => {
                if vx != vy {
                    // Higher index points to lower (see unify_one).
                    let bind = if vx > vy {
                        (*vx, y.clone())
                    } else {
                        (*vy, x.clone())
                    };
                    pending.push_binding(bind);
                }
                true
            }
            (Term::Var(vx), _) if y.is_atomic() => {
                pending.push_binding((*vx, y.clone()));
                true
            }
            (_, Term::Var(vy)) if x.is_atomic() => {
                pending.push_binding((*vy, x.clone()));
                true
            }
            (Term::Sym(p), Term::Sym(q)) => p == q,
            (Term::Int(p), Term::Int(q)) => p == q,
            _ => self.unify_one(x, y, occurs_check, pending),
        }
    }

    /// Unification proper (see [`Subst::unify_pending`]). List spines are
    /// followed by a loop, not by recursion: two long lists must not
    /// exhaust the stack.
    fn unify_one<B: Bindings>(
        &self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        pending: &mut B,
    ) -> bool {
        // Walked terms that live in the map or in `a`/`b` are borrowed as
        // they are; only one bound by `pending` (which the recursion below
        // extends) is cloned. Most are not, so most compound unifications
        // touch no reference count.
        let (held_a, held_b): (Term, Term);
        let a: &Term = match self.walk_m(a, pending) {
            Walked::Ref(t) => t,
            Walked::Pend(i) => {
                held_a = pending[i].1.clone();
                &held_a
            }
        };
        let b: &Term = match self.walk_m(b, pending) {
            Walked::Ref(t) => t,
            Walked::Pend(i) => {
                held_b = pending[i].1.clone();
                &held_b
            }
        };
        match (a, b) {
            (Term::Var(x), Term::Var(y)) => {
                if x == y {
                    return true;
                }
                // Higher index points to lower: chains run towards the
                // oldest variable, keeping them short and cycle-free.
                let (from, to) = if x > y {
                    (*x, b.clone())
                } else {
                    (*y, a.clone())
                };
                pending.push_binding((from, to));
                return true;
            }
            (Term::Var(x), _) => {
                if occurs_check && !b.is_atomic() && self.occurs(*x, b, pending) {
                    return false;
                }
                pending.push_binding((*x, b.clone()));
                return true;
            }
            (_, Term::Var(y)) => {
                if occurs_check && !a.is_atomic() && self.occurs(*y, a, pending) {
                    return false;
                }
                pending.push_binding((*y, a.clone()));
                return true;
            }
            (Term::Cons(b1, p1), Term::Cons(b2, p2)) => {
                if b1.ptr_eq(b2) && p1 == p2 {
                    return true;
                }
            }
            (Term::App(f, xs), Term::App(g, ys)) => {
                if f != g || xs.len() != ys.len() {
                    return false;
                }
                if Arc::ptr_eq(xs, ys) {
                    return true;
                }
            }
            (x, y) => return x == y,
        }
        match (a, b) {
            (Term::Cons(b1, p1), Term::Cons(b2, p2)) => {
                // Two cursors, each a block and a position in it: heads
                // are unified pairwise along the blocks, and a cursor at
                // its block's tail moves into the block that tail walks to.
                let (mut b1, mut o1) = (b1.clone(), p1.index(b1));
                let (mut b2, mut o2) = (b2.clone(), p2.index(b2));
                loop {
                    // A block has at least two slots (`ListBlock`'s
                    // invariant), so `tail_index` is at least 1.
                    let (s1, s2) = (b1.slots(), b2.slots());
                    let (e1, e2) = (b1.tail_index(), b2.tail_index());
                    while o1 < e1 && o2 < e2 {
                        if !self.unify_arg(&s1[o1], &s2[o2], occurs_check, pending) {
                            return false;
                        }
                        o1 += 1;
                        o2 += 1;
                    }
                    let mut stuck = false;
                    if o1 >= e1 {
                        match self.walk_p(&s1[e1], pending) {
                            Term::Cons(nb, np) => {
                                let (nb, np) = (nb.clone(), np.index(nb));
                                b1 = nb;
                                o1 = np;
                            }
                            _ => stuck = true,
                        }
                    }
                    if o2 >= e2 {
                        match self.walk_p(&s2[e2], pending) {
                            Term::Cons(nb, np) => {
                                let (nb, np) = (nb.clone(), np.index(nb));
                                b2 = nb;
                                o2 = np;
                            }
                            _ => stuck = true,
                        }
                    }
                    if stuck {
                        // One side ends in a non-cell: unify the rests.
                        let r1 = Term::skip_cells(&b1, o1);
                        let r2 = Term::skip_cells(&b2, o2);
                        return self.unify_one(&r1, &r2, occurs_check, pending);
                    }
                    if b1.ptr_eq(&b2) && o1 == o2 {
                        return true;
                    }
                }
            }
            (Term::App(_, xs), Term::App(_, ys)) => {
                // An index loop: measured 5 % fewer zebra instructions than
                // `zip(..).all(..)` (lengths are equal, checked above).
                for i in 0..xs.len().min(ys.len()) {
                    if !self.unify_arg(&xs[i], &ys[i], occurs_check, pending) {
                        return false;
                    }
                }
                true
            }
            _ => false,
        }
    }

    /// Adds the bindings found by [`Subst::unify_pending`]: to the
    /// overlay, which goes into the trie first when they would not fit.
    #[inline]
    pub(crate) fn commit(&mut self, pending: &[(Var, Term)]) {
        if self.recent() + pending.len() > OVERLAY {
            self.flush();
            if pending.len() > OVERLAY {
                let max = pending.iter().map(|(v, _)| v.0).max().unwrap_or(0);
                self.map
                    .insert_many(max, pending.iter().map(|(v, t)| (v.0, t.clone())));
                return;
            }
        }
        let ov = self.overlay.get_or_insert_with(|| Box::new(Overlay::new()));
        let Overlay {
            mask,
            len,
            keys,
            vals,
        } = &mut **ov;
        let n = *len;
        let mut m = *mask;
        for ((k, slot), (v, t)) in keys.iter_mut().zip(vals.iter_mut()).skip(n).zip(pending) {
            *k = v.0;
            *slot = t.clone();
            m |= mask_bit(v.0);
        }
        *mask = m;
        *len = (n + pending.len()).min(OVERLAY);
    }

    /// Unifies `a` and `b`, extending `self`; false (and `self` unchanged)
    /// when they do not unify. Every binding added is appended to `log`.
    pub(crate) fn unify(
        &mut self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        log: &mut Option<&mut Vec<(Var, Term)>>,
    ) -> bool {
        let mut pending = Pending::new();
        if !self.unify_pending(a, b, occurs_check, &mut pending) {
            return false;
        }
        self.commit(&pending);
        if let Some(log) = log {
            log.extend(pending);
        }
        true
    }
}

impl std::fmt::Debug for Subst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut pairs: Vec<(Var, &Term)> = self.iter().collect();
        pairs.sort_by_key(|p| p.0);
        f.debug_map().entries(pairs).finish()
    }
}

/// Where [`Subst::walk_m`] ended: a borrowed term, or a pending binding.
enum Walked<'a> {
    Ref(&'a Term),
    Pend(usize),
}

/// True when `t` is a proper (or atom-terminated) list of atoms: ground,
/// so `walk*` leaves it as it is. A tight loop with no lookups, which lets
/// `walk*` skip long data lists without recursing down them.
fn atomic_list(t: &Term) -> bool {
    let mut t = t;
    while let Some((items, tail)) = t.cells() {
        if !items.iter().all(Term::is_atomic) {
            return false;
        }
        t = tail;
    }
    t.is_atomic()
}

/// Unifies `a` and `b` in `s` (most general unifier), returning the extended
/// substitution or `None` when they do not unify.
pub fn unify(s: &Subst, a: &Term, b: &Term, occurs_check: bool) -> Option<Subst> {
    let mut out = s.clone();
    if out.unify(a, b, occurs_check, &mut None) {
        Some(out)
    } else {
        None
    }
}

#[cfg(test)]
mod tests;
