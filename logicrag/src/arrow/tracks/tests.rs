use super::*;
use arrow_array::{ArrayRef, Float64Array, Int64Array, StringArray};
use arrow_schema::{Field, Schema};

/// A batch from named columns (nullable, so null cases can be built).
fn batch(cols: Vec<(&str, ArrayRef)>) -> RecordBatch {
    let fields: Vec<Field> = cols
        .iter()
        .map(|(n, a)| Field::new(*n, a.data_type().clone(), true))
        .collect();
    RecordBatch::try_new(
        Arc::new(Schema::new(fields)),
        cols.into_iter().map(|(_, a)| a).collect(),
    )
    .unwrap()
}

fn f64s(v: &[f64]) -> ArrayRef {
    Arc::new(Float64Array::from(v.to_vec()))
}

fn i64s(v: &[i64]) -> ArrayRef {
    Arc::new(Int64Array::from(v.to_vec()))
}

fn strs(v: &[&str]) -> ArrayRef {
    Arc::new(StringArray::from(v.to_vec()))
}

/// Three rows: a car ahead-left at frame 0 and 1, the ego at frame 0.
fn table(frame: ArrayRef, track: ArrayRef, category: &[&str]) -> Vec<(&'static str, ArrayRef)> {
    vec![
        ("frame", frame),
        ("track_id", track),
        ("category", strs(category)),
        ("x", f64s(&[10.0, 11.0, 0.0])),
        ("y", f64s(&[2.0, 2.0, 0.0])),
        ("z", f64s(&[0.8, 0.8, 0.9])),
        ("length", f64s(&[4.5, 4.5, 4.8])),
        ("width", f64s(&[1.9, 1.9, 2.0])),
        ("height", f64s(&[1.6, 1.6, 1.8])),
        ("yaw", f64s(&[0.0, 0.1, 0.0])),
    ]
}

fn simple() -> Vec<(&'static str, ArrayRef)> {
    table(
        i64s(&[0, 1, 0]),
        i64s(&[3, 3, 9]),
        &["Car", "REGULAR_VEHICLE", "EGO_VEHICLE"],
    )
}

#[test]
fn rows_become_box_less_observations_in_the_camera_convention() {
    let s = tracks_from_batches("t", &[batch(simple())], None, None).unwrap();
    assert_eq!(s.source_label(), "tracks:t");
    assert_eq!((s.frame_count, s.fps), (2, 10.0));
    assert_eq!(s.observations.len(), 2);
    let o = &s.observations[0];
    assert_eq!((o.frame, o.track_id), (0, 3));
    assert_eq!(o.bbox, None);
    // X = −y, Y = −(z − h/2), Z = x; size [h, w, l].
    assert_eq!(o.position, Some([-2.0, -(0.8 - 0.8), 10.0]));
    assert_eq!(o.size, Some([1.6, 1.9, 4.5]));
    assert_eq!(
        o.yaw,
        Some(perception::coords::vehicle_yaw_to_rotation_y(0.0))
    );
    assert_eq!(o.type_name.as_deref(), Some("Car"));
    assert_eq!(
        s.observations[1].type_name.as_deref(),
        Some("RegularVehicle")
    );
    // The ego's row is counted, not an object.
    assert_eq!(s.skipped.len(), 1);
    assert!(
        s.skipped[0].reason.contains("EGO_VEHICLE"),
        "{:?}",
        s.skipped
    );
    assert!(s.track_keys.is_empty());
}

#[test]
fn categories_of_av2_our_types_and_classes() {
    for (c, class, t) in [
        ("BOX_TRUCK", ObjectClass::Vehicle, Some("BoxTruck")),
        ("box_truck", ObjectClass::Vehicle, Some("BoxTruck")),
        ("BoxTruck", ObjectClass::Vehicle, Some("BoxTruck")),
        ("car", ObjectClass::Vehicle, Some("Car")),
        ("Pedestrian", ObjectClass::Pedestrian, Some("Pedestrian")),
        ("BICYCLIST", ObjectClass::Cyclist, Some("Bicyclist")),
        ("Cyclist", ObjectClass::Cyclist, Some("Cyclist")),
        (
            "Person_sitting",
            ObjectClass::Person,
            Some("Person_sitting"),
        ),
        ("Pole", ObjectClass::Pole, None),
        ("Vehicles", ObjectClass::Vehicle, None),
        ("HOVERCRAFT", ObjectClass::Other, Some("Hovercraft")),
    ] {
        assert_eq!(category_class(c), (class, t.map(str::to_string)), "{c}");
    }
}

