//! `POST /v1/retrieve`: Logic-RAG as a retriever, in the shape LangChain
//! documents have (`page_content` and `metadata`), so that a retriever
//! wrapper of a few lines feeds it to any chain. For a question it returns,
//! in this order:
//!
//! 1. one `answer` document: the question, the query and the overall answer
//!    (the headline `logicrag ask` prints);
//! 2. per window shown (the one asked about; else those that say yes, then
//!    the others, at most `windows`): one `proof` document, the C2
//!    inference sentences (answer, bindings and their proofs, or why not);
//! 3. per window shown, one `fact` document per C3 sentence that mentions
//!    an object the answer rests on (a binding, a why-not candidate, a
//!    constant of the query) — all of the window's sentences when it rests
//!    on none — at most `facts` per window.

use crate::ask::{AskResult, Outcome};
use crate::engine::{Engine, Prepared, Summary};
use crate::kb::WindowKb;
use serde::{Deserialize, Serialize};
use serde_json::{Value, json};
use std::collections::BTreeSet;

/// The request: a question (`query`, LangChain's name, or `question`),
/// optionally one window and limits.
#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct RetrieveRequest {
    /// The question or query.
    #[serde(alias = "question")]
    pub query: String,
    /// Only this window (default: every window).
    #[serde(default)]
    pub window: Option<String>,
    /// Windows given a proof and facts (default [`DEFAULT_WINDOWS`]).
    #[serde(default)]
    pub windows: Option<usize>,
    /// Fact documents per window (default `DEFAULT_FACTS`).
    #[serde(default)]
    pub facts: Option<usize>,
    /// The most documents returned in all (LangChain's `k`; default: no
    /// limit beyond `windows` and `facts`). The best come first.
    #[serde(default)]
    pub k: Option<usize>,
    /// Bindings listed per window (as `/api/ask`'s `limit`).
    #[serde(default)]
    pub limit: Option<usize>,
    /// Bindings skipped per window (as `/api/ask`'s `offset`).
    #[serde(default)]
    pub offset: Option<usize>,
}

/// Windows shown by default.
pub const DEFAULT_WINDOWS: usize = 3;
/// Fact documents per window by default.
pub(crate) const DEFAULT_FACTS: usize = 20;

/// How much a retrieval returns.
#[derive(Debug, Clone, Copy)]
pub struct Limits {
    /// Windows given a proof and facts.
    pub windows: usize,
    /// Fact documents per window.
    pub facts: usize,
}

impl RetrieveRequest {
    /// The request's limits, with the defaults.
    pub fn limits(&self) -> Limits {
        Limits {
            windows: self.windows.unwrap_or(DEFAULT_WINDOWS),
            facts: self.facts.unwrap_or(DEFAULT_FACTS),
        }
    }
}

/// A LangChain-style document.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct Document {
    /// A stable id: `answer`, `WINDOW/proof`, `WINDOW/fact/N` (N: the
    /// sentence's place in the window's C3 context).
    pub id: String,
    /// The text a model reads.
    pub page_content: String,
    /// Where it comes from: `kind` (`answer`, `proof`, `fact`), window,
    /// frames and what else the kind has.
    pub metadata: Value,
}

/// Each document's `metadata.score`, from 0 to 1, so that a chain can
/// rank or cut them: the answer 1; a window's proof 1 when it says yes,
/// 0.5 otherwise; a fact 0.5 plus half the share of the answer's objects
/// it mentions (0.25 when the answer rests on no object).
pub mod score {
    /// The answer document's score.
    pub(crate) const ANSWER: f64 = 1.0;
    /// A proof document's score in a window that says yes.
    pub(crate) const PROOF_YES: f64 = 1.0;
    /// A proof document's score in a window that does not.
    pub(crate) const PROOF_OTHER: f64 = 0.5;
    /// A fact document's score when the answer rests on no object.
    pub(crate) const FACT_UNRELATED: f64 = 0.25;
}

/// The documents for prepared question `p` over `windows`, from their
/// answers (`results[i]` answers `windows[i]`; see the module
/// documentation for what and in which order): what
/// [`documents`] returns.
/// The retriever's documents (`POST /v1/retrieve`) for a prepared
/// question on the window named `window` of `pipeline`, or on every
/// window, each window's bindings cut to `page`.
pub fn documents(
    pipeline: &crate::pipeline::Pipeline,
    p: &Prepared,
    window: Option<&str>,
    opts: crate::ask::AskOptions,
    page: crate::engine::Page,
    limits: Limits,
) -> Result<Vec<Document>, crate::session::SessionError> {
    let answers = pipeline.ask_page(p, window, opts, page)?;
    let windows: Vec<&WindowKb> = answers.iter().map(|a| a.window).collect();
    let results: Vec<AskResult> = answers.into_iter().map(|a| a.result).collect();
    Ok(documents_from(
        pipeline.engine(),
        pipeline.label(),
        &windows,
        p,
        &results,
        limits,
    ))
}

