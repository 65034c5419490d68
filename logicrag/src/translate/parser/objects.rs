//! Object phrases: determiners and numbers ("the", "any", "another", "the
//! two"), adjectives (colours, attributive properties), the head noun (a
//! class, a type, "one", a pronoun, an object constant such as `car_3`)
//! and its post-modifiers (places, times, relative and participle clauses).

use super::{Arg, BARE_ADJECTIVE, ItemKind, MAX_DEPTH, Mode, Parser, Pred, Segment};
use crate::translate::lexer::{Closed, Det, Prep};
use crate::translate::lexicon::{Entry, Sense};

impl Parser<'_> {
    /// Does an object phrase start at `at`?
    pub(super) fn np_start(&self, at: usize) -> bool {
        if self.ego_at(at).is_some() {
            return true;
        }
        if let Some((_, _, len)) = self.quantifier(at) {
            return self.np_start(at + len);
        }
        if self.denial_ahead(at)
            && (matches!(self.first_raw(at), "nobody" | "noone" | "nothing")
                || (self.first_raw(at) == "none" && self.is_closed(at + 1, Closed::Prep(Prep::Of)))
                || (self.first_raw(at) == "no" && self.first_raw(at + 1) == "one"))
        {
            return true;
        }
        let mut j = at;
        let mut saw_det = false;
        let mut saw_adjective = false;
        loop {
            if self.superlative_at(j).is_some() {
                saw_adjective = true;
                j += 1;
                continue;
            }
            match self.kind(j) {
                // "the red one"
                Some(ItemKind::Closed(Closed::Num(1))) if saw_adjective => return true,
                Some(ItemKind::Closed(Closed::Det(_) | Closed::Num(_) | Closed::Rel))
                    if !saw_det || j > at =>
                {
                    saw_det = true;
                    j += 1;
                }
                Some(ItemKind::Closed(Closed::Neg)) => j += 1,
                Some(ItemKind::Content(e)) => match e.sense {
                    Sense::Class(_) | Sense::Type { .. } => return true,
                    Sense::Attr { .. } | Sense::Property { .. } => {
                        saw_adjective = true;
                        j += 1
                    }
                    _ => return false,
                },
                Some(ItemKind::Closed(Closed::HeadWord | Closed::Pronoun)) => return true,
                Some(ItemKind::Constant) => return true,
                _ => return false,
            }
        }
    }

    /// The subjects of a question: object phrases joined by "and". Each is
    /// recorded in `subjects` as soon as it is read, so that a participle
    /// after the second ("and the van getting closer") can relate the two.
    pub(super) fn np_list(&mut self, mode: Mode) -> Vec<usize> {
        let mut out = Vec::new();
        // "Are the car and the van moving?": the predicate is said of all
        // subjects, so no participle attaches to the nearest one alone.
        self.no_participles = mode != Mode::Existential;
        self.pair_ok = true;
        let first = self.np();
        self.pair_ok = false;
        let Some(e) = first else {
            self.no_participles = false;
            return out;
        };
        out.push(e);
        self.subjects.push(e);
        if let Some(y) = self.twin.take() {
            out.push(y);
            self.subjects.push(y);
        }
        while self.is_closed(self.i, Closed::And) && self.np_start(self.i + 1) {
            let save = self.i;
            self.i += 1;
            match self.np() {
                Some(e) => {
                    out.push(e);
                    self.subjects.push(e);
                }
                None => {
                    self.i = save;
                    break;
                }
            }
        }
        self.no_participles = false;
        out
    }

    /// Parses an object phrase and returns its entity, or `None` (with the
    /// position unchanged) when no object phrase starts here.
    pub(super) fn np(&mut self) -> Option<usize> {
        if self.depth >= MAX_DEPTH {
            let at = self.i;
            self.unsupported(at, "the question nests object phrases too deeply");
            self.i = self.items.len();
            return None;
        }
        self.depth += 1;
        let e = self.np_inner();
        self.depth -= 1;
        e
    }

    fn np_inner(&mut self) -> Option<usize> {
        let save = self.i;
        let mut pair_at: Option<usize> = None;
        // Only this phrase may be a pair, not the phrases nested in it.
        let pair_ok = std::mem::take(&mut self.pair_ok);
        let drafts_save = self.drafts.len();
        let mut another = false;
        if let Some(end) = self.ego_at(self.i) {
            self.i = end;
            let e = self.ego_entity();
            return Some(e);
        }
        let mut count: Option<(&'static str, u32, usize)> = None;
        let mut denied: Option<usize> = None;
        let mut head_class: Option<String> = None;
        let mut superlative: Option<(String, usize)> = None;
        loop {
            if let Some((op, n, len)) = self.quantifier(self.i) {
                let token = self.token_index(self.i);
                if count.is_none() {
                    count = Some((op, n, token));
                }
                self.i += len;
                continue;
            }
            if let Some(Closed::Temporal(w)) = self.closed_at(self.i) {
                // "is there still a truck?", "was there ever a truck?"
                let at = self.i;
                self.i += 1;
                self.set_wrap(w, at);
                continue;
            }
            if let Some(rel) = self.superlative_at(self.i)
                && self.head_follows(self.i + 1)
            {
                superlative = Some((rel, self.i));
                self.i += 1;
                continue;
            }
            match self.closed_at(self.i) {
                Some(Closed::Det(Det::Plain)) | Some(Closed::What) => self.i += 1,
                Some(Closed::Rel) if matches!(self.first_raw(self.i), "that" | "which") => {
                    self.i += 1
                }
                Some(Closed::Det(Det::Another)) => {
                    another = true;
                    self.i += 1;
                }
                Some(Closed::Det(Det::All)) => {
                    let at = self.i;
                    self.unsupported(
                        at,
                        "a question about every object is not read by the grammar: ask whether any one is not so ('is any pedestrian not walking?'), or write the universal query `∀x: Pedestrian(x) → Walk(x)`",
                    );
                    self.i += 1;
                }
                Some(Closed::Det(Det::No)) => {
                    let at = self.i;
                    denied = Some(self.token_index(at));
                    self.i += 1;
                    if let Some(c) = self.denied_head(at) {
                        head_class = Some(c);
                    } else if self.first_raw(at) == "nothing" {
                        head_class = Some(String::new());
                    }
                    if head_class.is_some() {
                        break;
                    }
                }
                Some(Closed::Num(2))
                    if pair_ok && matches!(self.first_raw(self.i), "two" | "2" | "both") =>
                {
                    pair_at = Some(self.token_index(self.i));
                    self.i += 1;
                }
                Some(Closed::Num(n)) if n >= 2 => {
                    let at = self.i;
                    self.unsupported(at, "a bare number is ambiguous: ask 'at least two', 'exactly two', 'more than two' or 'how many'");
                    self.i += 1;
                }
                Some(Closed::Num(_)) if self.np_start(self.i + 1) => self.i += 1,
                _ => break,
            }
        }
        if self.is_closed(self.i, Closed::Pronoun)
            && let Some(e) = self.last_entity
        {
            self.i += 1;
            return Some(e);
        }
        if matches!(self.kind(self.i), Some(ItemKind::Constant)) {
            let name = self.first_raw(self.i).to_string();
            self.i += 1;
            let e = self.new_entity();
            self.constants.push((e, name));
            self.postmods(e);
            return Some(e);
        }
        let e = self.entities;
        let mut adjectives = 0;
        let mut head = false;
        if let Some(class) = head_class.take() {
            // "nobody", "no one" (a person), "nothing" (anything)
            if !class.is_empty() {
                self.defining_atom(&class, vec![Arg::Var(e)]);
            }
            let e = self.new_entity();
            self.np_spans.push((e, drafts_save, self.drafts.len()));
            if let Some(t) = denied {
                self.denied.push((e, t));
            }
            self.postmods(e);
            return Some(e);
        }
        // Adjectives: colours and attributive properties ("moving", "parked").
        loop {
            let at = self.i;
            let neg = self.is_closed(at, Closed::Neg);
            let at_word = if neg { at + 1 } else { at };
            match self.entry_at(at_word).map(|e| e.sense.clone()) {
                Some(Sense::Attr { function, value }) if !neg => {
                    self.defining_atom(&function, vec![Arg::Var(e), Arg::Const(value)]);
                    self.note_synonym(at_word);
                    adjectives += 1;
                    self.i = at_word + 1;
                }
                Some(Sense::Property { .. })
                    if self.head_follows(at_word + 1) && self.bare_of_inflected(at_word) =>
                {
                    self.unplace(at_word, BARE_ADJECTIVE);
                    self.i = at_word + 1;
                }
                Some(Sense::Property { name, .. }) if self.head_follows(at_word + 1) => {
                    self.atom(&name, vec![Arg::Var(e)], neg);
                    self.note_synonym(at_word);
                    adjectives += 1;
                    self.i = at_word + 1;
                }
                // "a white-colored car", "a really white car"
                _ if !neg && self.is_closed(at, Closed::Filler) && self.head_follows(at + 1) => {
                    self.i = at + 1;
                }
                _ => break,
            }
        }
        // The head's atom goes before the adjectives' (the reference order:
        // `TypeOf(x, Car)^ColorOf(x, White)`).
        let plural = self.plural_noun(self.i);
        match self.entry_at(self.i).map(|e| e.sense.clone()) {
            Some(Sense::Class(name)) => {
                self.defining_atom(&name, vec![Arg::Var(e)]);
                self.head_first(drafts_save);
                self.note_synonym(self.i);
                self.i += 1;
                head = true;
            }
            Some(Sense::Type { function, value }) => {
                self.defining_atom(&function, vec![Arg::Var(e), Arg::Const(value)]);
                self.head_first(drafts_save);
                self.note_synonym(self.i);
                self.i += 1;
                head = true;
            }
            _ => {
                if self.is_closed(self.i, Closed::HeadWord)
                    || self.is_closed(self.i, Closed::Num(1))
                {
                    self.i += 1;
                    head = true;
                } else if matches!(self.kind(self.i), Some(ItemKind::Unknown))
                    && (self.i > save || adjectives > 0)
                {
                    // "a pedestrain on the left": report the unknown noun and
                    // read on as if it were one, so that only it is reported.
                    let at = self.i;
                    self.unplace(at, "not in the vocabulary");
                    self.i += 1;
                    head = true;
                }
            }
        }
        if !head && adjectives == 0 {
            self.i = save;
            self.drafts.truncate(drafts_save);
            return None;
        }
        let e = self.new_entity();
        if plural && head {
            self.plurals.push((e, drafts_save));
        }
        if another {
            self.note("'another'/'other' introduces a separate object variable".into());
        }
        if let Some((op, n, token)) = count {
            self.set_count(e, op, n, token);
        }
        if let Some(t) = denied {
            self.denied.push((e, t));
        }
        // The phrase's own drafts, post-modifiers included once read (a
        // superlative ranks the objects described alike).
        let span = self.np_spans.len();
        self.np_spans.push((e, drafts_save, usize::MAX));
        self.postmods(e);
        if let Some(s) = self.np_spans.get_mut(span) {
            s.2 = self.drafts.len();
        }
        if let Some((rel, at)) = superlative {
            self.superlative(e, &rel, at);
        }
        if let Some(token) = pair_at {
            let y = self.twin_of(e, drafts_save);
            self.twin = Some(y);
            self.pairs.push((e, y, token));
            let word = self.toks.get(token).map_or("two", |t| t.raw.as_str());
            let n = format!(
                "'{word}' read as two objects described alike; a conjunctive query cannot require them to differ"
            );
            self.note(n);
        }
        Some(e)
    }

    /// Whether the noun at `at` is plural ("cars", "people"): its last word
    /// is an inflected form ending in "s", or an irregular plural.
    fn plural_noun(&self, at: usize) -> bool {
        let Some(it) = self.items.get(at) else {
            return false;
        };
        if !matches!(
            it.kind,
            ItemKind::Content(Entry {
                sense: Sense::Class(_) | Sense::Type { .. },
                ..
            })
        ) {
            return false;
        }
        let Some(t) = it.end.checked_sub(1).and_then(|k| self.toks.get(k)) else {
            return false;
        };
        matches!(t.raw.as_str(), "people" | "men" | "women" | "children")
            || (t.raw != t.stem && t.raw.ends_with('s'))
    }

    /// A second object described like `e` ("the two cars"): copies the
    /// drafts from `from` on that mention `e`.
    pub(super) fn twin_of(&mut self, e: usize, from: usize) -> usize {
        let y = self.new_entity();
        let end = self.drafts.len();
        for k in from..end {
            let Some(d) = self.drafts.get(k) else {
                continue;
            };
            if !d.args.contains(&Arg::Var(e)) {
                continue;
            }
            let mut copy = d.clone();
            for a in copy.args.iter_mut() {
                if *a == Arg::Var(e) {
                    *a = Arg::Var(y);
                }
            }
            let pending = matches!(copy.pred, Pred::Location { .. });
            let idx = self.drafts.len();
            self.drafts.push(copy);
            if pending && let Some(c) = self.clauses.last_mut() {
                c.locs.push(idx);
            }
        }
        y
    }

    /// Moves the last draft to position `at`.
    fn head_first(&mut self, at: usize) {
        if let Some(d) = self.drafts.pop() {
            let at = at.min(self.drafts.len());
            self.drafts.insert(at, d);
        }
    }

    /// After attributive words, is there a head noun?
    pub(super) fn head_follows(&self, mut at: usize) -> bool {
        loop {
            match self.kind(at) {
                Some(ItemKind::Content(e)) => match e.sense {
                    Sense::Class(_) | Sense::Type { .. } => return true,
                    Sense::Attr { .. } | Sense::Property { .. } => at += 1,
                    _ => return false,
                },
                Some(ItemKind::Closed(Closed::HeadWord)) => return true,
                _ => return false,
            }
        }
    }

    /// Post-modifiers of an object phrase: places, times, scene words,
    /// prepositional relations, relative and participle clauses.
    fn postmods(&mut self, e: usize) {
        let seg = Segment::default();
        loop {
            let at = self.i;
            match self.kind(at).cloned() {
                Some(ItemKind::Closed(Closed::Prep(_))) => {
                    if !self.pp(&[e], seg, false) {
                        return;
                    }
                }
                Some(ItemKind::Closed(Closed::Time(_))) if self.lone_time_adjective(at) => return,
                Some(ItemKind::Closed(Closed::Time(a))) => {
                    self.i += 1;
                    self.set_time(a, at);
                }
                Some(ItemKind::Closed(Closed::Filler)) => self.i += 1,
                Some(ItemKind::Closed(Closed::Far | Closed::Close)) => {
                    if !self.near_relation(&[e], false) && !self.modified_place(&[e], seg, false) {
                        return;
                    }
                }
                // "the car closest to us"
                _ if self.superlative_at(at).is_some() => {
                    let Some(rel) = self.superlative_at(at) else {
                        return;
                    };
                    self.i += 1;
                    self.skip_superlative_tail();
                    self.superlative(e, &rel, at);
                }
                Some(ItemKind::Closed(Closed::Rel)) => {
                    self.i += 1;
                    self.push_clause();
                    self.vp(vec![e], true, Segment::default());
                    self.pop_clause();
                    return;
                }
                Some(ItemKind::Content(entry)) => match entry.sense {
                    Sense::Location(_) if self.is_closed(at + 1, Closed::Prep(Prep::Of)) => {
                        // "left of the van"
                        self.bare_location(&[e], seg, false);
                    }
                    Sense::Property { .. } | Sense::Relation(_)
                        if self.participle(at) && !self.no_participles =>
                    {
                        self.vp(vec![e], true, Segment::default());
                        return;
                    }
                    _ => return,
                },
                _ => return,
            }
        }
    }

    fn participle(&self, at: usize) -> bool {
        let w = self.first_raw(at);
        w.ends_with("ing") || w.ends_with("ed") || matches!(w, "stationary" | "halted")
    }
}
