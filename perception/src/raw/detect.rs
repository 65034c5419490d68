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
    /// Inside ONNX Runtime (`Session::run` alone).
    pub model: Duration,
    /// Everything else on the caller's thread (resampling unless prefetched,
    /// decoding, NMS, mapping, colour, 3D, tracking).
    pub other: Duration,
    /// Work done ahead on the prefetch thread (image file decoding and
    /// resampling into model tensors), overlapped with the model; zero
    /// without prefetch.
    pub prefetch: Duration,
}

impl StageTimes {
    /// A frame's times from the model's share of the caller's `total`.
    fn split(total: Duration, model: Duration) -> StageTimes {
        StageTimes {
            model,
            other: total.saturating_sub(model),
            prefetch: Duration::ZERO,
        }
    }

    /// Adds another frame's times.
    pub fn add(&mut self, other: StageTimes) {
        self.model += other.model;
        self.other += other.other;
        self.prefetch += other.prefetch;
    }
}

/// A frame resampled into a detector's input tensors, one per patch; made by
/// [`Preparer::prepare`], possibly on another thread, and consumed by
/// [`Detector::detect_prepared`].
///
/// Invariant: `tensors[i]` holds `patches[i]` of a frame of `frame_size`,
/// shaped by [`preprocess::new_tensor`] for the preparer's input spec.
#[derive(Debug, Clone)]
pub struct PreparedFrame {
    /// Frame width and height, pixels.
    pub frame_size: (u32, u32),
    /// The patches the frame was cut into.
    pub patches: Vec<preprocess::Patch>,
    /// One filled input tensor per patch.
    pub tensors: Vec<Array4<f32>>,
}

/// Resamples frames for one detector config; cheap to clone and `Send`, so a
/// prefetch thread can prepare the next frame while the model runs.
#[derive(Debug, Clone)]
pub struct Preparer {
    spec: super::config::InputSpec,
}

impl Preparer {
    /// A preparer for an input spec (a detector's is [`Detector::preparer`]).
    pub fn new(spec: super::config::InputSpec) -> Preparer {
        Preparer { spec }
    }

    /// Resamples `frame` into its patches' tensors, reusing `recycled`
    /// tensors (from an earlier frame) when their shape fits.
    pub fn prepare(&self, frame: &RgbImage, recycled: Vec<Array4<f32>>) -> PreparedFrame {
        let (fw, fh) = frame.dimensions();
        let patches = preprocess::plan(&self.spec, fw, fh);
        let shape = preprocess::new_tensor_shape(&self.spec);
        let mut pool: Vec<Array4<f32>> =
            recycled.into_iter().filter(|t| t.dim() == shape).collect();
        let tensors = patches
            .iter()
            .map(|p| {
                let mut t = pool.pop().unwrap_or_else(|| Array4::zeros(shape));
                preprocess::fill(&self.spec, frame, p, &mut t);
                t
            })
            .collect();
        PreparedFrame {
            frame_size: (fw, fh),
            patches,
            tensors,
        }
    }
}

/// The label map resolved per class id.
#[derive(Debug, Clone)]
struct MappedLabel {
    label: String,
    class: ObjectClass,
    type_name: Option<String>,
}

