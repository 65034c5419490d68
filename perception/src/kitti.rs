//! KITTI tracking labels: `label_02/NNNN.txt` + `calib/NNNN.txt` → [`Sequence`].
//!
//! A label line is `frame track_id type truncated occluded alpha left top
//! right bottom h w l x y z rotation_y [score]`. `DontCare` lines (track id
//! −1) mark regions the annotators skipped; they are not objects and are
//! counted in [`KittiLoad::dont_care`] instead of becoming observations.
//!
//! Intrinsics come from the calib file's `P2` (the rectified left colour
//! camera). The image size is taken from the data, in this order:
//! 1. the first PNG in `image_02/NNNN/` when present (its header);
//! 2. [`KITTI_RECORDING_DAYS`], a table keyed by the `P2` focal length: KITTI
//!    recorded on five days, each with one calibration and one rectified
//!    image size (published with the raw dataset);
//! 3. the label extents: KITTI clips boxes to the image, so the largest
//!    right/bottom edge + 1 bounds the size from below (also used to check 1
//!    and 2: a label outside the chosen image is an error).

use std::path::{Path, PathBuf};

use nalgebra::Matrix3x4;

use crate::error::PerceptionError;
use crate::model::{
    BBox2D, CameraConfig, CameraIntrinsics, DEFAULT_FPS, ObjectClass, Observation, Sequence,
};

/// Height of the KITTI colour cameras above the road, metres (the
/// recording platform's documented mounting height).
pub const KITTI_CAMERA_HEIGHT_M: f64 = 1.65;

/// KITTI's left colour camera on the 2011-09-26 drives (`P2` of tracking
/// sequences 0000–0013, 1242×375 pixels) at [`KITTI_CAMERA_HEIGHT_M`]: the
/// simulator's default camera and the tests' typical one. Real KITTI data
/// reads its own calibration file instead.
pub const KITTI_2011_09_26_CAMERA: CameraConfig = CameraConfig {
    intrinsics: CameraIntrinsics {
        fx: 721.5377,
        fy: 721.5377,
        cx: 609.5593,
        cy: 172.854,
        image_width: 1242,
        image_height: 375,
    },
    height_m: KITTI_CAMERA_HEIGHT_M,
};

/// One KITTI recording day: its `P2` focal length and rectified image size.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RecordingDay {
    /// Date of the recording (calibration) day.
    pub date: &'static str,
    /// `P2[0][0]`, pixels.
    pub fx: f64,
    /// Rectified image width.
    pub width: u32,
    /// Rectified image height.
    pub height: u32,
}

/// KITTI's five recording days (data from the KITTI raw dataset's
/// calibration files). Tracking sequences 0000–0013 are 2011-09-26,
/// 0014–0017 2011-09-28, 0018–0019 2011-09-29, 0020 2011-10-03.
pub const KITTI_RECORDING_DAYS: [RecordingDay; 5] = [
    RecordingDay {
        date: "2011-09-26",
        fx: 721.5377,
        width: 1242,
        height: 375,
    },
    RecordingDay {
        date: "2011-09-28",
        fx: 707.0493,
        width: 1224,
        height: 370,
    },
    RecordingDay {
        date: "2011-09-29",
        fx: 718.3351,
        width: 1238,
        height: 374,
    },
    RecordingDay {
        date: "2011-09-30",
        fx: 707.0912,
        width: 1226,
        height: 370,
    },
    RecordingDay {
        date: "2011-10-03",
        fx: 718.8560,
        width: 1241,
        height: 376,
    },
];

/// Slack (pixels) for labels beyond the image edge: KITTI boxes of
/// truncated objects are clipped, but a few annotations in 2011-09-29 spill
/// up to two pixels over.
const LABEL_EDGE_SLACK_PX: f64 = 3.0;

/// A loaded KITTI sequence and what was left out of it.
#[derive(Debug, Clone, PartialEq)]
pub struct KittiLoad {
    /// The sequence (source `"kitti"`, name `"NNNN"`).
    pub sequence: Sequence,
    /// Number of `DontCare` regions (not objects).
    pub dont_care: usize,
    /// Where the image size came from.
    pub image_size_source: ImageSizeSource,
}

