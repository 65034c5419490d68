//! Counting queries (`#{x: Q} >= N`): the distinct bindings of the counted
//! variables in the window, tested against `N`. The witnesses (the
//! counted objects) are the answer's bindings, their proofs its proofs,
//! whatever the outcome, so that a video can count distinct objects over
//! its windows ([`crate::engine::Summary`]).
//!
//! Under partial observability only what the unseen cannot change is said:
//! an object the source misses could add a witness (a predicate of `Q`
//! used positively), or a match it misses could remove one (a predicate of
//! a `¬∃` body), so the true count is at least, or at most, the one found
//! ([`Bound`]); the test is answered when it holds, or fails, for every
//! count on that side, and is unknown otherwise.

use super::*;
use logicpad::{CountOp, CountQuery};

/// What the count found in a window says about the true count.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Bound {
    /// The source observes everything `Q` uses: the count is the count.
    Exact,
    /// Every witness is real, but an unseen object could be another.
    AtLeast,
    /// An unseen match of a `¬∃` body could remove a witness.
    AtMost,
    /// Both, or a negated atom over what the source may miss.
    Unknowable,
}

/// The note's words for a count that is a lower bound.
pub(crate) const AT_LEAST_NOTE: &str = "found at least";
/// The note's words for a count that is an upper bound.
pub(crate) const AT_MOST_NOTE: &str = "found at most";

/// The answer of `count op n` when the true count is `found` (`Exact`),
/// or anything on `bound`'s side of it: `Some(true)` when the test holds
/// for every such count, `Some(false)` when it fails for every one,
/// `None` when it depends on what the source cannot see.
pub(crate) fn decide(op: CountOp, n: usize, found: usize, bound: Bound) -> Option<bool> {
    let holds = op.holds(found, n);
    match bound {
        Bound::Exact => Some(holds),
        // More objects only raise the count.
        Bound::AtLeast => match op {
            CountOp::AtLeast | CountOp::MoreThan => holds.then_some(true),
            CountOp::AtMost | CountOp::FewerThan => (!holds).then_some(false),
            CountOp::Exactly => (found > n).then_some(false),
        },
        // Unseen matches only lower it.
        Bound::AtMost => match op {
            CountOp::AtLeast | CountOp::MoreThan => (!holds).then_some(false),
            CountOp::AtMost | CountOp::FewerThan => holds.then_some(true),
            CountOp::Exactly => (found < n).then_some(false),
        },
        Bound::Unknowable => None,
    }
}

/// The bound a count's note states (see [`count_note`]): how a summary
/// reads a window's count back without re-asking it.
pub(crate) fn bound_of_note(r: &AskResult) -> Bound {
    if r.reasons.is_empty() {
        return Bound::Exact;
    }
    if r.notes.iter().any(|n| n.starts_with(AT_MOST_NOTE)) {
        Bound::AtMost
    } else if r.notes.iter().any(|n| n.starts_with(AT_LEAST_NOTE)) {
        Bound::AtLeast
    } else {
        Bound::Unknowable
    }
}

/// How many witnesses a count's note names before "and N more".
const NOTE_WITNESSES: usize = 8;

/// "found 2 cars (car_1, car_4); the question asks for more than 2".
pub(crate) fn count_note(
    c: &CountQuery,
    noun: &str,
    found: usize,
    witnesses: &[Vec<(String, String)>],
    bound: Bound,
) -> String {
    let verb = match bound {
        Bound::Exact => "found",
        Bound::AtLeast => AT_LEAST_NOTE,
        Bound::AtMost => AT_MOST_NOTE,
        Bound::Unknowable => "found (uncertainly)",
    };
    let unit = if found == 1 {
        singular(noun)
    } else {
        noun.to_string()
    };
    let mut s = format!("{verb} {found} {unit}");
    if !witnesses.is_empty() {
        let names: Vec<String> = witnesses
            .iter()
            .take(NOTE_WITNESSES)
            .map(|b| {
                let vals: Vec<&str> = c
                    .vars
                    .iter()
                    .filter_map(|v| b.iter().find(|(n, _)| n == v).map(|(_, x)| x.as_str()))
                    .collect();
                if vals.len() == 1 {
                    vals.join("")
                } else {
                    format!("({})", vals.join(", "))
                }
            })
            .collect();
        let more = witnesses.len().saturating_sub(NOTE_WITNESSES);
        let more = if more > 0 {
            format!(" and {more} more")
        } else {
            String::new()
        };
        s.push_str(&format!(" ({}{more})", names.join(", ")));
    }
    s.push_str(&format!("; the question asks for {} {}", c.op.words(), c.n));
    s
}

