//! The lazy answers of a query ([`Model::answers`]), pulled one at a time
//! from its kanren run.

use super::ask::{AnswerSet, sorted_bindings};
use super::ast::QueryAnswer;
use super::compile::Compiled;
use crate::eval::{Model, ProofLimits};
use kanren::RunError;

/// The lazy answers of a query ([`Model::answers`]): its kanren run, pulled
/// one answer at a time.
///
/// Invariant: `seen` holds the answer tuples already returned, so each
/// distinct binding comes once.
pub struct Answers<'m> {
    pub(super) model: &'m Model,
    pub(super) program: Compiled,
    pub(super) run: kanren::Run,
    pub(super) seen: AnswerSet,
    pub(super) proofs: Option<ProofLimits>,
    pub(super) error: Option<RunError>,
}

impl Answers<'_> {
    /// The error that ended the run early, if one did.
    pub fn error(&self) -> Option<&RunError> {
        self.error.as_ref()
    }

    /// The limit the run stopped at, once it has (`None` while it runs,
    /// and when it ended with every answer).
    pub fn stopped(&self) -> Option<super::Stopped> {
        super::Stopped::of(self.run.stop_reason())
    }

    /// Search steps taken so far (candidate facts tried, goals run).
    pub fn steps(&self) -> u64 {
        self.run.steps()
    }
}

impl Iterator for Answers<'_> {
    type Item = QueryAnswer;

    fn next(&mut self) -> Option<QueryAnswer> {
        loop {
            let answer = match self.run.next()? {
                Ok(a) => a,
                Err(e) => {
                    self.error = Some(e);
                    return None;
                }
            };
            let key = self.program.key(&answer);
            if self.seen.contains(&key) {
                continue;
            }
            let bindings = sorted_bindings(&self.program.plan.names, &key);
            let proof = match (self.proofs, self.program.premises(&answer)) {
                (Some(limits), Some((alt, prem))) => match self.program.rule(alt) {
                    Some(rule) => {
                        let mut budget = limits.max_nodes;
                        self.model.proof_from_premises(
                            rule,
                            self.program.not_exists(alt),
                            &prem,
                            limits,
                            &mut budget,
                        )
                    }
                    None => Vec::new(),
                },
                _ => Vec::new(),
            };
            self.seen.insert(key);
            return Some(QueryAnswer { bindings, proof });
        }
    }
}
