//! One target per parser: a `fn(&[u8])` that turns the bytes into text and
//! calls the project's real entry point, then (where it is cheap and the
//! parsed value is small) the code that consumes what was parsed — the
//! evaluator behind a query, the simulator behind a scenario, window facts
//! behind labels, tracks and configs — because a parser that accepts a
//! value its consumer cannot take is the same bug one step later.
//!
//! A target ignores `Ok`/`Err`: what it checks is that the call returns at
//! all, without a panic, an abort, a stack overflow, unbounded memory or a
//! hang. The supervisor ([`crate::supervisor`]) watches for the last four.
//!
//! Text: the `&str` entry points take any text, so the bytes are read
//! lossily (invalid UTF-8 becomes U+FFFD) and a BOM is left in place — a
//! caller holding text from stdin or a socket passes it as it is. The
//! file loaders (`kitti::load`, the `facts:` source, `ModelSet::load`) get
//! the raw bytes in a file, so their own UTF-8 and BOM handling is fuzzed
//! too.

use std::borrow::Cow;
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use logicpad::{FactBase, LogicPad, check_any_query, lint_source, parse_any_query};
use logicrag::ask::{AskOptions, AskResult};
use logicrag::engine::{Engine, Prepared, Summary};
use logicrag::kb::{Observability, WindowInput, WindowKb};
use logicrag::source::{LoadOptions, SourceSpec};
use perception::sim::Scenario;
use perception::{FactConfig, Sequence, WindowSpec};
use proptest::test_runner::TestRunner;

use crate::generate;

/// One fuzz target.
#[derive(Clone, Copy)]
pub struct Target {
    /// Short name: the corpus folder, the `--targets` value.
    pub name: &'static str,
    /// What it parses, through which entry point.
    pub about: &'static str,
    /// Runs one input.
    pub run: fn(&[u8]),
    /// A structure-aware generator (proptest strategies), where the format
    /// has a grammar worth generating from.
    pub generate: Option<fn(&mut TestRunner) -> Vec<u8>>,
}

impl std::fmt::Debug for Target {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name)
    }
}

