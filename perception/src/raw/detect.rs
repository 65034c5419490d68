//! The detection path: a frame in, mapped and suppressed detections out.

use std::time::{Duration, Instant};

use image::RgbImage;
use ndarray::Array4;

use super::RawError;
use super::config::{DetectorDecoder, Layout, LoadedConfig, OutputSpec};
use super::decode::{self, RawDetection};
use super::preprocess;
use super::runtime::{ModelRunner, Runtime};
use crate::model::{BBox2D, ObjectClass};

/// A detection mapped onto the LogicPad vocabulary, in frame pixels.
///
/// Invariant: `bbox` is valid and clipped to the frame; `class` and
/// `type_name` come from the config's label map entry for `class_id`.
#[derive(Debug, Clone, PartialEq)]
pub struct Detection {
    /// The model's class index.
    pub class_id: usize,
    /// The model's class name (`car`).
    pub label: String,
    /// LogicPad class.
    pub class: ObjectClass,
    /// `TypeOf` value.
    pub type_name: Option<String>,
    /// Score in `[0, 1]`.
    pub score: f32,
    /// Box in frame pixels.
    pub bbox: BBox2D,
}

/// Where the time of one frame went.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct StageTimes {
    /// Inside ONNX Runtime.
    pub model: Duration,
    /// Everything else (resampling, decoding, NMS, mapping).
    pub other: Duration,
}

impl StageTimes {
    /// Adds another frame's times.
    pub fn add(&mut self, other: StageTimes) {
        self.model += other.model;
        self.other += other.other;
    }
}

/// The label map resolved per class id.
#[derive(Debug, Clone)]
struct MappedLabel {
    label: String,
    class: ObjectClass,
    type_name: Option<String>,
}

/// Resolves the config's label map into a table indexed by class id.
fn label_table(loaded: &LoadedConfig, num_classes: usize) -> Result<Vec<Option<MappedLabel>>, RawError> {
    let mut table = vec![None; num_classes];
    for (i, l) in loaded.config.labels.iter().enumerate() {
        let class = ObjectClass::from_predicate(&l.class).ok_or_else(|| RawError::ConfigInvalid {
            path: loaded.config_path.clone(),
            field: format!("labels[{i}].class"),
            message: format!("`{}` is not a LogicPad class", l.class),
        })?;
        if let Some(slot) = table.get_mut(l.id) {
            *slot = Some(MappedLabel { label: l.name.clone(), class, type_name: l.type_name.clone() });
        }
    }
    Ok(table)
}

/// Opens the model named by a config, reporting a missing file with the config
/// that named it, and checks that the model's input shape is the one the
/// config promises.
pub fn open_model(runtime: &Runtime, loaded: &LoadedConfig) -> Result<ModelRunner, RawError> {
    if !loaded.model_path.is_file() {
        return Err(RawError::ModelNotFound {
            path: loaded.model_path.clone(),
            config: Some(loaded.config_path.clone()),
        });
    }
    let runner = ModelRunner::open(runtime, &loaded.model_path, loaded.config.threads)?;
    let input = &loaded.config.input;
    let (w, h) = (input.width as usize, input.height as usize);
    let c = 3 * input.frames.max(1) as usize;
    let promised = match input.layout {
        Layout::Nchw => [1, c, h, w],
        Layout::Nhwc => [1, h, w, c],
    };
    runner.check_input_shape(&promised)?;
    Ok(runner)
}

/// An object detector built from a model config.
#[derive(Debug)]
pub struct Detector {
    loaded: LoadedConfig,
    runner: ModelRunner,
    tensor: Array4<f32>,
    labels: Vec<Option<MappedLabel>>,
}

impl Detector {
    /// Opens the detector a config describes; the config's output must be a
    /// detector.
    pub fn open(runtime: &Runtime, loaded: LoadedConfig) -> Result<Detector, RawError> {
        let OutputSpec::Detector { decoder, .. } = &loaded.config.output else {
            return Err(RawError::ConfigInvalid {
                path: loaded.config_path.clone(),
                field: "output.kind".to_string(),
                message: "a detector config is needed here".to_string(),
            });
        };
        let num_classes = match decoder {
            DetectorDecoder::NanodetGfl { num_classes, .. } => *num_classes,
        };
        let labels = label_table(&loaded, num_classes)?;
        let runner = open_model(runtime, &loaded)?;
        let tensor = preprocess::new_tensor(&loaded.config.input);
        Ok(Detector { loaded, runner, tensor, labels })
    }

    /// The config in use.
    pub fn config(&self) -> &LoadedConfig {
        &self.loaded
    }

    /// Detects mapped objects in one frame. Classes absent from the label map
    /// are dropped before NMS; boxes are clipped to the frame.
    pub fn detect(&mut self, frame: &RgbImage) -> Result<(Vec<Detection>, StageTimes), RawError> {
        let start = Instant::now();
        let mut model_time = Duration::ZERO;
        let input = self.loaded.config.input.clone();
        let OutputSpec::Detector { decoder, score_threshold, nms_iou, max_detections, containment } = &self.loaded.config.output else {
            return Ok((Vec::new(), StageTimes::default()));
        };
        let (fw, fh) = frame.dimensions();
        let mut all: Vec<RawDetection> = Vec::new();
        for patch in preprocess::plan(&input, fw, fh) {
            preprocess::fill(&input, frame, &patch, &mut self.tensor);
            let t = Instant::now();
            let outputs = self.runner.run(self.tensor.view().into_dyn())?;
            model_time += t.elapsed();
            let raw = match decoder {
                DetectorDecoder::NanodetGfl { strides, reg_max, num_classes } => decode::nanodet_gfl(
                    self.runner.path(),
                    &outputs,
                    strides,
                    *reg_max,
                    *num_classes,
                    input.width,
                    input.height,
                    *score_threshold,
                )?,
            };
            all.extend(
                raw.into_iter()
                    .filter(|d| self.labels.get(d.class_id).is_some_and(Option::is_some))
                    .filter_map(|d| {
                        let bbox = patch.to_frame(&d.bbox).clip(fw, fh)?;
                        Some(RawDetection { bbox, ..d })
                    }),
            );
        }
        let kept = decode::nms(all, f64::from(*nms_iou), f64::from(*containment), *max_detections);
        let dets = kept
            .into_iter()
            .filter_map(|d| {
                let m = self.labels.get(d.class_id)?.as_ref()?;
                Some(Detection {
                    class_id: d.class_id,
                    label: m.label.clone(),
                    class: m.class,
                    type_name: m.type_name.clone(),
                    score: d.score,
                    bbox: d.bbox,
                })
            })
            .collect();
        let total = start.elapsed();
        Ok((dets, StageTimes { model: model_time, other: total.saturating_sub(model_time) }))
    }
}
