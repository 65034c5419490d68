//! Argoverse 2 logs end to end at the perception level: the facts of the two
//! scenario-mining logs in `../shared/data/av2/` checked against values
//! computed independently from the Feather and map files by
//! `scripts/av2_expected.py` (pyarrow and numpy, not logicrag) into
//! `tests/data/av2_expected.json`: each track's category, bearing-based
//! sides, crosswalk occupancy, turns and parked objects.
//!
//! The checks are on robust cases only (the script keeps bearings 10° away
//! from a sector's edge, pedestrians inside a crossing in every frame of a
//! window or 8 m away from all of them, turns of over 80°).

use std::collections::{BTreeMap, BTreeSet};

use perception::{FactConfig, Source, WindowFacts, WindowSpec, window_facts};
use serde_json::Value;

struct Log {
    expected: Value,
    windows: Vec<WindowFacts>,
    skipped: Vec<perception::Skipped>,
    map_sizes: (usize, usize, usize),
    frames: u32,
    /// Short key (`0f3c9a1e`) → object constant.
    names: BTreeMap<String, String>,
}

fn logs() -> Option<Vec<Log>> {
    let Some(shared) = integration_tests::shared_dir() else {
        integration_tests::missing_input("../shared is not present");
        return None;
    };
    let text = std::fs::read_to_string(
        std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("data/av2_expected.json"),
    )
    .expect("tests/data/av2_expected.json");
    let all: Vec<Value> = serde_json::from_str(&text).expect("expected facts JSON");
    let mut out = Vec::new();
    for expected in all {
        let log = expected["log"].as_str().expect("log name").to_string();
        let dir = shared.join("data/av2/scenario_mining").join(&log);
        let seq = Source::parse(&format!("av2:{}", dir.display()))
            .expect("spec")
            .load(None)
            .unwrap_or_else(|e| panic!("{log}: {e}"));
        let windows = window_facts(&seq, WindowSpec::PAPER, &FactConfig::default())
            .unwrap_or_else(|e| panic!("{log}: {e}"));
        let names = seq
            .tracks()
            .into_iter()
            .map(|t| {
                (
                    seq.short_key(t.track_id).expect("AV2 tracks have keys"),
                    t.name,
                )
            })
            .collect();
        let map = seq.map.as_ref().expect("the log has a map");
        out.push(Log {
            map_sizes: (
                map.lanes.len(),
                map.crosswalks.len(),
                map.drivable_areas.len(),
            ),
            frames: seq.frame_count,
            skipped: seq.skipped.clone(),
            expected,
            windows,
            names,
        });
    }
    Some(out)
}

impl Log {
    fn name(&self, key: &Value) -> &str {
        let key = key.as_str().expect("key");
        self.names
            .get(key)
            .unwrap_or_else(|| panic!("no track with short key {key}"))
    }

    fn has(&self, window: usize, predicate: &str, args: &[&str]) -> bool {
        self.windows[window].facts.iter().any(|f| {
            f.predicate == predicate && f.args.iter().map(String::as_str).eq(args.iter().copied())
        })
    }

    fn windows_with(&self, predicate: &str, args: &[&str]) -> BTreeSet<usize> {
        (0..self.windows.len())
            .filter(|&w| self.has(w, predicate, args))
            .collect()
    }

    fn windows_seen(&self, name: &str) -> BTreeSet<usize> {
        (0..self.windows.len())
            .filter(|&w| {
                self.windows[w]
                    .facts
                    .iter()
                    .any(|f| f.predicate == "TypeOf" && f.args[0] == name)
            })
            .collect()
    }
}

#[test]
fn shape_counts_and_the_ego_rows() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        let e = &log.expected;
        assert_eq!(i64::from(log.frames), e["frames"].as_i64().unwrap());
        assert_eq!(log.names.len() as i64, e["tracks"].as_i64().unwrap());
        assert_eq!(
            log.map_sizes,
            (
                e["lanes"].as_u64().unwrap() as usize,
                e["crosswalks"].as_u64().unwrap() as usize,
                e["drivable_areas"].as_u64().unwrap() as usize
            )
        );
        // The EGO_VEHICLE rows are the constant `ego`: counted, not lost.
        let ego_rows: usize = log
            .skipped
            .iter()
            .filter(|s| s.reason.contains("ego"))
            .map(|s| s.count)
            .sum();
        assert_eq!(
            ego_rows as i64,
            e["ego_rows"].as_i64().unwrap(),
            "{:?}",
            log.skipped
        );
    }
}

#[test]
fn every_track_has_its_category_as_its_type() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        for (key, ty) in log.expected["types"].as_object().unwrap() {
            let name = log.name(&Value::String(key.clone()));
            let ty = ty.as_str().unwrap();
            assert!(
                !log.windows_with("TypeOf", &[name, ty]).is_empty(),
                "{}: TypeOf({name}, {ty}) in no window",
                log.expected["log"]
            );
        }
    }
}

