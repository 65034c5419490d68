//! Clauses and negation: a verb phrase said of a focus, conjoined with
//! "and", negated with "not", nested as a relative clause ("that is on the
//! right"); each clause collects its places and time phrases and gives the
//! places their frames when it ends.

use super::{
    Arg, BARE_ADJECTIVE, Clause, Draft, ItemKind, LocHow, MAX_DEPTH, Order, Parser, Pred, Segment,
};
use crate::translate::lexer::{Closed, Det, Prep, Wrap};
use crate::translate::lexicon::Sense;
use crate::translate::{Anchor, TranslateError};

/// One-word time adverbs that order events: alone, with no place to
/// date, they cannot be placed and are refused.
const SEQUENCE_ADVERBS: &[&str] = &[
    "later",
    "afterwards",
    "afterward",
    "eventually",
    "earlier",
    "previously",
    "subsequently",
    "finally",
];

const LONE_TIME: &str = "a time word alone says nothing the vocabulary holds: to date a place, say 'in the last frames' or 'at the end'";

impl Parser<'_> {
    /// A verb phrase said of `focus`. In a relative clause (`nested`) it
    /// stops before "and" + object phrase so that the caller can take it.
    pub(super) fn vp(&mut self, focus: Vec<usize>, nested: bool, seg: Segment) {
        // Relative clauses nest by recursion; a bound keeps absurd input
        // ("a car that that that …") from exhausting the stack.
        if self.depth >= MAX_DEPTH {
            let at = self.i;
            self.unsupported(at, "the question nests clauses too deeply");
            self.i = self.items.len();
            return;
        }
        self.depth += 1;
        self.vp_inner(focus, nested, seg);
        self.depth -= 1;
    }

    fn vp_inner(&mut self, mut focus: Vec<usize>, nested: bool, mut seg: Segment) {
        let mut negated = false;
        while !self.at_end() {
            let at = self.i;
            let Some(kind) = self.kind(at).cloned() else {
                break;
            };
            if self.comparative(&focus, negated) {
                negated = false;
                seg.copula = false;
                continue;
            }
            // "which car is (the) closest (to us)?"
            let sup = if self.first_raw(at) == "the" {
                at + 1
            } else {
                at
            };
            if let Some(rel) = self.superlative_at(sup)
                && !self.head_follows(sup + 1)
            {
                if negated {
                    self.unsupported(
                        sup,
                        "a negated superlative cannot be said: ask which one is",
                    );
                }
                self.i = sup + 1;
                if self.is_closed(self.i, Closed::Num(1))
                    || self.is_closed(self.i, Closed::HeadWord)
                {
                    self.i += 1;
                }
                self.skip_superlative_tail();
                for f in focus.clone() {
                    self.superlative(f, &rel, sup);
                }
                negated = false;
                seg.copula = false;
                continue;
            }
            match kind {
                ItemKind::Closed(c) => match c {
                    Closed::Neg => {
                        negated = !negated;
                        self.i += 1;
                    }
                    Closed::Be | Closed::CopVerb => {
                        seg.copula = true;
                        self.i += 1;
                    }
                    Closed::Stay => {
                        seg.copula = true;
                        seg.stay = true;
                        self.i += 1;
                    }
                    Closed::Temporal(Wrap::Still) if seg.copula && at + 1 == self.items.len() => {
                        // "Is the car still?" would otherwise lose its point.
                        self.unplace(
                            at,
                            "'still' alone is ambiguous: say 'standing still' or 'stopped'",
                        );
                        self.i += 1;
                    }
                    Closed::Temporal(w) => {
                        self.i += 1;
                        self.set_wrap(w, at);
                    }
                    Closed::Again => {
                        self.unsupported(
                            at,
                            "a repetition cannot be said: ask 'did it stop at any point?' or 'did it stop and then move?'",
                        );
                        self.i += 1;
                    }
                    Closed::Then => {
                        self.i += 1;
                        self.split(Order::Then, at);
                        seg = Segment::default();
                        negated = false;
                    }
                    Closed::Before | Closed::After
                        if matches!(self.first_raw(at + 1), "that" | "this") =>
                    {
                        // "and after that": then; "before that" puts the
                        // second event first, which the question does not say.
                        if self.is_closed(at, Closed::After) {
                            self.i += 2;
                            self.split(Order::Then, at);
                        } else {
                            self.unsupported(at, "'before that' orders nothing the question said before it: ask 'did A happen and then B?'");
                            self.i += 2;
                        }
                        seg = Segment::default();
                        negated = false;
                    }
                    Closed::Before | Closed::After if self.np_start(at + 1) && !nested => {
                        // "did the pedestrian cross before the truck arrived?"
                        let order = if self.is_closed(at, Closed::Before) {
                            Order::Before
                        } else {
                            Order::After
                        };
                        self.i += 1;
                        self.split(order, at);
                        if let Some(e) = self.np() {
                            self.subjects.push(e);
                            focus = vec![e];
                        }
                        seg = Segment::default();
                        negated = false;
                    }
                    Closed::Before | Closed::After => {
                        self.unsupported(
                            at,
                            "a time order needs a second event: 'before the truck arrived', 'and then stop'",
                        );
                        self.i += 1;
                    }
                    // "a car that has a pedestrian to its left"
                    Closed::Aux
                        if self.raw_is(at, &["has", "have", "had"])
                            && self.with_around(&focus, negated) =>
                    {
                        negated = false;
                    }
                    Closed::Aux
                    | Closed::Filler
                    | Closed::There
                    | Closed::Pronoun
                    | Closed::Please => self.i += 1,
                    Closed::Rel => {
                        self.i += 1;
                        let target = self.last_entity.or(focus.last().copied());
                        if let Some(t) = target {
                            self.push_clause();
                            self.vp(vec![t], true, Segment::default());
                            self.pop_clause();
                        }
                    }
                    Closed::And if self.sequence_adverb(at + 1) => {
                        // "and later stops", "and eventually stops"
                        self.i += 2;
                        self.split(Order::Then, at + 1);
                        seg = Segment::default();
                        negated = false;
                    }
                    Closed::And => {
                        if self.np_start(at + 1) {
                            if nested {
                                return;
                            }
                            self.i += 1;
                            if let Some(e) = self.np() {
                                self.subjects.push(e);
                                focus = vec![e];
                            }
                        } else {
                            self.i += 1;
                        }
                        seg = Segment::default();
                        negated = false;
                    }
                    Closed::Or => {
                        self.unsupported(at, "a conjunctive query cannot say 'or'");
                        // Read on as if it were "and", so that only the real
                        // cause is reported.
                        self.i += 1;
                        if self.np_start(self.i)
                            && let Some(e) = self.np()
                        {
                            focus = vec![e];
                        }
                    }
                    Closed::Far | Closed::Close => {
                        if !self.near_relation(&focus, negated)
                            && !self.modified_place(&focus, seg, negated)
                        {
                            self.unplace(at, "not followed by a place");
                            self.i += 1;
                        }
                        negated = false;
                    }
                    Closed::Prep(_) => {
                        if !self.pp(&focus, seg, negated) {
                            self.unplace(at, "not followed by a place, a time or an object this preposition can relate");
                            self.i += 1;
                        }
                        negated = false;
                    }
                    Closed::Time(_) if self.lone_time_adjective(at) => {
                        self.unplace(at, LONE_TIME);
                        self.i += 1;
                    }
                    Closed::Time(a) => {
                        self.i += 1;
                        self.set_time(a, at);
                    }
                    Closed::MotionVerb if self.change_of_speed(&focus, negated) => {
                        negated = false;
                    }
                    Closed::MotionVerb => {
                        seg.motion = true;
                        self.i += 1;
                    }
                    // "before the truck arrived": an arrival is an appearance.
                    Closed::AnchorVerb(_)
                        if self.first_raw(at).starts_with("arriv")
                            && !matches!(
                                self.closed_at(at + 1),
                                Some(Closed::Prep(_) | Closed::Far | Closed::Close)
                            )
                            && self.arrival(&focus, negated) =>
                    {
                        negated = false;
                    }
                    Closed::AnchorVerb(a) => {
                        seg.anchor = Some(a);
                        self.i += 1;
                        // "ends up on the right"
                        if self.first_raw(self.i) == "up" {
                            self.i += 1;
                        }
                    }
                    // "How many trucks can you see?", "… are seen?": the
                    // viewer is the camera, and being seen is being there.
                    Closed::You
                        if self.is_closed(at + 1, Closed::Perceive)
                            || (self.is_closed(at + 1, Closed::Neg)
                                && self.is_closed(at + 2, Closed::Perceive)) =>
                    {
                        self.i += 1;
                    }
                    Closed::Perceive
                        if at > 0
                            && matches!(
                                self.closed_at(at - 1),
                                Some(Closed::You | Closed::Be | Closed::Aux | Closed::Neg)
                            ) =>
                    {
                        self.i += 1;
                    }
                    Closed::Due | Closed::Because => self.explanation(),
                    Closed::Scene => self.i += 1,
                    Closed::Det(_) | Closed::Num(_) | Closed::HeadWord if self.np_start(at) => {
                        self.predicative(&focus, seg, negated);
                        negated = false;
                    }
                    Closed::Det(Det::Plain)
                        if matches!(
                            self.entry_at(self.skip_dets(at)).map(|e| &e.sense),
                            Some(Sense::Property { .. } | Sense::Relation(_))
                        ) && !self.head_follows(self.skip_dets(at)) =>
                    {
                        // "keeps a constant speed": an article before a
                        // predicate phrase.
                        self.i = self.skip_dets(at);
                    }
                    Closed::Det(Det::Plain)
                        if self.is_closed(self.skip_dets(at), Closed::Scene) =>
                    {
                        self.i = self.skip_dets(at) + 1;
                    }
                    // "enters from the right" (the phrase took "from")
                    Closed::Det(Det::Plain)
                        if matches!(
                            self.entry_at(self.skip_dets(at)).map(|e| &e.sense),
                            Some(Sense::Location(_))
                        ) =>
                    {
                        self.i = self.skip_dets(at);
                    }
                    _ => {
                        self.unplace(at, "does not fit the sentence here");
                        self.i += 1;
                    }
                },
                ItemKind::Content(entry) => {
                    match entry.sense.clone() {
                        Sense::Property { .. } if seg.copula && self.bare_of_inflected(at) => {
                            self.unplace(at, BARE_ADJECTIVE);
                            self.i += 1;
                        }
                        Sense::Property { name, anchor } => {
                            for f in &focus {
                                self.atom(&name, vec![Arg::Var(*f)], negated);
                            }
                            self.note_synonym(at);
                            self.i += 1;
                            seg.anchor = anchor.or(seg.anchor);
                            seg.motion = true;
                            if let (Some(a), Some(c)) = (anchor, self.clauses.last_mut()) {
                                c.verb_anchor = Some(a);
                            }
                            negated = false;
                            // "in the middle of the road", "at the center of
                            // the scene": a place-like property.
                            if self.is_closed(self.i, Closed::Prep(Prep::Of)) {
                                self.place_tail(at);
                            }
                        }
                        Sense::Attr { function, value } => {
                            for f in &focus {
                                self.atom(
                                    &function,
                                    vec![Arg::Var(*f), Arg::Const(value.clone())],
                                    negated,
                                );
                            }
                            self.note_synonym(at);
                            self.i += 1;
                            negated = false;
                        }
                        Sense::Relation(name) => {
                            self.relation(&name, &focus, negated);
                            negated = false;
                        }
                        Sense::Location(_)
                            if let Some(anchor) = self.left_as_leave(&focus, negated) =>
                        {
                            seg.anchor = anchor.or(seg.anchor);
                            seg.motion = true;
                            if let (Some(a), Some(c)) = (anchor, self.clauses.last_mut()) {
                                c.verb_anchor = Some(a);
                            }
                            negated = false;
                        }
                        Sense::Location(_) => {
                            self.bare_location(&focus, seg, negated);
                            negated = false;
                        }
                        Sense::Class(_) | Sense::Type { .. } => {
                            self.predicative(&focus, seg, negated);
                            negated = false;
                        }
                        Sense::ValueNoun(_) => {
                            self.unplace(
                                at,
                                "a value is asked for at the start of a question: 'What colour is the van?'",
                            );
                            self.i += 1;
                        }
                    }
                    seg.copula = false;
                }
                ItemKind::Constant => {
                    self.predicative(&focus, seg, negated);
                    negated = false;
                }
                ItemKind::Unknown => {
                    self.unplace(at, "not in the vocabulary");
                    self.i += 1;
                }
            }
        }
    }

    pub(super) fn push_clause(&mut self) {
        self.clauses.push(Clause::default());
    }

    pub(super) fn pop_clause(&mut self) {
        let Some(mut c) = self.clauses.pop() else {
            return;
        };
        let default = match c.time {
            Some(t) => c.verb_anchor.unwrap_or(t),
            None => Anchor::Initial,
        };
        let pending = c.locs.iter().any(|idx| {
            matches!(
                self.drafts.get(*idx),
                Some(Draft {
                    pred: Pred::Location {
                        how: LocHow::Clause,
                        ..
                    },
                    ..
                })
            )
        });
        if pending && let Some(last) = c.times.last_mut() {
            last.2 = true;
        }
        for (text, frames, used) in &c.times {
            // A place whose frames are already fixed the same way ("moves to
            // the left in the last frames") agrees with the time phrase.
            let agrees = c.locs.iter().any(|idx| {
                matches!(
                    self.drafts.get(*idx),
                    Some(Draft { pred: Pred::Location { how: LocHow::Fixed(a), .. }, .. }) if a == frames
                )
            });
            if !used && !agrees && SEQUENCE_ADVERBS.contains(&text.as_str()) {
                // "did the car stop later?": an order in time the grammar
                // cannot place; never dropped.
                if self.unsupported.is_none() {
                    let index = self
                        .toks
                        .iter()
                        .find(|t| t.raw == *text)
                        .map_or(0, |t| t.index);
                    self.unsupported = Some(TranslateError::Unsupported {
                        what: text.clone(),
                        index,
                        why: "a time word that orders events needs two of them: ask 'did A happen and then B?', or 'at any point'".into(),
                    });
                }
            } else if !used && !agrees {
                let n = format!(
                    "'{text}' changes nothing here: the other predicates hold over the whole window"
                );
                self.note(n);
            }
        }
        for idx in std::mem::take(&mut c.locs) {
            let Some(d) = self.drafts.get(idx) else {
                continue;
            };
            let Pred::Location { value, how, token } = &d.pred else {
                continue;
            };
            let anchor = match how {
                LocHow::Fixed(a) => *a,
                LocHow::Clause => default,
            };
            let (value, token) = (value.clone(), *token);
            match self.lex.location_function(anchor, &value) {
                Some(f) => {
                    let f = f.to_string();
                    if let Some(d) = self.drafts.get_mut(idx) {
                        d.pred = Pred::Name(f);
                        d.args.push(Arg::Const(value));
                    }
                }
                None => {
                    if self.unsupported.is_none() {
                        let frames = match anchor {
                            Anchor::Initial => "first",
                            Anchor::Last => "last",
                        };
                        self.unsupported = Some(TranslateError::Unsupported {
                            what: value.clone(),
                            index: token,
                            why: format!(
                                "the vocabulary has no location function for the {frames} frames with the value {value}"
                            ),
                        });
                    }
                }
            }
        }
    }

    /// A time phrase (items `from..self.i`): it gives its frames to the
    /// clause's places read so far that have none, and to later ones.
    pub(super) fn set_time(&mut self, a: Anchor, from: usize) {
        let text = self.raw_span(from, self.i);
        let Self {
            clauses, drafts, ..
        } = self;
        let Some(c) = clauses.last_mut() else { return };
        let frames = c.verb_anchor.unwrap_or(a);
        let mut used = false;
        for idx in &c.locs {
            if let Some(Draft {
                pred: Pred::Location { how, .. },
                ..
            }) = drafts.get_mut(*idx)
                && *how == LocHow::Clause
            {
                *how = LocHow::Fixed(frames);
                used = true;
            }
        }
        c.time = Some(a);
        c.times.push((text, frames, used));
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::query;

    #[test]
    fn a_time_phrase_decides_the_frames_of_its_clause() {
        assert_eq!(
            query("Is there a car on the left in the last frames?"),
            "TypeOf(x, Car)^LastLocation(x, Left)"
        );
        assert_eq!(
            query("Is there a car in the last frames on the left?"),
            "TypeOf(x, Car)^LastLocation(x, Left)"
        );
        // A relative clause has its own time.
        assert_eq!(
            query("Is there a car on the left that is on the right in the last frames?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)^LastLocation(x, Right)"
        );
    }
}
