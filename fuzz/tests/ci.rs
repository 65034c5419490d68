//! The fuzz harness in CI (`cargo test --workspace`): every seed replayed
//! once, then a bounded fuzz run of every target, both supervised (a worker
//! process per target, so an abort or a stack overflow is caught and
//! reported rather than taking the test binary down), with a fixed seed.

use std::path::PathBuf;
use std::time::Duration;

use logicrag_fuzz::supervisor::{self, Options, Report};
use logicrag_fuzz::{corpus, targets};

/// Total seconds of the bounded run, split over the targets.
const CI_SECONDS: f64 = 60.0;

fn options(name: &str, seconds: f64, replay: bool) -> Options {
    let tmp = PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    Options {
        seconds,
        targets: targets::ALL.iter().collect(),
        seed: 1,
        timeout: Duration::from_secs(10),
        memory_mb: 3072,
        corpus_dir: corpus::default_dir(),
        artifacts_dir: tmp.join("artifacts"),
        work_dir: tmp.join("work"),
        worker_exe: PathBuf::from(env!("CARGO_BIN_EXE_logicrag-fuzz")),
        replay,
        progress: false,
    }
}

fn assert_clean(report: &Report) {
    assert!(report.is_clean(), "\n{}", report.render());
    assert_eq!(report.targets.len(), targets::ALL.len());
}

#[test]
fn every_seed_replays_without_failure() {
    let report = supervisor::run(&options("fuzz-replay", 0.0, true)).expect("replay runs");
    assert_clean(&report);
    for t in &report.targets {
        // Every seed ran: the test cannot pass on an empty corpus.
        assert!(t.seeds > 0, "{} has no seeds", t.name);
        assert_eq!(
            t.inputs,
            t.seeds,
            "{}: not every seed ran\n{}",
            t.name,
            report.render()
        );
    }
}

#[test]
fn a_bounded_fuzz_run_finds_no_failure() {
    let report = supervisor::run(&options("fuzz-ci", CI_SECONDS, false)).expect("fuzz run");
    println!("{}", report.render());
    assert_clean(&report);
    // Every target ran, and past the seeds mutations and generated inputs
    // ran too. Not per target: on a loaded 2-core CI machine a target whose
    // seeds are slow (the 3,000-rule LogicPad takes seconds) can spend its
    // few seconds on them; `every_seed_replays_without_failure` covers every
    // seed, and the one-hour run in docs/fuzzing.md every target's mutations.
    for t in &report.targets {
        assert!(t.inputs > 0, "{} ran no input\n{}", t.name, report.render());
    }
    let inputs: u64 = report.targets.iter().map(|t| t.inputs).sum();
    let seeds: u64 = report.targets.iter().map(|t| t.seeds).sum();
    assert!(
        inputs > 2 * seeds,
        "only {inputs} inputs for {seeds} seeds\n{}",
        report.render()
    );
}

/// The supervision itself: a target that fails on purpose in each way is
/// caught, classified, saved and restarted after, and the inputs after
/// each failure still run.
#[test]
fn the_supervisor_catches_every_kind_of_failure() {
    let mut opts = options("fuzz-selftest", 0.0, true);
    let corpus = opts.work_dir.with_file_name("corpus");
    let dir = corpus.join("selftest");
    std::fs::create_dir_all(&dir).expect("corpus dir");
    let inputs = ["ok", "panic", "abort", "stack", "memory", "hang", "ok"];
    for (i, text) in inputs.iter().enumerate() {
        std::fs::write(dir.join(format!("{i}-{text}")), text).expect("seed");
    }
    let _ = std::fs::remove_dir_all(&opts.artifacts_dir);
    opts.corpus_dir = corpus;
    opts.targets = vec![&targets::SELF_TEST];
    opts.timeout = Duration::from_secs(2);
    opts.memory_mb = 1024;
    let report = supervisor::run(&opts).expect("self-test runs");
    assert!(
        report.memory.contains("prlimit"),
        "the memory limit needs prlimit (util-linux): {}",
        report.memory
    );
    let t = &report.targets[0];
    let kinds: Vec<(u64, &str)> = t
        .failures
        .iter()
        .map(|f| (f.iteration, f.kind.name()))
        .collect();
    assert_eq!(
        kinds,
        vec![
            (1, "panic"),
            (2, "abort"),
            (3, "stack"),
            (4, "memory"),
            (5, "timeout")
        ],
        "\n{}",
        report.render()
    );
    // Every seed ran, the generated ones after the last failure included.
    assert_eq!(t.inputs, t.seeds, "\n{}", report.render());
    assert_eq!(t.restarts, 4);
    for f in &t.failures {
        let path = f.artifact.as_ref().expect("artifact saved");
        let saved = std::fs::read(path).expect("artifact readable");
        assert_eq!(
            saved,
            inputs[f.iteration as usize].as_bytes(),
            "{}",
            path.display()
        );
    }
}

/// A worker that never runs an input (here `true`, which exits at once) is
/// restarted a few times, then its target is given up and the run is not
/// clean: the supervisor neither waits forever nor reports a clean run.
#[test]
fn a_worker_that_runs_nothing_is_given_up() {
    let mut opts = options("fuzz-stall", 1.0, false);
    opts.targets = vec![targets::find("fol").expect("fol")];
    opts.worker_exe = PathBuf::from("true");
    let report = supervisor::run(&opts).expect("the run ends");
    let t = &report.targets[0];
    assert_eq!(
        t.stalls.len(),
        supervisor::MAX_STALLS,
        "\n{}",
        report.render()
    );
    assert!(t.gave_up.is_some());
    assert_eq!(t.inputs, 0);
    assert!(!report.is_clean());
    assert!(report.render().contains("GIVEN UP"));
}
