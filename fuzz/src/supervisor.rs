//! The supervisor: runs each target's inputs in a worker child process
//! (this same binary, `worker` subcommand) under an address-space limit,
//! watches it for a per-input time limit, and turns every way an input can
//! fail into a report line and an artifact:
//!
//! - **panic**: caught in the worker (`catch_unwind`) and reported on its
//!   protocol; the worker goes on. A panic on input is a bug, so it counts.
//! - **abort**: the worker died (SIGABRT, SIGSEGV, a non-zero exit);
//! - **stack**: … and its stderr says it overflowed its stack;
//! - **memory**: … and its stderr says an allocation failed (the
//!   `prlimit --as` limit), or it was SIGKILLed by someone else (the
//!   kernel's OOM killer);
//! - **timeout**: no new input started within the time limit; the
//!   supervisor kills the worker.
//!
//! After a death the culprit is `current.input` in the worker's folder;
//! it is saved under `artifacts/<target>/` and a fresh worker goes on with
//! the next iteration, so the input stream is the one an uninterrupted
//! worker would have run ([`crate::rng::Rng::for_input`]).

use std::collections::VecDeque;
use std::io::{BufRead, BufReader, Read};
use std::os::unix::process::ExitStatusExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, Stdio};
use std::sync::mpsc::{self, RecvTimeoutError};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant, SystemTime};

use crate::FuzzError;
use crate::targets::Target;
use crate::worker::current_input_path;

/// How a supervised run is set up.
#[derive(Debug, Clone)]
pub struct Options {
    /// Total fuzzing time, split evenly across the targets; each target
    /// replays its seeds first, outside this time.
    pub seconds: f64,
    /// The targets, run one after the other.
    pub targets: Vec<&'static Target>,
    /// The run's seed.
    pub seed: u64,
    /// Longest time one input may take.
    pub timeout: Duration,
    /// Address-space limit of a worker, MiB (0: none).
    pub memory_mb: u64,
    /// The corpus root (`fuzz/corpus`).
    pub corpus_dir: PathBuf,
    /// Where failing inputs are saved (`fuzz/artifacts`).
    pub artifacts_dir: PathBuf,
    /// The workers' folders (current input, scratch files).
    pub work_dir: PathBuf,
    /// The executable that has the `worker` subcommand.
    pub worker_exe: PathBuf,
    /// Replay the seeds only, each once, ignoring `seconds`.
    pub replay: bool,
    /// Print a line per target to stderr as it finishes.
    pub progress: bool,
}

/// A way an input failed.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum FailureKind {
    /// A panic, caught.
    Panic,
    /// The process aborted or crashed.
    Abort,
    /// The process overflowed its stack.
    StackOverflow,
    /// An allocation failed under the memory limit, or the OOM killer struck.
    Memory,
    /// The input ran past the time limit.
    Timeout,
}

impl FailureKind {
    /// Short name, used in artifact names and the report.
    pub fn name(self) -> &'static str {
        match self {
            FailureKind::Panic => "panic",
            FailureKind::Abort => "abort",
            FailureKind::StackOverflow => "stack",
            FailureKind::Memory => "memory",
            FailureKind::Timeout => "timeout",
        }
    }
}

/// One failing input.
#[derive(Debug, Clone)]
pub struct Failure {
    /// How it failed.
    pub kind: FailureKind,
    /// Its iteration.
    pub iteration: u64,
    /// Where it came from (`mutation of NAME`, …).
    pub origin: String,
    /// The panic message or the end of the worker's stderr.
    pub message: String,
    /// The saved input, when it was saved (the first few of each kind).
    pub artifact: Option<PathBuf>,
}

/// One target's figures.
#[derive(Debug, Clone, Default)]
pub struct TargetReport {
    /// The target's name.
    pub name: String,
    /// Inputs started.
    pub inputs: u64,
    /// Seeds in its corpus.
    pub seeds: u64,
    /// Failing inputs.
    pub failures: Vec<Failure>,
    /// Workers started after the first.
    pub restarts: u64,
    /// Wall time, seconds.
    pub seconds: f64,
    /// The slowest input that finished: milliseconds, iteration, origin.
    pub slowest: Option<(u64, u64, String)>,
    /// Workers that stalled or died with no input running (a loaded
    /// machine, a broken harness): restarted, and reported, but no input's
    /// fault.
    pub stalls: Vec<String>,
    /// Set when the workers stalled [`MAX_STALLS`] times in a row and the
    /// target was given up: the run is then not clean.
    pub gave_up: Option<String>,
}

