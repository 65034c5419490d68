//! Every window's facts of one Argoverse 2 log, timed: the load (Feather
//! tables, poses, map) and the facts, the number of windows and facts, and
//! the process's peak resident memory.
//!
//! ```text
//! cargo run --release -p perception --example av2_facts -- \
//!     ../shared/data/av2/scenario_mining/3b3570b4-7b0b-3268-a571-b0889dbf40b6
//! ```
//!
//! The argument is a log directory, with or without the `av2:` prefix.
//! Target (issue 32): ≤ 0.3 s and ≤ 150 MB for a 157-frame log.

use std::path::Path;
use std::time::Instant;

use perception::{FactConfig, WindowSpec, window_facts};

/// Peak resident set size in MB (`VmHWM` of `/proc/self/status`), where
/// the platform has it.
fn peak_rss_mb() -> Option<f64> {
    let status = std::fs::read_to_string("/proc/self/status").ok()?;
    let line = status.lines().find(|l| l.starts_with("VmHWM:"))?;
    let kb: f64 = line.split_whitespace().nth(1)?.parse().ok()?;
    Some(kb / 1024.0)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let Some(arg) = std::env::args().nth(1) else {
        return Err("usage: av2_facts [av2:]LOG_DIR".into());
    };
    let dir = arg.strip_prefix("av2:").unwrap_or(&arg);
    let start = Instant::now();
    let seq = perception::av2::load(Path::new(dir))?;
    let load_s = start.elapsed().as_secs_f64();
    let start = Instant::now();
    let windows = window_facts(&seq, WindowSpec::PAPER, &FactConfig::default())?;
    let facts_s = start.elapsed().as_secs_f64();
    let facts: usize = windows.iter().map(|w| w.facts.len()).sum();
    println!(
        "log {}: {} frames, {} tracks, {} observations, map: {}",
        seq.name,
        seq.frame_count,
        seq.track_keys.len(),
        seq.observations.len(),
        seq.map.as_ref().map_or("none".to_string(), |m| format!(
            "{} lanes, {} crossings, {} drivable areas",
            m.lanes.len(),
            m.crosswalks.len(),
            m.drivable_areas.len()
        ))
    );
    for s in &seq.skipped {
        println!("skipped {} ({}): e.g. {}", s.count, s.reason, s.example);
    }
    println!("load  {load_s:.3} s");
    println!(
        "facts {facts_s:.3} s: {} windows, {facts} facts",
        windows.len()
    );
    // The predicates with the most facts: where the time and memory go.
    let mut by_predicate: std::collections::BTreeMap<&str, usize> = Default::default();
    for f in windows.iter().flat_map(|w| &w.facts) {
        *by_predicate.entry(f.predicate.as_str()).or_default() += 1;
    }
    let mut top: Vec<(&str, usize)> = by_predicate.into_iter().collect();
    top.sort_by(|a, b| b.1.cmp(&a.1).then(a.0.cmp(b.0)));
    let top: Vec<String> = top
        .iter()
        .take(8)
        .map(|(p, n)| format!("{p} {n}"))
        .collect();
    println!("most facts: {}", top.join(", "));
    match peak_rss_mb() {
        Some(mb) => println!("peak RSS {mb:.1} MB"),
        None => println!("peak RSS unknown (no /proc/self/status)"),
    }
    Ok(())
}
