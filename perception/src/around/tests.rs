use super::turns::despiked_headings;
use super::*;
use crate::model::{LaneKind, MapArea, MapLane, ObjectClass, Observation, SceneMap, WorldPose};
use crate::{WindowFacts, WindowSpec};

/// Frames of the synthetic logs (10 Hz): two 10-frame windows.
pub(crate) const FRAMES: u32 = 20;

/// A synthetic object: its centre and heading (CCW from +x) in the
/// source world frame per frame.
pub(crate) struct ObjSpec {
    pub(crate) id: u32,
    pub(crate) class: ObjectClass,
    pub(crate) type_name: &'static str,
    pub(crate) size: [f64; 3],
    pub(crate) pos: Box<dyn Fn(u32) -> [f64; 2]>,
    pub(crate) yaw: Box<dyn Fn(u32) -> f64>,
}

impl ObjSpec {
    pub(crate) fn car(id: u32, pos: impl Fn(u32) -> [f64; 2] + 'static, yaw: f64) -> ObjSpec {
        ObjSpec {
            id,
            class: ObjectClass::Vehicle,
            type_name: "Car",
            size: [1.5, 1.8, 4.5],
            pos: Box::new(pos),
            yaw: Box::new(move |_| yaw),
        }
    }

    pub(crate) fn pedestrian(id: u32, pos: impl Fn(u32) -> [f64; 2] + 'static) -> ObjSpec {
        ObjSpec {
            id,
            class: ObjectClass::Pedestrian,
            type_name: "Pedestrian",
            size: [1.7, 0.6, 0.6],
            pos: Box::new(pos),
            yaw: Box::new(|_| 0.0),
        }
    }
}

/// A rigid motion of the source world frame: rotation by `angle`,
/// then translation.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Rigid {
    pub(crate) angle: f64,
    pub(crate) dx: f64,
    pub(crate) dy: f64,
}

impl Rigid {
    pub(crate) const IDENTITY: Rigid = Rigid {
        angle: 0.0,
        dx: 0.0,
        dy: 0.0,
    };

    fn point(&self, p: [f64; 2]) -> [f64; 2] {
        let (s, c) = self.angle.sin_cos();
        [c * p[0] - s * p[1] + self.dx, s * p[0] + c * p[1] + self.dy]
    }

    fn pose(&self, p: WorldPose) -> WorldPose {
        let [x, y] = self.point([p.x, p.y]);
        WorldPose {
            x,
            y,
            z: p.z,
            yaw: p.yaw + self.angle,
        }
    }

    fn map(&self, m: &SceneMap) -> SceneMap {
        let pts = |v: &[[f64; 2]]| v.iter().map(|p| self.point(*p)).collect::<Vec<_>>();
        SceneMap {
            origin: m.origin.clone(),
            lanes: m
                .lanes
                .iter()
                .map(|l| MapLane {
                    left_boundary: pts(&l.left_boundary),
                    right_boundary: pts(&l.right_boundary),
                    ..l.clone()
                })
                .collect(),
            crosswalks: m
                .crosswalks
                .iter()
                .map(|a| MapArea {
                    id: a.id,
                    polygon: pts(&a.polygon),
                })
                .collect(),
            drivable_areas: m
                .drivable_areas
                .iter()
                .map(|a| MapArea {
                    id: a.id,
                    polygon: pts(&a.polygon),
                })
                .collect(),
        }
    }
}

