//! Camera calibration for raw frames: what a calibration file states (focal
//! lengths, principal point, mounting height), without the image size, which
//! the frames themselves give.
//!
//! Two file forms are read by [`Calibration::read`]:
//! - a KITTI `calib/NNNN.txt` (its `P2:` line; the mounting height is
//!   KITTI's [`crate::kitti::KITTI_CAMERA_HEIGHT_M`]);
//! - a YAML (or JSON) file with `fx`, `fy`, `cx`, `cy` in pixels and
//!   `height_m`, the optical centre's height above the road in metres.

use super::error::RawError;
use crate::model::{CameraConfig, CameraIntrinsics};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// A pinhole calibration and mounting height.
///
/// Invariant (checked by [`Calibration::new`] and every reader): all fields
/// finite, `fx`, `fy` and `height_m` positive.
#[derive(Debug, Clone, Copy, PartialEq, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct Calibration {
    /// Focal length along x, pixels.
    pub fx: f64,
    /// Focal length along y, pixels.
    pub fy: f64,
    /// Principal point x, pixels.
    pub cx: f64,
    /// Principal point y, pixels.
    pub cy: f64,
    /// Height of the optical centre above the flat ground, metres.
    pub height_m: f64,
}

impl Calibration {
    /// A checked calibration; `origin` names where the numbers came from.
    pub fn new(
        fx: f64,
        fy: f64,
        cx: f64,
        cy: f64,
        height_m: f64,
        origin: &Path,
    ) -> Result<Calibration, RawError> {
        let c = Calibration {
            fx,
            fy,
            cx,
            cy,
            height_m,
        };
        c.check(origin)?;
        Ok(c)
    }

    fn check(&self, origin: &Path) -> Result<(), RawError> {
        let bad = |field: &str, message: &str| RawError::ConfigInvalid {
            path: origin.to_path_buf(),
            field: field.to_string(),
            message: message.to_string(),
        };
        for (field, v) in [
            ("fx", self.fx),
            ("fy", self.fy),
            ("height_m", self.height_m),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, &format!("expected a positive number, got {v}")));
            }
        }
        for (field, v) in [("cx", self.cx), ("cy", self.cy)] {
            if !v.is_finite() {
                return Err(bad(field, &format!("expected a finite number, got {v}")));
            }
        }
        Ok(())
    }

    /// Reads a KITTI calib file (recognised by its `P2:` line) or a YAML/JSON
    /// file with `fx`, `fy`, `cx`, `cy` and `height_m`.
    pub fn read(path: &Path) -> Result<Calibration, RawError> {
        let text = std::fs::read_to_string(path).map_err(|e| RawError::io(path, e))?;
        Calibration::parse(&text, path)
    }

    /// [`Calibration::read`] on text already in memory; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Calibration, RawError> {
        if text.lines().any(|l| l.trim_start().starts_with("P2:")) {
            let k = crate::kitti::parse_calib(text, path)?;
            return Calibration::new(
                k.fx,
                k.fy,
                k.cx,
                k.cy,
                crate::kitti::KITTI_CAMERA_HEIGHT_M,
                path,
            );
        }
        let c: Calibration = serde_saphyr::from_str(text).map_err(|e| RawError::ConfigSyntax {
            path: path.to_path_buf(),
            message: format!(
                "{} (expected a KITTI calib file with a `P2:` line, or YAML with fx, fy, cx, cy \
                 in pixels and height_m in metres)",
                crate::error::yaml_message(&e, &path.display().to_string())
            ),
        })?;
        c.check(path)?;
        Ok(c)
    }

    /// The camera for frames of `width × height` pixels. The principal point
    /// must lie inside the frame: one outside is the usual sign of a
    /// calibration made at another resolution, which would scale every depth.
    pub fn for_frames(
        &self,
        width: u32,
        height: u32,
        origin: &Path,
    ) -> Result<CameraConfig, RawError> {
        let (w, h) = (f64::from(width), f64::from(height));
        if !(0.0..=w).contains(&self.cx) || !(0.0..=h).contains(&self.cy) {
            return Err(RawError::Frames {
                path: PathBuf::from(origin),
                message: format!(
                    "the calibration's principal point ({:.1}, {:.1}) lies outside the \
                     {width}×{height} frames; was it made for another resolution?",
                    self.cx, self.cy
                ),
            });
        }
        Ok(CameraConfig {
            intrinsics: CameraIntrinsics {
                fx: self.fx,
                fy: self.fy,
                cx: self.cx,
                cy: self.cy,
                image_width: width,
                image_height: height,
            },
            height_m: self.height_m,
        })
    }
}

impl From<&CameraConfig> for Calibration {
    fn from(c: &CameraConfig) -> Calibration {
        Calibration {
            fx: c.intrinsics.fx,
            fy: c.intrinsics.fy,
            cx: c.intrinsics.cx,
            cy: c.intrinsics.cy,
            height_m: c.height_m,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const KITTI_P2: &str = "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nP2: 7.215377e+02 0 6.095593e+02 44.85 0 7.215377e+02 1.728540e+02 0.2163 0 0 1 0.0027\n";

    #[test]
    fn reads_a_kitti_calib_file() {
        let c = Calibration::parse(KITTI_P2, Path::new("0001.txt")).expect("parses");
        assert_eq!(c.fx, 721.5377);
        assert_eq!(c.cy, 172.854);
        assert_eq!(c.height_m, crate::kitti::KITTI_CAMERA_HEIGHT_M);
        let cam = c.for_frames(1242, 375, Path::new("d")).expect("fits");
        assert_eq!(cam.intrinsics.image_width, 1242);
    }

    #[test]
    fn reads_yaml_and_json() {
        let y = "fx: 700\nfy: 710\ncx: 640\ncy: 360\nheight_m: 1.4\n";
        let c = Calibration::parse(y, Path::new("cam.yaml")).expect("parses");
        assert_eq!(
            (c.fx, c.fy, c.cx, c.cy, c.height_m),
            (700.0, 710.0, 640.0, 360.0, 1.4)
        );
        let j = r#"{"fx": 700, "fy": 710, "cx": 640, "cy": 360, "height_m": 1.4}"#;
        assert_eq!(
            Calibration::parse(j, Path::new("cam.json")).expect("parses"),
            c
        );
    }

    #[test]
    fn bad_files_say_what_was_expected() {
        let missing = Calibration::parse("fx: 700\nfy: 700\ncx: 1\ncy: 1\n", Path::new("c.yaml"))
            .expect_err("no height")
            .to_string();
        assert!(missing.starts_with("c.yaml: "), "{missing}");
        assert!(missing.contains("height_m"), "{missing}");
        let negative = Calibration::parse(
            "fx: -700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.6\n",
            Path::new("c.yaml"),
        )
        .expect_err("negative focal length")
        .to_string();
        assert_eq!(
            negative,
            "c.yaml: field `fx`: expected a positive number, got -700"
        );
        let unknown = Calibration::parse(
            "fx: 700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.6\nfz: 3\n",
            Path::new("c.yaml"),
        )
        .expect_err("unknown field")
        .to_string();
        assert!(unknown.contains("fz"), "{unknown}");
    }

    #[test]
    fn a_calibration_for_another_resolution_is_refused() {
        let c = Calibration::parse(KITTI_P2, Path::new("0001.txt")).expect("parses");
        let err = c
            .for_frames(600, 180, Path::new("half"))
            .expect_err("cx 609.6 is outside 600 px")
            .to_string();
        assert!(err.contains("another resolution"), "{err}");
    }
}
