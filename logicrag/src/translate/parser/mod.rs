//! The grammar: items (lexicon phrases and closed-class words) → atoms.
//!
//! The parser is a hand-written recursive descent over items with three
//! levels: the question's opening frame ("is there", "does", "is", "can you
//! spot"), object phrases (determiners, adjectives, a head noun and
//! post-modifiers: places, times, relative clauses), and verb phrases said of
//! a focus (one or two objects). Places are collected per clause and given
//! their frames (initial or last) when the clause ends, because a time phrase
//! may follow the place it qualifies ("at the right in the last frames").
//!
//! This file is the driver: items, the parser's state, the helpers every
//! phrase kind shares, and the final atoms ([`parse`]). One file per phrase
//! kind holds the rest, each an `impl Parser` of its own:
//! - `opening`: opening frames and the question as a whole;
//! - `objects`: object phrases and their post-modifiers;
//! - `places`: places, prepositional phrases, relative positions;
//! - `actions`: predicatives, "left" as "leave", changes of speed;
//! - `relations`: relation verbs and "distance between" constructions;
//! - `clauses`: verb phrases, conjunction, negation, relative clauses and
//!   the frames of each clause's places;
//! - `values`: value questions ("what colour is the van?").

mod actions;
mod clauses;
mod forms;
mod objects;
mod opening;
mod places;
mod relations;
mod values;

use std::collections::BTreeSet;

use super::lexer::{Closed, Det, Token, Wrap, closed};
use super::lexicon::{Entry, Lexicon, Sense};
use super::{Anchor, QueryAtom, TranslateError, Translation, UnplacedWord};

#[derive(Debug, Clone)]
enum ItemKind {
    Content(Entry),
    Closed(Closed),
    /// An object constant such as `car_3`: a known object, not a variable.
    Constant,
    Unknown,
}

/// A run of tokens read as one unit. Invariant: `start < end <= tokens.len()`.
#[derive(Debug, Clone)]
struct Item {
    kind: ItemKind,
    start: usize,
    end: usize,
}

#[derive(Debug, Clone, PartialEq, Eq)]
enum Arg {
    Var(usize),
    Const(String),
}

/// How a place's frames are decided.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum LocHow {
    /// Fixed by a preposition ("to the right") or the verb ("disappears from").
    Fixed(Anchor),
    /// Decided by the clause's time phrase, initial frames without one.
    Clause,
}

#[derive(Debug, Clone)]
enum Pred {
    Name(String),
    Location {
        value: String,
        how: LocHow,
        token: usize,
    },
    /// Withdrawn after it was read ("car" in "what type of car").
    Dropped,
}

#[derive(Debug, Clone)]
struct Draft {
    pred: Pred,
    args: Vec<Arg>,
    negated: bool,
    /// The `¬∃` scope the atom belongs to (0: the query itself; `k`: the
    /// scope `scopes[k - 1]`).
    scope: usize,
    /// The part of a time-ordered question (0: before "then", 1: after).
    part: usize,
    /// Says what an object is (its class, type or colour), not what it
    /// does: repeated in the second part of a time-ordered question.
    defining: bool,
}

/// A negated existential scope, `¬∃y: (…)`: the drafts and the entities
/// read while it was open ("not on the road": the road is local to it).
#[derive(Debug, Clone)]
struct Scope {
    /// The enclosing scope (0: the query).
    parent: usize,
    /// Token of the words that opened it, for messages.
    token: usize,
}

/// A counting threshold, `#{x: Q} >= n`.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
struct Count {
    entity: usize,
    op: &'static str,
    n: u32,
    token: usize,
}

/// How two parts of a time-ordered question relate.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Order {
    Then,
    Before,
    After,
}

impl Order {
    fn keyword(self) -> &'static str {
        match self {
            Order::Then => "THEN",
            Order::Before => "BEFORE",
            Order::After => "AFTER",
        }
    }
}

#[derive(Debug, Clone, Default)]
struct Clause {
    time: Option<Anchor>,
    /// The anchor of the clause's verb ("appear": initial frames): a time
    /// phrase then says when the event happens, not where the object is.
    verb_anchor: Option<Anchor>,
    locs: Vec<usize>,
    /// Time phrases read, their frames, and whether a place took them.
    times: Vec<(String, Anchor, bool)>,
}

