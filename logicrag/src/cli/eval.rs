//! `logicrag eval`: a question set with expected answers (a CSV, or a
//! simulator scenario's built-in set) scored per category.

use super::{LlmArgs, SourceArgs};
use anyhow::{Context, Result, bail};
use clap::Args;
use logicrag::llm::Condition;
use logicrag::llm::eval::{LmmRecord, Table};
use logicrag::pipeline::{OpenOptions, Pipeline};
use logicrag::source::SourceSpec;
use perception::sim::NoiseLevel;
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
    /// Run noise seeds 0..N for every sim source (default: the source's
    /// own `@SEED`, 0 when not given).
    #[arg(long, value_parser = clap::value_parser!(u64).range(1..=10_000))]
    pub seeds: Option<u64>,
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
    // The LogicPad read and built once for every run.
    let (base, warning) = a.src.open_options(Some(a.llm.translator()?)).prepared()?;
    if let Some(w) = warning {
        eprintln!("note: {w}");
    }
    let mut reports = Vec::new();
    let mut lmm_records: Vec<LmmRecord> = Vec::new();
    let bases: Vec<SourceSpec> = if a.all_scenarios {
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
    let runs = plan_runs(&bases, &a.src.noise, a.seeds)?;
    let sources: Vec<SourceSpec> = runs.iter().map(|r| r.spec.clone()).collect();
    let mut run_labels: Vec<RunLabel> = Vec::new();
    for run in &runs {
        let spec = &run.spec;
        let src = SourceArgs {
            source: spec.clone(),
            noise: run.noise.into_iter().collect(),
            ..a.src.clone()
        };
        let options = OpenOptions {
            source: src.options(),
            keep_scene: a.questions.is_none(),
            ..base.clone()
        };
        // A noise study opens hundreds of runs: quietly, no progress bar.
        let open = |spec: SourceSpec| -> Result<Pipeline> {
            if run.noise.is_some() {
                Ok(Pipeline::open(spec, &options, &mut |_| {})?)
            } else {
                super::open(spec, &options)
            }
        };
        let (mut pipeline, questions, file) = match &a.questions {
            Some(path) => {
                let text = perception::textfile::read_text_file(path)
                    .with_context(|| format!("reading {}", path.display()))?;
                // The same loader as every other command: frames runs the
                // models, and flags another source would ignore are refused.
                let pipeline = open(src.spec()?)?;
                let default_window = if pipeline.windows().len() == 1 {
                    pipeline.windows().first().map(|w| w.id.clone())
                } else {
                    None
                };
                let file = path.display().to_string();
                let qs = logicrag::eval::read_questions(&text, &file, default_window.as_deref())?;
                (pipeline, qs, file)
            }
            None => {
                let full = src.spec()?;
                let SourceSpec::Sim { scenario: name, .. } = &full else {
                    bail!("{spec} has no built-in question set; give --questions FILE.csv");
                };
                let mut pipeline = open(full.clone())?;
                let qs = logicrag::eval::scenario_questions(&pipeline)?;
                pipeline.drop_scene();
                let file = format!("built-in questions of {name}");
                (pipeline, qs, file)
            }
        };
        run_labels.push(RunLabel {
            base: run.base.clone(),
            seed: run.seed(),
            noise: run
                .noise
                .map_or_else(|| "scenario".to_string(), |n| n.to_string()),
        });
        let pb = indicatif::ProgressBar::new(questions.len() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb.set_message(run.label());
        let images = pipeline.take_images();
        // The LMM evaluation asks the same windows again, after this one.
        let lmm_input = (!a.lmm.is_empty()).then(|| (pipeline.subset(|_| true), images));
        let report = logicrag::eval::evaluate_with_progress(pipeline, &questions, &file, &|n| {
            pb.inc(n as u64)
        })?;
        pb.finish_and_clear();
        let mut report = report;
        report.source = run.label();
        reports.push(report);
        if let Some((pipeline, images)) = lmm_input {
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
                    pipeline,
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
            total.add(&rec.category, rec.expected, rec.said);
        }
    }
    // The paper's columns: the logic (LR), then the model per condition.
    let columns = Table::new(&lmm_records).score_columns(&total);
    let json = serde_json::json!({
        "sources": reports.iter().zip(&run_labels).map(|(r, l)| serde_json::json!({"source": r.source, "scenario": l.base, "seed": l.seed, "noise": l.noise, "overall": r.overall, "by_category": r.by_category, "calibration": r.calibration.to_json(), "skill": r.skill.to_json(), "records": r.records})).collect::<Vec<_>>(),
        "noise_table": noise_table(&reports, &run_labels),
        "calibration": calibration_by_level(&reports, &run_labels).iter().map(|(level, c)| {
            let mut v = c.to_json();
            v["noise"] = serde_json::json!(level);
            v
        }).collect::<Vec<_>>(),
        "skill": skill_by_level(&reports, &run_labels).iter().map(|(level, k)| {
            let mut v = k.to_json();
            v["noise"] = serde_json::json!(level);
            v
        }).collect::<Vec<_>>(),
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
        let study = !a.src.noise.is_empty() || a.seeds.is_some();
        for r in reports.iter().filter(|_| !study || a.verbose) {
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
        if study {
            outp!(
                "{}",
                render_noise_table(&noise_table(&reports, &run_labels))
            );
            outp!(
                "{}",
                render_calibration(&calibration_by_level(&reports, &run_labels))
            );
        }
        // Skill and reliability per noise level (one level, "scenario",
        // without --noise), when any answer states a probability.
        for (level, k) in skill_by_level(&reports, &run_labels) {
            if k.overall.scored > 0 {
                outp!("{}", render_skill(&level, &k));
                outp!("{}", render_reliability(&level, &k));
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

/// One evaluation of the plan: a source at one seed under one noise level.
struct Run {
    /// The source as given (before the seed is set).
    base: String,
    spec: SourceSpec,
    /// `None`: the scenario's own noise.
    noise: Option<NoiseLevel>,
}

impl Run {
    fn seed(&self) -> Option<u64> {
        match &self.spec {
            SourceSpec::Sim { seed, .. } => Some(*seed),
            _ => None,
        }
    }

    /// The source with its seed always written, and the noise level.
    fn label(&self) -> String {
        let mut s = match &self.spec {
            SourceSpec::Sim { scenario, seed } => format!("sim:{scenario}@{seed}"),
            other => other.to_string(),
        };
        if let Some(n) = self.noise {
            s.push_str(&format!(" (noise {n})"));
        }
        s
    }
}

/// What the JSON report says of each run.
struct RunLabel {
    base: String,
    seed: Option<u64>,
    noise: String,
}

/// Every (noise level, source, seed) to evaluate, in that order. `--noise`
/// and `--seeds` apply to simulator sources only.
fn plan_runs(bases: &[SourceSpec], noise: &[NoiseLevel], seeds: Option<u64>) -> Result<Vec<Run>> {
    if noise.is_empty() && seeds.is_none() {
        return Ok(bases
            .iter()
            .map(|b| Run {
                base: base_name(b),
                spec: b.clone(),
                noise: None,
            })
            .collect());
    }
    if let Some(b) = bases.iter().find(|b| !matches!(b, SourceSpec::Sim { .. })) {
        bail!("--noise and --seeds apply to simulator sources (sim:NAME[@SEED]), not {b}");
    }
    let levels: Vec<Option<NoiseLevel>> = if noise.is_empty() {
        vec![None]
    } else {
        noise.iter().copied().map(Some).collect()
    };
    let mut out = Vec::new();
    for level in levels {
        for b in bases {
            let SourceSpec::Sim { scenario, seed } = b else {
                continue;
            };
            let seeds: Vec<u64> = match seeds {
                Some(n) => (0..n).collect(),
                None => vec![*seed],
            };
            for s in seeds {
                out.push(Run {
                    base: base_name(b),
                    spec: SourceSpec::Sim {
                        scenario: scenario.clone(),
                        seed: s,
                    },
                    noise: level,
                });
            }
        }
    }
    Ok(out)
}

fn base_name(spec: &SourceSpec) -> String {
    match spec {
        SourceSpec::Sim { scenario, .. } => scenario.clone(),
        other => other.to_string(),
    }
}

/// One cell of the noise table: a source's accuracy under one noise level,
/// over its seeds.
#[derive(serde::Serialize)]
struct NoiseCell {
    noise: String,
    scenario: String,
    seeds: Vec<u64>,
    mean_accuracy: f64,
    min_accuracy: f64,
    /// Questions answered right / asked, over every seed.
    correct: usize,
    questions: usize,
}

fn noise_table(reports: &[logicrag::eval::Report], labels: &[RunLabel]) -> Vec<NoiseCell> {
    let mut cells: Vec<NoiseCell> = Vec::new();
    for (r, l) in reports.iter().zip(labels) {
        let correct = r.records.iter().filter(|x| x.correct).count();
        let i = match cells
            .iter()
            .position(|c| c.noise == l.noise && c.scenario == l.base)
        {
            Some(i) => i,
            None => {
                cells.push(NoiseCell {
                    noise: l.noise.clone(),
                    scenario: l.base.clone(),
                    seeds: Vec::new(),
                    mean_accuracy: 0.0,
                    min_accuracy: f64::INFINITY,
                    correct: 0,
                    questions: 0,
                });
                cells.len() - 1
            }
        };
        let c = &mut cells[i];
        let n = c.seeds.len() as f64;
        c.mean_accuracy = (c.mean_accuracy * n + r.overall.accuracy) / (n + 1.0);
        c.min_accuracy = c.min_accuracy.min(r.overall.accuracy);
        c.seeds.extend(l.seed);
        c.correct += correct;
        c.questions += r.records.len();
    }
    cells
}

/// The calibration of the answers' probabilities per noise level, over
/// every scenario and seed of the level, levels in the plan's order.
fn calibration_by_level(
    reports: &[logicrag::eval::Report],
    labels: &[RunLabel],
) -> Vec<(String, logicrag::metrics::Calibration)> {
    let mut out: Vec<(String, logicrag::metrics::Calibration)> = Vec::new();
    for (r, l) in reports.iter().zip(labels) {
        match out.iter_mut().find(|(level, _)| *level == l.noise) {
            Some((_, c)) => c.merge(&r.calibration),
            None => out.push((l.noise.clone(), r.calibration.clone())),
        }
    }
    out
}

/// The answers' forecasts per noise level, over every scenario and seed of
/// the level, levels in the plan's order.
fn skill_by_level(
    reports: &[logicrag::eval::Report],
    labels: &[RunLabel],
) -> Vec<(String, logicrag::eval::Skill)> {
    let mut out: Vec<(String, logicrag::eval::Skill)> = Vec::new();
    for (r, l) in reports.iter().zip(labels) {
        match out.iter_mut().find(|(level, _)| *level == l.noise) {
            Some((_, k)) => k.merge(&r.skill),
            None => out.push((l.noise.clone(), r.skill.clone())),
        }
    }
    out
}

/// Category × (questions, accuracy, Brier, the base rate's Brier, skill,
/// confidently wrong answers), then the questions without U1 and all.
fn render_skill(level: &str, k: &logicrag::eval::Skill) -> String {
    let mut out = format!(
        "\n== noise {level}: Brier against the base rate of yes (base, skill = 1 − Brier/base) and against stating the accuracy on every answer (const, skill_c); wrong answers with p ≥ {}\n{:<12} {:>9} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>9}\n",
        logicrag::eval::CONFIDENT_P,
        "category",
        "questions",
        "accuracy",
        "Brier",
        "base",
        "skill",
        "const",
        "skill_c",
        "wrong≥p"
    );
    let f = |v: Option<f64>| v.map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
    let mut row = |name: &str, x: &logicrag::eval::Forecasts| {
        out.push_str(&format!(
            "{name:<12} {:>9} {:>8} {:>7} {:>7} {:>7} {:>7} {:>7} {:>9}\n",
            x.questions,
            f(x.accuracy()),
            f(x.brier()),
            f(x.base_brier()),
            f(x.skill()),
            f(x.constant_confidence_brier()),
            f(x.confidence_skill()),
            x.confident_wrong
        ));
    };
    for (c, x) in &k.by_category {
        row(if c.is_empty() { "(none)" } else { c }, x);
    }
    row(
        &format!("without {}", logicrag::eval::PRESENCE_CATEGORY),
        &k.without_presence,
    );
    row("all", &k.overall);
    out
}

/// The reliability table of all answers and of those without U1: per bin
/// of the forecast P(yes), answers, mean P(yes) and the frequency of yes.
fn render_reliability(level: &str, k: &logicrag::eval::Skill) -> String {
    let mut out = format!(
        "\n== noise {level}: reliability of the forecasts P(yes) (all | without {})\n{:<10} {:>7} {:>7} {:>7} | {:>7} {:>7} {:>7}\n",
        logicrag::eval::PRESENCE_CATEGORY,
        "P(yes)",
        "answers",
        "mean p",
        "freq",
        "answers",
        "mean p",
        "freq"
    );
    let all = k.overall.reliability();
    let rest = k.without_presence.reliability();
    for i in 0..logicrag::eval::Forecasts::BINS {
        let from = i as f64 / logicrag::eval::Forecasts::BINS as f64;
        let find = |bins: &[logicrag::eval::ReliabilityBin]| {
            bins.iter()
                .find(|b| (b.from - from).abs() < 1e-9)
                .map_or_else(
                    || format!("{:>7} {:>7} {:>7}", 0, "-", "-"),
                    |b| format!("{:>7} {:>7.3} {:>7.3}", b.n, b.mean_p_yes, b.frequency_yes),
                )
        };
        let to = (i + 1) as f64 / logicrag::eval::Forecasts::BINS as f64;
        let close = if i + 1 == logicrag::eval::Forecasts::BINS {
            ']'
        } else {
            ')'
        };
        out.push_str(&format!(
            "{:<10} {} | {}\n",
            format!("[{from:.1}, {to:.1}{close}"),
            find(&all),
            find(&rest)
        ));
    }
    out
}

/// Noise level × (answers with a probability, Brier score, expected
/// calibration error, mean probability).
fn render_calibration(levels: &[(String, logicrag::metrics::Calibration)]) -> String {
    let mut out = format!(
        "\n== calibration of the answers' probabilities per noise level\n{:<10} {:>8} {:>7} {:>7} {:>7}\n",
        "noise", "answers", "Brier", "ECE", "mean p"
    );
    let f = |v: Option<f64>| v.map_or_else(|| "-".to_string(), |v| format!("{v:.3}"));
    for (level, c) in levels {
        out.push_str(&format!(
            "{level:<10} {:>8} {:>7} {:>7} {:>7}\n",
            c.n,
            f(c.brier()),
            f(c.ece()),
            f(c.mean_probability())
        ));
    }
    out
}

/// Scenario × noise level: mean accuracy over the seeds (lowest seed's in
/// brackets).
fn render_noise_table(cells: &[NoiseCell]) -> String {
    let mut levels: Vec<&str> = Vec::new();
    let mut scenarios: Vec<&str> = Vec::new();
    for c in cells {
        if !levels.contains(&c.noise.as_str()) {
            levels.push(&c.noise);
        }
        if !scenarios.contains(&c.scenario.as_str()) {
            scenarios.push(&c.scenario);
        }
    }
    let seeds = cells.first().map_or(0, |c| c.seeds.len());
    let mut out = format!(
        "\n== accuracy per noise level, mean over {seeds} seed(s) (lowest seed)\n{:<16}",
        "scenario"
    );
    for l in &levels {
        out.push_str(&format!(" {l:>14}"));
    }
    out.push('\n');
    for s in &scenarios {
        out.push_str(&format!("{s:<16}"));
        for l in &levels {
            match cells.iter().find(|c| c.noise == *l && c.scenario == *s) {
                Some(c) => out.push_str(&format!(
                    " {:>6.3} ({:.2})",
                    c.mean_accuracy, c.min_accuracy
                )),
                None => out.push_str(&format!(" {:>14}", "-")),
            }
        }
        out.push('\n');
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use perception::sim::NoisePreset;

    fn sim(name: &str, seed: u64) -> SourceSpec {
        SourceSpec::Sim {
            scenario: name.into(),
            seed,
        }
    }

    #[test]
    fn the_plan_runs_every_seed_under_every_noise_level_and_names_the_seed() {
        let runs = plan_runs(
            &[sim("braking", 7)],
            &[NoisePreset::None.into(), NoisePreset::High.into()],
            Some(3),
        )
        .unwrap();
        let labels: Vec<String> = runs.iter().map(Run::label).collect();
        assert_eq!(
            labels,
            [
                "sim:braking@0 (noise none)",
                "sim:braking@1 (noise none)",
                "sim:braking@2 (noise none)",
                "sim:braking@0 (noise high)",
                "sim:braking@1 (noise high)",
                "sim:braking@2 (noise high)",
            ]
        );
        // Without --seeds the source's own seed runs, and is named even when 0.
        let runs = plan_runs(&[sim("braking", 7)], &[NoisePreset::High.into()], None).unwrap();
        assert_eq!(runs[0].label(), "sim:braking@7 (noise high)");
        let runs = plan_runs(&[sim("braking", 0)], &[], None).unwrap();
        assert_eq!(runs[0].label(), "sim:braking@0");
        let kitti: SourceSpec = "kitti:/nowhere".parse().unwrap();
        assert!(plan_runs(&[kitti], &[NoisePreset::High.into()], None).is_err());
        // A scaled level is named as written.
        let runs = plan_runs(&[sim("braking", 0)], &["high*2".parse().unwrap()], None).unwrap();
        assert_eq!(runs[0].label(), "sim:braking@0 (noise high*2)");
    }
}
