//! Sequences of observations from one camera, their tracks, frame-count
//! limits and the stable object constants (`car_3`).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use super::{CameraConfig, ObjectClass, Observation, SceneMap, Skipped, WorldPose};
use crate::error::PerceptionError;

/// All observations of one object, sorted by frame.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Track {
    /// Track identity.
    pub track_id: u32,
    /// Stable object constant, e.g. `car_3`.
    pub name: String,
    /// Class of the first observation.
    pub class: ObjectClass,
    /// Type of the first observation that has one.
    pub type_name: Option<String>,
    /// Colour of the first observation that has one.
    pub color: Option<String>,
    /// Observations sorted by frame, one per frame.
    pub observations: Vec<Observation>,
}

impl Track {
    /// First frame the object is seen.
    pub fn first_frame(&self) -> Option<u32> {
        self.observations.first().map(|o| o.frame)
    }
    /// Last frame the object is seen.
    pub fn last_frame(&self) -> Option<u32> {
        self.observations.last().map(|o| o.frame)
    }
}

/// A sequence of frames seen by one camera.
///
/// Invariant (checked by [`Sequence::validate`]): observations are sorted by
/// `(frame, track_id)` with no duplicate pair, every `frame < frame_count`,
/// `frame_count <= MAX_FRAMES`, every box valid.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct Sequence {
    /// Name used in provenance, e.g. `"0000"` or `"urban_crossing"`.
    pub name: String,
    /// Source prefix used in provenance, e.g. `"kitti"`, `"sim"`, `"json"`.
    #[serde(default = "default_source_kind")]
    pub source: String,
    /// The camera.
    pub camera: CameraConfig,
    /// Number of frames (frames without any observation count too).
    pub frame_count: u32,
    /// Frame rate in frames per second (KITTI: 10).
    #[serde(default = "default_fps")]
    pub fps: f64,
    /// Observations sorted by `(frame, track_id)`.
    pub observations: Vec<Observation>,
    /// Per frame, when it was taken (nanoseconds on the source's clock),
    /// strictly increasing, `frame_count` entries; `None`: frames are
    /// `1/fps` apart.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timestamps_ns: Option<Vec<i64>>,
    /// Per frame, the ego's known pose in the source's world frame,
    /// `frame_count` entries; `None`: ego-motion is estimated from the
    /// objects (`perception::ego`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ego_poses: Option<Vec<WorldPose>>,
    /// The static map, in the world frame of `ego_poses` (meaningless
    /// without them: `validate` rejects a map without poses).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<std::sync::Arc<SceneMap>>,
    /// The source's own track ids (AV2 `track_uuid`) by track id: the
    /// object constant becomes `<kind>_<first 8 characters>`
    /// ([`Sequence::short_key`]), the full id goes into provenance.
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub track_keys: BTreeMap<u32, String>,
    /// Inputs the source skipped, counted with their reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<Skipped>,
}

fn default_source_kind() -> String {
    "json".to_string()
}

/// KITTI's frame rate; also the default for JSON tracks that omit `fps`.
pub const DEFAULT_FPS: f64 = 10.0;

/// Most frames a sequence (`frame_count`) or a scenario (`frames`) may have.
///
/// Per-frame state (ego poses, window spans, simulator histories) is
/// allocated for every frame up front, so an untrusted count near
/// `u32::MAX` would exhaust memory before anything could fail. One million
/// is far beyond real inputs — KITTI tracking sequences have at most about
/// 1,100 frames and an hour of video at 30 fps is 108,000 — while every
/// per-frame allocation stays in the tens of megabytes.
pub const MAX_FRAMES: u32 = 1_000_000;

/// Checks a frame count against [`MAX_FRAMES`]; the error message names
/// `field` (`frame_count`, `frames`, …), the value and the limit, for the
/// caller to wrap with the file or scenario it came from.
pub fn check_frame_count(field: &str, frames: u32) -> Result<(), String> {
    if frames > MAX_FRAMES {
        return Err(format!(
            "`{field}` {frames} exceeds the limit of {MAX_FRAMES} frames (perception::MAX_FRAMES)"
        ));
    }
    Ok(())
}

/// Most observations a sequence may have in one frame.
///
/// Pair facts (`TooClose`, `LeftOf`, `On`, …) are computed for every pair of
/// objects of a window, so a frame with `n` objects costs `n²/2` pair
/// measurements and may emit a dozen facts per pair: 2,000 objects in one
/// KITTI frame (280 KB of labels) meant two million pairs and gigabytes of
/// facts. Real scenes stay far below the limit (KITTI tracking frames hold
/// at most a few dozen labelled objects), while 256 objects keep a window
/// to about 33,000 pairs.
pub const MAX_OBJECTS_PER_FRAME: usize = 256;

