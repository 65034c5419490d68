//! The persistent substitution: walking and unification.

use crate::term::{Term, Var};
use std::hash::{BuildHasherDefault, Hasher};
use std::sync::Arc;

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
    map: Map<Term>,
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
        self.map.get(&v.0)
    }

    /// Iterates over the bindings (unordered).
    pub(crate) fn iter(&self) -> impl Iterator<Item = (Var, &Term)> + '_ {
        self.map.iter().map(|(k, t)| (Var(*k), t))
    }

    /// Follows variable bindings until an unbound variable or a non-variable.
    #[inline]
    pub fn walk<'a>(&'a self, t: &'a Term) -> &'a Term {
        let mut t = t;
        while let Term::Var(v) = t {
            match self.map.get(&v.0) {
                Some(next) => t = next,
                None => break,
            }
        }
        t
    }

    /// Walks `t` and every subterm: the fully resolved term.
    pub fn walk_star(&self, t: &Term) -> Term {
        let t = self.walk(t);
        match t {
            Term::Cons(c) => {
                let h = self.walk_star(&c.0);
                let tl = self.walk_star(&c.1);
                Term::Cons(Arc::new((h, tl)))
            }
            Term::App(f, args) => Term::App(*f, args.iter().map(|a| self.walk_star(a)).collect()),
            other => other.clone(),
        }
    }

    fn occurs(&self, v: Var, t: &Term) -> bool {
        match self.walk(t) {
            Term::Var(w) => *w == v,
            Term::Cons(c) => self.occurs(v, &c.0) || self.occurs(v, &c.1),
            Term::App(_, args) => args.iter().any(|a| self.occurs(v, a)),
            _ => false,
        }
    }

    /// Unifies `a` and `b`, extending `self`. On failure `self` may hold a
    /// partial extension and must be discarded (callers unify into a clone).
    /// Every binding added is appended to `log` when one is given: the
    /// constraint store re-checks exactly those variables, and `neq` turns
    /// them into its disequality.
    pub(crate) fn unify(
        &mut self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        log: &mut Option<&mut Vec<(Var, Term)>>,
    ) -> bool {
        let a = self.walk(a).clone();
        let b = self.walk(b).clone();
        match (&a, &b) {
            (Term::Var(x), Term::Var(y)) => {
                if x == y {
                    return true;
                }
                // Higher index points to lower: chains run towards the oldest
                // variable, keeping them short and cycle-free.
                let (from, to) = if x > y { (*x, b) } else { (*y, a) };
                self.extend(from, to, log);
                true
            }
            (Term::Var(x), _) => {
                if occurs_check && self.occurs(*x, &b) {
                    return false;
                }
                self.extend(*x, b, log);
                true
            }
            (_, Term::Var(y)) => {
                if occurs_check && self.occurs(*y, &a) {
                    return false;
                }
                self.extend(*y, a, log);
                true
            }
            (Term::Cons(c1), Term::Cons(c2)) => {
                Arc::ptr_eq(c1, c2)
                    || (self.unify(&c1.0, &c2.0, occurs_check, log)
                        && self.unify(&c1.1, &c2.1, occurs_check, log))
            }
            (Term::App(f, xs), Term::App(g, ys)) => {
                if f != g || xs.len() != ys.len() {
                    return false;
                }
                if Arc::ptr_eq(xs, ys) {
                    return true;
                }
                xs.iter()
                    .zip(ys.iter())
                    .all(|(x, y)| self.unify(x, y, occurs_check, log))
            }
            (x, y) => x == y,
        }
    }

    #[inline]
    fn extend(&mut self, v: Var, t: Term, log: &mut Option<&mut Vec<(Var, Term)>>) {
        if let Some(log) = log {
            log.push((v, t.clone()));
        }
        self.map.insert(v.0, t);
    }
}

impl std::fmt::Debug for Subst {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut pairs: Vec<(Var, &Term)> = self.iter().collect();
        pairs.sort_by_key(|p| p.0);
        f.debug_map().entries(pairs).finish()
    }
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
