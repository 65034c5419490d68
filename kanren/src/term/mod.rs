//! Terms: interned symbols, logic variables, atoms and compound terms.
//!
//! A [`Term`] is an immutable tree; compound parts sit behind an [`Arc`], so a
//! clone is a tag copy plus at most one reference-count increment. Variables
//! are plain `u32` indexes ([`Var`]) whose bindings live in the substitution of
//! a search state, never in the term itself: this is what lets every branch of
//! a search share terms freely.

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

/// The string → id map, written under its lock when a new symbol comes.
struct Interner {
    /// FxHash: every fact read and every proof's provenance lookup hashes
    /// a name here, and SipHash was most of that cost.
    ids: rustc_hash::FxHashMap<&'static str, u32>,
    len: usize,
}

fn interner() -> &'static RwLock<Interner> {
    static INTERNER: OnceLock<RwLock<Interner>> = OnceLock::new();
    INTERNER.get_or_init(|| {
        RwLock::new(Interner {
            ids: rustc_hash::FxHashMap::default(),
            len: 0,
        })
    })
}

/// The id → string table, read without a lock: chunk `k` holds
/// `NAMES_BASE << k` slots, for ids from `NAMES_BASE * (2^k - 1)` on, so
/// chunks never move once made and a slot is written once, before its id is
/// handed out. [`Sym::as_str`] is called for every fact printed and every
/// proof rendered; a read lock there was a shared counter every thread
/// bounced on.
const NAMES_BASE: usize = 1024;
/// Enough chunks for every `u32` id: `NAMES_BASE * (2^23 - 1) > 2^32`.
const NAMES_CHUNKS: usize = 23;

