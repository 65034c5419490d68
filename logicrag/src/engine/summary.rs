//! A list of window answers read as one answer: [`Summary`] ("yes — in 3
//! of 7 windows: frames 10–19, …"; "2 pedestrians"; the values a "which"
//! question asks for).

use super::Prepared;
use crate::ask::{AskResult, Outcome};
use logicpad::ParsedQuery;
use serde::Serialize;
use std::collections::{BTreeMap, BTreeSet};

/// One window's answer in a summary.
#[derive(Debug, Clone, Serialize)]
pub struct WindowOutcome {
    /// Window id.
    pub window: String,
    /// First frame.
    pub first_frame: u32,
    /// Last frame.
    pub last_frame: u32,
    /// The window's outcome.
    pub answer: Outcome,
}

/// The answer over every window asked, read as one answer.
///
/// Invariant: `answer` is yes when some window says yes (for a universal
/// or a closed "no …" query, `Prepared::is_closed_negation`: when every
/// window that can tell says yes and none says no), unknown
/// when none says yes but some cannot tell, invalid when every window
/// finds the query invalid, and no otherwise — except for a counting
/// query (`#{x: Q} op N`), whose answer is its test on `how_many`, the
/// distinct counted objects over every window (unknown where what the
/// source cannot see could change it).
#[derive(Debug, Clone, Serialize)]
pub struct Summary {
    /// The overall outcome.
    pub answer: Outcome,
    /// Windows asked.
    pub windows: usize,
    /// The windows whose answer is yes.
    pub yes: Vec<WindowOutcome>,
    /// Windows that cannot tell (unknown).
    pub unknown: usize,
    /// For "how many" questions: distinct objects (or unordered pairs)
    /// over all windows.
    pub how_many: Option<usize>,
    /// What `how_many` counts: "pedestrians", "pairs", "objects".
    pub unit: Option<String>,
    /// For "what …/which …" questions: the values asked for, over every
    /// window that says yes ("What colour is the van?" → `["White"]`).
    pub values: Vec<String>,
    /// For a counting query (`#{x: Q} > 2`): its test in words ("more
    /// than 2"), which `how_many` (the distinct counted objects over every
    /// window) is held to.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub count_test: Option<String>,
}

impl Summary {
    /// Summarizes the answers of one prepared query over several windows;
    /// nouns and asked-for values come from `words` (the LogicPad's roles
    /// and phrases, [`super::Engine::words`]).
    pub fn new(words: &crate::context::Sentences, p: &Prepared, results: &[AskResult]) -> Summary {
        let yes: Vec<WindowOutcome> = results
            .iter()
            .filter(|r| r.answer == Outcome::Yes)
            .map(|r| WindowOutcome {
                window: r.window.clone(),
                first_frame: r.first_frame,
                last_frame: r.last_frame,
                answer: r.answer,
            })
            .collect();
        let count = |o: Outcome| results.iter().filter(|r| r.answer == o).count();
        let (no, unknown, invalid) = (
            count(Outcome::No),
            count(Outcome::Unknown),
            count(Outcome::Invalid),
        );
        let answer = if !results.is_empty() && invalid == results.len() {
            Outcome::Invalid
        } else if p.is_universal() || p.is_closed_negation() {
            if no > 0 {
                Outcome::No
            } else if unknown > 0 {
                Outcome::Unknown
            } else {
                Outcome::Yes
            }
        } else if !yes.is_empty() {
            Outcome::Yes
        } else if unknown > 0 {
            Outcome::Unknown
        } else {
            Outcome::No
        };
        let (how_many, unit) = if p.intent.counts() && matches!(answer, Outcome::Yes | Outcome::No)
        {
            let (n, unit) = count_objects(words, p, results);
            (Some(n), Some(unit))
        } else {
            (None, None)
        };
        let values = if answer == Outcome::Yes {
            asked_values(words, p, results)
        } else {
            Vec::new()
        };
        let mut summary = Summary {
            answer,
            windows: results.len(),
            yes,
            unknown,
            how_many,
            unit,
            values,
            count_test: None,
        };
        if let Ok(ParsedQuery::Count(c)) = &p.parsed
            && summary.answer != Outcome::Invalid
        {
            summary.count_over_video(words, c, results);
        }
        summary
    }

