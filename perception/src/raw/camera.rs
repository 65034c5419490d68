//! Camera calibration for raw frames: what a calibration file states (focal
//! lengths, principal point, mounting height, optionally the image size it
//! was made for); the frames give the image size they have.
//!
//! Two file forms are read by [`Calibration::read`]:
//! - a KITTI `calib/NNNN.txt` (its `P2:` line; the mounting height is
//!   KITTI's [`crate::kitti::KITTI_CAMERA_HEIGHT_M`]);
//! - a YAML (or JSON) file with `fx`, `fy`, `cx`, `cy` in pixels,
//!   `height_m`, the optical centre's height above the road in metres, and
//!   optionally `image_width`/`image_height`.

use nalgebra::Matrix3;

use super::error::RawError;
use crate::model::{CameraConfig, CameraIntrinsics};
use serde::Deserialize;
use std::path::{Path, PathBuf};

/// The plausible mounting heights, metres. A value outside is almost always
/// a unit slip (1650 for 1.65 m), which would push every flat-ground depth
/// beyond range without a word.
pub const CAMERA_HEIGHT_RANGE_M: std::ops::RangeInclusive<f64> = 0.1..=10.0;

/// Where the principal point may lie, as a fraction of the image size, when
/// the calibration does not say which size it was made for. Real cameras
/// put it near the centre (KITTI: 0.49 × 0.46). A calibration made for
/// frames 1.5× larger or smaller than these puts it at about 0.33 or 0.74
/// (720p ↔ 1080p), 4/3 or 3/4 at 0.37 or 0.65, twice or half at 0.25 or
/// 0.98: all outside. A camera that really is off-centre states its image
/// size instead.
pub const PRINCIPAL_POINT_RANGE: std::ops::RangeInclusive<f64> = 0.4..=0.6;

/// A pinhole calibration and mounting height, with the file it came from.
///
/// Invariant (checked by [`Calibration::new`], every reader and again by
/// [`Calibration::for_frames`]): all numbers finite, `fx`, `fy` positive,
/// `height_m` within [`CAMERA_HEIGHT_RANGE_M`].
#[derive(Debug, Clone, PartialEq)]
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
    /// The image size the calibration was made for, when it says.
    pub image_size: Option<(u32, u32)>,
    /// The file (or other origin) named in errors.
    pub origin: PathBuf,
}

/// The YAML/JSON form.
#[derive(Deserialize)]
#[serde(deny_unknown_fields)]
struct CalibrationFile {
    fx: f64,
    fy: f64,
    cx: f64,
    cy: f64,
    height_m: f64,
    #[serde(default)]
    image_width: Option<u32>,
    #[serde(default)]
    image_height: Option<u32>,
}

