//! The `logicrag` command line: a thin layer over the library crates.

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use logicpad::LogicPad;
use logicrag::ask::{AskOptions, AskResult, ask};
use logicrag::batch::{parse_queries, run_batch};
use logicrag::kb::WindowKb;
use logicrag::source::{LoadOptions, Loaded, load};
use logicrag::translate::Translator;
use perception::{FactConfig, WindowSpec};
use std::io::Write;
use std::path::PathBuf;
use std::process::ExitCode;

/// `println!` that reports a closed stdout (e.g. `| head`) as an error
/// instead of panicking.
macro_rules! outln {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        writeln!(std::io::stdout(), $($t)*)?
    }};
}
/// `print!` counterpart of [`outln!`].
macro_rules! outp {
    ($($t:tt)*) => {{
        use std::io::Write as _;
        write!(std::io::stdout(), $($t)*)?
    }};
}

#[derive(Parser)]
#[command(
    name = "logicrag",
    version,
    about = "Ask questions about driving video and get proved answers"
)]
struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run built-in simulator scenarios end to end: KBs, questions, answers, scores.
    Demo(DemoArgs),
    /// Run a simulator scenario and print or write its tracks, events and facts.
    Simulate(SimulateArgs),
    /// Print the facts of a source's windows (text KB or JSON with provenance).
    Facts(FactsArgs),
    /// Ask a question or a query on a source's windows.
    Ask(AskArgs),
    /// Translate a question (or a CSV of questions) into a query.
    Translate(TranslateArgs),
    /// Print the retrieval context (C2 inference result, C3 fact sentences) for a question.
    Context(ContextArgs),
    /// Check a LogicPad file and print all diagnostics (exit 0 clean, 1 warnings, 2 errors).
    Lint(LintArgs),
    /// Evaluate a question set with expected answers.
    Eval(EvalArgs),
    /// Interactive session over a source's windows.
    Repl(ReplArgs),
    /// Run perception on a source (raw frames with --models) and write its tracks as JSON.
    Perceive(PerceiveArgs),
}

#[derive(Args)]
struct PerceiveArgs {
    #[command(flatten)]
    src: SourceArgs,
    /// Output file for the tracks (default: stdout).
    #[arg(long)]
    out: Option<PathBuf>,
}

#[derive(Args, Clone)]
struct SourceArgs {
    /// Where windows come from: sim:SCENARIO[@SEED], kitti:DIR, json:FILE, facts:PATH, frames:DIR (with --models).
    #[arg(long, default_value = "sim:urban_crossing")]
    source: String,
    /// KITTI sequence, e.g. 0000.
    #[arg(long)]
    sequence: Option<String>,
    /// Frames per window.
    #[arg(long, default_value_t = 10)]
    window: u32,
    /// Frames between window starts (default: the window size, no overlap).
    #[arg(long)]
    stride: Option<u32>,
    /// One inclusive frame range instead of sliding windows, e.g. 0-9.
    #[arg(long)]
    frames: Option<String>,
    /// Perception thresholds (YAML or JSON FactConfig).
    #[arg(long)]
    config: Option<PathBuf>,
    /// LogicPad rules (default: the built-in LogicPad).
    #[arg(long)]
    logicpad: Option<PathBuf>,
    /// Model set YAML for `frames:DIR` sources (detector, optional depth and flow).
    #[arg(long)]
    models: Option<PathBuf>,
    /// Camera calibration for `frames:DIR`: a KITTI calib file (its `P2:`
    /// line) or YAML with fx, fy, cx, cy (pixels) and height_m (metres above
    /// the road). Without it: fx = fy = image width, centred, 1.65 m — depths
    /// are then only roughly metric.
    #[arg(long)]
    camera: Option<PathBuf>,
    /// Frame rate of `frames:DIR` frames, per second (default: 10, KITTI's).
    #[arg(long)]
    fps: Option<f64>,
}

