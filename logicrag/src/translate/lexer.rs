//! Normalisation, tokens, stems and the closed-class words of the grammar.
//!
//! Content words are compared by stem on both sides (question and phrase),
//! so the stemmer only needs to be consistent, not linguistically exact:
//! "moves", "moving", "moved" and "move" all become `mov`.

use super::vocab::Anchor;

/// One word of a question.
///
/// Invariant: `raw` is lower-case and non-empty; `index` is the word's
/// position among the question's words (0-based) and `offset` the byte
/// offset of its first character in the original question.
#[derive(Debug, Clone, PartialEq, Eq)]
pub(crate) struct Token {
    pub raw: String,
    pub stem: String,
    pub index: usize,
    pub offset: usize,
}

/// Splits a question into lower-case words, expanding contractions and
/// dropping punctuation. Hyphens split words ("left-hand" → "left", "hand").
pub(crate) fn tokenize(question: &str) -> Vec<Token> {
    let mut words: Vec<(String, usize)> = Vec::new();
    let mut cur = String::new();
    let mut start = 0usize;
    for (off, c) in question.char_indices() {
        let apostrophe = c == '\'' || c == '\u{2019}';
        // `_` joins the parts of an object constant such as `car_3`.
        let joiner = c == '_' && !cur.is_empty();
        if c.is_alphanumeric() || joiner || (apostrophe && !cur.is_empty()) {
            if cur.is_empty() {
                start = off;
            }
            if apostrophe {
                cur.push('\'');
            } else {
                cur.extend(c.to_lowercase());
            }
        } else if !cur.is_empty() {
            words.push((std::mem::take(&mut cur), start));
        }
    }
    if !cur.is_empty() {
        words.push((cur, start));
    }
    let mut out = Vec::new();
    for (w, off) in words {
        for part in expand_contraction(&w) {
            if part.is_empty() {
                continue;
            }
            let stem = stem(&part);
            out.push(Token {
                raw: part,
                stem,
                index: out.len(),
                offset: off,
            });
        }
    }
    out
}

fn expand_contraction(w: &str) -> Vec<String> {
    let w = w.trim_matches('\'');
    match w {
        "can't" | "cannot" => return vec!["can".into(), "not".into()],
        "won't" => return vec!["will".into(), "not".into()],
        "shan't" => return vec!["shall".into(), "not".into()],
        _ => {}
    }
    if let Some(base) = w.strip_suffix("n't") {
        return vec![base.to_string(), "not".into()];
    }
    for (suffix, full) in [
        ("'re", "are"),
        ("'ll", "will"),
        ("'ve", "have"),
        ("'m", "am"),
        ("'d", "would"),
    ] {
        if let Some(base) = w.strip_suffix(suffix) {
            return vec![base.to_string(), full.to_string()];
        }
    }
    if let Some(base) = w.strip_suffix("'s") {
        // "there's", "it's": a verb; a possessive stays visible as "'s" so that
        // the grammar reports it instead of dropping it.
        if matches!(
            base,
            "there" | "it" | "what" | "that" | "here" | "who" | "where" | "which"
        ) {
            return vec![base.to_string(), "is".into()];
        }
        return vec![base.to_string(), "'s".into()];
    }
    vec![w.replace('\'', "")]
}

/// Irregular forms mapped to a base form before stemming.
fn irregular(w: &str) -> Option<&'static str> {
    Some(match w {
        "people" => "person",
        "men" => "man",
        "women" => "woman",
        "children" => "child",
        "went" | "gone" | "goes" | "going" => "go",
        "ran" => "run",
        "drove" | "driven" => "drive",
        "rode" | "ridden" => "ride",
        "stood" => "stand",
        "sped" => "speed",
        "got" | "gotten" => "get",
        "came" => "come",
        "saw" | "seen" => "see",
        "shown" => "show",
        "found" => "find",
        "began" | "begun" => "begin",
        "taxis" => "taxi",
        "buses" | "busses" => "bus",
        "hit" | "hits" | "hitting" => "hit",
        "data" => "data",
        _ => return None,
    })
}

fn is_vowel(c: u8) -> bool {
    matches!(c, b'a' | b'e' | b'i' | b'o' | b'u' | b'y')
}

