//! The ego's facts against the simulator's own ego path: its speed and
//! heading from the scene states (the camera pose of every frame), never
//! from perception's estimate; its relations never those of a collision;
//! `Near(x, ego)` in step with the `Near*` locations.

use perception::facts::EGO;
use perception::sim::{BUILTIN_NAMES, Scenario, SimRun, simulate};
use perception::{FactConfig, WindowFacts, WindowSpec, window_facts};

fn run(name: &str) -> (SimRun, Vec<WindowFacts>) {
    let run = simulate(&Scenario::builtin(name).unwrap(), 0).unwrap();
    let ws = window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default()).unwrap();
    (run, ws)
}

fn has(w: &WindowFacts, line: &str) -> bool {
    w.facts.iter().any(|f| f.to_kb_line() == line)
}

/// The true ego speed (m/s) into frame `f` (from `f − 1`), from the
/// simulator's camera poses.
fn true_speed(run: &SimRun, f: u32) -> f64 {
    let p = |f: u32| run.states[f as usize].camera_pose.position;
    let (a, b) = (p(f - 1), p(f));
    (b[0] - a[0]).hypot(b[2] - a[2]) * run.sequence.fps
}

#[test]
fn the_ego_moves_speeds_up_and_slows_down_as_the_simulated_ego_does() {
    let cfg = FactConfig::default();
    let mut checked = 0;
    for name in [
        "braking",
        "intersection",
        "parking_lot",
        "highway_merge",
        "collision",
    ] {
        let (run, ws) = run(name);
        for w in &ws {
            let (a, b) = (w.first_frame.max(1), w.last_frame);
            let speeds: Vec<f64> = (a..=b).map(|f| true_speed(&run, f)).collect();
            let mean = speeds.iter().sum::<f64>() / speeds.len() as f64;
            let change = speeds[speeds.len() - 1] - speeds[0];
            let why = format!("{name} window {} speeds {speeds:.2?}", w.index);
            assert!(has(w, "Ego(ego)"), "{why}");
            // Clear cases only: well beyond or well below the thresholds.
            if mean > 2.0 * cfg.moving_speed_vehicle_mps {
                assert!(has(w, "Moving(ego)"), "{why}");
                checked += 1;
            }
            if mean < 0.5 * cfg.moving_speed_vehicle_mps && speeds.iter().all(|v| *v < 1.0) {
                assert!(!has(w, "Moving(ego)"), "{why}");
                checked += 1;
            }
            let span = f64::from(b - a) / run.sequence.fps;
            if change > 2.0 * cfg.speed_change_min_mps
                && change / span > 2.0 * cfg.speed_change_mps2
            {
                assert!(has(w, "SpeedUp(ego)") && !has(w, "SpeedDown(ego)"), "{why}");
                checked += 1;
            }
            if -change > 2.0 * cfg.speed_change_min_mps
                && -change / span > 2.0 * cfg.speed_change_mps2
            {
                assert!(has(w, "SpeedDown(ego)") && !has(w, "SpeedUp(ego)"), "{why}");
                checked += 1;
            }
            if speeds.iter().all(|v| (v - speeds[0]).abs() < 1e-6) {
                assert!(
                    !has(w, "SpeedUp(ego)") && !has(w, "SpeedDown(ego)"),
                    "{why}"
                );
                checked += 1;
            }
        }
    }
    assert!(checked > 30, "only {checked} clear windows");
}

#[test]
fn the_ego_turns_right_where_the_simulated_heading_turns_right() {
    let cfg = FactConfig::default();
    // parking_lot: a 15° right turn over frames 40–60 (6.75° per window).
    let (run, ws) = run("parking_lot");
    let mut turned = Vec::new();
    for w in &ws {
        let yaw = |f: u32| run.states[f as usize].camera_pose.yaw.to_degrees();
        let change = yaw(w.last_frame) - yaw(w.first_frame);
        let why = format!("window {} heading change {change:.2}°", w.index);
        assert!(!has(w, "TurnLeft(ego)"), "{why}");
        if change > cfg.turn_min_deg + 1.0 {
            assert!(has(w, "TurnRight(ego)"), "{why}");
            turned.push(w.index);
        } else if change.abs() < cfg.turn_min_deg - 1.0 {
            assert!(!has(w, "TurnRight(ego)"), "{why}");
        }
    }
    assert_eq!(turned, [4, 5]);
    let f = ws[4]
        .facts
        .iter()
        .find(|f| f.to_kb_line() == "TurnRight(ego)")
        .unwrap();
    assert!((f.provenance.measured.unwrap() - 6.75).abs() < 0.1, "{f:?}");
    assert_eq!(f.provenance.threshold, Some(("turn_min_deg".into(), 5.0)));
}

#[test]
fn the_ego_is_no_vehicle_and_never_in_a_collision_fact() {
    for name in BUILTIN_NAMES {
        let (_, ws) = run(name);
        for w in &ws {
            for f in w.facts.iter().filter(|f| f.args.iter().any(|a| a == EGO)) {
                assert!(
                    !matches!(
                        &*f.predicate,
                        "Vehicles"
                            | "TypeOf"
                            | "ColorOf"
                            | "TooClose"
                            | "DistanceZeroStart"
                            | "DistanceZeroEnd"
                            | "DistanceDecreasesToZero"
                            | "Closer"
                    ),
                    "{name} window {}: {}",
                    w.index,
                    f.to_kb_line()
                );
            }
        }
    }
}

#[test]
fn near_us_agrees_with_the_near_locations_in_every_builtin_scenario() {
    let cfg = FactConfig::default();
    for name in BUILTIN_NAMES {
        let (_, ws) = run(name);
        for w in &ws {
            for f in &w.facts {
                let near_location = matches!(&*f.predicate, "InitialLocation" | "LastLocation")
                    && f.args[1].starts_with("Near");
                if near_location {
                    let want = format!("Near({}, ego)", f.args[0]);
                    // Ground regions lie under us: never `Near`.
                    let region = ["road_", "sidewalk_", "lane_marking_", "terrain_"]
                        .iter()
                        .any(|p| f.args[0].starts_with(p));
                    assert!(
                        region || has(w, &want),
                        "{name} window {}: {} without {want}",
                        w.index,
                        f.to_kb_line()
                    );
                }
                if f.predicate == "Near" {
                    let z = f.provenance.measured.unwrap();
                    assert!(z < cfg.near_far_m, "{}", f.to_kb_line());
                    let (x, y) = (&f.args[0], &f.args[1]);
                    assert!(x == EGO || y == EGO, "{}", f.to_kb_line());
                    assert!(has(w, &format!("Near({y}, {x})")), "{}", f.to_kb_line());
                }
            }
        }
    }
}