#[test]
fn string_ids_and_timestamps_become_keys_and_frames() {
    let mut cols = table(
        i64s(&[2_000, 1_000, 1_000]),
        strs(&["b7-uuid", "a3-uuid", "b7-uuid"]),
        &["PEDESTRIAN", "BUS", "PEDESTRIAN"],
    );
    cols[0].0 = "timestamp_ns";
    let s = tracks_from_batches("t", &[batch(cols)], None, None).unwrap();
    assert_eq!(s.timestamps_ns, Some(vec![1_000, 2_000]));
    assert_eq!(s.fps, 1e6);
    // Sorted order: a3 is track 0, b7 track 1.
    assert_eq!(s.track_keys[&0], "a3-uuid");
    assert_eq!(s.track_keys[&1], "b7-uuid");
    let at: Vec<(u32, u32)> = s
        .observations
        .iter()
        .map(|o| (o.frame, o.track_id))
        .collect();
    assert_eq!(at, [(0, 0), (0, 1), (1, 1)]);
}

#[test]
fn errors_name_the_column_and_row() {
    let err = |cols: Vec<(&'static str, ArrayRef)>| {
        tracks_from_batches("t", &[batch(cols)], None, None)
            .unwrap_err()
            .to_string()
    };
    let mut c = simple();
    c[3].1 = Arc::new(Float64Array::from(vec![Some(1.0), None, Some(2.0)]));
    assert_eq!(err(c), "tracks table row 1: `x` is null");
    let mut c = simple();
    c[5].1 = f64s(&[0.8, f64::NAN, 0.9]);
    assert_eq!(
        err(c),
        "tracks table row 1: `z` is NaN, not a finite number"
    );
    let mut c = simple();
    c[6].1 = f64s(&[4.5, 4.5, -1.0]);
    assert!(err(c).starts_with("tracks table row 2: `length` is -1"));
    let mut c = simple();
    c.remove(9);
    assert!(err(c).starts_with("tracks table: no column `yaw`"));
    let mut c = simple();
    c[3].1 = strs(&["1", "2", "3"]);
    let e = err(c);
    assert!(e.contains("column `x` is Utf8, expected float64"), "{e}");
    let mut c = simple();
    c[1].1 = i64s(&[3, -3, 9]);
    assert!(err(c).starts_with("tracks table row 1: `track_id` is -3"));
    let mut c = simple();
    c.push(("color", strs(&["Red", "Plaid", "White"])));
    assert!(err(c).starts_with("tracks table row 1: `color` `Plaid` is not a colour"));
    let mut c = simple();
    c.push(("score", f64s(&[0.5, 2.0, 1.0])));
    assert_eq!(err(c), "tracks table row 1: `score` is 2, not in [0, 1]");
    let mut c = simple();
    c.push(("timestamp_ns", i64s(&[1, 2, 3])));
    assert!(err(c).contains("both `frame` and `timestamp_ns`"));
}

#[test]
fn repeated_rows_are_counted_and_rows_count_over_batches() {
    let dup = table(i64s(&[0, 0, 1]), i64s(&[3, 3, 3]), &["Car", "Car", "Car"]);
    let s = tracks_from_batches("t", &[batch(simple()), batch(dup)], None, None).unwrap();
    let rep = s
        .skipped
        .iter()
        .find(|k| k.reason.contains("repeated"))
        .unwrap();
    // Rows 3 and 4 (second batch) repeat (0, 3); row 5 repeats (1, 3).
    assert_eq!(rep.count, 3);
    assert_eq!(rep.example, "tracks table row 3");
    let mut bad = simple();
    bad[4].1 = f64s(&[1.0, f64::INFINITY, 1.0]);
    let e = tracks_from_batches("t", &[batch(simple()), batch(bad)], None, None)
        .unwrap_err()
        .to_string();
    assert!(e.starts_with("tracks table row 4: `y` is inf"), "{e}");
}