/// A small suffix-stripping stemmer (plural and verb endings, final `e`,
/// doubled final consonant). Non-ASCII words are returned unchanged.
pub(crate) fn stem(word: &str) -> String {
    if let Some(base) = irregular(word)
        && base != word
    {
        return stem(base);
    }
    if !word.is_ascii() {
        return word.to_string();
    }
    let mut s = word.to_string();
    let n = s.len();
    if n > 4 && s.ends_with("ies") {
        s.truncate(n - 3);
        s.push('y');
    } else if n > 4
        && ["sses", "ches", "shes", "xes", "zes", "ses"]
            .iter()
            .any(|e| s.ends_with(e))
    {
        s.truncate(n - 2);
    } else if n >= 4
        && s.ends_with('s')
        && !s.ends_with("ss")
        && !s.ends_with("us")
        && !s.ends_with("is")
    {
        s.truncate(n - 1);
    }
    let n = s.len();
    let has_vowel = |t: &str| t.bytes().any(is_vowel);
    if n >= 6 && s.ends_with("ing") && has_vowel(&s[..n - 3]) {
        s.truncate(n - 3);
    } else if n >= 5 && s.ends_with("ed") && !s.ends_with("eed") && has_vowel(&s[..n - 2]) {
        s.truncate(n - 2);
    }
    let n = s.len();
    if n > 3 && s.ends_with('e') {
        s.truncate(n - 1);
    }
    let b = s.as_bytes();
    let n = b.len();
    if n >= 4 {
        let (a, c) = (b[n - 2], b[n - 1]);
        if a == c && !is_vowel(c) && !matches!(c, b'l' | b's' | b'z') {
            s.truncate(n - 1);
        }
    }
    s
}

/// Kinds of determiner.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Det {
    /// a, an, any, some, the, this, these, those, every, each
    Plain,
    /// another, other
    Another,
    /// no (a negated existence)
    No,
    /// every, all (a universal)
    All,
}

/// Prepositions the grammar distinguishes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Prep {
    On,
    At,
    In,
    To,
    From,
    Of,
    Near,
    Toward,
    Into,
    With,
    By,
    Between,
    During,
    Other,
}

/// A time word that says over which windows of a video a query holds.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Wrap {
    /// ever, at any point, at some point: some window (`EVER: Q`).
    Ever,
    /// throughout, always, the whole time: every window (`THROUGHOUT: Q`).
    Throughout,
    /// still: the last window and every one since it first held (`STILL: Q`).
    Still,
}

/// Closed-class words: the fixed part of the grammar.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Closed {
    Det(Det),
    Num(u32),
    /// is, are, was, were, be, am
    Be,
    /// does, do, did, has, have, had, can, could, will, would, ...
    Aux,
    Neg,
    There,
    /// it, they, them, its, their
    Pronoun,
    /// you, we, i, me, us
    You,
    /// see, spot, find, notice, detect, observe, identify, show, list
    Perceive,
    Prep(Prep),
    And,
    Or,
    /// that, which, who, whose
    Rel,
    /// what, which (at the start)
    What,
    How,
    /// where, when, why
    OtherWh,
    /// scene, frame, image, video, view, ...
    Scene,
    Time(Anchor),
    Few,
    Filler,
    /// side, hand, part, half, lane, ...
    LocSuffix,
    /// far, close (as place modifiers)
    Far,
    Close,
    /// one, object, thing, something, anything, ...
    HeadWord,
    /// shift, change, go, head, drift, turn
    MotionVerb,
    /// start, begin (Initial); end, finish (Last)
    AnchorVerb(Anchor),
    /// keep, become, seem, look, get
    CopVerb,
    /// stay, remain: a place that holds in the first and the last frames
    Stay,
    Distance,
    SpeedNoun,
    PositionNoun,
    Each,
    Due,
    Because,
    Please,
    /// then: the next verb phrase happens after the one before it.
    Then,
    /// before, after: a clause ordered in time against another.
    Before,
    After,
    /// ever, always, still, throughout, "at any point", "the whole time".
    Temporal(Wrap),
    /// again, once more: a repetition no query can say.
    Again,
}

