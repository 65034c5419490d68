//! English driving questions → conjunctive queries over the LogicPad
//! vocabulary, deterministically and without a model.
//!
//! - [`Vocabulary`] holds the content words: predicates (class nouns,
//!   properties, relations) and functions (`TypeOf`, `ColorOf`, locations)
//!   with English phrases. [`Vocabulary::builtin`] is the project's canonical
//!   vocabulary, read from the built-in LogicPad; [`Vocabulary::from_schema`]
//!   reads a LogicPad's schema (its `role:` and `phrases:`, inferring roles
//!   it does not declare); [`Vocabulary::builder`] makes others.
//! - [`Translator`] compiles a vocabulary into a lexicon (`lexicon.rs`:
//!   phrases keyed by stems, with the senses the grammar reads) once and parses
//!   questions with a small closed-class grammar: opening frames ("is there",
//!   "can you spot", "does", "is"), object phrases (colour/type/class,
//!   plurals, "any", "another"), places (left/right/front, near/far, first vs
//!   last frames, "moves from front to left"), actions, relations between two
//!   objects ("the distance between A and B decreases", "gets closer to",
//!   "to the right of the pedestrian"), value questions ("what colour is the
//!   van?" → `ColorOf(x, y)`), relative clauses and negation (`parser/`,
//!   one file per phrase kind).
//! - [`Translation`] is the query in the reference form
//!   (`TypeOf(x, Car)^ColorOf(x, White)^InitialLocation(x, Left)`), its atoms
//!   and notes on every liberty taken ("'parked' read as Stopped").
//! - [`TranslateError`] names every word the grammar could not place, with
//!   its position; nothing in a question is silently dropped.
//! - [`csv`] reads a `Question` column and writes `Question,Query` files.

pub mod csv;
mod lexer;
mod lexicon;
mod parser;
mod schema;
mod vocab;

use std::fmt;

use thiserror::Error;

use lexicon::Lexicon;
pub use vocab::{
    Anchor, FunctionRole, FunctionSpec, PredicateRole, PredicateSpec, ValueSpec, Vocabulary,
    VocabularyBuilder, VocabularyError,
};
pub(crate) use vocab::{camel_words, default_phrase};

/// One atom of a translated query.
///
/// Invariant: `args` holds variables (`x`, `y`, `z`, ...) and CamelCase
/// value constants only, as many as the predicate's arity.
#[derive(Debug, Clone, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct QueryAtom {
    /// Predicate or function name, e.g. `TypeOf`.
    pub predicate: String,
    /// Arguments, e.g. `["x", "Car"]`.
    pub args: Vec<String>,
    /// True for `¬P(x)`.
    pub negated: bool,
}

impl fmt::Display for QueryAtom {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        if self.negated {
            f.write_str("¬")?;
        }
        write!(f, "{}({})", self.predicate, self.args.join(", "))
    }
}

/// A question's translation.
///
/// Invariant: for [`Form::Conjunction`], `query` is `atoms` rendered with
/// `^` between them; positive atoms come before negated ones so that every
/// variable of a negated atom is bound first; variables are named in order
/// of first appearance. For any other form `atoms` is empty and `query` is
/// the query's text in the LogicPad's syntax (`¬∃y: (…)`, `#{x: …} > 2`,
/// `(…) THEN (…)`, `EVER: …`), which is parsed to run it.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Translation {
    /// The query in the reference form.
    pub query: String,
    /// The atoms of the query, in order (empty unless a conjunction).
    pub atoms: Vec<QueryAtom>,
    /// Readings worth telling the user: synonyms, approximations.
    pub notes: Vec<String>,
    /// What the question asks for, as the grammar read it.
    pub intent: Intent,
    /// The shape of the query.
    pub form: Form,
}

/// The shape of a translated query.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Form {
    /// A conjunction of atoms and negated atoms: `atoms` is the query.
    #[default]
    Conjunction,
    /// A conjunction with scoped negations (`¬∃y: (Road(y)^On(x, y))`), or
    /// a denial as a whole (`¬∃x: (TypeOf(x, Truck))`): "not on the road",
    /// "no trucks", "which car is closest".
    Scoped,
    /// A counting threshold: `#{x: TypeOf(x, Car)} > 2`.
    Count,
    /// A query over a video's windows: `(Q1) THEN (Q2)`, `EVER: Q`, …
    Temporal,
}

