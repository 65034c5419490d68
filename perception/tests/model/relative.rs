//! Relative-position pair facts (`LeftOf`, `RightOf`, `InFrontOf`,
//! `Behind`) over the simulator's built-in scenarios: each predicate comes
//! out somewhere, every emitted fact has its converse in the same window,
//! no pair is ordered both ways, and provenance carries a measurement at or
//! beyond its threshold. The simulator knows the true camera-frame
//! positions, so the noiseless facts are also checked against them.

use std::collections::{BTreeMap, BTreeSet};

use perception::sim::{BUILTIN_NAMES, NoiseSpec, Scenario, SimRun, simulate};
use perception::{FactConfig, WindowFacts, WindowSpec, window_facts};

const RELATIVE: [(&str, &str); 4] = [
    ("LeftOf", "RightOf"),
    ("RightOf", "LeftOf"),
    ("InFrontOf", "Behind"),
    ("Behind", "InFrontOf"),
];

fn converse(predicate: &str) -> Option<&'static str> {
    RELATIVE
        .iter()
        .find(|(p, _)| *p == predicate)
        .map(|(_, c)| *c)
}

fn run(name: &str, noise: Option<NoiseSpec>, seed: u64) -> (SimRun, Vec<WindowFacts>) {
    let mut scenario = Scenario::builtin(name).unwrap();
    scenario.noise = noise;
    let run = simulate(&scenario, seed).unwrap();
    let ws = window_facts(&run.sequence, WindowSpec::PAPER, &FactConfig::default()).unwrap();
    (run, ws)
}

/// The converse, exclusivity and provenance properties for one run; returns
/// how many facts of each predicate it saw.
fn check_properties(label: &str, ws: &[WindowFacts], counts: &mut [usize; 4]) {
    for w in ws {
        for f in &w.facts {
            let Some(conv) = converse(&f.predicate) else {
                continue;
            };
            let k = RELATIVE
                .iter()
                .position(|(p, _)| *p == f.predicate)
                .unwrap();
            counts[k] += 1;
            let [x, y] = [&f.args[0], &f.args[1]];
            assert_ne!(x, y, "{label} w{}: {}", w.index, f.to_kb_line());
            assert!(
                w.contains(conv, &[y, x]),
                "{label} w{}: {} without {conv}({y}, {x})",
                w.index,
                f.to_kb_line()
            );
            // Opposite directions exclude each other: LeftOf(x, y) and
            // LeftOf(y, x) (equivalently RightOf(x, y)) never both hold.
            assert!(
                !w.contains(conv, &[x, y]),
                "{label} w{}: both {} and {conv}({x}, {y})",
                w.index,
                f.to_kb_line()
            );
            let p = &f.provenance;
            assert_eq!(
                (p.window, p.frames),
                (w.index, (w.first_frame, w.last_frame))
            );
            let (Some(m), Some((field, thr))) = (p.measured, &p.threshold) else {
                panic!(
                    "{label}: {} has no measurement or threshold",
                    f.to_kb_line()
                );
            };
            assert!(field.starts_with("relative."), "{label}: {field}");
            assert!(
                m >= *thr && m > 0.0,
                "{label} w{}: {} measured {m} below {field} {thr}",
                w.index,
                f.to_kb_line()
            );
        }
    }
}

#[test]
fn every_relative_fact_over_the_builtin_scenarios_has_its_converse() {
    let mut counts = [0usize; 4];
    for name in BUILTIN_NAMES {
        let (_, ws) = run(name, None, 0);
        check_properties(name, &ws, &mut counts);
        // Noise changes the measurements, never the properties.
        for seed in 1..=3 {
            let (_, ws) = run(name, Some(NoiseSpec::default()), seed);
            check_properties(&format!("{name}@{seed}"), &ws, &mut counts);
        }
    }
    for ((p, _), n) in RELATIVE.iter().zip(counts) {
        assert!(n > 0, "no scenario yields {p}");
    }
}