type NameChunk = Box<[OnceLock<&'static str>]>;

static NAMES: [OnceLock<NameChunk>; NAMES_CHUNKS] = [const { OnceLock::new() }; NAMES_CHUNKS];

/// The chunk and the slot of an id.
fn name_slot(id: usize) -> (usize, usize) {
    let blocks = id / NAMES_BASE + 1;
    let chunk = (usize::BITS - 1 - blocks.leading_zeros()) as usize;
    (chunk, id - NAMES_BASE * ((1usize << chunk) - 1))
}

thread_local! {
    /// The names this thread has found in the interner, with their ids:
    /// a query's constants are looked up on every window it is asked of,
    /// and the interner's read lock is one word that every thread's
    /// lookups bounced between the cores. Symbols are never removed, so an
    /// entry stays true; the copy stops growing at [`LOCAL_NAMES_MAX`].
    static LOCAL_NAMES: std::cell::RefCell<rustc_hash::FxHashMap<&'static str, u32>> =
        std::cell::RefCell::new(rustc_hash::FxHashMap::default());
}

/// How many names one thread keeps a copy of (a long-running server's
/// threads must not each copy an ever-growing table).
const LOCAL_NAMES_MAX: usize = 1 << 16;

/// The id of `s` from this thread's copy, when it has one.
fn local_id(s: &str) -> Option<u32> {
    LOCAL_NAMES
        .try_with(|m| m.try_borrow().ok().and_then(|m| m.get(s).copied()))
        .ok()
        .flatten()
}

/// Records that `id` names `name` (the interned text) in this thread's
/// copy.
fn remember(name: &'static str, id: u32) {
    let _ = LOCAL_NAMES.try_with(|m| {
        if let Ok(mut m) = m.try_borrow_mut()
            && m.len() < LOCAL_NAMES_MAX
        {
            m.insert(name, id);
        }
    });
}

impl Sym {
    /// Interns `s` (thread-safe) and returns its symbol.
    pub fn new(s: &str) -> Sym {
        if let Some(id) = local_id(s) {
            return Sym(id);
        }
        // A poisoned lock only means another thread panicked mid-insert; the
        // slot is written before the map entry, so the data is still
        // consistent and we keep going with it.
        {
            let r = interner().read().unwrap_or_else(|e| e.into_inner());
            if let Some((&name, &id)) = r.ids.get_key_value(s) {
                drop(r);
                remember(name, id);
                return Sym(id);
            }
        }
        let mut w = interner().write().unwrap_or_else(|e| e.into_inner());
        if let Some(&id) = w.ids.get(s) {
            return Sym(id);
        }
        let id = w.len;
        let leaked: &'static str = Box::leak(s.to_owned().into_boxed_str());
        let (chunk, slot) = name_slot(id);
        if let Some(cell) = NAMES.get(chunk) {
            let slots = cell.get_or_init(|| {
                (0..NAMES_BASE << chunk)
                    .map(|_| OnceLock::new())
                    .collect::<Vec<_>>()
                    .into_boxed_slice()
            });
            if let Some(cell) = slots.get(slot) {
                let _ = cell.set(leaked);
            }
        }
        let id32 = u32::try_from(id).unwrap_or(u32::MAX);
        w.len += 1;
        w.ids.insert(leaked, id32);
        drop(w);
        remember(leaked, id32);
        Sym(id32)
    }

    /// The symbol of `s` if it is interned, without interning it. The table
    /// is append-only, so text that only looks things up — a query sent to
    /// a long-running server — must not grow it: a constant that was never
    /// interned names nothing any fact holds.
    pub fn lookup(s: &str) -> Option<Sym> {
        if let Some(id) = local_id(s) {
            return Some(Sym(id));
        }
        let found = {
            let r = interner().read().unwrap_or_else(|e| e.into_inner());
            r.ids.get_key_value(s).map(|(&name, &id)| (name, id))
        };
        found.map(|(name, id)| {
            remember(name, id);
            Sym(id)
        })
    }

    /// The symbol's text, without taking a lock.
    pub fn as_str(&self) -> &'static str {
        let (chunk, slot) = name_slot(self.0 as usize);
        NAMES
            .get(chunk)
            .and_then(OnceLock::get)
            .and_then(|slots| slots.get(slot))
            .and_then(OnceLock::get)
            .copied()
            .unwrap_or("")
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
/// never built by [`Term::app`] (that gives `Sym(f)`).
///
/// Lists are stored *packed*: `Cons(block, pos)` is the cell whose head is
/// `block[pos]` and whose tail is the cell at `pos + 1` of the same block, or,
/// for the last cell of the block, the block's final element. Both fields are
/// opaque ([`ListBlock`], [`ListPos`]): only this crate makes them, and every
/// pairing of the two is a well-formed list, so code outside the crate can
/// take lists apart and put the pieces back together, but never build a
/// malformed one. `[1, 2, 3]` is one allocation, a suffix of it is the same block at a later position (no
/// allocation), and `walk*` builds a resolved list in one allocation instead
/// of one per cell. A list may span several blocks (`Term::cons` onto a list
/// makes a one-cell block whose tail is that list); equality, ordering and
/// hashing look at the cells, never at how they are split into blocks, so
/// they are exactly those of the textbook cell-by-cell representation. Build
/// lists with [`Term::cons`], [`Term::list`] and [`Term::list_with_tail`];
/// take them apart with [`Term::uncons`] or [`Term::to_vec`].
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
    /// A list cell: the cell at `ListPos` of a packed block (see above).
    Cons(ListBlock, ListPos),
    /// A compound term `functor(args…)` with at least one argument.
    App(Sym, Arc<[Term]>),
}

impl Clone for Term {
    /// As derived, but inlined: terms are cloned in the tightest loops
    /// (trie nodes copied on write, pending bindings), where a call per
    /// clone showed in profiles.
    #[inline(always)]
    fn clone(&self) -> Term {
        match self {
            Term::Var(v) => Term::Var(*v),
            Term::Sym(s) => Term::Sym(*s),
            Term::Int(i) => Term::Int(*i),
            Term::Str(s) => Term::Str(s.clone()),
            Term::Nil => Term::Nil,
            Term::Cons(block, pos) => Term::Cons(block.clone(), *pos),
            Term::App(f, args) => Term::App(*f, args.clone()),
        }
    }
}

/// The packed block of a list cell (see [`Term`]): the heads of one or more
/// cells, then the tail of the last of them.
///
/// Invariant: at least two slots (one cell and its tail). The field is
/// private and only this module makes blocks, so code outside the crate
/// cannot hand `Term::Cons` an empty or one-slot block (it used to be a bare
/// `Arc<[Term]>`, and an empty one made `unify` panic):
///
/// ```compile_fail
/// use kanren::term::{ListBlock, Term};
/// use std::sync::Arc;
/// let empty: Arc<[Term]> = Arc::from(Vec::new());
/// let _ = ListBlock(empty); // error: the field is private
/// ```
///
/// Why two opaque fields rather than one struct holding block and position:
/// such a struct has four bytes of padding that the enum cannot put its tag
/// in, so `Term` would grow from 24 to 32 bytes; as two fields, the tag and
/// the position share the word next to the block, as before.
#[derive(Clone)]
pub struct ListBlock(Arc<[Term]>);

impl ListBlock {
    /// The block's slots: the cells' heads, then the tail (at least two).
    #[inline(always)]
    pub(crate) fn slots(&self) -> &[Term] {
        &self.0
    }

    /// The index of the block's tail: its last slot (at least 1, by the
    /// invariant, so the subtraction cannot overflow).
    #[inline(always)]
    pub(crate) fn tail_index(&self) -> usize {
        self.0.len() - 1
    }

    /// The index of the block's last cell, for a position beyond it. Out of
    /// line: this module never makes such a position, only a `ListPos` moved
    /// from one list to another outside the crate does.
    #[cold]
    #[inline(never)]
    fn last_cell(&self) -> usize {
        self.0.len().saturating_sub(2)
    }

    /// Whether `self` and `other` are the same allocation.
    #[inline(always)]
    pub(crate) fn ptr_eq(&self, other: &ListBlock) -> bool {
        Arc::ptr_eq(&self.0, &other.0)
    }
}

impl fmt::Debug for ListBlock {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_list().entries(self.0.iter()).finish()
    }
}

