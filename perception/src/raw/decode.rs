//! Decoders from raw model outputs to detections or dense maps, and per-class
//! non-maximum suppression.

use std::path::Path;

use super::RawError;
use super::runtime::{ModelOutput, OutputTensor};
use crate::model::BBox2D;

/// One decoded box, in model-input pixels until mapped back by a
/// [`super::preprocess::Patch`].
///
/// Invariant: `bbox` valid, `score` in `[0, 1]`, `class_id` below the
/// decoder's class count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct RawDetection {
    /// The model's class index.
    pub class_id: usize,
    /// Class score.
    pub score: f32,
    /// The box.
    pub bbox: BBox2D,
}

/// Decodes NanoDet / GFL heads (see
/// [`super::config::DetectorDecoder::NanodetGfl`]). Outputs are matched to
/// strides by their cell count and to scores/distributions by their last
/// dimension, so their order in the graph does not matter.
#[allow(clippy::too_many_arguments)]
pub fn nanodet_gfl<O: OutputTensor>(
    model: &Path,
    outputs: &[O],
    strides: &[u32],
    reg_max: u32,
    num_classes: usize,
    input_w: u32,
    input_h: u32,
    score_threshold: f32,
) -> Result<Vec<RawDetection>, RawError> {
    let bins = reg_max as usize + 1;
    let reg_len = 4 * bins;
    let shape_err = |message: String| RawError::OutputShape {
        model: model.to_path_buf(),
        message,
    };
    // (cells, last dim) of an output shaped [1, cells, dim] or [cells, dim].
    let dims = |o: &O| -> Option<(usize, usize)> {
        match o.shape() {
            [1, n, d] | [n, d] => Some((*n, *d)),
            _ => None,
        }
    };
    let mut found = Vec::new();
    for &stride in strides {
        let gw = (input_w / stride) as usize;
        let gh = (input_h / stride) as usize;
        let cells = gw * gh;
        let pick = |dim: usize, used: &[usize]| {
            outputs
                .iter()
                .enumerate()
                .find(|(i, o)| !used.contains(i) && dims(o) == Some((cells, dim)))
                .map(|(i, _)| i)
        };
        let used: Vec<usize> = found
            .iter()
            .flat_map(|&(_, _, s, r): &(u32, usize, usize, usize)| [s, r])
            .collect();
        let score_idx = pick(num_classes, &used).ok_or_else(|| {
            shape_err(format!(
                "nanodet_gfl: no score output of shape [1, {cells}, {num_classes}] for stride {stride}; outputs are {}",
                describe(outputs)
            ))
        })?;
        let mut used2 = used.clone();
        used2.push(score_idx);
        let reg_idx = pick(reg_len, &used2).ok_or_else(|| {
            shape_err(format!(
                "nanodet_gfl: no distribution output of shape [1, {cells}, {reg_len}] (4 x (reg_max {reg_max} + 1)) for stride {stride}; outputs are {}",
                describe(outputs)
            ))
        })?;
        found.push((stride, gw, score_idx, reg_idx));
    }
    let mut dets = Vec::new();
    let mut probs = vec![0.0f32; bins];
    for (stride, gw, score_idx, reg_idx) in found {
        let (Some(scores), Some(regs)) = (outputs.get(score_idx), outputs.get(reg_idx)) else {
            continue;
        };
        let s = f64::from(stride);
        for (cell, (row, reg)) in scores
            .data()
            .chunks_exact(num_classes)
            .zip(regs.data().chunks_exact(reg_len))
            .enumerate()
        {
            // Most cells score below the threshold everywhere: one plain
            // scan (vectorisable) rejects them before the argmax.
            if !row.iter().any(|&v| v >= score_threshold) {
                continue;
            }
            let Some((class_id, &score)) = row
                .iter()
                .enumerate()
                .max_by(|a, b| a.1.total_cmp(b.1).then(b.0.cmp(&a.0)))
            else {
                continue;
            };
            if score < score_threshold {
                continue;
            }
            let cx = ((cell % gw) as f64 + 0.5) * s;
            let cy = ((cell / gw) as f64 + 0.5) * s;
            let mut dist = [0.0f64; 4];
            for (side, logits) in reg.chunks_exact(bins).enumerate() {
                dist[side] = f64::from(softmax_expectation(logits, &mut probs)) * s;
            }
            dets.push(RawDetection {
                class_id,
                score: score.clamp(0.0, 1.0),
                bbox: BBox2D {
                    left: cx - dist[0],
                    top: cy - dist[1],
                    right: cx + dist[2],
                    bottom: cy + dist[3],
                },
            });
        }
    }
    Ok(dets)
}

