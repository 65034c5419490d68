//! The JSON track format (`logicrag-tracks/1` and `logicrag-tracks/2`),
//! so any tracker's, simulator's or dataset's output (a CARLA export, a
//! detector + tracker, a nuScenes or Argoverse 2 log) can be turned into
//! facts. Documented in `docs/formats.md`.
//!
//! ```json
//! {
//!   "format": "logicrag-tracks/1",
//!   "name": "my_drive",
//!   "fps": 10,
//!   "camera": {"intrinsics": {"fx": 721.5, "fy": 721.5, "cx": 609.6, "cy": 172.9,
//!                             "image_width": 1242, "image_height": 375},
//!              "height_m": 1.65},
//!   "frame_count": 20,
//!   "observations": [
//!     {"frame": 0, "track_id": 3, "class": "Vehicles", "type_name": "Car", "color": "White",
//!      "bbox": {"left": 300, "top": 160, "right": 455, "bottom": 290},
//!      "position": [-4.5, 1.8, 13.4], "size": [1.5, 1.6, 4.0], "yaw": -1.6}
//!   ]
//! }
//! ```
//! Observations may come in any order (they are sorted); `frame_count`
//! defaults to the last frame + 1, `fps` to 10, `confidence` to 1.
//!
//! Version 2 (`logicrag-tracks/2`) carries what a 360° log has beyond its
//! tracks, every part optional: `camera` (default
//! [`crate::kitti::KITTI_2011_09_26_CAMERA`], the nominal camera that
//! box-less observations never use), `frames` (per frame a `timestamp_ns`
//! and the ego's world `ego_pose`: all frames or none), a `map`
//! ([`SceneMap`]), `track_keys` (the source's own track ids) and `skipped`
//! (what the converter left out, counted). An observation needs a `bbox`
//! or a `position`. [`to_tracks_json`] writes version 1 for a sequence
//! that has none of these, so version-1 files round-trip unchanged.

use std::collections::BTreeMap;
use std::path::Path;
use std::sync::Arc;

use serde::{Deserialize, Serialize};

use crate::error::PerceptionError;
use crate::model::{
    CameraConfig, DEFAULT_FPS, Observation, SceneMap, Sequence, Skipped, WorldPose,
};

/// The version-1 format tag (a camera box source's tracks).
pub const FORMAT_TAG: &str = "logicrag-tracks/1";

/// The version-2 format tag: version 1 plus per-frame timestamps and ego
/// poses, a map, source track ids and counted skips.
pub const FORMAT_TAG_V2: &str = "logicrag-tracks/2";

/// The camera of a version-2 document that names none: KITTI's nominal
/// left colour camera. Only observations with a pixel `bbox` use it.
pub const DEFAULT_CAMERA: CameraConfig = crate::kitti::KITTI_2011_09_26_CAMERA;

/// The on-disk document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackFile {
    /// [`FORMAT_TAG`] or [`FORMAT_TAG_V2`].
    pub format: String,
    /// Sequence name used in provenance (`json:<name>`).
    pub name: String,
    /// Frames per second.
    #[serde(default)]
    pub fps: Option<f64>,
    /// The camera; required in version 1, [`DEFAULT_CAMERA`] when a
    /// version-2 document omits it.
    #[serde(default)]
    pub camera: Option<CameraConfig>,
    /// Number of frames; defaults to the last observed (or listed) frame + 1.
    #[serde(default)]
    pub frame_count: Option<u32>,
    /// Version 2: per-frame timestamps and ego poses.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub frames: Vec<FrameInfo>,
    /// Version 2: the static map, in the world frame of the ego poses.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub map: Option<SceneMap>,
    /// Version 2: the source's own track ids by track id (`{"3": "0f3c…"}`).
    #[serde(default, skip_serializing_if = "BTreeMap::is_empty")]
    pub track_keys: BTreeMap<u32, String>,
    /// Version 2: inputs the converter skipped, counted with their reason.
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub skipped: Vec<Skipped>,
    /// Observations in any order.
    pub observations: Vec<Observation>,
}

