//! Detection quality against KITTI tracking labels: car recall and precision
//! at an IoU threshold, the monocular depth of matched cars against the
//! labelled `Z`, and ([`label_box_depth_eval`]) the monocular depth methods
//! on the labelled 2D boxes of every sequence taken as perfect detections.
//!
//! Protocol (stated so the figures can be reproduced and judged):
//! - Cared-for truth: `Car` labels with occlusion ≤ `max_occlusion` and box
//!   height ≥ `min_height_px`.
//! - Predictions: detections whose `TypeOf` is `Car` with box height ≥
//!   `min_height_px`.
//! - Matching: greedy by IoU (highest first), one-to-one, IoU ≥ `min_iou`.
//! - Unmatched predictions count as false positives unless they lie on an
//!   ignored region — a vehicle label not cared for (occluded or small cars,
//!   vans, trucks, trams, misc) or a `DontCare` region — meaning IoU ≥
//!   `min_iou` with it or at least `ignore_coverage` of the prediction's area
//!   inside it. Finding an occluded car is not an error; the label set just
//!   does not ask for it.

use std::path::Path;

use super::RawError;
use super::detect::Detection;
use super::ground::GroundConfig;
use super::mono::{DepthEstimate, MonoDepthConfig, estimate};
use crate::model::{BBox2D, CameraConfig, DepthSource, ObjectClass, Observation};

/// Evaluation thresholds.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CarEvalCriteria {
    /// IoU for a match.
    pub min_iou: f64,
    /// Minimum box height, pixels (truth and predictions).
    pub min_height_px: f64,
    /// Highest KITTI occlusion level cared for.
    pub max_occlusion: u8,
    /// Fraction of a prediction inside an ignored region that excuses it.
    pub ignore_coverage: f64,
    /// Depth is checked for matched cars up to this labelled `Z`, metres.
    pub depth_max_m: f64,
}

impl Default for CarEvalCriteria {
    fn default() -> Self {
        CarEvalCriteria {
            min_iou: 0.5,
            min_height_px: 25.0,
            max_occlusion: 0,
            ignore_coverage: 0.5,
            depth_max_m: 30.0,
        }
    }
}

/// The labels of one frame.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct FrameLabels {
    /// Labelled objects (KITTI classes).
    pub objects: Vec<Observation>,
    /// `DontCare` regions.
    pub dont_care: Vec<BBox2D>,
}

/// Reads a KITTI label file into per-frame labels for `frames` (objects
/// through [`crate::kitti::parse_labels`], `DontCare` boxes read here since
/// the loader counts but does not keep them).
pub fn read_frame_labels(path: &Path, frames: &[u32]) -> Result<Vec<FrameLabels>, RawError> {
    let text = crate::textfile::read_text_file(path).map_err(|e| RawError::io(path, e))?;
    let (objects, _) = crate::kitti::parse_labels(&text, path)?;
    let mut out = Vec::with_capacity(frames.len());
    for &frame in frames {
        let mut labels = FrameLabels {
            objects: objects
                .iter()
                .filter(|o| o.frame == frame)
                .cloned()
                .collect(),
            dont_care: Vec::new(),
        };
        for (i, line) in text.lines().enumerate() {
            let f: Vec<&str> = line.split_whitespace().collect();
            if f.get(2) != Some(&"DontCare")
                || f.first().and_then(|v| v.parse::<u32>().ok()) != Some(frame)
            {
                continue;
            }
            let num = |k: usize| -> Result<f64, RawError> {
                f.get(k)
                    .and_then(|v| v.parse::<f64>().ok())
                    .ok_or_else(|| RawError::Frames {
                        path: path.to_path_buf(),
                        message: format!(
                            "line {}: DontCare box field {} is not a number",
                            i + 1,
                            k + 1
                        ),
                    })
            };
            labels.dont_care.push(BBox2D {
                left: num(6)?,
                top: num(7)?,
                right: num(8)?,
                bottom: num(9)?,
            });
        }
        out.push(labels);
    }
    Ok(out)
}