#[test]
fn each_relative_predicate_comes_out_of_some_noiseless_scenario() {
    let mut seen = [Vec::new(), Vec::new(), Vec::new(), Vec::new()];
    for name in BUILTIN_NAMES {
        let (_, ws) = run(name, None, 0);
        for (k, (p, _)) in RELATIVE.iter().enumerate() {
            if ws.iter().flat_map(|w| &w.facts).any(|f| f.predicate == *p) {
                seen[k].push(name);
            }
        }
    }
    for ((p, _), names) in RELATIVE.iter().zip(&seen) {
        assert!(!names.is_empty(), "no built-in scenario yields {p}");
    }
}

/// The relative facts between the simulator's dynamic objects that the true
/// camera-frame positions demand in frames `first..=last`, computed from the
/// scene states (not from the observations) by the documented rule.
fn truth_relations(run: &SimRun, first: u32, last: u32, cfg: &FactConfig) -> BTreeSet<String> {
    let rel = &cfg.relative;
    // name -> frame -> camera-frame ground point (X, Z), visible frames only.
    let mut at: BTreeMap<&str, BTreeMap<u32, [f64; 2]>> = BTreeMap::new();
    for s in &run.states[first as usize..=last as usize] {
        for o in s.objects.iter().filter(|o| o.visible) {
            let c = o.camera.center;
            at.entry(&o.name).or_default().insert(s.frame, [c[0], c[2]]);
        }
    }
    let beyond = |d: f64, min: f64| d > 0.0 && d >= min;
    let mut out = BTreeSet::new();
    let names: Vec<&str> = at.keys().copied().collect();
    for (i, x) in names.iter().enumerate() {
        for y in &names[i + 1..] {
            let (px, py) = (&at[x], &at[y]);
            let both: Vec<([f64; 2], [f64; 2])> = px
                .iter()
                .filter_map(|(f, a)| py.get(f).map(|b| (*a, *b)))
                .collect();
            let n = both.len();
            if n < cfg.min_observations as usize {
                continue;
            }
            let count = |p: &dyn Fn(f64, f64) -> bool| {
                both.iter()
                    .filter(|(a, b)| p(b[0] - a[0], a[1] - b[1]))
                    .count()
            };
            let wins = |k: usize| k as f64 > rel.min_frame_fraction * n as f64;
            let ahead =
                |dx: f64, dz: f64| dx.abs() <= rel.corridor_m && beyond(dz, rel.forward_min_m);
            for (holds, facts) in [
                (
                    wins(count(&|dx, _| beyond(dx, rel.lateral_min_m))),
                    [("LeftOf", x, y), ("RightOf", y, x)],
                ),
                (
                    wins(count(&|dx, _| beyond(-dx, rel.lateral_min_m))),
                    [("LeftOf", y, x), ("RightOf", x, y)],
                ),
                (
                    wins(count(&|dx, dz| ahead(dx, dz))),
                    [("InFrontOf", x, y), ("Behind", y, x)],
                ),
                (
                    wins(count(&|dx, dz| ahead(dx, -dz))),
                    [("InFrontOf", y, x), ("Behind", x, y)],
                ),
            ] {
                if holds {
                    for (p, a, b) in facts {
                        out.insert(format!("{p}({a}, {b})"));
                    }
                }
            }
        }
    }
    out
}

#[test]
fn noiseless_relative_facts_between_road_users_match_the_true_positions() {
    let cfg = FactConfig::default();
    let mut compared = 0;
    for name in BUILTIN_NAMES {
        let (run, ws) = run(name, None, 0);
        let dynamic: BTreeSet<&str> = run
            .states
            .iter()
            .flat_map(|s| s.objects.iter().map(|o| o.name.as_str()))
            .collect();
        for w in &ws {
            let got: BTreeSet<String> = w
                .facts
                .iter()
                .filter(|f| converse(&f.predicate).is_some())
                .filter(|f| f.args.iter().all(|a| dynamic.contains(a.as_str())))
                .map(|f| f.to_kb_line())
                .collect();
            let want = truth_relations(&run, w.first_frame, w.last_frame, &cfg);
            assert_eq!(got, want, "{name} window {}", w.index);
            compared += want.len();
        }
    }
    assert!(compared > 100, "only {compared} facts compared");
}