/// One frame's timing and ego pose (version 2's `frames`).
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct FrameInfo {
    /// The frame index.
    pub frame: u32,
    /// When it was taken, nanoseconds on the source's clock.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub timestamp_ns: Option<i64>,
    /// The ego's pose in the world frame (`z` up, yaw CCW from `+x`).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub ego_pose: Option<WorldPose>,
}

impl TrackFile {
    /// The document of a sequence: version 2 when it has timestamps, ego
    /// poses, a map, track keys or skips, version 1 otherwise.
    pub fn from_sequence(seq: &Sequence) -> TrackFile {
        let v2 = seq.timestamps_ns.is_some()
            || seq.ego_poses.is_some()
            || seq.map.is_some()
            || !seq.track_keys.is_empty()
            || !seq.skipped.is_empty();
        let frames = if seq.timestamps_ns.is_some() || seq.ego_poses.is_some() {
            (0..seq.frame_count)
                .map(|f| FrameInfo {
                    frame: f,
                    timestamp_ns: seq
                        .timestamps_ns
                        .as_ref()
                        .and_then(|t| t.get(f as usize).copied()),
                    ego_pose: seq
                        .ego_poses
                        .as_ref()
                        .and_then(|p| p.get(f as usize).copied()),
                })
                .collect()
        } else {
            Vec::new()
        };
        TrackFile {
            format: if v2 { FORMAT_TAG_V2 } else { FORMAT_TAG }.to_string(),
            name: seq.name.clone(),
            fps: Some(seq.fps),
            camera: Some(seq.camera),
            frame_count: Some(seq.frame_count),
            frames,
            map: seq.map.as_deref().cloned(),
            track_keys: seq.track_keys.clone(),
            skipped: seq.skipped.clone(),
            observations: seq.observations.clone(),
        }
    }
}