/// State of one verb-phrase conjunct.
#[derive(Debug, Clone, Copy, Default)]
struct Segment {
    anchor: Option<Anchor>,
    motion: bool,
    copula: bool,
    /// After "stay"/"remain": a place holds in the first and last frames.
    stay: bool,
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Mode {
    Existential,
    Copular,
    Verbal,
}

struct Parser<'a> {
    lex: &'a Lexicon,
    toks: &'a [Token],
    items: Vec<Item>,
    i: usize,
    entities: usize,
    last_entity: Option<usize>,
    subjects: Vec<usize>,
    /// Entities that are named objects (`car_3`), by entity number.
    constants: Vec<(usize, String)>,
    no_participles: bool,
    /// The question opened with "what"/"which": it may ask for a value.
    wh_open: bool,
    /// Entities whose head noun is plural ("the cars"), with the first
    /// draft of their object phrase: "the cars … each other" is a pair.
    plurals: Vec<(usize, usize)>,
    /// Current nesting of object and verb phrases (bounded by `MAX_DEPTH`).
    depth: usize,
    /// Whether the next object phrase may be "the two cars" (a pair).
    pair_ok: bool,
    /// The second object of the pair just read.
    twin: Option<usize>,
    /// Pairs read ("the two cars"), with the token of "two": a binary
    /// relation must connect them, else the question is about counting.
    pairs: Vec<(usize, usize, usize)>,
    drafts: Vec<Draft>,
    clauses: Vec<Clause>,
    notes: Vec<String>,
    /// "How many …" was read.
    counts: bool,
    unplaced: Vec<UnplacedWord>,
    unsupported: Option<TranslateError>,
    /// The `¬∃` scopes opened so far (scope `k` is `scopes[k - 1]`).
    scopes: Vec<Scope>,
    /// The scope new atoms go to.
    scope: usize,
    /// The scope each entity was read in.
    entity_scope: Vec<usize>,
    /// The part of a time-ordered question new atoms go to.
    part: usize,
    /// "then", "before", "after": how the two parts relate, with the token.
    order: Option<(Order, usize)>,
    /// "ever", "throughout", "still", with the token.
    wrap: Option<(Wrap, usize)>,
    /// "more than two cars": the counted entity and the threshold.
    count: Option<Count>,
    /// "no pedestrian is …" as the subject: the whole query is denied.
    deny: Option<usize>,
    /// Each object phrase's entity with the drafts it wrote (from, to).
    np_spans: Vec<(usize, usize, usize)>,
    /// Object phrases read with "no" ("no pedestrian"), with the token,
    /// until a relation or the question takes them.
    denied: Vec<(usize, usize)>,
    /// The object whose own frame "its"/"it" names while the object phrase
    /// after "with"/"has" is read ("a vehicle with a bicycle to its
    /// right"), and whether a direction used it.
    holder: Option<Holder>,
}

/// See [`Parser::holder`].
#[derive(Debug, Clone, Copy)]
struct Holder {
    entity: usize,
    used: bool,
}

/// Reads items: at each token the longest vocabulary phrase, else a
/// closed-class word, else an unknown word.
fn items(lex: &Lexicon, toks: &[Token]) -> Vec<Item> {
    let mut out = Vec::new();
    let mut i = 0;
    // Stems as lexicon ids; a stem the lexicon has never seen cannot be
    // part of any phrase.
    let ids: Vec<Option<u32>> = toks.iter().map(|t| lex.stem_id(&t.stem)).collect();
    let mut key: Vec<u32> = Vec::with_capacity(lex.max_len);
    while i < toks.len() {
        let mut found = None;
        let longest = lex.max_len.min(toks.len() - i);
        let known = ids[i..].iter().take_while(|id| id.is_some()).count();
        for len in (1..=longest.min(known)).rev() {
            key.clear();
            key.extend(ids[i..i + len].iter().flatten());
            if let Some(e) = lex.phrases.get(&key) {
                if len == 1 && !one_word_fits(lex, &toks[i]) {
                    continue;
                }
                found = Some((e.clone(), len));
                break;
            }
        }
        if let Some((len, kind)) = closed_phrase(&toks[i..]) {
            // "right now", "at the moment": fillers that would otherwise
            // read as a place or a preposition; "at any point", "the whole
            // time": time words over a video's windows.
            out.push(Item {
                kind: ItemKind::Closed(kind),
                start: i,
                end: i + len,
            });
            i += len;
        } else if let Some((e, len)) = found {
            out.push(Item {
                kind: ItemKind::Content(e),
                start: i,
                end: i + len,
            });
            i += len;
        } else if is_object_constant(&toks[i].raw) {
            out.push(Item {
                kind: ItemKind::Constant,
                start: i,
                end: i + 1,
            });
            i += 1;
        } else {
            let kind = match closed(&toks[i].raw) {
                Some(c) => ItemKind::Closed(c),
                None => ItemKind::Unknown,
            };
            out.push(Item {
                kind,
                start: i,
                end: i + 1,
            });
            i += 1;
        }
    }
    out
}