/// Origin of a sequence's image size.
#[derive(Debug, Clone, PartialEq)]
pub enum ImageSizeSource {
    /// Read from an image file's header.
    Image(PathBuf),
    /// From [`KITTI_RECORDING_DAYS`] (the date).
    RecordingDay(&'static str),
    /// Inferred from the label extents.
    LabelExtent,
}

impl std::fmt::Display for ImageSizeSource {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            ImageSizeSource::Image(p) => write!(f, "size read from {}", p.display()),
            ImageSizeSource::RecordingDay(d) => write!(f, "size of the {d} recording day"),
            ImageSizeSource::LabelExtent => f.write_str("size inferred from the labels"),
        }
    }
}

/// Intrinsics parsed from a calib file's `P2` line.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Calib {
    /// `P2` focal length x.
    pub fx: f64,
    /// `P2` focal length y.
    pub fy: f64,
    /// `P2` principal point x.
    pub cx: f64,
    /// `P2` principal point y.
    pub cy: f64,
}

/// Lists the sequence names (`NNNN`) with a label file under `root/label_02`.
pub fn list_sequences(root: &Path) -> Result<Vec<String>, PerceptionError> {
    let dir = root.join("label_02");
    let rd = std::fs::read_dir(&dir).map_err(|e| PerceptionError::io(&dir, e))?;
    let mut out = Vec::new();
    for entry in rd {
        let entry = entry.map_err(|e| PerceptionError::io(&dir, e))?;
        let name = entry.file_name();
        let name = name.to_string_lossy();
        if let Some(stem) = name.strip_suffix(".txt") {
            out.push(stem.to_string());
        }
    }
    out.sort();
    Ok(out)
}

/// Parses a calib file's `P2` line.
pub fn parse_calib(text: &str, path: &Path) -> Result<Calib, PerceptionError> {
    for (i, line) in text.lines().enumerate() {
        let Some(rest) = line.trim_start().strip_prefix("P2:") else {
            continue;
        };
        let nums: Result<Vec<f64>, _> = rest.split_whitespace().map(str::parse::<f64>).collect();
        let nums = nums.map_err(|e| PerceptionError::Parse {
            path: path.to_path_buf(),
            line: i + 1,
            message: format!("P2 must be 12 numbers: {e}"),
        })?;
        if nums.len() != 12 {
            return Err(PerceptionError::Parse {
                path: path.to_path_buf(),
                line: i + 1,
                message: format!("P2 must be 12 numbers, found {}", nums.len()),
            });
        }
        // P2 = K·[I | t] for the left colour camera: its left 3×3 block is
        // the calibration matrix K (row-major in the file).
        let p2 = Matrix3x4::from_row_slice(&nums);
        return Ok(Calib {
            fx: p2[(0, 0)],
            fy: p2[(1, 1)],
            cx: p2[(0, 2)],
            cy: p2[(1, 2)],
        });
    }
    Err(PerceptionError::File {
        path: path.to_path_buf(),
        message: "no `P2:` line".into(),
    })
}

/// The object types of KITTI tracking labels (besides `DontCare`).
pub const KITTI_TYPES: [&str; 8] = [
    "Car",
    "Van",
    "Truck",
    "Tram",
    "Pedestrian",
    "Person_sitting",
    "Cyclist",
    "Misc",
];

pub(crate) fn kitti_class(t: &str) -> Option<ObjectClass> {
    Some(match t {
        "Car" | "Van" | "Truck" | "Tram" => ObjectClass::Vehicle,
        "Pedestrian" => ObjectClass::Pedestrian,
        "Person" | "Person_sitting" => ObjectClass::Person,
        "Cyclist" => ObjectClass::Cyclist,
        "Misc" => ObjectClass::Misc,
        _ => return None,
    })
}

