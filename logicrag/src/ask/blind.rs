//! Why a query is unknown rather than no: the predicates and constants
//! a source cannot observe ([`Blindness`]), in words.

use super::*;

/// What a source cannot see: the per-predicate classification, and the
/// source's reasons when they are at hand (for answers in words).
#[derive(Debug, Clone, Copy)]
pub(crate) struct Blindness<'a> {
    /// Observability of every predicate.
    pub observed: &'a BTreeMap<String, Observed>,
    /// The source's unobservable base predicates with their reasons.
    pub observability: Option<&'a crate::kb::Observability>,
    /// Every predicate of the LogicPad is fully observed (a KB of facts as
    /// given; see `all_fully`): no literal of a valid query can make an
    /// answer a guess, and none is looked up.
    pub all_observed: bool,
}

/// Whether `observed` says every predicate of `pad` (every one a valid
/// query can name) is fully observed.
pub(crate) fn all_fully(pad: &LogicPad, observed: &BTreeMap<String, Observed>) -> bool {
    pad.schema()
        .predicates()
        .all(|p| observed.get(&p.name) == Some(&Observed::Fully))
}

/// Constants of the query that the window never mentions and that every
/// alternative needs in a positive atom: the query cannot hold, whatever
/// the source observes. (A constant only under `¬` proves nothing absent.)
pub(super) fn absent_constants(pad: &LogicPad, kb: &WindowKb, ast: &QueryAst) -> Vec<String> {
    let mut all: BTreeSet<String> = BTreeSet::new();
    for d in &ast.disjuncts {
        let missing: BTreeSet<String> = d
            .iter()
            .filter_map(Literal::positive)
            .flat_map(|a| a.args.iter())
            .filter_map(|x| if let Arg::Const(c) = x { Some(c) } else { None })
            // A constant a rule or a declared value (`White`) names is the
            // LogicPad's: its absence is a matter of what the source
            // observes, which the outcome logic decides. (Asked first: a
            // set lookup, where the interner takes a lock.) A name the
            // interner does not know occurs in no fact.
            .filter(|c| {
                !pad.names_constant(c) && !kanren::Sym::lookup(c).is_some_and(|s| kb.is_constant(s))
            })
            .cloned()
            .collect();
        if missing.is_empty() {
            return Vec::new();
        }
        all.extend(missing);
    }
    all.into_iter().collect()
}

/// The predicates of a query the source does not fully observe, by what
/// they make a guess, each as a reason in words (sorted, without
/// duplicates): `always` — a negated atom (a binding found or not rests
/// on an absence the source may have missed); `yes` — an atom of a `¬∃`
/// body (an unseen match would break a "yes"); `no` — a positive atom
/// (an unseen object could make a "no" a "yes"), also one under two
/// `¬∃`. Nothing is looked up when every predicate is fully observed.
#[derive(Debug, Default)]
pub(super) struct Guesses {
    pub(super) always: Vec<String>,
    pub(super) yes: Vec<String>,
    pub(super) no: Vec<String>,
}

pub(super) fn blind_guesses(pad: &LogicPad, blind: &Blindness<'_>, ast: &QueryAst) -> Guesses {
    let mut g = Guesses::default();
    // Atoms the source cannot see although it observes their predicate
    // (`Behind(x, ego)` from a forward camera).
    let blind_atoms = blind
        .observability
        .filter(|o| !o.unobservable_atoms.is_empty());
    if blind.all_observed && blind_atoms.is_none() {
        return g;
    }
    // (literal, how many `¬∃` enclose it)
    let mut todo: Vec<(&Literal, usize)> = ast.disjuncts.iter().flatten().map(|l| (l, 0)).collect();
    while let Some((lit, depth)) = todo.pop() {
        let (atom, neg) = match lit {
            Literal::Pos(a) => (a, false),
            Literal::Neg(a) => (a, true),
            Literal::Cmp { .. } => continue,
            Literal::NotExists { body, .. } => {
                todo.extend(body.iter().map(|b| (b, depth + 1)));
                continue;
            }
        };
        let s = blind
            .observed
            .get(&atom.pred)
            .copied()
            .unwrap_or(Observed::Never);
        let unseen = blind_atoms.and_then(|o| {
            let args: Vec<Option<&str>> = atom
                .args
                .iter()
                .map(|a| match a {
                    Arg::Const(c) => Some(c.as_str()),
                    _ => None,
                })
                .collect();
            o.blind_atom(&atom.pred, &args)
        });
        let why = match (s, unseen) {
            (Observed::Fully, None) => continue,
            (Observed::Fully, Some(why)) => {
                format!(
                    "this source cannot observe `{}` about these objects: {why}",
                    atom.pred
                )
            }
            _ => blind_reason(pad, blind, &atom.pred, s),
        };
        if neg {
            g.always.push(why);
        } else if depth % 2 == 1 {
            g.yes.push(why);
        } else {
            g.no.push(why);
        }
    }
    for v in [&mut g.always, &mut g.yes, &mut g.no] {
        v.sort();
        v.dedup();
    }
    g
}

/// Why an atom's predicate makes an answer a guess, in words: the
/// predicate, and what the source lacks.
pub(super) fn blind_reason(
    pad: &LogicPad,
    blind: &Blindness<'_>,
    pred: &str,
    status: Observed,
) -> String {
    if status == Observed::Never && has_no_rule(pad, pred) {
        return format!(
            "`{pred}` is derived but none of its rules loaded (the LogicPad has errors; \
             `logicrag lint` shows them)"
        );
    }
    let words = crate::translate::default_phrase(pred);
    let spots = blind
        .observability
        .map(|o| o.blind_spots(pad, pred))
        .unwrap_or_default();
    let lacks = if spots.is_empty() {
        String::new()
    } else {
        let mut reasons: Vec<&str> = spots.iter().map(|(_, w)| w.as_str()).collect();
        reasons.sort();
        reasons.dedup();
        let via = if spots.len() == 1 && spots.first().is_some_and(|(p, _)| p == pred) {
            String::new()
        } else {
            let names: Vec<String> = spots.iter().map(|(p, _)| format!("`{p}`")).collect();
            format!(", which rests on {}", names.join(", "))
        };
        format!("{via}: {}", reasons.join("; "))
    };
    match status {
        Observed::Partly => format!("this source observes `{pred}` ({words}) only in part{lacks}"),
        _ => format!("this source cannot observe `{pred}` ({words}){lacks}"),
    }
}

/// Whether `pred` is a derived predicate without a single loaded rule: its
/// rules were rejected, so "unknown" is the LogicPad's fault, not the
/// source's.
pub(super) fn has_no_rule(pad: &LogicPad, pred: &str) -> bool {
    let derived = pad
        .schema()
        .predicates()
        .any(|p| p.name == pred && p.kind == logicpad::PredKind::Derived);
    let program = pad.program();
    derived
        && program
            .pred_id(pred)
            .is_none_or(|id| program.rules().iter().all(|r| r.head.pred != id))
}
