//! Sequences of observations from one camera, their tracks, frame-count
//! limits and the stable object constants (`car_3`).

use serde::{Deserialize, Serialize};
use std::collections::BTreeMap;

use super::{CameraConfig, ObjectClass, Observation};
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
            if !o.bbox.is_valid() {
                return Err(PerceptionError::invalid_sequence(
                    &self.name,
                    format!(
                        "observation {i} (frame {}, track {}) has an invalid box: left {}, top {}, right {}, bottom {} (need finite numbers with left <= right and top <= bottom)",
                        o.frame, o.track_id, o.bbox.left, o.bbox.top, o.bbox.right, o.bbox.bottom
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
        Ok(())
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
                let name = object_name_for(type_name.as_deref(), class, track_id);
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
            Some(c) => object_name_for(type_name, c, track_id),
            None => format!("object_{track_id}"),
        }
    }
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
                bbox: crate::model::BBox2D {
                    left: 10.0,
                    top: 10.0,
                    right: 20.0,
                    bottom: 20.0,
                },
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