/// Whether a one-word phrase may claim this word: a grammar word only when a
/// phrase names it exactly ("someone", not "coloured" for "colour").
fn one_word_fits(lex: &Lexicon, tok: &Token) -> bool {
    closed(&tok.raw).is_none() || lex.closed_forms.contains(&tok.raw)
}

/// Relations of distance to another object. Said with no second object
/// ("is the van approaching?", "is the pedestrian moving away?") the other
/// object is us, the camera: `GettingCloser(x, ego)`, where the vocabulary
/// has the ego. A fixed list: the LogicPad's rules say how these are
/// derived (from `DistanceDecrease`/`DistanceIncrease`), not which of its
/// relations a question may leave without an object; any other relation
/// ("collide", "on", "enter") still needs one.
const TOWARD_EGO: &[&str] = &[
    "GettingCloser",
    "ComeClose",
    "GoAway",
    "DistanceDecrease",
    "DistanceIncrease",
];

/// Relations that, said with no second object, mean a property about us
/// (the ego), when the vocabulary has both: "is the car going in the
/// opposite direction?", "driving the other way" → `Oncoming(x)` (the
/// LogicPad's rule: `Opposite(x, ego) ∧ DistanceDecrease(x, ego)`), the
/// everyday sense of traffic going the other way. A fixed list, as
/// [`TOWARD_EGO`] is.
const EGO_PROPERTY: &[(&str, &str)] = &[("Opposite", "Oncoming")];

/// The direction of `InDirectionOf` (in the other object's own frame) a
/// place value names: "to its right" → `Right`, "in front of it" →
/// `Forward`, "behind it" / "at its rear" → `Backward`.
fn own_direction(location: &str) -> Option<&'static str> {
    match location {
        "Left" => Some("Left"),
        "Right" => Some("Right"),
        "Front" => Some("Forward"),
        "Behind" => Some("Backward"),
        _ => None,
    }
}

/// Classes of the objects that move (the ego counts as `Ego`): a property
/// whose rules require other classes ([`Lexicon::guards`]: `Cross` is
/// derived for pedestrians) is refused when said of one of them, instead
/// of answering a confident "no". A static object ("is the pole moving?")
/// is not refused: "no" is the right answer there.
const MOVER_CLASSES: &[&str] = &["Vehicles", "Pedestrian", "Person", "Cyclist", "Ego"];

/// The class of an object of type `value` (`TypeOf(x, Van)`): the
/// perception types are vehicles, but for the types of people and riders,
/// and Argoverse 2's objects that are no vehicle. Those that move on their
/// own (a dog, a stroller, a wheelchair: AV2's `Misc`) are `Misc`, whose
/// motion no rule derives: "is the dog moving?" is refused, not a
/// confident no. Static ones (a bollard, a cone, a sign, a trailer) and
/// `Other`, `Animal` say nothing.
fn class_of_type(value: &str) -> Option<&'static str> {
    match value {
        "Pedestrian" | "OfficialSignaler" => Some("Pedestrian"),
        "Cyclist" | "Bicyclist" | "Motorcyclist" | "WheeledRider" => Some("Cyclist"),
        "WheeledDevice" | "Wheelchair" | "Stroller" | "Dog" => Some("Misc"),
        "Other"
        | "Animal"
        | "MessageBoardTrailer"
        | "TrafficLightTrailer"
        | "Bollard"
        | "ConstructionCone"
        | "ConstructionBarrel"
        | "Sign"
        | "StopSign"
        | "MobilePedestrianCrossingSign" => None,
        _ => Some("Vehicles"),
    }
}