/// The depth check of one matched car.
#[derive(Debug, Clone, PartialEq)]
pub struct DepthCheck {
    /// Frame index.
    pub frame: u32,
    /// Labelled `Z`, metres.
    pub label_z: f64,
    /// The detection's box.
    pub bbox: BBox2D,
    /// The camera of the frame (to redo the estimate by other methods).
    pub camera: CameraConfig,
    /// `Z` by the configured monocular method; `None` when no method applies.
    pub estimated_z: Option<f64>,
    /// Which method gave `estimated_z`.
    pub source: Option<DepthSource>,
    /// Whether the detection's box is cut by the image's bottom edge (the
    /// ground contact and the full height are not visible, so no monocular
    /// method applies).
    pub cut_by_image: bool,
    /// Labelled `Y` of the car's bottom: how far below the camera the ground
    /// under this car really is (the flat-ground model assumes the camera
    /// height).
    pub label_ground_y: f64,
    /// Half the labelled footprint's extent along `Z` (`(l·|sin ry| + w·|cos
    /// ry|) / 2`): the box bottom edge images the nearest face, the label's
    /// `Z` is the centre.
    pub label_half_depth: f64,
}

impl DepthCheck {
    /// `|estimated − label| / label`, when estimated.
    pub fn relative_error(&self) -> Option<f64> {
        self.estimated_z
            .map(|z| (z - self.label_z).abs() / self.label_z)
    }

    /// The estimate of this car's box by another configuration.
    pub fn estimate_with(
        &self,
        ground: &GroundConfig,
        mono: &MonoDepthConfig,
    ) -> Option<DepthEstimate> {
        estimate(&self.bbox, Some("Car"), &self.camera, ground, mono)
    }

    /// Diagnosis only (uses the label): the uncorrected flat-ground contact
    /// depth redone with the labelled ground height under the car instead of
    /// the camera height, plus the labelled nearest-face-to-centre offset.
    /// When this matches the label, the error of plain flat ground is the
    /// flat-ground assumption itself, not the detector or the geometry code.
    pub fn with_labelled_ground(&self, ground: &GroundConfig) -> Option<f64> {
        super::ground::ground_point(&self.bbox, &self.camera, ground).map(|g| {
            g.position.0.z * self.label_ground_y / self.camera.height_m + self.label_half_depth
        })
    }
}

/// Accumulated results.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct CarEval {
    /// Matched cared-for cars.
    pub true_positives: usize,
    /// Cared-for cars not matched.
    pub false_negatives: usize,
    /// Predictions matched to nothing and not on an ignored region.
    pub false_positives: usize,
    /// Predictions excused by an ignored region.
    pub ignored: usize,
    /// `(frame, box, score)` of every false positive.
    pub false_positive_boxes: Vec<(u32, BBox2D, f32)>,
    /// `(frame, box)` of every missed car.
    pub missed: Vec<(u32, BBox2D)>,
    /// Depth checks of matched cars with labelled `Z` ≤ `depth_max_m`.
    pub depth: Vec<DepthCheck>,
}

impl CarEval {
    /// `TP / (TP + FN)`; 1 when there is nothing to find.
    pub fn recall(&self) -> f64 {
        ratio(
            self.true_positives,
            self.true_positives + self.false_negatives,
        )
    }

    /// `TP / (TP + FP)`; 1 when nothing was predicted.
    pub fn precision(&self) -> f64 {
        ratio(
            self.true_positives,
            self.true_positives + self.false_positives,
        )
    }

    /// Depth checks whose ground contact is visible (not cut by the image).
    pub fn depth_checked(&self) -> impl Iterator<Item = &DepthCheck> {
        self.depth.iter().filter(|d| !d.cut_by_image)
    }

    /// Largest relative depth error over [`CarEval::depth_checked`]; infinity
    /// when one has no estimate.
    pub fn max_depth_error(&self) -> f64 {
        self.depth_checked()
            .map(|d| d.relative_error().unwrap_or(f64::INFINITY))
            .fold(0.0, f64::max)
    }

