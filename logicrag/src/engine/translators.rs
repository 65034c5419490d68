//! How questions become queries: the [`Translate`] trait and its three
//! implementations (the grammar, an LLM, the grammar then the LLM), chosen
//! by [`TranslatorMode`], and the [`PrepareError`]s of translating.

use super::{Engine, Prepared};
use crate::translate::TranslateError;
use serde::Serialize;

/// How a question becomes a query (`--translator`, the REPL's
/// `:translator`).
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq, Serialize)]
#[cfg_attr(feature = "cli", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum TranslatorMode {
    /// The built-in grammar (no network).
    #[default]
    Grammar,
    /// An LLM, its reply checked by the LogicPad and repaired.
    Llm,
    /// The grammar, and the LLM when the grammar refuses.
    Auto,
}

impl TranslatorMode {
    /// The mode's name as the flag takes it.
    pub fn as_str(self) -> &'static str {
        match self {
            TranslatorMode::Grammar => "grammar",
            TranslatorMode::Llm => "llm",
            TranslatorMode::Auto => "auto",
        }
    }
}

impl std::str::FromStr for TranslatorMode {
    type Err = String;
    fn from_str(s: &str) -> Result<TranslatorMode, String> {
        match s.trim() {
            "grammar" => Ok(TranslatorMode::Grammar),
            "llm" => Ok(TranslatorMode::Llm),
            "auto" => Ok(TranslatorMode::Auto),
            other => Err(format!(
                "unknown translator `{other}`: expected grammar, llm or auto"
            )),
        }
    }
}

/// The LLM half of a translator: a server, its prompts and the repair
/// rounds for a query the LogicPad rejects.
#[derive(Debug, Clone)]
pub struct LlmSetup {
    /// The server and its cache.
    pub chat: crate::llm::Chat,
    /// The prompts.
    pub templates: crate::llm::Templates,
    /// Repair rounds after the first answer.
    pub repairs: u32,
}

/// How an English question becomes a query: the grammar ([`Grammar`]), an
/// LLM (`ByLlm`), or the grammar and then the LLM when the grammar
/// refuses (`GrammarThenLlm`). Every front end's
/// [`crate::pipeline::Pipeline`] holds one (built by [`translator`] from
/// `--translator` and `--llm`) and prepares questions through it
/// ([`Engine::prepare_with`], which takes queries as written).
pub trait Translate: Send + Sync + std::fmt::Debug {
    /// The mode, as `--translator` names it.
    fn mode(&self) -> TranslatorMode;
    /// Translates an English question for `engine`'s LogicPad.
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError>;
    /// True when translating may ask a server (a front end may bound or
    /// time such calls).
    fn asks_server(&self) -> bool {
        false
    }
    /// The translation when it needs no server: the grammar's answer or
    /// refusal, or a question the grammar reads before an LLM would be
    /// asked; `None` when only a server can tell.
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>>;
}

/// The built-in grammar: no network, every question the same way.
#[derive(Debug, Clone, Copy, Default)]
pub struct Grammar;

impl Translate for Grammar {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Grammar
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        Ok(engine.prepare(question)?)
    }
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>> {
        Some(self.translate(engine, question))
    }
}

/// An LLM: its reply is checked by the LogicPad and repaired.
#[derive(Debug, Clone)]
pub(crate) struct ByLlm(pub LlmSetup);

impl ByLlm {
    fn run(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Result<Prepared, crate::llm::translate::LlmTranslateError> {
        let t = crate::llm::translate::LlmTranslator {
            chat: &self.0.chat,
            templates: &self.0.templates,
            pad: &engine.pad,
            repairs: self.0.repairs,
        };
        engine.prepare_llm(question, &t)
    }
}

impl Translate for ByLlm {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Llm
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        Ok(self.run(engine, question)?)
    }
    fn asks_server(&self) -> bool {
        true
    }
    fn translate_offline(&self, _: &Engine, _: &str) -> Option<Result<Prepared, PrepareError>> {
        None
    }
}

/// The grammar, then the LLM for the questions the grammar refuses.
#[derive(Debug, Clone)]
pub(crate) struct GrammarThenLlm(pub ByLlm);

impl Translate for GrammarThenLlm {
    fn mode(&self) -> TranslatorMode {
        TranslatorMode::Auto
    }
    fn translate(&self, engine: &Engine, question: &str) -> Result<Prepared, PrepareError> {
        match engine.prepare(question) {
            Ok(p) => Ok(p),
            Err(grammar) => self
                .0
                .run(engine, question)
                .map_err(|llm| PrepareError::Neither { grammar, llm }),
        }
    }
    fn asks_server(&self) -> bool {
        true
    }
    fn translate_offline(
        &self,
        engine: &Engine,
        question: &str,
    ) -> Option<Result<Prepared, PrepareError>> {
        engine.prepare(question).ok().map(Ok)
    }
}

/// The translator of a mode: `Llm` needs `llm` ([`PrepareError::NoLlm`]
/// without it); `Auto` without `llm` is the grammar alone.
pub fn translator(
    mode: TranslatorMode,
    llm: Option<LlmSetup>,
) -> Result<std::sync::Arc<dyn Translate>, PrepareError> {
    Ok(match (mode, llm) {
        (TranslatorMode::Grammar, _) | (TranslatorMode::Auto, None) => std::sync::Arc::new(Grammar),
        (TranslatorMode::Llm, None) => return Err(PrepareError::NoLlm),
        (TranslatorMode::Llm, Some(setup)) => std::sync::Arc::new(ByLlm(setup)),
        (TranslatorMode::Auto, Some(setup)) => std::sync::Arc::new(GrammarThenLlm(ByLlm(setup))),
    })
}

/// Why a question could not be prepared under a [`TranslatorMode`].
#[derive(Debug, thiserror::Error)]
pub enum PrepareError {
    /// Occurs when the grammar cannot read the question (grammar mode, or
    /// auto mode without an LLM).
    #[error("cannot translate the question: {0}")]
    Grammar(#[from] TranslateError),
    /// Occurs when the LLM cannot translate it (llm mode).
    #[error("cannot translate the question: {0}")]
    Llm(#[from] crate::llm::translate::LlmTranslateError),
    /// Occurs when neither can (auto mode).
    #[error("cannot translate the question: the grammar: {grammar}; the LLM: {llm}")]
    Neither {
        /// The grammar's reason.
        grammar: TranslateError,
        /// The LLM's reason.
        llm: crate::llm::translate::LlmTranslateError,
    },
    /// Occurs when the llm mode has no server to ask.
    #[error("the llm translator needs a server: give --llm URL (or set LOGICRAG_LLM_URL)")]
    NoLlm,
}

impl PrepareError {
    /// Why, without the leading "cannot translate the question: " (for a
    /// line that says what failed itself, as an evaluation record does).
    pub fn reason(&self) -> String {
        match self {
            PrepareError::Grammar(e) => e.to_string(),
            PrepareError::Llm(e) => e.to_string(),
            PrepareError::Neither { grammar, llm } => {
                format!("the grammar: {grammar}; the LLM: {llm}")
            }
            PrepareError::NoLlm => self.to_string(),
        }
    }
}