/// The position of a list cell in its packed block (see [`Term`]).
///
/// The position that counts is `ListPos::index`, which is clamped to the
/// block's last cell: a `ListPos` taken from one list and paired with the
/// block of another (both fields of `Term::Cons` are public to match on)
/// still names a cell of that block, so every `Cons` is a well-formed list.
/// This module only makes positions of cells (`pos < block.len() - 1`), for
/// which the clamp changes nothing.
#[derive(Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord, Debug)]
pub struct ListPos(u32);

impl ListPos {
    /// The index of the cell's head in `block`: the stored position, or the
    /// block's last cell if the position lies beyond it.
    #[inline(always)]
    pub(crate) fn index(self, block: &ListBlock) -> usize {
        let i = self.0 as usize;
        if i < block.tail_index() {
            i
        } else {
            block.last_cell()
        }
    }

    /// The next cell's position; the caller checks it is still a cell (so
    /// the position was in its block, and cannot be `u32::MAX`).
    pub(crate) fn step(&mut self) {
        self.0 += 1;
    }

    /// The position `i`; the caller checks it is a cell of its block.
    pub(crate) fn at(i: usize) -> ListPos {
        ListPos(u32::try_from(i).unwrap_or(u32::MAX))
    }
}

/// `Term::Sym(Sym::new(s))`.
pub fn sym(s: &str) -> Term {
    Term::Sym(Sym::new(s))
}

impl Term {
    /// A list cell `[head | tail]`.
    pub fn cons(head: impl Into<Term>, tail: impl Into<Term>) -> Term {
        Term::Cons(ListBlock(Arc::from([head.into(), tail.into()])), ListPos(0))
    }

    /// The proper list of `items`.
    pub fn list<T: Into<Term>>(items: impl IntoIterator<Item = T>) -> Term {
        Term::list_with_tail(items, Term::Nil)
    }

    /// The list of `items` ending in `tail` (`[a, b | T]`).
    pub fn list_with_tail<T: Into<Term>>(items: impl IntoIterator<Item = T>, tail: Term) -> Term {
        let mut items: Vec<Term> = items.into_iter().map(Into::into).collect();
        if items.is_empty() {
            return tail;
        }
        items.push(tail);
        Term::packed(items.into())
    }

    /// The list whose cells are `block[..len - 1]` and whose tail is
    /// `block[len - 1]`; just that tail when there is no cell.
    pub(crate) fn packed(block: Arc<[Term]>) -> Term {
        match block.len() {
            0 => Term::Nil,
            1 => block.first().cloned().unwrap_or(Term::Nil),
            _ => Term::Cons(ListBlock(block), ListPos(0)),
        }
    }

