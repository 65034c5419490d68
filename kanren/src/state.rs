//! Search states and the constraint store.
//!
//! The store keeps constraints as *attributes of unbound variables*: a
//! disequality, a type restriction or an absento tag sits on the variables
//! whose binding could change its truth. After a unification the store is
//! consulted only for the variables that unification just bound, so a
//! constraint is re-checked only when one of its variables changes — and a
//! search that posts no constraints never touches the store at all.

use crate::error::RunError;
use crate::proof::{self, ProofNode, ProofStep};
use crate::subst::{Map, Subst};
use crate::term::{Term, Var};
use std::sync::Arc;

/// The type a variable is restricted to (`symbolo`, `numbero`, `stringo`).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub(crate) enum TypeTag {
    Sym,
    Num,
    Str,
}

impl TypeTag {
    fn admits(self, t: &Term) -> bool {
        matches!(
            (self, t),
            (TypeTag::Sym, Term::Sym(_))
                | (TypeTag::Num, Term::Int(_))
                | (TypeTag::Str, Term::Str(_))
        )
    }

    pub(crate) fn goal_name(self) -> &'static str {
        match self {
            TypeTag::Sym => "symbolo",
            TypeTag::Num => "numbero",
            TypeTag::Str => "stringo",
        }
    }
}

/// A disequality in solved form: "not all of `x_i = t_i`".
///
/// Invariant: the pairs are exactly the bindings a unification of the two
/// sides would add to the substitution it was last checked against; it is
/// non-empty (an empty prefix means the sides are equal: the constraint has
/// failed and is never stored).
#[derive(Debug)]
pub(crate) struct Diseq {
    pub pairs: Vec<(Var, Term)>,
}

/// The constraints attached to one unbound variable.
#[derive(Clone, Default, Debug)]
pub(crate) struct Attr {
    /// Disequalities that may become violated when this variable is bound.
    pub neqs: Vec<Arc<Diseq>>,
    /// The type this variable must take, if restricted.
    pub ty: Option<TypeTag>,
    /// Ground terms that must not occur in this variable's value.
    pub absent: Vec<Term>,
}

/// A search state: a substitution, its constraint store, the next fresh
/// variable and (when proofs are on) the derivation so far.
///
/// Invariants: every variable in `subst` or `store` has an index below
/// `next_var`; `store` only has entries for variables unbound in `subst`, and
/// the constraints in it are satisfiable together with `subst` as far as
/// the checks below can tell (each one individually is).
#[derive(Clone)]
pub(crate) struct State {
    pub subst: Subst,
    pub store: Map<Attr>,
    pub next_var: u32,
    pub proof: Option<Arc<ProofNode>>,
}

impl State {
    pub fn new(next_var: u32) -> State {
        State {
            subst: Subst::new(),
            store: Map::default(),
            next_var,
            proof: None,
        }
    }

    pub fn fresh_var(&mut self) -> Term {
        let v = Var(self.next_var);
        self.next_var += 1;
        Term::Var(v)
    }

    pub fn record(&mut self, step: ProofStep) {
        self.proof = proof::push(&self.proof, step);
    }

    /// Unifies `a` and `b`, re-checking the constraints on every variable the
    /// unification binds. Consumes the state: callers that branch clone first.
    #[inline]
    pub fn unify(self, a: &Term, b: &Term, occurs_check: bool) -> Option<State> {
        let mut pending = crate::subst::Pending::new();
        if !self.subst.unify_pending(a, b, occurs_check, &mut pending) {
            return None;
        }
        self.extended(&pending, occurs_check)
    }

    /// Unifies `a` and `b` into `buf` (cleared first) without touching the
    /// substitution: the bindings a unification would add, or `false`.
    #[inline]
    fn pending_into(
        &self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        buf: &mut Vec<(Var, Term)>,
    ) -> bool {
        if !buf.is_empty() {
            buf.clear();
        }
        self.subst.unify_pending(a, b, occurs_check, buf)
    }

    /// [`State::unify`] with a caller's reusable binding buffer (cleared first).
    #[inline]
    pub(crate) fn unify_buf(
        self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        buf: &mut Vec<(Var, Term)>,
    ) -> Option<State> {
        if !self.pending_into(a, b, occurs_check, buf) {
            return None;
        }
        self.extended(buf, occurs_check)
    }

    /// A copy of this state for another branch of the search, its newest
    /// bindings moved into the shared substitution first (see
    /// [`Subst::fork`]): what the engine and the list scans use where they
    /// fork. A plain `clone` copies those bindings instead.
    #[inline]
    pub(crate) fn fork(&mut self) -> State {
        State {
            subst: self.subst.fork(),
            store: self.store.clone(),
            next_var: self.next_var,
            proof: self.proof.clone(),
        }
    }

    /// `self.fork().unify(a, b)` with a caller's reusable binding buffer,
    /// but a failed unification copies nothing: generators try many
    /// candidates against one state, and most fail.
    #[inline]
    pub(crate) fn unified_buf(
        &mut self,
        a: &Term,
        b: &Term,
        occurs_check: bool,
        buf: &mut Vec<(Var, Term)>,
    ) -> Option<State> {
        if !self.pending_into(a, b, occurs_check, buf) {
            return None;
        }
        self.fork().extended(buf, occurs_check)
    }

