//! The subcommands, one file each; what they share lives here: the source
//! flags ([`SourceArgs`]), loading the engine and the source, and picking
//! windows. Adding a subcommand is adding a file with an `Args` struct and
//! a `run` function, and one line in [`Command`] and [`run`].

use anyhow::{Result, bail};
use clap::{Args, Parser, Subcommand};
use logicrag::engine::TranslatorMode;
use logicrag::pipeline::{OpenOptions, PadChoice, Pipeline};
use logicrag::session::SourceOptions;
use logicrag::source::SourceSpec;
use std::path::PathBuf;
use std::process::ExitCode;

pub mod ask;
pub mod context;
pub mod demo;
pub mod eval;
pub mod facts;
pub mod lint;
pub mod perceive;
#[cfg(feature = "plot")]
pub mod plot;
pub mod repl;
pub mod rule;
#[cfg(feature = "serve")]
pub mod serve;
pub mod simulate;
pub mod translate;

#[derive(Parser)]
#[command(
    name = "logicrag",
    version,
    about = "Ask questions about driving video and get proved answers"
)]
pub struct Cli {
    #[command(subcommand)]
    command: Command,
}

#[derive(Subcommand)]
enum Command {
    /// Run built-in simulator scenarios end to end: KBs, questions, answers, scores.
    Demo(demo::DemoArgs),
    /// Run a simulator scenario and print or write its tracks, events and facts.
    Simulate(simulate::SimulateArgs),
    /// Print the facts of a source's windows (text KB or JSON with provenance).
    Facts(facts::FactsArgs),
    /// Ask a question or a query on a source's windows.
    Ask(ask::AskArgs),
    /// Translate a question (or a CSV of questions) into a query.
    Translate(translate::TranslateArgs),
    /// Print the retrieval context (C2 inference result, C3 fact sentences) for a question.
    Context(context::ContextArgs),
    /// Check a LogicPad file and print all diagnostics (exit 0 clean, 1 warnings, 2 errors).
    Lint(lint::LintArgs),
    /// Compose a rule, in FOL or as an English definition: check it against a LogicPad, and append it.
    Rule(rule::RuleArgs),
    /// Evaluate a question set with expected answers.
    Eval(eval::EvalArgs),
    /// Interactive session over a source's windows.
    Repl(repl::ReplArgs),
    /// Run perception on a source (raw frames with --models) and write its tracks as JSON.
    Perceive(perceive::PerceiveArgs),
    /// Serve a web page, a JSON API, a LangChain-style retriever and an OpenAI-compatible Logic-RAG proxy.
    #[cfg(feature = "serve")]
    Serve(serve::ServeArgs),
    /// Draw a window's bird's-eye view or an evaluation's scores (PNG or SVG).
    #[cfg(feature = "plot")]
    Plot(plot::PlotArgs),
}

/// Runs the parsed command line.
pub fn run(cli: Cli) -> Result<ExitCode> {
    match cli.command {
        Command::Demo(a) => demo::run(a),
        Command::Simulate(a) => simulate::run(a),
        Command::Facts(a) => facts::run(a),
        Command::Ask(a) => ask::run(a),
        Command::Translate(a) => translate::run(a),
        Command::Context(a) => context::run(a),
        Command::Lint(a) => lint::run(a),
        Command::Rule(a) => rule::run(a),
        Command::Eval(a) => eval::run(a),
        Command::Repl(a) => repl::run(a),
        Command::Perceive(a) => perceive::run(a),
        #[cfg(feature = "serve")]
        Command::Serve(a) => serve::run(a),
        #[cfg(feature = "plot")]
        Command::Plot(a) => plot::run(a),
    }
}

