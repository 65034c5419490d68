//! `logicrag facts`: a source's window facts, as a text KB (optionally with
//! each fact's provenance) or JSON.

use super::{SourceArgs, load_source};
use anyhow::Result;
use clap::Args;
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
}

pub fn run(a: FactsArgs) -> Result<ExitCode> {
    let loaded = load_source(&a.src)?;
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    for w in &loaded.windows {
        if a.json {
            let place = logicrag::json::WindowPlace {
                id: &w.id,
                index: w.index,
                first_frame: w.first_frame,
                last_frame: w.last_frame,
            };
            let v = logicrag::json::facts_object(&loaded.label, place, w.facts.iter(), false)?;
            writeln!(out, "{v}")?;
        } else {
            writeln!(
                out,
                "# window {} ({}, frames {}-{}): {} facts",
                w.id,
                loaded.label,
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
