//! What a window looks like, for people: each frame's 2D boxes with their
//! track ids and object names, and a bird's-eye view of the tracks and of
//! the camera's own path in the *ego frame* — the camera frame of the
//! window's first frame (X to the right, Z forward, metres). The web page
//! draws it, and [`crate::plot`] turns it into a picture.
//!
//! Positions are the ones perception reasons with: a labelled or estimated
//! 3D position where the source has one, else the box bottom on flat
//! ground; the camera path is perception's ego-motion estimate
//! ([`perception::ego::estimate`]) with the same configuration as the
//! facts, so the picture and the facts agree.
//!
//! A 360° log with a map (`av2:DIR`) adds the map around the window
//! ([`MapView`]): lanes, crosswalks and drivable areas moved from the
//! source's world frame into the same ego frame (the log's ego pose
//! anchors it, [`perception::coords::WorldAnchor`]) and cut to a box around
//! the window's objects and ego path, so the view stays small.

use perception::ego::{EgoMotion, EgoPose};
use perception::{FactConfig, SceneMap, Sequence};
use serde::Serialize;
use std::collections::BTreeMap;

/// One point of a bird's-eye path.
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct PathPoint {
    /// The frame the point was seen in.
    pub frame: u32,
    /// Metres to the right of the ego frame's origin.
    pub x: f64,
    /// Metres ahead of the ego frame's origin.
    pub z: f64,
}

/// One object's path over a window.
///
/// Invariant: `points` are sorted by frame, one per frame the object was
/// seen with a ground position, and hold at least one point.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct TrackPath {
    /// Track id.
    pub track_id: u32,
    /// Object constant, as in the facts (`car_3`).
    pub name: String,
    /// The class's predicate (`Vehicles`, `Pedestrian`, …).
    pub class: String,
    /// Colour name, when the source knows it (`White`).
    pub color: Option<String>,
    /// The path in the ego frame.
    pub points: Vec<PathPoint>,
}

/// One 2D box in a frame.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameBox {
    /// Track id.
    pub track_id: u32,
    /// Object constant (`car_3`).
    pub name: String,
    /// The class's predicate.
    pub class: String,
    /// `[left, top, right, bottom]` in pixels of the source's image size.
    pub bbox: [f64; 4],
}

/// One frame's boxes.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct FrameBoxes {
    /// Frame number in the source.
    pub frame: u32,
    /// The boxes, sorted by track id.
    pub boxes: Vec<FrameBox>,
}

/// A window as a picture: boxes per frame and a bird's-eye view.
///
/// Invariant: `frames` has one entry per frame `first_frame..=last_frame`
/// (frames without objects have no boxes); `ego` has one point per frame
/// of the window, the first at the origin; `tracks` are sorted by track id.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct SceneView {
    /// Window id.
    pub window: String,
    /// First frame.
    pub first_frame: u32,
    /// Last frame.
    pub last_frame: u32,
    /// Width of the source's images, pixels (box coordinates refer to it).
    pub image_width: u32,
    /// Height of the source's images, pixels.
    pub image_height: u32,
    /// Boxes per frame.
    pub frames: Vec<FrameBoxes>,
    /// Objects' ground paths in the ego frame.
    pub tracks: Vec<TrackPath>,
    /// The camera's path in the ego frame.
    pub ego: Vec<PathPoint>,
    /// The map around the window, in the ego frame; absent (not in the
    /// JSON) for a source without a map.
    #[serde(skip_serializing_if = "Option::is_none")]
    pub map: Option<MapView>,
}

/// Metres of map kept beyond the window's objects and ego path.
pub const MAP_MARGIN_M: f64 = 10.0;
/// Metres of map kept at most on each side of the window's ego path,
/// however far its objects reach: the view stays readable and small.
pub const MAP_REACH_M: f64 = 80.0;

/// The map around a window, in its ego frame (X to the right, Z forward,
/// metres, as [`PathPoint`]); every polygon is `[x, z]` points, cut to
/// `bounds` (an element wholly outside is left out).
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapView {
    /// The box the map was cut to: `[x_min, z_min, x_max, z_max]`.
    pub bounds: [f64; 4],
    /// Lane segments, in the map's order.
    pub lanes: Vec<LaneView>,
    /// Pedestrian crossings.
    pub crosswalks: Vec<AreaView>,
    /// Drivable areas.
    pub drivable_areas: Vec<AreaView>,
}

