//! The fact base: ground base facts by predicate, read before reasoning.

use kanren::{Relation, Sym, Term};
use std::collections::BTreeMap;

/// Errors while building a fact base or evaluating.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum FactError {
    /// Occurs when a predicate is used with two different arities.
    #[error("`{pred}` has {expected} argument(s), but a fact gives {got}")]
    Arity {
        /// Predicate.
        pred: String,
        /// Arity fixed earlier (by the LogicPad or the first fact).
        expected: usize,
        /// Arity of the offending fact.
        got: usize,
    },
    /// Occurs when a fact line of a `.facts` text does not parse.
    #[error("{file}:{line}:{column}: cannot read fact `{text}`: {message}")]
    Syntax {
        /// File name given to the parser.
        file: String,
        /// 1-based line.
        line: usize,
        /// 1-based column of the offending character.
        column: usize,
        /// What was expected there.
        message: String,
        /// The line's text.
        text: String,
    },
    /// Occurs when kanren refuses a tuple (e.g. a non-ground argument).
    #[error("cannot store a `{pred}` fact: {message}")]
    Store {
        /// Predicate.
        pred: String,
        /// kanren's message.
        message: String,
    },
}

/// Ground base facts by predicate name, before reasoning.
///
/// Invariant: every relation's name is its key, and its arity is fixed by
/// its first fact.
#[derive(Debug, Clone, Default)]
pub struct FactBase {
    pub(super) rels: BTreeMap<String, Relation>,
    pub(super) count: usize,
}

impl FactBase {
    /// An empty fact base.
    pub fn new() -> FactBase {
        FactBase::default()
    }

    /// Adds `pred(args…)` with constant arguments; `Ok(false)` for a duplicate.
    pub fn add(&mut self, pred: &str, args: &[&str]) -> Result<bool, FactError> {
        let terms: Vec<Term> = args.iter().map(|a| Term::Sym(Sym::new(a))).collect();
        self.add_terms(pred, &terms)
    }

    /// Adds a fact given as terms (ground atoms).
    pub fn add_terms(&mut self, pred: &str, args: &[Term]) -> Result<bool, FactError> {
        let rel = match self.rels.get_mut(pred) {
            Some(r) => r,
            None => self
                .rels
                .entry(pred.to_string())
                .or_insert_with(|| Relation::new(Sym::new(pred), args.len())),
        };
        if rel.arity() != args.len() {
            return Err(FactError::Arity {
                pred: pred.to_string(),
                expected: rel.arity(),
                got: args.len(),
            });
        }
        let (_, new) = rel.insert(args).map_err(|e| FactError::Store {
            pred: pred.to_string(),
            message: e.to_string(),
        })?;
        if new {
            self.count += 1;
        }
        Ok(new)
    }

    /// Adds every fact of a text with one `Pred(a, b)` (or `Pred()`) per line
    /// (blank lines and `#` or `%` comments skipped; the line syntax is
    /// [`crate::facts_text::parse_fact_line`]'s). Returns the number of new
    /// facts.
    pub fn add_text(&mut self, text: &str, file: &str) -> Result<usize, FactError> {
        let mut added = 0;
        let mut args: Vec<Term> = Vec::with_capacity(4);
        for (i, raw) in text.lines().enumerate() {
            let line = raw.trim();
            if line.is_empty() || line.starts_with('#') || line.starts_with('%') {
                continue;
            }
            let fact = crate::facts_text::parse_fact_line(line).map_err(|(col, message)| {
                FactError::Syntax {
                    file: file.to_string(),
                    line: i + 1,
                    column: col + 1 + (raw.len() - raw.trim_start().len()),
                    message,
                    text: line.to_string(),
                }
            })?;
            args.clear();
            args.extend(fact.args.iter().map(|a| Term::Sym(Sym::new(a))));
            let pred = fact.predicate.as_str();
            if self.add_terms(pred, &args)? {
                added += 1;
            }
        }
        Ok(added)
    }

    /// Parses a whole `.facts` text.
    pub fn from_text(text: &str, file: &str) -> Result<FactBase, FactError> {
        let mut fb = FactBase::new();
        fb.add_text(text, file)?;
        Ok(fb)
    }

    /// The relation of a predicate.
    pub fn relation(&self, pred: &str) -> Option<&Relation> {
        self.rels.get(pred)
    }

    /// Number of distinct facts.
    pub fn len(&self) -> usize {
        self.count
    }

    /// True when there is no fact.
    pub fn is_empty(&self) -> bool {
        self.count == 0
    }
}