/// Checks a per-frame object count against [`MAX_OBJECTS_PER_FRAME`]; the
/// message names the frame, the count and the limit, for the caller to wrap
/// with the file or sequence it came from.
pub fn check_objects_per_frame(frame: u32, objects: usize) -> Result<(), String> {
    if objects > MAX_OBJECTS_PER_FRAME {
        return Err(format!(
            "frame {frame} has {objects} objects, more than the limit of {MAX_OBJECTS_PER_FRAME} objects per frame (perception::MAX_OBJECTS_PER_FRAME)"
        ));
    }
    Ok(())
}

fn default_fps() -> f64 {
    DEFAULT_FPS
}

impl Sequence {
    /// `"<source>:<name>"`, used as provenance source.
    pub fn source_label(&self) -> String {
        format!("{}:{}", self.source, self.name)
    }

    /// Whether this is a *surround* (360°) sequence: some observation has
    /// no pixel box (a cuboid placed by its 3D position alone). Only these
    /// get the 360° relations and map facts (`perception::around`,
    /// `perception::mapfacts`); camera sources keep exactly their facts.
    pub fn is_surround(&self) -> bool {
        self.observations.iter().any(|o| o.bbox.is_none())
    }

    /// Sorts observations into the invariant order (stable for equal keys,
    /// which [`Sequence::validate`] then reports as duplicates).
    pub fn sort(&mut self) {
        self.observations.sort_by_key(|o| (o.frame, o.track_id));
    }