/// A class in words: singular, plural.
fn class_words(class: &str) -> (String, String) {
    match class {
        "Vehicles" => ("vehicle".into(), "vehicles".into()),
        "Person" => ("sitting person".into(), "sitting people".into()),
        "Ego" => ("our own vehicle".into(), "us".into()),
        other => {
            let w = super::default_phrase(other).to_lowercase();
            (w.clone(), format!("{w}s"))
        }
    }
}

/// "a, b and c".
fn and_list(words: &[String]) -> String {
    match words {
        [] => String::new(),
        [one] => one.clone(),
        [init @ .., last] => format!("{} and {last}", init.join(", ")),
    }
}

/// How deeply object and verb phrases may nest.
const MAX_DEPTH: usize = 64;

/// Multi-word closed phrases, longest first: fillers and time words.
const CLOSED_PHRASES: &[(&[&str], Closed)] = &[
    (
        &["at", "any", "point", "in", "time"],
        Closed::Temporal(Wrap::Ever),
    ),
    (&["at", "this", "moment"], Closed::Filler),
    (&["at", "the", "moment"], Closed::Filler),
    (&["at", "any", "point"], Closed::Temporal(Wrap::Ever)),
    (&["at", "some", "point"], Closed::Temporal(Wrap::Ever)),
    (&["at", "any", "time"], Closed::Temporal(Wrap::Ever)),
    (&["at", "some", "time"], Closed::Temporal(Wrap::Ever)),
    (
        &["the", "whole", "time"],
        Closed::Temporal(Wrap::Throughout),
    ),
    (
        &["the", "entire", "time"],
        Closed::Temporal(Wrap::Throughout),
    ),
    (&["all", "the", "time"], Closed::Temporal(Wrap::Throughout)),
    (&["all", "along"], Closed::Temporal(Wrap::Throughout)),
    (&["all", "the", "way"], Closed::Temporal(Wrap::Throughout)),
    (&["once", "more"], Closed::Again),
    (&["one", "more", "time"], Closed::Again),
    (&["right", "now"], Closed::Filler),
    (&["at", "present"], Closed::Filler),
    (&["at", "all"], Closed::Filler),
    (&["as", "well"], Closed::Filler),
];

fn closed_phrase(toks: &[Token]) -> Option<(usize, Closed)> {
    CLOSED_PHRASES
        .iter()
        .find(|(p, _)| p.len() <= toks.len() && p.iter().zip(toks).all(|(w, t)| *w == t.raw))
        .map(|(p, k)| (p.len(), *k))
}

/// An object constant of the KB: `car_3`, `pedestrian_1`, `person_sitting_4`.
fn is_object_constant(raw: &str) -> bool {
    let Some((kind, id)) = raw.rsplit_once('_') else {
        return false;
    };
    kind.chars().next().is_some_and(|c| c.is_ascii_lowercase())
        && kind.chars().all(|c| c.is_ascii_lowercase() || c == '_')
        && !id.is_empty()
        && id.chars().all(|c| c.is_ascii_digit())
}

pub(crate) fn parse(
    lex: &Lexicon,
    question: &str,
    toks: &[Token],
) -> Result<Translation, TranslateError> {
    let mut p = Parser {
        lex,
        toks,
        items: items(lex, toks),
        i: 0,
        entities: 0,
        last_entity: None,
        subjects: Vec::new(),
        constants: Vec::new(),
        no_participles: false,
        wh_open: false,
        plurals: Vec::new(),
        depth: 0,
        pair_ok: false,
        twin: None,
        pairs: Vec::new(),
        drafts: Vec::new(),
        clauses: Vec::new(),
        notes: Vec::new(),
        counts: false,
        unplaced: Vec::new(),
        unsupported: None,
        scopes: Vec::new(),
        scope: 0,
        entity_scope: Vec::new(),
        part: 0,
        order: None,
        wrap: None,
        count: None,
        deny: None,
        np_spans: Vec::new(),
        denied: Vec::new(),
        holder: None,
    };
    p.question();
    p.finish(question)
}

