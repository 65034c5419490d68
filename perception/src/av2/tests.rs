//! The AV2 reader on small logs written here with the Arrow IPC writer:
//! conventions, skips, duplicates, string encodings, bad input.

use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::sync::atomic::{AtomicUsize, Ordering};

use arrow_array::types::Int32Type;
use arrow_array::{
    ArrayRef, DictionaryArray, Float64Array, Int64Array, LargeStringArray, RecordBatch, StringArray,
};
use arrow_ipc::CompressionType;
use arrow_ipc::writer::{FileWriter, IpcWriteOptions};
use arrow_schema::{Field, Schema};

use super::*;
use crate::model::ObjectClass;

/// A fresh, empty directory under the system's temporary directory.
fn temp_dir(tag: &str) -> PathBuf {
    static N: AtomicUsize = AtomicUsize::new(0);
    let dir = std::env::temp_dir().join(format!(
        "perception-av2-{tag}-{}-{}",
        std::process::id(),
        N.fetch_add(1, Ordering::Relaxed)
    ));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

/// Writes `columns` as an LZ4-compressed Feather v2 file.
fn write_feather(path: &Path, columns: Vec<(&str, ArrayRef)>) {
    let fields: Vec<Field> = columns
        .iter()
        .map(|(n, a)| Field::new(*n, a.data_type().clone(), true))
        .collect();
    let schema = Arc::new(Schema::new(fields));
    let batch = RecordBatch::try_new(
        schema.clone(),
        columns.into_iter().map(|(_, a)| a).collect(),
    )
    .unwrap();
    let options = IpcWriteOptions::default()
        .try_with_compression(Some(CompressionType::LZ4_FRAME))
        .unwrap();
    let file = std::fs::File::create(path).unwrap();
    let mut w = FileWriter::try_new_with_options(file, &schema, options).unwrap();
    w.write(&batch).unwrap();
    w.finish().unwrap();
}

fn f64s(v: &[f64]) -> ArrayRef {
    Arc::new(Float64Array::from(v.to_vec()))
}

/// One annotation row: (timestamp, uuid, category, [l, w, h], yaw, [tx, ty, tz]).
type Row<'a> = (i64, &'a str, &'a str, [f64; 3], f64, [f64; 3]);

fn annotation_columns(rows: &[Row]) -> Vec<(&'static str, ArrayRef)> {
    let col = |f: &dyn Fn(&Row) -> f64| f64s(&rows.iter().map(f).collect::<Vec<_>>());
    vec![
        (
            "timestamp_ns",
            Arc::new(Int64Array::from(
                rows.iter().map(|r| r.0).collect::<Vec<_>>(),
            )) as ArrayRef,
        ),
        (
            "track_uuid",
            Arc::new(StringArray::from(
                rows.iter().map(|r| r.1).collect::<Vec<_>>(),
            )),
        ),
        (
            "category",
            Arc::new(StringArray::from(
                rows.iter().map(|r| r.2).collect::<Vec<_>>(),
            )),
        ),
        ("length_m", col(&|r| r.3[0])),
        ("width_m", col(&|r| r.3[1])),
        ("height_m", col(&|r| r.3[2])),
        ("qw", col(&|r| (r.4 / 2.0).cos())),
        ("qx", col(&|_| 0.0)),
        ("qy", col(&|_| 0.0)),
        ("qz", col(&|r| (r.4 / 2.0).sin())),
        ("tx_m", col(&|r| r.5[0])),
        ("ty_m", col(&|r| r.5[1])),
        ("tz_m", col(&|r| r.5[2])),
    ]
}

const CAR: &str = "0f3c9a1e-aaaa-bbbb-cccc-000000000001";
const PED: &str = "7b2e11d0-aaaa-bbbb-cccc-000000000002";
const EGO: &str = "ffffffff-aaaa-bbbb-cccc-000000000003";
const S: i64 = 100_000_000;

fn small_rows() -> Vec<Row<'static>> {
    vec![
        // A car 10 m ahead, 2 m to the left, heading left (yaw +90°).
        (
            0,
            CAR,
            "REGULAR_VEHICLE",
            [4.0, 2.0, 1.5],
            std::f64::consts::FRAC_PI_2,
            [10.0, 2.0, 0.75],
        ),
        (0, EGO, "EGO_VEHICLE", [4.8, 2.0, 1.8], 0.0, [0.0, 0.0, 0.9]),
        (
            S,
            PED,
            "PEDESTRIAN",
            [0.5, 0.5, 1.8],
            0.0,
            [-5.0, -1.0, 0.9],
        ),
        (
            S,
            CAR,
            "REGULAR_VEHICLE",
            [4.0, 2.0, 1.5],
            0.0,
            [11.0, 2.0, 0.75],
        ),
        // The same car twice at one timestamp: the first is kept.
        (
            S,
            CAR,
            "REGULAR_VEHICLE",
            [4.0, 2.0, 1.5],
            0.0,
            [99.0, 2.0, 0.75],
        ),
        (
            2 * S,
            CAR,
            "REGULAR_VEHICLE",
            [4.0, 2.0, f64::NAN],
            0.0,
            [12.0, 2.0, 0.75],
        ),
        (
            2 * S,
            PED,
            "HOVERCRAFT",
            [0.5, 0.5, 1.8],
            0.0,
            [-5.0, -1.0, 0.9],
        ),
    ]
}

