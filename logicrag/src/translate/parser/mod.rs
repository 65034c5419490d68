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
mod objects;
mod opening;
mod places;
mod relations;
mod values;

use super::lexer::{Closed, Det, Token, closed};
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
        if let Some(len) = closed_phrase(&toks[i..]) {
            // "right now", "at the moment": fillers that would otherwise
            // read as a place or a preposition.
            out.push(Item {
                kind: ItemKind::Closed(Closed::Filler),
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

/// How deeply object and verb phrases may nest.
const MAX_DEPTH: usize = 64;

/// Multi-word fillers, longest first.
const CLOSED_PHRASES: &[&[&str]] = &[
    &["at", "this", "moment"],
    &["at", "the", "moment"],
    &["at", "any", "point"],
    &["at", "some", "point"],
    &["right", "now"],
    &["at", "present"],
    &["at", "all"],
    &["as", "well"],
];

fn closed_phrase(toks: &[Token]) -> Option<usize> {
    CLOSED_PHRASES
        .iter()
        .find(|p| p.len() <= toks.len() && p.iter().zip(toks).all(|(w, t)| *w == t.raw))
        .map(|p| p.len())
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
        e
    }

    fn atom(&mut self, pred: &str, args: Vec<Arg>, negated: bool) {
        self.drafts.push(Draft {
            pred: Pred::Name(pred.to_string()),
            args,
            negated,
        });
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
                    why: "a conjunctive query cannot count objects; two objects can only be asked about through a relation between them".into(),
                });
            }
        }
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
        let mut positive = Vec::new();
        let mut negative = Vec::new();
        for d in &self.drafts {
            if !matches!(d.pred, Pred::Name(_)) {
                continue;
            }
            if d.negated {
                negative.push(d)
            } else {
                positive.push(d)
            }
        }
        let mut names: Vec<Option<String>> = vec![None; self.entities];
        let mut next = 0;
        let mut atoms: Vec<QueryAtom> = Vec::new();
        for d in positive.into_iter().chain(negative) {
            let Pred::Name(name) = &d.pred else { continue };
            let mut args = Vec::new();
            for a in &d.args {
                match a {
                    Arg::Const(c) => args.push(c.clone()),
                    Arg::Var(v) if self.constants.iter().any(|(e, _)| e == v) => {
                        let c = self
                            .constants
                            .iter()
                            .find(|(e, _)| e == v)
                            .map(|(_, c)| c.clone());
                        args.push(c.unwrap_or_default());
                    }
                    Arg::Var(v) => {
                        let slot = names.get_mut(*v);
                        let n = match slot {
                            Some(Some(n)) => n.clone(),
                            Some(s) => {
                                let n = var_name(next);
                                next += 1;
                                *s = Some(n.clone());
                                n
                            }
                            None => var_name(*v),
                        };
                        args.push(n);
                    }
                }
            }
            let atom = QueryAtom {
                predicate: name.clone(),
                args,
                negated: d.negated,
            };
            if !atoms.contains(&atom) {
                atoms.push(atom);
            }
        }
        if atoms.is_empty() {
            return Err(TranslateError::NoContent);
        }
        let query = atoms
            .iter()
            .map(|a| a.to_string())
            .collect::<Vec<_>>()
            .join("^");
        Ok(Translation {
            query,
            atoms,
            notes: self.notes,
            intent: if self.counts {
                super::Intent::HowMany
            } else if self.wh_open {
                super::Intent::Which
            } else {
                super::Intent::YesNo
            },
        })
    }
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
        assert_eq!(kinds("stop sign"), ["<TrafficSign>"]);
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
