//! `av2:DIR`, an Argoverse 2 log, as a user runs it: facts with the
//! skipped inputs said on stderr, `plot bev` over the map with objects all
//! around the ego, and `serve`'s scene with the map. The log is
//! `../shared/data/av2/…`: these tests fail where it is absent (CI has it),
//! unless `LOGICRAG_SKIP_MISSING` is set, as the cross-crate tests do.

use crate::common::{Served, client};
use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

/// The log every test reads (annotations with the ego, poses, map).
const LOG: &str = "data/av2/scenario_mining/3b3570b4-7b0b-3268-a571-b0889dbf40b6";

/// `av2:<the log>`, or `None` (after saying so) where `../shared` is absent
/// and `LOGICRAG_SKIP_MISSING` is set.
fn av2_source() -> Option<String> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared")
        .join(LOG);
    if !dir.join("annotations_with_ego.feather").is_file() {
        assert!(
            std::env::var_os("LOGICRAG_SKIP_MISSING").is_some(),
            "{} is not present (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)",
            dir.display()
        );
        eprintln!(
            "SKIPPED (LOGICRAG_SKIP_MISSING): {} is not present",
            dir.display()
        );
        return None;
    }
    Some(format!("av2:{}", dir.display()))
}

fn logicrag(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_logicrag"))
        .args(args)
        .output()
        .expect("the logicrag binary runs")
}

fn run_ok(args: &[&str]) -> (String, String) {
    let out = logicrag(args);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "logicrag {}: {stderr}",
        args.join(" ")
    );
    (String::from_utf8_lossy(&out.stdout).into_owned(), stderr)
}

/// A scratch directory under the target directory, emptied first.
fn scratch(name: &str) -> PathBuf {
    let dir = Path::new(env!("CARGO_TARGET_TMPDIR")).join(format!("av2-{name}"));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch dir");
    dir
}

#[test]
fn facts_of_a_log_list_objects_all_around_and_say_what_was_skipped() {
    let Some(src) = av2_source() else { return };
    let (stdout, stderr) = run_ok(&["facts", "--source", &src, "--frames", "0-9"]);
    assert!(
        stdout.starts_with("# window 3b3570b4-7b0b-3268-a571-b0889dbf40b6_000000 (av2:"),
        "{}",
        stdout.lines().next().unwrap_or_default()
    );
    for fact in ["Vehicles(", "Pedestrian(", "TypeOf(", "Behind("] {
        assert!(stdout.contains(fact), "no {fact}… fact");
    }
    // The ego vehicle's rows are the ego, not an object: counted, and said.
    let note = stderr
        .lines()
        .find(|l| l.contains("skipped"))
        .unwrap_or_else(|| panic!("no skipped note on stderr: {stderr}"));
    assert!(
        note.starts_with("note: av2:3b3570b4-7b0b-3268-a571-b0889dbf40b6 skipped 157 inputs")
            && note.contains("EGO_VEHICLE")
            && note.contains("`ego`"),
        "{note}"
    );
    assert!(!stdout.contains("EGO_VEHICLE") && !stdout.contains("ego_vehicle"));
}

/// A log without a pose file says what it lacks — not "skipped 0 inputs".
#[test]
fn a_log_without_poses_says_its_ego_motion_is_estimated() {
    let Some(src) = av2_source() else { return };
    let dir = src
        .strip_prefix("av2:")
        .and_then(|d| Path::new(d).parent()?.parent().map(Path::to_path_buf))
        .expect("the av2 folder")
        .join("logs/b87683ae-14c5-321f-8af3-623e7bafc3a7");
    let spec = format!("av2:{}", dir.display());
    let (_, stderr) = run_ok(&["facts", "--source", &spec, "--frames", "0-9"]);
    let note = stderr
        .lines()
        .find(|l| l.contains("city_SE3_egovehicle.feather"))
        .unwrap_or_else(|| panic!("no note on the missing pose file: {stderr}"));
    assert!(
        note.starts_with("note: av2:b87683ae-14c5-321f-8af3-623e7bafc3a7: no city_SE3_egovehicle.feather: ego motion estimated"),
        "{note}"
    );
    assert!(!stderr.contains("skipped 0"), "{stderr}");
}

#[test]
fn a_missing_log_directory_is_named_in_the_error() {
    let out = logicrag(&["facts", "--source", "av2:/nonexistent/av2-log"]);
    assert_eq!(out.status.code(), Some(2), "{out:?}");
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        stderr.contains("/nonexistent/av2-log") && stderr.contains("not a directory"),
        "{stderr}"
    );
    // A sequence name does not apply to a log (it holds one).
    let out = logicrag(&["facts", "--source", "av2:/x", "--sequence", "0000"]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(
        !out.status.success() && stderr.contains("--sequence"),
        "{stderr}"
    );
}