    /// Adds one frame.
    // One argument per independent input (frame, detections, truth, camera,
    // and three separately owned settings); a bundle type would only
    // rename them.
    #[allow(clippy::too_many_arguments)]
    pub fn add_frame(
        &mut self,
        frame: u32,
        detections: &[Detection],
        labels: &FrameLabels,
        camera: &CameraConfig,
        criteria: &CarEvalCriteria,
        ground: &GroundConfig,
        mono: &MonoDepthConfig,
    ) {
        let tall = |b: &BBox2D| b.height() >= criteria.min_height_px;
        let cared = |o: &Observation| {
            o.type_name.as_deref() == Some("Car")
                && o.occlusion.unwrap_or(u8::MAX) <= criteria.max_occlusion
                && o.bbox.as_ref().is_some_and(tall)
        };
        let truth: Vec<&Observation> = labels.objects.iter().filter(|o| cared(o)).collect();
        let ignore: Vec<BBox2D> = labels
            .objects
            .iter()
            .filter(|o| !cared(o) && matches!(o.class, ObjectClass::Vehicle | ObjectClass::Misc))
            .filter_map(|o| o.bbox)
            .chain(labels.dont_care.iter().copied())
            .collect();
        let preds: Vec<&Detection> = detections
            .iter()
            .filter(|d| d.type_name.as_deref() == Some("Car") && tall(&d.bbox))
            .collect();
        let mut pairs: Vec<(f64, usize, usize)> = Vec::new();
        for (ti, t) in truth.iter().enumerate() {
            for (pi, p) in preds.iter().enumerate() {
                // `cared` kept only boxed labels.
                let Some(tb) = &t.bbox else { continue };
                let iou = tb.iou(&p.bbox);
                if iou >= criteria.min_iou {
                    pairs.push((iou, ti, pi));
                }
            }
        }
        pairs.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)).then(a.2.cmp(&b.2)));
        let mut truth_used = vec![false; truth.len()];
        let mut pred_used = vec![false; preds.len()];
        for (_, ti, pi) in pairs {
            if truth_used[ti] || pred_used[pi] {
                continue;
            }
            truth_used[ti] = true;
            pred_used[pi] = true;
            self.true_positives += 1;
            let (t, p) = (truth[ti], preds[pi]);
            if let Some(pos) = t
                .position
                .filter(|p| p[2] > 0.0 && p[2] <= criteria.depth_max_m)
            {
                let e = estimate(&p.bbox, p.type_name.as_deref(), camera, ground, mono);
                let bottom_cut = p.bbox.bottom
                    >= f64::from(camera.intrinsics.image_height) - 1.0 - ground.bottom_margin_px;
                let half_depth = match (t.size, t.yaw) {
                    (Some([_, w, l]), Some(ry)) => 0.5 * (l * ry.sin().abs() + w * ry.cos().abs()),
                    _ => 0.0,
                };
                self.depth.push(DepthCheck {
                    frame,
                    label_z: pos[2],
                    bbox: p.bbox,
                    camera: *camera,
                    estimated_z: e.map(|e| e.z()),
                    source: e.map(|e| e.source),
                    cut_by_image: bottom_cut || e.is_none_or(|e| e.cut_by_image),
                    label_ground_y: pos[1],
                    label_half_depth: half_depth,
                });
            }
        }
        for (ti, t) in truth.iter().enumerate() {
            if !truth_used[ti] {
                self.false_negatives += 1;
                if let Some(b) = t.bbox {
                    self.missed.push((frame, b));
                }
            }
        }
        for (pi, p) in preds.iter().enumerate() {
            if pred_used[pi] {
                continue;
            }
            let excused = ignore.iter().any(|r| {
                r.iou(&p.bbox) >= criteria.min_iou
                    || super::decode::coverage(&p.bbox, r) >= criteria.ignore_coverage
            });
            if excused {
                self.ignored += 1;
            } else {
                self.false_positives += 1;
                self.false_positive_boxes.push((frame, p.bbox, p.score));
            }
        }
    }
}

/// The camera of a KITTI sequence: `P2` intrinsics from `calib/<seq>.txt`,
/// the frame size, and the KITTI mounting height
/// ([`crate::kitti::KITTI_CAMERA_HEIGHT_M`]).
pub fn kitti_camera(
    root: &Path,
    sequence: &str,
    width: u32,
    height: u32,
) -> Result<CameraConfig, RawError> {
    let path = root.join("calib").join(format!("{sequence}.txt"));
    super::camera::Calibration::read(&path)?.for_frames(width, height, &path)
}

