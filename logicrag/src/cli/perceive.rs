//! `logicrag perceive`: a source's tracks as JSON (raw frames through the
//! model set, or any other sequence source).

use super::SourceArgs;
use anyhow::{Context, Result, bail};
use clap::Args;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct PerceiveArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// Output file for the tracks (default: stdout).
    #[arg(long)]
    pub out: Option<PathBuf>,
}

pub fn run(a: PerceiveArgs) -> Result<ExitCode> {
    let options = logicrag::pipeline::OpenOptions {
        keep_scene: true,
        ..a.src.open_options(None)
    };
    let pipeline = super::open(a.src.spec()?, &options)?;
    let Some(seq) = &pipeline.extras().sequence else {
        bail!("{} holds facts, not tracks", a.src.source)
    };
    let json = perception::json::to_tracks_json(seq)?;
    match &a.out {
        Some(p) => {
            std::fs::write(p, json).with_context(|| format!("writing {}", p.display()))?;
            eprintln!(
                "wrote {} observations of {} tracks to {}",
                seq.observations.len(),
                seq.tracks().len(),
                p.display()
            );
        }
        None => outln!("{json}"),
    }
    Ok(ExitCode::SUCCESS)
}
