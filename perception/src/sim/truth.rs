//! Comparing window facts with the simulator's event log: which facts the
//! log *demands* ([`expected_facts`]) and which facts it *forbids*
//! ([`forbidden_facts`]; [`contradictions`] are the forbidden facts that
//! perception produced). Used by the property tests and to measure
//! robustness under noise.

use serde::{Deserialize, Serialize};

use super::run::{Event, EventKind, SimRun};
use crate::config::FactConfig;
use crate::model::WindowFacts;

/// A fact that should (or must not) hold in a window, with the event behind it.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Finding {
    /// Window index.
    pub window: u32,
    /// The fact in KB syntax, e.g. `SpeedUp(car_1)`.
    pub fact: String,
    /// The event that demands or forbids it.
    pub event: Event,
}

fn kb(pred: &str, args: &[&str]) -> String {
    format!("{pred}({})", args.join(", "))
}

fn visible_all(run: &SimRun, name: &str, first: u32, last: u32) -> bool {
    (first..=last).all(|f| {
        run.visible
            .get(f as usize)
            .is_some_and(|v| v.contains(name))
    })
}

/// Facts the event log forbids in each window, whatever perception said:
/// an event covering the whole window rules out `Moving` (parked, stopped,
/// standing), the opposite speed trend (accelerating vs `SpeedDown`,
/// braking vs `SpeedUp`, constant speed vs either), and the opposite
/// distance trend (approaching vs `DistanceIncrease`, receding vs
/// `DistanceDecrease`), both ways for pairs.
pub fn forbidden_facts(run: &SimRun, windows: &[WindowFacts]) -> Vec<Finding> {
    let mut out = Vec::new();
    for w in windows {
        for e in run
            .events
            .iter()
            .filter(|e| e.covers(w.first_frame, w.last_frame))
        {
            let x = e.object.as_str();
            let forbidden: Vec<String> = match (e.kind, e.other.as_deref()) {
                (EventKind::Parked | EventKind::Stop | EventKind::Stand, _) => {
                    vec![kb("Moving", &[x])]
                }
                (EventKind::Accelerate, _) => vec![kb("SpeedDown", &[x])],
                (EventKind::Brake, _) => vec![kb("SpeedUp", &[x])],
                (EventKind::ConstantSpeed, _) => vec![kb("SpeedUp", &[x]), kb("SpeedDown", &[x])],
                (EventKind::Approach, Some(y)) => vec![
                    kb("DistanceIncrease", &[x, y]),
                    kb("DistanceIncrease", &[y, x]),
                ],
                (EventKind::Recede, Some(y)) => vec![
                    kb("DistanceDecrease", &[x, y]),
                    kb("DistanceDecrease", &[y, x]),
                ],
                _ => vec![],
            };
            out.extend(forbidden.into_iter().map(|fact| Finding {
                window: w.index,
                fact,
                event: e.clone(),
            }));
        }
    }
    out
}

/// The forbidden facts ([`forbidden_facts`]) that perception produced.
pub fn contradictions(run: &SimRun, windows: &[WindowFacts]) -> Vec<Finding> {
    forbidden_facts(run, windows)
        .into_iter()
        .filter(|f| {
            windows
                .iter()
                .find(|w| w.index == f.window)
                .is_some_and(|w| w.facts.iter().any(|g| g.to_kb_line() == f.fact))
        })
        .collect()
}

/// Facts the event log demands, for events clear enough to be measured
/// (magnitudes at least twice the fact threshold, objects visible in every
/// frame of the window):
/// - accelerating → `SpeedUp`, braking → `SpeedDown`, constant speed or
///   walking above the moving threshold → `Moving`;
/// - approaching → `DistanceDecrease` both ways;
/// - entering the view at frame `f` → `Appear` in windows holding `f` where
///   the object was not visible earlier in the window nor in the look-back;
/// - crossing a road → `On(x, road)`, walking on a sidewalk → `On(x, sidewalk)`.
pub fn expected_facts(run: &SimRun, windows: &[WindowFacts], config: &FactConfig) -> Vec<Finding> {
    let mut out = Vec::new();
    let fps = run.sequence.fps;
    for w in windows {
        let (a, b) = (w.first_frame, w.last_frame);
        let span = f64::from(b - a) / fps;
        for e in &run.events {
            let x = e.object.as_str();
            let demanded: Vec<String> = match (e.kind, e.other.as_deref()) {
                (EventKind::AppearInView, _) => {
                    let f = e.first_frame;
                    let look = f.saturating_sub(config.appear_lookback_frames).min(a);
                    let unseen_before = (look..f)
                        .all(|g| run.visible.get(g as usize).is_some_and(|v| !v.contains(x)));
                    if a <= f && f <= b && f > 0 && unseen_before {
                        vec![kb("Appear", &[x])]
                    } else {
                        vec![]
                    }
                }
                _ if !e.covers(a, b)
                    || !visible_all(run, x, a, b)
                    || b - a + 1 < config.min_observations + 2 =>
                {
                    vec![]
                }
                (EventKind::Accelerate, _)
                    if e.magnitude >= 2.0 * config.speed_change_mps2
                        && e.magnitude * span >= 2.0 * config.speed_change_min_mps =>
                {
                    vec![kb("SpeedUp", &[x])]
                }
                (EventKind::Brake, _)
                    if -e.magnitude >= 2.0 * config.speed_change_mps2
                        && -e.magnitude * span >= 2.0 * config.speed_change_min_mps =>
                {
                    vec![kb("SpeedDown", &[x])]
                }
                (EventKind::ConstantSpeed, _)
                    if e.magnitude >= 2.0 * config.moving_speed_vehicle_mps =>
                {
                    vec![kb("Moving", &[x])]
                }
                (EventKind::CrossRoad | EventKind::WalkOnSidewalk, Some(y))
                    if visible_all(run, y, a, b) =>
                {
                    let mut v = vec![kb("On", &[x, y])];
                    if e.magnitude >= 2.0 * config.moving_speed_pedestrian_mps {
                        v.push(kb("Moving", &[x]));
                    }
                    v
                }
                (EventKind::Approach, Some(y))
                    if visible_all(run, y, a, b)
                        && -e.magnitude >= 2.0 * config.distance_rate_mps
                        && -e.magnitude * span >= 2.0 * config.distance_change_min_m =>
                {
                    vec![
                        kb("DistanceDecrease", &[x, y]),
                        kb("DistanceDecrease", &[y, x]),
                    ]
                }
                _ => vec![],
            };
            for f in demanded {
                out.push(Finding {
                    window: w.index,
                    fact: f,
                    event: e.clone(),
                });
            }
        }
    }
    out
}

/// The demanded facts that are missing from the windows.
pub fn missing_facts(run: &SimRun, windows: &[WindowFacts], config: &FactConfig) -> Vec<Finding> {
    expected_facts(run, windows, config)
        .into_iter()
        .filter(|f| {
            windows
                .iter()
                .find(|w| w.index == f.window)
                .is_none_or(|w| !w.facts.iter().any(|g| g.to_kb_line() == f.fact))
        })
        .collect()
}
