//! `logicrag plot`: pictures as PNG or SVG (by the file's extension) —
//! `plot bev`, a window's tracks and the camera's path from above, and
//! `plot eval`, per-category accuracy and F1 of the logic (LR) and, in a
//! report with a model's answers, of C1–C3, `plot noise`, accuracy
//! against noise level from an `eval --noise` report, and `plot
//! reliability`, the reliability diagram of an `eval` report's forecasts.

use super::SourceArgs;
use super::demo::scenario_questions;
use anyhow::{Context, Result, bail};
use clap::{Args, Subcommand};
use logicrag::metrics::ScoreColumn;
use std::path::PathBuf;
use std::process::ExitCode;

#[derive(Args)]
pub struct PlotArgs {
    #[command(subcommand)]
    pub what: PlotCommand,
}

// Parsed once per run: the size of the larger variant costs nothing.
#[allow(clippy::large_enum_variant)]
#[derive(Subcommand)]
pub enum PlotCommand {
    /// A window's tracks, the ego path and object names on the bird's-eye plane.
    Bev(BevArgs),
    /// Per-category accuracy and F1 bars (LR, and C1–C3 when the report has them).
    Eval(EvalPlotArgs),
    /// Accuracy against noise level, one line per scenario, from a report
    /// of `eval --noise LEVELS --seeds N --report FILE` (or `--json`).
    Noise(NoisePlotArgs),
    /// The reliability diagram of the answers' probabilities read as
    /// forecasts of yes, one curve per noise level, from a report of `eval
    /// [--noise LEVELS] --report FILE` (or `--json`).
    Reliability(ReliabilityPlotArgs),
}

#[derive(Args)]
pub struct ReliabilityPlotArgs {
    /// A JSON report written by `eval ... --report FILE` (or its `--json` output).
    #[arg(long)]
    pub report: PathBuf,
    /// Output file, .png or .svg.
    #[arg(long)]
    pub out: PathBuf,
    /// Draw every question, U1 (presence) included; by default the
    /// questions without U1, which are nearly always right.
    #[arg(long)]
    pub all_questions: bool,
    /// Width in pixels.
    #[arg(long, default_value_t = 900)]
    pub width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 900)]
    pub height: u32,
}

#[derive(Args)]
pub struct NoisePlotArgs {
    /// A JSON report written by `eval --noise ... --report FILE` (or its `--json` output).
    #[arg(long)]
    pub report: PathBuf,
    /// Output file, .png or .svg.
    #[arg(long)]
    pub out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 1000)]
    pub width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 650)]
    pub height: u32,
}

#[derive(Args)]
pub struct BevArgs {
    #[command(flatten)]
    pub src: SourceArgs,
    /// The window to draw (default: the first).
    #[arg(long = "window-id")]
    pub window_id: Option<String>,
    /// Output file, .png or .svg.
    #[arg(long)]
    pub out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 1000)]
    pub width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 800)]
    pub height: u32,
}

#[derive(Args)]
pub struct EvalPlotArgs {
    /// A JSON report written by `eval --report FILE` (default: evaluate
    /// every built-in scenario's question set now).
    #[arg(long)]
    pub report: Option<PathBuf>,
    /// Output file, .png or .svg.
    #[arg(long)]
    pub out: PathBuf,
    /// Width in pixels.
    #[arg(long, default_value_t = 1100)]
    pub width: u32,
    /// Height in pixels.
    #[arg(long, default_value_t = 760)]
    pub height: u32,
}

pub fn run(a: PlotArgs) -> Result<ExitCode> {
    match a.what {
        PlotCommand::Bev(b) => bev(b),
        PlotCommand::Eval(e) => eval(e),
        PlotCommand::Noise(n) => noise(n),
        PlotCommand::Reliability(r) => reliability(r),
    }
}

/// An `eval --report` file as JSON, the error naming the file.
fn read_report(path: &std::path::Path) -> Result<serde_json::Value> {
    let text =
        std::fs::read_to_string(path).with_context(|| format!("reading {}", path.display()))?;
    serde_json::from_str(&text).with_context(|| format!("{} is not JSON", path.display()))
}