    /// Checks the documented invariants.
    pub fn validate(&self) -> Result<(), PerceptionError> {
        check_frame_count("frame_count", self.frame_count)
            .map_err(|m| PerceptionError::invalid_sequence(&self.name, m))?;
        self.camera.intrinsics.validate()?;
        if !(self.camera.height_m.is_finite() && self.camera.height_m > 0.0) {
            return Err(PerceptionError::invalid_sequence(
                &self.name,
                format!(
                    "camera height must be positive, got {}",
                    self.camera.height_m
                ),
            ));
        }
        if !(self.fps.is_finite() && self.fps > 0.0) {
            return Err(PerceptionError::invalid_sequence(
                &self.name,
                format!("fps must be positive, got {}", self.fps),
            ));
        }
        // Sorted order makes each frame's observations one run.
        for run in self.observations.chunk_by(|a, b| a.frame == b.frame) {
            if let Some(o) = run.first() {
                check_objects_per_frame(o.frame, run.len())
                    .map_err(|m| PerceptionError::invalid_sequence(&self.name, m))?;
            }
        }
        let mut prev: Option<(u32, u32)> = None;
        for (i, o) in self.observations.iter().enumerate() {
            let key = (o.frame, o.track_id);
            if let Some(p) = prev
                && key <= p
            {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) is out of order or duplicated",
                        o.frame, o.track_id
                    ),
                ));
            }
            prev = Some(key);
            if o.frame >= self.frame_count {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} has frame {} >= frame_count {}",
                        o.frame, self.frame_count
                    ),
                ));
            }
            if let Some(b) = &o.bbox
                && !b.is_valid()
            {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has an invalid box: left {}, top {}, right {}, bottom {} (need finite numbers with left <= right and top <= bottom)",
                        o.frame, o.track_id, b.left, b.top, b.right, b.bottom
                    ),
                ));
            }
            if o.bbox.is_none() && o.position.is_none() {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has neither a pixel box (`bbox`) nor a 3D `position`: one of them places it",
                        o.frame, o.track_id
                    ),
                ));
            }
            let finite = o.position.is_none_or(|p| p.iter().all(|v| v.is_finite()))
                && o.size.is_none_or(|p| p.iter().all(|v| v.is_finite()))
                && o.yaw.is_none_or(f64::is_finite);
            if !finite {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has non-finite 3D values",
                        o.frame, o.track_id
                    ),
                ));
            }
        }
        self.validate_extras()
    }

    /// The per-frame and per-log additions of 360° logs: timestamps, poses,
    /// map and track keys.
    fn validate_extras(&self) -> Result<(), PerceptionError> {
        let bad = |m: String| PerceptionError::invalid_sequence(&self.name, m);
        let frames = self.frame_count as usize;
        if let Some(ts) = &self.timestamps_ns {
            if ts.len() != frames {
                return Err(bad(format!(
                    "{} timestamps for {frames} frames (need one per frame)",
                    ts.len()
                )));
            }
            if let Some(i) = ts.windows(2).position(|w| w[1] <= w[0]) {
                return Err(bad(format!(
                    "timestamp of frame {} ({}) is not after frame {}'s ({})",
                    i + 1,
                    ts[i + 1],
                    i,
                    ts[i]
                )));
            }
        }
        if let Some(poses) = &self.ego_poses {
            if poses.len() != frames {
                return Err(bad(format!(
                    "{} ego poses for {frames} frames (need one per frame)",
                    poses.len()
                )));
            }
            if let Some(i) = poses.iter().position(|p| !p.is_finite()) {
                return Err(bad(format!("the ego pose of frame {i} is not finite")));
            }
        }
        if let Some(map) = &self.map {
            if self.ego_poses.is_none() {
                return Err(bad(
                    "a map needs the ego's poses in the map's frame (`ego_poses`)".into(),
                ));
            }
            map.validate()
                .map_err(|m| bad(format!("map {}: {m}", map.origin)))?;
        }
        let mut shorts: BTreeMap<String, u32> = BTreeMap::new();
        for (id, key) in &self.track_keys {
            let short = short_key(key);
            if short.is_empty() {
                return Err(bad(format!(
                    "track {id}'s key `{key}` has no letter or digit to name it by"
                )));
            }
            if let Some(other) = shorts.insert(short.clone(), *id) {
                return Err(bad(format!(
                    "tracks {other} and {id} share the short key `{short}` (the first {SHORT_KEY_LEN} characters of their keys)"
                )));
            }
        }
        Ok(())
    }

    /// The short form of a track's source key (`0f3c9a1e` of an AV2 uuid),
    /// `None` for tracks without one.
    pub fn short_key(&self, track_id: u32) -> Option<String> {
        self.track_keys.get(&track_id).map(|k| short_key(k))
    }

    /// The object constant of a track (`car_3`, or `car_0f3c9a1e` for a
    /// track with a source key).
    pub fn name_for(&self, type_name: Option<&str>, class: ObjectClass, track_id: u32) -> String {
        let base = object_name_for(type_name, class, track_id);
        match self.short_key(track_id) {
            Some(short) => match base.rsplit_once('_') {
                Some((kind, _)) => format!("{kind}_{short}"),
                None => format!("{base}_{short}"),
            },
            None => base,
        }
    }

    /// Groups observations into tracks, sorted by track id.
    pub fn tracks(&self) -> Vec<Track> {
        let mut by_id: BTreeMap<u32, Vec<Observation>> = BTreeMap::new();
        for o in &self.observations {
            by_id.entry(o.track_id).or_default().push(o.clone());
        }
        by_id
            .into_iter()
            .filter_map(|(track_id, mut observations)| {
                observations.sort_by_key(|o| o.frame);
                let first = observations.first()?;
                let class = first.class;
                let type_name = observations.iter().find_map(|o| o.type_name.clone());
                let color = observations.iter().find_map(|o| o.color.clone());
                let name = self.name_for(type_name.as_deref(), class, track_id);
                Some(Track {
                    track_id,
                    name,
                    class,
                    type_name,
                    color,
                    observations,
                })
            })
            .collect()
    }

    /// Stable object constant for a track, e.g. `car_3`; `object_<id>` when
    /// the track id does not occur.
    pub fn object_name(&self, track_id: u32) -> String {
        let mut class = None;
        let mut type_name = None;
        for o in self.observations.iter().filter(|o| o.track_id == track_id) {
            class.get_or_insert(o.class);
            if type_name.is_none() {
                type_name = o.type_name.as_deref();
            }
        }
        match class {
            Some(c) => self.name_for(type_name, c, track_id),
            None => format!("object_{track_id}"),
        }
    }
}

/// Characters of a source key kept in object names.
pub const SHORT_KEY_LEN: usize = 8;

/// The first [`SHORT_KEY_LEN`] letters and digits of a source key,
/// lower-cased (an AV2 uuid's first 8 hex digits).
pub fn short_key(key: &str) -> String {
    key.chars()
        .filter(char::is_ascii_alphanumeric)
        .take(SHORT_KEY_LEN)
        .map(|c| c.to_ascii_lowercase())
        .collect()
}

/// The object constant `<kind>_<id>`: kind is the type lower-cased into snake
/// case (`PoliceCar` → `police_car`, KITTI `Person_sitting` → `person`) or
/// the class kind when no type is known.
pub fn object_name_for(type_name: Option<&str>, class: ObjectClass, track_id: u32) -> String {
    let kind = match type_name {
        Some(t) if !t.trim().is_empty() => type_kind(t),
        _ => class.kind().to_string(),
    };
    format!("{kind}_{track_id}")
}

