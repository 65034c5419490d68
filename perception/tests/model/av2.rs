//! Argoverse 2 logs from `../shared/data/av2`: the reader against values
//! computed independently from the same Feather and JSON files with pyarrow
//! and Python's json (hard-coded here), and bad input.

use std::path::{Path, PathBuf};

use perception::av2::{self, POSE_FILE};
use perception::{ObjectClass, Sequence, Source};

fn shared() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/av2")
}

const MIAMI: &str = "scenario_mining/3b3570b4-7b0b-3268-a571-b0889dbf40b6";
const PITTSBURGH: &str = "scenario_mining/3bffdcff-c3a7-38b6-a0f2-64196d130958";
const NO_POSE: &str = "logs/b87683ae-14c5-321f-8af3-623e7bafc3a7";

/// The log's directory; `None` (test skipped) only when `../shared` is
/// absent and `LOGICRAG_SKIP_MISSING` is set.
fn log(rel: &str) -> Option<PathBuf> {
    let dir = shared().join(rel);
    if dir.is_dir() {
        return Some(dir);
    }
    if std::env::var_os("LOGICRAG_SKIP_MISSING").is_none() {
        panic!(
            "{} is missing (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)",
            dir.display()
        );
    }
    eprintln!(
        "SKIPPED (LOGICRAG_SKIP_MISSING): {} is missing",
        dir.display()
    );
    None
}

fn close(a: f64, b: f64) -> bool {
    (a - b).abs() < 1e-9
}

fn obs_of<'a>(seq: &'a Sequence, uuid: &str, frame: u32) -> &'a perception::Observation {
    let id = seq
        .track_keys
        .iter()
        .find(|(_, k)| k.as_str() == uuid)
        .map(|(id, _)| *id)
        .unwrap_or_else(|| panic!("no track {uuid}"));
    seq.observations
        .iter()
        .find(|o| o.track_id == id && o.frame == frame)
        .unwrap_or_else(|| panic!("track {uuid} not in frame {frame}"))
}

#[test]
fn miami_log_matches_pyarrow() {
    let Some(dir) = log(MIAMI) else { return };
    let seq = av2::load(&dir).unwrap();
    assert_eq!(seq.name, "3b3570b4-7b0b-3268-a571-b0889dbf40b6");
    assert_eq!(seq.source_label(), format!("av2:{}", seq.name));
    // 157 distinct timestamps, 119 non-ego tracks, 13,820 rows of which
    // 157 are the ego's, no duplicates, no non-finite values.
    assert_eq!(seq.frame_count, 157);
    assert_eq!(seq.track_keys.len(), 119);
    assert_eq!(seq.observations.len(), 13_820 - 157);
    let ts = seq.timestamps_ns.as_ref().unwrap();
    assert_eq!(
        (ts[0], ts[156]),
        (315_971_916_960_141_000, 315_971_932_559_986_000)
    );
    // Median frame interval 100,196,000 ns.
    assert!(close(seq.fps, 1e9 / 100_196_000.0));
    assert_eq!(seq.skipped.len(), 1, "{:?}", seq.skipped);
    assert_eq!(seq.skipped[0].count, 157);
    assert!(seq.skipped[0].reason.contains("EGO_VEHICLE"));

    // Track 8ba41dd9… is a MOTORCYCLE, id 57 in sorted uuid order; at
    // timestamp 315971923659911000 (frame 67): tx -45.7897, ty 23.1167,
    // tz and height giving bottom height -0.26227; yaw about z 1.18463.
    let m = obs_of(&seq, "8ba41dd9-2ebc-4105-baa0-d58064df3812", 67);
    assert_eq!(ts[67], 315_971_923_659_911_000);
    assert_eq!((m.track_id, m.class), (57, ObjectClass::Vehicle));
    assert_eq!(m.type_name.as_deref(), Some("Motorcycle"));
    let p = m.position.unwrap();
    assert!(
        close(p[0], -23.11672550947401) && close(p[1], 0.2622682151746041),
        "{p:?}"
    );
    assert!(close(p[2], -45.78970597226248), "{p:?}");
    let s = m.size.unwrap();
    assert!(close(s[0], 1.2048568725585938) && close(s[1], 0.5) && close(s[2], 2.087327480316162));
    assert!(close(m.yaw.unwrap(), -2.7554219446620696), "{:?}", m.yaw);
    assert_eq!(seq.object_name(57), "motorcycle_8ba41dd9");
    // A pedestrian (1f9d538d…, frame 62) and a bicycle (2f28de2e…, frame 78).
    let ped = obs_of(&seq, "1f9d538d-8f86-447e-8342-f2bc8c2c4960", 62);
    assert_eq!(
        (ped.class, ped.type_name.as_deref()),
        (ObjectClass::Pedestrian, Some("Pedestrian"))
    );
    assert!(close(ped.position.unwrap()[0], 52.01747601147213));
    assert!(close(ped.yaw.unwrap(), 0.1308512860397828));
    let bike = obs_of(&seq, "2f28de2e-be7e-40df-8228-2956d92de90a", 78);
    assert_eq!(
        (bike.class, bike.type_name.as_deref()),
        (ObjectClass::Misc, Some("Bicycle"))
    );
    assert!(close(bike.position.unwrap()[2], 10.865813522261078));

    // Ego poses at frames 0 and 80 (pose rows exist at those timestamps).
    let poses = seq.ego_poses.as_ref().unwrap();
    assert_eq!(poses.len(), 157);
    let (p0, p80) = (poses[0], poses[80]);
    assert!(close(p0.x, 743.9777930173304) && close(p0.y, 2231.5482569447154));
    assert!(close(p0.z, -22.927443244886017) && close(p0.yaw, 1.6004710864558271));
    assert!(close(p80.x, 742.9358272244502) && close(p80.y, 2243.3033329996433));
    assert!(close(p80.yaw, 1.7821849838538721));

    // Map: 150 lanes (48 in intersections), 6 crossings, 5 drivable areas.
    let map = seq.map.as_ref().unwrap();
    assert_eq!(
        (
            map.lanes.len(),
            map.crosswalks.len(),
            map.drivable_areas.len()
        ),
        (150, 6, 5)
    );
    assert_eq!(map.lanes.iter().filter(|l| l.is_intersection).count(), 48);
    let cw = map.crosswalks.iter().find(|c| c.id == 2_348_559).unwrap();
    assert_eq!(cw.polygon.len(), 4);
    assert_eq!(cw.polygon[0], [754.35, 2263.44]);
    // edge1 then edge2 reversed: edge2's last point comes third.
    assert_eq!(cw.polygon[2], [757.96, 2248.4]);
    assert!(
        map.origin.ends_with(
            "log_map_archive_3b3570b4-7b0b-3268-a571-b0889dbf40b6____MIA_city_47894.json"
        )
    );
}