/// Lane 10 (Vehicle, travel +x) over y −2..2 and lane 11 (Bus) over y
/// 2..6, both x −50..30; lane 12 (intersection) x 30..50 continues
/// lane 10; pedestrian crossing 77 over x 18..22, y −6..6; drivable
/// area 5 over x −60..60, y −8..8.
pub(crate) fn map_fixture() -> SceneMap {
    let lane = |id, kind, y0: f64, y1: f64, x0: f64, x1: f64, inter, succ: Vec<i64>| MapLane {
        id,
        kind,
        is_intersection: inter,
        left_boundary: vec![[x0, y1], [x1, y1]],
        right_boundary: vec![[x0, y0], [x1, y0]],
        successors: succ,
        predecessors: vec![],
        left_neighbor: None,
        right_neighbor: None,
    };
    let rect = |id, x0, x1, y0, y1| MapArea {
        id,
        polygon: vec![[x0, y0], [x1, y0], [x1, y1], [x0, y1]],
    };
    SceneMap {
        origin: "fixture".into(),
        lanes: vec![
            lane(
                10,
                LaneKind::Vehicle,
                -2.0,
                2.0,
                -50.0,
                30.0,
                false,
                vec![12],
            ),
            lane(11, LaneKind::Bus, 2.0, 6.0, -50.0, 30.0, false, vec![]),
            lane(12, LaneKind::Vehicle, -2.0, 2.0, 30.0, 50.0, true, vec![]),
        ],
        crosswalks: vec![rect(77, 18.0, 22.0, -6.0, 6.0)],
        drivable_areas: vec![rect(5, -60.0, 60.0, -8.0, 8.0)],
    }
}

/// A surround log of [`FRAMES`] frames: the ego's poses `ego`, the
/// objects seen from them (camera convention, no pixel box), the map;
/// everything moved by `rigid` in the world except what the ego sees.
pub(crate) fn surround_with(
    objs: &[ObjSpec],
    map: Option<SceneMap>,
    ego: &dyn Fn(u32) -> WorldPose,
    rigid: Rigid,
) -> Sequence {
    let mut observations = Vec::new();
    for f in 0..FRAMES {
        let e = ego(f);
        let (s, c) = e.yaw.sin_cos();
        for o in objs {
            let p = (o.pos)(f);
            let (dx, dy) = (p[0] - e.x, p[1] - e.y);
            let (fwd, left) = (c * dx + s * dy, -s * dx + c * dy);
            observations.push(Observation {
                frame: f,
                track_id: o.id,
                class: o.class,
                type_name: Some(o.type_name.into()),
                color: None,
                bbox: None,
                position: Some([-left, 1.0, fwd]),
                size: Some(o.size),
                yaw: Some(crate::coords::vehicle_yaw_to_rotation_y((o.yaw)(f) - e.yaw)),
                confidence: 1.0,
                truncation: None,
                occlusion: None,
                footprint: None,
                depth_source: None,
            });
        }
    }
    let mut seq = Sequence {
        name: "around".into(),
        source: "test".into(),
        camera: crate::kitti::KITTI_2011_09_26_CAMERA,
        frame_count: FRAMES,
        fps: 10.0,
        observations,
        timestamps_ns: Some((0..i64::from(FRAMES)).map(|f| f * 100_000_000).collect()),
        ego_poses: Some((0..FRAMES).map(|f| rigid.pose(ego(f))).collect()),
        map: map.map(|m| Arc::new(rigid.map(&m))),
        track_keys: Default::default(),
        skipped: Vec::new(),
    };
    seq.sort();
    seq
}

/// [`surround_with`] with the ego parked at the origin facing +x.
pub(crate) fn surround(objs: Vec<ObjSpec>, map: Option<SceneMap>) -> Sequence {
    let parked = |_| WorldPose {
        x: 0.0,
        y: 0.0,
        z: 0.0,
        yaw: 0.0,
    };
    surround_with(&objs, map, &parked, Rigid::IDENTITY)
}

pub(crate) fn facts_of(seq: &Sequence) -> Vec<WindowFacts> {
    crate::window_facts(
        seq,
        WindowSpec {
            size: 10,
            stride: 10,
        },
        &FactConfig::default(),
    )
    .unwrap()
}

fn window_keys(seq: &Sequence) -> Vec<Vec<String>> {
    facts_of(seq)
        .into_iter()
        .map(|w| w.facts.iter().map(|f| f.to_kb_line()).collect())
        .collect()
}

fn all_keys(seq: &Sequence) -> Vec<String> {
    window_keys(seq).concat()
}

fn has(k: &[String], f: &str) -> bool {
    k.iter().any(|x| x == f)
}