impl TargetReport {
    /// Failures of one kind.
    pub fn count(&self, kind: FailureKind) -> usize {
        self.failures.iter().filter(|f| f.kind == kind).count()
    }
}

/// The whole run.
#[derive(Debug, Clone)]
pub struct Report {
    /// Per target, in run order.
    pub targets: Vec<TargetReport>,
    /// The seed.
    pub seed: u64,
    /// Seconds asked for.
    pub seconds: f64,
    /// Per-input time limit.
    pub timeout: Duration,
    /// How memory was limited.
    pub memory: String,
    /// UTC start, ISO 8601.
    pub started: String,
    /// Wall time, seconds.
    pub wall_seconds: f64,
    /// Replay of the seeds only.
    pub replay: bool,
    /// Lines the caller adds to the header (command, commit).
    pub notes: Vec<String>,
}

impl Report {
    /// Failing inputs over all targets.
    pub fn failures(&self) -> usize {
        self.targets.iter().map(|t| t.failures.len()).sum()
    }

    /// Targets given up because their workers kept stalling.
    pub fn given_up(&self) -> usize {
        self.targets.iter().filter(|t| t.gave_up.is_some()).count()
    }

    /// True when no input failed and no target was given up.
    pub fn is_clean(&self) -> bool {
        self.failures() == 0 && self.given_up() == 0
    }

    /// Inputs over all targets.
    pub fn inputs(&self) -> u64 {
        self.targets.iter().map(|t| t.inputs).sum()
    }

    /// The report as text (the `--report` file).
    pub fn render(&self) -> String {
        use std::fmt::Write as _;
        let mut s = String::new();
        let _ = writeln!(s, "logicrag-fuzz report");
        for n in &self.notes {
            let _ = writeln!(s, "{n}");
        }
        let _ = writeln!(s, "started:  {} (UTC)", self.started);
        let mode = if self.replay {
            "replay of the seed corpus".to_string()
        } else {
            format!(
                "{} s over {} targets ({:.1} s each)",
                self.seconds,
                self.targets.len(),
                self.seconds / self.targets.len().max(1) as f64
            )
        };
        let _ = writeln!(s, "mode:     {mode}, seed {}", self.seed);
        let _ = writeln!(
            s,
            "limits:   {} ms per input; memory: {}",
            self.timeout.as_millis(),
            self.memory
        );
        let _ = writeln!(s);
        let _ = writeln!(
            s,
            "{:<14} {:>10} {:>6} {:>6} {:>6} {:>6} {:>7} {:>8} {:>9} {:>11} {:>8}",
            "target",
            "inputs",
            "seeds",
            "panic",
            "abort",
            "stack",
            "memory",
            "timeout",
            "restarts",
            "slowest ms",
            "seconds"
        );
        for t in &self.targets {
            let _ = writeln!(
                s,
                "{:<14} {:>10} {:>6} {:>6} {:>6} {:>6} {:>7} {:>8} {:>9} {:>11} {:>8.1}",
                t.name,
                t.inputs,
                t.seeds,
                t.count(FailureKind::Panic),
                t.count(FailureKind::Abort),
                t.count(FailureKind::StackOverflow),
                t.count(FailureKind::Memory),
                t.count(FailureKind::Timeout),
                t.restarts,
                t.slowest
                    .as_ref()
                    .map_or("-".to_string(), |(ms, _, _)| ms.to_string()),
                t.seconds
            );
        }
        let _ = writeln!(
            s,
            "{:<14} {:>10} {:>6} {:>6} {:>6} {:>6} {:>7} {:>8}",
            "total",
            self.inputs(),
            self.targets.iter().map(|t| t.seeds).sum::<u64>(),
            self.targets
                .iter()
                .map(|t| t.count(FailureKind::Panic))
                .sum::<usize>(),
            self.targets
                .iter()
                .map(|t| t.count(FailureKind::Abort))
                .sum::<usize>(),
            self.targets
                .iter()
                .map(|t| t.count(FailureKind::StackOverflow))
                .sum::<usize>(),
            self.targets
                .iter()
                .map(|t| t.count(FailureKind::Memory))
                .sum::<usize>(),
            self.targets
                .iter()
                .map(|t| t.count(FailureKind::Timeout))
                .sum::<usize>(),
        );
        let _ = writeln!(s);
        let _ = writeln!(s, "wall time: {:.1} s", self.wall_seconds);
        let _ = writeln!(s, "slowest input of each target (regenerate with `input`):");
        for t in &self.targets {
            if let Some((ms, i, origin)) = &t.slowest {
                let _ = writeln!(s, "  {:<14} {ms:>6} ms  iteration {i} ({origin})", t.name);
            }
        }
        let _ = writeln!(s, "failures:  {}", self.failures());
        for t in &self.targets {
            for st in &t.stalls {
                let _ = writeln!(
                    s,
                    "  {} worker stalled (restarted, no input's fault): {st}",
                    t.name
                );
            }
            if let Some(why) = &t.gave_up {
                let _ = writeln!(s, "  {} GIVEN UP: {why}", t.name);
            }
        }
        for t in &self.targets {
            for f in t.failures.iter().take(10) {
                let _ = writeln!(
                    s,
                    "  {} {} at iteration {} ({}): {}{}",
                    t.name,
                    f.kind.name(),
                    f.iteration,
                    f.origin,
                    excerpt(&f.message, 300),
                    f.artifact
                        .as_ref()
                        .map(|p| format!(" [{}]", p.display()))
                        .unwrap_or_default()
                );
            }
            if t.failures.len() > 10 {
                let _ = writeln!(s, "  {} … and {} more", t.name, t.failures.len() - 10);
            }
        }
        s
    }
}