const BARE_ADJECTIVE: &str = "only its '-ing' form is a vocabulary phrase, and as an adjective the bare word means something else ('slow' is not 'slowing'): say 'slowing down'";

/// "change", "changes", "changing", "changed", "vary", "varies".
fn is_change_word(raw: &str) -> bool {
    raw.starts_with("chang") || raw == "vary" || raw == "varies" || raw == "varying"
}

fn var_name(n: usize) -> String {
    const NAMES: [&str; 6] = ["x", "y", "z", "u", "v", "w"];
    match NAMES.get(n) {
        Some(s) => (*s).to_string(),
        None => format!("{}{}", NAMES[n % NAMES.len()], n / NAMES.len()),
    }
}

impl<'a> Parser<'a> {
    // ---- item access -------------------------------------------------

    fn kind(&self, at: usize) -> Option<&ItemKind> {
        self.items.get(at).map(|it| &it.kind)
    }

    fn closed_at(&self, at: usize) -> Option<Closed> {
        match self.kind(at) {
            Some(ItemKind::Closed(c)) => Some(*c),
            _ => None,
        }
    }

    fn is_closed(&self, at: usize, c: Closed) -> bool {
        self.closed_at(at) == Some(c)
    }

    fn entry_at(&self, at: usize) -> Option<&Entry> {
        match self.kind(at) {
            Some(ItemKind::Content(e)) => Some(e),
            _ => None,
        }
    }

    fn raw_at(&self, at: usize) -> String {
        match self.items.get(at) {
            Some(it) => self.toks[it.start..it.end]
                .iter()
                .map(|t| t.raw.as_str())
                .collect::<Vec<_>>()
                .join(" "),
            None => String::new(),
        }
    }

    fn first_raw(&self, at: usize) -> &str {
        self.items
            .get(at)
            .and_then(|it| self.toks.get(it.start))
            .map_or("", |t| t.raw.as_str())
    }

    /// A time adjective with no noun after it ("is the bus late?", "does it
    /// come first?"): it says something of the object (punctuality, order)
    /// that no predicate holds, unlike "in the last frames" or "finally".
    fn lone_time_adjective(&self, at: usize) -> bool {
        matches!(
            self.first_raw(at),
            "late"
                | "early"
                | "first"
                | "last"
                | "final"
                | "initial"
                | "latter"
                | "subsequent"
                | "opening"
                | "closing"
                | "ending"
                | "starting"
                | "beginning"
        ) && !matches!(
            self.closed_at(at + 1),
            Some(Closed::Few | Closed::Scene | Closed::Time(_))
        )
    }

    /// The bare form of a word whose phrases are all "-ing" forms: "slow"
    /// for "slowing". A verb ("does the van slow?"), but as an adjective
    /// ("is the van slow?", "a slow van") it speaks of low speed, which the
    /// phrase does not mean.
    fn bare_of_inflected(&self, at: usize) -> bool {
        let Some(it) = self.items.get(at) else {
            return false;
        };
        let Some(t) = self.toks.get(it.start) else {
            return false;
        };
        it.end == it.start + 1
            && t.raw == t.stem
            && self
                .lex
                .stem_id(&t.stem)
                .is_some_and(|id| self.lex.inflected_only.contains(&vec![id]))
    }

    fn token_index(&self, at: usize) -> usize {
        self.items.get(at).map_or(self.toks.len(), |it| it.start)
    }

    fn at_end(&self) -> bool {
        self.i >= self.items.len()
    }

    fn skip_dets(&self, mut j: usize) -> usize {
        while matches!(
            self.closed_at(j),
            Some(Closed::Det(Det::Plain) | Closed::Few)
        ) {
            j += 1;
        }
        j
    }

    fn raw_span(&self, from: usize, to: usize) -> String {
        let mut words = Vec::new();
        for k in from..to {
            words.push(self.raw_at(k));
        }
        words.join(" ")
    }

    // ---- recording ---------------------------------------------------