/// Every target, in the order a run visits them.
pub const ALL: &[Target] = &[
    Target {
        name: "fol",
        about: "FOL formulas and rules: logicpad::fol::parse_formula",
        run: fol,
        generate: Some(generate::fol),
    },
    Target {
        name: "query",
        about: "queries: logicpad::parse_any_query, check_any_query against the built-in LogicPad, \
                then Engine::prepare_query + ask on a simulated window (--max-answers 1000)",
        run: query,
        generate: Some(generate::query),
    },
    Target {
        name: "logicpad",
        about: "LogicPad YAML: logicpad::LogicPad::parse (lenient and strict), lint_source, \
                the translator's vocabulary (Engine::new) and the rules evaluated on a window",
        run: logicpad_yaml,
        generate: Some(generate::logicpad),
    },
    Target {
        name: "facts",
        about: "text KB: logicpad::facts_text::parse_fact_line, logicrag::facts_text::parse_facts, \
                FactBase::from_text + evaluation, and the facts:FILE source (source::load)",
        run: facts,
        generate: Some(generate::facts),
    },
    Target {
        name: "queries_tsv",
        about: "window<TAB>query files: logicrag::batch::parse_queries, then run_batch over a \
                facts: source",
        run: queries_tsv,
        generate: Some(generate::queries_tsv),
    },
    Target {
        name: "kitti_labels",
        about: "KITTI tracking labels: perception::kitti::parse_labels, kitti::load from a file, \
                window facts",
        run: kitti_labels,
        generate: Some(generate::kitti_labels),
    },
    Target {
        name: "kitti_calib",
        about: "KITTI calib: perception::kitti::parse_calib, kitti::load from a file (image size \
                from P2), window facts",
        run: kitti_calib,
        generate: Some(generate::kitti_calib),
    },
    Target {
        name: "tracks_json",
        about: "JSON tracks: perception::json::parse_tracks, window facts, and the round trip \
                through to_tracks_json",
        run: tracks_json,
        generate: Some(generate::tracks_json),
    },
    Target {
        name: "scenario_yaml",
        about: "scenarios: perception::sim::Scenario::from_yaml, simulated when small",
        run: scenario_yaml,
        generate: Some(generate::scenario_yaml),
    },
    Target {
        name: "scenario_json",
        about: "scenarios: perception::sim::Scenario::from_json, simulated when small",
        run: scenario_json,
        generate: Some(generate::scenario_json),
    },
    Target {
        name: "config_yaml",
        about: "fact configs: perception::FactConfig::from_yaml, then window facts under it",
        run: config_yaml,
        generate: Some(generate::config_yaml),
    },
    Target {
        name: "config_json",
        about: "fact configs: perception::FactConfig::from_json, then window facts under it",
        run: config_json,
        generate: Some(generate::config_json),
    },
    Target {
        name: "model_config",
        about: "model configs: perception::raw::config::ModelConfig::parse and \
                raw::frames::ModelSet::load (single config or detector/depth/flow set)",
        run: model_config,
        generate: Some(generate::model_config),
    },
    Target {
        name: "camera",
        about: "camera calibrations: perception::raw::camera::Calibration::parse (KITTI P2 or \
                YAML) and for_frames",
        run: camera,
        generate: Some(generate::camera),
    },
    Target {
        name: "translate",
        about: "English questions: Engine::prepare (logicrag::translate::Translator), then ask",
        run: translate,
        generate: Some(generate::question),
    },
    Target {
        name: "translate_csv",
        about: "question CSV files: Translator::translate_csv",
        run: translate_csv,
        generate: Some(generate::question_csv),
    },
    Target {
        name: "llm_reply",
        about: "a language model's replies: llm::Verdict::parse, llm::translate::read_query, \
                then the query prepared and asked",
        run: llm_reply,
        generate: Some(generate::llm_reply),
    },
    Target {
        name: "source_spec",
        about: "source arguments: logicrag SourceSpec::from_str, perception::Source::parse, \
                source::parse_frame_range",
        run: source_spec,
        generate: Some(generate::source_spec),
    },
    Target {
        name: "av2_feather",
        about: "Argoverse 2 Feather (Arrow IPC) tables: perception::av2::parse_annotations and \
                parse_poses, av2::load of a log holding the file, window facts",
        run: av2_feather,
        generate: None,
    },
    Target {
        name: "av2_map",
        about: "Argoverse 2 map archives: perception::av2::parse_map_json, then window facts of a \
                simulated sequence placed in the map",
        run: av2_map,
        generate: None,
    },
];

/// The target of that name (one of [`ALL`], or [`SELF_TEST`]).
pub fn find(name: &str) -> Option<&'static Target> {
    ALL.iter()
        .find(|t| t.name == name)
        .or_else(|| (name == SELF_TEST.name).then_some(&SELF_TEST))
}

/// Not a parser: a target that fails on purpose, one way per input
/// (`panic`, `abort`, `stack`, `memory`, `hang`; anything else passes),
/// so the tests can check that the supervisor catches and names each.
pub const SELF_TEST: Target = Target {
    name: "selftest",
    about: "fails on purpose: input `panic`, `abort`, `stack`, `memory` or `hang`",
    run: self_test,
    generate: None,
};

fn self_test(bytes: &[u8]) {
    match bytes {
        b"panic" => panic!("self-test panic"),
        b"abort" => std::process::abort(),
        b"stack" => {
            std::hint::black_box(recurse(0));
        }
        b"memory" => {
            // Far beyond any `--memory-mb`: the allocation fails and the
            // process aborts, as a real memory blow-up does under the limit.
            let v: Vec<u8> = Vec::with_capacity(1 << 40);
            std::hint::black_box(&v);
        }
        b"hang" => loop {
            std::thread::sleep(std::time::Duration::from_secs(1));
        },
        _ => {}
    }
}

/// Recursion the optimiser cannot remove (each frame keeps a buffer), to
/// overflow the stack.
fn recurse(n: u64) -> u64 {
    let buf = [n; 64];
    std::hint::black_box(&buf);
    if n == u64::MAX {
        return 0;
    }
    recurse(n + 1).wrapping_add(buf[0])
}

/// The answer budget of every query a target asks: the CLI's
/// `--max-answers`, small, so a query that multiplies its variables
/// stops at it in microseconds instead of enumerating millions.
pub const MAX_ANSWERS: usize = 1000;