/// Parses a track document (version 1 or 2); `origin` names it in errors.
pub fn parse_tracks(text: &str, origin: &str) -> Result<Sequence, PerceptionError> {
    let json_err = |message: String| PerceptionError::Json {
        origin: origin.to_string(),
        message,
    };
    let file: TrackFile = serde_json::from_str(text).map_err(|e| json_err(e.to_string()))?;
    let v2 = match file.format.as_str() {
        FORMAT_TAG => false,
        FORMAT_TAG_V2 => true,
        other => {
            return Err(json_err(format!(
                "`format` must be \"{FORMAT_TAG}\" or \"{FORMAT_TAG_V2}\", found \"{other}\""
            )));
        }
    };
    if !v2 {
        // Version 1 has none of version 2's fields: a v1 file that uses
        // them is a mistake the user should hear about, not a v2 file.
        let extra = [
            ("frames", !file.frames.is_empty()),
            ("map", file.map.is_some()),
            ("track_keys", !file.track_keys.is_empty()),
            ("skipped", !file.skipped.is_empty()),
        ]
        .into_iter()
        .find(|(_, used)| *used);
        if let Some((field, _)) = extra {
            return Err(json_err(format!(
                "`{field}` needs \"format\": \"{FORMAT_TAG_V2}\" (this file says \"{FORMAT_TAG}\")"
            )));
        }
    }
    let camera = match (file.camera, v2) {
        (Some(c), _) => c,
        (None, true) => DEFAULT_CAMERA,
        (None, false) => {
            return Err(json_err(format!(
                "missing field `camera` (required by \"{FORMAT_TAG}\"; \"{FORMAT_TAG_V2}\" defaults it)"
            )));
        }
    };
    let last = file
        .observations
        .iter()
        .map(|o| o.frame)
        .chain(file.frames.iter().map(|f| f.frame))
        // Saturating: frame u32::MAX then fails validation (frame >=
        // frame_count) with a message instead of overflowing.
        .map(|f| f.saturating_add(1))
        .max()
        .unwrap_or(0);
    let frame_count = file.frame_count.unwrap_or(last);
    // Checked here as well as in `Sequence::validate` so the message says
    // whether the count was written or implied by an observation's frame.
    crate::model::check_frame_count("frame_count", frame_count).map_err(|m| {
        json_err(if file.frame_count.is_some() {
            m
        } else {
            // The implied count saturates at u32::MAX, so name the
            // largest frame itself rather than the count minus one.
            let max = file
                .observations
                .iter()
                .map(|o| o.frame)
                .chain(file.frames.iter().map(|f| f.frame))
                .max();
            format!(
                "an observation has frame {}, so the implied {m}",
                max.unwrap_or(0)
            )
        })
    })?;
    let (timestamps_ns, ego_poses) = frame_table(&file.frames, frame_count).map_err(json_err)?;
    let map = file.map.map(|mut m| {
        // Map facts name their map in provenance: a map without an
        // origin of its own is this file's.
        if m.origin.is_empty() {
            m.origin = origin.to_string();
        }
        Arc::new(m)
    });
    let mut seq = Sequence {
        name: file.name,
        source: "json".into(),
        camera,
        frame_count,
        fps: file.fps.unwrap_or(DEFAULT_FPS),
        observations: file.observations,
        timestamps_ns,
        ego_poses,
        map,
        track_keys: file.track_keys,
        skipped: file.skipped,
    };
    // Checked in the file's own order, so "observation 3" is the fourth in
    // the file. An unknown type or colour was silently read as `Other`.
    for (i, o) in seq.observations.iter().enumerate() {
        let bad = |message: String| PerceptionError::Json {
            origin: origin.to_string(),
            message: format!(
                "observation {i} (frame {}, track {}): {message}",
                o.frame, o.track_id
            ),
        };
        let known = |v: &str, list: &[&str]| list.iter().any(|k| k.eq_ignore_ascii_case(v));
        // KITTI's own type names (`Misc`, `Person_sitting`) are what
        // `perceive` writes for a KITTI source, so they read back.
        let kitti = |t: &str| crate::kitti::kitti_class(t).is_some();
        if let Some(t) = o
            .type_name
            .as_deref()
            .filter(|t| !known(t, &crate::facts::TYPE_VALUES) && !kitti(t))
        {
            return Err(bad(format!(
                "unknown type_name `{t}` (expected one of {})",
                crate::facts::TYPE_VALUES.join(", ")
            )));
        }
        if let Some(c) = o
            .color
            .as_deref()
            .filter(|c| !known(c, &crate::facts::COLOR_VALUES))
        {
            return Err(bad(format!(
                "unknown color `{c}` (expected one of {})",
                crate::facts::COLOR_VALUES.join(", ")
            )));
        }
        if o.size.is_some_and(|s| s.iter().any(|v| *v <= 0.0)) {
            return Err(bad(
                "size must be positive in every dimension (metres)".into()
            ));
        }
        if !(0.0..=1.0).contains(&o.confidence) {
            return Err(bad(format!(
                "confidence must be in [0, 1], got {}",
                o.confidence
            )));
        }
    }
    if !(seq.fps > 0.0 && seq.fps <= MAX_FPS) {
        return Err(PerceptionError::Json {
            origin: origin.to_string(),
            message: format!("fps must be in (0, {MAX_FPS}], got {}", seq.fps),
        });
    }
    seq.sort();
    seq.validate().map_err(|e| PerceptionError::Json {
        origin: origin.to_string(),
        message: e.to_string(),
    })?;
    Ok(seq)
}

/// The highest frame rate accepted (frames per second).
pub const MAX_FPS: f64 = 1000.0;

/// Version 2's `frames` as the sequence's per-frame columns: each column
/// (timestamps, poses) is given for every frame `0..frame_count` or for
/// none; the error names the frame that breaks the rule.
#[allow(clippy::type_complexity)]
fn frame_table(
    frames: &[FrameInfo],
    frame_count: u32,
) -> Result<(Option<Vec<i64>>, Option<Vec<WorldPose>>), String> {
    if frames.is_empty() {
        return Ok((None, None));
    }
    let mut by_frame: BTreeMap<u32, &FrameInfo> = BTreeMap::new();
    for (i, f) in frames.iter().enumerate() {
        if f.frame >= frame_count {
            return Err(format!(
                "frames[{i}]: frame {} >= frame_count {frame_count}",
                f.frame
            ));
        }
        if by_frame.insert(f.frame, f).is_some() {
            return Err(format!("frames[{i}]: frame {} is listed twice", f.frame));
        }
    }
    let any_time = frames.iter().any(|f| f.timestamp_ns.is_some());
    let any_pose = frames.iter().any(|f| f.ego_pose.is_some());
    let mut times = Vec::new();
    let mut poses = Vec::new();
    for frame in 0..frame_count {
        let info = by_frame.get(&frame);
        if any_time {
            match info.and_then(|f| f.timestamp_ns) {
                Some(t) => times.push(t),
                None => {
                    return Err(format!(
                        "frame {frame} has no `timestamp_ns` (when one frame has a timestamp, every frame 0..{frame_count} needs one)"
                    ));
                }
            }
        }
        if any_pose {
            match info.and_then(|f| f.ego_pose) {
                Some(p) => poses.push(p),
                None => {
                    return Err(format!(
                        "frame {frame} has no `ego_pose` (when one frame has an ego pose, every frame 0..{frame_count} needs one)"
                    ));
                }
            }
        }
    }
    Ok((any_time.then_some(times), any_pose.then_some(poses)))
}