    /// A counting query over a video: the distinct counted objects (or
    /// tuples) of every window that is not invalid, held to the test. Each
    /// window's count is exact, a lower or an upper bound
    /// (`crate::ask::Bound`, read back from its answer); the union is then
    /// one too, and the test is decided only where what no window could
    /// see cannot change it. Per-window outcomes stay as they were.
    fn count_over_video(
        &mut self,
        words: &crate::context::Sentences,
        c: &logicpad::CountQuery,
        results: &[AskResult],
    ) {
        use crate::ask::{Bound, bound_of_note, decide};
        let counted: Vec<&AskResult> = results
            .iter()
            .filter(|r| r.answer != Outcome::Invalid)
            .collect();
        let distinct: BTreeSet<Vec<(String, String)>> = counted
            .iter()
            .flat_map(|r| r.bindings.iter())
            .map(|b| {
                b.iter()
                    .filter(|(v, _)| c.vars.contains(v))
                    .cloned()
                    .collect()
            })
            .collect();
        let n = distinct.len();
        // One source, so one kind of bound for every window; any window
        // whose count is not exact makes the video's not exact.
        let bound = counted
            .iter()
            .map(|r| bound_of_note(r))
            .find(|b| *b != Bound::Exact)
            .unwrap_or(Bound::Exact);
        self.answer = match decide(c.op, c.n, n, bound) {
            Some(true) => Outcome::Yes,
            Some(false) => Outcome::No,
            None => Outcome::Unknown,
        };
        self.how_many = Some(n);
        self.unit = Some(match c.vars.as_slice() {
            [v] => noun_in(words, &c.query, v),
            [_, _] => "pairs".into(),
            _ => "tuples".into(),
        });
        self.count_test = Some(format!("{} {}", c.op.words(), c.n));
        self.values = Vec::new();
    }

    /// The one line that answers the question: "yes — in 3 of 7 windows:
    /// frames 10–19, 20–29, 60–69", "2 pedestrians — in 1 of 7 windows: …".
    pub fn headline(&self) -> String {
        let head = match (self.how_many, &self.unit) {
            // A counting query answers yes or no; the count says why.
            (Some(n), Some(unit)) if self.count_test.is_some() => format!(
                "{} ({n} {}{}; the question asks for {})",
                self.answer.as_str(),
                if n == 1 { singular(unit) } else { unit.clone() },
                if self.windows > 1 {
                    format!(" over {} windows", self.windows)
                } else {
                    String::new()
                },
                self.count_test.as_deref().unwrap_or_default()
            ),
            (Some(n), Some(unit)) => {
                format!("{n} {}", if n == 1 { singular(unit) } else { unit.clone() })
            }
            _ if !self.values.is_empty() => {
                let shown: Vec<&str> = self
                    .values
                    .iter()
                    .take(SUMMARY_VALUES)
                    .map(String::as_str)
                    .collect();
                let more = self.values.len().saturating_sub(SUMMARY_VALUES);
                if more > 0 {
                    format!("{} and {more} more", shown.join(", "))
                } else {
                    shown.join(", ")
                }
            }
            _ => self.answer.as_str().to_string(),
        };
        let of = |k: usize| {
            if self.windows == 1 {
                String::new()
            } else {
                format!(" in {k} of {} windows", self.windows)
            }
        };
        match self.answer {
            Outcome::Yes | Outcome::No if !self.yes.is_empty() => {
                let frames: Vec<String> = self
                    .yes
                    .iter()
                    .take(SUMMARY_WINDOWS)
                    .map(|w| format!("{}–{}", w.first_frame, w.last_frame))
                    .collect();
                let more = if self.yes.len() > SUMMARY_WINDOWS {
                    format!(" and {} more", self.yes.len() - SUMMARY_WINDOWS)
                } else {
                    String::new()
                };
                let sep = if self.windows == 1 { " in" } else { ":" };
                // A universal that fails somewhere still names where it held.
                let held = if self.answer == Outcome::No {
                    " it holds only"
                } else {
                    ""
                };
                format!(
                    "{head} —{held}{}{sep} frames {}{more}",
                    of(self.yes.len()),
                    frames.join(", ")
                )
            }
            Outcome::No => {
                if self.windows == 1 {
                    head
                } else {
                    format!("{head} — in none of {} windows", self.windows)
                }
            }
            Outcome::Unknown => format!(
                "{head} — no window proves it, and {} cannot tell",
                if self.windows == 1 {
                    "this window".to_string()
                } else {
                    format!("{} of {} windows", self.unknown, self.windows)
                }
            ),
            Outcome::Invalid | Outcome::Yes => head,
        }
    }
}