/// The limits of every query a target asks.
const LIMITS: logicpad::Limits = logicpad::Limits {
    answers: MAX_ANSWERS,
    steps: None,
    time: None,
    proof_nodes: logicpad::ProofLimits::DEFAULT_MAX_NODES,
    proof_depth: logicpad::ProofLimits::DEFAULT_MAX_DEPTH,
};

const ASK: AskOptions = AskOptions {
    proofs: true,
    why_not: true,
    count_only: false,
    limits: LIMITS,
};

/// The largest object-frames product simulated after a scenario parses:
/// the simulator's cost grows with it, and a fuzz input should take
/// milliseconds (the format's own limit, 500,000, is for real runs).
pub const SIMULATE_MAX_OBJECT_FRAMES: u64 = 5_000;

/// Parsed sequences larger than this are not turned into window facts (the
/// analysis is linear in observations and frames, but slow for a fuzz input).
pub const FACTS_MAX_OBSERVATIONS: usize = 4_000;
/// See [`FACTS_MAX_OBSERVATIONS`].
pub const FACTS_MAX_FRAMES: u32 = 2_000;

/// Built once per worker: the built-in LogicPad's engine, one simulated
/// window's KB and the sequence configs are tried on.
struct Shared {
    engine: Engine,
    window: WindowInput,
    kb: WindowKb,
    sequence: Sequence,
}

static SHARED: OnceLock<Shared> = OnceLock::new();
static SCRATCH: OnceLock<PathBuf> = OnceLock::new();

/// The harness itself is broken (the built-in data does not load, the
/// scratch folder cannot be written): reported as a failure of the input,
/// never skipped, so a broken harness cannot pass as a clean run.
fn harness_broken(what: &str, why: impl std::fmt::Display) -> ! {
    panic!("fuzz harness broken: {what}: {why}")
}

/// A property the parsed value must have that is not "no crash" (a round
/// trip): its violation is a bug, reported like a panic.
fn violated(what: String) -> ! {
    panic!("invariant violated: {what}")
}

/// Sets the folder the file-based targets write their inputs to (one per
/// worker); before the first input. Later calls are ignored.
pub fn set_scratch_dir(dir: PathBuf) {
    let _ = SCRATCH.set(dir);
}

fn scratch() -> &'static Path {
    SCRATCH
        .get_or_init(|| std::env::temp_dir().join(format!("logicrag-fuzz-{}", std::process::id())))
}

/// Writes `bytes` to `rel` under the scratch folder and returns the path.
fn scratch_file(rel: &str, bytes: &[u8]) -> PathBuf {
    let path = scratch().join(rel);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir)
            .unwrap_or_else(|e| harness_broken(&format!("create {}", dir.display()), e));
    }
    std::fs::write(&path, bytes)
        .unwrap_or_else(|e| harness_broken(&format!("write {}", path.display()), e));
    path
}

fn shared() -> &'static Shared {
    SHARED.get_or_init(|| {
        let engine = Engine::new(LogicPad::builtin(), Observability::everything())
            .unwrap_or_else(|e| harness_broken("built-in engine", e));
        // A real window of the simulator (objects, colours, relations):
        // queries then meet derived predicates with several answers.
        let scenario = Scenario::builtin("braking")
            .unwrap_or_else(|e| harness_broken("built-in scenario", e));
        let run = perception::sim::simulate(&scenario, 1)
            .unwrap_or_else(|e| harness_broken("simulate braking", e));
        let windows = perception::window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default())
            .unwrap_or_else(|e| harness_broken("window facts of braking", e));
        let w = windows
            .into_iter()
            .nth(1)
            .unwrap_or_else(|| harness_broken("window facts of braking", "fewer than two windows"));
        let window = WindowInput {
            id: "braking_000010".into(),
            index: w.index,
            first_frame: w.first_frame,
            last_frame: w.last_frame,
            facts: w.facts.into(),
            doubts: w.doubts,
        };
        let kb = engine
            .build(window.clone())
            .unwrap_or_else(|e| harness_broken("window KB", e));
        // Two windows of the text-KB form for batches (`w0`, `w1`).
        scratch_file("batch/w0.facts", b"Vehicles(car_1)\nMoving(car_1)\nTypeOf(car_1, Car)\nColorOf(car_1, White)\nPedestrian(pedestrian_2)\nDistanceDecrease(car_1, pedestrian_2)\n");
        scratch_file("batch/w1.facts", b"Vehicles(car_1)\nVehicles(car_3)\nTypeOf(car_3, Van)\nSpeedUp(car_3)\n");
        // The fixed halves of a KITTI sequence: each KITTI target replaces
        // one file and keeps the other.
        scratch_file("kitti/calib/0000.txt", KITTI_CALIB.as_bytes());
        scratch_file("kitti_calib/label_02/0000.txt", KITTI_LABELS.as_bytes());
        // Model configs a fuzzed model set may name.
        scratch_file("models/det.yaml", MODEL_DETECTOR.as_bytes());
        scratch_file("models/depth.yaml", MODEL_DEPTH.as_bytes());
        scratch_file("models/flow.yaml", MODEL_FLOW.as_bytes());
        Shared {
            engine,
            window,
            kb,
            sequence: run.sequence,
        }
    })
}