fn excerpt(s: &str, max: usize) -> String {
    let one_line = s.replace('\n', " | ");
    if one_line.chars().count() <= max {
        one_line
    } else {
        format!("{}…", one_line.chars().take(max).collect::<String>())
    }
}

/// How the workers' memory is limited: `prlimit --as` from util-linux when
/// it is installed (the Rust standard library cannot set rlimits without
/// `unsafe`).
fn memory_limiter(mb: u64) -> Option<PathBuf> {
    if mb == 0 {
        return None;
    }
    let ok = Command::new("prlimit")
        .arg("--version")
        .stdout(Stdio::null())
        .stderr(Stdio::null())
        .status()
        .is_ok_and(|s| s.success());
    ok.then(|| PathBuf::from("prlimit"))
}

/// `YYYY-MM-DDTHH:MM:SSZ` of a time (the proleptic Gregorian calendar,
/// Howard Hinnant's `civil_from_days`).
pub fn iso8601(t: SystemTime) -> String {
    let secs = t
        .duration_since(SystemTime::UNIX_EPOCH)
        .map_or(0, |d| d.as_secs()) as i64;
    let days = secs.div_euclid(86_400);
    let rem = secs.rem_euclid(86_400);
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z.rem_euclid(146_097);
    let yoe = (doe - doe / 1460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02}T{:02}:{:02}:{:02}Z",
        rem / 3600,
        rem % 3600 / 60,
        rem % 60
    )
}

/// Runs every target of `opts` under supervision.
pub fn run(opts: &Options) -> Result<Report, FuzzError> {
    let started = SystemTime::now();
    let t0 = Instant::now();
    let limiter = memory_limiter(opts.memory_mb);
    let memory = match (&limiter, opts.memory_mb) {
        (_, 0) => "not limited (--memory-mb 0)".to_string(),
        (Some(_), mb) => format!("{mb} MiB of address space per worker (prlimit --as)"),
        (None, mb) => format!("NOT limited: prlimit (util-linux) not found, {mb} MiB asked"),
    };
    let share = opts.seconds / opts.targets.len().max(1) as f64;
    let mut reports = Vec::new();
    for target in &opts.targets {
        let r = run_target(opts, target, share, limiter.as_deref())?;
        if opts.progress {
            eprintln!(
                "logicrag-fuzz: {:<14} {:>9} inputs, {} failure(s), {:.1} s",
                r.name,
                r.inputs,
                r.failures.len(),
                r.seconds
            );
        }
        reports.push(r);
    }
    Ok(Report {
        targets: reports,
        seed: opts.seed,
        seconds: opts.seconds,
        timeout: opts.timeout,
        memory,
        started: iso8601(started),
        wall_seconds: t0.elapsed().as_secs_f64(),
        replay: opts.replay,
        notes: Vec::new(),
    })
}

/// The last 64 KiB a worker wrote to stderr.
type Tail = Arc<Mutex<VecDeque<u8>>>;
const STDERR_TAIL: usize = 64 * 1024;

enum Event {
    Line(String),
    Eof,
}