/// One lane segment of a [`MapView`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct LaneView {
    /// The map's id of the segment (the facts' `lane_<id>`).
    pub id: i64,
    /// What it is for: `Vehicle`, `Bus` or `Bike` (`LaneType`'s value).
    pub kind: &'static str,
    /// Whether it lies inside an intersection.
    pub is_intersection: bool,
    /// Its area: the left boundary, then the right one reversed.
    pub polygon: Vec<[f64; 2]>,
}

/// One area (crosswalk, drivable area) of a [`MapView`].
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct AreaView {
    /// The map's id of the area.
    pub id: i64,
    /// Its outline.
    pub polygon: Vec<[f64; 2]>,
}

/// `poly` cut to the box `[x_min, z_min, x_max, z_max]` (Sutherland–Hodgman
/// against each side; the box is convex, so any polygon cuts right). Fewer
/// than three points: nothing of it is inside.
pub fn clip_polygon(poly: &[[f64; 2]], bounds: [f64; 4]) -> Vec<[f64; 2]> {
    let [x0, z0, x1, z1] = bounds;
    // Each side as (axis, limit, keep the side above the limit).
    let sides = [(0, x0, true), (0, x1, false), (1, z0, true), (1, z1, false)];
    let mut out: Vec<[f64; 2]> = poly.to_vec();
    for (axis, limit, above) in sides {
        if out.is_empty() {
            break;
        }
        let inside = |p: &[f64; 2]| {
            if above {
                p[axis] >= limit
            } else {
                p[axis] <= limit
            }
        };
        let input = std::mem::take(&mut out);
        let Some(&last) = input.last() else { break };
        let mut prev = last;
        for &p in &input {
            let (pin, qin) = (inside(&p), inside(&prev));
            if pin != qin {
                let t = (limit - prev[axis]) / (p[axis] - prev[axis]);
                let mut c = [
                    prev[0] + t * (p[0] - prev[0]),
                    prev[1] + t * (p[1] - prev[1]),
                ];
                c[axis] = limit;
                out.push(c);
            }
            if pin {
                out.push(p);
            }
            prev = p;
        }
    }
    if out.len() < 3 { Vec::new() } else { out }
}

/// The box around `points` widened by [`MAP_MARGIN_M`], and never more
/// than [`MAP_REACH_M`] beyond the ego path's own box. `None` without
/// any ego point.
fn map_bounds<'a>(
    ego: &'a [PathPoint],
    objects: impl Iterator<Item = &'a PathPoint>,
) -> Option<[f64; 4]> {
    let span = |pts: &mut dyn Iterator<Item = &PathPoint>| {
        pts.fold(None, |b: Option<[f64; 4]>, p| {
            Some(match b {
                None => [p.x, p.z, p.x, p.z],
                Some([a, b, c, d]) => [a.min(p.x), b.min(p.z), c.max(p.x), d.max(p.z)],
            })
        })
    };
    let e = span(&mut ego.iter())?;
    let all = span(&mut ego.iter().chain(objects))?;
    Some([
        (all[0] - MAP_MARGIN_M).max(e[0] - MAP_REACH_M),
        (all[1] - MAP_MARGIN_M).max(e[1] - MAP_REACH_M),
        (all[2] + MAP_MARGIN_M).min(e[2] + MAP_REACH_M),
        (all[3] + MAP_MARGIN_M).min(e[3] + MAP_REACH_M),
    ])
}

/// The map's elements in the ego frame of `origin`, cut to `bounds`.
fn map_view(
    map: &SceneMap,
    anchor: &perception::coords::WorldAnchor,
    origin: &EgoPose,
    bounds: [f64; 4],
) -> MapView {
    let to_view = |poly: &[[f64; 2]]| -> Vec<[f64; 2]> {
        let moved: Vec<[f64; 2]> = poly
            .iter()
            .map(|&p| {
                let c = origin.to_camera(anchor.to_bev(p));
                [c.x(), c.z()]
            })
            .collect();
        clip_polygon(&moved, bounds)
    };
    let areas = |list: &[perception::MapArea]| -> Vec<AreaView> {
        list.iter()
            .filter_map(|a| {
                let polygon = to_view(&a.polygon);
                (!polygon.is_empty()).then_some(AreaView { id: a.id, polygon })
            })
            .collect()
    };
    MapView {
        bounds,
        lanes: map
            .lanes
            .iter()
            .filter_map(|l| {
                let polygon = to_view(&l.polygon());
                (!polygon.is_empty()).then_some(LaneView {
                    id: l.id,
                    kind: l.kind.value(),
                    is_intersection: l.is_intersection,
                    polygon,
                })
            })
            .collect(),
        crosswalks: areas(&map.crosswalks),
        drivable_areas: areas(&map.drivable_areas),
    }
}

