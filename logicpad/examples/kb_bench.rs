//! The shared KB benchmark (`../shared/bench/README.md`) on logicpad:
//! `cargo run --release -p logicpad --example kb_bench -- DIR [--ask] [--proofs] [--reps N] [--slow]`
//! where DIR is a generated dataset such as `target/kb-bench/kitti`.
//! Prints load / rules / queries seconds and checks every answer count
//! against `expected.tsv` (exit code 1 on any difference).

use logicpad::{FactBase, LogicPad, RunConfig, parse_query};
use std::collections::BTreeMap;
use std::time::{Duration, Instant};

fn main() {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let dir = args
        .first()
        .cloned()
        .unwrap_or_else(|| "target/kb-bench/kitti".into());
    let proofs = args.iter().any(|a| a == "--proofs");
    // Every form runs the query's kanren program: `--ask` lists the answers
    // (Model::ask), `--proofs` with their proofs; the default counts them
    // (Model::count).
    let list_answers = proofs || args.iter().any(|a| a == "--ask");
    // `--slow` prints each query that takes more than 5 ms (last rep only).
    let show_slow = args.iter().any(|a| a == "--slow");
    let reps: usize = args
        .iter()
        .position(|a| a == "--reps")
        .and_then(|i| args.get(i + 1))
        .and_then(|s| s.parse().ok())
        .unwrap_or(3);
    let pad = match LogicPad::load(format!("{dir}/rules.yaml")) {
        Ok(p) => p,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let errors = pad.diagnostics().iter().filter(|d| d.is_error()).count();
    println!(
        "rules.yaml: {} rules, {} diagnostics ({errors} errors)",
        pad.program().rules().len(),
        pad.diagnostics().len()
    );
    let read = |name: &str| std::fs::read_to_string(format!("{dir}/{name}")).unwrap_or_default();
    let mut queries: BTreeMap<String, Vec<String>> = BTreeMap::new();
    for line in read("queries.tsv").lines() {
        if let Some((w, q)) = line.split_once('\t') {
            queries
                .entry(w.to_string())
                .or_default()
                .push(q.to_string());
        }
    }
    let mut expected: BTreeMap<(String, usize), usize> = BTreeMap::new();
    for line in read("expected.tsv").lines() {
        let f: Vec<&str> = line.split('\t').collect();
        if let [w, i, _, n] = f[..] {
            expected.insert(
                (w.to_string(), i.parse().unwrap_or(0)),
                n.parse().unwrap_or(0),
            );
        }
    }
    // Facts texts are read once, outside the timing (the SWI run reads a
    // pre-translated data.pl too); parsing them is timed as "load".
    let facts: Vec<(String, String)> = queries
        .keys()
        .map(|w| (w.clone(), read(&format!("facts/{w}.facts"))))
        .collect();
    let mut best = (
        Duration::MAX,
        Duration::ZERO,
        Duration::ZERO,
        Duration::ZERO,
    );
    let mut mismatches = 0;
    let mut derived = 0;
    for rep in 0..reps {
        let cpu0 = cpu_seconds();
        let (mut tl, mut tr, mut tq) = (Duration::ZERO, Duration::ZERO, Duration::ZERO);
        mismatches = 0;
        derived = 0;
        for (w, text) in &facts {
            let t0 = Instant::now();
            let fb = match FactBase::from_text(text, w) {
                Ok(fb) => fb,
                Err(e) => {
                    eprintln!("{e}");
                    std::process::exit(2);
                }
            };
            let t1 = Instant::now();
            let model = match pad.program().evaluate(fb) {
                Ok(m) => m,
                Err(e) => {
                    eprintln!("{w}: {e}");
                    std::process::exit(2);
                }
            };
            derived += model.stats().derived_facts;
            let t2 = Instant::now();
            for (i, q) in queries
                .get(w)
                .map(Vec::as_slice)
                .unwrap_or(&[])
                .iter()
                .enumerate()
            {
                let tq0 = Instant::now();
                let n = match parse_query(q) {
                    Ok(ast) => match if list_answers {
                        model
                            .ask(
                                &ast,
                                RunConfig {
                                    proofs,
                                    ..RunConfig::default()
                                },
                            )
                            .map(|a| a.len())
                    } else {
                        model.count(&ast)
                    } {
                        Ok(n) => n,
                        Err(e) => {
                            eprintln!("{w} #{i} {q}: {e}");
                            usize::MAX
                        }
                    },
                    Err(e) => {
                        eprintln!("{w} #{i} {q}: {}", e.summary());
                        usize::MAX
                    }
                };
                let took = tq0.elapsed();
                if show_slow && rep + 1 == reps && took > Duration::from_millis(5) {
                    println!("  {:.1} ms  {w} #{i} {q} -> {n}", took.as_secs_f64() * 1e3);
                }
                if expected.get(&(w.clone(), i)) != Some(&n) {
                    mismatches += 1;
                    if mismatches <= 5 {
                        eprintln!(
                            "MISMATCH {w} #{i} {q}: got {n}, expected {:?}",
                            expected.get(&(w.clone(), i))
                        );
                    }
                }
            }
            let t3 = Instant::now();
            tl += t1 - t0;
            tr += t2 - t1;
            tq += t3 - t2;
        }
        let total = tl + tr + tq;
        let cpu = match (cpu0, cpu_seconds()) {
            (Some(a), Some(b)) => format!("{:.2} s", b - a),
            _ => "n/a".into(),
        };
        println!(
            "rep {rep}: load {:.3} s, rules {:.3} s, queries {:.3} s, total {:.3} s wall; process CPU {cpu}",
            tl.as_secs_f64(),
            tr.as_secs_f64(),
            tq.as_secs_f64(),
            total.as_secs_f64()
        );
        if total < best.0 {
            best = (total, tl, tr, tq);
        }
    }
    println!(
        "best of {reps}: total {:.3} s (load {:.3}, rules {:.3}, queries {:.3}); {} windows, {} derived facts, {} queries, {mismatches} mismatches",
        best.0.as_secs_f64(),
        best.1.as_secs_f64(),
        best.2.as_secs_f64(),
        best.3.as_secs_f64(),
        facts.len(),
        derived,
        expected.len()
    );
    if mismatches > 0 {
        std::process::exit(1);
    }
}

/// User + system CPU seconds of this process (Linux `/proc/self/stat`,
/// 10 ms ticks): on a shared, loaded machine wall time overstates the cost.
fn cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/self/stat").ok()?;
    let rest = stat.rsplit_once(')')?.1;
    let fields: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = fields.get(11)?.parse().ok()?;
    let stime: f64 = fields.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}