#[derive(Args, Clone)]
pub struct SourceArgs {
    /// Where windows come from: sim:SCENARIO[@SEED], kitti:DIR, json:FILE, av2:DIR (an Argoverse 2 log), facts:PATH, frames:DIR (with --models).
    #[arg(long, default_value = "sim:urban_crossing")]
    pub source: SourceSpec,
    /// KITTI (or multi-sequence JSON) sequence, e.g. 0000.
    #[arg(long)]
    pub sequence: Option<String>,
    /// Frames per window (default: 10).
    #[arg(long)]
    pub window: Option<u32>,
    /// Frames between window starts (default: the window size, no overlap).
    #[arg(long)]
    pub stride: Option<u32>,
    /// One inclusive frame range instead of sliding windows, e.g. 0-9.
    #[arg(long, conflicts_with_all = ["window", "stride"])]
    pub frames: Option<String>,
    /// Perception thresholds (YAML or JSON FactConfig).
    #[arg(long)]
    pub config: Option<PathBuf>,
    /// LogicPad rules (default: the built-in LogicPad).
    #[arg(long)]
    pub logicpad: Option<PathBuf>,
    /// Model set YAML for `frames:DIR` sources (detector, optional depth and flow).
    #[arg(long)]
    pub models: Option<PathBuf>,
    /// Camera calibration for `frames:DIR`: a KITTI calib file (its `P2:`
    /// line) or YAML with fx, fy, cx, cy (pixels) and height_m (metres above
    /// the road). Without it: fx = fy = image width, centred, 1.65 m — depths
    /// are then only roughly metric.
    #[arg(long)]
    pub camera: Option<PathBuf>,
    /// Frame rate of `frames:DIR` frames, per second (default: 10, KITTI's).
    #[arg(long)]
    pub fps: Option<f64>,
    /// Simulator noise level replacing a sim: scenario's own (none, low,
    /// default, high, mono; NAME*K scales the preset's sigmas by K, as
    /// high*2); `eval` takes several, comma-separated, and runs each in
    /// turn.
    #[arg(long, value_delimiter = ',')]
    pub noise: Vec<perception::sim::NoiseLevel>,
}

impl SourceArgs {
    /// The flags as the library's source options.
    pub fn options(&self) -> SourceOptions {
        SourceOptions {
            sequence: self.sequence.clone(),
            window: self.window,
            stride: self.stride,
            frames: self.frames.clone(),
            config: self.config.clone(),
            models: self.models.clone(),
            camera: self.camera.clone(),
            fps: self.fps,
            noise: self.noise.first().copied(),
        }
    }

    /// The options to open a pipeline with: the source flags and
    /// `--logicpad`, questions translated by `translator` (`None`: the
    /// grammar).
    pub fn open_options(
        &self,
        translator: Option<std::sync::Arc<dyn logicrag::engine::Translate>>,
    ) -> OpenOptions {
        OpenOptions {
            source: self.options(),
            logicpad: PadChoice::from_flag(self.logicpad.clone()),
            translator,
            keep_scene: false,
        }
    }

    /// Opens the source the flags name ([`open`]).
    pub fn open(
        &self,
        translator: Option<std::sync::Arc<dyn logicrag::engine::Translate>>,
    ) -> Result<Pipeline> {
        open(self.spec()?, &self.open_options(translator))
    }

    /// The source with the options of its kind; a flag its kind would
    /// ignore is an error naming the flag.
    pub fn spec(&self) -> Result<SourceSpec> {
        if self.noise.len() > 1 {
            anyhow::bail!(
                "--noise takes one level here ({} given); `eval --noise` runs several in turn",
                self.noise.len()
            );
        }
        Ok(self.options().spec(self.source.clone())?)
    }
}

/// The LLM/LMM flags shared by `ask`, `translate`, `eval` and `repl`.
#[derive(Args, Clone)]
pub struct LlmArgs {
    /// OpenAI-compatible server, e.g. http://127.0.0.1:8080/v1 (default: $LOGICRAG_LLM_URL).
    #[arg(long)]
    pub llm: Option<String>,
    /// Model name (default: $LOGICRAG_LLM_MODEL). The key comes from
    /// $LOGICRAG_API_KEY or $OPENAI_API_KEY and is never printed.
    #[arg(long = "llm-model")]
    pub llm_model: Option<String>,
    /// Question → query: the grammar, an LLM, or the grammar then the LLM.
    #[arg(long, value_enum, default_value = "grammar")]
    pub translator: TranslatorMode,
    /// Repair rounds for an LLM query the LogicPad rejects.
    #[arg(long = "llm-repairs", default_value_t = 2)]
    pub llm_repairs: u32,
    /// Frames sent to the LMM per window, sampled evenly.
    #[arg(long = "lmm-frames", default_value_t = 5)]
    pub lmm_frames: usize,
    /// Response cache directory (default: ~/.cache/logicrag/lmm).
    #[arg(long = "lmm-cache")]
    pub lmm_cache: Option<PathBuf>,
    /// Send every request, keep no replies.
    #[arg(long = "no-lmm-cache", conflicts_with = "lmm_cache")]
    pub no_lmm_cache: bool,
    /// Prompt template for the --lmm condition (placeholders {question},
    /// {frame_count}, {inference}, {facts}).
    #[arg(long)]
    pub prompt: Option<PathBuf>,
}

