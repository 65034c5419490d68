//! Overlapping windows reasoned from scratch and chained (each window
//! reusing the previous window's unchanged components), side by side.
//!
//!     cargo run --release -p logicrag --example sliding_windows -- [SOURCE] [--window N] [--stride S] [--iters K]
//!
//! SOURCE defaults to `sim:urban_crossing`; `kitti:../shared/data/kitti-tracking`
//! takes `--sequence NNNN`. Prints, per mode, the median time to reason all
//! windows (sources are loaded once, outside the timing), the share of
//! components reused, and checks that both modes derive the same facts.

use logicpad::LogicPad;
use logicrag::kb::{WindowKb, build_all};
use logicrag::source::{LoadOptions, SourceSpec, load};
use perception::WindowSpec;
use std::time::{Duration, Instant};

struct Opts {
    source: String,
    sequence: Option<String>,
    window: u32,
    stride: u32,
    iters: usize,
}

fn parse() -> Result<Opts, String> {
    let mut o = Opts {
        source: "sim:urban_crossing".into(),
        sequence: None,
        window: 10,
        stride: 1,
        iters: 5,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        let mut num = |what: &str| -> Result<u32, String> {
            let v = args.next().unwrap_or_default();
            v.parse::<u32>()
                .ok()
                .filter(|&n| n > 0)
                .ok_or_else(|| format!("{what} expects a positive integer, got {v:?}"))
        };
        match a.as_str() {
            "--window" => o.window = num("--window")?,
            "--stride" => o.stride = num("--stride")?,
            "--iters" => o.iters = num("--iters")? as usize,
            "--sequence" => o.sequence = args.next(),
            s if !s.starts_with("--") => o.source = s.to_string(),
            other => return Err(format!("unknown option {other}")),
        }
    }
    Ok(o)
}

fn median(mut v: Vec<Duration>) -> Duration {
    v.sort();
    v.get(v.len() / 2).copied().unwrap_or_default()
}

fn derived_count(kbs: &[WindowKb]) -> usize {
    kbs.iter().map(|k| k.model.stats().derived_facts).sum()
}

fn main() {
    let o = match parse() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("sliding_windows: {e}");
            std::process::exit(2);
        }
    };
    let spec: SourceSpec = match o.source.parse::<SourceSpec>() {
        Ok(s) => match s.with_sequence(o.sequence.clone()) {
            Ok(s) => s,
            Err(e) => {
                eprintln!("sliding_windows: {e}");
                std::process::exit(2);
            }
        },
        Err(e) => {
            eprintln!("sliding_windows: {e}");
            std::process::exit(2);
        }
    };
    let opts = LoadOptions {
        windows: WindowSpec {
            size: o.window,
            stride: o.stride,
        },
        ..LoadOptions::default()
    };
    let loaded = match load(&spec, &opts, &mut |_| {}) {
        Ok(l) => l,
        Err(e) => {
            eprintln!("sliding_windows: {e}");
            std::process::exit(1);
        }
    };
    let pad = LogicPad::builtin();
    let prog = pad.program();
    let n = loaded.windows.len();
    let comps = prog.components().len() * n;
    let (mut alone_t, mut chain_t) = (Vec::new(), Vec::new());
    let (mut alone_derived, mut chain_derived, mut reused) = (0, 0, 0);
    for _ in 0..o.iters {
        let inputs = loaded.windows.clone();
        let t = Instant::now();
        let alone: Result<Vec<WindowKb>, _> = {
            use rayon::prelude::*;
            inputs
                .into_par_iter()
                .map(|w| WindowKb::build(w, prog))
                .collect()
        };
        alone_t.push(t.elapsed());
        let inputs = loaded.windows.clone();
        let t = Instant::now();
        let chained = build_all(prog, inputs, &|| {});
        chain_t.push(t.elapsed());
        match (alone, chained) {
            (Ok(a), Ok(c)) => {
                alone_derived = derived_count(&a);
                chain_derived = derived_count(&c);
                reused = c.iter().map(|k| k.model.stats().reused_components).sum();
            }
            (Err(e), _) | (_, Err(e)) => {
                eprintln!("sliding_windows: {e}");
                std::process::exit(1);
            }
        }
    }
    let facts: usize = loaded.windows.iter().map(|w| w.facts.len()).sum();
    println!(
        "{}: {n} windows of {} frames, stride {}, {facts} base facts, {} threads",
        loaded.label,
        o.window,
        o.stride,
        rayon::current_num_threads()
    );
    println!(
        "  each window alone: median {:.2} ms",
        median(alone_t).as_secs_f64() * 1e3
    );
    println!(
        "  chained (reuse):   median {:.2} ms, {reused} of {comps} components reused ({:.0}%)",
        median(chain_t).as_secs_f64() * 1e3,
        100.0 * reused as f64 / comps.max(1) as f64
    );
    if alone_derived != chain_derived {
        eprintln!(
            "sliding_windows: derived facts differ: {alone_derived} alone, {chain_derived} chained"
        );
        std::process::exit(1);
    }
    println!("  derived facts: {chain_derived} either way");
}