/// The frames of a KITTI tracking root that have images:
/// `(sequence, frame, path)` for every `image_02/<seq>/<frame>.png`, sorted.
pub fn kitti_frames(root: &Path) -> Result<Vec<(String, u32, std::path::PathBuf)>, RawError> {
    let images = root.join("image_02");
    let mut out = Vec::new();
    let seqs = std::fs::read_dir(&images).map_err(|e| RawError::io(&images, e))?;
    for seq in seqs {
        let seq = seq.map_err(|e| RawError::io(&images, e))?.path();
        let Some(name) = seq.file_name().and_then(|n| n.to_str()).map(str::to_string) else {
            continue;
        };
        if !seq.is_dir() {
            continue;
        }
        for entry in std::fs::read_dir(&seq).map_err(|e| RawError::io(&seq, e))? {
            let path = entry.map_err(|e| RawError::io(&seq, e))?.path();
            if path.extension().and_then(|e| e.to_str()) != Some("png") {
                continue;
            }
            let frame = path
                .file_stem()
                .and_then(|s| s.to_str())
                .and_then(|s| s.parse::<u32>().ok())
                .ok_or_else(|| RawError::Frames {
                    path: path.clone(),
                    message: "KITTI frame files are named NNNNNN.png".into(),
                })?;
            out.push((name.clone(), frame, path));
        }
    }
    out.sort();
    Ok(out)
}

/// One evaluated frame.
#[derive(Debug, Clone, PartialEq)]
pub struct EvaluatedFrame {
    /// Sequence name.
    pub sequence: String,
    /// Frame index.
    pub frame: u32,
    /// What the detector found.
    pub detections: Vec<Detection>,
    /// Where the time went.
    pub times: super::detect::StageTimes,
}

/// Runs `detector` over every imaged frame of a KITTI root and evaluates the
/// cars; also returns the per-frame detections and times.
pub fn evaluate_kitti(
    detector: &mut super::detect::Detector,
    root: &Path,
    criteria: &CarEvalCriteria,
    ground: &GroundConfig,
    mono: &MonoDepthConfig,
) -> Result<(CarEval, Vec<EvaluatedFrame>), RawError> {
    let frames = kitti_frames(root)?;
    if frames.is_empty() {
        return Err(RawError::Frames {
            path: root.join("image_02"),
            message: "no frames".into(),
        });
    }
    let mut eval = CarEval::default();
    let mut out = Vec::new();
    for (sequence, frame, path) in frames {
        let img = crate::raw::frames::open_image(&path)?.into_rgb8();
        let camera = kitti_camera(root, &sequence, img.width(), img.height())?;
        let labels = read_frame_labels(
            &root.join("label_02").join(format!("{sequence}.txt")),
            &[frame],
        )?;
        let (detections, times) = detector.detect(&img)?;
        if let Some(l) = labels.first() {
            eval.add_frame(frame, &detections, l, &camera, criteria, ground, mono);
        }
        out.push(EvaluatedFrame {
            sequence,
            frame,
            detections,
            times,
        });
    }
    Ok((eval, out))
}

/// Which labelled boxes [`label_box_depth_eval`] takes as perfect
/// detections.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LabelBoxCriteria {
    /// KITTI type evaluated.
    pub type_name: &'static str,
    /// Highest KITTI occlusion level.
    pub max_occlusion: u8,
    /// Highest KITTI truncation (KITTI's "easy" level uses 0.15).
    pub max_truncation: f32,
    /// Minimum box height, pixels.
    pub min_height_px: f64,
    /// Largest labelled `Z`, metres.
    pub max_z_m: f64,
    /// An estimate within this relative error counts as a hit.
    pub tolerance: f64,
}

impl Default for LabelBoxCriteria {
    fn default() -> Self {
        LabelBoxCriteria {
            type_name: "Car",
            max_occlusion: 0,
            max_truncation: 0.15,
            min_height_px: 25.0,
            max_z_m: 30.0,
            tolerance: 0.10,
        }
    }
}

/// One method's score over the labelled boxes.
#[derive(Debug, Clone, PartialEq)]
pub struct MethodScore {
    /// The caller's name for the configuration.
    pub name: String,
    /// Boxes evaluated.
    pub boxes: usize,
    /// Boxes the method gave a depth for (the others count as misses, with
    /// infinite error).
    pub estimated: usize,
    /// Median of `|Z − Z_label| / Z_label` over all boxes.
    pub median_error: f64,
    /// Fraction of boxes within the tolerance.
    pub within: f64,
    /// How many estimates came from each method (provenance), sorted.
    pub sources: Vec<(DepthSource, usize)>,
}