#[test]
fn the_pose_between_two_rows_is_interpolated() {
    let Some(dir) = log(MIAMI) else { return };
    let path = dir.join(POSE_FILE);
    let rows = av2::pose::sorted_poses(av2::read_poses(&path).unwrap(), &path).unwrap();
    assert_eq!(rows.len(), 2694);
    // 2 ms after frame 80, between rows 315971924959792000 and
    // 315971924962451243 (fraction 0.752094).
    let p = av2::pose::pose_at(&rows, 315_971_924_961_792_000, 0, &path).unwrap();
    assert!(
        close(p.x, 742.9354376650741) && close(p.y, 2243.3050288626837),
        "{p:?}"
    );
    assert!(close(p.yaw, 1.7822445903103195), "{p:?}");
}

#[test]
fn pittsburgh_log_matches_pyarrow() {
    let Some(dir) = log(PITTSBURGH) else { return };
    let seq = av2::load(&dir).unwrap();
    assert_eq!((seq.frame_count, seq.track_keys.len()), (156, 115));
    assert_eq!(seq.observations.len(), 12_342 - 156);
    let map = seq.map.as_ref().unwrap();
    assert_eq!(
        (
            map.lanes.len(),
            map.crosswalks.len(),
            map.drivable_areas.len()
        ),
        (211, 14, 15)
    );
    let kinds = |k| map.lanes.iter().filter(|l| l.kind == k).count();
    use perception::LaneKind;
    assert_eq!(
        (
            kinds(LaneKind::Vehicle),
            kinds(LaneKind::Bike),
            kinds(LaneKind::Bus)
        ),
        (173, 37, 1)
    );
}

#[test]
fn an_annotations_only_log_loads_without_poses_or_map() {
    let Some(dir) = log(NO_POSE) else { return };
    let seq = Source::parse(&format!("av2:{}", dir.display()))
        .unwrap()
        .load(None)
        .unwrap();
    assert_eq!(
        (
            seq.frame_count,
            seq.track_keys.len(),
            seq.observations.len()
        ),
        (157, 74, 6542)
    );
    assert!(seq.ego_poses.is_none() && seq.map.is_none());
    assert!(
        seq.skipped
            .iter()
            .any(|s| s.reason.contains("ego motion estimated") && s.count == 0)
    );
    // Facts still come (ego motion estimated).
    let w =
        perception::window_facts(&seq, perception::WindowSpec::PAPER, &Default::default()).unwrap();
    assert!(!w.is_empty());
}

#[test]
fn a_truncated_real_file_is_an_error_naming_it() {
    let Some(dir) = log(MIAMI) else { return };
    let path = dir.join("annotations_with_ego.feather");
    let bytes = std::fs::read(&path).unwrap();
    for cut in [10, 1000, bytes.len() / 2, bytes.len() - 1] {
        let e = av2::parse_annotations(&bytes[..cut], &path)
            .unwrap_err()
            .to_string();
        assert!(e.contains("annotations_with_ego.feather"), "{e}");
    }
    let map = std::fs::read_to_string(
        dir.join("map/log_map_archive_3b3570b4-7b0b-3268-a571-b0889dbf40b6____MIA_city_47894.json"),
    )
    .unwrap();
    let e = av2::parse_map_json(&map[..map.len() / 2], "cut.json")
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("cut.json: ") && e.contains("line"), "{e}");
}