impl Translation {
    /// True when the query is a plain conjunction of `atoms`.
    pub fn is_conjunction(&self) -> bool {
        self.form == Form::Conjunction
    }

    /// The atoms as the literals of a conjunctive query's syntax tree
    /// ([`logicpad::QueryAst::conjunction`]).
    pub fn literals(&self) -> Vec<logicpad::LiteralSpec> {
        self.atoms
            .iter()
            .map(|a| logicpad::LiteralSpec {
                pred: a.predicate.clone(),
                args: a.args.clone(),
                negated: a.negated,
            })
            .collect()
    }
}

/// What a question asks for: decided by whoever reads the question (the
/// grammar from its opening; an LLM translation from the question's first
/// words), and read by the summary, never re-derived from the text there.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, serde::Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Intent {
    /// "Is there …?", "Does …?": yes or no.
    #[default]
    YesNo,
    /// "How many …?": the number of distinct objects (or pairs).
    HowMany,
    /// "Which …?", "What colour …?": the objects or values that answer.
    Which,
}

impl Intent {
    /// The intent of a question no grammar read (an LLM translated it):
    /// its opening words.
    pub(crate) fn of_question(question: &str) -> Intent {
        let words: Vec<String> = question
            .split(|c: char| !c.is_alphanumeric())
            .filter(|w| !w.is_empty())
            .take(2)
            .map(str::to_lowercase)
            .collect();
        match words
            .iter()
            .map(String::as_str)
            .collect::<Vec<_>>()
            .as_slice()
        {
            ["how", "many"] => Intent::HowMany,
            ["what" | "which", ..] => Intent::Which,
            _ => Intent::YesNo,
        }
    }

    /// True for "how many".
    pub fn counts(self) -> bool {
        self == Intent::HowMany
    }
}

/// A word the grammar could not place.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct UnplacedWord {
    /// The word, lower-cased.
    pub word: String,
    /// Its position among the question's words, 0-based.
    pub index: usize,
    /// Byte offset of the word in the question.
    pub offset: usize,
    /// Why it could not be placed.
    pub reason: String,
    /// A close vocabulary word, when the word looks like a misspelling.
    pub suggestion: Option<String>,
}

impl fmt::Display for UnplacedWord {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "'{}' (word {}: {}",
            self.word,
            self.index + 1,
            self.reason
        )?;
        if let Some(s) = &self.suggestion {
            write!(f, "; did you mean '{s}'?")?;
        }
        f.write_str(")")
    }
}

fn list_words(words: &[UnplacedWord]) -> String {
    words
        .iter()
        .map(|w| w.to_string())
        .collect::<Vec<_>>()
        .join(", ")
}

/// Why a question could not be translated.
#[derive(Debug, Clone, PartialEq, Eq, Error)]
pub enum TranslateError {
    /// Occurs when the question holds no words.
    #[error("the question is empty")]
    Empty,
    /// Occurs when some words fit neither the grammar nor the vocabulary, or
    /// fit it only in a place where they make no sense.
    #[error("could not understand {}: {}", if .words.len() == 1 { "one word" } else { "some words" }, list_words(.words))]
    Unplaced {
        /// The question as given.
        question: String,
        /// Every word that could not be placed, in order.
        words: Vec<UnplacedWord>,
    },
    /// Occurs when the question is understood but asks for something a
    /// conjunctive query cannot say (counting, "or", "no car").
    #[error("cannot express {what} (word {}): {why}", .index + 1)]
    Unsupported {
        /// The words at fault.
        what: String,
        /// Position of the first of them, 0-based.
        index: usize,
        /// Why it cannot be expressed.
        why: String,
    },
    /// Occurs when the question's words were all understood but none of them
    /// constrains anything ("is there anything?").
    #[error("the question asks about nothing the vocabulary can describe")]
    NoContent,
    /// Occurs when the question is longer than `MAX_QUESTION_BYTES`: no
    /// question is, and the grammar's look-ahead is not linear in the
    /// words (the fuzzer's 1.2 MB question took 24 s).
    #[error("the question is {len} bytes long, more than the {limit} a question may have")]
    TooLong {
        /// Its length in bytes.
        len: usize,
        /// `MAX_QUESTION_BYTES`.
        limit: usize,
    },
}