/// A sequence's tracks and ego-motion, computed once, cut into windows on
/// demand.
#[derive(Debug, Clone)]
pub struct Scenes {
    seq: Sequence,
    ego: EgoMotion,
    /// Track id → (name, class predicate, colour).
    names: BTreeMap<u32, (String, String, Option<String>)>,
}

impl Scenes {
    /// The scenes of a pipeline's source, from the sequence it kept
    /// (`None` without [`crate::pipeline::OpenOptions::keep_scene`], or
    /// for a `facts:` source).
    pub fn of(pipeline: &crate::pipeline::Pipeline) -> Option<Scenes> {
        let extras = pipeline.extras();
        Some(Scenes::new(extras.sequence.as_ref()?, &extras.config))
    }

    /// Estimates the sequence's ego-motion with the configuration the
    /// facts were computed with.
    pub fn new(seq: &Sequence, config: &FactConfig) -> Scenes {
        let ego = perception::ego::estimate(seq, &config.ego);
        let names = seq
            .tracks()
            .into_iter()
            .map(|t| {
                (
                    t.track_id,
                    (t.name, t.class.predicate().to_string(), t.color),
                )
            })
            .collect();
        Scenes {
            seq: seq.clone(),
            ego,
            names,
        }
    }

    /// The window `first..=last` (frames past the sequence are left out)
    /// as a [`SceneView`] named `window`.
    pub fn window(&self, window: &str, first: u32, last: u32) -> SceneView {
        let last = last.min(self.seq.frame_count.saturating_sub(1)).max(first);
        let origin = self
            .ego
            .poses
            .get(first as usize)
            .copied()
            .unwrap_or(perception::EgoPose::IDENTITY);
        let lo = self.seq.observations.partition_point(|o| o.frame < first);
        let hi = self.seq.observations.partition_point(|o| o.frame <= last);
        let inside = self.seq.observations.get(lo..hi).unwrap_or_default();
        let mut frames: Vec<FrameBoxes> = (first..=last)
            .map(|frame| FrameBoxes {
                frame,
                boxes: Vec::new(),
            })
            .collect();
        let mut paths: BTreeMap<u32, Vec<PathPoint>> = BTreeMap::new();
        let unknown = (String::new(), String::new(), None);
        for o in inside {
            let (name, class, _) = self.names.get(&o.track_id).unwrap_or(&unknown);
            // A 360° log's cuboid has no pixel box: it shows in the
            // bird's-eye view only.
            if let (Some(f), Some(b)) = (frames.get_mut((o.frame - first) as usize), o.bbox) {
                f.boxes.push(FrameBox {
                    track_id: o.track_id,
                    name: name.clone(),
                    class: class.clone(),
                    bbox: [b.left, b.top, b.right, b.bottom],
                });
            }
            // A road or sidewalk is a region, not a point: its box says
            // nothing about where it lies.
            if o.class.is_ground_surface() || o.footprint.is_some() {
                continue;
            }
            let Some(cam) = perception::geometry::ground_point(o, &self.seq.camera) else {
                continue;
            };
            if let Some(world) = self.ego.to_world(o.frame, cam) {
                let p = origin.to_camera(world);
                paths.entry(o.track_id).or_default().push(PathPoint {
                    frame: o.frame,
                    x: p.x(),
                    z: p.z(),
                });
            }
        }
        let map = match (&self.seq.map, &self.ego.anchor) {
            (Some(m), Some(anchor)) => {
                let ego: Vec<PathPoint> = self.ego_path(&origin, first, last);
                map_bounds(&ego, paths.values().flatten())
                    .map(|bounds| map_view(m, anchor, &origin, bounds))
            }
            _ => None,
        };
        let tracks = paths
            .into_iter()
            .filter_map(|(track_id, points)| {
                let (name, class, color) = self.names.get(&track_id)?.clone();
                Some(TrackPath {
                    track_id,
                    name,
                    class,
                    color,
                    points,
                })
            })
            .collect();
        let ego = self.ego_path(&origin, first, last);
        let k = &self.seq.camera.intrinsics;
        SceneView {
            window: window.to_string(),
            first_frame: first,
            last_frame: last,
            image_width: k.image_width,
            image_height: k.image_height,
            frames,
            tracks,
            ego,
            map,
        }
    }

