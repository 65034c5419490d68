//! Opening frames and the question as a whole: "is there", "can you
//! spot", "does", "is", "what"/"which", polite lead-ins ("can you tell me
//! whether"), and the reading of what follows as subjects and a verb phrase.

use super::{ItemKind, Mode, Parser, Segment};
use crate::translate::lexer::Closed;

impl Parser<'_> {
    pub(super) fn question(&mut self) {
        self.push_clause();
        let mut mode = self.opening();
        let value = if self.wh_open {
            self.value_question(&mut mode)
        } else {
            None
        };
        // "which is the fastest vehicle?"
        if value.is_none()
            && self.wh_open
            && self.is_closed(self.i, Closed::Be)
            && self.np_start(self.i + 1)
        {
            self.i += 1;
            mode = Mode::Copular;
        }
        if value.is_none()
            && let Some(c @ (Closed::Distance | Closed::SpeedNoun | Closed::PositionNoun)) =
                self.noun_construction_ahead()
        {
            self.construction(c);
        } else {
            let mut subjects = self.np_list(mode);
            // "is no pedestrian on the road?", "are there no trucks?": the
            // whole question is denied.
            if let Some(&(_, t)) = self.denied.iter().find(|(e, _)| subjects.contains(e)) {
                self.deny = Some(t);
                self.denied.retain(|(e, _)| !subjects.contains(e));
            }
            if subjects.is_empty() && !self.at_end() {
                let at = self.i;
                let unknown = matches!(self.kind(at), Some(ItemKind::Unknown));
                if unknown {
                    self.unplace(at, "not in the vocabulary");
                } else {
                    self.unplace(
                        at,
                        "expected an object here (a noun such as 'car' or 'pedestrian')",
                    );
                }
                self.i += 1;
                if unknown {
                    // Read on with a stand-in subject so that only the unknown
                    // word is reported ("Is ther a car?").
                    subjects.push(self.new_entity());
                }
            }
            let seg = Segment {
                copula: mode == Mode::Copular,
                ..Segment::default()
            };
            let first = subjects.first().copied();
            self.vp(subjects, false, seg);
            if let Some((function, at, of)) = value {
                self.value_atom(&function, at, first, of);
            }
        }
        // Whatever the verb phrase could not take.
        while !self.at_end() {
            let at = self.i;
            self.unplace(at, "does not fit the sentence here");
            self.i += 1;
        }
        self.pop_clause();
    }

    /// Skips a polite or indirect lead-in ("is it true that", "tell me
    /// whether"); the rest is read as a question or a statement.
    fn lead_in(&mut self) {
        const LEAD_INS: &[&[&str]] = &[
            &["can", "you", "tell", "me", "if"],
            &["can", "you", "tell", "me", "whether"],
            &["could", "you", "tell", "me", "if"],
            &["could", "you", "tell", "me", "whether"],
            &["do", "you", "know", "if"],
            &["do", "you", "know", "whether"],
            &["is", "it", "the", "case", "that"],
            &["is", "it", "true", "that"],
            &["tell", "me", "if"],
            &["tell", "me", "whether"],
            &["check", "if"],
            &["check", "whether"],
            &["i", "wonder", "if"],
            &["i", "wonder", "whether"],
        ];
        let start = self.token_index(self.i);
        let rest = &self.toks[start.min(self.toks.len())..];
        if let Some(p) = LEAD_INS
            .iter()
            .find(|p| p.len() < rest.len() && p.iter().zip(rest).all(|(w, t)| *w == t.raw))
        {
            let next = start + p.len();
            while self.items.get(self.i).is_some_and(|it| it.start < next) {
                self.i += 1;
            }
        }
    }

    /// Reads the opening frame and returns the question's mode.
    fn opening(&mut self) -> Mode {
        while matches!(
            self.closed_at(self.i),
            Some(Closed::Please | Closed::Filler)
        ) {
            self.i += 1;
        }
        self.lead_in();
        let c0 = self.closed_at(self.i);
        let c1 = self.closed_at(self.i + 1);
        let c2 = self.closed_at(self.i + 2);
        match (c0, c1, c2) {
            (Some(Closed::What), _, _) => {
                self.i += 1;
                self.wh_open = true;
                Mode::Existential
            }
            (Some(Closed::Rel), _, _) if self.first_raw(self.i) == "which" => {
                self.i += 1;
                self.wh_open = true;
                Mode::Existential
            }
            (Some(Closed::How), Some(Closed::Num(_)), _)
                if self.first_raw(self.i + 1) == "many" =>
            {
                self.i += 2;
                self.counts = true;
                self.note("'how many' is answered by the number of distinct bindings".into());
                Mode::Existential
            }
            (Some(Closed::How | Closed::OtherWh), _, _) => {
                let at = self.i;
                self.unsupported(
                    at,
                    "only yes/no and 'which' questions become conjunctive queries",
                );
                self.i += 1;
                Mode::Existential
            }
            (Some(Closed::Be), Some(Closed::There), _) => {
                self.i += 2;
                Mode::Existential
            }
            (Some(Closed::Be), Some(Closed::Neg), Some(Closed::There)) => {
                self.i += 3;
                self.note("negative question read as the positive one".into());
                Mode::Existential
            }
            (Some(Closed::There), Some(Closed::Be), _) => {
                self.i += 2;
                Mode::Existential
            }
            // "did we stop?": the ego is the subject.
            (Some(Closed::Aux), Some(Closed::You), _) if self.ego_at(self.i + 1).is_some() => {
                self.i += 1;
                Mode::Verbal
            }
            (Some(Closed::Aux), Some(Closed::You), _) => {
                self.i += 2;
                if self.is_closed(self.i, Closed::Neg) {
                    self.i += 1;
                    self.note("negative question read as the positive one".into());
                }
                if self.is_closed(self.i, Closed::Perceive) {
                    self.i += 1;
                    Mode::Existential
                } else {
                    let at = self.i;
                    self.unplace(at, "expected a verb of seeing ('see', 'spot', 'find')");
                    self.i += 1;
                    Mode::Existential
                }
            }
            (Some(Closed::Perceive), _, _) => {
                self.i += 1;
                if self.is_closed(self.i, Closed::You) {
                    self.i += 1;
                }
                Mode::Existential
            }
            (Some(Closed::Be), _, _) => {
                self.i += 1;
                if self.is_closed(self.i, Closed::Neg) {
                    self.i += 1;
                    self.note("negative question read as the positive one".into());
                }
                Mode::Copular
            }
            (Some(Closed::Aux), _, _) => {
                self.i += 1;
                if self.is_closed(self.i, Closed::Neg) {
                    self.i += 1;
                    self.note("negative question read as the positive one".into());
                }
                Mode::Verbal
            }
            _ => Mode::Existential,
        }
    }
}