fn write_poses(path: &Path, ts: &[i64], x: &[f64]) {
    let n = ts.len();
    write_feather(
        path,
        vec![
            (
                "timestamp_ns",
                Arc::new(Int64Array::from(ts.to_vec())) as ArrayRef,
            ),
            ("qw", f64s(&vec![1.0; n])),
            ("qx", f64s(&vec![0.0; n])),
            ("qy", f64s(&vec![0.0; n])),
            ("qz", f64s(&vec![0.0; n])),
            ("tx_m", f64s(x)),
            ("ty_m", f64s(&vec![5.0; n])),
            ("tz_m", f64s(&vec![0.0; n])),
        ],
    );
}

const MAP: &str = r#"{"lane_segments": {"1": {"id": 1, "lane_type": "VEHICLE", "is_intersection": false,
  "left_lane_boundary": [{"x": 0, "y": 2, "z": 0}, {"x": 50, "y": 2, "z": 0}],
  "right_lane_boundary": [{"x": 0, "y": -2, "z": 0}, {"x": 50, "y": -2, "z": 0}],
  "successors": [], "predecessors": [], "left_neighbor_id": null, "right_neighbor_id": null}},
  "pedestrian_crossings": {}, "drivable_areas": {}}"#;

fn small_log(with_poses: bool, with_map: bool) -> PathBuf {
    let dir = temp_dir("log");
    write_feather(
        &dir.join("annotations_with_ego.feather"),
        annotation_columns(&small_rows()),
    );
    if with_poses {
        write_poses(&dir.join(POSE_FILE), &[-S, 3 * S], &[0.0, 40.0]);
    }
    if with_map {
        std::fs::create_dir_all(dir.join("map")).unwrap();
        std::fs::write(dir.join("map/log_map_archive_x.json"), MAP).unwrap();
    }
    dir
}

fn skip<'a>(seq: &'a Sequence, word: &str) -> &'a Skipped {
    seq.skipped
        .iter()
        .find(|s| s.reason.contains(word))
        .unwrap_or_else(|| panic!("no skip about {word}: {:?}", seq.skipped))
}

