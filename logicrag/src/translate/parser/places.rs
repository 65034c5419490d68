//! Places and prepositional phrases: "on the left", "far to the right",
//! "in the last frames", "of the scene", "at a constant speed", and "to the
//! right of the pedestrian", which is a relation between two objects
//! rather than a place in the image. A place's frames (initial or last)
//! are fixed by its preposition or verb, or left to its clause.

use super::Arg;
use super::{Holder, ItemKind, LocHow, Parser, Segment, own_direction};
use crate::translate::Anchor;
use crate::translate::lexer::{Closed, Prep, stem};
use crate::translate::lexicon::{Entry, Sense};

impl Parser<'_> {
    /// Reads a prepositional phrase for `focus`; false (nothing consumed)
    /// when what follows the preposition is not a place, time, scene,
    /// manner or related object.
    pub(super) fn pp(&mut self, focus: &[usize], seg: Segment, negated: bool) -> bool {
        let prep_item = self.i;
        let Some(Closed::Prep(prep)) = self.closed_at(prep_item) else {
            return false;
        };
        if prep == Prep::With && self.with_around(focus, negated) {
            return true;
        }
        if prep == Prep::Near && self.near_relation(focus, negated) {
            return true;
        }
        let mut j = prep_item + 1;
        // "next to", "close to"
        if prep == Prep::Near && self.is_closed(j, Closed::Prep(Prep::To)) {
            j += 1;
        }
        let after = self.skip_dets(j);
        match self.kind(after).cloned() {
            Some(ItemKind::Closed(Closed::Scene)) => {
                self.i = after + 1;
                self.skip_scene_tail();
                true
            }
            Some(ItemKind::Closed(Closed::Time(a))) => {
                self.i = after + 1;
                self.skip_time_tail();
                self.set_time(a, prep_item);
                true
            }
            Some(ItemKind::Closed(Closed::AnchorVerb(a)))
                if matches!(
                    prep,
                    Prep::At | Prep::In | Prep::By | Prep::Toward | Prep::During
                ) =>
            {
                // "at the end", "at the start", "by the end of the clip"
                self.i = after + 1;
                self.skip_time_tail();
                self.set_time(a, prep_item);
                true
            }
            Some(ItemKind::Closed(Closed::Far | Closed::Close))
            | Some(ItemKind::Content(Entry {
                sense: Sense::Location(_),
                ..
            })) => {
                self.i = after;
                let modifier = match prep {
                    Prep::Near => Some("near"),
                    _ => None,
                };
                self.place(focus, prep, modifier, seg, negated, prep_item)
            }
            Some(ItemKind::Content(Entry {
                sense: Sense::Property { .. },
                ..
            })) if matches!(prep, Prep::At | Prep::With | Prep::In)
                && !self.head_follows(after + 1) =>
            {
                // manner: "at a constant speed", "in motion"
                self.i = after;
                let name = match self.entry_at(after).map(|e| e.sense.clone()) {
                    Some(Sense::Property { name, .. }) => name,
                    _ => return false,
                };
                for f in focus {
                    self.atom(&name, vec![Arg::Var(*f)], negated);
                }
                self.note_synonym(after);
                self.i = after + 1;
                // "in the middle of the road": a place-like property.
                if self.is_closed(self.i, Closed::Prep(Prep::Of)) {
                    self.place_tail(prep_item);
                }
                true
            }
            _ => {
                let raw = self.first_raw(prep_item).to_string();
                // "with a pedestrian behind it": in the holder's own frame.
                if raw == "behind"
                    && self.own_pronoun(j)
                    && self.own_frame(focus, "Behind", negated, prep_item, j + 1)
                {
                    self.i = j + 1;
                    return true;
                }
                // "near", "close to": read by `near_relation`; "next to",
                // "beside" another object say side by side, which no
                // relation holds.
                let rel = match prep {
                    Prep::Near => None,
                    _ => self.lex.prep_relations.get(&raw).cloned(),
                };
                if let Some(rel) = rel
                    && self.np_start(j)
                {
                    self.i = j;
                    if let Some((y, scope)) = self.relation_object(negated, focus) {
                        self.relation_atoms(&rel, focus, y, scope, negated);
                        return true;
                    }
                    self.i = prep_item;
                }
                false
            }
        }
    }

    /// A place after its preposition (at `self.i`: an optional near/far
    /// modifier, then a location value).
    fn place(
        &mut self,
        focus: &[usize],
        prep: Prep,
        mut modifier: Option<&'static str>,
        seg: Segment,
        negated: bool,
        prep_item: usize,
    ) -> bool {
        match self.closed_at(self.i) {
            Some(Closed::Far) => {
                modifier = Some("far");
                self.i += 1;
            }
            Some(Closed::Close) => {
                modifier = Some("near");
                self.i += 1;
            }
            _ => {}
        }
        // "far to the left", "close to the right"
        if modifier.is_some() && self.is_closed(self.i, Closed::Prep(Prep::To)) {
            self.i += 1;
        }
        self.i = self.skip_dets(self.i);
        let ours = self.i > prep_item + 1 && self.possessive_place(self.i - 1);
        let its = self.i > prep_item + 1 && self.raw_is(self.i - 1, &["its", "their"]);
        let Some(Sense::Location(value)) = self.entry_at(self.i).map(|e| e.sense.clone()) else {
            self.i = prep_item;
            return false;
        };
        let value_item = self.i;
        // "(a vehicle with a bicycle) to its right": in the holder's frame.
        if its && modifier.is_none() {
            let mut end = value_item + 1;
            while self.is_closed(end, Closed::LocSuffix) {
                end += 1;
            }
            if self.own_frame(focus, &value, negated, prep_item, end) {
                self.i = end;
                return true;
            }
        }
        // "to our left", "on my right": relative to the ego.
        if ours
            && modifier.is_none()
            && let Some(rel) = self.lex.place_relations.get(&value).cloned()
        {
            self.i = value_item + 1;
            while self.is_closed(self.i, Closed::LocSuffix) {
                self.i += 1;
            }
            let ego = self.ego_entity();
            for f in focus {
                self.atom(&rel, vec![Arg::Var(*f), Arg::Var(ego)], negated);
            }
            let n = format!(
                "'{}' read as {rel} the ego",
                self.raw_span(prep_item, self.i)
            );
            self.note(n);
            return true;
        }
        let value = match modifier {
            Some(m) => self
                .modified_location(m, value_item)
                .unwrap_or_else(|| value.clone()),
            None => value,
        };
        self.i = value_item + 1;
        if let Some(Sense::Location(base)) = self.entry_at(value_item).map(|e| e.sense.clone())
            && self.relative_place(focus, &base, modifier, negated, prep_item)
        {
            return true;
        }
        if let Some(m) = modifier
            && self.modified_location(m, value_item).is_none()
        {
            let n = format!("'{m}' has no matching location value; read as {value}");
            self.note(n);
        }
        self.note_synonym(value_item);
        let how = match prep {
            // "moves to the left" is where it ends; "a car to the left" is
            // just where it is.
            Prep::To | Prep::Toward | Prep::Into if seg.motion || seg.anchor.is_some() => {
                LocHow::Fixed(seg.anchor.unwrap_or(Anchor::Last))
            }
            Prep::From => LocHow::Fixed(seg.anchor.unwrap_or(Anchor::Initial)),
            _ => seg.anchor.map_or(LocHow::Clause, LocHow::Fixed),
        };
        let token = self.token_index(value_item);
        self.locations(focus, &value, how, seg, negated, token);
        self.place_tail(prep_item);
        true
    }

    /// After a place (at `self.i`): "of" and another object make it a
    /// relation between the two ("to the right of the pedestrian" →
    /// `RightOf(x, y)`), never a place in the image; "of the scene", "of
    /// us" leave it a place (false, nothing consumed). A vocabulary without
    /// such a relation cannot say it: the question is refused.
    fn relative_place(
        &mut self,
        focus: &[usize],
        value: &str,
        modifier: Option<&'static str>,
        negated: bool,
        from: usize,
    ) -> bool {
        let mut of = self.i;
        while self.is_closed(of, Closed::LocSuffix) {
            of += 1;
        }
        if !self.is_closed(of, Closed::Prep(Prep::Of)) {
            return false;
        }
        // "(a truck with a car) in front of it": in the holder's frame.
        if modifier.is_none()
            && self.own_pronoun(of + 1)
            && self.own_frame(focus, value, negated, from, of + 2)
        {
            self.i = of + 2;
            return true;
        }
        let k = self.skip_dets(of + 1);
        let ego = self.ego_at(of + 1).is_some();
        if (!ego && matches!(self.closed_at(k), Some(Closed::You | Closed::Scene)))
            || !self.np_start(of + 1)
        {
            return false;
        }
        let place = self.raw_span(from, of);
        let relation = self.lex.place_relations.get(value).cloned();
        let save = self.i;
        self.i = of + 1;
        let Some((y, scope)) = self.relation_object(negated, focus) else {
            self.i = save;
            return false;
        };
        let Some(relation) = relation else {
            if let Some(id) = scope {
                self.close_scope(id);
            }
            self.unsupported(
                from,
                &format!(
                    "the vocabulary has no relation for being '{place} of' another object; ask where each object is in the image ('is the car on the left?'), or declare a relation with the phrase '{place} of'"
                ),
            );
            return true;
        };
        if let Some(m) = modifier {
            self.note(format!(
                "'{m}' dropped: {relation} says where one object is relative to the other, not how far"
            ));
        }
        self.relation_atoms(&relation, focus, y, scope, negated);
        self.note(format!("'{place} of' read as {relation}"));
        true
    }

    /// "with a bicycle to its right", "(that) has a pedestrian to its
    /// left", "with a car in front of it": the object phrase after
    /// "with"/"has" (at `self.i`) is read with the focus as the owner of
    /// "its"/"it", so that its place is a direction in the focus's own
    /// frame: `InDirectionOf(bicycle, vehicle, Right)` (RefAV's "vehicle
    /// with a bicycle to its right"). False, nothing consumed, unless the
    /// vocabulary has `InDirectionOf` and such a place follows; a "with"
    /// whose object took no such place is reported.
    pub(super) fn with_around(&mut self, focus: &[usize], negated: bool) -> bool {
        let at = self.i;
        let [holder] = focus else {
            return false;
        };
        if !self.np_start(at + 1) || !self.own_frame_ahead(at + 1) {
            return false;
        }
        self.i = at + 1;
        let outer = self.holder.replace(Holder {
            entity: *holder,
            used: false,
        });
        let mut read = false;
        // "with a car in front of it and a bus behind it"
        while let Some((_, scope)) = self.relation_object(negated, focus) {
            read = true;
            if let Some(id) = scope {
                self.close_scope(id);
            }
            let next = self.i + 1;
            if !(self.is_closed(self.i, Closed::And)
                && self.np_start(next)
                && self.own_frame_ahead(next))
            {
                break;
            }
            self.i = next;
        }
        let used = self.holder.is_some_and(|h| h.used);
        self.holder = outer;
        if !read {
            self.i = at;
            return false;
        }
        if !used {
            self.unplace(
                at,
                "'with' relates another object only by where it is around this one: 'with a bicycle to its right', 'with a car in front of it'",
            );
        }
        true
    }

    /// Whether a place in the own frame of another object ("its right",
    /// "of it", "behind it") follows at or after `from`, within the clause.
    fn own_frame_ahead(&self, from: usize) -> bool {
        if !self.lex.in_direction {
            return false;
        }
        for k in from..self.items.len() {
            if matches!(
                self.closed_at(k),
                Some(Closed::And | Closed::Or | Closed::Then | Closed::Before | Closed::After)
            ) {
                return false;
            }
            let located = matches!(
                self.entry_at(k + 1).map(|e| &e.sense),
                Some(Sense::Location(v)) if own_direction(v).is_some()
            );
            if (self.raw_is(k, &["its", "their"]) && located)
                || (k > 0
                    && self.raw_is(k, &["it", "them"])
                    && (self.is_closed(k - 1, Closed::Prep(Prep::Of))
                        || self.raw_is(k - 1, &["behind"])))
            {
                return true;
            }
        }
        false
    }

    /// "it", "them": the holder of [`Self::with_around`].
    fn own_pronoun(&self, at: usize) -> bool {
        self.holder.is_some() && self.raw_is(at, &["it", "them"])
    }

    /// `InDirectionOf(f, holder, D)` for each object of the focus, the
    /// direction `D` named by the place value `location` (items `from..to`).
    /// False when there is no holder or the place names no direction.
    fn own_frame(
        &mut self,
        focus: &[usize],
        location: &str,
        negated: bool,
        from: usize,
        to: usize,
    ) -> bool {
        let (Some(h), Some(dir)) = (self.holder, own_direction(location)) else {
            return false;
        };
        if !self.lex.in_direction || focus.contains(&h.entity) {
            return false;
        }
        for f in focus {
            self.atom(
                "InDirectionOf",
                vec![
                    Arg::Var(*f),
                    Arg::Var(h.entity),
                    Arg::Const(dir.to_string()),
                ],
                negated,
            );
        }
        if let Some(h) = self.holder.as_mut() {
            h.used = true;
        }
        let n = format!(
            "'{}' read as InDirectionOf(…, {dir}): in the other object's own frame (its heading)",
            self.raw_span(from, to)
        );
        self.note(n);
        true
    }

    /// A place introduced by "far"/"close" without a preposition:
    /// "far to the left", "close to the right".
    pub(super) fn modified_place(&mut self, focus: &[usize], seg: Segment, negated: bool) -> bool {
        let start = self.i;
        let ok = self.place(focus, Prep::At, None, seg, negated, start);
        if !ok {
            self.i = start;
        }
        ok
    }

    /// A place without a preposition: "moves left", "left of the van".
    pub(super) fn bare_location(&mut self, focus: &[usize], seg: Segment, negated: bool) {
        let at = self.i;
        let Some(Sense::Location(value)) = self.entry_at(at).map(|e| e.sense.clone()) else {
            return;
        };
        // "left of the van", "ahead of the truck"
        self.i = at + 1;
        if self.relative_place(focus, &value, None, negated, at) {
            return;
        }
        self.i = at;
        let how = if seg.motion && seg.anchor.is_none() {
            LocHow::Fixed(Anchor::Last)
        } else {
            seg.anchor.map_or(LocHow::Clause, LocHow::Fixed)
        };
        let token = self.token_index(at);
        self.locations(focus, &value, how, seg, negated, token);
        self.note_synonym(at);
        self.i = at + 1;
        self.place_tail(at);
    }

    /// One place for each object of the focus; after "stay"/"remain" a place
    /// without fixed frames holds in both the first and the last frames.
    fn locations(
        &mut self,
        focus: &[usize],
        value: &str,
        how: LocHow,
        seg: Segment,
        negated: bool,
        token: usize,
    ) {
        let hows: &[LocHow] = if seg.stay && how == LocHow::Clause && !negated {
            &[LocHow::Fixed(Anchor::Initial), LocHow::Fixed(Anchor::Last)]
        } else {
            &[how]
        };
        for f in focus {
            for h in hows {
                self.location(*f, value, *h, negated, token);
            }
        }
    }

    /// "near" + "left" → `NearLeft` when the vocabulary has it.
    fn modified_location(&self, modifier: &str, value_item: usize) -> Option<String> {
        let it = self.items.get(value_item)?;
        let modifier = stem(modifier);
        let mut stems = vec![modifier.as_str()];
        stems.extend(self.toks[it.start..it.end].iter().map(|t| t.stem.as_str()));
        match self.lex.lookup(&stems) {
            Some(Entry {
                sense: Sense::Location(v),
                ..
            }) => Some(v.clone()),
            _ => None,
        }
    }

    /// After a place: "side", "of the scene", "of the white car", and the
    /// typo "on the left the scene".
    pub(super) fn place_tail(&mut self, prep_item: usize) {
        while self.is_closed(self.i, Closed::LocSuffix) {
            self.i += 1;
        }
        let j = self.skip_dets(self.i);
        if self.is_closed(j, Closed::Scene) {
            self.i = j + 1;
            self.skip_scene_tail();
            return;
        }
        if self.is_closed(self.i, Closed::Prep(Prep::Of)) {
            let k = self.skip_dets(self.i + 1);
            if self.is_closed(k, Closed::You) {
                // "in front of us": places are already seen from the camera.
                self.i = k + 1;
            } else if self.is_closed(k, Closed::Scene) {
                self.i = k + 1;
                self.skip_scene_tail();
            } else if self.np_start(self.i + 1) {
                let place = self.raw_span(prep_item, self.i);
                self.i += 1;
                let before = self.i;
                if let Some(_y) = self.np() {
                    let other = self.raw_span(before, self.i);
                    self.note(format!(
                        "'{place} of {other}' read as a place in the scene and a second object: the vocabulary has no relative-position predicate"
                    ));
                }
            }
        }
    }

    fn skip_scene_tail(&mut self) {
        // "of the video", "in view"
        loop {
            let j = self.skip_dets(self.i + 1);
            if matches!(
                self.closed_at(self.i),
                Some(Closed::Prep(Prep::Of | Prep::In))
            ) && self.is_closed(j, Closed::Scene)
            {
                self.i = j + 1;
            } else {
                return;
            }
        }
    }

    fn skip_time_tail(&mut self) {
        while matches!(
            self.closed_at(self.i),
            Some(Closed::Few | Closed::Scene | Closed::Time(_))
        ) {
            self.i += 1;
        }
        self.skip_scene_tail();
    }
}

