//! Question → query by an LLM, Logic-LM style: the prompt lists the
//! LogicPad's vocabulary (predicates, arguments, phrases, declared values)
//! and few-shot examples; the reply is checked by the LogicPad checker, and
//! an invalid reply gets a repair prompt quoting the diagnostics, up to a
//! number of rounds. Then a clear refusal — never a weakened query.

use super::client::{LlmError, Message};
use super::{Chat, Templates, fill};
use logicpad::{LogicPad, ParsedQuery};
use serde::Serialize;

/// Why an LLM translation failed.
#[derive(Debug, thiserror::Error)]
pub enum LlmTranslateError {
    /// Occurs when the model says the question cannot be expressed.
    #[error("the LLM could not express the question: {0}")]
    Cannot(String),
    /// Occurs when every round's query failed the LogicPad's checks.
    #[error("the LLM's query `{query}` is still invalid after {rounds} round(s): {diagnostics}")]
    Invalid {
        /// The last query proposed.
        query: String,
        /// Rounds made (the first answer and its repairs).
        rounds: usize,
        /// The last diagnostics, one per line.
        diagnostics: String,
    },
    /// Occurs when the server cannot answer.
    #[error(transparent)]
    Llm(#[from] LlmError),
}

/// One request and reply of a translation.
#[derive(Debug, Clone, Serialize)]
pub struct Round {
    /// The prompt sent (the first, or a repair).
    pub prompt: String,
    /// The model's reply as given.
    pub reply: String,
    /// The query read from the reply.
    pub query: String,
    /// What the LogicPad checker said of it (empty when valid).
    pub diagnostics: Vec<String>,
}

/// A checked LLM translation.
#[derive(Debug, Clone)]
pub struct LlmTranslation {
    /// The valid query.
    pub query: String,
    /// It, parsed and checked.
    pub parsed: ParsedQuery,
    /// Every round, for the record.
    pub rounds: Vec<Round>,
}

/// Translates with an LLM, checking against a LogicPad.
#[derive(Debug, Clone, Copy)]
pub struct LlmTranslator<'a> {
    /// The server and cache.
    pub chat: &'a Chat,
    /// The prompts.
    pub templates: &'a Templates,
    /// The LogicPad whose vocabulary the query must use.
    pub pad: &'a LogicPad,
    /// Repair rounds after the first answer.
    pub repairs: u32,
}

/// Few-shot examples shown to the model.
pub(crate) const EXAMPLES: &str = include_str!("../../prompts/examples.txt");

impl LlmTranslator<'_> {
    /// The vocabulary part of the prompt: every predicate with its
    /// arguments, English phrases and declared values.
    pub fn vocabulary(&self) -> String {
        let mut lines = Vec::new();
        for p in self.pad.schema().predicates() {
            let args = if p.params.is_empty() {
                (0..p.arity)
                    .map(|i| ["x", "y", "z"].get(i).copied().unwrap_or("v").to_string())
                    .collect()
            } else {
                p.params.clone()
            };
            let mut line = format!("{}({})", p.name, args.join(", "));
            if !p.phrases.is_empty() {
                line.push_str(&format!(": {}", p.phrases.join(", ")));
            }
            if let Some(values) = &p.values {
                line.push_str(&format!(" — values: {}", values.join(", ")));
            }
            lines.push(line);
        }
        lines.join("\n")
    }

    /// Translates `question`: the first answer, then up to `repairs`
    /// repair rounds while the LogicPad rejects the query.
    pub fn translate(&self, question: &str) -> Result<LlmTranslation, LlmTranslateError> {
        let prompt = fill(
            &self.templates.translate,
            &[
                ("vocabulary", &self.vocabulary()),
                ("examples", EXAMPLES.trim()),
                ("question", question),
            ],
        );
        let mut messages = vec![Message::text("user", prompt.clone())];
        let mut rounds: Vec<Round> = Vec::new();
        let mut next_prompt = prompt;
        loop {
            let (reply, _) = self.chat.reply(&messages)?;
            let query = read_query(&reply);
            if let Some(reason) = query.strip_prefix("CANNOT:") {
                rounds.push(Round {
                    prompt: next_prompt,
                    reply: reply.clone(),
                    query: query.clone(),
                    diagnostics: Vec::new(),
                });
                return Err(LlmTranslateError::Cannot(reason.trim().to_string()));
            }
            match check(self.pad, &query) {
                Ok(parsed) => {
                    rounds.push(Round {
                        prompt: next_prompt,
                        reply,
                        query: query.clone(),
                        diagnostics: Vec::new(),
                    });
                    return Ok(LlmTranslation {
                        query,
                        parsed,
                        rounds,
                    });
                }
                Err(diags) => {
                    let said: Vec<String> = diags
                        .iter()
                        .map(|d| match &d.help {
                            Some(h) => format!("- {} ({h})", d.message),
                            None => format!("- {}", d.message),
                        })
                        .collect();
                    rounds.push(Round {
                        prompt: next_prompt,
                        reply: reply.clone(),
                        query: query.clone(),
                        diagnostics: said.clone(),
                    });
                    if rounds.len() > self.repairs as usize {
                        return Err(LlmTranslateError::Invalid {
                            query,
                            rounds: rounds.len(),
                            diagnostics: said.join("\n"),
                        });
                    }
                    next_prompt =
                        fill(&self.templates.repair, &[("diagnostics", &said.join("\n"))]);
                    messages.push(Message::text("assistant", reply));
                    messages.push(Message::text("user", next_prompt.clone()));
                }
            }
        }
    }
}

/// Checks a query as [`crate::engine::Engine::prepare_query`] does: a query
/// over a video's windows (`(Q1) THEN (Q2)`, `EVER: Q`) part by part,
/// any other (conjunctive, `¬∃`, `#{…}`, `∀`) as one; the parsed query of
/// a temporal one is its first part's.
fn check(pad: &logicpad::LogicPad, query: &str) -> Result<ParsedQuery, Vec<logicpad::Diagnostic>> {
    match crate::temporal::parse(pad, query) {
        None => crate::ask::prepare(pad, query),
        Some(Err(diags)) => Err(diags),
        Some(Ok(t)) => t.first_parsed().ok_or_else(Vec::new),
    }
}

/// The query in a reply: its first non-empty line, without code fences,
/// backticks, quotes or a `Query:` label.
pub fn read_query(reply: &str) -> String {
    read_answer_line(reply, "Query:")
}

/// A one-line answer in a reply (a query, a rule): the first non-empty
/// line, without code fences, backticks, quotes or the answer's `label`.
pub(crate) fn read_answer_line(reply: &str, label: &str) -> String {
    let line = reply
        .lines()
        .map(str::trim)
        .find(|l| !l.is_empty() && !l.starts_with("```"))
        .unwrap_or_default();
    let line = line.strip_prefix(label).unwrap_or(line).trim();
    line.trim_matches(|c| c == '`' || c == '"')
        .trim()
        .to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_query_is_read_out_of_its_wrapping() {
        assert_eq!(
            read_query("```\nPedestrian(x)^Walk(x)\n```"),
            "Pedestrian(x)^Walk(x)"
        );
        assert_eq!(read_query("Query: `Moving(x)`"), "Moving(x)");
        assert_eq!(
            read_query("\n  CANNOT: no such thing\n"),
            "CANNOT: no such thing"
        );
    }
}
