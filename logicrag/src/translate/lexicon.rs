//! The compiled vocabulary: every phrase of a [`Vocabulary`] keyed by its
//! stems, with the senses the grammar reads (class, type, attribute,
//! location, property, relation, value noun) and the side tables it needs:
//! prepositions of relations, "distance …" constructions, places of
//! relations ("to the left of"), inflected-only words, spelling words.
//!
//! A [`Lexicon`] is built once per [`Translator`](super::Translator) and
//! never changes; the parser only reads it.

use std::collections::{BTreeSet, HashMap, HashSet};

use super::lexer;
use super::vocab::{Anchor, FunctionRole, PredicateRole, Vocabulary, default_phrase};

/// What a lexicon phrase means.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) enum Sense {
    Class(String),
    Type {
        function: String,
        value: String,
    },
    Attr {
        function: String,
        value: String,
    },
    Location(String),
    Property {
        name: String,
        anchor: Option<Anchor>,
    },
    Relation(String),
    /// A noun that asks for a function's value: "colour" in "What colour
    /// is the van?" → `ColorOf(x, y)`.
    ValueNoun(String),
}

impl Sense {
    pub(crate) fn target(&self) -> &str {
        match self {
            Sense::Class(n) | Sense::Relation(n) | Sense::Location(n) | Sense::ValueNoun(n) => n,
            Sense::Property { name, .. } => name,
            Sense::Type { value, .. } | Sense::Attr { value, .. } => value,
        }
    }
}

/// A lexicon entry: a sense and whether its phrase differs from the name's
/// own words (then the translation notes the reading).
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Entry {
    pub sense: Sense,
    pub synonym: bool,
}

/// The compiled vocabulary: phrases keyed by their stems.
///
/// Invariant: every key is non-empty and at most `max_len` stems long; a
/// one-word phrase that is a closed-class word is never a key (it would
/// shadow the grammar) and is listed in `skipped` instead, except a
/// preposition of a relation, which goes to `prep_relations`, and a
/// generic head word of a class ("someone"), which is a key and listed in
/// `closed_forms`. A relation phrase made of a place and "of" ("to the
/// left of") is no key either: it is in `place_relations`. No class or
/// type phrase ends with a verb phrase ("person walking").
#[derive(Debug, Clone)]
pub(crate) struct Lexicon {
    /// Phrases keyed by the ids of their stems (see `stem_ids`).
    pub phrases: HashMap<Vec<u32>, Entry>,
    /// Every stem of every phrase, numbered.
    pub stem_ids: HashMap<String, u32>,
    pub max_len: usize,
    /// "on" → `On`: a preposition followed by an object phrase.
    pub prep_relations: HashMap<String, String>,
    /// "distance" → [(["increas"], DistanceIncrease), ...]: phrases that
    /// start with a noun taking "of"/"between" complements.
    pub noun_phrases: HashMap<String, Vec<(Vec<String>, Entry)>>,
    /// Location function per anchor, with its declared values.
    pub locations: Vec<(Anchor, String, BTreeSet<String>)>,
    pub skipped: Vec<String>,
    /// Every content word of every phrase, for spelling suggestions.
    pub words: BTreeSet<String>,
    /// Words known only inside a longer phrase: "light" → "traffic light".
    pub part_of: HashMap<String, String>,
    /// Location value → the relation of being there relative to another
    /// object: `Left` → `LeftOf` (from the phrase "to the left of").
    pub place_relations: HashMap<String, String>,
    /// One-word keys written only as "-ing" forms ("slowing"): they match
    /// an inflected word ("slowing", "slows"), not the bare one ("slow"),
    /// which is an adjective about speed, not a change of it.
    pub inflected_only: HashSet<Vec<u32>>,
    /// One-word keys some phrase wrote bare ("walk"): never inflected-only.
    bare_keys: HashSet<Vec<u32>>,
    /// Closed-class words that a vocabulary phrase claims as a whole
    /// ("someone" for `IsPerson`); any other closed word keeps its grammar
    /// reading even when its stem matches a phrase ("coloured" ≠ "colour").
    pub closed_forms: HashSet<String>,
    /// Names of the class predicates.
    pub classes: BTreeSet<String>,
    /// Names of the functions whose values are nouns (`TypeOf`).
    pub type_functions: BTreeSet<String>,
    /// Names of the property predicates (`Oncoming`).
    pub properties: BTreeSet<String>,
    /// The vocabulary has `InDirectionOf(x, y, direction)` (360° sources):
    /// "a vehicle with a bicycle to its right" is
    /// `InDirectionOf(bicycle, vehicle, Right)`, in the vehicle's own frame.
    pub in_direction: bool,
    /// The vocabulary has the ego (a predicate `Ego`): "we", "us", "our
    /// car" are the constant `ego`.
    pub ego: bool,
    /// Comparatives: "closer" → `Closer`, from a relation's phrase "closer
    /// than" (or a one-word phrase of a comparison relation); read only
    /// with "than" and another object.
    pub comparatives: HashMap<String, String>,
    /// Superlatives made from the comparatives: "closest" → `Closer`.
    pub superlatives: HashMap<String, String>,
    /// Property → the classes it is defined for (`Cross` → `Pedestrian`),
    /// from the LogicPad's rules ([`Vocabulary::guards`]).
    pub guards: HashMap<String, Vec<String>>,
}