/// The report's `skill` (one entry per noise level) as one curve per level.
fn reliability(a: ReliabilityPlotArgs) -> Result<ExitCode> {
    logicrag::plot::Format::of(&a.out)?;
    let path = &a.report;
    let report = read_report(path)?;
    let Some(levels) = report.get("skill").and_then(|t| t.as_array()) else {
        bail!(
            "{} has no `skill`: write it with `logicrag eval --report FILE`",
            path.display()
        );
    };
    let subset = if a.all_questions {
        "overall"
    } else {
        "without_u1"
    };
    let mut curves = Vec::new();
    for (i, level) in levels.iter().enumerate() {
        let (Some(noise), Some(bins)) = (
            level.get("noise").and_then(|v| v.as_str()),
            level.get(subset).and_then(|v| v.get("reliability")),
        ) else {
            bail!(
                "{}: skill[{i}] needs `noise` and `{subset}.reliability`",
                path.display()
            );
        };
        let bins: Vec<logicrag::eval::ReliabilityBin> = serde_json::from_value(bins.clone())
            .with_context(|| {
                format!(
                    "{}: skill[{i}].{subset}.reliability is not a list of bins",
                    path.display()
                )
            })?;
        curves.push(logicrag::plot::ReliabilityCurve {
            label: format!("noise {noise}"),
            bins,
        });
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let which = if a.all_questions {
        "all questions"
    } else {
        "without U1"
    };
    let title = format!("Reliability of P(yes), {which} ({name})");
    logicrag::plot::reliability_chart(&curves, &title, &a.out, (a.width, a.height))?;
    eprintln!("wrote {} ({} levels)", a.out.display(), curves.len());
    Ok(ExitCode::SUCCESS)
}

/// The report's `noise_table` (scenario × noise level, mean accuracy over
/// the seeds) as one line per scenario, in the order the table names them.
fn noise(a: NoisePlotArgs) -> Result<ExitCode> {
    logicrag::plot::Format::of(&a.out)?;
    let path = &a.report;
    let report = read_report(path)?;
    let Some(cells) = report.get("noise_table").and_then(|t| t.as_array()) else {
        bail!(
            "{} has no `noise_table`: write it with `logicrag eval --noise LEVELS --report FILE`",
            path.display()
        );
    };
    let mut lines: Vec<logicrag::plot::NoiseLine> = Vec::new();
    for (i, c) in cells.iter().enumerate() {
        let (Some(scenario), Some(level), Some(acc)) = (
            c.get("scenario").and_then(|v| v.as_str()),
            c.get("noise").and_then(|v| v.as_str()),
            c.get("mean_accuracy").and_then(|v| v.as_f64()),
        ) else {
            bail!(
                "{}: noise_table[{i}] needs `scenario`, `noise` and `mean_accuracy`",
                path.display()
            );
        };
        match lines.iter_mut().find(|l| l.scenario == scenario) {
            Some(l) => l.points.push((level.to_string(), acc)),
            None => lines.push(logicrag::plot::NoiseLine {
                scenario: scenario.to_string(),
                points: vec![(level.to_string(), acc)],
            }),
        }
    }
    let name = path
        .file_name()
        .map(|n| n.to_string_lossy().into_owned())
        .unwrap_or_default();
    let title = format!("Accuracy against noise level ({name})");
    logicrag::plot::noise_chart(&lines, &title, &a.out, (a.width, a.height))?;
    eprintln!("wrote {} ({} scenarios)", a.out.display(), lines.len());
    Ok(ExitCode::SUCCESS)
}

fn bev(a: BevArgs) -> Result<ExitCode> {
    // Checked before loading: a wrong extension should not cost a load.
    logicrag::plot::Format::of(&a.out)?;
    let options = logicrag::pipeline::OpenOptions {
        keep_scene: true,
        ..a.src.open_options(None)
    };
    let pipeline = super::open(a.src.spec()?, &options)?;
    let Some(scenes) = logicrag::scene::Scenes::of(&pipeline) else {
        bail!(
            "{} has no tracks to draw (a facts: source holds facts only)",
            pipeline.label()
        );
    };
    let window = match &a.window_id {
        Some(id) => pipeline.windows().iter().find(|w| &w.id == id),
        None => pipeline.windows().first(),
    };
    let Some(w) = window else {
        return Err(pipeline.no_window(&a.window_id.unwrap_or_default()).into());
    };
    let scene = scenes.window(&w.id, w.first_frame, w.last_frame);
    logicrag::plot::bev(&scene, &a.out, (a.width, a.height))?;
    eprintln!(
        "wrote {} ({} tracks, frames {}–{})",
        a.out.display(),
        scene.tracks.len(),
        scene.first_frame,
        scene.last_frame
    );
    Ok(ExitCode::SUCCESS)
}

fn eval(a: EvalPlotArgs) -> Result<ExitCode> {
    logicrag::plot::Format::of(&a.out)?;
    let (columns, title) = match &a.report {
        Some(path) => {
            let text = std::fs::read_to_string(path)
                .with_context(|| format!("reading {}", path.display()))?;
            let report: serde_json::Value = serde_json::from_str(&text)
                .with_context(|| format!("{} is not JSON", path.display()))?;
            let Some(columns) = report.get("columns") else {
                bail!(
                    "{} has no `columns`: write the report with `logicrag eval --report FILE`",
                    path.display()
                );
            };
            let columns: Vec<ScoreColumn> =
                serde_json::from_value(columns.clone()).with_context(|| {
                    format!(
                        "{}: `columns` is not a list of score columns",
                        path.display()
                    )
                })?;
            let name = path
                .file_name()
                .map(|n| n.to_string_lossy().into_owned())
                .unwrap_or_default();
            (columns, format!("Accuracy and F1 per category ({name})"))
        }
        None => (
            builtin_columns()?,
            "Logic-RAG on the built-in scenarios: accuracy and F1 per category".to_string(),
        ),
    };
    logicrag::plot::eval_chart(&columns, &title, &a.out, (a.width, a.height))?;
    eprintln!("wrote {}", a.out.display());
    Ok(ExitCode::SUCCESS)
}

/// LR's scores on every built-in scenario's question set.
fn builtin_columns() -> Result<Vec<ScoreColumn>> {
    let (options, _) = logicrag::pipeline::OpenOptions::default().prepared()?;
    let mut total = logicrag::metrics::Evaluation::default();
    for name in perception::sim::BUILTIN_NAMES {
        let (pipeline, questions) = scenario_questions(name, &options)?;
        let report = logicrag::eval::evaluate(pipeline, &questions, name)?;
        for rec in &report.records {
            total.add(&rec.category, rec.expected, rec.said);
        }
    }
    Ok(vec![ScoreColumn::from_evaluation("LR", &total)])
}
