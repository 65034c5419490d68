//! Robustness of window facts to perception noise: for each built-in
//! scenario and a ladder of noise levels, the share of facts the event log
//! demands that come out, and the number of facts it forbids that come out
//! anyway, averaged over seeds.
//!
//! ```sh
//! cargo run --release -p perception --example sim_robustness -- [SEEDS]
//! ```

use perception::sim::truth::{contradictions, expected_facts, missing_facts};
use perception::sim::{BUILTIN_NAMES, NoisePreset, NoiseSpec, Scenario, simulate};
use perception::{FactConfig, WindowSpec, window_facts};

fn main() {
    if let Err(e) = run() {
        eprintln!("error: {e}");
        std::process::exit(1);
    }
}

fn run() -> Result<(), Box<dyn std::error::Error>> {
    let seeds: u64 = std::env::args()
        .nth(1)
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(10);
    let config = FactConfig::default();
    let levels: Vec<(&str, Option<NoiseSpec>)> = NoisePreset::ALL
        .iter()
        .map(|p| (p.name(), p.spec()))
        .collect();
    println!(
        "{:<16} {:<8} {:>10} {:>14}",
        "scenario", "noise", "recall", "contradictions"
    );
    for name in BUILTIN_NAMES {
        for (label, noise) in &levels {
            let mut scenario = Scenario::builtin(name)?;
            scenario.noise = *noise;
            let (mut demanded, mut missing, mut contra) = (0usize, 0usize, 0usize);
            let mut by_pred: std::collections::BTreeMap<String, usize> = Default::default();
            let runs = if noise.is_some() { seeds } else { 1 };
            for seed in 0..runs {
                let run = simulate(&scenario, seed)?;
                let ws = window_facts(&run.sequence, WindowSpec::PAPER, &config)?;
                demanded += expected_facts(&run, &ws, &config).len();
                missing += missing_facts(&run, &ws, &config).len();
                let c = contradictions(&run, &ws);
                contra += c.len();
                for f in c {
                    let pred = f.fact.split('(').next().unwrap_or_default().to_string();
                    *by_pred.entry(pred).or_default() += 1;
                }
            }
            let recall = if demanded > 0 {
                1.0 - missing as f64 / demanded as f64
            } else {
                1.0
            };
            let kinds: Vec<String> = by_pred
                .iter()
                .map(|(p, n)| format!("{p} {:.1}", *n as f64 / runs as f64))
                .collect();
            println!(
                "{name:<16} {label:<8} {:>9.1}% {:>14.1}  {}",
                100.0 * recall,
                contra as f64 / runs as f64,
                kinds.join(", ")
            );
        }
    }
    Ok(())
}
