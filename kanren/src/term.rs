//! Terms: interned symbols, logic variables, atoms and compound terms.
//!
//! A [`Term`] is an immutable tree; compound parts sit behind an [`Arc`], so a
//! clone is a tag copy plus at most one reference-count increment. Variables
//! are plain `u32` indexes ([`Var`]) whose bindings live in the substitution of
//! a search state, never in the term itself: this is what lets every branch of
//! a search share terms freely.

use std::collections::HashMap;
use std::fmt;
use std::sync::{Arc, OnceLock, RwLock};

/// An interned symbol.
///
/// Invariant: the `u32` is an index into the global, append-only interner, so
/// two `Sym`s are equal exactly when their strings are equal, comparison and
/// hashing are integer operations, and [`Sym::as_str`] can hand out a
/// `&'static str` (interned strings are never freed).
///
/// `Ord` orders by interning order, not alphabetically: it is stable within a
/// process, which is what maps and sets need; sort by [`Sym::as_str`] for
/// output that must not depend on the order symbols were first seen.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Sym(u32);

struct Interner {
    ids: HashMap<&'static str, u32>,
    names: Vec<&'static str>,
}

fn interner() -> &'static RwLock<Interner> {
    static INTERNER: OnceLock<RwLock<Interner>> = OnceLock::new();
    INTERNER.get_or_init(|| {
        RwLock::new(Interner {
            ids: HashMap::new(),
            names: Vec::new(),
        })
    })
}

impl Sym {
    /// Interns `s` (thread-safe) and returns its symbol.
    pub fn new(s: &str) -> Sym {
        // A poisoned lock only means another thread panicked mid-insert; the
        // map and vector are updated together after allocation, so the data is
        // still consistent and we keep going with it.
        {
            let r = interner().read().unwrap_or_else(|e| e.into_inner());
            if let Some(&id) = r.ids.get(s) {
                return Sym(id);
            }
        }
        let mut w = interner().write().unwrap_or_else(|e| e.into_inner());
        if let Some(&id) = w.ids.get(s) {
            return Sym(id);
        }
        let id = u32::try_from(w.names.len()).unwrap_or(u32::MAX);
        let leaked: &'static str = Box::leak(s.to_owned().into_boxed_str());
        w.names.push(leaked);
        w.ids.insert(leaked, id);
        Sym(id)
    }

    /// The symbol's text.
    pub fn as_str(&self) -> &'static str {
        let r = interner().read().unwrap_or_else(|e| e.into_inner());
        r.names.get(self.0 as usize).copied().unwrap_or("")
    }

    /// The interning index (stable within one process only).
    pub fn index(&self) -> u32 {
        self.0
    }
}

impl From<&str> for Sym {
    fn from(s: &str) -> Sym {
        Sym::new(s)
    }
}

impl From<&String> for Sym {
    fn from(s: &String) -> Sym {
        Sym::new(s)
    }
}

impl fmt::Debug for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}", self.as_str())
    }
}

impl fmt::Display for Sym {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.as_str())
    }
}

/// A logic variable: an index into the substitution of a search state.
///
/// Invariant: variables are numbered densely per query — the query's own
/// variables first ([`crate::Query::var`]), then every `fresh` variable in the
/// order the search creates it. A `Var` therefore only means something inside
/// the query (or the answer) it came from. In a reified [`crate::Answer`],
/// `Var(i)` is the i-th distinct unbound variable, displayed `_i`.
#[derive(Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Var(pub(crate) u32);

impl Var {
    /// The variable's index.
    pub fn index(&self) -> u32 {
        self.0
    }

    /// The variable with index `i` (useful to build expected reified answers).
    pub fn from_index(i: u32) -> Var {
        Var(i)
    }
}

impl fmt::Debug for Var {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "_{}", self.0)
    }
}

impl fmt::Display for Var {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "_{}", self.0)
    }
}

/// A term.
///
/// Atoms are `Sym`, `Int`, `Str` and `Nil` (the empty list). Compound terms are
/// `Cons` (a list cell, Prolog's `'[|]'(H, T)`) and `App` (a functor applied to
/// at least one argument, like `h(red, english, _, _, _)`). Two compound terms
/// unify when they have the same shape and their parts unify; `App(f, [])` is
/// never built by [`Term::app`] (that gives `Sym(f)`), so every term has one
/// canonical form and structural equality is term identity.
#[derive(Clone, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum Term {
    /// A logic variable.
    Var(Var),
    /// An interned symbol (a Prolog atom).
    Sym(Sym),
    /// An integer.
    Int(i64),
    /// A string.
    Str(Arc<str>),
    /// The empty list.
    Nil,
    /// A list cell: head and tail.
    Cons(Arc<(Term, Term)>),
    /// A compound term `functor(args…)` with at least one argument.
    App(Sym, Arc<[Term]>),
}

