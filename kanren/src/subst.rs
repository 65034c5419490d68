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
/// rejects `x = f(… x …)`); clones are O(1) and share structure (imbl HAMT).
#[derive(Clone, Default)]
pub struct Subst {
    map: VarMap<Term>,
}

impl Subst {
    /// The empty substitution.
    pub fn new() -> Subst {
        Subst::default()
    }

    /// The number of bound variables.
    pub fn len(&self) -> usize {
        self.map.len()
    }

    /// True when nothing is bound.
    pub fn is_empty(&self) -> bool {
        self.map.is_empty()
    }

    /// The term `v` is bound to, one step (no walking).
    pub fn get(&self, v: Var) -> Option<&Term> {
        self.map.get(v.0)
    }

    /// Iterates over the bindings (unordered).
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Var, &Term)> + '_ {
        let mut out = Vec::with_capacity(self.map.len());
        self.map.for_each(|k, t| out.push((Var(k), t)));
        out.into_iter()
    }

    /// Follows variable bindings until an unbound variable or a non-variable.
    #[inline]
    pub fn walk<'a>(&'a self, t: &'a Term) -> &'a Term {
        let mut t = t;
        while let Term::Var(v) = t {
            match self.map.get(v.0) {
                Some(next) => t = next,
                None => break,
            }
        }
        t
    }

    /// Walks `t` and every subterm: the fully resolved term. Subterms that
    /// contain no bound variable are shared with `t`, not copied.
    pub fn walk_star(&self, t: &Term) -> Term {
        self.star(t, &mut false).unwrap_or_else(|| t.clone())
    }

    /// [`Subst::walk_star`], also telling whether the result holds a
    /// variable (found on the same traversal: reification needs both).
    pub(crate) fn walk_star_vars(&self, t: &Term) -> (Term, bool) {
        let mut vars = false;
        let out = self.star(t, &mut vars).unwrap_or_else(|| t.clone());
        (out, vars)
    }

    /// The fully resolved `t`, or `None` when that is `t` itself; sets
    /// `vars` when it meets an unbound variable.
    fn star(&self, t: &Term, vars: &mut bool) -> Option<Term> {
        match t {
            Term::Var(v) => {
                let Some(b) = self.map.get(v.0) else {
                    *vars = true;
                    return None;
                };
                if b.is_atomic() {
                    return Some(b.clone());
                }
                Some(self.star(b, vars).unwrap_or_else(|| b.clone()))
            }
            Term::App(f, args) => {
                let mut out: Option<Vec<Term>> = None;
                for (i, a) in args.iter().enumerate() {
                    match (self.star_head(a, vars), &mut out) {
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
            Term::Cons(c) => {
                if atomic_list(t) {
                    return None; // ground and unchanged: common for data lists
                }
                self.star_cons(c, 0, vars)
                    .unwrap_or_else(|()| self.star_list(t, vars))
            }
            _ => None,
        }
    }

    /// `star` of a subterm, with no call for atoms (list elements and
    /// arguments mostly are).
    #[inline]
    fn star_head(&self, t: &Term, vars: &mut bool) -> Option<Term> {
        if t.is_atomic() {
            None
        } else {
            self.star(t, vars)
        }
    }

    /// `star` of a list cell by recursion down the spine — no buffer to
    /// allocate — for lists up to `MAX_DEPTH` cells; `Err(())` past that, and
    /// the caller falls back to the iterative `star_list`.
    fn star_cons(
        &self,
        c: &Arc<(Term, Term)>,
        depth: usize,
        vars: &mut bool,
    ) -> Result<Option<Term>, ()> {
        const MAX_DEPTH: usize = 2048;
        if depth > MAX_DEPTH {
            return Err(());
        }
        let head = self.star_head(&c.0, vars);
        let mut next = &c.1;
        let mut via_var = false;
        while let Term::Var(v) = next {
            match self.map.get(v.0) {
                Some(b) => {
                    next = b;
                    via_var = true;
                }
                None => break,
            }
        }
        let tail = match next {
            Term::Cons(n) => self.star_cons(n, depth + 1, vars)?,
            other => self.star(other, vars),
        };
        if head.is_none() && tail.is_none() && !via_var {
            return Ok(None);
        }
        let tail = tail.unwrap_or_else(|| next.clone());
        let head = head.unwrap_or_else(|| c.0.clone());
        Ok(Some(Term::Cons(Arc::new((head, tail)))))
    }

    /// `star` for a list, iterating along the spine (lists can be long; the
    /// tails of lists built by relations are usually bound variables).
    fn star_list(&self, t: &Term, vars: &mut bool) -> Option<Term> {
        let mut spine: Vec<SpineCell<'_>> = Vec::new();
        let mut cur = t;
        while let Term::Cons(c) = cur {
            let head = self.star_head(&c.0, vars);
            let mut next = &c.1;
            let mut via_var = false;
            while let Term::Var(v) = next {
                match self.map.get(v.0) {
                    Some(b) => {
                        next = b;
                        via_var = true;
                    }
                    None => break,
                }
            }
            spine.push((c, head, next, via_var));
            cur = next;
        }
        let mut acc = self.star(cur, vars);
        for (c, head, next, via_var) in spine.into_iter().rev() {
            if head.is_none() && acc.is_none() && !via_var {
                continue;
            }
            let tail = acc.take().unwrap_or_else(|| next.clone());
            let head = head.unwrap_or_else(|| c.0.clone());
            acc = Some(Term::Cons(Arc::new((head, tail))));
        }
        acc
    }

    /// Looks `v` up in the bindings not yet committed, then in the map.
    #[inline]
    fn lookup<'a>(&'a self, v: Var, pending: &'a [(Var, Term)]) -> Option<&'a Term> {
        for (w, t) in pending.iter().rev() {
            if *w == v {
                return Some(t);
            }
        }
        self.map.get(v.0)
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
                Term::Cons(c) => {
                    if !c.0.is_atomic() && self.occurs(v, &c.0, pending) {
                        return true;
                    }
                    t = &c.1;
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
    #[inline]
    fn walk_m<'a>(&'a self, t: &'a Term, pending: &[(Var, Term)]) -> Walked<'a> {
        let mut t = t;
        loop {
            let Term::Var(v) = t else {
                return Walked::Ref(t);
            };
            if let Some(n) = self.map.get(v.0) {
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
                if let Some(n) = self.map.get(w.0) {
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
        pending: &mut Pending,
    ) -> bool {
        self.unify_one(a, b, occurs_check, pending)
    }

    /// Unification proper (see [`Subst::unify_pending`]). List spines are
    /// followed by a loop, not by recursion: two long lists must not
    /// exhaust the stack.
    fn unify_one(&self, a: &Term, b: &Term, occurs_check: bool, pending: &mut Pending) -> bool {
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
                pending.push((from, to));
                return true;
            }
            (Term::Var(x), _) => {
                if occurs_check && !b.is_atomic() && self.occurs(*x, b, pending) {
                    return false;
                }
                pending.push((*x, b.clone()));
                return true;
            }
            (_, Term::Var(y)) => {
                if occurs_check && !a.is_atomic() && self.occurs(*y, a, pending) {
                    return false;
                }
                pending.push((*y, a.clone()));
                return true;
            }
            (Term::Cons(c1), Term::Cons(c2)) => {
                if Arc::ptr_eq(c1, c2) {
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
            (Term::Cons(c1), Term::Cons(c2)) => {
                let (mut c1, mut c2) = (c1.clone(), c2.clone());
                loop {
                    if !self.unify_one(&c1.0, &c2.0, occurs_check, pending) {
                        return false;
                    }
                    let next = match (self.walk_p(&c1.1, pending), self.walk_p(&c2.1, pending)) {
                        (Term::Cons(n1), Term::Cons(n2)) => {
                            if Arc::ptr_eq(n1, n2) {
                                return true;
                            }
                            Some((n1.clone(), n2.clone()))
                        }
                        _ => None,
                    };
                    match next {
                        Some((n1, n2)) => {
                            c1 = n1;
                            c2 = n2;
                        }
                        None => return self.unify_one(&c1.1, &c2.1, occurs_check, pending),
                    }
                }
            }
            (Term::App(_, xs), Term::App(_, ys)) => {
                // An index loop: measured 5 % fewer zebra instructions than
                // `zip(..).all(..)` (lengths are equal, checked above).
                for i in 0..xs.len().min(ys.len()) {
                    if !self.unify_one(&xs[i], &ys[i], occurs_check, pending) {
                        return false;
                    }
                }
                true
            }
            _ => false,
        }
    }

    /// Adds the bindings found by [`Subst::unify_pending`].
    pub(crate) fn commit(&mut self, pending: &[(Var, Term)]) {
        for (v, t) in pending {
            self.map.insert(v.0, t.clone());
        }
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
    while let Term::Cons(c) = t {
        if !c.0.is_atomic() {
            return false;
        }
        t = &c.1;
    }
    t.is_atomic()
}

/// A list cell met by `star_list`: the cell, its resolved head (`None`:
/// unchanged), what its tail resolved to, and whether the tail was a bound
/// variable (so the cell must be rebuilt even if nothing below changed).
type SpineCell<'a> = (&'a Arc<(Term, Term)>, Option<Term>, &'a Term, bool);

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
