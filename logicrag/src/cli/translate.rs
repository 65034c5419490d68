//! `logicrag translate`: a question (or a CSV of questions) to its query,
//! with the translator's notes in the same stream.

use super::{LlmArgs, TranslatorMode};
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct TranslateArgs {
    /// The question.
    pub question: Option<String>,
    /// Take the words from this LogicPad (default: the built-in LogicPad).
    #[arg(long)]
    pub logicpad: Option<PathBuf>,
    /// A CSV with a `Question` column; writes `Question,Query`.
    #[arg(long, conflicts_with = "question")]
    pub csv: Option<PathBuf>,
    /// Output file for --csv (default: stdout).
    #[arg(long, requires = "csv")]
    pub out: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(a: TranslateArgs) -> Result<ExitCode> {
    let pipeline = super::sourceless(&a.logicpad, None)?;
    let translator = pipeline.engine().translator();
    if let Some(csv) = &a.csv {
        let input = perception::textfile::read_text_file(csv)
            .with_context(|| format!("reading {}", csv.display()))?;
        let output = translator
            .translate_csv(&input)
            .map_err(|e| anyhow::anyhow!("{}: {e}", csv.display()))?;
        match &a.out {
            Some(p) => {
                std::fs::write(p, output).with_context(|| format!("writing {}", p.display()))?
            }
            None => outp!("{output}"),
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(q) = &a.question else {
        bail!("give a question, or --csv FILE")
    };
    if a.llm.translator != TranslatorMode::Grammar {
        let p = pipeline.with_translator(a.llm.translator()?).prepare(q)?;
        if a.json {
            outln!(
                "{}",
                serde_json::json!({"question": q, "query": p.query, "notes": p.notes})
            );
        } else {
            outln!("{}", p.query);
            for n in &p.notes {
                outln!("note: {n}");
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    match translator.translate(q) {
        Ok(t) => {
            if a.json {
                outln!(
                    "{}",
                    serde_json::json!({"question": q, "query": t.query, "notes": t.notes})
                );
            } else {
                // Notes go to stdout with the query: a pipe keeps them.
                outln!("{}", t.query);
                for n in &t.notes {
                    outln!("note: {n}");
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e) => {
            if a.json {
                outln!(
                    "{}",
                    serde_json::json!({"question": q, "error": e.to_string()})
                );
            } else {
                eprintln!("cannot translate: {e}");
            }
            Ok(ExitCode::from(2))
        }
    }
}