/// The startup of a worker (loading the corpus, simulating the shared
/// window) is not an input: it gets this long, or the input limit if longer.
const STARTUP_LIMIT: Duration = Duration::from_secs(120);

/// Workers of one target that may stall in a row (die or go silent with no
/// input running) before the target is given up.
pub const MAX_STALLS: usize = 3;

/// Failing inputs of one kind saved per target; the rest are only counted.
const MAX_ARTIFACTS_PER_KIND: usize = 20;

struct Worker {
    child: Child,
    events: mpsc::Receiver<Event>,
    stderr: Tail,
}

fn spawn(
    opts: &Options,
    target: &Target,
    limiter: Option<&Path>,
    work: &Path,
    from: u64,
    budget: Duration,
) -> Result<Worker, FuzzError> {
    let mut cmd = match limiter {
        Some(p) => {
            let mut c = Command::new(p);
            c.arg(format!(
                "--as={}",
                opts.memory_mb.saturating_mul(1024 * 1024)
            ))
            .arg("--")
            .arg(&opts.worker_exe);
            c
        }
        None => Command::new(&opts.worker_exe),
    };
    cmd.arg("worker")
        .arg("--target")
        .arg(target.name)
        .arg("--seed")
        .arg(opts.seed.to_string())
        .arg("--from")
        .arg(from.to_string())
        .arg("--budget-ms")
        .arg(budget.as_millis().to_string())
        .arg("--corpus")
        .arg(&opts.corpus_dir)
        .arg("--work-dir")
        .arg(work);
    if opts.replay {
        cmd.arg("--replay");
    }
    // Backtraces would slow every panic and say nothing the artifact does not.
    cmd.env("RUST_BACKTRACE", "0")
        .stdin(Stdio::null())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped());
    let mut child = cmd.spawn().map_err(|source| FuzzError::Spawn {
        exe: opts.worker_exe.clone(),
        source,
    })?;
    let (tx, rx) = mpsc::channel();
    if let Some(out) = child.stdout.take() {
        std::thread::spawn(move || {
            for line in BufReader::new(out).lines() {
                match line {
                    Ok(l) => {
                        if tx.send(Event::Line(l)).is_err() {
                            return;
                        }
                    }
                    Err(_) => break,
                }
            }
            let _ = tx.send(Event::Eof);
        });
    }
    let tail: Tail = Arc::new(Mutex::new(VecDeque::new()));
    if let Some(mut err) = child.stderr.take() {
        let tail = Arc::clone(&tail);
        std::thread::spawn(move || {
            let mut buf = [0u8; 8192];
            while let Ok(n) = err.read(&mut buf) {
                if n == 0 {
                    break;
                }
                if let Ok(mut t) = tail.lock() {
                    t.extend(&buf[..n]);
                    let excess = t.len().saturating_sub(STDERR_TAIL);
                    t.drain(..excess);
                }
            }
        });
    }
    Ok(Worker {
        child,
        events: rx,
        stderr: tail,
    })
}

fn stderr_text(tail: &Tail) -> String {
    tail.lock()
        .map(|t| {
            let (a, b) = t.as_slices();
            let mut bytes = a.to_vec();
            bytes.extend_from_slice(b);
            String::from_utf8_lossy(&bytes).into_owned()
        })
        .unwrap_or_default()
}

/// What a dead worker's status and stderr say about how it died.
fn classify(status: std::process::ExitStatus, stderr: &str) -> FailureKind {
    if stderr.contains("has overflowed its stack") {
        FailureKind::StackOverflow
    } else if stderr.contains("memory allocation of")
        || stderr.contains("out of memory")
        || stderr.contains("Cannot allocate memory")
        || status.signal() == Some(9)
    {
        FailureKind::Memory
    } else {
        FailureKind::Abort
    }
}

struct Current {
    iteration: u64,
    origin: String,
    started: Instant,
}