    /// For a list cell: the heads of the cells from this one to the end of
    /// its block (never empty), and the block's tail.
    #[inline(always)]
    pub(crate) fn cells(&self) -> Option<(&[Term], &Term)> {
        match self {
            Term::Cons(block, pos) => {
                let slots = block.slots();
                // A one-cell block (every list built by `cons`) has one
                // position, whatever `pos` says.
                if let [head, tail] = slots {
                    return Some((std::slice::from_ref(head), tail));
                }
                let (tail, items) = slots.split_last()?;
                let items = items.get(pos.index(block)..)?;
                Some((items, tail))
            }
            _ => None,
        }
    }

    /// The rest of the list from slot `pos` of `block`: the cell there, or
    /// the block's tail when `pos` is past its last cell.
    pub(crate) fn skip_cells(block: &ListBlock, pos: usize) -> Term {
        if pos + 1 < block.slots().len() {
            Term::Cons(
                block.clone(),
                ListPos(u32::try_from(pos).unwrap_or(u32::MAX)),
            )
        } else {
            block.slots().last().cloned().unwrap_or(Term::Nil)
        }
    }

    /// A list cell's head and tail; `None` for anything else.
    pub fn uncons(&self) -> Option<(&Term, Term)> {
        match self {
            Term::Cons(block, pos) => {
                let i = pos.index(block);
                let head = block.slots().get(i)?;
                Some((head, Term::skip_cells(block, i + 1)))
            }
            _ => None,
        }
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
            Term::Cons(..) => {
                let mut t = self;
                while let Some((items, tail)) = t.cells() {
                    if !items.iter().all(Term::is_ground) {
                        return false;
                    }
                    t = tail;
                }
                t.is_ground()
            }
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
        while let Some((items, tail)) = t.cells() {
            out.extend(items.iter().cloned());
            t = tail;
        }
        matches!(t, Term::Nil).then_some(out)
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
            Term::Cons(..) => {
                // The mapped heads, and the first one that changed; a
                // changed list is rebuilt as one packed block.
                let mut heads: Vec<Option<Term>> = Vec::new();
                let mut changed = false;
                let mut cur = self;
                while let Some((items, tail)) = cur.cells() {
                    for h in items {
                        let n = h.try_map_vars(f)?;
                        changed |= n.is_some();
                        heads.push(n);
                    }
                    cur = tail;
                }
                let tail = cur.try_map_vars(f)?;
                if !changed && tail.is_none() {
                    return Ok(None);
                }
                let mut block: Vec<Term> = Vec::with_capacity(heads.len() + 1);
                let mut cur = self;
                let mut mapped = heads.into_iter();
                while let Some((items, next)) = cur.cells() {
                    for h in items {
                        block.push(mapped.next().flatten().unwrap_or_else(|| h.clone()));
                    }
                    cur = next;
                }
                block.push(tail.unwrap_or_else(|| cur.clone()));
                Ok(Some(Term::packed(block.into())))
            }
            _ => Ok(None),
        }
    }

    /// Calls `f` on every variable of the term, left to right.
    pub fn for_each_var(&self, f: &mut impl FnMut(Var)) {
        match self {
            Term::Var(v) => f(*v),
            Term::Cons(..) => {
                let mut cur = self;
                while let Some((items, tail)) = cur.cells() {
                    items.iter().for_each(|h| h.for_each_var(f));
                    cur = tail;
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

/// [`Term::rank`] of a list cell.
const CONS_RANK: u8 = 5;

impl Term {
    /// The variant's rank in declaration order: `Ord` sorts by it first.
    fn rank(&self) -> u8 {
        match self {
            Term::Var(_) => 0,
            Term::Sym(_) => 1,
            Term::Int(_) => 2,
            Term::Str(_) => 3,
            Term::Nil => 4,
            Term::Cons(..) => CONS_RANK,
            Term::App(..) => 6,
        }
    }
}

/// The heads of a list's cells across its blocks, with no substitution
/// lookups; once it is exhausted, `tail` is the list's final non-cell tail.
struct Cells<'a> {
    items: &'a [Term],
    tail: &'a Term,
}

impl<'a> Cells<'a> {
    fn new(t: &'a Term) -> Cells<'a> {
        Cells {
            items: &[],
            tail: t,
        }
    }

    #[inline]
    fn next(&mut self) -> Option<&'a Term> {
        loop {
            if let Some((h, rest)) = self.items.split_first() {
                self.items = rest;
                return Some(h);
            }
            let (items, tail) = self.tail.cells()?;
            self.items = items;
            self.tail = tail;
        }
    }
}

/// Equality, ordering and hashing are those of the cell-by-cell
/// representation: lists compare cell by cell (iteratively along the
/// spine), whatever blocks hold them; other variants compare as derived.
impl PartialEq for Term {
    fn eq(&self, other: &Term) -> bool {
        match (self, other) {
            (Term::Var(a), Term::Var(b)) => a == b,
            (Term::Sym(a), Term::Sym(b)) => a == b,
            (Term::Int(a), Term::Int(b)) => a == b,
            (Term::Str(a), Term::Str(b)) => a == b,
            (Term::Nil, Term::Nil) => true,
            (Term::App(f, xs), Term::App(g, ys)) => f == g && (Arc::ptr_eq(xs, ys) || xs == ys),
            (Term::Cons(b1, p1), Term::Cons(b2, p2)) => {
                if b1.ptr_eq(b2) && p1 == p2 {
                    return true;
                }
                let (mut x, mut y) = (Cells::new(self), Cells::new(other));
                loop {
                    match (x.next(), y.next()) {
                        (Some(h1), Some(h2)) => {
                            if h1 != h2 {
                                return false;
                            }
                        }
                        (None, None) => return x.tail == y.tail,
                        _ => return false,
                    }
                }
            }
            _ => false,
        }
    }
}

impl Eq for Term {}

impl Ord for Term {
    fn cmp(&self, other: &Term) -> std::cmp::Ordering {
        use std::cmp::Ordering;
        match (self, other) {
            (Term::Var(a), Term::Var(b)) => a.cmp(b),
            (Term::Sym(a), Term::Sym(b)) => a.cmp(b),
            (Term::Int(a), Term::Int(b)) => a.cmp(b),
            (Term::Str(a), Term::Str(b)) => a.cmp(b),
            (Term::Nil, Term::Nil) => Ordering::Equal,
            (Term::App(f, xs), Term::App(g, ys)) => f.cmp(g).then_with(|| xs.cmp(ys)),
            (Term::Cons(b1, p1), Term::Cons(b2, p2)) => {
                if b1.ptr_eq(b2) && p1 == p2 {
                    return Ordering::Equal;
                }
                let (mut x, mut y) = (Cells::new(self), Cells::new(other));
                loop {
                    match (x.next(), y.next()) {
                        (Some(h1), Some(h2)) => match h1.cmp(h2) {
                            Ordering::Equal => {}
                            o => return o,
                        },
                        (None, None) => return x.tail.cmp(y.tail),
                        // One spine ends where the other has a cell: the
                        // non-cell tail against a cell, by variant rank.
                        (None, Some(_)) => return x.tail.rank().cmp(&CONS_RANK),
                        (Some(_), None) => return CONS_RANK.cmp(&y.tail.rank()),
                    }
                }
            }
            (a, b) => a.rank().cmp(&b.rank()),
        }
    }
}

impl PartialOrd for Term {
    fn partial_cmp(&self, other: &Term) -> Option<std::cmp::Ordering> {
        Some(self.cmp(other))
    }
}

impl std::hash::Hash for Term {
    fn hash<H: std::hash::Hasher>(&self, state: &mut H) {
        state.write_u8(self.rank());
        match self {
            Term::Var(v) => v.hash(state),
            Term::Sym(s) => s.hash(state),
            Term::Int(i) => i.hash(state),
            Term::Str(s) => s.hash(state),
            Term::Nil => {}
            Term::App(f, args) => {
                f.hash(state);
                args.hash(state);
            }
            Term::Cons(..) => {
                let mut c = Cells::new(self);
                while let Some(h) = c.next() {
                    h.hash(state);
                }
                c.tail.hash(state);
            }
        }
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
            Term::Cons(..) => {
                f.write_str("[")?;
                let mut first = true;
                let mut t = self;
                while let Some((items, tail)) = t.cells() {
                    for h in items {
                        if !first {
                            f.write_str(", ")?;
                        }
                        first = false;
                        write!(f, "{h}")?;
                    }
                    t = tail;
                }
                if !matches!(t, Term::Nil) {
                    write!(f, " | {t}")?;
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
mod tests;
