//! Loads N facts into one relation and runs a point query: prints the load
//! time, the resident memory per fact and the query time.
//!
//!     cargo run --release -p kanren --example facts_scale -- 1000000

use kanren::{Query, Relation, RunConfig, Term, fact, sym};
use std::sync::Arc;
use std::time::Instant;

// The CLI's allocator, so the engine is measured as it ships there.
#[global_allocator]
static GLOBAL: mimalloc::MiMalloc = mimalloc::MiMalloc;

/// Resident set size in KiB (Linux); 0 where unknown.
fn rss_kib() -> u64 {
    std::fs::read_to_string("/proc/self/status")
        .ok()
        .and_then(|s| {
            s.lines()
                .find(|l| l.starts_with("VmRSS"))
                .and_then(|l| l.split_whitespace().nth(1)?.parse().ok())
        })
        .unwrap_or(0)
}

fn main() {
    let n: usize = match std::env::args().nth(1).map(|s| s.parse()) {
        None => 1_000_000,
        Some(Ok(n)) => n,
        Some(Err(_)) => {
            eprintln!("usage: facts_scale [N]");
            std::process::exit(2);
        }
    };
    let before = rss_kib();
    let t0 = Instant::now();
    let mut r = Relation::new("color_of", 2);
    let colors: Vec<Term> = (0..16).map(|i| sym(&format!("c{i}"))).collect();
    for i in 0..n {
        if let Err(e) = r.insert(&[Term::Int(i as i64), colors[i % 16].clone()]) {
            eprintln!("{e}");
            std::process::exit(1);
        }
    }
    r.shrink_to_fit();
    let load = t0.elapsed();
    let per_fact = (rss_kib().saturating_sub(before)) as f64 * 1024.0 / n.max(1) as f64;
    println!(
        "{n} facts color_of(i, c): loaded in {:.1} ms, ~{per_fact:.0} bytes/fact resident",
        load.as_secs_f64() * 1e3
    );
    let r = Arc::new(r);
    let mut q = Query::new();
    let c = q.var("c");
    let key = Term::Int((n / 2) as i64);
    let t0 = Instant::now();
    let answers: Vec<_> = q
        .run(fact(&r, vec![key, c]), RunConfig::default())
        .collect();
    println!(
        "point query color_of({}, C): {} answer(s) in {:?}",
        n / 2,
        answers.len(),
        t0.elapsed()
    );
}