#[test]
fn bearing_sides_match_the_feather_rows() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        let cases = log.expected["sides"].as_array().unwrap();
        assert!(cases.len() > 20);
        for c in cases {
            let name = log.name(&c["key"]);
            let w = c["window"].as_u64().unwrap() as usize;
            let side = c["side"].as_str().unwrap();
            assert!(
                log.has(w, "InitialLocation", &[name, side]),
                "window {w}: InitialLocation({name}, {side}) expected (bearing {}°)",
                c["bearing"]
            );
        }
    }
}

#[test]
fn crosswalk_occupancy_matches_the_map() {
    let Some(logs) = logs() else { return };
    let (mut on, mut off) = (0, 0);
    for log in &logs {
        for c in log.expected["on_crosswalk"].as_array().unwrap() {
            let name = log.name(&c["key"]);
            let w = c["window"].as_u64().unwrap() as usize;
            assert!(
                log.has(w, "OnCrosswalk", &[name]),
                "window {w}: OnCrosswalk({name})"
            );
            on += 1;
        }
        for c in log.expected["far_from_crosswalks"].as_array().unwrap() {
            let name = log.name(&c["key"]);
            let w = c["window"].as_u64().unwrap() as usize;
            assert!(
                !log.has(w, "OnCrosswalk", &[name]),
                "window {w}: not OnCrosswalk({name})"
            );
            assert!(
                !log.has(w, "NearCrosswalk", &[name]),
                "window {w}: not NearCrosswalk({name})"
            );
            off += 1;
        }
    }
    assert!(on > 0 && off > 0, "{on} on, {off} off");
}

#[test]
fn turns_of_a_quarter_circle_are_found_with_their_sense() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        for c in log.expected["turns"].as_array().unwrap() {
            let name = log.name(&c["key"]);
            let turn = c["turn"].as_str().unwrap();
            let other = if turn == "TurnLeft" {
                "TurnRight"
            } else {
                "TurnLeft"
            };
            assert!(
                !log.windows_with(turn, &[name]).is_empty(),
                "{turn}({name}) in no window ({}°)",
                c["degrees"]
            );
            assert!(
                log.windows_with(other, &[name]).is_empty(),
                "{other}({name})"
            );
        }
    }
}

#[test]
fn parked_objects_are_stationary_and_travellers_are_not() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        for key in log.expected["stationary"].as_array().unwrap() {
            let name = log.name(key);
            assert_eq!(
                log.windows_with("Stationary", &[name]),
                log.windows_seen(name),
                "Stationary({name}) in every window it is seen"
            );
        }
        for key in log.expected["travelling"].as_array().unwrap() {
            let name = log.name(key);
            assert!(
                log.windows_with("Stationary", &[name]).is_empty(),
                "not Stationary({name})"
            );
        }
    }
}

/// Regression: the labels of car `8765d532` (log `3b3570b4`) flip its box
/// yaw by 68° for single frames (83 and 85) in the middle of a right turn
/// (heading 181° → 90° in the city frame over frames 22–142, checked with
/// pyarrow); read raw, that was a 68° left turn inside the right one.
#[test]
fn a_one_frame_yaw_flip_is_not_a_turn() {
    let Some(logs) = logs() else { return };
    let log = logs
        .iter()
        .find(|l| {
            l.expected["log"]
                .as_str()
                .is_some_and(|n| n.starts_with("3b3570b4"))
        })
        .expect("the Miami log");
    let name = log.name(&Value::String("8765d532".into()));
    assert!(!log.windows_with("TurnRight", &[name]).is_empty());
    assert!(log.windows_with("TurnLeft", &[name]).is_empty());
}

/// Object names shorten the AV2 track uuid to its first 8 hex digits; the
/// class fact's provenance keeps the whole uuid.
#[test]
fn class_facts_carry_the_full_track_uuid() {
    let Some(logs) = logs() else { return };
    for log in &logs {
        for name in log.names.values() {
            let short = name.rsplit('_').next().unwrap_or_default();
            let note = log
                .windows
                .iter()
                .flat_map(|w| &w.facts)
                .find(|f| {
                    f.args.len() == 1
                        && f.args[0] == *name
                        && f.provenance.note.starts_with("class of track")
                })
                .map(|f| f.provenance.note.clone())
                .unwrap_or_else(|| panic!("no class fact for {name}"));
            let uuid = note
                .split("source track id ")
                .nth(1)
                .map(|t| t.trim_end_matches(')'))
                .unwrap_or_else(|| panic!("{note}"));
            assert_eq!(uuid.len(), 36, "{note}");
            assert!(uuid.starts_with(short), "{name}: {note}");
        }
    }
}
