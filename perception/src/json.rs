//! The JSON track format (`logicrag-tracks/1`), so any tracker's or
//! simulator's output (a CARLA export, a detector + tracker) can be turned
//! into facts. Documented in `docs/formats.md`.
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

use std::path::Path;

use serde::{Deserialize, Serialize};

use crate::error::PerceptionError;
use crate::model::{CameraConfig, DEFAULT_FPS, Observation, Sequence};

/// The format tag this crate reads and writes.
pub const FORMAT_TAG: &str = "logicrag-tracks/1";

/// The on-disk document.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct TrackFile {
    /// Must be [`FORMAT_TAG`].
    pub format: String,
    /// Sequence name used in provenance (`json:<name>`).
    pub name: String,
    /// Frames per second.
    #[serde(default)]
    pub fps: Option<f64>,
    /// The camera.
    pub camera: CameraConfig,
    /// Number of frames; defaults to the last observed frame + 1.
    #[serde(default)]
    pub frame_count: Option<u32>,
    /// Observations in any order.
    pub observations: Vec<Observation>,
}

/// Parses a track document; `origin` names it in errors.
pub fn parse_tracks(text: &str, origin: &str) -> Result<Sequence, PerceptionError> {
    let file: TrackFile = serde_json::from_str(text).map_err(|e| PerceptionError::Json {
        origin: origin.to_string(),
        message: e.to_string(),
    })?;
    if file.format != FORMAT_TAG {
        return Err(PerceptionError::Json {
            origin: origin.to_string(),
            message: format!(
                "`format` must be \"{FORMAT_TAG}\", found \"{}\"",
                file.format
            ),
        });
    }
    let last = file
        .observations
        .iter()
        // Saturating: frame u32::MAX then fails validation (frame >=
        // frame_count) with a message instead of overflowing.
        .map(|o| o.frame.saturating_add(1))
        .max()
        .unwrap_or(0);
    let frame_count = file.frame_count.unwrap_or(last);
    // Checked here as well as in `Sequence::validate` so the message says
    // whether the count was written or implied by an observation's frame.
    crate::model::check_frame_count("frame_count", frame_count).map_err(|m| {
        PerceptionError::Json {
            origin: origin.to_string(),
            message: if file.frame_count.is_some() {
                m
            } else {
                // The implied count saturates at u32::MAX, so name the
                // largest frame itself rather than the count minus one.
                let max = file.observations.iter().map(|o| o.frame).max();
                format!(
                    "an observation has frame {}, so the implied {m}",
                    max.unwrap_or(0)
                )
            },
        }
    })?;
    let mut seq = Sequence {
        name: file.name,
        source: "json".into(),
        camera: file.camera,
        frame_count,
        fps: file.fps.unwrap_or(DEFAULT_FPS),
        observations: file.observations,
        timestamps_ns: None,
        ego_poses: None,
        map: None,
        track_keys: Default::default(),
        skipped: Vec::new(),
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

/// Reads a track file.
pub fn load_tracks(path: &Path) -> Result<Sequence, PerceptionError> {
    let text = crate::textfile::read_text_file(path).map_err(|e| PerceptionError::io(path, e))?;
    parse_tracks(&text, &path.display().to_string())
}

/// Writes a sequence as a track document (pretty JSON).
pub fn to_tracks_json(seq: &Sequence) -> Result<String, PerceptionError> {
    let file = TrackFile {
        format: FORMAT_TAG.to_string(),
        name: seq.name.clone(),
        fps: Some(seq.fps),
        camera: seq.camera,
        frame_count: Some(seq.frame_count),
        observations: seq.observations.clone(),
    };
    serde_json::to_string_pretty(&file).map_err(|e| PerceptionError::Json {
        origin: seq.name.clone(),
        message: e.to_string(),
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
}