/// Resolves the config's label map into a table indexed by class id. Label
/// classes are [`super::config::LabelClass`]es, valid by construction; ids
/// are below `num_classes` after [`super::config::ModelConfig::validate`],
/// and an id beyond the table (a hand-built config) is simply never
/// produced by the decoder, so it is left out rather than indexed.
fn label_table(loaded: &LoadedConfig, num_classes: usize) -> Vec<Option<MappedLabel>> {
    let mut table = vec![None; num_classes];
    for l in &loaded.config.labels {
        if let Some(slot) = table.get_mut(l.id) {
            *slot = Some(MappedLabel {
                label: l.name.clone(),
                class: l.class.class(),
                type_name: l.type_name.clone(),
            });
        }
    }
    table
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
        let labels = label_table(&loaded, num_classes);
        let runner = open_model(runtime, &loaded)?;
        let tensor = preprocess::new_tensor(&loaded.config.input);
        Ok(Detector {
            loaded,
            runner,
            tensor,
            labels,
        })
    }

    /// The config in use.
    pub fn config(&self) -> &LoadedConfig {
        &self.loaded
    }

    /// A preparer for this detector's input (see [`PreparedFrame`]).
    pub fn preparer(&self) -> Preparer {
        Preparer {
            spec: self.loaded.config.input.clone(),
        }
    }

    /// Detects mapped objects in one frame. Classes absent from the label map
    /// are dropped before NMS; boxes are clipped to the frame.
    pub fn detect(&mut self, frame: &RgbImage) -> Result<(Vec<Detection>, StageTimes), RawError> {
        let start = Instant::now();
        let patches = preprocess::plan(&self.loaded.config.input, frame.width(), frame.height());
        // One tensor reused for every patch: fill, run, next.
        let mut tensor = std::mem::replace(&mut self.tensor, Array4::zeros((0, 0, 0, 0)));
        let result = self.run_patches(
            frame.dimensions(),
            &patches,
            std::slice::from_mut(&mut tensor),
            Some(frame),
        );
        self.tensor = tensor;
        let (dets, model_time) = result?;
        Ok((dets, StageTimes::split(start.elapsed(), model_time)))
    }

    /// Detects mapped objects in a frame already resampled by this
    /// detector's [`Preparer`]; `other` time is decoding, NMS and mapping
    /// only. The tensors stay in `prepared` for reuse.
    pub fn detect_prepared(
        &mut self,
        prepared: &mut PreparedFrame,
    ) -> Result<(Vec<Detection>, StageTimes), RawError> {
        let start = Instant::now();
        let (dets, model_time) = self.run_patches(
            prepared.frame_size,
            &prepared.patches,
            &mut prepared.tensors,
            None,
        )?;
        Ok((dets, StageTimes::split(start.elapsed(), model_time)))
    }

    /// Runs the model on every patch, decodes, suppresses and maps; returns
    /// the detections and the time inside the model. With `fill` the frame
    /// is resampled into `tensors[0]` before each patch's run; without,
    /// `tensors[i]` already holds patch `i`.
    fn run_patches(
        &mut self,
        frame_size: (u32, u32),
        patches: &[preprocess::Patch],
        tensors: &mut [Array4<f32>],
        fill: Option<&RgbImage>,
    ) -> Result<(Vec<Detection>, Duration), RawError> {
        let mut model_time = Duration::ZERO;
        let input = &self.loaded.config.input;
        let OutputSpec::Detector {
            decoder,
            score_threshold,
            nms_iou,
            max_detections,
            containment,
        } = &self.loaded.config.output
        else {
            return Ok((Vec::new(), Duration::ZERO));
        };
        let (fw, fh) = frame_size;
        let mut all: Vec<RawDetection> = Vec::new();
        for (i, patch) in patches.iter().enumerate() {
            let slot = if fill.is_some() { 0 } else { i };
            let Some(tensor) = tensors.get_mut(slot) else {
                return Err(RawError::Frames {
                    path: self.loaded.config_path.clone(),
                    message: format!(
                        "prepared frame has {} tensors for {} patches",
                        tensors.len(),
                        patches.len()
                    ),
                });
            };
            if let Some(frame) = fill {
                preprocess::fill(input, frame, patch, tensor);
            }
            // Model time is ONNX Runtime's run alone; checking and decoding
            // the outputs (borrowed from the runtime, not copied) is ours.
            let model_path = &self.loaded.model_path;
            let raw = self
                .runner
                .run_with(tensor.view().into_dyn(), |outputs| match decoder {
                    DetectorDecoder::NanodetGfl {
                        strides,
                        reg_max,
                        num_classes,
                    } => decode::nanodet_gfl(
                        model_path,
                        outputs,
                        strides,
                        *reg_max,
                        *num_classes,
                        input.width,
                        input.height,
                        *score_threshold,
                    ),
                })?;
            model_time += self.runner.last_session_time();
            all.extend(
                raw.into_iter()
                    .filter(|d| self.labels.get(d.class_id).is_some_and(Option::is_some))
                    .filter_map(|d| {
                        let bbox = patch.to_frame(&d.bbox).clip(fw, fh)?;
                        Some(RawDetection { bbox, ..d })
                    }),
            );
        }
        let kept = decode::nms(
            all,
            f64::from(*nms_iou),
            f64::from(*containment),
            *max_detections,
        );
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
        Ok((dets, model_time))
    }
}