/// The closed-class reading of a lower-case word.
pub(crate) fn closed(raw: &str) -> Option<Closed> {
    use Closed::*;
    Some(match raw {
        "a" | "an" | "any" | "some" | "the" | "this" | "these" | "those" | "its" | "their"
        | "our" | "my" | "your" | "his" | "her" => Det(self::Det::Plain),
        "every" | "all" | "everything" | "everyone" => Det(self::Det::All),
        "another" | "other" | "others" => Det(self::Det::Another),
        "no" | "none" | "nothing" | "nobody" | "noone" => Det(self::Det::No),
        "one" => Num(1),
        "two" | "2" | "both" | "pair" => Num(2),
        "three" => Num(3),
        "four" => Num(4),
        "five" => Num(5),
        "six" => Num(6),
        "seven" => Num(7),
        "eight" => Num(8),
        "nine" => Num(9),
        "ten" => Num(10),
        "eleven" => Num(11),
        "twelve" => Num(12),
        "zero" => Num(0),
        d if !d.is_empty() && d.len() <= 6 && d.bytes().all(|b| b.is_ascii_digit()) => {
            Num(d.parse().unwrap_or(u32::MAX))
        }
        "several" | "many" | "multiple" => Num(2),
        "is" | "are" | "was" | "were" | "be" | "am" | "been" | "being" => Be,
        "does" | "do" | "did" | "has" | "have" | "had" | "can" | "could" | "will" | "would"
        | "should" | "may" | "might" | "must" | "shall" => Aux,
        "not" | "never" | "non" => Neg,
        "there" => There,
        "it" | "they" | "them" | "itself" | "themselves" => Pronoun,
        "you" | "we" | "i" | "me" | "us" => You,
        "see" | "spot" | "find" | "notice" | "detect" | "observe" | "identify" | "show"
        | "list" | "locate" | "spotted" | "seen" | "saw" | "sees" | "spots" | "noticed"
        | "detected" | "observed" | "identified" => Perceive,
        "on" | "upon" => Prep(self::Prep::On),
        "at" => Prep(self::Prep::At),
        "in" | "inside" | "within" => Prep(self::Prep::In),
        "to" => Prep(self::Prep::To),
        "from" => Prep(self::Prep::From),
        "of" => Prep(self::Prep::Of),
        "near" | "nearby" | "beside" | "next" => Prep(self::Prep::Near),
        "towards" | "toward" => Prep(self::Prep::Toward),
        "into" | "onto" => Prep(self::Prep::Into),
        "with" => Prep(self::Prep::With),
        "by" => Prep(self::Prep::By),
        "between" | "among" => Prep(self::Prep::Between),
        "during" | "over" => Prep(self::Prep::During),
        "throughout" | "always" => Temporal(Wrap::Throughout),
        "ever" => Temporal(Wrap::Ever),
        "still" => Temporal(Wrap::Still),
        "again" => Again,
        "then" => Then,
        "before" => Before,
        "after" => After,
        "across" | "along" | "through" | "behind" | "off" | "out" | "up" | "down" | "away"
        | "under" | "above" | "around" | "than" | "for" | "about" | "against" | "past" => {
            Prep(self::Prep::Other)
        }
        "and" | "but" | "while" => And,
        "or" | "either" | "nor" => Or,
        "that" | "which" | "who" | "whose" => Rel,
        "what" => What,
        "how" => How,
        "where" | "when" | "why" | "whether" | "if" => OtherWh,
        "scene" | "scenes" | "frame" | "frames" | "image" | "images" | "video" | "videos"
        | "view" | "picture" | "clip" | "footage" | "sequence" | "window" | "screen" | "shot"
        | "snapshot" | "camera" | "dashcam" => Scene,
        "initial" | "first" | "beginning" | "early" | "earlier" | "initially" | "opening"
        | "starting" => Time(Anchor::Initial),
        "last" | "later" | "final" | "finally" | "late" | "latter" | "eventually" | "closing"
        | "ending" | "subsequent" | "afterwards" | "afterward" => Time(Anchor::Last),
        "few" | "couple" | "moments" | "moment" | "seconds" | "second" | "instants" => Few,
        "also" | "visible" | "currently" | "really" | "actually" | "just" | "somewhere"
        | "anywhere" | "here" | "now" | "located" | "positioned" | "situated" | "present"
        | "presently" | "exactly" | "indeed" | "kindly" | "seemingly" | "colored" | "coloured"
        | "painted" | "directly" | "immediately" => Filler,
        "side" | "sides" | "hand" | "part" | "half" | "area" | "portion" | "corner" | "edge"
        | "lane" | "lanes" | "region" | "section" | "zone" => LocSuffix,
        "far" | "farther" | "further" | "distant" => Far,
        "close" | "closely" => Close,
        "object" | "objects" | "thing" | "things" | "something" | "anything" | "someone"
        | "anyone" | "somebody" | "anybody" | "entity" | "entities" | "ones" | "item" | "items" => {
            HeadWord
        }
        "shift" | "shifts" | "shifted" | "shifting" | "change" | "changes" | "changed"
        | "changing" | "go" | "goes" | "went" | "going" | "head" | "heads" | "heading"
        | "headed" | "drift" | "drifts" | "drifting" | "relocate" | "relocates" | "pass"
        | "passes" | "passing" | "come" | "comes" | "coming" | "came" => MotionVerb,
        "start" | "starts" | "started" | "begin" | "begins" | "begun" | "began" => {
            AnchorVerb(Anchor::Initial)
        }
        "end" | "ends" | "ended" | "finish" | "finishes" | "finished" | "arrive" | "arrives"
        | "arrived" | "arriving" => AnchorVerb(Anchor::Last),
        "remain" | "remains" | "remained" | "remaining" | "stay" | "stays" | "stayed"
        | "staying" => Stay,
        "keep" | "keeps" | "kept" | "keeping" | "become" | "becomes" | "became" | "seem"
        | "seems" | "look" | "looks" | "get" | "gets" | "getting" => CopVerb,
        "distance" | "distances" | "gap" | "separation" => Distance,
        "speed" | "speeds" | "velocity" | "velocities" | "pace" => SpeedNoun,
        "position" | "positions" | "location" | "locations" | "place" | "placement" => PositionNoun,
        "each" => Each,
        "due" => Due,
        "because" => Because,
        "please" => Please,
        _ => return None,
    })
}

