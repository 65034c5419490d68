//! `logicrag facts`: a source's window facts, as a text KB (optionally with
//! each fact's provenance) or JSON.

use super::SourceArgs;
use anyhow::Result;
use clap::Args;
use logicrag::pipeline::Pipeline;
use std::io::Write;
use std::process::ExitCode;

#[derive(Args)]
pub struct FactsArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// JSON with provenance, one window object per line.
    #[arg(long)]
    pub json: bool,
    /// Show each fact's provenance as a comment.
    #[arg(long, conflicts_with = "json")]
    pub why: bool,
    /// Write each window's facts to DIR/<window id>.parquet (the facts
    /// table of docs/formats.md) instead of printing them.
    #[cfg(feature = "arrow")]
    #[arg(long, value_name = "DIR", conflicts_with_all = ["json", "why"])]
    pub parquet: Option<std::path::PathBuf>,
}

pub fn run(a: FactsArgs) -> Result<ExitCode> {
    let pipeline = a.src.open(None)?;
    #[cfg(feature = "arrow")]
    if let Some(dir) = &a.parquet {
        return write_parquet(&pipeline, dir);
    }
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    for w in pipeline.windows() {
        if a.json {
            let place = logicrag::json::WindowPlace::from(w);
            let v = logicrag::json::facts_object(pipeline.label(), place, w.facts.iter(), false)?;
            writeln!(out, "{v}")?;
        } else {
            writeln!(
                out,
                "# window {} ({}, frames {}-{}): {} facts",
                w.id,
                pipeline.label(),
                w.first_frame,
                w.last_frame,
                w.facts.len()
            )?;
            for f in w.facts.iter() {
                if a.why {
                    writeln!(
                        out,
                        "{}    # {}",
                        f.to_kb_line(),
                        logicrag::proof::describe_provenance(f.provenance())
                    )?;
                } else {
                    writeln!(out, "{}", f.to_kb_line())?;
                }
            }
        }
    }
    out.flush()?;
    Ok(ExitCode::SUCCESS)
}

/// `--parquet DIR`: one file per window, named by its id, so that a
/// reader can take one window or the whole directory (`DIR/*.parquet`).
#[cfg(feature = "arrow")]
fn write_parquet(pipeline: &Pipeline, dir: &std::path::Path) -> Result<ExitCode> {
    use anyhow::Context as _;
    use logicrag::arrow::{FactsBuilder, ParquetWriter, facts_schema, window_file};
    std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
    // Every name is checked before any file is written.
    let files = pipeline
        .windows()
        .iter()
        .map(|w| window_file(dir, &w.id).map_err(anyhow::Error::msg))
        .collect::<Result<Vec<_>>>()?;
    let mut facts = 0usize;
    for (w, path) in pipeline.windows().iter().zip(&files) {
        let place = logicrag::json::WindowPlace::from(w);
        let mut writer = ParquetWriter::create(path, facts_schema())?;
        let mut b = FactsBuilder::new();
        for f in w.facts.iter() {
            b.push(pipeline.label(), place, f);
            if b.is_full() {
                writer.write(&b.finish()?)?;
            }
        }
        if !b.is_empty() {
            writer.write(&b.finish()?)?;
        }
        facts += writer.finish()?;
    }
    eprintln!(
        "wrote {facts} facts of {} windows to {}",
        files.len(),
        dir.display()
    );
    Ok(ExitCode::SUCCESS)
}