fn type_kind(t: &str) -> String {
    // KITTI spells sitting people `Person_sitting`; the vocabulary calls them
    // `person`.
    if t.eq_ignore_ascii_case("person_sitting") {
        return "person".to_string();
    }
    let mut out = String::with_capacity(t.len() + 4);
    let chars: Vec<char> = t.chars().collect();
    for (i, &c) in chars.iter().enumerate() {
        if c.is_ascii_alphanumeric() {
            if c.is_ascii_uppercase() && i > 0 {
                let prev = chars[i - 1];
                let next_lower = chars.get(i + 1).is_some_and(|n| n.is_ascii_lowercase());
                if (prev.is_ascii_lowercase() || (prev.is_ascii_uppercase() && next_lower))
                    && !out.ends_with('_')
                {
                    out.push('_');
                }
            }
            out.push(c.to_ascii_lowercase());
        } else if !out.is_empty() && !out.ends_with('_') {
            out.push('_');
        }
    }
    let trimmed = out.trim_end_matches('_');
    if trimmed.is_empty() {
        "object".to_string()
    } else {
        trimmed.to_string()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::WindowSpec;

    #[test]
    fn object_names_are_snake_case() {
        assert_eq!(
            object_name_for(Some("Car"), ObjectClass::Vehicle, 3),
            "car_3"
        );
        assert_eq!(
            object_name_for(Some("Person_sitting"), ObjectClass::Person, 4),
            "person_4"
        );
        assert_eq!(
            object_name_for(Some("PoliceCar"), ObjectClass::Vehicle, 1),
            "police_car_1"
        );
        assert_eq!(
            object_name_for(Some("SUV"), ObjectClass::Vehicle, 2),
            "suv_2"
        );
        assert_eq!(
            object_name_for(None, ObjectClass::TrafficSign, 7),
            "traffic_sign_7"
        );
    }

    #[test]
    fn a_frame_count_beyond_max_frames_fails_validation_before_anything_is_sized() {
        // Regression: window_facts sized its window spans, then ego poses,
        // by an unchecked frame_count; near u32::MAX that exhausted memory.
        let mut seq = Sequence {
            name: "huge".into(),
            source: "test".into(),
            camera: crate::kitti::KITTI_2011_09_26_CAMERA,
            frame_count: u32::MAX,
            fps: DEFAULT_FPS,
            observations: Vec::new(),
            timestamps_ns: None,
            ego_poses: None,
            map: None,
            track_keys: Default::default(),
            skipped: Vec::new(),
        };
        let config = crate::FactConfig::default();
        for n in [u32::MAX, MAX_FRAMES + 1] {
            seq.frame_count = n;
            let e = seq.validate().unwrap_err().to_string();
            assert!(
                e.contains("sequence huge")
                    && e.contains(&format!("`frame_count` {n} exceeds the limit of 1000000")),
                "{e}"
            );
            let e = crate::window_facts(&seq, WindowSpec { size: 1, stride: 1 }, &config)
                .unwrap_err()
                .to_string();
            assert!(e.contains("exceeds the limit"), "{e}");
        }
        seq.frame_count = MAX_FRAMES;
        seq.validate().unwrap();
    }

    fn crowd(per_frame: usize) -> Sequence {
        let observations = (0..per_frame)
            .map(|k| Observation {
                frame: 1,
                track_id: k as u32,
                class: ObjectClass::Vehicle,
                type_name: Some("Car".into()),
                color: None,
                bbox: Some(crate::model::BBox2D {
                    left: 10.0,
                    top: 10.0,
                    right: 20.0,
                    bottom: 20.0,
                }),
                position: None,
                size: None,
                yaw: None,
                confidence: 1.0,
                truncation: None,
                occlusion: None,
                footprint: None,
                depth_source: None,
            })
            .collect();
        Sequence {
            name: "crowd".into(),
            source: "test".into(),
            camera: crate::kitti::KITTI_2011_09_26_CAMERA,
            frame_count: 2,
            fps: DEFAULT_FPS,
            observations,
            timestamps_ns: None,
            ego_poses: None,
            map: None,
            track_keys: Default::default(),
            skipped: Vec::new(),
        }
    }

    #[test]
    fn a_frame_with_more_objects_than_the_cap_fails_validation_naming_the_frame() {
        // Regression: 2,000 objects in one frame made the pair facts of
        // window_facts allocate gigabytes and abort.
        crowd(MAX_OBJECTS_PER_FRAME).validate().unwrap();
        let seq = crowd(MAX_OBJECTS_PER_FRAME + 1);
        let e = seq.validate().unwrap_err().to_string();
        assert!(
            e.contains("sequence crowd")
                && e.contains(&format!(
                    "frame 1 has {} objects",
                    MAX_OBJECTS_PER_FRAME + 1
                ))
                && e.contains("MAX_OBJECTS_PER_FRAME"),
            "{e}"
        );
        let e = crate::window_facts(
            &seq,
            WindowSpec { size: 1, stride: 1 },
            &crate::FactConfig::default(),
        )
        .unwrap_err()
        .to_string();
        assert!(e.contains("MAX_OBJECTS_PER_FRAME"), "{e}");
    }
}