/// Parses a label file into observations (unsorted) and the DontCare count.
pub fn parse_labels(text: &str, path: &Path) -> Result<(Vec<Observation>, usize), PerceptionError> {
    let mut out = Vec::new();
    let mut dont_care = 0;
    // Line of each (frame, track) seen and objects per frame, so that a
    // duplicate or an over-full frame is reported at its line while the file
    // is read, before anything quadratic in the objects of a frame runs.
    let mut seen: std::collections::HashMap<(u32, u32), usize> = std::collections::HashMap::new();
    let mut per_frame: std::collections::HashMap<u32, usize> = std::collections::HashMap::new();
    for (i, line) in text.lines().enumerate() {
        let err = |message: String| PerceptionError::Parse {
            path: path.to_path_buf(),
            line: i + 1,
            message,
        };
        let f: Vec<&str> = line.split_whitespace().collect();
        if f.is_empty() {
            continue;
        }
        if f.len() != 17 && f.len() != 18 {
            return Err(err(format!(
                "expected 17 fields (frame track type truncated occluded alpha 4×bbox 3×size 3×location rotation_y) or 18 with score, found {}",
                f.len()
            )));
        }
        let num = |k: usize, what: &str| -> Result<f64, PerceptionError> {
            let v: f64 = f[k].parse().map_err(|_| {
                err(format!(
                    "field {} ({what}) is not a number: `{}`",
                    k + 1,
                    f[k]
                ))
            })?;
            if v.is_finite() {
                Ok(v)
            } else {
                Err(err(format!("field {} ({what}) is not finite", k + 1)))
            }
        };
        let frame: u32 = f[0].parse().map_err(|_| {
            err(format!(
                "frame must be a non-negative integer, found `{}`",
                f[0]
            ))
        })?;
        let track: i64 = f[1]
            .parse()
            .map_err(|_| err(format!("track id must be an integer, found `{}`", f[1])))?;
        let type_name = f[2];
        if type_name == "DontCare" {
            dont_care += 1;
            continue;
        }
        let class = kitti_class(type_name).ok_or_else(|| {
            err(format!("unknown object type `{type_name}` (expected Car, Van, Truck, Tram, Pedestrian, Person_sitting, Cyclist, Misc or DontCare)"))
        })?;
        let track_id = u32::try_from(track).map_err(|_| {
            err(format!(
                "track id must be in 0..={} for `{type_name}`, found {track}",
                u32::MAX
            ))
        })?;
        let truncation = num(3, "truncated")?;
        let occluded: i64 = f[4]
            .parse()
            .map_err(|_| err(format!("occluded must be an integer 0-3, found `{}`", f[4])))?;
        let occlusion = u8::try_from(occluded)
            .ok()
            .filter(|o| *o <= 3)
            .ok_or_else(|| err(format!("occluded must be 0-3, found {occluded}")))?;
        let bbox = BBox2D {
            left: num(6, "left")?,
            top: num(7, "top")?,
            right: num(8, "right")?,
            bottom: num(9, "bottom")?,
        };
        if !bbox.is_valid() {
            return Err(err(format!(
                "box must have left <= right and top <= bottom, found left {}, top {}, right {}, bottom {}",
                bbox.left, bbox.top, bbox.right, bbox.bottom
            )));
        }
        let size = [num(10, "height")?, num(11, "width")?, num(12, "length")?];
        let position = [num(13, "x")?, num(14, "y")?, num(15, "z")?];
        let yaw = num(16, "rotation_y")?;
        let confidence = if f.len() == 18 {
            num(17, "score")? as f32
        } else {
            1.0
        };
        if let Some(first) = seen.insert((frame, track_id), i + 1) {
            return Err(err(format!(
                "track {track_id} appears twice in frame {frame} (first on line {first})"
            )));
        }
        let count = per_frame.entry(frame).or_insert(0);
        *count += 1;
        crate::model::check_objects_per_frame(frame, *count).map_err(err)?;
        // KITTI writes −1000 for unknown 3D; keep such objects 2D-only.
        let has_3d = size.iter().all(|v| *v > 0.0) && position[2] > -999.0;
        out.push(Observation {
            frame,
            track_id,
            class,
            type_name: Some(type_name.to_string()),
            color: None,
            bbox: Some(bbox),
            position: has_3d.then_some(position),
            size: has_3d.then_some(size),
            yaw: has_3d.then_some(yaw),
            confidence,
            truncation: Some(truncation as f32),
            occlusion: Some(occlusion),
            footprint: None,
            depth_source: None,
        });
    }
    Ok((out, dont_care))
}