/// Relations that compare two objects: their one-word phrases are
/// comparatives ("closer") even without "than" in the phrase.
const COMPARISONS: &[&str] = &["Closer", "Farther", "Faster", "Slower"];

/// Raw words dropped from the rest of a "distance ..."/"speed ..." phrase:
/// copulas and articles say nothing about which relation is meant.
pub(crate) fn is_rest_filler(raw: &str) -> bool {
    matches!(
        raw,
        "remain"
            | "remains"
            | "remained"
            | "remaining"
            | "stay"
            | "stays"
            | "stayed"
            | "staying"
            | "keep"
            | "keeps"
            | "keeping"
            | "be"
            | "is"
            | "are"
            | "was"
            | "were"
            | "been"
            | "being"
            | "get"
            | "gets"
            | "getting"
            | "become"
            | "becomes"
            | "becoming"
            | "does"
            | "do"
            | "did"
            | "the"
            | "a"
            | "an"
            | "still"
            | "also"
    )
}

/// The noun a construction phrase starts with, normalised.
pub(crate) fn construction_noun(raw: &str) -> Option<&'static str> {
    match raw {
        "distance" | "distances" | "gap" | "separation" => Some("distance"),
        "speed" | "speeds" | "velocity" | "velocities" => Some("speed"),
        "pace" => Some("pace"),
        _ => None,
    }
}