#[cfg(test)]
mod tests {
    use super::super::tests::query;
    use crate::translate::{TranslateError, Translator, Vocabulary};

    #[test]
    fn prepositions_and_verbs_fix_frames() {
        assert_eq!(
            query("Does the car move to the left?"),
            "TypeOf(x, Car)^Move(x)^LastLocation(x, Left)"
        );
        assert_eq!(
            query("Does the car move from the left?"),
            "TypeOf(x, Car)^Move(x)^InitialLocation(x, Left)"
        );
        assert_eq!(
            query("Does the car disappear from the left?"),
            "TypeOf(x, Car)^Disappear(x)^LastLocation(x, Left)"
        );
        assert_eq!(
            query("Does the car appear from the left?"),
            "TypeOf(x, Car)^Appear(x)^InitialLocation(x, Left)"
        );
        // The verb's own frames beat a time phrase that dates the event.
        assert_eq!(
            query("Does the car on the left appear in the last frames?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)^Appear(x)"
        );
        assert_eq!(
            query("Does the car stay on the left?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)^LastLocation(x, Right)"
                .replace("Right", "Left")
        );
    }

    #[test]
    fn a_place_with_another_object_is_a_relation() {
        assert_eq!(
            query("Which vehicles are to the right of the pedestrian?"),
            "Vehicles(x)^Pedestrian(y)^RightOf(x, y)"
        );
        assert_eq!(
            query("Is the car on the left side of the truck?"),
            "TypeOf(x, Car)^TypeOf(y, Truck)^LeftOf(x, y)"
        );
        assert_eq!(
            query("Is the cyclist ahead of the bus?"),
            "Cyclist(x)^TypeOf(y, Bus)^InFrontOf(x, y)"
        );
        // Negated: the other object is local to the negation.
        assert_eq!(
            query("Is the car not to the left of the truck?"),
            "TypeOf(x, Car)^¬∃y: (TypeOf(y, Truck)^LeftOf(x, y))"
        );
        // The scene keeps the place; "us" is the ego.
        assert_eq!(
            query("Is there a car on the left of the scene?"),
            "TypeOf(x, Car)^InitialLocation(x, Left)"
        );
        assert_eq!(
            query("Is the car in front of us?"),
            "TypeOf(x, Car)^InFrontOf(x, ego)"
        );
        // Without the relation in the vocabulary: refused, never weakened.
        let v = Vocabulary::builder()
            .function("TypeOf", &[("Car", &[]), ("Van", &[])])
            .function("InitialLocation", &[("Left", &[])])
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let t = Translator::new(v);
        assert!(matches!(
            t.translate("Is the car on the left of the van?"),
            Err(TranslateError::Unsupported { .. })
        ));
        assert_eq!(
            t.translate("Is the car on the left?").map(|t| t.query),
            Ok("TypeOf(x, Car)^InitialLocation(x, Left)".to_string())
        );
    }
}