    fn unplace(&mut self, at: usize, reason: &str) {
        let Some(it) = self.items.get(at) else { return };
        for t in &self.toks[it.start..it.end] {
            let mut reason = reason.to_string();
            let mut suggestion = None;
            if let ItemKind::Unknown = it.kind {
                match self.lex.part_of.get(&t.raw) {
                    Some(phrase) => reason = format!("known only as part of '{phrase}'"),
                    None => suggestion = self.lex.suggest(&t.raw),
                }
            }
            self.unplaced.push(UnplacedWord {
                word: t.raw.clone(),
                index: t.index,
                offset: t.offset,
                reason,
                suggestion,
            });
        }
    }

    fn unsupported(&mut self, at: usize, why: &str) {
        if self.unsupported.is_none() {
            self.unsupported = Some(TranslateError::Unsupported {
                what: self.raw_at(at),
                index: self.token_index(at),
                why: why.to_string(),
            });
        }
    }

    fn note(&mut self, n: String) {
        if !self.notes.contains(&n) {
            self.notes.push(n);
        }
    }

    fn note_synonym(&mut self, at: usize) {
        if let Some(e) = self.entry_at(at)
            && e.synonym
        {
            let target = match &e.sense {
                Sense::Class(n) | Sense::Relation(n) => n.clone(),
                Sense::Property { name, .. } => name.clone(),
                Sense::Type { function, value } | Sense::Attr { function, value } => {
                    format!("{function} {value}")
                }
                Sense::Location(v) => format!("location {v}"),
                Sense::ValueNoun(f) => format!("the value of {f}"),
            };
            let n = format!("'{}' read as {target}", self.raw_at(at));
            self.note(n);
        }
    }

    fn new_entity(&mut self) -> usize {
        let e = self.entities;
        self.entities += 1;
        self.last_entity = Some(e);
        match self.entity_scope.get_mut(e) {
            Some(s) => *s = self.scope,
            None => {
                self.entity_scope.resize(e, 0);
                self.entity_scope.push(self.scope);
            }
        }
        e
    }

    fn atom(&mut self, pred: &str, args: Vec<Arg>, negated: bool) {
        self.drafts.push(Draft {
            pred: Pred::Name(pred.to_string()),
            args,
            negated,
            scope: self.scope,
            part: self.part,
            defining: false,
        });
    }

    /// An atom that says what an object is (class, type, colour).
    fn defining_atom(&mut self, pred: &str, args: Vec<Arg>) {
        self.atom(pred, args, false);
        if let Some(d) = self.drafts.last_mut() {
            d.defining = true;
        }
    }

    /// Opens a `¬∃` scope: atoms and objects read until [`Self::close_scope`]
    /// belong to it.
    fn open_scope(&mut self, at: usize) -> usize {
        let token = self.token_index(at);
        self.scopes.push(Scope {
            parent: self.scope,
            token,
        });
        let id = self.scopes.len();
        self.scope = id;
        id
    }

    /// Closes scope `id`. A scope without objects of its own is no `¬∃`:
    /// its one atom is negated in place ("not near it"), and more than one
    /// cannot be said.
    fn close_scope(&mut self, id: usize) {
        let parent = self.scopes.get(id - 1).map_or(0, |s| s.parent);
        self.scope = parent;
        let local = self
            .entity_scope
            .iter()
            .enumerate()
            .take(self.entities)
            .any(|(e, s)| *s == id && !self.constants.iter().any(|(c, _)| *c == e));
        if local {
            return;
        }
        let mine: Vec<usize> = (0..self.drafts.len())
            .filter(|k| self.drafts.get(*k).is_some_and(|d| d.scope == id))
            .collect();
        if let [only] = mine.as_slice()
            && let Some(d) = self.drafts.get_mut(*only)
        {
            d.scope = parent;
            d.negated = !d.negated;
        } else if !mine.is_empty() {
            let token = self.scopes.get(id - 1).map_or(0, |s| s.token);
            if self.unsupported.is_none() {
                self.unsupported = Some(TranslateError::Unsupported {
                    what: self.toks.get(token).map_or_else(String::new, |t| t.raw.clone()),
                    index: token,
                    why: "the negation of several facts about known objects cannot be said; ask about each".into(),
                });
            }
        }
    }