impl Lexicon {
    pub(crate) fn new(vocab: &Vocabulary) -> Lexicon {
        let mut lex = Lexicon {
            phrases: HashMap::new(),
            stem_ids: HashMap::new(),
            max_len: 1,
            prep_relations: HashMap::new(),
            noun_phrases: HashMap::new(),
            locations: Vec::new(),
            skipped: Vec::new(),
            words: BTreeSet::new(),
            part_of: HashMap::new(),
            place_relations: HashMap::new(),
            inflected_only: HashSet::new(),
            bare_keys: HashSet::new(),
            closed_forms: HashSet::new(),
            classes: BTreeSet::new(),
            type_functions: BTreeSet::new(),
            properties: BTreeSet::new(),
            in_direction: vocab
                .predicate("InDirectionOf")
                .is_some_and(|p| p.arity == 3),
            ego: vocab.predicate("Ego").is_some(),
            comparatives: HashMap::new(),
            superlatives: HashMap::new(),
            guards: vocab
                .predicates()
                .iter()
                .filter(|p| !vocab.guards(&p.name).is_empty())
                .map(|p| (p.name.clone(), vocab.guards(&p.name).to_vec()))
                .collect(),
        };
        // Declaration order inside each group, groups in this order: the
        // first sense registered for a phrase wins.
        let preds = vocab.predicates();
        for p in preds.iter().filter(|p| p.role == PredicateRole::Class) {
            lex.classes.insert(p.name.clone());
            lex.add_all(&p.name, &p.phrases, &Sense::Class(p.name.clone()));
        }
        for f in vocab.functions() {
            match f.role {
                FunctionRole::Type => {
                    lex.type_functions.insert(f.name.clone());
                    for v in &f.values {
                        let sense = Sense::Type {
                            function: f.name.clone(),
                            value: v.name.clone(),
                        };
                        lex.add_all(&v.name, &v.phrases, &sense);
                    }
                    lex.add_nouns(&f.name, &f.nouns);
                }
                FunctionRole::Attribute => {
                    for v in &f.values {
                        let sense = Sense::Attr {
                            function: f.name.clone(),
                            value: v.name.clone(),
                        };
                        lex.add_all(&v.name, &v.phrases, &sense);
                    }
                    lex.add_nouns(&f.name, &f.nouns);
                }
                FunctionRole::Location(anchor) => {
                    let values: BTreeSet<String> =
                        f.values.iter().map(|v| v.name.clone()).collect();
                    lex.locations.push((anchor, f.name.clone(), values));
                    for v in &f.values {
                        lex.add_all(&v.name, &v.phrases, &Sense::Location(v.name.clone()));
                    }
                }
            }
        }
        for p in preds.iter().filter(|p| p.role == PredicateRole::Property) {
            lex.properties.insert(p.name.clone());
            lex.add_all(
                &p.name,
                &p.phrases,
                &Sense::Property {
                    name: p.name.clone(),
                    anchor: p.anchor,
                },
            );
        }
        for p in preds.iter().filter(|p| p.role == PredicateRole::Relation) {
            let phrases = lex.take_comparatives(&p.name, &p.phrases);
            if phrases.is_empty() && !p.phrases.is_empty() {
                continue;
            }
            lex.add_all(&p.name, &phrases, &Sense::Relation(p.name.clone()));
        }
        lex.drop_nouns_with_verbs(vocab);
        lex.add_class_participles(vocab);
        lex
    }

    /// Registers the comparatives of relation `name` ("closer than" →
    /// "closer", "closest"); returns the phrases left for the lexicon.
    /// A comparative is never a phrase of its own: without "than" and
    /// another object ("is the van closer?") it says nothing.
    fn take_comparatives(&mut self, name: &str, phrases: &[String]) -> Vec<String> {
        let default = [default_phrase(name)];
        let all: &[String] = if phrases.is_empty() {
            &default
        } else {
            phrases
        };
        let mut rest = Vec::new();
        for p in all {
            let toks = lexer::tokenize(p);
            // "closer than"; for a comparison relation also "closer",
            // "farther away" (the grammar skips "away", "to us").
            let word = match toks.as_slice() {
                [w, than] if than.raw == "than" => Some(w.raw.clone()),
                [w, ..] if COMPARISONS.contains(&name) => Some(w.raw.clone()),
                _ => None,
            };
            match word {
                Some(w) => {
                    if let Some(base) = w.strip_suffix("er") {
                        self.superlatives
                            .entry(format!("{base}est"))
                            .or_insert_with(|| name.to_string());
                    }
                    self.comparatives
                        .entry(w)
                        .or_insert_with(|| name.to_string());
                }
                None => rest.push(p.clone()),
            }
        }
        rest
    }

