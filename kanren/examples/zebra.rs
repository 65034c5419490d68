//! The zebra puzzle: prints its one solution and the time per solve.
//!
//!     cargo run --release -p kanren --example zebra -- --iters 50

use kanren::classic::zebrao;
use kanren::{Query, RunConfig};
use std::time::{Duration, Instant};

fn parse_iters() -> Result<usize, String> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    match args.as_slice() {
        [] => Ok(20),
        [flag, n] if flag == "--iters" => n
            .parse::<usize>()
            .ok()
            .filter(|&n| n > 0)
            .ok_or_else(|| format!("--iters expects a positive integer, got {n:?}")),
        other => Err(format!("usage: zebra [--iters N]  (got {other:?})")),
    }
}

fn main() {
    let iters = match parse_iters() {
        Ok(n) => n,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut q = Query::new();
    let hs = q.var("houses");
    let mut times: Vec<Duration> = Vec::with_capacity(iters);
    let mut last = Vec::new();
    for _ in 0..iters {
        let t0 = Instant::now();
        let answers: Result<Vec<_>, _> = q.run(zebrao(hs.clone()), RunConfig::default()).collect();
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
        let houses = a.values.first().and_then(|t| t.to_vec()).unwrap_or_default();
        for (i, h) in houses.iter().enumerate() {
            println!("  house {}: {h}", i + 1);
        }
        let find = |slot: usize, value: &str| {
            houses.iter().find_map(|h| match h {
                kanren::Term::App(_, args)
                    if args.get(slot).and_then(|t| t.as_sym()).map(|s| s.as_str()) == Some(value) =>
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
        "zebra (all solutions): median {:.3} ms, min {:.3} ms per solve over {iters} iterations",
        median.as_secs_f64() * 1e3,
        min.as_secs_f64() * 1e3
    );
}