#[test]
fn one_frame_heading_spikes_are_not_turns() {
    // The AV2 log 3b3570b4's car 8765d532 at frames 82-86: its box
    // yaw flips by 68° at 83 and 85 and comes back each next frame.
    let deg = [-21.2, -88.9, -19.0, -88.9, -17.1, -16.4, -15.7];
    let h: Vec<Option<f64>> = deg.iter().map(|d: &f64| Some(d.to_radians())).collect();
    let out = despiked_headings(&h);
    for (k, o) in out.iter().enumerate() {
        let o = o.unwrap().to_degrees();
        assert!(o > -22.0 && o < -15.0, "sighting {k}: {o}");
    }
    // A gap splits the runs; a lone heading stays itself.
    let out = despiked_headings(&[Some(1.0), None, Some(3.0)]);
    assert_eq!(out, vec![Some(1.0), None, Some(3.0)]);
    // Across ±π the median is taken on the unwrapped series.
    let out = despiked_headings(&[Some(3.1), Some(-3.1), Some(3.12)]);
    assert!(out.iter().all(|o| o.unwrap().abs() > 3.0), "{out:?}");
}

#[test]
fn directions_and_headings_in_the_other_objects_frame() {
    // car_1 10 m ahead of the ego heading +x; car_2 5 m to its right
    // (−y) heading the same way; car_3 30 m ahead, facing back;
    // car_4 20 m to car_1's left, heading +y (perpendicular).
    let seq = surround(
        vec![
            ObjSpec::car(1, |_| [10.0, 0.0], 0.0),
            ObjSpec::car(2, |_| [10.0, -5.0], 0.0),
            ObjSpec::car(3, |_| [30.0, 0.0], std::f64::consts::PI),
            ObjSpec::car(4, |_| [10.0, 20.0], std::f64::consts::FRAC_PI_2),
        ],
        None,
    );
    let k = all_keys(&seq);
    for want in [
        "InDirectionOf(car_2, car_1, Right)",
        "InDirectionOf(car_1, car_2, Left)",
        "InDirectionOf(car_1, ego, Forward)",
        "InDirectionOf(ego, car_1, Backward)",
        "InDirectionOf(car_3, car_1, Forward)",
        "InDirectionOf(car_1, car_3, Forward)",
        "InDirectionOf(car_4, car_1, Left)",
        "SameDirection(car_1, car_2)",
        "SameDirection(car_2, car_1)",
        "SameDirection(car_1, ego)",
        "Opposite(car_1, car_3)",
        "Opposite(car_3, car_1)",
        "Perpendicular(car_1, car_4)",
        "Near(car_1, car_2)",
        "Near(car_2, car_1)",
    ] {
        assert!(has(&k, want), "{want} missing: {k:?}");
    }
    for not in [
        "InDirectionOf(car_2, car_1, Left)",
        "InDirectionOf(car_1, car_2, Right)",
        "InDirectionOf(car_2, car_1, Forward)",
        "InDirectionOf(car_1, ego, Backward)",
        "SameDirection(car_1, car_3)",
        "Opposite(car_1, car_2)",
        "Perpendicular(car_1, car_2)",
        "Near(car_1, car_3)",
    ] {
        assert!(!has(&k, not), "{not} present: {k:?}");
    }
    // A lateral limit keeps car_4 (20 m off car_1's side line) out of
    // its front.
    let mut cfg = FactConfig::default();
    cfg.around.direction_lateral_m = Some(2.0);
    let w = crate::range_facts(&seq, 0, 9, &cfg).unwrap();
    assert!(w.contains("InDirectionOf", &["car_2", "car_1", "Right"]));
    assert!(!w.contains("InDirectionOf", &["car_4", "car_1", "Forward"]));
    // Provenance: measured, threshold field, frames.
    let f = w
        .facts
        .iter()
        .find(|f| f.to_kb_line() == "InDirectionOf(car_2, car_1, Right)")
        .unwrap();
    let p = &f.provenance;
    assert_eq!(
        p.threshold.as_ref().map(|t| t.0.as_str()),
        Some("around.direction_within_m")
    );
    assert!((p.measured.unwrap() - 5.0).abs() < 1e-6, "{p:?}");
    assert!(p.note.contains("in 10 of the 10 frames"), "{}", p.note);
}

