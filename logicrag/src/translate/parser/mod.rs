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
//! - `result`: the checks on the forms a question combines and the final
//!   atoms and query text.

mod actions;
mod clauses;
mod forms;
mod objects;
mod opening;
mod places;
mod relations;
mod result;
#[cfg(test)]
mod tests;
mod values;

use super::lexer::{Closed, Det, Token, Wrap, closed};
use super::lexicon::{Entry, Lexicon, Sense};
use super::{Anchor, TranslateError, Translation, UnplacedWord};

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
}
