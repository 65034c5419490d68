//! `logicrag-fuzz`: the supervisor (default), a worker (internal), and
//! tools to list targets, replay an artifact and regenerate an input.
#![forbid(unsafe_code)]

use std::path::PathBuf;
use std::process::ExitCode;
use std::time::Duration;

use anyhow::{Context, Result, bail};
use clap::{Args, Parser, Subcommand};
use logicrag_fuzz::supervisor::{self, Options};
use logicrag_fuzz::{corpus, select_targets, targets, worker};

/// Fuzzes every logicrag parser on stable Rust: seed corpus, mutations and
/// proptest generators, each target in a supervised worker process.
#[derive(Parser, Debug)]
#[command(name = "logicrag-fuzz", version)]
struct Cli {
    #[command(subcommand)]
    command: Option<Cmd>,
    #[command(flatten)]
    run: RunArgs,
}

#[derive(Args, Debug)]
struct RunArgs {
    /// Total fuzzing time in seconds, split evenly across the targets (each
    /// replays its seeds first, outside this time).
    #[arg(long, default_value_t = 60.0)]
    seconds: f64,
    /// Comma-separated targets (default: all; see `list`).
    #[arg(long, default_value = "")]
    targets: String,
    /// Seed of every random choice: the same seed runs the same inputs.
    #[arg(long, default_value_t = 1)]
    seed: u64,
    /// Longest time one input may take before it counts as a hang.
    #[arg(long, default_value_t = 10_000)]
    timeout_ms: u64,
    /// Address-space limit of a worker in MiB (0: none).
    #[arg(long, default_value_t = 3072)]
    memory_mb: u64,
    /// Also write the report to this file.
    #[arg(long)]
    report: Option<PathBuf>,
    /// Replay every seed once instead of fuzzing (ignores --seconds).
    #[arg(long)]
    replay_corpus: bool,
    /// The seed corpus (default: this crate's `corpus/`).
    #[arg(long)]
    corpus: Option<PathBuf>,
    /// Where failing inputs are saved (default: `fuzz/artifacts`).
    #[arg(long)]
    artifacts: Option<PathBuf>,
    /// The workers' folder (default: `target/fuzz-work`).
    #[arg(long)]
    work_dir: Option<PathBuf>,
}

#[derive(Subcommand, Debug)]
enum Cmd {
    /// Lists the targets.
    List,
    /// Runs saved inputs through a target in this process and says how each ends.
    Replay {
        /// The target.
        #[arg(long)]
        target: String,
        /// Input files (artifacts).
        files: Vec<PathBuf>,
    },
    /// Writes input ITERATION of a run with SEED to stdout.
    Input {
        /// The target.
        #[arg(long)]
        target: String,
        /// The run's seed.
        #[arg(long, default_value_t = 1)]
        seed: u64,
        /// The iteration.
        #[arg(long)]
        iteration: u64,
        /// The seed corpus.
        #[arg(long)]
        corpus: Option<PathBuf>,
    },
    /// Internal: the supervised worker process.
    #[command(hide = true)]
    Worker {
        #[arg(long)]
        target: String,
        #[arg(long)]
        seed: u64,
        #[arg(long)]
        from: u64,
        #[arg(long)]
        budget_ms: u64,
        #[arg(long)]
        corpus: PathBuf,
        #[arg(long)]
        work_dir: PathBuf,
        #[arg(long)]
        replay: bool,
    },
}

fn crate_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

fn target(name: &str) -> Result<&'static targets::Target> {
    select_targets(name)?
        .into_iter()
        .next()
        .context("no target named")
}

/// The checked-out commit, for the report; best effort.
fn commit() -> String {
    let git = |args: &[&str]| {
        std::process::Command::new("git")
            .args(args)
            .current_dir(crate_dir())
            .output()
            .ok()
            .filter(|o| o.status.success())
            .map(|o| String::from_utf8_lossy(&o.stdout).trim().to_string())
    };
    match git(&["rev-parse", "--short", "HEAD"]) {
        Some(c) => {
            let dirty = git(&["status", "--porcelain"]).is_some_and(|s| !s.is_empty());
            if dirty {
                format!("{c} (with uncommitted changes)")
            } else {
                c
            }
        }
        None => "unknown".into(),
    }
}

