//! All splits of the list [1..N] with appendo: prints the count (N + 1) and the time.
//!
//!     cargo run --release -p kanren --example appendo -- 400 [REPS] [--no-occurs-check]

use kanren::classic::appendo;
use kanren::{Query, RunConfig, Term};
use std::time::{Duration, Instant};

// The CLI's allocator, so the engine is measured as it ships there.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

fn main() {
    let all: Vec<String> = std::env::args().skip(1).collect();
    let occurs_check = !all.iter().any(|a| a == "--no-occurs-check");
    let args: Vec<String> = all
        .into_iter()
        .filter(|a| a != "--no-occurs-check")
        .collect();
    let parse = |i: usize, default: usize| -> usize {
        match args.get(i) {
            None => default,
            Some(s) => s.parse().unwrap_or_else(|_| {
                eprintln!("usage: appendo [N] [REPS]  (N, REPS positive integers; got {s:?})");
                std::process::exit(2);
            }),
        }
    };
    let n = parse(0, 400);
    let reps = parse(1, 20).max(1);
    let list = Term::list((1..=n as i64).map(Term::Int));
    let mut q = Query::new();
    q.set_occurs_check(occurs_check);
    let (x, y) = (q.var("x"), q.var("y"));
    let mut times: Vec<Duration> = Vec::with_capacity(reps);
    let mut count = 0;
    for _ in 0..reps {
        let t0 = Instant::now();
        let answers: Result<Vec<_>, _> = q
            .run(
                appendo(x.clone(), y.clone(), list.clone()),
                RunConfig::default(),
            )
            .collect();
        times.push(t0.elapsed());
        match answers {
            Ok(a) => count = a.len(),
            Err(e) => {
                eprintln!("appendo: {e}");
                std::process::exit(1);
            }
        }
    }
    times.sort();
    println!(
        "appendo N={n}: {count} splits (expected {}), occurs check {}",
        n + 1,
        if occurs_check { "on" } else { "off" }
    );
    println!(
        "median {:.3} ms, min {:.3} ms per run over {reps} runs",
        times[times.len() / 2].as_secs_f64() * 1e3,
        times[0].as_secs_f64() * 1e3
    );
    if count != n + 1 {
        std::process::exit(1);
    }
}
