//! `logicrag demo`: every built-in simulator scenario end to end — KBs,
//! generated questions, answers with their evidence, and scores.

use anyhow::Result;
use clap::Args;
use logicrag::ask::AskOptions;
use logicrag::pipeline::{OpenOptions, Pipeline};
use logicrag::source::SourceSpec;
use std::process::ExitCode;

#[derive(Args)]
pub struct DemoArgs {
    /// One built-in scenario (default: all).
    #[arg(long)]
    pub scenario: Option<String>,
    /// Answers shown per scenario.
    #[arg(long, default_value_t = 6)]
    pub show: usize,
    /// Machine-readable output.
    #[arg(long)]
    pub json: bool,
}

/// Opens a built-in scenario (noise seed 0) with `options` and generates
/// its question set.
pub fn scenario_questions(
    name: &str,
    options: &OpenOptions,
) -> Result<(Pipeline, Vec<logicrag::questions::Question>)> {
    let spec = SourceSpec::Sim {
        scenario: name.to_string(),
        seed: 0,
    };
    let options = OpenOptions {
        keep_scene: true,
        ..options.clone()
    };
    let pipeline = super::open(spec, &options)?;
    let questions = logicrag::eval::scenario_questions(&pipeline)?;
    Ok((pipeline, questions))
}

pub fn run(a: DemoArgs) -> Result<ExitCode> {
    // The built-in LogicPad, built once for every scenario.
    let (options, _) = OpenOptions::default().prepared()?;
    let names: Vec<String> = match &a.scenario {
        Some(s) => vec![s.clone()],
        None => perception::sim::BUILTIN_NAMES
            .iter()
            .map(|s| s.to_string())
            .collect(),
    };
    let mut total = logicrag::metrics::Evaluation::default();
    let mut reports = Vec::new();
    for name in &names {
        let (pipeline, questions) = scenario_questions(name, &options)?;
        // The worked examples ask one window again after the evaluation:
        // a pipeline of its own reasons that window alone.
        let example = questions
            .first()
            .map(|q| pipeline.subset(|w| w.id == q.window));
        let report = logicrag::eval::evaluate(pipeline, &questions, name)?;
        for r in &report.records {
            total.add(&r.category, r.expected, r.said);
        }
        if !a.json {
            outln!("== scenario {name}: {} questions", questions.len());
            if let Some(example) = &example
                && let Some(kb) = example.kbs()?.first()
            {
                for q in questions.iter().filter(|q| q.window == kb.id).take(a.show) {
                    let Ok(p) = example.prepare(&q.question) else {
                        continue;
                    };
                    let r = example.ask_window(kb, &p, AskOptions::default());
                    outln!("  Q [{}] {}", kb.id, q.question);
                    outln!("    query:  {}", p.query);
                    outln!(
                        "    answer: {} (expected {})",
                        r.answer.as_str(),
                        if q.answer { "yes" } else { "no" }
                    );
                    let ctx = logicrag::context::inference_sentences(&r);
                    for line in ctx.iter().skip(1).take(4) {
                        outln!("      {line}");
                    }
                }
            }
            let wrong: Vec<_> = report.records.iter().filter(|r| !r.correct).collect();
            outln!(
                "  accuracy {:.2} ({} of {} right)",
                report.overall.accuracy,
                report.records.len() - wrong.len(),
                report.records.len()
            );
            for r in wrong.iter().take(5) {
                outln!(
                    "    wrong: [{}] {} → {} said {}",
                    r.window,
                    r.question,
                    r.query.clone().unwrap_or_else(|e| e),
                    r.said.as_str()
                );
            }
        }
        reports.push(report);
    }
    if a.json {
        outln!(
            "{}",
            serde_json::json!({
                "scenarios": reports.iter().map(|r| serde_json::json!({"source": r.source, "overall": r.overall, "by_category": r.by_category})).collect::<Vec<_>>(),
                "overall": total.overall.scores(),
                "by_category": total.by_category.iter().map(|(k, c)| (k.clone(), c.scores())).collect::<std::collections::BTreeMap<_, _>>(),
            })
        );
    } else {
        outln!("\n== scores over all scenarios (oracle perception from the simulator)");
        outp!("{}", total.table());
        outln!();
        outp!("{}", total.confusion_table());
    }
    Ok(ExitCode::SUCCESS)
}
