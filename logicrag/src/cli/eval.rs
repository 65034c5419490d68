//! `logicrag eval`: a question set with expected answers (a CSV, or a
//! simulator scenario's built-in set) scored per category.

use super::demo::scenario_questions;
use super::{SourceArgs, load_engine, load_options, load_source};
use logicrag::source::SourceSpec;
use anyhow::{Context, Result, bail};
use clap::Args;
use logicrag::kb::Observability;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct EvalArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// CSV with Question, Answer (yes/no/1/0), optional Window and Category
    /// columns (default: the source's built-in question set; sim only).
    #[arg(long)]
    pub questions: Option<PathBuf>,
    /// Every built-in scenario with its built-in question set.
    #[arg(long)]
    pub all_scenarios: bool,
    /// Write the JSON report here.
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
    /// Print every wrong answer.
    #[arg(long)]
    pub verbose: bool,
}

pub fn run(a: EvalArgs) -> Result<ExitCode> {
    let engine = load_engine(&a.src.logicpad, Observability::everything())?;
    let opts = load_options(&a.src)?;
    let mut reports = Vec::new();
    let sources: Vec<SourceSpec> = if a.all_scenarios {
        perception::sim::BUILTIN_NAMES
            .iter()
            .map(|s| SourceSpec::Sim {
                scenario: (*s).to_string(),
                seed: 0,
            })
            .collect()
    } else {
        vec![a.src.source.clone()]
    };
    for spec in &sources {
        let src = SourceArgs {
            source: spec.clone(),
            ..a.src.clone()
        };
        let (loaded, questions, file) = match &a.questions {
            Some(path) => {
                let text = std::fs::read_to_string(path)
                    .with_context(|| format!("reading {}", path.display()))?;
                // The same loader as every other command: frames runs the
                // models, and flags another source would ignore are refused.
                let loaded = load_source(&src)?;
                let default_window = if loaded.windows.len() == 1 {
                    loaded.windows.first().map(|w| w.id.clone())
                } else {
                    None
                };
                let file = path.display().to_string();
                let qs = logicrag::eval::read_questions(&text, &file, default_window.as_deref())?;
                (loaded, qs, file)
            }
            None => {
                let SourceSpec::Sim { scenario: name, .. } = src.spec()? else {
                    bail!("{spec} has no built-in question set; give --questions FILE.csv");
                };
                let (loaded, qs) = scenario_questions(&name, &opts)?;
                (loaded, qs, format!("built-in questions of {name}"))
            }
        };
        let pb = indicatif::ProgressBar::new(questions.len() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb.set_message(spec.to_string());
        let report = logicrag::eval::evaluate_with_progress(
            &engine,
            loaded,
            &questions,
            &file,
            &|n| pb.inc(n as u64),
        )?;
        pb.finish_and_clear();
        reports.push(report);
    }
    let mut total = logicrag::metrics::Evaluation::default();
    for r in &reports {
        for rec in &r.records {
            total.add(&rec.category, rec.expected, rec.said.said());
        }
    }
    let json = serde_json::json!({
        "sources": reports.iter().map(|r| serde_json::json!({"source": r.source, "overall": r.overall, "by_category": r.by_category, "records": r.records})).collect::<Vec<_>>(),
        "overall": total.overall.scores(),
        "by_category": total.by_category.iter().map(|(k, c)| (k.clone(), c.scores())).collect::<std::collections::BTreeMap<_, _>>(),
        "confusion": total.overall,
    });
    if let Some(path) = &a.report {
        std::fs::write(path, serde_json::to_string_pretty(&json)?)
            .with_context(|| format!("writing {}", path.display()))?;
    }
    if a.json {
        outln!("{json}");
    } else {
        for r in &reports {
            outln!(
                "{}: {} questions, accuracy {:.2}",
                r.source,
                r.records.len(),
                r.overall.accuracy
            );
            if a.verbose {
                for rec in r.records.iter().filter(|x| !x.correct) {
                    outln!(
                        "  wrong: [{}] {} → {} said {} (expected {})",
                        rec.window,
                        rec.question,
                        rec.query.clone().unwrap_or_else(|e| e),
                        rec.said.as_str(),
                        if rec.expected { "yes" } else { "no" }
                    );
                }
            }
        }
        outln!();
        outp!("{}", total.table());
        outln!();
        outp!("{}", total.confusion_table());
    }
    Ok(ExitCode::SUCCESS)
}