fn describe<O: OutputTensor>(outputs: &[O]) -> String {
    outputs
        .iter()
        .map(|o| format!("{} {:?}", o.name(), o.shape()))
        .collect::<Vec<_>>()
        .join(", ")
}

/// Expectation of the bin index under softmax(`logits`).
fn softmax_expectation(logits: &[f32], scratch: &mut [f32]) -> f32 {
    let max = logits.iter().copied().fold(f32::NEG_INFINITY, f32::max);
    let mut sum = 0.0;
    for (p, &l) in scratch.iter_mut().zip(logits) {
        *p = (l - max).exp();
        sum += *p;
    }
    let mut e = 0.0;
    for (i, p) in scratch.iter().take(logits.len()).enumerate() {
        e += i as f32 * p;
    }
    if sum > 0.0 { e / sum } else { 0.0 }
}

/// Fraction of `inner`'s area covered by `outer`.
pub fn coverage(inner: &BBox2D, outer: &BBox2D) -> f64 {
    let w = (inner.right.min(outer.right) - inner.left.max(outer.left)).max(0.0);
    let h = (inner.bottom.min(outer.bottom) - inner.top.max(outer.top)).max(0.0);
    let a = inner.area();
    if a > 0.0 { w * h / a } else { 0.0 }
}

/// Per-class greedy NMS: boxes sorted by score (ties broken by class and
/// position, so the result is deterministic); a box is dropped when a kept box
/// of the same class overlaps it with IoU above `iou`, or covers more than
/// `containment` of its area (the partial boxes that tiles produce at seams).
/// At most `max_keep` boxes survive.
pub fn nms(
    mut dets: Vec<RawDetection>,
    iou: f64,
    containment: f64,
    max_keep: usize,
) -> Vec<RawDetection> {
    dets.sort_by(|a, b| {
        b.score
            .total_cmp(&a.score)
            .then(a.class_id.cmp(&b.class_id))
            .then(a.bbox.left.total_cmp(&b.bbox.left))
            .then(a.bbox.top.total_cmp(&b.bbox.top))
            .then(a.bbox.right.total_cmp(&b.bbox.right))
            .then(a.bbox.bottom.total_cmp(&b.bbox.bottom))
    });
    let mut kept: Vec<RawDetection> = Vec::new();
    for d in dets {
        if kept.len() >= max_keep {
            break;
        }
        let suppressed = kept.iter().any(|k| {
            k.class_id == d.class_id
                && (k.bbox.iou(&d.bbox) > iou || coverage(&d.bbox, &k.bbox) > containment)
        });
        if !suppressed {
            kept.push(d);
        }
    }
    kept
}

/// A dense per-pixel map.
///
/// Invariant: `data.len() == width * height * channels`, row-major, channel
/// fastest.
#[derive(Debug, Clone, PartialEq)]
pub struct DenseMap<T> {
    /// Width in pixels.
    pub width: usize,
    /// Height in pixels.
    pub height: usize,
    /// Values per pixel.
    pub channels: usize,
    /// The values.
    pub data: Vec<T>,
}

impl<T: Copy> DenseMap<T> {
    /// The value of channel `c` at `(x, y)`, `None` outside the map.
    pub fn get(&self, x: usize, y: usize, c: usize) -> Option<T> {
        if x >= self.width || y >= self.height || c >= self.channels {
            return None;
        }
        self.data
            .get((y * self.width + x) * self.channels + c)
            .copied()
    }
}