/// Builds what every target shares (the engine, a simulated window, the
/// scratch files), so that its cost is not charged to the first input.
pub fn warm_up() {
    let _ = shared();
}

/// A KITTI calibration (P2 of the 2011-09-26 recordings, rounded).
pub const KITTI_CALIB: &str = "P0: 721.5377 0 609.5593 0 0 721.5377 172.854 0 0 0 1 0\n\
P1: 721.5377 0 609.5593 -387.5744 0 721.5377 172.854 0 0 0 1 0\n\
P2: 721.5377 0 609.5593 44.85728 0 721.5377 172.854 0.2163791 0 0 1 0.002745884\n\
P3: 721.5377 0 609.5593 -339.5242 0 721.5377 172.854 2.199936 0 0 1 0.002729905\n";

/// A few label lines written for these tests (not taken from KITTI).
pub const KITTI_LABELS: &str = "0 0 Car 0 0 -1.57 500.0 170.0 620.0 260.0 1.5 1.6 4.0 1.0 1.7 15.0 -1.55\n\
0 1 Pedestrian 0 1 0.2 800.0 150.0 840.0 260.0 1.7 0.6 0.8 5.0 1.7 14.0 0.1\n\
1 0 Car 0 0 -1.57 505.0 171.0 626.0 262.0 1.5 1.6 4.0 1.0 1.7 14.5 -1.55\n\
1 1 Pedestrian 0 1 0.2 802.0 150.0 842.0 261.0 1.7 0.6 0.8 5.1 1.7 14.0 0.1\n\
1 -1 DontCare -1 -1 -10 900.0 160.0 950.0 190.0 -1 -1 -1 -1000 -1000 -1000 -10\n";

/// A working model config the fuzzed model sets may name.
pub const MODEL_DETECTOR: &str = "name: det\nmodel: det.onnx\ninput: { width: 32, height: 32, layout: nchw, colour: rgb, mean: [0, 0, 0], std: [255, 255, 255] }\noutput:\n  kind: detector\n  score_threshold: 0.5\n  nms_iou: 0.5\n  max_detections: 10\n  decoder: { name: nanodet_gfl, strides: [8, 16], reg_max: 3, num_classes: 3 }\nlabels:\n  - { id: 2, name: car, class: Vehicles, type: Car }\n";
/// A working model config the fuzzed model sets may name.
pub const MODEL_DEPTH: &str = "name: depth\nmodel: depth.onnx\ninput: { width: 64, height: 64, layout: nchw, colour: rgb, mean: [0, 0, 0], std: [255, 255, 255], resize: { mode: stretch } }\noutput: { kind: depth, mode: relative, relative: inverse_depth }\n";
/// A working model config the fuzzed model sets may name.
pub const MODEL_FLOW: &str = "name: flow\nmodel: flow.onnx\ninput: { width: 8, height: 8, layout: nchw, colour: rgb, mean: [0, 0, 0], std: [255, 255, 255], resize: { mode: stretch }, frames: 2 }\noutput: { kind: flow }\n";

fn text(bytes: &[u8]) -> Cow<'_, str> {
    String::from_utf8_lossy(bytes)
}

/// Renders what a user would see of an answer: the result lines, the
/// proofs, the retrieval context and the one-line summary.
fn show(engine: &Engine, kb: &WindowKb, p: &Prepared, r: AskResult) {
    let _ = logicrag::render::detail_lines(&r);
    let _ = logicrag::render::count_suffix(&r);
    let _ = engine.context(kb, p, &r).to_text();
    let _ = Summary::new(engine.words(), p, std::slice::from_ref(&r)).headline();
}