#[derive(Args)]
struct DemoArgs {
    /// One built-in scenario (default: all).
    #[arg(long)]
    scenario: Option<String>,
    /// Answers shown per scenario.
    #[arg(long, default_value_t = 6)]
    show: usize,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct SimulateArgs {
    /// Built-in scenario name or scenario file.
    scenario: String,
    /// Noise seed.
    #[arg(long, default_value_t = 0)]
    seed: u64,
    /// Write tracks.json, events.json and facts/ into this directory.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct FactsArgs {
    #[command(flatten)]
    src: SourceArgs,
    /// JSON with provenance, one window object per line.
    #[arg(long)]
    json: bool,
    /// Show each fact's provenance as a comment.
    #[arg(long)]
    why: bool,
}

#[derive(Args)]
struct AskArgs {
    #[command(flatten)]
    src: SourceArgs,
    /// A question in English or a query (`TypeOf(x, Car) ^ Moving(x)`).
    text: Option<String>,
    /// A batch of `window<TAB>query` lines.
    #[arg(long)]
    queries: Option<PathBuf>,
    /// Only this window id (default: every window).
    #[arg(long = "window-id")]
    window_id: Option<String>,
    /// One JSON object per line and answer.
    #[arg(long)]
    json: bool,
    /// `window<TAB>index<TAB>yes|no<TAB>count` lines (the KB benchmark's answer format).
    #[arg(long)]
    tsv: bool,
    /// Skip proofs and why-not (faster batches).
    #[arg(long)]
    no_proofs: bool,
}

#[derive(Args)]
struct TranslateArgs {
    /// The question.
    question: Option<String>,
    /// Take the words from this LogicPad (default: the built-in LogicPad).
    #[arg(long)]
    logicpad: Option<PathBuf>,
    /// A CSV with a `Question` column; writes `Question,Query`.
    #[arg(long)]
    csv: Option<PathBuf>,
    /// Output file for --csv (default: stdout).
    #[arg(long)]
    out: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct ContextArgs {
    #[command(flatten)]
    src: SourceArgs,
    /// The question (or query).
    text: String,
    /// Only this window id.
    #[arg(long = "window-id")]
    window_id: Option<String>,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct LintArgs {
    /// The LogicPad YAML file.
    file: PathBuf,
    /// Treat every error as fatal (nothing loads).
    #[arg(long)]
    strict: bool,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
}

#[derive(Args)]
struct EvalArgs {
    #[command(flatten)]
    src: SourceArgs,
    /// CSV with Question, Answer (yes/no/1/0), optional Window and Category
    /// columns (default: the source's built-in question set; sim only).
    #[arg(long)]
    questions: Option<PathBuf>,
    /// Every built-in scenario with its built-in question set.
    #[arg(long)]
    all_scenarios: bool,
    /// Write the JSON report here.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Machine-readable output.
    #[arg(long)]
    json: bool,
    /// Print every wrong answer.
    #[arg(long)]
    verbose: bool,
}

#[derive(Args)]
struct ReplArgs {
    #[command(flatten)]
    src: SourceArgs,
}

fn main() -> ExitCode {
    let cli = Cli::parse();
    match run(cli) {
        Ok(code) => code,
        Err(e) => {
            // A reader that stopped early (`| head`) is not an error.
            if e.downcast_ref::<std::io::Error>()
                .is_some_and(|io| io.kind() == std::io::ErrorKind::BrokenPipe)
            {
                return ExitCode::SUCCESS;
            }
            eprintln!("error: {}", error_text(&e));
            ExitCode::from(2)
        }
    }
}

/// The error and its causes on one line, each cause once: our library
/// errors already end their message with their cause (`{path}: {source}`),
/// so anyhow's `{:#}` would print "No such file … : No such file …".
fn error_text(e: &anyhow::Error) -> String {
    let mut text = e.to_string();
    for cause in e.chain().skip(1) {
        let c = cause.to_string();
        // Only a whole trailing cause (`…: cause`) counts as already said.
        if text != c && !text.ends_with(&format!(": {c}")) {
            text.push_str(": ");
            text.push_str(&c);
        }
    }
    text
}

fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Demo(a) => cmd::demo(a),
        Command::Simulate(a) => cmd::simulate(a),
        Command::Facts(a) => cmd_facts(a),
        Command::Ask(a) => cmd_ask(a),
        Command::Translate(a) => cmd_translate(a),
        Command::Context(a) => cmd::context(a),
        Command::Lint(a) => cmd_lint(a),
        Command::Eval(a) => cmd::eval(a),
        Command::Repl(a) => cmd::repl(a),
        Command::Perceive(a) => {
            let loaded = load_source(&a.src)?;
            let Some(seq) = &loaded.sequence else {
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
    }
}

fn load_pad(path: &Option<PathBuf>) -> Result<LogicPad> {
    match path {
        None => Ok(LogicPad::builtin()),
        Some(p) => {
            let pad = LogicPad::load(p).map_err(|e| anyhow::anyhow!("{e}"))?;
            let errors: Vec<_> = pad.diagnostics().iter().filter(|d| d.is_error()).collect();
            if !errors.is_empty() {
                eprintln!(
                    "warning: {} has {} error(s); the rules concerned are left out (see `logicrag lint {}`)",
                    p.display(),
                    errors.len(),
                    p.display()
                );
            }
            Ok(pad)
        }
    }
}

/// The translator whose words come from the LogicPad (its `phrases:` first,
/// then the built-in everyday phrases for the same names).
fn translator_for(pad: &LogicPad) -> Result<Translator> {
    let vocab = logicrag::translate::Vocabulary::from_schema(pad.schema()).map_err(|e| {
        anyhow::anyhow!("the LogicPad's vocabulary cannot drive the translator: {e}")
    })?;
    Ok(Translator::new(vocab))
}

fn load_options(src: &SourceArgs) -> Result<LoadOptions> {
    let config = match &src.config {
        None => FactConfig::default(),
        Some(p) => {
            let text =
                std::fs::read_to_string(p).with_context(|| format!("reading {}", p.display()))?;
            let origin = p.display().to_string();
            if p.extension().is_some_and(|e| e == "json") {
                FactConfig::from_json(&text, &origin)?
            } else {
                FactConfig::from_yaml(&text, &origin)?
            }
        }
    };
    let frames = match &src.frames {
        Some(f) => Some(perception::source::parse_frame_range(f)?),
        None => None,
    };
    if src.window == 0 {
        bail!("--window must be at least 1 frame");
    }
    let stride = src.stride.unwrap_or(src.window);
    if stride == 0 {
        bail!("--stride must be at least 1 frame");
    }
    Ok(LoadOptions {
        sequence: src.sequence.clone(),
        windows: WindowSpec {
            size: src.window,
            stride,
        },
        frames,
        config,
    })
}

/// Settings that only the frames pipeline reads must not be dropped without
/// a word when the source is another.
fn check_frames_flags(src: &SourceArgs) -> Result<()> {
    if let Some(dir) = src.source.strip_prefix("frames:") {
        // A frames directory is one sequence; a sequence name would be
        // dropped without a word.
        if src.sequence.is_some() {
            bail!(
                "--sequence does not apply to frames:DIR sources (the directory is the sequence)"
            );
        }
        // Frames are numbered by their order in the directory, not by their
        // file names: a range past the end is refused before any model runs.
        if let Some(range) = &src.frames {
            let count = perception::raw::frames::list_frames(std::path::Path::new(dir))?.len();
            let (_, last) = perception::source::parse_frame_range(range)?;
            if usize::try_from(last).map_or(true, |l| l >= count) {
                bail!(
                    "--frames {range}: {dir} has {count} frames, numbered 0–{} by their order \
                     in the directory (file names are not frame numbers)",
                    count.saturating_sub(1)
                );
            }
        }
        return Ok(());
    }
    for (flag, given) in [
        ("--models", src.models.is_some()),
        ("--camera", src.camera.is_some()),
        ("--fps", src.fps.is_some()),
    ] {
        if given {
            bail!(
                "{flag} applies to frames:DIR sources only (this source is `{}`)",
                src.source
            );
        }
    }
    Ok(())
}

fn load_source(src: &SourceArgs) -> Result<Loaded> {
    let opts = load_options(src)?;
    check_frames_flags(src)?;
    if src.source.starts_with("frames:") {
        let Some(models) = &src.models else {
            bail!(
                "a frames: source needs --models FILE (e.g. perception/models/nanodet-m-416-coco.yaml)"
            );
        };
        let mut frames = perception::raw::frames::FramesOptions::default();
        if let Some(path) = &src.camera {
            frames.camera = Some(perception::raw::camera::Calibration::read(path)?);
        }
        if let Some(fps) = src.fps {
            if !(fps.is_finite() && fps > 0.0) {
                bail!("--fps must be a positive number of frames per second, got {fps}");
            }
            frames.fps = fps;
        }
        let pb = indicatif::ProgressBar::new(0);
        pb.set_style(
            indicatif::ProgressStyle::with_template(
                "perceiving [{bar:30}] {pos}/{len} frames {msg}",
            )
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
        );
        let mut progress = |p: perception::raw::frames::Progress| {
            pb.set_length(u64::from(p.total));
            pb.set_position(u64::from(p.done));
        };
        let loaded =
            logicrag::source::load_frames(&src.source, models, &opts, &frames, &mut progress)?;
        pb.finish_and_clear();
        if frames.camera.is_none() {
            eprintln!(
                "note: no --camera calibration; assumed fx = fy = image width, principal point \
                 at the centre and a camera {} m above the road, so 3D positions are only roughly metric",
                perception::raw::frames::DEFAULT_CAMERA_HEIGHT_M
            );
        }
        return Ok(loaded);
    }
    Ok(load(&src.source, &opts)?)
}

/// Reasons the windows to ask about: all of them, or the one named by
/// `--window-id` (an id the source does not have is an error, not silence).
fn window_kbs(loaded: Loaded, pad: &LogicPad, window_id: Option<&str>) -> Result<Vec<WindowKb>> {
    let inputs: Vec<_> = match window_id {
        None => loaded.windows,
        Some(id) => {
            let known: Vec<String> = loaded
                .windows
                .iter()
                .take(5)
                .map(|w| w.id.clone())
                .collect();
            let found: Vec<_> = loaded.windows.into_iter().filter(|w| w.id == id).collect();
            if found.is_empty() {
                bail!(
                    "{} has no window `{id}` (it has {}, …)",
                    loaded.label,
                    known.join(", ")
                );
            }
            found
        }
    };
    inputs
        .into_iter()
        .map(|w| Ok(WindowKb::build(w, pad.program())?))
        .collect()
}

fn cmd_facts(a: FactsArgs) -> Result<ExitCode> {
    let loaded = load_source(&a.src)?;
    let out = std::io::stdout();
    let mut out = out.lock();
    for w in &loaded.windows {
        if a.json {
            let v = serde_json::json!({
                "window": w.id, "index": w.index, "first_frame": w.first_frame, "last_frame": w.last_frame,
                "source": loaded.label, "facts": w.facts,
            });
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
            for f in &w.facts {
                if a.why {
                    writeln!(
                        out,
                        "{}    # {}",
                        f.to_kb_line(),
                        logicrag::ask::describe_provenance(&f.provenance)
                    )?;
                } else {
                    writeln!(out, "{}", f.to_kb_line())?;
                }
            }
        }
    }
    Ok(ExitCode::SUCCESS)
}

fn to_query(translator: &Translator, text: &str) -> Result<(String, Option<String>)> {
    if logicrag::translate::looks_like_query(text) {
        Ok((text.to_string(), None))
    } else {
        let tr = translator
            .translate(text)
            .map_err(|e| anyhow::anyhow!("cannot translate the question: {e}"))?;
        Ok((tr.query.clone(), Some(text.to_string())))
    }
}

fn print_result(
    out: &mut impl Write,
    r: &AskResult,
    question: Option<&str>,
    json: bool,
    extra: Option<(usize,)>,
) -> Result<()> {
    if json {
        let mut v = serde_json::to_value(r)?;
        if let (Some(obj), Some((idx,))) = (v.as_object_mut(), extra) {
            obj.insert("query".into(), serde_json::json!(idx));
            obj.insert("query_text".into(), serde_json::json!(r.query));
        }
        if let (Some(obj), Some(q)) = (v.as_object_mut(), question) {
            obj.insert("question".into(), serde_json::json!(q));
        }
        writeln!(out, "{v}")?;
        return Ok(());
    }
    writeln!(
        out,
        "[{}] {} → {}{}",
        r.window,
        r.query,
        r.answer.as_str().to_uppercase(),
        logicrag::render::count_suffix(r)
    )?;
    for line in logicrag::render::detail_lines(r) {
        writeln!(out, "{line}")?;
    }
    Ok(())
}

fn cmd_ask(a: AskArgs) -> Result<ExitCode> {
    let pad = load_pad(&a.src.logicpad)?;
    let opts = if a.tsv {
        AskOptions::COUNT
    } else if a.no_proofs {
        AskOptions::BINDINGS
    } else {
        AskOptions::default()
    };
    let out = std::io::stdout();
    let mut out = std::io::BufWriter::new(out.lock());
    if let Some(qfile) = &a.queries {
        let text = std::fs::read_to_string(qfile)
            .with_context(|| format!("reading {}", qfile.display()))?;
        let file = qfile.display().to_string();
        let queries = parse_queries(&text, &file)?;
        let loaded = load_source(&a.src)?;
        let results = run_batch(&pad, loaded, &queries, &file, opts)?;
        for (q, r) in queries.iter().zip(&results) {
            if a.tsv {
                writeln!(
                    out,
                    "{}\t{}\t{}\t{}",
                    q.window,
                    q.index,
                    r.answer.as_str(),
                    r.count
                )?;
            } else if a.json {
                let mut v = serde_json::to_value(r)?;
                if let Some(obj) = v.as_object_mut() {
                    obj.insert("query".into(), serde_json::json!(q.index));
                    obj.insert("query_text".into(), serde_json::json!(q.query));
                }
                writeln!(out, "{v}")?;
            } else {
                print_result(&mut out, r, None, false, None)?;
            }
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(text) = &a.text else {
        bail!("give a question or query, or --queries FILE")
    };
    let translator = translator_for(&pad)?;
    let (query, question) = to_query(&translator, text)?;
    if let (false, Some(q)) = (a.json, &question) {
        writeln!(out, "question: {q}\nquery:    {query}")?;
    }
    let loaded = load_source(&a.src)?;
    let observed = loaded.observability.classify(&pad);
    for kb in window_kbs(loaded, &pad, a.window_id.as_deref())? {
        let r = ask(&pad, &kb, &observed, &query, opts);
        print_result(&mut out, &r, question.as_deref(), a.json, None)?;
    }
    Ok(ExitCode::SUCCESS)
}

fn cmd_translate(a: TranslateArgs) -> Result<ExitCode> {
    let translator = translator_for(&load_pad(&a.logicpad)?)?;
    if let Some(csv) = &a.csv {
        let input =
            std::fs::read_to_string(csv).with_context(|| format!("reading {}", csv.display()))?;
        let output = translator
            .translate_csv(&input)
            .map_err(|e| anyhow::anyhow!("{}: {e}", csv.display()))?;
        match &a.out {
            Some(p) => {
                std::fs::write(p, output).with_context(|| format!("writing {}", p.display()))?
            }
            None => outp!("{output}"),
        }
        return Ok(ExitCode::SUCCESS);
    }
    let Some(q) = &a.question else {
        bail!("give a question, or --csv FILE")
    };
    match translator.translate(q) {
        Ok(t) => {
            if a.json {
                outln!(
                    "{}",
                    serde_json::json!({"question": q, "query": t.query, "notes": t.notes})
                );
            } else {
                outln!("{}", t.query);
                for n in &t.notes {
                    eprintln!("note: {n}");
                }
            }
            Ok(ExitCode::SUCCESS)
        }
        Err(e) => {
            if a.json {
                outln!(
                    "{}",
                    serde_json::json!({"question": q, "error": e.to_string()})
                );
            } else {
                eprintln!("cannot translate: {e}");
            }
            Ok(ExitCode::from(2))
        }
    }
}

fn cmd_lint(a: LintArgs) -> Result<ExitCode> {
    let report = logicpad::lint_with(&a.file, a.strict);
    if a.json {
        let diags: Vec<_> = report
            .diagnostics
            .iter()
            .map(|d| {
                serde_json::json!({
                    "severity": if d.is_error() { "error" } else { "warning" },
                    "code": d.kind.code(), "line": d.line(), "column": d.column(), "message": d.message,
                })
            })
            .collect();
        outln!(
            "{}",
            serde_json::json!({"file": a.file.display().to_string(), "diagnostics": diags})
        );
    } else {
        outp!("{}", report.render());
    }
    Ok(ExitCode::from(report.exit_code() as u8))
}

mod cmd;