pub(crate) fn documents_from(
    engine: &Engine,
    source: &str,
    windows: &[&WindowKb],
    p: &Prepared,
    results: &[AskResult],
    limits: Limits,
) -> Vec<Document> {
    let summary = Summary::new(engine.words(), p, results);
    let question = p.question.as_deref().unwrap_or(&p.query);
    let mut docs = vec![Document {
        id: "answer".into(),
        page_content: format!(
            "Question: {question}\nLogical query: {}\nAnswer (proved by Logic-RAG over {} window{} of {source}): {}",
            p.query,
            results.len(),
            if results.len() == 1 { "" } else { "s" },
            summary.headline()
        ),
        metadata: json!({
            "kind": "answer", "source": source, "question": p.question, "query": p.query,
            "answer": summary.answer, "windows": results.len(), "score": score::ANSWER,
        }),
    }];
    // Windows that say yes first, in source order; the sort is stable.
    let mut order: Vec<usize> = (0..results.len()).collect();
    order.sort_by_key(|&i| results.get(i).map(|r| r.answer != Outcome::Yes));
    for i in order.into_iter().take(limits.windows) {
        let (Some(kb), Some(r)) = (windows.get(i), results.get(i)) else {
            continue;
        };
        let ctx = engine.context(kb, p, r);
        let frames = json!([kb.first_frame, kb.last_frame]);
        let proof_score = if r.answer == Outcome::Yes {
            score::PROOF_YES
        } else {
            score::PROOF_OTHER
        };
        docs.push(Document {
            id: format!("{}/proof", kb.id),
            page_content: format!(
                "Window {} (frames {}–{}): {}",
                kb.id,
                kb.first_frame,
                kb.last_frame,
                ctx.c2.join(" ")
            ),
            metadata: json!({
                "kind": "proof", "source": source, "window": kb.id, "frames": frames,
                "answer": r.answer, "bindings": r.bindings, "score": proof_score,
            }),
        });
        let relevant = relevant_objects(kb, r);
        let mentions = |s: &str| -> Vec<String> {
            relevant
                .iter()
                .filter(|o| mentions_word(s, o))
                .cloned()
                .collect()
        };
        let mut chosen: Vec<(usize, String, Vec<String>)> = ctx
            .c3
            .iter()
            .enumerate()
            .map(|(n, s)| (n, s.clone(), mentions(s)))
            .filter(|(_, _, m)| relevant.is_empty() || !m.is_empty())
            .collect();
        // Sentences about an object ("pedestrian_5 is a pedestrian …")
        // before those that only name it ("… seen with pedestrian_5").
        chosen.sort_by_key(|(_, s, m)| !m.iter().any(|o| s.starts_with(&format!("{o} "))));
        chosen.truncate(limits.facts);
        for (n, sentence, objects) in chosen {
            let score = if relevant.is_empty() {
                score::FACT_UNRELATED
            } else {
                0.5 + 0.5 * objects.len() as f64 / relevant.len() as f64
            };
            docs.push(Document {
                id: format!("{}/fact/{n}", kb.id),
                page_content: sentence,
                metadata: json!({
                    "kind": "fact", "source": source, "window": kb.id, "frames": frames,
                    "objects": objects, "score": score,
                }),
            });
        }
    }
    docs
}

/// The window's objects an answer rests on: its bindings, its why-not
/// candidates and the query's constants that the window contains.
fn relevant_objects(kb: &WindowKb, r: &AskResult) -> BTreeSet<String> {
    let mut out: BTreeSet<String> = r
        .bindings
        .iter()
        .flatten()
        .map(|(_, c)| c.clone())
        .chain(r.why_not.iter().map(|w| w.candidate.clone()))
        .filter(|c| kb.objects.contains(c.as_str()))
        .collect();
    for word in r
        .query
        .split(|c: char| !(c.is_alphanumeric() || c == '_'))
        .filter(|w| kb.objects.contains(*w))
    {
        out.insert(word.to_string());
    }
    out
}

/// Whether `word` occurs in `text` as a whole word (`car_1` is not in
/// `car_12`).
fn mentions_word(text: &str, word: &str) -> bool {
    let is_word = |c: char| c.is_alphanumeric() || c == '_';
    text.match_indices(word).any(|(i, _)| {
        let before = text[..i].chars().next_back();
        let after = text[i + word.len()..].chars().next();
        !before.is_some_and(is_word) && !after.is_some_and(is_word)
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn objects_are_mentioned_as_whole_words() {
        assert!(mentions_word("car_1 is a car.", "car_1"));
        assert!(mentions_word("It is near car_1.", "car_1"));
        assert!(!mentions_word("car_12 is a car.", "car_1"));
        assert!(!mentions_word("scar_1 is odd.", "car_1"));
    }
}