/// Windows named in a summary line before "and N more".
const SUMMARY_WINDOWS: usize = 8;
/// Values named in a summary line before "and N more".
const SUMMARY_VALUES: usize = 10;

/// The values a "what …/which …" question asks for: those of the variable
/// in a function's value position (`ColorOf(x, y)` → `y`), else of the
/// first answer variable ("Which vehicles …" → the vehicles), distinct and
/// sorted, over every window that says yes. Of the values bound to one
/// object, a value is dropped when another is its subtype by the LogicPad's
/// taxonomy rules (`TypeOf(x, Sedan) ==> TypeOf(x, Car)`): "What type is
/// the blue sedan?" answers `Sedan`, not `Car, Sedan`.
fn asked_values(
    words: &crate::context::Sentences,
    p: &Prepared,
    results: &[AskResult],
) -> Vec<String> {
    if p.intent != crate::translate::Intent::Which {
        return Vec::new();
    }
    let Ok(ParsedQuery::Exists(ast)) = &p.parsed else {
        return Vec::new();
    };
    use logicpad::fol::{Arg, Literal};
    // The valued literal: its predicate, the object variable (first
    // argument, when a variable) and the value variable.
    let valued = ast
        .disjuncts
        .first()
        .into_iter()
        .flatten()
        .find_map(|l| match l {
            Literal::Pos(a) if words.is_valued(&a.pred) => match a.args.get(1) {
                Some(Arg::Var(v)) => {
                    let object = match a.args.first() {
                        Some(Arg::Var(o)) => ast.vars.get(*o).cloned(),
                        _ => None,
                    };
                    Some((a.pred.clone(), object, ast.vars.get(*v).cloned()?))
                }
                _ => None,
            },
            _ => None,
        });
    let (var, taxonomy) = match valued {
        Some((pred, object, var)) => (var, object.map(|o| (pred, o))),
        None => match ast.answer_var_names().first() {
            Some(v) => (v.to_string(), None),
            None => return Vec::new(),
        },
    };
    let value_of =
        |b: &Vec<(String, String)>, v: &str| b.iter().find(|(n, _)| n == v).map(|(_, c)| c.clone());
    let bindings = results
        .iter()
        .filter(|r| r.answer == Outcome::Yes)
        .flat_map(|r| r.bindings.iter());
    let Some((pred, object)) = taxonomy else {
        let values: BTreeSet<String> = bindings.filter_map(|b| value_of(b, &var)).collect();
        return values.into_iter().collect();
    };
    // Values per object, then each object's most specific ones.
    let mut per_object: BTreeMap<Option<String>, BTreeSet<String>> = BTreeMap::new();
    for b in bindings {
        if let Some(v) = value_of(b, &var) {
            per_object
                .entry(value_of(b, &object))
                .or_default()
                .insert(v);
        }
    }
    let empty = BTreeMap::new();
    let supers = words.supertypes(&pred).unwrap_or(&empty);
    let values: BTreeSet<String> = per_object
        .values()
        .flat_map(|vs| {
            vs.iter()
                .filter(|v| {
                    !vs.iter()
                        .any(|w| supers.get(w.as_str()).is_some_and(|up| up.contains(*v)))
                })
                .cloned()
                .collect::<Vec<_>>()
        })
        .collect();
    values.into_iter().collect()
}