fn main() -> Result<ExitCode> {
    let cli = Cli::parse();
    match cli.command {
        Some(Cmd::List) => {
            for t in targets::ALL {
                println!(
                    "{:<14} {}",
                    t.name,
                    t.about.split_whitespace().collect::<Vec<_>>().join(" ")
                );
            }
            Ok(ExitCode::SUCCESS)
        }
        Some(Cmd::Replay {
            target: name,
            files,
        }) => {
            let t = target(&name)?;
            if files.is_empty() {
                bail!("name at least one input file");
            }
            let mut failed = false;
            for f in files {
                let bytes =
                    std::fs::read(&f).with_context(|| format!("reading {}", f.display()))?;
                let start = std::time::Instant::now();
                let r = std::panic::catch_unwind(|| (t.run)(&bytes));
                let ms = start.elapsed().as_millis();
                match r {
                    Ok(()) => println!("{}: ok ({ms} ms)", f.display()),
                    Err(_) => {
                        failed = true;
                        println!("{}: PANIC ({ms} ms)", f.display());
                    }
                }
            }
            Ok(if failed {
                ExitCode::FAILURE
            } else {
                ExitCode::SUCCESS
            })
        }
        Some(Cmd::Input {
            target: name,
            seed,
            iteration,
            corpus: dir,
        }) => {
            let t = target(&name)?;
            let seeds = corpus::load(&dir.unwrap_or_else(corpus::default_dir), t)?;
            let input = worker::input_for(t, &seeds, seed, iteration);
            eprintln!("{}", input.origin);
            use std::io::Write;
            std::io::stdout().write_all(&input.bytes)?;
            Ok(ExitCode::SUCCESS)
        }
        Some(Cmd::Worker {
            target: name,
            seed,
            from,
            budget_ms,
            corpus,
            work_dir,
            replay,
        }) => {
            let args = worker::WorkerArgs {
                target: target(&name)?,
                seed,
                from,
                budget: Duration::from_millis(budget_ms),
                replay,
                corpus_dir: corpus,
                work_dir,
            };
            let stdout = std::io::stdout();
            worker::run(&args, &mut stdout.lock())?;
            Ok(ExitCode::SUCCESS)
        }
        None => {
            let a = cli.run;
            if !(a.seconds.is_finite() && a.seconds >= 0.0) {
                bail!("--seconds must be a non-negative number, got {}", a.seconds);
            }
            // Before the run: the tree may change while it runs.
            let commit = commit();
            let root = crate_dir();
            let opts = Options {
                seconds: a.seconds,
                targets: select_targets(&a.targets)?,
                seed: a.seed,
                timeout: Duration::from_millis(a.timeout_ms),
                memory_mb: a.memory_mb,
                corpus_dir: a.corpus.unwrap_or_else(corpus::default_dir),
                artifacts_dir: a.artifacts.unwrap_or_else(|| root.join("artifacts")),
                work_dir: a
                    .work_dir
                    .unwrap_or_else(|| root.join("../target/fuzz-work")),
                worker_exe: std::env::current_exe().context("finding this executable")?,
                replay: a.replay_corpus,
                progress: true,
            };
            let mut report = supervisor::run(&opts)?;
            report.notes.push(format!(
                "command:  {}",
                std::env::args().collect::<Vec<_>>().join(" ")
            ));
            report
                .notes
                .push(format!("commit:   {commit} (at the start)"));
            let text = report.render();
            print!("{text}");
            if let Some(p) = a.report {
                std::fs::write(&p, &text).with_context(|| format!("writing {}", p.display()))?;
            }
            Ok(if report.is_clean() {
                ExitCode::SUCCESS
            } else {
                ExitCode::FAILURE
            })
        }
    }
}
