//! The candidates of a why-not variable: the window's objects scored by the
//! literals they satisfy, decided from holder sets (cached per window) and
//! per-object checks.

use super::claims::{Bounds, arg_str, bind_var, satisfiable};
use crate::kb::WindowKb;
use logicpad::fol::{Arg, Literal};
use logicpad::{LogicPad, QueryAst};
use std::sync::Arc;

/// Why-not's candidates for variable `v`: whether some object of the
/// window satisfies every identity literal (`identity[i]` says which of
/// `mentions` are), and each candidate that satisfies the identity
/// literals and at least one literal, with how many and which (in
/// `mentions` order), in no particular order. Only the candidates that can
/// score are visited; a test holds the result to the definition (every
/// object, every literal decided by a scan of its relation).
pub(super) fn scores<'k>(
    kb: &'k WindowKb,
    ast: &QueryAst,
    v: usize,
    mentions: &[&Literal],
    identity: &[bool],
    bounds: &Bounds,
) -> (bool, Vec<(usize, &'k str, Holds)>) {
    // Each literal's constants interned once, not once per candidate.
    let consts: Vec<Consts> = mentions.iter().map(|l| literal_consts(l)).collect();
    // Each atom's holders found once, by one probe of its relation,
    // instead of one probe per object: why-not runs for every "no" of
    // a batch, over every object of the window.
    let checks: Vec<Check> = mentions
        .iter()
        .zip(&consts)
        .map(|(l, c)| Check::of(kb, l, c, v))
        .collect();
    // One pass over the objects decides every literal for each: the
    // identity literals pick the candidates, all of them score it.
    // With an identity literal, only its holders can be candidates:
    // the smallest such set is walked instead of every object (a
    // window of a thousand objects has a handful of vans).
    let narrowest = checks
        .iter()
        .zip(identity)
        .filter_map(|(k, &id)| match k {
            Check::Holders(set, false) if id => Some(set),
            _ => None,
        })
        .min_by_key(|set| set.len());
    let candidates: Vec<(&str, kanren::Sym)> = match narrowest {
        // In any order: the ranking below is a total order.
        Some(set) => set
            .iter()
            .filter(|&&s| kb.is_object(s))
            .map(|&s| (s.as_str(), s))
            .collect(),
        // Without one, an object that holds no literal scores nothing
        // and is not shown: when every literal is a positive atom, the
        // union of their holders is every object that can score.
        None if checks.iter().all(|k| matches!(k, Check::Holders(_, false))) => {
            let mut all: Vec<kanren::Sym> = checks
                .iter()
                .flat_map(|k| match k {
                    Check::Holders(set, _) => &set[..],
                    Check::PerObject | Check::NoMatch => &[],
                })
                .copied()
                .collect();
            all.sort_unstable();
            all.dedup();
            all.into_iter()
                .filter(|&s| kb.is_object(s))
                .map(|s| (s.as_str(), s))
                .collect()
        }
        None => kb.objects_with_syms().collect(),
    };
    let mut of_kind = 0usize;
    let mut scored: Vec<(usize, &str, Holds)> = Vec::new();
    for (obj, sym) in candidates {
        let holds: Holds = checks
            .iter()
            .zip(mentions)
            .map(|(k, lit)| k.holds(kb, lit, ast, v, (obj, sym), bounds))
            .collect();
        if holds.iter().zip(identity).any(|(&h, &id)| id && !h) {
            continue;
        }
        of_kind += 1;
        let n = holds.iter().filter(|&&h| h).count();
        if n > 0 {
            scored.push((n, obj, holds));
        }
    }
    (of_kind > 0, scored)
}

/// Whether a literal says what kind of object variable `v` is: its class
/// (a predicate of the `semantic_segmentation` group, or a derived alias
/// of classes such as `IsPerson`) or its `TypeOf`.
pub(super) fn is_identity(pad: &LogicPad, l: &Literal, v: usize) -> bool {
    let Literal::Pos(a) = l else {
        return false;
    };
    let on_v = matches!(a.args.first(), Some(Arg::Var(x)) if *x == v);
    if !on_v {
        return false;
    }
    if a.pred == "TypeOf" {
        return matches!(a.args.get(1), Some(Arg::Const(_)));
    }
    if a.args.len() != 1 {
        return false;
    }
    let is_class = |name: &str| {
        pad.schema()
            .get(name)
            .is_some_and(|p| p.group.as_deref() == Some("semantic_segmentation"))
    };
    if is_class(&a.pred) {
        return true;
    }
    // A derived alias whose every rule rests on classes alone.
    let program = pad.program();
    let Some(pid) = program.pred_id(&a.pred) else {
        return false;
    };
    let rules: Vec<_> = program
        .rules()
        .iter()
        .filter(|r| r.head.pred == pid)
        .collect();
    !rules.is_empty()
        && rules.iter().all(|r| {
            r.negated.is_empty()
                && r.body.iter().all(|b| {
                    program
                        .pred_name(b.pred)
                        .is_some_and(|n| is_class(n) || n == "TypeOf")
                })
        })
}

/// Whether variable `v` is an argument of `l`.
pub(super) fn mentions_var(l: &Literal, v: usize) -> bool {
    let is_v = |a: &Arg| matches!(a, Arg::Var(x) if *x == v);
    match l {
        Literal::Pos(a) | Literal::Neg(a) => a.args.iter().any(is_v),
        Literal::Cmp { left, right, .. } => is_v(left) || is_v(right),
        Literal::NotExists { .. } => l.free_vars().contains(&v),
    }
}

/// Whether one literal holds with variable `v` set to `obj` (other
/// variables existential; a negated literal with other free variables is
/// read as "no binding of them makes the atom hold").
/// A literal's constant arguments as terms, by position (`None` for a
/// variable), for [`literal_holds`].
type Consts = smallvec::SmallVec<[Option<kanren::Term>; 4]>;

/// Which of a why-not variable's literals one candidate satisfies, in
/// literal order (inline up to eight: one allocation less per object).
pub(super) type Holds = smallvec::SmallVec<[bool; 8]>;

fn literal_consts(l: &Literal) -> Consts {
    match l {
        Literal::Pos(a) | Literal::Neg(a) => atom_consts(a),
        Literal::Cmp { .. } | Literal::NotExists { .. } => Consts::new(),
    }
}

/// An atom's constants as terms, `None` at its variables.
pub(super) fn atom_consts(a: &logicpad::fol::Atom) -> Consts {
    a.args
        .iter()
        .map(|x| match x {
            Arg::Const(c) => Some(logicpad::const_term(c)),
            Arg::Var(_) => None,
        })
        .collect()
}

/// How why-not decides a literal for one candidate object.
enum Check {
    /// An atom: the values of the why-not variable that some fact gives it
    /// (the literal's other variables existential), and whether the atom is
    /// negated.
    /// (Sorted and without duplicates, searched by binary search: the
    /// sets are small, and hashing cost more.)
    Holders(Arc<[kanren::Sym]>, bool),
    /// A comparison, decided per object by [`cmp_holds`].
    PerObject,
    /// A `¬∃`, decided per object by asking whether its conjunction has
    /// a match with the object in place.
    NoMatch,
}

/// The holder sets a window's why-not answers have found, by atom shape:
/// the questions of a batch on one window share their literals
/// (`TypeOf(x, Car)`, `Moving(x)`), and each set was found again for every
/// "no" (a probe of the relation, a sort).
///
/// Invariant: the set under a key is what [`Check::of`] finds for an atom
/// of that shape in the window the cache belongs to (the window's model
/// never changes).
#[derive(Debug, Default)]
pub(crate) struct HolderCache(
    std::sync::Mutex<rustc_hash::FxHashMap<HolderKey, Arc<[kanren::Sym]>>>,
);

/// An atom's shape for [`HolderCache`]: its relation, and per argument its
/// constant, the why-not variable, or another (existential) variable.
#[derive(Debug, Clone, PartialEq, Eq, Hash)]
pub(crate) struct HolderKey {
    pred: kanren::Sym,
    args: smallvec::SmallVec<[KeyArg; 4]>,
}

#[derive(Debug, Clone, PartialEq, Eq, Hash)]
enum KeyArg {
    Const(Option<kanren::Term>),
    Target,
    Other,
}

impl HolderCache {
    fn get(&self, key: &HolderKey) -> Option<Arc<[kanren::Sym]>> {
        self.0.lock().ok()?.get(key).cloned()
    }

    fn put(&self, key: HolderKey, set: Arc<[kanren::Sym]>) {
        if let Ok(mut m) = self.0.lock() {
            m.insert(key, set);
        }
    }
}

impl Check {
    fn of(kb: &WindowKb, l: &Literal, consts: &Consts, v: usize) -> Check {
        let (atom, neg) = match l {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => return Check::PerObject,
            Literal::NotExists { .. } => return Check::NoMatch,
        };
        let Some(rel) = kb.model.relation(&atom.pred) else {
            return Check::Holders(Arc::from([]), neg);
        };
        let key = HolderKey {
            pred: rel.name(),
            args: atom
                .args
                .iter()
                .zip(consts)
                .map(|(a, c)| match a {
                    Arg::Const(_) => KeyArg::Const(c.clone()),
                    Arg::Var(x) if *x == v => KeyArg::Target,
                    Arg::Var(_) => KeyArg::Other,
                })
                .collect(),
        };
        if let Some(set) = kb.holders.get(&key) {
            return Check::Holders(set, neg);
        }
        let set: Arc<[kanren::Sym]> = holders_of(rel, atom, consts, v).into();
        kb.holders.put(key, Arc::clone(&set));
        Check::Holders(set, neg)
    }

    fn holds(
        &self,
        kb: &WindowKb,
        l: &Literal,
        ast: &QueryAst,
        v: usize,
        (obj, obj_sym): (&str, kanren::Sym),
        bounds: &Bounds,
    ) -> bool {
        match self {
            Check::Holders(set, neg) => set.binary_search(&obj_sym).is_ok() != *neg,
            Check::PerObject => cmp_holds(l, ast, v, obj),
            Check::NoMatch => not_exists_holds(kb, ast, l, v, obj, bounds),
        }
    }
}

/// The values of variable `v` that some fact of `rel` gives atom `atom`
/// (its constants `consts`, its other variables existential): sorted,
/// without duplicates.
fn holders_of(
    rel: &kanren::Relation,
    atom: &logicpad::fol::Atom,
    consts: &Consts,
    v: usize,
) -> Vec<kanren::Sym> {
    let mut set = Vec::new();
    let pattern: smallvec::SmallVec<[Option<&kanren::Term>; 4]> = atom
        .args
        .iter()
        .zip(consts)
        .map(|(a, c)| match a {
            Arg::Const(_) => c.as_ref(),
            Arg::Var(_) => None,
        })
        .collect();
    let at: smallvec::SmallVec<[usize; 2]> = atom
        .args
        .iter()
        .enumerate()
        .filter(|(_, a)| matches!(a, Arg::Var(x) if *x == v))
        .map(|(i, _)| i)
        .collect();
    // Nothing but the why-not variable, at one position: its holders are
    // that position's distinct values, read off the index.
    if let [pos] = at[..]
        && pattern.iter().all(Option::is_none)
    {
        set.extend(rel.values_at(pos).filter_map(|t| match t {
            kanren::Term::Sym(s) => Some(*s),
            _ => None,
        }));
        set.sort_unstable();
        return set;
    }
    for id in rel.lookup(&pattern) {
        let Some(t) = rel.tuple(id) else { continue };
        let mut vals = at.iter().filter_map(|&i| t.get(i));
        // `P(x, x)`: every position of the variable takes one value.
        if let Some(kanren::Term::Sym(first)) = vals.next()
            && vals.all(|o| matches!(o, kanren::Term::Sym(s) if s == first))
        {
            set.push(*first);
        }
    }
    set.sort_unstable();
    set.dedup();
    set
}

/// Whether a `¬∃` holds with `v` bound to `obj`: its conjunction has no
/// match. Another free variable is existential, so the literal alone
/// cannot rule `obj` out (as for a comparison).
pub(super) fn not_exists_holds(
    kb: &WindowKb,
    ast: &QueryAst,
    l: &Literal,
    v: usize,
    obj: &str,
    bounds: &Bounds,
) -> bool {
    if l.free_vars().iter().any(|&w| w != v) {
        return true;
    }
    satisfiable(kb, ast, &[bind_var(l, v, obj)], bounds).unwrap_or(true)
}

/// Whether a comparison holds with `v` bound to `obj`.
pub(super) fn cmp_holds(l: &Literal, ast: &QueryAst, v: usize, obj: &str) -> bool {
    let Literal::Cmp {
        left,
        right,
        negated,
        ..
    } = l
    else {
        return true;
    };
    // Another free variable on either side is existential: the comparison
    // alone cannot rule `obj` out (its name is not a constant to compare
    // with).
    let free = |a: &Arg| matches!(a, Arg::Var(x) if *x != v);
    if free(left) || free(right) {
        return true;
    }
    let eq = arg_str(left, ast, Some((v, obj))) == arg_str(right, ast, Some((v, obj)));
    eq != *negated
}
