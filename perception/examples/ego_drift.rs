//! Ego-motion drift against the simulator's true camera poses: per built-in
//! scenario and noise preset, the mean and worst error (m) of the camera's
//! displacement across a 10-frame window, averaged over seeds.
//!
//! ```sh
//! cargo run -p perception --example ego_drift -- [SEEDS]
//! ```

use perception::sim::{BUILTIN_NAMES, NoisePreset, Scenario, simulate};
use perception::{FactConfig, ego};

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
        .unwrap_or(5);
    let config = FactConfig::default();
    println!(
        "{:<16} {:<8} {:>10} {:>10} {:>9}",
        "scenario", "noise", "mean_m", "worst_m", "fallback"
    );
    for name in BUILTIN_NAMES {
        for preset in NoisePreset::ALL {
            let mut scenario = Scenario::builtin(name)?;
            scenario.noise = preset.spec();
            let (mut sum, mut n, mut worst, mut fb, mut steps) =
                (0.0, 0usize, 0.0f64, 0usize, 0usize);
            for seed in 0..seeds {
                let run = simulate(&scenario, seed)?;
                let est = ego::estimate(&run.sequence, &config.ego);
                fb += est.steps.iter().skip(1).filter(|s| s.fallback).count();
                steps += est.steps.len() - 1;
                let truth: Vec<_> = run.states.iter().map(|s| s.camera_pose).collect();
                let t0 = truth[0];
                // True camera positions in the frame-0 camera frame.
                let rel = |p: &perception::model::CameraPose| {
                    let c = t0.world_to_camera(perception::WorldPoint(nalgebra::Point3::from(
                        p.position,
                    )));
                    (c.0.x, c.0.z)
                };
                let mut f = 0;
                while f + 9 < truth.len() {
                    let (ax, az) = rel(&truth[f]);
                    let (bx, bz) = rel(&truth[f + 9]);
                    let pa = est.poses[f].position.0;
                    let pb = est.poses[f + 9].position.0;
                    let e = (((pb.x - pa.x) - (bx - ax)).powi(2)
                        + ((pb.y - pa.y) - (bz - az)).powi(2))
                    .sqrt();
                    sum += e;
                    n += 1;
                    worst = worst.max(e);
                    f += 10;
                }
            }
            println!(
                "{name:<16} {:<8} {:>10.3} {:>10.3} {:>9.3}",
                preset.name(),
                sum / n.max(1) as f64,
                worst,
                fb as f64 / steps.max(1) as f64
            );
        }
    }
    Ok(())
}
