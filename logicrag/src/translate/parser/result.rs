//! The result: the checks on the forms a question combines (a count, a
//! denial, a time order, a time word), an elided second event filled in,
//! and the final atoms and query text (`finish`).

use super::{
    Arg, Draft, MOVER_CLASSES, Parser, Pred, and_list, class_of_type, class_words, var_name,
};
use crate::translate::lexer::Wrap;
use crate::translate::lexicon::Sense;
use crate::translate::{QueryAtom, TranslateError, Translation};
use std::collections::BTreeSet;

impl Parser<'_> {
    pub(super) fn finish(mut self, question: &str) -> Result<Translation, TranslateError> {
        while !self.clauses.is_empty() {
            self.pop_clause();
        }
        for (x, y, token) in self.pairs.clone() {
            let related = self.drafts.iter().any(|d| {
                matches!(d.pred, Pred::Name(_))
                    && d.args.contains(&Arg::Var(x))
                    && d.args.contains(&Arg::Var(y))
            });
            if !related && self.unsupported.is_none() {
                self.unsupported = Some(TranslateError::Unsupported {
                    what: self.toks.get(token).map_or_else(String::new, |t| t.raw.clone()),
                    index: token,
                    why: "a bare number is ambiguous: ask 'at least two', 'exactly two' or 'more than two', or 'how many'; two objects described alike can only be asked about through a relation between them".into(),
                });
            }
        }
        self.check_forms();
        if let Some(e) = self.unsupported {
            return Err(e);
        }
        if !self.unplaced.is_empty() {
            self.unplaced.sort_by_key(|w| w.index);
            self.unplaced.dedup_by_key(|w| w.index);
            return Err(TranslateError::Unplaced {
                question: question.to_string(),
                words: self.unplaced,
            });
        }
        if self.order.is_some() {
            self.repeat_defining();
        }
        let intent = if self.counts {
            super::super::Intent::HowMany
        } else if self.wh_open {
            super::super::Intent::Which
        } else {
            super::super::Intent::YesNo
        };
        let mut names = Names {
            of: vec![None; self.entities],
            next: 0,
        };
        let top = self.conj(0, 0, &mut names, &BTreeSet::new())?;
        if top.literals.is_empty() {
            return Err(TranslateError::NoContent);
        }
        let structured = !self.scopes.is_empty()
            || self.order.is_some()
            || self.wrap.is_some()
            || self.count.is_some()
            || self.deny.is_some();
        if !structured {
            let query = top.literals.join("^");
            return Ok(Translation {
                query,
                atoms: top.atoms,
                notes: self.notes,
                intent,
                form: super::super::Form::Conjunction,
            });
        }
        // Each part of a form must be a safe query of its own: "is
        // anything still not moving?" would be `STILL: ¬Move(x)`.
        let second = match self.order {
            Some(_) => Some(self.conj(0, 1, &mut names, &BTreeSet::new())?),
            None => None,
        };
        if let Some(v) = top
            .unbound
            .as_ref()
            .or(second.as_ref().and_then(|c| c.unbound.as_ref()))
        {
            let token = self
                .deny
                .or(self.count.map(|c| c.token))
                .or(self.order.map(|o| o.1))
                .or(self.wrap.map(|w| w.1))
                .unwrap_or(0);
            return Err(self.refuse(
                token,
                &format!(
                    "a negation speaks of an object ({v}) the question does not describe: name its kind ('is any car not moving?')"
                ),
            ));
        }
        let body = top.literals.join("^");
        let (query, form) = if let Some(c) = self.count {
            let Some(Some(v)) = names.of.get(c.entity).cloned() else {
                return Err(self.refuse(
                    c.token,
                    "the counted objects are described by nothing the vocabulary holds: name their kind",
                ));
            };
            (
                format!("#{{{v}: {body}}} {} {}", c.op, c.n),
                super::super::Form::Count,
            )
        } else if let Some(token) = self.deny {
            let vars = names.in_scope(&self.entity_scope, 0, &self.constants);
            if vars.is_empty() {
                return Err(self.refuse(token, "'no' must deny an object the question describes"));
            }
            (
                format!("¬∃{}: ({body})", vars.join(",")),
                super::super::Form::Scoped,
            )
        } else if let (Some((order, _)), Some(second)) = (self.order, second) {
            (
                format!(
                    "({body}) {} ({})",
                    order.keyword(),
                    second.literals.join("^")
                ),
                super::super::Form::Temporal,
            )
        } else if let Some((wrap, _)) = self.wrap {
            let keyword = match wrap {
                Wrap::Ever => "EVER",
                Wrap::Throughout => "THROUGHOUT",
                Wrap::Still => "STILL",
            };
            (format!("{keyword}: {body}"), super::super::Form::Temporal)
        } else {
            (body, super::super::Form::Scoped)
        };
        Ok(Translation {
            query,
            atoms: Vec::new(),
            notes: self.notes,
            intent: if self.count.is_some() || self.deny.is_some() {
                super::super::Intent::YesNo
            } else {
                intent
            },
            form,
        })
    }

    fn refuse(&self, token: usize, why: &str) -> TranslateError {
        TranslateError::Unsupported {
            what: self
                .toks
                .get(token)
                .map_or_else(String::new, |t| t.raw.clone()),
            index: token,
            why: why.to_string(),
        }
    }

    /// The forms a question combines must nest: a count, a denial, a time
    /// order or a time word, one at a time, each over a query that can be
    /// answered per window.
    fn check_forms(&mut self) {
        // An elided second event is filled in first, so that what it says
        // of its object is checked like the rest ("before the truck" does
        // not make a truck cross).
        if self.order.is_some()
            && !self
                .drafts
                .iter()
                .any(|d| d.part == 1 && !d.defining && matches!(d.pred, Pred::Name(_)))
        {
            self.elide_second_part();
        }
        let mut seen: Vec<(&str, usize)> = Vec::new();
        if let Some(c) = self.count {
            seen.push(("counting", c.token));
        }
        if let Some(t) = self.deny {
            seen.push(("'no'", t));
        }
        if let Some((_, t)) = self.order {
            seen.push(("a time order", t));
        }
        if let Some((_, t)) = self.wrap {
            seen.push(("a time word over the video", t));
        }
        if let [(a, _), (b, t), ..] = seen.as_slice() {
            let why =
                format!("{a} and {b} in one question cannot be said together: ask them apart");
            let e = self.refuse(*t, &why);
            self.unsupported.get_or_insert(e);
        }
        if self.counts && self.count.is_some() {
            let t = self.count.map_or(0, |c| c.token);
            let e = self.refuse(t, "'how many' with a threshold: ask one or the other");
            self.unsupported.get_or_insert(e);
        }
        if let Some(e) = self.unguarded() {
            self.unsupported.get_or_insert(e);
        }
        if let Some(&(_, t)) = self.denied.first() {
            let e = self.refuse(t, "'no' can deny the subject ('is no pedestrian on the road?') or the object of a relation ('on no road'), not this object");
            self.unsupported.get_or_insert(e);
        }
        if let Some(c) = self.count
            && (self.entity_scope.get(c.entity) != Some(&0) || !self.subjects.contains(&c.entity))
        {
            let e = self.refuse(c.token, "only the subject of a question can be counted");
            self.unsupported.get_or_insert(e);
        }
        if let Some((_, t)) = self.order {
            let said = self
                .drafts
                .iter()
                .any(|d| d.part == 1 && !d.defining && matches!(d.pred, Pred::Name(_)));
            if !said {
                let e = self.refuse(
                    t,
                    "nothing is said to happen after it: ask 'did A happen and then B?'",
                );
                self.unsupported.get_or_insert(e);
            }
        }
    }

    /// "Did the white car cross the junction before the van?": a second
    /// part that only names another object says that it did the same. When
    /// the second part describes exactly one new object, and the first
    /// says things of exactly one object with one-place atoms (its own
    /// motion: "slow down", "stop", "appear"), those atoms are said of the
    /// new object in the second part, with a note. True when they were.
    fn elide_second_part(&mut self) -> bool {
        let entities_of = |part: usize, defining: bool| -> BTreeSet<usize> {
            self.drafts
                .iter()
                .filter(|d| d.part == part && d.defining == defining && d.scope == 0)
                .flat_map(|d| d.args.iter())
                .filter_map(|a| match a {
                    Arg::Var(v) => Some(*v),
                    Arg::Const(_) => None,
                })
                .collect()
        };
        let second: Vec<usize> = entities_of(1, true).into_iter().collect();
        let said: Vec<usize> = entities_of(0, false).into_iter().collect();
        let (&[new], &[old]) = (second.as_slice(), said.as_slice()) else {
            return false;
        };
        if new == old || self.drafts.iter().any(|d| d.part == 1 && d.scope != 0) {
            return false;
        }
        let copies: Vec<Draft> = self
            .drafts
            .iter()
            .filter(|d| d.part == 0 && !d.defining && d.scope == 0)
            .map(|d| Draft {
                args: vec![Arg::Var(new)],
                part: 1,
                ..d.clone()
            })
            .collect();
        let unary = self
            .drafts
            .iter()
            .filter(|d| d.part == 0 && !d.defining && d.scope == 0)
            .all(|d| d.args == [Arg::Var(old)] && matches!(d.pred, Pred::Name(_)));
        if copies.is_empty() || !unary {
            return false;
        }
        let said: Vec<String> = copies
            .iter()
            .filter_map(|d| match &d.pred {
                Pred::Name(n) => Some(n.clone()),
                _ => None,
            })
            .collect();
        self.drafts.extend(copies);
        self.note(format!(
            "the second object of the time order read as doing the same as the first: {}",
            said.join(", ")
        ));
        true
    }

    /// The classes a question gives object `v`, each with the noun that
    /// names it: its class atoms, its type (`TypeOf(v, Van)` is a vehicle),
    /// the ego; `IsPerson` (anyone) counts as a pedestrian. Only the
    /// classes of [`MOVER_CLASSES`].
    fn mover_classes(&self, v: usize) -> Vec<(&'static str, String)> {
        let mut out: Vec<(&'static str, String)> = Vec::new();
        if self.constants.iter().any(|(e, c)| *e == v && c == "ego") {
            out.push(("Ego", class_words("Ego").0));
        }
        for d in self.drafts.iter().filter(|d| !d.negated) {
            let Pred::Name(n) = &d.pred else { continue };
            match d.args.as_slice() {
                [Arg::Var(w)] if *w == v => {
                    let class = if n == "IsPerson" {
                        Some(("Pedestrian", "person".to_string()))
                    } else {
                        MOVER_CLASSES
                            .iter()
                            .find(|c| **c == n.as_str())
                            .map(|c| (*c, class_words(c).0))
                    };
                    out.extend(class);
                }
                [Arg::Var(w), Arg::Const(value)]
                    if *w == v && self.lex.type_functions.contains(n) =>
                {
                    if let Some(c) = class_of_type(value) {
                        // "SUV" stays upper case; "PoliceCar" is "police car".
                        let noun = if value.chars().all(|c| c.is_ascii_uppercase()) {
                            value.clone()
                        } else {
                            super::super::default_phrase(value).to_lowercase()
                        };
                        out.push((c, noun));
                    }
                }
                _ => {}
            }
        }
        out
    }

    /// A property said of an object of a class its rules do not cover
    /// ("is the white car crossing?": `Cross` is derived for pedestrians
    /// only, so the answer would be "no" whatever the car does): refused,
    /// naming the classes it is defined for.
    fn unguarded(&self) -> Option<TranslateError> {
        for d in &self.drafts {
            let Pred::Name(name) = &d.pred else { continue };
            let Some(guards) = self.lex.guards.get(name) else {
                continue;
            };
            let [Arg::Var(v)] = d.args.as_slice() else {
                continue;
            };
            let classes = self.mover_classes(*v);
            if classes.is_empty() || classes.iter().any(|(c, _)| guards.iter().any(|g| g == c)) {
                continue;
            }
            let (_, noun) = &classes[0];
            // The question's words for the property, and where they are.
            let said = (0..self.items.len()).find(|k| {
                matches!(self.entry_at(*k), Some(e) if matches!(&e.sense, Sense::Property { name: n, .. } if n == name))
            });
            let (words, token) = match said {
                Some(k) => (self.raw_at(k), self.token_index(k)),
                None => (super::super::default_phrase(name).to_lowercase(), 0),
            };
            // "an SUV", "an MPV": an acronym is said letter by letter.
            let acronym = noun.chars().all(|c| c.is_ascii_uppercase());
            let an = if acronym {
                noun.starts_with(['A', 'E', 'F', 'H', 'I', 'L', 'M', 'N', 'O', 'R', 'S', 'X'])
            } else {
                noun.starts_with(['a', 'e', 'i', 'o', 'u'])
            };
            let whose = if noun == "our own vehicle" {
                format!("{noun}'s")
            } else if an {
                format!("an {noun}'s")
            } else {
                format!("a {noun}'s")
            };
            let defined: Vec<String> = guards.iter().map(|g| class_words(g).1).collect();
            return Some(self.refuse(
                token,
                &format!(
                    "{words} is defined for {} only (rule {name}); {whose} {words} is not observed",
                    and_list(&defined)
                ),
            ));
        }
        None
    }

    /// In a time-ordered question each part must stand on its own: the
    /// second repeats what the first says an object is (its class, type,
    /// colour), never where it was or what it did.
    fn repeat_defining(&mut self) {
        let Some(first_two) = self.drafts.iter().position(|d| d.part == 1) else {
            return;
        };
        let mut used: Vec<usize> = Vec::new();
        for d in self.drafts.iter().filter(|d| d.part == 1) {
            for a in &d.args {
                if let Arg::Var(v) = a
                    && !used.contains(v)
                {
                    used.push(*v);
                }
            }
        }
        let copies: Vec<Draft> = self
            .drafts
            .iter()
            .filter(|d| {
                d.part == 0
                    && d.defining
                    && d.scope == 0
                    && d.args
                        .iter()
                        .any(|a| matches!(a, Arg::Var(v) if used.contains(v)))
            })
            .map(|d| Draft {
                part: 1,
                ..d.clone()
            })
            .collect();
        let tail = self.drafts.split_off(first_two);
        self.drafts.extend(copies);
        self.drafts.extend(tail);
    }

    /// The literals of scope `scope` in part `part`: its positive atoms,
    /// its negated atoms (their variables bound first), then its nested
    /// scopes as `¬∃y: (…)`. `bound`: the variables positive atoms of the
    /// enclosing scopes bind, which a nested scope may use.
    fn conj(
        &self,
        scope: usize,
        part: usize,
        names: &mut Names,
        bound: &BTreeSet<String>,
    ) -> Result<Conj, TranslateError> {
        let mine = |d: &&Draft| d.scope == scope && d.part == part;
        let positive = self.drafts.iter().filter(mine).filter(|d| !d.negated);
        let negative = self.drafts.iter().filter(mine).filter(|d| d.negated);
        let mut out = Conj::default();
        for d in positive.chain(negative) {
            let Pred::Name(name) = &d.pred else { continue };
            let mut args = Vec::new();
            for a in &d.args {
                match a {
                    Arg::Const(c) => args.push(c.clone()),
                    Arg::Var(v) => match self.constants.iter().find(|(e, _)| e == v) {
                        Some((_, c)) => args.push(c.clone()),
                        None => {
                            let n = names.name(*v);
                            out.vars.insert(n.clone());
                            if !d.negated {
                                out.bound.insert(n.clone());
                            }
                            args.push(n);
                        }
                    },
                }
            }
            let atom = QueryAtom {
                predicate: name.clone(),
                args,
                negated: d.negated,
            };
            if !out.atoms.contains(&atom) {
                out.literals.push(atom.to_string());
                out.atoms.push(atom);
            }
        }
        let mut inner: BTreeSet<String> = bound.clone();
        inner.extend(out.bound.iter().cloned());
        out.unbound = out
            .atoms
            .iter()
            .filter(|a| a.negated)
            .flat_map(|a| a.args.iter())
            .find(|v| out.vars.contains(*v) && !inner.contains(*v))
            .cloned();
        for (k, s) in self.scopes.iter().enumerate() {
            let id = k + 1;
            if s.parent != scope || !self.drafts.iter().any(|d| d.scope == id && d.part == part) {
                continue;
            }
            let body = self.conj(id, part, names, &inner)?;
            let locals = names.in_scope(&self.entity_scope, id, &self.constants);
            let free: Vec<&String> = body.vars.iter().filter(|v| !locals.contains(v)).collect();
            if let Some(v) = free.iter().find(|v| !inner.contains(**v)) {
                return Err(self.refuse(
                    s.token,
                    &format!(
                        "the negation speaks of an object ({v}) the question does not describe: name its kind ('is any pedestrian not on the road?')"
                    ),
                ));
            }
            if locals.is_empty() || body.literals.is_empty() {
                return Err(self.refuse(s.token, "the negation has no object of its own to deny"));
            }
            out.vars.extend(free.into_iter().cloned());
            if out.unbound.is_none() {
                out.unbound = body.unbound.clone();
            }
            out.literals.push(format!(
                "¬∃{}: ({})",
                locals.join(","),
                body.literals.join("^")
            ));
        }
        Ok(out)
    }
}

