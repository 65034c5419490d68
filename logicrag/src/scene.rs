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

use perception::ego::EgoMotion;
use perception::{FactConfig, Sequence};
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
        let ego = (first..=last)
            .filter_map(|frame| {
                let pose = self.ego.poses.get(frame as usize)?;
                let p = origin.to_camera(pose.position);
                Some(PathPoint {
                    frame,
                    x: p.x(),
                    z: p.z(),
                })
            })
            .collect();
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
        }
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
    }
}