/// What a count counts, in words: "cars" for `TypeOf(x, Car)`,
/// "pedestrians" for a class atom `Pedestrian(x)`, "pairs" for two
/// counted variables, else "objects".
pub(crate) fn counted_noun(pad: &LogicPad, c: &CountQuery) -> String {
    match c.vars.len() {
        1 => {}
        2 => return "pairs".into(),
        _ => return "tuples".into(),
    }
    let Some(v) = c.query.answer_vars.first().copied() else {
        return "objects".into();
    };
    noun_of_var(
        &c.query,
        v,
        |f, t| (f == "TypeOf").then(|| words_of(t)),
        |p| is_class(pad, p).then(|| words_of(p)),
    )
    .map_or_else(|| "objects".into(), |n| plural(&n))
}

/// The noun for variable `v` of `ast`, read from the positive atoms of its
/// first disjunct: the first type atom `F(v, T)` that `type_noun(F, T)`
/// names, else the first class atom `C(v)` that `class_noun(C)` names.
/// A count's noun ([`counted_noun`]) and the English summary's differ only
/// in how they name a type and a class.
pub(crate) fn noun_of_var(
    ast: &QueryAst,
    v: usize,
    type_noun: impl Fn(&str, &str) -> Option<String>,
    class_noun: impl Fn(&str) -> Option<String>,
) -> Option<String> {
    use logicpad::fol::{Arg, Literal};
    let atoms = ast
        .disjuncts
        .first()
        .into_iter()
        .flatten()
        .filter_map(Literal::positive);
    let mut class = None;
    for a in atoms {
        match a.args.as_slice() {
            [Arg::Var(x), Arg::Const(t)] if *x == v => {
                if let Some(n) = type_noun(&a.pred, t) {
                    return Some(n);
                }
            }
            [Arg::Var(x)] if *x == v && class.is_none() => class = class_noun(&a.pred),
            _ => {}
        }
    }
    class
}

/// Whether a unary predicate names a kind of object: declared a class,
/// or of the segmentation group, or an `Is*` alias of one.
fn is_class(pad: &LogicPad, pred: &str) -> bool {
    let class = |p: &str| {
        pad.schema().get(p).is_some_and(|i| {
            i.role == Some(logicpad::Role::Class)
                || i.group.as_deref() == Some("semantic_segmentation")
        })
    };
    class(pred) || pred.strip_prefix("Is").is_some_and(class)
}

/// `TrafficSign` → "traffic sign"; a leading `Is` alias prefix dropped.
fn words_of(name: &str) -> String {
    let name = name
        .strip_prefix("Is")
        .filter(|r| r.starts_with(char::is_uppercase))
        .unwrap_or(name);
    let mut out = String::new();
    for (i, ch) in name.chars().enumerate() {
        if ch.is_uppercase() && i > 0 {
            out.push(' ');
        }
        out.extend(ch.to_lowercase());
    }
    out
}

fn plural(noun: &str) -> String {
    if let Some(head) = noun.strip_suffix("person") {
        return format!("{head}people");
    }
    if noun.ends_with('s') || noun.ends_with("sh") || noun.ends_with("ch") || noun.ends_with('x') {
        return format!("{noun}es");
    }
    if let Some(stem) = noun.strip_suffix('y')
        && !stem.ends_with(['a', 'e', 'o', 'u'])
    {
        return format!("{stem}ies");
    }
    format!("{noun}s")
}

fn singular(noun: &str) -> String {
    match noun {
        "people" => "person".into(),
        "pairs" => "pair".into(),
        "tuples" => "tuple".into(),
        "objects" => "object".into(),
        n if n.ends_with("people") => format!("{}person", &n[..n.len() - "people".len()]),
        n if n.ends_with("ies") => format!("{}y", &n[..n.len() - 3]),
        n if n.ends_with("ses")
            || n.ends_with("shes")
            || n.ends_with("ches")
            || n.ends_with("xes") =>
        {
            n[..n.len() - 2].to_string()
        }
        n => n.strip_suffix('s').unwrap_or(n).to_string(),
    }
}