    /// Commits the bindings of a successful unification and re-checks the
    /// constraints they touch.
    #[inline]
    pub(crate) fn extended(mut self, pending: &[(Var, Term)], occurs_check: bool) -> Option<State> {
        if pending.is_empty() {
            return Some(self);
        }
        self.subst.commit(pending);
        if self.store.is_empty() {
            Some(self)
        } else {
            self.recheck(pending, occurs_check)
        }
    }

    /// Re-posts the constraints of the variables just bound (listed in `log`).
    fn recheck(mut self, log: &[(Var, Term)], occurs_check: bool) -> Option<State> {
        for (v, _) in log {
            if let Some(attr) = self.store.remove(&v.0) {
                for d in &attr.neqs {
                    self = self.post_diseq(&d.pairs, occurs_check)?;
                }
                if let Some(ty) = attr.ty {
                    self = self.post_type(&Term::Var(*v), ty)?;
                }
                for tag in &attr.absent {
                    self = self.post_absent(tag, &Term::Var(*v), occurs_check)?;
                }
            }
        }
        Some(self)
    }

    /// Adds `a ≠ b`.
    pub fn neq(self, a: &Term, b: &Term, occurs_check: bool) -> Option<State> {
        self.post_neq_terms(a, b, occurs_check)
    }

    fn post_neq_terms(self, a: &Term, b: &Term, occurs_check: bool) -> Option<State> {
        let mut scratch = self.subst.clone();
        let mut log = Vec::new();
        if !scratch.unify(a, b, occurs_check, &mut Some(&mut log)) {
            return Some(self); // can never be equal: nothing to remember
        }
        self.store_diseq(log)
    }

    /// Re-checks a disequality given as pairs against the current substitution.
    fn post_diseq(self, pairs: &[(Var, Term)], occurs_check: bool) -> Option<State> {
        if pairs.is_empty() {
            return Some(self);
        }
        let mut scratch = self.subst.clone();
        let mut log = Vec::new();
        for (x, t) in pairs {
            if !scratch.unify(&Term::Var(*x), t, occurs_check, &mut Some(&mut log)) {
                return Some(self); // discharged for good
            }
        }
        self.store_diseq(log)
    }

    fn store_diseq(mut self, log: Vec<(Var, Term)>) -> Option<State> {
        let Some((x0, t0)) = log.first() else {
            return None; // the two sides are already equal: violated
        };
        // The first pair can only come to hold when x0 is bound, or when t0 (if
        // it is a variable) is bound towards x0: watching those two suffices.
        let watch_t0 = t0.as_var();
        let x0 = *x0;
        let d = Arc::new(Diseq { pairs: log });
        self.attr_mut(x0).neqs.push(d.clone());
        if let Some(y) = watch_t0 {
            self.attr_mut(y).neqs.push(d);
        }
        Some(self)
    }

    fn attr_mut(&mut self, v: Var) -> &mut Attr {
        self.store.entry(v.0).or_default()
    }

    /// Restricts `t` to the type `ty`.
    pub fn post_type(mut self, t: &Term, ty: TypeTag) -> Option<State> {
        match self.subst.walk(t) {
            Term::Var(v) => {
                let v = *v;
                let attr = self.attr_mut(v);
                match attr.ty {
                    None => {
                        attr.ty = Some(ty);
                        Some(self)
                    }
                    Some(t0) if t0 == ty => Some(self),
                    Some(_) => None,
                }
            }
            other => ty.admits(other).then_some(self),
        }
    }

    /// Requires that the ground term `tag` occurs nowhere in `t`.
    pub fn post_absent(mut self, tag: &Term, t: &Term, occurs_check: bool) -> Option<State> {
        match self.subst.walk(t).clone() {
            Term::Var(v) => {
                let attr = self.attr_mut(v);
                if !attr.absent.contains(tag) {
                    attr.absent.push(tag.clone());
                }
                Some(self)
            }
            cell @ Term::Cons(..) => {
                if !tag.is_atomic() {
                    self = self.post_neq_terms(&cell, tag, occurs_check)?;
                }
                let Some((head, tail)) = cell.uncons() else {
                    return Some(self);
                };
                self = self.post_absent(tag, head, occurs_check)?;
                self.post_absent(tag, &tail, occurs_check)
            }
            Term::App(f, args) => {
                if !tag.is_atomic() {
                    self = self.post_neq_terms(&Term::App(f, args.clone()), tag, occurs_check)?;
                }
                for a in args.iter() {
                    self = self.post_absent(tag, a, occurs_check)?;
                }
                Some(self)
            }
            atom => (atom != *tag).then_some(self),
        }
    }

    /// `absento` entry point: checks the tag is ground first.
    pub fn absento(
        self,
        tag: &Term,
        t: &Term,
        occurs_check: bool,
    ) -> Result<Option<State>, RunError> {
        let tag = self.subst.walk_star(tag);
        if !tag.is_ground() {
            return Err(RunError::NonGroundAbsento {
                tag: tag.to_string(),
            });
        }
        Ok(self.post_absent(&tag, t, occurs_check))
    }
}
