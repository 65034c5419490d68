use super::observe::MAP_PREDICATES;
use super::observe::frames_unobservable;
use super::*;
use std::path::Path;

#[test]
fn an_av2_spec_parses_through_perception_and_prints_back() {
    let spec: SourceSpec = "av2:logs/3b3570b4".parse().expect("parses");
    assert_eq!(
        spec,
        SourceSpec::Av2 {
            dir: PathBuf::from("logs/3b3570b4")
        }
    );
    assert_eq!(spec.to_string(), "av2:logs/3b3570b4");
    assert_eq!((spec.kind(), spec.syntax()), ("av2", "av2:DIR"));
    assert_eq!(
        spec.to_string().parse::<SourceSpec>().ok(),
        Some(spec.clone())
    );
    // One sequence per log: naming one is refused, not ignored.
    let e = spec
        .clone()
        .with_sequence(Some("0000".into()))
        .expect_err("a log has one sequence");
    assert!(e.to_string().contains("--sequence"), "{e}");
    assert!("av2:".parse::<SourceSpec>().is_err());
    let e = "nuscenes:x".parse::<SourceSpec>().expect_err("unknown");
    assert!(e.to_string().contains("av2"), "{e}");
    let e = "x".parse::<SourceSpec>().expect_err("no colon");
    assert!(e.to_string().contains("av2:DIR"), "{e}");
}

#[test]
fn a_missing_av2_directory_is_named() {
    let spec: SourceSpec = "av2:/nonexistent/log-dir".parse().expect("parses");
    let e = load(&spec, &LoadOptions::default(), &mut |_| {})
        .expect_err("no such directory")
        .to_string();
    assert!(
        e.contains("/nonexistent/log-dir") && e.contains("not a directory"),
        "{e}"
    );
}

#[test]
fn a_source_without_a_map_cannot_observe_the_map_s_predicates() {
    let spec: SourceSpec = "sim:urban_crossing".parse().expect("parses");
    let loaded = load(&spec, &LoadOptions::default(), &mut |_| {}).expect("loads");
    for p in MAP_PREDICATES {
        assert!(loaded.observability.unobservable.contains_key(*p), "{p}");
    }
    assert!(loaded.skipped().is_empty() && loaded.skipped_notes().is_empty());
}

#[test]
fn the_map_predicates_are_the_logicpad_s_map_group_and_lane_type() {
    // The list cannot drift from the built-in LogicPad's `map:` group.
    let pad = logicpad::LogicPad::builtin();
    let mut declared: Vec<&str> = pad
        .schema()
        .predicates()
        .filter(|p| p.group.as_deref() == Some("map") || p.name == "LaneType")
        .map(|p| p.name.as_str())
        .collect();
    declared.sort_unstable();
    let mut ours = MAP_PREDICATES.to_vec();
    ours.sort_unstable();
    assert_eq!(ours, declared);
}

#[test]
fn an_av2_log_cannot_tell_colours_nor_body_styles_but_tells_cars() {
    let obs = av2_observability();
    assert!(obs.unobservable.contains_key("ColorOf"));
    let blind = |v: &str| obs.blind_atom("TypeOf", &[None, Some(v)]).is_some();
    for v in ["Sedan", "SUV", "Van"] {
        assert!(blind(v), "{v}");
    }
    // Through the taxonomy: a RegularVehicle is a Car, a BoxTruck a Truck.
    for v in [
        "Car",
        "Truck",
        "Bus",
        "Pedestrian",
        "RegularVehicle",
        "Bicycle",
    ] {
        assert!(!blind(v), "{v}");
    }
}

#[test]
fn two_fact_files_with_one_stem_are_an_error_not_one_lost_window() {
    let dir = std::env::temp_dir().join(format!("logicrag-stems-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("w1.facts"), "Vehicles(car_1)\n").unwrap();
    std::fs::write(dir.join("w1.txt"), "Pedestrian(p_1)\n").unwrap();
    std::fs::write(dir.join("w2.facts"), "Vehicles(car_2)\n").unwrap();
    let spec: SourceSpec = format!("facts:{}", dir.display()).parse().unwrap();
    let e = load(&spec, &LoadOptions::default(), &mut |_| {})
        .err()
        .map(|e| e.to_string());
    std::fs::remove_file(dir.join("w1.txt")).unwrap();
    let ok = load(&spec, &LoadOptions::default(), &mut |_| {});
    std::fs::remove_dir_all(&dir).unwrap();
    let e = e.expect("duplicate stems must be refused");
    assert!(
        e.contains("w1.facts") && e.contains("w1.txt") && e.contains("`w1`"),
        "{e}"
    );
    let ids: Vec<String> = ok.unwrap().windows.iter().map(|w| w.id.clone()).collect();
    assert_eq!(ids, ["w1", "w2"]);
}

#[test]
fn a_byte_order_mark_is_not_a_bad_first_line() {
    // Regression: facts, KITTI and query files refused a UTF-8 BOM that
    // YAML files accepted.
    let dir = std::env::temp_dir().join(format!("logicrag-bom-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    std::fs::write(dir.join("w.facts"), "\u{feff}Vehicles(car_1)\n").unwrap();
    let spec: SourceSpec = format!("facts:{}", dir.join("w.facts").display())
        .parse()
        .unwrap();
    let loaded = load(&spec, &LoadOptions::default(), &mut |_| {});
    std::fs::remove_dir_all(&dir).unwrap();
    let loaded = loaded.expect("a BOM is skipped");
    let first = loaded.windows[0].facts.iter().next().expect("one fact");
    assert_eq!(first.args().collect::<Vec<_>>(), ["car_1"]);
}

#[test]
fn a_frames_run_cannot_observe_classes_its_detector_does_not_label() {
    // Regression: `Cyclist`, `Person` and `Misc` counted as observed for
    // the COCO detector, which has no such class, so "is there a
    // cyclist?" was answered "no" instead of "unknown".
    let models =
        Path::new(env!("CARGO_MANIFEST_DIR")).join("../perception/models/nanodet-m-416-coco.yaml");
    let set = perception::raw::frames::ModelSet::load(&models).unwrap();
    let un = frames_unobservable(&set);
    for p in ["On", "Cyclist", "Person", "Misc", "Road", "Building"] {
        assert!(un.contains(&p), "{p} should be unobservable: {un:?}");
    }
    for p in [
        "Vehicles",
        "Pedestrian",
        "TrafficLight",
        "TrafficSign",
        "ColorOf",
    ] {
        assert!(!un.contains(&p), "{p} is observed: {un:?}");
    }
}