/// The result of [`label_box_depth_eval`].
#[derive(Debug, Clone, PartialEq)]
pub struct LabelBoxEval {
    /// Sequences read.
    pub sequences: usize,
    /// Boxes meeting the criteria with a visible bottom edge.
    pub boxes: usize,
    /// Boxes meeting the criteria but cut by the image's bottom edge: no
    /// monocular method applies, so they are left out (as for detections).
    pub cut_by_image: usize,
    /// One score per configuration, in the order given.
    pub scores: Vec<MethodScore>,
}

/// Evaluates monocular depth configurations on the labelled 2D boxes of
/// every `label_02/<seq>.txt` under a KITTI tracking root, taken as perfect
/// detections, against the labelled `Z`. The camera is the KITTI loader's
/// ([`crate::kitti::load`]): intrinsics from `calib/<seq>.txt`, the frame
/// size from an image when present, else from the recording day, else from
/// the labelled boxes' extent. A sequence the loader rejects fails the
/// evaluation (the labels are then parsed a second time for the boxes; it
/// is cheap).
pub fn label_box_depth_eval(
    root: &Path,
    criteria: &LabelBoxCriteria,
    ground: &GroundConfig,
    configs: &[(String, MonoDepthConfig)],
) -> Result<LabelBoxEval, RawError> {
    let dir = root.join("label_02");
    let mut files: Vec<std::path::PathBuf> = std::fs::read_dir(&dir)
        .map_err(|e| RawError::io(&dir, e))?
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().and_then(|e| e.to_str()) == Some("txt"))
        .collect();
    files.sort();
    if files.is_empty() {
        return Err(RawError::Frames {
            path: dir,
            message: "no label files (<seq>.txt)".into(),
        });
    }
    let mut errors: Vec<Vec<f64>> = vec![Vec::new(); configs.len()];
    let mut sources: Vec<std::collections::BTreeMap<DepthSource, usize>> =
        vec![Default::default(); configs.len()];
    let (mut boxes, mut cut) = (0usize, 0usize);
    for file in &files {
        let Some(seq) = file.file_stem().and_then(|s| s.to_str()) else {
            continue;
        };
        let text = crate::textfile::read_text_file(file).map_err(|e| RawError::io(file, e))?;
        let (objects, _) = crate::kitti::parse_labels(&text, file)?;
        // The sequence's camera as the KITTI loader determines it: `P2`
        // from the calib file and the image size from an image, else from
        // the recording day (the label extents alone gave 0018 a 651 px
        // wide "image" and a principal point near its right edge).
        let camera = crate::kitti::load(root, seq)?.sequence.camera;
        let height = camera.intrinsics.image_height;
        for o in &objects {
            let (Some(pos), Some(bbox)) = (o.position, o.bbox) else {
                continue;
            };
            let keep = o.type_name.as_deref() == Some(criteria.type_name)
                && o.occlusion.is_some_and(|v| v <= criteria.max_occlusion)
                && o.truncation.is_some_and(|v| v <= criteria.max_truncation)
                && bbox.height() >= criteria.min_height_px
                && pos[2] > 0.0
                && pos[2] <= criteria.max_z_m;
            if !keep {
                continue;
            }
            if bbox.bottom >= f64::from(height) - 1.0 - ground.bottom_margin_px {
                cut += 1;
                continue;
            }
            boxes += 1;
            for (i, (_, config)) in configs.iter().enumerate() {
                let e = estimate(&bbox, o.type_name.as_deref(), &camera, ground, config);
                errors[i].push(e.map_or(f64::INFINITY, |e| (e.z() - pos[2]).abs() / pos[2]));
                if let Some(e) = e {
                    *sources[i].entry(e.source).or_default() += 1;
                }
            }
        }
    }
    let scores = configs
        .iter()
        .zip(errors)
        .zip(sources)
        .map(|(((name, _), mut errs), src)| {
            errs.sort_by(f64::total_cmp);
            let n = errs.len();
            MethodScore {
                name: name.clone(),
                boxes: n,
                estimated: errs.iter().filter(|e| e.is_finite()).count(),
                median_error: median_sorted(&errs),
                within: ratio(errs.iter().filter(|&&e| e <= criteria.tolerance).count(), n),
                sources: src.into_iter().collect(),
            }
        })
        .collect();
    Ok(LabelBoxEval {
        sequences: files.len(),
        boxes,
        cut_by_image: cut,
        scores,
    })
}