fn read(path: &Path) -> Result<String, PerceptionError> {
    crate::textfile::read_text_file(path).map_err(|e| PerceptionError::io(path, e))
}

fn image_size_from_dir(dir: &Path) -> Option<(u32, u32, PathBuf)> {
    let rd = std::fs::read_dir(dir).ok()?;
    let mut pngs: Vec<PathBuf> = rd
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x.eq_ignore_ascii_case("png")))
        .collect();
    pngs.sort();
    let first = pngs.into_iter().next()?;
    let (w, h) = png_dimensions(&first)?;
    Some((w, h, first))
}

/// Width and height from a PNG file's header (signature, then the `IHDR`
/// chunk); `None` when the file is not a PNG or cannot be read. Only the
/// first 24 bytes are read: this is all the loader needs from an image, and
/// it keeps KITTI loading free of an image decoder (feature `raw`).
fn png_dimensions(path: &Path) -> Option<(u32, u32)> {
    use std::io::Read;
    let mut head = [0u8; 24];
    crate::textfile::open_regular(path)
        .ok()?
        .read_exact(&mut head)
        .ok()?;
    parse_png_header(&head)
}

/// [`png_dimensions`] on the first 24 bytes of a file.
fn parse_png_header(head: &[u8; 24]) -> Option<(u32, u32)> {
    const SIGNATURE: [u8; 8] = [0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n'];
    if head[..8] != SIGNATURE || &head[12..16] != b"IHDR" {
        return None;
    }
    let be = |b: &[u8]| -> Option<u32> { Some(u32::from_be_bytes(b.try_into().ok()?)) };
    let (w, h) = (be(&head[16..20])?, be(&head[20..24])?);
    // The PNG specification forbids zero dimensions.
    (w > 0 && h > 0).then_some((w, h))
}

/// Loads sequence `name` (e.g. `"0000"`) from a KITTI tracking root holding
/// `label_02/` and `calib/` (and optionally `image_02/`).
pub fn load(root: &Path, name: &str) -> Result<KittiLoad, PerceptionError> {
    let label_path = root.join("label_02").join(format!("{name}.txt"));
    let calib_path = root.join("calib").join(format!("{name}.txt"));
    let calib = parse_calib(&read(&calib_path)?, &calib_path)?;
    let (mut observations, dont_care) = parse_labels(&read(&label_path)?, &label_path)?;
    // `parse_labels` has rejected duplicate (frame, track) pairs at their
    // line, so the sort leaves the order `Sequence::validate` expects.
    observations.sort_by_key(|o| (o.frame, o.track_id));
    let max_right = observations
        .iter()
        .filter_map(|o| o.bbox.map(|b| b.right))
        .fold(0.0, f64::max);
    let max_bottom = observations
        .iter()
        .filter_map(|o| o.bbox.map(|b| b.bottom))
        .fold(0.0, f64::max);
    let (width, height, source) =
        if let Some((w, h, p)) = image_size_from_dir(&root.join("image_02").join(name)) {
            (w, h, ImageSizeSource::Image(p))
        } else if let Some(day) = KITTI_RECORDING_DAYS
            .iter()
            .find(|d| (d.fx - calib.fx).abs() < 1e-3)
        {
            (
                day.width,
                day.height,
                ImageSizeSource::RecordingDay(day.date),
            )
        } else {
            let w = (max_right.ceil() + 1.0).max(2.0 * calib.cx).ceil();
            let h = (max_bottom.ceil() + 1.0).max(2.0 * calib.cy).ceil();
            (w as u32, h as u32, ImageSizeSource::LabelExtent)
        };
    if max_right > f64::from(width) + LABEL_EDGE_SLACK_PX
        || max_bottom > f64::from(height) + LABEL_EDGE_SLACK_PX
    {
        let culprit = observations
            .iter()
            .find(|o| {
                o.bbox.is_some_and(|b| {
                    b.right > f64::from(width) + LABEL_EDGE_SLACK_PX
                        || b.bottom > f64::from(height) + LABEL_EDGE_SLACK_PX
                })
            })
            .map(|o| format!(" (first: frame {} track {})", o.frame, o.track_id))
            .unwrap_or_default();
        return Err(PerceptionError::File {
            path: label_path,
            message: format!(
                "labels reach ({max_right}, {max_bottom}), outside the {width}x{height} image ({source}){culprit}"
            ),
        });
    }
    // Saturating: frame u32::MAX then fails validation (frame >= frame_count)
    // with a message instead of overflowing.
    let frame_count = observations.last().map_or(0, |o| o.frame.saturating_add(1));
    // Checked here as well as in `Sequence::validate` so the error names the
    // label file rather than only the sequence.
    crate::model::check_frame_count("frame_count", frame_count).map_err(|m| {
        let last = observations.last().map_or(0, |o| o.frame);
        PerceptionError::File {
            path: label_path.clone(),
            message: format!("a label has frame {last}, so {m}"),
        }
    })?;
    let sequence = Sequence {
        name: name.to_string(),
        source: "kitti".into(),
        camera: CameraConfig {
            intrinsics: CameraIntrinsics {
                fx: calib.fx,
                fy: calib.fy,
                cx: calib.cx,
                cy: calib.cy,
                image_width: width,
                image_height: height,
            },
            height_m: KITTI_CAMERA_HEIGHT_M,
        },
        frame_count,
        fps: DEFAULT_FPS,
        observations,
        timestamps_ns: None,
        ego_poses: None,
        map: None,
        track_keys: Default::default(),
        skipped: Vec::new(),
    };
    sequence.validate()?;
    Ok(KittiLoad {
        sequence,
        dont_care,
        image_size_source: source,
    })
}

#[cfg(test)]
mod tests {
    #[test]
    fn every_kitti_type_has_a_class() {
        for t in super::KITTI_TYPES {
            assert!(super::kitti_class(t).is_some(), "{t}");
        }
    }

    use super::*;

    #[test]
    fn malformed_lines_name_file_and_line() {
        let p = Path::new("label_02/0042.txt");
        let good = "0 0 Car 0 0 -1.5 10 20 30 40 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n";
        assert_eq!(parse_labels(good, p).unwrap().0.len(), 1);
        let bad =
            format!("{good}0 1 Car 0 0 -1.5 10 20 30 forty 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n");
        let e = parse_labels(&bad, p).unwrap_err().to_string();
        assert!(e.starts_with("label_02/0042.txt:2:"), "{e}");
        assert!(e.contains("bottom"), "{e}");
        let short = "0 0 Car 0 0\n";
        assert!(
            parse_labels(short, p)
                .unwrap_err()
                .to_string()
                .contains(":1:")
        );
        let unknown = "0 0 Spaceship 0 0 -1.5 10 20 30 40 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n";
        assert!(
            parse_labels(unknown, p)
                .unwrap_err()
                .to_string()
                .contains("Spaceship")
        );
        let dc = "0 -1 DontCare -1 -1 -10 1 2 3 4 -1 -1 -1 -1000 -1000 -1000 -10\n";
        assert_eq!(parse_labels(dc, p).unwrap(), (vec![], 1));
    }

    #[test]
    fn a_track_twice_in_a_frame_is_reported_at_its_line() {
        let p = Path::new("label_02/0042.txt");
        let row = |frame: u32, track: u32| {
            format!("{frame} {track} Car 0 0 -1.5 10 20 30 40 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n")
        };
        let text = format!("{}{}{}", row(0, 0), row(0, 1), row(0, 0));
        let e = parse_labels(&text, p).unwrap_err().to_string();
        assert!(
            e.starts_with("label_02/0042.txt:3:")
                && e.contains("track 0 appears twice in frame 0 (first on line 1)"),
            "{e}"
        );
    }

    #[test]
    fn a_frame_beyond_max_objects_per_frame_is_reported_at_its_line() {
        // Regression: 2,000 objects in one frame (280 KB of labels) aborted
        // in the pair facts; the cap stops it while the labels are read.
        let p = Path::new("label_02/0042.txt");
        let max = crate::model::MAX_OBJECTS_PER_FRAME;
        let text: String = (0..=max)
            .map(|k| format!("7 {k} Car 0 0 -1.5 10 20 30 40 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n"))
            .collect();
        let e = parse_labels(&text, p).unwrap_err().to_string();
        assert!(
            e.starts_with(&format!("label_02/0042.txt:{}:", max + 1))
                && e.contains(&format!("frame 7 has {} objects", max + 1))
                && e.contains(&format!("limit of {max} objects per frame")),
            "{e}"
        );
        // Exactly the cap, and the same count spread over two frames, load.
        let at_cap: String = text.lines().take(max).map(|l| format!("{l}\n")).collect();
        assert_eq!(parse_labels(&at_cap, p).unwrap().0.len(), max);
        let spread =
            format!("{at_cap}8 0 Car 0 0 -1.5 10 20 30 40 1.5 1.6 4.0 1.0 1.65 10.0 -1.57\n");
        assert_eq!(parse_labels(&spread, p).unwrap().0.len(), max + 1);
    }

    #[test]
    fn calib_p2() {
        let c = parse_calib(
            "P0: 1 0 0 0 0 1 0 0 0 0 1 0\nP2: 721.5 0 609.5 44.8 0 721.5 172.8 0.2 0 0 1 0.003\n",
            Path::new("c"),
        )
        .unwrap();
        assert_eq!((c.fx, c.fy, c.cx, c.cy), (721.5, 721.5, 609.5, 172.8));
        assert!(parse_calib("P2: 1 2 3\n", Path::new("c")).is_err());
        assert!(parse_calib("P0: 1\n", Path::new("c")).is_err());
    }

    #[test]
    fn png_headers_give_the_image_size_and_anything_else_none() {
        let mut head = [0u8; 24];
        head[..8].copy_from_slice(&[0x89, b'P', b'N', b'G', b'\r', b'\n', 0x1a, b'\n']);
        head[8..12].copy_from_slice(&13u32.to_be_bytes());
        head[12..16].copy_from_slice(b"IHDR");
        head[16..20].copy_from_slice(&1242u32.to_be_bytes());
        head[20..24].copy_from_slice(&375u32.to_be_bytes());
        assert_eq!(parse_png_header(&head), Some((1242, 375)));
        let mut jpeg = head;
        jpeg[..4].copy_from_slice(&[0xff, 0xd8, 0xff, 0xe0]);
        assert_eq!(parse_png_header(&jpeg), None);
        let mut empty = head;
        empty[16..20].copy_from_slice(&0u32.to_be_bytes());
        assert_eq!(parse_png_header(&empty), None);
        assert_eq!(png_dimensions(Path::new("no/such/frame.png")), None);
    }

    /// The header reader replaced `image::image_dimensions`; on real KITTI
    /// frames both must agree.
    #[cfg(feature = "raw")]
    #[test]
    fn png_header_sizes_match_the_image_decoder_on_kitti_frames() {
        let root =
            Path::new(env!("CARGO_MANIFEST_DIR")).join("../../shared/data/kitti-tracking/image_02");
        let dirs = std::fs::read_dir(&root).expect("KITTI frames under ../shared/data");
        let mut checked = 0;
        for dir in dirs.flatten() {
            for f in std::fs::read_dir(dir.path())
                .into_iter()
                .flatten()
                .flatten()
            {
                let p = f.path();
                assert_eq!(
                    png_dimensions(&p),
                    image::image_dimensions(&p).ok(),
                    "{}",
                    p.display()
                );
                checked += 1;
            }
        }
        assert!(checked > 0, "no frames under {}", root.display());
    }
}