    /// The ego's path over `first..=last` in the ego frame of `origin`.
    fn ego_path(&self, origin: &EgoPose, first: u32, last: u32) -> Vec<PathPoint> {
        (first..=last)
            .filter_map(|frame| {
                let pose = self.ego.poses.get(frame as usize)?;
                let p = origin.to_camera(pose.position);
                Some(PathPoint {
                    frame,
                    x: p.x(),
                    z: p.z(),
                })
            })
            .collect()
    }

    /// The inputs the source skipped, counted with their reason.
    pub fn skipped(&self) -> &[perception::Skipped] {
        &self.seq.skipped
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_simulated_window_has_boxes_tracks_and_an_ego_path_from_the_origin() {
        let seq = perception::Source::parse("sim:urban_crossing")
            .and_then(|s| s.load(None))
            .expect("the built-in scenario loads");
        let scenes = Scenes::new(&seq, &FactConfig::default());
        let v = scenes.window("w", 10, 19);
        assert_eq!(v.frames.len(), 10);
        assert_eq!(v.ego.len(), 10);
        let first = v.ego.first().expect("an ego point");
        assert!(first.x.abs() < 1e-9 && first.z.abs() < 1e-9, "{first:?}");
        assert!(v.frames.iter().any(|f| !f.boxes.is_empty()));
        assert!(!v.tracks.is_empty());
        for t in &v.tracks {
            assert!(!t.points.is_empty() && !t.name.is_empty());
            assert!(t.points.windows(2).all(|w| w[0].frame < w[1].frame));
            assert!(t.points.iter().all(|p| (10..=19).contains(&p.frame)));
        }
        // Names are the facts' constants.
        assert!(v.tracks.iter().any(|t| t.name.starts_with("pedestrian_")));
        // No map, none in the JSON either.
        assert!(v.map.is_none());
        let json = serde_json::to_value(&v).expect("serialises");
        assert!(json.get("map").is_none(), "{json}");
    }

    #[test]
    fn a_polygon_is_cut_to_the_box_and_one_outside_is_dropped() {
        let square = [[-5.0, -5.0], [5.0, -5.0], [5.0, 5.0], [-5.0, 5.0]];
        let cut = clip_polygon(&square, [0.0, 0.0, 10.0, 10.0]);
        assert_eq!(cut.len(), 4, "{cut:?}");
        for p in &cut {
            assert!(
                (0.0..=5.0).contains(&p[0]) && (0.0..=5.0).contains(&p[1]),
                "{p:?}"
            );
        }
        assert!(clip_polygon(&square, [20.0, 20.0, 30.0, 30.0]).is_empty());
        assert_eq!(
            clip_polygon(&square, [-9.0, -9.0, 9.0, 9.0]),
            square.to_vec()
        );
    }

    /// A 360° log: box-less objects around the ego (one behind it), a
    /// known pose heading along the world's +y, and a map in that world
    /// frame. The map comes out in the ego frame, cut near the objects.
    #[test]
    fn a_surround_log_s_map_is_drawn_in_the_ego_frame_around_its_objects() {
        use perception::{LaneKind, MapArea, MapLane, ObjectClass, Observation, WorldPose};
        let obs = |frame: u32, track_id: u32, x: f64, z: f64| Observation {
            frame,
            track_id,
            class: ObjectClass::Vehicle,
            type_name: Some("RegularVehicle".into()),
            color: None,
            bbox: None,
            position: Some([x, 0.8, z]),
            size: Some([1.6, 1.9, 4.5]),
            yaw: Some(0.0),
            confidence: 1.0,
            truncation: None,
            occlusion: None,
            footprint: None,
            depth_source: None,
        };
        // The ego at (100, 200) heading +y (yaw π/2), moving 1 m a frame.
        let poses: Vec<WorldPose> = (0..3)
            .map(|i| WorldPose {
                x: 100.0,
                y: 200.0 + f64::from(i),
                z: 0.0,
                yaw: std::f64::consts::FRAC_PI_2,
            })
            .collect();
        let lane = MapLane {
            id: 42,
            kind: LaneKind::Bike,
            is_intersection: true,
            // Along +y, 2–4 m to the ego's left (heading +y, its left is −x).
            left_boundary: vec![[96.0, 190.0], [96.0, 230.0]],
            right_boundary: vec![[98.0, 190.0], [98.0, 230.0]],
            successors: vec![],
            predecessors: vec![],
            left_neighbor: None,
            right_neighbor: None,
        };
        let crosswalk = MapArea {
            id: 7,
            polygon: vec![[95.0, 210.0], [105.0, 210.0], [105.0, 213.0], [95.0, 213.0]],
        };
        let far = MapArea {
            id: 8,
            polygon: vec![[900.0, 900.0], [901.0, 900.0], [901.0, 901.0]],
        };
        let seq = Sequence {
            name: "log".into(),
            source: "av2".into(),
            camera: perception::kitti::KITTI_2011_09_26_CAMERA,
            frame_count: 3,
            fps: 10.0,
            observations: vec![
                obs(0, 1, 0.0, 12.0),
                obs(0, 2, 3.0, -15.0),
                obs(1, 1, 0.0, 12.0),
                obs(1, 2, 3.0, -15.0),
            ],
            timestamps_ns: None,
            ego_poses: Some(poses),
            map: Some(std::sync::Arc::new(SceneMap {
                origin: "test".into(),
                lanes: vec![lane],
                crosswalks: vec![crosswalk, far],
                drivable_areas: vec![],
            })),
            track_keys: Default::default(),
            skipped: Vec::new(),
        };
        let v = Scenes::new(&seq, &FactConfig::default()).window("w", 0, 2);
        // Every object is drawn, the one behind the ego too (z < 0).
        assert_eq!(v.tracks.len(), 2);
        assert!(
            v.tracks
                .iter()
                .any(|t| t.points.iter().all(|p| p.z < -13.0))
        );
        assert!(v.frames.iter().all(|f| f.boxes.is_empty()));
        let map = v.map.as_ref().expect("a map");
        // The ego faces +y: world (96..98, y) lies 2–4 m to its left
        // (x = −4..−2 in the ego frame), from 10 m behind to 30 m ahead.
        let lane = map.lanes.first().expect("the lane");
        assert_eq!(
            (lane.id, lane.kind, lane.is_intersection),
            (42, "Bike", true)
        );
        for p in &lane.polygon {
            assert!((-4.0 - 1e-9..=-2.0 + 1e-9).contains(&p[0]), "{p:?}");
        }
        let zs: Vec<f64> = lane.polygon.iter().map(|p| p[1]).collect();
        assert!(zs.iter().any(|z| (z + 10.0).abs() < 1e-9), "{zs:?}");
        // The crosswalk: 10–13 m ahead, across x = −5..5.
        assert_eq!(map.crosswalks.len(), 1, "the far one is cut away");
        let cw = &map.crosswalks[0];
        assert_eq!(cw.id, 7);
        assert!(
            cw.polygon
                .iter()
                .all(|p| (10.0 - 1e-9..=13.0 + 1e-9).contains(&p[1]))
        );
        // Cut to the objects and ego plus the margin.
        let [x0, z0, x1, z1] = map.bounds;
        assert!(
            x0 <= -MAP_MARGIN_M && x1 >= 3.0 + MAP_MARGIN_M,
            "{:?}",
            map.bounds
        );
        assert!(z0 <= -15.0 - MAP_MARGIN_M + 1e-9 && z1 >= 12.0 + MAP_MARGIN_M - 1e-9);
        let json = serde_json::to_value(&v).expect("serialises");
        assert_eq!(json["map"]["lanes"][0]["kind"], "Bike");
        assert_eq!(json["map"]["crosswalks"][0]["id"], 7);
    }
}
