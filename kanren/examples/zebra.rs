//! The zebra puzzle: prints its one solution and the time per solve.
//!
//!     cargo run --release -p kanren --example zebra -- --iters 50
//!
//! Options: `--iters N` (default 20), `--no-occurs-check` (Prolog's default;
//! the occurs check is on otherwise), `--relational` (the textbook relational
//! `membero`/`nextto` instead of the list-walking ones).

use kanren::classic::{zebrao, zebrao_rel};
use kanren::{Query, RunConfig};
use std::time::{Duration, Instant};

// The CLI's allocator, so the engine is measured as it ships there.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

struct Opts {
    iters: usize,
    occurs_check: bool,
    relational: bool,
}

fn parse_opts() -> Result<Opts, String> {
    let mut opts = Opts {
        iters: 20,
        occurs_check: true,
        relational: false,
    };
    let mut args = std::env::args().skip(1);
    while let Some(a) = args.next() {
        match a.as_str() {
            "--iters" => {
                let n = args.next().unwrap_or_default();
                opts.iters = n
                    .parse::<usize>()
                    .ok()
                    .filter(|&n| n > 0)
                    .ok_or_else(|| format!("--iters expects a positive integer, got {n:?}"))?;
            }
            "--no-occurs-check" => opts.occurs_check = false,
            "--relational" => opts.relational = true,
            other => {
                return Err(format!(
                    "usage: zebra [--iters N] [--no-occurs-check] [--relational]  (unknown {other:?})"
                ));
            }
        }
    }
    Ok(opts)
}

fn main() {
    let opts = match parse_opts() {
        Ok(o) => o,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let iters = opts.iters;
    let mut q = Query::new();
    q.set_occurs_check(opts.occurs_check);
    let hs = q.var("houses");
    let puzzle = |hs: kanren::Term| {
        if opts.relational {
            zebrao_rel(hs)
        } else {
            zebrao(hs)
        }
    };
    let mut times: Vec<Duration> = Vec::with_capacity(iters);
    let mut last = Vec::new();
    for _ in 0..iters {
        let t0 = Instant::now();
        let answers: Result<Vec<_>, _> = q.run(puzzle(hs.clone()), RunConfig::default()).collect();
        times.push(t0.elapsed());
        match answers {
            Ok(a) => last = a,
            Err(e) => {
                eprintln!("zebra: {e}");
                std::process::exit(1);
            }
        }
    }
    println!("{} solution(s)", last.len());
    for a in &last {
        let houses = a
            .values
            .first()
            .and_then(|t| t.to_vec())
            .unwrap_or_default();
        for (i, h) in houses.iter().enumerate() {
            println!("  house {}: {h}", i + 1);
        }
        let find = |slot: usize, value: &str| {
            houses.iter().find_map(|h| match h {
                kanren::Term::App(_, args)
                    if args.get(slot).and_then(|t| t.as_sym()).map(|s| s.as_str())
                        == Some(value) =>
                {
                    args.get(1).map(|n| n.to_string())
                }
                _ => None,
            })
        };
        println!(
            "  the {} owns the zebra; the {} drinks water",
            find(2, "zebra").unwrap_or_default(),
            find(3, "water").unwrap_or_default()
        );
    }
    times.sort();
    let median = times[times.len() / 2];
    let min = times[0];
    println!(
        "zebra (all solutions, occurs check {}, {} membero): median {:.3} ms, min {:.3} ms per solve over {iters} iterations",
        if opts.occurs_check { "on" } else { "off" },
        if opts.relational {
            "relational"
        } else {
            "list-walking"
        },
        median.as_secs_f64() * 1e3,
        min.as_secs_f64() * 1e3
    );
}