#[test]
fn poses_by_frame_or_interpolated_by_timestamp_and_a_map_needs_them() {
    let poses = batch(vec![
        ("frame", i64s(&[1, 0])),
        ("x", f64s(&[5.0, 4.0])),
        ("y", f64s(&[1.0, 1.0])),
        ("yaw", f64s(&[0.2, 0.1])),
    ]);
    let s = tracks_from_batches(
        "t",
        &[batch(simple())],
        Some(std::slice::from_ref(&poses)),
        None,
    )
    .unwrap();
    let p = s.ego_poses.unwrap();
    assert_eq!((p[0].x, p[1].x, p[0].z), (4.0, 5.0, 0.0));
    // A frame without its pose.
    let one = batch(vec![
        ("frame", i64s(&[0])),
        ("x", f64s(&[4.0])),
        ("y", f64s(&[1.0])),
        ("yaw", f64s(&[0.1])),
    ]);
    let e = tracks_from_batches("t", &[batch(simple())], Some(&[one]), None)
        .unwrap_err()
        .to_string();
    assert!(e.contains("no pose for frame 1"), "{e}");
    // A map without poses is refused by the sequence's invariant.
    let map = SceneMap {
        origin: "m".into(),
        ..SceneMap::default()
    };
    let e = tracks_from_batches("t", &[batch(simple())], None, Some(map.clone()))
        .unwrap_err()
        .to_string();
    assert!(e.contains("a map needs the ego's poses"), "{e}");
    assert!(tracks_from_batches("t", &[batch(simple())], Some(&[poses]), Some(map)).is_ok());

    // Timestamped poses at 4× the rate, interpolated at the frames'.
    let mut cols = simple();
    cols[0] = ("timestamp_ns", i64s(&[100, 200, 100]));
    let poses = batch(vec![
        ("timestamp_ns", i64s(&[50, 150, 250])),
        ("x", f64s(&[0.0, 10.0, 20.0])),
        ("y", f64s(&[0.0, 0.0, 0.0])),
        ("z", f64s(&[1.0, 1.0, 1.0])),
        ("yaw", f64s(&[0.0, 0.0, 0.0])),
    ]);
    let s = tracks_from_batches("t", &[batch(cols.clone())], Some(&[poses]), None).unwrap();
    let p = s.ego_poses.unwrap();
    assert_eq!((p[0].x, p[1].x, p[1].z), (5.0, 15.0, 1.0));
    let far = batch(vec![
        ("timestamp_ns", i64s(&[100_000_000, 100_000_001])),
        ("x", f64s(&[0.0, 0.0])),
        ("y", f64s(&[0.0, 0.0])),
        ("yaw", f64s(&[0.0, 0.0])),
    ]);
    let e = tracks_from_batches("t", &[batch(cols)], Some(&[far]), None)
        .unwrap_err()
        .to_string();
    assert!(
        e.starts_with("poses table: the frame at timestamp_ns 100"),
        "{e}"
    );
}