#[test]
fn the_bird_s_eye_view_of_a_log_draws_its_map_and_objects_behind_the_ego() {
    let Some(src) = av2_source() else { return };
    let dir = scratch("bev");
    let svg = dir.join("bev.svg");
    let png = dir.join("bev.png");
    for out in [&svg, &png] {
        run_ok(&[
            "plot",
            "bev",
            "--source",
            &src,
            "--out",
            out.to_str().expect("path"),
        ]);
    }
    let text = std::fs::read_to_string(&svg).expect("svg");
    for label in ["drivable area", "lane", "crosswalk", "metres ahead"] {
        assert!(text.contains(label), "the SVG should name `{label}`");
    }
    // Crosswalks are drawn as polygons of their own colour
    // (plot::CROSSWALK), lanes as many polygons.
    let polygons: Vec<&str> = text.split("<polygon").skip(1).collect();
    assert!(
        polygons.iter().any(|p| p.contains("fill=\"#FFE27A\"")),
        "no crosswalk polygon"
    );
    assert!(polygons.len() > 20, "{} polygons", polygons.len());
    // The y axis reaches behind the ego: objects there are drawn.
    assert!(
        text.lines().any(|l| matches!(l.trim(), "-50" | "-100")),
        "no negative z tick"
    );
    let img = image::open(&png).expect("png").to_rgb8();
    assert_eq!((img.width(), img.height()), (1000, 800));
    assert!(
        img.pixels().any(|p| p.0 == [255, 226, 122]),
        "no crosswalk pixel"
    );
}

#[test]
fn serve_s_scene_of_a_log_window_has_the_map_and_the_skipped_inputs() {
    let Some(src) = av2_source() else { return };
    let s = Served::start(&["--source", &src, "--frames", "0-9"], &[]);
    let http = client();
    let w: Value = http
        .get(s.at("/api/windows"))
        .send()
        .expect("windows")
        .json()
        .expect("json");
    assert_eq!(w["scene"], Value::Bool(true));
    let skipped = w["skipped"].as_array().expect("skipped");
    assert!(
        skipped.iter().any(|k| k["count"] == 157
            && k["reason"]
                .as_str()
                .is_some_and(|r| r.contains("EGO_VEHICLE"))),
        "{skipped:?}"
    );
    let id = w["windows"][0]["id"].as_str().expect("a window id");
    let scene: Value = http
        .get(s.at(&format!("/api/scene?window={id}")))
        .send()
        .expect("scene")
        .json()
        .expect("json");
    let map = &scene["map"];
    let lanes = map["lanes"].as_array().expect("map.lanes");
    assert!(lanes.len() > 10, "{} lanes", lanes.len());
    for lane in lanes {
        assert!(lane["id"].is_i64() && lane["polygon"].as_array().is_some_and(|p| p.len() >= 3));
        assert!(
            matches!(lane["kind"].as_str(), Some("Vehicle" | "Bus" | "Bike")),
            "{lane}"
        );
    }
    assert!(!map["crosswalks"].as_array().expect("crosswalks").is_empty());
    assert!(map["drivable_areas"].is_array());
    // Every polygon point lies in the box the map was cut to.
    let b: Vec<f64> = map["bounds"]
        .as_array()
        .expect("bounds")
        .iter()
        .filter_map(Value::as_f64)
        .collect();
    assert_eq!(b.len(), 4);
    for p in lanes
        .iter()
        .flat_map(|l| l["polygon"].as_array().into_iter().flatten())
    {
        let (x, z) = (
            p[0].as_f64().unwrap_or(f64::NAN),
            p[1].as_f64().unwrap_or(f64::NAN),
        );
        assert!(
            x >= b[0] - 1e-6 && x <= b[2] + 1e-6 && z >= b[1] - 1e-6 && z <= b[3] + 1e-6,
            "{p}"
        );
    }
    // 360°: objects behind the ego (z < 0) are in the view; no pixel boxes.
    let tracks = scene["tracks"].as_array().expect("tracks");
    assert!(tracks.len() > 30, "{} tracks", tracks.len());
    assert!(
        tracks
            .iter()
            .any(|t| t["points"][0]["z"].as_f64().is_some_and(|z| z < -5.0))
    );
    assert!(
        scene["frames"]
            .as_array()
            .expect("frames")
            .iter()
            .all(|f| f["boxes"].as_array().is_some_and(Vec::is_empty))
    );
}