impl Calibration {
    /// A checked calibration without a stated image size; `origin` names
    /// where the numbers came from.
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
            image_size: None,
            origin: origin.to_path_buf(),
        };
        c.check(&FieldNames::YAML)?;
        Ok(c)
    }

    fn check(&self, names: &FieldNames) -> Result<(), RawError> {
        let bad = |field: &str, message: String| RawError::ConfigInvalid {
            path: self.origin.clone(),
            field: field.to_string(),
            message,
        };
        for (field, v) in [(names.fx, self.fx), (names.fy, self.fy)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(field, format!("expected a positive number, got {v}")));
            }
        }
        for (field, v) in [(names.cx, self.cx), (names.cy, self.cy)] {
            if !v.is_finite() {
                return Err(bad(field, format!("expected a finite number, got {v}")));
            }
        }
        if !CAMERA_HEIGHT_RANGE_M.contains(&self.height_m) {
            return Err(bad(
                "height_m",
                format!(
                    "expected the camera's height above the road in metres, {}–{}, got {}",
                    CAMERA_HEIGHT_RANGE_M.start(),
                    CAMERA_HEIGHT_RANGE_M.end(),
                    self.height_m
                ),
            ));
        }
        if let Some((w, h)) = self.image_size {
            for (field, v) in [("image_width", w), ("image_height", h)] {
                if v == 0 {
                    return Err(bad(
                        field,
                        "expected a positive number of pixels, got 0".into(),
                    ));
                }
            }
            // Even an off-centre camera images its principal point.
            for (field, c, size) in [(names.cx, self.cx, w), (names.cy, self.cy, h)] {
                if !(0.0..=f64::from(size)).contains(&c) {
                    return Err(bad(
                        field,
                        format!("expected a point inside the {w}×{h} image, got {c}"),
                    ));
                }
            }
        }
        Ok(())
    }

    /// The calibration matrix `K` (`[fx 0 cx; 0 fy cy; 0 0 1]`), the same
    /// as [`CameraIntrinsics::matrix`] of [`Calibration::for_frames`]'s camera.
    pub fn matrix(&self) -> Matrix3<f64> {
        Matrix3::new(
            self.fx, 0.0, self.cx, //
            0.0, self.fy, self.cy, //
            0.0, 0.0, 1.0,
        )
    }

    /// Reads a KITTI calib file (recognised by its `P2:` line) or a YAML/JSON
    /// file with `fx`, `fy`, `cx`, `cy`, `height_m` and optionally
    /// `image_width`, `image_height`.
    pub fn read(path: &Path) -> Result<Calibration, RawError> {
        let text = crate::textfile::read_text_file(path).map_err(|e| RawError::io(path, e))?;
        Calibration::parse(&text, path)
    }

    /// [`Calibration::read`] on text already in memory; `path` names it in errors.
    pub fn parse(text: &str, path: &Path) -> Result<Calibration, RawError> {
        if text.lines().any(|l| l.trim_start().starts_with("P2:")) {
            let k = crate::kitti::parse_calib(text, path)?;
            let c = Calibration {
                fx: k.fx,
                fy: k.fy,
                cx: k.cx,
                cy: k.cy,
                height_m: crate::kitti::KITTI_CAMERA_HEIGHT_M,
                image_size: None,
                origin: path.to_path_buf(),
            };
            c.check(&FieldNames::KITTI)?;
            return Ok(c);
        }
        let f: CalibrationFile =
            serde_saphyr::from_str(text).map_err(|e| RawError::ConfigSyntax {
                path: path.to_path_buf(),
                message: format!(
                    "{}\nnote: expected a KITTI calib file with a `P2:` line, or YAML with fx, fy, \
                     cx, cy in pixels, height_m in metres and optionally image_width, image_height",
                    crate::error::yaml_message(&e, &path.display().to_string())
                ),
            })?;
        let image_size = match (f.image_width, f.image_height) {
            (Some(w), Some(h)) => Some((w, h)),
            (None, None) => None,
            _ => {
                return Err(RawError::ConfigInvalid {
                    path: path.to_path_buf(),
                    field: "image_width".into(),
                    message: "give both image_width and image_height, or neither".into(),
                });
            }
        };
        let c = Calibration {
            fx: f.fx,
            fy: f.fy,
            cx: f.cx,
            cy: f.cy,
            height_m: f.height_m,
            image_size,
            origin: path.to_path_buf(),
        };
        c.check(&FieldNames::YAML)?;
        Ok(c)
    }

    /// The camera for frames of `width × height` pixels (`frame` names the
    /// first of them in errors). A calibration made for another resolution
    /// would scale every depth, so it is refused: by its stated image size
    /// when it has one, else when its principal point lies outside the
    /// central [`PRINCIPAL_POINT_RANGE`] of the frames.
    pub fn for_frames(
        &self,
        width: u32,
        height: u32,
        frame: &Path,
    ) -> Result<CameraConfig, RawError> {
        self.check(&FieldNames::YAML)?;
        let mismatch = |why: String| RawError::Frames {
            path: frame.to_path_buf(),
            message: format!(
                "the camera calibration {} does not fit these {width}×{height} frames: {why}",
                self.origin.display()
            ),
        };
        match self.image_size {
            Some((w, h)) if (w, h) != (width, height) => {
                return Err(mismatch(format!(
                    "it was made for {w}×{h} images (rescale the frames or the calibration)"
                )));
            }
            Some(_) => {}
            None => {
                let (u, v) = (self.cx / f64::from(width), self.cy / f64::from(height));
                if !PRINCIPAL_POINT_RANGE.contains(&u) || !PRINCIPAL_POINT_RANGE.contains(&v) {
                    return Err(mismatch(format!(
                        "its principal point ({:.1}, {:.1}) lies at {:.2} × {:.2} of the frame, \
                         not near the centre; was it made for another resolution? (if the \
                         camera really is off-centre, state image_width and image_height in a \
                         YAML calibration)",
                        self.cx, self.cy, u, v
                    )));
                }
            }
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

/// How the fields are called in the file form at hand, for errors.
struct FieldNames {
    fx: &'static str,
    fy: &'static str,
    cx: &'static str,
    cy: &'static str,
}

impl FieldNames {
    const YAML: FieldNames = FieldNames {
        fx: "fx",
        fy: "fy",
        cx: "cx",
        cy: "cy",
    };
    const KITTI: FieldNames = FieldNames {
        fx: "P2[0] (fx)",
        fy: "P2[5] (fy)",
        cx: "P2[2] (cx)",
        cy: "P2[6] (cy)",
    };
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
        assert_eq!(c.matrix(), cam.intrinsics.matrix());
        assert_eq!(c.matrix()[(0, 2)], c.cx);
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
        let from_json = Calibration::parse(j, Path::new("cam.json")).expect("parses");
        assert_eq!((from_json.fx, from_json.cy), (c.fx, c.cy));
    }

    #[test]
    fn bad_files_say_what_was_expected() {
        let err = |text: &str| {
            Calibration::parse(text, Path::new("c.yaml"))
                .expect_err("refused")
                .to_string()
        };
        let missing = err("fx: 700\nfy: 700\ncx: 1\ncy: 1\n");
        assert!(missing.starts_with("c.yaml: "), "{missing}");
        assert!(missing.contains("height_m"), "{missing}");
        assert!(
            missing.contains("\nnote: expected a KITTI calib file"),
            "{missing}"
        );
        assert_eq!(
            err("fx: -700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.6\n"),
            "c.yaml: field `fx`: expected a positive number, got -700"
        );
        assert!(err("fx: 700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.6\nfz: 3\n").contains("fz"));
        // Millimetres for metres.
        let mm = err("fx: 700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1650\n");
        assert!(
            mm.contains("field `height_m`") && mm.contains("got 1650"),
            "{mm}"
        );
        let half = err("fx: 700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.6\nimage_width: 640\n");
        assert!(
            half.contains("give both image_width and image_height"),
            "{half}"
        );
        // A KITTI file's fields are named as the file has them.
        let zero = KITTI_P2.replace("7.215377e+02 0 6.095593e+02", "0 0 6.095593e+02");
        let zero = Calibration::parse(&zero, Path::new("0001.txt"))
            .expect_err("zero focal length")
            .to_string();
        assert_eq!(
            zero,
            "0001.txt: field `P2[0] (fx)`: expected a positive number, got 0"
        );
    }

    #[test]
    fn a_calibration_for_another_resolution_is_refused() {
        // Regression: only "principal point inside the frame" was checked,
        // so KITTI's calibration passed on half-size (621×187) frames and
        // put a car on the wrong side of the road.
        let c = Calibration::parse(KITTI_P2, Path::new("0001.txt")).expect("parses");
        for (w, h) in [(621, 187), (2484, 750), (600, 180)] {
            let err = c
                .for_frames(w, h, Path::new("000010.png"))
                .expect_err("another resolution")
                .to_string();
            assert!(
                err.starts_with("000010.png: the camera calibration 0001.txt"),
                "{err}"
            );
            assert!(err.contains("another resolution"), "{err}");
        }
        // Regression: the central half let 1.5× mismatches through
        // (720p calibration on 1080p frames, KITTI's on 4/3-size frames).
        let hd = Calibration::parse(
            "fx: 1000\nfy: 1000\ncx: 640\ncy: 360\nheight_m: 1.5\n",
            Path::new("720p.yaml"),
        )
        .expect("parses");
        assert!(hd.for_frames(1280, 720, Path::new("f")).is_ok());
        assert!(hd.for_frames(1920, 1080, Path::new("f")).is_err());
        assert!(c.for_frames(1656, 500, Path::new("f")).is_err());
        assert!(c.for_frames(828, 250, Path::new("f")).is_err());
        // A stated size is compared exactly, and lets an off-centre camera in.
        let y = "fx: 700\nfy: 700\ncx: 100\ncy: 50\nheight_m: 1.5\nimage_width: 640\nimage_height: 480\n";
        let off = Calibration::parse(y, Path::new("off.yaml")).expect("parses");
        assert!(off.for_frames(640, 480, Path::new("f")).is_ok());
        let err = off
            .for_frames(1280, 960, Path::new("f"))
            .expect_err("wrong size")
            .to_string();
        assert!(err.contains("made for 640×480 images"), "{err}");
        // …but not a principal point outside the stated image.
        let outside = "fx: 700\nfy: 700\ncx: -5000\ncy: 50\nheight_m: 1.5\nimage_width: 640\nimage_height: 480\n";
        let err = Calibration::parse(outside, Path::new("o.yaml"))
            .expect_err("outside")
            .to_string();
        assert!(
            err.contains("field `cx`: expected a point inside the 640×480 image"),
            "{err}"
        );
        let zero =
            "fx: 700\nfy: 700\ncx: 1\ncy: 1\nheight_m: 1.5\nimage_width: 640\nimage_height: 0\n";
        let err = Calibration::parse(zero, Path::new("z.yaml"))
            .expect_err("zero")
            .to_string();
        assert!(err.contains("field `image_height`"), "{err}");
    }

    #[test]
    fn a_hand_built_calibration_is_checked_before_use() {
        let mut c = Calibration::parse(KITTI_P2, Path::new("0001.txt")).expect("parses");
        c.fx = 0.0;
        assert!(c.for_frames(1242, 375, Path::new("f")).is_err());
    }
}
