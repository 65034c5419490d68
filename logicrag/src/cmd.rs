//! Subcommands that combine several library steps: demo, simulate,
//! context, eval, repl.

use super::*;
use logicrag::context::RagContext;

pub fn simulate(a: SimulateArgs) -> Result<ExitCode> {
    let spec = format!("sim:{}@{}", a.scenario, a.seed);
    let source = perception::Source::parse(&spec)?;
    let run = source.simulate()?;
    let windows =
        perception::window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default())?;
    if let Some(dir) = &a.out {
        std::fs::create_dir_all(dir.join("facts"))
            .with_context(|| format!("creating {}", dir.display()))?;
        std::fs::write(
            dir.join("tracks.json"),
            perception::json::to_tracks_json(&run.sequence)?,
        )?;
        std::fs::write(
            dir.join("events.json"),
            serde_json::to_string_pretty(&run.events)?,
        )?;
        for w in &windows {
            let id = format!("{}_{:06}", run.sequence.name, w.first_frame);
            std::fs::write(dir.join("facts").join(format!("{id}.facts")), w.to_kb())?;
        }
        eprintln!(
            "wrote {}/tracks.json, events.json and {} window KBs under facts/",
            dir.display(),
            windows.len()
        );
    }
    if a.json {
        outln!(
            "{}",
            serde_json::json!({
                "scenario": run.sequence.name, "frames": run.sequence.frame_count,
                "observations": run.sequence.observations.len(), "events": run.events,
                "windows": windows.len(),
            })
        );
    } else {
        outln!(
            "scenario {}: {} frames, {} observations, {} tracks, {} windows",
            run.sequence.name,
            run.sequence.frame_count,
            run.sequence.observations.len(),
            run.sequence.tracks().len(),
            windows.len()
        );
        outln!("ground-truth events:");
        for e in &run.events {
            let other = e
                .other
                .as_ref()
                .map(|o| format!(" → {o}"))
                .unwrap_or_default();
            outln!(
                "  frames {:>3}-{:<3} {:<14} {}{}",
                e.first_frame,
                e.last_frame,
                format!("{:?}", e.kind),
                e.object,
                other
            );
        }
    }
    Ok(ExitCode::SUCCESS)
}

pub fn context(a: ContextArgs) -> Result<ExitCode> {
    let pad = load_pad(&a.src.logicpad)?;
    let translator = translator_for(&pad)?;
    let (query, question) = to_query(&translator, &a.text)?;
    let loaded = load_source(&a.src)?;
    let observed = loaded.observability.classify(&pad);
    for kb in window_kbs(loaded, &pad, a.window_id.as_deref())? {
        let r = ask(&pad, &kb, &observed, &query, AskOptions::default());
        let ctx = RagContext::new(&kb, question.as_deref(), &r);
        if a.json {
            outln!("{}", serde_json::to_string(&ctx)?);
        } else {
            outln!("{}", ctx.to_text());
        }
    }
    Ok(ExitCode::SUCCESS)
}

/// Loads a built-in scenario as a source and generates its question set.
fn scenario_questions(
    name: &str,
    opts: &LoadOptions,
) -> Result<(Loaded, Vec<logicrag::questions::Question>)> {
    let loaded = load(&format!("sim:{name}"), opts)?;
    let run = loaded
        .sim
        .as_ref()
        .context("a sim source keeps its simulation")?;
    let windows = perception::window_facts(&run.sequence, opts.windows, &opts.config)?;
    let questions = logicrag::questions::generate(run, &windows, &opts.config);
    Ok((loaded, questions))
}

