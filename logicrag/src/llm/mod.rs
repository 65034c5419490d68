//! The RAG half: a large multimodal model (LMM) answers a question from
//! the window's frames under the paper's three conditions — C1 frames and
//! question alone, C2 plus Logic-RAG's proved answer, C3 plus the window's
//! facts as template sentences — and an LLM translates what the grammar
//! cannot, its reply checked by the LogicPad and repaired
//! ([`translate::LlmTranslator`]).
//!
//! Main types: [`client::Client`] (an OpenAI-compatible chat server, over
//! real HTTP), [`cache::Cache`] (replies on disk by request hash),
//! [`Lmm`] (prompts from [`Templates`], a [`Verdict`] parsed from the reply).

pub mod cache;
pub mod client;
pub mod eval;
pub mod translate;

use crate::context::RagContext;
use cache::Cache;
use client::{Client, LlmError, Message, Part};
use serde::Serialize;
use std::path::Path;

/// The paper's three conditions.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Condition {
    /// Frames and question alone (the LMM's baseline).
    C1,
    /// Plus Logic-RAG's inference result: answer, bindings, proof summary.
    C2,
    /// Plus the window's facts as template sentences (no inference).
    C3,
}

impl Condition {
    /// `c1`, `c2` or `c3`.
    pub fn as_str(self) -> &'static str {
        match self {
            Condition::C1 => "c1",
            Condition::C2 => "c2",
            Condition::C3 => "c3",
        }
    }

    /// Every condition, in order.
    pub const ALL: [Condition; 3] = [Condition::C1, Condition::C2, Condition::C3];
}

impl std::str::FromStr for Condition {
    type Err = String;
    fn from_str(s: &str) -> Result<Condition, String> {
        match s.trim().to_ascii_lowercase().as_str() {
            "c1" => Ok(Condition::C1),
            "c2" => Ok(Condition::C2),
            "c3" => Ok(Condition::C3),
            other => Err(format!(
                "`{other}` is not a condition: expected c1, c2 or c3"
            )),
        }
    }
}

/// What a reply says, read from its first words.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Verdict {
    /// The reply starts with yes.
    Yes,
    /// The reply starts with no.
    No,
    /// Neither, or both.
    Unclear,
}

impl Verdict {
    /// `yes`, `no` or `unclear`.
    pub fn as_str(self) -> &'static str {
        match self {
            Verdict::Yes => "yes",
            Verdict::No => "no",
            Verdict::Unclear => "unclear",
        }
    }

    /// Reads a reply: its first word, or "the answer is yes/no" near the
    /// start; anything else is unclear rather than a guess.
    pub fn parse(reply: &str) -> Verdict {
        let lower = reply.to_lowercase();
        let words: Vec<&str> = lower
            .split(|c: char| !c.is_alphanumeric())
            .filter(|w| !w.is_empty())
            .collect();
        match words.first().copied() {
            Some("yes") => return Verdict::Yes,
            Some("no") => return Verdict::No,
            _ => {}
        }
        let head: Vec<&str> = words.iter().take(12).copied().collect();
        let yes = head.windows(3).any(|w| w == ["answer", "is", "yes"]);
        let no = head.windows(3).any(|w| w == ["answer", "is", "no"]);
        match (yes, no) {
            (true, false) => Verdict::Yes,
            (false, true) => Verdict::No,
            _ => Verdict::Unclear,
        }
    }
}

/// Prompt templates, with `{question}`, `{frame_count}`, `{inference}`,
/// `{facts}` placeholders (C1–C3), `{vocabulary}`, `{examples}`,
/// `{diagnostics}` (translation) and `{sentence}`, `{name}` (rules). The defaults live in `logicrag/prompts/`.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Templates {
    /// C1: frames and question.
    pub c1: String,
    /// C2: plus the inference result.
    pub c2: String,
    /// C3: plus the facts.
    pub c3: String,
    /// Question → query.
    pub translate: String,
    /// The repair round after an invalid query.
    pub repair: String,
    /// English definition → LogicPad rule (`logicrag rule`, `:define`).
    pub rule: String,
    /// The repair round after a rule the LogicPad rejects.
    pub repair_rule: String,
}

impl Default for Templates {
    fn default() -> Templates {
        Templates {
            c1: include_str!("../../prompts/c1.txt").to_string(),
            c2: include_str!("../../prompts/c2.txt").to_string(),
            c3: include_str!("../../prompts/c3.txt").to_string(),
            translate: include_str!("../../prompts/translate.txt").to_string(),
            repair: include_str!("../../prompts/repair.txt").to_string(),
            rule: include_str!("../../prompts/rule.txt").to_string(),
            repair_rule: include_str!("../../prompts/repair_rule.txt").to_string(),
        }
    }
}

impl Templates {
    /// The template of a condition.
    pub(crate) fn for_condition(&self, c: Condition) -> &str {
        match c {
            Condition::C1 => &self.c1,
            Condition::C2 => &self.c2,
            Condition::C3 => &self.c3,
        }
    }

    /// Replaces one condition's template with a file's text (`--prompt`).
    pub fn with_condition_file(mut self, c: Condition, path: &Path) -> Result<Templates, LlmError> {
        let text =
            perception::textfile::read_text_file(path).map_err(|source| LlmError::Prompt {
                path: path.display().to_string(),
                source,
            })?;
        match c {
            Condition::C1 => self.c1 = text,
            Condition::C2 => self.c2 = text,
            Condition::C3 => self.c3 = text,
        }
        Ok(self)
    }
}

