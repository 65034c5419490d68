//! KITTI labels → window facts for every sequence, timed: prints per
//! sequence frames, ego-motion fallbacks, mean ego speed and facts, then the
//! overall frames per second on one core. Run in release mode:
//!
//! ```sh
//! cargo run --release -p perception --example kitti_fps -- ../shared/data/kitti-tracking
//! ```

use std::time::Instant;

use perception::{FactConfig, WindowSpec};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let root = std::env::args()
        .nth(1)
        .unwrap_or_else(|| "../shared/data/kitti-tracking".to_string());
    let root = std::path::Path::new(&root);
    let config = FactConfig::default();
    let names = perception::kitti::list_sequences(root)?;
    let seqs: Vec<_> = names
        .iter()
        .map(|n| perception::kitti::load(root, n).map(|l| l.sequence))
        .collect::<Result<_, _>>()?;
    println!(
        "{:<6} {:>6} {:>9} {:>10} {:>8}",
        "seq", "frames", "fallback", "ego m/s", "facts"
    );
    let mut frames = 0u64;
    for s in &seqs {
        let a = perception::Analysis::new(s, &config)?;
        let fallbacks = a.ego.steps.iter().skip(1).filter(|st| st.fallback).count();
        let speed: f64 = (1..s.frame_count)
            .map(|f| a.ego.speed(f, s.fps))
            .sum::<f64>()
            / f64::from(s.frame_count.max(2) - 1);
        let facts: usize = perception::window_facts(s, WindowSpec::PAPER, &config)?
            .iter()
            .map(|w| w.facts.len())
            .sum();
        println!(
            "{:<6} {:>6} {:>9} {:>10.2} {:>8}",
            s.name, s.frame_count, fallbacks, speed, facts
        );
        frames += u64::from(s.frame_count);
    }
    // Timed pass: labels already parsed; facts for all windows of all sequences.
    let rounds = 5;
    let cpu0 = thread_cpu_seconds();
    let start = Instant::now();
    let mut total = 0usize;
    for _ in 0..rounds {
        for s in &seqs {
            total += perception::window_facts(s, WindowSpec::PAPER, &config)?.len();
        }
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "facts: {} frames x {rounds} rounds in {secs:.3} s wall = {:.0} frames/s ({total} windows)",
        frames,
        (frames * rounds) as f64 / secs
    );
    // On a shared machine wall time includes waiting for a core; CPU time of
    // this thread is what one core actually spent.
    if let (Some(a), Some(b)) = (cpu0, thread_cpu_seconds())
        && b > a
    {
        println!(
            "facts: {:.3} s of this thread's CPU time = {:.0} frames/s per CPU-second",
            b - a,
            (frames * rounds) as f64 / (b - a)
        );
    }
    let start = Instant::now();
    for n in &names {
        let s = perception::kitti::load(root, n)?.sequence;
        perception::window_facts(&s, WindowSpec::PAPER, &config)?;
    }
    let secs = start.elapsed().as_secs_f64();
    println!(
        "parse + facts: {frames} frames in {secs:.3} s = {:.0} frames/s",
        frames as f64 / secs
    );
    Ok(())
}

/// CPU time of the current thread from `/proc/thread-self/stat` (Linux;
/// `None` elsewhere), in seconds at the usual 100 ticks per second.
fn thread_cpu_seconds() -> Option<f64> {
    let stat = std::fs::read_to_string("/proc/thread-self/stat").ok()?;
    // Fields after the parenthesised command name; utime and stime are the
    // 14th and 15th fields of the whole line.
    let rest = stat.rsplit_once(')')?.1;
    let f: Vec<&str> = rest.split_whitespace().collect();
    let utime: f64 = f.get(11)?.parse().ok()?;
    let stime: f64 = f.get(12)?.parse().ok()?;
    Some((utime + stime) / 100.0)
}