/// The longest question translated, in bytes: some fifty lines of text,
/// far beyond any question, small enough that the grammar answers in
/// milliseconds whatever the words.
pub(crate) const MAX_QUESTION_BYTES: usize = 4096;

/// True when `text` is written as a query rather than a question: it holds
/// an atom, a capitalised name directly followed by `(` (`Moving(x)`,
/// `TypeOf(x, Car)`), which no English question does.
pub(crate) fn looks_like_query(text: &str) -> bool {
    let chars: Vec<char> = text.chars().collect();
    chars.iter().enumerate().any(|(i, &c)| {
        if c != '(' {
            return false;
        }
        let mut j = i;
        while j > 0
            && chars
                .get(j - 1)
                .is_some_and(|p| p.is_alphanumeric() || *p == '_')
        {
            j -= 1;
        }
        j < i && chars.get(j).is_some_and(|f| f.is_uppercase())
    })
}

/// Translates questions with one vocabulary.
///
/// Invariant: `lexicon` is compiled from `vocab` and never changes after
/// construction, so a translator can be shared between threads.
#[derive(Debug, Clone)]
pub struct Translator {
    vocab: Vocabulary,
    lexicon: Lexicon,
}

impl Translator {
    /// Compiles a vocabulary into a translator.
    pub fn new(vocab: Vocabulary) -> Translator {
        let lexicon = Lexicon::new(&vocab);
        Translator { vocab, lexicon }
    }

    /// A translator over [`Vocabulary::builtin`].
    pub fn builtin() -> Translator {
        Translator::new(Vocabulary::builtin())
    }

    /// The vocabulary this translator was built from.
    pub fn vocabulary(&self) -> &Vocabulary {
        &self.vocab
    }

    /// Vocabulary phrases that could not be used because they consist only
    /// of grammar words (e.g. a value named `Other`), with the reason.
    pub fn skipped_phrases(&self) -> &[String] {
        &self.lexicon.skipped
    }

    /// Translates one question.
    ///
    /// # Errors
    /// [`TranslateError`]: empty question, words that cannot be placed (all
    /// of them are listed), a meaning a conjunctive query cannot hold, or a
    /// question longer than `MAX_QUESTION_BYTES`.
    pub fn translate(&self, question: &str) -> Result<Translation, TranslateError> {
        if question.len() > MAX_QUESTION_BYTES {
            return Err(TranslateError::TooLong {
                len: question.len(),
                limit: MAX_QUESTION_BYTES,
            });
        }
        let tokens = lexer::tokenize(question);
        if tokens.is_empty() {
            return Err(TranslateError::Empty);
        }
        parser::parse(&self.lexicon, question, &tokens)
    }

