//! Relations between two objects: a relation verb with its object ("gets
//! closer to the truck"), reciprocal and plural pairs ("the cars … each
//! other", "drifting apart"), and noun constructions ("the distance
//! between A and B decreases", "the speed of A changes", "the position of
//! A").

use super::{Arg, EGO_PROPERTY, Parser, Segment, TOWARD_EGO, is_change_word};
use crate::translate::lexer::{Closed, Det, Prep, stem};
use crate::translate::lexicon::{Entry, Sense, construction_noun, is_rest_filler};

impl Parser<'_> {
    pub(super) fn relation(&mut self, name: &str, focus: &[usize], negated: bool) {
        let rel_item = self.i;
        // "rides towards the truck": the verb only says that the subject
        // moves; the preposition, a relation of its own, names the relation.
        let toward = self
            .lex
            .prep_relations
            .get(self.first_raw(rel_item + 1))
            .filter(|r| *r != name);
        if self.is_closed(rel_item + 1, Closed::Prep(Prep::Toward)) && toward.is_some() {
            let motion = stem("move");
            if let Some(Entry {
                sense: Sense::Property { name: moving, .. },
                ..
            }) = self.lex.lookup(&[motion.as_str()]).cloned()
            {
                for f in focus {
                    self.atom(&moving, vec![Arg::Var(*f)], negated);
                }
                let n = format!("'{}' read as {moving}", self.raw_at(rel_item));
                self.note(n);
            }
            self.i += 1;
            return;
        }
        self.note_synonym(rel_item);
        self.i += 1;
        while matches!(
            self.closed_at(self.i),
            Some(Closed::Prep(
                Prep::To
                    | Prep::With
                    | Prep::From
                    | Prep::Into
                    | Prep::Toward
                    | Prep::Of
                    | Prep::On
            ))
        ) {
            self.i += 1;
        }
        // "each other", "one another"
        let reciprocal = (self.is_closed(self.i, Closed::Each)
            || self.is_closed(self.i, Closed::Num(1)))
            && self.is_closed(self.i + 1, Closed::Det(Det::Another));
        if reciprocal {
            self.i += 2;
        }
        if self.lex.comparatives.values().any(|c| c == name) {
            // "is the van closer?": closer than what?
            self.unplace(
                rel_item,
                "a comparison needs 'than' and another object: 'closer to us than the truck'",
            );
            return;
        }
        if !reciprocal
            && self.np_start(self.i)
            && let Some((y, scope)) = self.relation_object(negated, focus)
        {
            self.relation_atoms(name, focus, y, scope, negated);
            return;
        }
        let mut pair: Vec<usize> = self.subjects.clone();
        for f in focus {
            if !pair.contains(f) {
                pair.push(*f);
            }
        }
        if focus.len() == 2 {
            pair = focus.to_vec();
        }
        // "are the cars getting closer to each other?", "are the cyclists
        // drifting apart?": a plural subject related to itself is two
        // objects described alike. Without such words ("are the cars
        // approaching?") a relation of distance is to us (below).
        let mutual = reciprocal
            || self.items.get(rel_item).is_some_and(|it| {
                self.toks[it.start..it.end].iter().any(|t| {
                    // "did the cars collide/crash?": a collision is
                    // between the objects said, as "each other" says.
                    matches!(t.raw.as_str(), "apart" | "together")
                        || t.raw.starts_with("collid")
                        || t.raw.starts_with("crash")
                })
            });
        if mutual
            && let [one] = pair.as_slice()
            && let Some(&(_, from)) = self.plurals.iter().find(|(e, _)| e == one)
        {
            let one = *one;
            let twin = self.twin_of(one, from);
            pair.push(twin);
            self.note(
                "a plural subject related to itself read as two objects described alike; a conjunctive query cannot require them to differ"
                    .into(),
            );
        }
        if let [a, b] = pair.as_slice() {
            self.atom(name, vec![Arg::Var(*a), Arg::Var(*b)], negated);
        } else if let [a] = pair.as_slice()
            && !mutual
            && self.lex.ego
            && TOWARD_EGO.contains(&name)
        {
            // "is the blue sedan approaching?", "is the pedestrian moving
            // away?": a distance with no second object is the distance to
            // us, the camera.
            let a = *a;
            let ego = self.ego_entity();
            self.atom(name, vec![Arg::Var(a), Arg::Var(ego)], negated);
            let n = format!(
                "'{}' with no object read as relative to us (the camera): {name}(…, ego)",
                self.raw_at(rel_item)
            );
            self.note(n);
        } else if let [a] = pair.as_slice()
            && !mutual
            && self.lex.ego
            && let Some((_, property)) = EGO_PROPERTY
                .iter()
                .find(|(r, p)| *r == name && self.lex.properties.contains(*p))
        {
            // "is the car going in the opposite direction?", "driving the
            // other way": oncoming, against us.
            let a = *a;
            self.atom(property, vec![Arg::Var(a)], negated);
            let n = format!(
                "'{}' with no object read as {property} (relative to us)",
                self.raw_at(rel_item)
            );
            self.note(n);
        } else {
            self.unplace(rel_item, "this relation needs a second object");
        }
    }

    /// "the distance between ...", "the speed of ...", "the position of ...".
    pub(super) fn noun_construction_ahead(&self) -> Option<Closed> {
        let mut j = self.i;
        while matches!(self.closed_at(j), Some(Closed::Det(Det::Plain))) {
            j += 1;
        }
        let c = self.closed_at(j)?;
        let next = self.closed_at(j + 1)?;
        match (c, next) {
            (Closed::Distance, Closed::Prep(Prep::Between | Prep::From | Prep::Of)) => Some(c),
            (Closed::SpeedNoun | Closed::PositionNoun, Closed::Prep(Prep::Of)) => Some(c),
            _ => None,
        }
    }

    pub(super) fn construction(&mut self, noun: Closed) {
        while matches!(self.closed_at(self.i), Some(Closed::Det(Det::Plain))) {
            self.i += 1;
        }
        let noun_item = self.i;
        let noun_raw = self.first_raw(noun_item).to_string();
        self.i += 1; // the noun
        let prep = self.closed_at(self.i);
        self.i += 1; // between / of / from
        self.pair_ok = noun == Closed::Distance && prep == Some(Closed::Prep(Prep::Between));
        let Some(x) = self.np() else {
            let at = self.i;
            self.unplace(noun_item, "expected an object after it");
            if !self.at_end() {
                self.unplace(at, "expected an object here");
                self.i += 1;
            }
            return;
        };
        self.subjects = vec![x];
        if noun == Closed::PositionNoun {
            let seg = Segment {
                motion: true,
                ..Segment::default()
            };
            self.vp(vec![x], false, seg);
            return;
        }
        let mut focus = vec![x];
        if noun == Closed::Distance
            && let Some(y) = self.twin.take()
        {
            // "the distance between the two cars"
            focus.push(y);
            self.subjects = focus.clone();
        } else if noun == Closed::Distance {
            let joiner_ok = match prep {
                Some(Closed::Prep(Prep::Between)) => self.is_closed(self.i, Closed::And),
                _ => matches!(
                    self.closed_at(self.i),
                    Some(Closed::Prep(Prep::To | Prep::Of)) | Some(Closed::And)
                ),
            };
            if !joiner_ok {
                self.unplace(
                    noun_item,
                    "a distance needs two objects ('between A and B')",
                );
                return;
            }
            self.i += 1;
            let Some(y) = self.np() else {
                self.unplace(
                    noun_item,
                    "a distance needs two objects ('between A and B')",
                );
                return;
            };
            focus.push(y);
            self.subjects = focus.clone();
        }
        let key = construction_noun(&noun_raw).unwrap_or("distance");
        self.construction_rest(key, &focus, noun_item);
        self.vp(focus, false, Segment::default());
    }

    /// Matches the words after "the distance between A and B" (or "the
    /// speed of A") against the vocabulary's phrases that start with the noun.
    fn construction_rest(&mut self, noun: &str, focus: &[usize], noun_item: usize) {
        let start_tok = self.token_index(self.i);
        // Token positions of the meaningful rest words.
        let mut rest: Vec<(usize, String, String)> = Vec::new();
        for (k, t) in self.toks.iter().enumerate().skip(start_tok) {
            if !is_rest_filler(&t.raw) {
                rest.push((k, t.raw.clone(), t.stem.clone()));
            }
        }
        let mut negated = false;
        let mut skip = 0;
        while rest
            .get(skip)
            .is_some_and(|(_, raw, _)| matches!(raw.as_str(), "not" | "never"))
        {
            negated = !negated;
            skip += 1;
        }
        let candidates = self.lex.noun_phrases.get(noun);
        let mut best: Option<(usize, Entry, bool)> = None;
        if let Some(cands) = candidates {
            for (phrase, entry) in cands {
                for (from, neg) in [(0usize, false), (skip, negated)] {
                    let words: Vec<&str> =
                        rest.iter().skip(from).map(|(_, _, s)| s.as_str()).collect();
                    if words.len() >= phrase.len()
                        && words
                            .iter()
                            .zip(phrase.iter())
                            .all(|(a, b)| *a == b.as_str())
                        && best
                            .as_ref()
                            .is_none_or(|(l, _, _)| from + phrase.len() > *l)
                    {
                        best = Some((from + phrase.len(), entry.clone(), neg));
                    }
                }
            }
        }
        if best.is_none()
            && let [f] = focus
            && let Some((k, raw, _)) = rest.get(skip)
            && is_change_word(raw)
            && self.speed_change(*f, noun, negated)
        {
            let next_tok = k + 1;
            while self.items.get(self.i).is_some_and(|it| it.start < next_tok) {
                self.i += 1;
            }
            return;
        }
        let Some((used, entry, neg)) = best else {
            let at = self.i;
            self.unplace(noun_item, "no vocabulary phrase says what happens to it");
            if !self.at_end() {
                self.unplace(at, "no vocabulary phrase starts with these words");
                self.i += 1;
            }
            return;
        };
        // Resynchronise items with the first token after the phrase.
        let next_tok = rest
            .get(used.saturating_sub(1))
            .map_or(start_tok, |(k, _, _)| k + 1);
        while self.items.get(self.i).is_some_and(|it| it.start < next_tok) {
            self.i += 1;
        }
        let args: Vec<Arg> = focus.iter().map(|e| Arg::Var(*e)).collect();
        match &entry.sense {
            Sense::Relation(name) if focus.len() == 2 => self.atom(name, args, neg),
            Sense::Property { name, .. } if focus.len() == 1 => self.atom(name, args, neg),
            _ => {
                self.unplace(noun_item, "the phrase does not fit this many objects");
                return;
            }
        }
        if entry.synonym {
            let words: Vec<&str> = self.toks[start_tok.min(next_tok)..next_tok]
                .iter()
                .map(|t| t.raw.as_str())
                .collect();
            let n = format!(
                "'{} {}' read as {}",
                self.first_raw(noun_item),
                words.join(" "),
                entry.sense.target()
            );
            self.note(n);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::query;

    #[test]
    fn plural_pairs_leaving_and_riding_towards() {
        assert_eq!(
            query("Are the cars getting closer to each other?"),
            "TypeOf(x, Car)^TypeOf(y, Car)^GettingCloser(x, y)"
        );
        assert_eq!(
            query("Are the cyclists drifting apart?"),
            "Cyclist(x)^Cyclist(y)^GoAway(x, y)"
        );
        assert_eq!(
            query("Did the cars crash?"),
            "TypeOf(x, Car)^TypeOf(y, Car)^Collide(x, y)"
        );
        // A distance with no second object is the distance to us.
        assert_eq!(
            query("Which vehicles are approaching?"),
            "Vehicles(x)^GettingCloser(x, ego)"
        );
        assert_eq!(
            query("Is the blue sedan approaching?"),
            "TypeOf(x, Sedan)^ColorOf(x, Blue)^GettingCloser(x, ego)"
        );
        assert_eq!(
            query("Is the pedestrian moving away?"),
            "Pedestrian(x)^GoAway(x, ego)"
        );
        assert_eq!(
            query("Are the cars approaching?"),
            "TypeOf(x, Car)^GettingCloser(x, ego)"
        );
        // Any other relation still needs its object.
        assert!(query("Is the car colliding?").starts_with("ERROR"));
        assert!(query("Is the pedestrian entering?").starts_with("ERROR"));
        assert_eq!(
            query("Has the pedestrian left the scene?"),
            "Pedestrian(x)^Disappear(x)"
        );
        assert_eq!(
            query("Is there a car on the left the scene?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)"
        );
        assert_eq!(
            query("Does the cyclist ride towards the truck?"),
            "Cyclist(x)^Move(x)^TypeOf(y, Truck)^GettingCloser(x, y)"
        );
        assert_eq!(
            query("Is the pedestrian riding a bike?"),
            "Pedestrian(x)^TypeOf(y, Bicycle)^Ride(x, y)"
        );
    }
}