pub fn demo(a: DemoArgs) -> Result<ExitCode> {
    let pad = LogicPad::builtin();
    let translator = translator_for(&pad)?;
    let names: Vec<String> = match &a.scenario {
        Some(s) => vec![s.clone()],
        None => perception::sim::BUILTIN_NAMES
            .iter()
            .map(|s| s.to_string())
            .collect(),
    };
    let opts = LoadOptions::default();
    let mut total = logicrag::metrics::Evaluation::default();
    let mut reports = Vec::new();
    for name in &names {
        let (loaded, questions) = scenario_questions(name, &opts)?;
        // Keep one window's KB for the worked examples.
        let example_window = questions.first().map(|q| q.window.clone());
        let example = example_window
            .as_ref()
            .and_then(|id| loaded.windows.iter().find(|w| &w.id == id).cloned());
        let observed = loaded.observability.classify(&pad);
        let report = logicrag::eval::evaluate(&pad, &translator, loaded, &questions, name)?;
        for r in &report.records {
            total.add(&r.category, r.expected, r.said.said());
        }
        if !a.json {
            outln!("== scenario {name}: {} questions", questions.len());
            if let Some(input) = example {
                let kb = WindowKb::build(input, pad.program())?;
                for q in questions.iter().filter(|q| q.window == kb.id).take(a.show) {
                    let Ok(t) = translator.translate(&q.question) else {
                        continue;
                    };
                    let r = ask(&pad, &kb, &observed, &t.query, AskOptions::default());
                    outln!("  Q [{}] {}", kb.id, q.question);
                    outln!("    query:  {}", t.query);
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

pub fn eval(a: EvalArgs) -> Result<ExitCode> {
    let pad = load_pad(&a.src.logicpad)?;
    let translator = translator_for(&pad)?;
    let opts = load_options(&a.src)?;
    let mut reports = Vec::new();
    let sources: Vec<String> = if a.all_scenarios {
        perception::sim::BUILTIN_NAMES
            .iter()
            .map(|s| format!("sim:{s}"))
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
                let Some(name) = spec.strip_prefix("sim:") else {
                    bail!("{spec} has no built-in question set; give --questions FILE.csv");
                };
                check_frames_flags(&src)?;
                let (loaded, qs) = scenario_questions(name, &opts)?;
                (loaded, qs, format!("built-in questions of {name}"))
            }
        };
        let pb = indicatif::ProgressBar::new(questions.len() as u64);
        pb.set_style(
            indicatif::ProgressStyle::with_template("{msg} [{bar:30}] {pos}/{len}")
                .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        pb.set_message(spec.clone());
        let report = logicrag::eval::evaluate_with_progress(
            &pad,
            &translator,
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

pub fn repl(a: ReplArgs) -> Result<ExitCode> {
    use rustyline::error::ReadlineError;
    let pad = load_pad(&a.src.logicpad)?;
    let loaded = load_source(&a.src)?;
    let label = loaded.label.clone();
    let mut session = logicrag::repl::Session::new(
        pad,
        a.src.logicpad.clone(),
        loaded.windows,
        loaded.observability,
    )?;
    let words = std::rc::Rc::new(std::cell::RefCell::new(session.completions()));
    let mut rl: rustyline::Editor<Completion, rustyline::history::DefaultHistory> =
        rustyline::Editor::new()?;
    rl.set_helper(Some(Completion {
        words: words.clone(),
    }));
    let history = std::env::var_os("HOME").map(|h| PathBuf::from(h).join(".logicrag_history"));
    if let Some(h) = &history {
        let _ = rl.load_history(h);
    }
    eprintln!(
        "logicrag repl on {label}: {} windows, starting at {}; `:help` for commands, Ctrl-D to leave",
        session.window_count(),
        session.window().id
    );
    loop {
        let prompt = format!("{}> ", session.window().id);
        match rl.readline(&prompt) {
            Ok(line) => {
                let t = line.trim();
                if t == ":quit" || t == ":q" {
                    break;
                }
                if !t.is_empty() {
                    let _ = rl.add_history_entry(t);
                }
                outp!("{}", session.handle(&line));
                *words.borrow_mut() = session.completions();
            }
            Err(ReadlineError::Interrupted) => continue,
            Err(ReadlineError::Eof) => break,
            Err(e) => return Err(e.into()),
        }
    }
    if let Some(h) = &history {
        let _ = rl.save_history(h);
    }
    Ok(ExitCode::SUCCESS)
}

/// Tab completion over predicates, values, objects and commands.
struct Completion {
    words: std::rc::Rc<std::cell::RefCell<Vec<String>>>,
}

impl rustyline::completion::Completer for Completion {
    type Candidate = String;
    fn complete(
        &self,
        line: &str,
        pos: usize,
        _ctx: &rustyline::Context<'_>,
    ) -> rustyline::Result<(usize, Vec<String>)> {
        let head = line.get(..pos).unwrap_or(line);
        let start = head
            .rfind(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':'))
            .map_or(0, |i| i + 1);
        let prefix = head.get(start..).unwrap_or("");
        if prefix.is_empty() {
            return Ok((pos, Vec::new()));
        }
        let found = self
            .words
            .borrow()
            .iter()
            .filter(|w| w.starts_with(prefix))
            .cloned()
            .collect();
        Ok((start, found))
    }
}
impl rustyline::hint::Hinter for Completion {
    type Hint = String;
}
impl rustyline::highlight::Highlighter for Completion {}
impl rustyline::validate::Validator for Completion {}
impl rustyline::Helper for Completion {}