fn ask_text(s: &Shared, query: &str) {
    let p = s.engine.prepare_query(query);
    if let Err(diags) = &p.parsed {
        for d in diags {
            let _ = d.render_plain(100);
        }
    }
    // A claim about time is answered over a video's windows (here the one
    // window), rendered as `ask` renders it.
    if let Some(t) = &p.temporal {
        let a = logicrag::temporal::answer(&s.engine, "fuzz", t, query, &[&s.kb], ASK);
        let _ = logicrag::temporal::headline(&a.result);
    }
    let r = s.engine.ask(&s.kb, &p, ASK);
    show(&s.engine, &s.kb, &p, r);
}

fn fol(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(f) = logicpad::fol::parse_formula(&t) {
        let _ = format!("{f:?}");
    }
}

fn query(bytes: &[u8]) {
    let t = text(bytes);
    let s = shared();
    match parse_any_query(&t) {
        Ok(q) => {
            for d in check_any_query(s.engine.pad().schema(), &q) {
                let _ = d.render_plain(100);
            }
            // The evaluator's own joins, without proofs (batch answers).
            for part in q.parts() {
                let _ = s.kb.model.bindings_limited(part, &LIMITS);
            }
        }
        Err(d) => {
            let _ = d.render_plain(100);
        }
    }
    ask_text(s, &t);
}

fn logicpad_yaml(bytes: &[u8]) {
    let t = text(bytes);
    let s = shared();
    for strict in [false, true] {
        match LogicPad::parse(&t, "fuzz.yaml", strict) {
            Ok(pad) => {
                for d in pad.diagnostics() {
                    let _ = d.render_plain(100);
                }
                if strict {
                    continue;
                }
                // The pad's phrases drive the translator; its rules are
                // evaluated over a real window.
                if let Ok(engine) = Engine::new(pad, Observability::everything())
                    && let Ok(kb) = engine.build(s.window.clone())
                {
                    for q in ["Vehicles(x)", "TypeOf(x, Car) ^ Moving(x)"] {
                        let p = engine.prepare_query(q);
                        let r = engine.ask(&kb, &p, ASK);
                        show(&engine, &kb, &p, r);
                    }
                    if let Ok(p) = engine.prepare("Is there a white car?") {
                        let r = engine.ask(&kb, &p, ASK);
                        show(&engine, &kb, &p, r);
                    }
                }
            }
            Err(e) => {
                for d in e.diagnostics() {
                    let _ = d.render_plain(100);
                }
            }
        }
    }
    let _ = lint_source(&t, "fuzz.yaml", false).render_with(false, 100);
}

fn facts(bytes: &[u8]) {
    let t = text(bytes);
    let s = shared();
    for line in t.lines() {
        let _ = logicpad::facts_text::parse_fact_line(line.trim());
    }
    let listed = logicrag::facts_text::parse_facts(&t, "fuzz.facts");
    // The interned reader must accept, refuse and report exactly as the
    // `String` one does: the `facts:` source reads through it.
    let interned = logicrag::facts_text::parse_facts_interned(&t, "fuzz.facts");
    match (&listed, &interned) {
        (Ok(a), Ok(b)) => {
            let same = a.len() == b.len()
                && a.iter().zip(b.iter()).all(|(x, (p, args))| {
                    x.predicate == p.as_str()
                        && x.args.len() == args.len()
                        && x.args.iter().zip(args).all(|(s, y)| s == y.as_str())
                });
            if !same {
                violated("parse_facts and parse_facts_interned read different facts".into());
            }
        }
        (Err(a), Err(b)) if a.to_string() == b.to_string() => {}
        _ => violated(format!(
            "parse_facts and parse_facts_interned disagree: {:?} vs {:?}",
            listed.as_ref().map(Vec::len).map_err(ToString::to_string),
            interned
                .as_ref()
                .map(|f| f.len())
                .map_err(ToString::to_string)
        )),
    }
    if let Ok(fb) = FactBase::from_text(&t, "fuzz.facts") {
        let _ = s.engine.pad().program().evaluate(fb);
    }
    // The real loader, on the raw bytes: UTF-8 and BOM handling included.
    let path = scratch_file("facts/window.facts", bytes);
    let spec = SourceSpec::Facts { path };
    if let Ok(loaded) = logicrag::source::load(&spec, &LoadOptions::default(), &mut |_| {}) {
        for w in loaded.windows.into_iter().take(2) {
            if let Ok(kb) = s.engine.build(w) {
                for q in ["Vehicles(x)", "TypeOf(x) = Car ∧ ¬Moving(x)"] {
                    let p = s.engine.prepare_query(q);
                    let r = s.engine.ask(&kb, &p, ASK);
                    show(&s.engine, &kb, &p, r);
                }
            }
        }
    }
}

