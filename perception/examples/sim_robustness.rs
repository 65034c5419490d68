//! Robustness of window facts to perception noise: for each built-in
//! scenario and a ladder of noise levels, the share of facts the event log
//! demands that come out, and the number of facts it forbids that come out
//! anyway, averaged over seeds.
//!
//! ```sh
//! cargo run --release -p perception --example sim_robustness -- [SEEDS]
//! ```

use perception::sim::truth::{contradictions, expected_facts, missing_facts};
use perception::sim::{BUILTIN_NAMES, NoiseSpec, Scenario, simulate};
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
    let levels = [
        ("none", None),
        (
            "low",
            Some(NoiseSpec {
                position_sigma_m: 0.05,
                depth_sigma_fraction: 0.005,
                box_jitter_px: 1.0,
                miss_probability: 0.01,
                id_switch_probability: 0.0,
            }),
        ),
        ("default", Some(NoiseSpec::default())),
        (
            "high",
            Some(NoiseSpec {
                position_sigma_m: 0.3,
                depth_sigma_fraction: 0.03,
                box_jitter_px: 4.0,
                miss_probability: 0.1,
                id_switch_probability: 0.005,
            }),
        ),
    ];
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