    /// "sitting" from "sitting person" (`Person`) when "person" is a class
    /// of its own (`IsPerson`): the participle alone says the object is of
    /// the narrower class ("is the person on the right sitting?" →
    /// `IsPerson(x)^Person(x)`). Only a participle that is no phrase yet.
    fn add_class_participles(&mut self, vocab: &Vocabulary) {
        let mut found: Vec<(String, String)> = Vec::new();
        for p in vocab
            .predicates()
            .iter()
            .filter(|p| p.role == PredicateRole::Class)
        {
            for phrase in &p.phrases {
                let toks = lexer::tokenize(phrase);
                let [first, noun] = toks.as_slice() else {
                    continue;
                };
                let participle = first.raw != first.stem
                    && (first.raw.ends_with("ing") || first.raw.ends_with("ed"));
                let other_class = matches!(
                    self.lookup(&[noun.stem.as_str()]).map(|e| &e.sense),
                    Some(Sense::Class(d)) if *d != p.name
                );
                if participle && other_class && self.lookup(&[first.stem.as_str()]).is_none() {
                    found.push((first.stem.clone(), p.name.clone()));
                }
            }
        }
        for (stem, name) in found {
            let entry = Entry {
                sense: Sense::Property { name, anchor: None },
                synonym: true,
            };
            let key = self.insert(vec![stem], entry);
            self.bare_keys.insert(key);
        }
    }

    /// Value nouns ("colour") of a function: their own words, so no note.
    fn add_nouns(&mut self, function: &str, nouns: &[String]) {
        let sense = Sense::ValueNoun(function.to_string());
        for n in nouns {
            let own: Vec<String> = lexer::tokenize(n).into_iter().map(|t| t.stem).collect();
            let joined = lexer::stem(&own.concat());
            self.add(n, &sense, &own, &joined);
        }
    }

    /// Removes class and type phrases that end with a verb phrase of the
    /// vocabulary ("person walking" for `Pedestrian`) or start with an
    /// "-ing" one ("walking person"), when the rest is a noun of its own:
    /// the phrase would swallow the verb, and "is the person walking?"
    /// would hold for a pedestrian standing still. The grammar reads the
    /// noun and the verb separately instead (`IsPerson(x)^Walk(x)`).
    fn drop_nouns_with_verbs(&mut self, vocab: &Vocabulary) {
        let nouns = vocab
            .predicates()
            .iter()
            .filter(|p| p.role == PredicateRole::Class)
            .map(|p| (p.name.as_str(), p.phrases.as_slice()))
            .chain(
                vocab
                    .functions()
                    .iter()
                    .filter(|f| f.role == FunctionRole::Type)
                    .flat_map(|f| f.values.iter())
                    .map(|v| (v.name.as_str(), v.phrases.as_slice())),
            );
        let mut drop: Vec<(Vec<String>, String, String)> = Vec::new();
        for (name, phrases) in nouns {
            for phrase in phrases {
                let toks = lexer::tokenize(phrase);
                let stems: Vec<&str> = toks.iter().map(|t| t.stem.as_str()).collect();
                let is_verb = |e: Option<&Entry>| {
                    matches!(
                        e.map(|e| &e.sense),
                        Some(Sense::Property { .. } | Sense::Relation(_))
                    )
                };
                let is_noun = |e: Option<&Entry>| {
                    matches!(
                        e.map(|e| &e.sense),
                        Some(Sense::Class(_) | Sense::Type { .. })
                    )
                };
                let swallows = (1..stems.len()).any(|k| {
                    let (head, tail) = stems.split_at(k);
                    let ing = toks
                        .get(k - 1)
                        .is_some_and(|t| t.raw.ends_with("ing") && t.raw != t.stem);
                    (is_noun(self.lookup(head)) && is_verb(self.lookup(tail)))
                        || (ing && is_verb(self.lookup(head)) && is_noun(self.lookup(tail)))
                });
                if swallows {
                    let stems = stems.iter().map(|s| (*s).to_string()).collect();
                    drop.push((stems, phrase.clone(), name.to_string()));
                }
            }
        }
        for (stems, phrase, name) in drop {
            let refs: Vec<&str> = stems.iter().map(String::as_str).collect();
            let key: Option<Vec<u32>> = refs.iter().map(|s| self.stem_id(s)).collect();
            let Some(key) = key else { continue };
            let ours = self
                .phrases
                .get(&key)
                .is_some_and(|e| e.sense.target() == name);
            if ours {
                self.phrases.remove(&key);
                let joined = lexer::stem(
                    &lexer::tokenize(&phrase)
                        .iter()
                        .map(|t| t.raw.as_str())
                        .collect::<String>(),
                );
                if let Some(id) = self.stem_id(&joined)
                    && self
                        .phrases
                        .get(&vec![id])
                        .is_some_and(|e| e.sense.target() == name)
                {
                    self.phrases.remove(&vec![id]);
                }
                self.skipped.push(format!(
                    "'{phrase}' for {name} (a noun and a verb: the grammar reads them apart)"
                ));
            }
        }
    }