#[test]
fn parked_objects_are_stationary_and_movers_are_not() {
    let seq = surround(
        vec![
            ObjSpec::car(1, |_| [10.0, 3.0], 0.0),
            ObjSpec::car(2, |f| [10.0 + f64::from(f), -3.0], 0.0),
        ],
        None,
    );
    let w = window_keys(&seq);
    for k in &w {
        assert!(has(k, "Stationary(car_1)"), "{k:?}");
        assert!(has(k, "Stationary(ego)"), "{k:?}");
        assert!(!has(k, "Stationary(car_2)"), "{k:?}");
    }
}

#[test]
fn a_car_turning_ninety_degrees_left_turns_left_in_that_window() {
    // A quarter circle of radius 10 m to the left over frames 0–9,
    // then straight on.
    let quarter = std::f64::consts::FRAC_PI_2;
    let theta = move |f: u32| (f64::from(f.min(9)) / 9.0) * quarter;
    let pos = move |f: u32| {
        let t = theta(f);
        let [x, y] = [10.0 * t.sin(), 10.0 - 10.0 * t.cos()];
        let extra = f64::from(f.saturating_sub(9)) * 1.745;
        [x, y + extra]
    };
    let mut turning = ObjSpec::car(1, pos, 0.0);
    turning.yaw = Box::new(theta);
    let straight = ObjSpec::car(2, |f| [-10.0 + f64::from(f), -3.0], 0.0);
    let w = window_keys(&surround(vec![turning, straight], None));
    assert!(has(&w[0], "TurnLeft(car_1)"), "{:?}", w[0]);
    assert!(!has(&w[0], "TurnRight(car_1)"), "{:?}", w[0]);
    assert!(!has(&w[1], "TurnLeft(car_1)"), "{:?}", w[1]);
    for k in &w {
        assert!(!k.iter().any(|f| f.contains("Turn") && f.contains("car_2")));
    }
    // Mirrored: a right turn.
    let pos = move |f: u32| {
        let [x, y] = pos(f);
        [x, -y]
    };
    let mut turning = ObjSpec::car(1, pos, 0.0);
    turning.yaw = Box::new(move |f| -theta(f));
    let w = window_keys(&surround(vec![turning], None));
    assert!(has(&w[0], "TurnRight(car_1)"), "{:?}", w[0]);
    assert!(!has(&w[0], "TurnLeft(car_1)"), "{:?}", w[0]);
}

#[test]
fn heading_toward_needs_speed_and_aim() {
    let seq = surround(
        vec![
            ObjSpec::car(1, |f| [0.5 * f64::from(f), 3.0], 0.0),
            ObjSpec::car(2, |_| [30.0, 3.0], 0.0),
            ObjSpec::car(3, |_| [30.0, 20.0], 0.0),
        ],
        None,
    );
    let k = all_keys(&seq);
    assert!(has(&k, "HeadingToward(car_1, car_2)"), "{k:?}");
    assert!(!has(&k, "HeadingToward(car_2, car_1)"), "{k:?}");
    assert!(!has(&k, "HeadingToward(car_1, car_3)"), "{k:?}");
}

#[test]
fn crossed_by_a_pedestrian_walking_across_the_path_ahead() {
    // car_1 parked at y = 10 facing +x, front at x = 2.25; the
    // pedestrian crosses its path at x = 6 between frames 8 and 9;
    // pedestrian_3 crosses 20 m ahead (beyond crossing_forward_m).
    let seq = surround(
        vec![
            ObjSpec::car(1, |_| [0.0, 10.0], 0.0),
            ObjSpec::pedestrian(2, |f| [6.0, 7.0 + 0.35 * f64::from(f)]),
            ObjSpec::pedestrian(3, |f| [20.0, 7.0 + 0.35 * f64::from(f)]),
            ObjSpec::pedestrian(4, |f| [6.0 + 0.1 * f64::from(f), 8.5]),
        ],
        None,
    );
    let w = window_keys(&seq);
    assert!(has(&w[0], "CrossedBy(car_1, pedestrian_2)"), "{:?}", w[0]);
    assert!(!has(&w[1], "CrossedBy(car_1, pedestrian_2)"), "{:?}", w[1]);
    for k in &w {
        assert!(!has(k, "CrossedBy(car_1, pedestrian_3)"), "{k:?}");
        assert!(!has(k, "CrossedBy(car_1, pedestrian_4)"), "{k:?}");
    }
}

