//! The worker: runs one target's inputs in a child process, so that an
//! abort, a stack overflow or an allocation failure kills only it.
//!
//! Protocol (one line each on stdout): `ready <seeds>`, then per input
//! `run <iteration> <bytes> <origin>` (flushed before the input runs),
//! `panic <iteration> <message>` after a caught panic, `done <iteration>`
//! when it is over (so that making the next input is never charged to
//! it), and `end <count>`
//! when the time budget (counted after the seeds) or, replaying, the
//! corpus is used up. Before
//! each input the worker writes it to `<work>/current.input`: when the
//! process dies, that file is the culprit. A panicking input is copied to
//! `<work>/panic-<iteration>.input` before the worker goes on, since the
//! next input overwrites `current.input` before the supervisor reads the
//! `panic` line.

use std::io::Write;
use std::os::unix::fs::FileExt;
use std::panic::{AssertUnwindSafe, catch_unwind};
use std::path::{Path, PathBuf};
use std::sync::Mutex;
use std::time::{Duration, Instant};

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

use crate::FuzzError;
use crate::corpus::{self, Seed};
use crate::mutate::mutate;
use crate::rng::Rng;
use crate::targets::{self, Target};

/// One input and where it came from.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Input {
    /// The bytes given to the target.
    pub bytes: Vec<u8>,
    /// `seed NAME`, `mutation of NAME`, `generator`, `generator + mutation`.
    pub origin: String,
}

/// Seeds larger than this are picked as mutation bases only one time in
/// ten: each costs as much as hundreds of small ones.
const BIG_SEED: usize = 64 * 1024;

/// Input `iteration` of `target` in a run with `seed`: the seeds verbatim
/// first, then mutations of seeds (60 %) and generated inputs (40 %, a
/// quarter of them mutated further). A pure function of its arguments.
pub fn input_for(target: &Target, seeds: &[Seed], seed: u64, iteration: u64) -> Input {
    if let Some(s) = usize::try_from(iteration).ok().and_then(|i| seeds.get(i)) {
        return Input {
            bytes: s.bytes.clone(),
            origin: format!("seed {}", s.name),
        };
    }
    let mut rng = Rng::for_input(seed, target.name, iteration);
    let others: Vec<&[u8]> = seeds.iter().map(|s| s.bytes.as_slice()).collect();
    if let Some(generate) = target.generate
        && rng.chance(40)
    {
        let mut runner = TestRunner::new_with_rng(
            Config::default(),
            TestRng::from_seed(RngAlgorithm::ChaCha, &rng.seed32()),
        );
        let mut bytes = generate(&mut runner);
        // No larger than a mutation may make an input.
        bytes.truncate(crate::mutate::MAX_MUTATED_LEN);
        if rng.chance(25) {
            return Input {
                bytes: mutate(&bytes, &others, &mut rng),
                origin: "generator + mutation".into(),
            };
        }
        return Input {
            bytes,
            origin: "generator".into(),
        };
    }
    let mut base = rng.below(seeds.len());
    for _ in 0..4 {
        let big = seeds.get(base).is_some_and(|s| s.bytes.len() > BIG_SEED);
        if !big || rng.chance(10) {
            break;
        }
        base = rng.below(seeds.len());
    }
    let (name, bytes) = seeds.get(base).map_or(("nothing", &[][..]), |s| {
        (s.name.as_str(), s.bytes.as_slice())
    });
    Input {
        bytes: mutate(bytes, &others, &mut rng),
        origin: format!("mutation of {name}"),
    }
}

/// What a worker runs.
#[derive(Debug, Clone)]
pub struct WorkerArgs {
    /// The target.
    pub target: &'static Target,
    /// The run's seed.
    pub seed: u64,
    /// The first iteration (after a restart, the one after the culprit).
    pub from: u64,
    /// Stop starting inputs this long after the seeds.
    pub budget: Duration,
    /// Run the seeds only (from `from` to the last), ignoring the budget.
    pub replay: bool,
    /// The corpus root.
    pub corpus_dir: PathBuf,
    /// This target's work folder.
    pub work_dir: PathBuf,
}

static LAST_PANIC: Mutex<String> = Mutex::new(String::new());