/// Reads a track file.
pub fn load_tracks(path: &Path) -> Result<Sequence, PerceptionError> {
    let text = crate::textfile::read_text_file(path).map_err(|e| PerceptionError::io(path, e))?;
    parse_tracks(&text, &path.display().to_string())
}

/// Writes a sequence as a track document (pretty JSON): version 2 when
/// it has timestamps, ego poses, a map, track keys or skips
/// ([`TrackFile::from_sequence`]), version 1 otherwise.
pub fn to_tracks_json(seq: &Sequence) -> Result<String, PerceptionError> {
    serde_json::to_string_pretty(&TrackFile::from_sequence(seq)).map_err(|e| {
        PerceptionError::Json {
            origin: seq.name.clone(),
            message: e.to_string(),
        }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const DOC: &str = r#"{
      "format": "logicrag-tracks/1", "name": "t",
      "camera": {"intrinsics": {"fx": 700, "fy": 700, "cx": 600, "cy": 180, "image_width": 1200, "image_height": 370}, "height_m": 1.65},
      "observations": [
        {"frame": 1, "track_id": 2, "class": "Pedestrian", "bbox": {"left": 1, "top": 2, "right": 3, "bottom": 4}},
        {"frame": 0, "track_id": 2, "class": "Vehicles", "type_name": "Car", "bbox": {"left": 1, "top": 2, "right": 3, "bottom": 4}}
      ]}"#;

    #[test]
    fn bad_values_are_refused_not_read_as_other() {
        for (from, to, want) in [
            (
                "\"type_name\": \"Car\"",
                "\"type_name\": \"Spaceship\"",
                "unknown type_name `Spaceship`",
            ),
            (
                "\"type_name\": \"Car\"",
                "\"type_name\": \"Car\", \"color\": \"Plaid\"",
                "unknown color `Plaid`",
            ),
            (
                "\"type_name\": \"Car\"",
                "\"type_name\": \"Car\", \"confidence\": 50",
                "confidence must be in [0, 1]",
            ),
            (
                "\"type_name\": \"Car\"",
                "\"type_name\": \"Car\", \"size\": [1.5, -1.6, 4.0]",
                "size must be positive",
            ),
            (
                "\"name\": \"t\"",
                "\"name\": \"t\", \"fps\": 1e300",
                "fps must be in (0, 1000]",
            ),
        ] {
            let doc = DOC.replacen(from, to, 1);
            assert_ne!(doc, DOC);
            let e = parse_tracks(&doc, "bad.json").unwrap_err().to_string();
            assert!(e.starts_with("bad.json") && e.contains(want), "{want}: {e}");
        }
        // The observation is numbered in the file's order.
        let e = parse_tracks(&DOC.replacen("\"Car\"", "\"Rocket\"", 1), "o.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("observation 1 (frame 0, track 2)"), "{e}");
    }

    #[test]
    fn parses_sorts_and_round_trips() {
        let s = parse_tracks(DOC, "doc").unwrap();
        assert_eq!(s.frame_count, 2);
        assert_eq!(s.observations[0].frame, 0);
        assert_eq!(s.source_label(), "json:t");
        let back = parse_tracks(&to_tracks_json(&s).unwrap(), "back").unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn the_largest_frame_number_is_an_error_not_an_overflow() {
        let doc = DOC.replace("\"frame\": 1,", "\"frame\": 4294967295,");
        let e = parse_tracks(&doc, "big.json").unwrap_err().to_string();
        assert!(e.starts_with("big.json:"), "{e}");
        assert!(
            e.contains("frame 4294967295, so the implied `frame_count` 4294967295 exceeds"),
            "{e}"
        );
    }

    #[test]
    fn a_frame_count_beyond_max_frames_is_an_error_naming_the_file_and_limit() {
        // Regression: `frame_count` near u32::MAX parsed, and window facts
        // then allocated ego poses for every frame until memory ran out.
        let with_count = |n: u32| {
            DOC.replace(
                "\"observations\"",
                &format!("\"frame_count\": {n}, \"observations\""),
            )
        };
        for n in [u32::MAX, crate::model::MAX_FRAMES + 1] {
            let e = parse_tracks(&with_count(n), "huge.json")
                .unwrap_err()
                .to_string();
            assert!(e.starts_with("huge.json:"), "{e}");
            assert!(
                e.contains(&format!(
                    "`frame_count` {n} exceeds the limit of 1000000 frames"
                )),
                "{e}"
            );
        }
        let ok = parse_tracks(&with_count(crate::model::MAX_FRAMES), "ok.json").unwrap();
        assert_eq!(ok.frame_count, crate::model::MAX_FRAMES);
    }

    #[test]
    fn depth_provenance_survives_a_round_trip() {
        // `logicrag perceive` writes raw-frame tracks with `depth_source`;
        // reading them back as `json:` must keep it, not reject the field.
        let mut s = parse_tracks(DOC, "doc").unwrap();
        s.observations[0].depth_source = Some(crate::model::DepthSource::Fused);
        let text = to_tracks_json(&s).unwrap();
        assert!(text.contains("\"depth_source\": \"fused\""), "{text}");
        assert_eq!(parse_tracks(&text, "back").unwrap(), s);
    }

    #[test]
    fn errors_name_the_origin_and_position() {
        let e = parse_tracks(&DOC.replace("\"left\": 1,", "\"lefty\": 1,"), "my.json")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("my.json:"), "{e}");
        assert!(e.contains("line"), "{e}");
        let e = parse_tracks(&DOC.replace("tracks/1", "tracks/9"), "my.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("format"), "{e}");
        let dup = DOC.replace("\"frame\": 1,", "\"frame\": 0,");
        assert!(
            parse_tracks(&dup, "d")
                .unwrap_err()
                .to_string()
                .contains("duplicated")
        );
    }

    /// A version-2 document with every new field: box-less observations,
    /// no camera, frames with timestamps and poses, a map, track keys.
    const DOC_V2: &str = r#"{
      "format": "logicrag-tracks/2", "name": "surround",
      "frames": [
        {"frame": 1, "timestamp_ns": 1100, "ego_pose": {"x": 11, "y": 5, "z": 0.5, "yaw": 0.1}},
        {"frame": 0, "timestamp_ns": 1000, "ego_pose": {"x": 10, "y": 5, "yaw": 0.1}}
      ],
      "map": {"lanes": [{"id": 7, "kind": "Bus", "left_boundary": [[0, 2], [30, 2]], "right_boundary": [[0, -2], [30, -2]]}],
              "crosswalks": [{"id": 8, "polygon": [[20, -5], [22, -5], [22, 5]]}],
              "drivable_areas": []},
      "track_keys": {"3": "0f3c9a1e-aaaa-bbbb"},
      "skipped": [{"reason": "the ego vehicle's own box", "count": 2, "example": "row 0"}],
      "observations": [
        {"frame": 0, "track_id": 3, "class": "Vehicles", "type_name": "Car",
         "position": [-2.0, 0.8, 12.0], "size": [1.6, 1.9, 4.5], "yaw": -1.57},
        {"frame": 1, "track_id": 3, "class": "Vehicles", "type_name": "Car",
         "position": [-2.0, 0.8, 11.0], "size": [1.6, 1.9, 4.5], "yaw": -1.57}
      ]}"#;

    #[test]
    fn version_two_reads_frames_map_keys_and_defaults_the_camera() {
        let s = parse_tracks(DOC_V2, "v2.json").unwrap();
        assert_eq!(s.frame_count, 2);
        assert_eq!(s.camera, DEFAULT_CAMERA);
        assert_eq!(s.timestamps_ns, Some(vec![1000, 1100]));
        let poses = s.ego_poses.as_ref().unwrap();
        assert_eq!((poses[0].x, poses[0].z, poses[1].z), (10.0, 0.0, 0.5));
        let map = s.map.as_ref().unwrap();
        assert_eq!(map.origin, "v2.json");
        assert_eq!(map.lanes[0].kind, crate::model::LaneKind::Bus);
        assert_eq!(s.track_keys[&3], "0f3c9a1e-aaaa-bbbb");
        assert_eq!(s.skipped[0].count, 2);
        assert!(s.observations.iter().all(|o| o.bbox.is_none()));
    }

    #[test]
    fn a_full_sequence_round_trips_through_version_two() {
        let s = parse_tracks(DOC_V2, "v2.json").unwrap();
        let text = to_tracks_json(&s).unwrap();
        assert!(text.contains(FORMAT_TAG_V2), "{text}");
        assert_eq!(parse_tracks(&text, "back").unwrap(), s);
        // Without the new fields the writer keeps version 1.
        let v1 = parse_tracks(DOC, "doc").unwrap();
        let text = to_tracks_json(&v1).unwrap();
        assert!(text.contains(&format!("\"{FORMAT_TAG}\"")), "{text}");
        assert!(
            !text.contains("frames") && !text.contains("track_keys"),
            "{text}"
        );
    }

    #[test]
    fn version_two_errors_name_the_frame_or_field() {
        for (from, to, want) in [
            // One frame without a pose while another has one.
            (
                "\"ego_pose\": {\"x\": 10, \"y\": 5, \"yaw\": 0.1}",
                "\"ego_pose\": null",
                "frame 0 has no `ego_pose`",
            ),
            (
                "\"timestamp_ns\": 1100,",
                "",
                "frame 1 has no `timestamp_ns`",
            ),
            (
                "\"timestamp_ns\": 1100,",
                "\"timestamp_ns\": 900,",
                "timestamp of frame 1 (900) is not after frame 0's (1000)",
            ),
            (
                "{\"frame\": 0, \"timestamp_ns\": 1000",
                "{\"frame\": 1, \"timestamp_ns\": 1000",
                "frame 1 is listed twice",
            ),
            (
                "\"y\": 5, \"z\": 0.5",
                "\"y\": 5, \"z\": 0.5, \"roll\": 0",
                "unknown field `roll`",
            ),
            (
                "[[20, -5], [22, -5], [22, 5]]",
                "[[20, -5], [22, -5]]",
                "pedestrian crossing 8 needs at least three points",
            ),
            (
                "\"position\": [-2.0, 0.8, 11.0], ",
                "",
                "neither a pixel box",
            ),
        ] {
            let doc = DOC_V2.replacen(from, to, 1);
            assert_ne!(doc, DOC_V2, "{from}");
            let e = parse_tracks(&doc, "v2.json").unwrap_err().to_string();
            assert!(e.starts_with("v2.json") && e.contains(want), "{want}: {e}");
        }
        // A version-1 file keeps its required camera and refuses v2 fields.
        let e = parse_tracks(&DOC_V2.replace("tracks/2", "tracks/1"), "v1.json")
            .unwrap_err()
            .to_string();
        assert!(e.contains("`frames` needs"), "{e}");
        let no_camera = DOC.replace(
            r#""camera": {"intrinsics": {"fx": 700, "fy": 700, "cx": 600, "cy": 180, "image_width": 1200, "image_height": 370}, "height_m": 1.65},"#,
            "",
        );
        assert_ne!(no_camera, DOC);
        let e = parse_tracks(&no_camera, "v1.json").unwrap_err().to_string();
        assert!(e.contains("missing field `camera`"), "{e}");
        let v2 = parse_tracks(&no_camera.replace("tracks/1", "tracks/2"), "v2.json").unwrap();
        assert_eq!(v2.camera, DEFAULT_CAMERA);
    }
}