#[test]
fn camera_sequences_get_none_of_it() {
    let mut seq = surround(vec![ObjSpec::car(1, |_| [10.0, 0.0], 0.0)], None);
    for o in &mut seq.observations {
        o.bbox = Some(crate::model::BBox2D {
            left: 600.0,
            top: 150.0,
            right: 640.0,
            bottom: 200.0,
        });
    }
    assert!(!seq.is_surround());
    let k = all_keys(&seq);
    for p in ["InDirectionOf", "SameDirection", "Stationary", "OnLane"] {
        assert!(!k.iter().any(|f| f.starts_with(p)), "{p}: {k:?}");
    }
}

/// The scene of the invariance property: a moving, slightly turning
/// ego and objects on and around the map of [`map_fixture`].
fn scene() -> Vec<ObjSpec> {
    vec![
        ObjSpec::car(1, |f| [-20.0 + 0.8 * f64::from(f), 0.3], 0.0),
        ObjSpec::car(2, |f| [-5.0 + 0.8 * f64::from(f), 0.2], 0.0),
        ObjSpec::car(3, |_| [12.0, 4.1], 0.0),
        ObjSpec::car(
            4,
            |f| [40.0 - 0.9 * f64::from(f), 4.0],
            std::f64::consts::PI,
        ),
        ObjSpec::pedestrian(5, |f| [20.3, -4.7 + 0.4 * f64::from(f)]),
        ObjSpec::pedestrian(6, |_| [24.7, 7.2]),
        ObjSpec::car(7, |_| [35.0, 12.6], std::f64::consts::FRAC_PI_2),
    ]
}

fn moving_ego(f: u32) -> WorldPose {
    let f = f64::from(f);
    WorldPose {
        x: -12.3 + 0.7 * f,
        y: -0.4 + 0.004 * f * f,
        z: 0.0,
        yaw: 0.011 * f,
    }
}

#[test]
fn the_invariance_scene_has_facts_of_every_kind() {
    let seq = surround_with(&scene(), Some(map_fixture()), &moving_ego, Rigid::IDENTITY);
    let k = all_keys(&seq);
    for p in [
        "OnCrosswalk(",
        "OnLane(",
        "InDrivableArea(",
        "SameLane(",
        "Following(",
        "InDirectionOf(",
        "Opposite(",
        "Stationary(",
        "NearIntersection(",
    ] {
        assert!(k.iter().any(|f| f.starts_with(p)), "{p}: {k:?}");
    }
}

use proptest::prelude::*;

proptest! {
    #![proptest_config(ProptestConfig { cases: 24, failure_persistence: None, rng_seed: proptest::test_runner::RngSeed::Fixed(32), ..ProptestConfig::default() })]

    /// Rotating and translating the source world (poses and map; what
    /// the ego sees stays as it is) changes no fact.
    #[test]
    fn a_rigid_motion_of_the_world_changes_no_fact(
        angle in -std::f64::consts::PI..std::f64::consts::PI,
        dx in -5000.0f64..5000.0,
        dy in -5000.0f64..5000.0,
    ) {
        let base = window_keys(&surround_with(&scene(), Some(map_fixture()), &moving_ego, Rigid::IDENTITY));
        let moved = window_keys(&surround_with(&scene(), Some(map_fixture()), &moving_ego, Rigid { angle, dx, dy }));
        prop_assert_eq!(base, moved);
    }
}