/// Answers `#{x: Q} op N` on a window (see the module's documentation).
pub(super) fn ask_count(
    pad: &LogicPad,
    kb: &WindowKb,
    blind: &Blindness<'_>,
    c: &CountQuery,
    opts: AskOptions,
    mut result: AskResult,
) -> AskResult {
    let q = &c.query;
    result.variables = q
        .answer_var_names()
        .into_iter()
        .map(str::to_string)
        .collect();
    // A constant the window never mentions, needed by every alternative:
    // nothing here can be counted, whatever the source observes.
    let absent = absent_constants(pad, kb, q);
    let found: Result<super::Ran, logicpad::AskError> = if !absent.is_empty() {
        Ok(super::Ran {
            count: 0,
            answers: Vec::new(),
            stopped: None,
        })
    } else {
        super::run_query(kb, q, opts)
    };
    let super::Ran {
        count,
        answers,
        stopped,
    } = match found {
        Ok(f) => f,
        Err(e) => {
            set_error(&mut result, &e);
            return result;
        }
    };
    result.stopped = stopped;
    let guesses = if absent.is_empty() {
        blind_guesses(pad, blind, q)
    } else {
        Default::default()
    };
    let bound = match (
        guesses.always.is_empty(),
        guesses.yes.is_empty(),
        guesses.no.is_empty(),
    ) {
        (true, true, true) => Bound::Exact,
        (true, true, false) => Bound::AtLeast,
        (true, false, true) => Bound::AtMost,
        _ => Bound::Unknowable,
    };
    // A run stopped at a limit counted only what it found before it: the
    // count is a lower bound.
    let bound = match (stopped, bound) {
        (None, b) => b,
        (Some(_), Bound::Exact | Bound::AtLeast) => Bound::AtLeast,
        (Some(_), _) => Bound::Unknowable,
    };
    let mut reasons: Vec<String> = guesses
        .always
        .into_iter()
        .chain(guesses.yes)
        .chain(guesses.no)
        .chain(stopped.map(|r| super::stopped_reason(r, &opts.limits, count)))
        .collect();
    reasons.sort();
    reasons.dedup();
    result.answer = match decide(c.op, c.n, count, bound) {
        Some(true) => Outcome::Yes,
        Some(false) => Outcome::No,
        None => Outcome::Unknown,
    };
    // What the answer could not see, for every outcome of a count that is
    // not exact: a summary reads it back (`bound_of_note`).
    result.reasons = reasons;
    result.count = count;
    let witnesses: Vec<Vec<(String, String)>> =
        answers.iter().map(|a| a.bindings.clone()).collect();
    for c in &absent {
        result.notes.push(format!("{c} is not seen in this window"));
    }
    result.notes.push(count_note(
        c,
        &counted_noun(pad, c),
        count,
        &witnesses,
        bound,
    ));
    if bound != Bound::Unknowable {
        for a in answers {
            if opts.proofs {
                result.proofs.push(crate::proof::of_answer(kb, &a));
            }
            result.bindings.push(a.bindings);
        }
    }
    result
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_bound_decides_only_what_the_unseen_cannot_change() {
        use Bound::{AtLeast as Lo, AtMost as Hi, Exact, Unknowable};
        use CountOp::*;
        // Exact: the test.
        assert_eq!(decide(MoreThan, 2, 3, Exact), Some(true));
        assert_eq!(decide(MoreThan, 2, 2, Exact), Some(false));
        // At least the count found: met thresholds stand, upper limits
        // broken stay broken.
        assert_eq!(decide(AtLeast, 3, 3, Lo), Some(true));
        assert_eq!(decide(AtLeast, 3, 2, Lo), None);
        assert_eq!(decide(FewerThan, 3, 3, Lo), Some(false));
        assert_eq!(decide(FewerThan, 3, 2, Lo), None);
        assert_eq!(decide(AtMost, 2, 2, Lo), None);
        assert_eq!(decide(Exactly, 1, 2, Lo), Some(false));
        assert_eq!(decide(Exactly, 1, 1, Lo), None);
        // At most: the mirror image.
        assert_eq!(decide(AtLeast, 3, 2, Hi), Some(false));
        assert_eq!(decide(AtLeast, 3, 3, Hi), None);
        assert_eq!(decide(AtMost, 3, 2, Hi), Some(true));
        assert_eq!(decide(Exactly, 3, 2, Hi), Some(false));
        assert_eq!(decide(Exactly, 2, 2, Hi), None);
        assert_eq!(decide(AtLeast, 0, 0, Unknowable), None);
    }

    #[test]
    fn nouns_and_notes_read_as_english() {
        let parse = |q: &str| match logicpad::parse_any_query(q) {
            Ok(logicpad::ParsedQuery::Count(c)) => c,
            other => panic!("{other:?}"),
        };
        let c = parse("#{x: TypeOf(x, Car)} > 2");
        let pad = LogicPad::builtin();
        assert_eq!(counted_noun(&pad, &c), "cars");
        let w = vec![
            vec![("x".to_string(), "car_1".to_string())],
            vec![("x".to_string(), "car_4".to_string())],
        ];
        assert_eq!(
            count_note(&c, "cars", 2, &w, Bound::Exact),
            "found 2 cars (car_1, car_4); the question asks for more than 2"
        );
        assert_eq!(
            count_note(&c, "cars", 1, &w[..1], Bound::AtLeast),
            "found at least 1 car (car_1); the question asks for more than 2"
        );
        assert_eq!(
            counted_noun(&pad, &parse("#{x: IsPerson(x)} = 1")),
            "people"
        );
        assert_eq!(
            counted_noun(&pad, &parse("#{x: Pedestrian(x)} = 1")),
            "pedestrians"
        );
        assert_eq!(counted_noun(&pad, &parse("#{x: Moving(x)} = 1")), "objects");
        assert_eq!(
            counted_noun(&pad, &parse("#{x, y: Collide(x, y)} = 1")),
            "pairs"
        );
        assert_eq!(singular("people"), "person");
        assert_eq!(singular("buses"), "bus");
        assert_eq!(plural("bus"), "buses");
    }
}