/// Queries of a batch answered per input: a batch of thousands is the
/// same code thousands of times.
const BATCH_MAX_QUERIES: usize = 64;

fn queries_tsv(bytes: &[u8]) {
    let t = text(bytes);
    let s = shared();
    let Ok(queries) = logicrag::batch::parse_queries(&t, "fuzz.tsv") else {
        return;
    };
    let queries: Vec<_> = queries.into_iter().take(BATCH_MAX_QUERIES).collect();
    let spec = SourceSpec::Facts {
        path: scratch().join("batch"),
    };
    let options = logicrag::pipeline::OpenOptions {
        logicpad: logicrag::pipeline::PadChoice::Built(Box::new(s.engine.clone())),
        ..Default::default()
    };
    let pipeline = logicrag::pipeline::Pipeline::open(spec, &options, &mut |_| {})
        .unwrap_or_else(|e| harness_broken("the batch facts source", e));
    let opts = AskOptions {
        count_only: true,
        proofs: false,
        why_not: false,
        limits: LIMITS,
    };
    let _ = logicrag::batch::run_batch(pipeline, &queries, "fuzz.tsv", opts);
}

/// Window facts of a parsed sequence, when it is small enough to be quick.
fn facts_of(seq: &Sequence, config: &FactConfig) {
    if seq.observations.len() <= FACTS_MAX_OBSERVATIONS
        && seq.frame_count <= FACTS_MAX_FRAMES
        && let Ok(ws) = perception::window_facts(seq, WindowSpec::PAPER, config)
    {
        for w in ws.iter().take(3) {
            let _ = w.to_kb();
        }
    }
}

fn kitti_labels(bytes: &[u8]) {
    let t = text(bytes);
    shared();
    let _ = perception::kitti::parse_labels(&t, Path::new("label_02/0000.txt"));
    scratch_file("kitti/label_02/0000.txt", bytes);
    if let Ok(k) = perception::kitti::load(&scratch().join("kitti"), "0000") {
        facts_of(&k.sequence, &FactConfig::default());
    }
}

fn kitti_calib(bytes: &[u8]) {
    let t = text(bytes);
    shared();
    let _ = perception::kitti::parse_calib(&t, Path::new("calib/0000.txt"));
    scratch_file("kitti_calib/calib/0000.txt", bytes);
    if let Ok(k) = perception::kitti::load(&scratch().join("kitti_calib"), "0000") {
        facts_of(&k.sequence, &FactConfig::default());
    }
}

fn tracks_json(bytes: &[u8]) {
    let t = text(bytes);
    let Ok(seq) = perception::json::parse_tracks(&t, "fuzz.json") else {
        return;
    };
    facts_of(&seq, &FactConfig::default());
    // What the project writes it must read back.
    if let Ok(json) = perception::json::to_tracks_json(&seq)
        && let Err(e) = perception::json::parse_tracks(&json, "round trip")
    {
        violated(format!(
            "tracks written by to_tracks_json do not read back: {e}"
        ));
    }
}

fn av2_feather(bytes: &[u8]) {
    let origin = Path::new("annotations.feather");
    let _ = perception::av2::parse_poses(bytes, origin);
    if perception::av2::parse_annotations(bytes, origin).is_err() {
        return;
    }
    scratch_file("av2/annotations.feather", bytes);
    if let Ok(seq) = perception::av2::load(&scratch().join("av2")) {
        facts_of(&seq, &FactConfig::default());
    }
}

/// Map elements beyond which a parsed map is not turned into facts (a fuzz
/// input should take milliseconds).
const AV2_MAP_MAX_POINTS: usize = 5_000;