    /// The location value of a relation phrase made of a place and "of"
    /// ("to the left of", "left of", "in front of", "ahead of"), if any.
    fn place_of(&self, toks: &[lexer::Token]) -> Option<String> {
        let (last, rest) = toks.split_last()?;
        if last.raw != "of" {
            return None;
        }
        let mut i = 0;
        if rest.first().is_some_and(|t| {
            matches!(lexer::closed(&t.raw), Some(lexer::Closed::Prep(p)) if p != lexer::Prep::Of)
        }) {
            i = 1;
        }
        while rest
            .get(i)
            .is_some_and(|t| matches!(lexer::closed(&t.raw), Some(lexer::Closed::Det(_))))
        {
            i += 1;
        }
        let mut end = rest.len();
        while end > i
            && rest
                .get(end - 1)
                .is_some_and(|t| lexer::closed(&t.raw) == Some(lexer::Closed::LocSuffix))
        {
            end -= 1;
        }
        let place: Vec<&str> = rest.get(i..end)?.iter().map(|t| t.stem.as_str()).collect();
        if place.is_empty() {
            return None;
        }
        match self.lookup(&place) {
            Some(Entry {
                sense: Sense::Location(v),
                ..
            }) => Some(v.clone()),
            _ => None,
        }
    }

    fn add_all(&mut self, name: &str, phrases: &[String], sense: &Sense) {
        let default = default_phrase(name);
        let canonical: Vec<String> = lexer::tokenize(&default)
            .into_iter()
            .map(|t| t.stem)
            .collect();
        let canonical_joined = lexer::stem(&canonical.concat());
        if phrases.is_empty() {
            self.add(&default, sense, &canonical, &canonical_joined);
        } else {
            for p in phrases {
                self.add(p, sense, &canonical, &canonical_joined);
            }
        }
    }

