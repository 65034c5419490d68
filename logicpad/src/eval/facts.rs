//! The fact base: ground base facts by predicate, read before reasoning.

use kanren::{FactId, Relation, Sym, Term};
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
    #[error("{}:{}:{}: cannot read fact `{}`: {}", .0.file, .0.line, .0.column, .0.trimmed(), .0.message)]
    Syntax(crate::facts_text::FactSyntax),
    /// Occurs when kanren refuses a tuple (e.g. a non-ground argument).
    #[error("cannot store a `{pred}` fact: {message}")]
    Store {
        /// Predicate.
        pred: String,
        /// kanren's message.
        message: String,
    },
}

impl From<crate::facts_text::FactSyntax> for FactError {
    fn from(s: crate::facts_text::FactSyntax) -> FactError {
        FactError::Syntax(s)
    }
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
        self.insert(pred, args).map(|(_, new)| new)
    }

    /// Adds a fact given as terms and returns its id in its predicate's
    /// relation with whether it is new (a duplicate returns the id of the
    /// copy already stored). Ids are insertion order from 0 per predicate,
    /// and [`crate::Program::evaluate`] keeps them for the base facts, so a
    /// caller can key side tables (provenance, source order) by them.
    pub fn insert(&mut self, pred: &str, args: &[Term]) -> Result<(FactId, bool), FactError> {
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
        let (id, new) = rel.insert(args).map_err(|e| FactError::Store {
            pred: pred.to_string(),
            message: e.to_string(),
        })?;
        if new {
            self.count += 1;
        }
        Ok((id, new))
    }

    /// Adds every fact of a text with one `Pred(a, b)` (or `Pred()`) per line
    /// (blank lines and `#` or `%` comments skipped; the line syntax is
    /// [`crate::facts_text::parse_fact_line`]'s). Returns the number of new
    /// facts.
    pub fn add_text(&mut self, text: &str, file: &str) -> Result<usize, FactError> {
        let mut added = 0;
        let mut args: Vec<Term> = Vec::with_capacity(4);
        // Names are borrowed from `text` and interned, never copied: a
        // `String` per name cost more than storing the fact.
        crate::facts_text::for_each_fact_line(text, file, |pred, names| {
            args.clear();
            args.extend(names.iter().map(|a| Term::Sym(Sym::new(a))));
            if self.add_terms(pred, &args)? {
                added += 1;
            }
            Ok::<(), FactError>(())
        })?;
        Ok(added)
    }

    /// Moves every fact of `other` into this base. A predicate only `other`
    /// holds moves whole, its fact ids unchanged (so bases filled on
    /// several threads, one set of predicates each, join without copying);
    /// one both hold gets `other`'s facts after its own, as [`Self::insert`]
    /// would add them.
    pub fn append(&mut self, other: FactBase) -> Result<(), FactError> {
        for rel in other.rels.into_values() {
            self.add_relation(rel)?;
        }
        Ok(())
    }

    /// Adds a whole relation under its own name: it moves in, its fact ids
    /// unchanged, when the base has no relation of that name; otherwise its
    /// facts follow the base's own, as [`Self::insert`] would add them.
    pub fn add_relation(&mut self, rel: Relation) -> Result<(), FactError> {
        let name = rel.name().as_str();
        if self.rels.contains_key(name) {
            let mut scratch = Vec::with_capacity(rel.arity());
            for (_, tuple) in rel.iter() {
                scratch.clear();
                scratch.extend(tuple.iter().cloned());
                self.insert(name, &scratch)?;
            }
        } else {
            self.count += rel.len();
            self.rels.insert(name.to_string(), rel);
        }
        Ok(())
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

#[cfg(test)]
mod tests {
    use super::*;

    fn ids(fb: &FactBase, pred: &str) -> Vec<String> {
        fb.relation(pred)
            .map(|r| r.iter().map(|(id, t)| format!("{id}:{t:?}")).collect())
            .unwrap_or_default()
    }

    #[test]
    fn append_moves_new_predicates_whole_and_merges_shared_ones() {
        let mut a = FactBase::from_text("P(x)\nQ(a, b)\n", "a").expect("parses");
        let b = FactBase::from_text("R(z)\nR(y)\nQ(c, d)\nQ(a, b)\n", "b").expect("parses");
        let r_before = ids(&b, "R");
        a.append(b).expect("appends");
        assert_eq!(a.len(), 5, "the duplicate `Q(a, b)` counts once");
        assert_eq!(ids(&a, "R"), r_before, "a moved relation keeps its ids");
        assert_eq!(a.relation("Q").map(|r| r.len()), Some(2));
        let c = FactBase::from_text("P(x, y)\n", "c").expect("parses");
        assert!(matches!(a.append(c), Err(FactError::Arity { .. })));
    }
}