/// The single output of a dense model as `(channels, height, width)`,
/// accepting `[1, C, H, W]`, `[C, H, W]` and (for one channel) `[1, H, W]`.
fn chw<'a>(
    model: &Path,
    outputs: &'a [ModelOutput],
    want_channels: Option<usize>,
) -> Result<(&'a ModelOutput, usize, usize, usize), RawError> {
    let err = |message: String| RawError::OutputShape {
        model: model.to_path_buf(),
        message,
    };
    let [out] = outputs else {
        return Err(err(format!(
            "expected one dense output, got {}: {}",
            outputs.len(),
            describe(outputs)
        )));
    };
    let (c, h, w) = match (out.shape.as_slice(), want_channels) {
        ([1, c, h, w], _) => (*c, *h, *w),
        ([1, h, w], Some(1) | None) => (1, *h, *w),
        ([c, h, w], _) => (*c, *h, *w),
        _ => {
            return Err(err(format!(
                "output `{}` has shape {}; expected 1×C×H×W",
                out.name,
                crate::raw::error::shape_text(&out.shape)
            )));
        }
    };
    if let Some(want) = want_channels
        && want != c
    {
        return Err(err(format!(
            "output `{}` has {c} channels, the config says {want}",
            out.name
        )));
    }
    // The runtime guarantees both checks for what it returns, but a
    // `ModelOutput` is a plain public struct: a hand-built one with a zero
    // side would make the per-channel chunking below divide by zero
    // (`chunks_exact(0)` panics), and one whose data disagrees with its shape
    // would yield a map that breaks `DenseMap`'s size invariant.
    if c == 0 || h == 0 || w == 0 {
        return Err(err(format!(
            "output `{}` has shape {}; expected every dimension to be positive",
            out.name,
            crate::raw::error::shape_text(&out.shape)
        )));
    }
    let expected = c.checked_mul(h).and_then(|ch| ch.checked_mul(w));
    if expected != Some(out.data.len()) {
        return Err(err(format!(
            "output `{}` has {} values; its shape {} needs {}",
            out.name,
            out.data.len(),
            crate::raw::error::shape_text(&out.shape),
            expected.map_or_else(|| "more than fit in memory".to_string(), |n| n.to_string())
        )));
    }
    Ok((out, c, h, w))
}

/// Semantic segmentation: the argmax class per pixel of a `1×C×H×W` output.
pub fn segmentation_argmax(
    model: &Path,
    outputs: &[ModelOutput],
    num_classes: usize,
) -> Result<DenseMap<u16>, RawError> {
    let (out, c, h, w) = chw(model, outputs, Some(num_classes))?;
    let plane = h * w;
    let mut data = vec![0u16; plane];
    let mut best = vec![f32::NEG_INFINITY; plane];
    for (k, chunk) in out.data.chunks_exact(plane).take(c).enumerate() {
        let label = u16::try_from(k).unwrap_or(u16::MAX);
        for ((b, d), &v) in best.iter_mut().zip(data.iter_mut()).zip(chunk) {
            if v > *b {
                *b = v;
                *d = label;
            }
        }
    }
    Ok(DenseMap {
        width: w,
        height: h,
        channels: 1,
        data,
    })
}

/// Depth: a one-channel map times `scale`.
pub fn depth_map(
    model: &Path,
    outputs: &[ModelOutput],
    scale: f32,
) -> Result<DenseMap<f32>, RawError> {
    let (out, _, h, w) = chw(model, outputs, Some(1))?;
    Ok(DenseMap {
        width: w,
        height: h,
        channels: 1,
        data: out.data.iter().map(|v| v * scale).collect(),
    })
}