/// True for words that only ever play a grammatical role; a vocabulary
/// phrase made only of such words cannot be told apart from the grammar.
pub(crate) fn is_closed_word(raw: &str) -> bool {
    closed(raw).is_some()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn stems_agree_across_forms() {
        let groups: &[&[&str]] = &[
            &["move", "moves", "moving", "moved"],
            &["stop", "stops", "stopping", "stopped"],
            &["cross", "crosses", "crossing", "crossed"],
            &["increase", "increases", "increasing", "increased"],
            &["car", "cars"],
            &["bus", "buses"],
            &["pedestrian", "pedestrians"],
            &["person", "persons", "people"],
            &["vehicle", "vehicles"],
            &["tree", "trees"],
            &["get", "gets", "getting", "got"],
            &["approach", "approaches", "approaching", "approached"],
            &["collide", "collides", "colliding", "collided"],
            &["speed", "speeds", "speeding"],
            &["brake", "brakes", "braking", "braked"],
            &["disappear", "disappears", "disappearing", "disappeared"],
            &["lorry", "lorries"],
            &["suv", "suvs"],
            &["taxi", "taxis"],
            &["ride", "rides", "riding", "rode"],
            &["park", "parked", "parking"],
            &["accelerate", "accelerates", "accelerating", "accelerated"],
        ];
        for g in groups {
            let s0 = stem(g[0]);
            for w in g.iter() {
                assert_eq!(stem(w), s0, "{w} vs {}", g[0]);
            }
        }
        assert_ne!(stem("red"), stem("r"));
        assert_eq!(stem("speed"), "speed");
        assert_eq!(stem("is"), "is");
    }

    #[test]
    fn tokenize_expands_contractions_and_drops_punctuation() {
        let t: Vec<String> = tokenize("Isn't the car's left-hand side, there's?")
            .into_iter()
            .map(|t| t.raw)
            .collect();
        assert_eq!(
            t,
            [
                "is", "not", "the", "car", "'s", "left", "hand", "side", "there", "is"
            ]
        );
        let t = tokenize("  Can't  SEE ");
        assert_eq!(t.len(), 3);
        assert_eq!(t[0].offset, 2);
        assert_eq!(t[2].raw, "see");
        assert_eq!(t[2].index, 2);
    }
}