fn singular(unit: &str) -> String {
    match unit {
        "people" => "person".into(),
        "pairs" => "pair".into(),
        u if u.ends_with("ies") => format!("{}y", &u[..u.len() - 3]),
        u if u.ends_with("ses") || u.ends_with("shes") || u.ends_with("ches") => {
            u[..u.len() - 2].to_string()
        }
        u => u.strip_suffix('s').unwrap_or(u).to_string(),
    }
}

/// Distinct objects over all windows bound to the query's first answer
/// variable, or unordered pairs when the bindings of two variables are
/// symmetric (`TooClose(x, y)` lists each pair both ways).
fn count_objects(
    words: &crate::context::Sentences,
    p: &Prepared,
    results: &[AskResult],
) -> (usize, String) {
    let bindings: Vec<&Vec<(String, String)>> = results
        .iter()
        .filter(|r| r.answer == Outcome::Yes)
        .flat_map(|r| r.bindings.iter())
        .collect();
    let vars: Vec<String> = results
        .iter()
        .find(|r| !r.variables.is_empty())
        .map(|r| r.variables.clone())
        .unwrap_or_default();
    let Some(first) = vars.first() else {
        return (bindings.len(), "answers".into());
    };
    let value =
        |b: &Vec<(String, String)>, v: &str| b.iter().find(|(n, _)| n == v).map(|(_, c)| c.clone());
    if let [x, y] = vars.as_slice() {
        let pairs: BTreeSet<(String, String)> = bindings
            .iter()
            .filter_map(|b| Some((value(b, x)?, value(b, y)?)))
            .collect();
        let symmetric = !pairs.is_empty()
            && pairs
                .iter()
                .all(|(a, b)| pairs.contains(&(b.clone(), a.clone())));
        if symmetric {
            let unordered: BTreeSet<(String, String)> = pairs
                .into_iter()
                .map(|(a, b)| if a <= b { (a, b) } else { (b, a) })
                .collect();
            return (unordered.len(), "pairs".into());
        }
    }
    let objects: BTreeSet<String> = bindings.iter().filter_map(|b| value(b, first)).collect();
    (objects.len(), noun_of(words, p, first))
}

/// The plural noun for what variable `var` stands for: its type or class
/// in the query, in the LogicPad's words (`Pedestrian(x)` → "pedestrians",
/// `TypeOf(x, Car)` → "cars"), else "objects".
fn noun_of(words: &crate::context::Sentences, p: &Prepared, var: &str) -> String {
    match &p.parsed {
        Ok(ParsedQuery::Exists(ast)) => noun_in(words, ast, var),
        Ok(ParsedQuery::Count(c)) => noun_in(words, &c.query, var),
        _ => "objects".into(),
    }
}

/// [`noun_of`] for the variable `var` of one existential query.
fn noun_in(words: &crate::context::Sentences, ast: &logicpad::QueryAst, var: &str) -> String {
    let Some(v) = ast.vars.iter().position(|n| n == var) else {
        return "objects".into();
    };
    crate::ask::noun_of_var(
        ast,
        v,
        |f, t| {
            if words.is_type(f) {
                words.noun(t).map(str::to_string)
            } else {
                None
            }
        },
        |p| {
            words
                .noun(p)
                .filter(|_| words.is_class(p))
                .map(str::to_string)
        },
    )
    .map_or_else(|| "objects".into(), |n| plural(&n))
}

fn plural(noun: &str) -> String {
    if let Some(head) = noun.strip_suffix("person") {
        return format!("{head}people");
    }
    match noun {
        "vehicles" => "vehicles".into(),
        n if n.ends_with('s') || n.ends_with("sh") || n.ends_with("ch") => format!("{n}es"),
        n => format!("{n}s"),
    }
}