impl LlmArgs {
    /// The chat server with its cache; an error when no server is named.
    pub fn chat(&self) -> Result<logicrag::llm::Chat> {
        let config = logicrag::llm::client::LlmConfig::from_flags(
            self.llm.as_deref(),
            self.llm_model.as_deref(),
        )?;
        let cache = if self.no_lmm_cache {
            None
        } else {
            Some(logicrag::llm::cache::Cache::new(
                self.lmm_cache
                    .clone()
                    .unwrap_or_else(logicrag::llm::cache::Cache::default_dir),
            ))
        };
        Ok(logicrag::llm::Chat {
            client: logicrag::llm::client::Client::new(config)?,
            cache,
        })
    }

    /// The prompt templates, with `--prompt` for `condition`.
    pub fn templates(
        &self,
        condition: Option<logicrag::llm::Condition>,
    ) -> Result<logicrag::llm::Templates> {
        let t = logicrag::llm::Templates::default();
        Ok(match (&self.prompt, condition) {
            (Some(p), Some(c)) => t.with_condition_file(c, p)?,
            (Some(_), None) => bail!("--prompt applies with --lmm c1|c2|c3"),
            (None, _) => t,
        })
    }

    /// The translator `--translator` and `--llm` ask for.
    pub fn translator(&self) -> Result<std::sync::Arc<dyn logicrag::engine::Translate>> {
        Ok(logicrag::engine::translator(
            self.translator,
            self.llm_setup()?,
        )?)
    }

    /// The LLM translator's server, prompts and repairs: for `--translator
    /// llm` (an error without a server), and for `auto` when a server is
    /// named (without one, `auto` is the grammar alone).
    pub fn llm_setup(&self) -> Result<Option<logicrag::engine::LlmSetup>> {
        let named = self.llm.is_some() || std::env::var_os("LOGICRAG_LLM_URL").is_some();
        let needed = match self.translator {
            TranslatorMode::Grammar => false,
            TranslatorMode::Llm => true,
            TranslatorMode::Auto => named,
        };
        if !needed {
            return Ok(None);
        }
        Ok(Some(logicrag::engine::LlmSetup {
            chat: self.chat()?,
            templates: self.templates(None)?,
            repairs: self.llm_repairs,
        }))
    }
}

/// Opens the pipeline `spec` and `options` name: one library call
/// ([`Pipeline::open`]), with a progress bar for the frames pipeline and
/// the pipeline's notes on stderr (a LogicPad with rules left out, an
/// assumed camera, what the source skipped: said, never dropped unseen).
pub fn open(spec: SourceSpec, options: &OpenOptions) -> Result<Pipeline> {
    let pb = indicatif::ProgressBar::new(0);
    pb.set_style(
        indicatif::ProgressStyle::with_template("perceiving [{bar:30}] {pos}/{len} frames {msg}")
            .unwrap_or_else(|_| indicatif::ProgressStyle::default_bar()),
    );
    let mut progress = |p: logicrag::source::Progress| {
        pb.set_length(u64::from(p.total));
        pb.set_position(u64::from(p.done));
    };
    let pipeline = Pipeline::open(spec, options, &mut progress)?;
    pb.finish_and_clear();
    print_notes(&pipeline);
    Ok(pipeline)
}

/// A pipeline without a source over the LogicPad `--logicpad` names, for
/// the subcommands that only translate or compose rules.
pub fn sourceless(
    logicpad: &Option<PathBuf>,
    translator: Option<std::sync::Arc<dyn logicrag::engine::Translate>>,
) -> Result<Pipeline> {
    let pipeline = Pipeline::sourceless(&OpenOptions {
        logicpad: PadChoice::from_flag(logicpad.clone()),
        translator,
        ..OpenOptions::default()
    })?;
    print_notes(&pipeline);
    Ok(pipeline)
}

fn print_notes(pipeline: &Pipeline) {
    for note in pipeline.notes() {
        eprintln!("note: {note}");
    }
}