    fn add(&mut self, phrase: &str, sense: &Sense, canonical: &[String], canonical_joined: &str) {
        let toks = lexer::tokenize(phrase);
        if toks.is_empty() {
            return;
        }
        let stems: Vec<String> = toks.iter().map(|t| t.stem.clone()).collect();
        let synonym = stems != canonical
            && !(stems.len() == 1 && stems.first().is_some_and(|s| s == canonical_joined));
        let entry = Entry {
            sense: sense.clone(),
            synonym,
        };
        for t in &toks {
            if !lexer::is_closed_word(&t.raw) {
                self.words.insert(t.raw.clone());
            }
        }
        if let Some(first) = toks.first()
            && let Some(noun) = construction_noun(&first.raw)
        {
            let rest: Vec<String> = toks
                .iter()
                .skip(1)
                .filter(|t| !is_rest_filler(&t.raw))
                .map(|t| t.stem.clone())
                .collect();
            if !rest.is_empty() {
                let list = self.noun_phrases.entry(noun.to_string()).or_default();
                if !list.iter().any(|(k, _)| *k == rest) {
                    list.push((rest, entry.clone()));
                }
            }
        }
        // A one-word phrase that is a grammar word would shadow the grammar
        // ("other", "on"); longer phrases ("get close", "away from") are
        // specific enough to win by length. A class may claim a generic head
        // word ("someone" is a person): it only narrows what the word means.
        if toks.len() == 1 && toks.iter().all(|t| lexer::is_closed_word(&t.raw)) {
            match (sense, toks.as_slice()) {
                (Sense::Relation(name), [only])
                    if matches!(lexer::closed(&only.raw), Some(lexer::Closed::Prep(_))) =>
                {
                    self.prep_relations
                        .entry(only.raw.clone())
                        .or_insert_with(|| name.clone());
                    return;
                }
                (Sense::Class(_), [only])
                    if lexer::closed(&only.raw) == Some(lexer::Closed::HeadWord) =>
                {
                    self.closed_forms.insert(only.raw.clone());
                }
                _ => {
                    self.skipped.push(format!(
                        "'{phrase}' for {} (only grammar words)",
                        sense.target()
                    ));
                    return;
                }
            }
        }
        // "close to", "next to" for `Near`: the grammar reads them as it
        // reads "near" ("close to the right" stays a place).
        if let (Sense::Relation(name), [first, to]) = (sense, toks.as_slice())
            && to.raw == "to"
            && matches!(
                lexer::closed(&first.raw),
                Some(lexer::Closed::Close | lexer::Closed::Prep(lexer::Prep::Near))
            )
        {
            self.prep_relations
                .entry(first.raw.clone())
                .or_insert_with(|| name.clone());
            return;
        }
        // "to the left of": the grammar reads the place and then decides
        // between a relation (another object follows) and a place in the
        // image ("of the scene").
        if let Sense::Relation(name) = sense
            && let Some(value) = self.place_of(&toks)
        {
            self.place_relations
                .entry(value)
                .or_insert_with(|| name.clone());
            return;
        }
        // "on the left" for a property would shadow the grammar's places,
        // which become InitialLocation/LastLocation with their frames.
        if !matches!(sense, Sense::Location(_))
            && toks.len() > 1
            && matches!(
                toks.first().and_then(|t| lexer::closed(&t.raw)),
                Some(lexer::Closed::Prep(_))
            )
        {
            let rest: Vec<String> = toks
                .iter()
                .skip(1)
                .filter(|t| !matches!(lexer::closed(&t.raw), Some(lexer::Closed::Det(_))))
                .map(|t| t.stem.clone())
                .collect();
            let rest: Vec<&str> = rest.iter().map(String::as_str).collect();
            if matches!(
                self.lookup(&rest),
                Some(Entry {
                    sense: Sense::Location(_),
                    ..
                })
            ) {
                self.skipped.push(format!(
                    "'{phrase}' for {} (a place: the grammar reads places as locations)",
                    sense.target()
                ));
                return;
            }
        }
        if toks.len() > 1 {
            for t in &toks {
                if !lexer::is_closed_word(&t.raw) {
                    self.part_of
                        .entry(t.raw.clone())
                        .or_insert_with(|| phrase.to_string());
                }
            }
        }
        self.max_len = self.max_len.max(stems.len());
        let key = self.insert(stems, entry.clone());
        if let [only] = toks.as_slice() {
            let inflected = only.raw != only.stem && only.raw.ends_with("ing");
            if inflected && !self.bare_keys.contains(&key) {
                self.inflected_only.insert(key);
            } else if !inflected {
                self.inflected_only.remove(&key);
                self.bare_keys.insert(key);
            }
        }
        if toks.len() > 1 {
            // "trafficlight" for "traffic light".
            let joined: String = toks.iter().map(|t| t.raw.as_str()).collect();
            self.insert(vec![lexer::stem(&joined)], entry);
        }
    }

    /// Registers a phrase. When two senses claim the same words, a sense
    /// whose own name the words spell ("car" for `TypeOf` `Car`) beats a
    /// synonym ("car" listed for `Vehicles`); otherwise the first wins.
    fn insert(&mut self, stems: Vec<String>, entry: Entry) -> Vec<u32> {
        let key: Vec<u32> = stems
            .into_iter()
            .map(|st| {
                let next = u32::try_from(self.stem_ids.len()).unwrap_or(u32::MAX);
                *self.stem_ids.entry(st).or_insert(next)
            })
            .collect();
        match self.phrases.get_mut(&key) {
            Some(old) => {
                if old.synonym && !entry.synonym {
                    *old = entry;
                }
            }
            None => {
                self.phrases.insert(key.clone(), entry);
            }
        }
        key
    }