fn run_target(
    opts: &Options,
    target: &Target,
    share: f64,
    limiter: Option<&Path>,
) -> Result<TargetReport, FuzzError> {
    let t0 = Instant::now();
    let share = Duration::from_secs_f64(share.max(0.0));
    // Set when the first input past the seeds starts: the seeds always run
    // whole, and the share is fuzzing time after them.
    let mut deadline: Option<Instant> = None;
    let work = opts.work_dir.join(target.name);
    std::fs::create_dir_all(&work).map_err(|source| FuzzError::Io {
        path: work.clone(),
        source,
    })?;
    let artifacts = opts.artifacts_dir.join(target.name);
    let mut report = TargetReport {
        name: target.name.to_string(),
        ..TargetReport::default()
    };
    let mut next = 0u64;
    let mut started_workers = 0u64;
    let mut stalls_in_a_row = 0usize;
    'workers: loop {
        if stalls_in_a_row >= MAX_STALLS {
            report.gave_up = Some(format!(
                "{MAX_STALLS} workers in a row stalled with no input running; last: {}",
                report.stalls.last().map_or("", String::as_str)
            ));
            break;
        }
        let budget = deadline.map_or(share, |d| d.saturating_duration_since(Instant::now()));
        if !opts.replay && budget.is_zero() && started_workers > 0 {
            break;
        }
        let mut w = spawn(opts, target, limiter, &work, next, budget)?;
        started_workers += 1;
        let mut current: Option<Current> = None;
        let mut last_event = Instant::now();
        let mut ready = false;
        let mut finished = false;
        loop {
            let limit = if ready {
                opts.timeout
            } else {
                opts.timeout.max(STARTUP_LIMIT)
            };
            let wait = limit.saturating_sub(last_event.elapsed());
            match w.events.recv_timeout(wait) {
                Ok(Event::Line(line)) => {
                    let now = Instant::now();
                    last_event = now;
                    let (word, rest) = line.split_once(' ').unwrap_or((line.as_str(), ""));
                    match word {
                        "ready" => {
                            ready = true;
                            report.seeds = rest.trim().parse().unwrap_or(0);
                        }
                        "run" => {
                            stalls_in_a_row = 0;
                            finish_input(&mut report, current.take(), now);
                            let mut parts = rest.splitn(3, ' ');
                            let iteration = parts.next().and_then(|s| s.parse().ok()).unwrap_or(0);
                            let _len = parts.next();
                            let origin = parts.next().unwrap_or("").to_string();
                            if deadline.is_none() && iteration >= report.seeds {
                                deadline = Some(now + share);
                            }
                            current = Some(Current {
                                iteration,
                                origin,
                                started: now,
                            });
                            report.inputs += 1;
                        }
                        "panic" => {
                            let (i, message) = rest.split_once(' ').unwrap_or((rest, ""));
                            let iteration: u64 = i.parse().unwrap_or(0);
                            let origin = current
                                .as_ref()
                                .map(|c| c.origin.clone())
                                .unwrap_or_default();
                            let copy = work.join(format!("panic-{iteration}.input"));
                            let artifact = save_artifact(
                                &report,
                                &artifacts,
                                FailureKind::Panic,
                                opts.seed,
                                iteration,
                                &copy,
                                target.name,
                                &origin,
                                message,
                            );
                            let _ = std::fs::remove_file(&copy);
                            report.failures.push(Failure {
                                kind: FailureKind::Panic,
                                iteration,
                                origin,
                                message: message.to_string(),
                                artifact,
                            });
                        }
                        "done" => finish_input(&mut report, current.take(), now),
                        "end" => {
                            finish_input(&mut report, current.take(), now);
                            finished = true;
                        }
                        _ => {}
                    }
                }
                Ok(Event::Eof) | Err(RecvTimeoutError::Disconnected) => {
                    let status = w.child.wait().map_err(|source| FuzzError::Spawn {
                        exe: opts.worker_exe.clone(),
                        source,
                    })?;
                    let stderr = stderr_text(&w.stderr);
                    if finished {
                        if !status.success() {
                            report.stalls.push(format!(
                                "the worker exited ({status}) after its last input: {}",
                                excerpt(stderr.trim(), 2000)
                            ));
                        }
                        break 'workers;
                    }
                    let Some(c) = current.take() else {
                        report.stalls.push(format!(
                            "the worker exited ({status}) with no input running: {}",
                            excerpt(stderr.trim(), 2000)
                        ));
                        stalls_in_a_row += 1;
                        continue 'workers;
                    };
                    let kind = classify(status, &stderr);
                    let message = format!("{status}; stderr: {}", excerpt(stderr.trim(), 1500));
                    record_death(
                        &mut report,
                        opts,
                        target,
                        &work,
                        &artifacts,
                        kind,
                        c.iteration,
                        &c.origin,
                        &message,
                    );
                    next = c.iteration + 1;
                    report.restarts += 1;
                    continue 'workers;
                }
                Err(RecvTimeoutError::Timeout) => {
                    let _ = w.child.kill();
                    let _ = w.child.wait();
                    if finished {
                        // Every input ran; only the exit was slow.
                        break 'workers;
                    }
                    // Silent with no input running: the worker is stuck
                    // outside any target (starting, or making the next
                    // input), not in an input.
                    let Some(c) = current.take() else {
                        report.stalls.push(format!(
                            "silent for {} s {}: {}",
                            limit.as_secs(),
                            if ready {
                                "with no input running (making the next one)"
                            } else {
                                "while starting"
                            },
                            excerpt(stderr_text(&w.stderr).trim(), 2000)
                        ));
                        stalls_in_a_row += 1;
                        continue 'workers;
                    };
                    let message = format!(
                        "no result after {} ms (killed)",
                        c.started.elapsed().as_millis()
                    );
                    record_death(
                        &mut report,
                        opts,
                        target,
                        &work,
                        &artifacts,
                        FailureKind::Timeout,
                        c.iteration,
                        &c.origin,
                        &message,
                    );
                    next = c.iteration + 1;
                    report.restarts += 1;
                    continue 'workers;
                }
            }
        }
    }
    report.seconds = t0.elapsed().as_secs_f64();
    Ok(report)
}