/// Optical flow: a `1×2×H×W` output into per-pixel `(dx, dy)` times `scale`.
pub fn flow_map(
    model: &Path,
    outputs: &[ModelOutput],
    scale: f32,
) -> Result<DenseMap<f32>, RawError> {
    let (out, _, h, w) = chw(model, outputs, Some(2))?;
    let plane = h * w;
    let mut data = vec![0.0f32; plane * 2];
    for (i, pair) in data.chunks_exact_mut(2).enumerate() {
        pair[0] = out.data.get(i).copied().unwrap_or(0.0) * scale;
        pair[1] = out.data.get(plane + i).copied().unwrap_or(0.0) * scale;
    }
    Ok(DenseMap {
        width: w,
        height: h,
        channels: 2,
        data,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn out(name: &str, shape: Vec<usize>, data: Vec<f32>) -> ModelOutput {
        ModelOutput {
            name: name.into(),
            shape,
            data,
        }
    }

    #[test]
    fn gfl_decodes_one_confident_cell() {
        // 16x16 input, stride 8 -> 2x2 cells, 2 classes, reg_max 1 (2 bins).
        let mut scores = vec![0.0; 4 * 2];
        scores[3 * 2 + 1] = 0.9; // cell 3 = (x 1, y 1), class 1
        let mut regs = vec![0.0; 4 * 8];
        // Cell 3: every side puts all mass on bin 1 -> distance 1 * stride.
        for side in 0..4 {
            regs[3 * 8 + side * 2 + 1] = 20.0;
        }
        let outputs = [
            out("r", vec![1, 4, 8], regs),
            out("s", vec![1, 4, 2], scores),
        ];
        let d = nanodet_gfl(Path::new("m"), &outputs, &[8], 1, 2, 16, 16, 0.5).unwrap();
        assert_eq!(d.len(), 1);
        assert_eq!(d[0].class_id, 1);
        let b = d[0].bbox;
        assert!(
            (b.left - 4.0).abs() < 1e-3 && (b.right - 20.0).abs() < 1e-3,
            "{b:?}"
        );
        assert!(
            (b.top - 4.0).abs() < 1e-3 && (b.bottom - 20.0).abs() < 1e-3,
            "{b:?}"
        );
    }

    #[test]
    fn gfl_reports_missing_outputs() {
        let outputs = [out("s", vec![1, 4, 2], vec![0.0; 8])];
        let err = nanodet_gfl(Path::new("m.onnx"), &outputs, &[8], 1, 2, 16, 16, 0.5)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("no distribution output") && err.contains("m.onnx"),
            "{err}"
        );
    }

    #[test]
    fn nms_is_per_class_and_deterministic() {
        let b = |l: f64| BBox2D {
            left: l,
            top: 0.0,
            right: l + 10.0,
            bottom: 10.0,
        };
        let dets = vec![
            RawDetection {
                class_id: 0,
                score: 0.8,
                bbox: b(0.0),
            },
            RawDetection {
                class_id: 0,
                score: 0.9,
                bbox: b(1.0),
            },
            RawDetection {
                class_id: 1,
                score: 0.7,
                bbox: b(0.0),
            },
            RawDetection {
                class_id: 0,
                score: 0.6,
                bbox: b(30.0),
            },
            RawDetection {
                class_id: 0,
                score: 0.5,
                bbox: BBox2D {
                    left: 31.0,
                    top: 1.0,
                    right: 36.0,
                    bottom: 9.0,
                },
            },
        ];
        let kept = nms(dets.clone(), 0.5, 0.8, 10);
        assert_eq!(kept.len(), 3);
        assert_eq!(kept[0].score, 0.9);
        assert_eq!(kept[1].class_id, 1);
        let mut rev = dets;
        rev.reverse();
        assert_eq!(nms(rev, 0.5, 0.8, 10), kept);
        assert_eq!(nms(kept.clone(), 0.5, 0.8, 1).len(), 1);
    }

    #[test]
    fn dense_decoders() {
        // 2 classes, 1x3 map.
        let seg = [out(
            "y",
            vec![1, 2, 1, 3],
            vec![1.0, 0.0, 5.0, 0.0, 2.0, 4.0],
        )];
        let m = segmentation_argmax(Path::new("m"), &seg, 2).unwrap();
        assert_eq!(m.data, vec![0, 1, 0]);
        assert!(segmentation_argmax(Path::new("m"), &seg, 3).is_err());
        let depth = [out("d", vec![1, 1, 1, 2], vec![0.5, 0.25])];
        assert_eq!(
            depth_map(Path::new("m"), &depth, 10.0).unwrap().data,
            vec![5.0, 2.5]
        );
        let flow = [out("f", vec![1, 2, 1, 2], vec![1.0, 2.0, 3.0, 4.0])];
        let f = flow_map(Path::new("m"), &flow, 1.0).unwrap();
        assert_eq!(f.get(1, 0, 0), Some(2.0));
        assert_eq!(f.get(1, 0, 1), Some(4.0));
        assert_eq!(f.get(2, 0, 0), None);
    }

    #[test]
    fn zero_sized_or_short_dense_outputs_are_errors_not_panics() {
        // Regression: a zero-sized plane reached `chunks_exact(0)`, which panics.
        for shape in [vec![1, 2, 0, 3], vec![1, 2, 3, 0], vec![1, 0, 1, 1]] {
            let zero = [out("y", shape.clone(), Vec::new())];
            let want = shape[1];
            let err = segmentation_argmax(Path::new("m.onnx"), &zero, want)
                .unwrap_err()
                .to_string();
            assert!(
                err.contains("m.onnx") && err.contains("every dimension to be positive"),
                "{shape:?}: {err}"
            );
        }
        let zero_depth = [out("d", vec![1, 1, 0, 4], Vec::new())];
        assert!(depth_map(Path::new("m"), &zero_depth, 1.0).is_err());
        // Data shorter than the shape: an error, not a map of the wrong size.
        let short = [out("y", vec![1, 2, 1, 3], vec![1.0, 0.0, 5.0])];
        let err = segmentation_argmax(Path::new("m.onnx"), &short, 2)
            .unwrap_err()
            .to_string();
        assert!(
            err.contains("has 3 values") && err.contains("needs 6"),
            "{err}"
        );
        let short_depth = [out("d", vec![1, 1, 2, 2], vec![1.0])];
        assert!(depth_map(Path::new("m"), &short_depth, 1.0).is_err());
    }
}