    /// Translates the `Question` column of a CSV text into a CSV text with
    /// the columns `Question,Query,Error`: the query when translated, else an
    /// empty query and the error message. Every input row gives one row.
    ///
    /// # Errors
    /// [`csv::CsvError`] when the input is not CSV or has no `Question` column.
    pub fn translate_csv(&self, input: &str) -> Result<String, csv::CsvError> {
        let questions = csv::column(input, "Question")?;
        let mut out = String::new();
        csv::write_record(&mut out, &["Question", "Query", "Error"]);
        for q in &questions {
            match self.translate(q) {
                Ok(t) => csv::write_record(&mut out, &[q, &t.query, ""]),
                Err(e) => csv::write_record(&mut out, &[q, "", &e.to_string()]),
            }
        }
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Regression (fuzzer, issue 13): a megabyte of text was parsed as a
    /// question, quadratically (`{"a":` × 100,000 took 24 s); it is refused
    /// by its length, and a question at the limit is still read.
    #[test]
    fn overlong_questions_are_refused_by_length() {
        let t = Translator::builtin();
        let huge = "{\"a\":".repeat(100_000);
        assert_eq!(
            t.translate(&huge),
            Err(TranslateError::TooLong {
                len: huge.len(),
                limit: MAX_QUESTION_BYTES,
            })
        );
        let question = "Is there a white car?";
        let padded = format!(
            "{question}{}",
            " ".repeat(MAX_QUESTION_BYTES - question.len())
        );
        assert_eq!(padded.len(), MAX_QUESTION_BYTES);
        assert!(t.translate(&padded).is_ok());
        assert!(t.translate(&format!("{padded} ")).is_err());
    }

    #[test]
    fn a_translator_is_shareable_between_threads() {
        fn shareable<T: Send + Sync>(_: &T) {}
        shareable(&Translator::builtin());
    }

    #[test]
    fn queries_are_told_from_questions() {
        assert!(looks_like_query("TypeOf(x, Car)^Moving(x)"));
        assert!(looks_like_query("∃x: ¬Moving(x)"));
        assert!(!looks_like_query("Is the car (the white one) moving?"));
        assert!(!looks_like_query("Is there a white car on the left?"));
        assert!(!looks_like_query(""));
    }

    /// Issue 22: counting questions that end in a verb of seeing or of
    /// being there were refused ("can you see" was read only at the start).
    #[test]
    fn counting_questions_may_end_in_seeing_or_being_there() {
        let t = Translator::builtin();
        let there = t.translate("How many trucks are there?").unwrap();
        assert!(there.intent.counts());
        for q in [
            "How many trucks can you see?",
            "How many trucks do you see?",
            "How many trucks are visible?",
            "How many trucks are seen?",
            "How many trucks are present?",
            "How many trucks can be seen?",
            "How many trucks can you spot?",
            "how many trucks can you see",
        ] {
            let got = t.translate(q).unwrap_or_else(|e| panic!("{q}: {e}"));
            assert_eq!(got.query, there.query, "{q}");
            assert!(got.intent.counts(), "{q}");
        }
        let moving = t.translate("How many moving cars are there?").unwrap();
        let seen = t.translate("How many moving cars can you see?").unwrap();
        assert_eq!(seen.query, moving.query);
        let which = t.translate("Which white car can you see on the left?");
        assert!(which.is_ok(), "{which:?}");
    }

    #[test]
    fn errors_read_well() {
        let t = Translator::builtin();
        let e = t.translate("Is the car wibbling?").unwrap_err();
        assert_eq!(
            e.to_string(),
            "could not understand one word: 'wibbling' (word 4: not in the vocabulary)"
        );
        let e = t.translate("Are there two cars?").unwrap_err();
        assert!(
            e.to_string().starts_with("cannot express two (word 3)"),
            "{e}"
        );
        let a = QueryAtom {
            predicate: "Moving".into(),
            args: vec!["x".into()],
            negated: true,
        };
        assert_eq!(a.to_string(), "¬Moving(x)");
    }
}

#[cfg(test)]
mod intent_tests {
    use super::Intent;
    use crate::engine::Engine;
    use crate::kb::Observability;

    #[test]
    fn the_grammar_gives_the_intent_and_the_summary_needs_no_rereading() {
        let Ok(e) = Engine::new(logicpad::LogicPad::builtin(), Observability::everything()) else {
            panic!("built-in engine")
        };
        for (q, want) in [
            ("Is there a white car?", Intent::YesNo),
            ("How many cars are there?", Intent::HowMany),
            ("How many trucks can you see?", Intent::HowMany),
            ("Which vehicles are moving?", Intent::Which),
            ("What colour is the van?", Intent::Which),
            ("Can you tell me whether a car is moving?", Intent::YesNo),
        ] {
            match e.prepare(q) {
                Ok(p) => assert_eq!(p.intent, want, "{q}"),
                Err(err) => panic!("{q}: {err}"),
            }
        }
        // A query as written asks yes or no.
        assert_eq!(e.prepare_query("Vehicles(x)").intent, Intent::YesNo);
        // What an LLM translated: the question's opening words.
        assert_eq!(
            Intent::of_question("how many people walk?"),
            Intent::HowMany
        );
        assert_eq!(Intent::of_question("Which one stops?"), Intent::Which);
        assert_eq!(Intent::of_question("Does anyone saunter?"), Intent::YesNo);
    }
}