/// `Term::Sym(Sym::new(s))`.
pub fn sym(s: &str) -> Term {
    Term::Sym(Sym::new(s))
}

impl Term {
    /// A list cell `[head | tail]`.
    pub fn cons(head: impl Into<Term>, tail: impl Into<Term>) -> Term {
        Term::Cons(Arc::new((head.into(), tail.into())))
    }

    /// The proper list of `items`.
    pub fn list<T: Into<Term>>(items: impl IntoIterator<Item = T>) -> Term {
        Term::list_with_tail(items, Term::Nil)
    }

    /// The list of `items` ending in `tail` (`[a, b | T]`).
    pub fn list_with_tail<T: Into<Term>>(items: impl IntoIterator<Item = T>, tail: Term) -> Term {
        let items: Vec<Term> = items.into_iter().map(Into::into).collect();
        items
            .into_iter()
            .rev()
            .fold(tail, |acc, t| Term::Cons(Arc::new((t, acc))))
    }

    /// The compound term `functor(args…)`; with no arguments, the symbol itself.
    pub fn app(functor: impl Into<Sym>, args: impl IntoIterator<Item = Term>) -> Term {
        let args: Vec<Term> = args.into_iter().collect();
        let f = functor.into();
        if args.is_empty() {
            Term::Sym(f)
        } else {
            Term::App(f, args.into())
        }
    }

    /// A string term.
    pub fn str(s: &str) -> Term {
        Term::Str(Arc::from(s))
    }

    /// True when the term contains no variable.
    pub fn is_ground(&self) -> bool {
        match self {
            Term::Var(_) => false,
            Term::Sym(_) | Term::Int(_) | Term::Str(_) | Term::Nil => true,
            Term::Cons(c) => c.0.is_ground() && c.1.is_ground(),
            Term::App(_, args) => args.iter().all(Term::is_ground),
        }
    }

    /// True for atoms: symbols, integers, strings and the empty list.
    pub fn is_atomic(&self) -> bool {
        matches!(self, Term::Sym(_) | Term::Int(_) | Term::Str(_) | Term::Nil)
    }

    /// The symbol, when the term is one.
    pub fn as_sym(&self) -> Option<Sym> {
        match self {
            Term::Sym(s) => Some(*s),
            _ => None,
        }
    }

    /// The variable, when the term is one.
    pub fn as_var(&self) -> Option<Var> {
        match self {
            Term::Var(v) => Some(*v),
            _ => None,
        }
    }

    /// The integer, when the term is one.
    pub fn as_int(&self) -> Option<i64> {
        match self {
            Term::Int(i) => Some(*i),
            _ => None,
        }
    }

    /// The string, when the term is one.
    pub fn as_str(&self) -> Option<&str> {
        match self {
            Term::Str(s) => Some(s),
            _ => None,
        }
    }

    /// The elements of a proper list, or `None` for anything else.
    pub fn to_vec(&self) -> Option<Vec<Term>> {
        let mut out = Vec::new();
        let mut t = self;
        loop {
            match t {
                Term::Nil => return Some(out),
                Term::Cons(c) => {
                    out.push(c.0.clone());
                    t = &c.1;
                }
                _ => return None,
            }
        }
    }