#[test]
fn a_small_log_becomes_frames_tracks_and_camera_convention_positions() {
    let dir = small_log(true, true);
    let seq = load(&dir).unwrap();
    assert_eq!(seq.source, "av2");
    assert_eq!(seq.frame_count, 3);
    assert_eq!(seq.timestamps_ns, Some(vec![0, S, 2 * S]));
    assert!((seq.fps - 10.0).abs() < 1e-9);
    // Sorted uuid order: the car (0f3c…) is track 0, the pedestrian 1.
    assert_eq!(seq.track_keys.get(&0).map(String::as_str), Some(CAR));
    assert_eq!(seq.track_keys.get(&1).map(String::as_str), Some(PED));
    let car0 = &seq.observations[0];
    assert_eq!(
        (car0.frame, car0.track_id, car0.class),
        (0, 0, ObjectClass::Vehicle)
    );
    assert_eq!(car0.type_name.as_deref(), Some("RegularVehicle"));
    assert!(car0.bbox.is_none());
    // X right = -y, Y down = -(bottom height), Z forward = x.
    assert_eq!(car0.position, Some([-2.0, -0.0, 10.0]));
    assert_eq!(car0.size, Some([1.5, 2.0, 4.0]));
    // Heading +90° (to the left): rotation_y -π, the box along -X.
    let ry = car0.yaw.unwrap();
    assert!((ry.cos() + 1.0).abs() < 1e-9, "{ry}");
    assert_eq!(
        seq.name_for(Some("RegularVehicle"), ObjectClass::Vehicle, 0),
        "regular_vehicle_0f3c9a1e"
    );
    // Frame 1: the first of the duplicated rows.
    let car1 = seq
        .observations
        .iter()
        .find(|o| o.frame == 1 && o.track_id == 0)
        .unwrap();
    assert_eq!(car1.position.unwrap()[2], 11.0);
    // An unknown category is kept as class Other.
    let odd = seq.observations.iter().find(|o| o.frame == 2).unwrap();
    assert_eq!(
        (odd.class, odd.type_name.as_deref()),
        (ObjectClass::Other, Some("Hovercraft"))
    );
    assert_eq!(seq.observations.len(), 4);
    // Every row is an observation or a counted skip.
    let ego = skip(&seq, "EGO_VEHICLE");
    assert_eq!(
        (ego.count, ego.example.as_str()),
        (1, "annotations_with_ego.feather row 1")
    );
    let dup = skip(&seq, "duplicate");
    assert_eq!(
        (dup.count, dup.example.as_str()),
        (1, "annotations_with_ego.feather row 4")
    );
    let nan = skip(&seq, "height_m");
    assert_eq!(
        (nan.count, nan.example.as_str()),
        (1, "annotations_with_ego.feather row 5")
    );
    // Poses: x from 0 at -S to 40 at 3S, so 10 per S.
    let poses = seq.ego_poses.as_ref().unwrap();
    assert!((poses[1].x - 20.0).abs() < 1e-9 && poses[1].y == 5.0 && poses[1].yaw == 0.0);
    let map = seq.map.as_ref().unwrap();
    assert_eq!(map.lanes.len(), 1);
    assert!(map.origin.ends_with("log_map_archive_x.json"));
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn without_poses_the_map_is_not_read_and_both_are_noted() {
    let dir = small_log(false, true);
    let seq = load(&dir).unwrap();
    assert!(seq.ego_poses.is_none() && seq.map.is_none());
    assert_eq!(skip(&seq, "ego motion estimated").count, 0);
    assert_eq!(skip(&seq, "map/ not read").count, 0);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn max_range_skips_far_cuboids_with_a_count() {
    let dir = small_log(true, false);
    let opts = Av2Options {
        max_range_m: Some(10.5),
        ..Av2Options::default()
    };
    let seq = load_with(&dir, &opts).unwrap();
    // The car at x 11 and its duplicate at x 99.
    assert_eq!(skip(&seq, "max_range_m").count, 2);
    assert!(
        seq.observations
            .iter()
            .all(|o| o.position.unwrap()[2] <= 10.5)
    );
    assert_eq!(skip(&seq, "no map/log_map_archive").count, 0);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn dictionary_and_large_strings_read_like_plain_ones() {
    let dir = temp_dir("dict");
    let mut cols = annotation_columns(&small_rows());
    let uuids: Vec<&str> = small_rows().iter().map(|r| r.1).collect();
    cols[1].1 = Arc::new(
        uuids
            .iter()
            .copied()
            .collect::<DictionaryArray<Int32Type>>(),
    );
    cols[2].1 = Arc::new(LargeStringArray::from(
        small_rows().iter().map(|r| r.2).collect::<Vec<_>>(),
    ));
    write_feather(&dir.join("annotations.feather"), cols);
    let plain = load(&small_log(false, false)).unwrap();
    let seq = load(&dir).unwrap();
    assert_eq!(seq.observations, plain.observations);
    assert_eq!(seq.track_keys, plain.track_keys);
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_missing_column_names_the_file_the_column_and_its_type() {
    let dir = temp_dir("nocol");
    let mut cols = annotation_columns(&small_rows());
    cols.remove(2);
    write_feather(&dir.join("annotations.feather"), cols);
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("annotations.feather")
            && e.contains("missing column `category`")
            && e.contains("string"),
        "{e}"
    );
    let mut cols = annotation_columns(&small_rows());
    cols[3].1 = Arc::new(StringArray::from(vec!["x"; 7]));
    write_feather(&dir.join("annotations.feather"), cols);
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("column `length_m` has type Utf8, expected double"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn garbage_and_truncated_files_are_errors_naming_the_file() {
    let dir = small_log(false, false);
    let path = dir.join("annotations_with_ego.feather");
    let good = std::fs::read(&path).unwrap();
    for bad in [
        b"not arrow at all".to_vec(),
        good[..good.len() / 2].to_vec(),
        {
            // Intact framing, body bytes flipped.
            let mut b = good.clone();
            for x in &mut b[200..good.len() - 400] {
                *x ^= 0x5a;
            }
            b
        },
        {
            // A footer length pointing outside the file.
            let mut b = good.clone();
            let n = b.len();
            b[n - 10..n - 6].copy_from_slice(&i32::MAX.to_le_bytes());
            b
        },
    ] {
        let e = parse_annotations(&bad, &path).unwrap_err().to_string();
        assert!(e.contains("annotations_with_ego.feather"), "{e}");
    }
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_non_finite_pose_is_an_error_naming_the_file_and_row() {
    let dir = small_log(false, false);
    write_poses(
        &dir.join(POSE_FILE),
        &[-S, S, 3 * S],
        &[0.0, f64::INFINITY, 2.0],
    );
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains(POSE_FILE) && e.contains("row 1") && e.contains("tx_m"),
        "{e}"
    );
    // Poses that end before the annotations do.
    write_poses(&dir.join(POSE_FILE), &[-S, S], &[0.0, 1.0]);
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("outside the ego poses") && e.contains("200000000"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn a_missing_directory_or_annotation_file_says_what_was_expected() {
    let e = load(Path::new("/nonexistent/av2-log"))
        .unwrap_err()
        .to_string();
    assert!(
        e.contains("av2:/nonexistent/av2-log") && e.contains("annotations.feather"),
        "{e}"
    );
    let dir = temp_dir("empty");
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("no annotations") && e.contains("annotations_with_ego.feather"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}

#[test]
fn too_many_objects_in_a_frame_is_an_error_naming_the_timestamp() {
    let dir = temp_dir("crowd");
    let uuids: Vec<String> = (0..=crate::model::MAX_OBJECTS_PER_FRAME)
        .map(|i| format!("{i:08x}-0000"))
        .collect();
    let rows: Vec<Row> = uuids
        .iter()
        .map(|u| {
            (
                7,
                u.as_str(),
                "BOLLARD",
                [0.3, 0.3, 1.0],
                0.0,
                [5.0, 0.0, 0.5],
            )
        })
        .collect();
    write_feather(&dir.join("annotations.feather"), annotation_columns(&rows));
    let e = load(&dir).unwrap_err().to_string();
    assert!(
        e.contains("timestamp_ns 7") && e.contains("257 objects"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(dir);
}