/// Keeps the message of the latest panic instead of printing it: the
/// worker reports it on its protocol line (and stderr stays free for what
/// an abort prints).
fn install_panic_hook() {
    std::panic::set_hook(Box::new(|info| {
        let text = info.to_string().replace(['\n', '\r'], " | ");
        if let Ok(mut m) = LAST_PANIC.lock() {
            *m = text;
        }
    }));
}

fn take_panic_message() -> String {
    LAST_PANIC
        .lock()
        .map(|mut m| std::mem::take(&mut *m))
        .unwrap_or_else(|_| "(panic message lost)".into())
}

/// The file the current input is written to.
pub fn current_input_path(work_dir: &Path) -> PathBuf {
    work_dir.join("current.input")
}

/// Runs the worker loop, writing the protocol to `out`.
pub fn run(args: &WorkerArgs, out: &mut impl Write) -> Result<(), FuzzError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| FuzzError::Io { path, source }
    };
    std::fs::create_dir_all(&args.work_dir).map_err(io(&args.work_dir))?;
    targets::set_scratch_dir(args.work_dir.join("scratch"));
    install_panic_hook();
    let seeds = corpus::load(&args.corpus_dir, args.target)?;
    if let Err(p) = catch_unwind(targets::warm_up) {
        drop(p);
        return Err(FuzzError::Worker {
            target: args.target.name.to_string(),
            message: format!("warm-up failed: {}", take_panic_message()),
        });
    }
    let proto = |e| FuzzError::Io {
        path: PathBuf::from("<stdout>"),
        source: e,
    };
    writeln!(out, "ready {}", seeds.len()).map_err(proto)?;
    out.flush().map_err(proto)?;
    let current_path = current_input_path(&args.work_dir);
    let current = std::fs::File::create(&current_path).map_err(io(&current_path))?;
    // The budget is for fuzzing: it starts after the seeds, so that every
    // run replays all of them however slow they are.
    let mut fuzz_start: Option<Instant> = None;
    let mut count = 0u64;
    let mut i = args.from;
    loop {
        let is_seed = usize::try_from(i).is_ok_and(|i| i < seeds.len());
        if args.replay {
            if !is_seed {
                break;
            }
        } else if !is_seed && fuzz_start.get_or_insert_with(Instant::now).elapsed() >= args.budget {
            break;
        }
        let input = input_for(args.target, &seeds, args.seed, i);
        current.set_len(0).map_err(io(&current_path))?;
        current
            .write_all_at(&input.bytes, 0)
            .map_err(io(&current_path))?;
        writeln!(out, "run {i} {} {}", input.bytes.len(), input.origin).map_err(proto)?;
        out.flush().map_err(proto)?;
        let target = args.target;
        if catch_unwind(AssertUnwindSafe(|| (target.run)(&input.bytes))).is_err() {
            let copy = args.work_dir.join(format!("panic-{i}.input"));
            std::fs::write(&copy, &input.bytes).map_err(io(&copy))?;
            writeln!(out, "panic {i} {}", take_panic_message()).map_err(proto)?;
        }
        // The input is over: time spent making the next one is not its.
        writeln!(out, "done {i}").map_err(proto)?;
        out.flush().map_err(proto)?;
        count += 1;
        i += 1;
    }
    writeln!(out, "end {count}").map_err(proto)?;
    out.flush().map_err(proto)?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn inputs_are_reproducible_and_start_with_the_seeds() {
        let t = targets::find("query").expect("target");
        let seeds = corpus::load(&corpus::default_dir(), t).expect("corpus");
        let first = input_for(t, &seeds, 1, 0);
        assert_eq!(first.bytes, seeds[0].bytes);
        assert!(first.origin.starts_with("seed "));
        let n = seeds.len() as u64;
        for i in n..n + 50 {
            assert_eq!(input_for(t, &seeds, 1, i), input_for(t, &seeds, 1, i));
        }
        let origins: Vec<String> = (n..n + 200)
            .map(|i| input_for(t, &seeds, 1, i).origin)
            .collect();
        assert!(origins.iter().any(|o| o.starts_with("mutation of")));
        assert!(origins.iter().any(|o| o.starts_with("generator")));
    }
}