fn av2_map(bytes: &[u8]) {
    let t = text(bytes);
    let Ok(map) = perception::av2::parse_map_json(&t, "log_map_archive_fuzz.json") else {
        return;
    };
    let points: usize = map
        .lanes
        .iter()
        .map(|l| l.left_boundary.len() + l.right_boundary.len())
        .sum::<usize>()
        + map
            .crosswalks
            .iter()
            .chain(&map.drivable_areas)
            .map(|a| a.polygon.len())
            .sum::<usize>();
    if points > AV2_MAP_MAX_POINTS {
        return;
    }
    // The simulated sequence, its ego standing at the map's first point.
    let mut seq = shared().sequence.clone();
    let at = map
        .lanes
        .first()
        .and_then(|l| l.left_boundary.first())
        .or_else(|| map.crosswalks.first().and_then(|a| a.polygon.first()))
        .copied()
        .unwrap_or([0.0, 0.0]);
    seq.ego_poses = Some(
        (0..seq.frame_count)
            .map(|f| perception::WorldPose {
                x: at[0] + f64::from(f) * 0.5,
                y: at[1],
                z: 0.0,
                yaw: 0.0,
            })
            .collect(),
    );
    seq.map = Some(std::sync::Arc::new(map));
    facts_of(&seq, &FactConfig::default());
}

fn simulate_small(s: &Scenario) {
    let object_frames = u64::from(s.frames).saturating_mul(s.object_count() as u64 + 1);
    if object_frames > SIMULATE_MAX_OBJECT_FRAMES {
        return;
    }
    if let Ok(run) = perception::sim::simulate(s, 7) {
        facts_of(&run.sequence, &FactConfig::default());
    }
}

fn scenario_yaml(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(s) = Scenario::from_yaml(&t, "fuzz.yaml") {
        simulate_small(&s);
    }
}

fn scenario_json(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(s) = Scenario::from_json(&t, "fuzz.json") {
        simulate_small(&s);
    }
}

fn config_yaml(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(c) = FactConfig::from_yaml(&t, "fuzz.yaml") {
        facts_of(&shared().sequence, &c);
    }
}

fn config_json(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(c) = FactConfig::from_json(&t, "fuzz.json") {
        facts_of(&shared().sequence, &c);
    }
}

fn model_config(bytes: &[u8]) {
    let t = text(bytes);
    shared();
    let _ = perception::raw::config::ModelConfig::parse(&t, Path::new("models/fuzz.yaml"));
    let path = scratch_file("models/fuzz.yaml", bytes);
    let _ = perception::raw::frames::ModelSet::load(&path);
}

fn camera(bytes: &[u8]) {
    let t = text(bytes);
    let path = Path::new("calib.yaml");
    if let Ok(c) = perception::raw::camera::Calibration::parse(&t, path) {
        let _ = c.matrix();
        for (w, h) in [(1242, 375), (1, 1), (640, 480), (u32::MAX, u32::MAX)] {
            let _ = c.for_frames(w, h, path);
        }
    }
}

fn translate(bytes: &[u8]) {
    let t = text(bytes);
    let s = shared();
    match s.engine.prepare(&t) {
        Ok(p) => {
            let r = s.engine.ask(&s.kb, &p, ASK);
            show(&s.engine, &s.kb, &p, r);
        }
        Err(e) => {
            let _ = e.to_string();
        }
    }
}

fn translate_csv(bytes: &[u8]) {
    let t = text(bytes);
    let _ = shared().engine.translator().translate_csv(&t);
}

fn llm_reply(bytes: &[u8]) {
    let t = text(bytes);
    let _ = logicrag::llm::Verdict::parse(&t);
    let q = logicrag::llm::translate::read_query(&t);
    ask_text(shared(), &q);
}

fn source_spec(bytes: &[u8]) {
    let t = text(bytes);
    if let Ok(spec) = t.parse::<SourceSpec>() {
        let _ = spec.to_string();
        let _ = spec.clone().with_sequence(Some("0000".into()));
        let _ = spec.with_frames_options(None, None, Some(10.0));
    }
    if let Ok(src) = perception::Source::parse(&t) {
        let _ = src.to_string();
    }
    let _ = perception::source::parse_frame_range(&t);
}
