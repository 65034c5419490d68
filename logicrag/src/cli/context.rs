//! `logicrag context`: the retrieval context (C2 inference result, C3 fact
//! sentences) of a question on each window.

use super::{LlmArgs, SourceArgs};
use anyhow::Result;
use clap::Args;
use std::process::ExitCode;

#[derive(Args)]
pub struct ContextArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// The question (or query).
    pub text: String,
    /// Only this window id.
    #[arg(long = "window-id")]
    pub window_id: Option<String>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    /// The translator (`--translator`, `--llm`), as `ask` takes it.
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(a: ContextArgs) -> Result<ExitCode> {
    let pipeline = a.src.open(Some(a.llm.translator()?))?;
    let prepared = pipeline.prepare(&a.text)?;
    // Only the window asked about is reasoned; a temporal query looks at
    // every window up to it.
    let (pipeline, at) = if prepared.temporal.is_some() {
        (pipeline, a.window_id.as_deref())
    } else {
        (pipeline.only(a.window_id.as_deref())?, None)
    };
    for ctx in pipeline.contexts(&prepared, at)? {
        if a.json {
            outln!("{}", serde_json::to_string(&ctx)?);
        } else {
            outln!("{}", ctx.to_text());
        }
    }
    Ok(ExitCode::SUCCESS)
}