#[test]
fn a_map_file_is_read_in_either_shape() {
    let dir = std::env::temp_dir().join(format!("logicrag-tracks-map-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ours = dir.join("scene.json");
    std::fs::write(
        &ours,
        r#"{"crosswalks": [{"id": 4, "polygon": [[0, 0], [1, 0], [1, 1]]}]}"#,
    )
    .unwrap();
    let m = read_map(&ours).unwrap();
    assert_eq!(
        (m.crosswalks[0].id, m.origin.clone()),
        (4, ours.display().to_string())
    );
    std::fs::write(&ours, r#"{"crosswalks": [{"id": 4, "polygon": [[0, 0]]}]}"#).unwrap();
    let e = read_map(&ours).unwrap_err().to_string();
    assert!(
        e.contains("pedestrian crossing 4 needs at least three points"),
        "{e}"
    );
    std::fs::write(&ours, r#"{"roads": []}"#).unwrap();
    let e = read_map(&ours).unwrap_err().to_string();
    assert!(e.contains("expected an Argoverse 2 map archive"), "{e}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The AV2 log converted by hand, as a user of another dataset would (the
/// annotation and pose tables' columns renamed, yaw from the quaternion),
/// gives the `av2:` source's sequence and facts. Fails where `../shared`
/// is absent (CI has it), unless `LOGICRAG_SKIP_MISSING` is set.
#[test]
fn the_av2_log_by_hand_equals_the_av2_source() {
    let log = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("../../shared/data/av2/scenario_mining/3b3570b4-7b0b-3268-a571-b0889dbf40b6");
    if !log.join("annotations_with_ego.feather").is_file() {
        assert!(
            std::env::var_os("LOGICRAG_SKIP_MISSING").is_some(),
            "../shared is not present (set LOGICRAG_SKIP_MISSING=1 to skip tests whose inputs are absent)"
        );
        eprintln!("SKIPPED (LOGICRAG_SKIP_MISSING): ../shared is not present");
        return;
    }
    let want = perception::av2::load(&log).unwrap();
    let yaw = perception::av2::pose::yaw_of_quaternion;
    let ann = perception::av2::read_annotations(&log.join("annotations_with_ego.feather"))
        .unwrap()
        .rows;
    let col = |f: &dyn Fn(&perception::av2::AnnotationRow) -> f64| {
        f64s(&ann.iter().map(f).collect::<Vec<_>>())
    };
    let tracks = batch(vec![
        (
            "timestamp_ns",
            i64s(&ann.iter().map(|r| r.timestamp_ns).collect::<Vec<_>>()),
        ),
        (
            "track_id",
            strs(
                &ann.iter()
                    .map(|r| r.track_uuid.as_str())
                    .collect::<Vec<_>>(),
            ),
        ),
        (
            "category",
            strs(&ann.iter().map(|r| r.category.as_str()).collect::<Vec<_>>()),
        ),
        ("x", col(&|r| r.centre()[0])),
        ("y", col(&|r| r.centre()[1])),
        ("z", col(&|r| r.centre()[2])),
        ("length", col(&|r| r.length_m())),
        ("width", col(&|r| r.width_m())),
        ("height", col(&|r| r.height_m())),
        ("yaw", col(&|r| yaw(r.quaternion()))),
    ]);
    let rows = perception::av2::read_poses(&log.join("city_SE3_egovehicle.feather")).unwrap();
    let pcol = |f: &dyn Fn(&perception::av2::PoseRow) -> f64| {
        f64s(&rows.iter().map(f).collect::<Vec<_>>())
    };
    let poses = batch(vec![
        (
            "timestamp_ns",
            i64s(&rows.iter().map(|r| r.timestamp_ns).collect::<Vec<_>>()),
        ),
        ("x", pcol(&|r| r.translation[0])),
        ("y", pcol(&|r| r.translation[1])),
        ("z", pcol(&|r| r.translation[2])),
        ("yaw", pcol(&|r| yaw(r.quaternion))),
    ]);
    let map_file = want.map.as_ref().map(|m| m.origin.clone()).unwrap();
    let map = read_map(Path::new(&map_file)).unwrap();
    let got = tracks_from_batches(&want.name, &[tracks], Some(&[poses]), Some(map)).unwrap();

    assert_eq!(got.frame_count, want.frame_count);
    assert_eq!(got.fps, want.fps);
    assert_eq!(got.timestamps_ns, want.timestamps_ns);
    assert_eq!(got.track_keys, want.track_keys);
    assert_eq!(got.map, want.map);
    assert_eq!(got.observations, want.observations);
    let (gp, wp) = (
        got.ego_poses.clone().unwrap(),
        want.ego_poses.clone().unwrap(),
    );
    for (f, (g, w)) in gp.iter().zip(&wp).enumerate() {
        let d = (g.x - w.x).abs() + (g.y - w.y).abs() + (g.z - w.z).abs() + (g.yaw - w.yaw).abs();
        assert!(d < 1e-9, "frame {f}: {g:?} vs {w:?}");
    }
    let facts = |s: &Sequence| {
        perception::window_facts(
            s,
            perception::model::WindowSpec::PAPER,
            &perception::FactConfig::default(),
        )
        .unwrap()
        .into_iter()
        .map(|w| {
            w.facts
                .into_iter()
                .map(|f| (f.predicate, f.args))
                .collect::<Vec<_>>()
        })
        .collect::<Vec<_>>()
    };
    let (g, w) = (facts(&got), facts(&want));
    assert_eq!(g.len(), w.len());
    for (i, (g, w)) in g.iter().zip(&w).enumerate() {
        assert_eq!(g, w, "window {i}");
    }
}