/// Fills `{name}` placeholders; unknown placeholders stay as written.
pub(crate) fn fill(template: &str, values: &[(&str, &str)]) -> String {
    let mut out = template.to_string();
    for (k, v) in values {
        out = out.replace(&format!("{{{k}}}"), v);
    }
    out
}

/// The model's answer under one condition.
#[derive(Debug, Clone, Serialize)]
pub struct LmmAnswer {
    /// The condition.
    pub condition: Condition,
    /// The text part of the prompt as sent.
    pub prompt: String,
    /// Number of frames attached.
    pub frames: usize,
    /// The model's reply.
    pub reply: String,
    /// Yes, no or unclear, read from the reply.
    pub verdict: Verdict,
    /// True when the reply came from the cache.
    pub cached: bool,
}

/// A chat client with a cache, answering chat requests once.
#[derive(Debug, Clone)]
pub struct Chat {
    /// The server.
    pub client: Client,
    /// Where replies are kept (`None`: every request goes out).
    pub cache: Option<Cache>,
}

impl Chat {
    /// The reply to `messages`, from the cache when it holds it.
    pub fn reply(&self, messages: &[Message]) -> Result<(String, bool), LlmError> {
        let key = self
            .cache
            .as_ref()
            .map(|_| Cache::key(self.client.config(), messages));
        if let (Some(cache), Some(key)) = (&self.cache, &key)
            && let Some(hit) = cache.get(key)?
        {
            return Ok((hit, true));
        }
        let reply = self.client.chat(messages)?;
        if let (Some(cache), Some(key)) = (&self.cache, &key) {
            cache.put(key, &self.client.config().model, &reply)?;
        }
        Ok((reply, false))
    }
}

/// Asks an LMM about a window under the paper's conditions.
#[derive(Debug, Clone)]
pub struct Lmm {
    /// The chat server and cache.
    pub chat: Chat,
    /// The prompts.
    pub templates: Templates,
}

impl Lmm {
    /// Asks `question` about a window whose frames are `images` (PNG
    /// bytes, in order). `context` is the window's RAG context: C2 adds its
    /// inference sentences, C3 its fact sentences, C1 neither.
    pub fn ask(
        &self,
        condition: Condition,
        question: &str,
        context: &RagContext,
        images: &[Vec<u8>],
    ) -> Result<LmmAnswer, LlmError> {
        let prompt = self.prompt(condition, question, context, images.len());
        let messages = [user_message(&prompt, images)];
        let (reply, cached) = self.chat.reply(&messages)?;
        Ok(LmmAnswer {
            condition,
            prompt,
            frames: images.len(),
            verdict: Verdict::parse(&reply),
            reply,
            cached,
        })
    }

    /// The text of the prompt for `question` under `condition` with
    /// `frame_count` frames attached: the condition's template filled with
    /// the context it allows (C2 the inference sentences, C3 the facts).
    pub fn prompt(
        &self,
        condition: Condition,
        question: &str,
        context: &RagContext,
        frame_count: usize,
    ) -> String {
        let bullet = |lines: &[String]| {
            lines
                .iter()
                .map(|l| format!("- {}", l.trim()))
                .collect::<Vec<_>>()
                .join("\n")
        };
        let frame_count = frame_count.to_string();
        let inference = bullet(&context.c2);
        let facts = bullet(&context.c3);
        let values: Vec<(&str, &str)> = match condition {
            Condition::C1 => vec![("question", question), ("frame_count", &frame_count)],
            Condition::C2 => vec![
                ("question", question),
                ("frame_count", &frame_count),
                ("inference", &inference),
            ],
            Condition::C3 => vec![
                ("question", question),
                ("frame_count", &frame_count),
                ("facts", &facts),
            ],
        };
        fill(self.templates.for_condition(condition), &values)
    }
}

/// The user message of an LMM question: the frames first, then the prompt.
pub(crate) fn user_message(prompt: &str, images: &[Vec<u8>]) -> Message {
    let mut parts: Vec<Part> = images.iter().cloned().map(Part::Png).collect();
    parts.push(Part::Text(prompt.to_string()));
    Message {
        role: "user".into(),
        parts,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn verdicts_are_read_from_the_start_of_a_reply() {
        assert_eq!(Verdict::parse("Yes. The car moves."), Verdict::Yes);
        assert_eq!(Verdict::parse("no, it stands"), Verdict::No);
        assert_eq!(Verdict::parse("**Yes** — clearly"), Verdict::Yes);
        assert_eq!(
            Verdict::parse("Looking closely, the answer is no."),
            Verdict::No
        );
        assert_eq!(Verdict::parse("It is hard to say."), Verdict::Unclear);
        assert_eq!(Verdict::parse("Nobody knows"), Verdict::Unclear);
    }

    #[test]
    fn templates_fill_their_placeholders() {
        let t = Templates::default();
        let p = fill(
            &t.c1,
            &[("question", "Is the car moving?"), ("frame_count", "5")],
        );
        assert!(
            p.contains("shown 5 frames") && p.contains("Question: Is the car moving?"),
            "{p}"
        );
        assert!(
            !t.c1.contains("{inference}")
                && t.c2.contains("{inference}")
                && t.c3.contains("{facts}")
        );
        assert_eq!("c2".parse::<Condition>(), Ok(Condition::C2));
        assert!("c4".parse::<Condition>().is_err());
    }
}