/// The configurations compared in docs/models.md: each monocular method
/// (`flat`, `size`, `fused`) without and with (`+centre`) the nearest-face
/// → centre correction, otherwise as `base`.
pub fn depth_method_variants(base: &MonoDepthConfig) -> Vec<(String, MonoDepthConfig)> {
    use super::mono::MonoDepthMethod;
    let mut out = Vec::new();
    for (name, method) in [
        ("flat", MonoDepthMethod::FlatGround),
        ("size", MonoDepthMethod::SizePrior),
        ("fused", MonoDepthMethod::Fused),
    ] {
        for (suffix, centre) in [("", false), ("+centre", true)] {
            out.push((
                format!("{name}{suffix}"),
                MonoDepthConfig {
                    centre_correction: centre,
                    ..base.with_method(method)
                },
            ));
        }
    }
    out
}

/// Median of a sorted slice (mean of the middle two for even lengths); NaN
/// when empty.
fn median_sorted(v: &[f64]) -> f64 {
    match v.len() {
        0 => f64::NAN,
        n if n % 2 == 1 => v[n / 2],
        n => 0.5 * (v[n / 2 - 1] + v[n / 2]),
    }
}

fn ratio(num: usize, den: usize) -> f64 {
    if den == 0 {
        1.0
    } else {
        num as f64 / den as f64
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::CameraIntrinsics;
    use crate::raw::mono::MonoDepthMethod;

    fn car(b: BBox2D, occlusion: u8, z: f64) -> Observation {
        Observation {
            frame: 0,
            track_id: 0,
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            color: None,
            bbox: Some(b),
            position: Some([0.0, 1.65, z]),
            size: None,
            yaw: None,
            confidence: 1.0,
            truncation: Some(0.0),
            occlusion: Some(occlusion),
            footprint: None,
            depth_source: None,
        }
    }

    fn det(b: BBox2D) -> Detection {
        Detection {
            class_id: 2,
            label: "car".into(),
            class: ObjectClass::Vehicle,
            type_name: Some("Car".into()),
            score: 0.9,
            bbox: b,
        }
    }

    #[test]
    fn counts_matches_misses_false_and_ignored() {
        let cam = CameraConfig {
            intrinsics: CameraIntrinsics {
                fx: 700.0,
                fy: 700.0,
                cx: 600.0,
                cy: 170.0,
                image_width: 1200,
                image_height: 370,
            },
            height_m: 1.65,
        };
        let b = |l: f64, t: f64, r: f64, bt: f64| BBox2D {
            left: l,
            top: t,
            right: r,
            bottom: bt,
        };
        // Bottom at 170 + 700*1.65/20 = 227.75 -> Z 20 m exactly.
        let labels = FrameLabels {
            objects: vec![
                car(b(100.0, 180.0, 160.0, 227.75), 0, 20.0),
                car(b(400.0, 180.0, 460.0, 230.0), 0, 25.0),
                car(b(700.0, 180.0, 760.0, 230.0), 2, 25.0),
            ],
            dont_care: vec![b(900.0, 150.0, 1000.0, 200.0)],
        };
        let dets = [
            det(b(101.0, 181.0, 160.0, 227.75)), // match
            det(b(702.0, 182.0, 758.0, 228.0)),  // occluded car: ignored
            det(b(910.0, 160.0, 950.0, 195.0)),  // inside DontCare: ignored
            det(b(300.0, 100.0, 340.0, 140.0)),  // false positive
            det(b(500.0, 100.0, 510.0, 110.0)),  // too small: not a prediction
        ];
        let flat_uncorrected = MonoDepthConfig {
            centre_correction: false,
            ..MonoDepthConfig::default().with_method(MonoDepthMethod::FlatGround)
        };
        let mut e = CarEval::default();
        e.add_frame(
            3,
            &dets,
            &labels,
            &cam,
            &CarEvalCriteria::default(),
            &GroundConfig::default(),
            &flat_uncorrected,
        );
        assert_eq!(
            (
                e.true_positives,
                e.false_negatives,
                e.false_positives,
                e.ignored
            ),
            (1, 1, 1, 2)
        );
        assert_eq!(e.recall(), 0.5);
        assert_eq!(e.precision(), 0.5);
        assert_eq!(e.depth.len(), 1);
        assert!(e.max_depth_error() < 1e-9, "{:?}", e.depth);
        assert_eq!(e.missed, vec![(3, b(400.0, 180.0, 460.0, 230.0))]);
    }
}