    /// The id of a stem, if any phrase uses it.
    pub(crate) fn stem_id(&self, stem: &str) -> Option<u32> {
        self.stem_ids.get(stem).copied()
    }

    /// The entry for a phrase given by its stems.
    pub(crate) fn lookup(&self, stems: &[&str]) -> Option<&Entry> {
        let key: Option<Vec<u32>> = stems.iter().map(|s| self.stem_id(s)).collect();
        self.phrases.get(&key?)
    }

    /// The location function for an anchor and whether it declares `value`.
    pub(crate) fn location_function(&self, anchor: Anchor, value: &str) -> Option<&str> {
        self.locations
            .iter()
            .find(|(a, _, vs)| *a == anchor && vs.contains(value))
            .map(|(_, n, _)| n.as_str())
    }

    /// The closest vocabulary word to a misspelt word, if close enough.
    pub(crate) fn suggest(&self, word: &str) -> Option<String> {
        if word.chars().count() < 4 {
            return None;
        }
        // Grammar words are misspelt too ("ther", "distnace").
        const GRAMMAR: &[&str] = &[
            "there", "where", "which", "between", "distance", "frames", "scene", "initial",
            "another", "spot", "does", "towards", "position", "speed",
        ];
        let mut best: Option<(usize, &str)> = None;
        for w in self
            .words
            .iter()
            .map(String::as_str)
            .chain(GRAMMAR.iter().copied())
        {
            let d = strsim::damerau_levenshtein(word, w);
            let limit = if word.chars().count() >= 8 { 2 } else { 1 };
            if d <= limit && best.is_none_or(|(bd, _)| d < bd) {
                best = Some((d, w));
            }
        }
        best.map(|(_, w)| w.to_string())
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::translate::{Translator, Vocabulary};

    fn sense(lex: &Lexicon, phrase: &str) -> Option<Sense> {
        let stems: Vec<String> = lexer::tokenize(phrase)
            .into_iter()
            .map(|t| t.stem)
            .collect();
        let stems: Vec<&str> = stems.iter().map(String::as_str).collect();
        lex.lookup(&stems).map(|e| e.sense.clone())
    }

    #[test]
    fn a_name_beats_a_synonym_for_the_same_words() {
        // "car" listed for Vehicles (as the project's LogicPad does) must not
        // hide TypeOf(x, Car), whatever the declaration order.
        let v = Vocabulary::builder()
            .class("Vehicles", &["vehicle", "car"])
            .function("TypeOf", &[("Car", &[])])
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let lex = Lexicon::new(&v);
        assert_eq!(
            sense(&lex, "cars"),
            Some(Sense::Type {
                function: "TypeOf".into(),
                value: "Car".into()
            })
        );
        assert_eq!(
            sense(&lex, "vehicle"),
            Some(Sense::Class("Vehicles".into()))
        );
    }

    #[test]
    fn grammar_words_and_places_are_not_taken_as_phrases() {
        let v = Vocabulary::builder()
            .function_with_role(
                "InitialLocation",
                FunctionRole::Location(Anchor::Initial),
                &[("Left", &[])],
            )
            .property("AtLeft", &["on the left", "leftish"])
            .relation("On", &[])
            .function("ColorOf", &[("Other", &[]), ("Red", &[])])
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let t = Translator::new(v);
        assert!(
            t.skipped_phrases()
                .iter()
                .any(|s| s.contains("'on the left' for AtLeft"))
        );
        assert!(
            t.skipped_phrases()
                .iter()
                .any(|s| s.starts_with("'other' for Other"))
        );
        assert_eq!(
            t.lexicon.prep_relations.get("on").map(String::as_str),
            Some("On")
        );
        assert_eq!(
            sense(&t.lexicon, "leftish"),
            Some(Sense::Property {
                name: "AtLeft".into(),
                anchor: None
            })
        );
        assert_eq!(sense(&t.lexicon, "on the left"), None);
    }

    #[test]
    fn compound_words_and_construction_phrases() {
        let t = Translator::builtin();
        assert_eq!(
            sense(&t.lexicon, "trafficsign"),
            Some(Sense::Class("TrafficSign".into()))
        );
        assert_eq!(
            sense(&t.lexicon, "policecar"),
            Some(Sense::Type {
                function: "TypeOf".into(),
                value: "PoliceCar".into()
            })
        );
        let distance = t
            .lexicon
            .noun_phrases
            .get("distance")
            .map(Vec::len)
            .unwrap_or(0);
        assert!(distance >= 10, "{distance}");
        assert_eq!(
            t.lexicon.suggest("pedestrain").as_deref(),
            Some("pedestrian")
        );
        assert_eq!(t.lexicon.suggest("xyzzy"), None);
    }

    #[test]
    fn nouns_that_end_with_a_verb_are_dropped() {
        // A LogicPad may list "person walking" for Pedestrian; it would
        // swallow the verb ("is the person walking?" → Pedestrian(x), yes
        // for a pedestrian standing still).
        let v = Vocabulary::builder()
            .class(
                "Pedestrian",
                &["pedestrian", "person walking", "walking person"],
            )
            .class("IsPerson", &["person", "someone"])
            .class("TrafficSign", &["stop sign"])
            .property("Walk", &["walk"])
            .property("Stopped", &["stop"])
            .build()
            .unwrap_or_else(|e| panic!("{e}"));
        let t = Translator::new(v);
        assert_eq!(sense(&t.lexicon, "person walking"), None);
        assert_eq!(sense(&t.lexicon, "walking person"), None);
        assert_eq!(sense(&t.lexicon, "personwalking"), None);
        assert!(
            t.skipped_phrases()
                .iter()
                .any(|s| s.starts_with("'person walking' for Pedestrian")),
            "{:?}",
            t.skipped_phrases()
        );
        // "stop" is no participle: "stop sign" is a noun of its own.
        assert_eq!(
            sense(&t.lexicon, "stop sign"),
            Some(Sense::Class("TrafficSign".into()))
        );
        let q = |s: &str| t.translate(s).map(|t| t.query);
        assert_eq!(
            q("Is the person walking?").as_deref(),
            Ok("IsPerson(x)^Walk(x)")
        );
        // A generic head word claimed by a class is that class.
        assert_eq!(
            q("Is someone walking?").as_deref(),
            Ok("IsPerson(x)^Walk(x)")
        );
        assert!(t.lexicon.closed_forms.contains("someone"));
    }

    #[test]
    fn place_relations_inflected_forms_and_value_nouns() {
        let t = Translator::builtin();
        let lex = &t.lexicon;
        for (value, rel) in [
            ("Left", "LeftOf"),
            ("Right", "RightOf"),
            ("Front", "InFrontOf"),
        ] {
            assert_eq!(
                lex.place_relations.get(value).map(String::as_str),
                Some(rel)
            );
        }
        // "to the left of" is read by the grammar, not as a phrase.
        assert_eq!(sense(lex, "to the left of"), None);
        assert_eq!(
            lex.prep_relations.get("behind").map(String::as_str),
            Some("Behind")
        );
        // "slowing" only; "slow down" is a phrase of its own.
        let slow = lex.stem_id("slow").map(|id| vec![id]);
        assert!(slow.is_some_and(|k| lex.inflected_only.contains(&k)));
        let walk = lex.stem_id("walk").map(|id| vec![id]);
        assert!(walk.is_some_and(|k| !lex.inflected_only.contains(&k)));
        assert_eq!(
            sense(lex, "colour"),
            Some(Sense::ValueNoun("ColorOf".into()))
        );
        assert_eq!(sense(lex, "kind"), Some(Sense::ValueNoun("TypeOf".into())));
        // "sitting" from "sitting person": a person who sits is a Person.
        assert_eq!(
            sense(lex, "sitting"),
            Some(Sense::Property {
                name: "Person".into(),
                anchor: None
            })
        );
        assert_eq!(sense(lex, "people"), Some(Sense::Class("IsPerson".into())));
    }
}