/// Variable names, given in order of first use.
struct Names {
    of: Vec<Option<String>>,
    next: usize,
}

impl Names {
    fn name(&mut self, v: usize) -> String {
        match self.of.get_mut(v) {
            Some(Some(n)) => n.clone(),
            Some(slot) => {
                let n = var_name(self.next);
                self.next += 1;
                *slot = Some(n.clone());
                n
            }
            None => var_name(v),
        }
    }

    /// The named variables of the entities read in `scope` (constants
    /// aside), in the order they were named.
    fn in_scope(
        &self,
        entity_scope: &[usize],
        scope: usize,
        constants: &[(usize, String)],
    ) -> Vec<String> {
        let mut vars: Vec<(usize, String)> = Vec::new();
        for (e, n) in self.of.iter().enumerate() {
            if let Some(n) = n
                && entity_scope.get(e).copied().unwrap_or(0) == scope
                && !constants.iter().any(|(c, _)| *c == e)
            {
                let order = (0..self.next)
                    .position(|k| var_name(k) == *n)
                    .unwrap_or(usize::MAX);
                vars.push((order, n.clone()));
            }
        }
        vars.sort();
        vars.into_iter().map(|(_, n)| n).collect()
    }
}

/// One conjunction as rendered.
#[derive(Debug, Default)]
struct Conj {
    /// Its literals' text, in order.
    literals: Vec<String>,
    /// Its own atoms (nested scopes aside).
    atoms: Vec<QueryAtom>,
    /// Every variable it uses, nested scopes included.
    vars: BTreeSet<String>,
    /// The variables its positive atoms bind.
    bound: BTreeSet<String>,
    /// A variable of a negated atom that no positive atom binds (here or
    /// in an enclosing conjunction), nested scopes included.
    unbound: Option<String>,
}
