//! `logicrag eval`: a question set with expected answers (a CSV, or a
//! simulator scenario's built-in set) scored per category.

use super::demo::scenario_questions;
use super::{LlmArgs, SourceArgs, load_engine, load_options, load_source};
use anyhow::{Context, Result, bail};
use clap::Args;
use logicrag::kb::Observability;
use logicrag::llm::Condition;
use logicrag::llm::eval::{LmmRecord, Table};
use logicrag::source::SourceSpec;
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
    /// Also ask a multimodal model under these conditions (c1,c2,c3) and
    /// print the paper's table: LR, C1, C2, C3 per category.
    #[arg(long, value_delimiter = ',')]
    pub lmm: Vec<Condition>,
    /// Write every prompt, raw reply and parsed answer here as JSONL
    /// (lmm.jsonl), for checking by hand.
    #[arg(long, requires = "lmm")]
    pub out: Option<PathBuf>,
    /// Draw per-category accuracy and F1 (LR, and C1–C3 with --lmm) to
    /// this .png or .svg file.
    #[cfg(feature = "plot")]
    #[arg(long)]
    pub plot: Option<PathBuf>,
    /// Requests to the model in flight at once (1 to 64).
    #[arg(long = "llm-parallel", default_value_t = 4, value_parser = clap::value_parser!(u16).range(1..=64))]
    pub llm_parallel: u16,
    #[command(flatten)]
    pub llm: LlmArgs,
}

pub fn run(a: EvalArgs) -> Result<ExitCode> {
    // A plot that cannot be written is said before the evaluation runs.
    #[cfg(feature = "plot")]
    if let Some(path) = &a.plot {
        logicrag::plot::Format::of(path)?;
    }
    let engine = load_engine(&a.src.logicpad, Observability::everything())?;
    let opts = load_options(&a.src)?;
    let mut reports = Vec::new();
    let mut lmm_records: Vec<LmmRecord> = Vec::new();
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
                let text = perception::textfile::read_text_file(path)
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
        let lmm_input =
            (!a.lmm.is_empty()).then(|| (loaded.windows.clone(), loaded.images.clone()));
        let source_engine = engine.for_source(loaded.observability.clone());
        let report =
            logicrag::eval::evaluate_with_progress(&engine, loaded, &questions, &file, &|n| {
                pb.inc(n as u64)
            })?;
        pb.finish_and_clear();
        reports.push(report);
        if let Some((windows, images)) = lmm_input {
            if images.is_none() {
                eprintln!("note: {spec} has no pictures; the model sees only the text");
            }
            let models: std::collections::BTreeMap<Condition, logicrag::llm::Lmm> = a
                .lmm
                .iter()
                .map(|c| {
                    Ok((
                        *c,
                        logicrag::llm::Lmm {
                            chat: a.llm.chat()?,
                            templates: a.llm.templates(Some(*c))?,
                        },
                    ))
                })
                .collect::<Result<_>>()?;
            let pb = indicatif::ProgressBar::new(questions.len() as u64);
            pb.set_style(
                indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
                    .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
            );
            pb.set_message(format!("{spec} lmm"));
            // At most --llm-parallel requests in flight: windows are asked
            // on a pool of that many threads, each request blocking one.
            let pool = rayon::ThreadPoolBuilder::new()
                .num_threads(usize::from(a.llm_parallel))
                .build()
                .context("starting the request threads")?;
            let records = pool.install(|| {
                logicrag::llm::eval::evaluate_lmm(
                    &source_engine,
                    windows,
                    images.as_ref(),
                    &questions,
                    &a.lmm,
                    &models,
                    a.llm.lmm_frames,
                    &|n| pb.inc(n as u64),
                )
            })?;
            pb.finish_and_clear();
            lmm_records.extend(records);
        }
    }
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir).with_context(|| format!("creating {}", dir.display()))?;
        let path = dir.join("lmm.jsonl");
        let mut text = String::new();
        for r in &lmm_records {
            text.push_str(&serde_json::to_string(r)?);
            text.push('\n');
        }
        std::fs::write(&path, text).with_context(|| format!("writing {}", path.display()))?;
        eprintln!(
            "wrote {} prompts and replies to {}",
            lmm_records.len(),
            path.display()
        );
    }
    let mut total = logicrag::metrics::Evaluation::default();
    for r in &reports {
        for rec in &r.records {
            total.add(&rec.category, rec.expected, rec.said.said());
        }
    }
    // The paper's columns: the logic (LR), then the model per condition.
    let columns = Table::new(&lmm_records).score_columns(&total);
    let json = serde_json::json!({
        "sources": reports.iter().map(|r| serde_json::json!({"source": r.source, "overall": r.overall, "by_category": r.by_category, "records": r.records})).collect::<Vec<_>>(),
        "overall": total.overall.scores(),
        "by_category": total.by_category.iter().map(|(k, c)| (k.clone(), c.scores())).collect::<std::collections::BTreeMap<_, _>>(),
        "confusion": total.overall,
        "lmm": lmm_records,
        "columns": columns,
    });
    #[cfg(feature = "plot")]
    if let Some(path) = &a.plot {
        let names: Vec<String> = sources.iter().map(ToString::to_string).collect();
        let title = if a.all_scenarios {
            "Logic-RAG on the built-in scenarios: accuracy and F1 per category".to_string()
        } else {
            format!(
                "Logic-RAG on {}: accuracy and F1 per category",
                names.join(", ")
            )
        };
        logicrag::plot::eval_chart(&columns, &title, path, (1100, 760))?;
        eprintln!("wrote {}", path.display());
    }
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
        if !lmm_records.is_empty() {
            outln!("\n== the logic alone (LR) and the model under each condition");
            outp!("{}", Table::new(&lmm_records).render());
        }
    }
    Ok(ExitCode::SUCCESS)
}