    /// The term with each variable `v` replaced by `f(v)` (`Ok(None)` from
    /// `f`: keep `v`). Returns `Ok(None)` when nothing changed, so unchanged
    /// subterms stay shared; list spines are walked iteratively.
    pub fn try_map_vars<E>(
        &self,
        f: &mut impl FnMut(Var) -> Result<Option<Term>, E>,
    ) -> Result<Option<Term>, E> {
        match self {
            Term::Var(v) => f(*v),
            Term::App(g, args) => {
                let mut out: Option<Vec<Term>> = None;
                for (i, a) in args.iter().enumerate() {
                    match (a.try_map_vars(f)?, &mut out) {
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
                Ok(out.map(|v| Term::App(*g, v.into())))
            }
            Term::Cons(_) => {
                // Each cell with its mapped head (`None`: unchanged).
                type Cell<'a> = (&'a Arc<(Term, Term)>, Option<Term>);
                let mut spine: Vec<Cell<'_>> = Vec::new();
                let mut cur = self;
                while let Term::Cons(c) = cur {
                    spine.push((c, c.0.try_map_vars(f)?));
                    cur = &c.1;
                }
                let mut acc = cur.try_map_vars(f)?;
                for (c, head) in spine.into_iter().rev() {
                    if head.is_none() && acc.is_none() {
                        continue;
                    }
                    let tail = acc.take().unwrap_or_else(|| c.1.clone());
                    let head = head.unwrap_or_else(|| c.0.clone());
                    acc = Some(Term::Cons(Arc::new((head, tail))));
                }
                Ok(acc)
            }
            _ => Ok(None),
        }
    }

    /// Calls `f` on every variable of the term, left to right.
    pub fn for_each_var(&self, f: &mut impl FnMut(Var)) {
        match self {
            Term::Var(v) => f(*v),
            Term::Cons(_) => {
                let mut cur = self;
                while let Term::Cons(c) = cur {
                    c.0.for_each_var(f);
                    cur = &c.1;
                }
                cur.for_each_var(f);
            }
            Term::App(_, args) => args.iter().for_each(|a| a.for_each_var(f)),
            _ => {}
        }
    }
}

impl From<Sym> for Term {
    fn from(s: Sym) -> Term {
        Term::Sym(s)
    }
}
impl From<i64> for Term {
    fn from(i: i64) -> Term {
        Term::Int(i)
    }
}
impl From<i32> for Term {
    fn from(i: i32) -> Term {
        Term::Int(i64::from(i))
    }
}
impl From<Var> for Term {
    fn from(v: Var) -> Term {
        Term::Var(v)
    }
}
impl From<&Term> for Term {
    fn from(t: &Term) -> Term {
        t.clone()
    }
}
impl From<&str> for Term {
    /// A `&str` becomes a *symbol* (the common case in relational code);
    /// use [`Term::str`] for a string term.
    fn from(s: &str) -> Term {
        sym(s)
    }
}
impl From<Vec<Term>> for Term {
    fn from(v: Vec<Term>) -> Term {
        Term::list(v)
    }
}

fn sym_needs_quotes(s: &str) -> bool {
    let mut chars = s.chars();
    match chars.next() {
        None => true,
        Some(c) if c.is_alphabetic() || c == '_' => {
            !s.chars().all(|c| c.is_alphanumeric() || c == '_')
        }
        Some(_) => true,
    }
}

impl fmt::Display for Term {
    /// Prolog-like syntax: `sym`, `42`, `"str"`, `_0`, `[a, b | _1]`, `f(a, b)`.
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Term::Var(v) => write!(f, "{v}"),
            Term::Sym(s) => {
                if sym_needs_quotes(s.as_str()) {
                    write!(f, "'{}'", s.as_str().replace('\'', "\\'"))
                } else {
                    f.write_str(s.as_str())
                }
            }
            Term::Int(i) => write!(f, "{i}"),
            Term::Str(s) => write!(f, "{:?}", &**s),
            Term::Nil => f.write_str("[]"),
            Term::Cons(c) => {
                write!(f, "[{}", c.0)?;
                let mut t = &c.1;
                loop {
                    match t {
                        Term::Nil => break,
                        Term::Cons(c) => {
                            write!(f, ", {}", c.0)?;
                            t = &c.1;
                        }
                        other => {
                            write!(f, " | {other}")?;
                            break;
                        }
                    }
                }
                f.write_str("]")
            }
            Term::App(fun, args) => {
                write!(f, "{}(", Term::Sym(*fun))?;
                for (i, a) in args.iter().enumerate() {
                    if i > 0 {
                        f.write_str(", ")?;
                    }
                    write!(f, "{a}")?;
                }
                f.write_str(")")
            }
        }
    }
}

impl fmt::Debug for Term {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        fmt::Display::fmt(self, f)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn interning_is_stable_and_shared_across_threads() {
        let a = Sym::new("kanren_test_sym");
        let b = std::thread::spawn(|| Sym::new("kanren_test_sym"))
            .join()
            .map_err(|_| "thread panicked");
        assert_eq!(Ok(a), b);
        assert_eq!(a.as_str(), "kanren_test_sym");
        assert_ne!(Sym::new("x1"), Sym::new("x2"));
    }

    #[test]
    fn display_is_prolog_like() {
        let t = Term::list_with_tail([sym("a"), Term::Int(2)], Term::Var(Var(3)));
        assert_eq!(t.to_string(), "[a, 2 | _3]");
        let h = Term::app("h", [sym("red"), Term::str("x y"), Term::Nil]);
        assert_eq!(h.to_string(), "h(red, \"x y\", [])");
        assert_eq!(sym("Hello World").to_string(), "'Hello World'");
        assert_eq!(Term::app("f", []), sym("f"));
    }

    #[test]
    fn groundness() {
        assert!(Term::list([1i64, 2]).is_ground());
        assert!(!Term::cons(1i64, Var(0)).is_ground());
        assert_eq!(
            Term::list([1i64, 2]).to_vec(),
            Some(vec![Term::Int(1), Term::Int(2)])
        );
    }
}
