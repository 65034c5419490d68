//! Value questions: "what colour is the van?", "which type is the vehicle
//! on the left?", "what is the colour of the parked car?": the asked value
//! becomes a variable (`ColorOf(x, y)`), the answer its bindings.

use super::{Arg, Mode, Parser, Pred};
use crate::translate::lexer::{Closed, Prep};
use crate::translate::lexicon::Sense;

impl Parser<'_> {
    /// After "what"/"which": "colour is the van", "type of vehicle is on
    /// the left", "is the colour of the van". Returns the function whose
    /// value is asked for and the item of its noun, with the position past
    /// the asking words and `mode` set for what follows.
    pub(super) fn value_question(&mut self, mode: &mut Mode) -> Option<(String, usize, bool)> {
        let noun = |p: &Self, at: usize| match p.entry_at(at).map(|e| &e.sense) {
            Some(Sense::ValueNoun(f)) => Some(f.clone()),
            _ => None,
        };
        if let Some(f) = noun(self, self.i) {
            let at = self.i;
            self.i += 1;
            let mut of = false;
            match self.closed_at(self.i) {
                // "what type of vehicle is on the left": the object phrase
                // is the subject.
                Some(Closed::Prep(Prep::Of)) => {
                    self.i += 1;
                    of = true;
                }
                Some(Closed::Be) => {
                    self.i += 1;
                    *mode = Mode::Copular;
                }
                Some(Closed::Aux) => {
                    self.i += 1;
                    *mode = Mode::Verbal;
                }
                _ => {}
            }
            return Some((f, at, of));
        }
        // "what is the colour of the van"
        if self.is_closed(self.i, Closed::Be) {
            let j = self.skip_dets(self.i + 1);
            if let Some(f) = noun(self, j)
                && self.is_closed(j + 1, Closed::Prep(Prep::Of))
            {
                self.i = j + 2;
                return Some((f, j, false));
            }
        }
        None
    }

    /// The atom of a value question: `ColorOf(x, y)`, the answer being
    /// the binding of `y`. `of`: the noun was followed by "of" and the
    /// subject's head ("what type of car").
    pub(super) fn value_atom(
        &mut self,
        function: &str,
        at: usize,
        subject: Option<usize>,
        of: bool,
    ) {
        let Some(x) = subject else {
            self.unplace(
                at,
                "asks for a value of nothing: name the object ('What colour is the van?')",
            );
            return;
        };
        // "what type of car": the type asked for may be a finer one than
        // "car" (a sedan, a taxi), so the head's own value is not required.
        // Not "what colour is the white car": that colour is asked for.
        let mut dropped = false;
        let head_type = of && self.lex.type_functions.contains(function);
        for d in self.drafts.iter_mut() {
            if head_type
                && matches!(&d.pred, Pred::Name(n) if n == function)
                && matches!(d.args.as_slice(), [Arg::Var(v), Arg::Const(_)] if *v == x)
                && !d.negated
            {
                // Marked, not removed: clauses index their places by position.
                d.pred = Pred::Dropped;
                dropped = true;
            }
        }
        if dropped {
            self.note(format!(
                "the type named in the question is not required: '{}' asks for the type itself",
                self.raw_span(at, at + 1)
            ));
        }
        let y = self.new_entity();
        self.atom(function, vec![Arg::Var(x), Arg::Var(y)], false);
        let word = self.raw_at(at);
        self.note(format!(
            "'{word}' is asked for: the answer is the values bound to the second argument of {function}"
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::query;

    #[test]
    fn value_questions_bind_a_variable() {
        assert_eq!(
            query("What colour is the van?"),
            "TypeOf(x, Van)^ColorOf(x, y)"
        );
        assert_eq!(
            query("Which type is the vehicle on the left?"),
            "Vehicles(x)^InitialLocation(x, Left)^TypeOf(x, y)"
        );
        assert_eq!(
            query("What is the colour of the parked car?"),
            "TypeOf(x, Car)^Stopped(x)^ColorOf(x, y)"
        );
        assert_eq!(query("What colour does car_3 have?"), "ColorOf(car_3, x)");
        // "type of car" asks for a finer type than "car".
        assert_eq!(
            query("What type of car is on the left?"),
            "InitialLocation(x, Left)^TypeOf(x, y)"
        );
        // A named colour stays.
        assert_eq!(
            query("What colour is the white car?"),
            "TypeOf(x, Car)^ColorOf(x, White)^ColorOf(x, y)"
        );
        assert!(query("What colour?").starts_with("ERROR"));
        // "coloured" is still a filler, not the value noun.
        assert_eq!(
            query("Is there a white-coloured car?"),
            "TypeOf(x, Car)^ColorOf(x, White)"
        );
    }
}