    fn location(&mut self, e: usize, value: &str, how: LocHow, negated: bool, token: usize) {
        let idx = self.drafts.len();
        self.drafts.push(Draft {
            pred: Pred::Location {
                value: value.to_string(),
                how,
                token,
            },
            args: vec![Arg::Var(e)],
            negated,
            scope: self.scope,
            part: self.part,
            defining: false,
        });
        if let Some(c) = self.clauses.last_mut() {
            c.locs.push(idx);
        }
    }

    // ---- result ------------------------------------------------------

    fn finish(mut self, question: &str) -> Result<Translation, TranslateError> {
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
            super::Intent::HowMany
        } else if self.wh_open {
            super::Intent::Which
        } else {
            super::Intent::YesNo
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
                form: super::Form::Conjunction,
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
                super::Form::Count,
            )
        } else if let Some(token) = self.deny {
            let vars = names.in_scope(&self.entity_scope, 0, &self.constants);
            if vars.is_empty() {
                return Err(self.refuse(token, "'no' must deny an object the question describes"));
            }
            (
                format!("¬∃{}: ({body})", vars.join(",")),
                super::Form::Scoped,
            )
        } else if let (Some((order, _)), Some(second)) = (self.order, second) {
            (
                format!(
                    "({body}) {} ({})",
                    order.keyword(),
                    second.literals.join("^")
                ),
                super::Form::Temporal,
            )
        } else if let Some((wrap, _)) = self.wrap {
            let keyword = match wrap {
                Wrap::Ever => "EVER",
                Wrap::Throughout => "THROUGHOUT",
                Wrap::Still => "STILL",
            };
            (format!("{keyword}: {body}"), super::Form::Temporal)
        } else {
            (body, super::Form::Scoped)
        };
        Ok(Translation {
            query,
            atoms: Vec::new(),
            notes: self.notes,
            intent: if self.count.is_some() || self.deny.is_some() {
                super::Intent::YesNo
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
                            super::default_phrase(value).to_lowercase()
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
                None => (super::default_phrase(name).to_lowercase(), 0),
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

#[cfg(test)]
mod tests {
    use super::super::lexer::tokenize;
    use super::super::{Translator, Vocabulary};
    use super::*;

    fn lexicon() -> Lexicon {
        Lexicon::new(&Vocabulary::builtin())
    }

    fn kinds(q: &str) -> Vec<String> {
        let lex = lexicon();
        let toks = tokenize(q);
        items(&lex, &toks)
            .into_iter()
            .map(|it| match it.kind {
                ItemKind::Content(e) => format!("<{}>", e.sense.target()),
                ItemKind::Closed(c) => format!("{c:?}"),
                ItemKind::Constant => "Constant".to_string(),
                ItemKind::Unknown => "?".to_string(),
            })
            .collect()
    }

    /// The built-in translator's query for `q`, or the error as text.
    pub(super) fn query(q: &str) -> String {
        Translator::builtin()
            .translate(q)
            .map(|t| t.query)
            .unwrap_or_else(|e| format!("ERROR {e}"))
    }

    #[test]
    fn items_take_the_longest_phrase() {
        assert_eq!(kinds("police car"), ["<PoliceCar>"]);
        assert_eq!(kinds("stop sign"), ["<StopSign>"]);
        assert_eq!(kinds("traffic sign"), ["<TrafficSign>"]);
        assert_eq!(kinds("stop"), ["<Stopped>"]);
        assert_eq!(kinds("enter the scene"), ["<Appear>"]);
        assert_eq!(kinds("trafficlights"), ["<TrafficLight>"]);
        assert_eq!(kinds("the far left"), ["Det(Plain)", "<FarLeft>"]);
        assert_eq!(
            kinds("near the left"),
            ["Prep(Near)", "Det(Plain)", "<Left>"]
        );
        assert_eq!(kinds("zzz"), ["?"]);
    }

    #[test]
    fn variables_are_named_in_order_of_appearance() {
        assert_eq!(var_name(0), "x");
        assert_eq!(var_name(2), "z");
        assert_eq!(var_name(6), "x1");
        assert_eq!(
            query("Does the van get closer to the truck that approaches the bus?"),
            "TypeOf(x, Van)^TypeOf(y, Truck)^TypeOf(z, Bus)^GettingCloser(y, z)^GettingCloser(x, y)"
        );
    }
}