fn finish_input(report: &mut TargetReport, c: Option<Current>, now: Instant) {
    if let Some(c) = c {
        let ms = now.duration_since(c.started).as_millis() as u64;
        if report
            .slowest
            .as_ref()
            .is_none_or(|(best, _, _)| ms > *best)
        {
            report.slowest = Some((ms, c.iteration, c.origin));
        }
    }
}

#[allow(clippy::too_many_arguments)]
fn record_death(
    report: &mut TargetReport,
    opts: &Options,
    target: &Target,
    work: &Path,
    artifacts: &Path,
    kind: FailureKind,
    iteration: u64,
    origin: &str,
    message: &str,
) {
    let artifact = save_artifact(
        report,
        artifacts,
        kind,
        opts.seed,
        iteration,
        &current_input_path(work),
        target.name,
        origin,
        message,
    );
    report.failures.push(Failure {
        kind,
        iteration,
        origin: origin.to_string(),
        message: message.to_string(),
        artifact,
    });
}

/// Copies a failing input to `artifacts/<target>/<kind>-seed<S>-iter<I>.input`
/// with a `.txt` beside it saying what happened and how to replay it.
#[allow(clippy::too_many_arguments)]
fn save_artifact(
    report: &TargetReport,
    dir: &Path,
    kind: FailureKind,
    seed: u64,
    iteration: u64,
    from: &Path,
    target: &str,
    origin: &str,
    message: &str,
) -> Option<PathBuf> {
    if report.count(kind) >= MAX_ARTIFACTS_PER_KIND {
        return None;
    }
    std::fs::create_dir_all(dir).ok()?;
    let base = format!("{}-seed{seed}-iter{iteration}", kind.name());
    let path = dir.join(format!("{base}.input"));
    std::fs::copy(from, &path).ok()?;
    let note = format!(
        "target: {target}\nkind: {}\nseed: {seed}\niteration: {iteration}\norigin: {origin}\n\
         replay: cargo run --release -p logicrag-fuzz -- replay --target {target} {}\n\
         regenerate: cargo run --release -p logicrag-fuzz -- input --target {target} --seed {seed} --iteration {iteration} > input\n\
         \n{message}\n",
        kind.name(),
        path.display()
    );
    std::fs::write(dir.join(format!("{base}.txt")), note).ok()?;
    Some(path)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dates_are_utc_iso() {
        assert_eq!(iso8601(SystemTime::UNIX_EPOCH), "1970-01-01T00:00:00Z");
        let t = SystemTime::UNIX_EPOCH + Duration::from_secs(951_782_400 + 3661);
        assert_eq!(iso8601(t), "2000-02-29T01:01:01Z");
    }

    #[test]
    fn deaths_are_classified_by_what_the_worker_said() {
        let abort = std::process::ExitStatus::from_raw(6);
        assert_eq!(
            classify(
                abort,
                "thread 'main' has overflowed its stack\nfatal runtime error: stack overflow"
            ),
            FailureKind::StackOverflow
        );
        assert_eq!(
            classify(abort, "memory allocation of 8589934592 bytes failed\n"),
            FailureKind::Memory
        );
        assert_eq!(classify(abort, ""), FailureKind::Abort);
        assert_eq!(
            classify(std::process::ExitStatus::from_raw(9), ""),
            FailureKind::Memory
        );
    }
}
