//! Actions and properties said of the focus beyond a plain phrase: a
//! predicative object phrase ("is the vehicle a van?"), "left" as the past
//! of "leave", a change of speed or pace (the negation of the constant
//! predicate, bound to its class), and the camera's own movement given as
//! an explanation.

use super::{Arg, Parser, Segment, is_change_word};
use crate::translate::Anchor;
use crate::translate::lexer::{Closed, Prep, stem};
use crate::translate::lexicon::{Entry, Sense, construction_noun};

impl Parser<'_> {
    /// "Is the vehicle a van?": an object phrase after a copula describes
    /// the focus itself.
    pub(super) fn predicative(&mut self, focus: &[usize], seg: Segment, negated: bool) {
        let at = self.i;
        if !seg.copula || focus.len() != 1 {
            let start = self.i;
            if self.np().is_some() {
                let end = self.i;
                for k in start..end {
                    self.unplace(
                        k,
                        "an object phrase not connected to the rest of the question",
                    );
                }
            } else {
                self.unplace(at, "does not fit the sentence here");
                self.i += 1;
            }
            return;
        }
        let drafts_before = self.drafts.len();
        let entities_before = self.entities;
        let last = self.last_entity;
        let Some(e) = self.np() else {
            self.unplace(at, "does not fit the sentence here");
            self.i += 1;
            return;
        };
        let Some(&target) = focus.first() else { return };
        for d in self.drafts.iter_mut().skip(drafts_before) {
            for a in d.args.iter_mut() {
                if *a == Arg::Var(e) {
                    *a = Arg::Var(target);
                }
            }
            if negated {
                d.negated = !d.negated;
            }
        }
        // "Is the white car car_3?": the subject is that object.
        for c in self.constants.iter_mut() {
            if c.0 == e {
                c.0 = target;
            }
        }
        if self.entities == entities_before + 1 {
            self.entities = entities_before;
            self.last_entity = last;
        }
    }

    /// "has the car left the scene": as a verb, "left" is the past of
    /// "leave", when a vocabulary phrase "leave …" goes on with the words
    /// after it. Returns the phrase's anchor (`None` inside when it has
    /// none), or `None` when "left" is the place.
    pub(super) fn left_as_leave(
        &mut self,
        focus: &[usize],
        negated: bool,
    ) -> Option<Option<Anchor>> {
        let at = self.i;
        let it = self.items.get(at)?;
        let start = it.start;
        if it.end != start + 1 || self.toks.get(start)?.raw != "left" {
            return None;
        }
        let leave = stem("leave");
        let longest = self.lex.max_len.min(self.toks.len() - start);
        for len in (2..=longest).rev() {
            let mut stems: Vec<&str> = vec![leave.as_str()];
            stems.extend(
                self.toks[start + 1..start + len]
                    .iter()
                    .map(|t| t.stem.as_str()),
            );
            let Some(Entry {
                sense: Sense::Property { name, anchor },
                ..
            }) = self.lex.lookup(&stems).cloned()
            else {
                continue;
            };
            for f in focus {
                self.atom(&name, vec![Arg::Var(*f)], negated);
            }
            let next = start + len;
            let text = self.toks[start..next]
                .iter()
                .map(|t| t.raw.as_str())
                .collect::<Vec<_>>()
                .join(" ");
            self.note(format!("'{text}' read as {name}"));
            while self.items.get(self.i).is_some_and(|it| it.start < next) {
                self.i += 1;
            }
            return Some(anchor);
        }
        None
    }

    /// "changes (its) speed", "change pace": not at a constant speed.
    pub(super) fn change_of_speed(&mut self, focus: &[usize], negated: bool) -> bool {
        let at = self.i;
        if !is_change_word(self.first_raw(at)) {
            return false;
        }
        let j = self.skip_dets(at + 1);
        if self.closed_at(j) != Some(Closed::SpeedNoun) {
            return false;
        }
        let noun = construction_noun(self.first_raw(j)).unwrap_or("speed");
        let mut ok = !focus.is_empty();
        for f in focus {
            ok &= self.speed_change(*f, noun, negated);
        }
        if ok {
            self.i = j + 1;
        }
        ok
    }

    /// A change of speed (or pace) of `x`: the negation of the vocabulary's
    /// constant-speed predicate ("speed constant"). That predicate is
    /// defined for vehicles only (pedestrians keep a pace), so its negation
    /// is bound to the same class, else it would hold for every pedestrian,
    /// pole and building: `Vehicles(x)^¬ConstantSpeed(x)`. False when the
    /// vocabulary has no such predicate.
    pub(super) fn speed_change(&mut self, x: usize, noun: &str, negated: bool) -> bool {
        let constant = stem("constant");
        let name = self.lex.noun_phrases.get(noun).and_then(|list| {
            list.iter().find_map(|(rest, e)| match &e.sense {
                Sense::Property { name, .. } if rest.as_slice() == [constant.clone()] => {
                    Some(name.clone())
                }
                _ => None,
            })
        });
        let Some(name) = name else { return false };
        let guard = match noun {
            "pace" => "Pedestrian",
            _ => "Vehicles",
        };
        if self.lex.classes.contains(guard) {
            self.atom(guard, vec![Arg::Var(x)], false);
        }
        self.atom(&name, vec![Arg::Var(x)], !negated);
        let n = format!("a change of {noun} read as not {name}");
        self.note(n);
        true
    }

    /// "due to the camera movement": an explanation, not a condition.
    pub(super) fn explanation(&mut self) {
        let start = self.i;
        let mut j = self.i + 1;
        if matches!(self.closed_at(j), Some(Closed::Prep(Prep::To | Prep::Of))) {
            j += 1;
        }
        let mut camera = false;
        let mut motion = false;
        while let Some(it) = self.items.get(j) {
            let raw = self.toks.get(it.start).map_or("", |t| t.raw.as_str());
            match raw {
                "the" | "a" | "its" | "our" | "own" => {}
                "camera" | "ego" | "egomotion" | "vehicle" | "car" | "dashcam" | "observer" => {
                    camera = true
                }
                "movement" | "motion" | "moving" | "turning" | "turn" | "shake" | "shaking" => {
                    motion = true
                }
                _ => break,
            }
            j += 1;
        }
        if camera && motion {
            let text = self.raw_span(start, j);
            self.note(format!(
                "'{text}' explains the change; it adds no condition"
            ));
            self.i = j;
        } else {
            self.unplace(
                start,
                "only the camera's own movement can be given as an explanation",
            );
            self.i += 1;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::query;

    #[test]
    fn predicative_phrases_describe_the_subject() {
        assert_eq!(
            query("Is the vehicle a truck?"),
            "Vehicles(x)^TypeOf(x, Truck)"
        );
        assert_eq!(
            query("Is the truck not red?"),
            "TypeOf(x, Truck)^¬ColorOf(x, Red)"
        );
        // Outside a copula an object phrase cannot describe the subject.
        assert!(query("Does the car the truck?").starts_with("ERROR"));
    }

    #[test]
    fn changes_of_speed_and_bare_adjectives() {
        assert_eq!(
            query("Does the bus change its speed?"),
            "TypeOf(x, Bus)^Vehicles(x)^¬ConstantSpeed(x)"
        );
        assert_eq!(
            query("Does the speed of the taxi change?"),
            "TypeOf(x, Cab)^Vehicles(x)^¬ConstantSpeed(x)"
        );
        assert_eq!(
            query("Does the bus not change its speed?"),
            "TypeOf(x, Bus)^Vehicles(x)^ConstantSpeed(x)"
        );
        assert_eq!(
            query("Does the pedestrian change pace?"),
            "Pedestrian(x)^¬ConstantSpeed(x)"
        );
        assert_eq!(query("Is the car slowing?"), "TypeOf(x, Car)^Decelerate(x)");
        assert_eq!(query("Does the van slow?"), "TypeOf(x, Van)^Decelerate(x)");
        assert!(query("Is the car slow?").contains("'slow' is not 'slowing'"));
        assert!(query("Is there a slow car?").starts_with("ERROR"));
        assert!(query("Is the bus late?").contains("a time word alone"));
    }
}
